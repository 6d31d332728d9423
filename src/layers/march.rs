//! Marching the front layer by layer: move the live columns, keep every new cell valid, emit
//! the slab.
//!
//! Each step proposes a new position for every live column (along its direction, by the height
//! of the next layer), merges the columns whose fronts meet ([`super::entropy`]), builds the
//! slab cell over every front face ([`super::slab`]) and checks it with exact predicates. An
//! invalid cell is repaired by a collapse where one of its edges is being crushed, otherwise by
//! stopping its columns (their top is their bottom); the cells around are rebuilt until every
//! cell is valid. Stopped and merged columns turn their cells into pyramids and tetrahedra, so
//! the slab stays conforming. Only then are the new nodes created, the cells emitted and the
//! merges applied to the front.

use rayon::prelude::*;

use super::collapse::Merges;
use super::entropy::VertexWalls;
use super::front::{ColumnState, Columns, Front};
use super::guard::{CrossingGuard, Reach};
use super::reshape::Reshape;
use super::slab::{slab_cell, Merging, Polygon, SlabCell};
use super::slab_plan::SlabPlan;
use super::split::{self, Adapt, Sizes, NONE};
use super::swap::{self, SwapRole};
use super::tuning::TUNING;
use super::{bend, coarsen, entropy};
use crate::geometry::DVec3;
use crate::mesh::{CellKind, VolumeMesh};
use crate::normals::constraint::Slide;
use crate::quality::measures::{is_float_flat, CellPoints};
use crate::quality::validity::cell_validity;

/// Zone of the layer cells in the output mesh.
pub const LAYER_ZONE: u32 = 0;

/// What the march did, for the report.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct MarchStats {
    pub layers_marched: u32,
    /// Columns stopped before their target because a cell would have been invalid.
    pub columns_stopped_early: usize,
    /// Cells split from an added centre point (their shape was not a standard cell).
    pub steiner_points: usize,
    /// Front edges collapsed where fronts met (two columns merged into one).
    pub collapses: usize,
    /// Times the crossing guard searched the whole front for candidate pairs.
    pub guard_rebuilds: usize,
    /// Front edges split (a column born at each one's middle).
    pub splits: usize,
    /// Short front edges collapsed to the tangential size (two columns merged into one).
    pub tangential_collapses: usize,
    /// Of the collapses where fronts met, those of faces left flat along a line.
    pub flat_top_collapses: usize,
    /// Columns turned towards their neighbours' direction to mend an invalid cell, instead of
    /// stopping.
    pub bent_columns: usize,
    /// Columns whose top tipped sideways to mend an invalid cell, instead of stopping.
    pub tipped_columns: usize,
    /// Columns whose stack ended in its transition layers at a front edge crushed shorter than
    /// any collapse could mend.
    pub crushed_columns: usize,
    /// Long front edges left unsplit for a layer because the split would have made an invalid
    /// cell.
    pub splits_given_up: usize,
    /// Front edges swapped (a pair of badly shaped triangles turned over their shared edge).
    pub swaps: usize,
    /// Columns stopped on the cone around a stack with no layer ([`grade_around_pits`]).
    pub columns_stopped_for_pits: usize,
    /// Columns stopped a layer under where the core could not fill around their tops
    /// ([`stop_at_caps`]).
    pub columns_stopped_at_caps: usize,
    /// Columns stopped to leave the core room below the medial surface of a gap
    /// ([`stop_at_gaps`]).
    pub columns_stopped_at_gaps: usize,
}

/// Node ids of the slab being built: committed nodes are `< committed`, a moving column `c`
/// proposes the node `committed + c` at `proposed[c]`.
struct Proposal<'a> {
    points: &'a [DVec3],
    proposed: &'a [DVec3],
    committed: u32,
}

impl<'a> Proposal<'a> {
    /// The nodes of `mesh` with the tops `plan` proposes after them.
    fn of_plan(mesh: &'a VolumeMesh, plan: &'a SlabPlan) -> Proposal<'a> {
        Proposal { points: &mesh.points, proposed: &plan.proposed, committed: mesh.points.len() as u32 }
    }

    fn position(&self, node: u32) -> DVec3 {
        match node.checked_sub(self.committed) {
            Some(c) => self.proposed[c as usize],
            None => self.points[node as usize],
        }
    }

    fn gather(&self, nodes: &[u32]) -> CellPoints {
        let mut x = [DVec3::ZERO; 8];
        for (xi, &n) in x.iter_mut().zip(nodes) {
            *xi = self.position(n);
        }
        x
    }

    /// Is the cell with these faces valid, whatever shape it is emitted as?
    fn cell_is_valid(&self, cell: &SlabCell) -> bool {
        match cell {
            SlabCell::Empty => true,
            SlabCell::Flat => false,
            SlabCell::Standard { kind, nodes } => solid(*kind, &self.gather(nodes)),
            SlabCell::Split { faces, apex } => {
                let apex_point = match apex {
                    Some(a) => self.position(*a),
                    None => self.centre(faces),
                };
                split_pieces(faces, *apex, u32::MAX).all(|(kind, nodes)| {
                    let last = nodes.len() - 1;
                    let mut x = self.gather(&nodes[..last]);
                    x[last] = apex_point;
                    solid(kind, &x)
                })
            }
        }
    }

    /// The mean of the distinct nodes of a split cell.
    fn centre(&self, faces: &[Polygon]) -> DVec3 {
        let mut nodes: Vec<u32> = faces.iter().flat_map(|f| f.nodes().iter().copied()).collect();
        nodes.sort_unstable();
        nodes.dedup();
        nodes.iter().map(|&n| self.position(n)).sum::<DVec3>() / nodes.len() as f64
    }
}

/// Whether a layer cell is valid by the exact tests and not flat in floating point, where a
/// finite-volume solver would see its face pyramids turn over.
fn solid(kind: CellKind, x: &CellPoints) -> bool {
    cell_validity(kind, x).is_valid() && !is_float_flat(kind, x)
}

/// The cells of a split polyhedron: a tetrahedron per triangle face and a pyramid per quad face,
/// with the apex as last node: node `apex` when given (faces through it give nothing), else the
/// new centre node `centre`.
fn split_pieces(
    faces: &[Polygon],
    apex: Option<u32>,
    centre: u32,
) -> impl Iterator<Item = (CellKind, Vec<u32>)> + '_ {
    let top = apex.unwrap_or(centre);
    faces.iter().filter(move |f| !f.nodes().contains(&top)).map(move |f| {
        // The outward face reversed points into the cell, towards the apex.
        let mut nodes: Vec<u32> = f.nodes().iter().rev().copied().collect();
        nodes.push(top);
        let kind = if f.is_quad() { CellKind::Pyramid } else { CellKind::Tetrahedron };
        (kind, nodes)
    })
}

/// Bottom node, top node (`top(c)`) and merging of every column of face `f`, and its size.
fn face_ends(
    front: &Front,
    f: usize,
    columns: &Columns,
    merges: &Merges,
    top: impl Fn(u32) -> u32,
) -> ([u32; 4], [u32; 4], usize, Merging) {
    let cols = front.face_columns(f);
    let n = cols.len();
    let mut b = [0; 4];
    let mut t = [0; 4];
    let mut merging = Merging::default();
    for (i, &c) in cols.iter().enumerate() {
        b[i] = columns.node[c as usize];
        t[i] = top(c);
        if merges.is_merged(c) {
            merging.merged |= 1 << i;
        }
    }
    for i in 0..n {
        let (a, c) = (cols[i], cols[(i + 1) % n]);
        if let Some(from) = lateral_cut(front, merges, columns, a, c) {
            merging.cut |= 1 << i;
            if from == a {
                merging.cut_from_first |= 1 << i;
            }
        }
    }
    (b, t, n, merging)
}

