//! Exact tests of what crosses a boundary edge or triangle missing from the tetrahedra.
//!
//! A missing edge `ab` (no vertex on it) is crossed by the faces whose interior it passes
//! through and by the edges it meets at one interior point (in their common plane): it is an
//! edge exactly when nothing crosses it. A missing triangle whose three edges are edges is
//! crossed by the edges that pass through its interior: no edge can lie in its plane and enter
//! it without crossing one of its edges, and a tetrahedron whose interior meets it has an edge
//! through it; so it is a face exactly when nothing crosses it.

use crate::geometry::predicates::{orient2d, orient3d, Sign};
use crate::geometry::DVec3;

/// A boundary edge or triangle to recover.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Target {
    Edge([u32; 2]),
    Triangle([u32; 3]),
}

impl Target {
    pub(super) fn vertices(&self) -> &[u32] {
        match self {
            Target::Edge(e) => e,
            Target::Triangle(t) => t,
        }
    }

    /// Whether an element with `nodes` shares one with the target: then it does not cross it
    /// (an edge or face through a target's node meets it there only, or in its plane).
    fn touches(&self, nodes: &[u32]) -> bool {
        nodes.iter().any(|v| self.vertices().contains(v))
    }

    /// Whether edge `xy` crosses the target.
    pub(super) fn crossed_by_edge(&self, points: &[DVec3], [x, y]: [u32; 2]) -> bool {
        if self.touches(&[x, y]) {
            return false;
        }
        let p = |v: u32| points[v as usize];
        match *self {
            Target::Edge([a, b]) => segments_cross(p(a), p(b), p(x), p(y)),
            Target::Triangle([a, b, c]) => segment_crosses_triangle(p(x), p(y), [p(a), p(b), p(c)]),
        }
    }

    /// Whether the interior of face `xyz` is crossed by the target (an edge's only).
    pub(super) fn crossed_by_face(&self, points: &[DVec3], face: [u32; 3]) -> bool {
        if self.touches(&face) {
            return false;
        }
        match *self {
            Target::Edge([a, b]) => {
                let p = |v: u32| points[v as usize];
                segment_crosses_triangle(p(a), p(b), face.map(p))
            }
            Target::Triangle(_) => false,
        }
    }
}

/// Whether the two boxes of the point sets overlap (exact: a necessary condition of a crossing).
fn boxes_overlap(first: &[DVec3], second: &[DVec3]) -> bool {
    let bounds = |s: &[DVec3]| {
        s.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)))
    };
    let ((lo1, hi1), (lo2, hi2)) = (bounds(first), bounds(second));
    lo1.cmple(hi2).all() && lo2.cmple(hi1).all()
}

/// Whether segment `ab` passes through the interior of triangle `t` at one point interior to
/// the segment (not in its plane).
pub(super) fn segment_crosses_triangle(a: DVec3, b: DVec3, t: [DVec3; 3]) -> bool {
    if !boxes_overlap(&[a, b], &t) {
        return false;
    }
    let [x, y, z] = t;
    let (sa, sb) = (orient3d(x, y, z, a), orient3d(x, y, z, b));
    if sa == Sign::Zero || sb == Sign::Zero || sa == sb {
        return false;
    }
    let s = orient3d(a, b, x, y);
    s != Sign::Zero && orient3d(a, b, y, z) == s && orient3d(a, b, z, x) == s
}

/// Whether segments `ab` and `xy` meet at one point interior to both (in a common plane).
pub(super) fn segments_cross(a: DVec3, b: DVec3, x: DVec3, y: DVec3) -> bool {
    if !boxes_overlap(&[a, b], &[x, y]) || orient3d(a, b, x, y) != Sign::Zero {
        return false;
    }
    let normal = [(b - a).cross(x - a), (b - a).cross(y - a)]
        .into_iter()
        .max_by(|m, n| m.length_squared().total_cmp(&n.length_squared()))
        .unwrap_or(DVec3::ZERO);
    if normal == DVec3::ZERO {
        // All four on a line: no single crossing point.
        return false;
    }
    let project = projection(normal);
    let [a, b, x, y] = [a, b, x, y].map(project);
    let opposite = |s: Sign, t: Sign| s != Sign::Zero && t != Sign::Zero && s != t;
    opposite(orient2d(a, b, x), orient2d(a, b, y)) && opposite(orient2d(x, y, a), orient2d(x, y, b))
}

/// Drop the coordinate along which `normal` (of the plane of the points projected) is largest:
/// exact, and it keeps the orientations of the plane's points (up to a sign common to all).
pub(super) fn projection(normal: DVec3) -> impl Fn(DVec3) -> [f64; 2] {
    let n = normal.abs();
    let drop = if n.x >= n.y && n.x >= n.z {
        0
    } else if n.y >= n.z {
        1
    } else {
        2
    };
    move |p: DVec3| crate::geometry::intersect::project(p, drop)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossings() {
        let t = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let (above, below) = (DVec3::new(0.2, 0.2, 1.0), DVec3::new(0.2, 0.2, -1.0));
        assert!(segment_crosses_triangle(above, below, t));
        assert!(!segment_crosses_triangle(above, DVec3::new(0.2, 0.2, 0.5), t));
        // Through an edge, or from a vertex: not through the interior.
        assert!(!segment_crosses_triangle(DVec3::new(0.5, 0.0, 1.0), DVec3::new(0.5, 0.0, -1.0), t));
        assert!(!segment_crosses_triangle(DVec3::ZERO, below, t));
        let (a, b) = (DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0));
        assert!(segments_cross(a, b, DVec3::X, DVec3::Y));
        assert!(!segments_cross(a, b, DVec3::X, DVec3::new(2.0, 0.0, 0.0)));
        assert!(!segments_cross(a, b, DVec3::X, DVec3::new(0.0, 1.0, 0.1)));
        assert!(!segments_cross(a, b, b, DVec3::Y));
        assert!(!segments_cross(a, b, DVec3::new(2.0, 2.0, 0.0), DVec3::new(3.0, 3.0, 0.0)));
    }
}
