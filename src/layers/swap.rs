//! Edge swaps on the front (tangential adaptivity): where two front
//! triangles `(a, b, c)` and `(b, a, d)` would top out badly shaped (splits fan long edges from
//! their middle; columns converge), their shared edge is swapped for `(c, d)`: the new front has
//! the triangles `(c, a, d)` and `(d, b, c)`. Along a concave ridge, where face columns merge
//! into the ridge's, a face can end up with its three columns on the ridge: a sliver lying in
//! the front's crease, which pinches it (the core then meets it with slivers); it is swapped
//! with its neighbour across its long edge like a pair a split made. A pair of the wall's own
//! triangles is swapped once the march has made it worse shaped than the wall did (see
//! [`propose`]).
//!
//! In the slab being built, the two cells over the pair become one polyhedron: the two bottom
//! triangles with the old diagonal, the two top triangles with the new one, and the four lateral
//! faces over the pair's outer edges, as its neighbours build them (so the slab stays
//! conforming). It is split from its centre ([`super::slab::cell_from_faces`]). A swap whose
//! cell would be invalid is given up for the layer; a swap whose columns do not all move on
//! their own (one stopped or merged) is not made.

use glam::DVec3;
use rayon::prelude::*;

use super::front::{Columns, Front};
use super::slab::{self, cell_from_faces, Polygon, SlabCell};
use super::slab_plan::SlabPlan;
use super::split::Splits;
use super::tuning::TUNING;
use crate::geometry::intersect::triangles_meet;
use crate::geometry::triangle_min_angle;

/// One swap: faces `f = (a, b, c)` and `g = (b, a, d)` become `(c, a, d)` and `(d, b, c)`.
#[derive(Clone, Copy, Debug)]
struct Swap {
    faces: [u32; 2],
    /// `[a, b, c, d]`: the shared edge, then `f`'s and `g`'s opposite columns.
    columns: [u32; 4],
    enabled: bool,
}

/// The swaps proposed for one slab.
#[derive(Clone, Debug, Default)]
pub(super) struct Swaps {
    swaps: Vec<Swap>,
    /// The swap on each face (`u32::MAX`: none); empty when there are no swaps.
    on_face: Vec<u32>,
}

/// How a face takes part in an active swap.
pub(super) enum SwapRole {
    /// The first face of the pair: its cell is the pair's polyhedron (bottom and top nodes of
    /// `[a, b, c, d]`).
    Cell([u32; 4]),
    /// The second face: its cell is the first's.
    Absorbed,
}

impl Swaps {
    pub fn len(&self) -> usize {
        self.swaps.len()
    }

    fn is_active(&self, s: usize, plan: &SlabPlan) -> bool {
        let swap = &self.swaps[s];
        swap.enabled && swap.columns.iter().all(|&c| plan.moving[c as usize] && !plan.merges.is_merged(c))
    }

    fn active_index(&self, f: usize, plan: &SlabPlan) -> Option<usize> {
        let s = *self.on_face.get(f)?;
        (s != u32::MAX && self.is_active(s as usize, plan)).then_some(s as usize)
    }

    /// Face `f`'s part in its active swap, if it has one.
    pub fn role(&self, f: usize, plan: &SlabPlan) -> Option<SwapRole> {
        let s = self.active_index(f, plan)?;
        let swap = &self.swaps[s];
        Some(if swap.faces[0] as usize == f { SwapRole::Cell(swap.columns) } else { SwapRole::Absorbed })
    }

    /// The columns of face `f`'s top after its active swap, if it has one.
    pub fn swapped_face(&self, f: usize, plan: &SlabPlan) -> Option<[[u32; 3]; 2]> {
        let s = self.active_index(f, plan)?;
        let [a, b, c, d] = self.swaps[s].columns;
        Some([[c, a, d], [d, b, c]])
    }

