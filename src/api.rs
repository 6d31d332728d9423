//! What the command line and the Python package both do, written once: the meshing settings on
//! top of a config, meshing a surface file, writing a mesh in the format its name asks for,
//! checking a mesh file, describing a surface, and the message of an error.

use std::path::Path;

use anyhow::{bail, Context, Result};
use clap::Args;
use serde::Deserialize;

use crate::config::{Config, ConfigError, LayerCount, Role};
use crate::io::{self, MeshFormat};
use crate::mesh::VolumeMesh;
use crate::pipeline::{self, MeshOptions, MeshOutput};
use crate::progress::Progress;
use crate::quality::{self, CheckReport};
use crate::surface::info::SurfaceInfo;

/// The meshing settings: `blmesh mesh`'s flags, and the Python package's keyword arguments of
/// the same names. Each one set replaces the config's value.
#[derive(Args, Clone, Debug, Default, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Settings {
    /// First layer height h0 (surface units).
    #[arg(long, allow_negative_numbers = true)]
    pub first_height: Option<f64>,
    /// Growth ratio r (layer k is h0 r^k high).
    #[arg(long, allow_negative_numbers = true)]
    pub growth: Option<f64>,
    /// Number of layers, or "auto" to stop where cells become isotropic.
    #[arg(long)]
    pub layers: Option<LayerCount>,
    /// Total layer thickness (instead of --layers).
    #[arg(long, conflicts_with = "layers", allow_negative_numbers = true)]
    pub thickness: Option<f64>,
    /// Edges turning more than this (degrees) are ridges.
    #[arg(long, allow_negative_numbers = true)]
    pub feature_angle: Option<f64>,
    /// Largest angle (degrees) between neighbouring normals of a fan at a convex ridge.
    #[arg(long, allow_negative_numbers = true)]
    pub fan_angle: Option<f64>,
    /// The core mesher: "tetgen" (default) or "native" (Delaunay, boundary recovery and refinement).
    #[arg(long, value_name = "MESHER")]
    pub core_mesher: Option<crate::config::CoreMesherChoice>,
    /// Write only the layers (no core tetrahedra).
    #[arg(long)]
    pub no_core: bool,
    /// March again at most N times to mend the core's slivers: with the tops under them pulled
    /// back, then with their stacks a layer lower (default 8; 0: never).
    #[arg(long, value_name = "N")]
    pub peel_rounds: Option<usize>,
    /// Do not split or collapse the layers' front edges to the tangential sizes (tangential adaptivity).
    #[arg(long)]
    pub no_adapt: bool,
    /// Stop at the layer count or thickness even where the last layer is still thinner than the
    /// front is wide (no transition layers up to isotropic cells).
    #[arg(long)]
    pub no_transition: bool,
}

impl Settings {
    /// `config` with these settings on top, validated.
    pub fn apply(&self, mut config: Config) -> Result<Config, ConfigError> {
        if self.layers.is_some() && self.thickness.is_some() {
            return Err(ConfigError::Parameter {
                name: "thickness".into(),
                value: format!("{:?}", self.thickness.unwrap_or_default()),
                why: "give either layers or thickness, not both".into(),
            });
        }
        let layers = &mut config.layers;
        layers.first_height = self.first_height.or(layers.first_height);
        layers.growth = self.growth.or(layers.growth);
        if self.layers.is_some() || self.thickness.is_some() {
            layers.count = self.layers;
            layers.thickness = self.thickness;
        }
        config.feature_angle = self.feature_angle.or(config.feature_angle);
        config.fan_angle = self.fan_angle.or(config.fan_angle);
        config.peel_rounds = self.peel_rounds.or(config.peel_rounds);
        config.core.mesher = self.core_mesher.or(config.core.mesher);
        if self.no_adapt {
            config.sizing.adapt = Some(false);
        }
        if self.no_transition {
            // The setting overrides the config's patch rules too.
            config.layers.transition = Some(false);
            config.patches.iter_mut().for_each(|p| p.layers.transition = Some(false));
        }
        config.validate()?;
        Ok(config)
    }
}

/// The format of an output path, or why it cannot be written (unknown, or not in this build):
/// asked before meshing, so that a run does not fail at its end.
pub fn output_format(path: &Path, ascii: bool) -> Result<MeshFormat> {
    let format = MeshFormat::from_path(path, ascii).with_context(|| {
        format!("{}: unknown output format (expected {})", path.display(), io::MESH_EXTENSIONS)
    })?;
    if let Some(why) = format.unavailable() {
        bail!("{}: {why}", path.display());
    }
    Ok(format)
}

