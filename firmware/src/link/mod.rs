//! The device's side of the host link (docs/protocol.md; the messages are `mccs-link`):
//!
//! - [`server`]: the main loop's end, [`LinkServer`] — the one message handler of every
//!   device, the board's and the host's soft device's;
//! - [`session`]: what each message does, and the answers;
//! - [`state`]: what the tick and the main loop share ([`LinkState`]), and the tick's
//!   side ([`LinkState::run_tick`]);
//! - [`guard`]: the safety rule — an armed host's silence fades the force to zero, and
//!   the force comes on gently;
//! - [`linked`]: the device with the host's pose and the guard's gain;
//! - [`work`]: the main loop's one job at a time — a replay ([`replayer`]) or a new
//!   tissue's check ([`check`]);
//! - [`mesh`]: the live patch's node positions for the host's visuals.

pub mod check;
pub mod guard;
pub mod linked;
pub mod mesh;
pub mod replayer;
pub mod server;
pub mod session;
pub mod state;
pub mod work;

pub use check::{CheckedTissue, TickBudget, TissueCheck};
pub use guard::{Guard, GuardTimes};
pub use linked::LinkedDevice;
pub use mesh::{Mesh, MeshClock};
pub use replayer::ReplayRun;
pub use server::LinkServer;
pub use session::{Effect, Live, Session};
pub use state::{LinkState, Snapshot, Swap};
pub use work::Work;
