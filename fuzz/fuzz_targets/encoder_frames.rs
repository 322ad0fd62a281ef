//! The encoder driver on any stream of response frames and any mounting: no panic, and
//! The check is `mccs_host::fuzz_checks::encoder_frames`, which an ordinary test also runs over
//! the committed inputs (`fuzz/seeds/encoder_frames/`) and whatever fuzzing left.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mccs_host::fuzz_checks::encoder_frames(data));
