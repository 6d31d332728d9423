//! After the march: undo the caps and folds of the final front, which the core fill cannot
//! mesh without slivers.
//!
//! A cap is a front triangle with a corner nearly on its opposite edge; a fold is a front edge
//! where the two triangles close on the core's side to a thin wedge. Over either, every
//! tetrahedron the fill can build is flat (fandisk: its one 4-degree fold held both of its
//! worst slivers). They form where stacks stop beside columns that go on: a column's top comes
//! to lie on the line of two stopped ones. Such a top is pulled back along its last step, by
//! part of that step, to where its front triangles are best; the column keeps its layers (its
//! last is thinner), every cell at it stays valid (exact test), and the moved front crosses
//! nothing (exact tests, moves undone until it does not). A stack at its full count ends on
//! the exact offset and stays, but at a fold so sharp that every core tetrahedron on its edge
//! would be a sliver
//! ([`TUNING.unfolding.sliver_fold_angle`](super::tuning::Unfolding::sliver_fold_angle)).

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;

use super::front::{Columns, Front};
use super::guard::pyramid_apex;
use super::tuning::TUNING;
use crate::geometry::{signed_turn_deg, triangle_max_angle};
use crate::mesh::{sorted_edge, CellKind, VolumeMesh};
use crate::normals::constraint::Slide;
use crate::quality::validity::{cell_validity, gather};
use crate::surface::topology::{group_by_key_with, opposite_vertex};
use crate::surface::Surface;

/// What [`unfold_front`] did.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct UnfoldStats {
    /// Caps and folds of the front after the march, and after the unfolding.
    pub defects_before: usize,
    pub defects_after: usize,
    /// Column tops pulled back.
    pub moved_tops: usize,
    /// Tops whose move was undone: their triangles crossed the core's boundary.
    pub undone_moves: usize,
}

/// The core's boundary over the layers as the fill will see it: the front's triangles and, for
/// each quad, the four triangles of the pyramid the fill caps it with (its apex placed as the
/// fill places it, [`pyramid_apex`]), with the edges between them.
struct CoreFront {
    /// The mesh's points, then each quad's apex.
    points: Vec<DVec3>,
    /// Triangles, right-hand normals towards the core.
    triangles: Vec<[u32; 3]>,
    quads: Vec<[u32; 4]>,
    /// The first apex's point.
    first_apex: usize,
    /// For each node, the quads at it (CSR by node: offsets, quads).
    quads_at: (Vec<u32>, Vec<u32>),
    /// For each node, the triangles at it, in increasing order (CSR by node).
    at_node: (Vec<u32>, Vec<u32>),
}

impl CoreFront {
    /// `None` when a quad cannot be capped (the fill would fail there whatever moves). The
    /// triangles' corners are distinct nodes (so are the tops [`final_front`] gives).
    fn new(mut points: Vec<DVec3>, mut triangles: Vec<[u32; 3]>, quads: Vec<[u32; 4]>) -> Option<CoreFront> {
        let first_apex = points.len();
        for (q, quad) in quads.iter().enumerate() {
            points.push(pyramid_apex(quad.map(|n| points[n as usize]))?);
            let apex = (first_apex + q) as u32;
            for i in 0..4 {
                triangles.push([quad[i], quad[(i + 1) % 4], apex]);
            }
        }
        let by_node = |corners: &[u32], per_item: usize| {
            let items: Vec<u32> = (0..corners.len()).map(|i| (i / per_item) as u32).collect();
            group_by_key_with(corners, &items, points.len())
        };
        let quads_at = by_node(quads.as_flattened(), 4);
        let at_node = by_node(triangles.as_flattened(), 3);
        Some(CoreFront { points, triangles, quads, first_apex, quads_at, at_node })
    }

    /// The quads at node `v`.
    fn quads_at(&self, v: u32) -> &[u32] {
        let (start, quads) = &self.quads_at;
        &quads[start[v as usize] as usize..start[v as usize + 1] as usize]
    }

    /// The triangles at node `v`, in increasing order.
    fn triangles_at(&self, v: u32) -> &[u32] {
        let (start, triangles) = &self.at_node;
        &triangles[start[v as usize] as usize..start[v as usize + 1] as usize]
    }

    fn corners(&self, t: u32) -> [DVec3; 3] {
        self.triangles[t as usize].map(|n| self.points[n as usize])
    }

