//! Tangential split of front edges (tangential adaptivity): a front edge
//! whose proposed top is longer than
//! [`TUNING.adaptation.split_length`](super::tuning::Adaptation::split_length) in the metric gets a
//! new column at its middle, born at this layer's top. Fan edges (two copies of one wall vertex)
//! start with no length and open like the distance times the fan angle; splitting them keeps fans
//! bounded.
//!
//! The new column has no bottom: in the slab being built, the lateral face over the split edge
//! `(a, b)` is the pentagon `(a, b, tb, m, ta)`. It is cut into a quad and a triangle by a rule
//! on its own node ids (the triangle on the side of the smaller of `a`, `b`), so the two cells
//! sharing it agree; their tops are subdivided with the new node ([`subdivide`]), and the cells
//! are emitted as standard shapes where their faces make one, else split from their centre
//! ([`super::slab::cell_from_faces`]). A split that would make an invalid cell is given up for
//! the layer; a split whose ends do not both move on their own is not made.

use glam::DVec3;
use rayon::prelude::*;

use super::front::{ColumnStart, Columns, Front};
use super::slab::{self, cell_from_faces, Merging, Polygon, SlabCell};
use super::slab_plan::SlabPlan;
use super::tuning::TUNING;
use crate::sizing::SizingField;

/// Whether, and to which sizes, the front's edges are split while it marches.
#[derive(Clone, Copy, Debug)]
pub enum Adapt<'a> {
    /// Never split: the front keeps the wall's columns (fans open without bound).
    Off,
    /// Keep the front's edges near the wall's own tangential size (the mean edge length at each
    /// column's wall vertex).
    Wall,
    /// Keep them near the sizing field's tangential sizes.
    Field(&'a SizingField),
}

/// No split (in the per-edge split lists of a face).
pub const NONE: u32 = u32::MAX;

/// The sizes the front's edges are measured against.
///
/// A front edge lies in the front, which follows the wall's offsets, so it is measured with
/// the tangential size alone (the metric restricted to the front's tangent plane): the normal
/// size, as small as the first layer, would turn the sagitta of a chord on a curved front into
/// a "long" edge and split every edge of a sphere's first layers.
///
/// The layers do not refine or coarsen the wall's own resolution because it is irregular (a
/// long thin wall triangle is the user's mesh, not a front that grew): an edge between two wall
/// columns is split only once it is longer than `sqrt(2)` times both the target and its own
/// length on the wall, and collapsed only once shorter than `1/sqrt(2)` times both the target
/// and [`TUNING.adaptation.compressed`](super::tuning::Adaptation::compressed) times its wall
/// length. Fronts that widen (convex walls, fans, whose edges have no length on the wall) or
/// compress (concave walls) and the user's own sizes (a sizing field's regions and maximum size)
/// change it.
pub struct Sizes<'a> {
    pub adapt: Adapt<'a>,
    field: Option<&'a SizingField>,
    /// The wall's tangential size where each column started (a split column: the mean of its
    /// edge's ends).
    pub wall: Vec<f64>,
}

impl<'a> Sizes<'a> {
    pub fn new(adapt: Adapt<'a>, wall: Vec<f64>) -> Self {
        let field = match adapt {
            Adapt::Field(field) => Some(field),
            Adapt::Off | Adapt::Wall => None,
        };
        Sizes { adapt, field, wall }
    }

    /// The tangential size wanted at `at[c]` for the columns with `wanted[c]` (the others get
    /// their wall size): the target of the front's edges.
    pub fn tangential(&self, at: &[DVec3], wanted: &[bool]) -> Vec<f64> {
        self.per_column(at, wanted, |field, x| field.tangential_size(x), |c| self.wall[c])
    }

    /// The user's size at `at[c]` for the columns with `wanted[c]` (infinite without a sizing
    /// field, and for the others).
    pub fn user(&self, at: &[DVec3], wanted: &[bool]) -> Vec<f64> {
        self.per_column(at, wanted, |field, x| field.user_size(x), |_| f64::INFINITY)
    }

