//! The arm's CSV inputs (`mccs arm fk --counts`, `torque --input`, `calibrate --poses`):
//! any text gives one line naming the file and row, or rows the fixed-point pose and the
//! gravity fit take without a panic or a non-finite figure.
//! The check is `mccs_host::fuzz_checks::arm_inputs`, which an ordinary test also runs over
//! the committed inputs (`fuzz/seeds/arm_inputs/`) and whatever fuzzing left.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mccs_host::fuzz_checks::arm_inputs(data));