    fn cap_angle(&self, t: u32) -> f64 {
        let [a, b, c] = self.corners(t);
        triangle_max_angle(a, b, c)
    }

    /// Put node `v` at `p`, with the apexes of its quads; `false` (and nothing moved) when a
    /// quad of it could not be capped there.
    fn move_node(&mut self, v: u32, p: DVec3) -> bool {
        self.move_nodes(&[(v, p)])
    }

    /// Move several nodes at once (`(node, position)`), their quads' apexes after all of them;
    /// `false`, with nothing moved, when a quad at them has no cap.
    fn move_nodes(&mut self, moves: &[(u32, DVec3)]) -> bool {
        let old: Vec<DVec3> = moves.iter().map(|&(v, _)| self.points[v as usize]).collect();
        for &(v, p) in moves {
            self.points[v as usize] = p;
        }
        let mut quads: Vec<u32> = moves.iter().flat_map(|&(v, _)| self.quads_at(v).iter().copied()).collect();
        quads.sort_unstable();
        quads.dedup();
        let apexes: Option<Vec<DVec3>> = quads
            .iter()
            .map(|&q| pyramid_apex(self.quads[q as usize].map(|n| self.points[n as usize])))
            .collect();
        let Some(apexes) = apexes else {
            for (&(v, _), &p) in moves.iter().zip(&old) {
                self.points[v as usize] = p;
            }
            return false;
        };
        for (&q, apex) in quads.iter().zip(apexes) {
            self.points[self.first_apex + q as usize] = apex;
        }
        true
    }

    /// The triangles a move of node `v` changes: those at it and at its quads' apexes.
    fn triangles_moved_by(&self, v: u32) -> Vec<u32> {
        let apexes = self.quads_at(v).iter().map(|&q| (self.first_apex + q as usize) as u32);
        let mut around: Vec<u32> =
            std::iter::once(v).chain(apexes).flat_map(|n| self.triangles_at(n).iter().copied()).collect();
        around.sort_unstable();
        around.dedup();
        around
    }

    /// How far the triangles a move of `v` changes, and their edges, are from being a cap or
    /// a fold: the smallest of 180 less the largest angle and of the core-side angles (degrees).
    fn quality_at(&self, v: u32) -> f64 {
        let mut worst = 180.0f64;
        for t in self.triangles_moved_by(v) {
            worst = worst.min(180.0 - self.cap_angle(t));
            let tri = self.triangles[t as usize];
            for i in 0..3 {
                worst = worst.min(self.core_angle(sorted_edge(tri[i], tri[(i + 1) % 3])));
            }
        }
        worst
    }

    /// The angle (degrees) on the core's side between the two triangles on `edge`: 180 plus
    /// the signed turn there (below 180 in a valley, near 0 at a fold); 180 for an edge with
    /// another number of triangles.
    fn core_angle(&self, edge: [u32; 2]) -> f64 {
        let [a, b] = edge;
        let mut on_edge = self.triangles_at(a).iter().filter(|&&t| self.triangles[t as usize].contains(&b));
        let (Some(&s), Some(&t), None) = (on_edge.next(), on_edge.next(), on_edge.next()) else {
            return 180.0;
        };
        let far = opposite_vertex(self.triangles[t as usize], edge);
        180.0 + signed_turn_deg(self.corners(s), self.corners(t), self.points[far as usize])
    }

    /// Whether triangle `t` is a cap or on a fold.
    fn is_defect(&self, t: u32) -> bool {
        self.cap_angle(t) > TUNING.unfolding.cap_angle
            || self.has_fold_sharper_than(t, TUNING.unfolding.fold_angle)
    }

    /// Whether an edge of triangle `t` has an angle on the core's side below `angle` (degrees).
    fn has_fold_sharper_than(&self, t: u32, angle: f64) -> bool {
        let tri = self.triangles[t as usize];
        (0..3).any(|i| self.core_angle(sorted_edge(tri[i], tri[(i + 1) % 3])) < angle)
    }

    /// The corners of the quads whose apexes are among `nodes` (a corner's move moves its apex).
    fn quad_corners_of_apexes(&self, nodes: [u32; 3]) -> Vec<u32> {
        nodes
            .iter()
            .filter_map(|&n| (n as usize).checked_sub(self.first_apex))
            .flat_map(|q| self.quads[q])
            .collect()
    }

