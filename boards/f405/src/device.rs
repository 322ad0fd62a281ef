//! The board's device wiring, from any embedded-hal 1.0 parts (the HAL's on the board,
//! mocks in `tests/wiring.rs`): the AS5047P on an SPI device in [`SPI_MODE`], the PWM motor
//! with its direction and driver-enable pins, put in the safe state as it is built, and
//! the controller that ticks it.

use crate::config::{BoardConfig, BoardConfigError};
use crate::tissue::SEGMENTS;
use embedded_hal::digital::OutputPin;
use embedded_hal::pwm::SetDutyCycle;
use embedded_hal::spi::{Mode, SpiDevice, MODE_1};
use mccs::{
    ArmError, Flat, Force, ForceTable, ProxyConfig, ProxyError, Solver, SolverError, TissuePose,
    Topology, TopologyError, Wide, WindowConfig,
};
use mccs_firmware::drivers::as5047p::As5047p;
use mccs_firmware::drivers::pwm_motor::{MotorError, PwmMotor};
use mccs_firmware::link::LinkedDevice;
use mccs_firmware::one_dof::{DirectionCheck, OneDofDevice, OneDofError, DIRECTION_COUNT_MM};
use mccs_firmware::{Controller, Glued, HapticDevice, Roaming};

use crate::device_part::pick;
pub use crate::device_part::DevicePart;

/// The AS5047P's SPI mode (datasheet: CPOL = 0, CPHA = 1; data sampled on the falling
/// edge). The board's SPI1 is set to it.
pub const SPI_MODE: Mode = MODE_1;

pub use crate::config::MAX_GRID;
/// Node slots (the ground included) of the N = 10 patch.
pub const NODES: usize = mccs::topology::standard_capacity(MAX_GRID).0;
/// Springs of the N = 10 patch.
pub const EDGES: usize = mccs::topology::standard_capacity(MAX_GRID).1;
pub use crate::config::SPACING_MM;

/// The passivity observer (the lever's and the arm's): energy put into the hand beyond
/// the credit by this much, mJ, is a fault (docs/safety.md).
pub const PASSIVITY_TRIP_MJ: f64 = 2.0;
/// The most the hand's earlier input may pay for later output, mJ: above what the
/// tissue stores at the force clamp (3 N over 6 mm: 9 mJ).
pub const PASSIVITY_CREDIT_MJ: f64 = 10.0;

/// The lever's start-up nudge (`OneDofDevice::with_direction_check`), N at the probe:
/// 0.2 N of the motor's 3 N at full duty, a little against the lever's friction.
pub const LEVER_NUDGE_N: f64 = 0.2;
/// How far a nudge must move the lever, mm (7 counts of the AS5047P on the shipped
/// lever), in the check's counts of 2⁻¹⁰ mm.
pub const LEVER_NUDGE_MM: f64 = 0.02;
/// How long a nudge (the lever's, an arm joint's) may take to move it, ms.
pub const NUDGE_TIMEOUT_MS: u32 = 200;
/// Zero duty before each nudge, ms.
pub const NUDGE_SETTLE_MS: u32 = 30;

/// The lever's direction check on `config`.
pub fn lever_check(config: &BoardConfig) -> DirectionCheck<1> {
    let duty = (LEVER_NUDGE_N / config.force_at_full_duty).clamp(0.0, 1.0);
    DirectionCheck::one(
        config.tick_hz,
        libm::round(duty * 65_536.0) as i32,
        libm::round(LEVER_NUDGE_MM / DIRECTION_COUNT_MM) as u32,
        NUDGE_TIMEOUT_MS,
        NUDGE_SETTLE_MS,
    )
}

/// The board's device on these parts.
pub type BoardDevice<SPI, PWM, DIR, EN> = OneDofDevice<SPI, PWM, DIR, EN>;
/// Its error.
pub type BoardDeviceError<SPI, PWM, DIR, EN> = OneDofError<
    <SPI as embedded_hal::spi::ErrorType>::Error,
    <PWM as embedded_hal::pwm::ErrorType>::Error,
    <DIR as embedded_hal::digital::ErrorType>::Error,
    <EN as embedded_hal::digital::ErrorType>::Error,
