//! What the device tells about itself: [`HelloInfo`] (what it is, its limits, its rates),
//! [`StatusInfo`] (its counters), [`Telemetry`] (a live tick) and [`MeshPart`] (the live
//! patch's nodes, for the visuals).

use crate::flags::Flags;
use crate::tissue::{Friction, Pose};
use postcard_schema::Schema;
use serde::{Deserialize, Serialize};

/// The core a device runs on.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq, Eq)]
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

/// What the device is.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq, Eq)]
pub enum DeviceKind {
    /// One axis: the probe moves along `z` only (a lever on an encoder and a motor).
    OneDof,
    /// A 3-DOF arm (WoodenHaptics-style: three revolute joints).
    Arm,
}

impl DeviceKind {
    /// Its name in lines: `1dof`, `arm`.
    pub const fn name(self) -> &'static str {
        match self {
            Self::OneDof => "1dof",
            Self::Arm => "arm",
        }
    }
}

/// How the probe touches the tissue.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactKind {
    /// Glued to the patch's contact node through a spring (the indentation test's
    /// contact: the 1-DOF device, which renders `z` only).
    Glued,
    /// Through a proxy that slides on a larger tissue with friction, the patch following
    /// it as a window.
    Roaming,
}

impl ContactKind {
    /// Its name in lines: `glued`, `roaming`.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Glued => "glued",
            Self::Roaming => "roaming",
        }
    }
}

/// Why a device is in its safe state.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FaultReason {
    /// No fault.
    #[default]
    None,
    /// The device could not read the probe.
    Read,
    /// The device could not render the force.
    Write,
    /// Ticks overran their period too many times in a row.
    Overruns,
    /// The drive was cut outside the MCU: the emergency stop or an amplifier's fault
    /// output tripped TIM1's break input.
    Amplifier,
}

impl FaultReason {
    /// In words.
    pub const fn message(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Read => "device read failed",
            Self::Write => "device write failed",
            Self::Overruns => "ticks overran their period too many times in a row",
            Self::Amplifier => {
                "the emergency stop or an amplifier fault cut the drive (break input)"
            }
        }
    }

    /// Its name in lines.
    pub const fn name(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Read => "read",
            Self::Write => "write",
            Self::Overruns => "overruns",
            Self::Amplifier => "amplifier",
        }
    }
}

/// The answer to `Hello`: what the device is, what it takes and how fast it talks.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq)]
pub struct HelloInfo {
    /// [`crate::PROTOCOL`] of the device.
    pub protocol: u16,
    /// [`crate::SCHEMA`] of the device.
    pub schema: u32,
    /// What it is.
    pub device: DeviceKind,
    /// Its plant is simulated (a QEMU build): no hand feels it.
    pub simulated: bool,
    /// Its core.
    pub core: Core,
    /// Its tick rate, Hz.
    pub tick_hz: u32,
    /// How its probe touches the tissue.
    pub contact: ContactKind,
    /// The live patch's side, nodes.
    pub grid: u8,
    /// The largest patch side a replay may ask for.
    pub max_grid: u8,
    /// The patch's (and tissue's) node spacing, Q24 mm.
    pub spacing: i32,
    /// The live tissue's size, nodes (glued: the patch alone, `grid × grid`).
    pub tissue_w: u8,
    /// See `tissue_w`.
    pub tissue_h: u8,
    /// The force table's knots (a tissue load must carry as many).
    pub knots: u16,
    /// The live tissue's hash ([`crate::table_bytes::hash`]).
    pub tissue: u32,
    /// The live tissue's friction.
    pub friction: Friction,
    /// Substeps per tick the live tissue runs.
    pub substeps: u16,
    /// The live solver's configuration: what a host needs to compute the substeps a
    /// tissue needs on this device, and propose them with the tissue.
    pub solver: SolverInfo,
    /// Path samples the device buffers for a replay.
    pub path_capacity: u32,
    /// The largest force it renders on any axis, Q20 N.
    pub force_clamp: i32,
    /// Where a pose's origin may be, Q24 mm in the device's frame: the low corner, then
    /// the high corner.
    pub workspace: [[i32; 3]; 2],
    /// The pose's slew limits: mm/s of its origin, degrees/s of its rotation.
    pub pose_speed_mm_s: u16,
    /// See `pose_speed_mm_s`.
    pub pose_turn_deg_s: u16,
    /// The link's baud rate (8N1: a tenth of it is bytes a second).
    pub baud: u32,
    /// The fewest ticks between two telemetry messages the byte budget allows.
    pub telemetry_least_every: u16,
    /// The fewest ticks between two meshes the byte budget allows.
    pub mesh_least_every: u16,
    /// Instructions a tick may spend on the patch (the device's tick budget).
    pub tick_budget: u32,
    /// Instructions one substep of the patch costs on this device, and what the rest of
    /// its tick costs: a tissue needing `n` substeps runs in `base + n × substep`.
    pub substep_cost: u32,
    /// See `substep_cost`.
    pub tick_base_cost: u32,
}