    fn defects(&self) -> usize {
        (0..self.triangles.len() as u32).into_par_iter().filter(|&t| self.is_defect(t)).count()
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
    at_slivers: &[bool],
) -> UnfoldStats {
    let (triangles, quads) = final_front(front, columns);
    let Some(mut core_front) = CoreFront::new(mesh.points.clone(), triangles, quads) else {
        return UnfoldStats::default();
    };
    let mut stats = UnfoldStats { defects_before: core_front.defects(), ..Default::default() };
    let at_sliver = |c: usize| at_slivers.get(columns.wall_vertex[c] as usize).copied().unwrap_or(false);
    if stats.defects_before == 0 && !(0..columns.len()).any(at_sliver) {
        return stats;
    }
    let tops = movable_tops(columns, &core_front, &at_sliver);
    let sliver_top = |v: u32| tops.get(&v).is_some_and(|&c| at_sliver(c));
    let cells = cells_at(mesh, &tops);
    let mut moved: HashMap<u32, (DVec3, f64)> = HashMap::new();
    for _ in 0..TUNING.unfolding.rounds {
        let mut changed = false;
        for t in 0..core_front.triangles.len() as u32 {
            if !core_front.is_defect(t) && !core_front.triangles[t as usize].into_iter().any(sliver_top) {
                continue;
            }
            let forces_slivers = core_front.has_fold_sharper_than(t, TUNING.unfolding.sliver_fold_angle);
            for v in core_front.triangles[t as usize] {
                let Some(&c) = tops.get(&v) else { continue };
                if ends_at_full_count(columns, c) && !forces_slivers && !at_sliver(c) {
                    continue;
                }
                if let Some(pull) = best_pull_back(&mut core_front, columns, &cells[&v], v, c) {
                    let old = core_front.points[v as usize];
                    moved.entry(v).or_insert((old, columns.last_step[c]));
                    let moves = core_front.move_node(v, old - columns.dir[c] * pull);
                    debug_assert!(moves, "a pull-back tried and capped");
                    columns.last_step[c] -= pull;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    stats.undone_moves =
        undo_crossing_moves(&mut core_front, columns, &tops, &cells, &mut moved, surface, layered);
    for &v in moved.keys() {
        mesh.points[v as usize] = core_front.points[v as usize];
    }
    stats.moved_tops = moved.len();
    stats.defects_after = core_front.defects();
    stats
}

/// The final front: the tops of the front's faces (wall faces where they did not rise) as
/// triangles and quads, normals towards the core.
fn final_front(front: &Front, columns: &Columns) -> (Vec<[u32; 3]>, Vec<[u32; 4]>) {
    let mut triangles = Vec::new();
    let mut quads = Vec::new();
    for top in super::front_tops(front, columns, 0..front.len()) {
        match *top.nodes() {
            [a, b, c] => triangles.push([a, b, c]),
            [a, b, c, d] => quads.push([a, b, c, d]),
            _ => {}
        }
    }
    (triangles, quads)
}

/// The tops that may move, with their column: above the wall, of the one column ending there
/// that did not merge (the others merged into it) and free to move anywhere. A stack that ends
/// at its full count ends on the exact offset, which a pull-back would leave (a V groove's
/// bisector tops by 15% of the thickness): such a top may move only where it is on a fold of
/// `front` sharper than
/// [`TUNING.unfolding.sliver_fold_angle`](super::tuning::Unfolding::sliver_fold_angle) (and
/// [`unfold_front`] moves it only for such a fold).
fn movable_tops(
    columns: &Columns,
    front: &CoreFront,
    at_sliver: &impl Fn(usize) -> bool,
) -> HashMap<u32, usize> {
    let mut on_sharp_fold = std::collections::HashSet::new();
    for t in 0..front.triangles.len() as u32 {
        if front.has_fold_sharper_than(t, TUNING.unfolding.sliver_fold_angle) {
            on_sharp_fold.extend(front.triangles[t as usize]);
        }
    }
    let mut ending: HashMap<u32, Vec<usize>> = HashMap::new();
    for c in (0..columns.len()).filter(|&c| columns.merged_into(c).is_none()) {
        ending.entry(columns.node[c]).or_default().push(c);
    }
    ending
        .into_iter()
        .filter_map(|(v, at)| match at[..] {
            [c] if columns.layers[c] > 0
                && (!ends_at_full_count(columns, c) || on_sharp_fold.contains(&v) || at_sliver(c))
                && columns.slide[c] == Slide::Free
                && columns.last_step[c] > 0.0 =>
            {
                Some((v, c))
            }
            _ => None,
        })
        .collect()
}

/// Whether column `c`'s stack ends at its full count (on the exact offset): neither short of it
/// nor in its transition layers.
fn ends_at_full_count(columns: &Columns, c: usize) -> bool {
    columns.full_count(c) == Some(columns.layers[c])
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
/// the front around it, keeping every cell at it valid and its quads cappable; `None` when
/// none raises it by a degree.
fn best_pull_back(
    front: &mut CoreFront,
    columns: &Columns,
    cells: &[(CellKind, Vec<u32>)],
    v: u32,
    c: usize,
) -> Option<f64> {
    let start = front.points[v as usize];
    let mut best = (front.quality_at(v) + 1.0, None);
    for part in TUNING.unfolding.pull_backs {
        let pull = part * columns.last_step[c];
        if !front.move_node(v, start - columns.dir[c] * pull) {
            continue;
        }
        let valid = cells_valid(front, cells);
        let quality = front.quality_at(v);
        if valid && quality > best.0 {
            best = (quality, Some(pull));
        }
    }
    let restored = front.move_node(v, start);
    debug_assert!(restored, "the start was cappable");
    best.1
}

/// Whether every one of `cells` is valid with the front's points.
fn cells_valid(front: &CoreFront, cells: &[(CellKind, Vec<u32>)]) -> bool {
    cells.iter().all(|(kind, nodes)| {
        gather(&front.points, nodes).is_some_and(|x| cell_validity(*kind, &x).is_valid())
    })
}

/// Undo the moves of tops whose triangles now cross the core's boundary (the front, its quads'
/// caps, the walls without layers; exact tests), until none does: the march left a front that
/// crosses nothing. A top whose cells turn invalid once a neighbour's move is undone (they were
/// tested with the neighbour moved) goes back too. Returns how many moves were undone.
fn undo_crossing_moves(
    front: &mut CoreFront,
    columns: &mut Columns,
    tops: &HashMap<u32, usize>,
    cells: &HashMap<u32, Vec<(CellKind, Vec<u32>)>>,
    moved: &mut HashMap<u32, (DVec3, f64)>,
    surface: &Surface,
    layered: impl Fn(u32) -> bool,
) -> usize {
    let mut undone = 0;
    let mut soup = front.triangles.clone();
    // The walls without layers: their nodes are the wall's, the mesh's first points.
    soup.extend(
        (0..surface.triangles.len())
            .filter(|&t| !layered(surface.triangle_patch[t]))
            .map(|t| surface.triangles[t]),
    );
    while !moved.is_empty() {
        let check = Surface {
            points: front.points.clone(),
            triangles: soup.clone(),
            triangle_patch: vec![0; soup.len()],
            patch_names: vec![String::new()],
        };
        let queries: Vec<u32> = moved.keys().flat_map(|&v| front.triangles_moved_by(v)).collect();
        let pairs = crate::surface::validate::intersecting_pairs_with(&check, &queries, false);
        // A crossing triangle's moved corners go back, and those of the quad whose cap it is.
        let mut undo: Vec<u32> = pairs
            .iter()
            .flat_map(|&(s, t)| [soup[s as usize], soup[t as usize]])
            .flat_map(|tri| tri.into_iter().chain(front.quad_corners_of_apexes(tri)))
            .filter(|v| moved.contains_key(v))
            .collect();
        undo.extend(moved.keys().copied().filter(|v| !cells_valid(front, &cells[v])));
        if undo.is_empty() {
            break;
        }
        undo.sort_unstable();
        undo.dedup();
        // A top whose quad would have no cap with another corner still moved goes back with
        // that corner (the march's positions are cappable).
        let back = |undo: &[u32]| -> Vec<(u32, DVec3)> { undo.iter().map(|v| (*v, moved[v].0)).collect() };
        while !front.move_nodes(&back(&undo)) {
            let quads = undo.iter().flat_map(|&v| front.quads_at(v).iter().copied());
            let mut more: Vec<u32> = quads
                .flat_map(|q| front.quads[q as usize])
                .filter(|c| moved.contains_key(c) && !undo.contains(c))
                .collect();
            if more.is_empty() {
                debug_assert!(false, "the march's positions were cappable");
                break;
            }
            undo.append(&mut more);
            undo.sort_unstable();
            undo.dedup();
        }
        undone += undo.len();
        for v in undo {
            let (_, step) = moved.remove(&v).expect("a moved top");
            columns.last_step[tops[&v]] = step;
        }
    }
    undone
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles on the edge (0, 1) along x, normals up (+z, the core's side), the first
    /// one's far corner at `d`.
    fn pair(d: DVec3) -> CoreFront {
        let points = vec![DVec3::ZERO, DVec3::X, DVec3::new(0.5, -1.0, 0.0), d];
        CoreFront::new(points, vec![[0, 1, 3], [1, 0, 2]], Vec::new()).unwrap()
    }

    #[test]
    fn the_core_angle_is_180_on_a_plane_small_in_a_valley_and_large_on_a_ridge() {
        let angle = |d: DVec3| pair(d).core_angle([0, 1]);
        assert!((angle(DVec3::new(0.5, 1.0, 0.0)) - 180.0).abs() < 1e-9);
        // The first triangle turned up and over towards the core: a valley of 45 degrees.
        let up = DVec3::new(0.5, -1.0, 1.0).normalize() + DVec3::new(0.5, 0.0, 0.0);
        assert!((angle(up) - 45.0).abs() < 1e-6);
        assert!((angle(DVec3::new(0.5, 1.0, -1.0)) - 225.0).abs() < 1e-6);
        // Folded back over the second one, nearly flat: a fold.
        let folded = pair(DVec3::new(0.5, -1.0, 0.05));
        assert!(folded.core_angle([0, 1]) < TUNING.unfolding.fold_angle);
        assert!(folded.is_defect(0) && folded.is_defect(1));
        assert!(folded.quality_at(3) < TUNING.unfolding.fold_angle);
    }

    /// A top whose cell turns invalid goes back even where nothing crosses: a neighbour's move
    /// that was undone leaves its cells as they were tested with that neighbour moved.
    #[test]
    fn an_undo_also_takes_back_a_top_whose_cell_turned_invalid() {
        use crate::layers::front::ColumnStart;
        let (below, above) = (DVec3::new(0.5, -0.3, -0.5), DVec3::new(0.5, -0.3, 0.5));
        let mut front = pair(DVec3::new(0.5, 1.0, 0.0));
        let tet = vec![(CellKind::Tetrahedron, vec![0, 2, 1, 3])];
        assert!(front.move_node(3, below));
        let valid_below = cells_valid(&front, &tet);
        assert!(front.move_node(3, above));
        assert!(valid_below != cells_valid(&front, &tet), "one side of the wall triangle is inside out");
        let (start, moved_to) = if valid_below { (below, above) } else { (above, below) };
        assert!(front.move_node(3, moved_to));
        let mut columns = Columns::default();
        columns.push(ColumnStart {
            base: DVec3::ZERO,
            dir: DVec3::Z,
            scale: 1.0,
            node: 3,
            layers: 1,
            wall_vertex: 0,
            slide: Slide::Free,
            spec: None,
            last_step: 0.5,
        });
        let tops = HashMap::from([(3, 0)]);
        let cells = HashMap::from([(3, tet)]);
        let mut moved = HashMap::from([(3, (start, 1.0))]);
        let nothing = Surface {
            points: Vec::new(),
            triangles: Vec::new(),
            triangle_patch: Vec::new(),
            patch_names: Vec::new(),
        };
        let undone =
            undo_crossing_moves(&mut front, &mut columns, &tops, &cells, &mut moved, &nothing, |_| true);
        assert_eq!(undone, 1);
        assert_eq!(front.points[3], start);
        assert_eq!(columns.last_step[0], 1.0, "its last step is restored");
    }

    /// A fold of a few degrees forces slivers in the core (where full stacks' tops give way);
    /// one of 30 degrees is a defect only (where they stay).
    #[test]
    fn a_fold_sharper_than_the_sliver_bound_is_told_from_a_mild_one() {
        let lifted = |degrees: f64| {
            let a = degrees.to_radians();
            pair(DVec3::new(0.5, -a.cos(), a.sin()))
        };
        let sharp = lifted(5.0);
        assert!((sharp.core_angle([0, 1]) - 5.0).abs() < 1e-6);
        assert!(sharp.is_defect(0) && sharp.has_fold_sharper_than(0, TUNING.unfolding.sliver_fold_angle));
        let mild = lifted(30.0);
        assert!((mild.core_angle([0, 1]) - 30.0).abs() < 1e-6);
        assert!(mild.is_defect(0) && !mild.has_fold_sharper_than(0, TUNING.unfolding.sliver_fold_angle));
    }

    /// A stack at its full count keeps its top (it ends on the exact offset), but one under a
    /// core sliver may give way.
    #[test]
    fn a_full_stacks_top_may_move_only_under_a_sliver() {
        use crate::layers::front::ColumnStart;
        let front = pair(DVec3::new(0.5, 1.0, 0.0));
        let mut columns = Columns::default();
        columns.push(ColumnStart {
            base: DVec3::new(0.5, 1.0, -0.5),
            dir: DVec3::Z,
            scale: 1.0,
            node: 3,
            layers: 5,
            wall_vertex: 7,
            slide: Slide::Free,
            spec: Some(crate::config::LayerSpec::fixed(0.1, 1.0, 5)),
            last_step: 0.1,
        });
        assert!(ends_at_full_count(&columns, 0));
        assert!(movable_tops(&columns, &front, &|_| false).is_empty());
        let under_a_sliver = |c: usize| columns.wall_vertex[c] == 7;
        assert_eq!(movable_tops(&columns, &front, &under_a_sliver), HashMap::from([(3, 0)]));
    }

    #[test]
    fn a_corner_on_the_opposite_edge_is_a_cap() {
        let mut front = pair(DVec3::new(0.5, 1.0, 0.0));
        assert_eq!(front.defects(), 0);
        assert!(front.move_node(3, DVec3::new(0.5, 0.01, 0.0)));
        assert!(front.is_defect(0), "a 178-degree corner");
        assert!(front.quality_at(3) < 180.0 - TUNING.unfolding.cap_angle);
    }

    #[test]
    fn a_quad_is_seen_as_its_pyramid_cap_and_its_apex_follows_its_corners() {
        let square = vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        let mut front = CoreFront::new(square, Vec::new(), vec![[0, 1, 2, 3]]).unwrap();
        assert_eq!(front.triangles.len(), 4);
        let apex = front.points[front.first_apex];
        assert!((apex - DVec3::new(0.5, 0.5, 0.5)).length() < 1e-12, "{apex:?}");
        assert_eq!(front.triangles_moved_by(0).len(), 4, "every cap triangle moves with the apex");
        assert!(front.move_node(2, DVec3::new(2.0, 2.0, 0.0)));
        assert!(front.points[front.first_apex].x > 0.5, "the apex moved with the corner");
        // A corner moved onto another makes a quad no pyramid caps: refused, nothing moves.
        assert!(!front.move_node(2, DVec3::ZERO));
        assert_eq!(front.points[2], DVec3::new(2.0, 2.0, 0.0));
        assert_eq!(front.quad_corners_of_apexes([0, 1, front.first_apex as u32]), vec![0, 1, 2, 3]);
    }

    /// Two corners of a quad pulled along x together: taking one back alone would cross the
    /// quad over itself (no cap), so an undo takes both back at once.
    #[test]
    fn corners_of_a_quad_go_back_together_where_one_alone_has_no_cap() {
        let square = vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        let mut front = CoreFront::new(square.clone(), Vec::new(), vec![[0, 1, 2, 3]]).unwrap();
        let apex = front.points[front.first_apex];
        assert!(front.move_nodes(&[(0, DVec3::new(2.0, 0.0, 0.0)), (1, DVec3::new(3.0, 0.0, 0.0))]));
        assert!(!front.move_node(1, square[1]), "corner 1 back alone crosses the quad over itself");
        assert_eq!(front.points[1], DVec3::new(3.0, 0.0, 0.0), "a refused move moves nothing");
        assert!(front.move_nodes(&[(0, square[0]), (1, square[1])]));
        assert_eq!(front.points[..4], square[..]);
        assert!((front.points[front.first_apex] - apex).length() < 1e-12, "the apex is back too");
    }
}
