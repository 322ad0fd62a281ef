//! The measured ticks: this core's demo configuration (its start-up, one tick glued and
//! one through a sliding proxy), and the demo's roaming, flat and over a cap (the
//! longest tick without and with a window shift).

use super::fw_common::exit;
use super::harness::Harness;
use core::hint::black_box;
use mccs::solver::stability::StabilityCheck;
use mccs::{Flat, ForceTable64, Length, ProxyConfig, ShapeSpec, Solver, Sphere, Topology};
use mccs_firmware::demo::{self, DemoSpec};
use mccs_firmware::entry as e;
use mccs_firmware::target::CORE;

/// This core's demo patch (`spec`'s grid at the demo's spacing); exits with failure if it
/// cannot be built.
fn demo_topology<const N: usize, const E: usize>(spec: &DemoSpec) -> Topology<N, E> {
    match Topology::<N, E>::standard_patch(spec.grid, demo::SPACING) {
        Ok(topo) => topo,
        Err(_) => exit(false),
    }
}

/// A solver of `table` on this core's demo patch with `spec`'s configuration; exits with
/// failure if it cannot be built.
fn demo_solver<const N: usize, const E: usize>(
    spec: &DemoSpec,
    table: &ForceTable64,
) -> Solver<N, E, 64> {
    match Solver::new(demo_topology(spec), *table, &spec.config()) {
        Ok(s) => s,
        Err(_) => exit(false),
    }
}

/// The solver's start-up for this core's demo configuration (`Solver::new`: the patch's
/// coefficients and its stability bound, whose estimate runs the linearised step about
/// ten times up to 1,536 steps, in block fixed point), once, in instructions.
#[inline(never)]
pub fn startup(h: &Harness, table: &ForceTable64) -> u64 {
    match demo::spec_for(CORE).grid {
        8 => startup_in::<37, 214>(h, table),
        5 => startup_in::<10, 61>(h, table),
        _ => startup_in::<5, 30>(h, table),
    }
}

#[inline(never)]
fn startup_in<const N: usize, const E: usize>(h: &Harness, table: &ForceTable64) -> u64 {
    let spec = demo::spec_for(CORE);
    let topo = demo_topology::<N, E>(&spec);
    let mut ok = false;
    let n = h.measure_long(|| {
        ok = black_box(Solver::new(black_box(topo), *table, &spec.config())).is_ok();
    });
    if !ok {
        exit(false)
    }
    n
}

/// Steps of the linearised patch in one slice of [`tissue_check`]'s second run (the arm
/// board's `check_steps_per_poll`).
pub const CHECK_SLICE_STEPS: u32 = 12;

/// A device's check of a new tissue as the link runs it: the host's proposed substeps
/// (the count the search finds) verified by the device's own runs
/// ([`StabilityCheck`] with a proposal, advanced to its end), once: its instructions, the
/// steps of the linearised patch it ran, and the most instructions one slice of
/// [`CHECK_SLICE_STEPS`] took when the check runs again in slices (a run's start and a
/// look at its energy fall in some). Exits with failure if the check does not take the
/// search's count.
#[inline(never)]
pub fn tissue_check(h: &Harness, table: &ForceTable64) -> (u64, u32, u64) {
    match demo::spec_for(CORE).grid {
        8 => tissue_check_in::<37, 214>(h, table),
        5 => tissue_check_in::<10, 61>(h, table),
        _ => tissue_check_in::<5, 30>(h, table),
    }
}

#[inline(never)]
fn tissue_check_in<const N: usize, const E: usize>(
    h: &Harness,
    table: &ForceTable64,
) -> (u64, u32, u64) {
    let spec = demo::spec_for(CORE);
    let topo = demo_topology::<N, E>(&spec);
    let config = spec.config();
    let proposal = demo_solver::<N, E>(&spec, table).substeps();
    let (mut outcome, mut steps) = (None, 0);
    let n = h.measure_long(|| {
        let check = StabilityCheck::new(black_box(&topo), table, &config, Some(proposal));
        if let Ok(mut check) = check {
            outcome = check.advance(&topo, u32::MAX);
            steps = check.steps_run();
        }
    });
    if outcome != Some(Ok(proposal)) {
        exit(false)
    }
    let Ok(mut check) = StabilityCheck::new(&topo, table, &config, Some(proposal)) else {
        exit(false)
    };
    let mut worst_slice = 0;
    while check.outcome().is_none() {
        worst_slice = worst_slice.max(h.measure_long(|| {
            black_box(check.advance(&topo, CHECK_SLICE_STEPS));
        }));
    }
    if check.outcome() != Some(Ok(proposal)) {
        exit(false)
    }
    (n, steps, worst_slice)
}

