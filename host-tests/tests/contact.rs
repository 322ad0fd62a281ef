//! Issue #19's contact tests that hold the roaming contact to physics, run on the `f64`
//! twin (`mccs_host::roam`) and on the fixed-point core in both arithmetics, all on a
//! flat 64 × 64 tissue at 2.5 mm with an N = 5 window: the force is continuous where the
//! contact crosses a triangle's edge or a node, a slow drag switches from stick to slip
//! once and never chatters, a closed loop of the probe puts energy in (never takes it
//! out), and the contact's weights sum to one. Prints `CONTACT` lines (the figures in
//! docs/roaming.md). The core's reaction summing to minus its force to the bit is
//! `mccs::solver::contact`'s own test.

use mccs::{Arith, Length, Narrow, Params, SolverConfig, Wide, WindowConfig};
use mccs_host::patch::{TwinConfig, V};
use mccs_host::reference::Reference;
use mccs_host::roam::{Friction, RoamConfig, RoamTwin, Shape, Tissue};

use crate::common::patch5::{fixed, proxy_config, N, SPACING};

/// One tick of a contact: the device force (N) for the probe at `p` (mm, tissue frame),
/// and whether the contact slips.
type Step<'a> = Box<dyn FnMut(V) -> (V, bool) + 'a>;

/// The twin with friction `mu`, its window centred near `(x, y)`, at the fixed core's
/// substeps.
fn twin_step<'a>(mu: (f64, f64), x: f64, y: f64) -> Step<'a> {
    let cfg = RoamConfig {
        tissue: Tissue::new(64, 64, SPACING, Shape::Flat).unwrap(),
        n: N,
        dynamics: TwinConfig::from_solver(&SolverConfig::default(), fixed::<Wide>().substeps()),
        friction: Friction::new(mu.0, mu.1).unwrap(),
        probe_radius: 0.0,
        window_hysteresis: 0.1,
    };
    let mut tw = RoamTwin::new(cfg, Reference::new(&Params::TABLE2).unwrap(), x, y).unwrap();
    Box::new(move |p| {
        let o = tw.step(p);
        if let Some(c) = tw.contact() {
            let sum: f64 = c.anchor.bary.iter().sum();
            assert!((sum - 1.0).abs() <= 1e-12, "weights sum to {sum}");
            assert!(c.anchor.bary.iter().all(|&w| w >= 0.0), "{:?}", c.anchor);
        }
        (o.force, tw.contact().is_some_and(|c| c.slip.0))
    })
}

/// The fixed-point core in arithmetic `A`, the same configuration.
fn core_step<'a, A: Arith + 'a>(mu: (f64, f64), x: f64, y: f64) -> Step<'a> {
    let mut s = fixed::<A>();
    let mut proxy = s.proxy(&proxy_config(mu, 0.0)).unwrap();
    let wc = WindowConfig {
        tissue_w: 64,
        tissue_h: 64,
        hysteresis: 0.1,
    };
    let mut window = s.window(&wc, &mccs::Flat, &proxy, x, y).unwrap();
    Box::new(move |p| {
        let f = s.step_roaming(p.map(Length::from_num), &mut proxy, &mut window);
        (f.map(|x| x.to_num::<f64>()), proxy.slipping())
    })
}

/// The three contacts: the twin, `Wide`, `Narrow`.
fn each(mu: (f64, f64), x: f64, y: f64) -> [(&'static str, Step<'static>); 3] {
    [
        ("twin", twin_step(mu, x, y)),
        ("wide", core_step::<Wide>(mu, x, y)),
        ("narrow", core_step::<Narrow>(mu, x, y)),
    ]
}

fn norm(a: V) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// The probe lowered from 0.5 mm above `(x, y)` to `depth` below the rest surface over
/// `ramp` ticks, then held `hold` ticks.
fn press(step: &mut Step<'_>, x: f64, y: f64, depth: f64, ramp: usize, hold: usize) {
    for t in 0..=ramp {
        step([x, y, 0.5 - (0.5 + depth) * t as f64 / ramp as f64]);
    }
    for _ in 0..hold {
        step([x, y, -depth]);
    }
}

/// Tissue node 32 of 64 is at 1.25 mm; the cell from it to node 33 spans 1.25 … 3.75 mm,
/// split by its diagonal `y = x`.
const NODE: f64 = 1.25;

/// Pressed 1 mm deep (frictionless, so that the force at a point does not depend on the
/// way there) at points 0.01 mm apart along `dir` through `through`, ±0.1 mm, each held
/// until settled: the largest step of the force between neighbours over its magnitude.
fn sweep(step: &mut Step<'_>, through: (f64, f64), dir: (f64, f64)) -> f64 {
    let l = (dir.0 * dir.0 + dir.1 * dir.1).sqrt();
    let at = |i: i32| {
        let s = 0.01 * i as f64 / l;
        (through.0 + s * dir.0, through.1 + s * dir.1)
    };
    let (x, y) = at(-10);
    press(step, x, y, 1.0, 200, 1500);
    let mut prev: Option<V> = None;
    let mut worst = 0.0f64;
    for i in -10..=10 {
        let (x, y) = at(i);
        let mut f = [0.0; 3];
        for _ in 0..300 {
            f = step([x, y, -1.0]).0;
        }
        if let Some(p) = prev {
            worst = worst.max(norm([0, 1, 2].map(|k| f[k] - p[k])) / norm(p));
        }
        prev = Some(f);
    }
    worst
}

