//! [`ArmDevice`]: a 3-DOF arm as the tick's [`HapticDevice`] — three joints, each a
//! [`JointEncoder`](crate::arm::encoder::JointEncoder) and a PWM channel with a direction pin, one driver-enable pin and a
//! home input — through the core's [`Arm`] (counts to the probe, the force to duties).
//!
//! # Safety
//! - **No force before the arm is homed.** Until the home input has read high for the
//!   debounce's ticks in a row with every joint within 2 counts of where it was when the
//!   input rose ([`ArmDevice::with_home_debounce`]; the board's: 50 ms), the counts are
//!   not known: every write is zero duty. A bounce, or motion, starts the wait again.
//!   Then each joint's count becomes its `home_count`.
//! - **Faults end at the actuator.** A failed read or write is an error for the
//!   controller, which puts the device in its safe state: zero duty on every joint first
//!   (each attempted whatever the others did), then the driver disabled. A failed duty
//!   or direction write sets all three duties to zero before it returns.
//! - A direction change goes through zero duty (a failed pin write leaves the joint
//!   idle, never pushing the wrong way).
//! - The joints' limits are reported ([`ArmDevice::flags`]); a probe beyond what the
//!   tissue's frame holds reads far above the tissue: no contact.
//! - **I²t** ([`Thermal`], [`ArmDevice::with_thermal`]): each joint's winding heat as a
//!   first-order model of the current's square (its time constant the winding's); at the
//!   continuous current's square the joint's duty folds back to the continuous current,
//!   and stays folded until the heat falls to 81 % of it (0.9 of the current); the
//!   `thermal` status while any joint is folded.
//! - **Passivity** ([`ArmDevice::with_passivity`], [`mccs::PassivityObserver`]): the
//!   work the rendered force does on the probe, tick by tick; energy put out beyond the
//!   hand's input (held to a credit out of contact) by more than the trip is
//!   [`ArmFault::EnergyOut`], zero duty first.
//! - **Trims** ([`Trims`], [`ArmDevice::with_trims`]): each duty, last, through its
//!   amplifier's offset and dead band, so that the current is what the force needs
//!   (zero duty before homing stays zero).
//! - **Virtual walls** ([`Walls`], [`ArmDevice::with_walls`]; the board's: 3° inside
//!   each mechanical stop): a homed joint past its wall gets a duty back toward its range,
//!   proportional to how far past, full duty at the stop, added to the tissue's (the sum
//!   held to ±100 %).
//! - **A motor wired the wrong way round** ([`DirectionCheck`],
//!   [`ArmDevice::with_direction_check`]): once homed and its home input released, before
//!   any tissue force, each joint is nudged both ways and must turn the way it is driven
//!   ([`ArmFault::Reversed`], [`ArmFault::Unmoved`]; the safe state, zero duty first). A
//!   failed check holds until a reset.
//! - **No runaway.** With [`SpeedLimits`] ([`ArmDevice::with_speed_limits`]), a joint
//!   faster than its limit (2 rev/s by default) or a probe faster than its limit (1 m/s)
//!   for [`SpeedLimits::ticks`] ticks in a row is a fault ([`ArmFault::Overspeed`],
//!   [`ArmFault::ProbeSpeed`]): the controller's safe state, zero duty first. Counted
//!   once the arm is homed (before, its counts mean nothing and its duty is zero), from
//!   the tick after (its counts jump to the home pose).

use crate::arm::runaway::Runaway;
pub use crate::arm::runaway::SpeedLimits;
pub use crate::arm::thermal::Thermal;
pub use crate::arm::trims::Trims;
pub use crate::arm::walls::Walls;
pub use crate::direction::DirectionCheck;

use crate::arm::encoder::Extended;
use crate::arm::joint::WriteFailed;
pub use crate::arm::joint::{Joint, JointParts, PartFailed};
use crate::arm::thermal::Heat;
use crate::device::HapticDevice;
use crate::direction::{Nudge, NudgeFault, Nudges};
use embedded_hal::digital::{InputPin, OutputPin};
use mccs::arm::OUTSIDE;
use mccs::{Arm, ArmPose, Force, Length, PassivityLimits, PassivityObserver};