/// A device's solver configuration, as `mccs::SolverConfig` holds it (the tick rate and
/// the force clamp are in [`HelloInfo`]).
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq)]
pub struct SolverInfo {
    /// Each free node's haptic mass, kg.
    pub node_mass_kg: f64,
    /// Each spring's relative-velocity damping, N·s/m.
    pub spring_damping: f64,
    /// Each node's absolute damping, N·s/m.
    pub node_damping: f64,
    /// The probe coupling's stiffness, N/mm.
    pub coupling_stiffness: f64,
    /// The probe coupling's damping, N·s/m.
    pub coupling_damping: f64,
    /// The symplectic integrator (`Integrator::SymplecticDamped`), not the paper's.
    pub symplectic: bool,
    /// The most substeps a tick the stability bound may ask for.
    pub max_substeps: u16,
}

/// The device's counters and state.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct StatusInfo {
    /// Ticks run, wrapping at 2³² (49.7 days at 1 kHz).
    pub ticks: u32,
    /// Ticks that overran.
    pub overruns: u32,
    /// Frames dropped: a bad CRC, COBS, length or message.
    pub bad_frames: u32,
    /// Telemetry messages dropped (the main loop late, or transmit busy).
    pub dropped_telemetry: u32,
    /// Meshes dropped.
    pub dropped_mesh: u32,
    /// Received bytes dropped because the receive queue was full.
    pub rx_dropped: u32,
    /// Whether a host holds the device armed.
    pub armed: bool,
    /// Why the device is in its safe state, if it is.
    pub fault: FaultReason,
    /// Whether a replay runs.
    pub replaying: bool,
    /// Whether a tissue is being checked.
    pub checking: bool,
    /// The pose the host last set (the tick moves toward it).
    pub pose: Pose,
    /// The link's force gain now, Q15.
    pub gain: u16,
}

/// A live tick.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Telemetry {
    /// Counts telemetry messages, sent or dropped: a gap is a drop.
    pub seq: u32,
    /// The tick (the count `StatusInfo::ticks` gives, wrapping at 2³²).
    pub tick: u32,
    /// The probe in the tissue's frame, Q24 mm.
    pub probe: [i32; 3],
    /// The force rendered, in the device's frame, the gain applied, Q20 N.
    pub force: [i32; 3],
    /// The link's force gain, Q15 (32768: full; it fades to 0 when a host falls silent
    /// and ramps up after `Arm`).
    pub gain: u16,
    /// What the tick says of itself.
    pub flags: Flags,
    /// Why the device is in its safe state (`None` when not).
    pub fault: FaultReason,
    /// The arm's joint duties last written, Q16 (zero on the 1-DOF device).
    pub duties: [i32; 3],
    /// The proxy (the contact point on the surface) in the tissue's frame, Q24 mm; valid
    /// with [`Flags::CONTACT`] on a roaming device.
    pub proxy: [i32; 3],
    /// The window's origin (the patch's centre) in the tissue's frame, Q24 mm.
    pub window: [i32; 2],
    /// Telemetry dropped so far.
    pub dropped: u32,
}

/// Nodes one [`MeshPart`] carries (its frame stays within [`crate::MAX_FRAME`]).
pub const MESH_PART: usize = 12;

/// Nodes `first .. first + MESH_PART` (those below `nodes`) of the live patch at `tick`:
/// each free node's position (rest plus displacement) in the patch's frame, whose origin
/// is at `origin` in the tissue's frame, and the node's place in the patch's
/// `grid × grid` surface grid (`(i, j)`, the fixed outer ring at 0 and `grid − 1`), so
/// that a scene can draw the triangles of the grid. The parts of one mesh share `seq`
/// and `tick`; a mesh the device could not send is counted as dropped and its `seq`
/// skipped.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct MeshPart {
    /// Counts meshes, sent or dropped: a gap is a drop.
    pub seq: u32,
    /// The tick the positions are from (wrapping at 2³², as `StatusInfo::ticks`).
    pub tick: u32,
    /// The first node in this part.
    pub first: u16,
    /// The nodes in the whole mesh.
    pub nodes: u16,
    /// The patch frame's origin in the tissue's frame (`x, y`), Q24 mm.
    pub origin: [i32; 2],
    /// Each node's `(i, j)` in the surface grid; past `nodes − first`, zero.
    pub grid: [[u8; 2]; MESH_PART],
    /// Positions, Q24 mm; past `nodes − first`, zero.
    pub positions: [[i32; 3]; MESH_PART],
}
