//! The roaming twin (`mccs_host::roam`) against physics: a frictionless slide feels the
//! static indentation at every point, kinetic friction holds its ratio, a stick holds,
//! the window's shifts are not felt and do not thrash, and the contact is unilateral.
//! Prints `ROAM` lines (the figures in docs/roaming.md).

use mccs::{Params, SolverConfig};
use mccs_host::patch::{TwinConfig, V};
use mccs_host::reference::Reference;
use mccs_host::roam::{Friction, RoamConfig, RoamError, RoamTwin, Shape, TickOut, Tissue};

const SPACING: f64 = 2.5;
/// Substeps per 1 kHz tick: the N = 5 patch's exact bound is 679 µs (docs/performance.md).
const SUBSTEPS: u32 = 3;

fn config(friction: Friction, shape: Shape) -> RoamConfig {
    RoamConfig {
        tissue: Tissue::new(64, 64, SPACING, shape).unwrap(),
        n: 5,
        dynamics: TwinConfig::from_solver(&SolverConfig::default(), SUBSTEPS),
        friction,
        probe_radius: 0.0,
        window_hysteresis: 0.1,
    }
}

fn twin(friction: Friction, x: f64, y: f64) -> RoamTwin {
    let law = Reference::new(&Params::TABLE2).unwrap();
    RoamTwin::new(config(friction, Shape::Flat), law, x, y).unwrap()
}

fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Normal and tangential parts of the device force against the contact normal.
fn split(o: &TickOut) -> (f64, f64) {
    let n = dot(o.force, o.normal);
    let t = [0, 1, 2].map(|k| o.force[k] - n * o.normal[k]);
    (n, dot(t, t).sqrt())
}

/// The probe lowered at `(x, y)` from above to `depth` below the rest surface over
/// `ramp` ticks.
fn press(tw: &mut RoamTwin, x: f64, y: f64, depth: f64, ramp: usize) -> TickOut {
    let mut o = TickOut::default();
    for t in 0..=ramp {
        let z = 0.5 - (0.5 + depth) * t as f64 / ramp as f64;
        o = tw.step([x, y, z]);
    }
    o
}

/// The static indentation force at `(x, y)`: pressed there and held until settled.
fn settled(x: f64, y: f64, depth: f64) -> f64 {
    let mut tw = twin(Friction::NONE, x, y);
    press(&mut tw, x, y, depth, 200);
    let mut o = TickOut::default();
    for _ in 0..1500 {
        o = tw.step([x, y, -depth]);
    }
    split(&o).0
}

#[test]
fn frictionless_slide_feels_the_static_indentation_everywhere() {
    let (depth, speed, from, length) = (1.0, 10.0, -15.0, 30.0);
    let y = 0.4;
    let mut tw = twin(Friction::NONE, from, y);
    press(&mut tw, from, y, depth, 200);
    for _ in 0..1000 {
        tw.step([from, y, -depth]);
    }
    let ticks = (length / speed * 1000.0) as usize;
    let (mut worst_normal, mut worst_tangent, mut worst_step) = (0.0f64, 0.0f64, 0.0f64);
    let mut prev: Option<TickOut> = None;
    let mut shifts = 0;
    for t in 1..=ticks {
        let x = from + speed * t as f64 / 1000.0;
        let o = tw.step([x, y, -depth]);
        let (fn_, ft) = split(&o);
        worst_tangent = worst_tangent.max(ft / fn_);
        if let (Some(p), true) = (prev, o.shifted) {
            shifts += 1;
            let d = [0, 1, 2].map(|k| o.force[k] - p.force[k]);
            worst_step = worst_step.max(dot(d, d).sqrt() / fn_);
        }
        if t % 271 == 0 {
            let s = settled(x, y, depth);
            let rel = (fn_ - s).abs() / s;
            worst_normal = worst_normal.max(rel);
            println!("slide x={x:.2} normal={fn_:.5} static={s:.5} rel={rel:.2e}");
        }
        prev = Some(o);
    }
    println!(
        "ROAM case=frictionless_slide normal_vs_static={worst_normal:.2e} \
         tangent_over_normal={worst_tangent:.2e} shift_step_over_normal={worst_step:.2e} \
         shifts={shifts}"
    );
    assert!(shifts >= 10, "the window shifted {shifts} times over 30 mm");
    assert!(
        worst_normal <= 0.01,
        "normal force off the static one by {worst_normal:.3e}"
    );
    assert!(
        worst_tangent <= 0.01,
        "tangential / normal {worst_tangent:.3e}"
    );
    assert!(
        worst_step <= 0.02,
        "a shift's force step is {worst_step:.3e} of the normal force"
    );
}

