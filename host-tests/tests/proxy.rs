//! The fixed-point proxy contact (`mccs::proxy`, `Solver::step_proxy`) against the `f64`
//! roaming twin on a tissue the size of the patch (its window cannot move): the same
//! press and slides, frictionless and with friction, in both arithmetics.

use mccs::{
    Arith, ForceTable64, Length, Narrow, Params, ProxyConfig, ProxyError, Solver, SolverConfig,
    Topology, Wide,
};
use mccs_host::patch::{TwinConfig, V};
use mccs_host::reference::Reference;
use mccs_host::roam::{Friction, RoamConfig, RoamTwin, Shape, Tissue};

const N: usize = 5;
const SPACING: f64 = 2.5;
type Fixed<A> = Solver<10, 61, 64, A>;

fn fixed<A: Arith>() -> Fixed<A> {
    let topo = Topology::standard_patch(N, SPACING).unwrap();
    let table = ForceTable64::new(&Params::TABLE2).unwrap();
    Solver::with_arith(topo, table, &SolverConfig::default(), A::default()).unwrap()
}

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

/// Runs the path in both; returns the largest force difference over the twin's force
/// magnitude (where it is above 0.05 N), and whether the slip states agreed.
fn compare<A: Arith>(mu: (f64, f64), radius: f64) -> (f64, usize) {
    let mut s = fixed::<A>();
    let config = ProxyConfig {
        grid: N,
        spacing: SPACING,
        mu_s: mu.0,
        mu_k: mu.1,
        probe_radius: radius,
    };
    let mut proxy = s.proxy(&config).unwrap();
    let mut tw = twin(s.substeps(), mu, radius);
    let (mut worst, mut slip_disagree) = (0.0f64, 0);
    for t in 0..1300 {
        let p = path(t);
        let got = s.step_proxy(p.map(Length::from_num), &mut proxy);
        let want = tw.step(p).force;
        let got = got.map(|f| f.to_num::<f64>());
        let mag = (want[0].powi(2) + want[1].powi(2) + want[2].powi(2)).sqrt();
        let diff = (0..3)
            .map(|k| (got[k] - want[k]).powi(2))
            .sum::<f64>()
            .sqrt();
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
    let ok = ProxyConfig {
        grid: N,
        spacing: SPACING,
        mu_s: 0.3,
        mu_k: 0.3,
        probe_radius: 0.0,
    };
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
        let cfg = ProxyConfig {
            grid: N,
            spacing: SPACING,
            mu_s: mu.0,
            mu_k: mu.1,
            probe_radius: radius,
        };
        let mut proxy = s.proxy(&cfg).unwrap();
        let max = SolverConfig::default().coupling.max_force;
        for &(x, y, z) in probes {
            let f = s.step_proxy([x, y, z].map(Length::from_num), &mut proxy);
            let f = f.map(|c| c.to_num::<f64>());
            let mag = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
            // The magnitude clamp, to the Q12 of its comparison.
            assert!(
                mag <= max * (1.0 + 1e-4),
                "{mag} N over the maximum at {x},{y},{z}"
            );
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
        }
    }
}
