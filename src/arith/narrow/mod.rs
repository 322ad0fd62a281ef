//! [`Narrow`]: the spring, the table lookup and the integrator with one 16-bit operand
//! per product — two 32-bit multiplies on the Cortex-M0 (which has no long multiply)
//! instead of four 16 × 16 ones and a dozen adds.
//!
//! It is written so that the 16-bit side is always an order-one quantity and the errors
//! are relative (a few 1e-4 of the force, measured: `docs/accuracy.md`):
//! - the strain comes without cancellation: with `d` the unit rest vector and
//!   `q = (u_b − u_a)/l0`, the edge over its rest length is `w = d + q` and
//!   `s = |w|² − 1 = q · (d + w)`, small when the spring is;
//! - `l0/l = 1/√(1 + s)` by a warm-started Newton step on its deviation from 1;
//! - node velocities are stored as `C_v v` in N ([`NarrowDamping`]), so that a spring's
//!   damping force is a difference of stored values, with no product from
//!   [`NARROW_MIN_DAMPING`] up;
//! - the table's straight lines use 15-bit slopes and its index a 15-bit scale
//!   ([`NarrowTable`]);
//! - the integrator's coefficients are 16-bit operands with run-time shifts
//!   ([`NarrowStep`]), with a fixed-shift fast path when every force's velocity step fits.

use super::{Arith, ArithTable, StepSpec, SPRING_FORCE_BITS};
use crate::q::{self, V3};
use crate::state::{
    for_each_spring, for_each_spring_checked, Ends, Node, SpringEnds, SpringKernel, VEL_LIMIT_MM_S,
};
use crate::table::ForceTable;
use crate::topology::{Edge, Topology};
use crate::units::{from_f64, Strain, DIR_FRAC, FORCE_FRAC, INV_LEN_FRAC, LEN_FRAC, ONE};

mod step;
mod table;

pub use step::NarrowStep;
pub use table::{table_force, table_force_for, NarrowTable};

/// Products with one 16-bit operand: the Cortex-M0's arithmetic.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Narrow;

/// The smallest spring damping, N·s/m, that [`Narrow`] applies without a product: its
/// node velocities are stored as `C_v v` with `C_v = max(C, this)`, in Q20 N from here
/// up (1 N·s/m: a resolution of 0.001 mm/s), with extra fraction bits below.
pub const NARROW_MIN_DAMPING: f64 = 1.0;

/// Upper bound of the [`Narrow`] `l0/l`: springs shorter than `l0/7` keep it at 7.
const R_MAX: i32 = 7 << LEN_FRAC;

/// [`Narrow`]'s coefficients: the spring damping and the integrator's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NarrowCoeffs {
    /// The spring damping.
    pub damping: NarrowDamping,
    /// The integrator.
    pub step: NarrowStep,
}

impl Arith for Narrow {
    type TableAux = NarrowTable;
    type Coeffs = NarrowCoeffs;
    const REST: i32 = 0;
    const MAX_RATIO: f64 = (R_MAX >> LEN_FRAC) as f64;
    /// `1/l0` is a 16-bit operand in Q15: 11 significant bits at 16 mm.
    const MAX_REST_LENGTH_MM: f64 = 16.0;

    fn warm_of_ratio(r: f64) -> i32 {
        from_f64(r - 1.0, LEN_FRAC).min(R_MAX - ONE - 1)
    }

    fn table_aux<const S: usize>(table: &ForceTable<S>) -> NarrowTable {
        NarrowTable::new(table.raw())
    }

    fn coeffs(spec: &StepSpec) -> NarrowCoeffs {
        let g =
            NarrowDamping::velocity_frac(spec.spring_damping, spec.velocity_h() / spec.node_mass);
        NarrowCoeffs {
            damping: NarrowDamping::with_frac(spec.spring_damping, g),
            step: NarrowStep::new(spec),
        }
    }

    #[inline(always)]
    fn store_velocity(c: &NarrowCoeffs, v: i32) -> i32 {
        c.step.store(v)
    }

    #[inline(always)]
    fn velocity(c: &NarrowCoeffs, stored: i32) -> i32 {
        c.step.velocity(stored)
    }

