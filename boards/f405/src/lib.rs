//! # haptic-f405 — mccs on an STM32F405 board
//!
//! The board firmware (`src/bin/haptic-f405.rs`, built for `thumbv7em-none-eabihf`)
//! runs the `mccs` patch in a TIM2 interrupt on a 1-DOF device: an AS5047P encoder on
//! SPI1 and a DC motor on TIM1's PWM, with an independent watchdog fed by the tick.
//! This library is the part that is the same on every board and is tested on the host:
//!
//! - [`config`]: [`BoardConfig`](config::BoardConfig), every constant a port changes
//!   but the pins, held to the parts' limits, and the HAL's clock arithmetic;
//! - [`arm`]: the arm variant's device (`--features arm`: the WoodenHaptics arm);
//! - [`device`]: the device wiring from any embedded-hal 1.0 parts, and the controller;
//! - [`device_part`]: each part of a device that can fail, its name and its code;
//! - [`safe_stop`]: the motor cut every way out of the firmware takes first;
//! - [`black_box`]: the last ticks and the stop of a run, kept across a reset;
//! - [`telemetry`]: the tick statistics and the verdict of a QEMU run;
//! - [`tissue`]: the force table the firmware runs (`boards/f405/tissue.rs`);
//! - `pins`, `arm_pins` (firmware builds only): the pin maps, 1-DOF and arm.
//!
//! docs/firmware.md, "Bring-up on a board", is the firmware engineer's guide.
#![cfg_attr(not(test), no_std)]
#![deny(missing_docs)]

pub mod arm;
#[cfg(target_os = "none")]
pub mod arm_pins;
pub mod black_box;
pub mod config;
pub mod device;
pub mod device_part;
#[cfg(target_os = "none")]
pub mod pins;
pub mod safe_stop;
pub mod telemetry;
pub mod tissue;

pub use config::{BoardConfig, BoardConfigError, BOARD};
pub use telemetry::BoardTelemetry;
