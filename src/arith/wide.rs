//! [`Wide`]: the spring and the integrator with every product a 32 × 32 → 64 multiply (one
//! `smull`/`smmulr` on the M3/M4F; the M0 builds each from 16-bit pieces with the same
//! bits, [`crate::q`]). Velocities are stored as they are, mm/s in Q16.

use super::{Arith, ArithTable, StepSpec, SPRING_FORCE_BITS, SPRING_FORCE_LIMIT};
use crate::q::{self, V3};
use crate::state::{for_each_spring, Ends, Node, SpringEnds, SpringKernel, DISP_LIMIT};
use crate::table::ForceTable;
use crate::topology::{Edge, Topology};
use crate::units::{from_f64, Strain, DIR_FRAC, FORCE_FRAC, INV_LEN_FRAC, LEN_FRAC, ONE, VEL_FRAC};

/// 32 × 32 → 64 products: the M3/M4F's arithmetic, and the host's default.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Wide;

/// Fraction bits of the spring damping (N·s/mm): Q16 mm/s · Q36 = Q52, the format of the
/// spring's `w · (f l0/l)` product (Q29 · Q23), whose high word is Q20 N.
const DAMP_FRAC: u32 = 36;
/// Fraction bits of the edge vector over the rest length, `w`: Q29 (±2 held).
const W_FRAC: u32 = 29;
const _: () = assert!(
    DIR_FRAC == LEN_FRAC + INV_LEN_FRAC - 32,
    "dir + the high word"
);
/// Fraction bits of `f l0/l`: Q23 (±256 N held).
const FR_FRAC: u32 = 23;
// The spring's two products share Q52, whose high word is Q20 N.
const _: () = assert!(VEL_FRAC + DAMP_FRAC == 32 + FORCE_FRAC);
const _: () = assert!(W_FRAC + FR_FRAC == 32 + FORCE_FRAC);
/// Upper bound of the warm-started `l0/l`: springs shorter than `l0/16` keep it at 16.
const R_MAX: i32 = (16 << LEN_FRAC) - 1;
/// Largest law force per unit current length, `|f| · l0/l`: 256 N = 2³¹ in Q23.
pub const FORCE_PER_STRETCH_LIMIT_N: i32 = 256;
const _: () = assert!(FORCE_PER_STRETCH_LIMIT_N as i64 == 1 << (31 - FR_FRAC));
/// Largest edge vector over the rest length, per axis: 2 (Q29).
const W_LIMIT: i32 = 2 << W_FRAC;

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
}

impl Arith for Wide {
    type TableAux = ();
    type Coeffs = WideCoeffs;
    const REST: i32 = ONE;
    const MAX_REST_LENGTH_MM: f64 = f64::INFINITY;

    fn table_aux<const S: usize>(_: &ForceTable<S>) {}

    fn coeffs(spec: &StepSpec) -> WideCoeffs {
        let StepSpec {
            h,
            node_mass: m,
            node_damping: c,
            spring_damping,
        } = *spec;
        // N·s/m → N·s/mm: / 1000. h/m: (s/kg = m/(s·N)) · 1000 → (mm/s)/N.
        WideCoeffs {
            h_over_m: from_f64(1000.0 * h / m, HM_FRAC),
            keep: from_f64(1.0 - h * c / m, KEEP_FRAC),
            half_h: from_f64(0.5 * h, HALF_H_FRAC),
            damping: from_f64(spring_damping / 1000.0, DAMP_FRAC),
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
        spring(&table.table, edge, e.into(), warm, c.damping)
    }

    #[inline(always)]
    fn spring_forces<const S: usize, const NODES: usize, const EDGES: usize>(
        table: &ArithTable<S, Self>,
        c: &WideCoeffs,
        topo: &Topology<NODES, EDGES>,
        warm: &mut [i32; EDGES],
        nodes: &mut [Node; NODES],
    ) {
        let kernel = Kernel {
            table: &table.table,
            damping: c.damping,
        };
        for_each_spring(topo, warm, nodes, &kernel);
    }

    #[inline(always)]
    fn integrate(c: &WideCoeffs, free: &mut [Node]) {
        free.iter_mut().for_each(|n| integrate(c, n));
    }
}

/// [`spring`] with its table and damping, for the solver's loop.
struct Kernel<'a, const S: usize> {
    table: &'a ForceTable<S>,
    damping: i32,
}

