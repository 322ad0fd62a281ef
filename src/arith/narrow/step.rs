//! [`NarrowStep`]: the integrator's step with 16-bit coefficients on the stored
//! velocity `V = C_v v`.

use super::NarrowDamping;
use crate::arith::StepSpec;
use crate::q;
use crate::state::{Node, DISP_LIMIT_BITS, VEL_LIMIT_MM_S};
use crate::units::{from_f64, FORCE_FRAC, LEN_FRAC, VEL_FRAC};

/// The integrator's coefficients as 16-bit operands with run-time shifts (each to 2⁻¹⁵
/// relative). The nodes store the velocity as `V = C_v v` in N, Q(20 + g) (`C_v` and `g`
/// from [`NarrowDamping`]), so that a spring's damping force is a difference of stored
/// values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NarrowStep {
    /// `h c_node / m` (≤ ½), Q(16 + `damp_sh`).
    damp: i32,
    damp_sh: u8,
    /// `C_v h / m` (dimensionless) as a 16-bit operand: `f · step` (f Q20 N) is a stored
    /// velocity after the shifts.
    step: i32,
    step_sh1: u8,
    step_sh2: u8,
    /// Largest force (Q20 N) whose velocity step fits: `|f step| / 2^step_sh1 ≤ 2³⁰`.
    f_hold: i32,
    /// Whether the fast path applies (no hold: `f_hold` is `i32::MAX`; `h/(2 C_v)` in
    /// stored units to mm < 2; stored velocities within ±2²⁸): the step as
    /// `⌊f · fast / 2¹⁶⌋ >> fast_sh` and the position change as
    /// `⌊(V + V') · fast_hh / 2¹⁴⌋ >> fast_hh_sh`.
    pub(super) fast_path: bool,
    /// [`crate::arith::Integrator::SymplecticDamped`]: `u' = u + h v'`.
    pub(super) symplectic: bool,
    fast: i32,
    fast_sh: u8,
    fast_hh: i32,
    fast_hh_sh: u8,
    /// `h / (2 C_v)`, mm/N, as a 16-bit operand: `V · hh` is Q24 mm after the shifts.
    hh: i32,
    hh_sh1: u8,
    hh_sh2: u8,
    /// `C_v` as a 16-bit operand: mm/s (Q16) to a stored velocity (`cv_sh` ≥ 8).
    cv: i32,
    cv_sh: u8,
    /// `1 / C_v` as a 16-bit operand: a stored velocity to mm/s (Q16).
    inv_cv: i32,
    inv_cv_sh: u8,
    /// The velocity limit (16384 mm/s) as a stored velocity.
    v_limit: i32,
}

/// `(sh1, sh2)` with `sh1 = min(sh, 16)`: a [`q::mul_s_by`] shift and the rest.
fn split_shift(sh: u32) -> (u32, u32) {
    (sh.min(16), sh.saturating_sub(16))
}

