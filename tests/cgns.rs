//! CGNS output (feature `cgns`): meshes written to `.cgns` and read back with the CGNS library
//! itself (our FFI), checked by the CGNS project's `cgnscheck`, and converted by its
//! `cgns_to_vtk` for meshio (`tests/python/cgns_vtk.py`; meshio 5.3's own CGNS reader takes only
//! a tetrahedron section named `GridElements`, not our MIXED sections).
#![cfg(feature = "cgns")]

use std::collections::HashMap;
use std::path::Path;
use std::process::Command;

use blmesh::config::Role;
use blmesh::io::cgns::{self, BcType, CgnsFile};
use blmesh::io::{read_volume_mesh, write_volume_mesh, write_volume_mesh_with_roles, MeshFormat};
use blmesh::mesh::{CellKind, VolumeMesh};
use blmesh::pipeline::{run, MeshOptions};
use blmesh::progress::Progress;
use blmesh::quality::{self, measures, validity};

mod common;

#[path = "common/shared.rs"]
mod shared;
use shared::shared_geometry;

const TRI_3: i32 = 5;
const QUAD_4: i32 = 7;
const MIXED: i32 = 20;

/// The layers of a box (prisms, fans of hexahedra, pyramids and tetrahedra at the corners), or
/// the full mesh with the core and the farfield.
fn box_mesh(core: bool) -> VolumeMesh {
    let (surface, config) = common::layered_box();
    let mesh = run(surface, &config, &MeshOptions { core }, Progress::hidden()).unwrap().mesh;
    for kind in CellKind::ALL {
        assert!(!mesh.block(kind).is_empty(), "the box mesh has {}s", kind.name());
    }
    assert!(quality::check(&mesh).is_valid(), "{}", quality::check(&mesh));
    mesh
}

/// Write `mesh` with `roles`, read it back and check everything against the original; the file.
fn round_trip(mesh: &VolumeMesh, roles: &[Role], dir: &Path) -> CgnsFile {
    let path = dir.join("mesh.cgns");
    write_volume_mesh_with_roles(&path, mesh, MeshFormat::Cgns, roles).unwrap();
    let file = cgns::read(&path).unwrap();
    assert_eq!((file.zone_vertices, file.zone_cells), (mesh.points.len(), mesh.cell_count()));
    assert_eq!(file.mesh.points, mesh.points, "coordinates are written as doubles");
    assert_sections(mesh, &file);
    assert_same_cells(mesh, &file.mesh);
    assert_boundary_conditions(mesh, roles, &file);
    let report = quality::check(&file.mesh);
    assert!(report.is_valid(), "{report}");
    let original = quality::check(mesh);
    assert_eq!(report.cells, original.cells);
    assert_eq!(report.volume.cells, original.volume.cells);
    run_cgnscheck(&path);
    check_with_cgns_to_vtk(&path, mesh, original.volume.cells);
    file
}

/// One MIXED section per volume zone with cells, then the triangles and the quads of each patch.
fn assert_sections(mesh: &VolumeMesh, file: &CgnsFile) {
    let mut expected = Vec::new();
    for (zone, name) in mesh.zone_names.iter().enumerate() {
        let cells = mesh.blocks.iter().flat_map(|b| &b.zone).filter(|&&z| z as usize == zone).count();
        if cells > 0 {
            expected.push((name.clone(), MIXED, cells));
        }
    }
    for (patch, name) in mesh.patch_names.iter().enumerate() {
        match patch_face_counts(mesh, patch as u32) {
            (0, 0) => {}
            (t, 0) => expected.push((name.clone(), TRI_3, t)),
            (0, q) => expected.push((name.clone(), QUAD_4, q)),
            (t, q) => {
                expected.push((name.clone(), TRI_3, t));
                expected.push((format!("{name}_quads"), QUAD_4, q));
            }
        }
    }
    let sections: Vec<_> =
        file.sections.iter().map(|s| (s.name.clone(), s.element_type, s.elements)).collect();
    assert_eq!(sections, expected);
}

fn patch_face_counts(mesh: &VolumeMesh, patch: u32) -> (usize, usize) {
    let b = &mesh.boundary;
    let count = |p: &[u32]| p.iter().filter(|&&q| q == patch).count();
    (count(&b.triangle_patch), count(&b.quad_patch))
}

