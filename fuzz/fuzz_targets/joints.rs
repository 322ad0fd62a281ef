//! The recorded arm motion's parser (`mccs replay --device FILE --joints CSV`): any text
//! The check is `mccs_host::fuzz_checks::joints`, which an ordinary test also runs over
//! the committed inputs (`fuzz/seeds/joints/`) and whatever fuzzing left.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mccs_host::fuzz_checks::joints(data));
