//! The replay's trajectory parser: any text gives a one-line error naming the file (and
//! The check is `mccs_host::fuzz_checks::trajectory`, which an ordinary test also runs over
//! the committed inputs (`fuzz/seeds/trajectory/`) and whatever fuzzing left.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mccs_host::fuzz_checks::trajectory(data));