/// The same cells of each kind (in the file's order: zone by zone) with the same volumes.
fn assert_same_cells(mesh: &VolumeMesh, back: &VolumeMesh) {
    for kind in CellKind::ALL {
        let block = mesh.block(kind);
        let mut order: Vec<usize> = (0..block.len()).collect();
        order.sort_by_key(|&i| block.zone[i]);
        let read = back.block(kind);
        assert_eq!(read.len(), block.len(), "{}s", kind.name());
        for (r, &i) in order.iter().enumerate() {
            assert_eq!(read.cell(r), block.cell(i), "{} {i}", kind.name());
            let volume = |m: &VolumeMesh, nodes: &[u32]| {
                measures::volume(kind, &validity::gather(&m.points, nodes).unwrap())
            };
            assert_eq!(volume(back, read.cell(r)), volume(mesh, block.cell(i)));
        }
    }
}

/// A condition per patch with faces, named after it, of the type of its role, on its faces.
fn assert_boundary_conditions(mesh: &VolumeMesh, roles: &[Role], file: &CgnsFile) {
    let faces_of = |m: &VolumeMesh| {
        let mut by_patch: HashMap<String, Vec<Vec<u32>>> = HashMap::new();
        let b = &m.boundary;
        let triangles = b.triangles.iter().map(|t| t.to_vec()).zip(&b.triangle_patch);
        for (face, &p) in triangles.chain(b.quads.iter().map(|q| q.to_vec()).zip(&b.quad_patch)) {
            by_patch.entry(m.patch_names[p as usize].clone()).or_default().push(face);
        }
        by_patch.values_mut().for_each(|f| f.sort());
        by_patch
    };
    assert_eq!(faces_of(&file.mesh), faces_of(mesh));
    let named: Vec<&str> = file.boundary_conditions.iter().map(|bc| bc.name.as_str()).collect();
    let with_faces: Vec<&str> = mesh
        .patch_names
        .iter()
        .enumerate()
        .filter(|&(p, _)| patch_face_counts(mesh, p as u32) != (0, 0))
        .map(|(_, n)| n.as_str())
        .collect();
    assert_eq!(named, with_faces);
    for bc in &file.boundary_conditions {
        let patch = mesh.patch_names.iter().position(|n| *n == bc.name).unwrap();
        let role = roles.get(patch).copied().unwrap_or_else(|| cgns::default_role(&bc.name));
        assert_eq!(bc.bc_type, BcType::for_role(role), "{}", bc.name);
        let (t, q) = patch_face_counts(mesh, patch as u32);
        assert_eq!(bc.faces, t + q, "{}", bc.name);
    }
}

/// `cgnscheck` (Debian cgns-convert), if installed, reports no error.
fn run_cgnscheck(path: &Path) {
    let Ok(out) = Command::new("cgnscheck").arg("-w3").arg(path).output() else {
        eprintln!("cgnscheck not found (Debian package cgns-convert): skipped");
        return;
    };
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "cgnscheck failed:\n{text}");
    assert!(!text.to_ascii_uppercase().contains("ERROR"), "cgnscheck reports errors:\n{text}");
    assert!(text.contains("checking complete"), "{text}");
    let warnings: Vec<&str> = text.lines().filter(|l| l.contains("WARNING")).collect();
    eprintln!("cgnscheck: no errors, {} warnings {warnings:?}", warnings.len());
}

/// `cgns_to_vtk` (cgns-convert) and meshio, if both are there: counts, positive cells, volume.
fn check_with_cgns_to_vtk(path: &Path, mesh: &VolumeMesh, volume: f64) {
    let Some(python) = std::env::var("BLMESH_PYTHON").ok().filter(|p| !p.is_empty()) else {
        eprintln!("BLMESH_PYTHON not set: cgns_to_vtk + meshio check skipped");
        return;
    };
    let out_dir = tempfile::tempdir().unwrap();
    let Ok(out) = Command::new("cgns_to_vtk").arg("-a").arg(path).arg(out_dir.path()).output() else {
        eprintln!("cgns_to_vtk not found (Debian package cgns-convert): skipped");
        return;
    };
    assert!(out.status.success(), "cgns_to_vtk failed: {}", String::from_utf8_lossy(&out.stderr));
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/python/cgns_vtk.py");
    let mut args = vec![out_dir.path().join("Zone.vtk").display().to_string()];
    for (kind, name) in CellKind::ALL.into_iter().zip(["tetra", "pyramid", "wedge", "hexahedron"]) {
        args.push(format!("--expect={name}={}", mesh.block(kind).len()));
    }
    args.push(format!("--volume={volume:.17e}"));
    let out = Command::new(&python).arg(script).args(&args).output().expect("cannot run BLMESH_PYTHON");
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "cgns_vtk.py failed:\n{text}");
    eprint!("{text}");
}