    #[inline(always)]
    fn spring<const S: usize>(
        table: &ArithTable<S, Self>,
        c: &NarrowCoeffs,
        edge: &Edge,
        e: &SpringEnds,
        warm: &mut i32,
    ) -> V3 {
        if c.damping.unit {
            spring::<S, true, true>(table, edge, e.into(), warm, &c.damping)
        } else {
            spring::<S, false, true>(table, edge, e.into(), warm, &c.damping)
        }
    }

    #[inline(always)]
    fn spring_forces<const S: usize, const NODES: usize, const EDGES: usize>(
        table: &ArithTable<S, Self>,
        c: &NarrowCoeffs,
        topo: &Topology<NODES, EDGES>,
        warm: &mut [i32; EDGES],
        nodes: &mut [Node; NODES],
    ) {
        let damping = &c.damping;
        // (A lower corner's check only in the loop of a table that has one.)
        // (The loop of a table with a lower corner out of line.)
        let edges = topo.edges();
        match (damping.unit, table.table.lower_corner()) {
            (true, false) => for_each_spring(
                topo,
                warm,
                nodes,
                &Kernel::<S, true, false> { table, damping },
            ),
            (false, false) => for_each_spring(
                topo,
                warm,
                nodes,
                &Kernel::<S, false, false> { table, damping },
            ),
            (true, true) => {
                let kernel = Kernel::<S, true, true> { table, damping };
                for_each_spring_checked(edges, warm, nodes, &kernel)
            }
            (false, true) => {
                let kernel = Kernel::<S, false, true> { table, damping };
                for_each_spring_checked(edges, warm, nodes, &kernel)
            }
        }
    }

    #[inline(always)]
    fn integrate(c: &NarrowCoeffs, free: &mut [Node]) {
        let s = &c.step;
        match (s.fast_path, s.symplectic) {
            (true, false) => free
                .iter_mut()
                .for_each(|n| step::integrate::<false, false>(s, n)),
            (false, false) => free
                .iter_mut()
                .for_each(|n| step::integrate::<true, false>(s, n)),
            (true, true) => free
                .iter_mut()
                .for_each(|n| step::integrate::<false, true>(s, n)),
            (false, true) => free
                .iter_mut()
                .for_each(|n| step::integrate::<true, true>(s, n)),
        }
    }
}

/// A spring's relative damping `C` (eq. 17) as [`Narrow`] applies it. Its nodes store
/// the velocity as `V = C_v v` in N, Q(20 + g) ([`NarrowDamping::velocity_scale`],
/// [`NarrowDamping::velocity_frac`]). With `unit` (`C ≥` [`NARROW_MIN_DAMPING`], so
/// `C_v = C` and `g = 0`) the damping force is `V_b − V_a`; else
/// `⌊(V_b − V_a) · mul / 2¹⁶⌋ >> sh`, `mul` being `C / C_v` to 15 bits (0 for no
/// damping).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NarrowDamping {
    /// See the type.
    pub unit: bool,
    /// See `unit`.
    pub mul: i32,
    /// See `mul`.
    pub sh: u32,
}

impl NarrowDamping {
    /// From `C` in N·s/m, for stored velocities in Q(20 + `g`) N
    /// ([`NarrowDamping::velocity_frac`]; 0 when `C ≥` [`NARROW_MIN_DAMPING`]).
    pub fn with_frac(n_s_per_m: f64, g: u32) -> Self {
        let unit = n_s_per_m >= NARROW_MIN_DAMPING;
        // The unit path needs neither; no damping is a zero product.
        let (mul, sh) = if unit || n_s_per_m <= 0.0 {
            (0, 0)
        } else {
            // C/C_v < 1 as a 16-bit operand: Q(16 + x) with x ≥ −1; then Q(20 + g + x).
            let (m, x) = q::norm16(n_s_per_m / NARROW_MIN_DAMPING, 15, 30);
            (m, g + x - 1)
        };
        Self { unit, mul, sh }
    }