/// Which part of the arm failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArmFault {
    /// Joint `0..3`'s counter.
    Encoder(u8),
    /// Its PWM channel.
    Pwm(u8),
    /// Its direction pin.
    Direction(u8),
    /// The driver-enable pin.
    Enable,
    /// The home input.
    Home,
    /// Joint `0..3` turned faster than its limit for the ticks [`SpeedLimits`] allows.
    Overspeed(u8),
    /// The probe moved faster than its limit for the ticks [`SpeedLimits`] allows.
    ProbeSpeed,
    /// The rendered force put energy into the hand beyond what the passivity observer
    /// allows ([`ArmDevice::with_passivity`]): an unstable tissue, a reversed sign.
    EnergyOut,
    /// Joint `0..3` turned against its nudge ([`DirectionCheck`]): its motor or encoder
    /// wired the wrong way round.
    Reversed(u8),
    /// Joint `0..3` did not move when nudged ([`DirectionCheck`]): held, jammed, or its
    /// motor or amplifier not connected.
    Unmoved(u8),
}

/// A 3-DOF arm.
#[derive(Debug)]
pub struct ArmDevice<A, B, C, EN, HOME> {
    arm: Arm,
    joints: (A, B, C),
    enable: EN,
    home: HOME,
    counts: [Extended; 3],
    /// The directions last written (None: unknown).
    forward: [Option<bool>; 3],
    homed: bool,
    pose: Option<ArmPose>,
    duty: [i32; 3],
    /// The speed limits and the runs of ticks over them.
    runaway: Runaway,
    /// Reads in a row the home input must be high, still, to home (at least 1).
    home_ticks: u32,
    /// The virtual walls (none by default).
    walls: Option<Walls>,
    /// The I²t model (none by default) and each joint's heat.
    thermal: Option<Thermal>,
    heat: [Heat; 3],
    /// The amplifiers' trims (none by default).
    trims: Trims,
    /// The passivity observer and its limits (none by default), and whether it watches
    /// (see [`ArmDevice::with_passivity`]).
    passivity: Option<(PassivityObserver, PassivityLimits)>,
    watching: bool,
    /// The probe came into the tissue's frame below its surface's rest height (from
    /// beside or beneath it, or homed there): no contact until it rises to that height
    /// inside the frame ([`ArmDevice::below_entry`]).
    below_entry: bool,
    /// Homed at the last read: that tick's write is zero duty (its force was computed
    /// with the gain of before; the link's ramp starts from the next).
    fresh_home: bool,
    /// Since the home input rose: the reads it has been high, and the counts then.
    home_since: Option<(u32, [i32; 3])>,
    /// The direction check (none by default) and where it is: `None` until the home
    /// input is released after homing. The check is over once `direction_checked`.
    direction: Option<DirectionCheck>,
    nudges: Option<Nudges>,
    direction_checked: bool,
    /// The check's duties for the next write (None: the tissue's force).
    nudge_duty: Option<[i32; 3]>,
}

/// The most a joint may move, counts, while the home input is being debounced.
pub const HOME_STILL_COUNTS: i32 = 2;

impl<A: Joint, B: Joint, C: Joint, EN: OutputPin, HOME: InputPin> ArmDevice<A, B, C, EN, HOME> {
    /// The device, not homed (zero duty until it is), the driver not enabled.
    pub fn new(arm: Arm, joints: (A, B, C), enable: EN, home: HOME) -> Self {
        Self {
            arm,
            joints,
            enable,
            home,
            counts: [Extended::default(); 3],
            forward: [None; 3],
            homed: false,
            pose: None,
            duty: [0; 3],
            runaway: Runaway::new(SpeedLimits::NONE),
            home_ticks: 1,
            home_since: None,
            fresh_home: false,
            walls: None,
            thermal: None,
            heat: [Heat::default(); 3],
            trims: Trims::default(),
            passivity: None,
            watching: false,
            below_entry: true,
            direction: None,
            nudges: None,
            direction_checked: true,
            nudge_duty: None,
        }
    }

    /// The device checking, once homed and its home input released, that each joint
    /// turns the way it is driven, before any tissue force ([`DirectionCheck`]): until
    /// it has, the probe reads out of contact and the duties are the check's (with the
    /// arm's gravity compensation).
    pub fn with_direction_check(mut self, check: DirectionCheck) -> Self {
        self.direction = Some(check);
        self.direction_checked = false;
        self
    }

    /// Whether every joint has turned the way it was driven (true without a check).
    pub fn direction_checked(&self) -> bool {
        self.direction_checked
    }

    /// The joint the direction check drives now, if any.
    pub fn direction_nudging(&self) -> Option<u8> {
        match (self.direction, self.nudges, self.direction_checked) {
            (Some(check), Some(nudges), false) => nudges.driving(&check),
            _ => None,
        }
    }