    fn per_column(
        &self,
        at: &[DVec3],
        wanted: &[bool],
        from_field: impl Fn(&SizingField, DVec3) -> f64 + Sync,
        otherwise: impl Fn(usize) -> f64 + Sync,
    ) -> Vec<f64> {
        (0..wanted.len())
            .into_par_iter()
            .map(|c| match self.field {
                Some(field) if wanted[c] => from_field(field, at[c]),
                _ => otherwise(c),
            })
            .collect()
    }

    /// Length of the edge `e` between columns `a` and `b` against the sizes `h` (from
    /// [`Sizes::tangential`]): the mean of its lengths in the sizes at its ends.
    pub fn edge_length(h: &[f64], a: usize, b: usize, e: DVec3) -> f64 {
        e.length() / mean_size(h, a, b)
    }

    /// The length in the sizes of every edge of the raised front (zero-length edges left out),
    /// and of its fan edges alone.
    pub fn front_edge_lengths(
        &self,
        points: &[DVec3],
        columns: &Columns,
        front: &Front,
    ) -> (Vec<f64>, Vec<f64>) {
        let at: Vec<DVec3> = columns.node.iter().map(|&n| points[n as usize]).collect();
        let h = self.tangential(&at, &vec![true; columns.len()]);
        let (mut all, mut fan) = (Vec::new(), Vec::new());
        for f in (0..front.len()).filter(|&f| front.raised[f]) {
            let cols = front.face_columns(f);
            for i in 0..cols.len() {
                let (a, b) = (cols[i] as usize, cols[(i + 1) % cols.len()] as usize);
                let e = at[b] - at[a];
                if a < b && e != DVec3::ZERO {
                    let length = Self::edge_length(&h, a, b, e);
                    all.push(length);
                    if columns.is_fan_edge(a, b) {
                        fan.push(length);
                    }
                }
            }
        }
        (all, fan)
    }
}

/// The size that measures an edge between columns `a` and `b` as the mean of its lengths in
/// the sizes `h` at its ends (their harmonic mean; infinite sizes count as no limit).
fn mean_size(h: &[f64], a: usize, b: usize) -> f64 {
    2.0 / (1.0 / h[a] + 1.0 / h[b])
}

/// The splits proposed for one slab.
#[derive(Clone, Debug, Default)]
pub(super) struct Splits {
    /// The columns `[a, b]` of each split edge, `a < b`.
    edges: Vec<[u32; 2]>,
    /// Where the new column starts from, its direction and scale.
    start: Vec<(DVec3, DVec3, f64)>,
    /// The new column's top in this slab.
    pub top: Vec<DVec3>,
    /// Not given up (a split that would make an invalid cell is given up for the layer).
    enabled: Vec<bool>,
    /// The two faces on each split edge.
    edge_faces: Vec<[u32; 2]>,
    /// The faces with a split edge (sorted) and the split on each of their edges (or [`NONE`]).
    faces: Vec<(u32, [u32; 4])>,
}

impl Splits {
    pub fn len(&self) -> usize {
        self.edges.len()
    }

    /// Whether split `s` is made under `plan`: not given up, and both its columns move on
    /// their own (not stopped, not merged).
    fn is_active(&self, s: usize, plan: &SlabPlan) -> bool {
        self.enabled[s] && self.edges[s].iter().all(|&c| plan.moving[c as usize] && !plan.merges.is_merged(c))
    }

    /// The active split on each edge of face `f` (or [`NONE`]); `None` when there is none.
    pub(super) fn active_on_face(&self, f: usize, plan: &SlabPlan) -> Option<[u32; 4]> {
        let i = self.faces.binary_search_by_key(&(f as u32), |e| e.0).ok()?;
        let mut any = false;
        let active = self.faces[i].1.map(|s| {
            if s != NONE && self.is_active(s as usize, plan) {
                any = true;
                s
            } else {
                NONE
            }
        });
        any.then_some(active)
    }