    /// Give up face `f`'s active swap; returns the two faces whose cells change.
    pub fn give_up(&mut self, f: usize, plan: &SlabPlan) -> Vec<usize> {
        let Some(s) = self.active_index(f, plan) else { return Vec::new() };
        self.swaps[s].enabled = false;
        self.swaps[s].faces.map(|g| g as usize).to_vec()
    }

    /// Both faces of every enabled swap with one of the `columns`.
    pub fn faces_with_columns(&self, columns: &[u32]) -> Vec<usize> {
        if self.swaps.is_empty() || columns.is_empty() {
            return Vec::new();
        }
        let changed: std::collections::HashSet<u32> = columns.iter().copied().collect();
        self.swaps
            .iter()
            .filter(|swap| swap.enabled && swap.columns.iter().any(|c| changed.contains(c)))
            .flat_map(|swap| swap.faces.map(|f| f as usize))
            .collect()
    }

    /// The swaps made under `plan`.
    pub fn active<'a>(&'a self, plan: &'a SlabPlan) -> impl Iterator<Item = usize> + 'a {
        (0..self.len()).filter(move |&s| self.is_active(s, plan))
    }
}

/// Propose swaps for layer `k` on the front with the tops at `proposed`: pairs of triangles of
/// one patch whose four columns are alive and slide alike, with no split on their edges, whose
/// worst top angle is poor and would gain by the swap without folding; each column in one swap
/// at most, the worst pairs first. A pair of the wall's own triangles (no column born by a
/// split, no face reshaped by a merge) is swapped only from the second layer on (the first
/// cells stay prisms on the wall), not across a ridge of the wall, and only when its worst top
/// angle has become poorer than its worst wall angle by the swap's gain: the march, not the
/// user's triangulation, made it poor (columns converging towards a bisector, a fan sweeping
/// over the wall beside it).
pub(super) fn propose(
    columns: &Columns,
    front: &Front,
    proposed: &[DVec3],
    splits: &Splits,
    k: u32,
) -> Swaps {
    let split_faces = splits.faces_with_splits(front.len());
    let reshaped = faces_reshaped_by_merges(columns, front);
    let (split_faces, reshaped) = (&split_faces, &reshaped);
    // Looked for by face in parallel, in face order.
    let mut candidates: Vec<(f64, Swap)> = (0..front.len())
        .into_par_iter()
        .flat_map_iter(|f| {
            let cols = front.face_columns(f);
            let looked_at =
                cols.len() == 3 && !split_faces[f] && cols.iter().all(|&c| columns.is_marching(c as usize));
            // A pair gains only when one of its triangles is poor: most faces stop here (a pair
            // is looked at from its poor face, so from both when both are).
            let poor = looked_at
                && triangle_min_angle(
                    proposed[cols[0] as usize],
                    proposed[cols[1] as usize],
                    proposed[cols[2] as usize],
                ) < TUNING.adaptation.swap_poor_angle;
            (0..if poor { 3 } else { 0 }).filter_map(move |i| {
                let (a, b, c) = (cols[i], cols[(i + 1) % 3], cols[(i + 2) % 3]);
                let g = opposite_face(front, f, a, b)?;
                if split_faces[g] || front.patch[g] != front.patch[f] {
                    return None;
                }
                let other = front.face_columns(g);
                let &d = other.iter().find(|&&x| x != a && x != b)?;
                let four = [a, b, c, d];
                let usable = |x: u32| {
                    columns.is_marching(x as usize) && columns.slide[x as usize] == columns.slide[a as usize]
                };
                if !four.iter().all(|&x| usable(x)) || c == d || front.are_neighbours(c, d) {
                    return None;
                }
                // The wall's own pairs keep the user's triangulation unless the march has made
                // them worse than the wall made them, never in the first layer (its cells stay
                // prisms on the wall) and never across a ridge (the front keeps the wall's
                // creases).
                let wall_born = four.iter().all(|&x| columns.born_at[x as usize] == 0) && !reshaped[f];
                let wall_vertex = |x: u32| columns.wall_vertex[x as usize];
                if wall_born && (k < 2 || front.is_wall_ridge(wall_vertex(a), wall_vertex(b))) {
                    return None;
                }
                let old = gain(four.map(|x| proposed[x as usize]))?;
                if wall_born {
                    let [a, b, c, d] = four.map(|x| columns.base[x as usize]);
                    let wall = triangle_min_angle(a, b, c).min(triangle_min_angle(b, a, d));
                    if old * TUNING.adaptation.swap_gain >= wall {
                        return None;
                    }
                }
                Some((old, Swap { faces: [f as u32, g as u32], columns: four, enabled: true }))
            })
        })
        .collect();
    candidates.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut swaps = Swaps::default();
    if candidates.is_empty() {
        return swaps;
    }
    swaps.on_face = vec![u32::MAX; front.len()];
    let mut used_column = vec![false; columns.len()];
    for (_, swap) in candidates {
        let [f, g] = swap.faces.map(|x| x as usize);
        // Swaps sharing a column (so also those sharing a face) would cut the same lateral
        // faces two ways.
        if swap.columns.iter().any(|&c| used_column[c as usize]) {
            continue;
        }
        for &c in &swap.columns {
            used_column[c as usize] = true;
        }
        let s = swaps.swaps.len() as u32;
        swaps.on_face[f] = s;
        swaps.on_face[g] = s;
        swaps.swaps.push(swap);
    }
    swaps
}

