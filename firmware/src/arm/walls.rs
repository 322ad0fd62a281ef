//! [`Walls`]: each joint's virtual walls inside its limits, as a duty back toward the
//! range (full duty at the stop), which [`super::device::ArmDevice`] adds to the tissue's.

/// Each joint's virtual walls: where they stand, in counts from home along the joint's
/// angle (`sign · (count − home_count)`), and the duty per count past them (Q16).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Walls {
    /// The low and the high wall, counts from home along the angle.
    pub at: [(i32, i32); 3],
    /// Duty per count past a wall, Q16 (full duty at the stop).
    pub duty_per_count: [i32; 3],
    /// Each joint's `sign` (+1 or −1): the duty's direction for a torque along the angle.
    pub sign: [i32; 3],
}

impl Walls {
    /// The walls of `spec`, `margin_deg` inside each joint's limits (start-up: floating
    /// point). A margin of at least one count.
    pub fn of(spec: &mccs::ArmSpec, margin_deg: f64) -> Self {
        let wall = |j: &mccs::JointSpec| {
            let per_deg = libm::fabs(j.counts_per_rev * j.ratio) / 360.0;
            let at = |deg: f64| libm::round((deg - j.home_angle_deg) * per_deg) as i32;
            let margin = libm::round(margin_deg * per_deg).max(1.0);
            (
                (
                    at(j.min_angle_deg + margin_deg),
                    at(j.max_angle_deg - margin_deg),
                ),
                libm::round(65_536.0 / margin) as i32,
                if j.sign < 0.0 { -1 } else { 1 },
            )
        };
        let w = [
            wall(&spec.joints[0]),
            wall(&spec.joints[1]),
            wall(&spec.joints[2]),
        ];
        Walls {
            at: w.map(|x| x.0),
            duty_per_count: w.map(|x| x.1),
            sign: w.map(|x| x.2),
        }
    }

    /// The walls' duties at joint counts `from_home` (`count − home_count`), Q16: zero
    /// inside, else back toward the range, at most full duty each.
    pub fn duty(&self, from_home: [i32; 3]) -> [i32; 3] {
        let mut out = [0i32; 3];
        let joints = self
            .at
            .iter()
            .zip(self.duty_per_count.iter().zip(&self.sign));
        for ((o, &count), (&(lo, hi), (&per, &sign))) in out.iter_mut().zip(&from_home).zip(joints)
        {
            let a = count.saturating_mul(sign);
            let past = if a > hi {
                a - hi
            } else if a < lo {
                a - lo
            } else {
                0
            };
            let d = (past as i64 * per as i64).clamp(-65_536, 65_536) as i32;
            *o = -d * sign;
        }
        out
    }
}
