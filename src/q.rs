//! Fixed-point helpers for the per-tick path: long products of raw `i32` values in mixed
//! Q formats, with exact floor (or round-to-nearest) semantics, and 3-vectors of them.
//!
//! Cores with a 32 × 32 → 64 multiply (M3, M4F) compute each product with one
//! instruction; the Cortex-M0 has none and builds it from 16 × 16 pieces (the `*_split`
//! functions, always compiled, so that the host tests hold them to the long multiply:
//! `host-tests/tests/arith.rs`). Both give the same bits, so a table or a solver gives
//! the same results on every core.

/// A 3-vector of raw fixed-point values (x, y, z).
pub type V3 = [i32; 3];

/// Whether this target has a 32 × 32 → 64 multiply (`smull`): every Arm target but
/// ARMv6-M (see the module docs), and every host.
pub const HAS_LONG_MULTIPLY: bool =
    cfg!(not(all(target_arch = "arm", not(target_has_atomic = "32"))));

/// Whether this target has a count-leading-zeros instruction (`clz`): the same targets
/// as [`HAS_LONG_MULTIPLY`] (ARMv6-M has neither).
pub const HAS_CLZ: bool = HAS_LONG_MULTIPLY;

/// `d.leading_zeros()`: one `clz` where the core has one ([`HAS_CLZ`]); else
/// [`leading_zeros_split`], a byte table, instead of the library's binary search (about
/// 30 instructions and a call on the M0). The same value for every `d`.
#[inline(always)]
pub fn leading_zeros(d: u32) -> u32 {
    if HAS_CLZ {
        d.leading_zeros()
    } else {
        leading_zeros_split(d)
    }
}

/// The leading zeros of each byte value (8 − its bit length; 8 for 0).
static BYTE_LEADING_ZEROS: [u8; 256] = {
    let mut t = [0u8; 256];
    let mut i = 0;
    while i < 256 {
        t[i] = (i as u8).leading_zeros() as u8;
        i += 1;
    }
    t
};

/// [`leading_zeros`] from a table of the leading zeros of each byte: one load for
/// `d ≥ 2²⁴` (every coordinate of a valid table's graded corner: a compare, a branch, a
/// shift and the load), a compare more for each lower byte. Always compiled: the host
/// tests hold it to `u32::leading_zeros` (`host-tests/tests/arith.rs`).
#[inline(always)]
pub fn leading_zeros_split(d: u32) -> u32 {
    let (shift, above) = if d >= 1 << 24 {
        (24, 0)
    } else if d >= 1 << 16 {
        (16, 8)
    } else if d >= 1 << 8 {
        (8, 16)
    } else {
        (0, 24)
    };
    above + BYTE_LEADING_ZEROS[(d >> shift) as usize & 0xFF] as u32
}

/// The long-multiply form of a product, or its 16-bit-piece form without a long multiply
/// ([`HAS_LONG_MULTIPLY`]; a constant, so only one form is compiled into the caller).
macro_rules! long_or_split {
    ($split:expr, $long:expr) => {{
        if HAS_LONG_MULTIPLY {
            $long
        } else {
            $split
        }
    }};
}

/// Clamps an `i64` into `i32`.
#[inline(always)]
pub fn sat(x: i64) -> i32 {
    x.clamp(i32::MIN as i64, i32::MAX as i64) as i32
}

/// `⌊p / 2^SH⌋` held within `±2^L` (`L` ≤ 31) through the high word alone: the high word
/// is clamped before the two words are joined, so a held value is the limit to within
/// its low `32 − SH` bits (which are the product's own). One `ssat` instead of a 64-bit
/// comparison; exact for every value inside the limit.
#[inline(always)]
pub fn shr_held<const SH: u32, const L: u32>(p: i64) -> i32 {
    const { assert!(SH >= 1 && SH <= 32 && L <= 31 && L + SH >= 32 && L + SH - 32 <= 30) };
    let bound = 1i32 << (L + SH - 32);
    let hi = ((p >> 32) as i32).clamp(-bound, bound - 1);
    (hi << (32 - SH)) | ((p as u32) >> SH) as i32
}

/// Component-wise saturating `a + b`.
#[inline(always)]
pub fn add(a: V3, b: V3) -> V3 {
    [
        a[0].saturating_add(b[0]),
        a[1].saturating_add(b[1]),
        a[2].saturating_add(b[2]),
    ]
}

