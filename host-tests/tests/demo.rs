//! The firmware's demo (`mccs_firmware::demo`) held to the `f64` twin: each core's
//! palpation (its patch as a window on the 64 × 64 tissue, friction 0.6 / 0.4, its
//! arithmetic and configuration) against `RoamTwin` along the same probe points, without
//! the mid-run swap (the twin has one tissue). Issue #19's bound: RMS ≤ 0.5 % and max
//! ≤ 2 % of the peak force; the windows move together; after the lift every node is back
//! at rest.

use mccs::{Arith, ForceTable64, Narrow, Params, Wide};
use mccs_firmware::demo::{self, DemoControllerIn, DemoSpec, FRICTION, SPACING, WINDOW};
use mccs_firmware::palpation_path;
use mccs_host::patch::TwinConfig;
use mccs_host::reference::Reference;
use mccs_host::roam::{Friction, RoamConfig, RoamTwin, Shape, Tissue};

/// `(RMS, max, peak, shifts)` of the fixed demo against the twin; panics where the
/// windows part.
fn compare<A: Arith>(spec: &DemoSpec) -> (f64, f64, f64, u32) {
    let table = ForceTable64::new(&Params::TABLE2).unwrap();
    let mut ctl: DemoControllerIn<37, 214, A> = spec.controller(&table).unwrap();
    let path = palpation_path(spec.tick_hz).unwrap();
    let start = path.at(0).map(|c| c.to_num::<f64>());
    let cfg = RoamConfig {
        tissue: Tissue::new(WINDOW.tissue_w, WINDOW.tissue_h, SPACING, Shape::Flat).unwrap(),
        n: spec.grid,
        dynamics: TwinConfig::from_solver(&spec.config(), ctl.solver().substeps()),
        friction: Friction::new(FRICTION.0, FRICTION.1).unwrap(),
        probe_radius: 0.0,
        window_hysteresis: WINDOW.hysteresis,
    };
    let law = Reference::new(&Params::TABLE2).unwrap();
    let mut tw = RoamTwin::new(cfg, law, start[0], start[1]).unwrap();
    let (mut peak, mut sum_sq, mut worst) = (0.0f64, 0.0, 0.0f64);
    for tick in 0..spec.ticks() {
        let p = path.at(tick).map(|c| c.to_num::<f64>());
        let got = ctl.tick(None).map(|f| f.to_num::<f64>());
        let want = tw.step(p).force;
        let e = (0..3).map(|k| (got[k] - want[k]).powi(2)).sum::<f64>();
        sum_sq += e;
        worst = worst.max(e.sqrt());
        peak = peak.max(want.iter().map(|f| f * f).sum::<f64>().sqrt());
        assert_eq!(
            ctl.telemetry().window_shifts,
            tw.shifts,
            "{}: tick {tick}: the windows part",
            spec.core
        );
    }
    // Lifted off from 3.45 s on: every free node of the window back at rest by the end.
    let rest = (1..ctl.solver().topology().node_count() as u16)
        .filter_map(|i| ctl.solver().displacement(i))
        .map(|u| {
            u.iter()
                .map(|c| c.to_num::<f64>().abs())
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    println!("DEMOREST core={} max_disp_mm={rest:.2e}", spec.core);
    assert!(rest < 1e-4, "{}: a node {rest} mm from rest", spec.core);
    let rms = (sum_sq / spec.ticks() as f64).sqrt();
    (rms / peak, worst / peak, peak, tw.shifts)
}

#[test]
fn each_cores_palpation_follows_the_twin() {
    for spec in [demo::M4F, demo::M3, demo::M0] {
        let (rms, max, peak, shifts) = if spec.core == "m0" {
            compare::<Narrow>(&spec)
        } else {
            compare::<Wide>(&spec)
        };
        println!(
            "DEMOTWIN core={} n={} rms_rel={rms:.2e} max_rel={max:.2e} peak_n={peak:.3} shifts={shifts}",
            spec.core, spec.grid
        );
        assert!(shifts >= 20, "{}: {shifts} shifts", spec.core);
        assert!(peak > 1.0, "{}: peak {peak}", spec.core);
        assert!(rms <= 0.005, "{}: RMS {rms:.2e} of the peak", spec.core);
        assert!(max <= 0.02, "{}: max {max:.2e} of the peak", spec.core);
    }
}
