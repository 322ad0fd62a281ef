//! The host link (`mccs-link`, docs/link.md): its codec here; the device's side of it in
//! `device.rs`; the firmware in QEMU behind `mccs link` in `qemu.rs`.

mod cli;
mod codec;
mod device;
mod qemu;
