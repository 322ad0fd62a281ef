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
    /// working branch, the elbow bent forward (`0 < B + C < 180°`: the other branch
    /// reaches the same point with the elbow below the line from shoulder to tip): of
    /// the solutions (the base's yaw or its opposite with the reach negated, each with
    /// the elbow's two places) the one on that branch within the joints' ranges nearest
    /// the home pose; `None` out of reach.
    pub fn ik(&self, p: [f64; 3]) -> Option<[f64; 3]> {
        let s = &self.spec;
        let (lb, lc) = (s.upper_arm_mm, s.forearm_mm);
        let z = p[2] - s.base_height_mm;
        let reach = p[0].hypot(p[1]);
        let home: [f64; 3] = std::array::from_fn(|k| s.joints[k].home_angle_deg.to_radians());
        let within = |t: &[f64; 3]| {
            (0..3).all(|k| {
                let j = &s.joints[k];
                let d = t[k].to_degrees();
                d >= j.min_angle_deg - 1e-6 && d <= j.max_angle_deg + 1e-6
            })
        };
        let mut best: Option<([f64; 3], f64)> = None;
        for (a, r) in [(p[1].atan2(p[0]), reach), ((-p[1]).atan2(-p[0]), -reach)] {
            let d2 = r * r + z * z;
            let d = d2.sqrt();
            if d > lb + lc || d < (lb - lc).abs() || d == 0.0 {
                continue;
            }
            // The elbow: on the circle of radius Lb about the shoulder and Lc about the tip.
            let along = (lb * lb - lc * lc + d2) / (2.0 * d);
            let h = (lb * lb - along * along).max(0.0).sqrt();
            let (ur, uz) = (r / d, z / d);
            for side in [1.0, -1.0] {
                let er = along * ur - side * h * uz;
                let ez = along * uz + side * h * ur;
                let t = [a, er.atan2(ez), (r - er).atan2(-(z - ez))];
                let branch = (t[1] + t[2]).sin() > 0.0;
                let dist: f64 = (0..3).map(|k| (t[k] - home[k]).abs()).sum::<f64>()
                    + if within(&t) { 0.0 } else { 1e3 }
                    + if branch { 0.0 } else { 1e6 };
                if best.is_none_or(|(_, b)| dist < b) {
                    best = Some((t, dist));
                }
            }
        }
        best.map(|(t, _)| t)
    }
}
