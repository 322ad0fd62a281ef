//! The arm's numeric CSV inputs (`mccs arm fk --counts`, `torque --input`, `calibrate
//! --poses`, and the recorded motion of `replay --joints`): a fixed header, then rows of
//! finite numbers, each column held to its kind.

use mccs_client::shown::Shown;

/// The rows of numeric CSV text with exactly `header`; one line naming `file` and the
/// row (the header is row 1) for anything else. Counts (`count_*`) whole and within
/// `i32`, forces (`*_n`) within ±2,000 N, duties (`duty_*`) within ±1. Blank lines are
/// skipped.
pub fn parse(text: &str, file: &str, header: &[&str]) -> Result<Vec<Vec<f64>>, String> {
    Ok(numbered(text, file, header)?
        .into_iter()
        .map(|(_, v)| v)
        .collect())
}

/// [`parse`], each row with its number in the file (the header is row 1), for checks
/// across rows.
pub fn numbered(text: &str, file: &str, header: &[&str]) -> Result<Vec<(usize, Vec<f64>)>, String> {
    let mut lines = text.lines();
    let want = header.join(",");
    match lines
        .next()
        .map(|h| h.trim().trim_start_matches('\u{feff}'))
    {
        Some(h) if h == want => {}
        Some(h) => {
            return Err(format!(
                "{file}: row 1: the header must be `{want}`, not `{}`",
                Shown(h)
            ))
        }
        None => return Err(format!("{file}: empty file")),
    }
    let mut out = Vec::new();
    for (i, line) in lines.enumerate() {
        let row = i + 2;
        if line.trim().is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != header.len() {
            return Err(format!(
                "{file}: row {row}: {} fields, {} expected",
                fields.len(),
                header.len()
            ));
        }
        let mut v = Vec::with_capacity(fields.len());
        for (f, name) in fields.iter().zip(header) {
            v.push(value(f, name).map_err(|what| format!("{file}: row {row}: {name}: {what}"))?);
        }
        out.push((row, v));
    }
    Ok(out)
}

/// One field of the column `name`, held to its kind.
fn value(field: &str, name: &str) -> Result<f64, String> {
    let x: f64 = field
        .parse()
        .ok()
        .filter(|x: &f64| x.is_finite())
        .ok_or_else(|| format!("`{}` is not a finite number", Shown(field)))?;
    if name.starts_with("count_") {
        if x.fract() != 0.0 {
            return Err("must be a whole number of counts".into());
        }
        // (An encoder's count is an `i32`: −2147483648 is one.)
        if !(f64::from(i32::MIN)..=f64::from(i32::MAX)).contains(&x) {
            return Err("must be within −2147483648 … 2147483647 counts (an i32)".into());
        }
    }
    if name.starts_with("duty_") && x.abs() > 1.0 {
        return Err("must be within ±1 (a fraction of full duty)".into());
    }
    if name.ends_with("_n") && x.abs() > 2000.0 {
        return Err("must be within ±2000 N".into());
    }
    Ok(x)
}
