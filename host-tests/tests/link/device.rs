//! The device's side of the link (`mccs_firmware::link`) on the host, tick by tick: the
//! guard's ramp and fade, the pose's slew and frames, what the server answers and when,
//! every refusal with its reason, the tissue check in slices and its budget, the byte
//! budget of the streams, the run of overruns, and replays equal to the host's.

use super::rig::{load, replay_spec as spec, Rig, P};
use haptic_f405::device::{EDGES, NODES};
use haptic_f405::BOARD;
use mccs::{Force, ForceTable64, Length, Params, SolverConfig, TissuePose};
use mccs_client::Tissue;
use mccs_firmware::link::{Guard, GuardTimes};
use mccs_host::replay::{Engine, Replay, RoamRow, Roaming, Row};
use mccs_host::roam::{Friction, Shape, Tissue as RoamTissue};
use mccs_host::trajectory;
use mccs_link::replay::PathPoint;
use mccs_link::scale::{self, GAIN_FULL};
use mccs_link::*;

fn table2() -> ForceTable64 {
    ForceTable64::new(&Params::TABLE2).unwrap()
}

fn params(name: &str) -> Params {
    mccs_host::paramfile::read(std::path::Path::new(&format!(
        "{}/../params/{name}",
        env!("CARGO_MANIFEST_DIR")
    )))
    .unwrap()
}

#[test]
fn force_comes_on_gently_and_an_armed_hosts_silence_fades_it() {
    // 1 kHz: a 100-tick timeout, a 20-tick fade, a 500-tick ramp.
    let mut g = Guard::new(GuardTimes::at_rate(1000, 500));
    // Standalone, the probe in contact from the start: no force until it leaves.
    for t in 0..300 {
        assert_eq!(g.gain(t, true), 0, "tick {t}");
    }
    // Out of contact: the ramp, never a step of more than a 500th.
    let mut last = 0;
    let mut full_at = None;
    for t in 300..1000 {
        let k = g.gain(t, t > 310);
        assert!(
            k >= last && k - last <= GAIN_FULL / 500 + 1,
            "tick {t}: {last} -> {k}"
        );
        if k == GAIN_FULL && full_at.is_none() {
            full_at = Some(t);
        }
        last = k;
    }
    let full_after = full_at.unwrap() - 300;
    assert!(
        (490..500).contains(&full_after),
        "full force {full_after} ticks after release"
    );
    // Armed, frames until tick 2000, then silence: zero within 120 ticks, disarmed.
    g.arm(1000);
    for t in 1000..2000 {
        g.frame(t);
        assert_eq!(g.gain(t, true), GAIN_FULL);
    }
    let zero_at = (2000..3000).find(|&t| g.gain(t, true) == 0).unwrap();
    assert!(
        zero_at - 1999 <= 120,
        "faded after {} ticks",
        zero_at - 1999
    );
    assert!(!g.armed());
    // A frame alone does not re-arm; Arm does, from zero, after the probe leaves.
    g.frame(3000);
    assert_eq!(g.gain(3001, false), 0);
    g.arm(3002);
    assert_eq!(g.gain(3003, true), 0, "in contact: the ramp waits");
    assert!(g.gain(3004, false) > 0);
    // Disarm: zero at once.
    g.disarm();
    assert_eq!(g.gain(3005, false), 0);
}

