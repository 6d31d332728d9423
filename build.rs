//! Builds the C++ shim around TetGen (feature `tetgen`, on by default; TetGen is AGPL and comes
//! from the system package `libtet1.5-dev`: header `tetgen.h`, library `libtet.so`), and links
//! the CGNS library (feature `cgns`; Debian `libcgns-dev`: header `cgnstypes.h`, `libcgns.so`).

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=csrc/tetgen_shim.cpp");
    println!("cargo::rustc-check-cfg=cfg(cgns_size64)");
    if std::env::var_os("CARGO_FEATURE_CGNS").is_some() {
        link_cgns();
    }
    if std::env::var_os("CARGO_FEATURE_TETGEN").is_some() {
        build_tetgen_shim();
    }
}

/// Link `libcgns` and tell the FFI the width of its `cgsize_t` (32 bits unless `cgnstypes.h`
/// says the library is a non-legacy 64-bit build). `CGNS_INCLUDE_DIR` names a non-standard
/// header directory.
fn link_cgns() {
    let dirs = std::env::var("CGNS_INCLUDE_DIR")
        .into_iter()
        .chain(["/usr/include".into(), "/usr/local/include".into()]);
    let header = dirs.map(|d| std::path::Path::new(&d).join("cgnstypes.h")).find(|p| p.exists());
    let Some(header) = header else {
        panic!(
            "the `cgns` feature needs the CGNS library: cgnstypes.h was not found in /usr/include or \
             $CGNS_INCLUDE_DIR.\nInstall it (Debian: apt-get install libcgns-dev, or run scripts/setup.sh), \
             or build without `--features cgns`"
        );
    };
    println!("cargo:rerun-if-env-changed=CGNS_INCLUDE_DIR");
    println!("cargo:rerun-if-changed={}", header.display());
    let text = std::fs::read_to_string(&header).unwrap_or_default();
    let defined = |name: &str| {
        text.lines().any(|l| {
            let words: Vec<&str> = l.split_whitespace().collect();
            words.len() >= 3 && words[0] == "#define" && words[1] == name && words[2] == "1"
        })
    };
    if !defined("CG_BUILD_LEGACY") && defined("CG_BUILD_64BIT") {
        println!("cargo:rustc-cfg=cgns_size64");
    }
    println!("cargo:rustc-link-lib=dylib=cgns");
}

fn build_tetgen_shim() {
    // `cpp(true)` also links the C++ runtime; the shim catches every exception itself.
    let built = cc::Build::new()
        .cpp(true)
        .file("csrc/tetgen_shim.cpp")
        .flag_if_supported("-std=c++11")
        .warnings(true)
        .try_compile("blmesh_tetgen_shim");
    if let Err(e) = built {
        panic!(
            "cannot build the TetGen shim ({e}).\nInstall TetGen (Debian: apt-get install libtet1.5-dev, \
             or run scripts/setup.sh), or build without the core fill: --no-default-features"
        );
    }
    // After the shim, so that the linker sees the shim's references to TetGen first.
    println!("cargo:rustc-link-lib=dylib=tet");
}
