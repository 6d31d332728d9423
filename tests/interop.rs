//! Our MSH (ASCII, binary) and VTU files: read back by our readers, by meshio and by Gmsh
//! (`tests/python/interop.py`, run with the interpreter named by `BLMESH_PYTHON`), and the files
//! meshio and Gmsh write from them read back by our readers. Our SU2 and Medit files (no volume
//! reader of ours) are read by meshio; the Medit boundary also by our surface reader.

use std::path::{Path, PathBuf};
use std::process::Command;

use blmesh::io::{read_surface, read_volume_mesh, write_volume_mesh, MeshFormat};
use blmesh::mesh::{CellKind, VolumeMesh};
use blmesh::quality::{check, samples::hybrid_column, CheckReport};

mod common;

const SCRIPT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/python/interop.py");

/// meshio's name of each cell kind.
fn meshio_name(kind: CellKind) -> &'static str {
    match kind {
        CellKind::Tetrahedron => "tetra",
        CellKind::Pyramid => "pyramid",
        CellKind::Prism => "wedge",
        CellKind::Hexahedron => "hexahedron",
    }
}

/// A valid report with the same counts and volume as the original's.
fn assert_same(what: &str, original: &CheckReport, read: &VolumeMesh) {
    let r = check(read);
    assert!(r.is_valid(), "{what}:\n{r}");
    assert_eq!(r.cells, original.cells, "{what}");
    assert_eq!(r.conformity.free_triangles, original.conformity.free_triangles, "{what}");
    assert_eq!(r.conformity.free_quads, original.conformity.free_quads, "{what}");
    let faces = |r: &CheckReport| r.patches.iter().map(|p| (p.triangles, p.quads)).collect::<Vec<_>>();
    assert_eq!(faces(&r), faces(original), "{what}");
    // meshio's ASCII VTU keeps about 11 significant digits of the coordinates.
    let tolerance = if what.contains("ascii.vtu") { 1e-8 } else { 1e-12 };
    let difference = (r.volume.cells - original.volume.cells).abs() / original.volume.cells;
    assert!(difference < tolerance, "{what}: volume differs by {difference:e} (relative)");
}

/// The interpreter for the Python checks: None (skip) outside CI when `BLMESH_PYTHON` is unset.
fn python() -> Option<String> {
    match std::env::var("BLMESH_PYTHON") {
        Ok(p) if !p.is_empty() => Some(p),
        _ if std::env::var_os("CI").is_some() => {
            panic!("BLMESH_PYTHON is not set: CI must name a Python with gmsh, meshio and numpy")
        }
        _ => {
            eprintln!(
                "skipping the meshio/Gmsh checks: set BLMESH_PYTHON to a Python with gmsh, meshio, numpy"
            );
            None
        }
    }
}

fn run(python: &str, args: &[&str]) {
    let out = Command::new(python).arg(SCRIPT).args(args).output().expect("cannot run BLMESH_PYTHON");
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "interop.py {args:?} failed:\n{text}");
}

fn expectations(mesh: &VolumeMesh, volume: f64) -> Vec<String> {
    let mut args = Vec::new();
    for kind in CellKind::ALL {
        args.push(format!("--expect={}={}", meshio_name(kind), mesh.block(kind).len()));
    }
    args.push(format!("--expect=triangle={}", mesh.boundary.triangles.len()));
    args.push(format!("--expect=quad={}", mesh.boundary.quads.len()));
    args.push(format!("--volume={volume:.17e}"));
    args
}

#[test]
fn hybrid_mesh_files_interoperate() {
    assert_interoperates(&hybrid_column());
}

/// The boundary layers of a box (prisms, fans of hexahedra, pyramids and tetrahedra at the
/// corners) as written by `blmesh mesh`.
#[test]
fn layer_mesh_files_interoperate() {
    use blmesh::pipeline::{run, MeshOptions};
    let (surface, config) = common::layered_box();
    let out =
        run(surface, &config, &MeshOptions { core: false }, blmesh::progress::Progress::hidden()).unwrap();
    for kind in CellKind::ALL {
        assert!(!out.mesh.block(kind).is_empty(), "the box layers have {}s", kind.name());
    }
    assert_interoperates(&out.mesh);
}

