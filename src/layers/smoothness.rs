//! How smoothly the layers end and grow (the report's smoothness): neighbouring wall
//! vertices should end at similar thicknesses, consecutive layers should grow by at most the
//! growth ratio, and a stack ended at isotropy should end with a last layer about as high as the
//! front is wide there.

use serde::Serialize;

use super::front::Columns;
use super::tuning::TUNING;
use crate::surface::Surface;

/// A distribution of ratios: quantiles, the largest, and the fraction within a tolerance band.
#[derive(Clone, Debug, Default, Serialize)]
pub struct RatioStats {
    pub count: usize,
    pub median: f64,
    pub p95: f64,
    pub max: f64,
    /// Fraction of the ratios within the band given where it is computed.
    pub within_band: f64,
    /// Counts in bins between powers of sqrt(2): bin `i` holds the ratios in
    /// `[sqrt2^(i-5), sqrt2^(i-4))` for `i` in 1..=8, bin 0 those below 1/4 and bin 9 those
    /// from 4 up (so bins 4 and 5 are [1/sqrt 2, 1) and [1, sqrt 2)).
    pub histogram: [usize; HISTOGRAM_BINS],
}

/// Bins of [`RatioStats::histogram`].
pub const HISTOGRAM_BINS: usize = 10;

/// The histogram bin of a ratio (see [`RatioStats::histogram`]).
fn histogram_bin(r: f64) -> usize {
    let i = (2.0 * r.log2()).floor() + 5.0;
    i.clamp(0.0, (HISTOGRAM_BINS - 1) as f64) as usize
}

impl RatioStats {
    /// Stats of `ratios` (all >= 1 or all two-sided), counting those within [lo, hi].
    pub fn of(mut ratios: Vec<f64>, lo: f64, hi: f64) -> RatioStats {
        ratios.retain(|r| r.is_finite());
        if ratios.is_empty() {
            return RatioStats::default();
        }
        ratios.sort_by(f64::total_cmp);
        let at = |q: f64| ratios[((ratios.len() - 1) as f64 * q).round() as usize];
        let within = ratios.iter().filter(|&&r| (lo..=hi).contains(&r)).count();
        let mut histogram = [0; HISTOGRAM_BINS];
        for &r in &ratios {
            histogram[histogram_bin(r)] += 1;
        }
        RatioStats {
            count: ratios.len(),
            median: at(0.5),
            p95: at(0.95),
            max: at(1.0),
            within_band: within as f64 / ratios.len() as f64,
            histogram,
        }
    }
}

/// The smoothness report of the layers.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Smoothness {
    /// Over the wall edges whose two vertices have layers: the larger final thickness over the
    /// smaller (band [1, r]).
    pub neighbour_thickness_ratio: RatioStats,
    /// The same over the wall edges with an end on a patch border (where per-patch settings
    /// meet).
    pub patch_border_thickness_ratio: RatioStats,
    /// Over the columns: the largest ratio of a layer's height to the one below it (band
    /// [1/r, r]; merged columns are re-aimed, which changes their step).
    pub layer_height_ratio: RatioStats,
    /// Over the stacks ended at isotropy (`count = "auto"`): the last layer's height over the
    /// front's tangential size when it ended ([`Front::mean_edge_length_at_columns`]; band
    /// [1/r, r]).
    pub isotropy_ratio: RatioStats,
    /// Over the edges of the final front: their length in the metric the front is split to
    /// (the sizing field's, else the wall's tangential size where their columns started; band
    /// [1/sqrt 2, sqrt 2]).
    pub front_edge_length: RatioStats,
    /// The same over the fan edges alone (between copies of one wall vertex).
    pub fan_edge_length: RatioStats,
}

