//! The device's side of the host link (docs/link.md; the protocol is `mccs-link`):
//!
//! - [`guard`]: the safety rule — an armed host's silence fades the force to zero;
//! - [`linked`]: the device as the link sees it, with the host's pose and the guard's
//!   gain;
//! - [`session`]: each message handled in the main loop, a tissue load checked whole
//!   before the tick sees it;
//! - [`replayer`]: a host's replay run on the device's own solver.

pub mod guard;
pub mod linked;
pub mod replayer;
pub mod session;

pub use guard::Guard;
pub use linked::LinkedDevice;
pub use replayer::Replayer;
pub use session::{Effect, Live, Now, Session};