#[test]
fn layered_box_round_trips_with_default_roles() {
    let mesh = box_mesh(false);
    let dir = tempfile::tempdir().unwrap();
    let file = round_trip(&mesh, &[], dir.path());
    let types: Vec<BcType> = file.boundary_conditions.iter().map(|bc| bc.bc_type).collect();
    assert!(types.contains(&BcType::WallViscous) && types.contains(&BcType::General), "{types:?}");
    // The generic volume reader reads .cgns too.
    let back = read_volume_mesh(&dir.path().join("mesh.cgns")).unwrap();
    assert_eq!(back.cell_count(), mesh.cell_count());
}

/// The full mesh, every role on some patch.
#[cfg(feature = "tetgen")]
#[test]
fn full_box_mesh_round_trips_with_every_role() {
    let mesh = box_mesh(true);
    let roles: Vec<Role> = mesh
        .patch_names
        .iter()
        .enumerate()
        .map(|(i, name)| match name.as_str() {
            blmesh::fill::FARFIELD_PATCH => Role::Farfield,
            _ => [Role::Wall, Role::Symmetry, Role::Inlet, Role::Outlet, Role::None][i % 5],
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let file = round_trip(&mesh, &roles, dir.path());
    let mut types: Vec<i32> = file.boundary_conditions.iter().map(|bc| bc.bc_type.code()).collect();
    types.sort_unstable();
    types.dedup();
    let all = [BcType::Farfield, BcType::General, BcType::Inflow, BcType::Outflow, BcType::SymmetryPlane];
    for t in all.into_iter().chain([BcType::WallViscous]) {
        assert!(types.contains(&t.code()), "{t:?} missing from {types:?}");
    }
}

/// `blmesh mesh -o out.cgns` takes the boundary condition types from the config's roles.
#[cfg(feature = "tetgen")]
#[test]
fn cli_writes_the_config_roles() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("roles.toml");
    std::fs::write(&config, "[[patch]]\nmatch = \"prescribed\"\nrole = \"inlet\"\n").unwrap();
    let output = dir.path().join("cut.cgns");
    let input = shared_geometry("cutcube_cfmesh.stl");
    let status = Command::new(env!("CARGO_BIN_EXE_blmesh"))
        .arg("mesh")
        .arg(&input)
        .args(["--quiet", "--config"])
        .arg(&config)
        .arg("-o")
        .arg(&output)
        .status()
        .unwrap();
    assert!(status.success());
    let file = cgns::read(&output).unwrap();
    let types: HashMap<&str, BcType> =
        file.boundary_conditions.iter().map(|bc| (bc.name.as_str(), bc.bc_type)).collect();
    let expected = [
        ("prescribed", BcType::Inflow),
        ("defaultFaces", BcType::WallViscous),
        ("farfield", BcType::Farfield),
    ];
    assert_eq!(types, expected.into_iter().collect());
    assert!(quality::check(&file.mesh).is_valid());
    run_cgnscheck(&output);
}

/// The plain writer entry point gives every patch its default role.
#[test]
fn write_volume_mesh_uses_default_roles() {
    let mesh = blmesh::quality::samples::hybrid_column();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("column.cgns");
    write_volume_mesh(&path, &mesh, MeshFormat::from_path(&path, false).unwrap()).unwrap();
    let file = cgns::read(&path).unwrap();
    assert!(file.boundary_conditions.iter().all(|bc| bc.bc_type == BcType::WallViscous));
    run_cgnscheck(&path);
}
