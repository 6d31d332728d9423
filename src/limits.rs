//! The accepted input ranges, and checked sizes for work computed from geometry.
//!
//! Every stage sizes some work from lengths (grid cells, samples along an edge, divisions of a
//! box). Inside the ranges below those sizes stay small; [`checked_count`] turns any size
//! computed from a ratio of lengths into a clear error instead of an overflow or an allocation
//! that cannot succeed. See `docs/input-ranges.md`.

/// The largest accepted magnitude of a coordinate: far below where squared lengths, volumes
/// and grid cell indices lose their meaning in `f64` and `i64`.
pub const MAX_COORDINATE: f64 = 1e12;

/// The smallest accepted body (bounding-box diagonal), relative to its largest coordinate
/// magnitude (or to 1 when every coordinate is smaller): a body of fewer than about 1e4
/// distinct `f64` positions across cannot be meshed meaningfully.
pub const MIN_BODY_RATIO: f64 = 1e-12;

/// The smallest accepted first layer height, relative to the body size and to the largest
/// coordinate magnitude (a height must span thousands of `f64` steps where it stands); the
/// largest is the body size itself.
pub const MIN_HEIGHT_RATIO: f64 = 1e-12;

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
    if h < MIN_HEIGHT_RATIO * body_size {
        Some(format!(
            "is below {MIN_HEIGHT_RATIO:e} of the body size {body_size:e} (is the surface in other units?)"
        ))
    } else if h < MIN_HEIGHT_RATIO * largest {
        Some(format!(
            "is below {MIN_HEIGHT_RATIO:e} of the largest coordinate magnitude {largest:e}, too thin to be \
             resolved there (move the surface nearer the origin)"
        ))
    } else if h > body_size {
        Some(format!("is above the body size {body_size:e} (is the surface in other units?)"))
    } else {
        None
    }
}

/// A size computed from geometry that is beyond what the stage can do.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{what} would be {value:e}, more than the {max} allowed")]
pub struct SizeError {
    pub what: &'static str,
    pub value: f64,
    pub max: usize,
}

/// `ceil(x)` as a count of at least 1 and at most `max`; an error names `what` otherwise (also
/// for NaN).
pub fn checked_count(x: f64, max: usize, what: &'static str) -> Result<usize, SizeError> {
    let n = x.ceil();
    if n <= max as f64 {
        Ok((n as usize).max(1))
    } else {
        Err(SizeError { what, value: x, max })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_are_bounded_and_nan_is_an_error() {
        assert_eq!(checked_count(0.0, 10, "samples"), Ok(1));
        assert_eq!(checked_count(2.5, 10, "samples"), Ok(3));
        assert_eq!(checked_count(10.0, 10, "samples"), Ok(10));
        let e = checked_count(1e19, 10, "samples").unwrap_err();
        assert_eq!(e.to_string(), "samples would be 1e19, more than the 10 allowed");
        assert!(checked_count(f64::NAN, 10, "samples").is_err());
        assert!(checked_count(f64::INFINITY, usize::MAX, "samples").is_err());
    }

    #[test]
    fn ranges() {
        assert!(coordinate_in_range(-1e12) && !coordinate_in_range(1.0001e12));
        assert!(!coordinate_in_range(f64::NAN) && !coordinate_in_range(f64::INFINITY));
        assert_eq!(smallest_body(0.5), 1e-12);
        assert_eq!(smallest_body(1e6), 1e-6);
        assert!(first_height_problem(1e-3, 1.0, 1.0).is_none());
        assert!(first_height_problem(1e-13, 1.0, 1.0).unwrap().contains("body size"));
        assert!(first_height_problem(1e-6, 1.0, 1e8).unwrap().contains("coordinate magnitude"));
        assert!(first_height_problem(2.0, 1.0, 1.0).unwrap().contains("above"));
    }
}
