//! The arm variant (`--features arm`): the WoodenHaptics 3-DOF arm — joints A, B, C on
//! TIM5, TIM4 and TIM3 in encoder mode, TIM1 CH1–CH3 with three direction pins, one
//! driver enable and a home input (`haptic_f405::arm`, `haptic_f405::arm_pins`).

use haptic_f405::arm::{self, BoardArm, LinkedArm, ARM};
use haptic_f405::arm_pins::{ArmEnable, ArmPins, Home, QeiEncoder};
use haptic_f405::config::{BoardConfig, BOARD};
use haptic_f405::device::{BoardController, StartFault};
use haptic_f405::telemetry::BoardTelemetry;
use mccs::ForceTable;
use mccs_firmware::arm_device::JointParts;
use mccs_firmware::drivers::as5047p::EncoderErrors;
use stm32f4xx_hal::gpio::{gpioa, gpiob, gpioc, Output, PushPull, PA2, PA3, PC0, PC1, PC2};
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::qei::Qei;
use stm32f4xx_hal::rcc::Clocks;
use stm32f4xx_hal::{pac, timer::PwmChannel};

type JointA = JointParts<QeiEncoder<pac::TIM5>, PwmChannel<pac::TIM1, 0>, PC0<Output<PushPull>>>;
type JointB = JointParts<QeiEncoder<pac::TIM4>, PwmChannel<pac::TIM1, 1>, PC1<Output<PushPull>>>;
type JointC = JointParts<QeiEncoder<pac::TIM3>, PwmChannel<pac::TIM1, 2>, PC2<Output<PushPull>>>;
/// The device as `main` builds it.
pub type Device = BoardArm<JointA, JointB, JointC, ArmEnable, Home>;
/// The tick's controller.
pub type Ctl = BoardController<LinkedArm<JointA, JointB, JointC, ArmEnable, Home>>;

/// The board's name in a QEMU run's SUMMARY.
#[cfg(all(feature = "qemu", not(feature = "qemu-link")))]
pub const NAME: &str = "f405-arm";
/// What the device is, for the start-up line.
pub const DEVICE: &str =
    "arm (WoodenHaptics: encoders on TIM5, TIM4, TIM3; motors on TIM1 CH1-CH3)";
/// QEMU's run never faults: its counters read, and its home input reads low (not homed,
/// zero duty throughout).
#[cfg(all(feature = "qemu", not(feature = "qemu-link")))]
pub const QEMU_FAULT_TICK: Option<u32> = None;

/// The pins, the outputs at their safe levels.
pub fn take_pins(a: gpioa::Parts, b: gpiob::Parts, c: gpioc::Parts) -> ArmPins {
    ArmPins::take(a, b, c)
}

/// The arm, in its safe state, the PWM's full scale and the host link's pins.
pub fn build_device(
    pins: ArmPins,
    clocks: &Clocks,
    t: crate::Timers,
) -> Result<(Device, u16, (PA2, PA3)), StartFault> {
    let link = (pins.link_tx, pins.link_rx);
    let (_pwm, (ch1, ch2, ch3, ..)) = t.tim1.pwm_hz(BOARD.pwm_hz.Hz(), clocks);
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
            encoder: QeiEncoder(Qei::new(t.tim5, pins.encoder_a)),
            pwm: pwm.0,
            direction: pins.direction_a,
        },
        JointParts {
            encoder: QeiEncoder(Qei::new(t.tim4, pins.encoder_b)),
            pwm: pwm.1,
            direction: pins.direction_b,
        },
        JointParts {
            encoder: QeiEncoder(Qei::new(t.tim3, pins.encoder_c)),
            pwm: pwm.2,
            direction: pins.direction_c,
        },
    );
    arm::arm_device(&BOARD, &ARM, joints, pins.enable, pins.home)
        .map(|d| (d, max_duty, link))
        .map_err(|e| e.fault())
}

/// The controller into `slot` ([`arm::arm_controller_into`]); an error hands the device
/// back in its safe state.
#[allow(clippy::type_complexity, clippy::result_large_err)]
pub fn controller_into<const S: usize>(
    config: &BoardConfig,
    table: ForceTable<S>,
    device: Device,
    slot: &mut Option<BoardController<LinkedArm<JointA, JointB, JointC, ArmEnable, Home>, S>>,
) -> Result<(), (StartFault, Device)> {
    arm::arm_controller_into(config, table, device, slot).map_err(|(e, d)| (e.fault(), d))
}

/// The arm's counters have no error counts.
pub fn encoder_errors(_ctl: &Ctl) -> EncoderErrors {
    BoardTelemetry::new().encoder
}

/// The joints' duties, limit flags and homing.
pub fn record(ctl: &Ctl, t: &mut BoardTelemetry) {
    let arm = ctl.device().inner();
    t.duties = arm.duties();
    t.arm_flags = arm.flags();
    t.homed = arm.homed();
}

/// The joints, every second.
pub fn log_second(t: &BoardTelemetry) {
    defmt::info!(
        "arm homed={=bool} flags={=u8:#04x} duty_q16=[{=i32}, {=i32}, {=i32}]",
        t.homed,
        t.arm_flags,
        t.duties[0],
        t.duties[1],
        t.duties[2]
    );
}
