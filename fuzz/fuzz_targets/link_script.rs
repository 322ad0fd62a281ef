//! A scene's script (`mccs link script FILE`): any text through the script's parser,
//! its loads answered without a file. The check is
//! `mccs_host::fuzz_checks::link_script`, which an ordinary test also runs over the
//! committed inputs (`fuzz/seeds/link_script/`) and whatever fuzzing left.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mccs_host::fuzz_checks::link_script(data));