/// One tick of this core's demo configuration, pressed in, averaged over 4.
#[inline(never)]
pub fn tick(h: &Harness, table: &ForceTable64, probe: [Length; 3]) -> u32 {
    if demo::spec_for(CORE).grid > 5 {
        tick_in::<37, 214>(h, table, probe)
    } else {
        tick_in::<10, 61>(h, table, probe)
    }
}

#[inline(never)]
fn tick_in<const N: usize, const E: usize>(
    h: &Harness,
    table: &ForceTable64,
    probe: [Length; 3],
) -> u32 {
    let spec = demo::spec_for(CORE);
    let mut s = demo_solver::<N, E>(&spec, table);
    for _ in 0..200 {
        e::tick(&mut s, probe);
    }
    h.measure(4, || {
        black_box(e::tick(&mut s, black_box(probe)));
    })
}

/// One tick of this core's demo patch (its grid and configuration, 2.5 mm) through a
/// proxy with friction (μ_s 0.6, μ_k 0.4), 0.5 mm deep and sliding along x at 10 mm/s
/// (the contact slipping), after 200 ticks of it; averaged over 4.
#[inline(never)]
pub fn tick_proxy(h: &Harness, table: &ForceTable64) -> u32 {
    match demo::spec_for(CORE).grid {
        8 => tick_proxy_in::<37, 214>(h, table),
        5 => tick_proxy_in::<10, 61>(h, table),
        _ => tick_proxy_in::<5, 30>(h, table),
    }
}

#[inline(never)]
fn tick_proxy_in<const N: usize, const E: usize>(h: &Harness, table: &ForceTable64) -> u32 {
    let spec = demo::spec_for(CORE);
    let mut s = demo_solver::<N, E>(&spec, table);
    let cfg = ProxyConfig {
        grid: spec.grid,
        spacing: 2.5,
        mu_s: 0.6,
        mu_k: 0.4,
        probe_radius: 0.0,
    };
    let Ok(mut proxy) = s.proxy(&cfg) else {
        exit(false)
    };
    let (step, z) = (Length::from_num(0.01), Length::from_num(-0.5));
    let mut x = Length::from_num(-1.0);
    for _ in 0..200 {
        x += step;
        e::tick_proxy(&mut s, [x, Length::ZERO, z], &mut proxy);
    }
    if !proxy.slipping() {
        exit(false)
    }
    h.measure(4, || {
        x += step;
        black_box(e::tick_proxy(
            &mut s,
            black_box([x, Length::ZERO, z]),
            &mut proxy,
        ));
    })
}

/// The demo's roaming ticks (`DemoSpec::roaming`: its patch as a window on the 64 × 64
/// tissue, friction 0.6 / 0.4), flat or over a cap of radius 150 mm (`cap`): a press to
/// `z = −1` mm at `x = −5` (200 ticks), then a slide along `x` at 10 mm/s for 1000 ticks
/// (4 window shifts; over the cap 1 … 0.92 mm deep), each tick measured alone.
#[derive(Clone, Copy)]
pub struct RoamingTicks {
    /// The longest tick of the slide without a shift.
    pub steady: u32,
    /// The longest tick with a shift.
    pub shift: u32,
    /// The most a shift tick took over the tick before it: the shift's own cost.
    pub shift_extra: u32,
}

/// [`RoamingTicks`] for this core's demo patch; `empty` is the harness's own count.
#[inline(never)]
pub fn roaming(h: &Harness, table: &ForceTable64, empty: u32) -> RoamingTicks {
    roaming_of(h, table, empty, &Flat)
}

