//! A bounding-volume hierarchy over triangles for exact nearest-point queries (branch and bound:
//! a subtree is skipped only when its box is certainly no better than the best found so far).

use super::distance::closest_point_on_triangle;
use super::{Aabb, DVec3};

/// Triangles per leaf at most.
const LEAF_SIZE: usize = 4;

#[derive(Clone, Debug)]
struct Node {
    bounds: Aabb,
    /// A box holding the node's triangles in a frame of its own: the mean normal and two
    /// directions across it, with the lowest and highest coordinates of their corners along
    /// each. On a patch of wall it is as thin as the patch is curved and as wide as the patch,
    /// where the axis-aligned box is as thick as the patch is wide and tilted, so it bounds the
    /// distance from points above the wall (layer fronts) far more tightly.
    frame: [DVec3; 3],
    extent: [[f64; 2]; 3],
    /// Leaf: `triangles[first..first + count]`; inner node: children `first` and `first + 1`.
    first: u32,
    count: u32,
}

/// A BVH over a fixed set of triangles (given as corner points, indexed by the caller's ids).
#[derive(Clone, Debug)]
pub struct TriangleBvh {
    corners: Vec<[DVec3; 3]>,
    nodes: Vec<Node>,
    /// Triangle ids in leaf order.
    order: Vec<u32>,
}

/// The point of the triangle set closest to a query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    pub triangle: u32,
    pub point: DVec3,
    pub distance: f64,
}

impl TriangleBvh {
    pub fn new(corners: Vec<[DVec3; 3]>) -> Self {
        let mut bvh = TriangleBvh { nodes: Vec::new(), order: (0..corners.len() as u32).collect(), corners };
        if !bvh.corners.is_empty() {
            let centroids: Vec<DVec3> = bvh.corners.iter().map(|c| (c[0] + c[1] + c[2]) / 3.0).collect();
            bvh.nodes.push(bvh.leaf(0, bvh.corners.len()));
            bvh.split(0, &centroids);
        }
        bvh
    }

    pub fn len(&self) -> usize {
        self.corners.len()
    }

    pub fn is_empty(&self) -> bool {
        self.corners.is_empty()
    }

    /// The corner points of triangle `t`.
    pub fn corners(&self, t: u32) -> [DVec3; 3] {
        self.corners[t as usize]
    }

    fn leaf(&self, first: usize, count: usize) -> Node {
        let triangles = || self.order[first..first + count].iter().map(|&t| &self.corners[t as usize]);
        let bounds = Aabb::from_points(triangles().flatten());
        let normal = triangles()
            .map(|&[a, b, c]| super::triangle_area_vector(a, b, c))
            .sum::<DVec3>()
            .try_normalize()
            .unwrap_or(DVec3::Z);
        let across = normal.any_orthonormal_vector();
        let frame = [normal, across, normal.cross(across)];
        let mut extent = [[f64::INFINITY, f64::NEG_INFINITY]; 3];
        for x in triangles().flatten() {
            for (axis, range) in frame.iter().zip(&mut extent) {
                let h = axis.dot(*x);
                *range = [range[0].min(h), range[1].max(h)];
            }
        }
        Node { bounds, frame, extent, first: first as u32, count: count as u32 }
    }

    /// A lower bound of the squared distance from `p` to the triangles of node `n`: the larger
    /// of the distances to its two boxes (the framed one's less a relative margin that covers
    /// the rounding of the dot products).
    fn node_distance_squared(&self, p: DVec3, n: usize) -> f64 {
        let node = &self.nodes[n];
        let mut framed = 0.0;
        for (axis, &[lo, hi]) in node.frame.iter().zip(&node.extent) {
            let h = axis.dot(p);
            let margin = 1e-9 * (h.abs() + lo.abs().max(hi.abs()));
            let gap = ((lo - h).max(h - hi) - margin).max(0.0);
            framed += gap * gap;
        }
        box_distance_squared(p, &node.bounds).max(framed)
    }

    /// Split node `n` at the median centroid along its longest centroid axis, recursively.
    fn split(&mut self, n: usize, centroids: &[DVec3]) {
        let (first, count) = (self.nodes[n].first as usize, self.nodes[n].count as usize);
        if count <= LEAF_SIZE {
            return;
        }
        let range = &mut self.order[first..first + count];
        let spread = Aabb::from_points(range.iter().map(|&t| &centroids[t as usize]));
        let axis = (spread.max - spread.min).max_position();
        let half = count / 2;
        range.select_nth_unstable_by(half, |&a, &b| {
            centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
        });
        let child = self.nodes.len();
        let (left, right) = (self.leaf(first, half), self.leaf(first + half, count - half));
        self.nodes.push(left);
        self.nodes.push(right);
        self.nodes[n].first = child as u32;
        self.nodes[n].count = 0;
        self.split(child, centroids);
        self.split(child + 1, centroids);
    }

    /// The closest point of all triangles to `p` (`None` for an empty set). Exact with respect
    /// to `closest_point_on_triangle`; ties go to the lower triangle id.
    pub fn nearest(&self, p: DVec3) -> Option<Nearest> {
        self.nearest_within(p, f64::INFINITY)
    }

