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
    }
}
