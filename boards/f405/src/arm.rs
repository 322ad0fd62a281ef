//! The board's arm variant (`--features arm`): the WoodenHaptics arm of
//! `devices/woodenhaptics.toml` ([`ARM`]) as the tick's device — three quadrature
//! counters, three PWM channels with their direction pins, one driver enable and a home
//! input ([`ArmDevice`]) — from any embedded-hal 1.0 parts (the HAL's on the board, mocks
//! in `tests/arm_wiring.rs`). docs/arm.md, "The arm on the board", has the pins and the
//! bring-up.

use crate::config::BoardConfig;
use crate::device::{
    roaming_controller_with, BoardController, BoardRoaming, DevicePart, StartError, StartFault,
    UnstableCoupling,
};
use embedded_hal::digital::{InputPin, OutputPin};
use mccs::{Arm, ArmSpec, ForceTable, PassivityLimits};
use mccs_firmware::arm::device::{
    ArmDevice, ArmFault, DirectionCheck, Joint, SpeedLimits, Thermal, Trims, Walls,
};
use mccs_firmware::link::LinkedDevice;
use mccs_firmware::HapticDevice;

/// The arm the board drives: the firmware's WoodenHaptics constant, which a host test
/// holds equal to `devices/woodenhaptics.toml`. A port to another arm replaces it.
pub const ARM: ArmSpec = mccs_firmware::arm::device::WOODENHAPTICS;

/// The arm's stable region, `(coupling damping N·s/m, stiffness N/mm)`: the shipped
/// device file's `[stability]` (`mccs arm stability` measured it on the simulated arm;
/// a host test holds the two equal). A port to another arm measures its own.
pub const STABLE_REGION: [(f64, f64); 5] = [
    (0.0, 64.0),
    (0.5, 90.51),
    (1.0, 90.51),
    (2.0, 128.0),
    (5.0, 181.019),
];

/// Whether `config`'s coupling is within half of [`STABLE_REGION`] at its damping, as
/// `mccs check --device arm` allows (start-up: floating point); else the refusal with
/// its figures.
pub fn check_coupling(config: &BoardConfig) -> Result<(), UnstableCoupling> {
    let milli = |x: f64| libm::round((x * 1000.0).clamp(0.0, u32::MAX as f64)) as u32;
    let half = mccs::arm::stable_region::stable_coupling(&STABLE_REGION, config.coupling_damping)
        .map(|k| k / 2.0);
    match half {
        Some(limit) if config.coupling_stiffness <= limit => Ok(()),
        _ => Err(UnstableCoupling {
            stiffness_mn_mm: milli(config.coupling_stiffness),
            damping_mn_s_m: milli(config.coupling_damping),
            limit_mn_mm: half.map(milli),
        }),
    }
}

/// The board's arm on these parts.
pub type BoardArm<A, B, C, EN, HOME> = ArmDevice<A, B, C, EN, HOME>;
/// The board's arm as the tick drives it, with the host link's pose and force gain.
pub type LinkedArm<A, B, C, EN, HOME> = LinkedDevice<BoardArm<A, B, C, EN, HOME>>;

impl StartError<ArmFault> {
    /// The error as the log tells it ([`StartFault`]), the device's error by the part
    /// that failed.
    pub fn fault(&self) -> StartFault {
        match self {
            Self::Config(e) => StartFault::Config(*e),
            Self::Arm(e) => StartFault::Arm(*e),
            Self::SafeState(e) => StartFault::SafeState(e.into()),
            Self::Topology(e) => StartFault::Topology(*e),
            Self::Solver(e) => StartFault::Solver(*e),
            Self::Contact(e) => StartFault::Contact(*e),
            Self::Coupling(c) => StartFault::Coupling(*c),
            Self::Budget(b) => StartFault::Budget(*b),
        }
    }
}

impl From<&ArmFault> for DevicePart {
    /// The part of the arm that failed, or what it did.
    fn from(e: &ArmFault) -> Self {
        match *e {
            ArmFault::Encoder(k) => DevicePart::JointEncoder(k),
            ArmFault::Pwm(k) => DevicePart::JointPwm(k),
            ArmFault::Direction(k) => DevicePart::JointDirection(k),
            ArmFault::Enable => DevicePart::Enable,
            ArmFault::Home => DevicePart::Home,
            ArmFault::Overspeed(k) => DevicePart::JointSpeed(k),
            ArmFault::ProbeSpeed => DevicePart::ProbeSpeed,
            ArmFault::EnergyOut => DevicePart::EnergyOut,
            ArmFault::Reversed(k) => DevicePart::JointReversed(k),
            ArmFault::Unmoved(k) => DevicePart::JointUnmoved(k),
        }
    }
}

