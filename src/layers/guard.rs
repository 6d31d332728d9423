//! The new front must not cross itself: each cell of a slab can be valid while two parts of the
//! front pass through each other (fronts meeting at a concave ridge, across a thin gap, or a fan
//! sweeping over its neighbours). The proposed front is tested with the same exact triangle
//! tests as the input surface; triangles sharing a vertex are left to the cells' validity test,
//! which sees any fold between neighbours.
//!
//! Finding the pairs of faces to test is what costs (a broad phase over the whole front), so
//! [`CrossingGuard`] finds them once for several layers: from each face's box swept over the
//! motion of those layers (columns move on straight lines, so the box of a face's start and end
//! positions holds every position in between). While the front keeps its faces and columns
//! their directions, each layer only tests the cached pairs, exactly.

use glam::DVec3;
use rayon::prelude::*;

use super::front::{Columns, Front};
use super::reshape::Reshape;
use super::slab::Polygon;
use super::slab_plan::SlabPlan;
use super::split::{self, NONE};
use super::tuning::TUNING;
use crate::geometry::grid::overlapping_pairs_where;
use crate::geometry::intersect::triangles_meet;
use crate::geometry::Aabb;
use crate::mesh::{CellKind, VolumeMesh};
use crate::quality::measures::quad_centre;
use crate::quality::validity::cell_validity;

/// Candidate pairs of front faces that may cross up to a given layer.
#[derive(Debug, Default)]
pub(super) struct CrossingGuard {
    /// Face pairs `(f, g)`, `f < g`, whose swept boxes overlap.
    pairs: Vec<(u32, u32)>,
    /// The triangles `(f, g)` sharing one column whose columns point apart by more than
    /// [`TUNING.guard.turned`](super::tuning::Guard::turned) seen from `f`, by `f`
    /// ([`turned_pairs`]): they hold while the pairs do (the front's faces and the columns'
    /// directions change only where the pairs are rebuilt).
    turned: Vec<(u32, u32)>,
    /// The last layer the pairs hold for; `None` before the first build and after the front
    /// changed (collapses, redirected columns).
    valid_through: Option<u32>,
    /// The plan's collapse count when the pairs were built: a new merge moves a face's top to
    /// another column's position, outside its swept box.
    collapses_at_build: usize,
    pub rebuilds: usize,
}

/// Where every column is at the end of the guard's horizon, and the horizon's last layer.
pub(super) struct Reach {
    pub end: Vec<DVec3>,
    pub through_layer: u32,
}

impl CrossingGuard {
    /// Whether the pairs must be rebuilt before testing layer `k` under `plan`.
    pub fn is_stale(&self, k: u32, plan: &SlabPlan) -> bool {
        self.valid_through.is_none_or(|last| k > last) || plan.collapses != self.collapses_at_build
    }

    /// The front changed under the pairs (faces merged, columns turned): rebuild next time.
    pub fn invalidate(&mut self) {
        self.valid_through = None;
    }