>;
/// The board's device as the tick drives it: with the host link's pose and force gain
/// ([`LinkedDevice`]; standalone, it is the device as wired).
pub type Linked<SPI, PWM, DIR, EN> = LinkedDevice<BoardDevice<SPI, PWM, DIR, EN>>;
/// The board's controller on a device through a contact (glued: the 1-DOF board; roaming
/// with friction: the arm), for a force table of `S` segments (by default the board's
/// tissue's, [`crate::tissue::TISSUE`]).
pub type BoardController<D, C = Glued, const S: usize = SEGMENTS> =
    Controller<D, NODES, EDGES, S, Wide, C>;
/// The arm's contact: a proxy with friction on the board's flat tissue, the patch its
/// window.
pub type BoardRoaming = Roaming<EDGES, Flat>;

/// `device` with the host link's pose (at the board's slew limits) and gain.
pub fn linked<D>(config: &BoardConfig, device: D) -> LinkedDevice<D> {
    LinkedDevice::new(
        device,
        TissuePose::new(
            config.pose_speed_mm_s as f64,
            config.pose_turn_deg_s as f64,
            config.tick_hz as f64,
        ),
        Force::saturating_from_num(config.max_force),
    )
}

/// Why the board could not start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StartError<E> {
    /// A constant of the [`BoardConfig`].
    Config(BoardConfigError),
    /// The arm's device constant ([`crate::arm`]).
    Arm(ArmError),
    /// Putting the new device in its safe state failed.
    SafeState(E),
    /// The patch.
    Topology(TopologyError),
    /// The solver.
    Solver(SolverError),
    /// The roaming contact: its proxy or window.
    Contact(ProxyError),
    /// The coupling over half the arm's stable region at its damping.
    Coupling(UnstableCoupling),
    /// The tissue's tick would pass the board's budget ([`BoardConfig::budget`]).
    Budget(OverBudget),
}

/// A tissue whose tick would pass the board's instruction budget: its substeps, what
/// they would cost (`tick_base_cost + substeps × substep_cost`) and the budget.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OverBudget {
    /// Substeps per tick the stability bound asks for.
    pub substeps: u32,
    /// Instructions the tick would take.
    pub instructions: u32,
    /// Instructions it may take.
    pub budget: u32,
}

impl<S, P, D, E> StartError<OneDofError<S, P, D, E>> {
    /// The error as the log tells it ([`StartFault`]): its type and values, the device's
    /// error by the part that failed (its HAL error type is the board's).
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

impl<S, P, D, E> From<&OneDofError<S, P, D, E>> for DevicePart {
    /// The part of the lever that failed (its HAL error type is the board's).
    fn from(e: &OneDofError<S, P, D, E>) -> Self {
        match e {
            OneDofError::Spi(_) => DevicePart::Spi,
            OneDofError::Encoder => DevicePart::Encoder,
            OneDofError::Travel => DevicePart::Travel,
            OneDofError::Motor(MotorError::Pwm(_)) => DevicePart::Pwm,
            OneDofError::Motor(MotorError::Direction(_)) => DevicePart::Direction,
            OneDofError::Motor(MotorError::Enable(_)) => DevicePart::Enable,
            OneDofError::EnergyOut => DevicePart::EnergyOut,
            OneDofError::Reversed => DevicePart::LeverReversed,
            OneDofError::Unmoved => DevicePart::LeverUnmoved,
        }
    }
}

/// A coupling the arm's stable region does not allow (`arm::check_coupling`), in
/// thousandths: mN/mm and mN·s/m.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnstableCoupling {
    /// The coupling's stiffness.
    pub stiffness_mn_mm: u32,
    /// Its damping.
    pub damping_mn_s_m: u32,
    /// Half the region's stiffness at that damping (`None`: the damping is outside the
    /// measured region).
    pub limit_mn_mm: Option<u32>,
}

