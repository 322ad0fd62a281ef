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
    /// A mass or centre of mass negative or not finite, `g` not within ±100 m/s², or a
    /// gravity torque of 32,768 N·mm or more.
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
            Self::Gravity => "gravity: masses and centres of mass must be finite and ≥ 0, g within ±100 m/s², the torques under 32768 N·mm",
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

/// What [`ArmSpec::check`] refuses, down to the key: the rule broken, and the device
/// file's key that breaks it (docs/arm.md), so that a reader of the file can name its
/// line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ArmFieldError {
    /// The rule, as [`ArmSpec::validate`] reports it.
    pub error: ArmError,
    /// The key within its section ([`ArmFieldError::section`]): `upper_arm_mm`,
    /// `min_angle_deg`, …
    pub key: &'static str,
    /// What the key must be: `must be > 0`, …
    pub rule: &'static str,
}

impl ArmFieldError {
    /// The device file's section of the key: `arm`, `joint.a`, `joint.b`, `joint.c` or
    /// `gravity`.
    pub const fn section(&self) -> &'static str {
        match (self.error, self.error.joint()) {
            (ArmError::Gravity, _) => "gravity",
            (_, Some(0)) => "joint.a",
            (_, Some(1)) => "joint.b",
            (_, Some(_)) => "joint.c",
            (_, None) => "arm",
        }
    }
}

/// `Err` of `error` at `key` where `ok` fails.
fn rule(
    ok: bool,
    error: ArmError,
    key: &'static str,
    rule: &'static str,
) -> Result<(), ArmFieldError> {
    if ok {
        Ok(())
    } else {
        Err(ArmFieldError { error, key, rule })
    }
}

/// Finite and > 0.
fn positive(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

impl ArmSpec {
    /// Checks the ranges [`ArmError`] names (see [`ArmSpec::check`] for the key).
    pub fn validate(&self) -> Result<(), ArmError> {
        self.check().map_err(|e| e.error)
    }

    /// Checks every field against its range: the project's one statement of an arm's
    /// rules, which the device-file reader maps to its file, line and key.
    pub fn check(&self) -> Result<(), ArmFieldError> {
        use ArmError as E;
        let within = |x: f64, zero_ok: bool| {
            x.is_finite() && x <= 1000.0 && (x > 0.0 || zero_ok && x == 0.0)
        };
        rule(
            within(self.base_height_mm, true),
            E::Length,
            "base_height_mm",
            "must be 0 … 1000 mm",
        )?;
        let arm = "must be > 0 and ≤ 1000 mm";
        rule(
            within(self.upper_arm_mm, false),
            E::Length,
            "upper_arm_mm",
            arm,
        )?;
        rule(within(self.forearm_mm, false), E::Length, "forearm_mm", arm)?;
        rule(
            self.tissue_origin_mm
                .iter()
                .all(|v| v.is_finite() && v.abs() <= 2000.0),
            E::Origin,
            "tissue_origin_mm",
            "must be [x, y, z]: three numbers of mm, each within ±2000",
        )?;
        for (i, j) in self.joints.iter().enumerate() {
            j.check(i as u8)?;
        }
        if let Some(g) = &self.gravity {
            g.check(self.upper_arm_mm)?;
        }
        Ok(())
    }
}

impl JointSpec {
    /// Joint `i`'s (0: A, 1: B, 2: C) ranges.
    fn check(&self, i: u8) -> Result<(), ArmFieldError> {
        use ArmError as E;
        let t = E::Transmission(i);
        rule(
            positive(self.counts_per_rev),
            t,
            "counts_per_rev",
            "must be > 0",
        )?;
        rule(positive(self.ratio), t, "ratio", "must be > 0")?;
        rule(
            (16.0..=(1u64 << 30) as f64).contains(&(self.counts_per_rev * self.ratio)),
            t,
            "counts_per_rev",
            "counts_per_rev × ratio (counts per joint turn) must be 16 … 2^30",
        )?;
        rule(
            self.sign == 1.0 || self.sign == -1.0,
            E::Sign(i),
            "sign",
            "must be 1 or -1",
        )?;
        let m = E::Motor(i);
        rule(
            positive(self.torque_constant_nm_per_a),
            m,
            "torque_constant_nm_per_a",
            "must be > 0",
        )?;
        rule(
            positive(self.max_current_a),
            m,
            "max_current_a",
            "must be > 0",
        )?;
        let th = E::Thermal(i);
        let c = self.continuous_current_a;
        rule(positive(c), th, "continuous_current_a", "must be > 0")?;
        rule(
            c <= self.max_current_a,
            th,
            "continuous_current_a",
            "must be at most max_current_a",
        )?;
        let tau = self.thermal_time_constant_s;
        rule(
            (1.0..=10_000.0).contains(&tau),
            th,
            "thermal_time_constant_s",
            "must be 1 … 10000 s",
        )?;
        let tr = E::Trim(i);
        let offset = (-0.2..=0.2).contains(&self.duty_offset);
        rule(
            offset,
            tr,
            "duty_offset",
            "must be -0.2 … 0.2 (of full duty)",
        )?;
        let band = (0.0..=0.2).contains(&self.dead_band);
        rule(band, tr, "dead_band", "must be 0 … 0.2 (of full duty)")?;
        let r = E::Range(i);
        let angle = |d: f64| d.is_finite() && d.abs() <= 180.0;
        let deg = "must be within ±180°";
        rule(angle(self.home_angle_deg), r, "home_angle_deg", deg)?;
        rule(angle(self.min_angle_deg), r, "min_angle_deg", deg)?;
        rule(angle(self.max_angle_deg), r, "max_angle_deg", deg)?;
        rule(
            self.min_angle_deg < self.home_angle_deg && self.home_angle_deg < self.max_angle_deg,
            r,
            "min_angle_deg",
            "must be below home_angle_deg, and max_angle_deg above it",
        )
    }
}

impl GravitySpec {
    /// The masses' ranges, `g` within ±100 m/s², and the torques they ask of the
    /// shoulder and the elbow (with the upper arm `upper_arm_mm` long) under 32,768 N·mm
    /// (the drive's Q16 gravity terms).
    fn check(&self, upper_arm_mm: f64) -> Result<(), ArmFieldError> {
        let ok = |x: f64| x.is_finite() && x >= 0.0;
        let g = ArmError::Gravity;
        rule(
            ok(self.upper_arm_mass_kg),
            g,
            "upper_arm_mass_kg",
            "must be ≥ 0",
        )?;
        rule(
            ok(self.upper_arm_com_mm),
            g,
            "upper_arm_com_mm",
            "must be ≥ 0",
        )?;
        rule(
            ok(self.forearm_mass_kg),
            g,
            "forearm_mass_kg",
            "must be ≥ 0",
        )?;
        rule(ok(self.forearm_com_mm), g, "forearm_com_mm", "must be ≥ 0")?;
        rule(
            self.g.is_finite() && self.g.abs() <= 100.0,
            g,
            "g",
            "must be within ±100 m/s²",
        )?;
        let torque = "with the other masses, asks a gravity torque of 32768 N·mm or more";
        let b = self.g
            * (self.upper_arm_mass_kg * self.upper_arm_com_mm
                + self.forearm_mass_kg * upper_arm_mm);
        rule(b.abs() < 32_768.0, g, "upper_arm_mass_kg", torque)?;
        let c = self.g * self.forearm_mass_kg * self.forearm_com_mm;
        rule(c.abs() < 32_768.0, g, "forearm_mass_kg", torque)
    }
}
