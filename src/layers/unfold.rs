//! After the march: undo the caps and folds of the final front, which the core fill cannot
//! mesh without slivers (issue 5).
//!
//! A cap is a front triangle with a corner nearly on its opposite edge; a fold is a front edge
//! where the two triangles close on the core's side to a thin wedge. Over either, every
//! tetrahedron the fill can build is flat (fandisk: its one 4-degree fold held both of its
//! worst slivers). They form where stacks stop beside columns that go on: a column's top comes
//! to lie on the line of two stopped ones. Such a top is pulled back along its last step, by
//! part of that step, to where its front triangles are best; the column keeps its layers (its
//! last is thinner), every cell at it stays valid (exact test), and the moved front crosses
//! nothing (exact tests, moves undone until it does not).

use std::collections::HashMap;

use glam::DVec3;

use super::front::{Columns, Front, NOT_MERGED};
use crate::geometry::triangle_max_angle;
use crate::mesh::{CellKind, VolumeMesh};
use crate::normals::constraint::Slide;
use crate::quality::measures::CellPoints;
use crate::quality::validity::cell_validity;
use crate::surface::Surface;

/// A front triangle whose largest angle is above this (degrees) is a cap...
const CAP_ANGLE: f64 = 160.0;
/// ...and a front edge whose angle on the core's side is below this (degrees) a fold.
const FOLD_ANGLE: f64 = 20.0;
/// The parts of its last step a top may be pulled back by.
const PULL_BACKS: [f64; 4] = [0.2, 0.4, 0.6, 0.8];
/// Rounds over the defects (a move may make one beside it).
const ROUNDS: usize = 3;

/// What [`unfold_front`] did.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct UnfoldStats {
    /// Caps and folds of the front after the march, and after the unfolding.
    pub defects_before: usize,
    pub defects_after: usize,
    /// Column tops pulled back.
    pub moved_tops: usize,
}

/// The final front as triangles (quads split on a diagonal for the crossing test only), with
/// the edges between them.
struct FrontTriangles {
    /// Triangles, right-hand normals towards the core.
    triangles: Vec<[u32; 3]>,
    /// For each node, the triangles at it.
    at_node: HashMap<u32, Vec<u32>>,
    /// For each edge (sorted), the triangles on it.
    on_edge: HashMap<[u32; 2], Vec<u32>>,
}

impl FrontTriangles {
    fn new(triangles: Vec<[u32; 3]>) -> FrontTriangles {
        let mut at_node: HashMap<u32, Vec<u32>> = HashMap::new();
        let mut on_edge: HashMap<[u32; 2], Vec<u32>> = HashMap::new();
        for (t, tri) in triangles.iter().enumerate() {
            for i in 0..3 {
                at_node.entry(tri[i]).or_default().push(t as u32);
                on_edge.entry(sorted(tri[i], tri[(i + 1) % 3])).or_default().push(t as u32);
            }
        }
        FrontTriangles { triangles, at_node, on_edge }
    }

    /// How far the triangles at `v`, and the edges of them, are from being a cap or a fold:
    /// the smallest of 180 less the largest angle and of the core-side angles (degrees).
    fn quality_at(&self, points: &[DVec3], v: u32) -> f64 {
        let Some(around) = self.at_node.get(&v) else { return 180.0 };
        let mut worst = 180.0f64;
        for &t in around {
            let tri = self.triangles[t as usize];
            let [a, b, c] = tri.map(|n| points[n as usize]);
            worst = worst.min(180.0 - triangle_max_angle(a, b, c));
            for i in 0..3 {
                worst = worst.min(self.core_angle(points, sorted(tri[i], tri[(i + 1) % 3])));
            }
        }
        worst
    }

    /// The angle (degrees) on the core's side between the two triangles on `edge`; 180 for an
    /// edge with another number of triangles.
    fn core_angle(&self, points: &[DVec3], edge: [u32; 2]) -> f64 {
        let Some(&[s, t]) = self.on_edge.get(&edge).map(Vec::as_slice) else { return 180.0 };
        let opposite = |t: u32| self.triangles[t as usize].into_iter().find(|n| !edge.contains(n));
        let (Some(c), Some(d)) = (opposite(s), opposite(t)) else { return 180.0 };
        let [a, b, c, d] = [edge[0], edge[1], c, d].map(|n| points[n as usize]);
        let axis = (b - a).normalize_or_zero();
        let across = |p: DVec3| {
            let q = p - a;
            (q - axis * q.dot(axis)).normalize_or_zero()
        };
        let (u, w) = (across(c), across(d));
        let angle = u.angle_between(w).to_degrees();
        let [x, y, z] = self.triangles[s as usize].map(|n| points[n as usize]);
        let normal = (y - x).cross(z - x);
        // `d` on the core's side of `s`: the front turns away from the core (a valley).
        if normal.dot(d - a) > 0.0 {
            angle
        } else {
            360.0 - angle
        }
    }

