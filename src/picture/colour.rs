//! Colours of the pictures: one light colour per cell kind, and a ramp for the scaled Jacobian
//! (red = bad, green then blue = good), quantised so that a cut is drawn in a few fills.

use crate::mesh::CellKind;
use crate::quality::measures::{scaled_jacobian, CellPoints};

/// How the cut cells are filled.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Colouring {
    /// One light colour per kind ([`kind_colour`]).
    #[default]
    Kind,
    /// The cell's scaled Jacobian on a colour ramp ([`quality_colour`]).
    Quality,
}

/// Steps of the quality ramp over (0, 1]; scaled Jacobians <= 0 (invalid cells) get their own.
const QUALITY_STEPS: usize = 20;

/// Quality ramp stops: (scaled Jacobian, colour).
const RAMP: [(f64, [u8; 3]); 5] = [
    (0.0, [215, 48, 39]),
    (0.3, [244, 165, 60]),
    (0.55, [240, 220, 90]),
    (0.8, [120, 198, 110]),
    (1.0, [70, 140, 210]),
];

const INVALID_COLOUR: [u8; 3] = [110, 10, 10];

/// Fill colour of a cell kind: light blue tetrahedra, yellow pyramids, green prisms, salmon hexahedra.
pub fn kind_colour(kind: CellKind) -> [u8; 3] {
    match kind {
        CellKind::Tetrahedron => [180, 205, 240],
        CellKind::Pyramid => [250, 220, 130],
        CellKind::Prism => [175, 225, 165],
        CellKind::Hexahedron => [245, 180, 160],
    }
}

/// Fill colour of a cell of this scaled Jacobian (the ramp at the centre of its step; dark red
/// for an invalid cell, <= 0 or NaN).
pub fn quality_colour(scaled_jacobian: f64) -> [u8; 3] {
    bucket_colour(Colouring::Quality, quality_bucket(scaled_jacobian))
}

fn quality_bucket(q: f64) -> usize {
    if q > 0.0 {
        1 + ((q * QUALITY_STEPS as f64) as usize).min(QUALITY_STEPS - 1)
    } else {
        0
    }
}

fn ramp(q: f64) -> [u8; 3] {
    let upper = RAMP.iter().position(|&(at, _)| at >= q).unwrap_or(RAMP.len() - 1).max(1);
    let ((q0, c0), (q1, c1)) = (RAMP[upper - 1], RAMP[upper]);
    let t = ((q - q0) / (q1 - q0)).clamp(0.0, 1.0);
    std::array::from_fn(|i| (f64::from(c0[i]) + t * (f64::from(c1[i]) - f64::from(c0[i]))).round() as u8)
}

impl Colouring {
    /// Number of distinct fill colours (the cells are drawn in one fill per colour).
    pub(super) fn buckets(self) -> usize {
        match self {
            Colouring::Kind => CellKind::ALL.len(),
            Colouring::Quality => QUALITY_STEPS + 1,
        }
    }

    /// The fill colour index of a cell (`x`: its points in space).
    pub(super) fn bucket(self, kind: CellKind, x: &CellPoints) -> usize {
        match self {
            Colouring::Kind => kind as usize,
            Colouring::Quality => quality_bucket(scaled_jacobian(kind, x)),
        }
    }
}

pub(super) fn bucket_colour(colouring: Colouring, bucket: usize) -> [u8; 3] {
    match colouring {
        Colouring::Kind => kind_colour(CellKind::ALL[bucket.min(CellKind::ALL.len() - 1)]),
        Colouring::Quality if bucket == 0 => INVALID_COLOUR,
        Colouring::Quality => ramp((bucket as f64 - 0.5) / QUALITY_STEPS as f64),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_have_distinct_colours() {
        for a in CellKind::ALL {
            for b in CellKind::ALL {
                assert_eq!(a == b, kind_colour(a) == kind_colour(b));
            }
        }
    }

    #[test]
    fn quality_ramp_goes_from_red_to_blue() {
        let [r, g, b] = quality_colour(0.01);
        assert!(r > 200 && g < 80 && b < 60, "bad is red: {r} {g} {b}");
        let [r, _, b] = quality_colour(1.0);
        assert!(b > 180 && r < 100, "good is blue: {r} {b}");
        assert_eq!(quality_colour(-0.5), INVALID_COLOUR);
        assert_eq!(quality_colour(f64::NAN), INVALID_COLOUR);
        assert_eq!(quality_colour(0.71), quality_colour(0.74), "same step, same colour");
        assert_eq!(quality_colour(7.0), quality_colour(1.0));
    }
}
