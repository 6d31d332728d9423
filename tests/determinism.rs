//! The same input and settings give byte-identical output files, run after run and for any
//! number of threads: two shared surfaces, one with the core (TetGen) and one with the layers
//! alone, each meshed twice with the default thread count and once with one thread.

use std::path::Path;
use std::process::Command;

fn geometry(name: &str) -> String {
    format!("{}/../shared/geometries/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// The output of one run, read back as bytes.
fn mesh(input: &str, output: &Path, threads: Option<usize>, extra: &[&str]) -> Vec<u8> {
    let mut command = Command::new(env!("CARGO_BIN_EXE_blmesh"));
    command.args(["mesh", input, "-o", output.to_str().unwrap(), "-q"]).args(extra);
    match threads {
        Some(n) => command.env("RAYON_NUM_THREADS", n.to_string()),
        None => command.env_remove("RAYON_NUM_THREADS"),
    };
    let out = command.output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    std::fs::read(output).unwrap()
}

fn assert_deterministic(surface: &str, output_name: &str, extra: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let input = geometry(surface);
    let runs: Vec<Vec<u8>> = [None, None, Some(1)]
        .into_iter()
        .enumerate()
        .map(|(i, threads)| mesh(&input, &dir.path().join(format!("{i}-{output_name}")), threads, extra))
        .collect();
    assert!(!runs[0].is_empty());
    assert!(runs[0] == runs[1], "{surface}: two runs with the default threads differ");
    assert!(runs[0] == runs[2], "{surface}: one thread and the default threads differ");
}

#[test]
fn same_bytes_every_run_and_any_thread_count_with_the_core() {
    assert_deterministic("cutcube_cfmesh.stl", "cutcube.msh", &[]);
}

#[test]
fn same_bytes_every_run_and_any_thread_count_layers_alone() {
    assert_deterministic("building_wtc2.obj", "building.vtu", &["--no-core"]);
}
