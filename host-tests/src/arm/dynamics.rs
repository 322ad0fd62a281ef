//! The arm as a body, in `f64` and SI units: what the board's arm device drives in the
//! closed-loop tests ([`super::closed_loop`]), where the firmware's own simulated arm
//! (`mccs_firmware::arm::plant`) only follows its path.
//!
//! - **Masses**: the upper arm's and the forearm's masses at their centres of mass (the
//!   device file's `[gravity]`), a hand's mass at the probe ([`Hand`]), and each motor's
//!   rotor inertia through its capstan (`ratio²` times it, [`BodySpec`]). The equations
//!   are d'Alembert's for point masses, `Σ mᵢ Jᵢᵀ (Jᵢ q̈ + q̇ᵀHᵢq̇) = τ + Σ Jᵢᵀ Fᵢ`, so
//!   the velocity-product (Coriolis, centrifugal) terms are in, and a free arm keeps its
//!   energy (a test holds it to 10⁻⁴ over 2 s).
//! - **Gravity** on the arm's masses (a hand carries its own weight).
//! - **Friction** per joint: viscous, and Coulomb's smoothed to viscous below
//!   [`BodySpec::stiction_rad_s`] (so that an explicit step stays stable).
//! - **The amplifier**: a first-order current stage ([`BodySpec::amplifier_s`]) after the
//!   duty's zero-order hold; torque `sign · ratio · Kt · i`.
//! - **The encoders**: whole counts (`floor`), the joint's `counts_per_rev · ratio` a turn.
//!
//! The values that are not in the device file are stand-ins, stated in [`BodySpec::STAND_IN`]
//! (docs/safety.md, "The arm's own dynamics"): measure your arm's.

use mccs::{ArmSpec, GravitySpec};
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

/// What the device file does not say about the arm as a body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodySpec {
    /// Each motor's rotor inertia, kg·m² (it counts `ratio²` times at the joint).
    pub rotor_kg_m2: [f64; 3],
    /// Each joint's viscous friction, N·m·s/rad.
    pub viscous_nm_s: [f64; 3],
    /// Each joint's Coulomb friction, N·m.
    pub coulomb_nm: [f64; 3],
    /// Below this joint speed, rad/s, Coulomb's friction grows linearly from 0.
    pub stiction_rad_s: f64,
    /// The amplifier's current stage, its time constant, s.
    pub amplifier_s: f64,
    /// Each motor's polarity as wired: +1 as the device file says, −1 reversed.
    pub polarity: [f64; 3],
}

impl BodySpec {
    /// Stand-ins for a WoodenHaptics-class arm: a Maxon RE40's rotor (142 g·cm²), its
    /// no-load friction (69 mA × 60.3 mN·m/A ≈ 4 mN·m at the motor, `ratio` times at
    /// the joint), a little viscous drag, and a current stage of 0.1 ms.
    pub const STAND_IN: BodySpec = BodySpec {
        rotor_kg_m2: [1.42e-5; 3],
        viscous_nm_s: [1e-3; 3],
        coulomb_nm: [0.067, 0.05, 0.05],
        stiction_rad_s: 0.02,
        amplifier_s: 1e-4,
        polarity: [1.0; 3],
    };
}

/// A hand on the handle: its mass moves with the probe; its spring and damper pull the
/// probe toward where the hand means it to be.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hand {
    /// kg (0 for no hand).
    pub mass_kg: f64,
    /// N·s/m, against the probe's speed relative to where it is led.
    pub damping_n_s_m: f64,
    /// N/m, toward where it is led.
    pub stiffness_n_m: f64,
}

impl Hand {
    /// No hand: the arm released.
    pub const OFF: Hand = Hand {
        mass_kg: 0.0,
        damping_n_s_m: 0.0,
        stiffness_n_m: 0.0,
    };
}

/// The arm's state and its parts' inputs.
#[derive(Clone, Debug)]
pub struct ArmBody {
    spec: ArmSpec,
    body: BodySpec,
    /// Joint angles, rad.
    pub angle: [f64; 3],
    /// Their rates, rad/s.
    pub rate: [f64; 3],
    /// Each motor's current, A.
    pub current: [f64; 3],
    /// The energy the motors have put into the arm and hand less the gravity work they
    /// did (what the device rendered), J.
    pub rendered_j: f64,
}

/// A point's position, m, at joint angles `q`.
type PointFn = fn(&ArmSpec, &[f64; 3]) -> Vector3<f64>;