impl<const S: usize> SpringKernel for Kernel<'_, S> {
    #[inline(always)]
    fn force(&self, edge: &Edge, ends: Ends<'_>, warm: &mut i32) -> V3 {
        spring(self.table, edge, ends, warm, self.damping)
    }
}

/// The force on end `a` of one spring (Q20 N): the law along the edge plus the relative
/// damping (eq. 17), from the ends' displacements (Q24 mm) and velocities (Q16 mm/s).
/// `dir` is the unit rest vector (Q29), `inv_len` is `1/l0` (Q31), `r` the spring's
/// warm-started `l0/l` (Q24), advanced by one guarded Newton step, and `damping` the
/// spring damping (Q36 N·s/mm).
///
/// Ranges that let most steps skip saturation: displacements within ±64 mm and velocities
/// within ±16384 mm/s (the integrator clamps them), rest lengths ≥ 1 mm and at most
/// [`crate::topology::MAX_SPRINGS_PER_NODE`] springs per node (the topology checks),
/// spring damping ≤ 30 N·s/m (the configuration checks). Limits that follow, documented
/// behaviour:
/// - the normalised edge vector `(x_b − x_a)/l0` is capped at ±2 per axis: a spring
///   stretched further pulls as if stretched to 2 `l0` along that axis;
/// - `l0/l` stays below 16: a spring crushed below `l0/16` keeps it at 16, so its
///   direction vector shortens with the spring and the force fades to zero at zero length
///   instead of flipping;
/// - the law force is limited to ±64 N, and `|f| l0/l` to 256 N (a spring at 64 N
///   compressed past `l0/4` pushes as if at `l0/4`);
/// - one spring's force (law and damping) is limited to ±64 N, so that a node's sum
///   cannot overflow.
///
/// Every product is one long multiply (the M0 builds it from 16-bit pieces with the same
/// bits, [`crate::q`]); the formats are chosen so that most need no shift after it.
#[inline(always)]
fn spring<const S: usize>(
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
    // pulls as if stretched to 2 l0 along that axis, never the other way. Then Q29.
    let w: V3 = core::array::from_fn(|k| {
        let w23 = q::mulhi_acc(ub[k].wrapping_sub(ua[k]), inv_len, dir[k]);
        w23.clamp(-(W_LIMIT >> 6), (W_LIMIT >> 6) - 1) << (W_FRAC - DIR_FRAC)
    });
    // a = |w|² ≤ 12: each square is Q58, its high word Q26; the sum of the three high
    // words is within 2 LSB (3e-8) of the high word of the sum, and costs the M0 no low
    // words. (`opaque`: a plain 32-bit value from here, so that the products below stay
    // single long multiplies.)
    let a = q::mulhi(w[0], w[0]) + q::mulhi(w[1], w[1]) + q::mulhi(w[2], w[2]);
    let a = q::opaque(a);
    let r0 = q::opaque(*r);
    // Newton for 1/|w|: r ← r (3 − a r²)/2 = r (3/2 − (a r) r / 2). `a r` ≤ 192 fits Q23
    // (Q26 · Q24 >> 27); held at 8 (|w| ≤ 8/r when converged), which already drives the
    // factor to its floor.
    let ar = q::opaque(((q::mul_wide(a, r0) >> 27) as i32).clamp(0, (8 << 23) - 1));
    // (a r) r / 2 in Q24: Q23 · Q24 = Q47 is a r², so Q48 is its half; ≤ 2³⁰, held
    // below 1 (one `usat`), so that the factor 3/2 − a r²/2 stays in (1/2, 3/2]: a step
    // from far above at most halves `r`.
    let half_x = ((q::mul_wide(ar, r0) >> LEN_FRAC) as i32).clamp(0, ONE - 1);
    let factor = q::opaque(3 * ONE / 2 - half_x);
    // r' ≤ 3/2 r, held below 16. No floor is needed: |w| ≤ 2√3 keeps 1/|w| ≥ 0.29, and a
    // step from above lands at ≥ r/2 > 1/(2|w|) ≥ 1/7.
    let rn = q::opaque(((q::mul_wide(r0, factor) >> LEN_FRAC) as i32).clamp(0, R_MAX));
    *r = rn;
    // |w| = a r' = (a r) · factor: Q23 · Q24 >> 23 → Q24, ≤ 12.
    let stretch = (q::mul_wide(ar, factor) >> 23) as i32;
    let strain = Strain::from_bits(ONE - stretch);
    let f = table.force_within::<SPRING_FORCE_BITS>(strain);
    // A compressed spring (f > 0) pushes a away from b: −f w/|w| = w (−f r).
    // −f r: Q20 · Q24 = Q44; Q23 is `>> 21`, held within ±256 N through the high word
    // (the low bits of a held value are the product's own, below 2⁻¹² N).
    let neg_fr = q::shr_held::<{ FORCE_FRAC + LEN_FRAC - FR_FRAC }, 31>(q::mul_wide(-f, rn));
    // The velocities are read only now (no instruction: it keeps the compiler from
    // loading them early and spilling them around the table lookup).
    core::sync::atomic::compiler_fence(core::sync::atomic::Ordering::SeqCst);
    // C (v_b − v_a) + w (−f r): Q16 · Q36 and Q29 · Q23, both Q52, whose high words are
    // Q20 N (|C (v_b − v_a)| < 2³⁰, |w f r| < 2²⁹: the sum fits). The two high words are
    // rounded to nearest, so that their sum has no bias against the high word of the sum
    // (floors would pull every spring by −1 LSB): one `smmulr` and one `smmlar` on the
    // M3/M4, no 64-bit sum on the M0.
    core::array::from_fn(|k| {
        let dv = vb[k].wrapping_sub(va[k]);
        let p = q::mulhi_round(dv, damping) + q::mulhi_round(w[k], neg_fr);
        p.clamp(-SPRING_FORCE_LIMIT, SPRING_FORCE_LIMIT - 1)
    })
}

/// Improved Euler for one node (eqs. 21, 22), and the node's force accumulator cleared
/// for the next substep.
#[inline(always)]
fn integrate(c: &WideCoeffs, n: &mut Node) {
    for j in 0..3 {
        let (u, v, f) = (n.u[j], n.v[j], n.f[j]);
        // v' = (1 − h c/m) v + (h/m) f: Q16 · Q24 and Q20 · Q20, both Q40. Held within
        // ±2³⁰ (±16384 mm/s) through the high word; the low bits of a held value are the
        // product's own (below 0.004 mm/s).
        let p = q::mul_wide(v, c.keep) + q::mul_wide(f, c.h_over_m);
        let v_new = q::shr_held::<{ FORCE_FRAC + HM_FRAC - VEL_FRAC }, 30>(p);
        // u' = u + (v + v') h/2: |v + v'| < 2³¹ and h/2 < 2³¹ in Q40, so |du| < 2³⁰ and
        // the sum cannot overflow before the clamp.
        let du = q::mulhi(v.wrapping_add(v_new), c.half_h);
        n.u[j] = u.wrapping_add(du).clamp(-DISP_LIMIT, DISP_LIMIT - 1);
        n.v[j] = v_new;
    }
    n.f = [0; 3];
}