/// The column whose bottom node the lateral face over front edge `(a, b)` is cut from, if it is
/// cut: twisted by a merge ([`cut_from`]), or closing a fan at a ridge end
/// ([`fan_end_cut_from`]). Both cells beside the face ask this of the same two columns.
fn lateral_cut(front: &Front, merges: &Merges, columns: &Columns, a: u32, b: u32) -> Option<u32> {
    if merges.is_merged(a) || merges.is_merged(b) {
        return Some(cut_from(front, merges, columns, a, b));
    }
    fan_end_cut_from(front, columns, a, b)
}

/// Where a convex ridge ends (its last vertex `w` has one column on it, the vertex `v` before
/// has a fan of copies), the fan's triangles `(w, v_j, v_j+1)` start from the wall edge
/// `(w, v)`: over it, the lateral quads `(w, v, V_j, W)` of consecutive fan triangles fold onto
/// each other along `w W`, and the cell between two of them has no standard shape. Cut from `v`,
/// the quads' halves `(w, v, W)` cancel and the cell is the tetrahedron `(v, W, V_j, V_j+1)`.
/// So the face over edge `(a, b)` is cut from `b`'s bottom when a front face on the edge has
/// another column standing on `b`'s node and none on `a`'s (and the other way round). That
/// holds only while the fan's copies stand together on the wall, in the first layer.
fn fan_end_cut_from(front: &Front, columns: &Columns, a: u32, b: u32) -> Option<u32> {
    // Only where a column stands on another's node (none once the fans have left the wall).
    if !columns.shares_node(a as usize) && !columns.shares_node(b as usize) {
        return None;
    }
    let node = |c: u32| columns.node[c as usize];
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    front.faces_of(lo).find_map(|f| {
        let cols = front.face_columns(f);
        if !cols.contains(&hi) {
            return None;
        }
        let shares = |x: u32| cols.iter().any(|&y| y != lo && y != hi && node(y) == node(x));
        match (shares(lo), shares(hi)) {
            (true, false) => Some(lo),
            (false, true) => Some(hi),
            _ => None,
        }
    })
}

/// Which end of front edge `(a, b)` the twisted lateral face over it is cut from (see
/// [`Merging`]): the column that merged; when both did, the one that is a front neighbour of the
/// other's survivor (the cell over the triangle they make with that survivor needs that cut),
/// else the one at the smaller node. Symmetric in `a` and `b`.
fn cut_from(front: &Front, merges: &Merges, columns: &Columns, a: u32, b: u32) -> u32 {
    match (merges.is_merged(a), merges.is_merged(b)) {
        (true, false) => a,
        (false, true) => b,
        _ => {
            let a_next = front.are_neighbours(a, merges.root(b));
            let b_next = front.are_neighbours(b, merges.root(a));
            match (a_next, b_next) {
                (true, false) => a,
                (false, true) => b,
                _ if (columns.node[a as usize], a) < (columns.node[b as usize], b) => a,
                _ => b,
            }
        }
    }
}

/// The cell over front face `f` under a slab plan, with its active splits and swap; the new
/// column of split `s` proposes the node `committed + columns.len() + s`.
fn face_cell(
    front: &Front,
    f: usize,
    plan: &SlabPlan,
    reshape: &Reshape,
    columns: &Columns,
    committed: u32,
) -> SlabCell {
    let first = committed + columns.len() as u32;
    cell_of_face(front, f, plan, reshape, columns, |c| plan.top(c, columns, committed), |s| first + s)
}

/// The cell over front face `f`, with the top node `top(c)` of every column and the top node
/// `mid(s)` of every active split `s`.
fn cell_of_face(
    front: &Front,
    f: usize,
    plan: &SlabPlan,
    reshape: &Reshape,
    columns: &Columns,
    top: impl Fn(u32) -> u32,
    mid: impl Fn(u32) -> u32,
) -> SlabCell {
    match reshape.swaps.role(f, plan) {
        Some(SwapRole::Absorbed) => return SlabCell::Empty,
        Some(SwapRole::Cell(four)) => {
            let cut = |a: u32, b: u32| {
                fan_end_cut_from(front, columns, four[a as usize], four[b as usize])
                    .map(|c| c == four[a as usize])
            };
            return swap::swap_cell(four.map(|c| columns.node[c as usize]), four.map(&top), cut);
        }
        None => {}
    }
    let (b, t, n, merging) = face_ends(front, f, columns, &plan.merges, top);
    match reshape.splits.active_on_face(f, plan) {
        None => slab_cell(&b[..n], &t[..n], merging),
        Some(on_edge) => {
            let mids = on_edge.map(|s| if s == NONE { NONE } else { mid(s) });
            split::split_cell(&b[..n], &t[..n], &mids[..n], merging)
        }
    }
}

/// March `layers` steps (or until every column has stopped), appending points and cells to
/// `mesh`. `columns.distance(c, k)` is how far column `c` should be from the wall after `k`
/// layers, or `None` when its stack is complete. Columns that stop when isotropic also end their
/// stack before the first layer whose height would reach the front's edge length around them
/// (`count = "auto"`); they end as [`ColumnState::EndedIsotropic`]. Unless `sizes.adapt` is
/// off, front edges
/// that grow too long for `sizes` are split ([`super::split`]), which adds columns. `caps` holds
/// the most layers of every wall vertex's stack ([`stop_at_caps`]).
#[allow(clippy::too_many_arguments)]
pub fn march(
    mesh: &mut VolumeMesh,
    columns: &mut Columns,
    front: &mut Front,
    max_layers: u32,
    sizes: &mut Sizes,
    walls: &VertexWalls,
    caps: &[u32],
    mut on_layer: impl FnMut(u32),
) -> MarchStats {
    let mut stats = MarchStats::default();
    let mut guard = CrossingGuard::default();
    let mut pit: Vec<Option<f64>> = vec![None; columns.len()];
    let mut rooms: Vec<f64> = Vec::new();
    for k in 1..=max_layers {
        let _layer = tracing::debug_span!("layer", k).entered();
        for c in 0..columns.len() {
            if columns.distance(c, k).is_none() {
                columns.stop(c);
            }
        }
        stats.columns_stopped_at_caps += stop_at_caps(columns, caps, &mut pit, k);
        plan_gaps(columns, walls, &mut rooms);
        stats.columns_stopped_at_gaps += stop_at_gaps(columns, &rooms, k);
        stats.columns_stopped_for_pits += grade_around_pits(columns, front, &mut pit, k);
        if (0..columns.len()).any(|c| columns.stops_when_isotropic(c, k)) {
            let wall_size = matches!(sizes.adapt, Adapt::Off).then_some(sizes.wall.as_slice());
            stop_isotropic_columns(mesh, columns, front, k, wall_size);
        }
        if !columns.state.contains(&ColumnState::Marching) {
            break;
        }
        columns.index_shared_nodes();
        let points = &mesh.points;
        let mut proposed: Vec<DVec3> = (0..columns.len())
            .into_par_iter()
            .map(|c| match (columns.distance(c, k), columns.distance(c, k - 1)) {
                (Some(d), Some(d_before)) if columns.is_marching(c) => columns.slide[c].project(
                    points[columns.node[c] as usize] + columns.dir[c] * (columns.scale[c] * (d - d_before)),
                ),
                _ => DVec3::ZERO,
            })
            .collect();
        let reshape = match sizes.adapt {
            Adapt::Off => Reshape::default(),
            Adapt::Wall | Adapt::Field(_) => {
                let target = sizes.tangential(&proposed, &columns.marching());
                let splits = split::propose(columns, front, &proposed, k, sizes, &target);
                let swaps = swap::propose(columns, front, &proposed, &splits, k);
                Reshape { splits, swaps, target }
            }
        };
        proposed.extend_from_slice(&reshape.splits.top);
        let (plan, reshape) =
            settle_slab_keeping_layers(mesh, columns, front, proposed, reshape, sizes, walls, &mut guard, k);
        stats.columns_stopped_early +=
            (0..columns.len()).filter(|&c| columns.is_marching(c) && !plan.moving[c]).count();
        stats.collapses += plan.collapses - plan.coarsened.len();
        stats.tangential_collapses += plan.coarsened.len();
        stats.flat_top_collapses += plan.flat_tops;
        stats.bent_columns += plan.bends;
        stats.tipped_columns += plan.tips;
        stats.crushed_columns += plan.crushed_stops;
        let (split_count, swap_count) =
            commit_slab(mesh, columns, front, &plan, &reshape, sizes, k, &mut stats);
        stats.splits += split_count;
        stats.splits_given_up += reshape.splits.len() - split_count;
        stats.swaps += swap_count;
        if plan.collapses > 0 || !plan.redirected.is_empty() || split_count > 0 || swap_count > 0 {
            guard.invalidate();
        }
        stats.layers_marched = k;
        on_layer(k);
    }
    stats.guard_rebuilds = guard.rebuilds;
    stats
}

