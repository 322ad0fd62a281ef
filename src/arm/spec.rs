//! What an arm is made of: its lengths, its tissue's place, its joints and, optionally,
//! its masses (the device file of docs/arm.md, `[arm]`, `[joint.a|b|c]`, `[gravity]`).

/// One joint: its encoder, transmission, motor and range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointSpec {
    /// Encoder counts per motor turn, after ×4 quadrature (> 0).
    pub counts_per_rev: f64,
    /// Motor turns per joint turn: the capstan's ratio (> 0).
    pub ratio: f64,
    /// +1 or −1: the joint's angle grows with the count, or against it.
    pub sign: f64,
    /// The count at the home pose.
    pub home_count: i32,
    /// The joint's angle at the home pose, degrees.
    pub home_angle_deg: f64,
    /// The motor's torque constant, N·m/A (> 0).
    pub torque_constant_nm_per_a: f64,
    /// The driver's current at 100 % duty, A (> 0).
    pub max_current_a: f64,
    /// The motor's continuous (rated) current, A (`0 < x ≤ max_current_a`): what the I²t
    /// model folds the current back to.
    pub continuous_current_a: f64,
    /// The motor winding's thermal time constant, s (1 … 10,000).
    pub thermal_time_constant_s: f64,
    /// The amplifier's trim: the duty at which its current is zero, a fraction of full
    /// duty (−0.2 … 0.2; measured by the locked-rotor sweep of docs/arm.md).
    pub duty_offset: f64,
    /// The amplifier's trim: how far past the offset the duty goes before current flows,
    /// a fraction of full duty (0 … 0.2).
    pub dead_band: f64,
    /// The joint's range, degrees (`min < max`, within ±180).
    pub min_angle_deg: f64,
    /// See `min_angle_deg`.
    pub max_angle_deg: f64,
}

/// The masses gravity compensation holds up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GravitySpec {
    /// The upper arm's mass, kg (≥ 0).
    pub upper_arm_mass_kg: f64,
    /// Its centre of mass from the shoulder, mm (≥ 0).
    pub upper_arm_com_mm: f64,
    /// The forearm's mass, kg (≥ 0).
    pub forearm_mass_kg: f64,
    /// Its centre of mass from the elbow, mm (≥ 0).
    pub forearm_com_mm: f64,
    /// Gravity, m/s².
    pub g: f64,
}

impl GravitySpec {
    /// No masses: no compensation.
    pub const NONE: GravitySpec = GravitySpec {
        upper_arm_mass_kg: 0.0,
        upper_arm_com_mm: 0.0,
        forearm_mass_kg: 0.0,
        forearm_com_mm: 0.0,
        g: 9.81,
    };
}

/// An arm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArmSpec {
    /// `Ln`: the shoulder's height above the device frame's origin, mm (≥ 0).
    pub base_height_mm: f64,
    /// `Lb`, mm (> 0).
    pub upper_arm_mm: f64,
    /// `Lc`, mm (> 0).
    pub forearm_mm: f64,
    /// The tissue's origin in the device frame, mm.
    pub tissue_origin_mm: [f64; 3],
    /// Joints A, B, C.
    pub joints: [JointSpec; 3],
    /// Gravity compensation (none: no masses).
    pub gravity: Option<GravitySpec>,
}

/// Why an arm is refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArmError {
    /// A length not finite, negative (the base) or not positive (the arm's), or over
    /// 1,000 mm.
    Length,
    /// The tissue's origin not finite or beyond 2,000 mm.
    Origin,
    /// Joint `0..3` (A, B, C): counts per turn or ratio not finite and positive, or a
    /// joint turn of fewer than 16 counts or more than 2³⁰.
    Transmission(u8),
    /// A sign other than ±1.
    Sign(u8),
    /// A torque constant or a current not finite and positive.
    Motor(u8),
    /// A range not within ±180° with `min < home < max`.
    Range(u8),
    /// A continuous current not `0 < x ≤ max_current_a`, or a thermal time constant not
    /// 1 … 10,000 s.
    Thermal(u8),
    /// A duty offset not −0.2 … 0.2, or a dead band not 0 … 0.2.
    Trim(u8),
    /// A mass or centre of mass negative or not finite, `g` not finite, or a gravity
    /// torque of 32,768 N·mm or more.
    Gravity,
}

