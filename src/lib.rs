//! # mccs — multi-component conical spring soft tissue for haptic firmware
//!
//! A `no_std`, heap-free, panic-free core that renders the force of soft tissue under a
//! haptic probe, after "A Multi-Component Conical Spring Model of Soft Tissue in Virtual
//! Surgery" and the project's reading of it (MODEL.md, summarised in the README).
//!
//! - [`Params`], [`Law`]: the spring and its `f64` law, used when tables are built.
//! - [`ForceTable`]: the inverse law `F(ε)` tabulated for constant-time fixed-point
//!   evaluation per tick.
//! - [`Topology`], [`Solver`], [`Coupling`]: the local mass-spring patch around the
//!   probe, stepped once per haptic tick.
//! - [`HapticDevice`], [`Controller`], [`Mailbox`]: the device layer, the tick with its
//!   safe state, and the double buffer between main loop and tick interrupt.
//!
//! Fixed-point formats (all from the `fixed` crate):
//! [`Strain`] `I8F24`, [`Force`] `I12F20` (N), [`Stiffness`] `I16F16` (N per unit strain).
#![cfg_attr(not(test), no_std)]
#![deny(missing_docs)]

// Lets generated tables (`tables/*.rs`, which say `mccs::…`) be included here too.
extern crate self as mccs;

pub mod as5047p;
pub mod controller;
pub mod coupling;
pub mod demo;
pub mod device;
pub mod entry;
pub mod float_patch;
pub mod law;
pub mod mailbox;
pub mod motor;
pub mod one_dof;
pub mod params;
pub mod q;
pub mod solver;
pub mod spring;
pub mod table;
pub mod topology;
pub mod trajectory;

#[cfg(feature = "defmt")]
mod defmt_impls;

pub use controller::{Controller, Fault, Telemetry};
pub use coupling::Coupling;
pub use device::{HapticDevice, SimulatedDevice};
pub use law::Law;
pub use mailbox::{Mailbox, Shared};
pub use params::{Cone, Linear, ParamError, ParamKey, Params};
pub use solver::{ConfigKey, Length, ParamSet, Solver, SolverConfig, SolverError, Velocity};
pub use table::{
    ForceTable, ForceTable128, ForceTable16, ForceTable32, ForceTable64, RawTable, TableError,
};
pub use topology::{Edge, End, Topology, TopologyError, GROUND};
pub use trajectory::{demo_path, PathError, ProbePath, Waypoint};

/// Compressive strain `ε = (l0 − l) / l0` (dimensionless; positive = compressed). ±128.
pub type Strain = fixed::types::I8F24;
/// Force in N. ±2048 N, resolution 9.5e-7 N.
pub type Force = fixed::types::I12F20;
/// Tangent stiffness `dF/dε` in N per unit strain. ±32768, resolution 1.5e-5.
pub type Stiffness = fixed::types::I16F16;
