//! The core's sizes away from the front (docs/design.md, the core): they grow from the front's (and
//! the farfield's) by the gradation, edges at most `gradation - 1` longer per unit length, stay
//! under the user's maximum size and shrink to the user's refinement regions (`[sizing]`).
//!
//! TetGen sizes the points it adds from the tetrahedron each lands in, whose corners at first
//! are the front's and the farfield's: its sizes grew about as fast as the distance from the
//! front (edges as long as they are far from it, on spot and the elbow). So the core is filled
//! twice: the first fill's points carry the graded sizes ([`graded_sizes`]) into the second,
//! with points sampled in the regions where the first fill is coarser than they ask
//! ([`region_points`]). (TetGen's background mesh, the other way to give it sizes inside, took
//! 7 to 25 times as long: it walks to every point it adds.)

use serde::Serialize;

use crate::layers::smoothness::RatioStats;

use super::improve::TET_EDGES;
use super::{merge, ClosedBoundary, CoreGuide, CoreMesher, CoreTets, FillError};
use crate::geometry::bvh::TriangleBvh;
use crate::geometry::{tet_signed_volume, DVec3};
use crate::sizing::Region;

/// The most core tetrahedra the graded sizes may ask for: more (a maximum size far below the
/// farfield's, say) is an error that names the sizes, not hours of meshing.
pub const MAX_CORE_TETRAHEDRA: f64 = 5.0e7;

/// Points sampled in the refinement regions at most (a warning says when they are cut short).
const MAX_REGION_POINTS: usize = 2_000_000;

/// Region points are sampled this many region sizes apart (the mesher refines between them).
const REGION_SPACING: f64 = 2.0;

/// When the second fill fails (TetGen aborted on the elbow at growth 1.1999), it is run again
/// with the first fill's points only where they are at least this many of their sizes away
/// from the boundary (the front's sizes hold near it anyway).
const RETRY_CLEARANCE: f64 = 1.0;

/// What the core's sizes follow beyond the boundary's.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CoreSizing {
    /// Sizes grow by at most `gradation - 1` per unit length (`[sizing] gradation`).
    pub gradation: f64,
    /// No edge longer (`[sizing] max_size`); `None`: the farfield's edges bound them.
    pub max_size: Option<f64>,
    /// The sizes wanted inside these, graded away from them (`[[sizing.regions]]`).
    pub regions: Vec<Region>,
}

impl Default for CoreSizing {
    fn default() -> Self {
        CoreSizing { gradation: crate::sizing::DEFAULT_GRADATION, max_size: None, regions: Vec::new() }
    }
}

impl CoreSizing {
    /// The user's size at `p`: the regions' graded away from them, the maximum size.
    fn user_size(&self, p: DVec3) -> f64 {
        crate::sizing::region_size(&self.regions, self.gradation, self.max_size.unwrap_or(f64::INFINITY), p)
    }
}

/// What the graded fill did.
#[derive(Clone, Copy, Debug, Default)]
pub struct Graded {
    /// Whether the second fill took (else the first stays).
    pub graded: bool,
    /// Points sampled in the refinement regions.
    pub region_points: usize,
}

