//! Exact intersection tests between closed segments and closed triangles (touching counts).
//!
//! Every decision is a sign of the exact [`orient3d`]/[`orient2d`] predicates, so the answers
//! are right for touching, coplanar and collinear configurations. Triangles are assumed
//! non-degenerate (the surface validation rejects zero-area triangles before using these).

use super::predicates::{orient2d, orient3d, Sign};
use super::DVec3;

/// A triangle as its three corner points.
pub type Triangle = [DVec3; 3];

/// Whether the closed segment `[p, q]` and the closed triangle `t` have a point in common.
pub fn segment_triangle(p: DVec3, q: DVec3, t: Triangle) -> bool {
    let [a, b, c] = t;
    let (sp, sq) = (orient3d(a, b, c, p), orient3d(a, b, c, q));
    if sp == sq && sp != Sign::Zero {
        return false;
    }
    if sp == Sign::Zero && sq == Sign::Zero {
        return coplanar_segment_triangle(p, q, t);
    }
    // The segment meets the plane in exactly one point: inside the triangle iff the line pq
    // passes through it, i.e. the line turns the same way (or not at all) around all three edges.
    !mixed_signs(&[orient3d(p, q, a, b), orient3d(p, q, b, c), orient3d(p, q, c, a)])
}

/// Whether the closed triangles `t` and `u` have a point in common (for triangles that share no
/// vertex). Their intersection, if any, has a boundary point on an edge of one of them, so it is
/// enough to test the six edges against the other triangle.
pub fn triangles_intersect(t: Triangle, u: Triangle) -> bool {
    if strictly_one_side(t, u) || strictly_one_side(u, t) {
        return false;
    }
    edges(t).into_iter().any(|[p, q]| segment_triangle(p, q, u))
        || edges(u).into_iter().any(|[p, q]| segment_triangle(p, q, t))
}

/// Whether triangles `(v, a, b)` and `(v, c, d)`, which share the vertex `v`, meet anywhere
/// else than at `v`: an edge opposite `v` touches the other triangle, or an edge from `v` lies in
/// the other triangle's plane and runs into its corner at `v`.
pub fn meet_beyond_shared_vertex(v: DVec3, a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> bool {
    segment_triangle(a, b, [v, c, d])
        || segment_triangle(c, d, [v, a, b])
        || [a, b].into_iter().any(|x| runs_into_corner(v, x, c, d))
        || [c, d].into_iter().any(|x| runs_into_corner(v, x, a, b))
}

/// Whether triangles `(u, w, a)` and `(u, w, b)`, which share the edge `(u, w)`, overlap: that
/// happens only when they are coplanar with `a` and `b` on the same side of the edge (a fold).
pub fn folds_over_shared_edge(u: DVec3, w: DVec3, a: DVec3, b: DVec3) -> bool {
    if orient3d(u, w, a, b) != Sign::Zero {
        return false;
    }
    let Some(axis) = projection_axis([u, w, a]) else { return false };
    let side_a = orient2d(project(u, axis), project(w, axis), project(a, axis));
    let side_b = orient2d(project(u, axis), project(w, axis), project(b, axis));
    side_a == side_b
}

/// Whether triangles `t` and `u` (node ids and points) meet elsewhere than in the vertices they
/// share (by id): anywhere when they share none, beyond the vertex when they share one
/// ([`meet_beyond_shared_vertex`]), folded flat onto each other when they share an edge
/// ([`folds_over_shared_edge`]).
pub fn triangles_meet(t_ids: [u32; 3], t: [DVec3; 3], u_ids: [u32; 3], u: [DVec3; 3]) -> bool {
    let shared_in_u = t_ids.map(|v| u_ids.iter().position(|&w| w == v));
    match shared_in_u.iter().filter(|s| s.is_some()).count() {
        0 => triangles_intersect(t, u),
        1 => {
            let i = shared_in_u.iter().position(|s| s.is_some()).unwrap_or(0);
            let j = shared_in_u[i].unwrap_or(0);
            let (a, b) = (t[(i + 1) % 3], t[(i + 2) % 3]);
            let (c, d) = (u[(j + 1) % 3], u[(j + 2) % 3]);
            meet_beyond_shared_vertex(t[i], a, b, c, d)
        }
        2 => {
            let lone_t = shared_in_u.iter().position(|s| s.is_none()).unwrap_or(0);
            let lone_u = (0..3).find(|&k| !t_ids.contains(&u_ids[k])).unwrap_or(0);
            let (v, w) = (t[(lone_t + 1) % 3], t[(lone_t + 2) % 3]);
            folds_over_shared_edge(v, w, t[lone_t], u[lone_u])
        }
        _ => false,
    }
}

/// Whether `x`, from the corner `v` of triangle `(v, c, d)`, points into that corner while
/// lying in the triangle's plane: then the segment `[v, x]` overlaps the triangle near `v`.
fn runs_into_corner(v: DVec3, x: DVec3, c: DVec3, d: DVec3) -> bool {
    if orient3d(v, c, d, x) != Sign::Zero {
        return false;
    }
    let Some(axis) = projection_axis([v, c, d]) else { return false };
    let [v2, x2, c2, d2] = [v, x, c, d].map(|p| project(p, axis));
    let outside = orient2d(v2, c2, d2).flip();
    orient2d(v2, c2, x2) != outside && orient2d(v2, x2, d2) != outside
}

/// `[p, q]` and `t` lie in one plane: compare them in a projection where `t` keeps its area.
fn coplanar_segment_triangle(p: DVec3, q: DVec3, t: Triangle) -> bool {
    let Some(axis) = projection_axis(t) else { return false };
    let [a, b, c] = t.map(|x| project(x, axis));
    let (p, q) = (project(p, axis), project(q, axis));
    point_in_triangle_2d(p, [a, b, c])
        || point_in_triangle_2d(q, [a, b, c])
        || [[a, b], [b, c], [c, a]].into_iter().any(|[r, s]| segments_intersect_2d(p, q, r, s))
}

/// Whether all three corners of `u` lie strictly on one side of the plane of `t`.
fn strictly_one_side(t: Triangle, u: Triangle) -> bool {
    let [a, b, c] = t;
    let s = u.map(|p| orient3d(a, b, c, p));
    s[0] != Sign::Zero && s[0] == s[1] && s[1] == s[2]
}

fn edges(t: Triangle) -> [[DVec3; 2]; 3] {
    [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]]
}