impl core::fmt::Display for UnstableCoupling {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let n = |m: u32| m as f64 / 1000.0;
        match self.limit_mn_mm {
            Some(limit) => write!(
                f,
                "coupling: {:.3} N/mm at {:.3} N·s/m is over half the arm's stable region there, {:.3} N/mm (docs/safety.md)",
                n(self.stiffness_mn_mm),
                n(self.damping_mn_s_m),
                n(limit)
            ),
            None => write!(
                f,
                "coupling: its damping, {:.3} N·s/m, is outside the arm's measured stable region (docs/safety.md)",
                n(self.damping_mn_s_m)
            ),
        }
    }
}

/// Why the board could not start, as its log says it: a [`StartError`] without the HAL's
/// error types, which vary by board (`Copy`, for the tick to hand to `main`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StartFault {
    /// A constant of the [`BoardConfig`].
    Config(BoardConfigError),
    /// The arm's device constant.
    Arm(ArmError),
    /// Putting the device in its safe state failed, at this part.
    SafeState(DevicePart),
    /// The patch.
    Topology(TopologyError),
    /// The solver (the substeps the stability bound needs, …).
    Solver(SolverError),
    /// The roaming contact: its proxy or window.
    Contact(ProxyError),
    /// The coupling over half the arm's stable region at its damping.
    Coupling(UnstableCoupling),
    /// The tissue's tick would pass the board's budget.
    Budget(OverBudget),
}

impl core::fmt::Display for StartFault {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Config(e) => write!(f, "config: {e}"),
            Self::Arm(e) => match e.joint() {
                Some(k) => write!(f, "{} (joint {})", e.message(), pick(k, ["A", "B", "C"])),
                None => f.write_str(e.message()),
            },
            Self::SafeState(p) => write!(f, "safe state: {} failed", p.name()),
            Self::Topology(e) => write!(f, "{e}"),
            Self::Solver(e) => write!(f, "solver: {e}"),
            Self::Contact(e) => write!(f, "{e}"),
            Self::Coupling(c) => write!(f, "{c}"),
            Self::Budget(b) => write!(
                f,
                "budget: the tissue needs {} substeps per tick, {} instructions, over the board's {} (tick_base_cost + substeps × substep_cost; docs/arm.md)",
                b.substeps, b.instructions, b.budget
            ),
        }
    }
}

#[cfg(target_os = "none")]
impl defmt::Format for StartFault {
    fn format(&self, f: defmt::Formatter) {
        match self {
            Self::Config(e) => defmt::write!(f, "config: {=str}", e.message()),
            Self::Arm(e) => match e.joint() {
                Some(k) => defmt::write!(
                    f,
                    "{=str} (joint {=str})",
                    e.message(),
                    pick(k, ["A", "B", "C"])
                ),
                None => defmt::write!(f, "{=str}", e.message()),
            },
            Self::SafeState(p) => defmt::write!(f, "safe state: {=str} failed", p.name()),
            Self::Topology(e) => defmt::write!(f, "{}", e),
            Self::Solver(e) => defmt::write!(f, "solver: {}", e),
            Self::Contact(e) => defmt::write!(f, "{=str}", e.message()),
            Self::Coupling(c) => match c.limit_mn_mm {
                Some(limit) => defmt::write!(
                    f,
                    "coupling: {=u32} mN/mm at {=u32} mN·s/m is over half the arm's stable region there, {=u32} mN/mm (docs/safety.md)",
                    c.stiffness_mn_mm,
                    c.damping_mn_s_m,
                    limit
                ),
                None => defmt::write!(
                    f,
                    "coupling: its damping, {=u32} mN·s/m, is outside the arm's measured stable region (docs/safety.md)",
                    c.damping_mn_s_m
                ),
            },
            Self::Budget(b) => defmt::write!(
                f,
                "budget: the tissue needs {=u32} substeps per tick, {=u32} instructions, over the board's {=u32} (tick_base_cost + substeps × substep_cost; docs/arm.md)",
                b.substeps,
                b.instructions,
                b.budget
            ),
        }
    }
}

