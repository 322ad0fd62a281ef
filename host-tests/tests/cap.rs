//! The fixed-point core roaming a spherical cap (`mccs::Sphere`) against the
//! `f64` roaming twin: palpations over the cap's top and down its slope, both arithmetics,
//! frictionless and with friction; the rest geometry a shift computes against a window
//! built in place; the rest state kept at rest; the refusals.

use mccs::{
    Arith, Flat, ForceTable64, Length, Narrow, Params, ProxyConfig, ProxyError, ShapeSpec, Solver,
    SolverConfig, Sphere, Topology, Wide, WindowConfig,
};
use mccs_host::patch::{TwinConfig, V};
use mccs_host::reference::Reference;
use mccs_host::roam::{Friction, RoamConfig, RoamTwin, Shape, Tissue};

use crate::common::patch5::{device_max, fixed, proxy_config, Fixed, N, SPACING};

const SIDE: usize = 64;
/// A cap over the 64 × 64 tissue (half-diagonal 111.4 mm; the smallest radius is 148.5).
const RADIUS: f64 = 150.0;

const TISSUE: WindowConfig = WindowConfig {
    tissue_w: SIDE,
    tissue_h: SIDE,
    hysteresis: 0.1,
};

/// The cap of radius `r` mm.
fn sphere(r: f64) -> Sphere {
    Sphere { radius_mm: r }
}

/// The cap's surface point above `(x, y)` and its normal.
fn on_cap(x: f64, y: f64) -> (V, V) {
    let z = (RADIUS * RADIUS - x * x - y * y).sqrt() - RADIUS;
    ([x, y, z], [x / RADIUS, y / RADIUS, (z + RADIUS) / RADIUS])
}

/// A palpation from `(x0, y0)` along `x`: from 1.5 mm above the cap, press to 1 mm deep
/// along the normal over 0.2 s, hold 0.3 s, slide 30 mm at 10 mm/s at that depth, press
/// to 1.5 mm, slide back, lift (5 s).
fn palpation(x0: f64, y0: f64, t: usize) -> V {
    let s = t as f64 / 1000.0;
    let depth = if s < 0.2 {
        -1.5 + 2.5 * s / 0.2
    } else if s < 3.5 {
        1.0
    } else if s < 3.7 {
        1.0 + 0.5 * (s - 3.5) / 0.2
    } else if s < 4.7 {
        1.5
    } else {
        1.5 - (s - 4.7) * 10.0
    };
    let x = if s < 3.5 {
        x0 + ((s - 0.5).max(0.0) * 10.0).min(30.0)
    } else {
        x0 + 30.0 - ((s - 3.7).max(0.0) * 30.0).min(30.0)
    };
    let (p, n) = on_cap(x, y0);
    [0, 1, 2].map(|k| p[k] - depth * n[k])
}

/// Runs a palpation through the core and the twin; returns the RMS and the largest force
/// difference over the twin's peak force, the core's shifts, and the ticks on which the
/// two windows were apart.
fn compare<A: Arith>(mu: (f64, f64), radius: f64, x0: f64, y0: f64) -> (f64, f64, u32, u32) {
    let mut s = fixed::<A>();
    let mut proxy = s.proxy(&proxy_config(mu, radius)).unwrap();
    let start = palpation(x0, y0, 0);
    let mut window = s
        .window(&TISSUE, &sphere(RADIUS), &proxy, start[0], start[1])
        .unwrap();
    let cfg = RoamConfig {
        tissue: Tissue::new(SIDE, SIDE, SPACING, Shape::Cap { radius: RADIUS }).unwrap(),
        n: N,
        dynamics: TwinConfig::from_solver(&SolverConfig::default(), s.substeps()),
        friction: Friction::new(mu.0, mu.1).unwrap(),
        probe_radius: radius,
        window_hysteresis: 0.1,
    };
    let mut tw = RoamTwin::new(
        cfg,
        Reference::new(&Params::TABLE2).unwrap(),
        start[0],
        start[1],
    )
    .unwrap();
    assert_eq!(window.centre(), tw.centre());
    let (mut sum2, mut worst, mut peak, mut apart) = (0.0f64, 0.0f64, 0.0f64, 0);
    let ticks = 5000;
    for t in 0..ticks {
        let p = palpation(x0, y0, t);
        let got = s.step_roaming(p.map(Length::from_num), &mut proxy, &mut window);
        let want = tw.step(p).force;
        let got = got.map(|f| f.to_num::<f64>());
        let d2: f64 = (0..3).map(|k| (got[k] - want[k]).powi(2)).sum();
        sum2 += d2;
        worst = worst.max(d2.sqrt());
        peak = peak.max(want.iter().map(|f| f * f).sum::<f64>().sqrt());
        if window.centre() != tw.centre() {
            apart += 1;
        }
        assert_eq!(
            proxy.grid_position().is_some(),
            tw.contact().is_some(),
            "tick {t}: contact"
        );
    }
    assert_eq!(window.shifts(), tw.shifts);
    let rms = (sum2 / ticks as f64).sqrt();
    (rms / peak, worst / peak, window.shifts(), apart)
}

