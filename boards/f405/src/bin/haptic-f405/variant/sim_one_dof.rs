//! The 1-DOF variant on a simulated lever (`--features sim`): the same 1-DOF device and
//! glued contact as `one_dof.rs`, its encoder's bus and motor pins those of a [`Lever`]
//! (`mccs_firmware::lever_sim`) pressing the tissue over and over. For QEMU, where SPI1
//! has no encoder behind it: the 1-DOF board's live path end to end.

use super::{BoardParts, BoardVariant, CtlOf, LinkPins};
use haptic_f405::config::{BoardConfig, BoardConfigError, BOARD};
use haptic_f405::device::{self, StartFault};
use haptic_f405::tissue::TissueTable;
use mccs_firmware::drivers::as5047p::EncoderErrors;
use mccs_firmware::lever_sim::{Lever, LeverPin, LeverPwm, LeverSpi, LEVER_MAX_DUTY};
use mccs_firmware::{Glued, Slot};
use mccs_link::{ContactKind, DeviceKind};
use stm32f4xx_hal::rcc::Clocks;

/// The 1-DOF board on a simulated lever.
pub struct SimOneDof;

impl BoardVariant for SimOneDof {
    type Device = device::BoardDevice<LeverSpi, LeverPwm, LeverPin<false>, LeverPin<true>>;
    type Contact = Glued;
    type Store = Lever;
    const NAME: &'static str = "f405-sim";
    const DESCRIPTION: &'static str = "1-DOF on a simulated lever pressing the tissue";
    const KIND: DeviceKind = DeviceKind::OneDof;
    const CONTACT: ContactKind = ContactKind::Glued;
    const SIMULATED: bool = true;
    const QEMU_FAULT_TICK: Option<u32> = None;

    fn build(
        parts: BoardParts,
        _clocks: &Clocks,
        store: &'static mut Slot<Lever>,
    ) -> Result<(Self::Device, u16, LinkPins), StartFault> {
        let (a, _, _) = parts.gpio;
        let link = (a.pa2, a.pa3);
        let lever = match Lever::new(BOARD.tick_hz, BOARD.encoder_zero, BOARD.mm_per_count) {
            Ok(l) => store.insert(l),
            Err(_) => return Err(StartFault::Config(BoardConfigError::Tick)),
        };
        let lever: &'static Lever = lever;
        let (spi, pwm, direction, enable) = lever.parts();
        device::device(&BOARD, spi, pwm, direction, enable)
            .map(|d| (d, LEVER_MAX_DUTY, link))
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
