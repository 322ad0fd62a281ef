//! Spring parameters in the units and schema of `docs/model.md`, and their validation.
//!
//! Lengths in mm, shear moduli in MPa, forces in N. Every value must be finite and > 0,
//! and the cone's large diameter must exceed its small one. Validation names the
//! offending key with [`ParamKey`], exactly as the TOML files spell it.
//!
//! [`ParamKey`] is the schema's one source: its section and name in the file, its
//! symbol and unit, whether it is required, and how to read and write it in a
//! [`Params`]. The parameter-file reader and writer, the CLI and the docs' schema table
//! all go through it.

use core::fmt;

/// The conical spring `S_e`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// `d`, wire diameter (mm).
    pub wire_diameter: f64,
    /// `D1`, diameter of the smallest coil (mm).
    pub small_diameter: f64,
    /// `D2`, diameter of the largest coil (mm); must exceed `D1`.
    pub large_diameter: f64,
    /// `n`, active coils.
    pub active_coils: f64,
    /// `H = L0 - Lc`, compressible height (mm).
    pub compressible_height: f64,
    /// `G`, shear modulus (MPa).
    pub shear_modulus: f64,
}

/// The cylindrical pre-variable spring `S_p`, in series with the cone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Linear {
    /// `d_p`, wire diameter (mm).
    pub wire_diameter: f64,
    /// `D_p`, mean coil diameter (mm).
    pub mean_diameter: f64,
    /// `n_p`, active coils.
    pub active_coils: f64,
    /// `G_p`, shear modulus (MPa).
    pub shear_modulus: f64,
    /// `P`, preload (N). `None` means the cone's transition force `F_T`.
    pub preload: Option<f64>,
}

/// A complete MCCS spring: the cone and the series spring.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// The conical spring.
    pub cone: Cone,
    /// The series (pre-variable) spring.
    pub linear: Linear,
}

/// A parameter key, spelled as in the TOML schema.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum ParamKey {
    ConeWireDiameter,
    ConeSmallDiameter,
    ConeLargeDiameter,
    ConeActiveCoils,
    ConeCompressibleHeight,
    ConeShearModulus,
    LinearWireDiameter,
    LinearMeanDiameter,
    LinearActiveCoils,
    LinearShearModulus,
    LinearPreload,
}

impl ParamKey {
    /// Every key, in schema order.
    pub const ALL: [ParamKey; 11] = [
        Self::ConeWireDiameter,
        Self::ConeSmallDiameter,
        Self::ConeLargeDiameter,
        Self::ConeActiveCoils,
        Self::ConeCompressibleHeight,
        Self::ConeShearModulus,
        Self::LinearWireDiameter,
        Self::LinearMeanDiameter,
        Self::LinearActiveCoils,
        Self::LinearShearModulus,
        Self::LinearPreload,
    ];