/// A pair of new front triangles turned over their shared edge in the slab whose merges made
/// them: faces `faces[0]` and `faces[1]` of the front before the merges become `(c, a, d)` and
/// `(d, b, c)` of the survivors `[a, b, c, d]`.
pub(super) struct MergedTurn {
    pub faces: [usize; 2],
    pub columns: [u32; 4],
}

/// Turn the new front's pairs that this slab's merges left badly shaped along a ridge, in the
/// slab that made them: where face columns merge into a concave ridge's columns, a face can end
/// with its three columns on the ridge (each carries merged columns), a sliver lying in the
/// front's crease that pinches it for the core; the next slab's swaps come a layer late, and
/// after the last slab never. `cells[f]` is the cell over face `f` with the survivors' tops
/// `top`; a turned pair's two cells become one polyhedron with the new top diagonal (its other
/// faces are the two cells' faces, so the slab stays conforming), split from its centre, and
/// the turn is made only when that cell is valid by `is_valid` and its new top triangles cross
/// none of the tops around ([`crosses_tops_around`]: the slab's crossing guard tested the pair
/// before the turn). As in [`propose`]: faces of one patch, no fan's column, no split or swap
/// of their own (`reshaped_otherwise`), poor and gaining by the turn, the worst first, each
/// survivor in one turn at most.
#[allow(clippy::too_many_arguments)]
pub(super) fn turn_merged_tops(
    front: &Front,
    columns: &Columns,
    plan: &SlabPlan,
    reshaped_otherwise: &[bool],
    top: &[u32],
    points: &[DVec3],
    cells: &mut [(bool, SlabCell)],
    is_valid: impl Fn(&SlabCell) -> bool,
) -> Vec<MergedTurn> {
    let merges = &plan.merges;
    let fan = fan_columns(columns);
    let after = |f: usize| -> Option<[u32; 3]> {
        let roots: Vec<u32> = front.face_columns(f).iter().map(|&c| merges.root(c)).collect();
        let polygon = Polygon::dedup(&roots)?;
        let n = polygon.nodes();
        (n.len() == 3 && n.iter().all(|&c| plan.moving[c as usize])).then(|| [n[0], n[1], n[2]])
    };
    let at = |c: u32| points[top[c as usize] as usize];
    let faces_after_around = |root: u32| {
        merges.group(root).flat_map(|x| front.faces_of(x)).filter_map(move |g| after(g).map(|t| (g, t)))
    };
    let mut carries = carrying_merged(columns);
    for c in 0..columns.len() as u32 {
        if merges.is_merged(c) {
            carries[merges.root(c) as usize] = true;
        }
    }
    let mut candidates: Vec<(f64, MergedTurn)> = Vec::new();
    for f in 0..front.len() {
        let cols = front.face_columns(f);
        if !cols.iter().any(|&c| merges.is_merged(c)) || reshaped_otherwise[f] {
            continue;
        }
        let Some(tri) = after(f) else { continue };
        let on_ridge = tri.iter().all(|&c| carries[c as usize]) && !tri.iter().any(|&c| fan[c as usize]);
        if !on_ridge
            || triangle_min_angle(at(tri[0]), at(tri[1]), at(tri[2])) >= TUNING.adaptation.swap_poor_angle
        {
            continue;
        }
        for i in 0..3 {
            let (a, b, c) = (tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]);
            let Some((g, other)) = faces_after_around(a)
                .find(|&(g, t)| g != f && (0..3).any(|j| t[j] == b && t[(j + 1) % 3] == a))
            else {
                continue;
            };
            let Some(&d) = other.iter().find(|&&x| x != a && x != b) else { continue };
            if reshaped_otherwise[g] || front.patch[g] != front.patch[f] || fan[d as usize] || c == d {
                continue;
            }
            if faces_after_around(c).any(|(_, t)| t.contains(&d)) {
                continue;
            }
            if let Some(old) = gain([a, b, c, d].map(at)) {
                candidates.push((old, MergedTurn { faces: [f, g], columns: [a, b, c, d] }));
            }
        }
    }
    candidates.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut used_column = vec![false; columns.len()];
    let mut used_face = vec![false; front.len()];
    let mut turns = Vec::new();
    for (_, turn) in candidates {
        let [f, g] = turn.faces;
        if used_face[f] || used_face[g] || turn.columns.iter().any(|&c| used_column[c as usize]) {
            continue;
        }
        let Some(cell) = turned_cell(&cells[f].1, &cells[g].1, turn.columns.map(|c| top[c as usize])) else {
            continue;
        };
        if !is_valid(&cell) || crosses_tops_around(front, plan, top, points, &turn) {
            continue;
        }
        cells[f].1 = cell;
        cells[g].1 = SlabCell::Empty;
        used_face[f] = true;
        used_face[g] = true;
        for &c in &turn.columns {
            used_column[c as usize] = true;
        }
        turns.push(turn);
    }
    turns
}

