//! The recorded arm motion's parser (`mccs replay --device FILE --joints CSV`): any text
//! gives a one-line error naming the file (and row), or rows with increasing times and
//! whole counts that the WoodenHaptics arm samples at 10 Hz without a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|text: &str| {
    match mccs_host::arm::joints::parse(text, "fuzz.csv") {
        Ok(rows) => {
            assert!(rows.windows(2).all(|w| w[1].0 > w[0].0));
            assert!(rows.iter().all(|r| r.1.iter().all(|c| c.fract() == 0.0)));
            let arm = mccs::Arm::new(&mccs_firmware::arm::device::WOODENHAPTICS).expect("valid");
            let ticks = mccs_host::arm::joints::ticks(&rows, 10.0, &arm);
            assert!(!ticks.is_empty());
        }
        Err(e) => assert!(e.starts_with("fuzz.csv") && !e.contains('\n'), "{e}"),
    }
});
