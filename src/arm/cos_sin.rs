//! `cos` and `sin` of a full-turn phase, Q31, by a table of the sine at 1,024 points of
//! the turn and linear interpolation between two of them: two loads, a subtraction, a
//! 32-bit product and a shift each, the same bits on every core (no long product).
//!
//! Error against the true values (amplitude [`AMPLITUDE`]): at most the chord's sag
//! `(2π/1024)² / 8` = 4.7e-6 of the amplitude, plus the product's truncations (the
//! difference's 8 low bits and the fraction's 17, under 3e-7); measured over every phase
//! 2⁻²⁰ of a turn and at each point's neighbours in `host-tests/tests/arm.rs`
//! (`cos_sin_is_within_5e_6`). The table takes 5,124 bytes of flash. It replaced
//! `idsp::cossin` (9e-6 at most; its call took about 40 instructions a joint on the M4F:
//! docs/experiments/performance.md, "A table `cos`/`sin`").

/// Table points per turn (a power of two).
const POINTS: usize = 1024;
/// Bits of the phase that pick the point.
const INDEX_BITS: u32 = POINTS.trailing_zeros();

/// The table's scale: `sin` of a point is `round(sin · SCALE)`. `2³¹ − 512`, not 2³¹ − 1:
/// an interpolation's truncations reach 256 below the lower point, which at −1 must not
/// wrap.
const SCALE: f64 = 2_147_483_136.0;

/// The amplitude of the values, `SCALE / 2³¹` (1 − 2.4e-7): what a length that
/// multiplies one is raised by (`Arm::new`).
pub const AMPLITUDE: f64 = SCALE / 2_147_483_648.0;

/// `round(sin(2π k / POINTS) · SCALE)` for `k` in `0 ..= POINTS + POINTS / 4`: a turn and
/// a quarter, so that `cos` (a quarter on) reads it without a wrap.
pub(super) static SINE: [i32; POINTS + POINTS / 4 + 1] = {
    let mut t = [0i32; POINTS + POINTS / 4 + 1];
    let mut k = 0;
    while k < t.len() {
        t[k] = round(sine_of_point(k % POINTS) * SCALE);
        k += 1;
    }
    t
};

/// `sin(2π k / POINTS)` in `f64` at compile time, from the first quadrant by symmetry
/// (so that the table is exactly symmetric), and there from a Taylor series (to the
/// 27th power: below 1e-18 at π/2).
const fn sine_of_point(k: usize) -> f64 {
    let quarter = POINTS / 4;
    let (j, sign) = match k / quarter {
        0 => (k, 1.0),
        1 => (POINTS / 2 - k, 1.0),
        2 => (k - POINTS / 2, -1.0),
        _ => (POINTS - k, -1.0),
    };
    let x = j as f64 * (core::f64::consts::TAU / POINTS as f64);
    let (mut term, mut sum, mut n) = (x, x, 1u32);
    while n < 27 {
        term = -term * x * x / ((n + 1) as f64 * (n + 2) as f64);
        sum += term;
        n += 2;
    }
    sign * sum
}

/// `v` to the nearest integer (halves away from zero), at compile time.
const fn round(v: f64) -> i32 {
    if v >= 0.0 {
        (v + 0.5) as i32
    } else {
        (v - 0.5) as i32
    }
}

/// `(cos, sin)` of `phase` (2³² a turn), Q31 of amplitude [`AMPLITUDE`] (`Arm::new` folds
/// it into the lengths). Out of line, returned in two registers: the pose calls it for
/// each joint, and inlined side by side the three spilled (the M4F's chain 334
/// instructions, against 331).
#[inline(never)]
pub fn cos_sin(phase: u32) -> (i32, i32) {
    let k = (phase >> (32 - INDEX_BITS)) as usize;
    // The phase between point k and k + 1, 15 bits: with the two points' difference
    // (|d| < 2π/1024 · 2³¹ < 2²⁴) shifted down 8, the product fits 31 bits.
    let within = ((phase >> (32 - INDEX_BITS - 15)) & 0x7FFF) as i32;
    let at = |k: usize| {
        let (a, b) = (SINE[k], SINE[k + 1]);
        a + ((((b - a) >> 8) * within) >> 7)
    };
    (at(k + POINTS / 4), at(k))
}

#[cfg(test)]
mod test {
    use super::{cos_sin, sine_of_point, POINTS, SINE};

    /// The table's points are the library's sine to an ulp of `f64` before rounding.
    #[test]
    fn the_table_is_the_sine() {
        for (k, &v) in SINE.iter().enumerate() {
            let x = k as f64 * core::f64::consts::TAU / POINTS as f64;
            assert!(
                (sine_of_point(k % POINTS) - libm::sin(x)).abs() < 1e-15,
                "{k}"
            );
            assert!(
                (v as f64 - libm::sin(x) * super::SCALE).abs() <= 0.5 + 1e-6,
                "{k}"
            );
        }
    }

    /// At a point, the point itself; at ±a quarter, the other's.
    #[test]
    fn the_quarters_are_exact() {
        let one = super::SCALE as i32;
        assert_eq!(cos_sin(0), (one, 0));
        assert_eq!(cos_sin(1 << 30), (0, one));
        assert_eq!(cos_sin(2 << 30), (-one, 0));
        assert_eq!(cos_sin(3 << 30), (0, -one));
    }
}
