//! `blmesh._native`: the library's entry points for the Python package (python/blmesh), which
//! wraps them. Arrays cross as bytes in native byte order, made into numpy arrays on the Python
//! side; reports cross as JSON text. Meshing, checking and writing run without the GIL.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use blmesh::api::{self, Settings};
use blmesh::config::Config;
use blmesh::pipeline::{MeshError, MeshOutput};
use blmesh::progress::Progress;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyBytes;

/// Which exception of `blmesh.errors` an error becomes.
#[derive(Clone, Copy)]
enum Kind {
    /// A bad surface, mesh file, setting or config, or an output name of no known format.
    Input,
    /// The mesher failed on valid input.
    Meshing,
    /// An output could not be written.
    Output,
}

/// The `blmesh.errors` exception of `kind`, with the message the command line prints.
fn raise(py: Python<'_>, kind: Kind, message: String) -> PyErr {
    let name = match kind {
        Kind::Input => "InputError",
        Kind::Meshing => "MeshingError",
        Kind::Output => "OutputError",
    };
    let class = py.import("blmesh.errors").and_then(|m| m.getattr(name));
    match class.and_then(|c| c.call1((message.clone(),))) {
        Ok(e) => PyErr::from_value(e),
        Err(_) => PyRuntimeError::new_err(message),
    }
}

fn err(py: Python<'_>, kind: Kind, e: &anyhow::Error) -> PyErr {
    raise(py, kind, api::error_message(e))
}

/// A meshing failure on valid input is the mesher's; anything else was the input's.
fn mesh_error_kind(e: &anyhow::Error) -> Kind {
    match e.downcast_ref::<MeshError>() {
        Some(MeshError::Fill(_) | MeshError::Sliding(_) | MeshError::InvalidResult(_)) => Kind::Meshing,
        _ => Kind::Input,
    }
}

/// The config (a TOML file, or its table as JSON) with the settings (JSON) on top, and the
/// settings.
fn config_of(
    config_path: Option<&Path>,
    config_json: Option<&str>,
    settings_json: &str,
) -> anyhow::Result<(Config, Settings)> {
    let config = match (config_path, config_json) {
        (Some(path), _) => Config::from_toml_file(path)?,
        (None, Some(json)) => {
            let table: toml::Table = serde_json::from_str(json).map_err(|e| {
                anyhow::anyhow!("config: not a table of the TOML file's keys: {}", without_position(&e))
            })?;
            Config::from_table(table).map_err(|e| anyhow::anyhow!("config: {e}"))?
        }
        (None, None) => Config::default(),
    };
    let settings: Settings = serde_json::from_str(settings_json)
        .map_err(|e| anyhow::anyhow!("settings: {}", without_position(&e)))?;
    Ok((settings.apply(config)?, settings))
}

/// A JSON error without its place in the JSON text, which the caller never saw.
fn without_position(e: &serde_json::Error) -> String {
    let text = e.to_string();
    match text.rfind(" at line ") {
        Some(at) if e.line() > 0 => text[..at].to_owned(),
        _ => text,
    }
}

/// Reports stages to a Python callable `(stage, fraction)`; its first exception is kept to be
/// raised when the run ends (the run itself goes on: it cannot be stopped midway).
fn observer(callback: Py<PyAny>, failure: Arc<Mutex<Option<PyErr>>>) -> Progress {
    Progress::observed(Arc::new(move |stage: &str, fraction: f64| {
        Python::attach(|py| {
            if let Err(e) = callback.call1(py, (stage, fraction)) {
                let mut kept = failure.lock().unwrap_or_else(|p| p.into_inner());
                kept.get_or_insert(e);
            }
        })
    }))
}

/// Mesh the surface file `surface`; `settings_json` holds `blmesh mesh`'s settings by name.
#[pyfunction]
#[pyo3(signature = (surface, settings_json, config_path=None, config_json=None, progress=None))]
fn mesh(
    py: Python<'_>,
    surface: PathBuf,
    settings_json: &str,
    config_path: Option<PathBuf>,
    config_json: Option<&str>,
    progress: Option<Py<PyAny>>,
) -> PyResult<NativeMesh> {
    let (config, settings) = config_of(config_path.as_deref(), config_json, settings_json)
        .map_err(|e| err(py, Kind::Input, &e))?;
    let failure = Arc::new(Mutex::new(None));
    let progress = match progress {
        Some(callback) => observer(callback, failure.clone()),
        None => Progress::hidden(),
    };
    let out = py.detach(|| api::mesh_file(&surface, &config, settings.no_core, progress));
    if let Some(e) = failure.lock().unwrap_or_else(|p| p.into_inner()).take() {
        return Err(e);
    }
    let out = out.map_err(|e| err(py, mesh_error_kind(&e), &e))?;
    Ok(NativeMesh { out, config })
}

/// The check report (JSON) of a mesh file.
#[pyfunction]
fn check_file(py: Python<'_>, path: PathBuf) -> PyResult<String> {
    let report = py.detach(|| api::check_file(&path)).map_err(|e| err(py, Kind::Input, &e))?;
    Ok(check_json(&report))
}