    /// The direction check's part of a read, once homed: the duties it asks for next,
    /// its fault, or the tissue's turn once it has passed.
    fn check_direction(&mut self, counts: [i32; 3]) -> Result<(), ArmFault> {
        let Some(check) = self.direction.filter(|_| !self.direction_checked) else {
            self.nudge_duty = None;
            return Ok(());
        };
        if self.nudges.is_none() {
            // The check starts once the home input is released (the arm let go of).
            if self.home.is_high().map_err(|_| ArmFault::Home)? {
                self.nudge_duty = Some([0; 3]);
                return Ok(());
            }
        }
        let nudges = self.nudges.get_or_insert_with(Nudges::default);
        match nudges.step(&check, counts) {
            Nudge::Drive(duty) => self.nudge_duty = Some(duty),
            Nudge::Passed => {
                self.direction_checked = true;
                self.nudge_duty = None;
            }
            Nudge::Failed(fault) => {
                self.nudge_duty = Some([0; 3]);
                let _ = self.zero();
                return Err(match fault {
                    NudgeFault::Reversed(k) => ArmFault::Reversed(k),
                    NudgeFault::Unmoved(k) => ArmFault::Unmoved(k),
                });
            }
        }
        Ok(())
    }

    /// The device with a passivity observer on the force it renders: energy put into
    /// the hand beyond `limits` is [`ArmFault::EnergyOut`] (zero duty first). It
    /// watches while the probe is within the tissue frame's range, from the first tick
    /// there with no force; beyond the range it forgets.
    pub fn with_passivity(mut self, limits: PassivityLimits) -> Self {
        self.passivity = Some((PassivityObserver::default(), limits));
        self
    }

    /// The energy the hand has put in over the observer's window, mJ (None: no
    /// observer).
    pub fn passivity_mj(&self) -> Option<f64> {
        self.passivity.map(|(o, _)| o.energy_mj())
    }

    /// The device with its amplifiers' trims: each duty written through them once the
    /// arm is homed (before, zero duty).
    pub fn with_trims(mut self, trims: Trims) -> Self {
        self.trims = trims;
        self
    }

    /// The device with an I²t model of its motors.
    pub fn with_thermal(mut self, thermal: Thermal) -> Self {
        self.thermal = Some(thermal);
        self
    }

    /// Each joint's heat, the current's square over the maximum's (0 … 1), and whether
    /// it is folded back.
    pub fn heat(&self) -> [(f32, bool); 3] {
        self.heat
            .map(|h| (h.q32 as f32 / 4_294_967_296.0, h.folded))
    }

    /// The device with virtual walls at its joints' limits.
    pub fn with_walls(mut self, walls: Walls) -> Self {
        self.walls = Some(walls);
        self
    }

    /// The device homing only once its home input has read high for `ticks` reads in a
    /// row (at least 1) with every joint within [`HOME_STILL_COUNTS`] of where it was
    /// when the input rose.
    pub fn with_home_debounce(mut self, ticks: u32) -> Self {
        self.home_ticks = ticks.max(1);
        self
    }

    /// Whether the home input, read now with the joints at `counts`, completes its
    /// debounce.
    fn home_settled(&mut self, high: bool, counts: [i32; 3]) -> bool {
        self.home_since = match (high, self.home_since) {
            (false, _) => None,
            (true, Some((n, at)))
                if (0..3).all(|k| {
                    counts[k].wrapping_sub(at[k]).unsigned_abs() <= HOME_STILL_COUNTS as u32
                }) =>
            {
                Some((n.saturating_add(1), at))
            }
            // Risen now, or moved: the wait starts again here.
            (true, _) => Some((1, counts)),
        };
        matches!(self.home_since, Some((n, _)) if n >= self.home_ticks)
    }

    /// The device with speed limits (a runaway is a fault).
    pub fn with_speed_limits(mut self, limits: SpeedLimits) -> Self {
        self.runaway = Runaway::new(limits);
        self
    }

    /// Enables the driver (duties still zero).
    pub fn enable(&mut self) -> Result<(), ArmFault> {
        self.enable.set_high().map_err(|_| ArmFault::Enable)
    }