    /// Find the face pairs whose boxes, swept from the committed front to `reach` (and holding
    /// the tops of this slab's splits), overlap.
    pub fn rebuild(
        &mut self,
        plan: &SlabPlan,
        reshape: &Reshape,
        mesh: &VolumeMesh,
        columns: &Columns,
        front: &Front,
        reach: Reach,
    ) {
        let splits = &reshape.splits;
        let bottom = |c: u32| mesh.points[columns.node[c as usize] as usize];
        let swept: Vec<(Aabb, bool)> = (0..front.len())
            .into_par_iter()
            .map(|f| {
                let cols = front.face_columns(f);
                let mut b = Aabb::empty();
                let mut moves = false;
                for &c in cols {
                    let (start, end) = (bottom(c), reach.end[c as usize]);
                    moves |= start != end;
                    b.grow(start);
                    b.grow(end);
                }
                for s in splits.active_on_face(f, plan).into_iter().flatten().filter(|&s| s != NONE) {
                    b.grow(splits.top[s as usize]);
                }
                // A swapped pair's two new triangles span both faces.
                for tri in reshape.swaps.swapped_face(f, plan).into_iter().flatten() {
                    for c in tri {
                        b.grow(bottom(c));
                        b.grow(reach.end[c as usize]);
                    }
                }
                if cols.len() == 4 {
                    // The pyramid cap's apex lies within half an edge of the quad's centre.
                    let pad = DVec3::splat(0.5 * b.diagonal());
                    b = Aabb { min: b.min - pad, max: b.max + pad };
                }
                (b, moves)
            })
            .collect();
        let (boxes, moving): (Vec<Aabb>, Vec<bool>) = swept.into_iter().unzip();
        // Two triangles sharing a column share a top vertex: the cells' validity judges them
        // (but next to a change of the front's topology, see `pairs_at_changes`).
        let keep = |f: u32, g: u32| {
            let (a, b) = (front.face_columns(f as usize), front.face_columns(g as usize));
            a.len() == 4 || b.len() == 4 || !a.iter().any(|c| b.contains(c))
        };
        self.pairs = overlapping_pairs_where(&boxes, &moving, keep);
        self.turned = turned_pairs(front, columns);
        self.valid_through = Some(reach.through_layer);
        self.collapses_at_build = plan.collapses;
        self.rebuilds += 1;
    }

    /// The pairs of faces of the proposed front that cross each other, its quads taken with the
    /// pyramid the core fill will cap them with; and the quads that no pyramid can cap.
    /// Only pairs with a face among `suspects` (the faces whose top moved since the last test)
    /// are tested.
    pub fn crossings(
        &self,
        plan: &SlabPlan,
        reshape: &Reshape,
        mesh: &VolumeMesh,
        columns: &Columns,
        front: &Front,
        suspects: &[usize],
    ) -> Crossings {
        let mut suspect = vec![false; front.len()];
        for &f in suspects {
            suspect[f] = true;
        }
        let top = TopFront { plan, reshape, mesh, columns, front };
        // Most cached pairs are apart now: their current boxes sort them out cheaply.
        let boxes: Vec<Aabb> = (0..front.len()).into_par_iter().map(|f| top.cap_box(f)).collect();
        let tested: Vec<(u32, u32)> = self
            .pairs
            .par_iter()
            .copied()
            .chain(pairs_at_changes(plan, reshape, front, &self.turned, suspects).into_par_iter())
            .filter(|&(f, g)| {
                (suspect[f as usize] || suspect[g as usize]) && boxes[f as usize].overlaps(&boxes[g as usize])
            })
            .collect();
        let mut shape_of = vec![u32::MAX; front.len()];
        let mut needed = Vec::new();
        for f in tested.iter().flat_map(|&(f, g)| [f, g]) {
            if shape_of[f as usize] == u32::MAX {
                shape_of[f as usize] = needed.len() as u32;
                needed.push(f as usize);
            }
        }
        let shapes: Vec<TopShape> = needed.par_iter().map(|&f| top.shape(f)).collect();
        let shape = |f: u32| &shapes[shape_of[f as usize] as usize];
        if tracing::enabled!(tracing::Level::TRACE) {
            let crossing = tested.iter().copied().filter(|&(f, g)| shape(f).crosses(shape(g)));
            trace_crossing_pairs(front, columns, crossing);
        }
        let mut pairs: Vec<(usize, usize)> = tested
            .par_iter()
            .filter(|&&(f, g)| shape(f).crosses(shape(g)))
            .map(|&(f, g)| (f as usize, g as usize))
            .collect();
        pairs.sort_unstable();
        pairs.dedup();
        let cappable = |f: usize| front.face_columns(f).len() != 4 || !top.shape(f).uncappable;
        let uncappable = suspects.par_iter().copied().filter(|&f| !cappable(f)).collect();
        Crossings { pairs, uncappable }
    }