    /// `C_v = max(C, NARROW_MIN_DAMPING)` in N·s/mm for `C` in N·s/m: the scale of
    /// [`Narrow`]'s stored velocities (`C_v v`, N).
    pub fn velocity_scale(n_s_per_m: f64) -> f64 {
        n_s_per_m.max(NARROW_MIN_DAMPING) / 1000.0
    }

    /// The extra fraction bits `g` of [`Narrow`]'s stored velocities, Q(20 + g) N, for a
    /// substep `h` over the node mass `m` (`h_over_m`, s/kg; 0 if unknown): none when
    /// `C ≥` [`NARROW_MIN_DAMPING`] (the damping is then the plain difference); below,
    /// the most (up to 12) that keep the difference of two at the velocity limit within
    /// 2³⁰, and, where one bit can, any force's velocity step `f C_v h/m` within 2³⁰
    /// (then the integrator needs no hold on the force).
    pub fn velocity_frac(n_s_per_m: f64, h_over_m: f64) -> u32 {
        if n_s_per_m >= NARROW_MIN_DAMPING {
            return 0;
        }
        let cv = Self::velocity_scale(n_s_per_m);
        let v_max = VEL_LIMIT_MM_S * cv * (1u64 << FORCE_FRAC) as f64;
        // The velocity step per Q20 force, dimensionless (with a margin for its
        // rounding to 15 bits).
        let step = cv * 1000.0 * h_over_m * (1.0 + 1.0 / 8192.0);
        let fits = |g: u32| {
            let scale = (1u64 << g) as f64;
            2.0 * v_max * scale <= (1u64 << 30) as f64 && (step * scale <= 0.5 || g == 0)
        };
        let mut g = 0;
        while g < 12 && fits(g + 1) {
            g += 1;
        }
        g
    }
}

/// [`spring`] with its table and damping, for the solver's loop.
struct Kernel<'a, const S: usize, const UNIT: bool, const LOWER: bool> {
    table: &'a ArithTable<S, Narrow>,
    damping: &'a NarrowDamping,
}

impl<const S: usize, const UNIT: bool, const LOWER: bool> SpringKernel
    for Kernel<'_, S, UNIT, LOWER>
{
    #[inline(always)]
    fn force(&self, edge: &Edge, ends: Ends<'_>, warm: &mut i32) -> V3 {
        spring::<S, UNIT, LOWER>(self.table, edge, ends, warm, self.damping)
    }
}

