//! The fixed-point scales of the messages: every quantity travels as the raw bits of the
//! format the device computes in, so that the device computes on exactly what the host
//! sent and the host prints exactly what the device computed. One place for each scale,
//! with its conversions (docs/protocol.md, "Units and scales").

/// Lengths: Q24 mm (`mccs::Length`): 1 mm is `1 << 24`; ±128 mm.
pub const LENGTH_FRAC: u32 = 24;
/// Forces: Q20 N (`mccs::Force`): 1 N is `1 << 20`; ±2048 N.
pub const FORCE_FRAC: u32 = 20;
/// The link's force gain: Q15, `1 << 15` is full force.
pub const GAIN_FRAC: u32 = 15;
/// The full gain.
pub const GAIN_FULL: u16 = 1 << GAIN_FRAC;
/// A joint's duty: Q16 of full scale, signed (`±65,536`: ±100 %).
pub const DUTY_FRAC: u32 = 16;
/// A rotation's quaternion components: Q30 (`1 << 30` is 1).
pub const QUAT_FRAC: u32 = 30;
/// Friction coefficients: Q16 (`1 << 16` is 1; 0 … 2).
pub const FRICTION_FRAC: u32 = 16;

/// `bits` of a `frac`-bit fixed-point value as a number.
pub fn to_f64(bits: i32, frac: u32) -> f64 {
    bits as f64 / (1u64 << frac) as f64
}

/// `x` in a `frac`-bit fixed-point format, rounded to nearest and held to `i32`'s range
/// (NaN is 0).
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

/// A length, mm.
pub fn mm(bits: i32) -> f64 {
    to_f64(bits, LENGTH_FRAC)
}

/// A length of `x` mm.
pub fn mm_bits(x: f64) -> i32 {
    from_f64(x, LENGTH_FRAC)
}

/// A force, N.
pub fn newtons(bits: i32) -> f64 {
    to_f64(bits, FORCE_FRAC)
}

/// A force of `x` N.
pub fn newton_bits(x: f64) -> i32 {
    from_f64(x, FORCE_FRAC)
}

/// A gain, 0 … 1.
pub fn gain(bits: u16) -> f64 {
    bits as f64 / GAIN_FULL as f64
}

/// A duty, −1 … 1 of full scale.
pub fn duty(bits: i32) -> f64 {
    to_f64(bits, DUTY_FRAC)
}