    /// Give up the active splits on face `f`'s edges; returns the faces whose cells change.
    pub(super) fn give_up(&mut self, f: usize, plan: &SlabPlan) -> Vec<usize> {
        let Some(active) = self.active_on_face(f, plan) else { return Vec::new() };
        let mut changed = Vec::new();
        for s in active.into_iter().filter(|&s| s != NONE) {
            self.enabled[s as usize] = false;
            changed.extend(self.edge_faces[s as usize].map(|g| g as usize));
        }
        changed
    }

    /// Whether each of the front's `face_count` faces has a split proposed on an edge.
    pub(super) fn faces_with_splits(&self, face_count: usize) -> Vec<bool> {
        let mut has = vec![false; face_count];
        for &(f, _) in &self.faces {
            has[f as usize] = true;
        }
        has
    }

    /// The splits made under `plan`.
    pub(super) fn active(&self, plan: &SlabPlan) -> Vec<usize> {
        (0..self.len()).filter(|&s| self.is_active(s, plan)).collect()
    }
}

/// The sizes a front edge is split and collapsed against, per column: the target
/// ([`Sizes::tangential`]), the layer's height and the user's size ([`Sizes::user`]).
pub struct EdgeSizes<'a> {
    pub target: &'a [f64],
    pub height: &'a [f64],
    pub user: &'a [f64],
}

impl EdgeSizes<'_> {
    /// Length of front edge `e` between columns `a` and `b` against the size it is split at:
    /// the target, or where they are longer the edge's length on the wall and the layer's
    /// height (a front finer than its layers are high would only make flat cells), but the
    /// user's size where that is smaller.
    pub fn split_length(&self, columns: &Columns, a: usize, b: usize, e: DVec3) -> f64 {
        let on_wall = columns.wall_edge_length(a, b).unwrap_or(0.0);
        let size = mean_size(self.target, a, b).max(on_wall).max(mean_size(self.height, a, b));
        e.length() / size.min(mean_size(self.user, a, b))
    }

    /// Length of front edge `e` between columns `a` and `b` against the size it is collapsed
    /// at: the target, or [`TUNING.adaptation.compressed`](super::tuning::Adaptation::compressed)
    /// times the edge's length on the wall where that is shorter; but an edge
    /// [`TUNING.adaptation.tallest_cell`](super::tuning::Adaptation::tallest_cell) times shorter
    /// than the layer's height is collapsed anyway (not coarser than the user's size, though): a
    /// front finer than its layers are high (a wall faceted finer than the first layer, as at a
    /// wing tip) makes needles, and coarsens whether it compressed or not.
    pub fn collapse_length(&self, columns: &Columns, a: usize, b: usize, e: DVec3) -> f64 {
        let on_wall =
            columns.wall_edge_length(a, b).map_or(f64::INFINITY, |w| TUNING.adaptation.compressed * w);
        // Collapsed below 1/sqrt 2 of this size: once the layer is `tallest_cell` times its width.
        let by_height =
            mean_size(self.height, a, b) * std::f64::consts::SQRT_2 / TUNING.adaptation.tallest_cell;
        let size = mean_size(self.target, a, b).min(on_wall).max(by_height.min(mean_size(self.user, a, b)));
        e.length() / size
    }
}