impl NarrowStep {
    /// For `spec` (start-up).
    #[inline(never)]
    pub fn new(spec: &StepSpec) -> Self {
        // The velocity step's substep `h D` and the position step's `h`.
        let (h, hd) = (spec.h, spec.velocity_h());
        let (node_mass, node_damping, spring_damping) =
            (spec.node_mass, spec.node_damping, spec.spring_damping);
        let cv = NarrowDamping::velocity_scale(spring_damping);
        // Stored velocities: Q(20 + g) N.
        let vq = FORCE_FRAC + NarrowDamping::velocity_frac(spring_damping, hd / node_mass);
        let (damp, damp_sh) = q::norm16(hd * node_damping / node_mass, 16, 30);
        // C_v h/m ≤ 0.03 · 2000 (checked), as Q(x): f · step / 2^(x + 20 − vq).
        let (step, x) = q::norm16(cv * 1000.0 * hd / node_mass, 0, 60);
        let (step_sh1, step_sh2) = split_shift((x + FORCE_FRAC).saturating_sub(vq));
        let f_hold = if step > 0 {
            ((1i64 << (30 + step_sh1)) / step as i64).min(i32::MAX as i64) as i32
        } else {
            i32::MAX
        };
        let v_limit = from_f64(VEL_LIMIT_MM_S * cv, vq);
        // Without the hold the step per unit force is ≤ ½ in stored units: one operand
        // and one right shift after a 16-bit product.
        let factor = cv * 1000.0 * hd / node_mass * libm::ldexp(1.0, vq as i32 - FORCE_FRAC as i32);
        let factor_hh = 0.5 * h / cv * libm::ldexp(1.0, LEN_FRAC as i32 - vq as i32);
        let fast_path = f_hold == i32::MAX && factor_hh < 2.0 - 1.0 / 16384.0 && v_limit <= 1 << 28;
        let ((fast, fast_sh), (fast_hh, fast_hh_sh)) = if fast_path {
            (q::norm16(factor, 16, 40), q::norm16(factor_hh, 14, 40))
        } else {
            ((0, 0), (0, 0))
        };
        // h/(2 C_v) ≤ 2⁻⁹ s / 10⁻⁴ N·s/mm < 20 mm/N, as Q(y): V · hh / 2^(vq + y − 24).
        let (hh, y) = q::norm16(0.5 * h / cv, 0, 60);
        let (hh_sh1, hh_sh2) = split_shift((vq + y).saturating_sub(LEN_FRAC));
        // mm/s Q16 · C_v Q(e) / 2^(16 + e − vq) = Q(vq).
        let (cvq, e) = q::norm16(cv, 0, 60);
        let cv_sh = (VEL_FRAC + e).saturating_sub(vq);
        // Q(vq) · 1/C_v Q(z) / 2^(vq + z − 16) = Q16 (1/C_v ≤ 10⁴: z ≥ 1).
        let (inv_cv, z) = q::norm16(1.0 / cv, 0, 30);
        Self {
            damp,
            damp_sh: damp_sh as u8,
            step,
            step_sh1: step_sh1 as u8,
            step_sh2: step_sh2 as u8,
            f_hold,
            fast_path,
            symplectic: spec.symplectic(),
            fast,
            fast_sh: fast_sh as u8,
            fast_hh,
            fast_hh_sh: fast_hh_sh as u8,
            hh,
            hh_sh1: hh_sh1 as u8,
            hh_sh2: hh_sh2 as u8,
            cv: cvq,
            cv_sh: cv_sh as u8,
            inv_cv,
            inv_cv_sh: (vq + z - VEL_FRAC) as u8,
            v_limit,
        }
    }

    /// A velocity (Q16 mm/s, within ±2³⁰) as the node stores it.
    pub(super) fn store(&self, v: i32) -> i32 {
        let (sh1, sh2) = split_shift(self.cv_sh as u32);
        (q::mul_s_by(v, self.cv, sh1) >> sh2)
            .max(-self.v_limit)
            .min(self.v_limit)
    }

    /// A stored velocity in mm/s (Q16).
    pub(super) fn velocity(&self, stored: i32) -> i32 {
        let (sh1, sh2) = split_shift(self.inv_cv_sh as u32);
        q::mul_s_by(stored, self.inv_cv, sh1) >> sh2
    }
}

