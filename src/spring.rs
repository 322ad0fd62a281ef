//! One spring of the patch: the tabulated law along the edge plus the relative-velocity
//! damping (eq. 17), in two arithmetics chosen per core ([`Arith`]).
//!
//! - [`Wide`]: every product a 32 × 32 → 64 multiply, one instruction on the M3/M4
//!   (`smull`, `smmulr`); lengths to ~1e-7 of `l0`, forces to ~1e-6. The default on
//!   cores that have a long multiply.
//! - [`Narrow`]: every product has one 16-bit operand, two 32-bit multiplies on the
//!   Cortex-M0 (which has no long multiply) instead of four; the strain comes without
//!   cancellation (`|w|² − 1 = q · (d + w)`) and `l0/l` from a Newton step on its
//!   deviation from 1, so that the 16-bit operands are always the `O(1)` factors and the
//!   errors are relative (a few 1e-4 of the force, measured: README). The default on the
//!   M0.
//!
//! Both give the same results on every core ([`crate::q`]); the host tests run both.

use crate::q::{self, V3};
use crate::table::ForceTable;
use crate::topology::{Edge, INV_LEN_FRAC, LEN_FRAC};
use crate::Strain;

/// Fraction bits of velocities (mm/s).
const VEL_FRAC: u32 = 16;
/// Fraction bits of forces (N).
const FORCE_FRAC: u32 = 20;
const ONE: i32 = 1 << LEN_FRAC;
/// Fraction bits of the spring damping (N·s/mm): Q16 mm/s · Q36 = Q52, the format of
/// the spring's `w · (f l0/l)` product (Q29 · Q23), whose high word is Q20 N.
pub(crate) const DAMP_FRAC: u32 = 36;
/// Fraction bits of the edge vector over the rest length, `w`: Q29 (±2 held).
const W_FRAC: u32 = 29;
/// Fraction bits of `f l0/l`: Q23 (±256 N held).
const FR_FRAC: u32 = 23;
// The spring's two products share Q52, whose high word is Q20 N.
const _: () = assert!(VEL_FRAC + DAMP_FRAC == 32 + FORCE_FRAC);
const _: () = assert!(W_FRAC + FR_FRAC == 32 + FORCE_FRAC);
/// Upper bound of the warm-started `l0/l`: springs shorter than `l0/16` keep it at 16.
const R_MAX_WIDE: i32 = (16 << LEN_FRAC) - 1;
/// Largest force of one spring (law and damping together), N in Q20: 64 N = 2²⁶.
pub const SPRING_FORCE_LIMIT: i32 = 1 << SPRING_FORCE_BITS;
const SPRING_FORCE_BITS: u32 = 26;
const _: () = assert!(SPRING_FORCE_LIMIT == 64 << FORCE_FRAC);
/// Largest law force per unit current length, `|f| · l0/l`: 256 N = 2³¹ in Q23.
pub const FORCE_PER_STRETCH_LIMIT_N: i32 = 256;
const _: () = assert!(FORCE_PER_STRETCH_LIMIT_N as i64 == 1 << (31 - FR_FRAC));
/// Largest edge vector over the rest length, per axis: 2 (Q29).
const W_LIMIT: i32 = 2 << W_FRAC;

/// A spring's relative damping `C` (eq. 17) in both kernels' formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Damping {
    /// `C` in N·s/mm, Q36 ([`Wide`]).
    pub wide: i32,
    /// [`Narrow`] stores a node's velocity as `V = C_v v` in N, Q(20 + g)
    /// ([`Damping::velocity_scale`], [`Damping::velocity_frac`]). With `unit`
    /// (`C ≥` [`NARROW_MIN_DAMPING`], so `C_v = C` and `g = 0`) the damping force is
    /// `V_b − V_a`; else `⌊(V_b − V_a) · mul / 2¹⁶⌋ >> sh`, `mul` being `C / C_v` to 15
    /// bits (0 for no damping).
    pub unit: bool,
    /// See `unit`.
    pub mul: i32,
    /// See `mul`.
    pub sh: u32,
}

/// The smallest spring damping, N·s/m, that [`Narrow`] applies without a product: its
/// node velocities are stored as `C_v v` with `C_v = max(C, this)`, in Q20 N from here
/// up (1 N·s/m: a resolution of 0.001 mm/s), with extra fraction bits below.
pub const NARROW_MIN_DAMPING: f64 = 1.0;

/// The fastest velocity the solvers hold, mm/s.
pub(crate) const VEL_LIMIT_MM_S: f64 = 16384.0;

impl Damping {
    /// From `C` in N·s/m (0 … 30; start-up only), for stored velocities with as many
    /// fraction bits as their range allows.
    pub fn new(n_s_per_m: f64) -> Self {
        Self::with_frac(n_s_per_m, Self::velocity_frac(n_s_per_m, 0.0))
    }