fn assert_interoperates(mesh: &VolumeMesh) {
    let original = check(mesh);
    assert!(original.is_valid(), "{original}");
    let dir = tempfile::tempdir().unwrap();
    let files: Vec<(PathBuf, MeshFormat)> = vec![
        (dir.path().join("ascii.msh"), MeshFormat::Msh { ascii: true }),
        (dir.path().join("binary.msh"), MeshFormat::Msh { ascii: false }),
        (dir.path().join("mesh.vtu"), MeshFormat::Vtu),
    ];
    for (path, format) in &files {
        write_volume_mesh(path, mesh, *format).unwrap();
        let back = read_volume_mesh(path).unwrap();
        assert_same(&path.display().to_string(), &original, &back);
        if path.extension().is_some_and(|e| e == "msh") {
            assert_eq!(back.patch_names, mesh.patch_names);
            assert_eq!(back.zone_names, mesh.zone_names);
        }
    }
    let solver_files: Vec<(PathBuf, MeshFormat)> = vec![
        (dir.path().join("mesh.su2"), MeshFormat::Su2),
        (dir.path().join("ascii.mesh"), MeshFormat::Medit { binary: false }),
        (dir.path().join("binary.meshb"), MeshFormat::Medit { binary: true }),
    ];
    for (path, format) in &solver_files {
        write_volume_mesh(path, mesh, *format).unwrap();
    }
    for (path, _) in &solver_files[1..] {
        assert_medit_boundary(path, mesh, original.volume.cells);
    }
    let Some(python) = python() else { return };
    let groups: Vec<&str> = mesh.patch_names.iter().chain(&mesh.zone_names).map(String::as_str).collect();
    for (path, _) in files.iter().chain(&solver_files) {
        let mut args = vec!["check".to_string(), path.display().to_string()];
        args.extend(expectations(mesh, original.volume.cells));
        if path.extension().is_some_and(|e| e == "msh") {
            args.push(format!("--groups={}", groups.join(",")));
        }
        run(&python, &args.iter().map(String::as_str).collect::<Vec<_>>());
    }
    read_other_tools_files(&python, &files[1].0, &files[2].0, dir.path(), &original);
}

/// The boundary of a Medit volume file, read by our surface reader: every face (quadrilaterals
/// split in two), enclosing the mesh's volume.
fn assert_medit_boundary(path: &Path, mesh: &VolumeMesh, volume: f64) {
    let surface = read_surface(path).unwrap_or_else(|e| panic!("{e}"));
    let b = &mesh.boundary;
    assert_eq!(surface.triangles.len(), b.triangles.len() + 2 * b.quads.len(), "{}", path.display());
    let difference = (surface.enclosed_volume() - volume).abs() / volume;
    assert!(difference < 1e-12, "{}: enclosed volume differs by {difference:e}", path.display());
}

/// Files written by meshio and Gmsh from ours, read back by our readers.
fn read_other_tools_files(python: &str, msh: &Path, vtu: &Path, dir: &Path, original: &CheckReport) {
    let out = dir.join("converted");
    run(
        python,
        &["convert", &msh.display().to_string(), &vtu.display().to_string(), &out.display().to_string()],
    );
    let names = [
        "meshio_zlib.vtu",
        "meshio_binary.vtu",
        "meshio_ascii.vtu",
        "meshio22.msh",
        "gmsh41_binary.msh",
        "gmsh22.msh",
    ];
    for name in names {
        let path = out.join(name);
        let mesh = read_volume_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_same(name, original, &mesh);
        if name.ends_with(".msh") {
            let patches: Vec<&str> = original.patches.iter().map(|p| p.name.as_str()).collect();
            assert_eq!(mesh.patch_names, patches, "{name}");
        }
    }
}
