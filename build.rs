//! Tells the core whether its target has the Armv7E-M DSP extension (the Cortex-M4/M7:
//! `thumbv7em-*`), whose spring loop is written in assembly (`src/arith/wide_dsp/`).
//! Rust does not expose the `dsp` target feature to `cfg` on stable.

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rustc-check-cfg=cfg(mccs_dsp)");
    let target = std::env::var("TARGET").unwrap_or_default();
    if target.starts_with("thumbv7em-") {
        println!("cargo:rustc-cfg=mccs_dsp");
    }
}