    /// From `C` in N·s/m for [`Wide`] only (the narrow fields unset).
    pub fn wide_only(n_s_per_m: f64) -> Self {
        Self {
            wide: q::from_f64(n_s_per_m / 1000.0, DAMP_FRAC),
            unit: false,
            mul: 0,
            sh: 0,
        }
    }

    /// From `C` in N·s/m, for stored velocities in Q(20 + `g`) N
    /// ([`Damping::velocity_frac`]; 0 when `C ≥` [`NARROW_MIN_DAMPING`]).
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
        Self {
            wide: q::from_f64(n_s_per_m / 1000.0, DAMP_FRAC),
            unit,
            mul,
            sh,
        }
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

/// A spring arithmetic: how [`crate::Solver`] turns one edge's end states into the force
/// on its first end.
pub trait Arith: Copy + core::fmt::Debug + Default + 'static {
    /// The per-spring warm-start value at rest.
    const REST: i32;
    /// Whether the solver's integrator takes 16-bit coefficients too.
    const NARROW: bool;
    /// The force on end `a` (Q20 N) from the ends' displacements (Q24 mm) and velocities
    /// (Q16 mm/s); advances the spring's warm-start value `warm`. `UNIT`: the caller has
    /// checked that `damping.unit` holds (see [`narrow`]).
    #[allow(clippy::too_many_arguments)]
    fn force<const S: usize, const UNIT: bool>(
        table: &ForceTable<S>,
        edge: &Edge,
        ua: V3,
        ub: V3,
        va: &V3,
        vb: &V3,
        warm: &mut i32,
        damping: &Damping,
    ) -> V3;
}

/// 32 × 32 → 64 products: [`wide`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Wide;

/// Products with one 16-bit operand: [`narrow`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Narrow;

/// The arithmetic of this build's core: [`Narrow`] on the Cortex-M0, else [`Wide`].
#[cfg(core = "m0")]
pub type DefaultArith = Narrow;
/// The arithmetic of this build's core: [`Narrow`] on the Cortex-M0, else [`Wide`].
#[cfg(not(core = "m0"))]
pub type DefaultArith = Wide;

impl Arith for Wide {
    const REST: i32 = ONE;
    const NARROW: bool = false;
    #[inline(always)]
    fn force<const S: usize, const UNIT: bool>(
        table: &ForceTable<S>,
        edge: &Edge,
        ua: V3,
        ub: V3,
        va: &V3,
        vb: &V3,
        warm: &mut i32,
        damping: &Damping,
    ) -> V3 {
        wide(
            table,
            edge.dir,
            edge.inv_len,
            ua,
            ub,
            va,
            vb,
            warm,
            damping.wide,
        )
    }
}

impl Arith for Narrow {
    const REST: i32 = 0;
    const NARROW: bool = true;
    #[inline(always)]
    fn force<const S: usize, const UNIT: bool>(
        table: &ForceTable<S>,
        edge: &Edge,
        ua: V3,
        ub: V3,
        va: &V3,
        vb: &V3,
        warm: &mut i32,
        damping: &Damping,
    ) -> V3 {
        narrow::<S, UNIT>(table, edge.dir, edge.inv_len, ua, ub, va, vb, warm, damping)
    }
}

/// Upper bound of the [`Narrow`] `l0/l`: springs shorter than `l0/7` keep it at 7.
const R_MAX_NARROW: i32 = 7 << LEN_FRAC;

