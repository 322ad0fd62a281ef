//! [`Wide`]: the spring and the integrator with every product a 32 × 32 → 64 multiply (one
//! `smull`/`smmulr` on the M3/M4F; the M0 builds each from 16-bit pieces with the same
//! bits, [`crate::q`]). Velocities are stored as they are, mm/s in Q16.

use super::{Arith, ArithTable, StepSpec, SPRING_FORCE_BITS, SPRING_FORCE_LIMIT};
use crate::q::{self, V3};
use crate::state::{
    for_each_spring, for_each_spring_checked, Ends, Node, SpringEnds, SpringKernel, DISP_LIMIT,
};
use crate::table::ForceTable;
use crate::topology::{Edge, Topology};
use crate::units::{from_f64, Strain, DIR_FRAC, FORCE_FRAC, INV_LEN_FRAC, LEN_FRAC, VEL_FRAC};

/// 32 × 32 → 64 products: the M3/M4F's arithmetic, and the host's default.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Wide;

/// Fraction bits of the spring damping (N·s/mm): Q16 mm/s · Q36 = Q52, the format of the
/// spring's `w · (f l0/l)` product (Q30 · Q22), whose high word is Q20 N.
const DAMP_FRAC: u32 = 36;
/// Fraction bits of the edge vector over the rest length, `w`: Q30 (±2 held; the
/// square of an axis is ≤ 2³⁰ in the product's high word, Q28, and the sum of three
/// fits a `u32`).
const W_FRAC: u32 = 30;
const _: () = assert!(
    DIR_FRAC == LEN_FRAC + INV_LEN_FRAC - 32,
    "dir + the high word"
);
/// Fraction bits of `|w|²` (`u32`, ≤ 12): the high word of two Q30 values' product.
const A_FRAC: u32 = 2 * W_FRAC - 32;
/// Fraction bits of the warm-started `l0/l`, `r`: Q27 (held below [`MAX_RATIO`]).
const R_FRAC: u32 = 27;
/// Fraction bits of `|w|² r` from the high word of `a · r`: Q23.
const AR_FRAC: u32 = A_FRAC + R_FRAC - 32;
/// `|w|² r` held below 4 (Q23): the converged value is `|w| ≤ 2√3`; above, the Newton
/// factor is at its floor anyway. Then Q28 (`<< 5`), so that `(a r) r` and `(a r) · factor`
/// are high words too.
const AR_LIMIT: i32 = 4 << AR_FRAC;
const AR_Q: u32 = 28;
/// Fraction bits of `a r²`: the high word of Q28 · Q27, Q23.
const ARR_FRAC: u32 = AR_Q + R_FRAC - 32;
/// Largest warm-started `l0/l` (exclusive): a spring crushed below `l0/8` keeps 8.
pub const MAX_RATIO: i32 = 8;
const R_MAX: i32 = (MAX_RATIO << R_FRAC) - 1;
/// `l0/l` as the spring's warm-start value stores it: 1 (rest) in Q27.
pub const REST_RATIO: i32 = 1 << R_FRAC;
/// Fraction bits of `−f l0/l`: Q22 (the law force within ±64 N times `l0/l` < 8 is within
/// ±512 N, which Q22 holds: never clamped).
const FR_FRAC: u32 = 22;
// The spring's two products share Q52, whose high word is Q20 N.
const _: () = assert!(VEL_FRAC + DAMP_FRAC == 32 + FORCE_FRAC);
const _: () = assert!(W_FRAC + FR_FRAC == 32 + FORCE_FRAC);
const _: () = assert!((64i64 * MAX_RATIO as i64) << FR_FRAC <= 1 << 31);
/// Largest edge vector over the rest length, per axis: 2 (Q23, the sum's format).
const W_LIMIT_23: i32 = 2 << DIR_FRAC;

/// Fraction bits of `h/m` ((mm/s)/N) and of `1 − h c/m` (the velocity kept through the
/// node damping): Q20 N · Q20 and Q16 mm/s · Q24 are both Q40, shifted by 24 to Q16 mm/s.
const HM_FRAC: u32 = 20;
const KEEP_FRAC: u32 = 24;
const _: () = assert!(VEL_FRAC + KEEP_FRAC == FORCE_FRAC + HM_FRAC);
/// Fraction bits of `h/2` (s): Q16 mm/s · Q40 s → high word Q24 mm.
const HALF_H_FRAC: u32 = 40;
const _: () = assert!(HALF_H_FRAC == 40, "MAX_SUBSTEP assumes h/2 in Q40");