/// The device, in its safe state (zero duty, driver disabled) before it is returned.
#[allow(clippy::type_complexity)]
pub fn device<SPI, PWM, DIR, EN>(
    config: &BoardConfig,
    spi: SPI,
    pwm: PWM,
    dir: DIR,
    enable: EN,
) -> Result<BoardDevice<SPI, PWM, DIR, EN>, StartError<BoardDeviceError<SPI, PWM, DIR, EN>>>
where
    SPI: SpiDevice<u8>,
    PWM: SetDutyCycle,
    DIR: OutputPin,
    EN: OutputPin,
{
    config.check().map_err(StartError::Config)?;
    let motor = PwmMotor::with_enable(pwm, dir, enable, config.motor())
        .map_err(|e| StartError::Config(BoardConfigError::Motor(e)))?;
    let mut device = OneDofDevice::new(
        As5047p::new(spi, config.encoder()),
        motor,
        config.max_bad_frames,
    )
    .with_passivity(mccs::PassivityLimits::new(
        PASSIVITY_TRIP_MJ,
        PASSIVITY_CREDIT_MJ,
    ))
    .with_direction_check(lever_check(config));
    device.safe_state().map_err(StartError::SafeState)?;
    Ok(device)
}

/// Builds the controller into `slot` on `device` and `table`, then enables the motor
/// driver (duty still zero). On an error the device is left in its safe state and handed
/// back with the error. Out of line: its stack frames are free again before the ticks.
#[inline(never)]
#[allow(clippy::type_complexity)]
// The device comes back whole with the error (no heap to box it in), so that the caller
// can hold it in its safe state.
#[allow(clippy::result_large_err)]
pub fn controller_into<SPI, PWM, DIR, EN, const S: usize>(
    config: &BoardConfig,
    table: ForceTable<S>,
    device: BoardDevice<SPI, PWM, DIR, EN>,
    slot: &mut Option<BoardController<Linked<SPI, PWM, DIR, EN>, Glued, S>>,
) -> Result<
    (),
    (
        StartError<BoardDeviceError<SPI, PWM, DIR, EN>>,
        BoardDevice<SPI, PWM, DIR, EN>,
    ),
>
where
    SPI: SpiDevice<u8>,
    PWM: SetDutyCycle,
    DIR: OutputPin,
    EN: OutputPin,
{
    controller_with(config, table, device, slot, |d| {
        d.motor.enable().map_err(OneDofError::Motor)
    })
}

/// The board's solver on `config` and `table`, its substeps within the tick's budget.
fn solver<const S: usize>(
    config: &BoardConfig,
    table: ForceTable<S>,
) -> Result<Solver<NODES, EDGES, S, Wide>, StartError<core::convert::Infallible>> {
    let topo = Topology::standard_patch(config.grid, SPACING_MM).map_err(StartError::Topology)?;
    let solver = Solver::new(topo, table, &config.solver()).map_err(StartError::Solver)?;
    // Within the tick's budget, as a tissue over the link is held to it (`Budget`).
    let (budget, substeps) = (config.budget(), solver.substeps());
    if let Some(instructions) = budget.over(substeps) {
        return Err(StartError::Budget(OverBudget {
            substeps,
            instructions,
            budget: budget.tick,
        }));
    }
    Ok(solver)
}

/// A start-up error of no device's (the patch, the solver, the contact) as one of `E`.
fn widen<E>(e: StartError<core::convert::Infallible>) -> StartError<E> {
    match e {
        StartError::Config(c) => StartError::Config(c),
        StartError::Arm(a) => StartError::Arm(a),
        StartError::Topology(t) => StartError::Topology(t),
        StartError::Solver(s) => StartError::Solver(s),
        StartError::Contact(c) => StartError::Contact(c),
        StartError::Coupling(c) => StartError::Coupling(c),
        StartError::Budget(b) => StartError::Budget(b),
        StartError::SafeState(never) => match never {},
    }
}