    /// [`nearest`](Self::nearest) when it is closer than `reach`, else `None`: subtrees
    /// farther than `reach` are never searched, so a query that only has to rule out the nearby
    /// triangles costs a few boxes instead of a descent to the nearest leaf.
    pub fn nearest_within(&self, p: DVec3, reach: f64) -> Option<Nearest> {
        let mut best: Option<Nearest> = None;
        let mut best_d2 = reach * reach;
        self.search(
            best_d2,
            |_, n| self.node_distance_squared(p, n),
            |t, corners| {
                let q = closest_point_on_triangle(p, corners[0], corners[1], corners[2]);
                let d2 = (q - p).length_squared();
                if d2 < best_d2 || (d2 == best_d2 && best.is_some_and(|b| t < b.triangle)) {
                    best_d2 = d2;
                    best = Some(Nearest { triangle: t, point: q, distance: 0.0 });
                }
                best_d2
            },
        );
        best.map(|b| Nearest { distance: best_d2.sqrt(), ..b })
    }

    /// Minimise a cost over the triangles: `node_bound(bounds, node)` must never exceed the
    /// cost of any triangle in that subtree; `visit(id, corners)` evaluates a triangle and
    /// returns the best cost so far. Subtrees whose bound exceeds the best are skipped.
    pub fn branch_and_bound(
        &self,
        mut node_bound: impl FnMut(&Aabb) -> f64,
        visit: impl FnMut(u32, &[DVec3; 3]) -> f64,
    ) {
        self.search(f64::INFINITY, |bounds, _| node_bound(bounds), visit);
    }

    /// As [`branch_and_bound`](Self::branch_and_bound), the bound also given the node index (for
    /// per-node data from [`node_minimum`](Self::node_minimum)).
    pub fn branch_and_bound_nodes(
        &self,
        node_bound: impl FnMut(&Aabb, usize) -> f64,
        visit: impl FnMut(u32, &[DVec3; 3]) -> f64,
    ) {
        self.search(f64::INFINITY, node_bound, visit);
    }

    /// The search of [`branch_and_bound_nodes`](Self::branch_and_bound_nodes), with costs
    /// above `ceiling` of no interest: subtrees whose bound exceeds it are skipped from the
    /// start.
    fn search(
        &self,
        ceiling: f64,
        mut node_bound: impl FnMut(&Aabb, usize) -> f64,
        mut visit: impl FnMut(u32, &[DVec3; 3]) -> f64,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let mut best = ceiling;
        let mut stack: Vec<(usize, f64)> = Vec::with_capacity(64);
        stack.push((0, node_bound(&self.nodes[0].bounds, 0)));
        while let Some((n, bound)) = stack.pop() {
            if bound > best {
                continue;
            }
            let node = &self.nodes[n];
            let first = node.first as usize;
            if node.count > 0 {
                for &t in &self.order[first..first + node.count as usize] {
                    best = best.min(visit(t, &self.corners[t as usize]));
                }
                continue;
            }
            let (a, b) = (
                node_bound(&self.nodes[first].bounds, first),
                node_bound(&self.nodes[first + 1].bounds, first + 1),
            );
            // Push the farther child first so the nearer one is searched first.
            let (near, far) =
                if a <= b { ((first, a), (first + 1, b)) } else { ((first + 1, b), (first, a)) };
            stack.push(far);
            stack.push(near);
        }
    }

    /// The nearest crossing beyond `skip` of the ray `origin + s direction` (`s >= 0`) with a
    /// triangle that `ignore` does not rule out (floating point, see [`ray_triangle`]): its `s`
    /// and the triangle.
    pub fn first_hit(
        &self,
        origin: DVec3,
        direction: DVec3,
        skip: f64,
        ignore: impl Fn(u32) -> bool,
    ) -> Option<(f64, u32)> {
        let mut best = (f64::INFINITY, u32::MAX);
        self.branch_and_bound(
            |bounds| ray_box_entry(origin, direction, bounds),
            |t, corners| {
                if !ignore(t) {
                    if let Some(s) = ray_triangle(origin, direction, corners).filter(|&s| s > skip) {
                        if s < best.0 {
                            best = (s, t);
                        }
                    }
                }
                best.0
            },
        );
        best.0.is_finite().then_some(best)
    }

    /// For every node, the minimum of `value(triangle)` over its subtree.
    pub fn node_minimum(&self, value: impl Fn(u32) -> f64) -> Vec<f64> {
        let mut out = vec![f64::INFINITY; self.nodes.len()];
        // Children always come after their parent, so a reverse sweep sees children first.
        for n in (0..self.nodes.len()).rev() {
            let node = &self.nodes[n];
            let first = node.first as usize;
            out[n] = if node.count > 0 {
                self.order[first..first + node.count as usize]
                    .iter()
                    .map(|&t| value(t))
                    .fold(f64::INFINITY, f64::min)
            } else {
                out[first].min(out[first + 1])
            };
        }
        out
    }
}

/// Squared distance from `p` to the box (zero inside).
pub fn box_distance_squared(p: DVec3, b: &Aabb) -> f64 {
    let gap = (b.min - p).max(p - b.max).max(DVec3::ZERO);
    gap.length_squared()
}