fn mixed_signs(signs: &[Sign]) -> bool {
    signs.contains(&Sign::Positive) && signs.contains(&Sign::Negative)
}

/// The coordinate axis to drop so that the projected triangle keeps a non-zero area (exactly),
/// trying the axis of the largest normal component first; `None` for a degenerate triangle.
pub fn projection_axis(t: Triangle) -> Option<usize> {
    let n = super::triangle_area_vector(t[0], t[1], t[2]).abs();
    let first = if n.x >= n.y && n.x >= n.z {
        0
    } else if n.y >= n.z {
        1
    } else {
        2
    };
    [first, (first + 1) % 3, (first + 2) % 3].into_iter().find(|&axis| {
        let [a, b, c] = t.map(|p| project(p, axis));
        orient2d(a, b, c) != Sign::Zero
    })
}

/// The point with coordinate `axis` dropped (the other two in cyclic order).
pub fn project(p: DVec3, axis: usize) -> [f64; 2] {
    match axis {
        0 => [p.y, p.z],
        1 => [p.z, p.x],
        _ => [p.x, p.y],
    }
}

/// Whether `p` lies in the closed 2D triangle `t` (of either orientation, non-degenerate).
fn point_in_triangle_2d(p: [f64; 2], t: [[f64; 2]; 3]) -> bool {
    let [a, b, c] = t;
    !mixed_signs(&[orient2d(a, b, p), orient2d(b, c, p), orient2d(c, a, p)])
}

