//! The device's side of the link on the host: the guard's fade, the pose's bounded step,
//! a tissue load checked whole (every refusal keeps the live tissue), and a replay on
//! the device's solver equal, row for row, to `mccs replay --backend fixed`.

use mccs::{Force, ForceTable64, Length, Params, SolverConfig, Wide};
use mccs_firmware::link::{guard, Effect, Guard, LinkedDevice, Live, Now, Replayer, Session};
use mccs_firmware::HapticDevice;
use mccs_host::replay::{probe_bits, Engine, Replay, RoamRow, Roaming, Row};
use mccs_host::roam::{Friction, Shape, Tissue};
use mccs_host::trajectory;
use mccs_link::message::*;
use mccs_link::table_bytes;

/// The board's capacity: the N = 8 patch.
const N: usize = mccs::topology::standard_capacity(8).0;
const E: usize = mccs::topology::standard_capacity(8).1;
const P: usize = 64;

fn live() -> Live {
    Live {
        core: Core::M4f,
        grid: 5,
        spacing: 2.5,
        config: SolverConfig::default(),
    }
}

#[test]
fn an_armed_hosts_silence_fades_the_force_within_120_ms() {
    let mut g = Guard::at_rate(1000);
    // Standalone: full force, however long the silence.
    assert_eq!(g.gain(1_000_000), guard::FULL);
    g.arm(10);
    let mut zero_at = None;
    for t in 10..400 {
        if t < 60 {
            g.frame(t);
        }
        let gain = g.gain(t);
        if t <= 159 {
            assert_eq!(gain, guard::FULL, "tick {t}");
        }
        if gain == 0 && zero_at.is_none() {
            zero_at = Some(t);
        }
    }
    let zero_at = zero_at.expect("never zero");
    // Silent from tick 59: the force is zero within 120 ticks (100 + the 20-tick fade).
    assert!(
        zero_at - 59 <= 120,
        "zero {} ticks after the last frame",
        zero_at - 59
    );
    assert!(!g.armed());
    // A frame alone does not re-arm; Arm does.
    g.frame(500);
    assert_eq!(g.gain(501), 0);
    g.arm(502);
    assert_eq!(g.gain(503), guard::FULL);
    g.disarm();
    assert_eq!(g.gain(504), 0);
}

/// A device that records what it was asked to render.
#[derive(Default)]
struct Probe {
    at: [Length; 3],
    written: Vec<[Force; 3]>,
}

impl HapticDevice for Probe {
    type Error = ();
    fn read_position(&mut self) -> Result<[Length; 3], ()> {
        Ok(self.at)
    }
    fn write_force(&mut self, f: [Force; 3]) -> Result<(), ()> {
        self.written.push(f);
        Ok(())
    }
    fn safe_state(&mut self) -> Result<(), ()> {
        Ok(())
    }
}

#[test]
fn the_pose_moves_by_a_bounded_step_and_the_gain_keeps_the_force_s_sign() {
    let mut d = LinkedDevice::new(Probe::default(), 0.01);
    d.set_target([
        Length::from_num(1.0).to_bits(),
        0,
        Length::from_num(-0.025).to_bits(),
    ]);
    let mut last = 0.0;
    for tick in 1..=150 {
        let p = d.read_position().unwrap();
        let x = -p[0].to_num::<f64>();
        assert!(
            x - last <= 0.01 + 1e-7,
            "tick {tick}: a step of {}",
            x - last
        );
        last = x;
    }
    assert_eq!(
        d.origin()[0],
        Length::from_num(1.0).to_bits(),
        "reached after 100 ticks"
    );
    assert_eq!(d.origin()[2], Length::from_num(-0.025).to_bits());
    for gain in [0u16, 1, 16384, 32767, 32768] {
        d.set_gain(gain);
        let f = [
            Force::from_num(-1.5),
            Force::from_num(2.0),
            Force::from_bits(-1),
        ];
        d.write_force(f).unwrap();
        let w = *d.inner().written.last().unwrap();
        for k in 0..3 {
            assert!(
                w[k].to_bits().signum() * f[k].to_bits().signum() >= 0,
                "sign flipped"
            );
            assert!(w[k].abs() <= f[k].abs());
        }
    }
}