#[test]
fn kinetic_friction_holds_its_ratio_while_sliding() {
    let f = Friction::new(0.4, 0.3).unwrap();
    let (depth, speed, from) = (1.0, 10.0, -10.0);
    let mut tw = twin(f, from, 0.0);
    press(&mut tw, from, 0.0, depth, 200);
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for t in 1..=2000 {
        let x = from + speed * t as f64 / 1000.0;
        let o = tw.step([x, 0.0, -depth]);
        let slipping = tw.contact().unwrap().slip.0;
        if t > 500 {
            assert!(slipping, "tick {t}: not slipping while dragged");
            let (fn_, ft) = split(&o);
            lo = lo.min(ft / fn_);
            hi = hi.max(ft / fn_);
        }
    }
    println!("ROAM case=kinetic_friction mu_k=0.3 ratio_min={lo:.4} ratio_max={hi:.4}");
    assert!(
        lo >= 0.3 * 0.98 && hi <= 0.3 * 1.02,
        "ratio {lo:.4} … {hi:.4}"
    );
}

#[test]
fn a_pull_within_static_friction_sticks() {
    let f = Friction::new(0.6, 0.4).unwrap();
    let depth = 1.0;
    let mut tw = twin(f, 0.3, 0.2);
    press(&mut tw, 0.3, 0.2, depth, 200);
    let start = tw.contact().unwrap().anchor;
    // A tangential pull to half the static cone (the proxy is about `depth` above the
    // probe: well within tan θ = 0.3 < 0.6), slowly.
    for t in 1..=500 {
        let dx = 0.3 * depth * t as f64 / 500.0;
        tw.step([0.3 + dx, 0.2, -depth]);
    }
    let held = tw.contact().unwrap();
    assert!(!held.slip.0, "slipping within the static cone");
    assert_eq!(held.anchor.cell, start.cell);
    let moved = (0..3)
        .map(|k| (held.anchor.bary[k] - start.bary[k]).abs())
        .fold(0.0, f64::max);
    assert!(moved < 1e-9, "the proxy moved on the surface: {moved:.3e}");
    // Past the static cone it slips.
    for t in 1..=500 {
        let dx = 0.3 * depth + 1.5 * depth * t as f64 / 500.0;
        tw.step([0.3 + dx, 0.2, -depth]);
    }
    assert!(
        tw.contact().unwrap().slip.0,
        "not slipping past the static cone"
    );
}

#[test]
fn a_probe_held_on_a_window_boundary_does_not_thrash() {
    // Tissue node 32 is at x = 1.25 mm (64 nodes, centred). The window centred there
    // moves when the contact is 0.6 spacings away: the probe trembles ±0.2 mm around
    // that threshold.
    let centre = 1.25;
    let x = centre + 0.6 * SPACING;
    let mut tw = twin(Friction::NONE, centre, 0.0);
    press(&mut tw, centre, 0.0, 1.0, 200);
    assert_eq!(tw.centre().0, 32);
    for t in 0..200 {
        tw.step([centre + (x - centre) * t as f64 / 200.0, 0.0, -1.0]);
    }
    let before = tw.shifts;
    for t in 0..3000 {
        let dx = 0.2 * (t as f64 * 0.05).sin();
        tw.step([x + dx, 0.0, -1.0]);
    }
    let shifts = tw.shifts - before;
    println!("ROAM case=boundary_tremor shifts={shifts}");
    assert!(
        shifts <= 1,
        "{shifts} shifts under a 0.2 mm tremor on the boundary"
    );
    assert_eq!(tw.centre().0, 33, "the window did not follow the contact");
}

#[test]
fn a_sphere_touches_at_its_radius() {
    let law = Reference::new(&Params::TABLE2).unwrap();
    let cfg = RoamConfig {
        probe_radius: 1.0,
        ..config(Friction::NONE, Shape::Flat)
    };
    let mut tw = RoamTwin::new(cfg, law, 0.0, 0.0).unwrap();
    assert_eq!(tw.step([0.0, 0.0, 1.05]).force, [0.0; 3]);
    assert!(tw.contact().is_none());
    tw.step([0.0, 0.0, 0.95]);
    assert!(tw.contact().is_some());
    // Held (no coupling damping): 0.05 mm into the 1 N/mm coupling, less the surface's
    // give.
    let o = tw.step([0.0, 0.0, 0.95]);
    assert!(
        o.force[2] > 0.0 && o.force[2] <= 0.05 + 1e-9,
        "{:?}",
        o.force
    );
}

