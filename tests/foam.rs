//! OpenFOAM polyMesh output judged by OpenFOAM itself: `blmesh mesh S -o CASE/constant/polyMesh`
//! on the example box, the shared spot and the ONERA M6 half wing, then `checkMesh` on the case
//! must say "Mesh OK." or fail only on high aspect ratio (thin layer cells are meant to be
//! anisotropic; any other `***` is a defect). `potentialFoam` must run to the end on the box.
//! Skipped, with a message, where OpenFOAM is not installed (scripts/setup.sh installs it).

#[path = "common/openfoam.rs"]
mod openfoam;

use std::path::{Path, PathBuf};
use std::process::Command;

use openfoam::CheckMesh;

#[path = "common/shared.rs"]
mod shared;
use shared::shared_geometry;

fn geometry(name: &str) -> String {
    shared_geometry(name).display().to_string()
}

/// A case `name` in a fresh directory meshed from `surface` by the blmesh binary (with the
/// flags `extra`): the directory guard, the case and its polyMesh. `None` without OpenFOAM.
fn case(name: &str, surface: &str, extra: &[&str]) -> Option<(tempfile::TempDir, PathBuf, PathBuf)> {
    if !openfoam::available() {
        return None;
    }
    let dir = tempfile::tempdir().unwrap();
    let case = dir.path().join(name);
    let poly = mesh_case(&case, surface, extra);
    Some((dir, case, poly))
}

/// Mesh `surface` with the blmesh binary into `case/constant/polyMesh` (its report in
/// `case/report.json`) and add `system/`.
fn mesh_case(case: &Path, surface: &str, extra: &[&str]) -> PathBuf {
    let poly = case.join("constant/polyMesh");
    // The report's directory must exist before the meshing starts (the polyMesh's is made).
    std::fs::create_dir_all(case).expect("the case directory");
    let out = Command::new(env!("CARGO_BIN_EXE_blmesh"))
        .args(["mesh", surface, "-o"])
        .arg(&poly)
        .arg("--report")
        .arg(case.join("report.json"))
        .args(extra)
        .output()
        .expect("blmesh runs");
    assert!(out.status.success(), "blmesh failed: {}", String::from_utf8_lossy(&out.stderr));
    openfoam::write_system(case);
    poly
}

fn boundary_patches(poly: &Path) -> Vec<(String, String)> {
    openfoam::patches(&std::fs::read_to_string(poly.join("boundary")).expect("a boundary file"))
}

/// checkMesh's figures on the case, printed, and the project's bar held; then our own
/// finite-volume figures from the run's report must agree with checkMesh's.
fn check(name: &str, case: &Path) -> CheckMesh {
    let (check, log) = openfoam::check_mesh(case);
    eprintln!("{name}: checkMesh: {}", check.summary());
    let report = std::fs::read_to_string(case.join("report.json")).expect("the run's report");
    let fv = openfoam::compare_fv(&report, &check);
    eprintln!("{name}: quality::fv against checkMesh: {}", fv.as_ref().unwrap_or_else(|e| e));
    assert!(check.passes(), "{name}: checkMesh found defects:\n{log}");
    assert!(fv.is_ok(), "{name}: our finite-volume figures disagree with checkMesh's");
    check
}

#[test]
fn box_polymesh_passes_check_mesh_and_potential_foam() {
    let box_stl = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/box.stl");
    let Some((_dir, case, poly)) = case("box", box_stl, &[]) else { return };
    let patches = boundary_patches(&poly);
    assert!(patches.iter().any(|(_, t)| t == "wall"), "{patches:?}");
    assert!(patches.iter().any(|(n, t)| n == "farfield" && t == "patch"), "{patches:?}");
    check("box", &case);
    openfoam::write_stream_fields(&case, &patches);
    let run = openfoam::run("potentialFoam", &case);
    eprintln!("box: potentialFoam {:.1} s", run.seconds);
    assert!(run.success && run.log.lines().any(|l| l.trim() == "End"), "potentialFoam failed:\n{}", run.log);
}

