//! The M4F's spring loop and integrator are assembly (`mccs/src/arith/wide_dsp/`);
//! this checks them against the portable Rust loops they replace, bit for bit, on the
//! core itself, before anything is measured, on two sets of states:
//! - the standard N = 5 patch (61 springs, 25 of them between two free nodes) at random
//!   displacements from 0.25 µm to past the 64 mm clamp;
//! - 48 springs of their own (rest lengths 1 … 10 mm, random directions; half of them
//!   between two free nodes), each put at a chosen strain, so that every path is taken:
//!   stretched past the table's lower end and past the `±2 l0` hold, on its segments,
//!   crushed past its upper end, below `l0/8` (the held `l0/l`) and through zero length.
//!
//! Each state takes one of eight tables: Table 2's; the same with its coefficients 64
//! times larger (forces past the ±64 N hold) and a shift past 31 (which wraps, as
//! `wrapping_shr` does), and a graded corner of any contents above its uniform part
//! (an index past the table, masked); one with the steepest slopes, the largest end
//! forces and its upper line from an eighth of its range (the lines' products held,
//! their sums saturated); one with its lower line's anchor at `i32::MAX` (the strain
//! difference saturates); one whose range ends at `i32::MIN + 1` (the upper line's
//! does); the stiff series spring's (`tables/stiff_series.rs`), whose last 32
//! segments are a graded corner; the steep kink's (`tables/steep_kink.rs`), whose
//! corner lies under its grid (a lower corner); and the near transition's
//! (`tables/near_transition.rs`), a lower corner above its anchor (a negative
//! `corner_pre`). A quarter of the single springs are put
//! in the corner of a table that has one. The
//! second and fourth put each line's stiffness at either end of the range where its
//! force takes the Q28 slope (`mccs::table::fine_line`), with the largest slopes.
//!
//! Warm-start values, velocities and force accumulators (which wrap) are random, and each
//! state runs a few loops in a row with the integrator between them (its velocity and
//! displacement holds included), so that the warm start also converges. Prints
//! `KERNEL core=<c> states=<n> springs=<n> mismatches=<n>`; a mismatch exits with
//! failure. It runs on the M4F only: on the M3 both sides would be the same portable
//! loop (its bench's flash, 256 KiB, has no room for a check that cannot fail there),
//! and the M0's arithmetic is [`mccs::Narrow`], not checked here.

use super::fw_common::exit;
use super::rng::Rng;
use mccs::arith::{wide, ArithTable, StepSpec};
use mccs::state::Node;
use mccs::{Arith, End, ForceTable64, Integrator, Topology, Wide};
use mccs_firmware::target::{Core, CORE};

/// States checked, per set.
const STATES: u32 = 400;
/// Loops run in a row on each state.
const ROUNDS: usize = 3;
/// The tables the states take in turn ([`variants`]).
const VARIANTS: usize = 8;
/// The single springs: half to the ground, half between two free nodes.
const SINGLE: usize = 48;

/// Both loops on copies of one state, `ROUNDS` times; whether they ever differ.
fn differs<const N: usize, const E: usize>(
    table: &ArithTable<64, Wide>,
    coeffs: &<Wide as Arith>::Coeffs,
    topo: &Topology<N, E>,
    nodes: [Node; N],
    warm: [i32; E],
) -> bool {
    let (mut nodes_asm, mut warm_asm) = (nodes, warm);
    let (mut nodes_rust, mut warm_rust) = (nodes, warm);
    for round in 0..ROUNDS {
        Wide::spring_forces(table, coeffs, topo, &mut warm_asm, &mut nodes_asm);
        wide::spring_forces_portable(&table.table, coeffs, topo, &mut warm_rust, &mut nodes_rust);
        if nodes_asm != nodes_rust || warm_asm != warm_rust {
            return true;
        }
        // The integrator on the forces (not after the last loop, so that the
        // accumulators' wrapping is seen as well).
        if round + 1 < ROUNDS {
            Wide::integrate(coeffs, &mut nodes_asm[1..]);
            wide::integrate_portable(coeffs, &mut nodes_rust[1..]);
            if nodes_asm != nodes_rust {
                return true;
            }
        }
    }
    false
}

/// A random state's velocities, accumulators and warm-start values.
fn stir<const N: usize, const E: usize>(
    rng: &mut Rng,
    state: u32,
    nodes: &mut [Node; N],
    warm: &mut [i32; E],
) {
    let vel_bits = 8 + (state / 20) % 24;
    for n in nodes.iter_mut().skip(1) {
        n.v = core::array::from_fn(|_| rng.within(vel_bits));
        n.f = core::array::from_fn(|_| rng.next() as i32);
    }
    if !state.is_multiple_of(4) {
        for w in warm.iter_mut() {
            *w = (rng.next() >> 2) as i32;
        }
    }
}

