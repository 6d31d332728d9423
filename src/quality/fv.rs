//! Finite-volume measures: the geometry a cell-centred finite-volume solver sees (face centres
//! and area vectors, cell centres and volumes) and what OpenFOAM's `checkMesh` reports on it
//! (non-orthogonality, skewness, face pyramids, cell openness, aspect ratio, face flatness).
//! A solver rejects a mesh with a wrong face pyramid or a face at 90 degrees or more; high skewness
//! and non-orthogonality cost it accuracy and stability.
//!
//! Faces come from the [`FaceTable`], oriented out of their owner. Definitions:
//! - face centre `C_f` and area vector `S_f`: a triangle's centroid and half the cross product of
//!   its edges; a polygon is cut into the triangle fan around the mean of its points, `S_f` is the
//!   sum of the fan's area vectors and `C_f` the mean of the fan's centroids weighted by their areas;
//! - cell centre `C` and volume `V`: from an estimated centre `E` (the mean of the face centres),
//!   the cell is cut into one pyramid per face with apex `E`, of volume `S_f.(C_f - E) / 3` and
//!   centroid `3/4 C_f + 1/4 E`; `V` is their sum and `C` their volume-weighted mean centroid;
//! - non-orthogonality of an interior face: the angle between `S_f` and `d = C_N - C_P` (owner P,
//!   neighbour N); of a boundary face the angle between `S_f` and `C_f - C_P`;
//! - skewness: where the line from `C_P` along `d` crosses the face's plane, at `C_P + s d` with
//!   `s = S_f.(C_f - C_P) / S_f.d`, the skew vector is `v = (C_f - C_P) - s d`; skewness is `|v|`
//!   over the larger of `0.2 |d|` and the extent of the face from `C_f` along `v` (the largest
//!   `|v/|v| . (p - C_f)|` over its points). A boundary face takes for `d` the projection of
//!   `C_f - C_P` on the face normal, so `v` is the offset of `C_f` from the foot of `C_P`;
//! - face pyramids: the pyramid on a face with apex at the owner centre, `S_f.(C_f - C_P) / 3`,
//!   must be positive, and with apex at the neighbour centre, `S_f.(C_f - C_N) / 3`, negative;
//! - cell openness: `|sum S_f| / sum |S_f|` over the cell's outward faces (0 for a closed cell);
//! - aspect ratio: with `A = sum |S_f|` taken component by component (the cell's area seen along
//!   each axis, twice), the larger of `max(A) / min(A)` and `(A_x + A_y + A_z) / (6 V^(2/3))`
//!   (1 for a unit cube);
//! - face flatness: `|S_f|` over the sum of the fan's triangle areas (1 for a flat face, less
//!   for a warped one).

use rayon::prelude::*;

use serde::Serialize;

use super::fv_report::{FaceSides, FvReport, FvTally};
pub use super::fv_report::{SEVERE_NON_ORTHOGONALITY, SOLVER_LIMIT_NON_ORTHOGONALITY};
use super::validity::gather;
use crate::geometry::DVec3;
use crate::mesh::{CellKind, CellNumbering, FaceTable, VolumeMesh};
use crate::surface::topology::Topology;
use crate::surface::Surface;

/// A face's centre, area vector and the area of its triangle fan (for the flatness).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceGeometry {
    pub centre: DVec3,
    pub area: DVec3,
    pub fan_area: f64,
}

impl FaceGeometry {
    /// `|S_f|` over the fan's area: 1 for a flat face.
    pub fn flatness(&self) -> f64 {
        if self.fan_area > 0.0 {
            self.area.length() / self.fan_area
        } else {
            1.0
        }
    }
}