/// Fill again with the graded sizes; `first` is the first fill (`seeds_used` seeds in place,
/// run with `guide`). Returns the tetrahedra, the seeds in place and what was done: where the
/// second fill fails or loses a boundary triangle, even with the points near the boundary left
/// out ([`RETRY_CLEARANCE`]), the first stays (a warning says so).
pub(super) fn fill_graded(
    mesher: &dyn CoreMesher,
    boundary: &ClosedBoundary,
    first: CoreTets,
    seeds_used: usize,
    mut guide: CoreGuide,
    sizing: &CoreSizing,
) -> Result<(CoreTets, usize, Graded), FillError> {
    let n = boundary.points.len();
    if guide.size.len() < n {
        return Ok((first, seeds_used, Graded::default()));
    }
    let size = graded_sizes(&first, &guide.size[..n], sizing);
    let expected = expected_tetrahedra(&first, &size);
    tracing::debug!(expected, "tetrahedra the graded sizes ask for");
    if expected > MAX_CORE_TETRAHEDRA {
        return Err(FillError::Options(format!(
            "the core's sizes ask for about {:.0} million tetrahedra (at most {:.0} million): raise \
             [sizing] max_size ({}) or the regions' sizes, or make the farfield smaller",
            expected / 1e6,
            MAX_CORE_TETRAHEDRA / 1e6,
            sizing.max_size.map_or("none".to_owned(), |m| m.to_string())
        )));
    }
    let regions = region_points(&first, n, &size, sizing);
    let region_points = regions.len();
    // Built for the retry only.
    let bvh = std::cell::OnceCell::new();
    let boundary_bvh = || {
        bvh.get_or_init(|| {
            TriangleBvh::new(
                boundary.triangles.iter().map(|t| t.map(|v| boundary.points[v as usize])).collect(),
            )
        })
    };
    let mut error = None;
    for clearance in [None, Some(RETRY_CLEARANCE)] {
        // The seeds in place, then the first fill's other points (those clear of the boundary
        // on the retry), then the regions'.
        let kept: Vec<usize> = (n..first.points.len())
            .filter(|&i| {
                i < n + seeds_used
                    || clearance.is_none_or(|c| {
                        boundary_bvh()
                            .nearest(first.points[i])
                            .is_none_or(|near| near.distance >= c * size[i])
                    })
            })
            .collect();
        guide.interior = kept.iter().map(|&i| first.points[i]).chain(regions.iter().map(|r| r.0)).collect();
        guide.size = size[..n].iter().chain(kept.iter().map(|&i| &size[i])).copied().collect();
        guide.size.extend(regions.iter().map(|r| r.1));
        guide.sizing_points = guide.interior.len() - seeds_used;
        let second = mesher.fill(boundary, &guide).and_then(|mut tets| {
            merge::drop_unused_points(&mut tets, n);
            let used = merge::seeds_in_place_first(boundary, &guide, &mut tets);
            merge::check_boundary_kept(boundary, &tets).map(|()| (tets, used))
        });
        match second {
            Ok((tets, used)) => return Ok((tets, used, Graded { graded: true, region_points })),
            Err(e) => {
                tracing::info!(error = %e, ?clearance, "the graded fill failed");
                error = Some(e);
            }
        }
    }
    if let Some(e) = error {
        tracing::warn!(error = %e, "the graded fill failed: the core keeps the mesher's own sizes");
    }
    Ok((first, seeds_used, Graded { graded: false, region_points }))
}

/// How many tetrahedra `size` (at the points of `mesh`) asks for: over the tetrahedra of
/// `mesh`, their volume over that of a regular tetrahedron whose edge is their corners' mean
/// size.
fn expected_tetrahedra(mesh: &CoreTets, size: &[f64]) -> f64 {
    mesh.tets
        .iter()
        .map(|t| {
            let [a, b, c, d] = t.map(|v| mesh.points[v as usize]);
            let volume = tet_signed_volume(a, b, c, d).abs();
            let edge = t.iter().map(|&v| size[v as usize]).sum::<f64>() / 4.0;
            volume / (edge.powi(3) / (6.0 * std::f64::consts::SQRT_2))
        })
        .sum()
}

/// The sizes at the points of `mesh` graded from `boundary_size` (at its first points) and the
/// user's sizes: at every interior point the least of the user's size there and, over the
/// boundary points and the other interior points, their size plus `gradation - 1` times the
/// distance to them along the mesh's edges; never more than the largest boundary size (the
/// farfield's). The boundary keeps its own sizes (the front's, raised to the seeds' heights,
/// set the first core cells).
pub(super) fn graded_sizes(mesh: &CoreTets, boundary_size: &[f64], sizing: &CoreSizing) -> Vec<f64> {
    let largest = boundary_size.iter().copied().filter(|s| s.is_finite()).fold(0.0, f64::max);
    let mut size: Vec<f64> = mesh.points.iter().map(|&p| sizing.user_size(p).min(largest)).collect();
    size[..boundary_size.len()].copy_from_slice(boundary_size);
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); mesh.points.len()];
    for t in &mesh.tets {
        for (i, j) in TET_EDGES {
            neighbours[t[i] as usize].push(t[j]);
            neighbours[t[j] as usize].push(t[i]);
        }
    }
    let slope = sizing.gradation - 1.0;
    let points = &mesh.points;
    crate::sizing::graded_minimum(
        &mut size,
        |v, out| out.extend(neighbours[v].iter().map(|&w| w as usize)),
        |v, w, s| s + slope * points[v].distance(points[w]),
    );
    size[..boundary_size.len()].copy_from_slice(boundary_size);
    size
}

