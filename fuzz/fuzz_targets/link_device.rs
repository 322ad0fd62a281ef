//! The device's side of the host link: any bytes, decoded and handled as the board's
//! The check is `mccs_host::fuzz_checks::link_device`, which an ordinary test also runs over
//! the committed inputs (`fuzz/seeds/link_device/`) and whatever fuzzing left.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mccs_host::fuzz_checks::link_device(data));