impl ArmError {
    /// The message.
    pub const fn message(&self) -> &'static str {
        match self {
            Self::Length => "arm: the lengths must be finite, the arm's > 0 and the base's ≥ 0, at most 1000 mm",
            Self::Origin => "arm: the tissue's origin must be finite, within 2000 mm",
            Self::Transmission(_) => "joint: counts_per_rev and ratio must be finite and > 0, a joint turn 16 to 2^30 counts",
            Self::Sign(_) => "joint: sign must be 1 or -1",
            Self::Motor(_) => "joint: torque_constant_nm_per_a and max_current_a must be finite and > 0",
            Self::Range(_) => "joint: min_angle_deg < home_angle_deg < max_angle_deg, within ±180",
            Self::Thermal(_) => "joint: 0 < continuous_current_a ≤ max_current_a, thermal_time_constant_s 1 … 10000",
            Self::Trim(_) => "joint: duty_offset must be -0.2 … 0.2 and dead_band 0 … 0.2",
            Self::Gravity => "gravity: masses and centres of mass must be finite and ≥ 0, g finite, the torques under 32768 N·mm",
        }
    }

    /// The joint it is about (0: A, 1: B, 2: C), if any.
    pub const fn joint(&self) -> Option<u8> {
        match self {
            Self::Transmission(j)
            | Self::Sign(j)
            | Self::Motor(j)
            | Self::Range(j)
            | Self::Thermal(j)
            | Self::Trim(j) => Some(*j),
            _ => None,
        }
    }
}

impl core::fmt::Display for ArmError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.message())
    }
}

impl core::error::Error for ArmError {}

impl ArmSpec {
    /// Checks the ranges [`ArmError`] names.
    pub fn validate(&self) -> Result<(), ArmError> {
        let len = |x: f64, zero_ok: bool| {
            x.is_finite() && x <= 1000.0 && (x > 0.0 || zero_ok && x == 0.0)
        };
        if !(len(self.base_height_mm, true)
            && len(self.upper_arm_mm, false)
            && len(self.forearm_mm, false))
        {
            return Err(ArmError::Length);
        }
        if !self
            .tissue_origin_mm
            .iter()
            .all(|v| v.is_finite() && v.abs() <= 2000.0)
        {
            return Err(ArmError::Origin);
        }
        for (i, j) in self.joints.iter().enumerate() {
            let i = i as u8;
            let per_turn = j.counts_per_rev * j.ratio;
            let positive = |x: f64| x.is_finite() && x > 0.0;
            if !(positive(j.counts_per_rev)
                && positive(j.ratio)
                && (16.0..=(1u64 << 30) as f64).contains(&per_turn))
            {
                return Err(ArmError::Transmission(i));
            }
            if j.sign != 1.0 && j.sign != -1.0 {
                return Err(ArmError::Sign(i));
            }
            if !(positive(j.torque_constant_nm_per_a) && positive(j.max_current_a)) {
                return Err(ArmError::Motor(i));
            }
            let within = |d: f64| d.is_finite() && d.abs() <= 180.0;
            if !(within(j.min_angle_deg)
                && within(j.max_angle_deg)
                && within(j.home_angle_deg)
                && j.min_angle_deg < j.home_angle_deg
                && j.home_angle_deg < j.max_angle_deg)
            {
                return Err(ArmError::Range(i));
            }
            let c = j.continuous_current_a;
            let tau = j.thermal_time_constant_s;
            if !(positive(c) && c <= j.max_current_a && (1.0..=10_000.0).contains(&tau)) {
                return Err(ArmError::Thermal(i));
            }
            if !((-0.2..=0.2).contains(&j.duty_offset) && (0.0..=0.2).contains(&j.dead_band)) {
                return Err(ArmError::Trim(i));
            }
        }
        if let Some(g) = &self.gravity {
            let ok = |x: f64| x.is_finite() && x >= 0.0;
            if !(ok(g.upper_arm_mass_kg)
                && ok(g.upper_arm_com_mm)
                && ok(g.forearm_mass_kg)
                && ok(g.forearm_com_mm)
                && g.g.is_finite())
            {
                return Err(ArmError::Gravity);
            }
            let b = g.g
                * (g.upper_arm_mass_kg * g.upper_arm_com_mm
                    + g.forearm_mass_kg * self.upper_arm_mm);
            let c = g.g * g.forearm_mass_kg * g.forearm_com_mm;
            if !(b.abs() < 32_768.0 && c.abs() < 32_768.0) {
                return Err(ArmError::Gravity);
            }
        }
        Ok(())
    }
}