/// Whether a turned pair's new top triangles cross the tops of the faces around its columns:
/// the slab's crossing guard tested the pair before it turned.
fn crosses_tops_around(
    front: &Front,
    plan: &SlabPlan,
    top: &[u32],
    points: &[DVec3],
    turn: &MergedTurn,
) -> bool {
    // In top nodes: a merged column's top is its root's.
    let [a, b, c, d] = turn.columns.map(|x| top[x as usize]);
    let triangle = |t: [u32; 3]| (t, t.map(|n| points[n as usize]));
    let turned = [[c, a, d], [d, b, c]].map(triangle);
    let mut around: Vec<usize> = turn
        .columns
        .iter()
        .flat_map(|&x| plan.merges.group(x).flat_map(|y| front.faces_of(y)))
        .filter(|g| !turn.faces.contains(g))
        .collect();
    around.sort_unstable();
    around.dedup();
    around.into_iter().any(|g| {
        let nodes: Vec<u32> = front.face_columns(g).iter().map(|&x| top[x as usize]).collect();
        let Some(polygon) = Polygon::dedup(&nodes) else { return false };
        let n = polygon.nodes();
        (1..n.len() - 1).any(|i| {
            let (ids, at) = triangle([n[0], n[i], n[i + 1]]);
            turned.iter().any(|&(t_ids, t)| triangles_meet(t_ids, t, ids, at))
        })
    })
}