/// `q` (Q30) as a rotation matrix, in f64.
fn matrix(q: [i32; 4]) -> [[f64; 3]; 3] {
    let [w, x, y, z] = q.map(|c| scale::to_f64(c, scale::QUAT_FRAC));
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

#[test]
fn the_pose_moves_at_its_limits_and_maps_the_probe_and_the_force() {
    let mut pose = TissuePose::new(200.0, 180.0, 1000.0);
    let target = Pose::from_mm_deg([20.0, -10.0, 5.0], [30.0, -20.0, 45.0]);
    pose.set_target(target.origin, target.rotation);
    let step = 200.0 / 1000.0;
    let turn = (180.0f64 / 1000.0).to_radians();
    let (mut o, mut q) = (pose.origin(), pose.rotation());
    let mut ticks = 0;
    while !pose.settled() {
        pose.step();
        ticks += 1;
        assert!(ticks < 2000, "never settled");
        let (o2, q2) = (pose.origin(), pose.rotation());
        for k in 0..3 {
            assert!((scale::mm(o2[k]) - scale::mm(o[k])).abs() <= step + 1e-6);
        }
        // The rotation between two ticks: 2 acos |q·q'|.
        let norm = |q: [i32; 4]| {
            q.iter()
                .map(|&c| scale::to_f64(c, 30).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        let dot: f64 = (0..4)
            .map(|k| scale::to_f64(q[k], 30) * scale::to_f64(q2[k], 30))
            .sum::<f64>()
            / (norm(q) * norm(q2));
        let angle = 2.0 * dot.abs().min(1.0).acos();
        assert!(angle <= turn * 1.001 + 1e-6, "tick {ticks}: {angle} rad");
        let n2: f64 = q2.iter().map(|&c| scale::to_f64(c, 30).powi(2)).sum();
        assert!((n2 - 1.0).abs() < 1e-8, "|q|² = {n2}");
        (o, q) = (o2, q2);
    }
    // 30 mm at 0.2 mm a tick; the rotation's angle (about 62°) at 0.18° a tick.
    assert!((340..=360).contains(&ticks), "{ticks} ticks");
    // The probe into the tissue's frame and the force back, against f64.
    let r = matrix(pose.rotation());
    let origin = pose.origin().map(scale::mm);
    for p in [[0.0, 0.0, 0.0], [12.5, -3.25, 7.0], [-40.0, 60.0, -20.0]] {
        let got = pose
            .to_tissue(p.map(Length::from_num))
            .map(|c| c.to_num::<f64>());
        let d = [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]];
        for i in 0..3 {
            let want: f64 = (0..3).map(|j| r[j][i] * d[j]).sum();
            assert!((got[i] - want).abs() < 1e-5, "{p:?}: {got:?}");
        }
        let f = [1.5, -0.25, 2.0];
        let fd = pose
            .to_device(f.map(Force::from_num))
            .map(|c| c.to_num::<f64>());
        for i in 0..3 {
            let want: f64 = (0..3).map(|j| r[i][j] * f[j]).sum();
            assert!((fd[i] - want).abs() < 1e-5, "{fd:?}");
        }
    }
}

#[test]
fn hello_says_what_the_device_is_its_limits_and_its_rates() {
    let mut rig = Rig::roaming(table2());
    let ToHost::Hello(h) = rig.ask(&ToDevice::Hello, 5, |m| matches!(m, ToHost::Hello(_))) else {
        unreachable!()
    };
    assert_eq!((h.protocol, h.schema), (PROTOCOL, SCHEMA));
    assert_eq!(
        (h.device, h.contact),
        (DeviceKind::Arm, ContactKind::Roaming)
    );
    assert_eq!((h.tissue_w, h.tissue_h), (64, 64));
    assert_eq!(h.knots, 65);
    assert_eq!(scale::newtons(h.force_clamp), BOARD.max_force);
    assert_eq!(h.workspace, BOARD.workspace_q24());
    assert_eq!((h.pose_speed_mm_s, h.pose_turn_deg_s), (200, 180));
    assert_eq!(h.baud, 1_000_000);
    assert_eq!(h.friction, mccs_link::Friction::new(0.6, 0.4));
    assert_eq!(
        h.telemetry_least_every,
        rates::telemetry_least_every(1000, 1_000_000)
    );
    assert_eq!(
        h.mesh_least_every,
        rates::mesh_least_every(1000, 1_000_000, free_nodes())
    );
    assert_eq!(h.tick_budget, BOARD.tick_budget);
    let mut glued = Rig::glued(table2());
    let ToHost::Hello(h) = glued.ask(&ToDevice::Hello, 5, |m| matches!(m, ToHost::Hello(_))) else {
        unreachable!()
    };
    assert_eq!(
        (h.device, h.contact),
        (DeviceKind::OneDof, ContactKind::Glued)
    );
    let n = BOARD.grid as u8;
    assert_eq!((h.tissue_w, h.tissue_h), (n, n), "glued: the patch alone");
}

#[test]
fn a_tissue_is_checked_in_slices_and_acknowledged_once_the_tick_runs_it() {
    let mut rig = Rig::roaming(table2());
    let stiffer = Tissue::from_params(&params("table2-stiffer.toml")).unwrap();
    rig.send(&ToDevice::Watch { every: 1 });
    rig.step();
    rig.out.clear();
    // Searching (no proposal): the check runs a slice a poll, hello and status are
    // answered meanwhile, and the telemetry says a check runs.
    rig.send(&ToDevice::TissueBegin(TissueBegin {
        segments: 64,
        len: stiffer.bytes().len() as u32,
        hash: stiffer.hash(),
        friction: None,
        substeps: 0,
    }));
    for (i, c) in stiffer.bytes().chunks(TISSUE_CHUNK).enumerate() {
        rig.send(&ToDevice::TissueChunk {
            offset: (i * TISSUE_CHUNK) as u32,
            bytes: c,
        });
    }
    rig.send(&ToDevice::TissueCommit);
    rig.step();
    let mut polls = 0;
    let mut answered = 0;
    let mut checking = 0;
    let ack = loop {
        rig.send(&ToDevice::Status);
        rig.step();
        polls += 1;
        assert!(polls < 5000, "no ack");
        if let Some(a) = rig
            .out
            .iter()
            .find(|m| matches!(m, ToHost::Ack { .. } | ToHost::Nak(_)))
        {
            break *a;
        }
        answered += rig
            .out
            .iter()
            .filter(|m| matches!(m, ToHost::Status(_)))
            .count();
        checking += rig
            .out
            .iter()
            .filter(|m| matches!(m, ToHost::Telemetry(t) if t.flags.contains(Flags::CHECKING)))
            .count();
        rig.out.clear();
    };
    assert!(
        checking * 4 >= polls,
        "{checking} samples say a check runs, in {polls} polls"
    );
    assert_eq!(
        ack,
        ToHost::Ack {
            tissue: stiffer.hash()
        }
    );
    // The search's runs (12 for the board's symplectic option, each up to 1,536 steps), a
    // slice of check_steps_per_poll a poll, as many as the same search takes on the host;
    // a status each.
    let topo = mccs::Topology::<NODES, EDGES>::standard_patch(BOARD.grid, 2.5).unwrap();
    let table = ForceTable64::from_raw(table_bytes::read::<64>(stiffer.bytes()).unwrap());
    let mut search =
        mccs::solver::stability::StabilityCheck::new(&topo, &table, &BOARD.solver(), None).unwrap();
    while search.advance(&topo, u32::MAX).is_none() {}
    let slices = search.steps_run().div_ceil(BOARD.check_steps_per_poll);
    assert!(
        slices > 100 && polls as u32 >= slices && polls as u32 <= slices + 10,
        "{polls} polls, {slices} slices"
    );
    assert!(
        answered + 1 >= polls,
        "{answered} statuses in {polls} polls"
    );
    assert_eq!(rig.ctl.telemetry().swaps, 1);
    // The ack names the tissue the tick runs, and hello says so.
    let ToHost::Hello(h) = rig.ask(&ToDevice::Hello, 5, |m| matches!(m, ToHost::Hello(_))) else {
        unreachable!()
    };
    assert_eq!(h.tissue, stiffer.hash());
}

#[test]
fn a_hosts_proposed_substeps_are_checked_in_two_runs() {
    for name in ["table2.toml", "table2-stiffer.toml"] {
        let mut rig = Rig::roaming(table2());
        let t = Tissue::from_params(&params(name)).unwrap();
        let topo = mccs::Topology::<NODES, EDGES>::standard_patch(8, 2.5).unwrap();
        let table = ForceTable64::from_raw(table_bytes::read::<64>(t.bytes()).unwrap());
        let n =
            mccs::Solver::<NODES, EDGES, 64>::substeps_for(&topo, &table, &BOARD.solver()).unwrap();
        let before = rig.ctl.telemetry().ticks;
        assert_eq!(
            load(&mut rig, &t, n as u16, t.hash()),
            ToHost::Ack { tissue: t.hash() },
            "{name}"
        );
        // Two runs of up to 1,536 steps, a slice a tick here.
        let ticks = rig.ctl.telemetry().ticks - before;
        assert!(
            ticks <= 2 * 1536 / BOARD.check_steps_per_poll + 5,
            "{name}: {ticks} ticks"
        );
        assert_eq!(rig.ctl.solver().substeps(), n, "{name}");
        // Fewer than the bound allows: refused, the live tissue kept.
        if n > 1 {
            let r = load(&mut rig, &t, (n - 1) as u16, t.hash());
            assert_eq!(
                r,
                ToHost::Nak(NakReason::Stability {
                    substeps: (n - 1) as u16
                }),
                "{name}"
            );
        }
    }
}

#[test]
fn the_device_refuses_what_it_cannot_run_with_its_reason() {
    let mut rig = Rig::roaming(table2());
    let good = Tissue::from_params(&Params::TABLE2).unwrap();
    let live = rig.server.session().tissue().1;
    // The bytes' hash, a table that breaks its own check, one over the bound.
    assert_eq!(
        load(&mut rig, &good, 0, good.hash() ^ 1),
        ToHost::Nak(NakReason::Hash)
    );
    let mut raw = *table2().raw();
    raw.strain_hi = raw.strain_lo;
    let broken = Tissue::of_table(&ForceTable64::from_raw(raw));
    assert_eq!(
        load(&mut rig, &broken, 0, broken.hash()),
        ToHost::Nak(NakReason::Table)
    );
    let mut raw = *table2().raw();
    raw.err_force_ppb = u32::MAX;
    let over = Tissue::of_table(&ForceTable64::from_raw(raw));
    assert_eq!(
        load(&mut rig, &over, 0, over.hash()),
        ToHost::Nak(NakReason::Bound)
    );
    // A tissue ten times stiffer: its tick would pass the budget, with the figures.
    let mut stiff = Params::TABLE2;
    stiff.cone.shear_modulus *= 10.0;
    stiff.linear.shear_modulus *= 10.0;
    let stiff = Tissue::from_params(&stiff).unwrap();
    match load(&mut rig, &stiff, 0, stiff.hash()) {
        ToHost::Nak(NakReason::Budget {
            substeps,
            instructions,
            budget,
        }) => {
            assert_eq!(budget, BOARD.tick_budget);
            assert!(
                substeps as u32 > BOARD.budget().most_substeps(),
                "{substeps}"
            );
            assert_eq!(instructions, BOARD.budget().cost(substeps as u32));
        }
        other => panic!("{other:?}"),
    }
    // Friction out of range.
    let slippery = good.clone().with_friction(0.5, 0.5).unwrap();
    let mut begin = TissueBegin {
        segments: 64,
        len: good.bytes().len() as u32,
        hash: good.hash(),
        friction: Some(mccs_link::Friction {
            mu_s: 1 << 16,
            mu_k: 3 << 16,
        }),
        substeps: 0,
    };
    let r = rig.ask(&ToDevice::TissueBegin(begin), 3, |_| false);
    assert_eq!(r, ToHost::Nak(NakReason::Friction));
    // Another knot count, another length; a chunk out of order; a commit alone.
    begin.friction = None;
    let r = rig.ask(
        &ToDevice::TissueBegin(TissueBegin {
            segments: 32,
            ..begin
        }),
        3,
        |_| false,
    );
    assert_eq!(r, ToHost::Nak(NakReason::Segments));
    let r = rig.ask(
        &ToDevice::TissueBegin(TissueBegin { len: 12, ..begin }),
        3,
        |_| false,
    );
    assert_eq!(r, ToHost::Nak(NakReason::Length));
    rig.send(&ToDevice::TissueBegin(begin));
    let r = rig.ask(
        &ToDevice::TissueChunk {
            offset: 200,
            bytes: &[0; 4],
        },
        3,
        |_| false,
    );
    assert_eq!(r, ToHost::Nak(NakReason::Order));
    let r = rig.ask(&ToDevice::TissueCommit, 3, |_| false);
    assert_eq!(r, ToHost::Nak(NakReason::Order));
    // Nothing changed; a good one with friction goes in.
    assert_eq!(rig.server.session().tissue().1, live);
    assert_eq!(rig.ctl.telemetry().swaps, 0);
    assert_eq!(
        load(&mut rig, &slippery, 0, slippery.hash()),
        ToHost::Ack {
            tissue: slippery.hash()
        }
    );
    let ToHost::Hello(h) = rig.ask(&ToDevice::Hello, 5, |m| matches!(m, ToHost::Hello(_))) else {
        unreachable!()
    };
    assert_eq!(h.friction, mccs_link::Friction::new(0.5, 0.5));
    // A glued device has no friction to take.
    let mut glued = Rig::glued(table2());
    let r = glued.ask(
        &ToDevice::TissueBegin(TissueBegin {
            friction: Some(mccs_link::Friction::new(0.5, 0.4)),
            ..begin
        }),
        3,
        |_| false,
    );
    assert_eq!(r, ToHost::Nak(NakReason::Friction));
}

#[test]
fn a_pose_outside_the_workspace_or_not_a_rotation_is_refused() {
    let mut rig = Rig::roaming(table2());
    let [lo, hi] = BOARD.workspace_mm;
    let r = rig.ask(
        &ToDevice::Pose(Pose::from_mm_deg([hi[0] + 1.0, 0.0, 0.0], [0.0; 3])),
        3,
        |_| false,
    );
    assert_eq!(
        r,
        ToHost::Nak(NakReason::Pose {
            axis: 0,
            limit: scale::mm_bits(hi[0])
        })
    );
    let r = rig.ask(
        &ToDevice::Pose(Pose::from_mm_deg([0.0, 0.0, lo[2] - 0.5], [0.0; 3])),
        3,
        |_| false,
    );
    assert_eq!(
        r,
        ToHost::Nak(NakReason::Pose {
            axis: 2,
            limit: scale::mm_bits(lo[2])
        })
    );
    let mut bad = Pose::IDENTITY;
    bad.rotation[1] = 1 << 29;
    let r = rig.ask(&ToDevice::Pose(bad), 3, |_| false);
    assert_eq!(r, ToHost::Nak(NakReason::Rotation));
    let ok = Pose::from_mm_deg([10.0, -5.0, 2.0], [0.0, 15.0, 0.0]);
    rig.send(&ToDevice::Pose(ok));
    let ToHost::Status(s) = rig.ask(&ToDevice::Status, 3, |m| matches!(m, ToHost::Status(_)))
    else {
        unreachable!()
    };
    assert_eq!(s.pose, ok);
}

#[test]
fn a_pose_change_never_jumps_the_force_by_more_than_the_clamp() {
    let mut rig = Rig::roaming(table2());
    // Out of contact until the gain is full, then pressed 1 mm in.
    for _ in 0..600 {
        rig.step();
    }
    rig.probe().at = [0.0, 0.4, -1.0];
    for _ in 0..300 {
        rig.step();
    }
    let clamp = Force::from_num(BOARD.max_force).to_bits() as i64;
    let mut last = rig.ctl.device().rendered();
    assert!(last[2] > Force::ZERO, "{last:?}");
    // The tissue thrown 40 mm sideways and tilted 60°: slewed, the force never jumps.
    rig.send(&ToDevice::Pose(Pose::from_mm_deg(
        [40.0, 0.0, 0.0],
        [60.0, 0.0, 0.0],
    )));
    let mut worst = 0i64;
    for _ in 0..1500 {
        rig.step();
        let now = rig.ctl.device().rendered();
        let d2: i64 = (0..3)
            .map(|k| (now[k].to_bits() as i64 - last[k].to_bits() as i64).pow(2))
            .sum();
        worst = worst.max(d2);
        last = now;
    }
    let worst = (worst as f64).sqrt();
    assert!(
        worst <= clamp as f64,
        "a jump of {} N",
        worst / (1u32 << 20) as f64
    );
    println!(
        "LINK case=pose_step worst_force_step_n={:.4}",
        worst / (1u32 << 20) as f64
    );
}

/// The link's clock wraps at 2³² (49.7 days at 1 kHz): across it, an armed host held by
/// its keepalives keeps its force, its silence still fades it, and the telemetry keeps
/// its period and its numbers. (The guard was fed the controller's count of ticks,
/// which saturates: from then on every frame and tick had one time, and a silence never
/// faded.)
#[test]
fn an_armed_host_s_silence_fades_across_the_clock_s_wrap() {
    let mut rig = Rig::roaming_from(table2(), u32::MAX - 1000);
    let mut samples: Vec<Telemetry> = Vec::new();
    // A tick, the telemetry it sent kept.
    let mut step = |rig: &mut Rig<_>| {
        rig.step();
        rig.out.retain(|m| match m {
            ToHost::Telemetry(t) => {
                samples.push(*t);
                false
            }
            _ => true,
        });
    };
    rig.send(&ToDevice::Watch { every: 10 });
    for _ in 0..600 {
        step(&mut rig);
    }
    rig.send(&ToDevice::Arm);
    // Keepalives across the wrap (the clock passes 0 at the 1,001st tick).
    for _ in 0..40 {
        for _ in 0..25 {
            step(&mut rig);
        }
        rig.send(&ToDevice::Keepalive);
    }
    let snap = rig.state.snapshot();
    assert!(snap.ticks < 1000, "the clock at {}", snap.ticks);
    assert_eq!(snap.gain, GAIN_FULL, "held armed across the wrap");
    // Silent: zero within the timeout and the fade, and disarmed.
    let times = GuardTimes::at_rate(BOARD.tick_hz, BOARD.ramp_ms);
    for _ in 0..times.timeout + times.fade + 2 {
        step(&mut rig);
    }
    assert_eq!(
        rig.state.snapshot().gain,
        0,
        "the silence did not fade the force"
    );
    assert_eq!(rig.ctl.device().rendered(), [Force::ZERO; 3]);
    rig.send(&ToDevice::Status);
    step(&mut rig);
    let statuses: Vec<bool> = rig
        .out
        .iter()
        .filter_map(|m| match m {
            ToHost::Status(s) => Some(s.armed),
            _ => None,
        })
        .collect();
    assert_eq!(statuses, [true, false], "Arm's, then after the silence");
    // The telemetry: every 10 ticks, across the wrap, numbered without a gap.
    assert!(
        samples.len() >= 170,
        "{} samples in 1,723 ticks",
        samples.len()
    );
    assert!(samples.iter().any(|t| t.tick < 1000), "none after the wrap");
    for w in samples.windows(2) {
        assert_eq!(w[1].tick.wrapping_sub(w[0].tick), 10, "{w:?}");
        assert_eq!(w[1].seq, w[0].seq + 1, "{w:?}");
    }
}

/// The 1-DOF board's glued contact clamps each axis in the tissue's frame; turned 45°
/// about `x`, a deep press saturates its `y` and `z`, which the rotation mixes into one
/// axis of the device's frame: 4.24 N against the 3 N clamp before the device held each
/// of its axes to it (`LinkedDevice`; found by `any_run`).
#[test]
fn a_turned_tissue_keeps_each_axis_of_the_device_within_the_clamp() {
    let mut rig = Rig::glued(table2());
    for _ in 0..600 {
        rig.step();
    }
    rig.send(&ToDevice::Pose(Pose::from_mm_deg(
        [0.0; 3],
        [45.0, 0.0, 0.0],
    )));
    for _ in 0..400 {
        rig.step();
    }
    rig.probe().at = [0.0, 0.0, -20.0];
    let clamp = Force::from_num(BOARD.max_force);
    let mut largest = Force::ZERO;
    for _ in 0..300 {
        rig.step();
        for c in rig.ctl.device().rendered() {
            largest = largest.max(c.saturating_abs());
        }
    }
    assert!(largest <= clamp, "{largest} N on one axis");
    assert!(
        largest > clamp * 99 / 100,
        "{largest} N: not pressed to the clamp"
    );
    println!("LINK case=turned_glued largest_axis_n={largest:.4}");
}

#[test]
fn a_run_of_overruns_ends_in_the_safe_state() {
    let mut rig = Rig::roaming(table2());
    for _ in 0..BOARD.max_overruns_in_row - 1 {
        rig.tick();
        rig.ctl.note_overrun();
    }
    rig.tick();
    rig.ctl.note_on_time();
    assert_eq!(rig.ctl.telemetry().fault, None, "nine, then one on time");
    for _ in 0..BOARD.max_overruns_in_row {
        rig.tick();
        rig.ctl.note_overrun();
    }
    assert_eq!(
        rig.ctl.telemetry().fault,
        Some(mccs_firmware::Fault::Overruns)
    );
    rig.step();
    let ToHost::Status(s) = rig.ask(&ToDevice::Status, 3, |m| matches!(m, ToHost::Status(_)))
    else {
        unreachable!()
    };
    assert_eq!(s.fault, FaultReason::Overruns);
    assert_eq!(rig.ctl.device().rendered(), [Force::ZERO; 3]);
}

#[test]
fn telemetry_is_held_to_the_byte_budget_and_its_gaps_are_the_drops() {
    let mut rig = Rig::roaming(table2());
    rig.send(&ToDevice::Watch { every: 1 });
    let least = rates::telemetry_least_every(1000, BOARD.baud) as u32;
    let mut got = Vec::new();
    // The main loop polls at irregular ticks: some due samples are missed.
    for t in 0..2000u32 {
        rig.tick();
        if t % 7 == 0 || t % 11 == 0 {
            rig.poll();
        }
    }
    for m in &rig.out {
        if let ToHost::Telemetry(t) = m {
            got.push(*t);
        }
    }
    let span = got.last().unwrap().tick - got[0].tick;
    assert!(
        got.len() as u32 <= span / least + 1,
        "{} samples in {span} ticks: over one every {least}",
        got.len()
    );
    assert!(got.windows(2).all(|w| w[1].seq > w[0].seq));
    let last = got.last().unwrap();
    let gaps: u32 = got.windows(2).map(|w| w[1].seq - w[0].seq - 1).sum::<u32>() + got[0].seq;
    assert_eq!(gaps, last.dropped);
    assert!(last.dropped > 0);
    // The largest telemetry frame is what the budget counts.
    let worst = ToHost::Telemetry(Telemetry {
        seq: u32::MAX,
        tick: u32::MAX,
        probe: [i32::MIN; 3],
        force: [i32::MIN; 3],
        gain: u16::MAX,
        flags: Flags(u16::MAX),
        fault: FaultReason::Overruns,
        duties: [i32::MIN; 3],
        proxy: [i32::MIN; 3],
        window: [i32::MIN; 2],
        dropped: u32::MAX,
    });
    let mut buf = [0u8; MAX_FRAME];
    assert_eq!(
        encode(&worst, &mut buf).unwrap().len() as u32,
        rates::TELEMETRY_FRAME_MAX
    );
}

#[test]
fn the_mesh_has_every_free_node_in_its_grid_place_within_the_byte_budget() {
    let mut rig = Rig::roaming(table2());
    rig.send(&ToDevice::WatchMesh { every: 1 });
    let least = rates::mesh_least_every(1000, BOARD.baud, free_nodes()) as u32;
    for _ in 0..300 {
        rig.step();
    }
    let parts: Vec<MeshPart> = rig
        .out
        .iter()
        .filter_map(|m| match m {
            ToHost::Mesh(p) => Some(*p),
            _ => None,
        })
        .collect();
    let starts: Vec<&MeshPart> = parts.iter().filter(|p| p.first == 0).collect();
    let span = starts.last().unwrap().tick - starts[0].tick;
    assert!(
        starts.len() as u32 <= span / least + 1,
        "{} meshes in {span} ticks",
        starts.len()
    );
    assert!(
        starts.len() as u32 >= 300 / least - 1,
        "{} meshes",
        starts.len()
    );
    // Each mesh: the free nodes in parts of 12, each node in its place of the board's
    // N × N grid at its rest position (the probe is above the tissue) plus the window's
    // origin.
    let (free, inner) = (free_nodes(), BOARD.grid - 2);
    let topo = mccs::Topology::<NODES, EDGES>::standard_patch(BOARD.grid, 2.5).unwrap();
    for p in parts.iter().filter(|p| p.seq == starts[1].seq) {
        assert_eq!(p.nodes as usize, free);
        for k in 0..MESH_PART.min(free - p.first as usize) {
            let node = p.first as usize + k;
            let [i, j] = p.grid[k];
            assert_eq!(
                (i as usize, j as usize),
                (1 + node / inner, 1 + node % inner)
            );
            let rest = topo.rest_q24(node + 1).unwrap();
            for c in 0..3 {
                assert!((p.positions[k][c] - rest[c]).abs() < 1 << 12, "node {node}");
            }
        }
    }
    // The largest part's frame is what the budget counts.
    let worst = ToHost::Mesh(MeshPart {
        seq: u32::MAX,
        tick: u32::MAX,
        first: u16::MAX,
        nodes: u16::MAX,
        origin: [i32::MIN; 2],
        grid: [[u8::MAX; 2]; MESH_PART],
        positions: [[i32::MIN; 3]; MESH_PART],
    });
    let mut buf = [0u8; MAX_FRAME];
    assert_eq!(
        encode(&worst, &mut buf).unwrap().len() as u32,
        rates::MESH_PART_FRAME_MAX
    );
}

/// The board's patch's free nodes, `(N − 2)²`: what its mesh streams.
fn free_nodes() -> usize {
    (BOARD.grid - 2).pow(2)
}

#[test]
fn friction_reaches_the_hand_and_the_flags_say_so() {
    let mut rig = Rig::roaming(table2());
    rig.send(&ToDevice::Watch { every: 1 });
    // Above the tissue until the ramp is done, pressed 1.5 mm in, then a slide along x.
    for _ in 0..600 {
        rig.step();
    }
    for k in 0..300 {
        rig.probe().at = [-15.0, 0.4, 5.0 - 6.5 * (k as f64 / 300.0)];
        rig.step();
    }
    for k in 0..1500 {
        rig.probe().at = [-15.0 + 30.0 * (k as f64 / 1500.0), 0.4, -1.5];
        rig.step();
    }
    let samples: Vec<Telemetry> = rig
        .out
        .iter()
        .filter_map(|m| match m {
            ToHost::Telemetry(t) => Some(*t),
            _ => None,
        })
        .collect();
    let slipping: Vec<&Telemetry> = samples
        .iter()
        .filter(|t| t.flags.contains(Flags::SLIPPING) && t.flags.contains(Flags::CONTACT))
        .collect();
    assert!(slipping.len() > 50, "{} slipping samples", slipping.len());
    let ratio = |t: &Telemetry| {
        let f = t.force.map(scale::newtons);
        f[0].hypot(f[1]) / f[2].abs()
    };
    let mean = slipping.iter().map(|t| ratio(t)).sum::<f64>() / slipping.len() as f64;
    assert!(
        (mean - BOARD.mu_k).abs() <= 0.1 * BOARD.mu_k,
        "lateral/normal {mean}, mu_k {}",
        BOARD.mu_k
    );
    assert!(samples.iter().all(|t| t.flags.contains(Flags::HOMED)));
    println!(
        "LINK case=friction_host slipping_samples={} lateral_over_normal={mean:.4} mu_k={}",
        slipping.len(),
        BOARD.mu_k
    );
}

/// Runs a replay through the rig as `mccs link replay` drives it.
fn device_replay(
    rig: &mut Rig<haptic_f405::device::BoardRoaming>,
    spec: ReplaySpec,
    samples: &[[f64; 3]],
) -> Vec<ReplayRow> {
    let ToHost::ReplayCredit { mut until } = rig.ask(&ToDevice::ReplayBegin(spec), 5, |m| {
        matches!(m, ToHost::ReplayCredit { .. })
    }) else {
        panic!("refused")
    };
    let mut rows = Vec::new();
    let mut sent = 0usize;
    let mut ended = false;
    let mut polls = 0;
    while !ended {
        while sent < samples.len() && (sent as u32) < until {
            let n = (until as usize - sent)
                .min(PathPoint::PER_FRAME)
                .min(samples.len() - sent);
            let points: Vec<u8> = samples[sent..sent + n]
                .iter()
                .flat_map(|p| {
                    PathPoint(mccs_client::replay::probe_bits(*p).map(|c| c.to_bits())).to_bytes()
                })
                .collect();
            rig.send(&ToDevice::ReplayPath {
                first: sent as u32,
                points: &points,
            });
            sent += n;
        }
        rig.poll();
        polls += 1;
        assert!(polls < 100_000, "stalled at {}", rows.len());
        for m in rig.out.drain(..) {
            match m {
                ToHost::ReplayRow(r) => rows.push(r),
                ToHost::ReplayCredit { until: u } => until = u,
                ToHost::ReplayEnd { .. } => ended = true,
                ToHost::Nak(n) => panic!("{n:?}"),
                _ => {}
            }
        }
    }
    rows
}

#[test]
fn a_replay_on_the_device_is_the_hosts_fixed_replay() {
    let table = table2();
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
    let mut rig = Rig::roaming(table);
    // Glued.
    let mut host = Vec::new();
    replay
        .run_with(&Params::TABLE2, Some(&table), &traj, |r: Row| host.push(r))
        .unwrap();
    let dev = device_replay(
        &mut rig,
        spec(samples.len() as u32, samples[0], None),
        &samples,
    );
    assert_eq!(dev.len(), host.len());
    for ((h, d), (t, p)) in host.iter().zip(&dev).zip(&ticks) {
        assert_eq!(*h, Row::of_raw(*t, *p, d), "tick {}", d.tick);
    }
    // Roaming with friction on a 64 × 64 tissue.
    let roaming = Roaming {
        tissue: RoamTissue::new(64, 64, 2.5, Shape::Flat).unwrap(),
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
        &mut rig,
        spec(samples.len() as u32, samples[0], Some(roam)),
        &samples,
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
    let mut rig = Rig::roaming(table2());
    let cases = [
        (
            ReplaySpec {
                grid: haptic_f405::device::MAX_GRID as u8 + 1,
                ..spec(10, [0.0; 3], None)
            },
            SpecOption::Grid,
            haptic_f405::device::MAX_GRID as i32,
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
        let r = rig.ask(&ToDevice::ReplayBegin(spec), 3, |_| false);
        assert_eq!(r, ToHost::Nak(NakReason::Option { option, limit }));
    }
    // A path out of order, or past the credit, abandons the replay.
    let r = rig.ask(&ToDevice::ReplayBegin(spec(1000, [0.0; 3], None)), 3, |m| {
        matches!(m, ToHost::ReplayCredit { .. })
    });
    assert_eq!(r, ToHost::ReplayCredit { until: P as u32 });
    let chunk = [0u8; 12 * PathPoint::PER_FRAME];
    let r = rig.ask(
        &ToDevice::ReplayPath {
            first: 5,
            points: &chunk,
        },
        3,
        |_| false,
    );
    assert_eq!(r, ToHost::Nak(NakReason::Order));
    let mut run = mccs_firmware::link::ReplayRun::<NODES, EDGES, 64, mccs::Wide, P>::idle();
    run.start(&spec(1000, [0.0; 3], None), table2(), false, 0, u32::MAX)
        .unwrap();
    for k in 0..P / PathPoint::PER_FRAME {
        run.path((k * PathPoint::PER_FRAME) as u32, &chunk, 0)
            .unwrap();
    }
    assert_eq!(
        run.path(P as u32, &chunk, 0),
        Err(NakReason::Order),
        "past the credit"
    );
    let ToHost::Status(s) = rig.ask(&ToDevice::Status, 3, |m| matches!(m, ToHost::Status(_)))
    else {
        unreachable!()
    };
    assert!(!s.replaying);
}

#[test]
fn a_flood_of_garbage_is_counted_and_never_stalls_the_tick_or_the_link() {
    let mut rig = Rig::roaming(table2());
    let mut garbage = Vec::new();
    for k in 0..20_000u32 {
        garbage.push((k.wrapping_mul(2_654_435_761) >> 24) as u8 | 1);
        if k % 97 == 0 {
            garbage.push(0);
        }
    }
    garbage.push(0);
    rig.send_raw(&garbage);
    let mut polls = 0;
    while rig.queued() > 0 {
        rig.step();
        polls += 1;
    }
    // At most 512 bytes a poll: the tick ran between them.
    assert!(polls >= garbage.len() / 512, "{polls} polls");
    let ToHost::Status(s) = rig.ask(&ToDevice::Status, 3, |m| matches!(m, ToHost::Status(_)))
    else {
        unreachable!()
    };
    assert!(s.bad_frames > 100, "{} bad frames", s.bad_frames);
    assert_eq!(s.ticks as usize, polls + 1);
}

/// A slice of a tissue's check (`BoardConfig::check_steps_per_poll` steps of the
/// linearised patch between two polls of the link) holds the main loop at most 5 ms on
/// the M4F at 168 MHz at the board's N: the bench's `case=tissue_check` runs the check
/// again in slices of as many steps at N = 8 and gives the most one took
/// (`worst_slice_instructions`, bench/baseline.txt: a run's start and a look at its
/// energy fall in some), at the bench's estimate of the M4F's cycles per instruction.
#[test]
fn a_slice_of_a_tissue_check_holds_the_main_loop_under_5_ms() {
    let field = |name: &str| {
        mccs_host::cli::bench_figure("m4f", "tissue_check", name)
            .unwrap_or_else(|| panic!("no M4F tissue_check {name} in bench/baseline.txt"))
            as f64
    };
    let (worst, slice_steps) = (field("worst_slice_instructions"), field("slice_steps"));
    assert_eq!(field("n"), 8.0, "the M4F's check at N = 8");
    assert_eq!(
        slice_steps, BOARD.check_steps_per_poll as f64,
        "the bench's slices are the board's"
    );
    // A slice's cost is a sum over the springs and the free nodes: from N = 8's (214
    // springs, 36 free nodes) to the board's it grows by at most the larger ratio.
    let inner = (BOARD.grid - 2) as f64;
    let springs = mccs::topology::standard_capacity(BOARD.grid).1 as f64;
    let growth = (springs / 214.0).max(inner * inner / 36.0);
    let (mhz, cpi_percent) = mccs_firmware::target::Core::M4F.clock_estimate();
    let slice_ms = worst * growth * cpi_percent as f64 / 100.0 / (mhz as f64 * 1000.0);
    println!(
        "LINK case=check_slice ms_at_clock={slice_ms:.2} steps={}",
        BOARD.check_steps_per_poll
    );
    assert!(
        slice_ms <= 5.0,
        "a slice of {} steps takes {slice_ms:.2} ms",
        BOARD.check_steps_per_poll
    );
}

/// The board's budget model charges the link's work at the budgets the bench holds it
/// to: `LINK_WORK_COST` is the sum of bench/budgets.txt's M4F `tick_link`,
/// `link_swap_n10` and `link_mesh_n10`, and the tick's base is the rest and that.
#[test]
fn the_budget_model_charges_the_link_s_work_at_its_budgets() {
    let budgets =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../bench/budgets.txt"))
            .unwrap();
    let max = |case: &str| -> u32 {
        let head = format!("BUDGET core=m4f case={case} max=");
        let line = budgets
            .lines()
            .find(|l| l.starts_with(&head))
            .unwrap_or_else(|| panic!("no M4F budget for {case} in bench/budgets.txt"));
        line[head.len()..]
            .split_whitespace()
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    let link = max("tick_link") + max("link_swap_n10") + max("link_mesh_n10");
    assert_eq!(haptic_f405::config::LINK_WORK_COST, link);
    assert_eq!(
        BOARD.tick_base_cost,
        haptic_f405::config::TICK_REST_COST + link
    );
}

/// A device whose homing the test decides, held out of contact (far above the tissue).
struct Homing(std::rc::Rc<std::cell::Cell<bool>>);

impl mccs_firmware::HapticDevice for Homing {
    type Error = ();
    fn read_position(&mut self) -> Result<[Length; 3], ()> {
        Ok([Length::ZERO, Length::ZERO, Length::from_num(20)])
    }
    fn write_force(&mut self, _: [Force; 3]) -> Result<(), ()> {
        Ok(())
    }
    fn safe_state(&mut self) -> Result<(), ()> {
        Ok(())
    }
    fn status(&self) -> mccs_firmware::DeviceStatus {
        mccs_firmware::DeviceStatus {
            homed: self.0.get(),
            ..mccs_firmware::DeviceStatus::default()
        }
    }
}

/// Homing restarts the link's ramp: the gain, full before (standalone, out of contact),
/// is zero the tick after the arm homes and climbs again over the ramp (500 ms). (Homing
/// once left the force at full at once, with the hand perhaps resting in the tissue.)
#[test]
fn homing_restarts_the_ramp() {
    use mccs_firmware::link::{LinkState, LinkedDevice};
    let homed = std::rc::Rc::new(std::cell::Cell::new(false));
    let state: LinkState<NODES, 64, mccs::Wide> =
        LinkState::new(Guard::new(GuardTimes::at_rate(1000, 500)));
    let topo = mccs::Topology::<NODES, EDGES>::standard_patch(BOARD.grid, 2.5).unwrap();
    let solver = mccs::Solver::new(
        topo,
        ForceTable64::new(&Params::TABLE2).unwrap(),
        &BOARD.solver(),
    )
    .unwrap();
    let device = LinkedDevice::new(
        Homing(homed.clone()),
        TissuePose::new(200.0, 180.0, 1000.0),
        solver.max_force(),
    );
    let mut ctl = mccs_firmware::Controller::new(solver, device, u32::MAX);
    for _ in 0..600 {
        state.run_tick(&mut ctl);
    }
    assert_eq!(
        state.snapshot().gain,
        mccs_link::scale::GAIN_FULL,
        "the start's ramp done"
    );
    homed.set(true);
    state.run_tick(&mut ctl);
    state.run_tick(&mut ctl);
    let after = state.snapshot().gain;
    assert!(
        after <= mccs_link::scale::GAIN_FULL / 250,
        "the gain after homing: {after}"
    );
    for _ in 0..250 {
        state.run_tick(&mut ctl);
    }
    let half = state.snapshot().gain;
    assert!(
        half > after && half < mccs_link::scale::GAIN_FULL,
        "climbing: {half}"
    );
    for _ in 0..300 {
        state.run_tick(&mut ctl);
    }
    assert_eq!(
        state.snapshot().gain,
        mccs_link::scale::GAIN_FULL,
        "full again"
    );
}