/// [`wide`] with one 16-bit operand per product (the Cortex-M0's arithmetic). `rho` is
/// the spring's warm-started `l0/l − 1` (Q24) and `damping` its [`Damping`]; the node
/// velocities `va`, `vb` are stored as `C_v v` (N, Q(20 + g); see [`Damping`]), so that
/// the damping force is their difference, with no product unless `C` is below
/// [`NARROW_MIN_DAMPING`] (`UNIT`: the caller has checked that `damping.unit` holds, and
/// the loop is compiled without the product). The other arguments, the ranges
/// and the limits are those of [`wide`], except that `l0/l` stays below 7 (a spring
/// crushed below `l0/7` keeps it at 7).
///
/// With `d` the unit rest vector and `q = (u_b − u_a)/l0`, the edge over its rest length
/// is `w = d + q` and `s = |w|² − 1 = q · (d + w)`: small when the spring is, with the
/// 16-bit factor `d + w` of order 1. Newton for `r = l0/l = 1/√(1 + s)` runs on `ρ = r − 1`:
/// `e = a r² − 1 = s + a ρ (2 + ρ)`, `ρ' = ρ − r e / 2`, and the strain is
/// `ε = 1 − a r' = −(s + ρ' + s ρ')`. Each product's 16-bit operand (`1/l0`, `d + w`,
/// `r`, `s`, `w`, `C/C_v`) is an order-one quantity rounded or truncated to at most 2⁻¹¹,
/// so each term is within ~1e-4 of itself (the whole spring against the f64 twin: README).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn narrow<const S: usize, const UNIT: bool>(
    table: &ForceTable<S>,
    dir: V3,
    inv_len: i32,
    ua: V3,
    ub: V3,
    va: &V3,
    vb: &V3,
    rho: &mut i32,
    damping: &Damping,
) -> V3 {
    // Q23 geometry: d (Q29 → Q23) and 1/l0 truncated to Q15 (< 2¹⁵ for l0 ≥ 1 mm).
    const _: () = assert!(INV_LEN_FRAC == 31 && LEN_FRAC == 24);
    let inv = inv_len >> 16;
    let d: V3 = dir.map(|x| x >> 6);
    // w = d + (u_b − u_a)/l0, Q24 · Q15 / 2¹⁶ = Q23, held within ±2 per axis; then q = w − d
    // (so that q and w agree where w is held) and the Q13 factor d + w, truncated
    // (|d + w| < 3).
    let w: V3 = core::array::from_fn(|k| {
        let qk = q::mul_s::<16>(ub[k].wrapping_sub(ua[k]), inv);
        d[k].wrapping_add(qk).clamp(-(2 << 23), (2 << 23) - 1)
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
    // the steady force at most, see README).
    let r12 = q::narrow::<12>(r0.wrapping_add(ONE));
    let s11 = s >> 9;
    // t = ρ r + ρ/16 (the 1 of 2 + ρ as a shift), a t = t + s t.
    let t = q::mul_s::<16>(r0, r12).wrapping_add(r0 >> 4);
    let e = s
        .wrapping_add(t)
        .wrapping_add(q::mul_s::<11>(t, s11))
        .min((1 << FORCE_FRAC) - 1);
    // ρ' = ρ − r e / 2: Q20 · Q12 / 2⁹ = Q24 (|r e/2| < 4), held below 6 (r < 7).
    let rn = q::opaque(
        r0.wrapping_sub(q::mul_s::<9>(e, r12))
            .min(R_MAX_NARROW - ONE - 1),
    );
    *rho = rn;
    // ε = −(s + ρ' + s ρ') in Q20 (ρ' Q24 · s Q11 / 2¹⁵), then Q24 (|ε| < 7).
    let srho = q::mul_s::<15>(rn, s11);
    let lm1 = s.wrapping_add(rn >> 4).wrapping_add(srho);
    // (The shift behind a barrier: LLVM would make it a product by −16.)
    let strain = Strain::from_bits(q::opaque(lm1 << 4).wrapping_neg());
    let f = table.force_narrow(strain);
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
        push.wrapping_add(damp)
            .clamp(-SPRING_FORCE_LIMIT, SPRING_FORCE_LIMIT - 1)
    })
}

/// The force on end `a` of one spring (Q20 N): the law along the edge plus the relative
/// damping (eq. 17), from the ends' displacements (Q24 mm) and velocities (Q16 mm/s).
/// `dir` is the unit rest vector (Q29), `inv_len` is `1/l0` (Q31), `r` the spring's
/// warm-started `l0/l` (Q24), advanced by one guarded Newton step, and `damping` the
/// spring damping (Q36 N·s/mm).
///
/// Ranges that let most steps skip saturation: displacements within ±64 mm and velocities
/// within ±16384 mm/s (the integrator clamps them), rest lengths ≥ 1 mm and at most
/// [`crate::solver::MAX_SPRINGS_PER_NODE`] springs per node (the topology checks), spring damping ≤ 30
/// N·s/m (the configuration checks). Limits that follow, documented behaviour:
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
#[allow(clippy::too_many_arguments)]
pub fn wide<const S: usize>(
    table: &ForceTable<S>,
    dir: V3,
    inv_len: i32,
    ua: V3,
    ub: V3,
    va: &V3,
    vb: &V3,
    r: &mut i32,
    damping: i32,
) -> V3 {
    // w = (x_b − x_a) / l0 = dir + (u_b − u_a) / l0, Q29: the high word of Q24 · Q31 is
    // Q23, times 64; |u_b − u_a| < 2³¹ (the displacement clamp).
    const Q_FRAC: u32 = LEN_FRAC + INV_LEN_FRAC - 32;
    let w: V3 = core::array::from_fn(|k| {
        let q = q::mulhi(ub[k].wrapping_sub(ua[k]), inv_len);
        dir[k]
            .wrapping_add(q.wrapping_mul(1 << (W_FRAC - Q_FRAC)))
            .clamp(-W_LIMIT, W_LIMIT - 1)
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
    let rn = q::opaque(((q::mul_wide(r0, factor) >> LEN_FRAC) as i32).clamp(0, R_MAX_WIDE));
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
