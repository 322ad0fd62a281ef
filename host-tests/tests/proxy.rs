//! The fixed-point proxy contact (`mccs::proxy`, `Solver::step_proxy`) against the `f64`
//! roaming twin on a tissue the size of the patch (its window cannot move): the same
//! press and slides, frictionless and with friction, in both arithmetics.

use mccs::{Arith, Length, Narrow, Params, ProxyConfig, ProxyError, SolverConfig, Wide};
use mccs_host::patch::{TwinConfig, V};
use mccs_host::reference::Reference;
use mccs_host::roam::{Friction, RoamConfig, RoamTwin, Shape, Tissue};

use crate::common::patch5::{build, device_max, fixed, proxy_config, N, SPACING};

fn twin(substeps: u32, mu: (f64, f64), radius: f64) -> RoamTwin {
    let cfg = RoamConfig {
        tissue: Tissue::new(N, N, SPACING, Shape::Flat).unwrap(),
        n: N,
        dynamics: TwinConfig::from_solver(&SolverConfig::default(), substeps),
        friction: Friction::new(mu.0, mu.1).unwrap(),
        probe_radius: radius,
        window_hysteresis: 0.1,
    };
    RoamTwin::new(cfg, Reference::new(&Params::TABLE2).unwrap(), 0.0, 0.0).unwrap()
}

/// From 1.5 mm above (out of reach of a 1 mm sphere), press at (0.3, 0.2) to 1 mm over
/// 0.2 s, hold 0.3 s, slide 2 mm along x and 1 mm along y at 10 mm/s, hold, lift.
fn path(t: usize) -> V {
    let s = t as f64 / 1000.0;
    let z = if s < 0.2 {
        1.5 - 2.5 * s / 0.2
    } else if s < 1.1 {
        -1.0
    } else {
        -1.0 + (s - 1.1) * 10.0
    };
    let slide = ((s - 0.5).max(0.0) * 10.0).min(2.0);
    let side = ((s - 0.7).max(0.0) * 10.0).min(1.0);
    [0.3 + slide, 0.2 + side, z]
}

/// The solver at rest that the tests keep and clone (`common::patch5::fixed`) is a
/// fresh build: the same state, and the same forces along a press and a slide with
/// friction, in both arithmetics, after it has been cloned and run before.
#[test]
fn the_kept_solver_at_rest_is_a_fresh_build() {
    fn run<A: Arith>(mut s: crate::common::patch5::Fixed<A>) -> Vec<[mccs::Force; 3]> {
        let mut proxy = s.proxy(&proxy_config((0.6, 0.4), 0.5)).unwrap();
        (0..800)
            .map(|t| s.step_proxy(path(t).map(Length::from_num), &mut proxy))
            .collect()
    }
    fn same<A: Arith>() {
        let first = run(fixed::<A>());
        let kept = fixed::<A>();
        let fresh = build::<A>();
        assert_eq!(format!("{kept:?}"), format!("{fresh:?}"));
        assert_eq!(run(kept), run(fresh));
        assert_eq!(first, run(build::<A>()));
    }
    same::<Wide>();
    same::<Narrow>();
}

/// How far the core's force `got` is from the twin's `want`, and `|want|` (N).
fn off_by(got: [mccs::Force; 3], want: V) -> (f64, f64) {
    let got = got.map(|f| f.to_num::<f64>());
    let mag = (want[0].powi(2) + want[1].powi(2) + want[2].powi(2)).sqrt();
    let diff = (0..3)
        .map(|k| (got[k] - want[k]).powi(2))
        .sum::<f64>()
        .sqrt();
    (diff, mag)
}

/// Runs the path in both; returns the largest force difference over the twin's force
/// magnitude (where it is above 0.05 N), and whether the slip states agreed.
fn compare<A: Arith>(mu: (f64, f64), radius: f64) -> (f64, usize) {
    let mut s = fixed::<A>();
    let config = proxy_config(mu, radius);
    let mut proxy = s.proxy(&config).unwrap();
    let mut tw = twin(s.substeps(), mu, radius);
    let (mut worst, mut slip_disagree) = (0.0f64, 0);
    for t in 0..1300 {
        let p = path(t);
        let got = s.step_proxy(p.map(Length::from_num), &mut proxy);
        let want = tw.step(p).force;
        let (diff, mag) = off_by(got, want);
        assert!(
            diff < 0.02 + 0.02 * mag,
            "tick {t}: {got:?} against {want:?}"
        );
        if mag > 0.05 {
            worst = worst.max(diff / mag);
        }
        let twin_slips = tw.contact().is_some_and(|c| c.slip.0);
        assert_eq!(
            proxy.grid_position().is_some(),
            tw.contact().is_some(),
            "tick {t}: contact"
        );
        if proxy.slipping() != twin_slips {
            slip_disagree += 1;
        }
    }
    (worst, slip_disagree)
}

