//! Picks the memory map by target, with no hand edits: `memory/stm32f405.x` (the default
//! STM32F405-class Cortex-M4F) for thumbv7em, `memory/lm3s6965.x` for thumbv7m (Cortex-M3),
//! and `memory/nrf51.x` for thumbv6m (Cortex-M0), all at the workspace root. It is copied
//! to OUT_DIR as `target-memory.x`, which the root `memory.x` includes (see the comment
//! there for why the root file is a selector). Host builds need none of it.

use std::{env, fs, path::PathBuf};

fn main() {
    let root = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it")).join("..");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=../memory.x");
    println!("cargo:rerun-if-changed=../memory");
    let target = env::var("TARGET").unwrap_or_default();
    let memory = if target.starts_with("thumbv7em") {
        "memory/stm32f405.x"
    } else if target.starts_with("thumbv7m") {
        "memory/lm3s6965.x"
    } else if target.starts_with("thumbv6m") {
        "memory/nrf51.x"
    } else {
        return;
    };
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let dir = out.join("link");
    fs::create_dir_all(&dir).expect("create OUT_DIR/link");
    fs::copy(root.join(memory), dir.join("target-memory.x")).expect("copy the memory map");
    println!("cargo:rustc-link-search={}", dir.display());
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