/// End the stacks at the `crushed` edges ([`coarsen::Coarsening::crushed`]) whose columns are
/// both in their transition layers, with every column of their wall points (a fan ends
/// together); returns how many columns stopped. Converging columns that no collapse can merge
/// (two fans crossing where a convex ridge runs into a concave corner) would go on with their
/// tops ever closer, and the core would have to fill the needle they leave with slivers. In the
/// transition layers an end costs no coverage.
fn stop_crushed_transition(plan: &mut SlabPlan, columns: &Columns, crushed: &[(u32, u32)]) -> usize {
    let in_transition =
        |c: u32| columns.full_count(c as usize).is_some_and(|n| columns.layers[c as usize] >= n);
    let mut ending: Vec<u32> = crushed
        .iter()
        .filter(|&&(a, b)| in_transition(a) && in_transition(b))
        .flat_map(|&(a, b)| [columns.wall_vertex[a as usize], columns.wall_vertex[b as usize]])
        .collect();
    if ending.is_empty() {
        return 0;
    }
    ending.sort_unstable();
    ending.dedup();
    let fans = (0..columns.len() as u32).filter(|&c| {
        columns.is_marching(c as usize) && ending.binary_search(&columns.wall_vertex[c as usize]).is_ok()
    });
    plan.stop_all(fans).len()
}

/// End the stacks of the columns whose next layer (the `k`-th) would be at least as high as the
/// front's tangential size around them: its cells would be isotropic, which the core's
/// tetrahedra do better. That size is the mean edge length at the column's wall vertex
/// ([`Front::mean_edge_length_at_columns`]) graded over the front so that neighbours' sizes
/// differ by at most the growth ratio ([`front_sizes`]): then neighbouring stacks end at most one
/// layer apart (the cliff rule below seldom has to end a stack early). Where the front widens
/// faster than the layers grow and is not split (`wall_size` given: convex walls coarser than
/// the growth rate can follow), the wall's own tangential size ends the stack instead.
fn stop_isotropic_columns(
    mesh: &VolumeMesh,
    columns: &mut Columns,
    front: &Front,
    k: u32,
    wall_size: Option<&[f64]>,
) {
    let size = front_sizes(&mesh.points, columns, front);
    let (ended, stopped) = ended_neighbour_layers(columns, front);
    let ends = |c: usize| {
        let (Some(d), Some(d_before)) = (columns.distance(c, k), columns.distance(c, k - 1)) else {
            return false;
        };
        // A neighbour's stack ended more than one layer lower: end here too, so that the stacks
        // step down one layer at a time (no cliff in the final front). A full stack (in its
        // transition layers) steps down to a stopped neighbour alike: the steps it would leave
        // make slivers and size jumps in the core (spot: 401 -> 198 tetrahedra below 10 deg).
        let full = columns.full_count(c).is_some_and(|n| columns.layers[c] >= n);
        let cliff = ended[c] < columns.layers[c] || (full && stopped[c] < columns.layers[c]);
        cliff || d - d_before >= wall_size.map_or(size[c], |w| size[c].min(w[c]))
    };
    let candidates: Vec<bool> =
        (0..columns.len()).map(|c| columns.is_marching(c) && columns.stops_when_isotropic(c, k)).collect();
    // The columns of one wall vertex (a fan) end together: a fan strip cell with one side
    // stopped and the other moving would be flat.
    let mut vertex_ends = vec![false; columns.wall_vertex_count()];
    for c in (0..columns.len()).filter(|&c| candidates[c] && ends(c)) {
        vertex_ends[columns.wall_vertex[c] as usize] = true;
    }
    for c in 0..columns.len() {
        if candidates[c] && vertex_ends[columns.wall_vertex[c] as usize] {
            // The last layer built, against the tangential size it ended at.
            let (d_before, d_last) = (
                columns.distance(c, k - 1).unwrap_or(0.0),
                k.checked_sub(2).and_then(|j| columns.distance(c, j)),
            );
            let ratio = (d_before - d_last.unwrap_or(0.0)) / size[c];
            // What its neighbours are graded from: no more than the layer it did not build (a
            // column may end with its wall vertex's others before its own size says so).
            let refused = columns.distance(c, k).map_or(size[c], |d| d - d_before);
            columns.state[c] = ColumnState::EndedIsotropic { ratio, size: size[c].min(refused) };
        }
    }
}

/// The front's tangential size at every column for the isotropic stop: the mean edge length at
/// its wall vertex (for a stack already ended: the size it ended at), lowered where a
/// neighbour's size times a little less than the growth ratio is smaller. The columns of a
/// wall vertex, which end together, share the smallest of their sizes.
fn front_sizes(points: &[DVec3], columns: &Columns, front: &Front) -> Vec<f64> {
    let mut size = front.mean_edge_length_at_columns(points, columns);
    for (c, s) in size.iter_mut().enumerate() {
        if let Some(ended) = columns.isotropic_size(c) {
            *s = ended;
        }
    }
    let mut by_vertex: Vec<u32> = (0..columns.len() as u32).collect();
    by_vertex.sort_unstable_by_key(|&c| columns.wall_vertex[c as usize]);
    let mut first = vec![0u32; columns.wall_vertex_count() + 1];
    for &c in &by_vertex {
        first[columns.wall_vertex[c as usize] as usize + 1] += 1;
    }
    for v in 0..first.len() - 1 {
        first[v + 1] += first[v];
    }
    let siblings = |c: usize| {
        let v = columns.wall_vertex[c] as usize;
        by_vertex[first[v] as usize..first[v + 1] as usize].iter().map(|&s| s as usize)
    };
    let growth = |c: usize| columns.spec[c].map_or(f64::INFINITY, |s| s.growth);
    let ratio = |a: usize, b: usize| {
        if columns.wall_vertex[a] == columns.wall_vertex[b] {
            1.0
        } else {
            growth(a).min(growth(b)).powf(TUNING.grading.growth_share)
        }
    };
    let neighbours = |c: usize, out: &mut Vec<usize>| {
        front.neighbours(c, out);
        out.extend(siblings(c));
    };
    crate::sizing::graded_minimum(&mut size, neighbours, |v, w, x| x * ratio(v, w));
    size
}

/// For every column, the fewest layers of a neighbour (across a front edge) whose stack ended:
/// at isotropy, and stopped (early, or past its count by a crossing), a merged neighbour counted
/// by the column it merged into (`u32::MAX` if none).
fn ended_neighbour_layers(columns: &Columns, front: &Front) -> (Vec<u32>, Vec<u32>) {
    let mut isotropic = vec![u32::MAX; columns.len()];
    let mut stopped = vec![u32::MAX; columns.len()];
    for (a, b) in front.edges() {
        for (c, n) in [(a, b), (b, a)] {
            let n = columns.carrier(n);
            match columns.state[n] {
                ColumnState::EndedIsotropic { .. } => isotropic[c] = isotropic[c].min(columns.layers[n]),
                ColumnState::Stopped { .. } if columns.spec[n].is_some() => {
                    stopped[c] = stopped[c].min(columns.layers[n])
                }
                _ => {}
            }
        }
    }
    (isotropic, stopped)
}

