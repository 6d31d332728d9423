//! Checking the mesher's output against the boundary it was given, and merging it into the
//! layered mesh.

use std::collections::HashMap;

use super::front::CoreBuild;
use super::{sorted_triangle, ClosedBoundary, CoreGuide, CoreStats, CoreTets, FillError};
use crate::geometry::predicates::{orient3d, Sign};
use crate::geometry::DVec3;
use crate::mesh::compact_points;
use crate::mesh::{CellKind, VolumeMesh};
use crate::quality::measures::{dihedral_range, edge_face_pairs};

/// No point of the mesh's boundary faces (the wall, the farfield, the layer faces on patches
/// without layers) may have moved in the improvement: boundary point `i` is mesh node
/// `nodes[i]`, at `core.points[i]` now.
pub(super) fn check_mesh_boundary_kept(
    build: &CoreBuild,
    nodes: &[u32],
    core: &CoreTets,
) -> Result<(), FillError> {
    let on_boundary: std::collections::HashSet<u32> = build.mesh.boundary.nodes().collect();
    let moved = nodes
        .iter()
        .zip(&core.points)
        .find(|&(m, p)| build.mesh.points[*m as usize] != *p && on_boundary.contains(m));
    match moved {
        Some((&m, p)) => Err(FillError::BadOutput(format!(
            "mesh boundary node {m} moved from {:?} to {:?} in the core's improvement",
            build.mesh.points[m as usize].to_array(),
            p.to_array()
        ))),
        None => Ok(()),
    }
}

/// The tetrahedra must be positive, keep the boundary points first and unchanged, and have
/// every boundary triangle as a face of exactly one tetrahedron, on its inner side.
pub(super) fn check_boundary_kept(boundary: &ClosedBoundary, core: &CoreTets) -> Result<(), FillError> {
    let n = boundary.points.len();
    if core.points.len() < n {
        return Err(FillError::BadOutput(format!("{} points for {n} boundary points", core.points.len())));
    }
    if let Some(i) = (0..n).find(|&i| core.points[i] != boundary.points[i]) {
        return Err(FillError::BadOutput(format!(
            "point {i} moved from {:?} to {:?} (of {n} boundary points)",
            boundary.points[i], core.points[i]
        )));
    }
    check_tets_positive(core)?;
    let index: HashMap<[u32; 3], usize> =
        boundary.triangles.iter().enumerate().map(|(t, &tri)| (sorted_triangle(tri), t)).collect();
    let mut tets_on = vec![0usize; boundary.triangles.len()];
    for tet in &core.tets {
        for face in CellKind::Tetrahedron.faces() {
            let key = sorted_triangle([tet[face[0]], tet[face[1]], tet[face[2]]]);
            let Some(&t) = index.get(&key) else { continue };
            let opposite = tet.iter().copied().find(|v| !key.contains(v)).unwrap_or(tet[0]);
            let [a, b, c] = boundary.triangles[t].map(|v| core.points[v as usize]);
            if orient3d(a, b, c, core.points[opposite as usize]) == Sign::Positive {
                tets_on[t] += 1;
            } else {
                // A tetrahedron outside the region (behind a boundary triangle) is never right.
                tets_on[t] += 2;
            }
        }
    }
    match tets_on.iter().position(|&k| k != 1) {
        None => Ok(()),
        Some(t) => {
            let nodes = boundary.triangles[t];
            let centre = nodes.iter().map(|&v| core.points[v as usize]).sum::<DVec3>() / 3.0;
            Err(FillError::BoundaryNotKept {
                triangle: t,
                nodes,
                centre: centre.to_array(),
                tets: tets_on[t],
            })
        }
    }
}

