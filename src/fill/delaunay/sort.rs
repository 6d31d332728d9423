//! The order of bulk insertion: a biased randomised insertion order (BRIO: Amenta, Choi and
//! Rote, "Incremental constructions con BRIO", 2003) whose rounds follow a Hilbert curve.
//!
//! The rounds keep the expected cost of a random order (each round's points are spread over
//! the whole set, so the tetrahedra they land in are small and their cavities too); the curve
//! within a round puts each point next to the one before, so the walk from the last tetrahedron
//! created is short and the tetrahedra it touches are still in the cache.

use std::ops::Range;

use super::SEED;
use crate::geometry::{Aabb, DVec3};
use crate::surface::family::SplitMix64;

/// Bits of each coordinate in a Hilbert index: a grid of 2^21 cells a side over the points'
/// bounding box (3 x 21 = 63 bits).
const HILBERT_BITS: u32 = 21;

/// The most points of the first round; the rounds after it double.
const FIRST_ROUND: usize = 64;

/// The indices of `points` in insertion order: shuffled with a fixed seed, cut into rounds that
/// double in size (the last holds half of the points, the one before a quarter, ...), each
/// round sorted along the Hilbert curve through the points' bounding box.
pub(super) fn insertion_order(points: &[DVec3]) -> Vec<u32> {
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    let mut rng = SplitMix64::new(SEED);
    for i in (1..order.len()).rev() {
        order.swap(i, rng.below(i + 1));
    }
    let keys = hilbert_keys(points);
    for round in rounds(order.len()) {
        order[round].sort_unstable_by_key(|&v| (keys[v as usize], v));
    }
    order
}

/// The rounds of `n` points: ..., `n/4..n/2`, `n/2..n`, the first of at most [`FIRST_ROUND`].
fn rounds(n: usize) -> Vec<Range<usize>> {
    let mut starts = vec![n];
    let mut start = n;
    while start > FIRST_ROUND {
        start /= 2;
        starts.push(start);
    }
    starts.push(0);
    starts.reverse();
    starts.windows(2).filter(|w| w[0] < w[1]).map(|w| w[0]..w[1]).collect()
}

/// The index of every point on the Hilbert curve of [`HILBERT_BITS`] through the points'
/// bounding box (scaled alike on every axis).
fn hilbert_keys(points: &[DVec3]) -> Vec<u64> {
    let bounds = Aabb::from_points(points);
    let extent = (bounds.max - bounds.min).max_element();
    let cells = ((1u64 << HILBERT_BITS) - 1) as f64;
    let scale = if extent > 0.0 { cells / extent } else { 0.0 };
    let cell = |x: f64| (x * scale).clamp(0.0, cells) as u32;
    points
        .iter()
        .map(|&p| {
            let q = p - bounds.min;
            hilbert_index([cell(q.x), cell(q.y), cell(q.z)], HILBERT_BITS)
        })
        .collect()
}

/// The position of grid cell `x` (coordinates of `bits` bits) along the 3D Hilbert curve
/// through the grid, by Skilling's method ("Programming the Hilbert curve", 2004): the
/// coordinates are turned, from the top bit down, into the curve's "transposed" index, whose
/// bits interleaved (top bit of x, y, z first) are the index.
pub(super) fn hilbert_index(mut x: [u32; 3], bits: u32) -> u64 {
    let top = 1u32 << (bits - 1);
    // Undo the rotations and reflections of the sub-cubes, top level first.
    let mut q = top;
    while q > 1 {
        let low = q - 1;
        for i in 0..3 {
            if x[i] & q != 0 {
                x[0] ^= low;
            } else {
                let swap = (x[0] ^ x[i]) & low;
                x[0] ^= swap;
                x[i] ^= swap;
            }
        }
        q >>= 1;
    }
    // Gray code.
    x[1] ^= x[0];
    x[2] ^= x[1];
    let mut flip = 0;
    let mut q = top;
    while q > 1 {
        if x[2] & q != 0 {
            flip ^= q - 1;
        }
        q >>= 1;
    }
    x.iter_mut().for_each(|c| *c ^= flip);
    let mut index = 0u64;
    for bit in (0..bits).rev() {
        for c in x {
            index = (index << 1) | u64::from((c >> bit) & 1);
        }
    }
    index
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The curve visits every cell of a grid once, each next to the one before.
    #[test]
    fn hilbert_index_walks_the_grid_by_neighbours() {
        for bits in 1..=4u32 {
            let side = 1u32 << bits;
            let mut cell_at = vec![None; (side * side * side) as usize];
            for x in 0..side {
                for y in 0..side {
                    for z in 0..side {
                        let i = hilbert_index([x, y, z], bits) as usize;
                        assert!(cell_at[i].is_none(), "two cells at index {i}");
                        cell_at[i] = Some([x, y, z]);
                    }
                }
            }
            let cells: Vec<[u32; 3]> = cell_at.into_iter().map(|c| c.expect("every index")).collect();
            for w in cells.windows(2) {
                let step: u32 = (0..3).map(|k| w[0][k].abs_diff(w[1][k])).sum();
                assert_eq!(step, 1, "{bits} bits: {:?} -> {:?}", w[0], w[1]);
            }
        }
    }

    #[test]
    fn rounds_double_up_to_half_the_points() {
        assert_eq!(rounds(0), Vec::<Range<usize>>::new());
        assert_eq!(rounds(50), vec![0..50]);
        assert_eq!(rounds(1000), vec![0..62, 62..125, 125..250, 250..500, 500..1000]);
    }

    #[test]
    fn order_is_a_fixed_permutation() {
        let points: Vec<DVec3> =
            (0..500).map(|i| DVec3::new((i % 7) as f64, (i % 11) as f64, i as f64)).collect();
        let order = insertion_order(&points);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..500).collect::<Vec<u32>>());
        assert_eq!(order, insertion_order(&points));
    }
}
