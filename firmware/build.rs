//! Puts the STM32F405's real memory map (the repository root's `memory.x`) and the stack
//! placement (`stack.x`) on the linker's search path, and the defmt linker script when the
//! `defmt` (QEMU) or `board` feature is on. The `m7` feature takes `memory-an500.x` instead
//! (QEMU's mps2-an500).

use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    // The one memory map of the part lives at the repository root (docs/spec.md §1); copy it verbatim.
    // The `m7` build runs on QEMU's mps2-an500 (Cortex-M7), whose memory starts at 0.
    let memory_x = if env::var_os("CARGO_FEATURE_M7").is_some() {
        manifest.join("memory-an500.x")
    } else {
        manifest.join("../memory.x")
    };
    fs::copy(&memory_x, out.join("memory.x"))
        .unwrap_or_else(|e| panic!("copying {}: {e}", memory_x.display()));
    let stack_x = manifest.join("stack.x");
    fs::copy(&stack_x, out.join("stack.x"))
        .unwrap_or_else(|e| panic!("copying {}: {e}", stack_x.display()));
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory_x.display());
    println!("cargo:rerun-if-changed={}", stack_x.display());
    println!("cargo:rerun-if-changed=build.rs");
    if env::var_os("CARGO_FEATURE_DEFMT").is_some() || env::var_os("CARGO_FEATURE_BOARD").is_some()
    {
        println!("cargo:rustc-link-arg=-Tdefmt.x");
    }
}
