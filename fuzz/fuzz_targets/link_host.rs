//! The scene's library's side of the host link: any bytes from a device, raw or framed,
//! read by `mccs_client`'s worker after the device's hello. The check is
//! `mccs_host::fuzz_checks::link_host`, which an ordinary test also runs over the
//! committed inputs (`fuzz/seeds/link_host/`) and whatever fuzzing left.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mccs_host::fuzz_checks::link_host(data));
