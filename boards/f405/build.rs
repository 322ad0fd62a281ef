//! The board firmware's build facts:
//!
//! - the platform, one `cfg` per fact, from the features (so that the code names the
//!   fact, not the feature that implies it; docs/firmware.md, "Builds"):
//!   - `board_qemu`: it runs in QEMU (`netduinoplus2`): the reset clock, QEMU's timer
//!     clock, defmt over semihosting, SysTick as the cycle counter, the exit through
//!     semihosting (features `qemu`, `qemu-link`);
//!   - `board_run_ends`: a QEMU run that ends after `qemu_ticks` with its SUMMARY
//!     (`qemu` without `qemu-link`);
//!   - `board_sim`: the plant is simulated — no encoder, no driver (`sim`);
//!   - `board_arm`: the 3-DOF arm, not the 1-DOF lever (`arm`);
//!   - `board_fault_test`: a fault injected after 100 ticks (`fault-test`);
//! - the STM32F405's memory map: `memory/stm32f405.x` at the workspace root, copied to
//!   OUT_DIR as `target-memory.x`, which the root `memory.x` (a selector: see its
//!   comment) includes. Host builds need none of it.

use std::{env, fs, path::PathBuf};

/// Whether cargo builds with `feature`.
fn feature(name: &str) -> bool {
    env::var_os(format!(
        "CARGO_FEATURE_{}",
        name.to_uppercase().replace('-', "_")
    ))
    .is_some()
}

fn main() {
    let facts = [
        ("board_qemu", feature("qemu") || feature("qemu-link")),
        ("board_run_ends", feature("qemu") && !feature("qemu-link")),
        ("board_sim", feature("sim")),
        ("board_arm", feature("arm")),
        ("board_fault_test", feature("fault-test")),
    ];
    for (name, on) in facts {
        println!("cargo::rustc-check-cfg=cfg({name})");
        if on {
            println!("cargo::rustc-cfg={name}");
        }
    }
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
