//! Everything `blmesh info` prints about a surface: sizes, patches, shells, validation result,
//! feature counts and element quality, as data ([`SurfaceInfo`], serializable) and as a compact
//! human-readable block (its `Display`).

use std::fmt;

use super::features::{FeatureCounts, Features};
use super::topology::Topology;
use super::validate::{format_coordinate, format_point, validate, ValidationOptions};
use super::Surface;
use crate::geometry::{triangle_min_angle, Aabb};

#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct PatchInfo {
    pub name: String,
    pub triangles: usize,
}

#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ShellInfo {
    pub triangles: usize,
    pub vertices: usize,
    /// Only for a closed manifold shell.
    pub genus: Option<u32>,
    /// Only for a valid surface (after inverted shells were flipped: positive).
    pub volume: Option<f64>,
    /// The innermost shell enclosing this one (only for a valid surface).
    pub parent: Option<u32>,
}

#[derive(Clone, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum ValidationSummary {
    Valid { warnings: Vec<String>, seconds: f64 },
    Invalid { error: String },
}

#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SurfaceInfo {
    pub triangles: usize,
    pub vertices: usize,
    pub patches: Vec<PatchInfo>,
    pub bounding_box: Aabb,
    pub diagonal: f64,
    pub shells: Vec<ShellInfo>,
    pub validation: ValidationSummary,
    pub feature_angle_deg: f64,
    /// Seen from outside the shells (an external body); `None` for an invalid surface.
    pub features: Option<FeatureCounts>,
    pub min_edge_length: Option<f64>,
    pub max_edge_length: Option<f64>,
    /// Smallest angle of any triangle, in degrees.
    pub min_angle_deg: Option<f64>,
}

impl SurfaceInfo {
    /// Validate a copy of `surface` (flipping inverted shells as validation does) and describe it;
    /// on an invalid surface the validation error is reported and the features are skipped.
    pub fn compute(surface: &Surface, feature_angle_deg: f64) -> SurfaceInfo {
        let mut checked = surface.clone();
        let outcome = validate(&mut checked, &ValidationOptions::default());
        let topology = Topology::new(&checked);
        let mut shells: Vec<ShellInfo> = topology
            .shells
            .iter()
            .map(|s| ShellInfo {
                triangles: s.triangles,
                vertices: s.vertices,
                genus: s.genus,
                volume: None,
                parent: None,
            })
            .collect();
        let (validation, features) = match outcome {
            Ok(report) => {
                // Validation measured the same shells (flipping does not change connectivity).
                for (shell, measured) in shells.iter_mut().zip(&report.shells) {
                    shell.volume = Some(measured.volume);
                    shell.parent = measured.parent;
                }
                let features = Features::compute(&checked, &topology, feature_angle_deg).counts;
                (
                    ValidationSummary::Valid { warnings: report.warnings, seconds: report.seconds },
                    Some(features),
                )
            }
            Err(error) => (ValidationSummary::Invalid { error: error.to_string() }, None),
        };
        let bounding_box = surface.bounding_box();
        let (min_edge_length, max_edge_length) = edge_length_range(surface, &topology);
        SurfaceInfo {
            triangles: surface.triangles.len(),
            vertices: surface.points.len(),
            patches: patches(surface),
            bounding_box,
            diagonal: bounding_box.diagonal(),
            shells,
            validation,
            feature_angle_deg,
            features,
            min_edge_length,
            max_edge_length,
            min_angle_deg: min_angle_deg(surface),
        }
    }
}

/// Triangle count per patch name; triangles with a missing patch id are counted as "(no patch)".
fn patches(surface: &Surface) -> Vec<PatchInfo> {
    let mut counts = vec![0; surface.patch_names.len() + 1];
    for t in 0..surface.triangles.len() {
        let patch = surface.triangle_patch.get(t).map_or(usize::MAX, |&p| p as usize);
        counts[patch.min(surface.patch_names.len())] += 1;
    }
    let names = surface.patch_names.iter().map(String::as_str).chain(["(no patch)"]);
    names
        .zip(counts)
        .enumerate()
        .filter(|&(i, (_, n))| i < surface.patch_names.len() || n > 0)
        .map(|(_, (name, triangles))| PatchInfo { name: name.to_owned(), triangles })
        .collect()
}

