//! The STM32F405's memory map for the board firmware: `memory/stm32f405.x` at the
//! workspace root, copied to OUT_DIR as `target-memory.x`, which the root `memory.x`
//! (a selector: see its comment) includes. Host builds need none of it.

use std::{env, fs, path::PathBuf};

fn main() {
    let root =
        PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it")).join("../..");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=../../memory/stm32f405.x");
    if !env::var("TARGET")
        .unwrap_or_default()
        .starts_with("thumbv7em")
    {
        return;
    }
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR")).join("link");
    fs::create_dir_all(&out).expect("create OUT_DIR/link");
    fs::copy(root.join("memory/stm32f405.x"), out.join("target-memory.x"))
        .expect("copy the memory map");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