/// Where the ray `origin + s direction`, `s >= 0`, enters the box (0 inside it; infinite if
/// it misses).
pub fn ray_box_entry(origin: DVec3, direction: DVec3, bounds: &Aabb) -> f64 {
    let (mut enter, mut leave) = (0.0f64, f64::INFINITY);
    for axis in 0..3 {
        let (o, d) = (origin[axis], direction[axis]);
        let (lo, hi) = (bounds.min[axis], bounds.max[axis]);
        if d == 0.0 {
            if o < lo || o > hi {
                return f64::INFINITY;
            }
            continue;
        }
        let (s0, s1) = ((lo - o) / d, (hi - o) / d);
        enter = enter.max(s0.min(s1));
        leave = leave.min(s0.max(s1));
    }
    if enter <= leave {
        enter
    } else {
        f64::INFINITY
    }
}

/// The ray parameter where `origin + s direction` crosses the triangle (Moller-Trumbore, in
/// floating point: for measures and margins, never for topology).
pub fn ray_triangle(origin: DVec3, direction: DVec3, [a, b, c]: &[DVec3; 3]) -> Option<f64> {
    let (e1, e2) = (*b - *a, *c - *a);
    let h = direction.cross(e2);
    let det = e1.dot(h);
    if det.abs() < 1e-300 {
        return None;
    }
    let offset = origin - *a;
    let u = offset.dot(h) / det;
    let q = offset.cross(e1);
    let v = direction.dot(q) / det;
    let s = e2.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && s >= 0.0).then_some(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::shapes::{cuboid, icosphere};
    use crate::surface::Surface;
    use proptest::prelude::*;

    fn corners(s: &Surface) -> Vec<[DVec3; 3]> {
        (0..s.triangles.len()).map(|t| s.triangle_points(t)).collect()
    }

    fn brute(corners: &[[DVec3; 3]], p: DVec3) -> f64 {
        corners
            .iter()
            .map(|c| (closest_point_on_triangle(p, c[0], c[1], c[2]) - p).length())
            .fold(f64::INFINITY, f64::min)
    }

    proptest! {
        /// The nearest distance equals the brute-force minimum, and the point lies on the
        /// reported triangle at that distance.
        #[test]
        fn agrees_with_brute_force(level in 0usize..3, n in 1usize..4, box_not_sphere in any::<bool>(),
                                   size in proptest::array::uniform3(0.1f64..3.0),
                                   points in proptest::collection::vec(proptest::array::uniform3(-4.0f64..4.0), 20)) {
            let s = if box_not_sphere { cuboid(DVec3::from_array(size), n) } else { icosphere(size[0], level) };
            let c = corners(&s);
            let bvh = TriangleBvh::new(c.clone());
            for p in points.into_iter().map(DVec3::from_array) {
                let near = bvh.nearest(p).unwrap();
                prop_assert_eq!(near.distance, brute(&c, p));
                let t = c[near.triangle as usize];
                prop_assert_eq!(closest_point_on_triangle(p, t[0], t[1], t[2]), near.point);
            }
        }

        /// Within a reach, the nearest is found exactly when it is closer than the reach, and
        /// nothing otherwise.
        #[test]
        fn nearest_within_a_reach_is_the_nearest_or_none(level in 0usize..3, n in 1usize..4,
                                   box_not_sphere in any::<bool>(), reach in 0.0f64..3.0,
                                   size in proptest::array::uniform3(0.1f64..3.0),
                                   points in proptest::collection::vec(proptest::array::uniform3(-4.0f64..4.0), 20)) {
            let s = if box_not_sphere { cuboid(DVec3::from_array(size), n) } else { icosphere(size[0], level) };
            let bvh = TriangleBvh::new(corners(&s));
            for p in points.into_iter().map(DVec3::from_array) {
                let near = bvh.nearest(p).unwrap();
                let within = bvh.nearest_within(p, reach);
                prop_assert_eq!(within, (near.distance < reach).then_some(near));
            }
        }
    }

    #[test]
    fn empty_set_has_no_nearest() {
        assert!(TriangleBvh::new(Vec::new()).nearest(DVec3::ZERO).is_none());
    }

    #[test]
    fn far_points_and_random_soups_are_exact() {
        // A soup of scattered triangles of very different sizes, queried from near and far.
        let mut c = Vec::new();
        for i in 0..200 {
            let x = ((i * 37) % 101) as f64 * 0.3;
            let y = ((i * 53) % 89) as f64 * 0.2;
            let s = 0.01 + (i % 7) as f64;
            c.push([DVec3::new(x, y, 0.0), DVec3::new(x + s, y, 0.1 * s), DVec3::new(x, y + s, -s)]);
        }
        let bvh = TriangleBvh::new(c.clone());
        for q in [DVec3::new(1e3, -5e2, 7.0), DVec3::new(10.0, 5.0, 0.3), DVec3::new(-1.0, 40.0, -3.0)] {
            assert_eq!(bvh.nearest(q).unwrap().distance, brute(&c, q));
        }
    }
}
