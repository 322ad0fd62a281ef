//! The arm variant on a simulated arm (`--features arm,sim`): the same arm device, contact
//! and tick as `arm.rs`, its joints, driver enable and home input those of a
//! [`Plant`] (`mccs_firmware::arm::plant`): homed at start, its hand palpating the
//! tissue over and over on its own clock. For QEMU, where no encoder turns: the live
//! loop — scene, link, tick, arm, force — runs end to end (scripts/qemu-link.sh --sim).

use super::{log_joints, BoardParts, BoardVariant, CtlOf, LinkPins};
use haptic_f405::arm::{self, BoardArm, ARM};
use haptic_f405::config::{BoardConfig, BoardConfigError, BOARD};
use haptic_f405::device::{BoardRoaming, StartFault};
use haptic_f405::telemetry::BoardTelemetry;
use haptic_f405::tissue::TissueTable;
use mccs_firmware::arm::plant::{
    Plant, PlantEnable, PlantHome, PlantJoint, APPROACH_TICKS, HOME_TICKS, NUDGE_TICKS,
    PALPATION_TICKS, PLANT_MAX_DUTY,
};
use mccs_firmware::Slot;
use mccs_link::{ContactKind, DeviceKind};
use stm32f4xx_hal::rcc::Clocks;

/// The arm board on a simulated arm.
pub struct SimArm;

impl BoardVariant for SimArm {
    type Device = BoardArm<PlantJoint<0>, PlantJoint<1>, PlantJoint<2>, PlantEnable, PlantHome>;
    type Contact = BoardRoaming;
    type Store = Plant;
    const NAME: &'static str = "f405-arm-sim";
    const DESCRIPTION: &'static str = "arm (WoodenHaptics) on a simulated arm palpating the tissue";
    const KIND: DeviceKind = DeviceKind::Arm;
    const CONTACT: ContactKind = ContactKind::Roaming;
    const SIMULATED: bool = true;
    const QEMU_FAULT_TICK: Option<u32> = None;
    /// Homed, the direction checked, the approach and one whole palpation (about 1.5 s
    /// in contact, sliding 30 mm each way): the trainer's tick at its worst
    /// (`BENCH … case=trainer_tick`).
    const QEMU_TICKS: u32 = HOME_TICKS + NUDGE_TICKS + APPROACH_TICKS + PALPATION_TICKS;

    fn build(
        parts: BoardParts,
        _clocks: &Clocks,
        store: &'static mut Slot<Plant>,
    ) -> Result<(Self::Device, u16, LinkPins), StartFault> {
        let (a, _, _) = parts.gpio;
        let link = (a.pa2, a.pa3);
        let Ok(path) = mccs_firmware::palpation_path(BOARD.tick_hz) else {
            return Err(StartFault::Config(BoardConfigError::Tick));
        };
        let plant = match Plant::new(&ARM, &path) {
            Ok(p) => store.insert(p),
            Err(_) => return Err(StartFault::Config(BoardConfigError::Tissue)),
        };
        let plant: &'static Plant = plant;
        let (joints, enable, home) = plant.joints();
        arm::arm_device(&BOARD, &ARM, joints, enable, home)
            .map(|d| (d, PLANT_MAX_DUTY, link))
            .map_err(|e| e.fault())
    }

    fn controller_into(
        config: &BoardConfig,
        table: TissueTable,
        device: Self::Device,
        slot: &mut Option<CtlOf<Self>>,
    ) -> Result<(), (StartFault, Self::Device)> {
        arm::arm_start_into(config, table, device, slot).map_err(|(e, d)| (e.fault(), d))
    }

    fn log_second(t: &BoardTelemetry) {
        log_joints(t);
    }

    fn box_counts(ctl: &CtlOf<Self>) -> [i32; 3] {
        ctl.device().inner().counts()
    }
}