/// The front edges whose proposed top (`proposed[c]` for the live columns) is too long, with
/// the new column at the middle of each. Only edges between two faces are split (an edge seen
/// once borders a patch without layers), and only between columns that slide alike.
/// `h` is the tangential size at every column's proposed top ([`Sizes::tangential`]).
pub(super) fn propose(
    columns: &Columns,
    front: &Front,
    proposed: &[DVec3],
    k: u32,
    sizes: &Sizes,
    h: &[f64],
) -> Splits {
    let user = sizes.user(proposed, &columns.marching());
    let height: Vec<f64> = (0..columns.len()).map(|c| columns.layer_height(c, k)).collect();
    let mut long: Vec<([u32; 2], u32, u8)> = (0..front.len())
        .into_par_iter()
        .flat_map_iter(|f| {
            let cols = front.face_columns(f);
            let n = cols.len();
            let (limits, proposed) = (EdgeSizes { target: h, height: &height, user: &user }, proposed);
            (0..n).filter_map(move |i| {
                let (a, b) = (cols[i], cols[(i + 1) % n]);
                let (ua, ub) = (a as usize, b as usize);
                let live = columns.is_marching(ua) && columns.is_marching(ub);
                let long = live
                    && limits.split_length(columns, ua, ub, proposed[ub] - proposed[ua])
                        > TUNING.adaptation.split_length;
                long.then_some(([a.min(b), a.max(b)], f as u32, i as u8))
            })
        })
        .collect();
    long.sort_unstable();
    let mut splits = Splits::default();
    let mut face_edges: Vec<(u32, u8, u32)> = Vec::new();
    for pair in long.chunk_by(|x, y| x.0 == y.0) {
        let &[(edge, f, i), (_, g, j)] = pair else { continue };
        let Some((start, top)) = new_column(columns, proposed, k, edge) else { continue };
        let s = splits.len() as u32;
        splits.edges.push(edge);
        splits.start.push(start);
        splits.top.push(top);
        splits.enabled.push(true);
        splits.edge_faces.push([f, g]);
        face_edges.extend([(f, i, s), (g, j, s)]);
    }
    face_edges.sort_unstable();
    for group in face_edges.chunk_by(|x, y| x.0 == y.0) {
        let mut on_edge = [NONE; 4];
        for &(_, i, s) in group {
            on_edge[i as usize] = s;
        }
        splits.faces.push((group[0].0, on_edge));
    }
    splits
}

/// The column born at the middle of `edge` in layer `k`: from the middle of the arc between its
/// ends' wall points (the wall vertex itself for a fan edge), along their mean direction at the
/// scale [`Columns::scale_along`] gives, its top the middle of theirs pushed along that
/// direction onto the layer's distance (by at least
/// [`TUNING.adaptation.split_lift`](super::tuning::Adaptation::split_lift) of the layer). `None`
/// where the ends slide differently or point opposite ways.
fn new_column(
    columns: &Columns,
    proposed: &[DVec3],
    k: u32,
    edge: [u32; 2],
) -> Option<((DVec3, DVec3, f64), DVec3)> {
    let [a, b] = edge.map(|c| c as usize);
    if columns.slide[a] != columns.slide[b] {
        return None;
    }
    let dir = (columns.dir[a] + columns.dir[b]).try_normalize()?;
    let scale = columns.scale_along(a, b, dir);
    let (p, q) = (columns.base[a], columns.base[b]);
    let base = 0.5 * (p + q) + dir * arc_rise(p, columns.dir[a], q, columns.dir[b]);
    let d = columns.distance(a, k)?;
    let middle = 0.5 * (proposed[a] + proposed[b]);
    // Where the walls' offset is planar the middle already lies on it; a top left on the
    // chord would make the triangles over a collapsed edge flat, so it rises a little.
    let lift = TUNING.adaptation.split_lift * columns.layer_height(a, k);
    let push = (scale * d - (middle - base).dot(dir)).max(lift);
    let top = columns.slide[a].project(middle + dir * push);
    Some(((base, dir, scale), top))
}

/// The cell over a front face whose edge `i` (from corner `i` to `i + 1`) is split with the top
/// node `mids[i]` ([`NONE`] where it is not): the bottom, the subdivided top, and the lateral
/// faces, split ones cut by [`cut_lateral`], the others as [`slab::push_lateral`] makes them
/// (`merging`: the twisted ones cut as in the cell next to them).
pub fn split_cell(bottom: &[u32], top: &[u32], mids: &[u32], merging: Merging) -> SlabCell {
    let n = bottom.len();
    let mut faces = Vec::with_capacity(2 * n + 4);
    let reversed_bottom: Vec<u32> = bottom.iter().rev().copied().collect();
    faces.extend(Polygon::dedup(&reversed_bottom));
    faces.extend(subdivide(top, mids).iter().filter_map(|part| Polygon::dedup(part)));
    for i in 0..n {
        let j = (i + 1) % n;
        if mids[i] == NONE {
            slab::push_lateral(&mut faces, [bottom[i], bottom[j], top[j], top[i]], merging.cut_of(i));
        } else {
            faces.extend(cut_lateral(bottom[i], bottom[j], top[j], mids[i], top[i]));
        }
    }
    slab::remove_opposite_pairs(&mut faces);
    cell_from_faces(faces)
}

