//! Exact geometric predicates (Shewchuk's adaptive arithmetic via the `robust` crate).
//!
//! One sign convention for the whole crate, matching [`super::tet_signed_volume`]:
//! `orient3d(a, b, c, d)` is `Positive` when `d` lies on the side that the right-hand normal of
//! triangle `(a, b, c)` points to, i.e. when tetrahedron `(a, b, c, d)` has positive volume in the
//! Gmsh/VTK convention. (The raw `robust::orient3d` has the opposite sign; never call it directly.)

use glam::DVec3;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Sign {
    Negative,
    Zero,
    Positive,
}

impl Sign {
    fn of(x: f64) -> Sign {
        if x > 0.0 {
            Sign::Positive
        } else if x < 0.0 {
            Sign::Negative
        } else {
            Sign::Zero
        }
    }

    pub fn flip(self) -> Sign {
        match self {
            Sign::Negative => Sign::Positive,
            Sign::Zero => Sign::Zero,
            Sign::Positive => Sign::Negative,
        }
    }
}

fn c3(p: DVec3) -> robust::Coord3D<f64> {
    robust::Coord3D { x: p.x, y: p.y, z: p.z }
}

/// Exact orientation of `d` relative to the oriented plane `(a, b, c)` (see module docs).
pub fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Sign {
    Sign::of(-robust::orient3d(c3(a), c3(b), c3(c), c3(d)))
}

/// Exact position of `e` relative to the sphere through `a, b, c, d`, a tetrahedron positive by
/// [`orient3d`]: `Positive` strictly inside, `Zero` on the sphere, `Negative` outside. (The raw
/// `robust::insphere` expects the opposite orientation; never call it directly.)
///
/// A semi-static filter first: the floating-point determinant (Shewchuk's expression, over the
/// coordinates relative to `e`) decides where it exceeds a bound on its error computed from
/// the largest relative coordinate on each axis, `X`, `Y`, `Z`: Shewchuk's bound is a multiple
/// of the determinant's permanent, which is at most `24 X Y Z (X^2 + Y^2 + Z^2)` (four lifted
/// terms, each at most `X^2 + Y^2 + Z^2` times three products of at most `2 X Y Z`). It is
/// cheaper than the permanent, and as exact: the adaptive predicate decides the rest.
pub fn insphere(a: DVec3, b: DVec3, c: DVec3, d: DVec3, e: DVec3) -> Sign {
    let (ae, be, ce, de) = (a - e, b - e, c - e, d - e);
    let det = insphere_determinant(ae, be, ce, de);
    let m = ae.abs().max(be.abs()).max(ce.abs()).max(de.abs());
    // Padded for the rounding of the permanent and of the bound itself.
    let bound = INSPHERE_ERROR_A * 24.000_01 * (m.x * m.y * m.z) * m.length_squared();
    // Below: the bound may have lost its accuracy to underflow.
    const SMALLEST_BOUND: f64 = 1e-250;
    if bound > SMALLEST_BOUND && det.abs() > bound {
        return if det > 0.0 { Sign::Negative } else { Sign::Positive };
    }
    Sign::of(-robust::insphere(c3(a), c3(b), c3(c), c3(d), c3(e)))
}

/// Relative error bound of the floating-point `insphere` determinant over its permanent
/// (Shewchuk's "isperrboundA").
const INSPHERE_ERROR_A: f64 = (16.0 + 224.0 * HALF_EPSILON) * HALF_EPSILON;

/// The determinant `robust::insphere` computes first (its sign for our orientation is the
/// opposite), of the corners relative to the tested point, in the same order of operations
/// (its error bound is for that order).
#[inline]
fn insphere_determinant(ae: DVec3, be: DVec3, ce: DVec3, de: DVec3) -> f64 {
    let ab = ae.x * be.y - be.x * ae.y;
    let bc = be.x * ce.y - ce.x * be.y;
    let cd = ce.x * de.y - de.x * ce.y;
    let da = de.x * ae.y - ae.x * de.y;
    let ac = ae.x * ce.y - ce.x * ae.y;
    let bd = be.x * de.y - de.x * be.y;
    let abc = ae.z * bc - be.z * ac + ce.z * ab;
    let bcd = be.z * cd - ce.z * bd + de.z * bc;
    let cda = ce.z * da + de.z * ac + ae.z * cd;
    let dab = de.z * ab + ae.z * bd + be.z * da;
    let lift = |p: DVec3| p.x * p.x + p.y * p.y + p.z * p.z;
    (lift(de) * abc - lift(ce) * dab) + (lift(be) * cda - lift(ae) * bcd)
}

