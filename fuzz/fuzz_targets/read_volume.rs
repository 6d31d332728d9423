//! The volume mesh readers (`check`'s input) on arbitrary bytes: the first byte picks MSH or
//! VTU; no panic, and a mesh that is read is checked without one.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&pick, bytes)) = data.split_first() else { return };
    let parsed = if pick % 2 == 0 { blmesh::io::msh::parse_volume(bytes) } else { blmesh::io::vtu::parse(bytes) };
    if let Ok(mesh) = parsed {
        if mesh.points.len() < 10_000 {
            let _ = blmesh::quality::check(&mesh);
        }
    }
});
