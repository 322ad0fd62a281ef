//! The arm variant's pin map (`--features arm`), as the HAL's pin types, and
//! [`QeiEncoder`]: a timer in encoder mode as a [`JointEncoder`]. docs/arm.md, "The arm
//! on the board", has the table with the joints' conventions.
//!
//! | Signal               | Pin  | Mode                              | At reset         |
//! |----------------------|------|-----------------------------------|------------------|
//! | Joint A encoder A/B  | PA0, PA1 | TIM5 CH1/CH2 AF2, encoder mode | input, floating |
//! | Joint B encoder A/B  | PB6, PB7 | TIM4 CH1/CH2 AF2, encoder mode | input, floating |
//! | Joint C encoder A/B  | PC6, PC7 | TIM3 CH1/CH2 AF2, encoder mode | input, floating |
//! | Joint A/B/C PWM      | PA8, PA9, PA10 | TIM1 CH1/CH2/CH3 AF1, 20 kHz | input, floating |
//! | Joint A/B/C direction | PC0, PC1, PC2 | push-pull, high = angle grows | input, floating |
//! | Driver enable        | PB1  | push-pull output, high = on       | input, floating  |
//! | Stop chain (BKIN)    | PB12 | TIM1_BKIN AF1, pull-down (raw: `safe_stop`) | input, floating |
//! | Home                 | PC3  | input, pull-down, high = at home  | input, floating  |
//! | Host link TX / RX    | PA2, PA3 | USART2 AF7, 1 Mbaud 8N1       | input, floating  |
//!
//! As on the 1-DOF board, the driver's enable and PWM inputs need pull-downs, so that a
//! reset leaves the driver off; the home switch pulls PC3 high while the arm is held in
//! its home pose.

use mccs_firmware::arm::encoder::JointEncoder;
use stm32f4xx_hal::gpio::{
    gpioa, gpiob, gpioc, Input, Output, PinState, PushPull, PA0, PA1, PA10, PA2, PA3, PA8, PA9,
    PB1, PB6, PB7, PC0, PC1, PC2, PC3, PC6, PC7,
};
use stm32f4xx_hal::qei::{Instance, Qei};

/// The driver's enable.
pub type ArmEnable = PB1<Output<PushPull>>;
/// The home input.
pub type Home = PC3<Input>;

/// The pins, taken from the GPIO ports.
pub struct ArmPins {
    /// Joint A's counter inputs (TIM5).
    pub encoder_a: (PA0, PA1),
    /// Joint B's (TIM4).
    pub encoder_b: (PB6, PB7),
    /// Joint C's (TIM3).
    pub encoder_c: (PC6, PC7),
    /// TIM1 CH1, CH2, CH3: joints A, B, C.
    pub pwm: (PA8, PA9, PA10),
    /// Joint A's direction, low.
    pub direction_a: PC0<Output<PushPull>>,
    /// Joint B's direction, low.
    pub direction_b: PC1<Output<PushPull>>,
    /// Joint C's direction, low.
    pub direction_c: PC2<Output<PushPull>>,
    /// The driver's enable, low (off).
    pub enable: ArmEnable,
    /// The home input, pulled down.
    pub home: Home,
    /// The host link's USART2 TX.
    pub link_tx: PA2,
    /// The host link's USART2 RX.
    pub link_rx: PA3,
}

impl ArmPins {
    /// Takes the pins, the outputs driven at once to their safe levels (directions and
    /// enable low).
    pub fn take(a: gpioa::Parts, b: gpiob::Parts, c: gpioc::Parts) -> Self {
        Self {
            encoder_a: (a.pa0, a.pa1),
            encoder_b: (b.pb6, b.pb7),
            encoder_c: (c.pc6, c.pc7),
            pwm: (a.pa8, a.pa9, a.pa10),
            direction_a: c.pc0.into_push_pull_output_in_state(PinState::Low),
            direction_b: c.pc1.into_push_pull_output_in_state(PinState::Low),
            direction_c: c.pc2.into_push_pull_output_in_state(PinState::Low),
            enable: b.pb1.into_push_pull_output_in_state(PinState::Low),
            home: c.pc3.into_pull_down_input(),
            link_tx: a.pa2,
            link_rx: a.pa3,
        }
    }
}

/// A timer in encoder mode (the HAL's [`Qei`]) as a joint's 16-bit counter: its low 16
/// bits (TIM2 and TIM5 count 32 bits; [`Extended`](mccs_firmware::arm::encoder::Extended)
/// carries 16). A register read: it cannot fail.
pub struct QeiEncoder<TIM: Instance>(pub Qei<TIM>);

impl<TIM: Instance> JointEncoder for QeiEncoder<TIM> {
    type Error = core::convert::Infallible;
    fn read(&mut self) -> Result<u16, Self::Error> {
        use stm32f4xx_hal::hal_02::Qei as _;
        let count: u32 = self.0.count().into();
        Ok(count as u16)
    }
}