/// Whether the closed 2D segments `[p, q]` and `[r, s]` have a point in common.
fn segments_intersect_2d(p: [f64; 2], q: [f64; 2], r: [f64; 2], s: [f64; 2]) -> bool {
    let (o1, o2) = (orient2d(p, q, r), orient2d(p, q, s));
    if o1 == Sign::Zero && o2 == Sign::Zero {
        // Collinear: they meet iff their extents overlap along both coordinates.
        return (0..2).all(|k| p[k].min(q[k]) <= r[k].max(s[k]) && r[k].min(s[k]) <= p[k].max(q[k]));
    }
    o1 != o2 && orient2d(r, s, p) != orient2d(r, s, q)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    /// Triangles sharing a vertex meet beyond it only when one runs through the other; sharing an
    /// edge, only when folded flat onto each other; sharing nothing, when they intersect.
    #[test]
    fn triangles_meet_beyond_what_they_share() {
        let t = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)];
        // Sharing vertex 0: lifted apart, then dipping through t.
        let apart = [v(0.0, 0.0, 0.0), v(-1.0, 0.0, 0.5), v(0.0, -1.0, 0.5)];
        let through = [v(0.0, 0.0, 0.0), v(0.5, 0.2, -0.5), v(0.2, 0.5, 0.5)];
        assert!(!triangles_meet([0, 1, 2], t, [0, 3, 4], apart));
        assert!(triangles_meet([0, 1, 2], t, [0, 3, 4], through));
        // Sharing the edge (1, 2): across it, then folded onto t.
        let across = [v(1.0, 0.0, 0.0), v(1.0, 1.0, 0.0), v(0.0, 1.0, 0.0)];
        let folded = [v(1.0, 0.0, 0.0), v(0.2, 0.2, 0.0), v(0.0, 1.0, 0.0)];
        assert!(!triangles_meet([0, 1, 2], t, [1, 5, 2], across));
        assert!(triangles_meet([0, 1, 2], t, [1, 5, 2], folded));
        // Nothing shared: a triangle piercing t.
        let pierce = [v(0.2, 0.2, -1.0), v(0.3, 0.2, 1.0), v(0.2, 0.3, 1.0)];
        assert!(triangles_meet([0, 1, 2], t, [6, 7, 8], pierce));
    }

    /// The unit right triangle in the plane z = 0.
    fn base() -> Triangle {
        [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)]
    }

    #[test]
    fn segment_through_interior_edge_vertex_and_beside() {
        let t = base();
        assert!(segment_triangle(v(0.2, 0.2, -1.0), v(0.2, 0.2, 1.0), t));
        assert!(segment_triangle(v(0.5, 0.0, -1.0), v(0.5, 0.0, 1.0), t), "through an edge");
        assert!(segment_triangle(v(0.0, 0.0, -1.0), v(0.0, 0.0, 1.0), t), "through a vertex");
        assert!(segment_triangle(v(0.2, 0.2, 0.0), v(0.2, 0.2, 1.0), t), "ends on the face");
        assert!(!segment_triangle(v(0.6, 0.6, -1.0), v(0.6, 0.6, 1.0), t), "beside");
        assert!(!segment_triangle(v(0.2, 0.2, 0.5), v(0.2, 0.2, 1.0), t), "above");
    }

    #[test]
    fn coplanar_segments() {
        let t = base();
        assert!(segment_triangle(v(-1.0, 0.2, 0.0), v(2.0, 0.2, 0.0), t), "crosses");
        assert!(segment_triangle(v(0.1, 0.1, 0.0), v(0.2, 0.1, 0.0), t), "inside");
        assert!(segment_triangle(v(1.0, 0.0, 0.0), v(2.0, 0.0, 0.0), t), "touches a vertex");
        assert!(segment_triangle(v(0.5, 0.5, 0.0), v(1.0, 1.0, 0.0), t), "touches an edge");
        assert!(!segment_triangle(v(0.6, 0.6, 0.0), v(1.0, 1.0, 0.0), t), "outside");
        assert!(!segment_triangle(v(2.0, 0.0, 0.0), v(3.0, 0.0, 0.0), t), "collinear apart");
    }

    #[test]
    fn triangle_pairs() {
        let t = base();
        let pierce = [v(0.2, 0.2, -1.0), v(0.3, 0.2, 1.0), v(0.2, 0.3, 1.0)];
        assert!(triangles_intersect(t, pierce));
        let above = [v(0.2, 0.2, 0.1), v(0.3, 0.2, 1.0), v(0.2, 0.3, 1.0)];
        assert!(!triangles_intersect(t, above));
        let touch_vertex = [v(0.2, 0.2, 0.0), v(0.3, 0.2, 1.0), v(0.2, 0.3, 1.0)];
        assert!(triangles_intersect(t, touch_vertex));
        // Edge-edge crossing of two perpendicular triangles.
        let cross_edges = [v(0.5, 0.5, 0.0), v(0.0, 0.0, 1.0), v(1.0, 1.0, 1.0)];
        assert!(triangles_intersect(t, cross_edges));
        let coplanar_inside = [v(0.1, 0.1, 0.0), v(0.2, 0.1, 0.0), v(0.1, 0.2, 0.0)];
        assert!(triangles_intersect(t, coplanar_inside), "contained");
        assert!(triangles_intersect(coplanar_inside, t), "containing");
        let coplanar_apart = [v(1.0, 1.0, 0.0), v(2.0, 1.0, 0.0), v(1.0, 2.0, 0.0)];
        assert!(!triangles_intersect(t, coplanar_apart));
        let parallel = [v(0.0, 0.0, 1.0), v(1.0, 0.0, 1.0), v(0.0, 1.0, 1.0)];
        assert!(!triangles_intersect(t, parallel));
    }

    #[test]
    fn shared_vertex_pairs() {
        let [o, x, y] = base();
        // A triangle standing on the corner: meets only there.
        assert!(!meet_beyond_shared_vertex(o, x, y, v(-1.0, -1.0, 1.0), v(-1.0, 0.0, 1.0)));
        // Its opposite edge pierces the base triangle.
        assert!(meet_beyond_shared_vertex(o, x, y, v(0.5, 0.1, -1.0), v(0.1, 0.5, 1.0)));
        // Coplanar, overlapping near the shared corner.
        assert!(meet_beyond_shared_vertex(o, x, y, v(0.5, 0.5, 0.0), v(2.0, 0.1, 0.0)));
        // Coplanar, in the opposite quadrant: only the corner is shared.
        assert!(!meet_beyond_shared_vertex(o, x, y, v(-1.0, 0.0, 0.0), v(0.0, -1.0, 0.0)));
        // Coplanar, sharing the ray along x but not the edge itself: overlap along a segment.
        assert!(meet_beyond_shared_vertex(o, x, y, v(2.0, 0.0, 0.0), v(0.0, -1.0, 0.0)));
        // An edge from the shared vertex lies in the other's plane, pointing away from it.
        assert!(!meet_beyond_shared_vertex(o, x, y, v(-1.0, -1.0, 0.0), v(0.0, 0.0, 1.0)));
    }

    #[test]
    fn shared_edge_pairs() {
        let (u, w) = (v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0));
        assert!(!folds_over_shared_edge(u, w, v(0.5, 1.0, 0.0), v(0.5, -1.0, 0.0)), "flat");
        assert!(!folds_over_shared_edge(u, w, v(0.5, 1.0, 0.0), v(0.5, 0.0, 1.0)), "dihedral");
        assert!(folds_over_shared_edge(u, w, v(0.5, 1.0, 0.0), v(0.2, 3.0, 0.0)), "fold");
    }

    fn point(c: &[f64]) -> DVec3 {
        v(c[0], c[1], c[2])
    }

    fn triangle(c: &[f64]) -> Triangle {
        [point(&c[0..3]), point(&c[3..6]), point(&c[6..9])]
    }

    fn nondegenerate(t: Triangle) -> bool {
        projection_axis(t).is_some()
    }

    /// A rotation built from three angles (floating point; used only with clear margins).
    fn rotate(p: DVec3, angles: [f64; 3]) -> DVec3 {
        let q = glam::DQuat::from_euler(glam::EulerRot::XYZ, angles[0], angles[1], angles[2]);
        q * p
    }

    proptest! {
        /// Clearly separated triangles (a slab of width 0.2 between them, any orientation)
        /// never intersect; the answer does not depend on argument or vertex order.
        #[test]
        fn separated_triangles_do_not_intersect(
            a in proptest::array::uniform9(0.0f64..10.0),
            b in proptest::array::uniform9(0.0f64..10.0),
            angles in proptest::array::uniform3(-3.2f64..3.2),
        ) {
            let mut t = triangle(&a);
            let mut u = triangle(&b);
            for p in &mut t { p.x = -0.1 - p.x; }
            for p in &mut u { p.x += 0.1; }
            let (t, u) = (t.map(|p| rotate(p, angles)), u.map(|p| rotate(p, angles)));
            prop_assume!(nondegenerate(t) && nondegenerate(u));
            prop_assert!(!triangles_intersect(t, u));
            prop_assert!(!triangles_intersect(u, t));
        }

        /// A triangle crossed transversally by an edge of another, through an interior point,
        /// intersects it whatever the argument and vertex order.
        #[test]
        fn pierced_triangles_intersect(
            a in proptest::array::uniform9(-10.0f64..10.0),
            w in proptest::array::uniform3(0.1f64..1.0),
            far in proptest::array::uniform3(-10.0f64..10.0),
            depth in proptest::array::uniform2(0.1f64..5.0),
        ) {
            let t = triangle(&a);
            let normal = triangle_area_vector_of(t);
            prop_assume!(normal.length() > 1.0);
            let n = normal.normalize();
            let sum = w[0] + w[1] + w[2];
            let x = (w[0] * t[0] + w[1] * t[1] + w[2] * t[2]) / sum;
            let (p, q) = (x + depth[0] * n, x - depth[1] * n);
            let u = [p, q, point(&far)];
            prop_assume!(nondegenerate(u));
            for k in 0..3 {
                let tk = [t[k], t[(k + 1) % 3], t[(k + 2) % 3]];
                prop_assert!(triangles_intersect(tk, u));
                prop_assert!(triangles_intersect(u, tk));
                prop_assert!(triangles_intersect([tk[0], tk[2], tk[1]], u));
            }
        }

        /// On a small integer grid (many exactly touching and coplanar configurations), the
        /// answer agrees with an exact separating-axis reference, is symmetric in the argument
        /// order and invariant under vertex rotation and reversal.
        #[test]
        fn grid_triangles_agree_with_separating_axes(
            mut a in proptest::array::uniform9(0i32..4),
            mut b in proptest::array::uniform9(0i32..4),
            flat in proptest::bool::ANY,
        ) {
            if flat {
                // Both in the plane z = 0: the coplanar cases.
                for k in [2, 5, 8] {
                    a[k] = 0;
                    b[k] = 0;
                }
            }
            let t = triangle(&a.map(f64::from));
            let u = triangle(&b.map(f64::from));
            if !(nondegenerate(t) && nondegenerate(u)) {
                return Ok(());
            }
            let r = triangles_intersect(t, u);
            prop_assert_eq!(r, !separating_axis_exists(a, b));
            prop_assert_eq!(triangles_intersect(u, t), r);
            prop_assert_eq!(triangles_intersect([t[1], t[2], t[0]], u), r);
            prop_assert_eq!(triangles_intersect(t, [u[2], u[1], u[0]]), r);
            prop_assert_eq!(triangles_intersect([u[2], u[0], u[1]], [t[0], t[2], t[1]]), r);
        }

        /// The shared-vertex and shared-edge tests do not depend on which triangle comes first
        /// or on the order of the other corners (integer grid: many exact coplanar cases).
        #[test]
        fn shared_corner_tests_are_symmetric(
            c in proptest::array::uniform12(0i32..3),
            flat in proptest::bool::ANY,
        ) {
            let z = |k: usize| if flat { 0.0 } else { f64::from(c[k]) };
            let p = |k: usize| v(f64::from(c[k]), f64::from(c[k + 1]), z(k + 2));
            let (o, a, b, d) = (p(0), p(3), p(6), p(9));
            let e = v(f64::from(c[2]), f64::from(c[5]), z(8));
            if !(nondegenerate([o, a, b]) && nondegenerate([o, d, e])) {
                return Ok(());
            }
            let r = meet_beyond_shared_vertex(o, a, b, d, e);
            prop_assert_eq!(meet_beyond_shared_vertex(o, b, a, d, e), r);
            prop_assert_eq!(meet_beyond_shared_vertex(o, d, e, a, b), r);
            prop_assert_eq!(meet_beyond_shared_vertex(o, e, d, b, a), r);
            if nondegenerate([o, a, d]) {
                let fold = folds_over_shared_edge(o, a, b, d);
                prop_assert_eq!(folds_over_shared_edge(a, o, b, d), fold);
                prop_assert_eq!(folds_over_shared_edge(o, a, d, b), fold);
            }
        }
    }

    /// Reference for integer triangles: closed triangles are disjoint iff their projections on
    /// one of the candidate axes (both normals, the 9 edge-edge cross products, and the in-plane
    /// edge normals that separate coplanar triangles) are disjoint. Exact in i64.
    fn separating_axis_exists(a: [i32; 9], b: [i32; 9]) -> bool {
        type V = [i64; 3];
        let pts = |c: [i32; 9]| -> [V; 3] { [0, 3, 6].map(|k| [c[k], c[k + 1], c[k + 2]].map(i64::from)) };
        let sub = |p: V, q: V| [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
        let cross =
            |p: V, q: V| [p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]];
        let dot = |p: V, q: V| p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
        let (t, u) = (pts(a), pts(b));
        let edges = |t: [V; 3]| [sub(t[1], t[0]), sub(t[2], t[1]), sub(t[0], t[2])];
        let (et, eu) = (edges(t), edges(u));
        let (nt, nu) = (cross(et[0], et[1]), cross(eu[0], eu[1]));
        let mut axes = vec![nt, nu];
        for i in 0..3 {
            axes.push(cross(nt, et[i]));
            axes.push(cross(nu, eu[i]));
            for &edge in &eu {
                axes.push(cross(et[i], edge));
            }
        }
        let range = |t: [V; 3], l: V| {
            let d = t.map(|p| dot(p, l));
            (d.iter().copied().min().unwrap_or(0), d.iter().copied().max().unwrap_or(0))
        };
        axes.into_iter().any(|l| {
            let ((t0, t1), (u0, u1)) = (range(t, l), range(u, l));
            t1 < u0 || u1 < t0
        })
    }

    fn triangle_area_vector_of(t: Triangle) -> DVec3 {
        super::super::triangle_area_vector(t[0], t[1], t[2])
    }
}