/// The issue's bound for the core against the twin along a palpation: RMS ≤ 0.5 %, max ≤
/// 2 % of the peak force; over the cap's top and down its slope (where the normal leans
/// by 17° … 30°), a point and a 1 mm sphere, frictionless and with friction, both
/// arithmetics. The windows agree on all but at most two ticks: where the contact creeps
/// across a shift's limit the last bits decide the tick. (The paths start off the grid's
/// lines: at 10 mm/s from a node's line the contact lands on the limit exactly.)
#[test]
fn the_core_roams_a_cap_with_the_twin() {
    for (name, mu, radius, x0, y0) in [
        ("top", (0.6, 0.4), 0.0, -15.0737, 0.4),
        ("top-frictionless", (0.0, 0.0), 0.0, -15.0737, 0.4),
        ("top-sphere", (0.0, 0.0), 1.0, -15.0737, 0.4),
        ("slope", (0.6, 0.4), 0.0, 40.5737, 20.3),
        ("slope-frictionless", (0.0, 0.0), 0.0, 40.5737, 20.3),
        ("slope-sphere", (0.0, 0.0), 1.0, 40.5737, 20.3),
        ("slope-sphere-friction", (0.6, 0.4), 1.0, 40.5737, 20.3),
    ] {
        let (rms_w, max_w, shifts, apart_w) = compare::<Wide>(mu, radius, x0, y0);
        let (rms_n, max_n, _, apart_n) = compare::<Narrow>(mu, radius, x0, y0);
        let apart = apart_w.max(apart_n);
        println!(
            "CAPTWIN case={name} wide_rms_rel={rms_w:.2e} wide_max_rel={max_w:.2e} narrow_rms_rel={rms_n:.2e} narrow_max_rel={max_n:.2e} shifts={shifts} ticks_apart={apart}"
        );
        assert!(shifts >= 20, "{name}: {shifts} shifts");
        assert!(
            apart <= 2,
            "{name}: the windows were apart on {apart} ticks"
        );
        for (what, rms, max) in [("wide", rms_w, max_w), ("narrow", rms_n, max_n)] {
            assert!(
                rms <= 0.005 && max <= 0.02,
                "{name} {what}: RMS {rms:.2e}, max {max:.2e}"
            );
        }
    }
}

/// After any shifts, every spring's rest geometry equals that of a window built in place
/// (within one unit of its last place), and the free nodes' rest heights equal too: a
/// shift computes what start-up computes. The probe goes out along +x and +y and back
/// along −x and −y (the geometry moves in place, in each direction's own order).
/// Without the flip of a continued spring's direction, with a wrong entering height, or
/// with a source overwritten before it is read, this fails.
#[test]
fn a_shifted_window_has_the_geometry_of_one_built_in_place() {
    let mut s = fixed::<Wide>();
    let mut proxy = s.proxy(&proxy_config((0.0, 0.0), 0.0)).unwrap();
    let mut window = s
        .window(&TISSUE, &sphere(RADIUS), &proxy, -40.0, -30.0)
        .unwrap();
    // The probe far above the cap, moving over it: the window follows the probe.
    let mut checked = 0;
    for t in 0..=2400 {
        let a = if t <= 1200 { t } else { 2400 - t } as f64 / 1200.0;
        let (x, y) = (-40.0 + 95.0 * a, -30.0 + 80.0 * a * a);
        s.step_roaming([x, y, 30.0].map(Length::from_num), &mut proxy, &mut window);
        if t % 100 != 0 {
            continue;
        }
        let (ci, cj) = window.centre();
        let at = |i: usize| (i as f64 - (SIDE - 1) as f64 / 2.0) * SPACING;
        let mut fresh = fixed::<Wide>();
        let fresh_proxy = fresh.proxy(&proxy_config((0.0, 0.0), 0.0)).unwrap();
        let w2 = fresh
            .window(&TISSUE, &sphere(RADIUS), &fresh_proxy, at(ci), at(cj))
            .unwrap();
        assert_eq!(w2.centre(), (ci, cj));
        for (e, (got, want)) in s
            .topology()
            .edges()
            .iter()
            .zip(fresh.topology().edges())
            .enumerate()
        {
            let close = (0..3).all(|k| (got.dir[k] - want.dir[k]).abs() <= 1)
                && (got.inv_len - want.inv_len).abs() <= 1;
            assert!(
                close,
                "tick {t} window {ci},{cj} edge {e}: {got:?} vs {want:?}"
            );
        }
        for i in 1..s.topology().node_count() as u16 {
            assert_eq!(
                s.topology().rest(i),
                fresh.topology().rest(i),
                "tick {t} node {i}"
            );
        }
        checked += 1;
    }
    assert!(window.shifts() >= 80, "{} shifts", window.shifts());
    assert_eq!(checked, 25);
}