/// `⌊a · b / 2³²⌋`: the high word of the signed 64-bit product.
///
/// One `smull` on cores with a long multiply; on the Cortex-M0 (32 × 32 → 32 only)
/// [`mulhi_split`], which gives the same bits.
#[inline(always)]
pub fn mulhi(a: i32, b: i32) -> i32 {
    long_or_split!(mulhi_split(a, b), ((a as i64 * b as i64) >> 32) as i32)
}

/// [`mulhi`] from four 16 × 16 products, exact: with `a = a₁2¹⁶ + a₀`, `b = b₁2¹⁶ + b₀`
/// (`a₀, b₀ ∈ [0, 2¹⁶)`), `m = a₁b₀ + ⌊a₀b₀/2¹⁶⌋` and `n = a₀b₁ + (m mod 2¹⁶)` both
/// fit `i32`, and `⌊ab/2³²⌋ = a₁b₁ + ⌊m/2¹⁶⌋ + ⌊n/2¹⁶⌋`.
#[inline(always)]
pub fn mulhi_split(a: i32, b: i32) -> i32 {
    // See `mulhi_u_split` on `opaque`.
    let (a1, a0) = (a >> 16, opaque(a & 0xFFFF) as u32);
    let (b1, b0) = (b >> 16, (b & 0xFFFF) as u32);
    let m = a1
        .wrapping_mul(b0 as i32)
        .wrapping_add((a0.wrapping_mul(b0) >> 16) as i32);
    let n = (a0 as i32).wrapping_mul(b1).wrapping_add(m & 0xFFFF);
    a1.wrapping_mul(b1)
        .wrapping_add(m >> 16)
        .wrapping_add(n >> 16)
}

/// `c + ⌊a · b / 2³²⌋` (wrapping): one `smmla` on the M4F (its DSP extension), a
/// `smull` and an add on the M3; the caller's ranges keep the sum within `i32`.
#[inline(always)]
pub fn mulhi_acc(a: i32, b: i32, c: i32) -> i32 {
    c.wrapping_add(mulhi(a, b))
}

/// `⌊(a · b + 2³¹) / 2³²⌋`: the high word of the product, rounded to nearest (`smmulr`
/// on cores with a long multiply). The M0 adds the low word's top bit to
/// [`mulhi_split`]: the same bits.
#[inline(always)]
pub fn mulhi_round(a: i32, b: i32) -> i32 {
    long_or_split!(
        mulhi_round_split(a, b),
        ((a as i64 * b as i64 + (1 << 31)) >> 32) as i32
    )
}

/// [`mulhi_round`] from [`mulhi_split`] and the low word, exact.
#[inline(always)]
pub fn mulhi_round_split(a: i32, b: i32) -> i32 {
    mulhi_split(a, b).wrapping_add((a.wrapping_mul(b) as u32 >> 31) as i32)
}

/// The full signed product `a · b`: one `smull` with a long multiply; on the M0 the high
/// word from [`mulhi_split`] and the low word from one 32-bit multiply (the same bits,
/// without the `__aeabi_lmul` call).
#[inline(always)]
pub fn mul_wide(a: i32, b: i32) -> i64 {
    long_or_split!(mul_wide_split(a, b), a as i64 * b as i64)
}

/// [`mul_wide`] from [`mulhi_split`] and the low word, exact.
#[inline(always)]
pub fn mul_wide_split(a: i32, b: i32) -> i64 {
    ((mulhi_split(a, b) as i64) << 32) | a.wrapping_mul(b) as u32 as i64
}

/// `⌊a · b / 2³²⌋` unsigned: one `umull` with a long multiply, else [`mulhi_u_split`].
#[inline(always)]
pub fn mulhi_u(a: u32, b: u32) -> u32 {
    long_or_split!(mulhi_u_split(a, b), ((a as u64 * b as u64) >> 32) as u32)
}

/// [`mulhi_u`] from four 16 × 16 products, exact (the unsigned [`mulhi_split`]).
#[inline(always)]
pub fn mulhi_u_split(a: u32, b: u32) -> u32 {
    // LLVM recognises this pattern and would fold it back into a 64-bit product, which
    // on the M0 is a library call (`__aeabi_lmul`): an empty `asm!` hides one half.
    let (a1, a0) = (a >> 16, opaque((a & 0xFFFF) as i32) as u32);
    let (b1, b0) = (b >> 16, b & 0xFFFF);
    let m = a1.wrapping_mul(b0).wrapping_add(a0.wrapping_mul(b0) >> 16);
    let n = a0.wrapping_mul(b1).wrapping_add(m & 0xFFFF);
    a1.wrapping_mul(b1)
        .wrapping_add(m >> 16)
        .wrapping_add(n >> 16)
}

