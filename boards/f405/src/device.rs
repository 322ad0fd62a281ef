//! The board's device wiring, from any embedded-hal 1.0 parts (the HAL's on the board,
//! mocks in `tests/wiring.rs`): the AS5047P on an SPI device in [`SPI_MODE`], the PWM motor
//! with its direction and driver-enable pins, put in the safe state as it is built, and
//! the controller that ticks it.

use crate::config::{BoardConfig, BoardConfigError};
use crate::tissue::SEGMENTS;
use embedded_hal::digital::OutputPin;
use embedded_hal::pwm::SetDutyCycle;
use embedded_hal::spi::{Mode, SpiDevice, MODE_1};
use mccs::{ArmError, ForceTable, Solver, SolverError, Topology, TopologyError};
use mccs_firmware::drivers::as5047p::As5047p;
use mccs_firmware::drivers::pwm_motor::{MotorError, PwmMotor};
use mccs_firmware::link::LinkedDevice;
use mccs_firmware::one_dof::{OneDofDevice, OneDofError};
use mccs_firmware::{Controller, HapticDevice};

/// The AS5047P's SPI mode (datasheet: CPOL = 0, CPHA = 1; data sampled on the falling
/// edge). The board's SPI1 is set to it.
pub const SPI_MODE: Mode = MODE_1;

/// The largest patch the board's controller holds: N = 8.
pub const MAX_GRID: usize = 8;
/// Node slots (the ground included) of the N = 8 patch.
pub const NODES: usize = mccs::topology::standard_capacity(MAX_GRID).0;
/// Springs of the N = 8 patch.
pub const EDGES: usize = mccs::topology::standard_capacity(MAX_GRID).1;
/// Grid spacing of the patch, mm.
pub const SPACING_MM: f64 = 2.5;

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
/// The largest step of the tissue's pose per tick, mm (10 mm/s at 1 kHz: a moved organ,
/// breathing), whatever the host asks.
pub const MAX_POSE_STEP_MM: f64 = 0.01;
/// The board's controller on a device, for a force table of `S` segments (by default the
/// board's tissue's, [`crate::tissue::TISSUE`]).
pub type BoardController<D, const S: usize = SEGMENTS> = Controller<D, NODES, EDGES, S>;

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
}

impl<S, P, D, E> StartError<OneDofError<S, P, D, E>> {
    /// The error as the log tells it ([`StartFault`]): its type and values, the device's
    /// error by the part that failed (its HAL error type is the board's).
    pub fn fault(&self) -> StartFault {
        match self {
            Self::Config(e) => StartFault::Config(*e),
            Self::Arm(e) => StartFault::Arm(*e),
            Self::SafeState(e) => StartFault::SafeState(match e {
                OneDofError::Spi(_) => DevicePart::Spi,
                OneDofError::Encoder => DevicePart::Encoder,
                OneDofError::Motor(MotorError::Pwm(_)) => DevicePart::Pwm,
                OneDofError::Motor(MotorError::Direction(_)) => DevicePart::Direction,
                OneDofError::Motor(MotorError::Enable(_)) => DevicePart::Enable,
            }),
            Self::Topology(e) => StartFault::Topology(*e),
            Self::Solver(e) => StartFault::Solver(*e),
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
}

/// A part of the board's device.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DevicePart {
    /// The encoder's SPI bus.
    Spi,
    /// The encoder's frames (too many bad ones in a row).
    Encoder,
    /// The motor's PWM channel.
    Pwm,
    /// The motor's direction pin.
    Direction,
    /// The motor driver's enable pin.
    Enable,
    /// The arm's joint `0..3` (A, B, C): its quadrature counter.
    JointEncoder(u8),
    /// Its PWM channel.
    JointPwm(u8),
    /// Its direction pin.
    JointDirection(u8),
    /// The arm's home input.
    Home,
}

impl DevicePart {
    /// Its name in the log.
    pub const fn name(&self) -> &'static str {
        match self {
            Self::Spi => "the encoder's SPI bus",
            Self::Encoder => "the encoder's frames",
            Self::Pwm => "the motor's PWM channel",
            Self::Direction => "the motor's direction pin",
            Self::Enable => "the motor driver's enable pin",
            Self::JointEncoder(k) => pick(
                *k,
                [
                    "joint A's counter",
                    "joint B's counter",
                    "joint C's counter",
                ],
            ),
            Self::JointPwm(k) => pick(
                *k,
                [
                    "joint A's PWM channel",
                    "joint B's PWM channel",
                    "joint C's PWM channel",
                ],
            ),
            Self::JointDirection(k) => pick(
                *k,
                [
                    "joint A's direction pin",
                    "joint B's direction pin",
                    "joint C's direction pin",
                ],
            ),
            Self::Home => "the arm's home input",
        }
    }
}

/// Joint `k`'s name of three (C past the end).
const fn pick(k: u8, names: [&'static str; 3]) -> &'static str {
    match k {
        0 => names[0],
        1 => names[1],
        _ => names[2],
    }
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
    let mut device = OneDofDevice {
        encoder: As5047p::new(spi, config.encoder()),
        motor,
        max_bad_frames: config.max_bad_frames,
    };
    device.safe_state().map_err(StartError::SafeState)?;
    Ok(device)
}

/// Builds the controller into `slot` on `device` and `table`, then enables the motor
/// driver (duty still zero). On an error the device is left in its safe state and handed
/// back with the error. Out of line: its stack frames are free again before the ticks.
#[inline(never)]
#[allow(clippy::type_complexity)]
pub fn controller_into<SPI, PWM, DIR, EN, const S: usize>(
    config: &BoardConfig,
    table: ForceTable<S>,
    device: BoardDevice<SPI, PWM, DIR, EN>,
    slot: &mut Option<BoardController<Linked<SPI, PWM, DIR, EN>, S>>,
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

/// [`controller_into`] for any device (the arm's too, [`crate::arm`]): the patch and the
/// solver on `config` and `table`, then `enable` (the motor driver on, duty still zero);
/// on an error the device is put in its safe state and handed back with the error.
#[inline(never)]
#[allow(clippy::type_complexity)]
pub fn controller_with<D: HapticDevice, const S: usize>(
    config: &BoardConfig,
    table: ForceTable<S>,
    mut device: D,
    slot: &mut Option<BoardController<LinkedDevice<D>, S>>,
    enable: impl FnOnce(&mut D) -> Result<(), D::Error>,
) -> Result<(), (StartError<D::Error>, D)> {
    let built = Topology::standard_patch(config.grid, SPACING_MM)
        .map_err(StartError::Topology)
        .and_then(|topo| Solver::new(topo, table, &config.solver()).map_err(StartError::Solver));
    let solver = match built {
        Ok(s) => s,
        Err(e) => {
            let _ = device.safe_state();
            return Err((e, device));
        }
    };
    if let Err(e) = enable(&mut device) {
        let _ = device.safe_state();
        return Err((StartError::SafeState(e), device));
    }
    *slot = Some(Controller::new(
        solver,
        LinkedDevice::new(device, MAX_POSE_STEP_MM),
        u32::MAX,
    ));
    Ok(())
}