#[test]
fn the_contact_is_unilateral() {
    let mut tw = twin(Friction::new(0.6, 0.4).unwrap(), 0.0, 0.0);
    for t in 0..200 {
        let o = tw.step([0.01 * t as f64, 0.0, 0.3]);
        assert_eq!(o.force, [0.0; 3]);
        assert!(tw.contact().is_none());
    }
    press(&mut tw, 2.0, 0.0, 1.0, 100);
    assert!(tw.contact().is_some());
    // Lifted: the contact ends, and no force pulls the probe down on the way up.
    for t in 0..300 {
        let z = -1.0 + 2.0 * t as f64 / 300.0;
        let o = tw.step([2.0, 0.0, z]);
        assert!(
            o.force[2] >= 0.0,
            "pulled down at z = {z:.3}: {:?}",
            o.force
        );
    }
    assert!(tw.contact().is_none());
}

#[test]
fn on_a_cap_a_frictionless_push_follows_the_surface_normal() {
    let law = Reference::new(&Params::TABLE2).unwrap();
    let cfg = config(Friction::NONE, Shape::Cap { radius: 160.0 });
    let (x, y) = (20.0, -10.0);
    let mut tw = RoamTwin::new(cfg, law, x, y).unwrap();
    let z0 = cfg.tissue.height(x, y);
    let mut o = TickOut::default();
    for t in 0..=1200 {
        let z = z0 + 0.5 - 1.5 * (t.min(200) as f64 / 200.0);
        o = tw.step([x, y, z]);
    }
    let (fn_, ft) = split(&o);
    // The rest surface's normal there.
    let r = 160.0f64;
    let c = [x / r, y / r, (r * r - x * x - y * y).sqrt() / r];
    let cos = dot(o.force, c) / dot(o.force, o.force).sqrt();
    println!("ROAM case=cap_push normal={fn_:.4} tangent={ft:.2e} cos_to_rest_normal={cos:.5}");
    assert!(
        ft <= 1e-3 * fn_,
        "tangential {ft:.3e} against normal {fn_:.3e}"
    );
    assert!(
        cos > 0.999,
        "the force is {:.2}° off the rest normal",
        cos.acos().to_degrees()
    );
}

#[test]
fn bad_configurations_are_refused() {
    let law = || Reference::new(&Params::TABLE2).unwrap();
    assert_eq!(
        Tissue::new(2, 10, 2.5, Shape::Flat),
        Err(RoamError::TissueSize)
    );
    assert_eq!(
        Tissue::new(65, 10, 2.5, Shape::Flat),
        Err(RoamError::TissueSize)
    );
    assert_eq!(
        Tissue::new(10, 10, 0.5, Shape::Flat),
        Err(RoamError::Spacing)
    );
    assert_eq!(
        Tissue::new(64, 64, 4.0, Shape::Flat),
        Err(RoamError::TissueExtent)
    );
    assert_eq!(
        Tissue::new(64, 64, 2.5, Shape::Cap { radius: 50.0 }),
        Err(RoamError::CapRadius)
    );
    assert_eq!(Friction::new(-0.1, 0.0), Err(RoamError::Friction));
    assert_eq!(Friction::new(0.3, f64::NAN), Err(RoamError::Friction));
    let ok = config(Friction::NONE, Shape::Flat);
    for (bad, err) in [
        (RoamConfig { n: 2, ..ok }, RoamError::Window),
        (RoamConfig { n: 65, ..ok }, RoamError::Window),
        (
            RoamConfig {
                probe_radius: 2.0,
                ..ok
            },
            RoamError::ProbeRadius,
        ),
        (
            RoamConfig {
                probe_radius: -1.0,
                ..ok
            },
            RoamError::ProbeRadius,
        ),
        (
            RoamConfig {
                window_hysteresis: 0.0,
                ..ok
            },
            RoamError::Hysteresis,
        ),
        (
            RoamConfig {
                friction: Friction {
                    mu_s: 3.0,
                    ..Friction::NONE
                },
                ..ok
            },
            RoamError::Friction,
        ),
    ] {
        assert_eq!(RoamTwin::new(bad, law(), 0.0, 0.0).err(), Some(err));
    }
}