/// Centre and area vector of a face from its points in order (see the module docs).
pub fn face_geometry(p: &[DVec3]) -> FaceGeometry {
    if let [a, b, c] = *p {
        let area = 0.5 * (b - a).cross(c - a);
        return FaceGeometry { centre: (a + b + c) / 3.0, area, fan_area: area.length() };
    }
    let n = p.len().max(1);
    let mean = p.iter().sum::<DVec3>() / n as f64;
    let (mut area, mut fan_area, mut weighted) = (DVec3::ZERO, 0.0, DVec3::ZERO);
    for (i, &a) in p.iter().enumerate() {
        let b = p[(i + 1) % n];
        let s = 0.5 * (b - a).cross(mean - a);
        area += s;
        fan_area += s.length();
        weighted += s.length() * (a + b + mean) / 3.0;
    }
    let centre = if fan_area > 0.0 { weighted / fan_area } else { mean };
    FaceGeometry { centre, area, fan_area }
}

/// A cell's centre and volume, and the checks on its outward faces alone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellGeometry {
    pub centre: DVec3,
    pub volume: f64,
    pub openness: f64,
    pub aspect_ratio: f64,
}

/// Centre, volume, openness and aspect ratio of a cell from its outward faces (module docs).
pub fn cell_geometry(faces: &[FaceGeometry]) -> CellGeometry {
    let estimate = faces.iter().map(|f| f.centre).sum::<DVec3>() / faces.len().max(1) as f64;
    let (mut volume3, mut weighted) = (0.0, DVec3::ZERO);
    let (mut sum, mut magnitude, mut projected) = (DVec3::ZERO, 0.0, DVec3::ZERO);
    for f in faces {
        let pyramid3 = f.area.dot(f.centre - estimate);
        volume3 += pyramid3;
        weighted += pyramid3 * (0.75 * f.centre + 0.25 * estimate);
        sum += f.area;
        magnitude += f.area.length();
        projected += f.area.abs();
    }
    let volume = volume3 / 3.0;
    let centre = if volume3.abs() > 0.0 { weighted / volume3 } else { estimate };
    let openness = if magnitude > 0.0 { sum.length() / magnitude } else { 0.0 };
    let by_axis = projected.max_element() / projected.min_element();
    let by_volume = projected.element_sum() / (6.0 * volume.max(f64::MIN_POSITIVE).powf(2.0 / 3.0));
    CellGeometry { centre, volume, openness, aspect_ratio: by_axis.max(by_volume) }
}

/// Every cell's geometry in [`CellNumbering`] order (NaN for a cell with a node out of range).
pub fn cell_geometries(mesh: &VolumeMesh) -> Vec<CellGeometry> {
    let nan = DVec3::splat(f64::NAN);
    let missing = CellGeometry { centre: nan, volume: f64::NAN, openness: f64::NAN, aspect_ratio: f64::NAN };
    let mut out = Vec::with_capacity(mesh.cell_count());
    for block in &mesh.blocks {
        let kind = block.kind;
        let cells = block.nodes.par_chunks_exact(kind.node_count());
        out.par_extend(
            cells.map(|nodes| gather(&mesh.points, nodes).map_or(missing, |x| one_cell(kind, &x))),
        );
    }
    out
}

fn one_cell(kind: CellKind, x: &[DVec3; 8]) -> CellGeometry {
    let mut faces = [FaceGeometry { centre: DVec3::ZERO, area: DVec3::ZERO, fan_area: 0.0 }; 6];
    let local = kind.faces();
    for (g, f) in faces.iter_mut().zip(local) {
        let mut p = [DVec3::ZERO; 4];
        for (q, &l) in p.iter_mut().zip(f.iter()) {
            *q = x[l];
        }
        *g = face_geometry(&p[..f.len()]);
    }
    cell_geometry(&faces[..local.len()])
}

/// The measures of one face of a [`FaceTable`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceMeasures {
    pub centre: DVec3,
    /// Degrees; NaN where a point or centre is missing.
    pub non_orthogonality: f64,
    pub skewness: f64,
    /// The pyramid on the face with apex at the owner centre is not positive, or at the
    /// neighbour centre not negative.
    pub wrong_pyramid: bool,
    pub flatness: f64,
}

