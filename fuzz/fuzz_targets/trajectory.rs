//! The replay's trajectory parser: any text gives a one-line error naming the file (and
//! line), or a trajectory whose samples are finite and within range.
#![no_main]
use libfuzzer_sys::fuzz_target;
use mccs_host::trajectory::{parse, MAX_POSITION_MM};

fuzz_target!(|text: &str| {
    match parse(text, "fuzz.csv") {
        Ok(t) => {
            let (a, b) = t.span();
            assert!(a.is_finite() && b.is_finite() && b >= a);
            for x in [a, (a + b) / 2.0, b, a - 1.0, b + 1.0] {
                assert!(t.at(x).iter().all(|c| c.is_finite() && c.abs() <= MAX_POSITION_MM));
            }
        }
        Err(e) => {
            let line = e.to_string();
            assert!(line.starts_with("fuzz.csv") && !line.contains('\n'), "{line}");
        }
    }
});