/// The board's roaming contact on `solver`: a point probe with the board's friction on
/// its flat tissue of `tissue_nodes`, the window centred on the tissue.
pub fn roaming<const S: usize>(
    config: &BoardConfig,
    solver: &mut Solver<NODES, EDGES, S, Wide>,
) -> Result<BoardRoaming, ProxyError> {
    let proxy = solver.proxy(&ProxyConfig {
        grid: config.grid,
        spacing: SPACING_MM,
        mu_s: config.mu_s,
        mu_k: config.mu_k,
        probe_radius: 0.0,
    })?;
    let window = solver.window(
        &WindowConfig {
            tissue_w: config.tissue_nodes[0],
            tissue_h: config.tissue_nodes[1],
            hysteresis: 0.1,
        },
        &Flat,
        &proxy,
        0.0,
        0.0,
    )?;
    Ok(Roaming::new(proxy, window))
}

/// [`controller_into`] for any device (the arm's too, [`crate::arm`]), glued: the patch
/// and the solver on `config` and `table`, then `enable` (the motor driver on, duty still
/// zero); on an error the device is put in its safe state and handed back with the
/// error.
#[inline(never)]
#[allow(clippy::type_complexity)]
pub fn controller_with<D: HapticDevice, const S: usize>(
    config: &BoardConfig,
    table: ForceTable<S>,
    mut device: D,
    slot: &mut Option<BoardController<LinkedDevice<D>, Glued, S>>,
    enable: impl FnOnce(&mut D) -> Result<(), D::Error>,
) -> Result<(), (StartError<D::Error>, D)> {
    let solver = match solver(config, table) {
        Ok(s) => s,
        Err(e) => {
            let _ = device.safe_state();
            return Err((widen(e), device));
        }
    };
    if let Err(e) = enable(&mut device) {
        let _ = device.safe_state();
        return Err((StartError::SafeState(e), device));
    }
    let ctl = slot.insert(Controller::new(solver, linked(config, device), u32::MAX));
    ctl.set_overrun_limit(config.max_overruns_in_row);
    Ok(())
}

/// [`controller_with`] through the board's roaming contact with friction
/// ([`roaming`]): the arm's.
#[inline(never)]
#[allow(clippy::type_complexity)]
pub fn roaming_controller_with<D: HapticDevice, const S: usize>(
    config: &BoardConfig,
    table: ForceTable<S>,
    mut device: D,
    slot: &mut Option<BoardController<LinkedDevice<D>, BoardRoaming, S>>,
    enable: impl FnOnce(&mut D) -> Result<(), D::Error>,
) -> Result<(), (StartError<D::Error>, D)> {
    let built = solver(config, table).and_then(|mut s| {
        // The arm's probe velocity for the coupling's damping: the tracker's, from
        // counts of 64 µm (docs/safety.md, "The probe's velocity").
        let gains = mccs::TrackerGains::default_at(config.tick_hz)
            .map_err(|_| StartError::Config(BoardConfigError::Tick))?;
        let contact = roaming(config, &mut s).map_err(StartError::Contact)?;
        Ok((s, contact.with_velocity_tracker(gains)))
    });
    let (solver, contact) = match built {
        Ok(b) => b,
        Err(e) => {
            let _ = device.safe_state();
            return Err((widen(e), device));
        }
    };
    if let Err(e) = enable(&mut device) {
        let _ = device.safe_state();
        return Err((StartError::SafeState(e), device));
    }
    let ctl = slot.insert(Controller::with_contact(
        solver,
        contact,
        linked(config, device),
        u32::MAX,
    ));
    ctl.set_overrun_limit(config.max_overruns_in_row);
    Ok(())
}
