//! `include/mccs.h` is what cbindgen makes of `src/ffi.rs` and `src/ffi/` now: a change to the C ABI
//! fails here until the header moves with it (`MCCS_UPDATE_HEADER=1 cargo test -p
//! mccs-client --test header` rewrites it).

use std::path::Path;

#[test]
fn the_header_is_the_c_abi() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut out = Vec::new();
    let mut builder = cbindgen::Builder::new()
        .with_config(config)
        .with_src(dir.join("src/ffi.rs"));
    // cbindgen reads the files it is given, not their modules: each of `src/ffi/`.
    let mut parts: Vec<_> = std::fs::read_dir(dir.join("src/ffi"))
        .expect("src/ffi")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "rs"))
        .collect();
    parts.sort();
    for p in parts {
        builder = builder.with_src(p);
    }
    builder
        .generate()
        .expect("cbindgen reads src/ffi.rs")
        .write(&mut out);
    let made = String::from_utf8(out).unwrap();
    let path = dir.join("include/mccs.h");
    if std::env::var("MCCS_UPDATE_HEADER").as_deref() == Ok("1") {
        std::fs::write(&path, &made).unwrap();
        return;
    }
    let checked_in = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        checked_in == made,
        "client/include/mccs.h is not what cbindgen makes of src/ffi.rs: MCCS_UPDATE_HEADER=1 cargo test -p mccs-client --test header"
    );
    for f in [
        "mccs_open",
        "mccs_close",
        "mccs_last_error",
        "mccs_load_tissue",
        "mccs_arm",
        "mccs_mesh",
        "mccs_black_box",
        "mccs_stop_cause_name",
    ] {
        assert!(made.contains(f), "{f}");
    }
}