/// Where every column will be at the end of the guard's horizon: after layer `k` if the slab
/// has merged columns (they move to other columns' positions), else after the next
/// [`TUNING.guard.lookahead_layers`](super::tuning::Guard::lookahead_layers) layers if it keeps
/// moving (or its last layer, if that comes first).
fn reach(plan: &SlabPlan, mesh: &VolumeMesh, columns: &Columns, k: u32) -> Reach {
    let proposal = Proposal::of_plan(mesh, plan);
    let committed = proposal.committed;
    if plan.collapses > 0 {
        let end =
            (0..columns.len() as u32).map(|c| proposal.position(plan.top(c, columns, committed))).collect();
        return Reach { end, through_layer: k };
    }
    let last = k + TUNING.guard.lookahead_layers - 1;
    let end = (0..columns.len())
        .into_par_iter()
        .map(|c| {
            let node = mesh.points[columns.node[c] as usize];
            let now = columns.distance(c, k - 1);
            let ahead = (k..=last).rev().find_map(|j| columns.distance(c, j));
            match (now, ahead) {
                (Some(d0), Some(d1)) if plan.moving[c] => {
                    node + columns.dir[c] * (columns.scale[c] * (d1 - d0))
                }
                _ => node,
            }
        })
        .collect();
    Reach { end, through_layer: last }
}

/// [`settle_slab`], taking back the tangential collapses whose columns the slab then stops
/// because the new front crossed itself, where that stops fewer columns. A collapse is made only
/// where the cells around it stay valid, but whether the front crosses itself is known only once
/// the slab is settled; coarsening the front is not worth a layer. The slab is settled again with
/// those edges kept (each retry vetoes at least one more of the finitely many collapses, so this
/// ends), and the settling that stops the fewest columns is kept (the first, with the most
/// collapses, among equals). Returns the plan and the reshaping it settled with.
#[allow(clippy::too_many_arguments)]
fn settle_slab_keeping_layers(
    mesh: &VolumeMesh,
    columns: &Columns,
    front: &Front,
    proposed: Vec<DVec3>,
    reshape: Reshape,
    sizes: &Sizes,
    walls: &VertexWalls,
    guard: &mut CrossingGuard,
    k: u32,
) -> (SlabPlan, Reshape) {
    let mut vetoed: Vec<(u32, u32)> = Vec::new();
    let mut best: Option<(usize, SlabPlan, Reshape)> = None;
    loop {
        if !vetoed.is_empty() {
            // The pairs were built for the last settling's merges; another set of merges of the
            // same count would pass for them.
            guard.invalidate();
        }
        let mut attempt = reshape.clone();
        let plan = settle_slab(
            mesh,
            columns,
            front,
            proposed.clone(),
            &mut attempt,
            sizes,
            walls,
            guard,
            k,
            &vetoed,
        );
        let stops = (0..columns.len()).filter(|&c| columns.is_marching(c) && !plan.moving[c]).count();
        let uncrossed = |c: u32| plan.uncrossed.contains(&c);
        let blamed: Vec<(u32, u32)> =
            plan.coarsened.iter().copied().filter(|&(a, b)| uncrossed(a) || uncrossed(b)).collect();
        if best.as_ref().is_none_or(|(fewest, _, _)| stops < *fewest) {
            best = Some((stops, plan, attempt));
        }
        if blamed.is_empty() {
            break;
        }
        tracing::debug!(
            ?blamed,
            "tangential collapses whose columns stopped where the front crossed itself: settling the slab again without them"
        );
        vetoed.extend(blamed);
    }
    if !vetoed.is_empty() {
        // The pairs were last built for another settling's merges.
        guard.invalidate();
    }
    let (_, plan, reshape) = best.expect("settled at least once");
    (plan, reshape)
}

/// Decide which columns move and merge so that every cell of the slab is valid and the new
/// front does not cross itself, leaving the edges `vetoed` uncollapsed: first the tangential
/// collapses of short edges (unless adaptivity is off), then the merges of face columns passing
/// a concave ridge's bisector ([`entropy::merge_bisector_crossings`]), then the repairs of
/// invalid cells and of crossings.
#[allow(clippy::too_many_arguments)]
fn settle_slab(
    mesh: &VolumeMesh,
    columns: &Columns,
    front: &Front,
    proposed: Vec<DVec3>,
    reshape: &mut Reshape,
    sizes: &Sizes,
    walls: &VertexWalls,
    guard: &mut CrossingGuard,
    k: u32,
    vetoed: &[(u32, u32)],
) -> SlabPlan {
    let mut plan = SlabPlan::new(columns.marching(), proposed);
    {
        let invalid_cells =
            |plan: &SlabPlan, group: &[u32]| invalid_cells_around(plan, reshape, mesh, columns, front, group);
        if !matches!(sizes.adapt, Adapt::Off) {
            let user = sizes.user(&plan.proposed, &plan.moving);
            let limits = (&reshape.target[..], &user[..], k);
            let coarsening =
                coarsen::collapse_short_edges(&mut plan, front, columns, limits, vetoed, |plan, group| {
                    invalid_cells(plan, group) == 0
                });
            plan.coarsened = coarsening.made;
            plan.crushed_stops = stop_crushed_transition(&mut plan, columns, &coarsening.crushed);
        }
        entropy::merge_bisector_crossings(&mut plan, front, columns, &mesh.points, walls, invalid_cells);
        entropy::merge_overtaken(&mut plan, front, columns, &mesh.points, walls, k, invalid_cells);
        plan.flat_tops = entropy::merge_flat_tops(&mut plan, front, columns, &mesh.points, k, invalid_cells);
    }
    let mut to_check: Vec<usize> = (0..front.len()).collect();
    // Two faces that do not move cannot start to cross: only moving ones are suspects.
    let mut suspects: Vec<usize> = (0..front.len())
        .filter(|&f| front.face_columns(f).iter().any(|&c| plan.moving[c as usize]))
        .collect();
    loop {
        // The faces whose tops the repairs changed (a column stopped or merged, a split or swap
        // given up) must be tested again too: a quad whose corner stopped may no longer be
        // cappable.
        let repaired = repair_invalid_cells(&mut plan, reshape, mesh, columns, front, walls, to_check);
        suspects.extend(repaired);
        suspects.sort_unstable();
        suspects.dedup();
        if guard.is_stale(k, &plan) {
            guard.rebuild(&plan, reshape, mesh, columns, front, reach(&plan, mesh, columns, k));
        }
        let crossings = guard.crossings(&plan, reshape, mesh, columns, front, &suspects);
        let mut changed = Vec::new();
        let invalid_cells =
            |plan: &SlabPlan, group: &[u32]| invalid_cells_around(plan, reshape, mesh, columns, front, group);
        // A V closing along a crease closes at once (and its merges may make the next crease).
        let pair_crosses = |plan: &SlabPlan, (f, g): (usize, usize)| {
            CrossingGuard::pair_crosses(plan, reshape, mesh, columns, front, f, g)
        };
        loop {
            let crossing: Vec<(usize, usize)> =
                crossings.pairs.iter().copied().filter(|&pair| pair_crosses(&plan, pair)).collect();
            let mut merged_any = false;
            for pairs in entropy::crease_groups(&plan, front, &crossing).into_iter().filter(|p| p.len() > 1) {
                let crosses = |plan: &SlabPlan| pairs.iter().any(|&pair| pair_crosses(plan, pair));
                if let Some(merged) =
                    entropy::merge_into_crease(&mut plan, front, columns, &pairs, &crosses, &invalid_cells)
                {
                    changed.extend(merged);
                    merged_any = true;
                }
            }
            if !merged_any {
                break;
            }
        }
        for (f, g) in crossings.pairs {
            // An earlier stop or merge may have uncrossed them (fronts meeting head on across a
            // gap both stop, at the medial surface).
            let crosses =
                |plan: &SlabPlan| CrossingGuard::pair_crosses(plan, reshape, mesh, columns, front, f, g);
            if !crosses(&plan) {
                continue;
            }
            if let Some(merged) =
                entropy::merge_into_crease(&mut plan, front, columns, &[(f, g)], &crosses, &invalid_cells)
            {
                changed.extend(merged);
                continue;
            }
            if let Some(merged) = entropy::retreat_fans(&mut plan, front, columns, (f, g), &invalid_cells) {
                changed.extend(merged);
                continue;
            }
            let stopped = stop_fewest_to_uncross(&mut plan, reshape, mesh, columns, front, (f, g), k)
                .unwrap_or_else(|| stop_to_uncross(&mut plan, front, columns, f, g));
            plan.uncrossed.extend(&stopped);
            changed.extend(stopped);
        }
        for f in crossings.uncappable {
            tracing::debug!(face = f, at = ?wall_points(front, f, columns), "no pyramid caps the quad: stopping its columns");
            changed.extend(plan.stop_all(front.face_columns(f).iter().copied()));
        }
        if changed.is_empty() {
            return plan;
        }
        to_check = reshape.faces_around_columns(front, &changed);
        suspects = to_check.clone();
    }
}

