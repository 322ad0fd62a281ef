//! The tissue's force to the motors: `τ = Jᵀ F` plus gravity compensation, each joint's
//! duty, and one scale for all three when any would pass 100 %.

use super::{recip::recip, Arm, ArmPose};
use crate::units::Force;

/// What the motors are given at one tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Drive {
    /// The joints' torques before saturation (`Jᵀ F` + gravity), Q20 N·mm.
    pub torque_q20: [i64; 3],
    /// The duties after it, Q16 (±65,536 = ±100 %).
    pub duty_q16: [i32; 3],
    /// Whether they were scaled down to fit.
    pub scaled: bool,
}

/// The largest torque the duty's product takes, Q20 N·mm (2²¹ N·mm: 2 kN·m).
const TORQUE_HOLD: i64 = 1 << 41;
/// 100 % duty, Q16.
const FULL: i64 = 1 << 16;

impl Arm {
    /// The duties that render `force` (N, tissue frame) at `pose`.
    pub fn drive(&self, pose: &ArmPose, force: [Force; 3]) -> Drive {
        let [(ca, sa), (cb, sb), (cc, sc)] = pose.cos_sin.map(|(c, s)| (c as i64, s as i64));
        let [fx, fy, fz] = force.map(|f| f.to_bits() as i64);
        // The force along the arm's plane (u) and across it (v), Q20 N: Q31 × Q20 = Q51,
        // two terms within √2 · 2⁶².
        let u = (ca * fx + sa * fy) >> 31;
        let v = (ca * fy - sa * fx) >> 31;
        // τ_A = r v (Q20 × Q20 = Q40 → Q20); τ_B = Lb (cos B u − sin B F_z);
        // τ_C = Lc (cos C u + sin C F_z) (Q51 → Q20 N, × Q16 mm → Q36 → Q20).
        let jt = [
            (pose.reach_q20 * v) >> 20,
            (self.upper_q16 * ((cb * u - sb * fz) >> 31)) >> 16,
            (self.fore_q16 * ((cc * u + sc * fz) >> 31)) >> 16,
        ];
        // ∂U/∂θ: B: −G_B sin B, C: G_C sin C (Q16 N·mm × Q31 = Q47 → Q20).
        let gravity = [
            0,
            -(self.gravity_b_q16 * sb) >> 27,
            (self.gravity_c_q16 * sc) >> 27,
        ];
        let mut torque_q20 = [0i64; 3];
        let mut duty = [0i64; 3];
        let mut most = 0i64;
        for k in 0..3 {
            torque_q20[k] = jt[k] + gravity[k];
            let t = torque_q20[k].clamp(-TORQUE_HOLD, TORQUE_HOLD);
            let j = &self.joints[k];
            duty[k] = (t * j.duty_gain) >> j.duty_shift;
            most = most.max(duty[k].abs());
        }
        let scaled = most > FULL;
        if scaled {
            // d / most for each, through one reciprocal: `most` and the duties shifted
            // alike so that `most` lies in [2³⁰, 2³¹).
            let lz = (most as u64).leading_zeros() as i64;
            let shift = 33 - lz;
            let (m, d) = if shift >= 0 {
                (most >> shift, duty.map(|d| d >> shift))
            } else {
                (most << -shift, duty.map(|d| d << -shift))
            };
            let y = recip(m);
            duty = d.map(|d| (d * y) >> 46);
        }
        Drive {
            torque_q20,
            duty_q16: duty.map(|d| d.clamp(-FULL, FULL) as i32),
            scaled,
        }
    }
}
