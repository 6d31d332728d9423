//! The `blmesh` binary on good and bad input: clear errors, non-zero exits, no panics, no partial
//! output files; `check` tells valid meshes from broken ones; `mesh` runs end to end on every
//! shared surface and its output passes `check`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use blmesh::io::{write_volume_mesh, MeshFormat};
use blmesh::mesh::{CellKind, VolumeMesh};
use blmesh::quality::samples::hybrid_column;

#[path = "common/shared.rs"]
mod shared;
use shared::shared_geometry;

fn blmesh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_blmesh")).args(args).output().expect("blmesh runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Assert a clean failure: exit code 1, the expected words in the message, no panic.
fn assert_fails_with(o: &Output, words: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(1), "expected exit code 1, stderr: {err}");
    assert!(!err.contains("panicked"), "panic: {err}");
    for w in words {
        assert!(err.to_lowercase().contains(&w.to_lowercase()), "missing {w:?} in: {err}");
    }
}

fn geometry(name: &str) -> String {
    shared_geometry(name).display().to_string()
}

/// A unit cube as OBJ text, with `edit` applied to its 12 faces first.
fn cube_obj(edit: impl FnOnce(&mut Vec<[usize; 3]>, &mut Vec<[f64; 3]>)) -> String {
    let mut v: Vec<[f64; 3]> =
        (0..8).map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64]).collect();
    let mut f: Vec<[usize; 3]> = vec![
        [0, 2, 3],
        [0, 3, 1],
        [4, 5, 7],
        [4, 7, 6],
        [0, 1, 5],
        [0, 5, 4],
        [2, 6, 7],
        [2, 7, 3],
        [0, 4, 6],
        [0, 6, 2],
        [1, 3, 7],
        [1, 7, 5],
    ];
    edit(&mut f, &mut v);
    let mut s = String::new();
    for p in &v {
        s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for t in &f {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

struct Case {
    file: &'static str,
    bytes: Vec<u8>,
    words: &'static [&'static str],
}

fn bad_inputs() -> Vec<Case> {
    let mut truncated_stl = vec![0u8; 80];
    truncated_stl.extend(12u32.to_le_bytes());
    truncated_stl.extend(vec![0u8; 50 * 3 + 7]);
    vec![
        Case {
            file: "open.obj",
            bytes: cube_obj(|f, _| {
                f.pop();
            })
            .into(),
            words: &["open", "edge"],
        },
        Case {
            file: "nonmanifold.obj",
            // A tetrahedron hanging on the cube's edge (0, 1): four triangles on that edge.
            bytes: cube_obj(|f, v| {
                v.push([0.5, -1.0, -0.2]);
                v.push([0.5, -0.2, -1.0]);
                f.extend([[0, 8, 1], [1, 9, 0], [0, 9, 8], [1, 8, 9]]);
            })
            .into(),
            words: &["non-manifold", "edge"],
        },
        Case {
            file: "flipped.obj",
            bytes: cube_obj(|f, _| {
                f[0].swap(1, 2);
                f[1].swap(1, 2);
            })
            .into(),
            words: &["orient"],
        },
        Case {
            file: "intersecting.obj",
            // A second cube shifted by half an edge overlaps the first.
            bytes: {
                let a = cube_obj(|_, _| {});
                let b = cube_obj(|_, v| v.iter_mut().for_each(|p| p.iter_mut().for_each(|x| *x += 0.5)));
                let mut s = a.clone();
                s += &b.lines().filter(|l| l.starts_with('v')).map(|l| format!("{l}\n")).collect::<String>();
                for l in b.lines().filter(|l| l.starts_with('f')) {
                    let ids: Vec<usize> =
                        l[2..].split(' ').map(|x| x.parse::<usize>().unwrap() + 8).collect();
                    s += &format!("f {} {} {}\n", ids[0], ids[1], ids[2]);
                }
                s.into()
            },
            words: &["intersect"],
        },
        Case {
            file: "nan.obj",
            bytes: cube_obj(|_, v| v[3][1] = f64::NAN).into(),
            words: &["finite", "vertex 3"],
        },
        Case { file: "truncated.stl", bytes: truncated_stl, words: &["truncated.stl"] },
        Case { file: "empty.stl", bytes: Vec::new(), words: &["empty.stl"] },
        Case { file: "empty.msh", bytes: Vec::new(), words: &["empty.msh"] },
        Case {
            file: "garbage.off",
            bytes: (0..4096u32).map(|i| (i.wrapping_mul(2654435761) >> 13) as u8).collect(),
            words: &["garbage.off"],
        },
        Case {
            file: "garbage.obj",
            bytes: b"\x7fELF\x02\x01\x01\0\0\0\xff\xfe garbage".to_vec(),
            words: &["garbage.obj", "line 1"],
        },
    ]
}

#[test]
fn bad_surfaces_give_clear_errors_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    for case in bad_inputs() {
        let input = dir.path().join(case.file);
        std::fs::write(&input, &case.bytes).unwrap();
        let out = dir.path().join("out.msh");
        let info = blmesh(&["info", input.to_str().unwrap()]);
        assert_fails_with(&info, case.words);
        let mesh = blmesh(&["mesh", input.to_str().unwrap(), "-o", out.to_str().unwrap()]);
        assert_fails_with(&mesh, case.words);
        assert!(!out.exists(), "{}: a failed run left an output file", case.file);
    }
    let leftovers: Vec<PathBuf> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().path()).collect();
    assert!(
        leftovers.iter().all(|p| !p.file_name().unwrap().to_string_lossy().starts_with(".blmesh")),
        "temporaries left: {leftovers:?}"
    );
}

