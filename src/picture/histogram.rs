//! A bar chart of a quality measure (bars and axes, no text: the title goes in the file name).

use tiny_skia::{Pixmap, Rect, Transform};

use super::cut::{blank, paint};

const BAR_COLOUR: [u8; 3] = [70, 130, 180];
const AXIS_COLOUR: [u8; 3] = [0, 0, 0];

/// Most bins of a [`histogram`].
const MAX_BINS: usize = 1 << 16;

/// Counts of `values` in `bins` equal bins over `range` (bins clamped to 1..=65536); values
/// outside the range count in the end bins, NaN nowhere. An empty or non-finite range counts
/// nothing.
pub fn histogram(values: &[f64], bins: usize, (lo, hi): (f64, f64)) -> Vec<usize> {
    let bins = bins.clamp(1, MAX_BINS);
    let mut counts = vec![0; bins];
    if !(lo < hi && (hi - lo).is_finite()) {
        return counts;
    }
    for &x in values.iter().filter(|x| !x.is_nan()) {
        let at = ((x - lo) / (hi - lo) * bins as f64).floor().clamp(0.0, (bins - 1) as f64);
        counts[at as usize] += 1;
    }
    counts
}

/// The plot area of a `width` x `height` histogram: (left, top, right, bottom) in pixels.
fn plot_area(width: u32, height: u32) -> (f32, f32, f32, f32) {
    let (w, h) = (width as f32, height as f32);
    ((0.05 * w).max(2.0), (0.05 * h).max(1.0), w - (0.03 * w).max(1.0), h - (0.06 * h).max(2.0))
}

/// A bar chart of [`histogram`]`(values, bins, range)` on a white background: bar heights are
/// proportional to the counts, the tallest bar filling the plot height; an axis line below
/// and on the left. Sides are clamped to 1..=8192 pixels; bins to at most one per pixel.
pub fn histogram_picture(values: &[f64], bins: usize, range: (f64, f64), width: u32, height: u32) -> Pixmap {
    let mut pixmap = blank(width, height);
    let (left, top, right, bottom) = plot_area(pixmap.width(), pixmap.height());
    let counts = histogram(values, bins.min(pixmap.width() as usize), range);
    let tallest = counts.iter().copied().max().unwrap_or(0).max(1) as f32;
    let bin_width = (right - left) / counts.len() as f32;
    let gap = if bin_width >= 4.0 { 0.15 * bin_width } else { 0.0 };
    let mut bar = paint(BAR_COLOUR);
    bar.anti_alias = false;
    for (i, &count) in counts.iter().enumerate() {
        let x = left + i as f32 * bin_width + 0.5 * gap;
        let y = bottom - (bottom - top) * count as f32 / tallest;
        if let Some(r) = Rect::from_ltrb(x, y, x + bin_width - gap, bottom) {
            pixmap.fill_rect(r, &bar, Transform::identity(), None);
        }
    }
    let axis = paint(AXIS_COLOUR);
    for r in [
        Rect::from_ltrb(left - 1.5, bottom, right, bottom + 1.5),
        Rect::from_ltrb(left - 1.5, top, left, bottom),
    ]
    .into_iter()
    .flatten()
    {
        pixmap.fill_rect(r, &axis, Transform::identity(), None);
    }
    pixmap
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_clamp_to_the_end_bins_and_skip_nan() {
        let values = [-1.0, 0.0, 0.1, 0.5, 0.99, 1.0, 7.0, f64::NAN];
        assert_eq!(histogram(&values, 2, (0.0, 1.0)), vec![3, 4]);
        assert_eq!(histogram(&values, 0, (0.0, 1.0)), vec![7]);
        assert_eq!(histogram(&values, usize::MAX, (0.0, 1.0)).len(), MAX_BINS);
        assert_eq!(histogram(&values, 3, (1.0, 1.0)), vec![0, 0, 0]);
        assert_eq!(histogram(&values, 1, (f64::NAN, 1.0)), vec![0]);
    }

    /// Pixels of the bar colour in column `x`.
    fn bar_height(pixmap: &Pixmap, x: u32) -> u32 {
        let [r, g, b] = BAR_COLOUR;
        (0..pixmap.height())
            .filter(|&y| pixmap.pixel(x, y).is_some_and(|p| (p.red(), p.green(), p.blue()) == (r, g, b)))
            .count() as u32
    }

    #[test]
    fn bar_heights_are_proportional_to_counts() {
        let counts = [1usize, 2, 4, 3];
        let values: Vec<f64> =
            counts.iter().enumerate().flat_map(|(i, &c)| vec![(i as f64 + 0.5) / 4.0; c]).collect();
        let (width, height) = (400, 300);
        let pixmap = histogram_picture(&values, 4, (0.0, 1.0), width, height);
        let (left, top, right, bottom) = plot_area(width, height);
        let bin = (right - left) / 4.0;
        let heights: Vec<u32> =
            (0..4).map(|i| bar_height(&pixmap, (left + (i as f32 + 0.5) * bin) as u32)).collect();
        let full = bottom - top;
        for (h, c) in heights.iter().zip(counts) {
            let expected = full * c as f32 / 4.0;
            assert!((*h as f32 - expected).abs() <= 1.0, "bar of count {c}: {h} px, expected {expected}");
        }
        assert_eq!(bar_height(&pixmap, (left + 0.01 * bin) as u32), 0, "gap between bars");
        for (w, h) in [(0, 0), (1, 1), (3, 2), (100_000, 5)] {
            let tiny = histogram_picture(&values, usize::MAX, (0.0, 1.0), w, h);
            assert_eq!((tiny.width(), tiny.height()), (w.clamp(1, 8192), h.clamp(1, 8192)));
        }
    }
}
