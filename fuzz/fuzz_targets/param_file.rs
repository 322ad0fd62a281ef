//! The parameter-file parser and validator: any text gives a typed, one-line error or a
//! The check is `mccs_host::fuzz_checks::param_file`, which an ordinary test also runs over
//! the committed inputs (`fuzz/seeds/param_file/`) and whatever fuzzing left.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mccs_host::fuzz_checks::param_file(data));