/// [`Wide`]'s coefficients.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WideCoeffs {
    /// Spring damping `C`, N·s/mm, Q36.
    damping: i32,
    /// `h/m`, (mm/s)/N, Q20.
    h_over_m: i32,
    /// `1 − h c_node / m`, dimensionless, Q24 (in [½, 1] by the stability bound).
    keep: i32,
    /// `h/2`, s, Q40.
    half_h: i32,
    /// [`super::Integrator::SymplecticDamped`]: `u' = u + h v'`.
    symplectic: bool,
}

impl Arith for Wide {
    type TableAux = ();
    type Coeffs = WideCoeffs;
    const REST: i32 = REST_RATIO;
    const MAX_RATIO: f64 = MAX_RATIO as f64;
    const MAX_REST_LENGTH_MM: f64 = f64::INFINITY;

    fn table_aux<const S: usize>(_: &ForceTable<S>) {}

    fn warm_of_ratio(r: f64) -> i32 {
        from_f64(r, R_FRAC).clamp(0, R_MAX)
    }

    fn coeffs(spec: &StepSpec) -> WideCoeffs {
        let (h, hd) = (spec.h, spec.velocity_h());
        let (m, c) = (spec.node_mass, spec.node_damping);
        // N·s/m → N·s/mm: / 1000. h/m: (s/kg = m/(s·N)) · 1000 → (mm/s)/N.
        WideCoeffs {
            h_over_m: from_f64(1000.0 * hd / m, HM_FRAC),
            keep: from_f64(1.0 - hd * c / m, KEEP_FRAC),
            half_h: from_f64(0.5 * h, HALF_H_FRAC),
            damping: from_f64(spec.spring_damping / 1000.0, DAMP_FRAC),
            symplectic: spec.symplectic(),
        }
    }

    #[inline(always)]
    fn store_velocity(_: &WideCoeffs, v: i32) -> i32 {
        v
    }

    #[inline(always)]
    fn velocity(_: &WideCoeffs, stored: i32) -> i32 {
        stored
    }

    #[inline(always)]
    fn spring<const S: usize>(
        table: &ArithTable<S, Self>,
        c: &WideCoeffs,
        edge: &Edge,
        e: &SpringEnds,
        warm: &mut i32,
    ) -> V3 {
        spring::<S, true>(&table.table, edge, e.into(), warm, c.damping)
    }

    #[inline(always)]
    fn spring_forces<const S: usize, const NODES: usize, const EDGES: usize>(
        table: &ArithTable<S, Self>,
        c: &WideCoeffs,
        topo: &Topology<NODES, EDGES>,
        warm: &mut [i32; EDGES],
        nodes: &mut [Node; NODES],
    ) {
        #[cfg(mccs_dsp)]
        if super::wide_dsp::serves::<S, NODES>() {
            super::wide_dsp::spring_forces(&table.table, c.damping, topo, warm, nodes);
            return;
        }
        spring_forces_portable(&table.table, c, topo, warm, nodes);
    }

    #[inline(always)]
    fn integrate(c: &WideCoeffs, free: &mut [Node]) {
        #[cfg(mccs_dsp)]
        {
            super::wide_dsp::integrate(c.keep, c.h_over_m, c.half_h, c.symplectic, free);
        }
        #[cfg(not(mccs_dsp))]
        integrate_portable(c, free);
    }
}

/// Every spring's force, accumulated on its two nodes, in Rust: what [`Wide`] runs on
/// every core but the Armv7E-M ones (M4F), whose loop is in assembly
/// (`arith/wide_dsp/`) and must give the same bits; public so that the bench firmware
/// can check that on the M4F itself.
#[inline(always)]
pub fn spring_forces_portable<const S: usize, const NODES: usize, const EDGES: usize>(
    table: &ForceTable<S>,
    c: &WideCoeffs,
    topo: &Topology<NODES, EDGES>,
    warm: &mut [i32; EDGES],
    nodes: &mut [Node; NODES],
) {
    let damping = c.damping;
    // (A lower corner's check only in the loop of a table that has one, out of line.)
    if table.lower_corner() {
        let kernel = Kernel::<S, true> { table, damping };
        for_each_spring_checked(topo.edges(), warm, nodes, &kernel);
    } else {
        for_each_spring(topo, warm, nodes, &Kernel::<S, false> { table, damping });
    }
}

/// [`spring`] with its table and damping, for the solver's loop (`LOWER`: whether the
/// table may have a lower corner, [`ForceTable::force_within_for`]).
struct Kernel<'a, const S: usize, const LOWER: bool> {
    table: &'a ForceTable<S>,
    damping: i32,
}

