//! The 3-DOF arm on the host: its `f64` twin ([`twin`]), the device file
//! ([`device_file`]).

pub mod columns;
pub mod device_file;
pub mod gravity_fit;
pub mod joints;
pub mod twin;

pub use twin::ArmTwin;