    /// The TOML section: `cone` or `linear`.
    pub const fn section(self) -> &'static str {
        match self {
            Self::ConeWireDiameter
            | Self::ConeSmallDiameter
            | Self::ConeLargeDiameter
            | Self::ConeActiveCoils
            | Self::ConeCompressibleHeight
            | Self::ConeShearModulus => "cone",
            _ => "linear",
        }
    }

    /// The key within its section, e.g. `wire_diameter`.
    pub const fn name(self) -> &'static str {
        let path = self.as_str().as_bytes();
        let skip = self.section().len() + 1;
        let (_, name) = path.split_at(skip);
        match core::str::from_utf8(name) {
            Ok(n) => n,
            Err(_) => "",
        }
    }

    /// The paper's symbol and the unit: e.g. `("d", "mm")`.
    pub const fn symbol_and_unit(self) -> (&'static str, &'static str) {
        match self {
            Self::ConeWireDiameter => ("d", "mm"),
            Self::ConeSmallDiameter => ("D1", "mm"),
            Self::ConeLargeDiameter => ("D2", "mm"),
            Self::ConeActiveCoils => ("n", "1"),
            Self::ConeCompressibleHeight => ("H", "mm"),
            Self::ConeShearModulus => ("G", "MPa"),
            Self::LinearWireDiameter => ("d_p", "mm"),
            Self::LinearMeanDiameter => ("D_p", "mm"),
            Self::LinearActiveCoils => ("n_p", "1"),
            Self::LinearShearModulus => ("G_p", "MPa"),
            Self::LinearPreload => ("P", "N"),
        }
    }

    /// Whether a parameter file must give the key (only the preload is optional: it
    /// defaults to the cone's transition force `F_T`).
    pub const fn required(self) -> bool {
        !matches!(self, Self::LinearPreload)
    }

    /// The key's value in `p` (`None`: the optional preload, absent).
    pub const fn get(self, p: &Params) -> Option<f64> {
        let (c, l) = (&p.cone, &p.linear);
        Some(match self {
            Self::ConeWireDiameter => c.wire_diameter,
            Self::ConeSmallDiameter => c.small_diameter,
            Self::ConeLargeDiameter => c.large_diameter,
            Self::ConeActiveCoils => c.active_coils,
            Self::ConeCompressibleHeight => c.compressible_height,
            Self::ConeShearModulus => c.shear_modulus,
            Self::LinearWireDiameter => l.wire_diameter,
            Self::LinearMeanDiameter => l.mean_diameter,
            Self::LinearActiveCoils => l.active_coils,
            Self::LinearShearModulus => l.shear_modulus,
            Self::LinearPreload => return l.preload,
        })
    }

    /// Sets the key's value in `p`.
    pub fn set(self, p: &mut Params, value: f64) {
        let (c, l) = (&mut p.cone, &mut p.linear);
        let slot = match self {
            Self::ConeWireDiameter => &mut c.wire_diameter,
            Self::ConeSmallDiameter => &mut c.small_diameter,
            Self::ConeLargeDiameter => &mut c.large_diameter,
            Self::ConeActiveCoils => &mut c.active_coils,
            Self::ConeCompressibleHeight => &mut c.compressible_height,
            Self::ConeShearModulus => &mut c.shear_modulus,
            Self::LinearWireDiameter => &mut l.wire_diameter,
            Self::LinearMeanDiameter => &mut l.mean_diameter,
            Self::LinearActiveCoils => &mut l.active_coils,
            Self::LinearShearModulus => &mut l.shear_modulus,
            Self::LinearPreload => {
                l.preload = Some(value);
                return;
            }
        };
        *slot = value;
    }

    /// The dotted TOML path, e.g. `cone.wire_diameter`.
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::ConeWireDiameter => "cone.wire_diameter",
            Self::ConeSmallDiameter => "cone.small_diameter",
            Self::ConeLargeDiameter => "cone.large_diameter",
            Self::ConeActiveCoils => "cone.active_coils",
            Self::ConeCompressibleHeight => "cone.compressible_height",
            Self::ConeShearModulus => "cone.shear_modulus",
            Self::LinearWireDiameter => "linear.wire_diameter",
            Self::LinearMeanDiameter => "linear.mean_diameter",
            Self::LinearActiveCoils => "linear.active_coils",
            Self::LinearShearModulus => "linear.shear_modulus",
            Self::LinearPreload => "linear.preload",
        }
    }
}

impl fmt::Display for ParamKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A quantity derived from the parameters that the fixed-point formats must hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Derived {
    /// `k`, the cone's linear stiffness (N per unit strain).
    K,
    /// `k_p`, the series spring's stiffness (N per unit strain).
    Kp,
    /// `F_T`, the force at the end of the linear phase (N).
    Ft,
    /// `F_C`, the cone's solid force (N).
    Fc,
    /// `H`, the compressible height, a strain.
    H,
}

impl Derived {
    /// Every derived quantity, in the order they are checked.
    pub const ALL: [Derived; 5] = [Self::K, Self::Kp, Self::Ft, Self::Fc, Self::H];

    /// The range the fixed-point formats hold: stiffnesses in Q16 (±32768, with the
    /// headroom a table needs), forces in Q20 (±2048 N; a table holds ±1024 N), strains in
    /// Q24 (±128).
    pub const fn range(self) -> (f64, f64) {
        match self {
            Self::K | Self::Kp => (1e-4, 16384.0),
            Self::Ft => (1e-5, 1024.0),
            Self::Fc => (1e-5, 1e9),
            Self::H => (1e-6, 100.0),
        }
    }