impl<const S: usize, const LOWER: bool> SpringKernel for Kernel<'_, S, LOWER> {
    #[inline(always)]
    fn force(&self, edge: &Edge, ends: Ends<'_>, warm: &mut i32) -> V3 {
        spring::<S, LOWER>(self.table, edge, ends, warm, self.damping)
    }
}

/// The force on end `a` of one spring (Q20 N): the law along the edge plus the relative
/// damping (eq. 17), from the ends' displacements (Q24 mm) and velocities (Q16 mm/s).
/// `dir` is the unit rest vector (Q23), `inv_len` is `1/l0` (Q31), `r` the spring's
/// warm-started `l0/l` (Q27), advanced by one guarded Newton step, and `damping` the
/// spring damping (Q36 N·s/mm). `LOWER`: whether the table may have a lower corner
/// ([`ForceTable::force_within_for`]).
///
/// Ranges that let most steps skip saturation: displacements within ±64 mm and velocities
/// within ±16384 mm/s (the integrator clamps them), rest lengths ≥ 1 mm and at most
/// [`crate::topology::MAX_SPRINGS_PER_NODE`] springs per node (the topology checks),
/// spring damping ≤ 30 N·s/m (the configuration checks). Limits that follow, documented
/// behaviour:
/// - the normalised edge vector `(x_b − x_a)/l0` is capped at ±2 per axis: a spring
///   stretched further pulls as if stretched to 2 `l0` along that axis;
/// - `l0/l` stays below 8: a spring crushed below `l0/8` keeps it at 8, so its
///   direction vector shortens with the spring and the force fades to zero at zero length
///   instead of flipping;
/// - the law force is limited to ±64 N;
/// - one spring's force (law and damping) is limited to ±64 N, so that a node's sum
///   cannot overflow.
///
/// Every product is one long multiply (the M0 builds it from 16-bit pieces with the same
/// bits, [`crate::q`]); the formats are chosen so that most need no shift after it.
#[inline(always)]
fn spring<const S: usize, const LOWER: bool>(
    table: &ForceTable<S>,
    edge: &Edge,
    ends: Ends<'_>,
    r: &mut i32,
    damping: i32,
) -> V3 {
    let (dir, inv_len) = (edge.dir, edge.inv_len);
    let Ends { ua, ub, va, vb } = ends;
    // w = (x_b − x_a) / l0 = dir + (u_b − u_a) / l0: dir (Q23) plus the high word of
    // Q24 · Q31 (one `smmla`); |u_b − u_a| < 2³¹ (the displacement clamp) and
    // 1/l0 ≤ 1 keep that high word within ±2³⁰, so the sum cannot overflow. Held within
    // ±2 per axis (one `ssat`), whatever the displacement: a spring stretched further
    // pulls as if stretched to 2 l0 along that axis, never the other way. Then Q30.
    let w: V3 = core::array::from_fn(|k| {
        let w23 = q::mulhi_acc(ub[k].wrapping_sub(ua[k]), inv_len, dir[k]);
        w23.clamp(-W_LIMIT_23, W_LIMIT_23 - 1) << (W_FRAC - DIR_FRAC)
    });
    // a = |w|² ≤ 12: each square is Q60, its high word Q28 (≤ 2³⁰); the sum of the
    // three high words (within 2 LSB, 7e-9, of the high word of the sum) fits a `u32`.
    // (`opaque`: a plain 32-bit value from here, so that the products below stay single
    // long multiplies.)
    let a = (q::mulhi(w[0], w[0]) as u32)
        .wrapping_add(q::mulhi(w[1], w[1]) as u32)
        .wrapping_add(q::mulhi(w[2], w[2]) as u32);
    let a = q::opaque(a as i32) as u32;
    let r0 = q::opaque(*r);
    // Newton for 1/|w|: r ← r (3 − a r²)/2 = r + r g with g = (1 − a r²)/2. `a r`
    // (Q28 · Q27, high word Q23, ≤ 96) held below 4, then Q28; `a r²` the high word of
    // Q28 · Q27, Q23, held within [0, 2) (one `usat`), so that the factor 1 + g stays in
    // (1/2, 3/2]: a step from far above at most halves `r`. g in Q32 is
    // `2³¹ − 1 − (a r²) · 2⁸` (one `eor`: 2⁻³² below the exact half, a bias of 2e-10).
    let ar =
        q::opaque((q::mulhi_u(a, r0 as u32) as i32).clamp(0, AR_LIMIT - 1) << (AR_Q - AR_FRAC));
    let arr = q::mulhi(ar, r0).clamp(0, (2 << ARR_FRAC) - 1);
    let g = q::opaque((arr << (32 - 1 - ARR_FRAC)) ^ i32::MAX);
    // r' = r + r g (one `smmla`) ≤ 3/2 r < 12 (Q27: no overflow), held below 8. No floor
    // is needed: |w| ≤ 2√3 keeps 1/|w| ≥ 0.29, and a step from above lands at
    // ≥ r/2 > 1/(2|w|) ≥ 1/7.
    let rn = q::opaque(q::mulhi_acc(r0, g, r0).clamp(0, R_MAX));
    *r = rn;
    // |w| = a r' = (a r) + (a r) g: Q28, < 6 (one `smmla`); the strain 1 − |w| in Q24.
    let stretch = q::mulhi_acc(ar, g, ar);
    let strain = Strain::from_bits(((1 << AR_Q) - stretch) >> (AR_Q - LEN_FRAC));
    let f = table.force_within_for::<SPRING_FORCE_BITS, LOWER>(strain);
    // A compressed spring (f > 0) pushes a away from b: −f w/|w| = w (−f r).
    // f r: Q20 · Q27 = Q47, Q22 is `>> 25`: |f| ≤ 64 N and r < 8 keep it within
    // ±512 N, which Q22 holds (and its negation). Negated after the shift, so that the
    // M4F's loop subtracts the product instead (`smmlsr`, one negation fewer).
    let neg_fr = ((q::mul_wide(f, rn) >> (FORCE_FRAC + R_FRAC - FR_FRAC)) as i32).wrapping_neg();
    // The velocities are read only now (no instruction: it keeps the compiler from
    // loading them early and spilling them around the table lookup).
    core::sync::atomic::compiler_fence(core::sync::atomic::Ordering::SeqCst);
    // C (v_b − v_a) + w (−f r): Q16 · Q36 and Q30 · Q22, both Q52, whose high words are
    // Q20 N (|C (v_b − v_a)| < 2³⁰, |w f r| ≤ 2³⁰: the sum fits). The two high words are
    // rounded to nearest, so that their sum has no bias against the high word of the sum
    // (floors would pull every spring by −1 LSB): one `smmulr` and one `smmlar` on the
    // M3/M4, no 64-bit sum on the M0.
    core::array::from_fn(|k| {
        let dv = vb[k].wrapping_sub(va[k]);
        let p = q::mulhi_round(dv, damping) + q::mulhi_round(w[k], neg_fr);
        p.clamp(-SPRING_FORCE_LIMIT, SPRING_FORCE_LIMIT - 1)
    })
}