/// Shortest and longest edge (edges with a missing or non-finite vertex are skipped).
fn edge_length_range(surface: &Surface, topology: &Topology) -> (Option<f64>, Option<f64>) {
    let lengths = topology.edges.iter().filter_map(|&[a, b]| {
        let (p, q) = (surface.points.get(a as usize)?, surface.points.get(b as usize)?);
        Some(p.distance(*q)).filter(|l| l.is_finite())
    });
    let (min, max) = lengths.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), l| (lo.min(l), hi.max(l)));
    (Some(min).filter(|m| m.is_finite()), Some(max).filter(|m| m.is_finite()))
}

/// Smallest corner angle of any triangle, in degrees.
fn min_angle_deg(surface: &Surface) -> Option<f64> {
    surface
        .triangles
        .iter()
        .filter_map(|tri| {
            let [a, b, c] = [0, 1, 2].map(|i| surface.points.get(tri[i] as usize).copied());
            let (a, b, c) = (a?, b?, c?);
            let angle = triangle_min_angle(a, b, c);
            Some(angle).filter(|x| x.is_finite())
        })
        .min_by(f64::total_cmp)
}

/// At most this many shells and patches are listed one per line.
const LISTED: usize = 20;

/// One "label   value" line with the labels aligned.
fn line(f: &mut fmt::Formatter<'_>, label: &str, value: impl fmt::Display) -> fmt::Result {
    writeln!(f, "{label:<16} {value}")
}

fn optional(x: Option<f64>, unit: &str) -> String {
    x.map_or_else(|| "-".to_owned(), |x| format!("{}{unit}", format_coordinate(x)))
}

impl fmt::Display for SurfaceInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        line(f, "triangles", self.triangles)?;
        line(f, "vertices", self.vertices)?;
        for p in self.patches.iter().take(LISTED) {
            line(f, "patch", format!("{}: {} triangles", p.name, p.triangles))?;
        }
        if self.patches.len() > LISTED {
            line(f, "patch", format!("... and {} more", self.patches.len() - LISTED))?;
        }
        let b = &self.bounding_box;
        line(f, "bounding box", format!("{} to {}", format_point(b.min), format_point(b.max)))?;
        line(f, "diagonal", format_coordinate(self.diagonal))?;
        self.fmt_shells(f)?;
        match &self.validation {
            ValidationSummary::Valid { warnings, seconds } => {
                line(f, "validation", format!("valid, {} warnings ({:.3} s)", warnings.len(), seconds))?;
                for w in warnings {
                    line(f, "warning", w)?;
                }
            }
            ValidationSummary::Invalid { error } => line(f, "validation", format!("INVALID: {error}"))?,
        }
        self.fmt_features(f)?;
        let lengths =
            format!("{} to {}", optional(self.min_edge_length, ""), optional(self.max_edge_length, ""));
        line(f, "edge length", lengths)?;
        line(f, "min angle", optional(self.min_angle_deg, " deg"))
    }
}

impl SurfaceInfo {
    fn fmt_shells(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        line(f, "shells", self.shells.len())?;
        for (i, s) in self.shells.iter().enumerate().take(LISTED) {
            let mut text = format!("{} triangles, {} vertices", s.triangles, s.vertices);
            match s.genus {
                Some(g) => text += &format!(", genus {g}"),
                None => text += ", open or non-manifold",
            }
            if let Some(v) = s.volume {
                text += &format!(", volume {}", format_coordinate(v));
            }
            if let Some(p) = s.parent {
                text += &format!(", inside shell {p}");
            }
            line(f, &format!("shell {i}"), text)?;
        }
        if self.shells.len() > LISTED {
            line(f, "shell", format!("... and {} more", self.shells.len() - LISTED))?;
        }
        Ok(())
    }

