//! The host's end of the link, beyond the scene's library (`mccs_client`, which every
//! host path talks through): [`soft`], a device in software that runs the firmware's own
//! link server and tick on a simulated arm, for the tests and `mccs view --demo`.

pub mod soft;
