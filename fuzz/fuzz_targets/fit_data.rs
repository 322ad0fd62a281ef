//! The fit's data parser: any text gives a one-line error naming the file (and row), or
//! rows the models can take.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|text: &str| {
    match mccs_host::fit::parse_data(text, "fuzz.csv") {
        Ok(points) => {
            assert!(points.len() >= 5 && points.len() <= mccs_host::fit::MAX_ROWS);
            for w in points.windows(2) {
                assert!(w[1].0 > w[0].0 && w[1].1 > w[0].1);
            }
            assert!(points.iter().all(|&(e, f)| e > 0.0 && e < 1.0 && f > 0.0));
            let m = mccs_host::fit::metrics(&mccs_host::fit::Fitted::Mccs(mccs::Params::TABLE2), &points);
            assert!(m.mean_abs.is_finite());
        }
        Err(e) => {
            let line = e.to_string();
            assert!(line.starts_with("fuzz.csv: ") && !line.contains('\n'), "{line}");
        }
    }
});