/// The union of the cells `first` and `second` under the tops `(a, b, c)` and `(b, a, d)` with
/// the top diagonal turned to `(c, d)`; `None` unless the two cells share their lateral face
/// over `(a, b)` (the union is then closed).
fn turned_cell(first: &SlabCell, second: &SlabCell, [a, b, c, d]: [u32; 4]) -> Option<SlabCell> {
    let mut faces = cell_faces(first)?;
    faces.extend(cell_faces(second)?);
    for old in [[a, b, c], [b, a, d]] {
        let old = Polygon::dedup(&old)?;
        let i = faces.iter().position(|f| f.same_cycle(&old))?;
        faces.remove(i);
    }
    faces.extend(Polygon::dedup(&[c, a, d]));
    faces.extend(Polygon::dedup(&[d, b, c]));
    slab::remove_opposite_pairs(&mut faces);
    slab::is_closed(&faces).then(|| cell_from_faces(faces))
}

/// The outward faces of a slab cell, `None` for an empty or flat one.
fn cell_faces(cell: &SlabCell) -> Option<Vec<Polygon>> {
    match cell {
        SlabCell::Standard { kind, nodes } => Some(
            kind.faces()
                .iter()
                .filter_map(|f| Polygon::dedup(&f.iter().map(|&i| nodes[i]).collect::<Vec<_>>()))
                .collect(),
        ),
        SlabCell::Split { faces, .. } => Some(faces.clone()),
        SlabCell::Empty | SlabCell::Flat => None,
    }
}

/// Whether each column carries a column merged into it in an earlier slab.
pub(super) fn carrying_merged(columns: &Columns) -> Vec<bool> {
    let mut carries = vec![false; columns.len()];
    for r in (0..columns.len()).filter_map(|c| columns.merged_into(c)) {
        carries[r as usize] = true;
    }
    carries
}

/// Whether each column is one of several of its wall vertex: a fan's, or one whose edges were
/// split (the split columns take its wall vertex).
fn sharing_a_wall_vertex(columns: &Columns) -> Vec<bool> {
    let mut per_vertex = vec![0u32; columns.wall_vertex_count()];
    for &v in &columns.wall_vertex {
        per_vertex[v as usize] += 1;
    }
    columns.wall_vertex.iter().map(|&v| per_vertex[v as usize] > 1).collect()
}

/// Whether each column is a fan's: one of several columns its wall vertex started with.
fn fan_columns(columns: &Columns) -> Vec<bool> {
    let mut per_vertex = vec![0u32; columns.wall_vertex_count()];
    let at_wall = |c: usize| columns.born_at[c] == 0;
    for c in (0..columns.len()).filter(|&c| at_wall(c)) {
        per_vertex[columns.wall_vertex[c] as usize] += 1;
    }
    (0..columns.len()).map(|c| at_wall(c) && per_vertex[columns.wall_vertex[c] as usize] > 1).collect()
}

/// Whether every face is no longer its wall triangle's shape because a column merged into one
/// of its columns: it then spans other wall vertices (along a concave ridge, three columns on
/// the ridge itself, a sliver that only a swap turns back into the front's shape). Faces with a
/// column of a wall vertex that has others (a fan's, or one whose edges were split: the split
/// columns take its wall vertex) are left as they are: next to a fan's strip of quads, a
/// swapped pair's new edge can run under the pyramid that will cap a quad (fandisk: 12 stacks
/// stopped).
fn faces_reshaped_by_merges(columns: &Columns, front: &Front) -> Vec<bool> {
    let carries = carrying_merged(columns);
    let fan = sharing_a_wall_vertex(columns);
    (0..front.len())
        .map(|f| {
            let cols = front.face_columns(f);
            cols.iter().any(|&c| carries[c as usize]) && !cols.iter().any(|&c| fan[c as usize])
        })
        .collect()
}