#[test]
fn the_force_is_continuous_across_triangle_edges_and_nodes() {
    // Through a node (slanted, so that it crosses the node's edges too), across a cell's
    // diagonal, and across an edge between two nodes.
    let cases = [
        ("node", (NODE, NODE), (1.0, 0.37)),
        ("diagonal", (2.5, 2.5), (0.0, 1.0)),
        ("edge", (2.5, NODE), (0.2, 1.0)),
    ];
    for (name, through, dir) in cases {
        for (who, mut step) in each((0.0, 0.0), through.0, through.1) {
            let worst = sweep(&mut step, through, dir);
            println!("CONTACT case=continuity_{name}_{who} max_step_rel={worst:.2e}");
            assert!(
                worst <= 0.005,
                "{who}, across the {name}: a step of {worst:.3e} of the force over 0.01 mm"
            );
        }
    }
}

#[test]
fn a_slow_drag_slips_once_and_never_chatters() {
    // μ_s > μ_k; pressed 1 mm, then dragged 10 mm along x at 2 mm/s (the window shifts
    // on the way).
    let (x0, y0) = (-5.0, 0.4);
    for (who, mut step) in each((0.6, 0.4), x0, y0) {
        press(&mut step, x0, y0, 1.0, 200, 500);
        let (mut switches, mut toggles) = (0, 0);
        let mut was = step([x0, y0, -1.0]).1;
        assert!(!was, "{who}: slipping before the drag");
        for t in 1..=5000 {
            let x = x0 + 2.0 * t as f64 / 1000.0;
            let slips = step([x, y0, -1.0]).1;
            if slips != was {
                if slips && switches == 0 {
                    switches = 1;
                } else {
                    toggles += 1;
                }
            }
            was = slips;
        }
        println!("CONTACT case=drag_{who} stick_to_slip={switches} toggles={toggles}");
        assert_eq!(switches, 1, "{who}: never slipped");
        assert_eq!(toggles, 0, "{who}: {toggles} toggles after the first slip");
        assert!(was, "{who}: not slipping at the end of the drag");
    }
}

/// Around a closed loop: from 1 mm above `(x, y) + (3, 0)`, press 1 mm in over 0.3 s, go
/// twice around a circle of 3 mm about `(x, y)` at 10 mm/s, lift back to the start over
/// 0.3 s and wait 1 s above. The energy the device put in, `−Σ F_t · (p_{t+1} − p_t)`
/// (the force held over each tick, as a device renders it), mJ; and the largest energy
/// stored in the way in (the running sum's peak).
fn loop_energy(step: &mut Step<'_>, x: f64, y: f64) -> (f64, f64) {
    let r = 3.0;
    let ramp = 300;
    let turn = (2.0 * std::f64::consts::PI * r / 10.0 * 1000.0) as usize;
    let path = |t: usize| -> V {
        if t <= ramp {
            [x + r, y, 1.0 - 2.0 * t as f64 / ramp as f64]
        } else if t <= ramp + 2 * turn {
            let a = 2.0 * std::f64::consts::PI * (t - ramp) as f64 / turn as f64;
            [x + r * a.cos(), y + r * a.sin(), -1.0]
        } else if t <= 2 * ramp + 2 * turn {
            [
                x + r,
                y,
                -1.0 + 2.0 * (t - ramp - 2 * turn) as f64 / ramp as f64,
            ]
        } else {
            [x + r, y, 1.0]
        }
    };
    let (mut energy, mut peak) = (0.0f64, 0.0f64);
    let end = 2 * ramp + 2 * turn + 1000;
    for t in 0..end {
        let (p, next) = (path(t), path(t + 1));
        let f = step(p).0;
        energy -= (0..3).map(|k| f[k] * (next[k] - p[k])).sum::<f64>();
        peak = peak.max(energy);
    }
    assert_eq!(path(0), path(end), "the loop is not closed");
    (energy, peak)
}

#[test]
fn a_closed_loop_puts_energy_in() {
    for (name, mu) in [("frictionless", (0.0, 0.0)), ("friction", (0.6, 0.4))] {
        for (who, mut step) in each(mu, -2.0, 0.4) {
            let (energy, peak) = loop_energy(&mut step, -2.0, 0.4);
            println!(
                "CONTACT case=loop_{name}_{who} energy_in_mj={energy:.4e} \
                 peak_mj={peak:.4e}"
            );
            assert!(
                energy >= 0.0,
                "{who}, {name}: the loop took {energy:.3e} mJ out of the tissue"
            );
        }
    }
}
