//! The shared test data: the project's `shared/` directory (surfaces in `geometries/`), which
//! lives beside the repository as `../shared` (CI lays a copy there) or where `BLMESH_SHARED`
//! says. Every test, bench and unit test that needs it finds it here, and one that runs without
//! it fails saying where to get it.
#![allow(dead_code)] // each test crate that includes this file uses part of it

use std::path::PathBuf;

/// The shared data directory; panics, saying where to get it, when it is absent.
pub fn shared_dir() -> PathBuf {
    let dir = match std::env::var_os("BLMESH_SHARED") {
        Some(dir) => PathBuf::from(dir),
        None => PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared")),
    };
    if !dir.join("geometries").is_dir() {
        panic!(
            "the shared test data is missing: no directory {}/geometries. This test needs the \
             project's shared data (the directory `shared/` with the test surfaces in \
             `geometries/`, kept beside the repository): put it beside this checkout as ../shared \
             (`cp -r` or `ln -s` from where it lives), or set BLMESH_SHARED to its path",
            dir.display()
        );
    }
    dir
}

/// The path of shared surface `name` (a file of `geometries/`); panics when it is absent.
pub fn shared_geometry(name: &str) -> PathBuf {
    let path = shared_dir().join("geometries").join(name);
    assert!(
        path.exists(),
        "the shared test surface {} is missing (the shared data there is incomplete)",
        path.display()
    );
    path
}
