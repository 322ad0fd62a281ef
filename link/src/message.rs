//! The messages. Positions and forces travel as the core's raw fixed-point bits
//! (`Length`: Q24 mm, `Force`: Q20 N), so that the device computes on exactly what the
//! host sent and the host prints exactly what the device computed.

use serde::{Deserialize, Serialize};

/// From the host to the device.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq)]
pub enum ToDevice<'a> {
    /// Who are you? Answered with [`ToHost::Hello`].
    Hello,
    /// Answered with [`ToHost::Status`].
    Status,
    /// The host takes the device: from now on, no valid frame for the link timeout fades
    /// the force to zero and disarms (docs/link.md, "Safety"). Answered with a status.
    Arm,
    /// Force to zero now, until the next `Arm`. Answered with a status.
    Disarm,
    /// The tissue's origin in the device frame (Q24 mm each): latest wins; the tick moves
    /// toward it by a bounded step. Not answered.
    Pose {
        /// `x, y, z`, Q24 mm.
        origin: [i32; 3],
    },
    /// A tissue load starts: the force table's `segments` (knots − 1), its length in
    /// bytes and its hash ([`crate::table_bytes`]).
    TissueBegin {
        /// Segments.
        segments: u16,
        /// Bytes to come.
        len: u32,
        /// FNV-1a of the bytes.
        hash: u32,
    },
    /// The next piece of the table's bytes, at `offset`.
    TissueChunk {
        /// Where it goes (the bytes so far).
        offset: u32,
        /// The bytes.
        bytes: &'a [u8],
    },
    /// The table is whole: the device checks it and swaps it in at a tick boundary, or
    /// refuses it. Answered with [`ToHost::Ack`] or [`ToHost::Nak`].
    TissueCommit,
    /// Live telemetry every `every` ticks (0: none).
    Watch {
        /// Ticks between two telemetry messages.
        every: u16,
    },
    /// A replay starts: the patch and the solver it runs on. Answered with a
    /// [`ToHost::ReplayCredit`] (or a `Nak`).
    ReplayBegin(ReplaySpec),
    /// Probe positions for ticks `first`, `first + 1`, …: Q24 mm `x, y, z`, 12 bytes each,
    /// little-endian.
    ReplayPath {
        /// The first sample's tick.
        first: u32,
        /// The samples.
        points: &'a [u8],
    },
    /// The live patch's node positions every `every` ticks (0: none), for the visuals;
    /// the device holds it to 60 a second at most. Answered by [`ToHost::Mesh`] parts.
    WatchMesh {
        /// Ticks between two meshes.
        every: u16,
    },
}

/// From the device to the host.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq)]
pub enum ToHost {
    /// The device and its tissue.
    Hello(HelloInfo),
    /// A tissue swapped in, by its hash.
    Ack {
        /// The tissue's hash.
        tissue: u32,
    },
    /// Refused; the device's state is unchanged.
    Nak(NakReason),
    /// The counters.
    Status(StatusInfo),
    /// A live tick.
    Telemetry(Telemetry),
    /// A replayed tick.
    ReplayRow(ReplayRow),
    /// The device takes path samples up to (not including) tick `until`.
    ReplayCredit {
        /// The first tick it has no room for.
        until: u32,
    },
    /// The replay ran all its ticks.
    ReplayEnd {
        /// Ticks run.
        ticks: u32,
    },
    /// A part of a live mesh: up to [`MESH_PART`] nodes' positions.
    Mesh(MeshPart),
}

/// Nodes one [`ToHost::Mesh`] part carries (its frame stays within 256 bytes).
pub const MESH_PART: usize = 12;

/// Nodes `first .. first + MESH_PART` (those below `nodes`) of the live patch at `tick`:
/// each free node's rest position plus its displacement, in the patch's frame, Q24 mm
/// (`x, y, z`). The parts of one mesh share `seq` and `tick`; a mesh the device could
/// not send is counted in the telemetry's drops and its `seq` skipped.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct MeshPart {
    /// Counts meshes, sent or dropped: a gap is a drop.
    pub seq: u32,
    /// The tick the positions are from.
    pub tick: u32,
    /// The first node in this part.
    pub first: u16,
    /// The nodes in the whole mesh.
    pub nodes: u16,
    /// Positions, Q24 mm; past `nodes − first`, zero.
    pub positions: [[i32; 3]; MESH_PART],
}

