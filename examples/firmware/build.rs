//! Puts `memory.x` where the linker finds it (cortex-m-rt's `link.x` includes it), and
//! rebuilds when it or the embedded fixture changes.

use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy("memory.x", out.join("memory.x")).expect("copy memory.x to OUT_DIR");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=../../fixtures/firmware/bench_run_20s.i16be");
}