/// The full unsigned product `a · b`: one `umull` with a long multiply; on the M0 the
/// high word from [`mulhi_u_split`] and the low word from one 32-bit multiply (the same
/// bits, without the `__aeabi_lmul` call).
#[inline(always)]
pub fn mul_wide_u(a: u32, b: u32) -> u64 {
    long_or_split!(mul_wide_u_split(a, b), a as u64 * b as u64)
}

/// [`mul_wide_u`] from [`mulhi_u_split`] and the low word, exact.
#[inline(always)]
pub fn mul_wide_u_split(a: u32, b: u32) -> u64 {
    ((mulhi_u_split(a, b) as u64) << 32) | a.wrapping_mul(b) as u64
}

/// `⌊a · t / 2¹⁶⌋` for `t ∈ [0, 2¹⁵)`: a product by a Q15 fraction that comes out halved
/// (callers scale their coefficients for it). One `smull` against `t · 2¹⁶` with a long
/// multiply, else [`mul_t_split`]; the same bits. Larger `t` are masked to 15 bits.
#[inline(always)]
pub fn mul_t(a: i32, t: u32) -> i32 {
    long_or_split!(
        mul_t_split(a, t),
        ((a as i64 * (((t & 0x7FFF) << 16) as i32) as i64) >> 32) as i32
    )
}

/// [`mul_t`] from two 16 × 16 products, exact: `⌊at/2¹⁶⌋ = a₁t + ⌊a₀t/2¹⁶⌋`.
#[inline(always)]
pub fn mul_t_split(a: i32, t: u32) -> i32 {
    let t = t & 0x7FFF;
    let (a1, a0) = (a >> 16, (a & 0xFFFF) as u32);
    a1.wrapping_mul(t as i32)
        .wrapping_add((a0.wrapping_mul(t) >> 16) as i32)
}

/// `⌊d · w / 2¹⁶⌋` (within one unit) for a Q16 weight `0 ≤ w ≤ 2¹⁶` and any `d`: one
/// [`mul_s`] with a 16-bit operand, `w` itself up to 2¹⁵, else `d − d (2¹⁶ − w)/2¹⁶`. No
/// 64-bit product (a library call on the M0): the proxy's blends, slip and reaction.
#[inline(always)]
pub fn mul_weight(d: i32, w: i32) -> i32 {
    if w <= 1 << 15 {
        mul_s::<16>(d, w)
    } else {
        d.saturating_sub(mul_s::<16>(d, (1 << 16) - w))
    }
}

/// `⌊a · b / 2^SH⌋` for a 16-bit `b` (`|b| ≤ 2¹⁵`, `SH` ≤ 16): a product with one
/// narrow operand. One long multiply and a shift on the M3/M4; on the Cortex-M0
/// [`mul_s_split`], two 32-bit multiplies with the same bits. The caller's ranges must
/// keep the result (and, for `SH` < 16, `⌊a/2¹⁶⌋ · b · 2^(16 − SH)`) within `i32`.
#[inline(always)]
pub fn mul_s<const SH: u32>(a: i32, b: i32) -> i32 {
    const { assert!(SH <= 16) };
    mul_s_by(a, b, SH)
}

/// [`mul_s`] from two 32-bit products, exact: with `a = a₁2¹⁶ + a₀` (`a₀ ∈ [0, 2¹⁶)`),
/// `⌊ab/2^SH⌋ = a₁b·2^(16 − SH) + ⌊a₀b/2^SH⌋` (`|a₀b| < 2³¹`).
#[inline(always)]
pub fn mul_s_split<const SH: u32>(a: i32, b: i32) -> i32 {
    const { assert!(SH <= 16) };
    mul_s_by_split(a, b, SH)
}

/// [`mul_s`] with the shift known only at run time (`sh` ≤ 16): two variable shifts
/// on the M0 instead of immediates (with a constant `sh`, as from [`mul_s`], the same
/// code as immediates). The same conditions on the ranges.
#[inline(always)]
pub fn mul_s_by(a: i32, b: i32, sh: u32) -> i32 {
    long_or_split!(
        mul_s_by_split(a, b, sh),
        ((a as i64 * b as i64) >> sh) as i32
    )
}

/// [`mul_s_by`] from two 32-bit products, exact (see [`mul_s_split`]).
#[inline(always)]
pub fn mul_s_by_split(a: i32, b: i32, sh: u32) -> i32 {
    let (a1, a0) = (a >> 16, opaque(a & 0xFFFF));
    (a1.wrapping_mul(b) << (16 - sh)).wrapping_add(a0.wrapping_mul(b) >> sh)
}