/// The cap the bench roams: radius 150 mm.
const CAP: Sphere = Sphere { radius_mm: 150.0 };

/// [`roaming`] over a cap of radius 150 mm.
#[inline(never)]
pub fn roaming_cap(h: &Harness, table: &ForceTable64, empty: u32) -> RoamingTicks {
    roaming_of(h, table, empty, &CAP)
}

/// [`roaming`] on a tissue of `shape`.
fn roaming_of<Spec: ShapeSpec>(
    h: &Harness,
    table: &ForceTable64,
    empty: u32,
    shape: &Spec,
) -> RoamingTicks {
    let spec = demo::spec_for(CORE);
    match spec.grid {
        8 => roaming_in::<37, 214, Spec>(h, table, empty, &spec, shape),
        5 => roaming_in::<10, 61, Spec>(h, table, empty, &spec, shape),
        _ => roaming_in::<5, 30, Spec>(h, table, empty, &spec, shape),
    }
}

/// [`roaming_cap`] with this core's demo configuration on an N = 5 patch: issue #19's
/// configuration for the M4F.
#[inline(never)]
pub fn roaming_cap_n5(h: &Harness, table: &ForceTable64, empty: u32) -> RoamingTicks {
    let spec = DemoSpec {
        grid: 5,
        ..demo::spec_for(CORE)
    };
    roaming_in::<10, 61, Sphere>(h, table, empty, &spec, &CAP)
}

#[inline(never)]
fn roaming_in<const N: usize, const E: usize, Spec: ShapeSpec>(
    h: &Harness,
    table: &ForceTable64,
    empty: u32,
    spec: &DemoSpec,
    shape: &Spec,
) -> RoamingTicks {
    let mut s = demo_solver::<N, E>(spec, table);
    let (x0, y) = (Length::from_num(-5), Length::from_num(0.4));
    let Ok(mut proxy) = s.proxy(&spec.proxy_config()) else {
        exit(false)
    };
    let Ok(mut window) = s.window(&demo::WINDOW, shape, &proxy, -5.0, 0.4) else {
        exit(false)
    };
    let depth = Length::from_num(-1);
    for k in 0..200 {
        let z = depth / 200 * k;
        e::tick_roaming(&mut s, [x0, y, z], &mut proxy, &mut window);
    }
    let step = Length::from_num(0.01);
    let mut x = x0;
    let mut out = RoamingTicks {
        steady: 0,
        shift: 0,
        shift_extra: 0,
    };
    let mut last = 0;
    for _ in 0..1000 {
        x += step;
        let before = window.shifts();
        let n = h
            .measure(1, || {
                black_box(e::tick_roaming(
                    &mut s,
                    black_box([x, y, depth]),
                    &mut proxy,
                    &mut window,
                ));
            })
            .saturating_sub(empty);
        if window.shifts() != before {
            out.shift = out.shift.max(n);
            out.shift_extra = out.shift_extra.max(n.saturating_sub(last));
        } else {
            out.steady = out.steady.max(n);
        }
        last = n;
    }
    if window.shifts() < 3 || !proxy.slipping() {
        exit(false)
    }
    out
}

