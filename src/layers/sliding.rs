//! Closing the layers against the patches their columns slid on (symmetry planes, inlets,
//! outlets; see [`crate::normals::constraint`]).
//!
//! The layer cells at such a patch have faces lying in its plane that no other cell shares:
//! they become boundary faces of the patch. The patch's own triangles are then partly under
//! those faces, so the rest of the patch is triangulated anew (a constrained Delaunay
//! triangulation in the plane, bounded by the layers' top edges and the patch's uncovered
//! edges, through the patch's interior vertices that keep a clearance from that boundary), and
//! the core meets these triangles instead of the original ones.

use std::collections::{HashMap, HashSet};

use spade::{AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation};

use super::tuning::TUNING;
use crate::geometry::DVec3;
use crate::mesh::VolumeMesh;
use crate::normals::constraint::Plane;
use crate::surface::Surface;

/// A free face lies on a plane when its nodes are this close to it (fraction of body size).
const ON_PLANE: f64 = 1e-9;

#[derive(Debug, thiserror::Error)]
pub enum SlidingError {
    #[error("a layer face {nodes:?} at {centre:?} has no neighbour and lies on no patch plane")]
    StrayFace { nodes: Vec<u32>, centre: [f64; 3] },
    #[error("patch {patch}: {why}")]
    Retriangulation { patch: String, why: String },
}

/// Add the layer faces lying on the patch planes to the mesh's boundary and return the wall
/// as the core must meet it: the input wall's triangles with every patch that layer faces
/// cover re-triangulated around them, and without the symmetry patches (`symmetry_patch[p]`)
/// the layers slid away from (a body's cut face in an external flow: returned apart, the
/// farfield closes the plane); its points are all the mesh's points (the mesh starts with the
/// wall's, so [`crate::fill::fill_core`] accepts it). The layer faces that slid off the edge
/// of any other patch join the top of the layers ([`super::TOP_PATCH`]): the core meets them.
/// Without such faces, the wall itself.
pub fn close_sliding_patches(
    mesh: &mut VolumeMesh,
    wall: &Surface,
    planes: &[Option<Plane>],
    symmetry_patch: &[bool],
) -> Result<Closed, SlidingError> {
    // Without a planar patch to slide on, every layer face is on the wall or the top.
    let free = if planes.iter().all(Option::is_none) { Vec::new() } else { free_faces(mesh) };
    if free.is_empty() {
        return Ok(Closed { core_wall: wall.clone(), symmetry: Vec::new() });
    }
    let tolerance = ON_PLANE * wall.bounding_box().diagonal();
    let mut on_patch: Vec<Vec<Vec<u32>>> = vec![Vec::new(); wall.patch_names.len()];
    for face in free {
        let p = patch_of_face(&mesh.points, &face, planes, tolerance).ok_or_else(|| {
            let centre = face.iter().map(|&n| mesh.points[n as usize]).sum::<DVec3>() / face.len() as f64;
            SlidingError::StrayFace { nodes: face.clone(), centre: centre.to_array() }
        })?;
        on_patch[p].push(face);
    }
    let top = mesh.patch_names.iter().position(|n| n == super::TOP_PATCH).unwrap_or(mesh.patch_names.len());
    if top == mesh.patch_names.len() {
        mesh.patch_names.push(super::TOP_PATCH.to_owned());
    }
    // Patches whose own triangles the core still meets, and the triangles replacing the others.
    let mut kept = vec![true; wall.patch_names.len()];
    let mut new_triangles: Vec<(u32, [u32; 3])> = Vec::new();
    let mut symmetry = Vec::new();
    for (p, faces) in on_patch.iter().enumerate() {
        let Some(plane) = planes.get(p).copied().flatten().filter(|_| !faces.is_empty()) else { continue };
        let face_patch = if !is_cap(&mesh.points, faces, &plane) {
            kept[p] = false;
            let triangles = retriangulate(&mut mesh.points, wall, p as u32, faces, &plane)
                .map_err(|why| SlidingError::Retriangulation { patch: wall.patch_names[p].clone(), why })?;
            new_triangles.extend(triangles.into_iter().map(|t| (p as u32, t)));
            p
        } else if symmetry_patch.get(p).copied().unwrap_or(false) {
            // A body cut by its symmetry plane: the fluid is across the cut face, which is no
            // boundary; the rest of the plane is.
            kept[p] = false;
            symmetry.push(SymmetryPlane { patch: p as u32, plane: Plane { normal: -plane.normal, ..plane } });
            p
        } else {
            // Layers sliding off the edge of a patch the fluid sees: their faces there are
            // front, which the core meets like the top of the layers.
            top
        };
        for face in faces {
            push_face(mesh, face, face_patch as u32);
        }
    }
    let mut core_wall = Surface { patch_names: wall.patch_names.clone(), ..Default::default() };
    for (t, &tri) in wall.triangles.iter().enumerate() {
        if kept[wall.triangle_patch[t] as usize] {
            core_wall.triangles.push(tri);
            core_wall.triangle_patch.push(wall.triangle_patch[t]);
        }
    }
    for (p, t) in new_triangles {
        core_wall.triangles.push(t);
        core_wall.triangle_patch.push(p);
    }
    core_wall.points = mesh.points.clone();
    Ok(Closed { core_wall, symmetry })
}

