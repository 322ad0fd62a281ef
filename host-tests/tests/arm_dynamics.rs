//! The board's arm loop closed through the arm's own dynamics
//! (`mccs_host::arm::{dynamics, closed_loop}`): the board's arm device and roaming
//! controller, as the board builds them, drive a body with inertia, friction, a current
//! stage, whole-count encoders and half a tick's delay, held by a hand. docs/safety.md,
//! "The arm's own dynamics", quotes the `ARMLOOP` lines.

use haptic_f405::arm::ARM;
use haptic_f405::device::{EDGES, NODES, SPACING_MM};
use haptic_f405::tissue::TISSUE;
use haptic_f405::{BoardConfig, BOARD};
use mccs::{Solver, Topology};
use mccs_firmware::arm::plant::{HOME_TICKS, PALPATION_TICKS};
use mccs_host::arm::closed_loop::{
    hand_verdict, hand_verdicts, held_press, stiffness_grid, verdict, ClosedLoop, HoldAt, HANDS,
    HOLD_DEPTH_MM, LEAD_TICKS,
};
use mccs_host::arm::device_file;
use mccs_host::arm::dynamics::{ArmBody, BodySpec, Hand};
use nalgebra::Vector3;
use std::path::Path;

/// The board's arm's stable region, as its device file holds it.
fn region() -> device_file::StableRegion {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../devices/woodenhaptics.toml");
    device_file::read_stability(&path)
        .unwrap_or_else(|e| panic!("{e}"))
        .unwrap_or_else(|| panic!("devices/woodenhaptics.toml has no [stability]"))
}

