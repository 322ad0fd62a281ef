//! A device's address (`--connect`, `Device::open`): any text gives an address that reads
//! back as itself or a reason, and the client's error names it on one line.
//! The check is `mccs_host::fuzz_checks::addr`, which an ordinary test also runs over
//! the committed inputs (`fuzz/seeds/addr/`) and whatever fuzzing left.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mccs_host::fuzz_checks::addr(data));