/// One spring in [`Narrow`]'s arithmetic. `rho` is the spring's warm-started `l0/l − 1`
/// (Q24) and `damping` its [`NarrowDamping`]; the node velocities are stored as `C_v v`
/// (N, Q(20 + g)), so that the damping force is their difference, with no product unless
/// `C` is below [`NARROW_MIN_DAMPING`] (`UNIT`: the caller has checked that
/// `damping.unit` holds, and the loop is compiled without the product). The ranges and
/// the limits are those of the wide spring ([`super::Wide`]), except that `l0/l` stays
/// below 7 (a spring crushed below `l0/7` keeps it at 7). `LOWER`: whether the table may
/// have a lower corner ([`table_force_for`]).
///
/// Newton for `r = l0/l = 1/√(1 + s)` runs on `ρ = r − 1`: `e = a r² − 1 = s + a ρ (2 + ρ)`,
/// `ρ' = ρ − r e / 2`, and the strain is `ε = 1 − a r' = −(s + ρ' + s ρ')`. Each
/// product's 16-bit operand (`1/l0`, `d + w`, `r`, `s`, `w`, `C/C_v`) is an order-one
/// quantity rounded or truncated to at most 2⁻¹¹, so each term is within ~1e-4 of itself.
#[inline(always)]
fn spring<const S: usize, const UNIT: bool, const LOWER: bool>(
    table: &ArithTable<S, Narrow>,
    edge: &Edge,
    ends: Ends<'_>,
    rho: &mut i32,
    damping: &NarrowDamping,
) -> V3 {
    let Ends { ua, ub, va, vb } = ends;
    // Q23 geometry: d (Q23) and 1/l0 truncated to Q15 (< 2¹⁵ for l0 ≥ 1 mm).
    const _: () = assert!(INV_LEN_FRAC == 31 && LEN_FRAC == 24 && DIR_FRAC == 23);
    let inv = edge.inv_len >> 16;
    let d: V3 = edge.dir;
    // w = d + (u_b − u_a)/l0, Q24 · Q15 / 2¹⁶ = Q23, held within ±2 per axis; then q = w − d
    // (so that q and w agree where w is held) and the Q13 factor d + w, truncated
    // (|d + w| < 3).
    let w: V3 = core::array::from_fn(|k| {
        let qk = q::mul_s::<16>(ub[k].wrapping_sub(ua[k]), inv);
        q::hold::<24>(d[k].wrapping_add(qk))
    });
    // s = |w|² − 1 = Σ q (d + w): Q23 · Q13 / 2¹⁶ = Q20, each term ≤ 9.
    let s = q::opaque(
        (0..3)
            .map(|k| {
                let p = d[k].wrapping_add(w[k]) >> 10;
                q::mul_s::<16>(w[k].wrapping_sub(d[k]), p)
            })
            .fold(0i32, i32::wrapping_add),
    );
    // Newton on ρ = r − 1 (Q24, r ∈ (0, 7)): t = ρ (2 + ρ) (Q24 · Q12 / 2¹⁶ = Q20, ≤ 48),
    // e = s + a t = s + t + s t (Q20 · Q11 / 2¹¹, s ≤ 11, so |e| < 600), held below 1 so that
    // the factor 1 − e/2 stays in (1/2, 3/2] (e ≥ −1 always: a r² ≥ 0).
    let r0 = q::opaque(*rho);
    // r in Q12, rounded; s in Q11, truncated (one add fewer for the M0's per-spring
    // budget: a bias of −2⁻¹² on average in the `a t` and `s ρ'` terms, measured 4e-4 of
    // the steady force at most, see docs/accuracy.md).
    let r12 = q::narrow::<12>(r0.wrapping_add(ONE));
    let s11 = s >> 9;
    // t = ρ r + ρ/16 (the 1 of 2 + ρ as a shift), a t = t + s t.
    let t = q::mul_s::<16>(r0, r12).wrapping_add(r0 >> 4);
    let e = s
        .wrapping_add(t)
        .wrapping_add(q::mul_s::<11>(t, s11))
        .min((1 << FORCE_FRAC) - 1);
    // ρ' = ρ − r e / 2: Q20 · Q12 / 2⁹ = Q24 (|r e/2| < 4), held below 6 (r < 7).
    let rn = q::opaque(r0.wrapping_sub(q::mul_s::<9>(e, r12)).min(R_MAX - ONE - 1));
    *rho = rn;
    // ε = −(s + ρ' + s ρ') in Q20 (ρ' Q24 · s Q11 / 2¹⁵), then Q24 (|ε| < 7).
    let srho = q::mul_s::<15>(rn, s11);
    let lm1 = s.wrapping_add(rn >> 4).wrapping_add(srho);
    // (The shift behind a barrier: LLVM would make it a product by −16.)
    let strain = Strain::from_bits(q::opaque(lm1 << 4).wrapping_neg());
    let f = table_force_for::<S, LOWER>(table, strain);
    // −f r' (Q20 · Q12 / 2¹² = Q20, |f r'| < 448 N).
    let neg_fr = q::mul_s::<12>(f, q::narrow::<12>(rn.wrapping_add(ONE))).wrapping_neg();

    let (mul, sh) = (damping.mul, damping.sh);
    // w (−f r') + C (v_b − v_a): Q20 · Q14 / 2¹⁴, and C_v (v_b − v_a) from Q(20 + g) to
    // Q20 N (times C/C_v when that is below one), each < 2³⁰.
    core::array::from_fn(|k| {
        let push = q::mul_s::<14>(neg_fr, w[k] >> 9);
        let dv = vb[k].wrapping_sub(va[k]);
        let damp = if UNIT {
            dv
        } else {
            q::mul_s::<16>(dv, mul) >> sh
        };
        q::hold::<SPRING_FORCE_BITS>(push.wrapping_add(damp))
    })
}