    /// Whether the proposed tops of faces `f` and `g` cross (as in [`CrossingGuard::crossings`]).
    #[allow(clippy::too_many_arguments)]
    pub fn pair_crosses(
        plan: &SlabPlan,
        reshape: &Reshape,
        mesh: &VolumeMesh,
        columns: &Columns,
        front: &Front,
        f: usize,
        g: usize,
    ) -> bool {
        let top = TopFront { plan, reshape, mesh, columns, front };
        top.shape(f).crosses(&top.shape(g))
    }
}

/// What the crossing guard found: pairs of faces whose tops cross, and quads no pyramid caps.
#[derive(Debug, Default)]
pub(super) struct Crossings {
    pub pairs: Vec<(usize, usize)>,
    pub uncappable: Vec<usize>,
}

/// Log every crossing pair with how near the two faces are on the front (columns shared; a
/// column of one next to or from the same wall vertex as one of the other): far apart, they are
/// fronts meeting across a gap or a fold, not a local collapse; and where they start and how
/// their columns meet.
fn trace_crossing_pairs(front: &Front, columns: &Columns, pairs: impl Iterator<Item = (u32, u32)>) {
    for (f, g) in pairs {
        let (a, b) = (front.face_columns(f as usize), front.face_columns(g as usize));
        let shared = a.iter().filter(|c| b.contains(c)).count();
        let wall = |c: u32| columns.wall_vertex[c as usize];
        let near = a.iter().any(|&x| b.iter().any(|&y| front.are_neighbours(x, y) || wall(x) == wall(y)));
        // Where the two faces start on the wall, how far apart, and how their columns meet
        // (`converge`: the cosine between their mean directions; `ahead`: of f's direction
        // with the way from f's wall points to g's, positive when g lies ahead of f).
        let base = |cs: &[u32]| cs.iter().map(|&c| columns.base[c as usize]).sum::<DVec3>() / cs.len() as f64;
        let dir = |cs: &[u32]| cs.iter().map(|&c| columns.dir[c as usize]).sum::<DVec3>().normalize_or_zero();
        let (fb, gb) = (base(a), base(b));
        let (converge, ahead) = (dir(a).dot(dir(b)), (gb - fb).normalize_or_zero().dot(dir(a)));
        let layers = a.iter().map(|&c| columns.layers[c as usize]).max().unwrap_or(0);
        tracing::trace!(
            f, g, shared, near, at = ?fb.to_array(), apart = fb.distance(gb), converge, ahead, layers,
            "crossing pair"
        );
    }
}

/// The pairs of triangles sharing a column but no edge where one of them changes shape this
/// slab (a column of it stops while another moves, merges, or has a split on its edge), among
/// the `suspects`, or whose columns point apart by more than
/// [`TUNING.guard.turned`](super::tuning::Guard::turned) (`turned`, from [`turned_pairs`]). A front
/// moving as a whole cannot fold over a shared vertex without turning a cell between them inside
/// out unless it turns sharply there (a hole a few edges round, whose fronts meet on its axis:
/// flange); where columns stop at different layers or merge, thin triangles can, with every cell
/// valid, so these pairs are tested beyond their shared vertex.
fn pairs_at_changes(
    plan: &SlabPlan,
    reshape: &Reshape,
    front: &Front,
    turned: &[(u32, u32)],
    suspects: &[usize],
) -> Vec<(u32, u32)> {
    let changes = |f: usize| {
        let cols = front.face_columns(f);
        let moving = |c: u32| plan.moving[plan.merges.root(c) as usize];
        let mixed = cols.iter().any(|&c| moving(c)) && cols.iter().any(|&c| !moving(c));
        let merged = cols.iter().any(|&c| plan.merges.is_merged(c) || plan.merges.group(c).nth(1).is_some());
        mixed
            || merged
            || reshape.splits.active_on_face(f, plan).is_some()
            || reshape.swaps.role(f, plan).is_some()
    };
    let turned_from = |f: usize| {
        let f = f as u32;
        let first = turned.partition_point(|&(t, _)| t < f);
        turned[first..].iter().take_while(move |&&(t, _)| t == f).map(|&(_, g)| g as usize)
    };
    let mut pairs: Vec<(u32, u32)> = suspects
        .par_iter()
        .copied()
        .filter(|&f| front.face_columns(f).len() == 3)
        .flat_map_iter(|f| {
            let changed = changes(f);
            let all = changed.then(|| vertex_neighbours(front, f)).into_iter().flatten();
            let turned = (!changed).then(|| turned_from(f)).into_iter().flatten();
            all.chain(turned).map(move |g| (f.min(g) as u32, f.max(g) as u32))
        })
        .collect();
    pairs.par_sort_unstable();
    pairs.dedup();
    pairs
}

