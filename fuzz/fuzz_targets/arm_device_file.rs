//! The arm's device-file parser (`mccs arm`, `mccs replay --device`): any text gives a
//! one-line error naming the file (and the line and key where there is one), or a valid
//! arm that the core builds and whose chain runs at its home counts without a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|text: &str| {
    match mccs_host::arm::device_file::parse(text, Path::new("fuzz.toml")) {
        Ok(spec) => {
            assert!(spec.validate().is_ok());
            let arm = mccs::Arm::new(&spec).expect("validated");
            let pose = arm.pose(arm.home_counts());
            let drive = arm.drive(&pose, [mccs::Force::from_num(1); 3]);
            assert!(drive.duty_q16.iter().all(|d| d.abs() <= 65_536));
        }
        Err(e) => assert!(e.starts_with("fuzz.toml") && !e.contains('\n'), "{e}"),
    }
});
