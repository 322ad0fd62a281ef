//! A request to `mccs view`'s server: any bytes are refused with a status, or read
//! whole, and a body that is not a pose or a tissue says why in one line. The check is
//! `mccs_host::fuzz_checks::view_request`, which an ordinary test also runs over the
//! committed inputs (`fuzz/seeds/view_request/`) and whatever fuzzing left.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mccs_host::fuzz_checks::view_request(data));