/// The triangles `(f, g)` sharing one column (no edge) whose columns' summed directions make a
/// cosine below [`TUNING.guard.turned`](super::tuning::Guard::turned), seen from `f`, in the order
/// of `f`.
fn turned_pairs(front: &Front, columns: &Columns) -> Vec<(u32, u32)> {
    let direction = |f: usize| front.face_columns(f).iter().map(|&c| columns.dir[c as usize]).sum::<DVec3>();
    let turned = |f: usize, g: usize| {
        let (a, b) = (direction(f), direction(g));
        a.dot(b) < TUNING.guard.turned * a.length() * b.length()
    };
    (0..front.len())
        .into_par_iter()
        .filter(|&f| front.face_columns(f).len() == 3)
        .flat_map_iter(|f| {
            vertex_neighbours(front, f).filter(move |&g| turned(f, g)).map(move |g| (f as u32, g as u32))
        })
        .collect()
}

/// The triangles sharing exactly one column with triangle `f`.
fn vertex_neighbours(front: &Front, f: usize) -> impl Iterator<Item = usize> + '_ {
    let cols = front.face_columns(f);
    cols.iter().flat_map(move |&c| front.faces_of(c)).filter(move |&g| {
        let other = front.face_columns(g);
        g != f && other.len() == 3 && other.iter().filter(|c| cols.contains(c)).count() == 1
    })
}

/// The proposed top of the front faces under a slab plan.
struct TopFront<'a> {
    plan: &'a SlabPlan,
    reshape: &'a Reshape,
    mesh: &'a VolumeMesh,
    columns: &'a Columns,
    front: &'a Front,
}

/// A face's proposed top as triangles: the top triangle, or a quad's four pyramid-cap triangles.
/// Vertex ids are the proposal's node ids (an apex gets an id of its own), so that triangles
/// sharing a vertex are recognised.
#[derive(Default)]
struct TopShape {
    ids: Vec<[u32; 3]>,
    points: Vec<[DVec3; 3]>,
    boxes: Vec<Aabb>,
    uncappable: bool,
}

