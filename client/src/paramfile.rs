//! Reading and writing spring parameters in the TOML schema of `docs/model.md`, with
//! one-line errors that name the file and the key. The schema is the core's
//! [`ParamKey`]: its sections, keys, which are required, and how each is stored.

use crate::shown::Shown;
use mccs::{Derived, ParamError, ParamKey, Params};
use std::fmt;
use std::path::{Path, PathBuf};

/// What went wrong reading a parameter file. `Display` is one line naming file and key.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamFileError {
    /// The file could not be read.
    Read {
        /// The file.
        path: PathBuf,
        /// The OS error, as text.
        reason: String,
    },
    /// The file is not valid TOML.
    Toml {
        /// The file.
        path: PathBuf,
        /// Line of the error (1-based), when known.
        line: Option<usize>,
        /// The parser's message.
        message: String,
    },
    /// A required key is absent.
    Missing {
        /// The file.
        path: PathBuf,
        /// The key.
        key: ParamKey,
    },
    /// A key holds something other than a number.
    NotNumber {
        /// The file.
        path: PathBuf,
        /// The key's line (1-based), when found.
        line: Option<usize>,
        /// The key.
        key: ParamKey,
    },
    /// A key or table not in the schema (most often a typo).
    Unknown {
        /// The file.
        path: PathBuf,
        /// The key's line (1-based), when found.
        line: Option<usize>,
        /// The dotted key as written.
        key: String,
        /// The schema's nearest key or section, when one is close.
        nearest: Option<String>,
    },
    /// The values are numbers but break the rules (finite, > 0, D2 > D1).
    Invalid {
        /// The file.
        path: PathBuf,
        /// The line of the key at fault (1-based), when found.
        line: Option<usize>,
        /// The rule broken.
        error: ParamError,
        /// The values behind it, for the message (`F_C = 10.23 N`), when it is about a
        /// derived quantity.
        found: Option<String>,
    },
}

/// `FILE: ` or `FILE: line N: `.
fn at(f: &mut fmt::Formatter<'_>, path: &Path, line: Option<usize>) -> fmt::Result {
    match line {
        Some(l) => write!(f, "{}: line {l}: ", crate::shown::ShownPath(path)),
        None => write!(f, "{}: ", crate::shown::ShownPath(path)),
    }
}

impl fmt::Display for ParamFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Read { path, reason } => write!(
                f,
                "{}: cannot read: {reason}",
                crate::shown::ShownPath(path)
            ),
            Self::Toml {
                path,
                line,
                message,
            } => {
                at(f, path, *line)?;
                write!(f, "invalid TOML: {message}")
            }
            Self::Missing { path, key } => {
                write!(f, "{}: {key}: missing", crate::shown::ShownPath(path))
            }
            Self::NotNumber { path, line, key } => {
                at(f, path, *line)?;
                write!(f, "{key}: must be a number")
            }
            Self::Unknown {
                path,
                line,
                key,
                nearest,
            } => {
                at(f, path, *line)?;
                match nearest {
                    Some(n) => write!(f, "{}: unknown key; did you mean {n}?", Shown(key)),
                    None => write!(
                        f,
                        "{}: unknown key (docs/model.md lists the schema)",
                        Shown(key)
                    ),
                }
            }
            Self::Invalid {
                path,
                line,
                error,
                found,
            } => {
                at(f, path, *line)?;
                match found {
                    Some(v) => write!(f, "{error} ({v})"),
                    None => write!(f, "{error}"),
                }
            }
        }
    }
}

impl std::error::Error for ParamFileError {}

/// Reads and validates a parameter file.
pub fn read(path: &Path) -> Result<Params, ParamFileError> {
    let text = crate::input::read_text(path, crate::input::CONFIG_BYTES).map_err(|e| {
        ParamFileError::Read {
            path: path.to_owned(),
            reason: e.to_string(),
        }
    })?;
    parse(&text, path)
}