    /// Whether the probe is held out of contact because it came into the tissue's frame
    /// below the surface's rest height (`z < 0`: from beside or beneath the frame, or
    /// homed there). A contact starts only by coming down onto the surface: a probe that
    /// appeared beneath it would otherwise be met at once by the whole depth's force (a
    /// pop-through, up to the force limit, along whatever way the probe moves). Cleared
    /// once the probe is at or above `z = 0` inside the frame. The height is the tissue's
    /// at rest in the arm's tissue frame, before the link's pose (docs/safety.md).
    pub fn below_entry(&self) -> bool {
        self.below_entry
    }

    /// Whether the arm has been homed.
    pub fn homed(&self) -> bool {
        self.homed
    }

    /// The last pose's flags (`mccs::arm::LIMIT_*`, `OUTSIDE`); 0 before the first read.
    pub fn flags(&self) -> u8 {
        self.pose.map_or(0, |p| p.flags)
    }

    /// The duties last written, Q16 (±65,536: ±100 %).
    pub fn duties(&self) -> [i32; 3] {
        self.duty
    }

    /// The joints' counts.
    pub fn counts(&self) -> [i32; 3] {
        self.counts.map(|c| c.count())
    }

    /// Zero duty on every joint, each attempted; the first failure.
    fn zero(&mut self) -> Result<(), ArmFault> {
        let a = self.joints.0.duty(0).map_err(|_| ArmFault::Pwm(0));
        let b = self.joints.1.duty(0).map_err(|_| ArmFault::Pwm(1));
        let c = self.joints.2.duty(0).map_err(|_| ArmFault::Pwm(2));
        self.duty = [0; 3];
        a.and(b).and(c)
    }
}

/// Writes joint `k`'s duty (Q16, signed), its failure as the arm's fault.
fn write_joint<J: Joint>(
    j: &mut J,
    forward_was: &mut Option<bool>,
    k: u8,
    duty_q16: i32,
) -> Result<(), ArmFault> {
    j.write(forward_was, duty_q16).map_err(|e| match e {
        WriteFailed::Pwm => ArmFault::Pwm(k),
        WriteFailed::Direction => ArmFault::Direction(k),
    })
}

