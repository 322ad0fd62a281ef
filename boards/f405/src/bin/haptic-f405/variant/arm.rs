//! The arm variant (`--features arm`): the WoodenHaptics 3-DOF arm — joints A, B, C on
//! TIM5, TIM4 and TIM3 in encoder mode, TIM1 CH1–CH3 with three direction pins, one
//! driver enable and a home input (`haptic_f405::arm`, `haptic_f405::arm_pins`) —
//! roaming the board's tissue with friction.

use super::{log_joints, BoardParts, BoardVariant, CtlOf, LinkPins};
use haptic_f405::arm::{self, BoardArm, ARM};
use haptic_f405::arm_pins::{ArmEnable, ArmPins, Home, QeiEncoder};
use haptic_f405::config::{BoardConfig, BOARD};
use haptic_f405::device::{BoardRoaming, StartFault};
use haptic_f405::telemetry::BoardTelemetry;
use haptic_f405::tissue::TissueTable;
use mccs_firmware::arm::device::JointParts;
use mccs_firmware::Slot;
use mccs_link::{ContactKind, DeviceKind};
use stm32f4xx_hal::gpio::{Output, PushPull, PC0, PC1, PC2};
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::qei::Qei;
use stm32f4xx_hal::rcc::Clocks;
use stm32f4xx_hal::{pac, timer::PwmChannel};

type JointA = JointParts<QeiEncoder<pac::TIM5>, PwmChannel<pac::TIM1, 0>, PC0<Output<PushPull>>>;
type JointB = JointParts<QeiEncoder<pac::TIM4>, PwmChannel<pac::TIM1, 1>, PC1<Output<PushPull>>>;
type JointC = JointParts<QeiEncoder<pac::TIM3>, PwmChannel<pac::TIM1, 2>, PC2<Output<PushPull>>>;

/// The arm board.
pub struct Arm;

impl BoardVariant for Arm {
    type Device = BoardArm<JointA, JointB, JointC, ArmEnable, Home>;
    type Contact = BoardRoaming;
    type Store = ();
    const NAME: &'static str = "f405-arm";
    const DESCRIPTION: &'static str =
        "arm (WoodenHaptics: encoders on TIM5, TIM4, TIM3; motors on TIM1 CH1-CH3)";
    const KIND: DeviceKind = DeviceKind::Arm;
    const CONTACT: ContactKind = ContactKind::Roaming;
    const SIMULATED: bool = false;
    /// QEMU's counters read and its home input reads low: never homed, zero duty, no
    /// fault.
    const QEMU_FAULT_TICK: Option<u32> = None;

    fn build(
        parts: BoardParts,
        clocks: &Clocks,
        _store: &'static mut Slot<()>,
    ) -> Result<(Self::Device, u16, LinkPins), StartFault> {
        let (a, b, c) = parts.gpio;
        let pins = ArmPins::take(a, b, c);
        let link = (pins.link_tx, pins.link_rx);
        let (_pwm, (ch1, ch2, ch3, ..)) = parts.tim1.pwm_hz(BOARD.pwm_hz.Hz(), clocks);
        let (p1, p2, p3) = pins.pwm;
        let mut pwm = (ch1.with(p1), ch2.with(p2), ch3.with(p3));
        pwm.0.set_duty(0);
        pwm.1.set_duty(0);
        pwm.2.set_duty(0);
        pwm.0.enable();
        pwm.1.enable();
        pwm.2.enable();
        let max_duty = pwm.0.get_max_duty();
        let joints = (
            JointParts {
                encoder: QeiEncoder(Qei::new(parts.tim5, pins.encoder_a)),
                pwm: pwm.0,
                direction: pins.direction_a,
            },
            JointParts {
                encoder: QeiEncoder(Qei::new(parts.tim4, pins.encoder_b)),
                pwm: pwm.1,
                direction: pins.direction_b,
            },
            JointParts {
                encoder: QeiEncoder(Qei::new(parts.tim3, pins.encoder_c)),
                pwm: pwm.2,
                direction: pins.direction_c,
            },
        );
        arm::arm_device(&BOARD, &ARM, joints, pins.enable, pins.home)
            .map(|d| (d, max_duty, link))
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
