//! Faults around a run of the binary: a real SIGINT or SIGTERM during the meshing or during the
//! writing leaves no output and no temporary file and exits with 130 or 143; an output directory
//! that is missing or not writable is an error before the meshing starts.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

fn geometry(name: &str) -> String {
    format!("{}/../shared/geometries/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// A surface whose meshing with the core takes a second or two.
fn slow_surface() -> String {
    geometry("cutcube_cfmesh.stl")
}

fn spawn_mesh(output: &Path, extra: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_blmesh"))
        .args(["mesh", &slow_surface(), "-o", output.to_str().unwrap(), "-q"])
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("blmesh starts")
}

fn send(child: &Child, signal: i32) {
    // SAFETY: the child is ours and not reaped yet.
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, signal) }, 0);
}

fn entries(dir: &Path) -> Vec<PathBuf> {
    let mut found: Vec<PathBuf> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    found.sort();
    found
}

/// The exit code, the message, and that the directory holds nothing but the input's absence.
fn assert_interrupted(out: Output, code: i32, dir: &Path) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "stderr: {err}");
    assert!(err.contains("interrupted by"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(entries(dir), Vec::<PathBuf>::new(), "an output or a temporary was left behind");
}

#[test]
fn a_signal_during_the_meshing_leaves_nothing() {
    for (signal, code) in [(libc::SIGINT, 130), (libc::SIGTERM, 143)] {
        let dir = tempfile::tempdir().unwrap();
        let child = spawn_mesh(&dir.path().join("out.vtu"), &[]);
        std::thread::sleep(Duration::from_millis(400));
        send(&child, signal);
        assert_interrupted(child.wait_with_output().unwrap(), code, dir.path());
    }
}

/// The signal comes as soon as the output's temporary appears: the temporary is removed.
#[test]
fn a_signal_during_the_writing_removes_the_temporary() {
    let (mut caught, mut interrupted) = (0, 0);
    for _ in 0..3 {
        let dir = tempfile::tempdir().unwrap();
        // ASCII MSH: the slowest writer, so that the temporary lives long enough to be seen.
        let mut child = spawn_mesh(&dir.path().join("out.msh"), &["--ascii"]);
        let start = Instant::now();
        let seen = loop {
            if entries(dir.path()).iter().any(|p| p.to_string_lossy().contains(".blmesh-")) {
                break true;
            }
            if child.try_wait().unwrap().is_some() || start.elapsed() > Duration::from_secs(120) {
                break false;
            }
            std::thread::sleep(Duration::from_micros(500));
        };
        if !seen {
            // Written before the poll saw it: a whole output, nothing else.
            let names = entries(dir.path());
            assert_eq!(names, vec![dir.path().join("out.msh")]);
            continue;
        }
        caught += 1;
        send(&child, libc::SIGINT);
        let out = child.wait_with_output().unwrap();
        if out.status.code() == Some(0) {
            // The signal came after the rename: one whole output.
            assert_eq!(entries(dir.path()), vec![dir.path().join("out.msh")]);
        } else {
            assert_interrupted(out, 130, dir.path());
            interrupted += 1;
        }
    }
    eprintln!("temporary seen in {caught} of 3 runs, interrupted while writing in {interrupted}");
    assert!(interrupted > 0, "no signal came while the temporary existed: the test proved nothing");
}

fn mesh_into(output: &Path, input: &str) -> Output {
    Command::new(env!("CARGO_BIN_EXE_blmesh"))
        .args(["mesh", input, "-o", output.to_str().unwrap(), "-q"])
        .output()
        .unwrap()
}

fn assert_output_error(out: &Output, words: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains(words), "missing {words:?} in {err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn a_missing_output_directory_fails_before_the_meshing() {
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("missing/out.vtu");
    // Checked before the input is even read: the error is about the output, not the input.
    let out = mesh_into(&output, "/nonexistent/surface.stl");
    assert_output_error(&out, &format!("directory {} does not exist", dir.path().join("missing").display()));
    // A polyMesh directory is created with its parents: only an unwritable ancestor is an error.
    let file = dir.path().join("file");
    std::fs::write(&file, "").unwrap();
    let out = mesh_into(&file.join("constant/polyMesh"), "/nonexistent/surface.stl");
    assert_output_error(&out, "is not a directory");
}

/// A directory that this process cannot write: a read-only one, or for root (whom permission
/// bits do not stop) one of sysfs, where nobody creates files.
fn unwritable_dir() -> Option<(tempfile::TempDir, PathBuf)> {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let locked = dir.path().join("locked");
    std::fs::create_dir(&locked).unwrap();
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o555)).unwrap();
    if std::fs::write(locked.join("probe"), "").is_err() {
        return Some((dir, locked));
    }
    let sys = PathBuf::from("/sys/kernel");
    (sys.is_dir() && std::fs::write(sys.join("probe"), "").is_err()).then_some((dir, sys))
}

#[test]
fn a_read_only_output_directory_fails_before_the_meshing() {
    let Some((_keep, locked)) = unwritable_dir() else {
        eprintln!("no unwritable directory here: skipped");
        return;
    };
    // An input that does not exist: the error is about the output, so it came before the reading.
    let out = mesh_into(&locked.join("out.vtu"), "/nonexistent/surface.stl");
    assert_output_error(&out, &format!("directory {} is not writable", locked.display()));
    let out = mesh_into(&locked.join("new/polyMesh"), "/nonexistent/surface.stl");
    assert_output_error(&out, "is not writable");
}
