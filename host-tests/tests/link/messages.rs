//! One of every message, each with every field away from its default and its name, for
//! the codec's tests and the protocol page's example frames. A new variant does not
//! compile until it is added here ([`covers_to_device`], [`covers_to_host`]).

use mccs_link::*;

/// The index of a message to the device: every variant named, no wildcard.
pub fn covers_to_device(m: &ToDevice) -> usize {
    match m {
        ToDevice::Hello => 0,
        ToDevice::Status => 1,
        ToDevice::Arm => 2,
        ToDevice::Disarm => 3,
        ToDevice::Pose(_) => 4,
        ToDevice::TissueBegin(_) => 5,
        ToDevice::TissueChunk { .. } => 6,
        ToDevice::TissueCommit => 7,
        ToDevice::Watch { .. } => 8,
        ToDevice::ReplayBegin(_) => 9,
        ToDevice::ReplayPath { .. } => 10,
        ToDevice::WatchMesh { .. } => 11,
        ToDevice::Keepalive => 12,
        ToDevice::BlackBox { .. } => 13,
    }
}

/// The index of a message to the host: every variant named, no wildcard.
pub fn covers_to_host(m: &ToHost) -> usize {
    match m {
        ToHost::Hello(_) => 0,
        ToHost::Ack { .. } => 1,
        ToHost::Nak(_) => 2,
        ToHost::Status(_) => 3,
        ToHost::Telemetry(_) => 4,
        ToHost::ReplayRow(_) => 5,
        ToHost::ReplayCredit { .. } => 6,
        ToHost::ReplayEnd { .. } => 7,
        ToHost::Mesh(_) => 8,
        ToHost::BlackBox(_) => 9,
    }
}

/// Every refusal: every variant named, no wildcard.
pub fn covers_nak(r: &NakReason) -> usize {
    match r {
        NakReason::Busy => 0,
        NakReason::Order => 1,
        NakReason::Length => 2,
        NakReason::Hash => 3,
        NakReason::Segments => 4,
        NakReason::Table => 5,
        NakReason::Bound => 6,
        NakReason::Solver => 7,
        NakReason::NoTissue => 8,
        NakReason::Option { .. } => 9,
        NakReason::Budget { .. } => 10,
        NakReason::Stability { .. } => 11,
        NakReason::Friction => 12,
        NakReason::Pose { .. } => 13,
        NakReason::Rotation => 14,
    }
}

static BYTES: [u8; 5] = [1, 0, 2, 0xFF, 0];

/// A replay's spec, every field set.
pub fn spec() -> ReplaySpec {
    ReplaySpec {
        grid: 5,
        spacing_mm: 2.5,
        tick_hz: 1000.0,
        node_mass_kg: 0.005,
        spring_damping: 1.0,
        coupling_stiffness: 1.0,
        coupling_damping: 0.5,
        max_force: 10.0,
        symplectic: true,
        narrow: false,
        samples: 7401,
        start: [-15.0, 0.4],
        roaming: Some(RoamSpec {
            tissue_w: 64,
            tissue_h: 63,
            mu_s: 0.6,
            mu_k: 0.4,
            probe_radius: 0.5,
            cap_radius: Some(300.0),
        }),
    }
}

/// A device's hello, as the arm board sends it.
pub fn hello() -> HelloInfo {
    HelloInfo {
        protocol: PROTOCOL,
        schema: SCHEMA,
        device: DeviceKind::Arm,
        simulated: false,
        core: Core::M4f,
        tick_hz: 1000,
        contact: ContactKind::Roaming,
        grid: 8,
        max_grid: 8,
        spacing: 5 << 23,
        tissue_w: 64,
        tissue_h: 64,
        knots: 65,
        tissue: 0x1234_5678,
        friction: Friction::new(0.6, 0.4),
        substeps: 3,
        solver: SolverInfo {
            node_mass_kg: 0.005,
            spring_damping: 1.0,
            node_damping: 0.05,
            coupling_stiffness: 1.0,
            coupling_damping: 0.5,
            symplectic: false,
            max_substeps: 64,
        },
        path_capacity: 128,
        force_clamp: 3 << 20,
        workspace: [
            [-50 << 24, -50 << 24, -40 << 24],
            [50 << 24, 50 << 24, 40 << 24],
        ],
        pose_speed_mm_s: 200,
        pose_turn_deg_s: 180,
        baud: 1_000_000,
        telemetry_least_every: 3,
        mesh_least_every: 18,
        tick_budget: 84_000,
        substep_cost: 18_000,
        tick_base_cost: 27_000,
    }
}

/// One of every message to the device, named.
pub fn to_device() -> Vec<(&'static str, ToDevice<'static>)> {
    vec![
        ("ToDevice::Hello", ToDevice::Hello),
        ("ToDevice::Status", ToDevice::Status),
        ("ToDevice::Arm", ToDevice::Arm),
        ("ToDevice::Disarm", ToDevice::Disarm),
        (
            "ToDevice::Pose",
            ToDevice::Pose(Pose::from_mm_deg([10.0, -5.0, 2.5], [0.0, 15.0, 0.0])),
        ),
        (
            "ToDevice::TissueBegin",
            ToDevice::TissueBegin(TissueBegin {
                segments: 64,
                len: 1112,
                hash: 0xDEAD_BEEF,
                friction: Some(Friction::new(0.6, 0.4)),
                substeps: 3,
            }),
        ),
        (
            "ToDevice::TissueChunk",
            ToDevice::TissueChunk {
                offset: 200,
                bytes: &BYTES,
            },
        ),
        ("ToDevice::TissueCommit", ToDevice::TissueCommit),
        ("ToDevice::Watch", ToDevice::Watch { every: 10 }),
        ("ToDevice::ReplayBegin", ToDevice::ReplayBegin(spec())),
        (
            "ToDevice::ReplayPath",
            ToDevice::ReplayPath {
                first: 16,
                points: &BYTES,
            },
        ),
        ("ToDevice::WatchMesh", ToDevice::WatchMesh { every: 17 }),
        ("ToDevice::Keepalive", ToDevice::Keepalive),
        ("ToDevice::BlackBox", ToDevice::BlackBox { first: 496 }),
    ]
}

