//! Wall-clock time of `mccs fit`'s three models on synthetic data (the Table 2 MCCS
//! law with 1 % noise) of 1,000 and 10,000 rows: `cargo bench -p mccs-host --bench fit`.
//! Prints `FITBENCH rows=<n> model=<m> seconds=<s> mean_abs=<f>`. A benchmark, not a
//! test: nothing is asserted.

use mccs::Params;
use mccs_host::fit::{self, synthesize, Fitted, ModelKind};
use std::time::Instant;

fn main() {
    let rows: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let rows = if rows.is_empty() {
        vec![1_000, 10_000]
    } else {
        rows
    };
    for n in rows {
        let forces: Vec<f64> = (1..=n).map(|i| i as f64 / n as f64).collect();
        let data = synthesize(&Fitted::Mccs(Params::TABLE2), &forces, 0.01, 7);
        let mut total = 0.0;
        for kind in ModelKind::ALL {
            let t = Instant::now();
            let f = fit::fit_rows(kind, &data, &mut |_| {}).expect("fits");
            let s = t.elapsed().as_secs_f64();
            total += s;
            println!(
                "FITBENCH rows={n} model={} seconds={s:.3} mean_abs={:.6}",
                kind.name(),
                f.metrics.mean_abs
            );
        }
        println!("FITBENCH rows={n} model=all seconds={total:.3}");
    }
}
