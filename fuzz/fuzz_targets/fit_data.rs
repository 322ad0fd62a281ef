//! The fit's data parser: any text gives a one-line error naming the file (and row), or
//! The check is `mccs_host::fuzz_checks::fit_data`, which an ordinary test also runs over
//! the committed inputs (`fuzz/seeds/fit_data/`) and whatever fuzzing left.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mccs_host::fuzz_checks::fit_data(data));