/// Out of contact the cap's window stays at rest through its shifts, in both
/// arithmetics: its rest geometry holds no strain beyond its directions' rounding (Q23:
/// the flat patch's diagonals move its nodes by about 1e-6 mm in the wide arithmetic),
/// each node within 1e-5 mm of rest.
#[test]
fn the_cap_at_rest_stays_at_rest() {
    fn run<A: Arith, Spec: ShapeSpec>(shape: &Spec) -> f64 {
        let mut s = fixed::<A>();
        let mut proxy = s.proxy(&proxy_config((0.0, 0.0), 0.0)).unwrap();
        let mut window = s.window(&TISSUE, shape, &proxy, 0.0, 0.0).unwrap();
        let mut worst = 0.0f64;
        for t in 0..2000 {
            let x = 75.0 * (t as f64 / 2000.0);
            s.step_roaming([x, -x, 5.0].map(Length::from_num), &mut proxy, &mut window);
            for i in 1..s.topology().node_count() as u16 {
                let u = s.displacement(i).unwrap().map(|c| c.to_num::<f64>());
                worst = worst.max(u.iter().map(|c| c.abs()).fold(0.0, f64::max));
            }
        }
        assert!(window.shifts() >= 40);
        worst
    }
    let (flat_wide, flat_narrow) = (run::<Wide, _>(&Flat), run::<Narrow, _>(&Flat));
    let cap = sphere(RADIUS);
    let (wide, narrow) = (run::<Wide, _>(&cap), run::<Narrow, _>(&cap));
    println!(
        "CAPREST wide_max_disp_mm={wide:.2e} narrow_max_disp_mm={narrow:.2e} flat_wide_max_disp_mm={flat_wide:.2e} flat_narrow_max_disp_mm={flat_narrow:.2e}"
    );
    assert!(wide <= 1e-5 && narrow <= 1e-5, "{wide:e} {narrow:e}");
}

/// Radii outside 4/3 of the half-diagonal … 2000 mm, a cap whose base would reach below
/// −100 mm, and (in the M0's arithmetic) springs longer than 16 mm are refused.
#[test]
fn caps_the_core_cannot_run_are_refused() {
    let mut s = fixed::<Wide>();
    let proxy = s.proxy(&proxy_config((0.0, 0.0), 0.0)).unwrap();
    assert!(s.window(&TISSUE, &sphere(148.5), &proxy, 0.0, 0.0).is_ok());
    for bad in [148.0, 2000.5, f64::NAN, -150.0] {
        let got = s.window(&TISSUE, &sphere(bad), &proxy, 0.0, 0.0).err();
        assert_eq!(got, Some(ProxyError::Cap), "radius {bad}");
    }
    // 41 × 41 at 5 mm (±100 mm): the smallest cap's corner lies 63.9 mm down, its base
    // 68.9 mm: runs. At 10 mm (21 × 21) with the M0's 16 mm limit its diagonal is too long.
    let wide = |grid: usize, spacing: f64| {
        let topo = Topology::<10, 61>::standard_patch(grid, spacing).unwrap();
        let table = ForceTable64::new(&Params::TABLE2).unwrap();
        Solver::<10, 61, 64>::new(topo, table, &SolverConfig::default()).unwrap()
    };
    let mut s = wide(N, 5.0);
    let p = s
        .proxy(&ProxyConfig {
            spacing: 5.0,
            ..proxy_config((0.0, 0.0), 0.0)
        })
        .unwrap();
    let cfg = |w: usize| WindowConfig {
        tissue_w: w,
        tissue_h: w,
        hysteresis: 0.1,
    };
    let smallest = sphere(4.0 / 3.0 * 141.43);
    assert!(s.window(&cfg(41), &smallest, &p, 0.0, 0.0).is_ok());
    let topo = Topology::<10, 61>::standard_patch(N, 10.0).unwrap();
    let table = ForceTable64::new(&Params::TABLE2).unwrap();
    let mut m0 = Solver::with_arith(topo, table, &SolverConfig::default(), Narrow).unwrap();
    let p = m0
        .proxy(&ProxyConfig {
            spacing: 10.0,
            ..proxy_config((0.0, 0.0), 0.0)
        })
        .unwrap();
    assert_eq!(
        m0.window(&cfg(21), &smallest, &p, 0.0, 0.0).err(),
        Some(ProxyError::Cap)
    );
}

