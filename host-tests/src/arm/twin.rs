//! The arm in `f64`, independent of the core's fixed point (it shares only `ArmSpec`):
//! counts to angles, the forward kinematics and its Jacobian, the masses' potential and
//! its gradient, the torques and duties, and the inverse kinematics.

use mccs::{ArmSpec, GravitySpec};
use std::f64::consts::PI;

/// The `f64` arm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArmTwin {
    /// Its description.
    pub spec: ArmSpec,
}

impl ArmTwin {
    /// Joint angles (rad) at counts.
    pub fn angles(&self, counts: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|k| {
            let j = &self.spec.joints[k];
            j.home_angle_deg.to_radians()
                + j.sign * 2.0 * PI * (counts[k] - j.home_count as f64)
                    / (j.counts_per_rev * j.ratio)
        })
    }

    /// Counts (fractional) at joint angles (rad).
    pub fn counts(&self, angles: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|k| {
            let j = &self.spec.joints[k];
            j.home_count as f64
                + (angles[k] - j.home_angle_deg.to_radians()) * j.counts_per_rev * j.ratio
                    / (2.0 * PI * j.sign)
        })
    }

    /// The probe in the device frame, mm.
    pub fn fk(&self, t: [f64; 3]) -> [f64; 3] {
        let s = &self.spec;
        let r = s.upper_arm_mm * t[1].sin() + s.forearm_mm * t[2].sin();
        [
            r * t[0].cos(),
            r * t[0].sin(),
            s.base_height_mm + s.upper_arm_mm * t[1].cos() - s.forearm_mm * t[2].cos(),
        ]
    }

    /// `∂p/∂θ`, mm/rad: rows x, y, z; columns A, B, C.
    pub fn jacobian(&self, t: [f64; 3]) -> [[f64; 3]; 3] {
        let s = &self.spec;
        let (lb, lc) = (s.upper_arm_mm, s.forearm_mm);
        let r = lb * t[1].sin() + lc * t[2].sin();
        let (ca, sa) = (t[0].cos(), t[0].sin());
        [
            [-r * sa, lb * t[1].cos() * ca, lc * t[2].cos() * ca],
            [r * ca, lb * t[1].cos() * sa, lc * t[2].cos() * sa],
            [0.0, -lb * t[1].sin(), lc * t[2].sin()],
        ]
    }

    /// The masses' potential, N·mm (its zero at the shoulder's height).
    pub fn potential(&self, t: [f64; 3]) -> f64 {
        let s = &self.spec;
        let g = s.gravity.unwrap_or(GravitySpec::NONE);
        let upper = g.upper_arm_com_mm * t[1].cos();
        let fore = s.upper_arm_mm * t[1].cos() - g.forearm_com_mm * t[2].cos();
        g.g * (g.upper_arm_mass_kg * upper + g.forearm_mass_kg * fore)
    }

    /// `∂U/∂θ`, N·mm.
    pub fn gravity(&self, t: [f64; 3]) -> [f64; 3] {
        let s = &self.spec;
        let g = s.gravity.unwrap_or(GravitySpec::NONE);
        [
            0.0,
            -g.g * t[1].sin()
                * (g.upper_arm_mass_kg * g.upper_arm_com_mm + g.forearm_mass_kg * s.upper_arm_mm),
            g.g * g.forearm_mass_kg * g.forearm_com_mm * t[2].sin(),
        ]
    }

    /// `Jᵀ F + ∂U/∂θ`, N·mm, for `F` in N.
    pub fn torque(&self, t: [f64; 3], f: [f64; 3]) -> [f64; 3] {
        let j = self.jacobian(t);
        let g = self.gravity(t);
        std::array::from_fn(|k| j[0][k] * f[0] + j[1][k] * f[1] + j[2][k] * f[2] + g[k])
    }

    /// The duties (±1) for torques in N·mm, scaled alike when any would pass 1; and
    /// whether they were.
    pub fn duties(&self, tau: [f64; 3]) -> ([f64; 3], bool) {
        let d: [f64; 3] = std::array::from_fn(|k| {
            let j = &self.spec.joints[k];
            j.sign * tau[k] / 1000.0 / (j.ratio * j.torque_constant_nm_per_a * j.max_current_a)
        });
        let most = d.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if most > 1.0 {
            (d.map(|x| x / most), true)
        } else {
            (d, false)
        }
    }

    /// Joint angles (rad) that put the probe at `p` (device frame, mm), on the arm's
    /// working branch within the joints' ranges: the one inverse kinematics of the
    /// project (`mccs::arm::inverse`, held to this twin's forward kinematics by the
    /// tests); `None` out of reach.
    pub fn ik(&self, p: [f64; 3]) -> Option<[f64; 3]> {
        mccs::arm::inverse::angles(&self.spec, p)
    }
}