#[test]
fn the_fixed_proxy_follows_the_twin() {
    for (name, mu, radius) in [
        ("frictionless", (0.0, 0.0), 0.0),
        ("friction", (0.6, 0.4), 0.0),
        ("friction_sphere", (0.6, 0.4), 1.0),
    ] {
        let (wide, wide_slip) = compare::<Wide>(mu, radius);
        let (narrow, narrow_slip) = compare::<Narrow>(mu, radius);
        println!(
            "PROXY case={name} wide_rel={wide:.2e} narrow_rel={narrow:.2e} \
             slip_ticks_disagreeing_wide={wide_slip} slip_ticks_disagreeing_narrow={narrow_slip}"
        );
        assert!(wide <= 0.01, "{name}: wide off by {wide:.3e}");
        assert!(narrow <= 0.02, "{name}: narrow off by {narrow:.3e}");
        assert!(
            wide_slip <= 5 && narrow_slip <= 5,
            "{name}: the slip states disagree"
        );
    }
}

#[test]
fn a_proxy_for_another_patch_is_refused() {
    let s = fixed::<Wide>();
    let ok = proxy_config((0.3, 0.3), 0.0);
    assert!(s.proxy(&ok).is_ok());
    for (bad, err) in [
        (ProxyConfig { grid: 6, ..ok }, ProxyError::Grid),
        (ProxyConfig { spacing: 3.0, ..ok }, ProxyError::Grid),
        (ProxyConfig { grid: 2, ..ok }, ProxyError::Grid),
        (
            ProxyConfig {
                spacing: f64::NAN,
                ..ok
            },
            ProxyError::Grid,
        ),
        (ProxyConfig { mu_s: 2.5, ..ok }, ProxyError::Friction),
        (ProxyConfig { mu_k: -0.1, ..ok }, ProxyError::Friction),
        (
            ProxyConfig {
                probe_radius: 1.5,
                ..ok
            },
            ProxyError::ProbeRadius,
        ),
    ] {
        assert_eq!(s.proxy(&bad).err(), Some(err), "{bad:?}");
    }
}

mod robust {
    use super::*;
    use proptest::prelude::*;

    fn run<A: Arith>(mu: (f64, f64), radius: f64, probes: &[(f64, f64, f64)]) {
        let mut s = fixed::<A>();
        let cfg = proxy_config(mu, radius);
        let mut proxy = s.proxy(&cfg).unwrap();
        let max = device_max();
        for &(x, y, z) in probes {
            let f = s.step_proxy([x, y, z].map(Length::from_num), &mut proxy);
            let f = f.map(|c| c.to_num::<f64>());
            let mag = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
            // The magnitude clamp: never above the maximum (as the core holds it).
            assert!(mag <= max, "{mag} N over the maximum at {x},{y},{z}");
            assert!(f[2] >= 0.0, "pulled into the tissue: {f:?}");
            if let Some(g) = proxy.grid_position() {
                let top = ((N - 1) << 16) as i32;
                assert!(
                    g.iter().all(|&c| (0..=top).contains(&c)),
                    "{g:?} off the patch"
                );
            }
        }
    }

    /// The same on a 64 × 64 tissue, the window following: it stays on the tissue.
    fn roam<A: Arith>(mu: (f64, f64), probes: &[(f64, f64, f64)]) {
        let mut s = fixed::<A>();
        let cfg = proxy_config(mu, 0.0);
        let mut proxy = s.proxy(&cfg).unwrap();
        let wc = mccs::WindowConfig {
            tissue_w: 64,
            tissue_h: 64,
            hysteresis: 0.1,
        };
        let mut window = s.window(&wc, &mccs::Flat, &proxy, 0.0, 0.0).unwrap();
        let max = device_max();
        for &(x, y, z) in probes {
            let f = s.step_roaming([x, y, z].map(Length::from_num), &mut proxy, &mut window);
            let f = f.map(|c| c.to_num::<f64>());
            let mag = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
            assert!(mag <= max, "{mag} N over the maximum at {x},{y},{z}");
            assert!(f[2] >= 0.0, "pulled into the tissue: {f:?}");
            let (i, j) = window.centre();
            assert!((N / 2..64 - N / 2).contains(&i) && (N / 2..64 - N / 2).contains(&j));
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]
        /// Any probe path, from anywhere within ±100 mm in jumps of any size: no panic
        /// (overflow checks are on here), the force within the device maximum and never
        /// pulling the probe into the tissue, the proxy on the patch.
        #[test]
        fn any_probe_path_is_safe(
            mu in (0.0f64..2.0, 0.0f64..2.0),
            radius in 0.0f64..1.25,
            probes in prop::collection::vec(
                prop_oneof![
                    (-100.0f64..100.0, -100.0f64..100.0, -60.0f64..60.0),
                    (-6.0f64..6.0, -6.0f64..6.0, -3.0f64..1.0),
                ],
                1..200,
            ),
        ) {
            run::<Wide>(mu, radius, &probes);
            run::<Narrow>(mu, radius, &probes);
            roam::<Wide>(mu, &probes);
            roam::<Narrow>(mu, &probes);
        }
    }
}

