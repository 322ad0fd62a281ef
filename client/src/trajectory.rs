//! Recorded probe trajectories: CSV `time_s,x_mm,y_mm,z_mm`, positions in the patch frame
//! (surface at `z = 0`, `z` up) at strictly increasing times, sampled linearly at a tick
//! rate. Every rejected file gets one line naming the file and the row (the header is row 1,
//! as in `mccs fit`'s data).

use crate::shown::Shown;
use std::fmt;
use std::path::Path;

/// The header a trajectory file starts with.
pub const HEADER: &str = "time_s,x_mm,y_mm,z_mm";
/// The most rows a trajectory may have (10 million: over 2 hours at 1 kHz).
pub const MAX_ROWS: usize = 10_000_000;
/// The largest |coordinate|, mm (the fixed-point solver's probe range).
pub const MAX_POSITION_MM: f64 = 100.0;
/// The longest trajectory, s.
pub const MAX_DURATION_S: f64 = 3600.0;

/// Why a trajectory file was rejected. `Display` is one line naming the file and row.
#[derive(Debug, Clone, PartialEq)]
pub struct TrajectoryError {
    /// The file.
    pub file: String,
    /// The row (1-based, the header is row 1), when one is at fault.
    pub row: Option<usize>,
    /// What is wrong.
    pub what: String,
}

impl fmt::Display for TrajectoryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.row {
            Some(r) => write!(f, "{}: row {r}: {}", self.file, self.what),
            None => write!(f, "{}: {}", self.file, self.what),
        }
    }
}

impl std::error::Error for TrajectoryError {}

/// A probe trajectory: times (s) and positions (mm).
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    samples: Vec<(f64, [f64; 3])>,
}

impl Trajectory {
    /// From samples (checked as a file's rows are).
    pub fn new(samples: Vec<(f64, [f64; 3])>) -> Result<Self, TrajectoryError> {
        let mut text = format!("{HEADER}\n");
        for (t, p) in &samples {
            text.push_str(&format!("{t:?},{:?},{:?},{:?}\n", p[0], p[1], p[2]));
        }
        parse(&text, "trajectory")
    }

    /// The first and last times, s.
    pub fn span(&self) -> (f64, f64) {
        (self.samples[0].0, self.samples[self.samples.len() - 1].0)
    }

    /// The position at time `t` (s): linear between samples, held before the first and
    /// after the last.
    pub fn at(&self, t: f64) -> [f64; 3] {
        let i = self.samples.partition_point(|s| s.0 <= t);
        if i == 0 {
            return self.samples[0].1;
        }
        if i == self.samples.len() {
            return self.samples[i - 1].1;
        }
        let ((t0, p0), (t1, p1)) = (self.samples[i - 1], self.samples[i]);
        let u = (t - t0) / (t1 - t0);
        std::array::from_fn(|k| p0[k] + (p1[k] - p0[k]) * u)
    }

    /// The sample times `t0 + k / rate` from the first time up to the last, and the
    /// positions there.
    pub fn ticks(&self, rate: f64) -> impl Iterator<Item = (f64, [f64; 3])> + '_ {
        let (t0, t1) = self.span();
        let n = ((t1 - t0) * rate * (1.0 + 1e-12)).floor() as usize;
        (0..=n).map(move |k| {
            let t = t0 + k as f64 / rate;
            (t, self.at(t))
        })
    }
}

/// Reads a trajectory file.
pub fn read(path: &Path) -> Result<Trajectory, TrajectoryError> {
    let file = crate::shown::ShownPath(path).to_string();
    let text =
        crate::input::read_text(path, crate::input::DATA_BYTES).map_err(|e| TrajectoryError {
            file: file.clone(),
            row: None,
            what: format!("cannot read: {e}"),
        })?;
    parse(&text, &file)
}

/// Parses trajectory text; `file` names it in errors.
pub fn parse(text: &str, file: &str) -> Result<Trajectory, TrajectoryError> {
    let err = |row: Option<usize>, what: String| TrajectoryError {
        file: file.to_string(),
        row,
        what,
    };
    let mut lines = text.lines().enumerate();
    match lines.next() {
        Some((_, h)) if h.trim().trim_start_matches('\u{feff}') == HEADER => {}
        Some((_, h)) => {
            return Err(err(
                Some(1),
                format!("the header must be `{HEADER}`, not `{}`", Shown(h.trim())),
            ))
        }
        None => return Err(err(None, "empty file".into())),
    }
    let mut samples: Vec<(f64, [f64; 3])> = Vec::new();
    for (i, line) in lines {
        let n = i + 1;
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        if samples.len() >= MAX_ROWS {
            return Err(err(Some(n), format!("more than {MAX_ROWS} rows")));
        }
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != 4 {
            return Err(err(Some(n), format!("{} fields, 4 expected", fields.len())));
        }
        let mut v = [0.0; 4];
        for (k, f) in fields.iter().enumerate() {
            v[k] = f
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| err(Some(n), format!("`{}` is not a finite number", Shown(f))))?;
        }
        let (t, p) = (v[0], [v[1], v[2], v[3]]);
        if p.iter().any(|x| x.abs() > MAX_POSITION_MM) {
            return Err(err(
                Some(n),
                format!("a position beyond ±{MAX_POSITION_MM} mm"),
            ));
        }
        if let Some(&(prev, _)) = samples.last() {
            if t <= prev {
                return Err(err(Some(n), "times must increase strictly".into()));
            }
        }
        if let Some(&(first, _)) = samples.first() {
            if t - first > MAX_DURATION_S {
                return Err(err(
                    Some(n),
                    format!("longer than {MAX_DURATION_S} s from the first row"),
                ));
            }
        }
        samples.push((t, p));
    }
    if samples.is_empty() {
        return Err(err(None, "no rows after the header".into()));
    }
    Ok(Trajectory { samples })
}
