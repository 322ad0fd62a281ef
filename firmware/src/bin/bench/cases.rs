//! The measured cases of the arithmetic: one table evaluation, one spring (alone, in its
//! loop, and on each path of the table), one substep of the standard patch (fixed point
//! and floating point). Whole ticks and the start-up: `ticks.rs`.

use super::fw_common::exit;
use super::harness::Harness;
use core::hint::black_box;
use mccs::arith::ArithTable;
use mccs::state::SpringEnds;
use mccs::{
    Arith, DefaultArith, Edge, End, ForceTable64, Length, Solver, SolverConfig, Strain, Topology,
};
use mccs_firmware::entry as e;
use mccs_firmware::float_patch::{FloatPatch, Real};

/// `force_and_stiffness` over strains sweeping [−0.25, 0.75): both straight lines and
/// the cubic part. The harness (the next strain, the black boxes) is measured alone and
/// taken off. Out of line, like every case: its stack frame is gone before the next.
#[inline(never)]
pub fn force_and_stiffness(h: &Harness, table: &ForceTable64) -> u32 {
    let mut k = 0i32;
    let harness = h.measure(256, || {
        k = k.wrapping_add(65_713);
        let eps = Strain::from_bits((k & 0x00FF_FFFF) - 0x0040_0000);
        black_box((black_box(table), eps));
    });
    let mut k = 0i32;
    let fs = h.measure(256, || {
        k = k.wrapping_add(65_713);
        let eps = Strain::from_bits((k & 0x00FF_FFFF) - 0x0040_0000);
        black_box(e::force_and_stiffness(black_box(table), eps));
    });
    fs - harness
}

/// `force_and_stiffness` over strains sweeping a graded corner (`table` must have one:
/// the stiff series spring's, `tables/stiff_series.rs`, or the steep kink's lower one,
/// `tables/steep_kink.rs`), harness taken off: what an
/// evaluation costs there (its octave's `clz`, the stiffness's scale per octave).
#[inline(never)]
pub fn force_and_stiffness_corner(h: &Harness, table: &ForceTable64) -> u32 {
    let Some((a, b)) = table.corner() else {
        return 0;
    };
    let (lo, span) = (a.to_bits(), (b.to_bits() - a.to_bits()).max(1) as u32);
    let mut k = 0u32;
    let harness = h.measure(256, || {
        k = k.wrapping_add(65_713);
        let eps = Strain::from_bits(lo + (k % span) as i32);
        black_box((black_box(table), eps));
    });
    let mut k = 0u32;
    let fs = h.measure(256, || {
        k = k.wrapping_add(65_713);
        let eps = Strain::from_bits(lo + (k % span) as i32);
        black_box(e::force_and_stiffness(black_box(table), eps));
    });
    fs - harness
}

/// The spring case's inputs (raw formats of `mccs::arith`).
struct SpringCase {
    edge: Edge,
    ends: SpringEnds,
    coeffs: <DefaultArith as Arith>::Coeffs,
}

/// A 4 mm spring along −z compressed by 2 mm (strain 0.5: the table's cubic part, the
/// longest path), its ends moving, 1 N·s/m of damping (the default configuration).
fn spring_case() -> SpringCase {
    let cfg = SolverConfig::default();
    SpringCase {
        edge: Edge {
            a: 1,
            b: 2,
            dir: [0, 0, -(1 << mccs::units::DIR_FRAC)],
            inv_len: 1 << 29,
        },
        ends: SpringEnds {
            ua: [0; 3],
            ub: [1 << 20, -(1 << 20), 2 << 24],
            va: [10, -20, 30],
            vb: [0; 3],
        },
        coeffs: DefaultArith::coeffs(&mccs::arith::StepSpec {
            h: 1.0 / 6000.0,
            node_mass: cfg.node_mass,
            node_damping: cfg.node_damping,
            spring_damping: cfg.spring_damping,
            integrator: mccs::Integrator::ImprovedEuler,
            damping_factor: 1.0,
        }),
    }
}

/// [`e::spring`]'s signature, and nothing but taking its arguments into registers
/// (empty `asm!`) and returning zeros: the spring case's harness.
#[inline(never)]
fn no_spring(
    table: &ArithTable<64, DefaultArith>,
    coeffs: &<DefaultArith as Arith>::Coeffs,
    edge: &Edge,
    ends: &SpringEnds,
    warm: &mut i32,
) -> [i32; 3] {
    // SAFETY: the template is a comment: nothing is read or written.
    unsafe {
        core::arch::asm!(
            "/* {0} {1} {2} {3} {4} */",
            in(reg) table,
            in(reg) coeffs,
            in(reg) edge,
            in(reg) ends,
            in(reg) warm,
            options(nostack, preserves_flags)
        );
    }
    [0; 3]
}

