//! The fixed-point formats of the core, each defined once: a named `fixed` type for every
//! quantity that crosses a module boundary, its fraction bits, and the conversions from
//! `f64` used at start-up.
//!
//! | quantity | type | unit | range | resolution |
//! |---|---|---|---|---|
//! | compressive strain `ε` | [`Strain`] `I8F24` | 1 | ±128 | 6.0e-8 |
//! | force | [`Force`] `I12F20` | N | ±2048 N | 9.5e-7 N |
//! | tangent stiffness `dF/dε` | [`Stiffness`] `I16F16` | N per unit strain | ±32768 | 1.5e-5 |
//! | displacement, position | [`Length`] `I8F24` | mm | ±128 mm | 6.0e-8 mm |
//! | velocity | [`Velocity`] `I16F16` | mm/s | ±32768 mm/s | 1.5e-5 mm/s |
//! | unit edge direction | raw Q[`DIR_FRAC`] | 1 | ±256 | 1.2e-7 |
//! | inverse rest length `1/l0` | raw Q[`INV_LEN_FRAC`] | 1/mm | < 1 (l0 ≥ 1 mm) | 4.7e-10 |
//!
//! The per-tick code works on the raw `i32` bits of these types; the intermediate formats
//! of one computation are defined where that computation is (and nowhere else).

/// Compressive strain `ε = (l0 − l) / l0` (dimensionless; positive = compressed). ±128.
pub type Strain = fixed::types::I8F24;
/// Force in N. ±2048 N, resolution 9.5e-7 N.
pub type Force = fixed::types::I12F20;
/// Tangent stiffness `dF/dε` in N per unit strain. ±32768, resolution 1.5e-5.
pub type Stiffness = fixed::types::I16F16;
/// Length (a displacement or a position) in mm. ±128 mm.
pub type Length = fixed::types::I8F24;
/// Velocity in mm/s. ±32768 mm/s.
pub type Velocity = fixed::types::I16F16;

/// Fraction bits of [`Strain`].
pub const STRAIN_FRAC: u32 = Strain::FRAC_NBITS;
/// Fraction bits of [`Force`].
pub const FORCE_FRAC: u32 = Force::FRAC_NBITS;
/// Fraction bits of [`Stiffness`].
pub const STIFF_FRAC: u32 = Stiffness::FRAC_NBITS;
/// Fraction bits of [`Length`] (and of dimensionless ratios of lengths in the patch).
pub const LEN_FRAC: u32 = Length::FRAC_NBITS;
/// Fraction bits of [`Velocity`].
pub const VEL_FRAC: u32 = Velocity::FRAC_NBITS;
/// Fraction bits of an edge's unit rest vector: the format of `(x_b − x_a)/l0` in the
/// spring kernels, so that it is the rest vector plus one high-word product.
pub const DIR_FRAC: u32 = 23;
/// Fraction bits of an edge's `1 / l0` (1/mm).
pub const INV_LEN_FRAC: u32 = 31;

/// Raw Q[`FORCE_FRAC`] of one newton.
pub const ONE_NEWTON: i32 = 1 << FORCE_FRAC;
/// Raw Q[`LEN_FRAC`] of one (a length of 1 mm, or the ratio 1).
pub const ONE: i32 = 1 << LEN_FRAC;

/// Rounds an `f64` to the nearest raw value with `frac` fraction bits, saturating at the
/// `i32` range; NaN gives 0 (start-up only).
pub fn from_f64(x: f64, frac: u32) -> i32 {
    let v = libm::round(x * (1u64 << frac) as f64);
    if v.is_nan() {
        0
    } else if v >= i32::MAX as f64 {
        i32::MAX
    } else if v <= i32::MIN as f64 {
        i32::MIN
    } else {
        v as i32
    }
}

/// Rounds an `f64` to the nearest raw value with `frac` fraction bits, or `None` when it
/// is not finite or does not fit an `i32` (start-up only).
pub fn checked_from_f64(x: f64, frac: u32) -> Option<i32> {
    let v = libm::round(x * (1u64 << frac) as f64);
    if v.is_finite() && v >= i32::MIN as f64 && v <= i32::MAX as f64 {
        Some(v as i32)
    } else {
        None
    }
}

/// A raw value with `frac` fraction bits as an `f64`.
pub fn to_f64(raw: i32, frac: u32) -> f64 {
    raw as f64 / (1u64 << frac) as f64
}
