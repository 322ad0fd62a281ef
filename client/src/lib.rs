//! # mccs-client — the scene's library for an mccs haptic device
//!
//! What a trainer scene (C++, C#, Python or Rust) needs of a device over the host link
//! (docs/protocol.md): open it and read its facts, load tissues, place them, hold it
//! armed while the program runs, read its telemetry and its patch's mesh, replay probe
//! motions on it.
//!
//! ```no_run
//! let device = mccs_client::Device::open("unix:/tmp/mccs.sock")?;
//! println!("{}", device.info());
//! device.load_tissue(&mccs_client::Tissue::from_param_file("params/table2.toml".as_ref())?)?;
//! device.watch(10)?;
//! let armed = device.arm()?;            // keepalives from a background thread
//! std::thread::sleep(std::time::Duration::from_secs(2));
//! println!("{:?}", armed.device().telemetry());
//! drop(armed);                           // disarms
//! # Ok::<(), mccs_client::Error>(())
//! ```
//!
//! - [`Device`]: the session; [`Info`], [`Status`], [`TelemetrySample`], [`Mesh`],
//!   [`BlackBox`] (the device's record of its last run);
//! - [`Tissue`]: a tissue's table bytes, from a parameter file (the one table builder,
//!   `mccs::ForceTable::new`), from parameters in memory, or from a `.bin` file;
//! - [`Error`]: every error, typed; a device's refusal is [`Error::Refused`];
//! - [`Addr`]: where a device is (`unix:PATH` on Unix, `tcp:HOST:PORT`, a serial port);
//! - [`replay`]: a probe path replayed on the device's solver;
//! - [`paramfile`], [`trajectory`]: the parameter and probe-path files; [`pose_text`]: a
//!   pose as comma-separated numbers;
//! - [`ffi`]: the C ABI (`include/mccs.h`), which the Python module uses (callable from
//!   Rust too, as its tests do).

pub mod addr;
pub mod black_box;
pub mod device;
pub mod error;
mod facts;
pub mod ffi;
pub mod input;
pub mod mesh;
pub mod paramfile;
pub mod pose_text;
pub mod replay;
mod session;
pub mod shown;
pub mod substeps;
pub mod telemetry;
pub mod tissue;
pub mod trajectory;
mod transport;

pub use addr::Addr;
pub use black_box::BlackBox;
pub use device::{Armed, Device, Info, Options, Proposal, Status, TelemetrySample};
pub use error::{Error, Refusal};
pub use mccs_link::{FaultReason, Flags, Pose};
pub use mesh::{Mesh, MeshNode};
pub use tissue::{Tissue, TissueError};
