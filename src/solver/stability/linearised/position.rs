//! The position step of the linearised step ([`super::step_once`]), in `i32`.

use super::STATE_LIMIT;

/// The position step of [`super::step_once`] for one run: `X' = X + (S + half) >> shift`,
/// with `S = V + V'` over `2^g` (the paper's integrator), or `2 V'` over `2^g` taken as
/// `V'` over `2^(g − 1)` (symplectic; `2 V'` itself at `g = 0`), rounded.
#[derive(Clone, Copy)]
pub(super) struct PositionStep {
    shift: u32,
    half: i32,
    /// 1 for the symplectic step at `g = 0` (`S = 2 V'`), else 0.
    double: u32,
    symplectic: bool,
}

impl PositionStep {
    pub(super) fn new(symplectic: bool, g: u32) -> Self {
        let (shift, double) = match (symplectic, g) {
            (false, _) => (g, 0),
            (true, 0) => (0, 1),
            (true, _) => (g - 1, 0),
        };
        Self {
            shift,
            half: (1i32 << shift) >> 1,
            double,
            symplectic,
        }
    }

    /// `X'` from `X` and `V` (within ±2²¹, as renormalised) and `V'`, or `None` where
    /// `V'` or `X'` reaches [`STATE_LIMIT`]. In `i32` throughout: with `|V'| < 2³⁰`
    /// (checked first) each `S + half` is within `i32`, and `X'` wraps only past 2³¹,
    /// into `±(2³¹ − 2²¹)` at least: past the limit either way. The same as the step in
    /// `i64` for every input (`linearised::test_step`), which took about 50 instructions
    /// a component on the M4F with its variable 64-bit shift.
    #[inline(always)]
    pub(super) fn advance(self, x: i32, v: i32, v_new: i32) -> Option<i32> {
        if v_new.unsigned_abs() >= STATE_LIMIT {
            return None;
        }
        let s = if self.symplectic {
            v_new << self.double
        } else {
            v + v_new
        };
        let x_new = x.wrapping_add((s + self.half) >> self.shift);
        (x_new.unsigned_abs() < STATE_LIMIT).then_some(x_new)
    }
}
