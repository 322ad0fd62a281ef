//! Reading and writing spring parameters in the TOML schema of `docs/model.md`, with
//! one-line errors that name the file and the key. The schema is the core's
//! [`ParamKey`]: its sections, keys, which are required, and how each is stored.

use mccs::{ParamError, ParamKey, Params};
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
        /// The key.
        key: ParamKey,
    },
    /// A key or table not in the schema (most often a typo).
    Unknown {
        /// The file.
        path: PathBuf,
        /// The dotted key as written.
        key: String,
    },
    /// The values are numbers but break the rules (finite, > 0, D2 > D1).
    Invalid {
        /// The file.
        path: PathBuf,
        /// The rule broken.
        error: ParamError,
    },
}

impl fmt::Display for ParamFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Read { path, reason } => write!(f, "{}: cannot read: {reason}", path.display()),
            Self::Toml {
                path,
                line,
                message,
            } => match line {
                Some(l) => write!(f, "{}: line {l}: invalid TOML: {message}", path.display()),
                None => write!(f, "{}: invalid TOML: {message}", path.display()),
            },
            Self::Missing { path, key } => write!(f, "{}: {key}: missing", path.display()),
            Self::NotNumber { path, key } => {
                write!(f, "{}: {key}: must be a number", path.display())
            }
            Self::Unknown { path, key } => {
                write!(f, "{}: {key}: unknown key", path.display())
            }
            Self::Invalid { path, error } => write!(f, "{}: {error}", path.display()),
        }
    }
}

impl std::error::Error for ParamFileError {}

/// Reads and validates a parameter file.
pub fn read(path: &Path) -> Result<Params, ParamFileError> {
    let text = std::fs::read_to_string(path).map_err(|e| ParamFileError::Read {
        path: path.to_owned(),
        reason: e.to_string(),
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
        let unknown = |key: String| ParamFileError::Unknown {
            path: path.to_owned(),
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
                    return Err(unknown(format!("{name}.{k}")));
                }
            }
            _ => return Err(unknown(name.clone())),
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
    params.validate().map_err(|error| ParamFileError::Invalid {
        path: path.to_owned(),
        error,
    })?;
    Ok(params)
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
