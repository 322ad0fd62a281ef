//! Reading spring parameters from MODEL.md's TOML schema, with one-line errors that name
//! the file and the key.

use mccs::{Cone, Linear, ParamError, ParamKey, Params};
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
        let known: &[&str] = match name.as_str() {
            "cone" => &[
                "wire_diameter",
                "small_diameter",
                "large_diameter",
                "active_coils",
                "compressible_height",
                "shear_modulus",
            ],
            "linear" => &[
                "wire_diameter",
                "mean_diameter",
                "active_coils",
                "shear_modulus",
                "preload",
            ],
            _ => &[],
        };
        let unknown = |key: String| ParamFileError::Unknown {
            path: path.to_owned(),
            key,
        };
        match value.as_table() {
            Some(t) if !known.is_empty() => {
                if let Some(k) = t.keys().find(|k| !known.contains(&k.as_str())) {
                    return Err(unknown(format!("{name}.{k}")));
                }
            }
            _ => return Err(unknown(name.clone())),
        }
    }
    let get = |key: ParamKey| -> Result<Option<f64>, ParamFileError> {
        let (section, name) = key.as_str().split_once('.').unwrap_or(("", key.as_str()));
        let value = table.get(section).and_then(|s| s.get(name));
        match value {
            None => Ok(None),
            Some(toml::Value::Float(x)) => Ok(Some(*x)),
            Some(toml::Value::Integer(i)) => Ok(Some(*i as f64)),
            Some(_) => Err(ParamFileError::NotNumber {
                path: path.to_owned(),
                key,
            }),
        }
    };
    let req = |key: ParamKey| -> Result<f64, ParamFileError> {
        get(key)?.ok_or(ParamFileError::Missing {
            path: path.to_owned(),
            key,
        })
    };
    use ParamKey as K;
    let params = Params {
        cone: Cone {
            wire_diameter: req(K::ConeWireDiameter)?,
            small_diameter: req(K::ConeSmallDiameter)?,
            large_diameter: req(K::ConeLargeDiameter)?,
            active_coils: req(K::ConeActiveCoils)?,
            compressible_height: req(K::ConeCompressibleHeight)?,
            shear_modulus: req(K::ConeShearModulus)?,
        },
        linear: Linear {
            wire_diameter: req(K::LinearWireDiameter)?,
            mean_diameter: req(K::LinearMeanDiameter)?,
            active_coils: req(K::LinearActiveCoils)?,
            shear_modulus: req(K::LinearShearModulus)?,
            preload: get(K::LinearPreload)?,
        },
    };
    params.validate().map_err(|error| ParamFileError::Invalid {
        path: path.to_owned(),
        error,
    })?;
    Ok(params)
}

/// Writes `params` in MODEL.md's schema (full precision, round-trips through [`parse`]).
pub fn to_toml(params: &Params) -> String {
    let c = &params.cone;
    let l = &params.linear;
    let mut s = format!(
        "[cone]\nwire_diameter = {:?}\nsmall_diameter = {:?}\nlarge_diameter = {:?}\n\
         active_coils = {:?}\ncompressible_height = {:?}\nshear_modulus = {:?}\n\n\
         [linear]\nwire_diameter = {:?}\nmean_diameter = {:?}\nactive_coils = {:?}\n\
         shear_modulus = {:?}\n",
        c.wire_diameter,
        c.small_diameter,
        c.large_diameter,
        c.active_coils,
        c.compressible_height,
        c.shear_modulus,
        l.wire_diameter,
        l.mean_diameter,
        l.active_coils,
        l.shear_modulus
    );
    if let Some(p) = l.preload {
        s.push_str(&format!("preload = {p:?}\n"));
    }
    s
}