/// [`insphere`] with the cospherical case decided by a symbolic perturbation, so that the answer
/// is never `Zero` for five distinct points. Every point is lifted onto the paraboloid
/// `|p|^2` plus an infinitesimal that is larger the later the point comes in lexicographic
/// `(x, y, z)` order, the larger ones infinitely so; the sign of the perturbed determinant is
/// that of its first non-zero term, taken from the latest point on:
/// - `e` itself: lifted above the sphere's hyperplane, it is outside (`Negative`);
/// - a corner: the hyperplane rises there, so `e` is inside exactly when it lies strictly on
///   that corner's side of the opposite face, the sign of [`orient3d`] with `e` in the
///   corner's place; when it is zero (`e` in that face's plane), the next point decides.
///
/// A perturbation depends on the point alone, so every test sees the same perturbed point set:
/// Delaunay's insertion algorithms work on it as on points in general position. Coincident
/// points are not perturbed apart (the answer is then `Negative`).
pub fn insphere_perturbed(a: DVec3, b: DVec3, c: DVec3, d: DVec3, e: DVec3) -> Sign {
    match insphere(a, b, c, d, e) {
        Sign::Zero => insphere_tie(a, b, c, d, e),
        exact => exact,
    }
}

/// [`insphere_perturbed`] where [`insphere`] is zero (`e` on the sphere): the perturbation's
/// verdict alone.
pub fn insphere_tie(a: DVec3, b: DVec3, c: DVec3, d: DVec3, e: DVec3) -> Sign {
    let mut latest_first = [(a, 0), (b, 1), (c, 2), (d, 3), (e, 4)];
    latest_first.sort_unstable_by(|p, q| lexicographic(q.0, p.0));
    let corners = [a, b, c, d];
    for (_, which) in latest_first {
        if which == 4 {
            return Sign::Negative;
        }
        let mut moved = corners;
        moved[which] = e;
        let side = orient3d(moved[0], moved[1], moved[2], moved[3]);
        if side != Sign::Zero {
            return side;
        }
    }
    Sign::Negative
}

/// The order of points by x, then y, then z (the order of [`insphere_perturbed`]).
pub fn lexicographic(p: DVec3, q: DVec3) -> std::cmp::Ordering {
    let by = |s: f64, t: f64| s.partial_cmp(&t).unwrap_or(std::cmp::Ordering::Equal);
    by(p.x, q.x).then(by(p.y, q.y)).then(by(p.z, q.z))
}

/// Whether `a`, `b` and `c` lie on one line (or coincide), exactly: the cross product of
/// `b - a` and `c - a` vanishes when its three components, the orientations of the points
/// projected on the three coordinate planes, all do.
pub fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    let on = |i: usize, j: usize| orient2d([a[i], a[j]], [b[i], b[j]], [c[i], c[j]]) == Sign::Zero;
    on(0, 1) && on(1, 2) && on(2, 0)
}

/// Relative error bound of the floating-point `orient3d` determinant over its permanent
/// (Shewchuk's first stage, "errboundA"), with the half-ulp epsilon of f64.
const ORIENT3D_ERROR_A: f64 = (7.0 + 56.0 * HALF_EPSILON) * HALF_EPSILON;
const HALF_EPSILON: f64 = f64::EPSILON / 2.0;

/// Exact [`orient3d`] for many tetrahedra whose points all lie in one box (the corners and
/// centres of one cell): a static error bound from the box's extents decides the sign from the
/// plain floating-point determinant, and only the near-degenerate cases go to the adaptive
/// predicate. Every coordinate difference is at most the extent on its axis, so the permanent
/// that bounds the determinant's error is at most 6 ex ey ez (padded for rounding).
#[derive(Clone, Copy, Debug)]
pub struct BoxedOrient3d {
    bound: f64,
}