/// Sends a table to a session as a host does; the answers and the effect of the commit.
fn load(
    s: &mut Session<64>,
    table: &ForceTable64,
    corrupt: impl Fn(&mut Vec<u8>, &mut u32),
) -> (Vec<ToHost>, Option<Effect<64, Wide>>) {
    let mut bytes = vec![0u8; table_bytes::len(64)];
    table_bytes::write(table, &mut bytes);
    let mut hash = table_bytes::hash(table);
    corrupt(&mut bytes, &mut hash);
    let mut r = Replayer::<N, E, 64, Wide, P>::new(false);
    let mut out = Vec::new();
    let mut send = |m: &ToHost| out.push(*m);
    let now = Now::default();
    s.handle(
        ToDevice::TissueBegin {
            segments: 64,
            len: bytes.len() as u32,
            hash,
        },
        now,
        &mut r,
        &mut send,
    );
    for (i, c) in bytes.chunks(200).enumerate() {
        s.handle(
            ToDevice::TissueChunk {
                offset: (i * 200) as u32,
                bytes: c,
            },
            now,
            &mut r,
            &mut send,
        );
    }
    let e = s.handle(ToDevice::TissueCommit, now, &mut r, &mut send);
    (out, Some(e))
}

#[test]
fn a_tissue_is_checked_whole_before_the_tick_sees_it() {
    let t2 = ForceTable64::new(&Params::TABLE2).unwrap();
    let mut s = Session::<64>::new(live(), t2);
    let old = s.tissue().1;
    let stiffer = ForceTable64::new(
        &mccs_host::paramfile::read(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../params/table2-stiffer.toml"
        )))
        .unwrap(),
    )
    .unwrap();
    // A good load: the set for the live patch, named by its hash.
    let (out, e) = load(&mut s, &stiffer, |_, _| {});
    assert!(out.is_empty(), "{out:?}");
    match e {
        Some(Effect::Swap { tissue, set }) => {
            assert_eq!(tissue, table_bytes::hash(&stiffer));
            assert_eq!(set.table().raw(), stiffer.raw());
        }
        other => panic!("{other:?}"),
    }
    // Refusals: each a Nak with its reason, the live tissue unchanged.
    let refused =
        |s: &mut Session<64>, table: &ForceTable64, corrupt: &dyn Fn(&mut Vec<u8>, &mut u32)| {
            let (out, e) = load(s, table, corrupt);
            assert_eq!(e, Some(Effect::None));
            assert_eq!(s.tissue().1, old);
            match out.last() {
                Some(ToHost::Nak(r)) => *r,
                other => panic!("{other:?}"),
            }
        };
    assert_eq!(
        refused(&mut s, &stiffer, &|b, _| b[100] ^= 1),
        NakReason::Hash
    );
    assert_eq!(refused(&mut s, &stiffer, &|_, h| *h ^= 1), NakReason::Hash);
    // A table that breaks its own invariants (its hash made to match).
    let broken = |b: &mut Vec<u8>, h: &mut u32| {
        b[8..12].copy_from_slice(&3u32.to_le_bytes()); // index_pre: not a power of two
        *h = table_bytes::hash_bytes(b);
    };
    assert_eq!(refused(&mut s, &stiffer, &broken), NakReason::Table);
    // A table with no measured error, or over the bound.
    let law = mccs::Law::new(&Params::TABLE2).unwrap();
    let unmeasured = ForceTable64::one_placement_unmeasured(&law, -0.5, 0.95).unwrap();
    assert_eq!(refused(&mut s, &unmeasured, &|_, _| {}), NakReason::Bound);
    // A tissue the live patch cannot run at its tick (its substeps).
    let stiff = ForceTable64::new(
        &mccs_host::paramfile::read(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../params/steep-kink.toml"
        )))
        .unwrap(),
    )
    .unwrap();
    assert_eq!(refused(&mut s, &stiff, &|_, _| {}), NakReason::Solver);
    // Pieces out of order; a commit without a begin.
    let mut r = Replayer::<N, E, 64, Wide, P>::new(false);
    let mut out = Vec::new();
    let mut send = |m: &ToHost| out.push(*m);
    s.handle(
        ToDevice::TissueBegin {
            segments: 64,
            len: 1112,
            hash: 0,
        },
        Now::default(),
        &mut r,
        &mut send,
    );
    s.handle(
        ToDevice::TissueChunk {
            offset: 4,
            bytes: &[0; 4],
        },
        Now::default(),
        &mut r,
        &mut send,
    );
    s.handle(ToDevice::TissueCommit, Now::default(), &mut r, &mut send);
    s.handle(
        ToDevice::TissueBegin {
            segments: 32,
            len: 1112,
            hash: 0,
        },
        Now::default(),
        &mut r,
        &mut send,
    );
    assert_eq!(
        out,
        vec![
            ToHost::Nak(NakReason::Order),
            ToHost::Nak(NakReason::Order),
            ToHost::Nak(NakReason::Segments)
        ]
    );
    assert_eq!(s.tissue().1, old);
}