/// The upper arm's centre of mass, the forearm's, and the probe, device frame, m.
fn upper_com(s: &ArmSpec, q: &[f64; 3]) -> Vector3<f64> {
    let c = gravity(s).upper_arm_com_mm;
    at(q, c * q[1].sin(), s.base_height_mm + c * q[1].cos())
}
fn fore_com(s: &ArmSpec, q: &[f64; 3]) -> Vector3<f64> {
    let (lb, c) = (s.upper_arm_mm, gravity(s).forearm_com_mm);
    let r = lb * q[1].sin() + c * q[2].sin();
    at(q, r, s.base_height_mm + lb * q[1].cos() - c * q[2].cos())
}
fn probe(s: &ArmSpec, q: &[f64; 3]) -> Vector3<f64> {
    let (lb, lc) = (s.upper_arm_mm, s.forearm_mm);
    let r = lb * q[1].sin() + lc * q[2].sin();
    at(q, r, s.base_height_mm + lb * q[1].cos() - lc * q[2].cos())
}
/// A point at reach `r_mm` and height `z_mm` about the base's yaw `q[0]`, m.
fn at(q: &[f64; 3], r_mm: f64, z_mm: f64) -> Vector3<f64> {
    Vector3::new(r_mm * q[0].cos(), r_mm * q[0].sin(), z_mm) / 1000.0
}
fn gravity(s: &ArmSpec) -> GravitySpec {
    s.gravity.unwrap_or(GravitySpec::NONE)
}

/// `∂p/∂q` of `point` (central differences), columns A, B, C.
fn jacobian(s: &ArmSpec, point: PointFn, q: &[f64; 3]) -> Matrix3<f64> {
    const H: f64 = 1e-6;
    let mut j = Matrix3::zeros();
    for k in 0..3 {
        let (mut a, mut b) = (*q, *q);
        a[k] += H;
        b[k] -= H;
        j.set_column(k, &((point(s, &a) - point(s, &b)) / (2.0 * H)));
    }
    j
}

/// `q̇ᵀ H q̇` of `point`: its acceleration at `q̈ = 0` (a second difference along `q̇`).
fn velocity_product(s: &ArmSpec, point: PointFn, q: &[f64; 3], rate: &[f64; 3]) -> Vector3<f64> {
    let speed = rate.iter().fold(0.0f64, |m, r| m.max(r.abs()));
    if speed < 1e-12 {
        return Vector3::zeros();
    }
    let e = 1e-4 / speed;
    let step = |sign: f64| -> [f64; 3] { std::array::from_fn(|k| q[k] + sign * e * rate[k]) };
    (point(s, &step(1.0)) - 2.0 * point(s, q) + point(s, &step(-1.0))) / (e * e)
}

impl ArmBody {
    /// The arm of `spec` at rest at its home angles, its amplifiers off.
    pub fn new(spec: ArmSpec, body: BodySpec) -> Self {
        Self {
            angle: spec.joints.map(|j| j.home_angle_deg.to_radians()),
            spec,
            body,
            rate: [0.0; 3],
            current: [0.0; 3],
            rendered_j: 0.0,
        }
    }

    /// Each joint's encoder now: whole counts, as a counter holds them.
    pub fn counts(&self) -> [i32; 3] {
        std::array::from_fn(|k| {
            let j = &self.spec.joints[k];
            let turns = (self.angle[k] - j.home_angle_deg.to_radians()) / (2.0 * PI) * j.sign;
            j.home_count + (turns * j.counts_per_rev * j.ratio).floor() as i32
        })
    }

    /// The probe in the device frame, m, and its velocity, m/s.
    pub fn probe(&self) -> (Vector3<f64>, Vector3<f64>) {
        let j = jacobian(&self.spec, probe, &self.angle);
        (probe(&self.spec, &self.angle), j * Vector3::from(self.rate))
    }

    /// The arm's kinetic and potential energy (its masses, its rotors, `hand`'s mass), J.
    pub fn energy(&self, hand: &Hand) -> f64 {
        let m = self.mass_matrix(hand);
        let v = Vector3::from(self.rate);
        0.5 * v.dot(&(m * v)) + self.potential()
    }

    /// The arm's masses' potential, J (zero at the base).
    fn potential(&self) -> f64 {
        let g = gravity(&self.spec).g;
        self.masses(&Hand::OFF)
            .iter()
            .map(|(point, mass)| g * mass * point(&self.spec, &self.angle).z)
            .sum()
    }

