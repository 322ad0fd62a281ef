//! The demo check's SUMMARY parser (`mccs demo --check`, the arm demo's fields too): any
//! The check is `mccs_host::fuzz_checks::demo_summary`, which an ordinary test also runs over
//! the committed inputs (`fuzz/seeds/demo_summary/`) and whatever fuzzing left.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mccs_host::fuzz_checks::demo_summary(data));
