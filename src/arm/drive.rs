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
const FULL: i64 = 1 << 16;

impl Arm {
    /// The duties that render `force` (N, tissue frame) at `pose`. The force is held to
    /// ±1,024 N per component.
    pub fn drive(&self, pose: &ArmPose, force: [Force; 3]) -> Drive {
        let [(ca, sa), (cb, sb), (cc, sc)] = pose.cos_sin;
        let [fx, fy, fz] = force.map(|f| f.to_bits().clamp(-(1 << 30), 1 << 30));
        // Along the arm's plane (u) and across it (v), Q19 N (Q31 × Q20 / 2³²).
        let u = hi(ca, fx) + hi(sa, fy);
        let v = hi(ca, fy) - hi(sa, fx);
        let fz = fz >> 1;
        // τ_A = r v: Q17 × Q19 = Q36 → Q8. τ_B = Lb (cos B u − sin B F_z),
        // τ_C = Lc (cos C u + sin C F_z): Q31 × Q19 / 2³² = Q18 N, × Q17 mm = Q35 → Q8.
        let jt = [
            ((pose.reach_q17 as i64 * v as i64) >> 28) as i32,
            ((self.upper_q17 as i64 * (hi(cb, u) - hi(sb, fz)) as i64) >> 27) as i32,
            ((self.fore_q17 as i64 * (hi(cc, u) + hi(sc, fz)) as i64) >> 27) as i32,
        ];
        // ∂U/∂θ: B: −G_B sin B, C: G_C sin C (Q16 × Q31 / 2³² = Q15 → Q8).
        let gravity = [
            0,
            -(hi(self.gravity_b_q16, sb) >> 7),
            hi(self.gravity_c_q16, sc) >> 7,
        ];
        let mut torque_q8 = [0i32; 3];
        let mut duty = [0i64; 3];
        let mut most = 0i64;
        for k in 0..3 {
            torque_q8[k] = jt[k].saturating_add(gravity[k]);
            let j = &self.joints[k];
            duty[k] = (torque_q8[k] as i64 * j.duty_gain as i64) >> j.duty_shift;
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
            torque_q8,
            duty_q16: duty.map(|d| d.clamp(-FULL, FULL) as i32),
            scaled,
        }
    }
}