/// Put the guide's interior points that are still where they were given (the mesher may move
/// or drop some, and TetGen's optimisation smooths them like its own) right after the
/// boundary's, in the guide's order, renumbering the tetrahedra; returns how many there are.
/// Then the fixed prefix of points holds every seed in place, not only those before the first
/// one missing.
pub(super) fn seeds_in_place_first(
    boundary: &ClosedBoundary,
    guide: &CoreGuide,
    core: &mut CoreTets,
) -> usize {
    let n = boundary.points.len();
    let key = |p: DVec3| p.to_array().map(f64::to_bits);
    let mut at: HashMap<[u64; 3], usize> = HashMap::with_capacity(core.points.len().saturating_sub(n));
    for (i, p) in core.points.iter().enumerate().skip(n) {
        at.entry(key(*p)).or_insert(i);
    }
    let mut placed = vec![false; core.points.len()];
    let mut order: Vec<usize> = (0..n).collect();
    let seeds = &guide.interior[..guide.interior.len() - guide.sizing_points];
    for i in seeds.iter().filter_map(|g| at.get(&key(*g)).copied()) {
        if !std::mem::replace(&mut placed[i], true) {
            order.push(i);
        }
    }
    let in_place = order.len() - n;
    order.extend((n..core.points.len()).filter(|&i| !placed[i]));
    let mut new_index = vec![0u32; core.points.len()];
    for (new, &old) in order.iter().enumerate() {
        new_index[old] = new as u32;
    }
    core.points = order.iter().map(|&i| core.points[i]).collect();
    for t in &mut core.tets {
        *t = t.map(|v| new_index[v as usize]);
    }
    in_place
}

/// Drop the points after the first `fixed` that no tetrahedron uses (a mesher may leave an
/// interior point it was given out of its mesh), renumbering the others.
pub(super) fn drop_unused_points(core: &mut CoreTets, fixed: usize) {
    let mut used = vec![false; core.points.len()];
    used[..fixed].fill(true);
    for &v in core.tets.iter().flatten() {
        used[v as usize] = true;
    }
    if used.iter().all(|&u| u) {
        return;
    }
    let (points, new_index) = compact_points(&core.points, &used);
    core.points = points;
    for t in &mut core.tets {
        *t = t.map(|v| new_index[v as usize]);
    }
}

fn check_tets_positive(core: &CoreTets) -> Result<(), FillError> {
    let points = core.points.len();
    for (i, tet) in core.tets.iter().enumerate() {
        if tet.iter().any(|&v| v as usize >= points) {
            return Err(FillError::BadOutput(format!("tetrahedron {i} {tet:?} has a node >= {points}")));
        }
        let [a, b, c, d] = tet.map(|v| core.points[v as usize]);
        if orient3d(a, b, c, d) != Sign::Positive {
            return Err(FillError::BadOutput(format!(
                "tetrahedron {i} {tet:?} is not positive: {:?}",
                [a, b, c, d].map(|p| p.to_array())
            )));
        }
    }
    Ok(())
}

/// Append the mesher's points and tetrahedra (boundary point `i` is mesh node `nodes[i]`).
pub(super) fn merge(build: CoreBuild, nodes: &[u32], core: &CoreTets) -> (VolumeMesh, CoreStats) {
    let CoreBuild { mut mesh, core_zone, pyramids, .. } = build;
    // The front points the improvement slid down their columns.
    for (&m, &p) in nodes.iter().zip(&core.points) {
        mesh.points[m as usize] = p;
    }
    let offset = mesh.points.len() as u32;
    let n = nodes.len() as u32;
    mesh.points.extend_from_slice(&core.points[nodes.len()..]);
    let node = |v: u32| if v < n { nodes[v as usize] } else { offset + (v - n) };
    let pairs = edge_face_pairs(CellKind::Tetrahedron);
    let (mut min_dihedral, mut max_dihedral) = (f64::INFINITY, f64::NEG_INFINITY);
    for tet in &core.tets {
        let mut x = [DVec3::ZERO; 8];
        for (xi, &v) in x.iter_mut().zip(tet) {
            *xi = core.points[v as usize];
        }
        let (lo, hi) = dihedral_range(CellKind::Tetrahedron, &x, &pairs);
        min_dihedral = min_dihedral.min(lo);
        max_dihedral = max_dihedral.max(hi);
        mesh.push_cell(CellKind::Tetrahedron, &tet.map(node), core_zone);
    }
    let stats = CoreStats {
        tetrahedra: core.tets.len(),
        pyramids,
        steiner_points: core.points.len() - nodes.len(),
        min_dihedral,
        max_dihedral,
        ..Default::default()
    };
    (mesh, stats)
}
