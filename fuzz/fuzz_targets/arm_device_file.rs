//! The arm's device-file parser (`mccs arm`, `mccs replay --device`): any text gives a
//! The check is `mccs_host::fuzz_checks::arm_device_file`, which an ordinary test also runs over
//! the committed inputs (`fuzz/seeds/arm_device_file/`) and whatever fuzzing left.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mccs_host::fuzz_checks::arm_device_file(data));
