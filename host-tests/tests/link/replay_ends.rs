//! How a replay on the device ends when its host does not see it through: one of no
//! samples ends at once, and one whose path stops coming is abandoned once it has waited
//! `mccs_link::rates::REPLAY_STARVED_MS` for it, with `ReplayEnd` and the ticks it ran.
//! Either way the device's one job is free again: a tissue load is taken (a stalled
//! replay held it, and every load after it was refused `Busy`, until a new replay).

use super::rig::Rig;
use haptic_f405::BOARD;
use mccs::{ForceTable64, Params};
use mccs_client::Tissue;
use mccs_link::replay::PathPoint;
use mccs_link::*;

fn table2() -> ForceTable64 {
    ForceTable64::new(&Params::TABLE2).unwrap()
}

fn spec(samples: u32) -> ReplaySpec {
    super::rig::replay_spec(samples, [0.0; 3], None)
}

/// The device's ticks a replay waits for its path before it is abandoned.
fn starved_ticks() -> u32 {
    BOARD.tick_hz * rates::REPLAY_STARVED_MS / 1000
}

/// A tissue load, as a host sends it: its answer (`Ack` once the tick runs it, or the
/// refusal).
fn load(rig: &mut Rig<mccs_firmware::Glued>) -> ToHost {
    let t = Tissue::from_params(&Params::TABLE2).unwrap();
    super::rig::load(rig, &t, 0, t.hash())
}

/// The replay's rows (their ticks) and its end (its ticks) the device sent since the
/// last call.
fn replayed(rig: &mut Rig<mccs_firmware::Glued>) -> (Vec<u32>, Option<u32>) {
    let (mut rows, mut end) = (Vec::new(), None);
    for m in rig.out.drain(..) {
        match m {
            ToHost::ReplayRow(r) => rows.push(r.tick),
            ToHost::ReplayEnd { ticks } => end = Some(ticks),
            _ => {}
        }
    }
    (rows, end)
}

/// `n` path samples from `first` on, the probe 1 mm into the tissue.
fn path(rig: &mut Rig<mccs_firmware::Glued>, first: u32, n: usize) {
    let at = PathPoint([0, 0, -(1 << 24)]).to_bytes();
    let points: Vec<u8> = (0..n).flat_map(|_| at).collect();
    rig.send(&ToDevice::ReplayPath {
        first,
        points: &points,
    });
}

#[test]
fn a_replay_of_no_samples_ends_at_once() {
    let mut rig = Rig::glued(table2());
    let credit = rig.ask(&ToDevice::ReplayBegin(spec(0)), 5, |m| {
        matches!(m, ToHost::ReplayCredit { .. })
    });
    assert_eq!(credit, ToHost::ReplayCredit { until: 0 });
    let end = rig.wait(5, |m| matches!(m, ToHost::ReplayEnd { .. }));
    assert_eq!(end, ToHost::ReplayEnd { ticks: 0 });
    assert!(matches!(load(&mut rig), ToHost::Ack { .. }));
}

#[test]
fn a_replay_whose_path_stops_coming_is_abandoned_and_loads_are_taken_again() {
    let mut rig = Rig::glued(table2());
    rig.ask(&ToDevice::ReplayBegin(spec(100)), 5, |m| {
        matches!(m, ToHost::ReplayCredit { .. })
    });
    path(&mut rig, 0, 10);
    let starved = starved_ticks();
    // Its ten rows, then nothing until it has waited its limit for the eleventh sample.
    let (mut rows, mut end) = (Vec::new(), None);
    for tick in 0..starved + 20 {
        rig.step();
        let (r, e) = replayed(&mut rig);
        rows.extend(r);
        if let Some(ticks) = e {
            end = Some((ticks, tick));
            break;
        }
    }
    let (ticks, at) = end.expect("the starved replay never ended");
    assert_eq!(rows, (0..10).collect::<Vec<u32>>());
    assert_eq!(ticks, 10);
    assert!(
        (starved..starved + 10).contains(&at),
        "ended at tick {at}, its limit {starved} ticks"
    );
    // Its path past the end is out of order; the device takes a load again.
    path(&mut rig, 10, 1);
    assert_eq!(
        rig.wait(5, |m| matches!(m, ToHost::Nak(_))),
        ToHost::Nak(NakReason::Order)
    );
    assert!(matches!(load(&mut rig), ToHost::Ack { .. }));
}

/// A replay the host feeds slowly, each sample within the limit, runs to its end.
#[test]
fn a_replay_fed_within_the_limit_runs_to_its_end() {
    let mut rig = Rig::glued(table2());
    rig.ask(&ToDevice::ReplayBegin(spec(6)), 5, |m| {
        matches!(m, ToHost::ReplayCredit { .. })
    });
    let mut rows = Vec::new();
    for k in 0..6 {
        path(&mut rig, k, 1);
        for _ in 0..starved_ticks() - 5 {
            rig.step();
        }
        let (r, end) = replayed(&mut rig);
        rows.extend(r);
        assert_eq!(end, (k == 5).then_some(6), "after sample {k}");
    }
    assert_eq!(rows, (0..6).collect::<Vec<u32>>());
}
