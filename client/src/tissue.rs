//! [`Tissue`]: a tissue as a device takes it — its force table's bytes, their hash, and
//! the friction to render it with — made from a parameter file or parameters in memory
//! (by the one table builder, `mccs::ForceTable::new`: the best placement of the knots,
//! measured, held to the product's bound) or read from a `.bin` file that
//! `mccs table --format bin` wrote (`mccs_link::tissue_file`).

use mccs::{ForceTable, Params};
use mccs_link::tissue_file::{TissueFile, TissueFileError};
use mccs_link::{table_bytes, Friction};
use std::path::{Path, PathBuf};

/// Why a tissue could not be made.
#[derive(Debug, thiserror::Error)]
pub enum TissueError {
    /// A parameter file's error (one line naming the file, the line and the key).
    #[error(transparent)]
    Params(#[from] crate::paramfile::ParamFileError),
    /// The parameters are out of range.
    #[error("{0}")]
    Invalid(mccs::ParamError),
    /// The table builder refused (the bound not met, no nonlinear phase, …).
    #[error("{}: the force table: {source}", crate::shown::ShownPath(.file))]
    Table {
        /// The parameters' file (`<memory>` for parameters in memory).
        file: PathBuf,
        /// Why.
        source: mccs::TableError,
    },
    /// A `.bin` file could not be read.
    #[error("{}: {source}", crate::shown::ShownPath(.file))]
    Read {
        /// The file.
        file: PathBuf,
        /// The OS's reason.
        source: std::io::Error,
    },
    /// A `.bin` file is not a tissue's.
    #[error("{}: {source}", crate::shown::ShownPath(.file))]
    Bin {
        /// The file.
        file: PathBuf,
        /// Why.
        source: TissueFileError,
    },
    /// Friction coefficients out of range.
    #[error("mu_s and mu_k must be within 0 … 2 with mu_k ≤ mu_s (got {0}, {1})")]
    Friction(f64, f64),
}

/// A tissue's table bytes, ready for a device.
#[derive(Clone, Debug, PartialEq)]
pub struct Tissue {
    segments: u16,
    bytes: Vec<u8>,
    hash: u32,
    friction: Option<Friction>,
}

/// The knots the builder makes (the devices' tables: 65).
pub const KNOTS: usize = 65;

impl Tissue {
    /// From a parameter file (docs/model.md's TOML schema), 65 knots.
    pub fn from_param_file(path: &Path) -> Result<Tissue, TissueError> {
        let p = crate::paramfile::read(path)?;
        Self::build(&p, path)
    }

    /// From parameters in memory, 65 knots.
    pub fn from_params(p: &Params) -> Result<Tissue, TissueError> {
        p.validate().map_err(TissueError::Invalid)?;
        Self::build(p, Path::new("<memory>"))
    }

    fn build(p: &Params, file: &Path) -> Result<Tissue, TissueError> {
        let table = ForceTable::<{ KNOTS - 1 }>::new(p).map_err(|source| TissueError::Table {
            file: file.to_path_buf(),
            source,
        })?;
        Ok(Self::of_table(&table))
    }

    /// The bytes of a table.
    pub fn of_table<const S: usize>(table: &ForceTable<S>) -> Tissue {
        let mut bytes = vec![0u8; table_bytes::len(S)];
        table_bytes::write(table, &mut bytes);
        Tissue {
            segments: S as u16,
            hash: table_bytes::hash(table),
            bytes,
            friction: None,
        }
    }

    /// From a `.bin` file's contents (checked: its header, length and hash).
    pub fn from_bin(data: &[u8]) -> Result<Tissue, TissueFileError> {
        let f = TissueFile::parse(data)?;
        Ok(Tissue {
            segments: f.segments,
            hash: f.hash,
            bytes: f.bytes.to_vec(),
            friction: None,
        })
    }

    /// From a `.bin` file.
    pub fn from_bin_file(path: &Path) -> Result<Tissue, TissueError> {
        let data =
            crate::input::read_bytes(path, crate::input::CONFIG_BYTES).map_err(|source| {
                TissueError::Read {
                    file: path.to_path_buf(),
                    source,
                }
            })?;
        Self::from_bin(&data).map_err(|source| TissueError::Bin {
            file: path.to_path_buf(),
            source,
        })
    }

    /// From a file: a `.bin` table, else a parameter file.
    pub fn from_file(path: &Path) -> Result<Tissue, TissueError> {
        if path.extension().is_some_and(|e| e == "bin") {
            Self::from_bin_file(path)
        } else {
            Self::from_param_file(path)
        }
    }

    /// With friction coefficients (a roaming device's; 0 … 2, `mu_k ≤ mu_s`).
    pub fn with_friction(mut self, mu_s: f64, mu_k: f64) -> Result<Tissue, TissueError> {
        let ok = |m: f64| m.is_finite() && (0.0..=2.0).contains(&m);
        if !ok(mu_s) || !ok(mu_k) || mu_k > mu_s {
            return Err(TissueError::Friction(mu_s, mu_k));
        }
        self.friction = Some(Friction::new(mu_s, mu_k));
        Ok(self)
    }

    /// Its table's segments (knots − 1).
    pub fn segments(&self) -> u16 {
        self.segments
    }

    /// Its table's bytes.
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// Its hash (what the device's `Ack` and hello name it by).
    pub fn hash(&self) -> u32 {
        self.hash
    }

    /// Its friction, if given.
    pub fn friction(&self) -> Option<Friction> {
        self.friction
    }

    /// As a `.bin` file's contents.
    pub fn to_bin(&self) -> Vec<u8> {
        let mut out = TissueFile::header(self.segments, &self.bytes).to_vec();
        out.extend_from_slice(&self.bytes);
        out
    }
}
