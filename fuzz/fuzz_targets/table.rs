//! The table builder's arguments (any spring scale, domain and knot count) and any raw
//! The check is `mccs_host::fuzz_checks::table`, which an ordinary test also runs over
//! the committed inputs (`fuzz/seeds/table/`) and whatever fuzzing left.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mccs_host::fuzz_checks::table(data));