/// The measures of face `f` of `table`, given the cells' geometry.
pub fn face_measures(mesh: &VolumeMesh, table: &FaceTable, cells: &[CellGeometry], f: usize) -> FaceMeasures {
    let nodes = table.nodes(f);
    let mut p = [DVec3::splat(f64::NAN); 4];
    for (q, &n) in p.iter_mut().zip(nodes) {
        *q = mesh.points.get(n as usize).copied().unwrap_or(DVec3::NAN);
    }
    let p = &p[..nodes.len().min(4)];
    let face = face_geometry(p);
    let owner = cells[table.owner(f) as usize].centre;
    let neighbour = table.neighbour(f).map(|n| cells[n as usize].centre);
    let owner_to_face = face.centre - owner;
    let d = match neighbour {
        Some(n) => n - owner,
        None => face.area.normalize_or_zero() * face.area.normalize_or_zero().dot(owner_to_face),
    };
    // Negated so a NaN (a point out of range) counts as wrong.
    let wrong_owner = !(face.area.dot(owner_to_face) > 0.0);
    let wrong_neighbour = neighbour.is_some_and(|n| !(face.area.dot(face.centre - n) < 0.0));
    let across = if neighbour.is_some() { d } else { owner_to_face };
    FaceMeasures {
        centre: face.centre,
        non_orthogonality: angle_deg(face.area, across),
        skewness: skewness(&face, p, owner_to_face, d),
        wrong_pyramid: wrong_owner || wrong_neighbour,
        flatness: face.flatness(),
    }
}

/// The angle between two vectors in degrees (90 when either is zero).
fn angle_deg(a: DVec3, b: DVec3) -> f64 {
    let scale = a.length() * b.length();
    if scale > 0.0 {
        (a.dot(b) / scale).clamp(-1.0, 1.0).acos().to_degrees()
    } else {
        90.0
    }
}

/// Skewness of a face with `owner_to_face = C_f - C_P` and centre line `d` (module docs).
fn skewness(face: &FaceGeometry, p: &[DVec3], owner_to_face: DVec3, d: DVec3) -> f64 {
    let along = face.area.dot(d);
    let s = if along != 0.0 { face.area.dot(owner_to_face) / along } else { 0.0 };
    let skew = owner_to_face - s * d;
    let direction = skew.normalize_or_zero();
    let extent = p.iter().map(|&q| direction.dot(q - face.centre).abs()).fold(0.2 * d.length(), f64::max);
    if extent > 0.0 {
        skew.length() / extent
    } else {
        0.0
    }
}

/// The measures of every face of `table`, in its order.
pub fn all_face_measures(mesh: &VolumeMesh, table: &FaceTable, cells: &[CellGeometry]) -> Vec<FaceMeasures> {
    (0..table.len()).into_par_iter().map(|f| face_measures(mesh, table, cells, f)).collect()
}

/// The kinds of the cells on the two sides of face `f` (None across a boundary).
pub fn face_kinds(table: &FaceTable, numbering: &CellNumbering, f: usize) -> (CellKind, Option<CellKind>) {
    let kind = |c: u32| numbering.locate(c as usize).0;
    (kind(table.owner(f)), table.neighbour(f).map(kind))
}

/// The non-orthogonality of the interior faces touching each kind of cell, in degrees, in
/// [`CellKind::ALL`] order: a face between two kinds counts for both, between two cells of one
/// kind once.
pub fn non_orthogonality_by_kind(mesh: &VolumeMesh) -> [Vec<f64>; 4] {
    let table = FaceTable::new(mesh);
    let numbering = CellNumbering::new(mesh);
    let cells = cell_geometries(mesh);
    let faces: Vec<(f64, (CellKind, Option<CellKind>))> = (0..table.interior_count())
        .into_par_iter()
        .map(|f| {
            (face_measures(mesh, &table, &cells, f).non_orthogonality, face_kinds(&table, &numbering, f))
        })
        .collect();
    CellKind::ALL.map(|kind| {
        let touches = |(a, b): (CellKind, Option<CellKind>)| a == kind || b == Some(kind);
        faces.iter().filter(|(_, kinds)| touches(*kinds)).map(|(value, _)| *value).collect()
    })
}