/// Stop the columns of the crossing faces `f` and `g`. Returns the columns that stopped.
fn stop_to_uncross(plan: &mut SlabPlan, front: &Front, columns: &Columns, f: usize, g: usize) -> Vec<u32> {
    tracing::debug!(face = f, other = g, at = ?wall_points(front, f, columns), other_at = ?wall_points(front, g, columns), "the new front crosses itself: stopping both faces' columns");
    let mut stopped = plan.stop_all(front.face_columns(f).iter().copied());
    stopped.extend(plan.stop_all(front.face_columns(g).iter().copied()));
    stopped
}

/// How many cells around the columns `group` are invalid under `plan`.
fn invalid_cells_around(
    plan: &SlabPlan,
    reshape: &Reshape,
    mesh: &VolumeMesh,
    columns: &Columns,
    front: &Front,
    group: &[u32],
) -> usize {
    front
        .faces_around_columns(group)
        .into_iter()
        .filter(|&f| !face_cell_is_valid(plan, reshape, mesh, columns, front, f))
        .count()
}

/// Whether the cell over face `f` is valid under `plan`.
fn face_cell_is_valid(
    plan: &SlabPlan,
    reshape: &Reshape,
    mesh: &VolumeMesh,
    columns: &Columns,
    front: &Front,
    f: usize,
) -> bool {
    let proposal = Proposal::of_plan(mesh, plan);
    let committed = proposal.committed;
    proposal.cell_is_valid(&face_cell(front, f, plan, reshape, columns, committed))
}

/// Merge columns to mend the invalid cell over face `f`: its crushed edge ([`entropy::collapse_crushed_edge`]),
/// else a face column of it merging early into the bisector it is about to pass
/// ([`entropy::merge_before_crossing`]). Returns the columns whose cells changed.
fn mend_by_merge(
    plan: &mut SlabPlan,
    reshape: &Reshape,
    mesh: &VolumeMesh,
    columns: &Columns,
    front: &Front,
    walls: &VertexWalls,
    f: usize,
) -> Option<Vec<u32>> {
    if let Some(merged) = entropy::collapse_crushed_edge(plan, front, f, columns, &mesh.points) {
        return Some(merged);
    }
    let invalid_cells =
        |plan: &SlabPlan, group: &[u32]| invalid_cells_around(plan, reshape, mesh, columns, front, group);
    let root = entropy::merge_before_crossing(plan, front, f, columns, &mesh.points, walls, &invalid_cells)?;
    Some(plan.merges.group(root).collect())
}

/// Check the cells over `to_check` and repair the invalid ones until every cell is valid: giving
/// up their swap or splits, else merges that mend them ([`mend_by_merge`]), else a column bent
/// to its neighbours ([`bend::bend_to_mend`]) or its top tipped sideways
/// ([`bend::nudge_to_mend`]), else stopping the fewest of their columns
/// ([`stop_fewest_columns`]) or all of them.
/// Merges come first: an invalid cell without a crushed edge of its own may be mended by a
/// collapse next to it (its neighbour crosses the bisector in another cell), so its columns stop
/// only after a round that merged nothing. Returns the faces whose cells changed.
#[allow(clippy::too_many_arguments)]
fn repair_invalid_cells(
    plan: &mut SlabPlan,
    reshape: &mut Reshape,
    mesh: &VolumeMesh,
    columns: &Columns,
    front: &Front,
    walls: &VertexWalls,
    mut to_check: Vec<usize>,
) -> Vec<usize> {
    let mut changed_anywhere = Vec::new();
    while !to_check.is_empty() {
        let invalid: Vec<usize> = {
            let (plan, reshape) = (&*plan, &*reshape);
            to_check
                .par_iter()
                .copied()
                .filter(|&f| !face_cell_is_valid(plan, reshape, mesh, columns, front, f))
                .collect()
        };
        let mut changed = Vec::new();
        let mut changed_faces = Vec::new();
        let mut uncollapsed = Vec::new();
        for &f in &invalid {
            let given_up = reshape.give_up(f, plan);
            if !given_up.is_empty() {
                changed_faces.extend(given_up);
                continue;
            }
            match mend_by_merge(plan, reshape, mesh, columns, front, walls, f) {
                Some(merged) => changed.extend(merged),
                None => uncollapsed.push(f),
            }
        }
        if changed.is_empty() && changed_faces.is_empty() {
            for &f in &uncollapsed {
                // A merge or bend for a face before it in this round may have mended it.
                if face_cell_is_valid(plan, reshape, mesh, columns, front, f) {
                    continue;
                }
                let invalid_cells = |plan: &SlabPlan, group: &[u32]| {
                    invalid_cells_around(plan, reshape, mesh, columns, front, group)
                };
                if let Some(root) = entropy::merge_to_mend(plan, front, f, columns, &invalid_cells) {
                    changed.extend(plan.merges.group(root));
                    continue;
                }
                let face_valid = |plan: &SlabPlan| face_cell_is_valid(plan, reshape, mesh, columns, front, f);
                if let Some(root) =
                    bend::bend_to_mend(plan, front, f, columns, &mesh.points, &face_valid, &invalid_cells)
                {
                    changed.extend(plan.merges.group(root));
                    continue;
                }
                if let Some(root) =
                    bend::nudge_to_mend(plan, front, f, columns, &mesh.points, &face_valid, &invalid_cells)
                {
                    changed.extend(plan.merges.group(root));
                    continue;
                }
                tracing::debug!(face = f, at = ?wall_points(front, f, columns), "invalid cell: stopping its columns");
                if tracing::enabled!(tracing::Level::TRACE) {
                    trace_invalid_cell(plan, reshape, mesh, columns, front, f);
                }
                let stopped = stop_fewest_columns(plan, reshape, mesh, columns, front, f)
                    .unwrap_or_else(|| stop_face_columns(plan, front, columns, f));
                changed.extend(stopped);
            }
            uncollapsed.clear();
        }
        // Only the cells around a column that stopped or merged, or on a split given up, change;
        // the invalid ones left wait for the next round.
        to_check = reshape.faces_around_columns(front, &changed);
        to_check.extend(changed_faces);
        changed_anywhere.extend_from_slice(&to_check);
        to_check.extend(uncollapsed);
        to_check.sort_unstable();
        to_check.dedup();
    }
    changed_anywhere.sort_unstable();
    changed_anywhere.dedup();
    changed_anywhere
}