/// Parses and validates parameter-file text; `path` is only used in errors.
pub fn parse(text: &str, path: &Path) -> Result<Params, ParamFileError> {
    let table: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| ParamFileError::Toml {
            path: path.to_owned(),
            line: e
                .span()
                .map(|s| text[..s.start.min(text.len())].lines().count().max(1)),
            message: e.message().lines().next().unwrap_or("").to_owned(),
        })?;
    for (name, value) in &table {
        let unknown = |key: String, line: Option<usize>| ParamFileError::Unknown {
            path: path.to_owned(),
            line,
            nearest: nearest(&key),
            key,
        };
        let known = |k: &str| {
            ParamKey::ALL
                .iter()
                .any(|p| p.section() == name.as_str() && p.name() == k)
        };
        match value.as_table() {
            Some(t) if ParamKey::ALL.iter().any(|p| p.section() == name.as_str()) => {
                if let Some(k) = t.keys().find(|k| !known(k)) {
                    return Err(unknown(format!("{name}.{k}"), key_line(text, name, k)));
                }
            }
            _ => return Err(unknown(name.clone(), section_line(text, name))),
        }
    }
    // Every key starts at its Table 2 value and is overwritten; a required key missing
    // from the file is an error, the optional preload is absent unless given.
    let mut params = Params::TABLE2;
    for key in ParamKey::ALL {
        let value = table.get(key.section()).and_then(|s| s.get(key.name()));
        match value {
            Some(toml::Value::Float(x)) => key.set(&mut params, *x),
            Some(toml::Value::Integer(i)) => key.set(&mut params, *i as f64),
            Some(_) => {
                return Err(ParamFileError::NotNumber {
                    path: path.to_owned(),
                    line: key_line(text, key.section(), key.name()),
                    key,
                })
            }
            None if key.required() => {
                return Err(ParamFileError::Missing {
                    path: path.to_owned(),
                    key,
                })
            }
            None => {}
        }
    }
    params.validate().map_err(|error| {
        let key = error.key();
        ParamFileError::Invalid {
            path: path.to_owned(),
            line: key_line(text, key.section(), key.name()),
            found: found(&params, error),
            error,
        }
    })?;
    Ok(params)
}

/// The values behind a derived quantity's error: the quantity as computed, with the
/// given preload against it.
fn found(p: &Params, e: ParamError) -> Option<String> {
    match e {
        ParamError::PreloadNotBelowSolid => Some(format!(
            "preload = {} N, F_C = {} N",
            p.linear.preload.unwrap_or(f64::NAN),
            sig(Derived::Fc.of(p))
        )),
        ParamError::OutOfFormat { quantity, .. } => {
            let (name, unit) = match quantity {
                Derived::K => ("k", " N"),
                Derived::Kp => ("k_p", " N"),
                Derived::Ft => ("F_T", " N"),
                Derived::Fc => ("F_C", " N"),
                Derived::H => ("H", ""),
            };
            Some(format!("{name} = {}{unit}", sig(quantity.of(p))))
        }
        _ => None,
    }
}

/// `x` to 4 significant digits.
fn sig(x: f64) -> String {
    if x != 0.0 && !(1e-3..1e6).contains(&x.abs()) {
        return format!("{x:.3e}");
    }
    let digits = (3 - x.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// The line (1-based) of `key = …` in the section `[section]` (or written `section.key`
/// at the top level), if it is there.
pub fn key_line(text: &str, section: &str, key: &str) -> Option<usize> {
    let mut current = String::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if let Some(name) = line.strip_prefix('[').and_then(|l| l.split(']').next()) {
            current = name.trim().to_string();
            continue;
        }
        let Some((lhs, _)) = line.split_once('=') else {
            continue;
        };
        let lhs: String = lhs.chars().filter(|c| !c.is_whitespace()).collect();
        if (current == section && lhs == key)
            || (current.is_empty() && lhs == format!("{section}.{key}"))
        {
            return Some(i + 1);
        }
    }
    None
}

/// The line (1-based) of the table `[section]` or of the first key `section.…`.
pub fn section_line(text: &str, section: &str) -> Option<usize> {
    text.lines()
        .position(|raw| {
            let line = raw.trim();
            let header = line
                .strip_prefix('[')
                .and_then(|l| l.split(']').next())
                .is_some_and(|n| n.trim() == section);
            header
                || line.starts_with(&format!("{section}."))
                || line.starts_with(&format!("{section} "))
        })
        .map(|i| i + 1)
}

/// The schema's key (`section.name`) or section nearest `given`, if a few edits away.
fn nearest(given: &str) -> Option<String> {
    let mut names: Vec<String> = ParamKey::ALL
        .iter()
        .map(|k| format!("{}.{}", k.section(), k.name()))
        .collect();
    names.extend(["cone".to_string(), "linear".to_string()]);
    nearest_in(given, names)
}

/// Of `names`, the one nearest `given`, if a few edits away.
pub fn nearest_in(given: &str, names: impl IntoIterator<Item = String>) -> Option<String> {
    let (d, best) = names
        .into_iter()
        .map(|n| (edits(given, &n), n))
        .min_by_key(|(d, _)| *d)?;
    (d <= 3.max(given.len() / 5)).then_some(best)
}

/// Levenshtein distance.
fn edits(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for j in 0..b.len() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != b[j]))
                .min(row[j] + 1)
                .min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

/// Writes `params` in the schema (full precision, round-trips through [`parse`]).
pub fn to_toml(params: &Params) -> String {
    let mut s = String::new();
    let mut section = "";
    for key in ParamKey::ALL {
        let Some(v) = key.get(params) else { continue };
        if key.section() != section {
            if !section.is_empty() {
                s.push('\n');
            }
            section = key.section();
            s.push_str(&format!("[{section}]\n"));
        }
        s.push_str(&format!("{} = {v:?}\n", key.name()));
    }
    s
}