mod friction_cone {
    use super::*;
    use mccs_host::roam::Slip;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]
        /// Over any sequence of goals, the proxy ends inside the cone of the state it is
        /// in, never moves while sticking inside the static cone, moves only toward the
        /// goal, and is the goal without friction.
        #[test]
        fn the_proxy_stays_in_its_cone(
            mu in (0.0f64..1.5, 0.0f64..1.5),
            moves in prop::collection::vec((-2.0f64..2.0, -2.0f64..2.0, 0.05f64..2.0), 1..40),
        ) {
            let f = Friction::new(mu.0, mu.1).unwrap();
            let n = [0.0, 0.0, 1.0];
            let mut slip = Slip::default();
            let mut proxy = [0.0, 0.0, 0.0];
            for (gx, gy, depth) in moves {
                let goal = [gx, gy, 0.0];
                let before = slip;
                let r0 = ((proxy[0] - gx).powi(2) + (proxy[1] - gy).powi(2)).sqrt();
                let next = slip.advance(&f, proxy, goal, depth, n);
                let r = ((next[0] - gx).powi(2) + (next[1] - gy).powi(2)).sqrt();
                if f.mu_s == 0.0 && f.mu_k == 0.0 {
                    prop_assert_eq!(next, goal);
                } else {
                    let mu_now = if slip.0 { f.mu_k } else { f.mu_s };
                    prop_assert!(r <= mu_now * depth + 1e-12, "outside the cone");
                    prop_assert!(r <= r0 + 1e-12, "moved away from the goal");
                    if !before.0 && r0 <= f.mu_s * depth && f.mu_k <= f.mu_s {
                        prop_assert_eq!(next, proxy, "moved while sticking");
                        prop_assert!(!slip.0);
                    }
                }
                proxy = next;
            }
        }
    }
}

#[test]
fn on_a_cap_the_window_follows_a_slide_without_a_felt_step() {
    // Across the top of a cap (R = 160 mm) at 1 mm depth along the rest normal: the
    // window's mesh is rebuilt at every shift (its rest geometry changes with its
    // place); the step a shift causes stays within 2 % of the normal force.
    let law = Reference::new(&Params::TABLE2).unwrap();
    let cfg = config(Friction::NONE, Shape::Cap { radius: 160.0 });
    let (from, length, depth, y) = (-12.0, 24.0, 1.0, 0.4);
    let mut tw = RoamTwin::new(cfg, law, from, y).unwrap();
    let at = |x: f64| {
        let n = cfg.tissue.normal(x, y);
        let z = cfg.tissue.height(x, y);
        [x - depth * n[0], y - depth * n[1], z - depth * n[2]]
    };
    for t in 0..=1200 {
        let p = at(from);
        let lift = 0.5 - 1.5 * (t.min(200) as f64 / 200.0);
        tw.step([p[0], p[1], p[2] + depth + lift]);
    }
    let (mut worst_step, mut worst_tangent, mut shifts) = (0.0f64, 0.0f64, 0);
    let mut prev = None;
    for t in 1..=(length / 10.0 * 1000.0) as usize {
        let o = tw.step(at(from + 10.0 * t as f64 / 1000.0));
        let (fn_, ft) = split(&o);
        worst_tangent = worst_tangent.max(ft / fn_);
        if let (Some(p), true) = (prev, o.shifted) {
            let p: TickOut = p;
            shifts += 1;
            let d = [0, 1, 2].map(|k| o.force[k] - p.force[k]);
            worst_step = worst_step.max(dot(d, d).sqrt() / fn_);
        }
        prev = Some(o);
    }
    println!(
        "ROAM case=cap_slide shifts={shifts} shift_step_over_normal={worst_step:.2e} \
         tangent_over_normal={worst_tangent:.2e}"
    );
    assert!(shifts >= 8, "{shifts} shifts");
    assert!(
        worst_step <= 0.02,
        "a shift's step is {worst_step:.3e} of the normal force"
    );
    assert!(
        worst_tangent <= 0.01,
        "tangential / normal {worst_tangent:.3e}"
    );
}

#[test]
fn a_replay_that_starts_in_contact_feels_no_start_up_kick() {
    // The first tick has no previous probe: its velocity is zero, so the coupling's
    // damping adds nothing (a probe starting 1 mm deep feels 1 mm of coupling at most).
    let mut tw = twin(Friction::NONE, 0.0, 0.0);
    let o = tw.step([0.0, 0.0, -1.0]);
    assert!(tw.contact().is_some());
    assert!(
        o.force[2] > 0.0 && o.force[2] <= 1.0 + 1e-9,
        "{:?}",
        o.force
    );
}