/// Runs a replay through a session as `mccs link replay` drives it: the spec, the path
/// in pieces within the credit, the rows back.
fn device_replay(spec: ReplaySpec, samples: &[[f64; 3]], table: ForceTable64) -> Vec<ReplayRow> {
    let mut s = Session::<64>::new(live(), table);
    let mut r = Replayer::<N, E, 64, Wide, P>::new(false);
    let mut rows = Vec::new();
    let mut credit = 0;
    let mut sent = 0usize;
    let handle = |s: &mut Session<64>,
                  r: &mut Replayer<N, E, 64, Wide, P>,
                  m: ToDevice,
                  rows: &mut Vec<ReplayRow>,
                  credit: &mut u32| {
        s.handle(m, Now::default(), r, &mut |h: &ToHost| match h {
            ToHost::ReplayCredit { until } => *credit = *until,
            ToHost::Nak(n) => panic!("{n:?}"),
            _ => {}
        });
        let _ = rows;
    };
    handle(
        &mut s,
        &mut r,
        ToDevice::ReplayBegin(spec),
        &mut rows,
        &mut credit,
    );
    let bits: Vec<u8> = samples
        .iter()
        .flat_map(|p| {
            probe_bits(*p)
                .into_iter()
                .flat_map(|c| c.to_bits().to_le_bytes())
        })
        .collect();
    let mut ended = false;
    while !ended {
        while sent < samples.len() && (sent as u32) < credit {
            let n = (credit as usize - sent).min(16).min(samples.len() - sent);
            let chunk = &bits[12 * sent..12 * (sent + n)];
            handle(
                &mut s,
                &mut r,
                ToDevice::ReplayPath {
                    first: sent as u32,
                    points: chunk,
                },
                &mut rows,
                &mut credit,
            );
            sent += n;
        }
        let ran = r.step(&mut |h: &ToHost| match h {
            ToHost::ReplayRow(row) => rows.push(*row),
            ToHost::ReplayCredit { until } => credit = *until,
            ToHost::ReplayEnd { ticks } => {
                assert_eq!(*ticks as usize, samples.len());
                ended = true;
            }
            other => panic!("{other:?}"),
        });
        assert!(
            ran || ended,
            "stalled at {} of {}",
            rows.len(),
            samples.len()
        );
    }
    rows
}

fn spec(samples: u32, start: [f64; 3], roaming: Option<RoamSpec>) -> ReplaySpec {
    let c = SolverConfig::default();
    ReplaySpec {
        grid: 5,
        spacing_mm: 2.5,
        tick_hz: 1000.0,
        node_mass_kg: c.node_mass,
        spring_damping: c.spring_damping,
        coupling_stiffness: c.coupling.stiffness,
        coupling_damping: c.coupling.damping,
        max_force: c.coupling.max_force,
        symplectic: false,
        narrow: false,
        samples,
        start: [start[0], start[1]],
        roaming,
    }
}

