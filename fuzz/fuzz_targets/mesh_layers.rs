//! `mesh --no-core` on small surfaces: OBJ bytes (the text format that libFuzzer's mutations
//! keep readable longest) through validation, features, normals and the layers. No panic.
#![no_main]

use blmesh::config::Config;
use blmesh::pipeline::{run, MeshOptions};
use blmesh::progress::Progress;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(surface) = blmesh::io::obj::parse(data) else { return };
    if surface.triangles.len() > 400 {
        return;
    }
    let _ = run(surface, &Config::default(), &MeshOptions { core: false }, Progress::new(true));
});