/// The core a device runs on.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Core {
    /// Cortex-M0.
    M0,
    /// Cortex-M3.
    M3,
    /// Cortex-M4F.
    M4f,
}

impl Core {
    /// Its name in lines: `m0`, `m3`, `m4f`.
    pub const fn name(self) -> &'static str {
        match self {
            Self::M0 => "m0",
            Self::M3 => "m3",
            Self::M4f => "m4f",
        }
    }
}

/// The answer to `Hello`.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq)]
pub struct HelloInfo {
    /// [`crate::PROTOCOL`] of the device.
    pub protocol: u16,
    /// [`crate::SCHEMA`] of the device.
    pub schema: u32,
    /// Its core.
    pub core: Core,
    /// Its tick rate, Hz.
    pub tick_hz: u32,
    /// The live patch's side, nodes.
    pub grid: u8,
    /// The largest patch side a replay may ask for.
    pub max_grid: u8,
    /// The live tissue's size, nodes (the patch alone: `grid × grid`).
    pub tissue_w: u8,
    /// See `tissue_w`.
    pub tissue_h: u8,
    /// The force table's knots.
    pub knots: u16,
    /// The live tissue's hash ([`crate::table_bytes::hash`]).
    pub tissue: u32,
    /// Path samples the device buffers for a replay.
    pub path_capacity: u32,
}

/// Why the device refused.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq)]
pub enum NakReason {
    /// A replay or a load is under way.
    Busy,
    /// A chunk out of order, or a commit without a begin.
    Order,
    /// The bytes received are not the length announced, or not a table's.
    Length,
    /// The bytes' hash is not the one announced.
    Hash,
    /// The table has another knot count than the device's.
    Segments,
    /// The table's own check refused it (`ForceTable::validate`).
    Table,
    /// Its recorded error is over the product's bound, or unmeasured.
    Bound,
    /// The solver refused it on the device's patch (its substeps or coefficients).
    Solver,
    /// A replay without a tissue.
    NoTissue,
    /// A replay asks for more than the device holds: the option, and its limit.
    Option {
        /// The option at fault.
        option: SpecOption,
        /// The device's limit for it.
        limit: i32,
    },
}

impl NakReason {
    /// In words, for the host's one line.
    pub const fn message(self) -> &'static str {
        match self {
            Self::Busy => "the device is busy with a replay or a load",
            Self::Order => "a piece out of order, or a commit without a begin",
            Self::Length => "the bytes received are not the length announced",
            Self::Hash => "the bytes' hash is not the one announced",
            Self::Segments => "the table's knot count is not the device's",
            Self::Table => "the table failed its own check (ForceTable::validate)",
            Self::Bound => "the table's recorded error is over the product's bound, or unmeasured",
            Self::Solver => "the device's solver refused the tissue on its patch",
            Self::NoTissue => "no tissue",
            Self::Option { .. } => "the device does not hold that option's value",
        }
    }
}

/// An option of a replay the device may not hold.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpecOption {
    /// `--grid`.
    Grid,
    /// `--spacing`.
    Spacing,
    /// `--rate`.
    Rate,
    /// `--node-mass`.
    NodeMass,
    /// `--arith`.
    Arith,
    /// `--tissue`.
    Tissue,
    /// `--cap-radius`.
    CapRadius,
    /// The path's length.
    Samples,
    /// The solver's configuration as a whole (its substeps).
    Config,
}

impl SpecOption {
    /// The host's option it stands for.
    pub const fn flag(self) -> &'static str {
        match self {
            Self::Grid => "--grid",
            Self::Spacing => "--spacing",
            Self::Rate => "--rate",
            Self::NodeMass => "--node-mass",
            Self::Arith => "--arith",
            Self::Tissue => "--tissue",
            Self::CapRadius => "--cap-radius",
            Self::Samples => "--probe",
            Self::Config => "--rate",
        }
    }
}

