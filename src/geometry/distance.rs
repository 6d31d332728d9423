//! Closest points and distances (floating point: these measure, they decide no topology).

use glam::DVec3;

/// The point of triangle (a, b, c) closest to `p` (Voronoi-region walk, after Ericson,
/// *Real-Time Collision Detection*, 5.1.5). Degenerate triangles are handled.
pub fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom.abs() < f64::MIN_POSITIVE {
        // Degenerate (collinear) triangle: the nearest of its three edges.
        return [(a, b), (b, c), (c, a)]
            .into_iter()
            .map(|(s, t)| closest_point_on_segment(p, s, t))
            .min_by(|x, y| (*x - p).length_squared().total_cmp(&(*y - p).length_squared()))
            .unwrap_or(a);
    }
    a + ab * (vb / denom) + ac * (vc / denom)
}

/// The point of segment (a, b) closest to `p`.
pub fn closest_point_on_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let e = b - a;
    let len2 = e.length_squared();
    if len2 == 0.0 {
        return a;
    }
    a + e * ((p - a).dot(e) / len2).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn regions_of_a_right_triangle() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let q = |p: DVec3| closest_point_on_triangle(p, a, b, c);
        assert!((q(DVec3::new(0.2, 0.2, 5.0)) - DVec3::new(0.2, 0.2, 0.0)).length() < 1e-15);
        assert_eq!(q(DVec3::new(-1.0, -1.0, 0.0)), a);
        assert_eq!(q(DVec3::new(2.0, -1.0, 1.0)), b);
        assert_eq!(q(DVec3::new(0.5, -3.0, 0.0)), DVec3::new(0.5, 0.0, 0.0));
        assert!((q(DVec3::new(1.0, 1.0, 0.0)) - DVec3::new(0.5, 0.5, 0.0)).length() < 1e-15);
    }

    proptest! {
        /// No point of the triangle (sampled by barycentrics) is closer than the answer.
        #[test]
        fn nothing_is_closer(v in proptest::array::uniform12(-5.0f64..5.0),
                             s in proptest::collection::vec((0.0f64..1.0, 0.0f64..1.0), 16)) {
            let p = DVec3::new(v[0], v[1], v[2]);
            let (a, b, c) = (DVec3::new(v[3], v[4], v[5]), DVec3::new(v[6], v[7], v[8]), DVec3::new(v[9], v[10], v[11]));
            let q = closest_point_on_triangle(p, a, b, c);
            let d = (q - p).length();
            for (x, y) in s {
                let (x, y) = if x + y > 1.0 { (1.0 - x, 1.0 - y) } else { (x, y) };
                let r = a + (b - a) * x + (c - a) * y;
                prop_assert!(d <= (r - p).length() + 1e-9);
            }
        }
    }
}
