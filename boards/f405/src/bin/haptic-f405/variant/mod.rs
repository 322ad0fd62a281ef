//! The device the board drives, one file per variant, each a [`BoardVariant`]: the
//! contract `main` and the tick rely on. [`Variant`] is this build's (`board_arm`,
//! `board_sim` from build.rs):
//!
//! | | the plant | file |
//! |---|---|---|
//! | default | the 1-DOF lever: AS5047P on SPI1, a motor on TIM1 CH1 | `one_dof.rs` |
//! | `arm` | the WoodenHaptics arm: TIM5/TIM4/TIM3 encoders, TIM1 CH1–CH3 | `arm.rs` |
//! | `arm,sim` | the same arm device on a simulated arm ([`mccs_firmware::arm::plant`]) | `sim_arm.rs` |
//! | `sim` | the same 1-DOF device on a simulated lever and encoder | `sim_one_dof.rs` |

use haptic_f405::config::BoardConfig;
use haptic_f405::device::{BoardController, DevicePart, StartFault};
use haptic_f405::telemetry::BoardTelemetry;
use haptic_f405::tissue::TissueTable;
use mccs_firmware::drivers::as5047p::EncoderErrors;
use mccs_firmware::link::LinkedDevice;
use mccs_firmware::{Contact, HapticDevice, Slot};
use mccs_link::{ContactKind, DeviceKind};
use stm32f4xx_hal::gpio::{gpioa, gpiob, gpioc, PA2, PA3};
use stm32f4xx_hal::pac;
use stm32f4xx_hal::rcc::Clocks;

#[cfg(all(board_arm, not(board_sim)))]
mod arm;
#[cfg(all(not(board_arm), not(board_sim)))]
mod one_dof;
#[cfg(all(board_arm, board_sim))]
mod sim_arm;
#[cfg(all(not(board_arm), board_sim))]
mod sim_one_dof;

/// This build's variant.
#[cfg(all(board_arm, not(board_sim)))]
pub type Variant = arm::Arm;
/// This build's variant.
#[cfg(all(board_arm, board_sim))]
pub type Variant = sim_arm::SimArm;
/// This build's variant.
#[cfg(all(not(board_arm), not(board_sim)))]
pub type Variant = one_dof::OneDof;
/// This build's variant.
#[cfg(all(not(board_arm), board_sim))]
pub type Variant = sim_one_dof::SimOneDof;

/// The peripherals and ports `main` hands a variant: it takes what its device uses (the
/// 1-DOF: SPI1 and TIM1; the arm: TIM1, TIM3, TIM4, TIM5) and drops the rest, which stay
/// in their reset state (hence `dead_code`: each variant reads its own).
#[allow(dead_code)]
pub struct BoardParts {
    /// GPIO ports A, B, C.
    pub gpio: (gpioa::Parts, gpiob::Parts, gpioc::Parts),
    /// The motors' PWM.
    pub tim1: pac::TIM1,
    /// The 1-DOF encoder's bus.
    pub spi1: pac::SPI1,
    /// The arm's encoders' timers (joints C, B, A).
    pub tim3: pac::TIM3,
    /// See `tim3`.
    pub tim4: pac::TIM4,
    /// See `tim3`.
    pub tim5: pac::TIM5,
}

/// The host link's USART2 pins, which every variant leaves free.
pub type LinkPins = (PA2, PA3);

/// The tick's controller of a variant.
pub type CtlOf<V> =
    BoardController<LinkedDevice<<V as BoardVariant>::Device>, <V as BoardVariant>::Contact>;

/// What a device variant gives the board's main and tick.
pub trait BoardVariant {
    /// The device as `main` builds it, in its safe state.
    type Device: HapticDevice + Send;
    /// How its probe touches the tissue.
    type Contact: Contact<
            { haptic_f405::device::NODES },
            { haptic_f405::device::EDGES },
            { haptic_f405::tissue::SEGMENTS },
            mccs::Wide,
        > + Send;
    /// What the variant keeps for the whole run beside its device (a simulated plant),
    /// in a `'static` slot `main` owns.
    type Store: 'static;
    /// Its name in a QEMU run's SUMMARY.
    const NAME: &'static str;
    /// What the device is, for the start-up line.
    const DESCRIPTION: &'static str;
    /// What it is, for the host's hello.
    const KIND: DeviceKind;
    /// How its probe touches the tissue, for the host's hello.
    const CONTACT: ContactKind;
    /// Its plant is simulated.
    const SIMULATED: bool;
    /// The tick on which a QEMU run (`board_run_ends`) enters the safe state, if any
    /// (read only by that build).
    #[allow(dead_code)]
    const QEMU_FAULT_TICK: Option<u32>;
    /// Ticks of a QEMU run (`board_run_ends`, read only by that build): the board's
    /// second, or what the plant needs to show its work.
    #[allow(dead_code)]
    const QEMU_TICKS: u32 = haptic_f405::config::BOARD.qemu_ticks;

    /// Takes its pins and peripherals and builds the device in its safe state; returns
    /// it, the PWM's full scale and the link's pins.
    fn build(
        parts: BoardParts,
        clocks: &Clocks,
        store: &'static mut Slot<Self::Store>,
    ) -> Result<(Self::Device, u16, LinkPins), StartFault>;

    /// The controller on `device` into `slot`, the driver enabled (duty still zero); an
    /// error hands the device back in its safe state.
    #[allow(clippy::result_large_err)]
    fn controller_into(
        config: &BoardConfig,
        table: TissueTable,
        device: Self::Device,
        slot: &mut Option<CtlOf<Self>>,
    ) -> Result<(), (StartFault, Self::Device)>
    where
        Self: Sized;

    /// The encoder's error counters (zeros where there are none).
    fn encoder_errors(_ctl: &CtlOf<Self>) -> EncoderErrors
    where
        Self: Sized,
    {
        BoardTelemetry::new().encoder
    }

    /// The part whose failure put the device in its safe state, if a failed read or
    /// write did.
    fn device_part(ctl: &CtlOf<Self>) -> Option<DevicePart>
    where
        Self: Sized,
        for<'e> DevicePart: From<&'e <Self::Device as HapticDevice>::Error>,
    {
        ctl.device_error().map(DevicePart::from)
    }

    /// What the black box keeps as a tick's counts: by default the probe in the tissue's
    /// frame, µm (the lever's travel along `z`); the arm's its joints' counts.
    fn box_counts(ctl: &CtlOf<Self>) -> [i32; 3]
    where
        Self: Sized,
    {
        ctl.device()
            .probe()
            .map(|x| ((x.to_bits() as i64 * 1000) >> mccs::Length::FRAC_NBITS) as i32)
    }

    /// Its own line in the log every second (none by default).
    fn log_second(_t: &BoardTelemetry) {}
}

/// The joints, every second.
#[allow(dead_code)] // (the arm's variants' own line)
pub fn log_joints(t: &BoardTelemetry) {
    let d = t.device;
    defmt::info!(
        "arm homed={=bool} at_limit={=bool} duty_q16=[{=i32}, {=i32}, {=i32}]",
        d.homed,
        d.at_limit,
        d.duties[0],
        d.duties[1],
        d.duties[2]
    );
}