/// Points (with their sizes) inside the tetrahedra of `mesh` that a refinement region wants
/// finer than they are: on a lattice [`REGION_SPACING`] sizes apart (the size at the
/// tetrahedron's centre), where the region's size is less than half its longest edge, sized by
/// the least of the region's size and the corners' graded `size`. Only tetrahedra with no corner among the first
/// `boundary` points (the front's and the farfield's) are sampled: no point comes near the
/// boundary.
pub(super) fn region_points(
    mesh: &CoreTets,
    boundary: usize,
    size: &[f64],
    sizing: &CoreSizing,
) -> Vec<(DVec3, f64)> {
    let mut out = Vec::new();
    if sizing.regions.is_empty() {
        return out;
    }
    for tet in mesh.tets.iter().filter(|t| t.iter().all(|&v| v as usize >= boundary)) {
        let x = tet.map(|v| mesh.points[v as usize]);
        let longest = TET_EDGES.iter().map(|&(i, j)| x[i].distance(x[j])).fold(0.0, f64::max);
        let centre = (x[0] + x[1] + x[2] + x[3]) / 4.0;
        // The user's size anywhere in the tetrahedron is at least this.
        if (sizing.user_size(centre) - (sizing.gradation - 1.0) * longest) * 2.0 >= longest {
            continue;
        }
        // Spaced by the size at the centre (where the region only grazes the tetrahedron, a few
        // points; the mesher interpolates between them), at most 32 across.
        let divisions = (longest / (REGION_SPACING * sizing.user_size(centre))).ceil().min(32.0) as usize;
        let corner_size = tet.map(|v| size[v as usize]);
        for i in 1..divisions {
            for j in 1..divisions - i {
                for k in 1..divisions - i - j {
                    let l = divisions - i - j - k;
                    let w = [i, j, k, l].map(|c| c as f64 / divisions as f64);
                    let p = x[0] * w[0] + x[1] * w[1] + x[2] * w[2] + x[3] * w[3];
                    let wanted = sizing.user_size(p);
                    if wanted * 2.0 >= longest {
                        continue;
                    }
                    let graded = (0..4).map(|c| w[c] * corner_size[c]).sum::<f64>();
                    out.push((p, wanted.min(graded)));
                    if out.len() >= MAX_REGION_POINTS {
                        tracing::warn!(
                            MAX_REGION_POINTS,
                            "the refinement regions ask for too many points: cut short"
                        );
                        return out;
                    }
                }
            }
        }
    }
    out
}

/// How smoothly the sizes of `tets` grow: over every edge, the larger of its two ends' sizes
/// (the mean length of the edges at a point) over the smaller, counted within `[1, gradation]`.
/// TetGen's own sizes: spot's 95th percentile 1.74, the elbow's 5.4; graded by 1.2: 1.46, 2.5.
pub fn size_ratio_across_edges(points: &[DVec3], tets: &[[u32; 4]], gradation: f64) -> RatioStats {
    let mut edges: Vec<[u32; 2]> =
        tets.iter().flat_map(|t| TET_EDGES.map(|(i, j)| crate::mesh::sorted_edge(t[i], t[j]))).collect();
    edges.sort_unstable();
    edges.dedup();
    let mut sum = vec![(0.0, 0usize); points.len()];
    for &[a, b] in &edges {
        let length = points[a as usize].distance(points[b as usize]);
        for v in [a, b] {
            let (total, count) = &mut sum[v as usize];
            (*total, *count) = (*total + length, *count + 1);
        }
    }
    let size = |v: u32| sum[v as usize].0 / sum[v as usize].1 as f64;
    let ratios = edges.iter().map(|&[a, b]| size(a).max(size(b)) / size(a).min(size(b))).collect();
    RatioStats::of(ratios, 1.0, gradation)
}