fn push_face(mesh: &mut VolumeMesh, face: &[u32], patch: u32) {
    match *face {
        [a, b, c] => {
            mesh.boundary.triangles.push([a, b, c]);
            mesh.boundary.triangle_patch.push(patch);
        }
        [a, b, c, d] => {
            mesh.boundary.quads.push([a, b, c, d]);
            mesh.boundary.quad_patch.push(patch);
        }
        _ => {}
    }
}

/// The wall the core meets, and the symmetry planes that need a farfield.
pub struct Closed {
    pub core_wall: Surface,
    /// Patches whose layer faces lie outside them (a body cut by its symmetry plane, with the
    /// fluid on the other side of its cut face): the core is bounded there by the rest of the
    /// plane, which the farfield must supply.
    pub symmetry: Vec<SymmetryPlane>,
}

/// A symmetry plane of an external flow: the plane of `patch`, its normal into the fluid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SymmetryPlane {
    pub patch: u32,
    pub plane: Plane,
}

/// Do the layer faces on the patch face the way its triangles do? Then they lie outside it:
/// the layers slid away from the patch (a convex junction), not over it.
fn is_cap(points: &[DVec3], faces: &[Vec<u32>], plane: &Plane) -> bool {
    let area: DVec3 = faces
        .iter()
        .map(|f| {
            let x: Vec<DVec3> = f.iter().map(|&n| points[n as usize]).collect();
            (1..x.len() - 1)
                .map(|i| crate::geometry::triangle_area_vector(x[0], x[i], x[i + 1]))
                .sum::<DVec3>()
        })
        .sum();
    area.dot(plane.normal) > 0.0
}

/// Faces of exactly one cell that are not boundary faces of the mesh, oriented out of it.
fn free_faces(mesh: &VolumeMesh) -> Vec<Vec<u32>> {
    // A face's key: its sorted nodes, a triangle's padded with u32::MAX.
    let key = |f: &[u32]| {
        let mut k = [u32::MAX; 4];
        k[..f.len()].copy_from_slice(f);
        k.sort_unstable();
        k
    };
    let mut uses: HashMap<[u32; 4], (u32, [u32; 4], usize)> = HashMap::new();
    for (kind, cell) in mesh.cells() {
        for local in kind.faces() {
            let mut face = [0; 4];
            for (x, &i) in face.iter_mut().zip(local.iter()) {
                *x = cell[i];
            }
            uses.entry(key(&face[..local.len()])).or_insert((0, face, local.len())).0 += 1;
        }
    }
    let listed: HashSet<[u32; 4]> = (mesh.boundary.triangles.iter().map(|t| key(t)))
        .chain(mesh.boundary.quads.iter().map(|q| key(q)))
        .collect();
    let mut free: Vec<Vec<u32>> = uses
        .into_iter()
        .filter(|(k, (n, _, _))| *n == 1 && !listed.contains(k))
        .map(|(_, (_, f, len))| f[..len].to_vec())
        .collect();
    free.sort_unstable();
    free
}

/// The patch whose plane holds every node of `face`.
fn patch_of_face(points: &[DVec3], face: &[u32], planes: &[Option<Plane>], tolerance: f64) -> Option<usize> {
    planes.iter().position(|plane| {
        plane.is_some_and(|plane| {
            face.iter().all(|&n| plane.signed_distance(points[n as usize]).abs() <= tolerance)
        })
    })
}