#[test]
fn a_replay_on_the_device_is_the_hosts_fixed_replay() {
    let table = ForceTable64::new(&Params::TABLE2).unwrap();
    let traj = trajectory::read(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../params/palpation.csv"
    )))
    .unwrap();
    let ticks: Vec<(f64, [f64; 3])> = traj.ticks(1000.0).collect();
    let samples: Vec<[f64; 3]> = ticks.iter().map(|t| t.1).collect();
    let replay = Replay {
        grid: 5,
        spacing: 2.5,
        config: SolverConfig::default(),
        engine: Engine::Wide,
    };
    // Glued.
    let mut host = Vec::new();
    replay
        .run_with(&Params::TABLE2, Some(&table), &traj, |r: Row| host.push(r))
        .unwrap();
    let dev = device_replay(
        spec(samples.len() as u32, samples[0], None),
        &samples,
        table,
    );
    assert_eq!(dev.len(), host.len());
    for ((h, d), (t, p)) in host.iter().zip(&dev).zip(&ticks) {
        assert_eq!(*h, Row::of_raw(*t, *p, d), "tick {}", d.tick);
    }
    // Roaming with friction on a 64 × 64 tissue.
    let roaming = Roaming {
        tissue: Tissue::new(64, 64, 2.5, Shape::Flat).unwrap(),
        friction: Friction::new(0.6, 0.4).unwrap(),
        probe_radius: 0.0,
    };
    let mut host = Vec::new();
    replay
        .roam_with(
            &Params::TABLE2,
            Some(&table),
            &traj,
            &roaming,
            |r: RoamRow| host.push(r),
        )
        .unwrap();
    let roam = RoamSpec {
        tissue_w: 64,
        tissue_h: 64,
        mu_s: 0.6,
        mu_k: 0.4,
        probe_radius: 0.0,
        cap_radius: None,
    };
    let dev = device_replay(
        spec(samples.len() as u32, samples[0], Some(roam)),
        &samples,
        table,
    );
    assert_eq!(dev.len(), host.len());
    let mut shifts = 0;
    for ((h, d), (t, p)) in host.iter().zip(&dev).zip(&ticks) {
        assert_eq!(*h, RoamRow::of_raw(*t, *p, d), "tick {}", d.tick);
        shifts = d.shifts;
    }
    assert!(shifts > 10, "{shifts} window shifts");
}

#[test]
fn a_replay_beyond_the_device_is_refused_naming_the_option() {
    let table = ForceTable64::new(&Params::TABLE2).unwrap();
    let mut s = Session::<64>::new(live(), table);
    let mut r = Replayer::<N, E, 64, Wide, P>::new(false);
    let mut naks = Vec::new();
    let cases = [
        (
            ReplaySpec {
                grid: 9,
                ..spec(10, [0.0; 3], None)
            },
            SpecOption::Grid,
            8,
        ),
        (
            ReplaySpec {
                narrow: true,
                ..spec(10, [0.0; 3], None)
            },
            SpecOption::Arith,
            0,
        ),
        (
            spec(
                10,
                [0.0; 3],
                Some(RoamSpec {
                    tissue_w: 64,
                    tissue_h: 64,
                    mu_s: 0.0,
                    mu_k: 0.0,
                    probe_radius: 0.0,
                    cap_radius: Some(300.0),
                }),
            ),
            SpecOption::CapRadius,
            0,
        ),
    ];
    for (spec, option, limit) in cases {
        s.handle(
            ToDevice::ReplayBegin(spec),
            Now::default(),
            &mut r,
            &mut |h: &ToHost| naks.push(*h),
        );
        assert_eq!(
            naks.pop(),
            Some(ToHost::Nak(NakReason::Option { option, limit }))
        );
        assert!(!r.running());
    }
    // A path past the credit abandons the replay.
    s.handle(
        ToDevice::ReplayBegin(spec(1000, [0.0; 3], None)),
        Now::default(),
        &mut r,
        &mut |h: &ToHost| naks.push(*h),
    );
    assert_eq!(naks.pop(), Some(ToHost::ReplayCredit { until: P as u32 }));
    let too_many = vec![0u8; 12 * (P + 1)];
    s.handle(
        ToDevice::ReplayPath {
            first: 0,
            points: &too_many,
        },
        Now::default(),
        &mut r,
        &mut |h: &ToHost| naks.push(*h),
    );
    assert_eq!(naks.pop(), Some(ToHost::Nak(NakReason::Order)));
    assert!(!r.running());
}

#[test]
fn telemetry_gaps_are_the_drops() {
    let table = ForceTable64::new(&Params::TABLE2).unwrap();
    let mut s = Session::<64>::new(live(), table);
    let mut r = Replayer::<N, E, 64, Wide, P>::new(false);
    s.handle(
        ToDevice::Watch { every: 10 },
        Now::default(),
        &mut r,
        &mut |_| {},
    );
    let mut got = Vec::new();
    let mut refuse = false;
    // The main loop looks at irregular ticks; the link refuses some messages.
    for tick in [0u32, 5, 10, 35, 40, 41, 77, 80, 200, 210] {
        refuse = !refuse && tick == 80;
        s.telemetry(tick, [0; 3], [0; 3], guard::FULL, 0, &mut |m: &ToHost| {
            if refuse {
                return false;
            }
            if let ToHost::Telemetry(t) = m {
                got.push(*t);
            }
            true
        });
    }
    let last = got.last().unwrap();
    let gaps: u32 = got.windows(2).map(|w| w[1].seq - w[0].seq - 1).sum::<u32>() + got[0].seq;
    assert_eq!(gaps, last.dropped, "{got:?}");
    assert!(last.dropped > 0);
}

