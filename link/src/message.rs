//! The messages: [`ToDevice`] and [`ToHost`]. Each enum's
//! variants travel as their index (a postcard varint) in declaration order: a new
//! message goes at the end, and any change here changes [`crate::SCHEMA`]
//! (docs/protocol.md lists them all, with an example frame each).

use crate::black_box::BlackBoxPart;
use crate::info::{HelloInfo, MeshPart, StatusInfo, Telemetry};
use crate::nak::NakReason;
use crate::replay::{ReplayRow, ReplaySpec};
use crate::tissue::{Pose, TissueBegin};
use postcard_schema::Schema;
use serde::{Deserialize, Serialize};

/// From the host to the device.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq)]
pub enum ToDevice<'a> {
    /// (0) Who are you? Answered with [`ToHost::Hello`].
    Hello,
    /// (1) Answered with [`ToHost::Status`].
    Status,
    /// (2) The host takes the device: from now on, no valid frame for the link timeout
    /// fades the force to zero and disarms (docs/protocol.md, "Keepalive"). The force
    /// ramps up once the probe is out of contact. Answered with a status.
    Arm,
    /// (3) Force to zero now, until the next `Arm`. Answered with a status.
    Disarm,
    /// (4) Where the tissue lies in the device's frame: latest wins; the tick moves toward
    /// it at the device's slew limits. Refused with a `Nak` outside the workspace or for
    /// a rotation that is not a unit quaternion; not answered otherwise.
    Pose(Pose),
    /// (5) A tissue load starts ([`TissueBegin`]).
    TissueBegin(TissueBegin),
    /// (6) The next piece of the table's bytes, at `offset`.
    TissueChunk {
        /// Where it goes (the bytes so far).
        offset: u32,
        /// The bytes (at most [`TISSUE_CHUNK`](crate::TISSUE_CHUNK)).
        bytes: &'a [u8],
    },
    /// (7) The table is whole: the device checks it (the old tissue renders meanwhile) and
    /// swaps it in at a tick boundary, or refuses it. Answered with [`ToHost::Ack`] once
    /// the tick runs it, or [`ToHost::Nak`].
    TissueCommit,
    /// (8) Live telemetry every `every` ticks (0: none); the device holds it to its
    /// byte budget (`HelloInfo::telemetry_least_every`).
    Watch {
        /// Ticks between two telemetry messages.
        every: u16,
    },
    /// (9) A replay starts: the patch and the solver it runs on. Answered with a
    /// [`ToHost::ReplayCredit`] (or a `Nak`).
    ReplayBegin(ReplaySpec),
    /// (10) Probe positions for ticks `first`, `first + 1`, …
    /// ([`crate::replay::PathPoint`]: 12 bytes each).
    ReplayPath {
        /// The first sample's tick.
        first: u32,
        /// The samples.
        points: &'a [u8],
    },
    /// (11) The live patch's node positions every `every` ticks (0: none), for the
    /// visuals; the device holds it to its byte budget (`HelloInfo::mesh_least_every`).
    /// Answered by [`ToHost::Mesh`] parts.
    WatchMesh {
        /// Ticks between two meshes.
        every: u16,
    },
    /// (12) Nothing but a valid frame, which feeds the guard: what a host with nothing
    /// else to say sends at least every [`crate::rates::KEEPALIVE_MS`]. Not answered.
    Keepalive,
    /// (13) The black box the device kept from its last run, ticks `first ..`: answered
    /// with one [`ToHost::BlackBox`] part.
    BlackBox {
        /// The first tick wanted (0: the oldest kept).
        first: u16,
    },
}

/// From the device to the host.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq)]
pub enum ToHost {
    /// (0) The device, its limits and its tissue.
    Hello(HelloInfo),
    /// (1) A tissue swapped in (the tick runs it), by its hash.
    Ack {
        /// The tissue's hash.
        tissue: u32,
    },
    /// (2) Refused; the device's state is unchanged.
    Nak(NakReason),
    /// (3) The counters.
    Status(StatusInfo),
    /// (4) A live tick.
    Telemetry(Telemetry),
    /// (5) A replayed tick.
    ReplayRow(ReplayRow),
    /// (6) The device takes path samples up to (not including) tick `until`.
    ReplayCredit {
        /// The first tick it has no room for.
        until: u32,
    },
    /// (7) The replay ran all its ticks.
    ReplayEnd {
        /// Ticks run.
        ticks: u32,
    },
    /// (8) A part of a live mesh: up to [`crate::info::MESH_PART`] nodes.
    Mesh(MeshPart),
    /// (9) A part of the black box: up to [`crate::black_box::BOX_PART`] ticks.
    BlackBox(BlackBoxPart),
}