impl TopFront<'_> {
    fn node_and_position(&self, c: u32) -> (u32, DVec3) {
        let committed = self.mesh.points.len() as u32;
        let r = self.plan.merges.root(c);
        if self.plan.moving[r as usize] {
            (committed + r, self.plan.proposed[r as usize])
        } else {
            let node = self.columns.node[c as usize];
            (node, self.mesh.points[node as usize])
        }
    }

    /// Face `f`'s proposed top: its corners and, on its split edges, the splits' tops (node ids
    /// as in [`super::march`]: split `s` proposes node `committed + columns.len() + s`), and
    /// the split on each edge (or [`NONE`]) if it has any.
    fn top(&self, f: usize) -> (Vec<(u32, DVec3)>, Option<[u32; 4]>) {
        let mut top: Vec<(u32, DVec3)> =
            self.front.face_columns(f).iter().map(|&c| self.node_and_position(c)).collect();
        if let Some(swapped) = self.reshape.swaps.swapped_face(f, self.plan) {
            // The pair's fourth column, across the swapped edge.
            let cols = self.front.face_columns(f);
            top.extend(
                swapped.iter().flatten().find(|c| !cols.contains(c)).map(|&c| self.node_and_position(c)),
            );
            return (top, None);
        }
        let splits = &self.reshape.splits;
        let on_edge = splits.active_on_face(f, self.plan);
        let first = self.mesh.points.len() as u32 + self.columns.len() as u32;
        let mids = on_edge.map(|e| e.map(|s| if s == NONE { NONE } else { first + s }));
        for (s, id) in on_edge.into_iter().flatten().zip(mids.into_iter().flatten()) {
            if s != NONE {
                top.push((id, splits.top[s as usize]));
            }
        }
        (top, mids)
    }

    /// A box around face `f`'s proposed top and the cap it may get.
    fn cap_box(&self, f: usize) -> Aabb {
        let mut b = Aabb::empty();
        for (_, p) in self.top(f).0 {
            b.grow(p);
        }
        if self.front.face_columns(f).len() < 4 {
            return b;
        }
        let pad = DVec3::splat(0.5 * b.diagonal());
        Aabb { min: b.min - pad, max: b.max + pad }
    }

    /// The top's triangles: each part of a split top ([`split::subdivide`]) as a triangle, or
    /// as the four triangles of its pyramid cap for a quad.
    fn shape(&self, f: usize) -> TopShape {
        let mut shape = TopShape::default();
        let (top, mids) = self.top(f);
        let n = self.front.face_columns(f).len();
        let ids: Vec<u32> = top[..n].iter().map(|t| t.0).collect();
        let at = |id: u32| top.iter().find(|t| t.0 == id).map_or(DVec3::ZERO, |t| t.1);
        let node = |c: u32| self.node_and_position(c).0;
        let parts = match (mids, self.reshape.swaps.swapped_face(f, self.plan)) {
            // Both faces of a swapped pair carry its two new triangles.
            (_, Some(swapped)) => swapped.iter().map(|tri| tri.map(node).to_vec()).collect(),
            (Some(mids), None) => split::subdivide(&ids, &mids[..n]),
            (None, None) => vec![ids],
        };
        for (i, part) in parts.iter().enumerate() {
            let Some(polygon) = Polygon::dedup(part) else { continue };
            let n = polygon.nodes();
            if n.len() == 3 {
                shape.push([n[0], n[1], n[2]], [n[0], n[1], n[2]].map(at));
                continue;
            }
            let x = [0, 1, 2, 3].map(|i| at(n[i]));
            let Some(apex) = pyramid_apex(x) else {
                shape.uncappable = true;
                continue;
            };
            // An id of its own for each cap's apex, far above the node ids.
            let apex_id = u32::MAX - (4 * f + i) as u32;
            for k in 0..4 {
                let (a, b) = (k, (k + 1) % 4);
                shape.push([n[a], n[b], apex_id], [x[a], x[b], apex]);
            }
        }
        shape
    }
}

impl TopShape {
    fn push(&mut self, ids: [u32; 3], points: [DVec3; 3]) {
        self.ids.push(ids);
        self.boxes.push(Aabb::from_points(&points));
        self.points.push(points);
    }

    /// Whether a triangle of `self` and one of `other` meet where they should not (exact):
    /// anywhere, for triangles that share no vertex; beyond the shared vertex, or folded over the
    /// shared edge (faces that merged tops brought together, or a quad's cap against a
    /// neighbour: no slab cell lies between them to judge such a fold).
    fn crosses(&self, other: &TopShape) -> bool {
        (0..self.ids.len()).any(|i| {
            (0..other.ids.len()).any(|j| {
                self.boxes[i].overlaps(&other.boxes[j])
                    && triangles_meet(self.ids[i], self.points[i], other.ids[j], other.points[j])
            })
        })
    }
}

