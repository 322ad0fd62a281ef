//! Compression data: reading and checking `strain,force_n` files, and synthetic data
//! from a model.

use super::Fitted;
use mccs::Params;
use mccs_client::shown::ShownPath;
use mccs_client::shown::{Shown, ShownNumber};
use std::fmt;
use std::path::Path;

/// One measurement: strain (dimensionless) and force (N).
pub type Point = (f64, f64);

/// Why a data file was rejected. `Display` is one line naming the file and row.
#[derive(Debug, Clone, PartialEq)]
pub struct DataError {
    /// The file.
    pub file: String,
    /// 1-based row number in the file (the header is row 1), when it is about a row.
    pub row: Option<usize>,
    /// What is wrong.
    pub what: String,
}

impl fmt::Display for DataError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.row {
            Some(r) => write!(f, "{}: row {r}: {}", self.file, self.what),
            None => write!(f, "{}: {}", self.file, self.what),
        }
    }
}

impl std::error::Error for DataError {}

/// The most data rows a file may have.
pub const MAX_ROWS: usize = 1_000_000;

/// Reads and checks a data file: header `strain,force_n`, 5 … [`MAX_ROWS`] rows, every
/// value a finite number, the loading branch of a compression test (strain in (0, 1),
/// force > 0, both strictly increasing; a first row at `(0, 0)` is dropped:
/// [`read_data_noted`]).
pub fn read_data(path: &Path) -> Result<Vec<Point>, DataError> {
    read_data_noted(path).map(|(points, _)| points)
}

/// [`read_data`] on text; `file` names it in errors.
pub fn parse_data(text: &str, file: &str) -> Result<Vec<Point>, DataError> {
    parse_data_noted(text, file).map(|(points, _)| points)
}

/// [`read_data`], with what it did that the data do not show: a first row at `(0, 0)`,
/// the unloaded sample every compression test starts from and every model passes
/// through, is dropped (the models take strains above zero), and said so: the note.
pub fn read_data_noted(path: &Path) -> Result<(Vec<Point>, Option<String>), DataError> {
    let file = ShownPath(path).to_string();
    let text =
        mccs_client::input::read_text(path, mccs_client::input::DATA_BYTES).map_err(|e| {
            DataError {
                file: file.clone(),
                row: None,
                what: format!("cannot read: {e}"),
            }
        })?;
    parse_data_noted(&text, &file)
}

/// The fewest data rows a fit takes.
const MIN_ROWS: usize = 5;

/// [`read_data_noted`] on text.
pub fn parse_data_noted(text: &str, file: &str) -> Result<(Vec<Point>, Option<String>), DataError> {
    let err = |row: Option<usize>, what: String| DataError {
        file: file.to_owned(),
        row,
        what,
    };
    if text.trim().is_empty() {
        return Err(err(
            None,
            format!(
                "empty file: it needs the header `strain,force_n` and at least {MIN_ROWS} rows"
            ),
        ));
    }
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let header = reader
        .headers()
        .map_err(|e| err(Some(1), format!("unreadable header: {e}")))?;
    if header.iter().collect::<Vec<_>>() != ["strain", "force_n"] {
        let found: Vec<&str> = header.iter().collect();
        return Err(err(
            Some(1),
            format!(
                "the header must be `strain,force_n`, not `{}`",
                Shown(&found.join(","))
            ),
        ));
    }
    let mut points: Vec<Point> = Vec::new();
    let mut note = None;
    for (i, record) in reader.records().enumerate() {
        let row = i + 2;
        let record = record.map_err(|e| err(Some(row), format!("unreadable: {e}")))?;
        let (e, f) = row_values(&record).map_err(|what| err(Some(row), what))?;
        if points.is_empty() && note.is_none() && e == 0.0 && f == 0.0 {
            note = Some(format!(
                "{file}: row {row}: (0, 0), the unloaded sample: dropped (every model passes through it)"
            ));
            continue;
        }
        row_admissible(&points, e, f).map_err(|what| err(Some(row), what))?;
        points.push((e, f));
    }
    if points.len() < MIN_ROWS {
        return Err(err(
            None,
            format!("{} data rows, at least {MIN_ROWS} needed", points.len()),
        ));
    }
    Ok((points, note))
}

/// A row's strain and force, each a finite number.
fn row_values(record: &csv::StringRecord) -> Result<(f64, f64), String> {
    if record.len() != 2 {
        return Err(format!("{} fields, expected 2", record.len()));
    }
    let value = |k: usize, name: &str| -> Result<f64, String> {
        let v: f64 = record[k]
            .parse()
            .map_err(|_| format!("{name} `{}` is not a number", Shown(&record[k])))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(format!("{name} must be finite"))
        }
    };
    Ok((value(0, "strain")?, value(1, "force_n")?))
}

/// Whether the models can take the point `(e, f)` after `points`: they start unloaded at
/// zero strain (a row at or below zero carries nothing to fit, and breaks the starting
/// points), the MS model's stretch 1 − strain must stay positive, and both columns rise
/// strictly.
fn row_admissible(points: &[Point], e: f64, f: f64) -> Result<(), String> {
    if !(e > 0.0 && e < 1.0) {
        return Err(format!(
            "strain {} is outside (0, 1): the models take compressive strains above zero and below 1",
            ShownNumber(e)
        ));
    }
    if f <= 0.0 {
        return Err(format!(
            "force_n {} must be > 0 (the loading branch, from zero load)",
            ShownNumber(f)
        ));
    }
    if points.len() >= MAX_ROWS {
        return Err(format!("more than {MAX_ROWS} data rows"));
    }
    if let Some(&(e0, f0)) = points.last() {
        if e <= e0 {
            return Err("strain must increase strictly".into());
        }
        if f <= f0 {
            return Err("force_n must increase strictly".into());
        }
    }
    Ok(())
}

/// Data generated by `model` at `forces`, with multiplicative Gaussian noise of relative
/// size `noise` on the strain (seeded, reproducible).
pub fn synthesize(model: &Fitted, forces: &[f64], noise: f64, seed: u64) -> Vec<Point> {
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let normal = Normal::new(0.0, 1.0).expect("unit normal");
    let mut out: Vec<Point> = Vec::new();
    for &f in forces {
        let e = model.strain_at(f) * (1.0 + noise * normal.sample(&mut rng));
        // Keep the strain increasing (noise may not reorder a compression test).
        let e = out.last().map_or(e, |&(prev, _)| e.max(prev + 1e-9));
        out.push((e, f));
    }
    out
}

/// The shipped demo data set (`params/demo-data.csv`): synthetic, not measured. The
/// Table 2 MCCS spring loaded to 1 N (the paper's test) at 40 forces from 0.025 N,
/// strains with 1 % Gaussian noise, seed 2020.
pub fn demo_data() -> Vec<Point> {
    let forces: Vec<f64> = (1..=40).map(|i| i as f64 * 0.025).collect();
    synthesize(&Fitted::Mccs(Params::TABLE2), &forces, 0.01, 2020)
}

/// Writes points as CSV text.
pub fn to_csv(points: &[Point]) -> String {
    let mut s = String::from("strain,force_n\n");
    for (e, f) in points {
        s.push_str(&format!("{e:.9},{f:.6}\n"));
    }
    s
}