/// `(n, sh)` with `n = round(x · 2^(base + sh))` ≤ 2¹⁵ for the largest `sh` ≤ `max_sh`:
/// a positive coefficient as the 16-bit operand of [`mul_s`], to 2⁻¹⁵ relative
/// (start-up only; `x · 2^base` must be ≤ 2¹⁵ − ½).
#[inline(never)]
pub fn norm16(x: f64, base: u32, max_sh: u32) -> (i32, u32) {
    let at = |sh: u32| libm::round(x * libm::ldexp(1.0, (base + sh) as i32));
    let mut sh = 0;
    while sh < max_sh && at(sh + 1) <= 32768.0 {
        sh += 1;
    }
    (at(sh).clamp(0.0, 32768.0) as i32, sh)
}

/// `x` rounded to nearest and shifted right by `SH` (`SH` ≥ 1): the narrow operand of a
/// [`mul_s`] from a wide value.
#[inline(always)]
pub fn narrow<const SH: u32>(x: i32) -> i32 {
    x.wrapping_add(1 << (SH - 1)) >> SH
}

/// Intervals of the first guess's table over `M ∈ [¼, 1)`, each `2⁻⁸` wide.
const RSQRT_CELLS: usize = 192;

/// `1/√M − 1` at the middle of each of [`RSQRT_CELLS`] intervals of `M ∈ [¼, 1)`, Q16
/// (`1/√M ∈ (1, 2)` there; to nearest, within `2⁻¹⁷`): [`rsqrt`]'s first guess, within
/// 4e-3 relative (half an interval's width, `2⁻⁹`, over `2M` at `M = ¼`). Built at
/// compile time by Newton's method in `f64` (60 steps from 1: far past convergence).
const RSQRT_GUESS: [u16; RSQRT_CELLS] = {
    let mut t = [0u16; RSQRT_CELLS];
    let mut i = 0;
    while i < RSQRT_CELLS {
        let m = 0.25 + (i as f64 + 0.5) / 256.0;
        let mut y = 1.0f64;
        let mut k = 0;
        while k < 60 {
            y = y * (3.0 - m * y * y) / 2.0;
            k += 1;
        }
        t[i] = ((y - 1.0) * 65536.0 + 0.5) as u16;
        i += 1;
    }
    t
};

/// `1/√x` for `x > 0` as `(y, e)`: `1/√x = y · 2^(e/2 − 62)`, `y` in Q30 within (1, 2],
/// within 2e-8 relative (`proxy`'s `rsqrt_matches_f64` prints the measured figure).
/// A first guess from a 384-byte table ([`RSQRT_GUESS`], within 4e-3), then two Newton
/// steps (each squares the relative error and takes 1.5 of it: 2.4e-5, then 1e-9 plus
/// the steps' rounding). Each product is a high word of 32 × 32 bits ([`mulhi_u`]: one
/// `umull`, or four 16-bit products on the M0): six in all.
pub(crate) fn rsqrt(x: i64) -> (u32, u32) {
    let (m30, e) = normalise(x.max(1) as u64);
    // The guess's interval: M's bits below ¼ in steps of 2⁻⁸ (0 … 191).
    let cell = ((m30 >> 22) as usize).saturating_sub(64);
    let guess = RSQRT_GUESS.get(cell).copied().unwrap_or(0);
    // y ← y (3 − M y²)/2: y² in Q28 (≤ 4.1), M y² in Q26 then Q30 (≤ 1.01), y (3 − M y²)
    // in Q28, halved into Q30.
    let mut y = (1u32 << 30) + ((guess as u32) << 14);
    for _ in 0..2 {
        let y2 = mulhi_u(y, y);
        let my2 = mulhi_u(m30, y2) << 4;
        y = mulhi_u(y, (3u32 << 30) - my2) << 1;
    }
    (y, e)
}

/// `x > 0` normalised by an even shift `e`: `m = x 2^e ∈ [2^62, 2^64)`, so that
/// `M = m / 2^64 ∈ [¼, 1)`, returned in Q30 (`m30 ∈ [2^28, 2^30)`) with `e`. By 32-bit
/// halves: the Cortex-M0 has no `clz` ([`leading_zeros`]: a byte table there) and no
/// 64-bit shift (a library call), so that a 64-bit `leading_zeros` took two library
/// calls and the shift a third. The same bits as `((x << e) >> 34, leading_zeros(x) &
/// !1)` (tested).
#[inline(always)]
pub(crate) fn normalise(x: u64) -> (u32, u32) {
    let (hi, lo) = ((x >> 32) as u32, x as u32);
    if hi != 0 {
        let e = leading_zeros(hi) & !1;
        // The top word of x 2^e: hi's bits, then lo's top e (none when e = 0).
        let top = if e == 0 { hi } else { hi << e | lo >> (32 - e) };
        (top >> 2, e)
    } else {
        let e = 32 + (leading_zeros(lo) & !1);
        ((lo << (e - 32)) >> 2, e)
    }
}