/// The lateral face `(a, b, tb, m, ta)` over a split edge: as it is once repeated nodes are
/// removed, and a pentagon cut into a quad and a triangle, the triangle on the side of the
/// smaller of `a` and `b` (a rule both cells sharing the face evaluate alike).
fn cut_lateral(a: u32, b: u32, tb: u32, m: u32, ta: u32) -> Vec<Polygon> {
    let mut ring: Vec<u32> = Vec::with_capacity(5);
    for n in [a, b, tb, m, ta] {
        if ring.last() != Some(&n) {
            ring.push(n);
        }
    }
    while ring.len() > 1 && ring.first() == ring.last() {
        ring.pop();
    }
    if ring.len() < 5 {
        return Polygon::dedup(&ring).into_iter().collect();
    }
    let parts: [&[u32]; 2] =
        if a < b { [&[a, b, tb, m], &[a, m, ta]] } else { [&[b, tb, m], &[a, b, m, ta]] };
    parts.iter().filter_map(|p| Polygon::dedup(p)).collect()
}

/// The faces a polygon with corners `corners` becomes when its edge `i` gets the node `mids[i]`
/// ([`NONE`]: not split), in the polygon's orientation: a triangle with three split edges its
/// four corner and centre triangles, a quad split on two opposite edges two quads, anything
/// else triangles fanned from the first new node. Used alike on node ids (the cell's top) and
/// column ids (the new front), so the two agree.
pub fn subdivide(corners: &[u32], mids: &[u32]) -> Vec<Vec<u32>> {
    let n = corners.len();
    let c = |i: usize| corners[i % n];
    let m = |i: usize| mids[i % n];
    let split: Vec<usize> = (0..n).filter(|&i| mids[i] != NONE).collect();
    match (n, split.as_slice()) {
        (_, []) => vec![corners.to_vec()],
        (3, [_, _, _]) => {
            vec![
                vec![c(0), m(0), m(2)],
                vec![m(0), c(1), m(1)],
                vec![m(1), c(2), m(2)],
                vec![m(0), m(1), m(2)],
            ]
        }
        (4, &[i, j]) if j == i + 2 => {
            vec![vec![c(i), m(i), m(j), c(j + 1)], vec![m(i), c(i + 1), c(j), m(j)]]
        }
        (_, &[first, ..]) => {
            let mut ring = Vec::with_capacity(2 * n);
            for i in first + 1..first + 1 + n {
                ring.push(c(i));
                if m(i) != NONE {
                    ring.push(m(i));
                }
            }
            // `ring` ends with the first split's node: fan from it.
            let apex = ring[ring.len() - 1];
            (0..ring.len() - 2).map(|t| vec![apex, ring[t], ring[t + 1]]).collect()
        }
    }
}

/// How far the middle of the circular arc through `p` and `q` with normals `n_p` and `n_q` lies
/// from the chord's middle, along their mean normal: `|q - p| / 2 tan(angle / 4)`, positive where
/// the normals open along the chord (convex). A node born at the chord's middle sits in a dent
/// of the front, and the core's mesher fills a dent with a flat tetrahedron on front nodes.
fn arc_rise(p: DVec3, n_p: DVec3, q: DVec3, n_q: DVec3) -> f64 {
    let angle = n_p.angle_between(n_q);
    if !angle.is_finite() || angle == 0.0 {
        return 0.0;
    }
    let rise = 0.5 * p.distance(q) * (0.25 * angle).tan();
    if (n_q - n_p).dot(q - p) >= 0.0 {
        rise
    } else {
        -rise
    }
}