#[test]
fn impossible_parameters_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.msh");
    let cube = dir.path().join("cube.obj");
    std::fs::write(&cube, cube_obj(|_, _| {})).unwrap();
    let o = out.to_str().unwrap();
    let c = cube.to_str().unwrap();
    for (args, words) in [
        (vec!["--first-height", "-1"], &["first_height", "positive"][..]),
        (vec!["--growth", "0.5"], &["growth"][..]),
        (vec!["--first-height", "1", "--thickness", "0.1"], &["thinner than the first layer"][..]),
        (vec!["--fan-angle", "0"], &["fan_angle"][..]),
        (vec!["--first-height", "nan"], &["first_height"][..]),
    ] {
        let mut all = vec!["mesh", c, "-o", o];
        all.extend(args);
        assert_fails_with(&blmesh(&all), words);
        assert!(!out.exists());
    }
    assert_fails_with(
        &blmesh(&["mesh", c, "-o", dir.path().join("out.xyz").to_str().unwrap()]),
        &["out.xyz", "format"],
    );
}

/// Write `mesh` to `dir/name` and run `blmesh check` on it.
fn check_file(dir: &Path, name: &str, mesh: &VolumeMesh) -> Output {
    let path = dir.join(name);
    write_volume_mesh(&path, mesh, MeshFormat::from_path(&path, false).unwrap()).unwrap();
    blmesh(&["check", path.to_str().unwrap()])
}

#[test]
fn check_passes_a_valid_hybrid_mesh_and_names_each_breakage() {
    let dir = tempfile::tempdir().unwrap();
    let valid = hybrid_column();
    for name in ["valid.msh", "valid.vtu"] {
        let o = check_file(dir.path(), name, &valid);
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stdout));
    }
    let mut inverted = valid.clone();
    let tets = inverted.block_mut(CellKind::Tetrahedron);
    assert!(!tets.is_empty());
    tets.nodes.swap(0, 1);
    let o = check_file(dir.path(), "inverted.msh", &inverted);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stdout).contains("invalid cells"));

    let mut doubled = valid.clone();
    let first: Vec<u32> = doubled.block(CellKind::Prism).cell(0).to_vec();
    doubled.push_cell(CellKind::Prism, &first, 0);
    let o = check_file(dir.path(), "doubled.msh", &doubled);
    assert_eq!(o.status.code(), Some(1));

    let mut missing = valid.clone();
    let b = missing.block_mut(CellKind::Pyramid);
    let n = b.kind.node_count();
    b.nodes.truncate(b.nodes.len() - n);
    b.zone.pop();
    let o = check_file(dir.path(), "missing.msh", &missing);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stdout).contains("hole"), "{}", String::from_utf8_lossy(&o.stdout));
}

#[test]
fn mesh_runs_end_to_end_on_every_shared_surface() {
    let dir = tempfile::tempdir().unwrap();
    let mut rows = Vec::new();
    for name in [
        "cutcube_cfmesh.stl",
        "mech_test_gapdetection.obj",
        "building_wtc2.obj",
        "spot.obj",
        "fandisk.obj",
        "flange.stl",
        "arrow_cape.uh3d",
        "elbow_90degree_cfmesh.stl",
        "bunny_closed_herholz.off",
        "onera_m6_gmsh_coarse.stl",
    ] {
        let out = dir.path().join(format!("{name}.msh"));
        let report = dir.path().join(format!("{name}.json"));
        let o = blmesh(&[
            "mesh",
            &geometry(name),
            "-o",
            out.to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
            "-q",
        ]);
        assert_eq!(o.status.code(), Some(0), "{name}: {}", stderr(&o));
        let check = blmesh(&["check", out.to_str().unwrap()]);
        assert_eq!(check.status.code(), Some(0), "{name}: {}", String::from_utf8_lossy(&check.stdout));
        let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
        let l = &json["layers"];
        assert!(l["layers_max"].as_u64().unwrap() >= 10, "{name}: no column reached its 10 layers");
        rows.push(format!("{name}: coverage {:.4}, stopped {}", l["full_coverage"], l["stopped_vertices"]));
    }
    eprintln!("{}", rows.join("\n"));
}

#[test]
fn yplus_prints_the_first_height_and_refuses_bad_inputs() {
    let o = blmesh(&["yplus", "--re", "14.6e6", "--length", "0.64607", "--yplus", "1"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.contains("Schlichting") && out.contains("Cf    = 2.438352e-3"), "{out}");
    assert!(out.contains("first layer height y     = 1.267341e-6 (units of L)"), "{out}");
    let air = ["--velocity", "330.0993", "--density", "1.225", "--viscosity", "1.7894e-5"];
    let o = blmesh(&[&["yplus", "--re", "14.6e6", "--length", "0.64607", "--yplus", "1"][..], &air].concat());
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("u_tau = 1.152598e1 m/s") && out.contains("= 1.267341e-6 m"), "{out}");
    assert_fails_with(&blmesh(&["yplus", "--re", "-1", "--length", "1", "--yplus", "1"]), &["reynolds"]);
    assert_fails_with(&blmesh(&["yplus", "--re", "1e6", "--length", "inf", "--yplus", "1"]), &["length"]);
    assert_fails_with(&blmesh(&["yplus", "--re", "1e6", "--length", "1", "--yplus", "0"]), &["yplus"]);
    let o = blmesh(&[&["yplus", "--re", "1e6", "--length", "1", "--yplus", "1"][..], &air].concat());
    assert_fails_with(&o, &["inconsistent units"]);
}