/// Measure the layers' smoothness. `reached[c]` is the wall distance column `c`'s stack reached
/// (`None` without layers): the march puts every top at its stack's distance from the wall (a
/// bisector column too, not its longer path along the bisector). `growth` is the (largest)
/// growth ratio, for the bands. `front_edges` are the metric lengths of the final front's edges
/// and of its fan edges ([`super::split::Sizes::front_edge_lengths`]).
pub fn measure(
    surface: &Surface,
    columns: &Columns,
    reached: &[Option<f64>],
    growth: f64,
    front_edges: (Vec<f64>, Vec<f64>),
) -> Smoothness {
    let thickness = vertex_thickness(surface, columns, reached);
    let mut edges: Vec<[u32; 2]> = surface
        .triangles
        .iter()
        .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
        .map(|[a, b]| [a.min(b), a.max(b)])
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let ratio = |e: &[u32; 2]| {
        let (a, b) = (thickness[e[0] as usize]?, thickness[e[1] as usize]?);
        (a.min(b) > 0.0).then(|| a.max(b) / a.min(b))
    };
    let neighbour: Vec<f64> = edges.iter().filter_map(ratio).collect();
    let border = patch_border_vertices(surface);
    let at_border: Vec<f64> =
        edges.iter().filter(|e| border[e[0] as usize] || border[e[1] as usize]).filter_map(ratio).collect();
    let steps: Vec<f64> =
        (0..columns.len()).map(|c| columns.max_step_ratio[c]).filter(|&r| r > 0.0).collect();
    let isotropy: Vec<f64> = (0..columns.len()).filter_map(|c| columns.isotropic_ratio(c)).collect();
    Smoothness {
        neighbour_thickness_ratio: RatioStats::of(neighbour, 1.0, growth * (1.0 + 1e-9)),
        patch_border_thickness_ratio: RatioStats::of(at_border, 1.0, growth * (1.0 + 1e-9)),
        layer_height_ratio: RatioStats::of(steps, 1.0 / growth - 1e-9, growth * (1.0 + 1e-9)),
        isotropy_ratio: RatioStats::of(isotropy, 1.0 / growth, growth),
        front_edge_length: RatioStats::of(
            front_edges.0,
            1.0 / TUNING.adaptation.split_length,
            TUNING.adaptation.split_length,
        ),
        fan_edge_length: RatioStats::of(
            front_edges.1,
            1.0 / TUNING.adaptation.split_length,
            TUNING.adaptation.split_length,
        ),
    }
}

/// The vertices whose triangles are in more than one patch.
fn patch_border_vertices(surface: &Surface) -> Vec<bool> {
    let mut first = vec![u32::MAX; surface.points.len()];
    let mut border = vec![false; surface.points.len()];
    for (t, &patch) in surface.triangles.iter().zip(&surface.triangle_patch) {
        for &v in t {
            let f = &mut first[v as usize];
            if *f == u32::MAX {
                *f = patch;
            } else if *f != patch {
                border[v as usize] = true;
            }
        }
    }
    border
}

/// Final thickness at every wall vertex with layers: the largest over its columns of the wall
/// distance the column (or the bisector column it merged into) reached, `reached[c]`.
fn vertex_thickness(surface: &Surface, columns: &Columns, reached: &[Option<f64>]) -> Vec<Option<f64>> {
    let mut thickness: Vec<Option<f64>> = vec![None; surface.points.len()];
    for (c, t) in reached.iter().enumerate() {
        let v = columns.wall_vertex[c] as usize;
        if let Some(t) = *t {
            thickness[v] = Some(thickness[v].map_or(t, |x: f64| x.max(t)));
        }
    }
    thickness
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ratio_stats_count_the_band() {
        let s = RatioStats::of(vec![1.0, 1.1, 1.2, 1.5, f64::NAN], 1.0, 1.2);
        assert_eq!(s.count, 4);
        assert_eq!(s.max, 1.5);
        assert!((s.within_band - 0.75).abs() < 1e-12);
        assert_eq!(RatioStats::of(vec![], 1.0, 2.0).count, 0);
        // 1.0, 1.1, 1.2 in [1, sqrt 2); 1.5 in [sqrt 2, 2).
        assert_eq!(s.histogram, [0, 0, 0, 0, 0, 3, 1, 0, 0, 0]);
    }

    #[test]
    fn histogram_bins_are_powers_of_sqrt2() {
        let at = |r: f64| histogram_bin(r);
        assert_eq!((at(0.01), at(0.25), at(0.5), at(0.7), at(0.71), at(0.99)), (0, 1, 3, 3, 4, 4));
        assert_eq!((at(1.0), at(1.41), at(1.42), at(3.99), at(4.0), at(1e9)), (5, 5, 6, 8, 9, 9));
    }
}