    fn fmt_features(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        line(
            f,
            "feature angle",
            format!("{} deg (seen from outside the shells)", format_coordinate(self.feature_angle_deg)),
        )?;
        let Some(c) = &self.features else {
            return line(f, "features", "skipped (invalid surface)");
        };
        line(
            f,
            "ridge edges",
            format!(
                "{} convex, {} concave ({} convex and {} concave lines)",
                c.convex_ridge_edges, c.concave_ridge_edges, c.convex_ridge_lines, c.concave_ridge_lines
            ),
        )?;
        line(
            f,
            "ridge vertices",
            format!("{} convex, {} concave", c.convex_ridge_vertices, c.concave_ridge_vertices),
        )?;
        line(
            f,
            "corners",
            format!(
                "{} convex, {} concave, {} saddle",
                c.convex_corners, c.concave_corners, c.saddle_corners
            ),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::topology::tests::{cube_without_octant, voxel_surface};

    #[test]
    fn cut_cube_info() {
        let info = SurfaceInfo::compute(&cube_without_octant(), 30.0);
        assert_eq!((info.triangles, info.vertices), (48, 26));
        assert_eq!(info.patches.len(), 6);
        assert!(info.patches.iter().all(|p| p.triangles == 8));
        assert_eq!(info.patches[0], PatchInfo { name: "xmin".into(), triangles: 8 });
        assert_eq!(info.shells.len(), 1);
        assert_eq!(info.shells[0].volume, Some(7.0));
        assert!((info.diagonal - 12f64.sqrt()).abs() < 1e-12);
        assert_eq!(info.min_edge_length, Some(1.0));
        assert!((info.max_edge_length.unwrap() - 2f64.sqrt()).abs() < 1e-12);
        assert!((info.min_angle_deg.unwrap() - 45.0).abs() < 1e-9);
        let c = info.features.as_ref().unwrap();
        assert_eq!((c.concave_ridge_edges, c.concave_corners, c.saddle_corners), (3, 1, 3));
        let text = info.to_string();
        assert!(text.contains("triangles        48\n"), "{text}");
        assert!(text.contains("shell 0          48 triangles, 26 vertices, genus 0, volume 7\n"), "{text}");
        assert!(text.contains("validation       valid, 0 warnings"), "{text}");
        assert!(text.contains("corners          10 convex, 1 concave, 3 saddle\n"), "{text}");
        assert!(serde_json::to_string(&info).unwrap().contains("\"status\":\"valid\""));
    }

    #[test]
    fn invalid_surface_reports_the_error_and_skips_features() {
        let mut s = voxel_surface(&[[0, 0, 0]]);
        s.triangles.pop();
        s.triangle_patch.pop();
        s.triangles.push([0, 1, 77]);
        s.triangle_patch.push(9);
        let info = SurfaceInfo::compute(&s, 30.0);
        assert!(info.features.is_none());
        let ValidationSummary::Invalid { error } = &info.validation else { panic!("{info}") };
        assert!(error.contains("triangle 11 with vertices (0, 1, 77)"), "{error}");
        let text = info.to_string();
        assert!(text.contains("validation       INVALID: "), "{text}");
        assert!(text.contains("features         skipped"), "{text}");
        assert!(text.contains("patch            (no patch): 1 triangles"), "{text}");
    }

    #[test]
    fn inverted_cube_is_reported_flipped() {
        let mut s = voxel_surface(&[[0, 0, 0]]);
        s.flip_all();
        let info = SurfaceInfo::compute(&s, 30.0);
        let ValidationSummary::Valid { warnings, .. } = &info.validation else { panic!("{info}") };
        assert_eq!(warnings.len(), 1);
        assert_eq!(info.features.unwrap().convex_ridge_edges, 12);
        assert!((info.shells[0].volume.unwrap() - 1.0).abs() < 1e-12);
    }
}