/// Runs the check (on the M4F, whose loops are assembly; elsewhere both sides would be
/// the same portable loop, and the M3's flash has no room for it) and exits with
/// failure on a mismatch.
#[inline(never)]
pub fn check(table: &ForceTable64) {
    if CORE == Core::M4F {
        run(table);
    }
}

/// The check itself (out of line: its states stay off the M0's stack).
#[inline(never)]
fn run(table: &ForceTable64) {
    let Ok(topo) = Topology::<10, 61>::standard_patch(5, 2.5) else {
        exit(false)
    };
    let tables = variants(table);
    let mut rng = Rng(0x2545_F491);
    let mut mismatches = 0u32;
    let limit = mccs::state::DISP_LIMIT;
    let Some(single) = single_springs(&mut rng) else {
        exit(false)
    };
    for state in 0..STATES {
        let table = &tables[((state / 3) % VARIANTS as u32) as usize];
        // The graded corner's range (of the stiff series spring's table), in strain.
        let corner = table
            .table
            .corner()
            .map(|(a, b)| (a.to_num::<f64>(), b.to_num::<f64>()));
        let coeffs = Wide::coeffs(&StepSpec {
            h: 1.0 / 6000.0,
            node_mass: 0.005,
            node_damping: 0.05,
            spring_damping: [0.0, 1.0, 30.0][(state % 3) as usize],
            // Both integrators' loops, the symplectic one with a velocity factor.
            integrator: [Integrator::ImprovedEuler, Integrator::SymplecticDamped]
                [(state / 15 % 2) as usize],
            damping_factor: [1.0, 0.6][(state / 15 % 2) as usize],
        });
        // The patch: displacement scales 2^12 … 2^31 Q24 mm.
        let disp_bits = 12 + state % 20;
        let mut nodes = [Node::ZERO; 10];
        for n in nodes.iter_mut().skip(1) {
            n.u = core::array::from_fn(|_| rng.within(disp_bits).clamp(-limit, limit - 1));
        }
        let mut warm = [Wide::REST; 61];
        stir(&mut rng, state, &mut nodes, &mut warm);
        mismatches += differs(table, &coeffs, &topo, nodes, warm) as u32;
        // The single springs, each at a strain of its own: b − a = −e l0 d + a
        // perpendicular part of up to l0.
        let mut nodes = [Node::ZERO; 1 + 3 * SINGLE / 2];
        for s in &single.springs {
            let e = match rng.next() % 4 {
                0 => rng.uniform(-3.0, -0.4),
                1 => rng.uniform(-0.6, 1.0),
                2 => match corner {
                    Some((a, b)) => rng.uniform(a - 0.01, b + 0.01),
                    None => rng.uniform(0.85, 1.0),
                },
                _ => rng.uniform(0.9, 2.5),
            };
            let side = rng.uniform(-1.0, 1.0) * [0.0, 0.01, 0.3, 1.0][(state % 4) as usize];
            let p = s.perp;
            let rel: [f64; 3] = core::array::from_fn(|k| (-e * s.dir[k] + side * p[k]) * s.len);
            // Q24 mm; a ground spring moves a by −rel, a pair splits it.
            let q = |x: f64| ((x * 16_777_216.0) as i32).clamp(-limit, limit - 1);
            match s.b {
                None => nodes[s.a].u = rel.map(|x| q(-x)),
                Some(b) => {
                    nodes[s.a].u = rel.map(|x| q(-0.5 * x));
                    nodes[b].u = rel.map(|x| q(0.5 * x));
                }
            }
        }
        let mut warm = [Wide::REST; SINGLE];
        stir(&mut rng, state, &mut nodes, &mut warm);
        mismatches += differs(table, &coeffs, &single.topo, nodes, warm) as u32;
    }
    defmt::println!(
        "KERNEL core={=str} states={=u32} springs={=usize} mismatches={=u32}",
        CORE.name(),
        2 * STATES,
        61 + SINGLE,
        mismatches
    );
    if mismatches != 0 {
        exit(false)
    }
}

