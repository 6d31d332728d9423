//! The sizing field (docs/design.md): a metric `M(x) = Q diag(h_n^-2, h_t^-2, h_t^-2) Q^T`
//! defined everywhere, from the wall (normal size growing like the geometric layers, tangential
//! size from the wall's edge lengths graded away from it) intersected with the user's isotropic
//! sizing (maximum size, refinement regions graded from their boundary).
//!
//! ```toml
//! first_height = 1.0e-4     # h0
//! growth = 1.2              # r: h_n(d) = h0 + (r - 1) d
//! max_size = 0.5            # no size anywhere exceeds this
//! gradation = 1.2           # sizes grow at most (g - 1) per unit length
//! [[regions]]
//! shape = "sphere"
//! center = [0.0, 0.0, 0.0]
//! radius = 1.1
//! size = 0.02
//! [[regions]]
//! shape = "box"
//! min = [1.0, -1.0, -1.0]
//! max = [3.0, 1.0, 1.0]
//! size = 0.05
//! ```

pub mod metric;
pub mod wall;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::geometry::bvh::box_distance_squared;
use crate::geometry::Aabb;
use crate::surface::Surface;
pub use metric::Metric;
pub use wall::{WallDistance, WallPoint};

pub const DEFAULT_GRADATION: f64 = 1.2;

/// Where the user wants a given isotropic size.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(tag = "shape", rename_all = "lowercase", deny_unknown_fields)]
pub enum Region {
    Sphere { center: DVec3, radius: f64, size: f64 },
    Box { min: DVec3, max: DVec3, size: f64 },
}

impl Region {
    /// Distance from `x` to the region (zero inside).
    pub fn distance(&self, x: DVec3) -> f64 {
        match self {
            Region::Sphere { center, radius, .. } => ((x - *center).length() - radius).max(0.0),
            Region::Box { min, max, .. } => box_distance_squared(x, &Aabb { min: *min, max: *max }).sqrt(),
        }
    }

    pub fn size(&self) -> f64 {
        match self {
            Region::Sphere { size, .. } | Region::Box { size, .. } => *size,
        }
    }

    fn check(&self, index: usize) -> Result<(), SpecError> {
        let fail = |what: String| Err(SpecError(format!("region {index}: {what}")));
        if !(self.size() > 0.0 && self.size().is_finite()) {
            return fail(format!("size must be positive and finite, got {}", self.size()));
        }
        match self {
            Region::Sphere { center, radius, .. }
                if !(center.is_finite() && *radius >= 0.0 && radius.is_finite()) =>
            {
                fail(format!("sphere needs a finite center and radius >= 0, got {center} and {radius}"))
            }
            Region::Box { min, max, .. }
                if !(min.is_finite() && max.is_finite() && min.cmple(*max).all()) =>
            {
                fail(format!("box needs finite corners with min <= max, got {min} and {max}"))
            }
            _ => Ok(()),
        }
    }
}

/// The sizing parameters (absolute lengths, in the surface's units).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SizingSpec {
    /// First layer height h0.
    pub first_height: f64,
    /// Layer growth ratio r.
    pub growth: f64,
    /// Largest size anywhere.
    pub max_size: f64,
    /// Sizes grow by at most `gradation - 1` per unit length away from where they are set.
    #[serde(default = "default_gradation")]
    pub gradation: f64,
    #[serde(default)]
    pub regions: Vec<Region>,
}

fn default_gradation() -> f64 {
    DEFAULT_GRADATION
}

/// An invalid sizing parameter, named.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("sizing: {0}")]
pub struct SpecError(pub String);

impl SizingSpec {
    pub fn check(&self) -> Result<(), SpecError> {
        let positive = |name: &str, v: f64| {
            if v > 0.0 && v.is_finite() {
                Ok(())
            } else {
                Err(SpecError(format!("{name} must be positive and finite, got {v}")))
            }
        };
        positive("first_height", self.first_height)?;
        positive("max_size", self.max_size)?;
        for (name, v) in [("growth", self.growth), ("gradation", self.gradation)] {
            if !(v >= 1.0 && v.is_finite()) {
                return Err(SpecError(format!("{name} must be a finite ratio >= 1, got {v}")));
            }
        }
        self.regions.iter().enumerate().try_for_each(|(i, r)| r.check(i))
    }
}

/// The sizes wanted at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sizes {
    /// Unit direction away from the closest wall point (the distance gradient); zero without a wall.
    pub normal: DVec3,
    /// Size along `normal`.
    pub normal_size: f64,
    /// Size in the plane orthogonal to `normal`.
    pub tangential_size: f64,
    pub wall_distance: f64,
}

/// The metric field of a wall and a sizing spec. Evaluation is thread-safe (`&self`).
#[derive(Clone, Debug)]
pub struct SizingField {
    spec: SizingSpec,
    wall: WallDistance,
    /// Tangential size at every wall vertex: its mean edge length.
    wall_size: Vec<f64>,
    /// `wall_size` minimum per BVH node (bounds for the graded minimum).
    wall_size_node_min: Vec<f64>,
}

/// Gauss-Legendre points and weights on [0, 1] (exact for polynomials of degree 5).
const GAUSS: [(f64, f64); 3] = [
    (0.5 - 0.387_298_334_620_741_7, 5.0 / 18.0),
    (0.5, 8.0 / 18.0),
    (0.5 + 0.387_298_334_620_741_7, 5.0 / 18.0),
];