impl<A: Joint, B: Joint, C: Joint, EN: OutputPin, HOME: InputPin> HapticDevice
    for ArmDevice<A, B, C, EN, HOME>
{
    type Error = ArmFault;

    fn read_position(&mut self) -> Result<[Length; 3], ArmFault> {
        let raw = [
            self.joints.0.read().map_err(|_| ArmFault::Encoder(0))?,
            self.joints.1.read().map_err(|_| ArmFault::Encoder(1))?,
            self.joints.2.read().map_err(|_| ArmFault::Encoder(2))?,
        ];
        let mut counts = [0i32; 3];
        let mut deltas = [0i32; 3];
        for k in 0..3 {
            let was = self.counts[k].count();
            counts[k] = self.counts[k].update(raw[k]);
            deltas[k] = counts[k].wrapping_sub(was);
        }
        // (Only the tick that homes writes zero for it.)
        self.fresh_home = false;
        let settled = !self.homed && {
            let high = self.home.is_high().map_err(|_| ArmFault::Home)?;
            self.home_settled(high, counts)
        };
        if settled {
            let home = self.arm.home_counts();
            for k in 0..3 {
                self.counts[k].rebase(home[k]);
            }
            counts = home;
            self.homed = true;
            self.fresh_home = true;
            // The counts jumped to the home pose: no speed this tick.
            deltas = [0; 3];
            self.runaway.forget_probe();
        }
        // The pose written where it is kept (on the M4F the assembly stores it there; a
        // returned pose took a copy of its 14 words after).
        let pose = self.pose.get_or_insert_with(ArmPose::default);
        self.arm.pose_into(counts, pose);
        let (probe, flags) = (pose.probe, pose.flags);
        if self.homed {
            // (Before homing the counts mean nothing and every duty is zero.)
            self.runaway.check(deltas, probe)?;
            if !settled {
                self.check_direction(counts)?;
            }
        }
        let below = probe[2] < Length::ZERO;
        if flags & OUTSIDE != 0 || settled {
            // Beyond the tissue's frame (or just homed): no contact, and none on coming
            // into it below the surface.
            self.below_entry |= below;
        } else if !below {
            self.below_entry = false;
        }
        if flags & OUTSIDE != 0 || self.below_entry || !self.direction_checked {
            // Far above the tissue: no contact (nor before the direction check passes).
            return Ok([Length::ZERO, Length::ZERO, Length::MAX]);
        }
        Ok(probe)
    }

    fn write_force(&mut self, force: [Force; 3]) -> Result<(), ArmFault> {
        let fresh = core::mem::take(&mut self.fresh_home);
        if let (Some((observer, limits)), Some(pose), true) =
            (self.passivity.as_mut(), self.pose, self.homed && !fresh)
        {
            if pose.flags & OUTSIDE != 0 {
                self.watching = false;
            } else if !self.watching && force == [Force::ZERO; 3] {
                observer.reset();
                self.watching = true;
            }
            if self.watching && observer.tick(pose.probe, force, *limits) {
                let _ = self.zero();
                return Err(ArmFault::EnergyOut);
            }
        }
        let mut duty = match (self.homed && !fresh, self.pose, self.nudge_duty) {
            // The direction check: its nudge on the arm's own duties, no tissue force.
            (true, Some(pose), Some(nudge)) => {
                let own = self.arm.drive(&pose, [Force::ZERO; 3]).duty_q16;
                core::array::from_fn(|k| own[k].saturating_add(nudge[k]))
            }
            (true, Some(pose), None) => self.arm.drive(&pose, force).duty_q16,
            _ => [0; 3],
        };
        if let (Some(walls), true) = (self.walls, self.homed && !fresh) {
            let (home, c) = (self.arm.home_counts(), self.counts);
            let from_home = [
                c[0].count().wrapping_sub(home[0]),
                c[1].count().wrapping_sub(home[1]),
                c[2].count().wrapping_sub(home[2]),
            ];
            let wall = walls.duty(from_home);
            for k in 0..3 {
                duty[k] = duty[k].saturating_add(wall[k]).clamp(-65_536, 65_536);
            }
        }
        // The motors' heat, every tick (zero duty cools them).
        if let Some(model) = self.thermal {
            for k in 0..3 {
                let (a, l, t) = (model.alpha_q32[k], model.limit_q16[k], model.trip_q32[k]);
                duty[k] = self.heat[k].tick(duty[k], a, l, t);
            }
        }
        if self.homed && !fresh {
            // The current each duty stands for, as the amplifiers give it.
            duty = self.trims.apply(duty);
        }
        let written = write_joint(&mut self.joints.0, &mut self.forward[0], 0, duty[0])
            .and_then(|()| write_joint(&mut self.joints.1, &mut self.forward[1], 1, duty[1]))
            .and_then(|()| write_joint(&mut self.joints.2, &mut self.forward[2], 2, duty[2]));
        if let Err(e) = written {
            let _ = self.zero();
            return Err(e);
        }
        self.duty = duty;
        Ok(())
    }

    fn safe_state(&mut self) -> Result<(), ArmFault> {
        let duty = self.zero();
        let enable = self.enable.set_low().map_err(|_| ArmFault::Enable);
        duty.and(enable)
    }

    fn status(&self) -> crate::device::DeviceStatus {
        crate::device::DeviceStatus {
            homed: self.homed,
            at_limit: self.flags() & mccs::arm::LIMITS != 0,
            thermal: self.heat.iter().any(|h| h.folded),
            duties: self.duty,
        }
    }
}

/// The WoodenHaptics arm of `devices/woodenhaptics.toml`, for the firmware's bench and
/// demo (a host test holds the two equal).
pub const WOODENHAPTICS: mccs::ArmSpec = {
    use mccs::{ArmSpec, GravitySpec, JointSpec};
    const fn joint(ratio: f64, kt: f64, min: f64, max: f64) -> JointSpec {
        JointSpec {
            counts_per_rev: 2000.0,
            ratio,
            sign: 1.0,
            home_count: 0,
            home_angle_deg: 0.0,
            torque_constant_nm_per_a: kt,
            max_current_a: 3.0,
            continuous_current_a: 1.0,
            thermal_time_constant_s: 41.6,
            duty_offset: 0.0,
            dead_band: 0.0,
            min_angle_deg: min,
            max_angle_deg: max,
        }
    }
    ArmSpec {
        base_height_mm: 80.0,
        upper_arm_mm: 205.0,
        forearm_mm: 245.0,
        tissue_origin_mm: [220.0, 0.0, 80.0],
        joints: [
            joint(16.0, 0.321, -60.0, 60.0),
            joint(12.0, 0.0603, -30.0, 90.0),
            joint(12.0, 0.0603, -30.0, 120.0),
        ],
        gravity: Some(GravitySpec {
            upper_arm_mass_kg: 0.170,
            upper_arm_com_mm: 51.0,
            forearm_mass_kg: 0.110,
            forearm_com_mm: 91.0,
            g: 9.81,
        }),
    }
};