/// The mesh for the visuals: at most 60 a second, every free node once per mesh in parts
/// of 12 (rest position plus displacement), the tick's countdown due exactly every
/// `every` ticks, and a mesh the main loop never sent counted as dropped.
#[test]
fn the_mesh_is_every_free_node_at_most_60_times_a_second() {
    use mccs_firmware::link::{Mesh, MeshClock};
    let table = ForceTable64::new(&Params::TABLE2).unwrap();
    let mut s = Session::<64>::new(live(), table);
    let mut r = Replayer::<N, E, 64, Wide, P>::new(false);
    // Asked for every tick at 1 kHz: held to 17 ticks (58.8 a second).
    let effect = s.handle(
        ToDevice::WatchMesh { every: 1 },
        Now::default(),
        &mut r,
        &mut |_| {},
    );
    assert_eq!(effect, Effect::WatchMesh(17));
    let clock = MeshClock::new();
    assert!(!(0..100).any(|_| clock.due()), "never before it is set");
    clock.set(17);
    let at: Vec<u32> = (0..100u32).filter(|_| clock.due()).collect();
    assert_eq!(at, vec![0, 17, 34, 51, 68, 85]);
    // A displaced node: rest plus displacement, in its place among the parts.
    let topo = mccs::Topology::<N, E>::standard_patch(5, 2.5).unwrap();
    let mut solver = mccs::Solver::new(topo, table, &SolverConfig::default()).unwrap();
    let shift = [Length::from_num(0.25), Length::ZERO, Length::from_num(-1)];
    solver.set_state(14, shift, [mccs::Velocity::ZERO; 3]);
    let mesh = Mesh::of(&solver, 34);
    let free = solver.topology().node_count() - 1;
    assert_eq!(mesh.nodes as usize, free);
    let mut parts = Vec::new();
    s.mesh(&mesh, &mut |m: &ToHost| {
        if let ToHost::Mesh(p) = m {
            parts.push(*p);
        }
        true
    });
    assert_eq!(parts.len(), free.div_ceil(12));
    let mut seen = vec![None; free];
    for p in &parts {
        assert_eq!((p.tick, p.nodes, p.seq), (34, free as u16, 0));
        for (k, pos) in p.positions.iter().enumerate() {
            let node = p.first as usize + k;
            if node < free {
                seen[node] = Some(*pos);
            } else {
                assert_eq!(*pos, [0; 3], "past the nodes: zero");
            }
        }
    }
    for (k, pos) in seen.iter().enumerate() {
        let pos = pos.expect("every free node once");
        let rest = solver.topology().rest_q24(k + 1).unwrap();
        let u = if k + 1 == 14 {
            shift.map(|x| x.to_bits())
        } else {
            [0; 3]
        };
        assert_eq!(pos, [0, 1, 2].map(|j| rest[j] + u[j]), "node {k}");
    }
    // The next mesh the main loop sees is two periods on: one was never sent.
    let mut seqs = Vec::new();
    s.mesh(&Mesh::of(&solver, 34 + 2 * 17), &mut |m: &ToHost| {
        if let ToHost::Mesh(p) = m {
            seqs.push(p.seq);
        }
        true
    });
    assert!(seqs.iter().all(|&q| q == 2), "{seqs:?}");
    let mut dropped = 0;
    s.handle(ToDevice::Status, Now::default(), &mut r, &mut |m| {
        if let ToHost::Status(st) = m {
            dropped = st.dropped_telemetry;
        }
    });
    assert_eq!(dropped, 1);
    // Off: no mesh.
    s.handle(
        ToDevice::WatchMesh { every: 0 },
        Now::default(),
        &mut r,
        &mut |_| {},
    );
    let mut any = false;
    s.mesh(&mesh, &mut |_| {
        any = true;
        true
    });
    assert!(!any);
}