/// One spring (`spring_case`) through `e::spring`, less the same call to `no_spring`
/// (the call, the arguments and the harness's black boxes).
#[inline(never)]
pub fn spring(h: &Harness, table: &ForceTable64) -> u32 {
    let table = black_box(ArithTable::<64, DefaultArith>::new(*table));
    let mut r = DefaultArith::REST;
    let case = spring_case();
    let harness = h.measure(256, || {
        let c = black_box(&case);
        black_box(no_spring(
            black_box(&table),
            &c.coeffs,
            &c.edge,
            &c.ends,
            &mut r,
        ));
    });
    let spring = h.measure(256, || {
        let c = black_box(&case);
        black_box(e::spring(
            black_box(&table),
            &c.coeffs,
            &c.edge,
            &c.ends,
            &mut r,
        ));
    });
    spring - harness
}

/// One substep of the standard N × N patch (2.5 mm, default configuration), after
/// 200 ticks pressed in, averaged over 16.
#[inline(never)]
pub fn substep<const N: usize, const E: usize>(
    h: &Harness,
    n: usize,
    table: &ForceTable64,
    probe: [Length; 3],
    integrator: mccs::Integrator,
) -> u32 {
    let Ok(topo) = Topology::<N, E>::standard_patch(n, 2.5) else {
        exit(false)
    };
    // The cost of a substep does not depend on the substeps per tick: the conservative
    // bound spares the bench the estimate's start-up time.
    let cfg = SolverConfig {
        bound: mccs::Bound::Conservative,
        integrator,
        ..SolverConfig::default()
    };
    let Ok(mut s) = Solver::new(topo, *table, &cfg) else {
        exit(false)
    };
    for _ in 0..200 {
        e::tick(&mut s, probe);
    }
    h.measure(16, || e::substep(&mut s, black_box(probe)))
}

/// The spring loop alone ([`e::spring_loop`]) over the standard N × N patch pressed as
/// [`substep`] presses it, per spring: the loop's instructions (averaged over 16 runs)
/// over the patch's springs, rounded to the nearest. What one spring costs where the
/// solver runs it (on the M4F, its assembly loop; the `spring` case is the portable
/// kernel called alone).
#[inline(never)]
pub fn spring_in_loop<const N: usize, const E: usize>(
    h: &Harness,
    n: usize,
    table: &ForceTable64,
    probe: [Length; 3],
    empty: u32,
) -> u32 {
    let Ok(topo) = Topology::<N, E>::standard_patch(n, 2.5) else {
        exit(false)
    };
    let cfg = SolverConfig {
        bound: mccs::Bound::Conservative,
        ..SolverConfig::default()
    };
    let Ok(mut s) = Solver::new(topo, *table, &cfg) else {
        exit(false)
    };
    for _ in 0..200 {
        e::tick(&mut s, probe);
    }
    let coeffs = DefaultArith::coeffs(&mccs::arith::StepSpec {
        h: 1.0 / (cfg.tick_hz * s.substeps() as f64),
        node_mass: cfg.node_mass,
        node_damping: cfg.node_damping,
        spring_damping: cfg.spring_damping,
        integrator: cfg.integrator,
        damping_factor: 1.0,
    });
    // The solver's pressed state, node by node (its velocities as this arithmetic stores
    // them).
    let mut nodes = [mccs::state::Node::ZERO; N];
    for (i, node) in nodes.iter_mut().enumerate().skip(1) {
        let (Some(u), Some(v)) = (s.displacement(i as u16), s.velocity(i as u16)) else {
            continue;
        };
        node.u = u.map(Length::to_bits);
        node.v = v.map(|x| DefaultArith::store_velocity(&coeffs, x.to_bits()));
    }
    let table = ArithTable::<64, DefaultArith>::new(*table);
    let mut warm = [DefaultArith::REST; E];
    // One run first, so that the warm starts are the pressed state's.
    let topo = s.topology();
    e::spring_loop(&table, &coeffs, topo, &mut warm, &mut nodes);
    let run = h.measure(16, || {
        e::spring_loop(
            black_box(&table),
            &coeffs,
            black_box(topo),
            &mut warm,
            &mut nodes,
        )
    });
    let springs = topo.edges().len().max(1) as u32;
    (run.saturating_sub(empty) + springs / 2) / springs
}

/// One floating-point substep of the standard N × N patch at `substeps` per tick (the
/// fixed-point solver's), after 200 substeps pressed in, averaged over 4.
#[inline(never)]
pub fn float<T: Real, const N: usize, const E: usize>(
    h: &Harness,
    n: usize,
    substeps: u32,
    table: &ForceTable64,
) -> u32 {
    let Ok(topo) = Topology::<N, E>::standard_patch(n, 2.5) else {
        exit(false)
    };
    let cfg = SolverConfig::default();
    let mut p = FloatPatch::<T, N, E, 64>::new(&topo, table, &cfg, substeps);
    let probe = [T::ZERO, T::ZERO, T::of(-0.5)];
    for _ in 0..200 {
        float_substep(&mut p, probe);
    }
    h.measure(4, || float_substep(&mut p, black_box(probe)))
}