/// The integrator's step with 16-bit coefficients on the stored velocity `V = C_v v`
/// ([`NarrowStep`]): two 32-bit multiplies per product on the M0. With `HOLD` (the
/// general path) the force is held at `f_hold` so that the velocity step fits (16384
/// mm/s in one substep: never reached by a stable patch), and the shifts are run-time;
/// without (`fast_path`: every force fits, the stored velocities' fraction bits being
/// chosen for it where they can be, see [`NarrowDamping::velocity_frac`]), two
/// fixed-shift products with one run-time shift each. With `SYMPLECTIC` the position
/// advances by the new velocity alone (the velocity step's `h D` is in the coefficients).
#[inline(always)]
pub(super) fn integrate<const HOLD: bool, const SYMPLECTIC: bool>(c: &NarrowStep, n: &mut Node) {
    for j in 0..3 {
        let (u, v, f) = (n.u[j], n.v[j], n.f[j]);
        // V' = V − (h c/m) V + (C_v h/m) f: |V (1 − h c/m)| < 2³⁰ and the step ≤ 2³⁰,
        // so the sum fits before the clamp (max/min: no panic path).
        let drag = q::mul_s::<16>(v, c.damp) >> c.damp_sh;
        let step = if HOLD {
            let f = f.max(-c.f_hold).min(c.f_hold);
            q::mul_s_by(f, c.step, c.step_sh1 as u32) >> c.step_sh2
        } else {
            q::mul_s::<16>(f, c.fast) >> c.fast_sh
        };
        let v_new = v
            .wrapping_sub(drag)
            .wrapping_add(step)
            .max(-c.v_limit)
            .min(c.v_limit);
        // u' = u + (V + V') h/(2 C_v), or (V' + V') h/(2 C_v) with `SYMPLECTIC`: to Q24
        // mm by the shifts, |du| < 2³⁰ (the fast path: |V + V'| ≤ 2²⁹ and the factor
        // < 2, so its 16-bit pieces and its result stay within 2³⁰).
        let vv = if SYMPLECTIC { v_new } else { v }.wrapping_add(v_new);
        let du = if HOLD {
            q::mul_s_by(vv, c.hh, c.hh_sh1 as u32) >> c.hh_sh2
        } else {
            q::mul_s::<14>(vv, c.fast_hh) >> c.fast_hh_sh
        };
        n.u[j] = q::hold::<DISP_LIMIT_BITS>(u.wrapping_add(du));
        n.v[j] = v_new;
    }
    n.f = [0; 3];
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(c: f64, m: f64, hz: f64, n: f64) -> StepSpec {
        StepSpec {
            h: 1.0 / (hz * n),
            node_mass: m,
            node_damping: 0.05,
            spring_damping: c,
            integrator: crate::arith::Integrator::ImprovedEuler,
            damping_factor: 1.0,
        }
    }

    /// The narrow integrator's velocity step fits 2³⁰ for every force it may see: any
    /// `i32` when `f_hold` is `i32::MAX` (no hold), else the held force; and the
    /// configurations that allow it (the default among them) need no hold.
    #[test]
    fn narrow_velocity_step_fits() {
        let mut no_hold = 0;
        for c in [0.0, 0.05, 0.1, 1.0, 3.0, 30.0] {
            for m in [0.001, 0.005, 0.03, 0.2] {
                for hz in [250.0, 1000.0, 10_000.0] {
                    for n in [1.0, 6.0] {
                        let sp = spec(c, m, hz, n);
                        if 1000.0 * sp.h / m >= 2000.0 {
                            continue;
                        }
                        let s = NarrowStep::new(&sp);
                        let limit = if s.f_hold == i32::MAX {
                            no_hold += 1;
                            i32::MAX
                        } else {
                            s.f_hold
                        };
                        let lowest = if limit == i32::MAX { i32::MIN } else { -limit };
                        for f in [lowest, limit, limit / 3] {
                            let exact = (f as i64 * s.step as i64) >> s.step_sh1;
                            assert!(exact.abs() <= 1 << 30, "C={c} m={m} {hz} Hz n={n}");
                            assert_eq!(q::mul_s_by(f, s.step, s.step_sh1 as u32) as i64, exact);
                            if s.fast_path {
                                // The fast path: the same step to 2⁻¹⁴, within 2³⁰.
                                let fast = (f as i64 * s.fast as i64) >> (16 + s.fast_sh);
                                let general = exact >> s.step_sh2;
                                assert!(fast.abs() <= 1 << 30);
                                assert!((fast - general).abs() <= 2 + general.abs() / 16384);
                                assert_eq!(q::mul_s::<16>(f, s.fast) as i64 >> s.fast_sh, fast);
                            }
                        }
                        if s.fast_path {
                            assert_eq!(s.f_hold, i32::MAX);
                            // |V + V'| ≤ 2 v_limit ≤ 2²⁹: the fast position step, within
                            // 2³⁰ and equal to the general one to 2⁻¹³.
                            assert!(s.v_limit <= 1 << 28);
                            let vm = 2 * s.v_limit;
                            for vv in [-vm, vm, 12345] {
                                let fast = q::mul_s::<14>(vv, s.fast_hh) as i64 >> s.fast_hh_sh;
                                let exact = ((vv as i64 * s.fast_hh as i64) >> 14) >> s.fast_hh_sh;
                                assert_eq!(fast, exact);
                                let general = ((vv as i64 * s.hh as i64) >> s.hh_sh1) >> s.hh_sh2;
                                assert!((fast - general).abs() <= 2 + general.abs() / 8192);
                                assert!(fast.abs() <= 1 << 30);
                            }
                        }
                    }
                }
            }
        }
        assert!(no_hold > 0);
        let d = spec(1.0, 0.005, 1000.0, 6.0);
        assert_eq!(NarrowStep::new(&d).f_hold, i32::MAX);
        assert!(NarrowStep::new(&d).fast_path);
    }
}