impl SizingField {
    pub fn new(wall: &Surface, spec: &SizingSpec) -> Result<SizingField, SpecError> {
        spec.check()?;
        check_wall(wall)?;
        let distance = WallDistance::new(wall);
        let wall_size = wall::mean_edge_length_per_vertex(&wall.points, &wall.triangles);
        let wall_size_node_min = distance.node_minimum(&wall_size);
        Ok(SizingField { spec: spec.clone(), wall: distance, wall_size, wall_size_node_min })
    }

    pub fn spec(&self) -> &SizingSpec {
        &self.spec
    }

    pub fn wall(&self) -> &WallDistance {
        &self.wall
    }

    /// The user's isotropic size at `x`: the maximum size, lowered near the refinement regions.
    pub fn user_size(&self, x: DVec3) -> f64 {
        region_size(&self.spec.regions, self.spec.gradation, self.spec.max_size, x)
    }

    /// Normal and tangential sizes at `x`. The normal size is `h0 + (r - 1) d` at wall distance
    /// `d`, the tangential size the wall's edge length graded away from the wall; both are capped
    /// by the user size, and the normal size never exceeds the tangential one (cells past the
    /// layers are isotropic).
    pub fn sizes(&self, x: DVec3) -> Sizes {
        let user = self.user_size(x);
        let Some(near) = self.wall.closest(x) else {
            return Sizes {
                normal: DVec3::ZERO,
                normal_size: user,
                tangential_size: user,
                wall_distance: f64::INFINITY,
            };
        };
        let slope = self.spec.gradation - 1.0;
        let tangential = self
            .wall
            .graded_minimum(x, &near, &self.wall_size, &self.wall_size_node_min, slope, self.spec.max_size)
            .min(user);
        let normal_size = (self.spec.first_height + (self.spec.growth - 1.0) * near.distance).min(tangential);
        Sizes {
            normal: self.wall.direction_from(&near, x),
            normal_size,
            tangential_size: tangential,
            wall_distance: near.distance,
        }
    }

    pub fn normal_size(&self, x: DVec3) -> f64 {
        self.sizes(x).normal_size
    }

    pub fn tangential_size(&self, x: DVec3) -> f64 {
        self.sizes(x).tangential_size
    }

    /// The metric at `x`: the wall metric (normal size along the normal, tangential size across)
    /// intersected with the isotropic user metric. Intersecting with an isotropic metric only
    /// clamps each principal size, which [`sizes`](Self::sizes) already did.
    pub fn metric(&self, x: DVec3) -> Metric {
        let s = self.sizes(x);
        if s.normal == DVec3::ZERO {
            return Metric::isotropic(s.tangential_size);
        }
        let (t1, t2) = s.normal.any_orthonormal_pair();
        Metric::from_sizes([s.normal, t1, t2], [s.normal_size, s.tangential_size, s.tangential_size])
    }

    /// Length of segment (a, b) in the metric field (3-point Gauss quadrature along it).
    pub fn edge_length(&self, a: DVec3, b: DVec3) -> f64 {
        let e = b - a;
        GAUSS.iter().map(|&(t, w)| w * self.metric(a + e * t).edge_length(e)).sum()
    }
}

/// The wall must have finite points and in-range triangle indices (a validated surface has).
fn check_wall(wall: &Surface) -> Result<(), SpecError> {
    if let Some(v) = wall.points.iter().position(|p| !p.is_finite()) {
        return Err(SpecError(format!("wall point {v} is not finite: {}", wall.points[v])));
    }
    match wall.triangles.iter().position(|t| t.iter().any(|&v| v as usize >= wall.points.len())) {
        Some(t) => Err(SpecError(format!(
            "wall triangle {t} {:?} uses a vertex beyond the {} points",
            wall.triangles[t],
            wall.points.len()
        ))),
        None => Ok(()),
    }
}

/// The size the refinement `regions` want at `x`, graded away from them by `gradation`, and
/// at most `max_size` (the front's sizing field and the core's share it).
pub fn region_size(regions: &[Region], gradation: f64, max_size: f64, x: DVec3) -> f64 {
    let slope = gradation - 1.0;
    regions.iter().map(|r| r.size() + slope * r.distance(x)).fold(max_size, f64::min)
}

/// Lower `values` over a graph so that no value exceeds `limit(neighbour, it, neighbour's
/// value)` (a growth ratio: `x * r`; a gradation: `x + (g - 1) * length`): the largest such
/// field under the given one (a graded minimum, by Dijkstra's order: smallest first; `limit`
/// must not be below its value argument). Values that are not finite stay as they are and
/// constrain nothing. `neighbours(v, out)` appends the neighbours of `v` to `out`.
pub fn graded_minimum(
    values: &mut [f64],
    neighbours: impl Fn(usize, &mut Vec<usize>),
    limit: impl Fn(usize, usize, f64) -> f64,
) {
    use std::cmp::Reverse;
    let mut heap: std::collections::BinaryHeap<Reverse<(u64, usize)>> = (0..values.len())
        .filter(|&v| values[v].is_finite() && values[v] >= 0.0)
        .map(|v| Reverse((values[v].to_bits(), v)))
        .collect();
    let mut around = Vec::new();
    while let Some(Reverse((bits, v))) = heap.pop() {
        if f64::from_bits(bits) > values[v] {
            continue;
        }
        around.clear();
        neighbours(v, &mut around);
        for &w in &around {
            let limit = limit(v, w, values[v]);
            if values[w].is_finite() && limit < values[w] {
                values[w] = limit;
                heap.push(Reverse((limit.to_bits(), w)));
            }
        }
    }
}

#[cfg(test)]
mod tests;