/// Add the columns of the splits made under `plan` (`mid_node[s]` is split `s`'s top node) and
/// subdivide the front faces on their edges; the front's adjacency must be rebuilt after.
/// Returns how many columns were added.
pub(super) fn commit(
    splits: &Splits,
    plan: &SlabPlan,
    mid_node: &[u32],
    k: u32,
    columns: &mut Columns,
    front: &mut Front,
    sizes: &mut Sizes,
) -> usize {
    let mut new_column = vec![NONE; splits.len()];
    let active = splits.active(plan);
    for &s in &active {
        let [a, b] = splits.edges[s].map(|c| c as usize);
        let (base, dir, scale) = splits.start[s];
        let step = columns.layer_height(a, k);
        new_column[s] = columns.push(ColumnStart {
            base,
            dir,
            scale,
            node: mid_node[s],
            layers: k,
            wall_vertex: columns.wall_vertex[a],
            slide: columns.slide[a],
            spec: columns.spec[a],
            last_step: scale * step,
        });
        sizes.wall.push(0.5 * (sizes.wall[a] + sizes.wall[b]));
    }
    for &(f, on_edge) in &splits.faces {
        let mids = on_edge.map(|s| if s == NONE { NONE } else { new_column[s as usize] });
        let f = f as usize;
        let n = front.face_columns(f).len();
        if mids[..n].iter().any(|&m| m != NONE) {
            let parts = subdivide(&front.face_columns(f).to_vec(), &mids[..n]);
            front.subdivide_face(f, &parts);
        }
    }
    active.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A front edge as long as on the wall (0.3, not compressed) is kept under a thin layer,
    /// collapsed under one 1.67 high (the ONERA M6's wing tip), but kept where the user asks
    /// for 0.3 there; it is never split under the tall layer either.
    #[test]
    fn an_edge_much_shorter_than_its_layer_is_high_is_collapsed_within_the_users_size() {
        let columns =
            Columns { base: vec![DVec3::ZERO, 0.3 * DVec3::X], born_at: vec![0, 0], ..Default::default() };
        let (e, target, unbounded) = (0.3 * DVec3::X, [0.3; 2], [f64::INFINITY; 2]);
        let collapse = TUNING.adaptation.collapse_length;
        let (thin, tall, user) = ([0.1; 2], [1.67; 2], [0.3; 2]);
        let thin_layer = EdgeSizes { target: &target, height: &thin, user: &unbounded };
        let tall_layer = EdgeSizes { target: &target, height: &tall, user: &unbounded };
        let users_size = EdgeSizes { target: &target, height: &tall, user: &user };
        assert!(thin_layer.collapse_length(&columns, 0, 1, e) > collapse);
        assert!(tall_layer.collapse_length(&columns, 0, 1, e) < collapse);
        assert!(users_size.collapse_length(&columns, 0, 1, e) > collapse);
        assert!(tall_layer.split_length(&columns, 0, 1, e) < TUNING.adaptation.split_length);
    }

    /// On a circle of radius 2 the middle of the arc between two points rises above their
    /// chord's middle by R (1 - cos(phi)); on the inside of the circle (normals converging) it
    /// sinks by as much; between parallel normals it does not move.
    #[test]
    fn the_arc_middle_rises_on_convex_walls_and_sinks_on_concave_ones() {
        let (r, phi) = (2.0f64, 0.3f64);
        let p = DVec3::new(-r * phi.sin(), r * phi.cos(), 0.0);
        let q = DVec3::new(r * phi.sin(), r * phi.cos(), 0.0);
        let (n_p, n_q) = (p / r, q / r);
        let rise = r * (1.0 - phi.cos());
        assert!((arc_rise(p, n_p, q, n_q) - rise).abs() < 1e-12);
        assert!((arc_rise(p, -n_p, q, -n_q) + rise).abs() < 1e-12);
        assert_eq!(arc_rise(p, DVec3::Y, q, DVec3::Y), 0.0);
    }
    use crate::mesh::CellKind;

    #[test]
    fn subdivision_patterns() {
        let n = NONE;
        assert_eq!(subdivide(&[0, 1, 2], &[n, n, n]), vec![vec![0, 1, 2]]);
        assert_eq!(subdivide(&[0, 1, 2], &[10, n, n]), vec![vec![10, 1, 2], vec![10, 2, 0]]);
        assert_eq!(subdivide(&[0, 1, 2], &[10, 11, 12]).len(), 4);
        assert_eq!(subdivide(&[0, 1, 2, 3], &[n, 11, n, 13]), vec![vec![1, 11, 13, 0], vec![11, 2, 3, 13]]);
        assert_eq!(subdivide(&[0, 1, 2, 3], &[10, n, n, n]).len(), 3);
    }

    /// Every directed edge of the subdivision appears once, and the polygon's boundary edges
    /// (with their new nodes) are covered exactly: the parts tile it with one orientation.
    #[test]
    fn subdivisions_tile_the_polygon() {
        let n = NONE;
        for (corners, mids) in [
            (vec![0, 1, 2], vec![10, n, 12]),
            (vec![0, 1, 2], vec![10, 11, 12]),
            (vec![0, 1, 2, 3], vec![10, n, 12, n]),
            (vec![0, 1, 2, 3], vec![10, 11, n, 13]),
        ] {
            let parts = subdivide(&corners, &mids);
            let mut directed: Vec<(u32, u32)> =
                parts.iter().flat_map(|p| (0..p.len()).map(move |i| (p[i], p[(i + 1) % p.len()]))).collect();
            directed.sort_unstable();
            let before = directed.len();
            directed.dedup();
            assert_eq!(before, directed.len(), "{parts:?}");
            let mut boundary = Vec::new();
            for i in 0..corners.len() {
                let j = (i + 1) % corners.len();
                match mids[i] {
                    m if m == n => boundary.push((corners[i], corners[j])),
                    m => boundary.extend([(corners[i], m), (m, corners[j])]),
                }
            }
            let unpaired: Vec<_> = directed
                .iter()
                .filter(|&&(a, b)| directed.binary_search(&(b, a)).is_err())
                .copied()
                .collect();
            let mut boundary_sorted = boundary.clone();
            boundary_sorted.sort_unstable();
            assert_eq!(unpaired, boundary_sorted, "{corners:?} {mids:?}");
        }
    }

    #[test]
    fn the_two_cells_on_a_split_edge_cut_it_alike() {
        // Edge (a, b) = (5, 3) seen from both sides: the same two faces.
        let mut one = cut_lateral(5, 3, 13, 20, 15);
        let mut other = cut_lateral(3, 5, 15, 20, 13);
        let key = |p: &Polygon| {
            let mut n = p.nodes().to_vec();
            n.sort_unstable();
            n
        };
        one.sort_by_key(key);
        other.sort_by_key(key);
        assert_eq!(one.len(), 2);
        for (x, y) in one.iter().zip(&other) {
            let reversed: Vec<u32> = y.nodes().iter().rev().copied().collect();
            assert_eq!(key(x), key(y));
            let rotations = (0..x.nodes().len())
                .any(|r| x.nodes().iter().cycle().skip(r).take(x.nodes().len()).eq(reversed.iter()));
            assert!(rotations, "opposite orientations: {x:?} {y:?}");
        }
        assert!(one.iter().any(|p| !p.is_quad() && p.nodes().contains(&3)), "triangle on the smaller side");
    }

    #[test]
    fn a_fan_corner_tetrahedron_with_a_split_edge_is_a_pyramid() {
        // Three fan copies of wall node 0 rise to 1, 2, 3; the edge (1, 2) is split by node 4.
        match split_cell(&[0, 0, 0], &[1, 2, 3], &[4, NONE, NONE], Merging::default()) {
            SlabCell::Standard { kind, nodes } => {
                assert_eq!(kind, CellKind::Pyramid);
                assert_eq!(nodes[4], 3, "the unsplit corner is the apex");
            }
            other => panic!("{other:?}"),
        }
    }
}
