//! The pin map: the only pins the firmware touches, as the HAL's pin types (a wrong
//! alternate function does not compile). docs/firmware.md, "Bring-up on a board", has
//! them in one table with the [`BoardConfig`](crate::BoardConfig) constants.
//!
//! | Signal            | Pin | Mode                          | At reset / watchdog reset |
//! |-------------------|-----|-------------------------------|---------------------------|
//! | AS5047P SCK       | PA5 | SPI1 AF5                      | input, floating           |
//! | AS5047P MISO      | PA6 | SPI1 AF5                      | input, floating           |
//! | AS5047P MOSI      | PA7 | SPI1 AF5                      | input, floating           |
//! | AS5047P CSn       | PA4 | push-pull output, idle high   | input, floating           |
//! | Motor PWM         | PA8 | TIM1 CH1 AF1, 20 kHz          | input, floating           |
//! | Motor direction   | PB0 | push-pull output, low = −z    | input, floating           |
//! | Motor enable      | PB1 | push-pull output, high = on   | input, floating           |
//! | Stop chain (BKIN) | PB12 | TIM1_BKIN AF1, pull-down (raw: `safe_stop`) | input, floating      |
//! | Host link TX      | PA2 | USART2 AF7, 1 Mbaud 8N1       | input, floating           |
//! | Host link RX      | PA3 | USART2 AF7                    | input, floating           |
//!
//! Every pin is a floating input from reset until the firmware drives it: the motor
//! driver's enable and PWM inputs need pull-downs on the board (most driver boards have
//! them), so that a reset — the watchdog's included — leaves the driver off.

use stm32f4xx_hal::gpio::{
    gpioa, gpiob, Output, PinState, PushPull, PA2, PA3, PA4, PA5, PA6, PA7, PA8, PB0, PB1,
};

/// The encoder's chip select.
pub type EncoderCs = PA4<Output<PushPull>>;
/// The motor driver's direction input.
pub type MotorDirection = PB0<Output<PushPull>>;
/// The motor driver's enable input.
pub type MotorEnable = PB1<Output<PushPull>>;

/// The pins, taken from the GPIO ports.
pub struct Pins {
    /// SPI1 SCK.
    pub sck: PA5,
    /// SPI1 MISO.
    pub miso: PA6,
    /// SPI1 MOSI.
    pub mosi: PA7,
    /// Encoder chip select, high (idle).
    pub cs: EncoderCs,
    /// TIM1 CH1.
    pub pwm: PA8,
    /// Motor direction, low.
    pub direction: MotorDirection,
    /// Motor enable, low (driver off).
    pub enable: MotorEnable,
    /// The host link's USART2 TX.
    pub link_tx: PA2,
    /// The host link's USART2 RX.
    pub link_rx: PA3,
}

impl Pins {
    /// Takes the pins, the outputs driven at once to their safe levels: chip select
    /// high, direction low, enable low.
    pub fn take(a: gpioa::Parts, b: gpiob::Parts) -> Self {
        Self {
            sck: a.pa5,
            miso: a.pa6,
            mosi: a.pa7,
            cs: a.pa4.into_push_pull_output_in_state(PinState::High),
            pwm: a.pa8,
            direction: b.pb0.into_push_pull_output_in_state(PinState::Low),
            enable: b.pb1.into_push_pull_output_in_state(PinState::Low),
            link_tx: a.pa2,
            link_rx: a.pa3,
        }
    }
}