/// The integrator on every node of `free`, in Rust: what [`Wide`] runs on every core but
/// the Armv7E-M ones, whose loop is in assembly (`arith/wide_dsp/`) and must give the
/// same bits (the bench firmware checks it on the M4F). (The scheme's flag is read per
/// node: on the M3 that measured fewer instructions at N = 5 than two loops.)
#[inline(always)]
pub fn integrate_portable(c: &WideCoeffs, free: &mut [Node]) {
    free.iter_mut().for_each(|n| integrate(c, n));
}

/// One node's step, and its force accumulator cleared for the next substep: improved
/// Euler (eqs. 21, 22), or with `c.symplectic` the position from the new velocity alone
/// (`h D/m` and `1 − h D c/m` are in the coefficients).
#[inline(always)]
fn integrate(c: &WideCoeffs, n: &mut Node) {
    for j in 0..3 {
        let (u, v, f) = (n.u[j], n.v[j], n.f[j]);
        // v' = (1 − h c/m) v + (h/m) f: Q16 · Q24 and Q20 · Q20, both Q40. Held within
        // ±2³⁰ (±16384 mm/s) through the high word; the low bits of a held value are the
        // product's own (below 0.004 mm/s).
        let p = q::mul_wide(v, c.keep) + q::mul_wide(f, c.h_over_m);
        let v_new = q::shr_held::<{ FORCE_FRAC + HM_FRAC - VEL_FRAC }, 30>(p);
        // u' = u + (v + v') h/2, or (v' + v') h/2 = h v': |v + v'| < 2³¹ and h/2 < 2³¹
        // in Q40, so |du| < 2³⁰ and the sum cannot overflow before the clamp.
        let from = if c.symplectic { v_new } else { v };
        let du = q::mulhi(from.wrapping_add(v_new), c.half_h);
        n.u[j] = u.wrapping_add(du).clamp(-DISP_LIMIT, DISP_LIMIT - 1);
        n.v[j] = v_new;
    }
    n.f = [0; 3];
}
