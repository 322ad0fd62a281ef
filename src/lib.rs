//! # mccs — multi-component conical spring soft tissue for haptic firmware
//!
//! A `no_std`, heap-free, panic-free core that renders the force of soft tissue under a
//! haptic probe, after "A Multi-Component Conical Spring Model of Soft Tissue in Virtual
//! Surgery" and the project's reading of it (`docs/model.md`). It holds the model and the
//! solver only; the device layer and the firmware are the `mccs-firmware` crate
//! (`firmware/`), the `f64` reference and the CLI the `mccs-host` crate (`host-tests/`).
//! `docs/architecture.md` draws the layers.
//!
//! - [`Params`], [`Law`]: the spring and its `f64` law, used when tables are built.
//! - [`ForceTable`]: the inverse law `F(ε)` tabulated for constant-time fixed-point
//!   evaluation per tick.
//! - [`Topology`], [`Solver`], [`Coupling`]: the local mass-spring patch around the
//!   probe, stepped once per haptic tick, in the arithmetic of the core it runs on
//!   ([`arith`]).
//!
//! Fixed-point formats: [`units`].
#![cfg_attr(not(test), no_std)]
#![deny(missing_docs)]
#![deny(unsafe_code)]

// Lets generated tables (`tables/*.rs`, which say `mccs::…`) be included here too.
extern crate self as mccs;

/// `asm!` for the M4F's assembly blocks (`arith/wide_dsp`, `arm`): the operands given,
/// then r4, r5, r8–r12 and lr declared written (what every block uses beyond its inputs),
/// then the options after `options(…);`, if given. The blocks' own macros add the rest:
/// `asm_writing_all!` r1–r3, `arm_asm!` the joints' offsets and `nostack`.
#[cfg(mccs_dsp)]
macro_rules! asm_writing_r4_to_lr {
    (options($($options:tt)*); $($operands:tt)*) => {
        core::arch::asm!(
            $($operands)*
            out("r4") _,
            out("r5") _,
            out("r8") _,
            out("r9") _,
            out("r10") _,
            out("r11") _,
            out("r12") _,
            out("lr") _,
            options($($options)*),
        )
    };
    ($($operands:tt)*) => {
        asm_writing_r4_to_lr!(options(); $($operands)*)
    };
}

pub mod arith;
pub mod arm;
pub mod coupling;
pub mod fnv;
pub mod law;
pub mod params;
pub mod passivity;
pub mod proxy;
pub mod q;
pub mod shape;
pub mod solver;
pub mod state;
pub mod table;
pub mod tissue_pose;
pub mod topology;
pub mod units;
pub mod velocity;
pub mod window;

#[cfg(feature = "defmt")]
mod defmt;

pub use arith::{Arith, DefaultArith, Integrator, Narrow, Wide};
pub use arm::{Arm, ArmError, ArmFieldError, ArmPose, ArmSpec, Drive, GravitySpec, JointSpec};
pub use coupling::Coupling;
pub use law::Law;
pub use params::{Cone, Derived, Linear, ParamError, ParamKey, Params};
pub use passivity::{PassivityLimits, PassivityObserver};
pub use proxy::{Friction, Proxy, ProxyConfig, ProxyError};
pub use shape::{Cap, Flat, Shape, ShapeSpec, Sphere};
pub use solver::{Bound, ConfigKey, ParamSet, Solver, SolverConfig, SolverError};
pub use table::{
    ForceTable, ForceTable128, ForceTable16, ForceTable32, ForceTable64, RawTable, TableBound,
    TableError,
};
pub use tissue_pose::TissuePose;
pub use topology::{Edge, End, Topology, TopologyError, GROUND};
pub use units::{Force, Length, Stiffness, Strain, Velocity};
pub use velocity::{TrackedVelocity, TrackerError, TrackerGains, VelocityTracker};
pub use window::{Window, WindowConfig};
