//! The board's device wiring, from any embedded-hal 1.0 parts (the HAL's on the board,
//! mocks in `tests/wiring.rs`): the AS5047P on an SPI device in [`SPI_MODE`], the PWM motor
//! with its direction and driver-enable pins, put in the safe state as it is built, and
//! the controller that ticks it.

use crate::config::{BoardConfig, BoardConfigError};
use embedded_hal::digital::OutputPin;
use embedded_hal::pwm::SetDutyCycle;
use embedded_hal::spi::{Mode, SpiDevice, MODE_1};
use mccs::{ForceTable64, Solver, SolverError, Topology, TopologyError};
use mccs_firmware::drivers::as5047p::As5047p;
use mccs_firmware::drivers::pwm_motor::PwmMotor;
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
/// The board's controller on a device.
pub type BoardController<D> = Controller<D, NODES, EDGES, 64>;

/// Why the board could not start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StartError<E> {
    /// A constant of the [`BoardConfig`].
    Config(BoardConfigError),
    /// Putting the new device in its safe state failed.
    SafeState(E),
    /// The patch.
    Topology(TopologyError),
    /// The solver.
    Solver(SolverError),
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
pub fn controller_into<SPI, PWM, DIR, EN>(
    config: &BoardConfig,
    table: ForceTable64,
    mut device: BoardDevice<SPI, PWM, DIR, EN>,
    slot: &mut Option<BoardController<BoardDevice<SPI, PWM, DIR, EN>>>,
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
    if let Err(e) = device.motor.enable() {
        let _ = device.safe_state();
        return Err((StartError::SafeState(OneDofError::Motor(e)), device));
    }
    *slot = Some(Controller::new(solver, device, u32::MAX));
    Ok(())
}
