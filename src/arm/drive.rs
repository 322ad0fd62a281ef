//! The tissue's force to the motors: `τ = Jᵀ F` plus gravity compensation, each joint's
//! duty, and one scale for all three when any would pass 100 %.

use super::pose::hi;
use super::{recip::recip, Arm, ArmPose};
use crate::units::Force;

/// What the motors are given at one tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Drive {
    /// The joints' torques before saturation (`Jᵀ F` + gravity), Q8 N·mm.
    pub torque_q8: [i32; 3],
    /// The duties after it, Q16 (±65,536 = ±100 %).
    pub duty_q16: [i32; 3],
    /// Whether they were scaled down to fit.
    pub scaled: bool,
}

/// 100 % duty, Q16.
pub(super) const FULL_DUTY_Q16: i32 = 1 << 16;

/// `m · up` (`up` a power of two, `limit` = `i32::MAX / up`), saturated at the ends of
/// `i32`: a compare each way and a product (a saturating product is a long one).
#[inline(always)]
fn mul_saturating(m: i32, up: i32, limit: i32) -> i32 {
    if m > limit {
        i32::MAX
    } else if m < !limit {
        i32::MIN
    } else {
        m.wrapping_mul(up)
    }
}

impl Arm {
    /// The duties that render `force` (N, tissue frame: all of `Force`'s ±2,048 N) at
    /// `pose`. On the M4F its every-tick part in assembly (`drive_dsp.rs`), bit for bit
    /// [`Arm::drive_portable`], which every other core runs.
    pub fn drive(&self, pose: &ArmPose, force: [Force; 3]) -> Drive {
        #[cfg(mccs_dsp)]
        {
            let mut drive = Drive {
                torque_q8: [0; 3],
                duty_q16: [0; 3],
                scaled: false,
            };
            if super::drive_dsp::torques_and_duties(self, pose, &force, &mut drive) {
                drive.duty_q16 = scale_to_full(drive.duty_q16);
                drive.scaled = true;
            }
            drive
        }
        #[cfg(not(mccs_dsp))]
        self.drive_portable(pose, force)
    }

    /// [`Arm::drive`] in portable Rust: what the M3 and M0 (and the host) run, and what
    /// the M4F's assembly must equal (public so that the bench firmware checks it).
    pub fn drive_portable(&self, pose: &ArmPose, force: [Force; 3]) -> Drive {
        let [(ca, sa), (cb, sb), (cc, sc)] = pose.cos_sin;
        // Q19 N: each product below within half of `i32`, so that two sum within it.
        let [fx, fy, fz] = force.map(|f| f.to_bits() >> 1);
        // Along the arm's plane (u) and across it (v), Q18 N (Q31 × Q19 / 2³²).
        let u = hi(ca, fx) + hi(sa, fy);
        let v = hi(ca, fy) - hi(sa, fx);
        let fz = fz >> 1;
        // τ_A = r v: Q17 × Q18 = Q35 → Q8. τ_B = Lb (cos B u − sin B F_z),
        // τ_C = Lc (cos C u + sin C F_z): Q31 × Q18 / 2³² = Q17 N, × Q17 mm = Q34 → Q8.
        let jt = [
            ((pose.reach_q17 as i64 * v as i64) >> 27) as i32,
            ((self.upper_q17 as i64 * (hi(cb, u) - hi(sb, fz)) as i64) >> 26) as i32,
            ((self.fore_q17 as i64 * (hi(cc, u) + hi(sc, fz)) as i64) >> 26) as i32,
        ];
        // ∂U/∂θ: B: −G_B sin B, C: G_C sin C (Q16 × Q31 / 2³² = Q15 → Q8).
        let gravity = [
            0,
            -(hi(self.gravity_b_q16, sb) >> 7),
            hi(self.gravity_c_q16, sc) >> 7,
        ];
        let mut drive = Drive {
            torque_q8: [0; 3],
            duty_q16: [0; 3],
            scaled: false,
        };
        // Each duty plus 100 %, unsigned: the largest over 200 % is a duty past ±100 %.
        let mut offset_most = 0u32;
        for k in 0..3 {
            let torque = jt[k].saturating_add(gravity[k]);
            let j = &self.joints[k];
            // In `i32`: the duty's high word, then its shift (`Arm::new`'s `duty_gain`).
            let high = hi(torque, j.duty_gain);
            let duty = mul_saturating(high, j.duty_up, j.duty_limit) >> j.duty_down;
            offset_most = offset_most.max(duty.wrapping_add(FULL_DUTY_Q16) as u32);
            drive.torque_q8[k] = torque;
            drive.duty_q16[k] = duty;
        }
        if offset_most > 2 * FULL_DUTY_Q16 as u32 {
            drive.duty_q16 = scale_to_full(drive.duty_q16);
            drive.scaled = true;
        }
        drive
    }
}

/// The duties scaled by one factor so that the largest is ±100 % (at least one is
/// past it): `d / most` for each, through one reciprocal, `most` and the duties shifted
/// alike so that `most` lies in [2³⁰, 2³¹) (`most` ≤ 2³¹, over 2¹⁶ here). Out of line:
/// the rare path.
#[inline(never)]
fn scale_to_full(duty: [i32; 3]) -> [i32; 3] {
    let most = duty.iter().fold(0u32, |most, d| most.max(d.unsigned_abs()));
    let shift = 1 - most.leading_zeros() as i32;
    let (m, d) = if shift >= 0 {
        ((most >> shift) as i64, duty.map(|d| (d >> shift) as i64))
    } else {
        ((most << -shift) as i64, duty.map(|d| (d as i64) << -shift))
    };
    let y = recip(m);
    d.map(|d| (((d * y) >> 46) as i32).clamp(-FULL_DUTY_Q16, FULL_DUTY_Q16))
}