/// Undirected edge key.
fn edge(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// The new triangles of patch `p` (oriented like its own), covering what `covered` leaves;
/// the points added inside are appended to `points`.
fn retriangulate(
    points: &mut Vec<DVec3>,
    wall: &Surface,
    p: u32,
    covered: &[Vec<u32>],
    plane: &Plane,
) -> Result<Vec<[u32; 3]>, String> {
    // The region's boundary: the patch's border edges and the covering faces' edges, each
    // edge met twice cancelling (a border edge under a layer face, an edge between two faces).
    let patch: Vec<[u32; 3]> = (0..wall.triangles.len())
        .filter(|&t| wall.triangle_patch[t] == p)
        .map(|t| wall.triangles[t])
        .collect();
    let mut count: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &patch {
        for i in 0..3 {
            *count.entry(edge(t[i], t[(i + 1) % 3])).or_default() += 1;
        }
    }
    let border: HashSet<(u32, u32)> = count.iter().filter(|(_, &n)| n == 1).map(|(&e, _)| e).collect();
    let mut boundary: HashMap<(u32, u32), u32> = border.iter().map(|&e| (e, 1)).collect();
    for face in covered {
        for i in 0..face.len() {
            *boundary.entry(edge(face[i], face[(i + 1) % face.len()])).or_default() += 1;
        }
    }
    let mut boundary: Vec<(u32, u32)> =
        boundary.into_iter().filter(|(_, n)| n % 2 == 1).map(|(e, _)| e).collect();
    boundary.sort_unstable(); // the same mesh on every run
    let on_border: HashSet<u32> = border.iter().flat_map(|&(a, b)| [a, b]).collect();
    let mut interior: Vec<u32> = patch.iter().flatten().copied().filter(|n| !on_border.contains(n)).collect();
    interior.sort_unstable();
    interior.dedup();
    interior.retain(|&n| clear_of(points[n as usize], &boundary, points));
    let patch_area: f64 = patch.iter().map(|t| triangle_area(points, *t)).sum();
    triangulate_region(points, &boundary, &interior, plane, patch_area / patch.len().max(1) as f64)
}

/// A constrained Delaunay triangulation of the region of `plane` that `boundary` (node pairs,
/// closed loops; holes allowed) encloses, through the `interior` nodes, refined until no angle
/// is below 25 degrees and no triangle larger than `max_area` or an equilateral triangle on
/// the mean boundary edge (the boundary edges are kept). Added points are appended to
/// `points`, on the plane. The triangles face like `plane.normal`.
pub fn triangulate_region(
    points: &mut Vec<DVec3>,
    boundary: &[(u32, u32)],
    interior: &[u32],
    plane: &Plane,
    max_area: f64,
) -> Result<Vec<[u32; 3]>, String> {
    let (u, v) = plane.frame();
    let flat = |x: DVec3| Point2::new((x - plane.origin).dot(u), (x - plane.origin).dot(v));
    let mut nodes: Vec<u32> =
        boundary.iter().flat_map(|&(a, b)| [a, b]).chain(interior.iter().copied()).collect();
    nodes.sort_unstable();
    nodes.dedup();
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> = ConstrainedDelaunayTriangulation::new();
    let mut handle_node: HashMap<usize, u32> = HashMap::new();
    let mut node_handle: HashMap<u32, spade::handles::FixedVertexHandle> = HashMap::new();
    for &n in &nodes {
        let h = cdt
            .insert(flat(points[n as usize]))
            .map_err(|e| format!("node {n} at {:?}: {e:?}", points[n as usize]))?;
        if let Some(other) = handle_node.insert(h.index(), n) {
            return Err(format!("nodes {other} and {n} coincide at {:?}", points[n as usize]));
        }
        node_handle.insert(n, h);
    }
    for &(a, b) in boundary {
        let (ha, hb) = (node_handle[&a], node_handle[&b]);
        if !cdt.can_add_constraint(ha, hb) {
            return Err(format!(
                "the boundary edge {a}-{b} at {:?} crosses another one (the layers fold on the patch)",
                points[a as usize]
            ));
        }
        cdt.add_constraint(ha, hb);
    }
    refine(&mut cdt, boundary, points, max_area);
    let added: Vec<_> = cdt.fixed_vertices().filter(|h| !handle_node.contains_key(&h.index())).collect();
    for h in added {
        let x = cdt.vertex(h).position();
        handle_node.insert(h.index(), points.len() as u32);
        points.push(plane.project(plane.origin + u * x.x + v * x.y));
    }
    let inside = crate::geometry::cdt::inside_faces(&cdt, |e| cdt.is_constraint_edge(e));
    let mut triangles = Vec::new();
    for face in cdt.inner_faces() {
        if !inside[face.fix().index()] {
            continue;
        }
        let [a, b, c] = face.vertices().map(|h| handle_node[&h.fix().index()]);
        triangles.push([a, b, c]);
    }
    check_covers(&triangles, boundary, points, plane)?;
    Ok(triangles)
}

/// Add points inside the region (see [`triangulate_region`]).
fn refine(
    cdt: &mut ConstrainedDelaunayTriangulation<Point2<f64>>,
    boundary: &[(u32, u32)],
    points: &[DVec3],
    mean_area: f64,
) {
    let lengths = boundary.iter().map(|&(a, b)| (points[a as usize] - points[b as usize]).length());
    let mean_edge = lengths.sum::<f64>() / boundary.len().max(1) as f64;
    let max_area = mean_area.max(0.25 * 3f64.sqrt() * mean_edge * mean_edge);
    let parameters = RefinementParameters::<f64>::new()
        .exclude_outer_faces(true)
        .keep_constraint_edges()
        .with_angle_limit(AngleLimit::from_deg(25.0))
        .with_max_allowed_area(max_area)
        .with_max_additional_vertices(TUNING.sliding.max_added_per_edge * boundary.len() + 1000);
    cdt.refine(parameters);
}

fn triangle_area(points: &[DVec3], [a, b, c]: [u32; 3]) -> f64 {
    crate::geometry::triangle_area_vector(points[a as usize], points[b as usize], points[c as usize]).length()
}

/// Is `x` at least [`TUNING.sliding.clearance`](super::tuning::Sliding::clearance) edge lengths
/// away from every boundary edge?
fn clear_of(x: DVec3, boundary: &[(u32, u32)], points: &[DVec3]) -> bool {
    boundary.iter().all(|&(a, b)| {
        let (a, b) = (points[a as usize], points[b as usize]);
        let length = (b - a).length();
        let t = ((x - a).dot(b - a) / (length * length)).clamp(0.0, 1.0);
        (a + (b - a) * t - x).length() >= TUNING.sliding.clearance * length
    })
}

/// The new triangles must face like the plane and use every boundary edge once.
fn check_covers(
    triangles: &[[u32; 3]],
    boundary: &[(u32, u32)],
    points: &[DVec3],
    plane: &Plane,
) -> Result<(), String> {
    let mut used: HashMap<(u32, u32), u32> = HashMap::new();
    for &[a, b, c] in triangles {
        let [x, y, z] = [a, b, c].map(|n| points[n as usize]);
        if crate::geometry::triangle_area_vector(x, y, z).dot(plane.normal) <= 0.0 {
            return Err(format!("the new triangle {:?} at {:?} is flat or reversed", [a, b, c], x));
        }
        for (p, q) in [(a, b), (b, c), (c, a)] {
            *used.entry(edge(p, q)).or_default() += 1;
        }
    }
    match boundary.iter().find(|&&(a, b)| used.get(&edge(a, b)) != Some(&1)) {
        Some(&(a, b)) => {
            Err(format!("the boundary edge {a}-{b} at {:?} is not closed off", points[a as usize]))
        }
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_with_a_square_hole_is_covered_once_facing_the_plane() {
        let square = |h: f64| [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(x, y)| DVec3::new(x, y, 0.0));
        let mut points: Vec<DVec3> = square(2.0).into_iter().chain(square(0.5)).collect();
        let boundary: Vec<(u32, u32)> =
            (0..4).flat_map(|i| [(i, (i + 1) % 4), (4 + i, 4 + (i + 1) % 4)]).collect();
        let plane = Plane { origin: DVec3::ZERO, normal: DVec3::Z };
        let triangles = triangulate_region(&mut points, &boundary, &[], &plane, 0.5).unwrap();
        let area: f64 = triangles.iter().map(|&t| triangle_area(&points, t)).sum::<f64>() / 2.0;
        assert!((area - (16.0 - 1.0)).abs() < 1e-12, "area {area}");
        assert!(points.iter().all(|p| p.z == 0.0 && p.x.abs() <= 2.0 && p.y.abs() <= 2.0));
        for t in &triangles {
            assert!(!t.iter().all(|&n| n >= 4 && n < 8), "a triangle inside the hole: {t:?}");
        }
    }

    #[test]
    fn crossing_boundary_edges_are_an_error() {
        let mut points: Vec<DVec3> =
            [(0.0, 0.0), (1.0, 1.0), (1.0, 0.0), (0.0, 1.0)].map(|(x, y)| DVec3::new(x, y, 0.0)).to_vec();
        let plane = Plane { origin: DVec3::ZERO, normal: DVec3::Z };
        let e = triangulate_region(&mut points, &[(0, 1), (2, 3)], &[], &plane, 1.0).unwrap_err();
        assert!(e.contains("crosses"), "{e}");
    }
}