mod roaming {
    use super::*;
    use mccs::WindowConfig;

    /// From 1.5 mm above (−15, 0.4), press to 1 mm over 0.2 s, hold 0.3 s, slide 30 mm
    /// along x at 10 mm/s, then 5 mm along y, lift.
    fn path(t: usize) -> V {
        let s = t as f64 / 1000.0;
        let z = if s < 0.2 {
            1.5 - 2.5 * s / 0.2
        } else if s < 4.0 {
            -1.0
        } else {
            -1.0 + (s - 4.0) * 10.0
        };
        let x = -15.0 + ((s - 0.5).max(0.0) * 10.0).min(30.0);
        let y = 0.4 + ((s - 3.5).max(0.0) * 10.0).min(5.0);
        [x, y, z]
    }

    fn compare<A: Arith>(mu: (f64, f64)) -> (f64, u32) {
        let mut s = fixed::<A>();
        let config = proxy_config(mu, 0.0);
        let mut proxy = s.proxy(&config).unwrap();
        let wc = WindowConfig {
            tissue_w: 64,
            tissue_h: 64,
            hysteresis: 0.1,
        };
        let start = path(0);
        let mut window = s
            .window(&wc, &mccs::Flat, &proxy, start[0], start[1])
            .unwrap();
        let cfg = RoamConfig {
            tissue: Tissue::new(64, 64, SPACING, Shape::Flat).unwrap(),
            n: N,
            dynamics: TwinConfig::from_solver(&SolverConfig::default(), s.substeps()),
            friction: Friction::new(mu.0, mu.1).unwrap(),
            probe_radius: 0.0,
            window_hysteresis: 0.1,
        };
        let law = Reference::new(&Params::TABLE2).unwrap();
        let mut tw = RoamTwin::new(cfg, law, start[0], start[1]).unwrap();
        assert_eq!(window.centre(), tw.centre());
        let mut worst = 0.0f64;
        for t in 0..4200 {
            let p = path(t);
            let got = s.step_roaming(p.map(Length::from_num), &mut proxy, &mut window);
            let want = tw.step(p).force;
            let (diff, mag) = off_by(got, want);
            assert!(
                diff < 0.02 + 0.03 * mag,
                "tick {t}: {got:?} against {want:?}"
            );
            assert_eq!(window.centre(), tw.centre(), "tick {t}: the windows differ");
            if mag > 0.05 {
                worst = worst.max(diff / mag);
            }
        }
        assert_eq!(window.shifts(), tw.shifts);
        (worst, window.shifts())
    }

    #[test]
    fn the_fixed_window_follows_the_twin() {
        // Frictionless the two agree within 2e-3 (5e-3 if the springs' warm-start values
        // were not carried across a shift: the bound holds the window's maps to account).
        for (name, mu, bound) in [
            ("frictionless", (0.0, 0.0), 0.002),
            ("friction", (0.6, 0.4), 0.01),
        ] {
            let (wide, shifts) = compare::<Wide>(mu);
            let (narrow, _) = compare::<Narrow>(mu);
            println!(
                "ROAMFIXED case={name} wide_rel={wide:.2e} narrow_rel={narrow:.2e} shifts={shifts}"
            );
            assert!(shifts >= 12, "{name}: {shifts} shifts");
            assert!(wide <= bound, "{name}: wide off by {wide:.3e}");
            assert!(narrow <= 2.0 * bound, "{name}: narrow off by {narrow:.3e}");
        }
    }

    #[test]
    fn a_window_that_does_not_fit_is_refused() {
        let mut s = fixed::<Wide>();
        let proxy = s.proxy(&proxy_config((0.0, 0.0), 0.0)).unwrap();
        let ok = WindowConfig {
            tissue_w: 64,
            tissue_h: 64,
            hysteresis: 0.1,
        };
        assert!(s.window(&ok, &mccs::Flat, &proxy, 0.0, 0.0).is_ok());
        for bad in [
            WindowConfig { tissue_w: 4, ..ok },
            WindowConfig { tissue_h: 65, ..ok },
            WindowConfig {
                hysteresis: 0.5,
                ..ok
            },
            WindowConfig {
                hysteresis: f64::NAN,
                ..ok
            },
        ] {
            assert_eq!(
                s.window(&bad, &mccs::Flat, &proxy, 0.0, 0.0).err(),
                Some(ProxyError::Window),
                "{bad:?}"
            );
        }
    }
}
