//! Builds the C++ shim around TetGen (feature `tetgen`, on by default; TetGen is AGPL and comes
//! from the system package `libtet1.5-dev`: header `tetgen.h`, library `libtet.so`).

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=csrc/tetgen_shim.cpp");
    if std::env::var_os("CARGO_FEATURE_TETGEN").is_none() {
        return;
    }
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