    /// How each parameter enters the quantity: `(key, exponent)` of its power law (the
    /// diameters of `k` approximately).
    const fn dependencies(self) -> &'static [(ParamKey, f64)] {
        use ParamKey as P;
        match self {
            Self::K => &[
                (P::ConeShearModulus, 1.0),
                (P::ConeWireDiameter, 4.0),
                (P::ConeActiveCoils, -1.0),
                (P::ConeSmallDiameter, -1.5),
                (P::ConeLargeDiameter, -1.5),
            ],
            Self::Kp => &[
                (P::LinearShearModulus, 1.0),
                (P::LinearWireDiameter, 4.0),
                (P::LinearActiveCoils, -1.0),
                (P::LinearMeanDiameter, -3.0),
            ],
            Self::Ft => &[
                (P::ConeShearModulus, 1.0),
                (P::ConeWireDiameter, 4.0),
                (P::ConeCompressibleHeight, 1.0),
                (P::ConeActiveCoils, -1.0),
                (P::ConeLargeDiameter, -3.0),
            ],
            Self::Fc => &[
                (P::ConeShearModulus, 1.0),
                (P::ConeWireDiameter, 4.0),
                (P::ConeCompressibleHeight, 1.0),
                (P::ConeActiveCoils, -1.0),
                (P::ConeSmallDiameter, -3.0),
            ],
            Self::H => &[(P::ConeCompressibleHeight, 1.0)],
        }
    }

    /// The quantity's value for `p` (whose values are finite and > 0).
    pub fn of(self, p: &Params) -> f64 {
        let (c, l) = (&p.cone, &p.linear);
        let gd4 = c.shear_modulus * pow4(c.wire_diameter);
        let (d1, d2) = (c.small_diameter, c.large_diameter);
        match self {
            Self::K => gd4 / (2.0 * c.active_coils * (d1 * d1 + d2 * d2) * (d1 + d2)),
            Self::Kp => {
                l.shear_modulus * pow4(l.wire_diameter)
                    / (8.0 * l.active_coils * l.mean_diameter * l.mean_diameter * l.mean_diameter)
            }
            Self::Ft => gd4 * c.compressible_height / (8.0 * c.active_coils * d2 * d2 * d2),
            Self::Fc => gd4 * c.compressible_height / (8.0 * c.active_coils * d1 * d1 * d1),
            Self::H => c.compressible_height,
        }
    }

    /// The parameter that pushed the quantity out of its range the most: the largest
    /// term `exponent · ln(value / Table 2's value)` in the direction of the excess.
    fn culprit(self, p: &Params, high: bool) -> ParamKey {
        let mut best = (f64::NEG_INFINITY, self.dependencies()[0].0);
        for &(key, exp) in self.dependencies() {
            let (Some(v), Some(t)) = (key.get(p), key.get(&Params::TABLE2)) else {
                continue;
            };
            let push = exp * libm::log(v / t);
            let push = if high { push } else { -push };
            if push > best.0 {
                best = (push, key);
            }
        }
        best.1
    }

    /// The quantity's name in messages.
    pub const fn name(self) -> &'static str {
        match self {
            Self::K => "the cone's stiffness k",
            Self::Kp => "the series spring's stiffness k_p",
            Self::Ft => "the transition force F_T",
            Self::Fc => "the solid force F_C",
            Self::H => "the compressible height H",
        }
    }
}

fn pow4(x: f64) -> f64 {
    let x2 = x * x;
    x2 * x2
}

/// Why a parameter set was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamError {
    /// The value is NaN or infinite.
    NotFinite(ParamKey),
    /// The value is zero or negative.
    NotPositive(ParamKey),
    /// `cone.large_diameter` is not larger than `cone.small_diameter`.
    LargeNotAboveSmall,
    /// `linear.preload` is not below the cone's solid force `F_C`: the series spring
    /// would never move before the cone is solid, and the law would have a vertical step.
    PreloadNotBelowSolid,
    /// The values are valid one by one, but make a derived quantity too large (`high`)
    /// or too small for the fixed-point formats ([`Derived::range`]); `key` is the value
    /// that pushed it there the most.
    OutOfFormat {
        /// The value at fault.
        key: ParamKey,
        /// The derived quantity out of range.
        quantity: Derived,
        /// Above the range (else below).
        high: bool,
    },
}

