//! The `plant` executable exports its `exit` and `_exit` (plant/src/fmu_exit.rs), so that an
//! in-process controller FMU's calls of them are bound to the plant's, not the C library's.

fn main() {
    println!("cargo:rustc-link-arg-bin=plant=-Wl,--export-dynamic-symbol=exit,--export-dynamic-symbol=_exit");
    println!("cargo:rerun-if-changed=build.rs");
}