mod robust {
    use super::*;
    use proptest::prelude::*;

    fn roam<A: Arith>(r_cap: f64, mu: (f64, f64), radius: f64, probes: &[(f64, f64, f64)]) {
        let mut s = fixed::<A>();
        let mut proxy = s.proxy(&proxy_config(mu, radius)).unwrap();
        let mut window = s.window(&TISSUE, &sphere(r_cap), &proxy, 0.0, 0.0).unwrap();
        let height = |x: f64, y: f64| (r_cap * r_cap - x * x - y * y).max(0.0).sqrt() - r_cap;
        let max = device_max();
        for &(x, y, dz) in probes {
            let p = [x, y, height(x, y) + dz];
            let f = s.step_roaming(p.map(Length::saturating_from_num), &mut proxy, &mut window);
            let f = f.map(|c| c.to_num::<f64>());
            let mag = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
            assert!(mag <= max, "{mag} N over the maximum at {p:?}");
            // Never pulling the probe into the tissue: along the normal the contact used
            // (the cap's at the proxy's rest point), within the components' truncation;
            // and that normal within the cap's normals near the proxy.
            if let Some(q) = s.proxy_point_in(&proxy, &window) {
                let n = proxy.normal();
                let along = f[0] * n[0] + f[1] * n[1] + f[2] * n[2];
                assert!(along >= -1e-5, "pulled in: {f:?} against {n:?}");
                let o = window.origin_mm().map(|c| c.to_num::<f64>());
                let (qx, qy) = (q[0].to_num::<f64>() + o[0], q[1].to_num::<f64>() + o[1]);
                let exact = [qx / r_cap, qy / r_cap, (height(qx, qy) + r_cap) / r_cap];
                let cos: f64 = (0..3).map(|k| n[k] * exact[k]).sum();
                assert!(
                    cos > 0.999,
                    "normal {n:?} against the cap's {exact:?} near the proxy"
                );
            } else {
                assert_eq!(mag, 0.0, "a force out of contact at {p:?}");
            }
            let (i, j) = window.centre();
            assert!((N / 2..SIDE - N / 2).contains(&i) && (N / 2..SIDE - N / 2).contains(&j));
        }
    }

    /// 64 cases in the test command; `PROPTEST_CASES` for a long run (`scripts/long.sh`).
    fn cases() -> u32 {
        std::env::var("PROPTEST_CASES")
            .ok()
            .and_then(|c| c.parse().ok())
            .unwrap_or(64)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(cases()))]
        /// Any probe path over any cap the 64 × 64 tissue takes, from anywhere within
        /// ±100 mm (and 60 mm above or below the cap) in jumps of any size, or wandering
        /// near its surface: no panic (overflow checks are on here), the force within the
        /// device maximum and never pulling the probe into the tissue, none out of
        /// contact, the window on the tissue; both arithmetics.
        #[test]
        fn any_probe_path_over_any_cap_is_safe(
            r_cap in 148.5f64..2000.0,
            mu in (0.0f64..2.0, 0.0f64..2.0),
            radius in 0.0f64..1.25,
            probes in prop::collection::vec(
                prop_oneof![
                    (-100.0f64..100.0, -100.0f64..100.0, -60.0f64..60.0),
                    (-8.0f64..8.0, -8.0f64..8.0, -3.0f64..1.0),
                    (50.0f64..70.0, -70.0f64..-50.0, -3.0f64..1.0),
                ],
                1..150,
            ),
        ) {
            roam::<Wide>(r_cap, mu, radius, &probes);
            roam::<Narrow>(r_cap, mu, radius, &probes);
        }
    }
}

/// A parameter set for a solver on a cap comes from the flat patch's topology (the
/// solver keeps the flat patch's fingerprint and substeps); one prepared from the cap's
/// current geometry is refused, so that a set's substeps are always the flat patch's.
#[test]
fn a_param_set_on_a_cap_is_prepared_from_the_flat_patch() {
    let mut s = fixed::<Wide>();
    let proxy = s.proxy(&proxy_config((0.0, 0.0), 0.0)).unwrap();
    s.window(&TISSUE, &sphere(RADIUS), &proxy, 40.0, 20.0)
        .unwrap();
    let table = ForceTable64::new(&Params::TABLE2).unwrap();
    let config = SolverConfig::default();
    let own = s.prepare(table, &config).unwrap();
    assert_eq!(s.apply(own).err(), Some(mccs::SolverError::ForeignParamSet));
    let flat = Topology::<10, 61>::standard_patch(N, SPACING).unwrap();
    let set = Fixed::<Wide>::prepare_for(&flat, table, &config).unwrap();
    assert!(s.apply(set).is_ok());
}
