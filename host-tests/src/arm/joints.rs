//! A recorded arm motion: CSV `time_s,count_a,count_b,count_c` (times strictly
//! increasing, whole counts), sampled linearly at a tick rate and rounded to counts, as
//! an encoder would read them; each tick's probe is the core's fixed forward kinematics
//! (`mccs replay --device --joints`).

use mccs::{Arm, ArmPose};
use mccs_client::shown::ShownPath;

/// The rows of a joints file, or one line naming the file and the row (the header is
/// row 1).
pub fn read(path: &std::path::Path) -> Result<Vec<(f64, [f64; 3])>, String> {
    let file = ShownPath(path).to_string();
    let text = mccs_client::input::read_text(path, mccs_client::input::DATA_BYTES)
        .map_err(|e| format!("{file}: cannot read: {e}"))?;
    parse(&text, &file)
}

/// [`read`] on text; `file` names it in errors.
pub fn parse(text: &str, file: &str) -> Result<Vec<(f64, [f64; 3])>, String> {
    let header = ["time_s", "count_a", "count_b", "count_c"];
    let mut rows: Vec<(f64, [f64; 3])> = Vec::new();
    for (row, v) in super::columns::numbered(text, file, &header)? {
        if rows.last().is_some_and(|&(t, _)| v[0] <= t) {
            return Err(format!("{file}: row {row}: times must increase strictly"));
        }
        if rows.first().is_some_and(|&(t, _)| v[0] - t > 3600.0) {
            return Err(format!(
                "{file}: row {row}: longer than 3600 s from the first row"
            ));
        }
        rows.push((v[0], [v[1], v[2], v[3]]));
    }
    if rows.is_empty() {
        return Err(format!("{file}: no rows after the header"));
    }
    Ok(rows)
}

/// Each tick's time, counts (rounded) and pose, at `rate` Hz from the first row to the
/// last (the ticks `mccs replay` samples a probe trajectory at).
pub fn ticks(rows: &[(f64, [f64; 3])], rate: f64, arm: &Arm) -> Vec<(f64, [i32; 3], ArmPose)> {
    let (t0, t1) = (rows[0].0, rows[rows.len() - 1].0);
    let n = ((t1 - t0) * rate * (1.0 + 1e-12)).floor() as usize;
    (0..=n)
        .map(|k| {
            let t = t0 + k as f64 / rate;
            let i = rows.partition_point(|r| r.0 <= t);
            let c = if i == 0 {
                rows[0].1
            } else if i == rows.len() {
                rows[i - 1].1
            } else {
                let ((ta, a), (tb, b)) = (rows[i - 1], rows[i]);
                let u = (t - ta) / (tb - ta);
                std::array::from_fn(|j| a[j] + (b[j] - a[j]) * u)
            };
            let counts = c.map(|x| x.round() as i32);
            (t, counts, arm.pose(counts))
        })
        .collect()
}