/// The board with the stiffest coupling it accepts at its damping: half the region there
/// (`mccs check --device arm`'s limit), or, where that coupling asks for more substeps
/// than the tick's budget holds (the board refuses it at start-up), the stiffest it
/// starts with, to 0.1 %.
fn stiffest_board() -> BoardConfig {
    let at = |k: f64| BoardConfig {
        coupling_stiffness: k,
        ..BOARD
    };
    let starts = |k: f64| {
        let config = at(k);
        let topo = Topology::<NODES, EDGES>::standard_patch(config.grid, SPACING_MM).unwrap();
        Solver::new(topo, TISSUE, &config.solver())
            .is_ok_and(|s| s.substeps() <= config.budget().most_substeps())
    };
    let half = region().max_coupling(BOARD.coupling_damping).unwrap() / 2.0;
    if starts(half) {
        return at(half);
    }
    let (mut lo, mut hi) = (BOARD.coupling_stiffness, half);
    assert!(starts(lo), "the board's own coupling is over its budget");
    while hi - lo > 1e-3 * lo {
        let mid = 0.5 * (lo + hi);
        if starts(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    at(lo)
}

/// The body's own check: with no friction, no motor and no hand, a swinging arm keeps
/// its energy to 0.2 % (the velocity-product terms are right; semi-implicit Euler's own
/// bounded wobble is the rest), over 2 s of 0.1 ms steps.
#[test]
fn a_free_arm_swinging_keeps_its_energy() {
    let body = BodySpec {
        viscous_nm_s: [0.0; 3],
        coulomb_nm: [0.0; 3],
        ..BodySpec::STAND_IN
    };
    let mut arm = ArmBody::new(ARM, body);
    arm.angle = [0.3, 0.5, 0.9];
    arm.rate = [2.0, -1.0, 3.0];
    let e0 = arm.energy(&Hand::OFF);
    let mut most = 0.0f64;
    for _ in 0..20_000 {
        arm.step(
            1e-4,
            [0.0; 3],
            &Hand::OFF,
            Vector3::zeros(),
            Vector3::zeros(),
        );
        most = most.max((arm.energy(&Hand::OFF) - e0).abs() / e0);
    }
    println!("ARMLOOP case=free_swing energy_drift={most:.2e}");
    assert!(most < 2e-3, "the energy drifted by {most:e} of {e0} J");
}

/// Each hand of the range (0.1–0.5 kg, 2–10 N·s/m, 100–1000 N/m) leads the probe home,
/// down and twice along the demo's palpation (10 s in all), with the stiffest coupling
/// `mccs check --device arm` accepts: no fault, and no net energy out of the device.
#[test]
fn every_hand_palpates_10_s_at_the_stiffest_coupling_allowed_with_no_energy_out() {
    let config = stiffest_board();
    let ticks = 10_000;
    assert!(LEAD_TICKS + 2 * PALPATION_TICKS <= ticks);
    let mut most = f64::MIN;
    for hand in HANDS {
        let mut lp = ClosedLoop::new(&config, &ARM, BodySpec::STAND_IN, hand).unwrap();
        let mut pressed = 0.0f64;
        for t in 0..ticks {
            let f = lp.step();
            pressed = pressed.max(f[2]);
            assert_eq!(lp.fault(), None, "tick {t}, hand {hand:?}");
        }
        let mj = lp.rendered_mj();
        assert!(pressed > 0.2, "{hand:?}: pressed only {pressed} N");
        assert!(mj <= 0.0, "{hand:?}: the device put out {mj} mJ");
        most = most.max(mj);
    }
    println!(
        "ARMLOOP case=palpation coupling_n_mm={:.3} hands={} most_energy_out_mj={most:.3}",
        config.coupling_stiffness,
        HANDS.len()
    );
}

/// A held press at that coupling with each hand: no cycle over 2 counts, no energy
/// out; then the hand lets go: the arm comes to rest, the board unfaulted.
#[test]
fn a_held_press_is_still_and_the_released_arm_comes_to_rest() {
    let config = stiffest_board();
    let mut worst = 0.0f64;
    for hand in HANDS {
        let h = held_press(&config, &ARM, BodySpec::STAND_IN, hand).unwrap();
        assert_eq!(verdict(&h), Ok(()), "{hand:?}: {h:?}");
        worst = worst.max(h.cycle_counts.iter().cloned().fold(0.0, f64::max));
    }
    println!("ARMLOOP case=held_press most_cycle_counts={worst:.2}");
    // Released in the tissue (a light hand, held firmly: 1000 N/m): the tissue pushes
    // the arm out; a second later it is still (each joint within one count over the
    // last 0.5 s).
    let hand = HANDS[4];
    assert_eq!(hand.stiffness_n_m, 1000.0);
    let mut lp = ClosedLoop::new(&config, &ARM, BodySpec::STAND_IN, hand).unwrap();
    let start = lp.lead.at(LEAD_TICKS);
    lp.lead.hold = Some(HoldAt {
        from: LEAD_TICKS,
        wait: 500,
        ramp: 500,
        to: [
            start[0],
            start[1],
            lp.lead.device([0.0; 3])[2] - HOLD_DEPTH_MM,
        ],
    });
    while lp.ticks() < LEAD_TICKS + 2500 {
        lp.step();
    }
    assert!(
        lp.probe_mm()[2] < -0.2,
        "pressing before the release: {:?}",
        lp.probe_mm()
    );
    lp.hand = Hand::OFF;
    let (mut lo, mut hi) = ([i32::MAX; 3], [i32::MIN; 3]);
    for t in 0..1500 {
        lp.step();
        assert_eq!(lp.fault(), None, "{t} ticks after the release");
        if t >= 1000 {
            let c = lp.body.counts();
            for k in 0..3 {
                lo[k] = lo[k].min(c[k]);
                hi[k] = hi[k].max(c[k]);
            }
        }
    }
    let spread: Vec<i32> = (0..3).map(|k| hi[k] - lo[k]).collect();
    println!(
        "ARMLOOP case=released rest_mm={:.2} spread_counts={}",
        lp.probe_mm()[2],
        spread.iter().max().unwrap()
    );
    assert!(spread.iter().all(|&s| s <= 1), "not at rest: {spread:?}");
}

/// The edge of the region in devices/woodenhaptics.toml at the board's damping, as the
/// region judges a hand (`hand_verdict`: most of its holds across a count): its stiffness
/// is stable with every hand, the grid's next is not. (`scripts/long.sh` re-measures the
/// whole region against the file.)
#[test]
fn the_device_file_s_edge_is_stable_and_the_next_stiffness_is_not() {
    let b = BOARD.coupling_damping;
    let edge = region().max_coupling(b).unwrap();
    let on_grid = stiffness_grid().any(|k| (k - edge).abs() < 1e-3);
    assert!(
        on_grid,
        "{edge} N/mm is not on the grid: remeasure (`mccs arm stability`)"
    );
    // The arm's stability, not the tick's: any substeps the bound asks for (the board
    // refuses a coupling whose substeps pass its budget; that is not what this measures).
    let at = |k: f64| BoardConfig {
        coupling_stiffness: k,
        coupling_damping: b,
        tick_budget: u32::MAX,
        ..BOARD
    };
    // (Side by side: every hand's holds are needed here.)
    let verdicts = hand_verdicts(&at(edge), &ARM, BodySpec::STAND_IN, &HANDS);
    for (hand, v) in HANDS.iter().zip(verdicts) {
        assert_eq!(v.unwrap(), Ok(()), "{edge} N/mm, {hand:?}");
    }
    let next = edge * 2f64.sqrt();
    let unstable = HANDS.iter().any(|hand| {
        hand_verdict(&at(next), &ARM, BodySpec::STAND_IN, *hand).map_or(true, |v| v.is_err())
    });
    assert!(
        unstable,
        "{next} N/mm is stable with every hand: the region is larger"
    );
}

/// The count the stable region's holds and energy floor are measured in is one count of
/// the forearm's joint at the probe, from the shipped arm: its length over its counts a
/// turn (encoder counts times the capstan's ratio), to 1 µm.
#[test]
fn the_count_at_the_probe_is_the_forearm_s() {
    use mccs_host::arm::closed_loop::COUNT_AT_PROBE_MM;
    let c = &ARM.joints[2];
    let count_mm = ARM.forearm_mm * std::f64::consts::TAU / (c.counts_per_rev * c.ratio);
    assert!(
        (count_mm - COUNT_AT_PROBE_MM).abs() < 1e-3,
        "{count_mm} mm against {COUNT_AT_PROBE_MM}"
    );
}

/// A held press's net energy out is judged against one count's energy in the coupling
/// (½ k c², 0.131 mJ at 64 N/mm): at it, stable; past it, not, with both figures. A
/// joint over 2 counts or a fault is not stable whatever the energy.
#[test]
fn a_press_is_judged_by_its_energy_beyond_a_count_s_in_the_coupling() {
    use mccs_host::arm::closed_loop::{Held, COUNT_AT_PROBE_MM};
    let count_mj = 0.5 * 64.0 * COUNT_AT_PROBE_MM * COUNT_AT_PROBE_MM;
    assert!((count_mj - 0.131072).abs() < 1e-12, "{count_mj}");
    let held = |run_mj: f64, cycle: f64| Held {
        cycle_counts: [cycle, 0.0, 0.0],
        window_mj: 0.0,
        run_mj,
        count_mj,
        most_n: 1.0,
        fault: None,
    };
    assert_eq!(verdict(&held(-1.0, 1.0)), Ok(()));
    assert_eq!(verdict(&held(count_mj, 2.0)), Ok(()));
    assert_eq!(
        verdict(&held(count_mj + 1e-3, 1.0)),
        Err("the device put out 0.132 mJ net, over a count's 0.131 mJ in the coupling".into())
    );
    assert_eq!(
        verdict(&held(-1.0, 2.1)),
        Err("joint A cycles over 2.1 counts".into())
    );
    let faulted = Held {
        fault: Some((7, "EnergyOut".into())),
        ..held(-1.0, 0.0)
    };
    assert_eq!(
        verdict(&faulted),
        Err("the board faulted at tick 7: EnergyOut".into())
    );
}

/// A count's limit cycle at one depth does not decide a hand: at 16 N/mm and the board's
/// damping, a light, stiffly held hand's press held exactly 3 mm deep put out 0.2 mJ net
/// (one hold judged a hand until 2026-11-30, and the region measured 11.3 N/mm there);
/// held across a count it is stable, as at 22.6 to 64 N/mm (docs/safety.md, "The
/// stable region").
#[test]
fn a_count_s_limit_cycle_at_one_depth_does_not_decide_a_hand() {
    let config = BoardConfig {
        coupling_stiffness: 16.0,
        tick_budget: u32::MAX,
        ..BOARD
    };
    for hand in HANDS
        .into_iter()
        .filter(|h| h.mass_kg == 0.1 && h.stiffness_n_m == 1000.0)
    {
        let v = hand_verdict(&config, &ARM, BodySpec::STAND_IN, hand).unwrap();
        assert_eq!(v, Ok(()), "{hand:?}");
    }
}

/// The board's own copy of the region (`haptic_f405::arm::STABLE_REGION`, what it checks
/// its coupling against at start-up) is the device file's.
#[test]
fn the_board_s_stable_region_is_the_device_file_s() {
    assert_eq!(region().points, haptic_f405::arm::STABLE_REGION.to_vec());
}

/// What a direction check on the closed loop did.
struct Checked {
    /// The board's fault, if any.
    fault: Option<String>,
    /// Ticks the check took (the lead waiting at home).
    ticks: u32,
    /// From the first tick joint `joint` was nudged to the verdict: ticks, and how far the
    /// probe moved, mm.
    after_nudge: (u32, f64),
    /// The nudges' work, mJ.
    nudged_mj: f64,
}

/// Runs the loop until the board's direction check has a verdict (or `limit` ticks),
/// watching `joint`'s nudge.
fn direction_check(body: BodySpec, hand: Hand, joint: u8, limit: u32) -> Checked {
    let mut lp = ClosedLoop::new(&BOARD, &ARM, body, hand).unwrap();
    let mut nudged: Option<(u32, [f64; 3])> = None;
    let mut after = (0, 0.0f64);
    for t in 0..limit {
        lp.step();
        if nudged.is_none() && lp.nudging() == Some(joint) {
            nudged = Some((t, lp.probe_mm()));
        }
        if let Some((t0, at)) = nudged {
            let p = lp.probe_mm();
            let moved = (0..3).map(|k| (p[k] - at[k]).powi(2)).sum::<f64>().sqrt();
            after = (t - t0, after.1.max(moved));
        }
        if lp.fault().is_some() || lp.ticks() > HOME_TICKS {
            break;
        }
    }
    assert!(
        lp.fault().is_none() || lp.safe(),
        "a fault not in the safe state"
    );
    Checked {
        fault: lp.fault(),
        ticks: lp.checking_ticks(),
        after_nudge: after,
        nudged_mj: lp.nudged_mj(),
    }
}

/// A motor wired the wrong way round (issue "safe with a hand on it": "reaches the safe
/// state within 50 ms and 20 mm"): the board's start-up nudges find it before any
/// tissue force, whichever joint, whichever hand rests on the handle, within 50 ms and
/// 1 mm of the nudge that finds it; the right wiring passes with every hand and with
/// none.
#[test]
fn a_reversed_motor_is_found_by_its_start_up_nudge_before_any_force() {
    let (mut ms, mut mm) = (0u32, 0.0f64);
    for k in 0..3u8 {
        for hand in HANDS.iter().chain([&Hand::OFF]) {
            let mut body = BodySpec::STAND_IN;
            body.polarity[k as usize] = -1.0;
            let c = direction_check(body, *hand, k, 3000);
            let joint = ["A", "B", "C"][k as usize];
            let said = format!("joint {joint} turning against its drive");
            assert!(
                c.fault.as_deref().is_some_and(|f| f.contains(&said)),
                "joint {joint} reversed, {hand:?}: {:?}",
                c.fault
            );
            (ms, mm) = (ms.max(c.after_nudge.0), mm.max(c.after_nudge.1));
        }
    }
    println!("DIRECTION case=reversed found_ms={ms} moved_mm={mm:.3}");
    assert!(
        ms <= 50 && mm <= 1.0,
        "found {ms} ms and {mm:.3} mm after its nudge"
    );
    let (mut ticks, mut nudged_mj) = (0u32, 0.0f64);
    for hand in HANDS.iter().chain([&Hand::OFF]) {
        let c = direction_check(BodySpec::STAND_IN, *hand, 0, 3000);
        assert_eq!(c.fault, None, "{hand:?}");
        (ticks, nudged_mj) = (ticks.max(c.ticks), nudged_mj.max(c.nudged_mj));
    }
    println!("DIRECTION case=wired_right check_ms={ticks} nudges_mj={nudged_mj:.3}");
}

/// A jammed joint (or one whose motor or amplifier is not connected: the friction here
/// 25 times the stand-in's) fails the check as "not moving", never passes it: no
/// tissue force until a reset.
#[test]
fn a_jammed_joint_fails_the_check_as_not_moving() {
    for k in 0..3 {
        let mut body = BodySpec::STAND_IN;
        body.coulomb_nm[k] *= 25.0;
        let c = direction_check(body, HANDS[0], k as u8, 3000);
        let said = format!("joint {} not moving when nudged", ["A", "B", "C"][k]);
        assert!(
            c.fault.as_deref().is_some_and(|f| f.contains(&said)),
            "{:?}",
            c.fault
        );
    }
}
