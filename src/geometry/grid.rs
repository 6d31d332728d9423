//! Broad phase for many small boxes: a uniform grid, sorted by cell. Every pair of boxes that
//! overlap is reported once, from the cell holding the low corner of their overlap.

use rayon::prelude::*;

use super::{Aabb, DVec3};

/// Cells per axis are packed in 21 bits each.
const AXIS_BITS: u32 = 21;
const AXIS_MAX: i64 = (1 << AXIS_BITS) - 1;
/// A box spanning more cells than this stays out of the grid (the grid is sized by the mean box).
const MAX_CELLS_PER_BOX: i64 = 4096;

/// The pairs `(a, b)`, `a < b`, of overlapping (touching counts) boxes with at least one of them
/// a query (`is_query[i]`), each once, in no particular order (but the same every run).
pub fn overlapping_pairs(boxes: &[Aabb], is_query: &[bool]) -> Vec<(u32, u32)> {
    overlapping_pairs_where(boxes, is_query, |_, _| true)
}

/// [`overlapping_pairs`] among the pairs that `keep` accepts (tested before any is stored).
pub fn overlapping_pairs_where(
    boxes: &[Aabb],
    is_query: &[bool],
    keep: impl Fn(u32, u32) -> bool + Sync,
) -> Vec<(u32, u32)> {
    if boxes.len() < 2 {
        return Vec::new();
    }
    let mut bounds = Aabb::empty();
    let mut extent = 0.0;
    for b in boxes {
        bounds.grow(b.min);
        bounds.grow(b.max);
        extent += (b.max - b.min).max_element();
    }
    let span = (bounds.max - bounds.min).max_element();
    // About the mean box size, but never more than AXIS_MAX cells across the whole set.
    let cell = (2.0 * extent / boxes.len() as f64).max(span / AXIS_MAX as f64).max(f64::MIN_POSITIVE);
    let cell_of = |p: DVec3| {
        let q = ((p - bounds.min) / cell).floor();
        [q.x as i64, q.y as i64, q.z as i64].map(|c| c.clamp(0, AXIS_MAX))
    };
    let key = |c: [i64; 3]| ((c[0] as u64) << (2 * AXIS_BITS)) | ((c[1] as u64) << AXIS_BITS) | c[2] as u64;
    let cells_of = |b: &Aabb| {
        let (lo, hi) = (cell_of(b.min), cell_of(b.max));
        ((0..3).map(|a| hi[a] - lo[a] + 1).product::<i64>(), lo, hi)
    };
    // Boxes spanning too many cells stay out of the grid and meet every box directly.
    let big: Vec<u32> =
        (0..boxes.len() as u32).filter(|&i| cells_of(&boxes[i as usize]).0 > MAX_CELLS_PER_BOX).collect();
    let mut entries: Vec<(u64, u32)> = boxes
        .par_iter()
        .enumerate()
        .filter(|(_, b)| cells_of(b).0 <= MAX_CELLS_PER_BOX)
        .flat_map_iter(|(i, b)| {
            let (_, lo, hi) = cells_of(b);
            (lo[0]..=hi[0]).flat_map(move |x| {
                (lo[1]..=hi[1]).flat_map(move |y| (lo[2]..=hi[2]).map(move |z| (key([x, y, z]), i as u32)))
            })
        })
        .collect();
    entries.par_sort_unstable();
    // The low cell of each box: the overlap of two boxes starts in the larger of their low cells.
    let low: Vec<[i64; 3]> = boxes.par_iter().map(|b| cell_of(b.min)).collect();
    let groups: Vec<&[(u64, u32)]> = entries.chunk_by(|a, b| a.0 == b.0).collect();
    let mut pairs: Vec<(u32, u32)> = groups
        .par_iter()
        .flat_map_iter(|group| {
            // Sweep the cell's boxes by their low x: a box meets only those starting before it
            // ends along x.
            let mut by_x: Vec<(f64, u32)> =
                group.iter().map(|&(_, b)| (boxes[b as usize].min.x, b)).collect();
            by_x.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            let k = group[0].0;
            let mut out = Vec::new();
            for (i, &(_, a)) in by_x.iter().enumerate() {
                let ba = &boxes[a as usize];
                for &(min_x, b) in &by_x[i + 1..] {
                    if min_x > ba.max.x {
                        break;
                    }
                    let bb = &boxes[b as usize];
                    if !(is_query[a as usize] || is_query[b as usize]) || !ba.overlaps(bb) {
                        continue;
                    }
                    // Report from one cell only.
                    let (la, lb) = (low[a as usize], low[b as usize]);
                    if key([la[0].max(lb[0]), la[1].max(lb[1]), la[2].max(lb[2])]) == k
                        && keep(a.min(b), a.max(b))
                    {
                        out.push((a.min(b), a.max(b)));
                    }
                }
            }
            out
        })
        .collect();
    // The boxes out of the grid meet every box directly (a pair of two of them twice).
    let mut with_big = Vec::new();
    for &b in &big {
        for a in 0..boxes.len() as u32 {
            if a != b
                && (is_query[a as usize] || is_query[b as usize])
                && boxes[a as usize].overlaps(&boxes[b as usize])
                && keep(a.min(b), a.max(b))
            {
                with_big.push((a.min(b), a.max(b)));
            }
        }
    }
    with_big.sort_unstable();
    with_big.dedup();
    pairs.extend(with_big);
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn sorted(mut pairs: Vec<(u32, u32)>) -> Vec<(u32, u32)> {
        pairs.sort_unstable();
        pairs
    }

    fn brute(boxes: &[Aabb], q: &[bool]) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        for a in 0..boxes.len() {
            for b in a + 1..boxes.len() {
                if (q[a] || q[b]) && boxes[a].overlaps(&boxes[b]) {
                    out.push((a as u32, b as u32));
                }
            }
        }
        out
    }

    proptest! {
        /// The grid finds exactly the overlapping pairs a brute force finds.
        #[test]
        fn agrees_with_brute_force(raw in proptest::collection::vec(
            (proptest::array::uniform3(-10.0f64..10.0), proptest::array::uniform3(0.0f64..3.0), any::<bool>()), 2..60)) {
            let boxes: Vec<Aabb> = raw.iter().map(|(p, s, _)| {
                let min = DVec3::from_array(*p);
                Aabb { min, max: min + DVec3::from_array(*s) }
            }).collect();
            let q: Vec<bool> = raw.iter().map(|r| r.2).collect();
            prop_assert_eq!(sorted(overlapping_pairs(&boxes, &q)), brute(&boxes, &q));
        }
    }

    #[test]
    fn a_huge_box_meets_all_small_ones() {
        let mut boxes: Vec<Aabb> = (0..100)
            .map(|i| Aabb { min: DVec3::splat(i as f64 * 0.01), max: DVec3::splat(i as f64 * 0.01 + 0.001) })
            .collect();
        boxes.push(Aabb { min: DVec3::splat(-1e6), max: DVec3::splat(1e6) });
        let q = vec![true; boxes.len()];
        assert_eq!(sorted(overlapping_pairs(&boxes, &q)), brute(&boxes, &q));
    }
}