/// Stop the live columns whose wall vertex's stack is capped below layer `k` (`caps`, by wall
/// vertex: the core could not fill around their tops, [`crate::pipeline`]); they count as
/// pits of their thickness for [`grade_around_pits`]. Returns how many stopped.
fn stop_at_caps(columns: &mut Columns, caps: &[u32], pit: &mut Vec<Option<f64>>, k: u32) -> usize {
    pit.resize(columns.len(), None);
    let mut stopped = 0;
    for (c, depth) in pit.iter_mut().enumerate() {
        let capped = caps.get(columns.wall_vertex[c] as usize).is_some_and(|&cap| cap < k);
        if columns.is_marching(c) && capped {
            columns.stop(c);
            *depth = Some(columns.distance(c, k - 1).unwrap_or(0.0));
            stopped += 1;
        }
    }
    stopped
}

/// The medial surface of the gap each new column faces (`rooms`, by column): how far its climb
/// from its wall point along the exact wall distance gets before it stalls
/// ([`super::gap::room_above`]). Infinite where it does not stall within twice the stack, and
/// where it stalls within the first layer: that is the column's own corner (a concave ridge's
/// bisector), where the entropy merges carry the stack on.
fn plan_gaps(columns: &Columns, walls: &VertexWalls, rooms: &mut Vec<f64>) {
    let start = rooms.len();
    rooms.resize(columns.len(), f64::INFINITY);
    let fresh: Vec<(usize, f64)> = (start..columns.len())
        .into_par_iter()
        .filter_map(|c| {
            let full = columns.distance(c, columns.full_count(c)?)?;
            let first = columns.distance(c, 1)?;
            let reach = 2.0 * full;
            let (base, dir) = (columns.base[c], columns.dir[c]);
            // Only a wall nearer than `reach` at `reach` along the column makes a gap: without
            // one the distance rises all the way there (it is 1-Lipschitz), so the climb would
            // not stall.
            walls.distance_within(base + dir * reach, reach * (1.0 - 1e-9))?;
            let room = walls.room_above(base, dir, reach);
            (room < reach && room > first).then_some((c, room))
        })
        .collect();
    for (c, room) in fresh {
        rooms[c] = room;
    }
}

/// Stop, before layer `k`, the stacks of the wall vertices with a column whose layer would leave
/// less than its own height between its top and the medial surface of its gap (`rooms`): the
/// fronts meeting there from both sides leave the core a gap of two layers' height, where
/// stopping at their crossing left slabs of any thinness, which only slivers fill. Returns how
/// many columns stopped.
fn stop_at_gaps(columns: &mut Columns, rooms: &[f64], k: u32) -> usize {
    let mut vertex_ends = vec![false; columns.wall_vertex_count()];
    for c in 0..columns.len() {
        let close = match (columns.distance(c, k), columns.distance(c, k - 1)) {
            (Some(d), Some(d_before)) => rooms[c] - d < d - d_before,
            _ => false,
        };
        if columns.is_marching(c) && close {
            vertex_ends[columns.wall_vertex[c] as usize] = true;
        }
    }
    let mut stopped = 0;
    for c in 0..columns.len() {
        if columns.is_marching(c) && vertex_ends[columns.wall_vertex[c] as usize] {
            columns.state[c] = ColumnState::Stopped { at_gap: true };
            stopped += 1;
        }
    }
    stopped
}

/// Stacks that stopped with no layer leave a pit to the wall that the core fills with slivers
/// (its walls are steep and narrow: the ONERA M6's wing tip). Around such a stack, and around
/// the ones stopped for it, a stack stops before it rises above its neighbour's thickness by
/// more than [`TUNING.grading.pit_slope`](super::tuning::Grading::pit_slope) times the distance
/// between their wall points, so the pit opens into a cone. `pit` records the thickness of each
/// stack stopped in a pit. Returns how many columns stopped.
fn grade_around_pits(columns: &mut Columns, front: &Front, pit: &mut Vec<Option<f64>>, k: u32) -> usize {
    // Splits add columns as the front marches.
    pit.resize(columns.len(), None);
    for (c, depth) in pit.iter_mut().enumerate() {
        // Stopped with no layer: not merged on, not held by the wall, not ended at isotropy.
        let stopped = matches!(columns.state[c], ColumnState::Stopped { .. })
            && columns.spec[c].is_some()
            && columns.slide[c] != Slide::Fixed;
        if depth.is_none() && stopped && columns.layers[c] == 0 {
            *depth = Some(0.0);
        }
    }
    // From the pits out to the live stacks sharing a front face with them (none on most walls).
    let mut stop = Vec::new();
    for (n, h) in pit.iter().enumerate().filter_map(|(n, h)| Some((n, (*h)?))) {
        for c in front.faces_of(n as u32).flat_map(|f| front.face_columns(f)) {
            let c = *c as usize;
            let Some(height) = columns.distance(c, k).filter(|_| columns.is_marching(c)) else { continue };
            if height > h + TUNING.grading.pit_slope * columns.base[c].distance(columns.base[n]) {
                stop.push(c as u32);
            }
        }
    }
    stop.sort_unstable();
    stop.dedup();
    for &c in &stop {
        columns.stop(c as usize);
        pit[c as usize] = Some(columns.distance(c as usize, k - 1).unwrap_or(0.0));
    }
    stop.len()
}

/// Stop the columns of face `f`; when `f` is a fan face (a strip quad, a ridge end's
/// triangle), also their fan mates: the other columns from the same wall points, joined to them
/// by fan edges. A fan cell with one corner stopped and its fan neighbour moving is flat on the
/// wall and folded above it (its top edges across the fan point opposite ways: a fan step is
/// narrower than a layer is high), so a partial stop would stop the fans cell by cell along the
/// whole ridge (the ONERA M6 trailing edge from one cell at its tip, an elbow ridge from one
/// crushed wall triangle); a whole fan stopped leaves its strips wedges, which stand. A corner
/// patch on the wall stops alone: there its mates are the corner's every column (wtc2's ledge
/// corners, whose wall triangles fail in the first layer, would take all their ridges along).
/// Returns the columns whose cells change.
fn stop_face_columns(plan: &mut SlabPlan, front: &Front, columns: &Columns, f: usize) -> Vec<u32> {
    let cols = front.face_columns(f);
    let fan_edges = face_fan_edges(front, columns, f);
    let corner_on_wall =
        fan_edges.iter().all(|&e| e) && cols.iter().any(|&c| columns.layers[c as usize] == 0);
    let mut group: Vec<u32> = cols.to_vec();
    if fan_edges.contains(&true) && !corner_on_wall {
        add_fan_mates(front, columns, &mut group);
    }
    plan.stop_all(group)
}

/// Whether each edge of face `f` (from its corner `i` to the next) is a fan edge.
fn face_fan_edges(front: &Front, columns: &Columns, f: usize) -> Vec<bool> {
    let cols = front.face_columns(f);
    let n = cols.len();
    (0..n).map(|i| columns.is_fan_edge(cols[i] as usize, cols[(i + 1) % n] as usize)).collect()
}

/// Stop the fewest wall points that mend invalid face `f` ([`stop_fewest`]), if that leaves its
/// cell valid and fewer invalid cells around. `None` when no such stop does. A face whose far
/// corner is still short of the bisector its other corners merged on needs only that corner
/// stopped. A fan whose columns merged into different bisector columns (a fin's trailing edge
/// 0.2 above the body: its fan is swallowed by the fin's root, its trailing edge's root and the
/// saddle corner between them) needs only that fan stopped, where stopping a root would stop
/// every column merged into it.
fn stop_fewest_columns(
    plan: &mut SlabPlan,
    reshape: &Reshape,
    mesh: &VolumeMesh,
    columns: &Columns,
    front: &Front,
    f: usize,
) -> Option<Vec<u32>> {
    stop_fewest(plan, reshape, mesh, columns, front, &[f], |trial, before, after| {
        face_cell_is_valid(trial, reshape, mesh, columns, front, f) && after < before
    })
}

