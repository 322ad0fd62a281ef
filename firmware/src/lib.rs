//! # mccs-firmware — the device layer and the firmware around the `mccs` core
//!
//! What a controller needs beyond the model and the solver (`mccs`), kept apart from
//! them so that the core builds for every target without any of it:
//!
//! - [`device`]: [`HapticDevice`], what the tick needs of the hardware, and the
//!   [`SimulatedDevice`] replaying a [`ProbePath`];
//! - [`drivers`]: the AS5047P SPI encoder and the PWM motor (embedded-hal 1.0), and
//!   [`one_dof`], a 1-DOF device made of the two; [`lever_sim`], a simulated lever
//!   behind those parts;
//! - [`arm`]: a 3-DOF arm (three quadrature joints, PWM motors) through the core's
//!   `Arm`, its encoder, its simulations (the demo's, the board's plant) and its `f32`
//!   peer;
//! - [`controller`]: one tick end to end with its safe state; [`mailbox`]: the double
//!   buffer between the main loop and the tick interrupt; [`black_box`]: the last ticks
//!   and the stop of a run, kept across a reset;
//! - [`link`]: the device's side of the host link (`mccs-link`);
//! - [`demo`]: the demo run shared by the QEMU firmware and the host (`mccs demo`);
//! - [`entry`], [`float_patch`]: what the instruction-count bench calls.
//!
//! The bins (`src/bin/`) are thin and build only for `target_os = "none"`: `haptic`, the
//! demo firmware, and `bench`, the instruction counts. `docs/architecture.md` draws the
//! layers; `docs/firmware.md` is the firmware engineer's guide.
#![cfg_attr(not(test), no_std)]
#![deny(missing_docs)]

pub mod arm;
pub mod black_box;
#[cfg(target_os = "none")]
pub mod command_line;
pub mod controller;
pub mod demo;
pub mod device;
pub mod direction;
pub mod drivers;
pub mod entry;
pub mod float_patch;
pub mod lever_sim;
pub mod link;
pub mod mailbox;
pub mod one_dof;
pub mod probe_path;
pub mod slot;
pub mod target;

// With the `defmt` feature, and on every firmware target, where defmt is the log.
#[cfg(any(feature = "defmt", target_os = "none"))]
mod defmt;

pub use controller::{Contact, ContactState, Controller, Fault, Glued, Roaming, Telemetry};
pub use device::{DeviceStatus, HapticDevice, SimulatedDevice};
pub use mailbox::{Mailbox, Shared};
pub use probe_path::{indentation_path, palpation_path, PathError, ProbePath, Waypoint};
pub use slot::Slot;
