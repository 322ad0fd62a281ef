//! The demo check's SUMMARY parser (`mccs demo --check`, the arm demo's fields too): any
//! line gives `None` or a summary whose fields, printed again as the firmware prints
//! them, parse to the same.
#![no_main]
use libfuzzer_sys::fuzz_target;
use mccs_host::cli::parse_summary;

fuzz_target!(|line: &str| {
    if let Some(s) = parse_summary(line) {
        let mut again = format!(
            "SUMMARY ticks={} overruns={} max_force_n={} steady_force_n={} window_shifts={}",
            s.ticks, s.overruns, s.max_force, s.steady_force, s.window_shifts
        );
        if let Some(arm) = s.arm {
            let [a, b, c] = arm.steady_duty;
            again += &format!(
                " steady_duty_a={a} steady_duty_b={b} steady_duty_c={c} max_duty={}",
                arm.max_duty
            );
        }
        let t = parse_summary(&again).expect("a printed summary parses");
        assert_eq!(t.ticks, s.ticks);
        assert_eq!(t.window_shifts, s.window_shifts);
        assert!(t.max_force.to_bits() == s.max_force.to_bits() || s.max_force.is_nan());
        assert_eq!(t.arm.is_some(), s.arm.is_some());
        if let (Some(x), Some(y)) = (t.arm, s.arm) {
            assert!(x.max_duty.to_bits() == y.max_duty.to_bits() || y.max_duty.is_nan());
        }
    }
});
