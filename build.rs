//! Build script: with the `mumps` feature, compiles the C side of the MUMPS binding
//! (`src/linsolve/mumps/shim.c`) and links MUMPS (Debian's `libmumps-dev`). Without
//! it, nothing.

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    #[cfg(feature = "mumps")]
    mumps();
}

#[cfg(feature = "mumps")]
fn mumps() {
    let shim = "src/linsolve/mumps/shim.c";
    println!("cargo:rerun-if-changed={shim}");
    println!("cargo:rerun-if-env-changed=MUMPS_INCLUDE_DIR");
    println!("cargo:rerun-if-env-changed=MUMPS_LIB_DIR");
    let mut build = cc::Build::new();
    build.file(shim).warnings(true);
    if let Ok(dir) = std::env::var("MUMPS_INCLUDE_DIR") {
        build.include(dir);
    }
    build.compile("rothe_mumps_shim");
    if let Ok(dir) = std::env::var("MUMPS_LIB_DIR") {
        println!("cargo:rustc-link-search=native={dir}");
    }
    // The MPI library itself comes in through the `mpi` crate.
    println!("cargo:rustc-link-lib=dmumps");
    println!("cargo:rustc-link-lib=mumps_common");
}