/// The device's counters.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct StatusInfo {
    /// Ticks run.
    pub ticks: u32,
    /// Ticks that overran.
    pub overruns: u32,
    /// Frames dropped: a bad CRC, COBS, length or message.
    pub bad_frames: u32,
    /// Telemetry messages dropped because transmit was busy.
    pub dropped_telemetry: u32,
    /// Whether a host holds the device armed.
    pub armed: bool,
    /// Whether the device is in its safe state after a fault.
    pub fault: bool,
    /// Whether a replay runs.
    pub replaying: bool,
    /// The tissue's origin the host last set (Q24 mm; the tick moves toward it).
    pub pose: [i32; 3],
}

/// A live tick.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Telemetry {
    /// Counts telemetry messages, sent or dropped: a gap is a drop.
    pub seq: u32,
    /// The tick.
    pub tick: u32,
    /// The probe in the tissue frame, Q24 mm.
    pub probe: [i32; 3],
    /// The force rendered, Q20 N.
    pub force: [i32; 3],
    /// The link's force gain, Q15 (32768: full; it fades to 0 when a host falls silent).
    pub gain: u16,
    /// Bit 0: in contact; bit 1: slipping; bit 2: armed; bit 3: fault.
    pub flags: u8,
    /// Telemetry dropped so far.
    pub dropped: u32,
}

/// A replay tick's raw outputs; the host prints them as `mccs replay` does.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ReplayRow {
    /// The tick (0: the path's first sample).
    pub tick: u32,
    /// The device force, Q20 N.
    pub force: [i32; 3],
    /// Glued: the contact node's displacement; roaming: the proxy point in the window's
    /// frame (when bit 2 of `flags`), Q24 mm.
    pub point: [i32; 3],
    /// Roaming: the window's origin, Q24 mm.
    pub origin: [i32; 2],
    /// The displacement of the node that moved most, Q24 mm.
    pub max_disp: [i32; 3],
    /// Bit 0: in contact; bit 1: slipping; bit 2: `point` holds a proxy.
    pub flags: u8,
    /// Roaming: the window's shifts so far.
    pub shifts: u32,
}

/// The patch and solver of a replay: `mccs replay`'s options.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq)]
pub struct ReplaySpec {
    /// `--grid`.
    pub grid: u8,
    /// `--spacing`, mm.
    pub spacing_mm: f64,
    /// `--rate`, Hz.
    pub tick_hz: f64,
    /// `--node-mass`, kg.
    pub node_mass_kg: f64,
    /// `--spring-damping`, N·s/m.
    pub spring_damping: f64,
    /// `--coupling-stiffness`, N/mm.
    pub coupling_stiffness: f64,
    /// `--coupling-damping`, N·s/m.
    pub coupling_damping: f64,
    /// `--max-force`, N.
    pub max_force: f64,
    /// `--integrator symplectic-damped`.
    pub symplectic: bool,
    /// `--arith narrow`.
    pub narrow: bool,
    /// Path samples (ticks) to come.
    pub samples: u32,
    /// The first sample's `x, y`, mm, as the host read it: where a roaming window
    /// starts (the host's own replay starts it there, before any rounding).
    pub start: [f64; 2],
    /// `--tissue` and its options.
    pub roaming: Option<RoamSpec>,
}

/// A roaming replay's tissue, friction and probe.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq)]
pub struct RoamSpec {
    /// Tissue nodes along `x`.
    pub tissue_w: u8,
    /// Tissue nodes along `y`.
    pub tissue_h: u8,
    /// Static friction.
    pub mu_s: f64,
    /// Kinetic friction.
    pub mu_k: f64,
    /// Probe radius, mm.
    pub probe_radius: f64,
    /// A spherical cap's radius, mm (none: flat).
    pub cap_radius: Option<f64>,
}