/// Table 2's table, the four variants that reach the holds and saturations, the stiff
/// series spring's, the steep kink's and the near transition's (module docs).
fn variants(table: &ForceTable64) -> [ArithTable<64, Wide>; VARIANTS] {
    static STIFF_SERIES: ForceTable64 = include!("../../../../tables/stiff_series.rs");
    let raw = *table.raw();
    let mut large = raw;
    // A corner over the top eighth of the range with an anchor and scale of any
    // contents: indices past the last segment, and through zero.
    large.corner_hi = raw.strain_hi;
    large.strain_hi = raw.strain_hi - (raw.strain_hi - raw.strain_lo) / 8;
    large.corner_anchor = raw.strain_hi + 12_345;
    large.corner_pre = 0x9E37_79B9;
    large.corner_base = 61;
    large.shift = raw.shift.saturating_sub(6) + 32;
    large.force_lo = raw.force_lo.saturating_mul(64);
    large.force_hi = raw.force_hi.saturating_mul(64);
    let mut steep = raw;
    steep.stiffness_lo = i32::MAX;
    steep.slope_lo = i32::MAX;
    steep.stiffness_hi = i32::MAX;
    steep.slope_hi = i32::MAX;
    steep.force_lo = i32::MIN + 1;
    steep.force_hi = i32::MAX - 1;
    steep.strain_hi = raw.strain_lo + (raw.strain_hi - raw.strain_lo) / 8;
    steep.corner_hi = steep.strain_hi;
    // The lower line's slope at the two ends of the gentle loop's range (the M4F's
    // assembly takes another product, with a Q28 slope, for a stiffness within ±2¹⁹):
    // the largest within it, with the largest Q28 slope and the anchor past every strain
    // (the product's largest magnitude), and the least beyond it (a Q16 slope).
    large.stiffness_lo = -(1 << 19) - 1;
    large.slope_lo = -(1 << 19) - 1;
    let mut anchored = raw;
    anchored.anchor_lo = i32::MAX;
    anchored.stiffness_lo = (1 << 19) - 1;
    anchored.slope_lo = i32::MAX;
    // The same for the line above (its Q28 product or its Q16 one, chosen per strain).
    large.stiffness_hi = (1 << 19) - 1;
    large.slope_hi = i32::MAX;
    anchored.stiffness_hi = 1 << 19;
    anchored.slope_hi = i32::MIN;
    let mut ends = raw;
    ends.strain_lo = i32::MIN;
    ends.strain_hi = i32::MIN + 1;
    ends.corner_hi = i32::MIN + 1;
    static STEEP_KINK: ForceTable64 = include!("../../../../tables/steep_kink.rs");
    static NEAR_TRANSITION: ForceTable64 = include!("../../../../tables/near_transition.rs");
    [
        raw,
        large,
        steep,
        anchored,
        ends,
        *STIFF_SERIES.raw(),
        *STEEP_KINK.raw(),
        *NEAR_TRANSITION.raw(),
    ]
    .map(|r| ArithTable::new(ForceTable64::from_raw(r)))
}

/// One spring of the single set: its nodes, rest length (mm), rest direction and a unit
/// vector across it.
struct Single {
    a: usize,
    b: Option<usize>,
    len: f64,
    dir: [f64; 3],
    perp: [f64; 3],
}

/// The single springs and their topology.
struct Singles {
    topo: Topology<{ 1 + 3 * SINGLE / 2 }, SINGLE>,
    springs: [Single; SINGLE],
}

/// `SINGLE` springs at random directions and rest lengths of 1.01 … 10 mm (the
/// topology's least is 1 mm), each with nodes of its own: the first half to the ground,
/// the second between two free nodes.
fn single_springs(rng: &mut Rng) -> Option<Singles> {
    let mut topo = Topology::new();
    let mut springs = core::array::from_fn(|_| Single {
        a: 0,
        b: None,
        len: 0.0,
        dir: [0.0; 3],
        perp: [0.0; 3],
    });
    for (i, s) in springs.iter_mut().enumerate() {
        let v: [f64; 3] = core::array::from_fn(|_| rng.uniform(-1.0, 1.0));
        let norm = libm::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).max(1e-3);
        let dir = v.map(|x| x / norm);
        // A unit vector across `dir`: dir × (the axis it is least along).
        let k = (0..3).min_by(|&i, &j| dir[i].abs().total_cmp(&dir[j].abs()))?;
        let axis: [f64; 3] = core::array::from_fn(|j| (j == k) as u8 as f64);
        let c = [
            dir[1] * axis[2] - dir[2] * axis[1],
            dir[2] * axis[0] - dir[0] * axis[2],
            dir[0] * axis[1] - dir[1] * axis[0],
        ];
        let cn = libm::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        let len = [1.01, 2.5, 4.0, 10.0][i % 4];
        let at = [
            (i % 8) as f64 * 10.0 - 40.0,
            (i / 8) as f64 * 10.0 - 30.0,
            0.0,
        ];
        let far: [f64; 3] = core::array::from_fn(|k| at[k] + len * dir[k]);
        let a = topo.add_free_node(at).ok()?;
        let b = if i < SINGLE / 2 {
            topo.add_edge(End::Free(a), End::Fixed(far)).ok()?;
            None
        } else {
            let b = topo.add_free_node(far).ok()?;
            topo.add_edge(End::Free(a), End::Free(b)).ok()?;
            Some(b as usize)
        };
        *s = Single {
            a: a as usize,
            b,
            len,
            dir,
            perp: c.map(|x| x / cn),
        };
    }
    Some(Singles { topo, springs })
}