/// A joint turning faster than this, rev/s, is running away (docs/safety.md).
pub const RUNAWAY_JOINT_REV_S: f64 = 2.0;
/// A probe moving faster than this, mm/s, is running away.
pub const RUNAWAY_PROBE_MM_S: f64 = 1000.0;
/// Ticks in a row over either that make the fault.
pub const RUNAWAY_TICKS: u8 = 5;
/// The virtual walls stand this far inside each joint's mechanical stops, degrees.
pub const WALL_MARGIN_DEG: f64 = 3.0;
/// How long the home input must stay high, with the arm still, before the arm homes, ms.
pub const HOME_DEBOUNCE_MS: u32 = 50;
pub use crate::device::{
    NUDGE_SETTLE_MS, NUDGE_TIMEOUT_MS, PASSIVITY_CREDIT_MJ, PASSIVITY_TRIP_MJ,
};
/// The direction check's nudge at each joint, N·m (docs/safety.md).
pub const NUDGE_TORQUE_NM: f64 = 0.2;
/// Motor counts a nudge must move its joint.
pub const NUDGE_COUNTS: u32 = 8;

/// The arm on `spec` and its parts, in its safe state (zero duty on every joint, the
/// driver disabled) before it is returned; not homed (no force until the home input
/// reads high).
#[allow(clippy::type_complexity)]
pub fn arm_device<A: Joint, B: Joint, C: Joint, EN: OutputPin, HOME: InputPin>(
    config: &BoardConfig,
    spec: &ArmSpec,
    joints: (A, B, C),
    enable: EN,
    home: HOME,
) -> Result<BoardArm<A, B, C, EN, HOME>, StartError<ArmFault>> {
    config.check().map_err(StartError::Config)?;
    let arm = Arm::new(spec).map_err(StartError::Arm)?;
    let limits = SpeedLimits::of(
        spec,
        config.tick_hz,
        RUNAWAY_JOINT_REV_S,
        RUNAWAY_PROBE_MM_S,
        RUNAWAY_TICKS,
    );
    let debounce = (HOME_DEBOUNCE_MS as u64 * config.tick_hz as u64).div_ceil(1000) as u32;
    let mut device = ArmDevice::new(arm, joints, enable, home)
        .with_speed_limits(limits)
        .with_home_debounce(debounce)
        .with_walls(Walls::of(spec, WALL_MARGIN_DEG))
        .with_thermal(Thermal::of(spec, config.tick_hz))
        .with_trims(Trims::of(spec))
        .with_passivity(PassivityLimits::new(PASSIVITY_TRIP_MJ, PASSIVITY_CREDIT_MJ))
        .with_direction_check(DirectionCheck::of(
            spec,
            config.tick_hz,
            NUDGE_TORQUE_NM,
            NUDGE_COUNTS,
            NUDGE_TIMEOUT_MS,
            NUDGE_SETTLE_MS,
        ));
    device.safe_state().map_err(StartError::SafeState)?;
    Ok(device)
}

/// [`crate::device::controller_into`] for the arm, through the roaming contact with
/// friction ([`crate::device::roaming`]): the controller into `slot`, then the driver
/// enabled (duties still zero, and zero until the arm is homed). The error hands the
/// device back, in its safe state (large: no heap to box it in, and it runs once).
#[inline(never)]
#[allow(clippy::type_complexity, clippy::result_large_err)]
pub fn arm_controller_into<
    A: Joint,
    B: Joint,
    C: Joint,
    EN: OutputPin,
    HOME: InputPin,
    const S: usize,
>(
    config: &BoardConfig,
    table: ForceTable<S>,
    device: BoardArm<A, B, C, EN, HOME>,
    slot: &mut Option<BoardController<LinkedArm<A, B, C, EN, HOME>, BoardRoaming, S>>,
) -> Result<(), (StartError<ArmFault>, BoardArm<A, B, C, EN, HOME>)> {
    roaming_controller_with(config, table, device, slot, |d| d.enable())
}

/// The board's start-up: [`arm_controller_into`] once the coupling is within half the
/// arm's stable region ([`check_coupling`]; the device handed back, never enabled, if
/// not). The simulated arm's measurement of the region calls [`arm_controller_into`]
/// itself, to run couplings beyond it.
#[allow(clippy::type_complexity, clippy::result_large_err)]
pub fn arm_start_into<
    A: Joint,
    B: Joint,
    C: Joint,
    EN: OutputPin,
    HOME: InputPin,
    const S: usize,
>(
    config: &BoardConfig,
    table: ForceTable<S>,
    device: BoardArm<A, B, C, EN, HOME>,
    slot: &mut Option<BoardController<LinkedArm<A, B, C, EN, HOME>, BoardRoaming, S>>,
) -> Result<(), (StartError<ArmFault>, BoardArm<A, B, C, EN, HOME>)> {
    if let Err(c) = check_coupling(config) {
        return Err((StartError::Coupling(c), device));
    }
    arm_controller_into(config, table, device, slot)
}