/// The check report as JSON, with `accepted`: `blmesh check`'s exit code 0.
fn check_json(report: &blmesh::quality::CheckReport) -> String {
    let mut value = serde_json::to_value(report).unwrap_or_default();
    if let Some(map) = value.as_object_mut() {
        map.insert("accepted".into(), api::accepted(report).into());
    }
    value.to_string()
}

/// The description (JSON) of a surface file.
#[pyfunction]
#[pyo3(signature = (path, feature_angle=None))]
fn info(py: Python<'_>, path: PathBuf, feature_angle: Option<f64>) -> PyResult<String> {
    let feature_angle = feature_angle.unwrap_or(blmesh::config::DEFAULT_FEATURE_ANGLE);
    let info = py.detach(|| api::surface_info(&path, feature_angle)).map_err(|e| err(py, Kind::Input, &e))?;
    serde_json::to_string(&info).map_err(|e| raise(py, Kind::Input, e.to_string()))
}

/// A volume mesh made by `mesh`, with its report and the config it was made with (the patch
/// roles its outputs need).
#[pyclass(frozen)]
struct NativeMesh {
    out: MeshOutput,
    config: Config,
}

fn f64_bytes<'py>(py: Python<'py>, values: impl Iterator<Item = f64>) -> Bound<'py, PyBytes> {
    let bytes: Vec<u8> = values.flat_map(f64::to_ne_bytes).collect();
    PyBytes::new(py, &bytes)
}

fn u32_bytes<'py>(py: Python<'py>, values: impl Iterator<Item = u32>) -> Bound<'py, PyBytes> {
    let bytes: Vec<u8> = values.flat_map(u32::to_ne_bytes).collect();
    PyBytes::new(py, &bytes)
}

#[pymethods]
impl NativeMesh {
    /// The points' coordinates, x y z point after point (float64).
    fn points<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        f64_bytes(py, self.out.mesh.points.iter().flat_map(|p| p.to_array()))
    }

    /// Every cell kind as (name, nodes per cell, nodes (uint32), zone of each cell (uint32)), in
    /// the Gmsh node orders (`blmesh::mesh`).
    #[allow(clippy::type_complexity)]
    fn cells<'py>(
        &self,
        py: Python<'py>,
    ) -> Vec<(&'static str, usize, Bound<'py, PyBytes>, Bound<'py, PyBytes>)> {
        self.out
            .mesh
            .blocks
            .iter()
            .map(|b| {
                let nodes = u32_bytes(py, b.nodes.iter().copied());
                (b.kind.name(), b.kind.node_count(), nodes, u32_bytes(py, b.zone.iter().copied()))
            })
            .collect()
    }

    fn zone_names(&self) -> Vec<String> {
        self.out.mesh.zone_names.clone()
    }

    fn patch_names(&self) -> Vec<String> {
        self.out.mesh.patch_names.clone()
    }

    /// The boundary faces, outward: (triangles, their patches, quads, their patches), uint32.
    #[allow(clippy::type_complexity)]
    fn boundary<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyBytes>, Bound<'py, PyBytes>, Bound<'py, PyBytes>, Bound<'py, PyBytes>) {
        let b = &self.out.mesh.boundary;
        (
            u32_bytes(py, b.triangles.iter().flatten().copied()),
            u32_bytes(py, b.triangle_patch.iter().copied()),
            u32_bytes(py, b.quads.iter().flatten().copied()),
            u32_bytes(py, b.quad_patch.iter().copied()),
        )
    }

    /// The run's report as JSON (`blmesh mesh --report`).
    fn report_json(&self) -> String {
        serde_json::to_string(&self.out.report).unwrap_or_default()
    }

    /// The summary `blmesh mesh` prints.
    fn summary(&self) -> String {
        self.out.report.to_string()
    }

    /// Write the mesh; the format follows the name, as for `blmesh mesh -o`.
    #[pyo3(signature = (path, ascii=false))]
    fn write(&self, py: Python<'_>, path: PathBuf, ascii: bool) -> PyResult<()> {
        let format = api::output_format(&path, ascii).map_err(|e| err(py, Kind::Input, &e))?;
        py.detach(|| api::write_mesh(&path, &self.out.mesh, format, &self.config))
            .map_err(|e| err(py, Kind::Output, &e))
    }

    fn write_report(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| api::write_report(&path, &self.out)).map_err(|e| err(py, Kind::Output, &e))
    }

    fn write_pictures(&self, py: Python<'_>, dir: PathBuf) -> PyResult<()> {
        py.detach(|| api::write_pictures(&dir, &self.out)).map_err(|e| err(py, Kind::Output, &e))
    }

    /// The check report (JSON) of the mesh in memory, as `check_file` gives for its file.
    fn check(&self, py: Python<'_>) -> String {
        let report = py.detach(|| blmesh::quality::check(&self.out.mesh));
        check_json(&report)
    }
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(mesh, m)?)?;
    m.add_function(wrap_pyfunction!(check_file, m)?)?;
    m.add_function(wrap_pyfunction!(info, m)?)?;
    m.add_class::<NativeMesh>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("CGNS", cfg!(feature = "cgns"))?;
    Ok(())
}