#[inline(never)]
fn float_substep<T: Real, const N: usize, const E: usize>(
    p: &mut FloatPatch<T, N, E, 64>,
    probe: [T; 3],
) {
    p.substep(probe)
}

/// One spring where the solver runs it (`e::spring_loop`, on the M4F its assembly loop),
/// per spring, with every spring at the same `strain` (compression positive) on `table`,
/// which must fall on `path` (else the bench fails): 16 springs in parallel between two
/// free nodes 2.5 mm apart, the far end displaced along the springs (and 0.001 mm
/// across, which moves the strain by less than 1e-4), both ends moving. What each path of
/// a spring costs (the table's line below, uniform part, graded corner and line above,
/// an edge vector held at ±2, `l0/l` held), so that a tick's cost can be bounded over
/// every state, not only the pressed patch's. The loop's own overhead per call is in
/// the figure (1/16 of it per spring).
#[inline(never)]
pub fn spring_path(
    h: &Harness,
    table: &ForceTable64,
    strain: f64,
    path: TablePath,
    empty: u32,
) -> u32 {
    const SPRINGS: usize = 16;
    const L0: f64 = 2.5;
    // The far end's displacement: along the springs by `strain`, and a little across.
    const ACROSS: f64 = 0.001;
    // The springs' strain as placed (the crossways offset lengthens them a little), on
    // the path named, or the figure would be another path's.
    let along = L0 * (1.0 - strain);
    let placed = 1.0 - libm::sqrt(2.0 * ACROSS * ACROSS + along * along) / L0;
    if TablePath::of(table, placed) != path {
        exit(false)
    }
    let mut topo = Topology::<3, SPRINGS>::new();
    let (Ok(a), Ok(b)) = (
        topo.add_free_node([0.0, 0.0, 0.0]),
        topo.add_free_node([0.0, 0.0, -L0]),
    ) else {
        exit(false)
    };
    for _ in 0..SPRINGS {
        if topo.add_edge(End::Free(a), End::Free(b)).is_err() {
            exit(false)
        }
    }
    let cfg = SolverConfig::default();
    let coeffs = DefaultArith::coeffs(&mccs::arith::StepSpec {
        h: 1.0 / 3000.0,
        node_mass: cfg.node_mass,
        node_damping: cfg.node_damping,
        spring_damping: cfg.spring_damping,
        integrator: cfg.integrator,
        damping_factor: 1.0,
    });
    let q24 = |mm: f64| Length::from_num(mm).to_bits();
    let v16 = |mm_s: i32| DefaultArith::store_velocity(&coeffs, mm_s << 16);
    let mut nodes = [mccs::state::Node::ZERO; 3];
    nodes[1].v = [v16(3), v16(-2), v16(5)];
    nodes[2].u = [q24(ACROSS), q24(-ACROSS), q24(strain * L0)];
    nodes[2].v = [v16(-1), v16(4), v16(-6)];
    let (u, v) = (nodes[2].u, nodes[2].v);
    let table = ArithTable::<64, DefaultArith>::new(*table);
    let mut warm = [DefaultArith::REST; SPRINGS];
    // Settle the warm starts on this state first (each run takes one Newton step).
    for _ in 0..8 {
        e::spring_loop(&table, &coeffs, &topo, &mut warm, &mut nodes);
    }
    let run = h.measure(16, || {
        // The loop accumulates forces on the nodes; the ends do not move.
        e::spring_loop(
            black_box(&table),
            &coeffs,
            black_box(&topo),
            &mut warm,
            &mut nodes,
        );
        nodes[2].u = u;
        nodes[2].v = v;
    });
    (run.saturating_sub(empty) + SPRINGS as u32 / 2) / SPRINGS as u32
}

/// Where a strain falls in a force table: which of its evaluation's paths it takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TablePath {
    /// The line below the table.
    Below,
    /// The uniform part.
    Uniform,
    /// The graded corner.
    Corner,
    /// The line above.
    Above,
}

impl TablePath {
    /// The path `strain` takes in `table`, from its layout (`tabulated_range`, `corner`).
    pub fn of(table: &ForceTable64, strain: f64) -> Self {
        let e = Strain::from_num(strain);
        let (lo, hi) = table.tabulated_range();
        if e <= lo {
            Self::Below
        } else if e >= hi {
            Self::Above
        } else if table.corner().is_some_and(|(a, b)| e >= a && e < b) {
            Self::Corner
        } else {
            Self::Uniform
        }
    }
}