/// The centre of the quad `x` and its unit normal (across its diagonals, right-handed): where
/// [`pyramid_apex`] stands a pyramid's apex over it.
pub fn quad_frame(x: [DVec3; 4]) -> (DVec3, DVec3) {
    let centre = quad_centre(x[0], x[1], x[2], x[3]);
    (centre, (x[2] - x[0]).cross(x[3] - x[1]).normalize_or_zero())
}

/// The apex of a valid pyramid on the quad `x` (its right-hand normal pointing to the apex):
/// above the quad's centre at half its shortest edge (fan-strip quads are long and narrow: a
/// taller apex would poke through the front nearby), or lower where that is invalid.
pub fn pyramid_apex(x: [DVec3; 4]) -> Option<DVec3> {
    let (centre, normal) = quad_frame(x);
    let min_edge = (0..4).map(|i| x[i].distance(x[(i + 1) % 4])).fold(f64::INFINITY, f64::min);
    (0..TUNING.pyramids.apex_tries).map(|k| centre + normal * (0.5 * min_edge * 0.5f64.powi(k))).find(
        |&apex| {
            let mut p = [DVec3::ZERO; 8];
            p[..4].copy_from_slice(&x);
            p[4] = apex;
            cell_validity(CellKind::Pyramid, &p).is_valid()
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles marching towards each other: a floor rising from z = 0 and a tilted triangle
    /// sinking from z = 0.6, 0.1 per layer each. Their tops first touch at layer 3 (floor at
    /// 0.3, the other's lowest edge at 0.3). The pairs found at layer 1 for four layers must
    /// still catch it.
    #[test]
    fn cached_pairs_catch_a_crossing_layers_later() {
        let floor = [DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0)];
        let tilted = [DVec3::new(0.1, 0.1, 0.6), DVec3::new(0.4, 0.1, 0.6), DVec3::new(0.2, 0.2, 1.5)];
        let mut mesh = VolumeMesh { points: [floor, tilted].concat(), ..Default::default() };
        let mut columns = Columns::default();
        for (i, &p) in mesh.points.iter().enumerate() {
            columns.base.push(p);
            columns.dir.push(if i < 3 { DVec3::Z } else { -DVec3::Z });
            columns.scale.push(1.0);
            columns.node.push(i as u32);
            columns.state.push(crate::layers::front::ColumnState::Marching);
            columns.layers.push(0);
            columns.wall_vertex.push(i as u32);
        }
        let mut front = Front::default();
        front.push(&[0, 1, 2], 0, None);
        front.push(&[3, 5, 4], 0, None);
        front.index_columns(6);
        let mut guard = CrossingGuard::default();
        let mut crossings = Vec::new();
        for k in 1..=3u32 {
            let proposed: Vec<DVec3> =
                (0..6).map(|c| mesh.points[columns.node[c] as usize] + columns.dir[c] * 0.1).collect();
            let plan = SlabPlan::moving_to(proposed.clone());
            if guard.is_stale(k, &plan) {
                let end: Vec<DVec3> = (0..6)
                    .map(|c| {
                        mesh.points[columns.node[c] as usize]
                            + columns.dir[c] * (0.1 * TUNING.guard.lookahead_layers as f64)
                    })
                    .collect();
                guard.rebuild(
                    &plan,
                    &Reshape::default(),
                    &mesh,
                    &columns,
                    &front,
                    Reach { end, through_layer: k + TUNING.guard.lookahead_layers - 1 },
                );
            }
            let found = guard.crossings(&plan, &Reshape::default(), &mesh, &columns, &front, &[0, 1]);
            crossings.push(found.pairs);
            for (c, p) in proposed.into_iter().enumerate() {
                columns.node[c] = mesh.points.len() as u32;
                mesh.points.push(p);
            }
        }
        assert_eq!(guard.rebuilds, 1);
        assert_eq!(crossings, vec![vec![], vec![], vec![(0, 1)]]);
    }
}