/// The finite-volume measures of `mesh`, whose faces are `table`.
pub fn measure(mesh: &VolumeMesh, table: &FaceTable) -> FvReport {
    let cells = cell_geometries(mesh);
    let numbering = CellNumbering::new(mesh);
    let faces = (0..table.len()).into_par_iter().fold(FvTally::default, |tally, f| {
        let (owner, neighbour) = face_kinds(table, &numbering, f);
        let sides = FaceSides { owner, neighbour, across: table.across(f) };
        tally.add_face(&face_measures(mesh, table, &cells, f), &sides)
    });
    let all = cells.par_iter().fold(FvTally::default, |tally, c| tally.add_cell(c));
    faces.chain(all).reduce(FvTally::default, FvTally::merge).finish()
}

/// What a wall's own triangulation gives the lateral faces of the prisms extruded from it
/// ([`wall_non_orthogonality`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct WallNonOrthogonality {
    /// Edges between two triangles that get layers.
    pub edges: usize,
    /// Degrees; 0 without such edges.
    pub max: f64,
    pub edges_above_70: usize,
    pub edges_above_85: usize,
    /// The middle of the worst edge.
    pub worst_at: Option<[f64; 3]>,
}

/// The non-orthogonality of the lateral faces of thin prisms over the wall's edges: over an
/// edge shared by two triangles that get layers, the angle between the lateral face's area
/// vector (the edge crossed with the mean of the triangles' unit normals) and the line between
/// the triangles' centroids, the limit of the face's non-orthogonality as the prisms' height
/// goes to 0. It is set by the triangulation alone (two needle triangles side by side make it
/// near 90 degrees), so every layer of full prisms over the edge repeats it, whatever the
/// layers do: only another wall triangulation changes it.
pub fn wall_non_orthogonality(
    surface: &Surface,
    topology: &Topology,
    layered_patch: &[bool],
) -> WallNonOrthogonality {
    let layered = |t: u32| layered_patch[surface.triangle_patch[t as usize] as usize];
    let at = |v: u32| surface.points[v as usize];
    let centroid = |t: u32| surface.triangle_points(t as usize).iter().sum::<DVec3>() / 3.0;
    let normal = |t: u32| surface.triangle_normal(t as usize);
    let angles: Vec<(f64, u32)> = (0..topology.edge_count() as u32)
        .into_par_iter()
        .filter_map(|e| {
            let [u, w] = topology.edge_uses(e) else { return None };
            let (s, t) = (u.triangle, w.triangle);
            if !(layered(s) && layered(t)) {
                return None;
            }
            let [a, b] = topology.edges[e as usize].map(at);
            let face = (b - a).cross(normal(s) + normal(t));
            let across = centroid(t) - centroid(s);
            let angle = angle_deg(face, across);
            Some((angle.min(180.0 - angle), e))
        })
        .collect();
    let worst = angles.iter().max_by(|x, y| x.0.total_cmp(&y.0));
    WallNonOrthogonality {
        edges: angles.len(),
        max: worst.map_or(0.0, |w| w.0),
        edges_above_70: angles.iter().filter(|a| a.0 > SEVERE_NON_ORTHOGONALITY).count(),
        edges_above_85: angles.iter().filter(|a| a.0 > SOLVER_LIMIT_NON_ORTHOGONALITY).count(),
        worst_at: worst.map(|&(_, e)| {
            let [a, b] = topology.edges[e as usize].map(at);
            (0.5 * (a + b)).to_array()
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::check;
    use crate::quality::fv_report::WORST_FACES as WORST;
    use crate::quality::samples::{cube_grid, CubeSplit};

    fn measures_of(mesh: &VolumeMesh) -> (FaceTable, Vec<FaceMeasures>) {
        let table = FaceTable::new(mesh);
        let cells = cell_geometries(mesh);
        let faces = (0..table.len()).map(|f| face_measures(mesh, &table, &cells, f)).collect();
        (table, faces)
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * (1.0 + b.abs())
    }

    /// A unit cube's faces, each cut along a diagonal, stay well below 70 deg (over a diagonal
    /// the centroids lie square to it); sheared into long thin parallelograms, their diagonals'
    /// faces pass 85 deg; patches without layers are left out.
    #[test]
    fn wall_non_orthogonality_is_that_of_thin_prisms_over_the_wall_edges() {
        use crate::surface::shapes::cuboid;
        let measure = |surface: &Surface, layered: &[bool]| {
            wall_non_orthogonality(surface, &Topology::new(surface), layered)
        };
        let cube = cuboid(DVec3::ONE, 1);
        let every = vec![true; cube.patch_names.len()];
        let wall = measure(&cube, &every);
        assert_eq!(wall.edges, 18);
        assert_eq!((wall.edges_above_70, wall.edges_above_85), (0, 0));
        // Over a cube's diagonal the centroids are square to it; over its edges they are not.
        assert!(wall.max > 0.0 && wall.max < 70.0, "{wall:?}");
        let none = measure(&cube, &vec![false; cube.patch_names.len()]);
        assert_eq!((none.edges, none.max, none.worst_at), (0, 0.0, None));
        // Sheared along x into a parallelogram 50 times longer than tall on its top: the top's
        // diagonal runs nearly along x, and its centroids lie nearly along it.
        let mut sheared = cube.clone();
        for p in &mut sheared.points {
            p.x = 50.0 * p.x + 50.0 * p.y;
        }
        let wall = measure(&sheared, &vec![true; sheared.patch_names.len()]);
        assert!(wall.max > 85.0 && wall.edges_above_85 >= 1, "{wall:?}");
    }

    #[test]
    fn a_unit_cube_grid_is_orthogonal_and_unskewed() {
        let mesh = cube_grid([3, 2, 2], DVec3::ONE, &|_| CubeSplit::Hexahedron, &|_| 0);
        let r = check(&mesh).fv;
        assert_eq!((r.faces, r.interior_faces, r.boundary_faces), (52, 20, 32));
        assert!(r.non_orthogonality_max < 1e-6 && r.boundary_non_orthogonality_max < 1e-6, "{r}");
        assert!(r.skewness_max < 1e-12 && r.wrong_face_pyramids == 0, "{r}");
        assert!(
            r.cell_openness_max < 1e-15 && close(r.aspect_ratio_max, 1.0) && close(r.face_flatness_min, 1.0)
        );
        assert!(close(r.cell_volume_min, 1.0) && r.rejection().is_none());
        assert_eq!(r.non_orthogonality_by_kinds["hexahedron-hexahedron"].faces, 20);
    }

    #[test]
    fn a_unit_cube_has_the_centre_and_volume_of_its_pyramids() {
        let mesh = cube_grid([1, 1, 1], DVec3::new(2.0, 1.0, 1.0), &|_| CubeSplit::Hexahedron, &|_| 0);
        let c = cell_geometries(&mesh)[0];
        assert!(close(c.volume, 2.0) && (c.centre - DVec3::new(1.0, 0.5, 0.5)).length() < 1e-15);
        // Areas seen along the axes 2, 4, 4: 4 / 2 beats (2 + 4 + 4) / (6 * 2^(2/3)).
        assert!(close(c.aspect_ratio, 2.0), "{}", c.aspect_ratio);
    }

    /// Two unit cubes along x, the far face moved by `shift`.
    fn hexahedral_pair(shift: DVec3) -> VolumeMesh {
        let mut mesh = cube_grid([2, 1, 1], DVec3::ONE, &|_| CubeSplit::Hexahedron, &|_| 0);
        for p in mesh.points.iter_mut().filter(|p| p.x == 2.0) {
            *p += shift;
        }
        mesh
    }

    #[test]
    fn a_sheared_hexahedral_pair_has_the_angle_of_its_centre_line() {
        // Cell 1 is a parallelepiped: centre (1.5, 1, 0.5), so d = (1, 0.5, 0) against the normal x.
        let (table, faces) = measures_of(&hexahedral_pair(DVec3::new(0.0, 1.0, 0.0)));
        assert_eq!(table.interior_count(), 1);
        let shared = faces[0];
        assert!(close(shared.non_orthogonality, 0.5f64.atan().to_degrees()), "{shared:?}");
        // The centre line crosses x = 1 at y = 0.75: 0.25 from the face centre, over its half width.
        assert!(close(shared.skewness, 0.5), "{shared:?}");
        assert!(!shared.wrong_pyramid);
    }

    #[test]
    fn a_face_tilted_along_the_centre_line_is_non_orthogonal_but_not_skewed() {
        // x' = x + z tan 30 deg: the shared face tilts by 30 deg, the centre line stays along x.
        let mut mesh = cube_grid([2, 1, 1], DVec3::ONE, &|_| CubeSplit::Hexahedron, &|_| 0);
        let t = 30f64.to_radians().tan();
        mesh.points.iter_mut().for_each(|p| p.x += t * p.z);
        let (_, faces) = measures_of(&mesh);
        assert!(close(faces[0].non_orthogonality, 30.0) && faces[0].skewness < 1e-12, "{:?}", faces[0]);
    }

    /// Tetrahedra (a, b, c, top) and (a, c, b, bottom) on the triangle a b c in z = 0.
    fn tetrahedron_pair(bottom: DVec3) -> VolumeMesh {
        let mut mesh = VolumeMesh { zone_names: vec!["fluid".into()], ..Default::default() };
        mesh.points = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z, bottom];
        mesh.push_cell(CellKind::Tetrahedron, &[0, 1, 2, 3], 0);
        mesh.push_cell(CellKind::Tetrahedron, &[0, 2, 1, 4], 0);
        mesh
    }

    #[test]
    fn a_tetrahedron_pair_is_orthogonal_with_a_known_skewness() {
        let (table, faces) = measures_of(&tetrahedron_pair(-DVec3::Z));
        assert_eq!((table.len(), table.interior_count()), (7, 1));
        // Centres (1/4, 1/4, +-1/4) cross z = 0 at (1/4, 1/4), 1/12 sqrt 2 from the face centre
        // (1/3, 1/3); the face reaches 2/3 sqrt 2 / 2 from its centre that way.
        assert!(faces[0].non_orthogonality < 1e-6 && close(faces[0].skewness, 0.25), "{:?}", faces[0]);
        assert!(faces.iter().all(|f| !f.wrong_pyramid));
    }

    #[test]
    fn an_inverted_face_pyramid_is_counted_and_rejected() {
        // The second tetrahedron's apex is above the shared face: its centre is on the owner's side.
        let mesh = tetrahedron_pair(DVec3::new(0.0, 0.0, 0.5));
        let (_, faces) = measures_of(&mesh);
        assert!(faces[0].wrong_pyramid, "{:?}", faces[0]);
        let r = check(&mesh).fv;
        assert!(r.wrong_face_pyramids >= 1 && r.rejection().is_some(), "{r}");
        assert_eq!(r.wrong_pyramid_examples.len(), r.wrong_face_pyramids.min(WORST));
    }

    #[test]
    fn a_warped_quad_is_less_flat_than_a_plane_one() {
        let flat = face_geometry(&[DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y]);
        assert!(close(flat.flatness(), 1.0) && close(flat.area.z, 1.0));
        assert!((flat.centre - DVec3::new(0.5, 0.5, 0.0)).length() < 1e-15);
        let warped = face_geometry(&[DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 1.0), DVec3::Y]);
        assert!(warped.flatness() < 0.99);
    }
}