/// What the host link adds to a tick (the board's TIM2, docs/link.md): the guard's gain
/// stepped in a critical section, the pose and the swap flag read, the device's pose
/// step, frame change and force scaling ([`mccs_firmware::link::LinkedDevice`]), the
/// flags and the snapshot for the main loop. Two controllers on the 3 × 3 patch (the
/// cost does not depend on the patch) follow the same indentation, one through the
/// link's device under a tilted pose (the rotation's cost: its worst case); the
/// difference of their ticks, averaged over 4.
#[inline(never)]
pub fn tick_link(h: &Harness, table: &ForceTable64) -> u32 {
    use mccs_firmware::link::{Guard, GuardTimes, LinkState, LinkedDevice};
    use mccs_firmware::{Controller, SimulatedDevice};
    const N: usize = mccs::topology::standard_capacity(3).0;
    const E: usize = mccs::topology::standard_capacity(3).1;
    // The board's call (boards/f405's bin keeps it in a static; here it is on the stack:
    // the M0's 16 KiB hold no second parameter set beside the bench's stack).
    let link: LinkState<N, 64, mccs::DefaultArith> =
        LinkState::new(Guard::new(GuardTimes::at_rate(1000, 0)));
    // A quarter turn about z, still turning while the ticks are measured (it takes 500
    // ticks at 180°/s): the slew's worst case, the probe still on the z axis.
    link.set_pose(mccs_link::Pose::from_mm_deg([0.0; 3], [0.0, 0.0, 90.0]));
    let solver = || {
        let Ok(topo) = Topology::<N, E>::standard_patch(3, 2.5) else {
            exit(false)
        };
        let Ok(s) = Solver::new(topo, *table, &mccs::SolverConfig::default()) else {
            exit(false)
        };
        s
    };
    let Ok(path) = mccs_firmware::indentation_path(1000) else {
        exit(false)
    };
    let mut bare = Controller::new(solver(), SimulatedDevice::new(path), u32::MAX);
    let mut linked = Controller::new(
        solver(),
        LinkedDevice::new(
            SimulatedDevice::new(path),
            mccs::TissuePose::new(200.0, 180.0, 1000.0),
            solver().max_force(),
        ),
        u32::MAX,
    );
    let link_tick = |ctl: &mut Controller<LinkedDevice<SimulatedDevice<7>>, N, E, 64>| {
        let f = link.run_tick(ctl);
        black_box(ctl.device().probe());
        f
    };
    for _ in 0..400 {
        bare.tick(None);
        link_tick(&mut linked);
    }
    let plain = h.measure(4, || {
        black_box(bare.tick(None));
    });
    let with_link = h.measure(4, || {
        black_box(link_tick(&mut linked));
    });
    with_link.saturating_sub(plain)
}

/// What the link's rarer work adds to the board's tick at the board's patch (N = 10, its
/// arithmetic, Table 2): a checked tissue swapped in (its parameter set copied out of
/// the mailbox and applied: [`Solver::apply`]) and a mesh captured and posted for the
/// main loop (`Mesh::of`, the mailbox's post, which copies an untaken one out), as
/// `LinkState::run_tick` does them; each averaged over 4, `(swap, mesh)`, the empty
/// call's cost included (the caller takes it off). The swap's counts the main loop's
/// post of the set too, one copy more than the tick makes. The board's budget model
/// adds both at their budgets (boards/f405's `LINK_WORK_COST`): one tick may do both.
#[inline(never)]
pub fn link_extras(h: &Harness, table: &ForceTable64) -> (u32, u32) {
    use mccs_firmware::link::Mesh;
    use mccs_firmware::Mailbox;
    const N: usize = mccs::topology::standard_capacity(10).0;
    const E: usize = mccs::topology::standard_capacity(10).1;
    let Ok(topo) = Topology::<N, E>::standard_patch(10, 2.5) else {
        exit(false)
    };
    // (The conservative bound spares the bench the estimate: `apply` does not run it.)
    let cfg = mccs::SolverConfig {
        bound: mccs::Bound::Conservative,
        integrator: mccs::Integrator::SymplecticDamped,
        ..mccs::SolverConfig::default()
    };
    let Ok(mut s) = Solver::<N, E, 64, mccs::Wide>::with_arith(topo, *table, &cfg, mccs::Wide)
    else {
        exit(false)
    };
    let Ok(set) = s.prepare(*table, &cfg) else {
        exit(false)
    };
    let probe = [Length::ZERO, Length::ZERO, Length::from_bits(-(1 << 23))];
    for _ in 0..200 {
        black_box(s.step(probe));
    }
    let swaps: Mailbox<mccs::ParamSet<64, mccs::Wide>> = Mailbox::new();
    let swap = h.measure(4, || {
        let _ = swaps.post(black_box(set));
        if let Some(taken) = swaps.take() {
            let _ = black_box(s.apply(taken));
        }
    });
    let meshes: Mailbox<Mesh<N>> = Mailbox::new();
    let mesh = h.measure(4, || {
        black_box(meshes.post(Mesh::of(&s, black_box(7), [0; 2])));
    });
    (swap, mesh)
}
