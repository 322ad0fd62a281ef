//! The main loop hands parameter sets to the tick through a `Mailbox` (double buffer):
//! under real concurrency (two threads, critical-section's std implementation), every tick
//! runs wholly on the old set or wholly on a new one, never a mix.

use mccs::{ForceTable64, ParamSet, Params};
use mccs_firmware::demo::{self, SmallDemoController};
use mccs_firmware::{Mailbox, Shared, Telemetry};
use std::sync::atomic::{AtomicBool, Ordering};

static SWAP: Mailbox<ParamSet<64>> = Mailbox::new();
static TELEMETRY: Shared<Telemetry> = Shared::new(Telemetry::new());
static DONE: AtomicBool = AtomicBool::new(false);

#[test]
fn a_tick_runs_on_one_whole_parameter_set() {
    let spec = demo::M3;
    let ctl: SmallDemoController = spec
        .controller(&ForceTable64::new(&Params::TABLE2).unwrap())
        .unwrap();
    let a = spec.swapped_set::<10, 61, mccs::DefaultArith>().unwrap();
    let b = ctl
        .solver()
        .prepare(*ctl.solver().table(), &spec.config())
        .unwrap();
    assert_ne!(a.table(), b.table());

    let poster = std::thread::spawn(move || {
        let mut posts = 0u32;
        while !DONE.load(Ordering::Relaxed) {
            let _ = SWAP.post(if posts.is_multiple_of(2) { a } else { b });
            posts += 1;
            if posts.is_multiple_of(7) {
                std::thread::yield_now();
            }
        }
        posts
    });

    let mut ctl = ctl;
    let mut swaps_seen = 0;
    let mut ticks = 0u32;
    // Tick until 50 swaps have happened (the threads interleave as the OS pleases).
    while swaps_seen < 50 && ticks < 200_000 {
        ticks += 1;
        if ticks.is_multiple_of(5) {
            std::thread::yield_now();
        }
        // What the tick could produce: the active set, A, or B — each wholly.
        let candidates: Vec<_> = [None, Some(a), Some(b)]
            .into_iter()
            .map(|set| {
                let (mut solver, mut device) = (ctl.solver().clone(), *ctl.device());
                let mut contact = ctl.contact().clone();
                if let Some(s) = set {
                    solver.apply(s).expect("prepared for this solver");
                }
                let p = mccs_firmware::HapticDevice::read_position(&mut device).unwrap();
                mccs_firmware::Contact::step(&mut contact, &mut solver, p)
            })
            .collect();
        let swap = SWAP.take();
        swaps_seen += swap.is_some() as u32;
        let force = ctl.tick(swap);
        assert!(candidates.contains(&force), "a tick mixed parameter sets");
        let (t, k) = (ctl.solver().table(), ctl.solver().substeps());
        assert!(
            (t == a.table() && k == a.substeps()) || (t == b.table() && k == b.substeps()),
            "the active set is not one of the posted ones"
        );
        TELEMETRY.set(ctl.telemetry());
    }
    DONE.store(true, Ordering::Relaxed);
    let posts = poster.join().unwrap();
    assert!(swaps_seen >= 50, "posts {posts}, swaps {swaps_seen}");
    assert_eq!(TELEMETRY.get().ticks, ticks);
}

#[test]
fn an_untaken_post_is_returned_to_the_poster() {
    let m: Mailbox<u32> = Mailbox::new();
    assert_eq!(m.post(1), None);
    assert_eq!(m.post(2), Some(1));
    assert_eq!(m.take(), Some(2));
    assert_eq!(m.take(), None);
}

#[test]
fn host_demo_matches_a_hand_run() {
    for spec in [demo::M4F, demo::M3, demo::M0] {
        let s = demo::run_on_host(&spec).unwrap();
        assert_eq!(s.ticks, spec.ticks());
        assert_eq!(s.overruns, 0);
        // 1 mm deep (the first hold): about 0.7 N on every core's patch.
        assert!(
            s.steady_force > 0.6 && s.steady_force < 0.8,
            "{}",
            s.steady_force
        );
        assert!(s.max_force > s.steady_force);
        // Two 30 mm slides at 2.5 mm a node: 11 shifts each.
        assert_eq!(s.window_shifts, 22);
    }
}
