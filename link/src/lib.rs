//! The host link: what a PC that draws the scene and the haptic controller say to each
//! other (docs/link.md). `no_std`, no heap: the firmware and the host share this crate.
//!
//! - [`message`]: the messages, [`ToDevice`] and [`ToHost`], and what they carry;
//! - [`frame`]: a message on the wire — postcard bytes, a CRC-32 over them, COBS with a
//!   `0x00` delimiter, at most [`MAX_FRAME`] bytes — and the byte-stream [`Decoder`];
//! - [`crc`]: the CRC-32 (IEEE 802.3), so that a corrupted frame is never a different
//!   valid message;
//! - [`schema`]: the protocol's version and schema hash, checked in the handshake;
//! - [`table_bytes`]: a force table as the bytes a tissue load carries, and its hash;
//! - [`replay`]: one tick of a replay in the fixed-point core, the same code on the host
//!   (`mccs replay --backend fixed`) and on the device (`mccs link replay`).
#![no_std]

pub mod crc;
pub mod frame;
pub mod message;
pub mod replay;
pub mod schema;
pub mod table_bytes;

pub use frame::{encode, Decoder, FrameError, MAX_FRAME, MAX_PAYLOAD};
pub use message::{
    Core, HelloInfo, MeshPart, NakReason, ReplayRow, ReplaySpec, RoamSpec, SpecOption, StatusInfo,
    Telemetry, ToDevice, ToHost, MESH_PART,
};
pub use schema::{PROTOCOL, SCHEMA};
