//! Exact distance to the wall, its closest point and triangle, and per-vertex wall data
//! interpolated there.

use glam::DVec3;

use crate::geometry::bvh::{box_distance_squared, TriangleBvh};
use crate::geometry::distance::closest_point_on_triangle;
use crate::surface::Surface;

/// The wall point closest to a query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallPoint {
    pub triangle: u32,
    pub point: DVec3,
    pub distance: f64,
    /// Weights of the triangle's three vertices at `point` (non-negative, summing to 1).
    pub barycentric: DVec3,
}

/// Distance queries against a wall surface (a BVH over its triangles).
#[derive(Clone, Debug)]
pub struct WallDistance {
    bvh: TriangleBvh,
    triangles: Vec<[u32; 3]>,
}

impl WallDistance {
    pub fn new(wall: &Surface) -> Self {
        let corners = (0..wall.triangles.len()).map(|t| wall.triangle_points(t)).collect();
        WallDistance { bvh: TriangleBvh::new(corners), triangles: wall.triangles.clone() }
    }

    /// The wall's triangles, for searches of their own.
    pub fn bvh(&self) -> &TriangleBvh {
        &self.bvh
    }

    /// The closest wall point to `p` (`None` for an empty wall).
    pub fn closest(&self, p: DVec3) -> Option<WallPoint> {
        let near = self.bvh.nearest(p)?;
        let corners = self.bvh.corners(near.triangle);
        Some(WallPoint {
            triangle: near.triangle,
            point: near.point,
            distance: near.distance,
            barycentric: barycentric(near.point, corners),
        })
    }

    /// Unit direction from the wall point `near` to `p` (the distance gradient); the triangle's
    /// normal when `p` is on the wall.
    pub fn direction_from(&self, near: &WallPoint, p: DVec3) -> DVec3 {
        let away = p - near.point;
        if near.distance > 1e-14 * p.abs().max_element().max(1.0) {
            return away / near.distance;
        }
        let [a, b, c] = self.bvh.corners(near.triangle);
        crate::geometry::triangle_area_vector(a, b, c).normalize_or_zero()
    }

    /// A per-vertex value interpolated linearly on triangle `t` at the given weights.
    pub fn interpolate(&self, values: &[f64], t: u32, weights: DVec3) -> f64 {
        let [a, b, c] = self.triangles[t as usize];
        weights.dot(DVec3::new(values[a as usize], values[b as usize], values[c as usize]))
    }

    /// `min over wall points y of (v(y) + slope |p - y|)`, capped at `cap`, with `v` the
    /// per-vertex `values` interpolated linearly: the largest function below `v` on the wall that
    /// grows at most `slope` per unit length. Each triangle contributes its closest point and its
    /// vertices, so the result is Lipschitz (constant `slope` + the steepest `v` gradient).
    /// `near` is the closest wall point to `p` (its candidate seeds the search, so that it prunes
    /// from the start).
    pub fn graded_minimum(
        &self,
        p: DVec3,
        near: &WallPoint,
        values: &[f64],
        node_min: &[f64],
        slope: f64,
        cap: f64,
    ) -> f64 {
        let mut best =
            cap.min(self.interpolate(values, near.triangle, near.barycentric) + slope * near.distance);
        self.bvh.branch_and_bound_nodes(
            |bounds, node| node_min[node] + slope * box_distance_squared(p, bounds).sqrt(),
            |t, c| {
                let q = closest_point_on_triangle(p, c[0], c[1], c[2]);
                let [a, b, v] = self.triangles[t as usize];
                let at_q = self.interpolate(values, t, barycentric(q, *c));
                best = best.min(at_q + slope * (p - q).length());
                for (i, corner) in [a, b, v].into_iter().zip(c) {
                    best = best.min(values[i as usize] + slope * (p - *corner).length());
                }
                best
            },
        );
        best
    }

    /// Per BVH node, the minimum of a per-vertex value over its triangles (for
    /// [`graded_minimum`](Self::graded_minimum)).
    pub fn node_minimum(&self, values: &[f64]) -> Vec<f64> {
        self.bvh.node_minimum(|t| {
            self.triangles[t as usize].iter().map(|&v| values[v as usize]).fold(f64::INFINITY, f64::min)
        })
    }
}

/// Barycentric weights of point `q` (on the triangle) in triangle `c`, clamped to the triangle;
/// a degenerate triangle gives equal weights.
fn barycentric(q: DVec3, c: [DVec3; 3]) -> DVec3 {
    let (e0, e1, eq) = (c[1] - c[0], c[2] - c[0], q - c[0]);
    let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
    let (d20, d21) = (eq.dot(e0), eq.dot(e1));
    let denominator = d00 * d11 - d01 * d01;
    if denominator.is_nan() || denominator <= f64::EPSILON * d00 * d11 {
        return DVec3::splat(1.0 / 3.0);
    }
    let v = (d11 * d20 - d01 * d21) / denominator;
    let w = (d00 * d21 - d01 * d20) / denominator;
    let weights = DVec3::new(1.0 - v - w, v, w).max(DVec3::ZERO);
    weights / weights.element_sum()
}

/// Mean length of the edges at every point (each triangle side counted once per triangle
/// using it, so both sides weigh alike); 0 for a point no triangle uses. Indices must be valid.
pub fn mean_edge_length_per_vertex(points: &[DVec3], triangles: &[[u32; 3]]) -> Vec<f64> {
    let (mut sum, mut count) = (vec![0.0; points.len()], vec![0u32; points.len()]);
    for t in triangles {
        for i in 0..3 {
            let (a, b) = (t[i] as usize, t[(i + 1) % 3] as usize);
            let length = points[a].distance(points[b]);
            for v in [a, b] {
                sum[v] += length;
                count[v] += 1;
            }
        }
    }
    sum.iter().zip(&count).map(|(s, &n)| if n > 0 { s / n as f64 } else { 0.0 }).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::shapes::{cuboid, icosphere};
    use proptest::prelude::*;

    proptest! {
        /// Distance, closest point and weights agree with a brute force over all triangles.
        #[test]
        fn closest_point_agrees_with_brute_force(level in 0usize..3, n in 1usize..4, sphere in any::<bool>(),
                                                 points in proptest::collection::vec(
                                                     proptest::array::uniform3(-3.0f64..3.0), 20)) {
            let s = if sphere { icosphere(1.3, level) } else { cuboid(DVec3::new(1.0, 2.0, 0.5), n) };
            let wall = WallDistance::new(&s);
            for p in points.into_iter().map(DVec3::from_array) {
                let w = wall.closest(p).unwrap();
                let brute = (0..s.triangles.len())
                    .map(|t| { let [a, b, c] = s.triangle_points(t); (closest_point_on_triangle(p, a, b, c) - p).length() })
                    .fold(f64::INFINITY, f64::min);
                prop_assert_eq!(w.distance, brute);
                let [a, b, c] = s.triangle_points(w.triangle as usize);
                let rebuilt = a * w.barycentric.x + b * w.barycentric.y + c * w.barycentric.z;
                prop_assert!((rebuilt - w.point).length() <= 1e-12 * (1.0 + p.length()));
            }
        }
    }

    #[test]
    fn mean_edge_lengths_of_a_unit_grid() {
        // A unit cube face split in 2x2 squares: edges 0.5 and diagonals 0.5 sqrt(2).
        let s = cuboid(DVec3::ONE, 2);
        let h = mean_edge_length_per_vertex(&s.points, &s.triangles);
        assert!(h.iter().all(|&x| (0.5..=0.5 * 2f64.sqrt()).contains(&x)), "{h:?}");
    }
}