    fn is_defect(&self, points: &[DVec3], t: u32) -> bool {
        let tri = self.triangles[t as usize];
        let [a, b, c] = tri.map(|n| points[n as usize]);
        triangle_max_angle(a, b, c) > CAP_ANGLE
            || (0..3).any(|i| self.core_angle(points, sorted(tri[i], tri[(i + 1) % 3])) < FOLD_ANGLE)
    }
}

fn sorted(a: u32, b: u32) -> [u32; 2] {
    if a < b {
        [a, b]
    } else {
        [b, a]
    }
}

/// Pull column tops back along their last steps where the final front has caps or folds (see
/// the module). `surface` and `layered` give the walls without layers, which the moved front
/// must not cross either. Updates the moved columns' last steps.
pub fn unfold_front(
    mesh: &mut VolumeMesh,
    columns: &mut Columns,
    front: &Front,
    surface: &Surface,
    layered: impl Fn(u32) -> bool,
) -> UnfoldStats {
    let (front_triangles, quad_nodes) = final_front(front, columns);
    let triangles = FrontTriangles::new(front_triangles);
    let defects = |points: &[DVec3]| {
        (0..triangles.triangles.len() as u32).filter(|&t| triangles.is_defect(points, t)).count()
    };
    let mut stats = UnfoldStats { defects_before: defects(&mesh.points), ..Default::default() };
    if stats.defects_before == 0 {
        stats.defects_after = 0;
        return stats;
    }
    let tops = movable_tops(columns, &quad_nodes);
    let cells = cells_at(mesh, &tops);
    let mut moved: HashMap<u32, (DVec3, f64)> = HashMap::new();
    for _ in 0..ROUNDS {
        let mut changed = false;
        for t in 0..triangles.triangles.len() as u32 {
            if !triangles.is_defect(&mesh.points, t) {
                continue;
            }
            for v in triangles.triangles[t as usize] {
                let Some(&c) = tops.get(&v) else { continue };
                if let Some(pull) = best_pull_back(mesh, columns, &triangles, &cells[&v], v, c) {
                    let old = mesh.points[v as usize];
                    moved.entry(v).or_insert((old, columns.last_step[c]));
                    mesh.points[v as usize] = old - columns.dir[c] * pull;
                    columns.last_step[c] -= pull;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    undo_crossing_moves(mesh, columns, &triangles, &tops, &mut moved, surface, layered);
    stats.moved_tops = moved.len();
    stats.defects_after = defects(&mesh.points);
    stats
}

/// The final front's triangles (the tops of the front's faces, their normals towards the core;
/// quads split on a diagonal) and the nodes of its quads (the fill caps a quad with a pyramid
/// whose apex depends on them: they stay).
fn final_front(front: &Front, columns: &Columns) -> (Vec<[u32; 3]>, Vec<u32>) {
    let mut triangles = Vec::new();
    let mut quad_nodes = Vec::new();
    for f in 0..front.len() {
        let nodes: Vec<u32> = front.face_columns(f).iter().map(|&c| columns.node[c as usize]).collect();
        match super::slab::Polygon::dedup(&nodes).as_ref().map(|p| p.nodes()) {
            Some(&[a, b, c]) => triangles.push([a, b, c]),
            Some(&[a, b, c, d]) => {
                triangles.extend([[a, b, c], [a, c, d]]);
                quad_nodes.extend([a, b, c, d]);
            }
            _ => {}
        }
    }
    (triangles, quad_nodes)
}

/// The tops that may move, with their column: above the wall, of the one column ending there
/// that did not merge (the others merged into it), free to move anywhere, on no quad of the
/// front (the fill caps a quad with a pyramid whose apex depends on its corners).
fn movable_tops(columns: &Columns, quad_nodes: &[u32]) -> HashMap<u32, usize> {
    let mut ending: HashMap<u32, Vec<usize>> = HashMap::new();
    for c in (0..columns.len()).filter(|&c| columns.merged_into[c] == NOT_MERGED) {
        ending.entry(columns.node[c]).or_default().push(c);
    }
    ending
        .into_iter()
        .filter_map(|(v, at)| match at[..] {
            [c] if columns.layers[c] > 0
                && columns.slide[c] == Slide::Free
                && columns.last_step[c] > 0.0
                && !quad_nodes.contains(&v) =>
            {
                Some((v, c))
            }
            _ => None,
        })
        .collect()
}

/// The layer cells at each of `tops`, as (kind, nodes).
fn cells_at(mesh: &VolumeMesh, tops: &HashMap<u32, usize>) -> HashMap<u32, Vec<(CellKind, Vec<u32>)>> {
    let mut cells: HashMap<u32, Vec<(CellKind, Vec<u32>)>> = tops.keys().map(|&v| (v, Vec::new())).collect();
    for (kind, nodes) in mesh.cells() {
        for v in nodes {
            if let Some(list) = cells.get_mut(v) {
                list.push((kind, nodes.to_vec()));
            }
        }
    }
    cells
}

/// The pull-back of top `v` (column `c`) along its last step that best raises the quality of
/// the front around it, keeping every cell at it valid; `None` when none raises it.
fn best_pull_back(
    mesh: &mut VolumeMesh,
    columns: &Columns,
    triangles: &FrontTriangles,
    cells: &[(CellKind, Vec<u32>)],
    v: u32,
    c: usize,
) -> Option<f64> {
    let start = mesh.points[v as usize];
    let mut best = (triangles.quality_at(&mesh.points, v) + 1.0, None);
    for part in PULL_BACKS {
        let pull = part * columns.last_step[c];
        mesh.points[v as usize] = start - columns.dir[c] * pull;
        let valid = cells.iter().all(|(kind, nodes)| {
            let mut x: CellPoints = [DVec3::ZERO; 8];
            for (xi, &n) in x.iter_mut().zip(nodes) {
                *xi = mesh.points[n as usize];
            }
            cell_validity(*kind, &x).is_valid()
        });
        let quality = triangles.quality_at(&mesh.points, v);
        if valid && quality > best.0 {
            best = (quality, Some(pull));
        }
    }
    mesh.points[v as usize] = start;
    best.1
}

/// Undo the moves of tops whose front triangles now cross the front or a wall without layers
/// (exact tests), until none does: the march left a front that crosses nothing.
fn undo_crossing_moves(
    mesh: &mut VolumeMesh,
    columns: &mut Columns,
    triangles: &FrontTriangles,
    tops: &HashMap<u32, usize>,
    moved: &mut HashMap<u32, (DVec3, f64)>,
    surface: &Surface,
    layered: impl Fn(u32) -> bool,
) {
    let mut soup: Vec<[u32; 3]> = triangles.triangles.clone();
    // The walls without layers, their nodes numbered as in the mesh (the wall's points come
    // first in it).
    soup.extend(
        (0..surface.triangles.len())
            .filter(|&t| !layered(surface.triangle_patch[t]))
            .map(|t| surface.triangles[t]),
    );
    loop {
        if moved.is_empty() {
            return;
        }
        let check = Surface {
            points: mesh.points.clone(),
            triangles: soup.clone(),
            triangle_patch: vec![0; soup.len()],
            patch_names: vec![String::new()],
        };
        let queries: Vec<u32> =
            moved.keys().flat_map(|v| triangles.at_node.get(v).into_iter().flatten().copied()).collect();
        let pairs = crate::surface::validate::intersecting_pairs_with(&check, &queries, false);
        let mut undo: Vec<u32> = pairs
            .iter()
            .flat_map(|&(s, t)| [s, t])
            .flat_map(|t| soup[t as usize])
            .filter(|v| moved.contains_key(v))
            .collect();
        undo.sort_unstable();
        undo.dedup();
        if undo.is_empty() {
            return;
        }
        for v in undo {
            let (position, step) = moved.remove(&v).expect("a moved top");
            mesh.points[v as usize] = position;
            columns.last_step[tops[&v]] = step;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles on the edge (0, 1) along x, normals up (+z, the core's side), the second
    /// one's far corner at `d`.
    fn pair(d: DVec3) -> (Vec<DVec3>, FrontTriangles) {
        let points = vec![DVec3::ZERO, DVec3::X, DVec3::new(0.5, -1.0, 0.0), d];
        (points, FrontTriangles::new(vec![[0, 1, 3], [1, 0, 2]]))
    }

    #[test]
    fn the_core_angle_is_180_on_a_plane_small_in_a_valley_and_large_on_a_ridge() {
        let angle = |d: DVec3| {
            let (points, front) = pair(d);
            front.core_angle(&points, [0, 1])
        };
        assert!((angle(DVec3::new(0.5, 1.0, 0.0)) - 180.0).abs() < 1e-9);
        // The second triangle turned up towards the core: a valley of 45 degrees.
        assert!(
            (angle(DVec3::new(0.5, -1.0, 1.0).normalize() + DVec3::new(0.5, 0.0, 0.0)) - 45.0).abs() < 1e-6
        );
        assert!((angle(DVec3::new(0.5, 1.0, -1.0)) - 225.0).abs() < 1e-6);
        // Folded back over the first one, nearly flat: a fold.
        let (points, front) = pair(DVec3::new(0.5, -1.0, 0.05));
        assert!(front.core_angle(&points, [0, 1]) < FOLD_ANGLE);
        assert!(front.is_defect(&points, 0) && front.is_defect(&points, 1));
        assert!(front.quality_at(&points, 3) < FOLD_ANGLE);
    }

    #[test]
    fn a_corner_on_the_opposite_edge_is_a_cap() {
        let (mut points, front) = pair(DVec3::new(0.5, 1.0, 0.0));
        assert!(!front.is_defect(&points, 0));
        points[3] = DVec3::new(0.5, 0.01, 0.0);
        assert!(front.is_defect(&points, 0), "a 178-degree corner");
        assert!(front.quality_at(&points, 3) < 180.0 - CAP_ANGLE);
    }
}