/// A probe position as the arm reads it: 20 µm RMS of noise (Gaussian, seeded), then
/// whole 64 µm counts on each axis (the arm's count at the probe).
struct Quantised(rand_chacha::ChaCha8Rng);

impl Quantised {
    const COUNT_MM: f64 = 0.064;
    const NOISE_MM: f64 = 0.020;

    fn new() -> Self {
        use rand::SeedableRng;
        Quantised(rand_chacha::ChaCha8Rng::seed_from_u64(62))
    }

    fn read(&mut self, p: V) -> V {
        use rand_distr::{Distribution, Normal};
        let noise = Normal::new(0.0, Self::NOISE_MM).unwrap();
        p.map(|x| ((x + noise.sample(&mut self.0)) / Self::COUNT_MM).round() * Self::COUNT_MM)
    }
}

/// Kinetic friction on quantised, noisy positions: dragged 20 mm at 10 mm/s, 1 mm deep,
/// read in 64 µm counts with 20 µm of noise. The probe's read stops between counts
/// (one every 6.4 ticks) and the noise steps it back: the proxy sticks now and then, and
/// the tangential force over the normal, over each 0.1 s, falls below μ_k. Measured:
/// 5–12 % below, 6 % of the ticks stuck (docs/roaming.md); held here to within 15 %
/// and 10 % (a tick's own ratio jumps with each count).
#[test]
fn kinetic_friction_holds_its_ratio_on_quantised_noisy_positions() {
    let f = Friction::new(0.4, 0.3).unwrap();
    let (depth, speed, from) = (1.0, 10.0, -10.0);
    let mut q = Quantised::new();
    let mut tw = twin(f, from, 0.0);
    for t in 0..=200 {
        let z = 0.5 - (0.5 + depth) * t as f64 / 200.0;
        tw.step(q.read([from, 0.0, z]));
    }
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    let (mut sum_t, mut sum_n, mut stuck) = (0.0, 0.0, 0);
    for t in 1..=2000 {
        let x = from + speed * t as f64 / 1000.0;
        let o = tw.step(q.read([x, 0.0, -depth]));
        if t > 500 {
            stuck += usize::from(!tw.contact().unwrap().slip.0);
            let (fn_, ft) = split(&o);
            sum_t += ft;
            sum_n += fn_;
            if t % 100 == 0 {
                lo = lo.min(sum_t / sum_n);
                hi = hi.max(sum_t / sum_n);
                (sum_t, sum_n) = (0.0, 0.0);
            }
        }
    }
    println!(
        "ROAM case=kinetic_friction_quantised mu_k=0.3 ratio_min={lo:.4} ratio_max={hi:.4} stuck_ticks={stuck}"
    );
    assert!(stuck <= 150, "{stuck} of 1500 ticks stuck while dragged");
    assert!(
        lo >= 0.3 * 0.85 && hi <= 0.3 * 1.02,
        "ratio {lo:.4} … {hi:.4}"
    );
}

/// Static friction on quantised, noisy positions: a pull to half the static cone, read
/// in 64 µm counts with 20 µm of noise, never slips and the proxy stays where it stuck;
/// past the cone it slips.
#[test]
fn a_pull_within_static_friction_sticks_on_quantised_noisy_positions() {
    let f = Friction::new(0.6, 0.4).unwrap();
    let depth = 1.0;
    let mut q = Quantised::new();
    let mut tw = twin(f, 0.3, 0.2);
    for t in 0..=200 {
        let z = 0.5 - (0.5 + depth) * t as f64 / 200.0;
        tw.step(q.read([0.3, 0.2, z]));
    }
    // Settled under the noise first.
    for _ in 0..300 {
        tw.step(q.read([0.3, 0.2, -depth]));
    }
    let start = tw.contact().unwrap().anchor;
    let mut slips = 0;
    for t in 1..=1000 {
        let dx = 0.3 * depth * (t.min(500)) as f64 / 500.0;
        tw.step(q.read([0.3 + dx, 0.2, -depth]));
        slips += usize::from(tw.contact().unwrap().slip.0);
    }
    let held = tw.contact().unwrap();
    println!("ROAM case=static_friction_quantised slipping_ticks={slips}");
    assert_eq!(slips, 0, "slipped within the static cone");
    assert_eq!(held.anchor.cell, start.cell);
    for t in 1..=500 {
        let dx = 0.3 * depth + 1.5 * depth * t as f64 / 500.0;
        tw.step(q.read([0.3 + dx, 0.2, -depth]));
    }
    assert!(
        tw.contact().unwrap().slip.0,
        "not slipping past the static cone"
    );
}
