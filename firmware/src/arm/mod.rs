//! The arm in the firmware: the core's fixed-point chain ([`mccs::Arm`]) as the tick's
//! device, with what surrounds it.
//!
//! - [`device`]: a 3-DOF arm as a [`crate::HapticDevice`] — three joints (a counter, a
//!   PWM channel and a direction pin each), a driver enable and a home input — with its
//!   homing and safe state, and the WoodenHaptics constant;
//! - [`runaway`], [`walls`], [`thermal`]: what keeps the device safe beyond its parts'
//!   faults — the speed limits, the virtual walls, the I²t model;
//! - [`direction`](crate::direction): the start-up check that each motor turns its joint the way it is
//!   driven;
//! - [`trims`]: each amplifier's duty offset and dead band;
//! - [`joint`]: a joint's counter, PWM channel and direction pin behind one interface;
//! - [`encoder`]: a joint's quadrature counter, carried past its 16 bits;
//! - [`sim`]: the arm's chain on a recorded motion (the demo on the arm);
//! - [`plant`]: a simulated arm behind the board's own parts (the board's `sim` build);
//! - [`float`]: the same chain in `f32`, the bench's peer.

pub mod device;
pub mod encoder;
pub mod float;
pub mod joint;
pub mod plant;
pub mod runaway;
pub mod sim;
pub mod thermal;
pub mod trims;
pub mod walls;