impl ParamError {
    /// What is wrong with the key's value (see `Display`, which puts the key first): one
    /// source for `Display` and the `defmt` impl.
    pub const fn reason(&self) -> &'static str {
        match self {
            Self::NotFinite(_) => "must be a finite number",
            Self::NotPositive(_) => "must be > 0",
            Self::LargeNotAboveSmall => "must be larger than cone.small_diameter",
            Self::PreloadNotBelowSolid => {
                "must be below the cone's solid force F_C = G d^4 H / (8 n D1^3)"
            }
            Self::OutOfFormat { quantity, high, .. } => match (quantity, high) {
                (Derived::K, true) => {
                    "makes the cone's stiffness k exceed 16384 N per unit strain, more than the fixed point holds"
                }
                (Derived::K, false) => {
                    "makes the cone's stiffness k fall below 1e-4 N per unit strain, less than the fixed point resolves"
                }
                (Derived::Kp, true) => {
                    "makes the series spring's stiffness k_p exceed 16384 N per unit strain, more than the fixed point holds"
                }
                (Derived::Kp, false) => {
                    "makes the series spring's stiffness k_p fall below 1e-4 N per unit strain, less than the fixed point resolves"
                }
                (Derived::Ft, true) => {
                    "makes the transition force F_T exceed 1024 N, more than the fixed point holds"
                }
                (Derived::Ft, false) => {
                    "makes the transition force F_T fall below 1e-5 N, less than the fixed point resolves"
                }
                (Derived::Fc, true) => "makes the solid force F_C exceed 1e9 N",
                (Derived::Fc, false) => {
                    "makes the solid force F_C fall below 1e-5 N, less than the fixed point resolves"
                }
                (Derived::H, true) => "must be at most 100 (a strain)",
                (Derived::H, false) => "must be at least 1e-6 (a strain)",
            },
        }
    }

    /// The key the error is about.
    pub const fn key(&self) -> ParamKey {
        match self {
            Self::NotFinite(k) | Self::NotPositive(k) => *k,
            Self::LargeNotAboveSmall => ParamKey::ConeLargeDiameter,
            Self::PreloadNotBelowSolid => ParamKey::LinearPreload,
            Self::OutOfFormat { key, .. } => *key,
        }
    }
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.key(), self.reason())
    }
}

impl core::error::Error for ParamError {}

impl Params {
    /// Checks the rules of `docs/model.md`: every value finite and > 0, `D2 > D1`, the
    /// derived quantities within what the fixed-point formats hold ([`Derived::range`]),
    /// and a preload (when given) below the cone's solid force `F_C`.
    pub fn validate(&self) -> Result<(), ParamError> {
        for key in ParamKey::ALL {
            if let Some(v) = key.get(self) {
                if !v.is_finite() {
                    return Err(ParamError::NotFinite(key));
                }
                if v <= 0.0 {
                    return Err(ParamError::NotPositive(key));
                }
            }
        }
        let c = &self.cone;
        if c.large_diameter <= c.small_diameter {
            return Err(ParamError::LargeNotAboveSmall);
        }
        for quantity in Derived::ALL {
            let v = quantity.of(self);
            let (lo, hi) = quantity.range();
            if !(v >= lo && v <= hi) {
                // NaN (both parts of a ratio out of range): blame the larger excess.
                let high = v.is_nan() || v > hi;
                return Err(ParamError::OutOfFormat {
                    key: quantity.culprit(self, high),
                    quantity,
                    high,
                });
            }
        }
        if let Some(p) = self.linear.preload {
            if p >= Derived::Fc.of(self) {
                return Err(ParamError::PreloadNotBelowSolid);
            }
        }
        Ok(())
    }

    /// The paper's Table 2 spring with this project's coil counts (n = 5, n_p = 10).
    pub const TABLE2: Params = Params {
        cone: Cone {
            wire_diameter: 0.1,
            small_diameter: 0.3,
            large_diameter: 0.8,
            active_coils: 5.0,
            compressible_height: 0.6,
            shear_modulus: 1.8472e5,
        },
        linear: Linear {
            wire_diameter: 0.068,
            mean_diameter: 0.2,
            active_coils: 10.0,
            shear_modulus: 4.9151e5,
            preload: None,
        },
    };
}
