//! The 1-DOF device (the default): an AS5047P on SPI1 and one motor on TIM1 CH1 with its
//! direction and enable pins (`haptic_f405::device`, `haptic_f405::pins`); the probe
//! glued to the patch (it renders `z` only).

use super::{BoardParts, BoardVariant, CtlOf, LinkPins};
use embedded_hal_bus::spi::{ExclusiveDevice, NoDelay};
use haptic_f405::config::{self, spi_clock_hz, BoardConfig, AS5047P_MAX_SPI_HZ, BOARD};
use haptic_f405::device::{self, StartFault};
use haptic_f405::pins::{EncoderCs, MotorDirection, MotorEnable, Pins};
use haptic_f405::tissue::TissueTable;
use mccs_firmware::drivers::as5047p::EncoderErrors;
use mccs_firmware::{Glued, Slot};
use mccs_link::{ContactKind, DeviceKind};
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::rcc::Clocks;
use stm32f4xx_hal::spi::Spi;
use stm32f4xx_hal::{pac, timer::PwmChannel};

type Encoder = ExclusiveDevice<Spi<pac::SPI1>, EncoderCs, NoDelay>;
type Motor = PwmChannel<pac::TIM1, 0>;

/// The 1-DOF board.
pub struct OneDof;

impl BoardVariant for OneDof {
    type Device = device::BoardDevice<Encoder, Motor, MotorDirection, MotorEnable>;
    type Contact = Glued;
    type Store = ();
    const NAME: &'static str = "f405";
    const DESCRIPTION: &'static str = "1-DOF (AS5047P on SPI1, motor on TIM1 CH1)";
    const KIND: DeviceKind = DeviceKind::OneDof;
    const CONTACT: ContactKind = ContactKind::Glued;
    const SIMULATED: bool = false;
    /// QEMU's SPI reads zeros: the safe state on the tick the fault rules say.
    const QEMU_FAULT_TICK: Option<u32> = haptic_f405::telemetry::zeros_fault_tick(&BOARD);

    fn build(
        parts: BoardParts,
        clocks: &Clocks,
        _store: &'static mut Slot<()>,
    ) -> Result<(Self::Device, u16, LinkPins), StartFault> {
        let (a, b, _) = parts.gpio;
        let pins = Pins::take(a, b);
        let link = (pins.link_tx, pins.link_rx);
        let spi_hz = spi_clock_hz(clocks.pclk2().raw(), BOARD.spi_request_hz);
        if spi_hz == 0 || spi_hz > AS5047P_MAX_SPI_HZ {
            return Err(StartFault::Config(config::BoardConfigError::SpiTooFast));
        }
        defmt::info!("AS5047P on SPI1: {=u32} Hz (mode 1)", spi_hz);
        let spi = Spi::new(
            parts.spi1,
            (pins.sck, pins.miso, pins.mosi),
            device::SPI_MODE,
            BOARD.spi_request_hz.Hz(),
            clocks,
        );
        // The chip select's error is `Infallible`.
        let Ok(encoder) = ExclusiveDevice::new_no_delay(spi, pins.cs);
        let (_pwm, (ch1, ..)) = parts.tim1.pwm_hz(BOARD.pwm_hz.Hz(), clocks);
        let mut motor = ch1.with(pins.pwm);
        motor.set_duty(0);
        motor.enable();
        let max_duty = motor.get_max_duty();
        device::device(&BOARD, encoder, motor, pins.direction, pins.enable)
            .map(|d| (d, max_duty, link))
            .map_err(|e| e.fault())
    }

    fn controller_into(
        config: &BoardConfig,
        table: TissueTable,
        device: Self::Device,
        slot: &mut Option<CtlOf<Self>>,
    ) -> Result<(), (StartFault, Self::Device)> {
        device::controller_into(config, table, device, slot).map_err(|(e, d)| (e.fault(), d))
    }

    fn encoder_errors(ctl: &CtlOf<Self>) -> EncoderErrors {
        ctl.device().inner().encoder.errors()
    }
}