impl BoxedOrient3d {
    /// For points inside the box of `points`, or means of up to 8 of them computed in floating
    /// point (they may round out of the box by a few ulps of the coordinates: padded for).
    pub fn new(points: &[DVec3]) -> Self {
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for &p in points {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        let magnitude = lo.abs().max(hi.abs());
        let e = (hi - lo + magnitude * (32.0 * f64::EPSILON)) * (1.0 + 1e-12);
        // The permanent's six terms, each an x, a y and a z difference; 1% pad for rounding.
        BoxedOrient3d { bound: ORIENT3D_ERROR_A * 6.06 * e.x * e.y * e.z }
    }

    /// [`orient3d`] of points inside the box (a point outside it gives a wrong answer).
    #[inline]
    pub fn orient3d(&self, a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Sign {
        let (ad, bd, cd) = (a - d, b - d, c - d);
        // The determinant robust::orient3d computes, negated for our convention.
        let det = -(ad.z * (bd.x * cd.y - cd.x * bd.y)
            + bd.z * (cd.x * ad.y - ad.x * cd.y)
            + cd.z * (ad.x * bd.y - bd.x * ad.y));
        if !(det.abs() > self.bound) {
            return orient3d(a, b, c, d);
        }
        if det > 0.0 {
            Sign::Positive
        } else {
            Sign::Negative
        }
    }
}

/// Exact orientation of 2D points: `Positive` when `(a, b, c)` turn counter-clockwise.
pub fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> Sign {
    let p = |v: [f64; 2]| robust::Coord { x: v[0], y: v[1] };
    Sign::of(robust::orient2d(p(a), p(b), p(c)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::tet_signed_volume;
    use proptest::prelude::*;

    #[test]
    fn unit_tet_is_positive() {
        let (a, b, c, d) = (DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z);
        assert_eq!(orient3d(a, b, c, d), Sign::Positive);
        assert_eq!(orient3d(a, c, b, d), Sign::Negative);
        assert_eq!(orient3d(a, b, c, DVec3::new(0.3, 0.3, 0.0)), Sign::Zero);
    }

    #[test]
    fn orient2d_ccw_is_positive() {
        assert_eq!(orient2d([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]), Sign::Positive);
        assert_eq!(orient2d([0.0, 0.0], [1.0, 1.0], [2.0, 2.0]), Sign::Zero);
    }

    #[test]
    fn insphere_is_positive_inside_a_positive_tet() {
        let (a, b, c, d) = (DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z);
        assert_eq!(orient3d(a, b, c, d), Sign::Positive);
        assert_eq!(insphere(a, b, c, d, DVec3::splat(0.25)), Sign::Positive);
        assert_eq!(insphere(a, b, c, d, DVec3::splat(2.0)), Sign::Negative);
        assert_eq!(insphere(a, b, c, d, DVec3::ONE), Sign::Zero, "a cube's corners share a sphere");
    }

    /// On the eight corners of a cube every insphere is zero; the perturbed one is never zero,
    /// and it agrees with a lifting in which a later point (lexicographic) rises more: the
    /// corner (1, 1, 1), latest of all, is outside every sphere of the others.
    #[test]
    fn perturbed_insphere_decides_cospherical_points() {
        let corner = |i: u32| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64);
        let latest = DVec3::ONE;
        for t in 0..8u32.pow(4) {
            let mut tet = [t % 8, t / 8 % 8, t / 64 % 8, t / 512].map(corner);
            if orient3d(tet[0], tet[1], tet[2], tet[3]) != Sign::Positive || tet.contains(&latest) {
                tet.swap(0, 1);
                if orient3d(tet[0], tet[1], tet[2], tet[3]) != Sign::Positive || tet.contains(&latest) {
                    continue;
                }
            }
            let [a, b, c, d] = tet;
            assert_eq!(insphere(a, b, c, d, latest), Sign::Zero);
            assert_eq!(insphere_perturbed(a, b, c, d, latest), Sign::Negative);
            for e in (0..8).map(corner).filter(|e| !tet.contains(e)) {
                assert_ne!(insphere_perturbed(a, b, c, d, e), Sign::Zero);
            }
        }
    }

    #[test]
    fn collinear_is_exact() {
        // a + 3 (b - a), exactly.
        let (a, b) = (DVec3::new(0.5, 0.25, 1.0), DVec3::new(1.5, 2.25, -1.0));
        assert!(collinear(a, b, DVec3::new(3.5, 6.25, -5.0)));
        assert!(collinear(a, a, b));
        let (o, c) = (DVec3::ZERO, DVec3::new(2.0, 2.0, 2.0 + 2f64.powi(-50)));
        assert!(collinear(o, DVec3::ONE, DVec3::splat(2.0)));
        assert!(!collinear(o, DVec3::ONE, c), "two ulps off the line");
    }

    proptest! {
        /// Where the floating-point volume is clearly non-zero, the exact sign agrees with it,
        /// and swapping two vertices flips the sign.
        #[test]
        fn agrees_with_float_volume(p in proptest::array::uniform12(-10.0f64..10.0)) {
            let a = DVec3::new(p[0], p[1], p[2]);
            let b = DVec3::new(p[3], p[4], p[5]);
            let c = DVec3::new(p[6], p[7], p[8]);
            let d = DVec3::new(p[9], p[10], p[11]);
            let v = tet_signed_volume(a, b, c, d);
            let s = orient3d(a, b, c, d);
            if v.abs() > 1e-6 {
                prop_assert_eq!(s, if v > 0.0 { Sign::Positive } else { Sign::Negative });
            }
            prop_assert_eq!(orient3d(b, a, c, d), s.flip());
        }

        /// The filtered insphere gives the adaptive predicate's sign, also for points on or
        /// within a hair of the sphere, and in tiny or far boxes.
        #[test]
        fn insphere_filter_agrees_with_exact(
            p in proptest::array::uniform12(-1.0f64..1.0),
            q in proptest::array::uniform3(-1.0f64..1.0),
            off in prop_oneof![Just(0.0), 1e-18f64..1e-12, 1e-6f64..1.0],
            offset in prop_oneof![Just(0.0), -1e6f64..1e6],
            scale in prop_oneof![Just(1.0), 1e-9f64..1e-3, 1e3f64..1e9],
        ) {
            // Four corners and a fifth point on (or off by `off`) the unit sphere around 0.
            let on_sphere = |x: f64, y: f64, z: f64| {
                let v = DVec3::new(x, y, z);
                if v.length() > 1e-3 { v.normalize() } else { DVec3::X }
            };
            let corner = |i: usize| on_sphere(p[i], p[i + 1], p[i + 2]) * scale + DVec3::splat(offset);
            let (mut a, mut b, c, d) = (corner(0), corner(3), corner(6), corner(9));
            if orient3d(a, b, c, d) == Sign::Negative {
                std::mem::swap(&mut a, &mut b);
            }
            let e = on_sphere(q[0], q[1], q[2]) * (1.0 + off) * scale + DVec3::splat(offset);
            let exact = Sign::of(-robust::insphere(c3(a), c3(b), c3(c), c3(d), c3(e)));
            prop_assert_eq!(insphere(a, b, c, d, e), exact);
            prop_assert_eq!(insphere(a, b, c, d, a), Sign::Zero);
        }

        /// The boxed filter gives the exact sign, also for nearly flat tetrahedra (d pulled
        /// towards the plane of a, b, c by a tiny amount) and for points in a tiny far box.
        #[test]
        fn boxed_agrees_with_exact(
            p in proptest::array::uniform12(-1.0f64..1.0),
            flatness in prop_oneof![Just(0.0), 1e-18f64..1e-12, 1e-6f64..1.0],
            offset in prop_oneof![Just(0.0), -1e6f64..1e6],
            scale in prop_oneof![Just(1.0), 1e-9f64..1e-3],
        ) {
            let q = |i: usize| DVec3::new(p[i], p[i + 1], p[i + 2]) * scale + DVec3::splat(offset);
            let (a, b, c) = (q(0), q(3), q(6));
            // d near the plane of a, b, c: a point of it plus a small normal offset.
            let on_plane = a + (b - a) * p[9].abs() + (c - a) * p[10].abs() * 0.5;
            let d = on_plane + (b - a).cross(c - a) * flatness * p[11];
            let filter = BoxedOrient3d::new(&[a, b, c, d]);
            prop_assert_eq!(filter.orient3d(a, b, c, d), orient3d(a, b, c, d));
            prop_assert_eq!(filter.orient3d(b, a, c, d), orient3d(b, a, c, d));
            prop_assert_eq!(filter.orient3d(d, b, c, a), orient3d(d, b, c, a));
        }
    }
}
