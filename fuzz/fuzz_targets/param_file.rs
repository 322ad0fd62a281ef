//! The parameter-file parser and validator: any text gives a typed, one-line error or a
//! valid spring whose law, reference and table build without a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|text: &str| {
    match mccs_host::paramfile::parse(text, Path::new("fuzz.toml")) {
        Ok(p) => {
            assert!(p.validate().is_ok());
            let law = mccs::Law::new(&p).expect("validated");
            let _ = mccs_host::reference::Reference::new(&p).expect("validated");
            let _ = mccs::ForceTable64::one_placement_unmeasured(&law, -0.5, 0.95);
            let again = mccs_host::paramfile::parse(&mccs_host::paramfile::to_toml(&p), Path::new("x"));
            assert_eq!(again, Ok(p), "round trip");
        }
        Err(e) => {
            let line = e.to_string();
            assert!(line.starts_with("fuzz.toml: ") && !line.contains('\n'), "{line}");
        }
    }
});
