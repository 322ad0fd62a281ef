//! A tissue file (`mccs table --format bin`): any bytes give a typed reason on one line
//! or a tissue that writes back as the same bytes.
//! The check is `mccs_host::fuzz_checks::tissue_file`, which an ordinary test also runs
//! over the committed inputs (`fuzz/seeds/tissue_file/`) and whatever fuzzing left.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mccs_host::fuzz_checks::tissue_file(data));
