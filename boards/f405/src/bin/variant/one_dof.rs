//! The 1-DOF device (the default): an AS5047P on SPI1 and one motor on TIM1 CH1 with its
//! direction and enable pins (`haptic_f405::device`, `haptic_f405::pins`).

use embedded_hal_bus::spi::{ExclusiveDevice, NoDelay};
use haptic_f405::config::{self, spi_clock_hz, BoardConfig, AS5047P_MAX_SPI_HZ, BOARD};
use haptic_f405::device::{self, BoardController, Linked, StartFault};
use haptic_f405::pins::{EncoderCs, MotorDirection, MotorEnable, Pins};
use haptic_f405::telemetry::BoardTelemetry;
use mccs::ForceTable;
use mccs_firmware::drivers::as5047p::EncoderErrors;
use stm32f4xx_hal::gpio::{gpioa, gpiob, gpioc, PA2, PA3};
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::rcc::Clocks;
use stm32f4xx_hal::spi::Spi;
use stm32f4xx_hal::{pac, timer::PwmChannel};

type Encoder = ExclusiveDevice<Spi<pac::SPI1>, EncoderCs, NoDelay>;
type Motor = PwmChannel<pac::TIM1, 0>;
/// The device as `main` builds it.
pub type Device = device::BoardDevice<Encoder, Motor, MotorDirection, MotorEnable>;
/// The tick's controller.
pub type Ctl = BoardController<Linked<Encoder, Motor, MotorDirection, MotorEnable>>;

/// The board's name in a QEMU run's SUMMARY.
#[cfg(all(feature = "qemu", not(feature = "qemu-link")))]
pub const NAME: &str = "f405";
/// What the device is, for the start-up line.
pub const DEVICE: &str = "1-DOF (AS5047P on SPI1, motor on TIM1 CH1)";
/// The tick on which QEMU's run enters the safe state: its SPI reads zeros.
#[cfg(all(feature = "qemu", not(feature = "qemu-link")))]
pub const QEMU_FAULT_TICK: Option<u32> = haptic_f405::telemetry::zeros_fault_tick(&BOARD);

/// The pins, the outputs at their safe levels.
pub fn take_pins(a: gpioa::Parts, b: gpiob::Parts, _c: gpioc::Parts) -> Pins {
    Pins::take(a, b)
}

/// The device, in its safe state, the PWM's full scale and the host link's pins.
pub fn build_device(
    pins: Pins,
    clocks: &Clocks,
    t: crate::Timers,
) -> Result<(Device, u16, (PA2, PA3)), StartFault> {
    let link = (pins.link_tx, pins.link_rx);
    let spi_hz = spi_clock_hz(clocks.pclk2().raw(), BOARD.spi_request_hz);
    if spi_hz == 0 || spi_hz > AS5047P_MAX_SPI_HZ {
        return Err(StartFault::Config(config::BoardConfigError::SpiTooFast));
    }
    defmt::info!("AS5047P on SPI1: {=u32} Hz (mode 1)", spi_hz);
    let spi = Spi::new(
        t.spi1,
        (pins.sck, pins.miso, pins.mosi),
        device::SPI_MODE,
        BOARD.spi_request_hz.Hz(),
        clocks,
    );
    // The chip select's error is `Infallible`.
    let Ok(encoder) = ExclusiveDevice::new_no_delay(spi, pins.cs);
    let (_pwm, (ch1, ..)) = t.tim1.pwm_hz(BOARD.pwm_hz.Hz(), clocks);
    let mut motor = ch1.with(pins.pwm);
    motor.set_duty(0);
    motor.enable();
    let max_duty = motor.get_max_duty();
    device::device(&BOARD, encoder, motor, pins.direction, pins.enable)
        .map(|d| (d, max_duty, link))
        .map_err(|e| e.fault())
}

/// The controller into `slot` ([`device::controller_into`]).
pub fn controller_into<const S: usize>(
    config: &BoardConfig,
    table: ForceTable<S>,
    device: Device,
    slot: &mut Option<BoardController<Linked<Encoder, Motor, MotorDirection, MotorEnable>, S>>,
) -> Result<(), (StartFault, Device)> {
    device::controller_into(config, table, device, slot).map_err(|(e, d)| (e.fault(), d))
}

/// The encoder's error counters.
pub fn encoder_errors(ctl: &Ctl) -> EncoderErrors {
    ctl.device().inner().encoder.errors()
}

/// Nothing beyond the common telemetry.
pub fn record(_ctl: &Ctl, _t: &mut BoardTelemetry) {}

/// Nothing beyond the common line.
pub fn log_second(_t: &BoardTelemetry) {}
