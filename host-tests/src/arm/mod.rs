//! The 3-DOF arm on the host: its `f64` twin ([`twin`]), the device file
//! ([`device_file`]), its body ([`dynamics`]) and the board's loop closed through it
//! ([`closed_loop`], its hand's path: [`lead`]).

pub mod closed_loop;
pub mod columns;
pub mod device_file;
pub mod dynamics;
pub mod gravity_fit;
pub mod joints;
pub mod lead;
pub mod twin;

pub use twin::ArmTwin;
