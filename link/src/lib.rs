//! The host link: what a PC that draws the scene and the haptic controller say to each
//! other (docs/protocol.md is the normative page; docs/link.md the how-to). `no_std`, no
//! heap: the firmware, the host's client and the CLI share this crate.
//!
//! - [`message`]: the messages, [`ToDevice`] and [`ToHost`];
//! - [`tissue`]: what a host says about a tissue ([`Pose`], [`Friction`],
//!   [`TissueBegin`]);
//! - [`info`]: what the device tells of itself: hello, status, telemetry, mesh;
//! - [`nak`]: why it refuses; [`flags`]: a live tick's flags;
//! - [`black_box`]: the record a device keeps of its last run, as a message carries it;
//! - [`frame`]: a message on the wire — postcard bytes, a CRC-32 over them, COBS with a
//!   `0x00` delimiter, at most [`MAX_FRAME`] bytes — and the byte-stream [`Decoder`];
//! - [`crc`]: the CRC-32 (IEEE 802.3); [`fnv`]: the FNV-1a hash of tissues;
//! - [`schema`]: the protocol's version and the schema hash derived from the types;
//! - [`scale`]: the fixed-point scales the messages carry;
//! - [`rates`]: the byte budget, the keepalive and the stream rates it allows;
//! - [`table_bytes`]: a force table as the bytes a tissue load carries, and its hash;
//!   [`tissue_file`]: those bytes as a file;
//! - [`replay`]: a replay both ways (spec, path points, rows) and one replay tick in the
//!   fixed-point core, the same code on the host and on the device.
#![no_std]

pub mod black_box;
pub mod crc;
pub mod flags;
/// FNV-1a, the core's ([`mccs::fnv`]): the one hash.
pub use mccs::fnv;
pub mod frame;
pub mod info;
pub mod message;
pub mod nak;
pub mod rates;
pub mod replay;
pub mod scale;
pub mod schema;
pub mod table_bytes;
pub mod tissue;
pub mod tissue_file;

pub use black_box::{BlackBoxPart, BoxStop, BoxTick, StopCause, BOX_PART};
pub use flags::Flags;
pub use frame::{encode, parse, Decoder, FrameError, MAX_FRAME, MAX_PAYLOAD};
pub use info::{
    ContactKind, Core, DeviceKind, FaultReason, HelloInfo, MeshPart, SolverInfo, StatusInfo,
    Telemetry, MESH_PART,
};
pub use message::{ToDevice, ToHost};
pub use nak::{NakReason, SpecOption};
pub use replay::{PathPoint, ReplayRow, ReplaySpec, RoamSpec};
pub use schema::{PROTOCOL, SCHEMA};
pub use tissue::{Friction, Pose, TissueBegin, TISSUE_CHUNK};