/// The other face on the front edge `(a, b)` of face `f` (a triangle), if it is a triangle
/// holding `(b, a)`.
fn opposite_face(front: &Front, f: usize, a: u32, b: u32) -> Option<usize> {
    front.faces_of(a).filter(|&g| g != f).find(|&g| {
        let cols = front.face_columns(g);
        cols.len() == 3 && (0..3).any(|i| cols[i] == b && cols[(i + 1) % 3] == a)
    })
}

/// For tops `[a, b, c, d]` of the pair `(a, b, c)`, `(b, a, d)`: the pair's worst angle when
/// swapping to `(c, a, d)`, `(d, b, c)` is worth it (the worst is poor, rises by
/// [`TUNING.adaptation.swap_gain`](super::tuning::Adaptation::swap_gain), and the new triangles
/// face the old pair's way), else `None`.
fn gain([a, b, c, d]: [DVec3; 4]) -> Option<f64> {
    let old = triangle_min_angle(a, b, c).min(triangle_min_angle(b, a, d));
    if old >= TUNING.adaptation.swap_poor_angle {
        return None;
    }
    let new = triangle_min_angle(c, a, d).min(triangle_min_angle(d, b, c));
    let normal = (b - a).cross(c - a) + (a - b).cross(d - b);
    let (n1, n2) = ((a - c).cross(d - c), (b - d).cross(c - d));
    let facing = n1.dot(normal) > 0.0 && n2.dot(normal) > 0.0 && n1.dot(n2) > 0.5 * n1.length() * n2.length();
    (facing && new > TUNING.adaptation.swap_gain * old).then_some(old)
}

/// The cell over a swapped pair with bottom nodes `bottom` and top nodes `top` of `[a, b, c, d]`
/// (see the module docs); the lateral faces over the outer edges as [`slab::push_lateral`] makes
/// them for the neighbours (no column of a swap merges; `cut(i, j)` says whether the face over
/// outer edge `(i, j)` is cut, from `i`'s bottom when `Some(true)`, as the neighbour cuts it).
pub(super) fn swap_cell(bottom: [u32; 4], top: [u32; 4], cut: impl Fn(u32, u32) -> Option<bool>) -> SlabCell {
    let [a, b, c, d] = [0, 1, 2, 3];
    let mut faces = Vec::with_capacity(8);
    for tri in [[a, b, c], [b, a, d]] {
        let reversed = [bottom[tri[2]], bottom[tri[1]], bottom[tri[0]]];
        faces.extend(Polygon::dedup(&reversed));
    }
    for tri in [[c, a, d], [d, b, c]] {
        faces.extend(Polygon::dedup(&tri.map(|i| top[i])));
    }
    for (i, j) in [(b, c), (c, a), (a, d), (d, b)] {
        slab::push_lateral(&mut faces, [bottom[i], bottom[j], top[j], top[i]], cut(i as u32, j as u32));
    }
    slab::remove_opposite_pairs(&mut faces);
    cell_from_faces(faces)
}

/// Swap the front faces of the swaps made under `plan`; the front's adjacency must be rebuilt
/// after. Returns how many were made.
pub(super) fn commit(swaps: &Swaps, plan: &SlabPlan, front: &mut Front) -> usize {
    let active: Vec<usize> = swaps.active(plan).collect();
    for &s in &active {
        let swap = &swaps.swaps[s];
        turn_faces(front, swap.faces.map(|x| x as usize), swap.columns);
    }
    active.len()
}

/// Turn the front faces of `turns` (made on the front before the slab's merges, which keep the
/// survivors); the front's adjacency must be rebuilt after. Returns how many were made.
pub(super) fn commit_turns(turns: &[MergedTurn], front: &mut Front) -> usize {
    for turn in turns {
        turn_faces(front, turn.faces, turn.columns);
    }
    turns.len()
}