/// `x`, through an empty `asm!` block: no instruction, but the optimiser cannot see what
/// it is, so it cannot rewrite the arithmetic around it (fold a split product back into
/// a library call, or widen a value it cannot prove fits 32 bits).
#[inline(always)]
#[allow(unsafe_code)]
pub fn opaque(mut x: i32) -> i32 {
    // SAFETY: the template is an assembler comment, so no instruction is emitted: the
    // block reads and writes only the register holding `x` (declared `inout`), touches
    // no memory (`nomem`) and no stack (`nostack`), and its output is its input
    // (`pure`). Nothing the compiler relies on can change.
    #[cfg(target_arch = "arm")]
    unsafe {
        core::arch::asm!("/* {0} */", inout(reg) x, options(pure, nomem, nostack))
    };
    #[cfg(not(target_arch = "arm"))]
    {
        x = core::hint::black_box(x);
    }
    x
}

/// `x` held within `[−2^B, 2^B − 1]` (`1 ≤ B ≤ 30`): `x.clamp(−2^B, 2^B − 1)`. On the
/// Cortex-M0 in assembly: a value within costs a sign extension from bit `B` (two
/// shifts), a compare and a branch, with no bound loaded from a literal (seven
/// instructions with one from the compiler); a value outside takes `sign ^ (2^B − 1)`.
/// The bench firmware checks it against `clamp` on the M0 before it measures
/// (`firmware/src/bin/bench/hold_check.rs`).
#[inline(always)]
#[allow(unsafe_code)]
pub fn hold<const B: u32>(x: i32) -> i32 {
    const { assert!(B >= 1 && B <= 30) };
    #[cfg(all(target_arch = "arm", not(target_has_atomic = "32")))]
    {
        let mut x = x;
        // SAFETY: registers only (`x` and a scratch one, both declared; the flags are
        // not declared preserved), no memory, no stack; the branch stays within the
        // block.
        unsafe {
            core::arch::asm!(
                "lsls {t}, {x}, #{up}",
                "asrs {t}, {t}, #{up}",
                "cmp {t}, {x}",
                "beq 2f",
                "asrs {x}, {x}, #31",
                "movs {t}, #1",
                "lsls {t}, {t}, #{b}",
                "subs {t}, {t}, #1",
                "eors {x}, {t}",
                "2:",
                x = inout(reg) x,
                t = out(reg) _,
                up = const 31 - B,
                b = const B,
                options(pure, nomem, nostack),
            );
        }
        x
    }
    #[cfg(not(all(target_arch = "arm", not(target_has_atomic = "32"))))]
    {
        x.clamp(-(1 << B), (1 << B) - 1)
    }
}

/// Patch-frame point `p` (Q24 mm) with its `xy` held to `rect` (`[x_lo, x_hi, y_lo,
/// y_hi]`, Q24 mm): the goal
/// of the proxy's update past the surface's edge is the point above the nearest point
/// of it.
pub(crate) fn held_to(rect: [i32; 4], p: V3) -> V3 {
    [
        p[0].max(rect[0]).min(rect[1]),
        p[1].max(rect[2]).min(rect[3]),
        p[2],
    ]
}

#[cfg(test)]
mod tests {
    /// `mul_weight` against the exact product, over weights 0 … 2¹⁶ and values up to ±2³¹.
    #[test]
    fn mul_weight_matches_the_exact_product() {
        let ds = [
            i32::MIN,
            i32::MIN + 1,
            -1 << 30,
            -123_456_789,
            -65_537,
            -1,
            0,
            1,
            65_535,
            987_654_321,
            i32::MAX,
        ];
        for w in (0..=65_536)
            .step_by(7)
            .chain([32_767, 32_768, 32_769, 65_535, 65_536])
        {
            for d in ds {
                let exact = (d as i64 * w as i64) >> 16;
                let got = super::mul_weight(d, w) as i64;
                assert!((got - exact).abs() <= 1, "{d} × {w}: {got} vs {exact}");
                // The M0's split product is exact for the operand `mul_weight` gives it.
                let b = if w <= 1 << 15 { w } else { 65_536 - w };
                let split = super::mul_s_split::<16>(d, b) as i64;
                assert_eq!(split, (d as i64 * b as i64) >> 16, "{d} × {b}");
            }
        }
    }
}