/// Stop the fewest wall points that uncross faces `f` and `g` ([`stop_fewest`] on either face),
/// leaving no more invalid cells around; `None` when no single stop does. Stopping both faces'
/// columns would stop every column merged into their roots too: where a ridge's fan meets its
/// floor's front (a wing's trailing edge at its root), that is most of the crease between them.
/// Only while a column of the two faces is within its full count at layer `k`: in the
/// transition layers a stop costs no stack its count, and stopping both faces leaves the core a
/// plainer front than a pit one column wide.
fn stop_fewest_to_uncross(
    plan: &mut SlabPlan,
    reshape: &Reshape,
    mesh: &VolumeMesh,
    columns: &Columns,
    front: &Front,
    (f, g): (usize, usize),
    k: u32,
) -> Option<Vec<u32>> {
    let within_count = [f, g]
        .iter()
        .flat_map(|&h| front.face_columns(h))
        .any(|&c| columns.full_count(c as usize).is_some_and(|n| k <= n));
    if !within_count {
        return None;
    }
    stop_fewest(plan, reshape, mesh, columns, front, &[f, g], |trial, before, after| {
        after <= before && !CrossingGuard::pair_crosses(trial, reshape, mesh, columns, front, f, g)
    })
}

/// Of the stops of one root of `faces` (with its fan mates on a fan face, and every column
/// merged into it) and, on a fan face, of one fan of it taken out of the groups its columns
/// merged into ([`SlabPlan::stop_out_of_groups`]), the one that `accept`s the trial plan (given
/// the invalid cells around before and after) and stops the fewest wall points; applied to
/// `plan`, returning the columns whose cells change.
fn stop_fewest(
    plan: &mut SlabPlan,
    reshape: &Reshape,
    mesh: &VolumeMesh,
    columns: &Columns,
    front: &Front,
    faces: &[usize],
    accept: impl Fn(&SlabPlan, usize, usize) -> bool,
) -> Option<Vec<u32>> {
    let mut candidates: Vec<(Vec<u32>, bool)> = Vec::new();
    for &f in faces {
        let roots = plan.merges.face_roots(front, f);
        if roots.len() < 2 {
            continue;
        }
        let fan_face = face_fan_edges(front, columns, f).contains(&true);
        let with_mates = |c: u32| {
            let mut group = vec![c];
            if fan_face {
                add_fan_mates(front, columns, &mut group);
            }
            group
        };
        candidates.extend(roots.iter().map(|&r| (with_mates(r), false)));
        if fan_face {
            let merged = front.face_columns(f).iter().filter(|&&c| plan.merges.is_merged(c));
            candidates.extend(merged.map(|&c| (with_mates(c), true)));
        }
    }
    let mut best: Option<(usize, SlabPlan, Vec<u32>)> = None;
    for (group, out_of_groups) in candidates {
        let around: Vec<u32> = group.iter().flat_map(|&g| plan.merges.group(plan.merges.root(g))).collect();
        let before = invalid_cells_around(plan, reshape, mesh, columns, front, &around);
        let mut trial = plan.clone();
        let changed = if out_of_groups { trial.stop_out_of_groups(&group) } else { trial.stop_all(group) };
        let stopped = wall_point_count(columns, &changed);
        if best.as_ref().is_none_or(|b| stopped < b.0)
            && accept(&trial, before, invalid_cells_around(&trial, reshape, mesh, columns, front, &around))
        {
            best = Some((stopped, trial, changed));
        }
    }
    let (_, trial, changed) = best?;
    *plan = trial;
    Some(changed)
}

/// How many wall points the columns `cols` start from (a fan's columns share one).
fn wall_point_count(columns: &Columns, cols: &[u32]) -> usize {
    let mut points: Vec<u32> = cols.iter().map(|&c| columns.wall_vertex[c as usize]).collect();
    points.sort_unstable();
    points.dedup();
    points.len()
}

/// Add to `group` the fan mates of its columns: the columns joined to them by fan edges.
fn add_fan_mates(front: &Front, columns: &Columns, group: &mut Vec<u32>) {
    let mut mates = Vec::new();
    let mut i = 0;
    while i < group.len() {
        front.fan_mates(columns, group[i] as usize, &mut mates);
        for &m in &mates {
            if !group.contains(&(m as u32)) {
                group.push(m as u32);
            }
        }
        i += 1;
    }
}

/// Log the invalid cell over face `f`: its shape and its bottom and top nodes with their
/// positions.
fn trace_invalid_cell(
    plan: &SlabPlan,
    reshape: &Reshape,
    mesh: &VolumeMesh,
    columns: &Columns,
    front: &Front,
    f: usize,
) {
    let proposal = Proposal::of_plan(mesh, plan);
    let committed = proposal.committed;
    let cell = face_cell(front, f, plan, reshape, columns, committed);
    let cols = front.face_columns(f);
    let nodes: Vec<(u32, DVec3)> = cols
        .iter()
        .map(|&c| columns.node[c as usize])
        .chain(cols.iter().map(|&c| plan.top(c, columns, committed)))
        .map(|n| (n, proposal.position(n)))
        .collect();
    tracing::trace!(?cell, ?nodes, "the invalid cell");
}

/// Where face `f`'s columns start on the wall, with their scales (for the debug log).
fn wall_points(front: &Front, f: usize, columns: &Columns) -> Vec<(u32, [f32; 3], f32)> {
    let at = |c: u32| (c, columns.base[c as usize].as_vec3().to_array(), columns.scale[c as usize] as f32);
    front.face_columns(f).iter().map(|&c| at(c)).collect()
}

/// Create the nodes of the moving columns and of the splits, emit the slab's cells, swap the
/// swapped faces, add the split columns and apply the merges; returns the number of splits and
/// of swaps made.
#[allow(clippy::too_many_arguments)]
fn commit_slab(
    mesh: &mut VolumeMesh,
    columns: &mut Columns,
    front: &mut Front,
    plan: &SlabPlan,
    reshape: &Reshape,
    sizes: &mut Sizes,
    k: u32,
    stats: &mut MarchStats,
) -> (usize, usize) {
    let splits = &reshape.splits;
    let mut new_node = vec![u32::MAX; columns.len()];
    for c in 0..columns.len() {
        if plan.moving[c] && !plan.merges.is_merged(c as u32) {
            new_node[c] = mesh.points.len() as u32;
            mesh.points.push(plan.proposed[c]);
        }
    }
    let mut mid_node = vec![NONE; splits.len()];
    for s in splits.active(plan) {
        mid_node[s] = mesh.points.len() as u32;
        mesh.points.push(splits.top[s]);
    }
    let top: Vec<u32> = (0..columns.len() as u32)
        .map(|c| {
            let r = plan.merges.root(c) as usize;
            if plan.moving[r] {
                new_node[r]
            } else {
                columns.node[c as usize]
            }
        })
        .collect();
    // The cells are decided in parallel, then emitted in face order (deterministic output).
    let mut cells: Vec<(bool, SlabCell)> = (0..front.len())
        .into_par_iter()
        .map(|f| {
            let moved = front.face_columns(f).iter().any(|&c| top[c as usize] != columns.node[c as usize]);
            let cell =
                cell_of_face(front, f, plan, reshape, columns, |c| top[c as usize], |s| mid_node[s as usize]);
            (moved, cell)
        })
        .collect();
    let turns = if plan.collapses > 0 && !matches!(sizes.adapt, Adapt::Off) {
        let reshaped: Vec<bool> = (0..front.len())
            .map(|f| {
                reshape.swaps.role(f, plan).is_some() || reshape.splits.active_on_face(f, plan).is_some()
            })
            .collect();
        let proposal = Proposal { points: &mesh.points, proposed: &[], committed: u32::MAX };
        swap::turn_merged_tops(front, columns, plan, &reshaped, &top, &mesh.points, &mut cells, |cell| {
            proposal.cell_is_valid(cell)
        })
    } else {
        Vec::new()
    };
    for (f, (moved, cell)) in cells.into_iter().enumerate() {
        if moved {
            // The top is now front, even under a flat cell whose top lies on a neighbour's face.
            front.raise(f);
        }
        emit_cell(mesh, cell, stats);
    }
    for c in 0..columns.len() {
        let r = plan.merges.root(c as u32) as usize;
        if !plan.moving[r] {
            columns.stop(c);
        } else if r != c {
            columns.state[c] = ColumnState::MergedInto(r as u32);
            columns.node[c] = top[c];
        } else {
            record_step(
                columns,
                c,
                mesh.points[columns.node[c] as usize].distance(mesh.points[top[c] as usize]),
            );
            columns.node[c] = top[c];
            columns.layers[c] += 1;
        }
    }
    for &(c, dir, scale) in &plan.redirected {
        columns.dir[c as usize] = dir;
        columns.scale[c as usize] = scale;
    }
    let swapped = swap::commit(&reshape.swaps, plan, front) + swap::commit_turns(&turns, front);
    let old_count = columns.len() as u32;
    let made = split::commit(splits, plan, &mid_node, k, columns, front, sizes);
    if plan.collapses > 0 {
        let mut carrier = plan.merges.roots().to_vec();
        carrier.extend(old_count..columns.len() as u32);
        front.apply_merges(&carrier);
    } else if made > 0 || swapped > 0 {
        front.index_columns(columns.len());
    }
    (made, swapped)
}