/// One of every refusal, named.
pub fn naks() -> Vec<(&'static str, NakReason)> {
    vec![
        ("NakReason::Busy", NakReason::Busy),
        ("NakReason::Order", NakReason::Order),
        ("NakReason::Length", NakReason::Length),
        ("NakReason::Hash", NakReason::Hash),
        ("NakReason::Segments", NakReason::Segments),
        ("NakReason::Table", NakReason::Table),
        ("NakReason::Bound", NakReason::Bound),
        ("NakReason::Solver", NakReason::Solver),
        ("NakReason::NoTissue", NakReason::NoTissue),
        (
            "NakReason::Option",
            NakReason::Option {
                option: SpecOption::Grid,
                limit: 8,
            },
        ),
        (
            "NakReason::Budget",
            NakReason::Budget {
                substeps: 5,
                instructions: 117_000,
                budget: 84_000,
            },
        ),
        ("NakReason::Stability", NakReason::Stability { substeps: 2 }),
        ("NakReason::Friction", NakReason::Friction),
        (
            "NakReason::Pose",
            NakReason::Pose {
                axis: 2,
                limit: 40 << 24,
            },
        ),
        ("NakReason::Rotation", NakReason::Rotation),
    ]
}

/// One of every message to the host, named (every refusal among them).
pub fn to_host() -> Vec<(&'static str, ToHost)> {
    let mut v = vec![
        ("ToHost::Hello", ToHost::Hello(hello())),
        (
            "ToHost::Ack",
            ToHost::Ack {
                tissue: 0x1234_5678,
            },
        ),
    ];
    v.extend(naks().into_iter().map(|(n, r)| (n, ToHost::Nak(r))));
    v.extend([
        (
            "ToHost::Status",
            ToHost::Status(StatusInfo {
                ticks: 12_345,
                overruns: 2,
                bad_frames: 3,
                dropped_telemetry: 4,
                dropped_mesh: 5,
                rx_dropped: 6,
                armed: true,
                fault: FaultReason::None,
                replaying: false,
                checking: true,
                pose: Pose::from_mm_deg([10.0, -5.0, 2.5], [0.0, 15.0, 0.0]),
                gain: 1 << 15,
            }),
        ),
        (
            "ToHost::Telemetry",
            ToHost::Telemetry(Telemetry {
                seq: 7,
                tick: 12_345,
                probe: [-15 << 24, 6_710_886, -1 << 24],
                force: [-314_573, 0, 786_432],
                gain: 1 << 15,
                flags: Flags::CONTACT | Flags::SLIPPING | Flags::ARMED | Flags::HOMED,
                fault: FaultReason::None,
                duties: [0, -1738, 1983],
                proxy: [-14 << 24, 6_710_886, -1 << 23],
                window: [-15 << 24, 0],
                dropped: 0,
            }),
        ),
        (
            "ToHost::ReplayRow",
            ToHost::ReplayRow(ReplayRow {
                tick: 1,
                force: [-1, 2 << 20, 0],
                point: [1, 2, 3],
                origin: [-4, 5],
                max_disp: [6, 7, -8],
                flags: replay::CONTACT | replay::PROXY,
                shifts: 22,
            }),
        ),
        ("ToHost::ReplayCredit", ToHost::ReplayCredit { until: 128 }),
        ("ToHost::ReplayEnd", ToHost::ReplayEnd { ticks: 7401 }),
        (
            "ToHost::Mesh",
            ToHost::Mesh(MeshPart {
                seq: 3,
                tick: 1700,
                first: 12,
                nodes: 36,
                origin: [-15 << 24, 0],
                grid: core::array::from_fn(|k| [(3 + k / 6) as u8, (1 + k % 6) as u8]),
                positions: core::array::from_fn(|k| {
                    [(k as i32 - 6) << 23, 7 << 22, -(k as i32) << 18]
                }),
            }),
        ),
        (
            "ToHost::BlackBox",
            ToHost::BlackBox(BlackBoxPart {
                kept: true,
                reset_flags: 1 << 29,
                cause: StopCause::Read,
                part: 22,
                tick: 2_599,
                end: StopCause::HardFault,
                end_tick: 2_700,
                pc: 0x0800_1234,
                ticks: 500,
                first: 496,
                part_ticks: core::array::from_fn(|k| BoxTick {
                    tick: 2_596 + k as u32,
                    counts: [k as i32, -1_000, 2_000],
                    force_mn: [0, -5, 1_200],
                    duty_q15: [0, -1_738, 1_983],
                    gain: 1 << 15,
                    flags: black_box::box_flags::HOMED,
                }),
            }),
        ),
    ]);
    v
}