    /// The points with mass: each one's position function and mass, kg.
    fn masses(&self, hand: &Hand) -> [(PointFn, f64); 3] {
        let g = gravity(&self.spec);
        [
            (upper_com as PointFn, g.upper_arm_mass_kg),
            (fore_com as PointFn, g.forearm_mass_kg),
            (probe as PointFn, hand.mass_kg),
        ]
    }

    /// The Jacobians of the points with mass ([`Self::masses`], in its order) at the
    /// arm's angles: computed once a step, as each of them takes six of the point's
    /// positions (the probe's also gives its velocity).
    fn jacobians(&self) -> [Matrix3<f64>; 3] {
        self.masses(&Hand::OFF)
            .map(|(point, _)| jacobian(&self.spec, point, &self.angle))
    }

    fn mass_matrix(&self, hand: &Hand) -> Matrix3<f64> {
        self.mass_matrix_of(hand, &self.jacobians())
    }

    /// [`Self::mass_matrix`] from the points' Jacobians ([`Self::jacobians`]).
    fn mass_matrix_of(&self, hand: &Hand, jacobians: &[Matrix3<f64>; 3]) -> Matrix3<f64> {
        let mut m = Matrix3::from_diagonal(&Vector3::from(std::array::from_fn(|k| {
            self.body.rotor_kg_m2[k] * self.spec.joints[k].ratio.powi(2)
        })));
        for ((_, mass), j) in self.masses(hand).into_iter().zip(jacobians) {
            m += mass * j.transpose() * j;
        }
        m
    }

    /// One step of `dt` s: the amplifiers driven toward `command` (A, each motor), the
    /// hand led to `led` (device frame, m) moving at `led_velocity` (m/s). Semi-implicit
    /// Euler; `dt` of 0.1 ms or less.
    pub fn step(
        &mut self,
        dt: f64,
        command: [f64; 3],
        hand: &Hand,
        led: Vector3<f64>,
        led_velocity: Vector3<f64>,
    ) {
        let s = self.spec;
        let follow = 1.0 - (-dt / self.body.amplifier_s).exp();
        let mut tau = Vector3::zeros();
        for k in 0..3 {
            self.current[k] += (command[k] - self.current[k]) * follow;
            let j = &s.joints[k];
            tau[k] = self.body.polarity[k]
                * j.sign
                * j.ratio
                * j.torque_constant_nm_per_a
                * self.current[k];
        }
        let rate = Vector3::from(self.rate);
        let jacobians = self.jacobians();
        let gravity_torque = self.gravity_torque_of(&jacobians);
        // What the motors render: their torque less what holds the arm against gravity.
        self.rendered_j += (tau - gravity_torque).dot(&rate) * dt;
        let mut force = tau + gravity_torque.map(|t| -t);
        for k in 0..3 {
            let w = self.rate[k];
            let coulomb = self.body.coulomb_nm[k] * (w / self.body.stiction_rad_s).clamp(-1.0, 1.0);
            force[k] -= self.body.viscous_nm_s[k] * w + coulomb;
        }
        // (As `probe()` gives them, its Jacobian the one computed above.)
        let (p, v) = (probe(&s, &self.angle), jacobians[2] * rate);
        let pull = (led - p) * hand.stiffness_n_m + (led_velocity - v) * hand.damping_n_s_m;
        force += jacobians[2].transpose() * pull;
        for ((point, mass), j) in self.masses(hand).into_iter().zip(&jacobians) {
            force -= mass * j.transpose() * velocity_product(&s, point, &self.angle, &self.rate);
        }
        let accel = self
            .mass_matrix_of(hand, &jacobians)
            .lu()
            .solve(&force)
            .unwrap_or_else(Vector3::zeros);
        for k in 0..3 {
            self.rate[k] += accel[k] * dt;
            self.angle[k] += self.rate[k] * dt;
        }
    }

    /// `∂U/∂q`, N·m: the torque that holds the arm still against gravity.
    pub fn gravity_torque(&self) -> Vector3<f64> {
        self.gravity_torque_of(&self.jacobians())
    }

    /// [`Self::gravity_torque`] from the points' Jacobians ([`Self::jacobians`]).
    fn gravity_torque_of(&self, jacobians: &[Matrix3<f64>; 3]) -> Vector3<f64> {
        // (A hand carries its own weight: the arm's masses only.)
        let g = gravity(&self.spec).g;
        let mut t = Vector3::zeros();
        for ((_, mass), j) in self.masses(&Hand::OFF).into_iter().zip(jacobians) {
            t += j.transpose() * Vector3::new(0.0, 0.0, mass * g);
        }
        t
    }
}
