//! The "most normal" direction at a wall vertex.
//!
//! For unit face normals `n_i`, the direction `u` maximising `min_i n_i . u` is `p / |p|`, where
//! `p` is the point of the convex hull of the `n_i` nearest to the origin, and the maximum is `|p|`
//! (the dual of `min |x|^2 s.t. n_i . x >= 1`, with `x* = p / |p|^2`). In 3D that point lies on a
//! hull simplex of at most three normals (Caratheodory), so we solve it exactly by enumerating
//! the active sets of size 1, 2 and 3 and keeping the best candidate: no iteration, no tolerance.

use glam::DVec3;

/// Result of [`most_normal`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MostNormal {
    /// Unit direction maximising the smallest cosine with the face normals.
    pub direction: DVec3,
    /// That smallest cosine, `min_i n_i . direction`, in (0, 1].
    pub min_cos: f64,
}

impl MostNormal {
    /// How far to move along `direction` to be at distance `d` from every incident face plane
    /// (at least `d` from all, exactly `d` from the active ones): `d / min_cos`.
    pub fn extrusion_scale(&self) -> f64 {
        1.0 / self.min_cos
    }
}

/// The most normal direction of unit normals `normals`; `None` when no direction sees every
/// face from the front (the origin lies in their convex hull) or `normals` is empty.
pub fn most_normal(normals: &[DVec3]) -> Option<MostNormal> {
    let mut best: Option<MostNormal> = None;
    let mut consider = |p: DVec3| {
        let Some(u) = p.try_normalize() else { return };
        let min_cos = normals.iter().map(|n| n.dot(u)).fold(f64::INFINITY, f64::min);
        if min_cos > 0.0 && best.is_none_or(|b| min_cos > b.min_cos) {
            best = Some(MostNormal { direction: u, min_cos });
        }
    };
    let k = normals.len();
    for i in 0..k {
        consider(normals[i]);
        for j in i + 1..k {
            if let Some(p) = nearest_on_segment(normals[i], normals[j]) {
                consider(p);
            }
            for l in j + 1..k {
                if let Some(p) = nearest_in_triangle(normals[i], normals[j], normals[l]) {
                    consider(p);
                }
            }
        }
    }
    best
}

/// The point of segment (a, b) nearest the origin, when it is strictly inside the segment.
fn nearest_on_segment(a: DVec3, b: DVec3) -> Option<DVec3> {
    let e = b - a;
    let t = -a.dot(e) / e.length_squared();
    (t > 0.0 && t < 1.0).then(|| a + t * e)
}

/// The point of triangle (a, b, c) nearest the origin, when it is strictly inside the triangle.
fn nearest_in_triangle(a: DVec3, b: DVec3, c: DVec3) -> Option<DVec3> {
    // p = a + s e1 + t e2 with p orthogonal to e1 and e2: a 2x2 Gram system.
    let (e1, e2) = (b - a, c - a);
    let (g11, g12, g22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (r1, r2) = (-a.dot(e1), -a.dot(e2));
    let det = g11 * g22 - g12 * g12;
    if !(det.abs() > 1e-300) {
        return None;
    }
    let s = (r1 * g22 - r2 * g12) / det;
    let t = (g11 * r2 - g12 * r1) / det;
    (s > 0.0 && t > 0.0 && s + t < 1.0).then(|| a + s * e1 + t * e2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn flat_vertex_keeps_its_normal() {
        let m = most_normal(&[DVec3::Z, DVec3::Z, DVec3::Z]).unwrap();
        assert!(close(m.direction, DVec3::Z));
        assert_eq!(m.min_cos, 1.0);
    }

    #[test]
    fn right_angle_ridge_gives_the_bisector() {
        let m = most_normal(&[DVec3::X, DVec3::Y]).unwrap();
        assert!(close(m.direction, DVec3::new(1.0, 1.0, 0.0).normalize()));
        assert!((m.extrusion_scale() - 2f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn cube_corner_gives_the_diagonal() {
        // Extra normals inside the cone must not change the answer.
        let inner = DVec3::new(1.0, 1.0, 0.5).normalize();
        let m = most_normal(&[DVec3::X, DVec3::Y, DVec3::Z, inner]).unwrap();
        assert!(close(m.direction, DVec3::ONE.normalize()));
        assert!((m.min_cos - 1.0 / 3f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn opposite_faces_have_no_common_normal() {
        assert!(most_normal(&[DVec3::X, -DVec3::X]).is_none());
        assert!(most_normal(&[DVec3::X, DVec3::Y, DVec3::Z, -DVec3::ONE.normalize()]).is_none());
        assert!(most_normal(&[]).is_none());
    }

    fn unit(v: [f64; 3]) -> Option<DVec3> {
        DVec3::from_array(v).try_normalize()
    }

    proptest! {
        /// No other direction does better than the one found (checked against random directions
        /// and the face normals themselves), and the found one sees every face.
        #[test]
        fn is_optimal(raw in proptest::collection::vec(proptest::array::uniform3(-1.0f64..1.0), 1..8),
                      probes in proptest::collection::vec(proptest::array::uniform3(-1.0f64..1.0), 32)) {
            // Normals in the upper half-space (tilted), so a solution usually exists.
            let normals: Vec<DVec3> = raw.iter().filter_map(|v| unit([v[0], v[1], v[2].abs() + 0.2])).collect();
            prop_assume!(!normals.is_empty());
            let m = most_normal(&normals).expect("normals in an open half-space have a common normal");
            let score = |u: DVec3| normals.iter().map(|n| n.dot(u)).fold(f64::INFINITY, f64::min);
            prop_assert!((score(m.direction) - m.min_cos).abs() < 1e-12);
            for p in probes.iter().filter_map(|&p| unit(p)).chain(normals.iter().copied()) {
                prop_assert!(score(p) <= m.min_cos + 1e-12, "probe {p} beats {m:?}");
            }
        }
    }
}