/// Faces `f = (a, b, c)` and `g = (b, a, d)` become `(c, a, d)` and `(d, b, c)`.
fn turn_faces(front: &mut Front, [f, g]: [usize; 2], [a, b, c, d]: [u32; 4]) {
    front.subdivide_face(f, &[vec![c, a, d]]);
    front.subdivide_face(g, &[vec![d, b, c]]);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_thin_pair_gains_by_the_swap_and_a_good_one_does_not() {
        let p = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        // A long diagonal (a, b) between two flat triangles: the swap to (c, d) is better.
        assert!(gain([p(0.0, 0.0), p(4.0, 0.0), p(2.0, 0.5), p(2.0, -0.5)]).is_some());
        // Two equilateral triangles: nothing to gain.
        let h = 3f64.sqrt() / 2.0;
        assert!(gain([p(0.0, 0.0), p(1.0, 0.0), p(0.5, h), p(0.5, -h)]).is_none());
        // A non-convex pair: the swap would fold.
        assert!(gain([p(0.0, 0.0), p(4.0, 0.0), p(0.5, 0.3), p(-1.0, -0.2)]).is_none());
    }

    /// A swap's two faces change together: the face without a column that changes turns back
    /// into a cell of its own when the swap is no longer made, so both must be looked at again.
    #[test]
    fn both_faces_of_a_swap_change_with_any_of_its_columns() {
        let swap = Swap { faces: [4, 7], columns: [0, 1, 2, 3], enabled: true };
        let swaps = Swaps { swaps: vec![swap], on_face: Vec::new() };
        for c in 0..4 {
            assert_eq!(swaps.faces_with_columns(&[9, c]), vec![4, 7]);
        }
        assert!(swaps.faces_with_columns(&[9]).is_empty());
        let given_up = Swaps { swaps: vec![Swap { enabled: false, ..swap }], on_face: Vec::new() };
        assert!(given_up.faces_with_columns(&[3]).is_empty());
    }

    #[test]
    fn the_swapped_pair_is_one_cell_closed_by_its_faces() {
        // Bottom nodes 0..4, top nodes 10..14: 2 + 2 triangles and 4 lateral quads.
        match swap_cell([0, 1, 2, 3], [10, 11, 12, 13], |_, _| None) {
            SlabCell::Split { faces, .. } => {
                assert_eq!(faces.len(), 8);
                assert!(slab::is_closed(&faces));
            }
            other => panic!("{other:?}"),
        }
    }

    /// The prisms over faces (0, 1, 2) and (1, 0, 3) (tops 10..13) turned over their shared
    /// edge: one cell closed by the two bottoms, the four outer laterals and the turned tops.
    #[test]
    fn a_turned_pair_of_cells_is_their_union_under_the_new_diagonal() {
        let prism = |bottom: [u32; 3]| {
            let mut nodes = [0; 8];
            nodes[..3].copy_from_slice(&bottom);
            nodes[3..6].copy_from_slice(&bottom.map(|n| n + 10));
            SlabCell::Standard { kind: crate::mesh::CellKind::Prism, nodes }
        };
        let (first, second) = (prism([0, 1, 2]), prism([1, 0, 3]));
        let SlabCell::Split { faces, .. } = turned_cell(&first, &second, [10, 11, 12, 13]).unwrap() else {
            panic!("a polyhedron to split")
        };
        assert_eq!(faces.len(), 8);
        assert!(slab::is_closed(&faces));
        let has = |t: [u32; 3]| faces.iter().any(|f| f.same_cycle(&Polygon::dedup(&t).unwrap()));
        assert!(has([12, 10, 13]) && has([13, 11, 12]), "the turned tops");
        assert!(!has([10, 11, 12]) && !has([11, 10, 13]), "no old top");
        // Cells that do not share the lateral face over the edge are not turned.
        assert!(turned_cell(&first, &prism([4, 5, 6]), [10, 11, 12, 13]).is_none());
    }
}
