//! Every test geometry reads through `blmesh::io::read_surface` with the triangle and patch
//! counts of `../shared/geometries/README.md`, as a clean indexed surface enclosing a positive
//! volume; the UH3D and STL versions of the CAPE arrow are the same surface.

use std::collections::BTreeSet;
use std::path::PathBuf;

use blmesh::io::read_surface;
use blmesh::surface::Surface;

#[path = "common/shared.rs"]
mod shared;

fn geometry(name: &str) -> PathBuf {
    shared::shared_dir().join("geometries").join(name)
}

fn read(name: &str) -> Surface {
    read_surface(&geometry(name)).unwrap_or_else(|e| panic!("{e}"))
}

/// (file, triangles, patches where the README gives them, genus). The genus checks the
/// vertex count (welding, unused points) through Euler's formula for a closed surface.
const TABLE: &[(&str, usize, Option<usize>, i64)] = &[
    ("cutcube_cfmesh.stl", 48, Some(2), 0),
    ("mech_test_gapdetection.obj", 76, None, 0),
    ("building_wtc2.obj", 198, None, 0),
    ("fandisk.obj", 12946, None, 0),
    ("flange.stl", 6468, Some(4), 4),
    ("spot.obj", 5856, None, 0),
    ("bunny_closed_herholz.off", 28576, None, 0),
    ("arrow_cape.uh3d", 9216, Some(7), 0),
    ("arrow_cape.stl", 9216, Some(7), 0),
    ("elbow_90degree_cfmesh.stl", 5150, Some(9), 0),
    ("onera_m6_gmsh_coarse.stl", 28944, Some(11), 0),
];

/// Every index in range, every point used, one patch per triangle and every patch used.
fn assert_clean(name: &str, s: &Surface) {
    let n = s.points.len() as u32;
    let mut used = vec![false; s.points.len()];
    for t in &s.triangles {
        for &v in t {
            assert!(v < n, "{name}: index {v} out of range ({n} points)");
            used[v as usize] = true;
        }
    }
    assert!(used.iter().all(|&u| u), "{name}: unused points");
    assert_eq!(s.triangle_patch.len(), s.triangles.len(), "{name}");
    assert!(s.patch_triangle_counts().iter().all(|&c| c > 0), "{name}: empty patch");
}

#[test]
fn every_geometry_reads_with_the_readme_counts() {
    let files: BTreeSet<String> = std::fs::read_dir(geometry(""))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|f| f != "README.md")
        .collect();
    let listed: BTreeSet<String> = TABLE.iter().map(|(f, ..)| f.to_string()).collect();
    assert_eq!(files, listed, "every file of the geometries folder is in the table");
    for &(name, triangles, patches, genus) in TABLE {
        let s = read(name);
        assert_eq!(s.triangles.len(), triangles, "{name}: triangles");
        // V - E + T = 2 - 2 genus with E = 3T/2.
        let euler = 2 * s.points.len() as i64 - triangles as i64;
        assert_eq!(euler, 4 - 4 * genus, "{name}: {} points", s.points.len());
        if let Some(p) = patches {
            assert_eq!(s.patch_names.len(), p, "{name}: patches {:?}", s.patch_names);
        }
        assert_clean(name, &s);
        assert!(s.enclosed_volume() > 0.0, "{name}: volume {}", s.enclosed_volume());
    }
}

fn relative_difference(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs())
}

#[test]
fn arrow_uh3d_and_stl_are_the_same_surface() {
    let uh3d = read("arrow_cape.uh3d");
    let stl = read("arrow_cape.stl");
    assert_eq!(uh3d.triangles.len(), 9216);
    assert_eq!(stl.triangles.len(), 9216);
    assert_eq!(uh3d.points.len(), stl.points.len(), "welded vertex counts");
    let names = |s: &Surface| s.patch_names.iter().cloned().collect::<BTreeSet<_>>();
    assert_eq!(names(&uh3d), names(&stl));
    assert_eq!(names(&stl).len(), 7);
    let (vu, vs) = (uh3d.enclosed_volume(), stl.enclosed_volume());
    assert!(relative_difference(vu, vs) < 1e-9, "volumes {vu} {vs}");
    let (bu, bs) = (uh3d.bounding_box(), stl.bounding_box());
    let scale = bu.diagonal();
    assert!((bu.min - bs.min).abs().max_element() < 1e-9 * scale, "{bu:?} {bs:?}");
    assert!((bu.max - bs.max).abs().max_element() < 1e-9 * scale, "{bu:?} {bs:?}");
    // Patch by patch: the same number of triangles under each name.
    let per_name = |s: &Surface| {
        let counts = s.patch_triangle_counts();
        s.patch_names.iter().cloned().zip(counts).collect::<BTreeSet<_>>()
    };
    assert_eq!(per_name(&uh3d), per_name(&stl));
}

/// Medit round trip: points bit-exact, triangles and patches unchanged (references = patch
/// index + 1, so patches come back in the same order, named `ref_<n>`).
#[test]
fn medit_ascii_and_binary_round_trip_every_geometry() {
    use blmesh::io::medit;
    for &(name, ..) in TABLE {
        let s = read(name);
        for binary in [false, true] {
            let mut bytes = Vec::new();
            medit::write_surface(&mut bytes, &s, binary).unwrap();
            let back = medit::parse_surface(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
            let bits =
                |s: &Surface| s.points.iter().map(|p| p.to_array().map(f64::to_bits)).collect::<Vec<_>>();
            assert!(bits(&back) == bits(&s), "{name} (binary: {binary}): points differ");
            assert!(back.triangles == s.triangles, "{name} (binary: {binary}): triangles differ");
            assert!(back.triangle_patch == s.triangle_patch, "{name} (binary: {binary}): patches");
            let names: Vec<String> = (1..=s.patch_names.len()).map(|r| format!("ref_{r}")).collect();
            assert_eq!(back.patch_names, names, "{name}");
        }
    }
}
