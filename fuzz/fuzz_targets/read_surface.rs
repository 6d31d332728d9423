//! Every surface reader on arbitrary bytes: the first byte picks the format. A reader returns a
//! surface or an error; it never panics, and a surface it returns has its indices in range.
#![no_main]

use blmesh::io::SurfaceFormat;
use libfuzzer_sys::fuzz_target;

const FORMATS: [&str; 8] = ["stl", "obj", "off", "msh", "mesh", "meshb", "tri", "uh3d"];

fuzz_target!(|data: &[u8]| {
    let Some((&pick, bytes)) = data.split_first() else { return };
    let name = format!("x.{}", FORMATS[pick as usize % FORMATS.len()]);
    let format = SurfaceFormat::from_path(name.as_ref()).expect("a known extension");
    if let Ok(surface) = format.parse(bytes) {
        let n = surface.points.len();
        assert!(surface.triangles.iter().flatten().all(|&v| (v as usize) < n));
        assert_eq!(surface.triangle_patch.len(), surface.triangles.len());
    }
});
