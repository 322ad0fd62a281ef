//! Spring parameters in the units and schema of MODEL.md, and their validation.
//!
//! Lengths in mm, shear moduli in MPa, forces in N. Every value must be finite and > 0,
//! and the cone's large diameter must exceed its small one. Validation names the
//! offending key with [`ParamKey`], exactly as the TOML files spell it.

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
}

impl ParamError {
    /// The key the error is about.
    pub const fn key(&self) -> ParamKey {
        match self {
            Self::NotFinite(k) | Self::NotPositive(k) => *k,
            Self::LargeNotAboveSmall => ParamKey::ConeLargeDiameter,
            Self::PreloadNotBelowSolid => ParamKey::LinearPreload,
        }
    }
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotFinite(k) => write!(f, "{k}: must be a finite number"),
            Self::NotPositive(k) => write!(f, "{k}: must be > 0"),
            Self::LargeNotAboveSmall => {
                f.write_str("cone.large_diameter: must be larger than cone.small_diameter")
            }
            Self::PreloadNotBelowSolid => f.write_str(
                "linear.preload: must be below the cone's solid force F_C = G d^4 H / (8 n D1^3)",
            ),
        }
    }
}

impl core::error::Error for ParamError {}

impl Params {
    /// The values in schema order (the preload, when absent, as `None`).
    fn values(&self) -> [Option<f64>; 11] {
        let (c, l) = (&self.cone, &self.linear);
        [
            Some(c.wire_diameter),
            Some(c.small_diameter),
            Some(c.large_diameter),
            Some(c.active_coils),
            Some(c.compressible_height),
            Some(c.shear_modulus),
            Some(l.wire_diameter),
            Some(l.mean_diameter),
            Some(l.active_coils),
            Some(l.shear_modulus),
            l.preload,
        ]
    }

    /// Checks MODEL.md's rules: every value finite and > 0, `D2 > D1`, and a preload (when
    /// given) below the cone's solid force `F_C`.
    pub fn validate(&self) -> Result<(), ParamError> {
        for (key, value) in ParamKey::ALL.iter().zip(self.values()) {
            if let Some(v) = value {
                if !v.is_finite() {
                    return Err(ParamError::NotFinite(*key));
                }
                if v <= 0.0 {
                    return Err(ParamError::NotPositive(*key));
                }
            }
        }
        let c = &self.cone;
        if c.large_diameter <= c.small_diameter {
            return Err(ParamError::LargeNotAboveSmall);
        }
        if let Some(p) = self.linear.preload {
            let d1 = c.small_diameter;
            let d4 = c.wire_diameter * c.wire_diameter * c.wire_diameter * c.wire_diameter;
            let f_c = c.shear_modulus * d4 * c.compressible_height
                / (8.0 * c.active_coils * d1 * d1 * d1);
            if p >= f_c {
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