/// Remember column `c`'s new step and how it compares with the one before.
fn record_step(columns: &mut Columns, c: usize, step: f64) {
    let before = columns.last_step[c];
    if before > 0.0 && step > 0.0 {
        let ratio = step / before;
        let worst = columns.max_step_ratio[c];
        if worst == 0.0 || ratio.ln().abs() > worst.ln().abs() {
            columns.max_step_ratio[c] = ratio;
        }
    }
    columns.last_step[c] = step;
}

fn emit_cell(mesh: &mut VolumeMesh, cell: SlabCell, stats: &mut MarchStats) {
    match cell {
        SlabCell::Empty | SlabCell::Flat => {}
        SlabCell::Standard { kind, nodes } => mesh.push_cell(kind, &nodes[..kind.node_count()], LAYER_ZONE),
        SlabCell::Split { faces, apex: Some(apex) } => {
            for (kind, nodes) in split_pieces(&faces, Some(apex), u32::MAX) {
                mesh.push_cell(kind, &nodes, LAYER_ZONE);
            }
        }
        SlabCell::Split { faces, apex: None } => {
            let centre = mesh.points.len() as u32;
            let proposal = Proposal { points: &mesh.points, proposed: &[], committed: u32::MAX };
            let c = proposal.centre(&faces);
            mesh.points.push(c);
            for (kind, nodes) in split_pieces(&faces, None, centre) {
                mesh.push_cell(kind, &nodes, LAYER_ZONE);
            }
            stats.steiner_points += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::LayerSpec;

    /// Four columns in a row, 10 layers to their full stack; columns 2 and 3 are a fan (one wall
    /// point), column 3 the copy.
    fn row(layers: [u32; 4]) -> (Columns, SlabPlan) {
        let bottoms: Vec<DVec3> = (0..4).map(|i| DVec3::new(i as f64, 0.0, 0.0)).collect();
        let mut columns = Columns::rising(&bottoms, Some(LayerSpec::fixed(0.1, 1.2, 10)));
        columns.layers = layers.to_vec();
        columns.wall_vertex[3] = 2;
        let proposed = bottoms.iter().map(|&b| b + DVec3::Z).collect();
        (columns, SlabPlan::moving_to(proposed))
    }

    /// Spacing of the strip's wall points along it ([`strip_marched_around`]).
    const STRIP_STEP: f64 = 0.25;

    /// Stacks over a strip of wall, two columns wide and eight long (column `2 i + j` at
    /// `(i STRIP_STEP, j)`), marched 10 layers (first height 0.1, growth 1.2: 2.6 thick) with
    /// [`stop_at_caps`] (`caps` by column) and [`grade_around_pits`] before each, the two
    /// columns at `i = 0` stopped first with `first_stop` layers (at isotropy if `isotropic`):
    /// the layer counts of the columns at `j = 0` along the strip.
    fn strip_marched_around(first_stop: u32, isotropic: bool, caps: &[u32]) -> Vec<u32> {
        let bottoms: Vec<DVec3> =
            (0..16).map(|c| DVec3::new((c / 2) as f64 * STRIP_STEP, (c % 2) as f64, 0.0)).collect();
        let mut columns = Columns::rising(&bottoms, Some(LayerSpec::fixed(0.1, 1.2, 10)));
        let mut front = Front::default();
        for i in 0..7u32 {
            let (a, b, c, d) = (2 * i, 2 * i + 2, 2 * i + 1, 2 * i + 3);
            front.push(&[a, b, c], 0, None);
            front.push(&[b, d, c], 0, None);
        }
        front.index_columns(columns.len());
        let mut pit = Vec::new();
        for k in 1..=10 {
            if k == first_stop + 1 {
                for c in [0, 1] {
                    columns.state[c] = if isotropic {
                        ColumnState::EndedIsotropic { ratio: 1.0, size: STRIP_STEP }
                    } else {
                        ColumnState::Stopped { at_gap: false }
                    };
                }
            }
            stop_at_caps(&mut columns, caps, &mut pit, k);
            grade_around_pits(&mut columns, &front, &mut pit, k);
            for c in 0..16 {
                columns.layers[c] += u32::from(columns.is_marching(c));
            }
        }
        (0..8).map(|i| columns.layers[2 * i]).collect()
    }

    #[test]
    fn stacks_around_a_stack_with_no_layer_open_it_into_a_cone() {
        let spec = LayerSpec::fixed(0.1, 1.2, 10);
        let layers = strip_marched_around(0, false, &[]);
        for i in 1..layers.len() {
            // The thickest stack within the slope over its neighbour towards the pit, or full.
            let thickness = |n: u32| spec.distance(n);
            let below = thickness(layers[i - 1]) + TUNING.grading.pit_slope * STRIP_STEP;
            let (l, rising) = (layers[i], thickness(layers[i]) <= below + 1e-12);
            assert!(rising && (l == 10 || thickness(l + 1) > below), "{layers:?}");
        }
        assert!(layers[1] < 10 && layers[7] == 10, "a cone, closed within the strip: {layers:?}");
        // A stack that stopped with layers leaves no pit to the wall, nor one that ended at
        // isotropy (`count = "auto"` over a wall faceted finer than the first layer): its
        // neighbours go on.
        assert_eq!(strip_marched_around(4, false, &[]), [4, 10, 10, 10, 10, 10, 10, 10]);
        assert_eq!(strip_marched_around(0, true, &[]), [0, 10, 10, 10, 10, 10, 10, 10]);
    }

    #[test]
    fn a_capped_stack_stops_at_its_cap_and_a_deep_one_opens_into_a_cone() {
        let never = 11;
        let mut caps = vec![never; 16];
        caps[6] = 9;
        assert_eq!(strip_marched_around(10, false, &caps), [10, 10, 10, 9, 10, 10, 10, 10]);
        // One layer (0.1 thick) under neighbours 0.25 away: they stop before they rise above
        // 0.1 + 3 * 0.25 (5 layers, 0.74), theirs in turn above 0.74 + 0.75 (7 layers).
        caps[6] = 1;
        assert_eq!(strip_marched_around(10, false, &caps), [8, 7, 5, 1, 5, 7, 8, 9]);
    }

    #[test]
    fn a_crushed_edge_in_the_transition_layers_ends_its_columns_with_their_fans() {
        let (columns, mut plan) = row([12, 9, 11, 11]);
        assert_eq!(
            stop_crushed_transition(&mut plan, &columns, &[(1, 2)]),
            0,
            "column 1 is in its full stack"
        );
        assert!(plan.moving.iter().all(|&m| m));
        assert_eq!(stop_crushed_transition(&mut plan, &columns, &[(0, 2)]), 3);
        assert_eq!(plan.moving, [false, true, false, false], "column 3 is column 2's fan mate");
    }
}
