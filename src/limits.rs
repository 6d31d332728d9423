//! The accepted input ranges.
//!
//! Every stage sizes some work from lengths (grid cells, samples along an edge, divisions of a
//! box); outside these ranges such ratios overflow, and thin layers drown in round-off. The
//! surface validation and the pipeline reject inputs beyond them, naming where. See
//! `docs/input-ranges.md`.

/// The largest accepted magnitude of a coordinate: far below where squared lengths, volumes
/// and grid cell indices lose their meaning in `f64` and `i64`.
pub const MAX_COORDINATE: f64 = 1e12;

/// The smallest accepted body (bounding-box diagonal), relative to its largest coordinate
/// magnitude (or to 1 when every coordinate is smaller): a body of fewer than about 1e4
/// distinct `f64` positions across cannot be meshed meaningfully.
pub const MIN_BODY_RATIO: f64 = 1e-12;

/// The smallest accepted first layer height, relative to the largest coordinate magnitude (or
/// the body size, if larger): the height then spans some 5e7 `f64` steps where it stands.
/// Thinner layers come out of round-off as much as out of the geometry, and the volume check
/// of the mesh can no longer confirm them (layers 1e-9 of a coarse unit body already fail it).
pub const MIN_HEIGHT_RATIO: f64 = 1e-8;

/// Whether a coordinate is in the accepted range (finite and at most [`MAX_COORDINATE`]).
pub fn coordinate_in_range(x: f64) -> bool {
    x.abs() <= MAX_COORDINATE
}

/// The smallest accepted body size for a surface whose largest coordinate magnitude is
/// `largest`.
pub fn smallest_body(largest: f64) -> f64 {
    MIN_BODY_RATIO * largest.max(1.0)
}

/// Why a first layer height `h` makes no sense on a body of size `body_size` whose largest
/// coordinate magnitude is `largest`, if it does not.
pub fn first_height_problem(h: f64, body_size: f64, largest: f64) -> Option<String> {
    let (reference, what) = if largest >= body_size {
        (largest, "the largest coordinate magnitude")
    } else {
        (body_size, "the body size")
    };
    if h < MIN_HEIGHT_RATIO * reference {
        Some(format!(
            "is below {MIN_HEIGHT_RATIO:e} of {what} {reference:e}, too thin for double precision there \
             (is the surface in other units, or far from the origin?)"
        ))
    } else if h > body_size {
        Some(format!("is above the body size {body_size:e} (is the surface in other units?)"))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges() {
        assert!(coordinate_in_range(-1e12) && !coordinate_in_range(1.0001e12));
        assert!(!coordinate_in_range(f64::NAN) && !coordinate_in_range(f64::INFINITY));
        assert_eq!(smallest_body(0.5), 1e-12);
        assert_eq!(smallest_body(1e6), 1e-6);
        assert!(first_height_problem(1e-3, 1.0, 1.0).is_none());
        assert!(first_height_problem(2e-8, 2.0, 0.5).is_none());
        assert!(first_height_problem(1e-9, 2.0, 0.5).unwrap().contains("body size 2e0"));
        assert!(first_height_problem(1e-6, 1.0, 1e3).unwrap().contains("coordinate magnitude 1e3"));
        assert!(first_height_problem(2.0, 1.0, 1.0).unwrap().contains("above"));
    }
}