/// Read the surface at `input` and mesh it with `config` (settings applied already).
pub fn mesh_file(input: &Path, config: &Config, no_core: bool, progress: Progress) -> Result<MeshOutput> {
    let surface = io::read_surface(input)?;
    let options = MeshOptions { core: !no_core };
    Ok(pipeline::run(surface, config, &options, progress)?)
}

/// Write `mesh` to `path` in `format`, with the patch roles of `config`.
pub fn write_mesh(path: &Path, mesh: &VolumeMesh, format: MeshFormat, config: &Config) -> Result<()> {
    let roles = patch_roles(&mesh.patch_names, config);
    io::write_volume_mesh_with_roles(path, mesh, format, &roles)
        .with_context(|| format!("{}: cannot write", path.display()))
}

/// Write the run's report as JSON.
pub fn write_report(path: &Path, out: &MeshOutput) -> Result<()> {
    let text = serde_json::to_string_pretty(&out.report)?;
    io::write_atomic(path, |w| w.write_all(text.as_bytes()))
        .with_context(|| format!("{}: cannot write", path.display()))
}

/// Write the pictures of cuts through the mesh and its histograms into `dir`.
pub fn write_pictures(dir: &Path, out: &MeshOutput) -> Result<()> {
    crate::picture::write_overview(&out.mesh, dir, &out.report.picture_spots)
        .with_context(|| format!("{}: cannot write the pictures", dir.display()))?;
    Ok(())
}

/// The role of every patch of the mesh: the config's, except that a patch the config leaves a
/// wall by default but that blmesh made (the farfield, the layer top) gets its own role.
fn patch_roles(patch_names: &[String], config: &Config) -> Vec<Role> {
    patch_names
        .iter()
        .map(|name| match config.patch_settings(name).0 {
            Role::Wall => io::cgns::default_role(name),
            role => role,
        })
        .collect()
}

/// Read a volume mesh and check it.
pub fn check_file(path: &Path) -> Result<CheckReport> {
    Ok(quality::check(&io::read_volume_mesh(path)?))
}

/// Whether a finite-volume solver would take the mesh: valid, with no wrong face pyramid and no
/// face at 90 degrees of non-orthogonality or more (`blmesh check`'s exit code 0).
pub fn accepted(report: &CheckReport) -> bool {
    report.is_valid() && report.fv.rejection().is_none()
}

/// Read a surface and describe it; an invalid surface is described too (its `validation`).
pub fn surface_info(path: &Path, feature_angle: f64) -> Result<SurfaceInfo> {
    if !(feature_angle > 0.0 && feature_angle < 180.0) {
        bail!("--feature-angle {feature_angle} must be between 0 and 180 degrees");
    }
    Ok(SurfaceInfo::compute(&io::read_surface(path)?, feature_angle))
}

/// The error and its causes, each once: our error types already print their source in their own
/// message, which `{:#}` would repeat.
pub fn error_message(e: &anyhow::Error) -> String {
    let mut message = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if !message.contains(&text) {
            if !message.is_empty() {
                message.push_str(": ");
            }
            message.push_str(&text);
        }
    }
    message
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cause that the message above already quotes is not repeated; a new one is added.
    #[test]
    fn error_message_names_each_cause_once() {
        let read = crate::io::read_surface(Path::new("/nonexistent/x.stl")).unwrap_err();
        let quoted = read.to_string();
        let e = anyhow::Error::new(read);
        assert_eq!(error_message(&e), quoted);
        let e = e.context("meshing failed");
        assert_eq!(error_message(&e), format!("meshing failed: {quoted}"));
    }

    /// Settings arrive from Python as JSON: unknown names are refused with the valid ones listed.
    #[test]
    fn settings_from_json_name_the_valid_keys() {
        let s: Settings = serde_json::from_str(r#"{"layers": 10, "first_height": 1e-3}"#).unwrap();
        assert_eq!(s.layers, Some(LayerCount::Fixed(10)));
        let e = serde_json::from_str::<Settings>(r#"{"layer": 10}"#).unwrap_err().to_string();
        assert!(e.contains("unknown field `layer`") && e.contains("first_height"), "{e}");
        let both = Settings { layers: Some(LayerCount::Auto), thickness: Some(1.0), ..Default::default() };
        assert!(both.apply(Config::default()).unwrap_err().to_string().contains("not both"));
    }
}