#[test]
fn spot_polymesh_passes_check_mesh() {
    let Some((_dir, case, _)) = case("spot", &geometry("spot.obj"), &[]) else { return };
    check("spot", &case);
}

/// The ONERA M6 half wing at the defaults on its symmetry plane (root face `face9`, y = 0, a
/// `symmetryPlane` patch): checkMesh finds nothing to fail.
#[test]
fn onera_m6_half_wing_at_the_defaults_passes_check_mesh() {
    let config = tempfile::NamedTempFile::new().unwrap();
    std::fs::write(config.path(), "[[patch]]\nmatch = \"face9\"\nrole = \"symmetry\"\n").unwrap();
    let flags = ["--config", config.path().to_str().unwrap()];
    let Some((_dir, case, poly)) = case("m6", &geometry("onera_m6_gmsh_coarse.stl"), &flags) else { return };
    let patches = boundary_patches(&poly);
    assert!(patches.contains(&("face9".to_owned(), "symmetryPlane".to_owned())), "{patches:?}");
    let check = check("onera_m6_defaults", &case);
    assert!(check.mesh_ok, "the ONERA M6 at the defaults: checkMesh does not say Mesh OK");
}

/// The half wing with 25 layers from y+ = 1 on its symmetry plane, as in tests/cfd.rs.
///
/// Known defect: checkMesh fails one core face on skewness (5.33 > 4, between two core
/// tetrahedra near (1036, 803, -0.6), behind the wing's trailing edge); the core keeps ~3200
/// tetrahedra below 10 degrees on this set-up. The rest passes: only high aspect ratio (7275)
/// fails besides, and quality::fv agrees with checkMesh (89.955 deg, 13876 faces > 70).
#[test]
#[ignore = "known defect: one core face with skewness 5.33 on the ONERA M6 (checkMesh fails above 4)"]
fn onera_m6_polymesh_passes_check_mesh() {
    let config = tempfile::NamedTempFile::new().unwrap();
    let toml = "[layers]\nyplus = 1.0\ncount = 25\ngrowth = 1.2\n\
                [flow_conditions]\nreynolds = 14.6e6\nlength = 646.07\n\
                [[patch]]\nmatch = \"face9\"\nrole = \"symmetry\"\n";
    std::fs::write(config.path(), toml).unwrap();
    let flags = ["--config", config.path().to_str().unwrap()];
    let Some((_dir, case, poly)) = case("m6", &geometry("onera_m6_gmsh_coarse.stl"), &flags) else { return };
    let patches = boundary_patches(&poly);
    assert!(patches.contains(&("face9".to_owned(), "symmetryPlane".to_owned())), "{patches:?}");
    check("onera_m6", &case);
}

#[test]
fn parses_a_check_mesh_log_with_failures() {
    let log = "    cells:            12345\n\
               \x20   Mesh non-orthogonality Max: 78.12 average: 21.5\n\
               \x20  *Number of severely non-orthogonal (> 70 degrees) faces: 17.\n\
               \x20***Max skewness = 5.25, 3 highly skew faces detected\n\
               \x20***High aspect ratio cells found, Max aspect ratio: 1203.4, number of cells 80\n\
               \nFailed 2 mesh checks.\n";
    let c = openfoam::parse_check_mesh(log);
    assert_eq!((c.cells, c.severely_non_orthogonal), (12345, 17));
    assert_eq!((c.max_non_orthogonality, c.max_skewness, c.max_aspect_ratio), (78.12, 5.25, 1203.4));
    assert!(!c.mesh_ok && !c.passes(), "skewness is a defect");
    let ok = openfoam::parse_check_mesh("    Max aspect ratio = 3.5 OK.\n\nMesh OK.\n");
    assert!(ok.passes() && ok.max_aspect_ratio == 3.5);
}
