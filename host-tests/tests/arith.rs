//! The Cortex-M0 has no 32 × 32 → 64 multiply: its products are built from 16 × 16
//! pieces (`mccs::q::*_split`). They must give the same bits as the long multiply the
//! other cores use, over the whole input range, so that the host tests (long multiply)
//! also hold for the M0 firmware.

use mccs::q::{
    mul_s, mul_s_by, mul_s_by_split, mul_s_split, mul_t, mul_t_split, mul_wide, mul_wide_split,
    mul_wide_u, mul_wide_u_split, mulhi, mulhi_round, mulhi_round_split, mulhi_split, mulhi_u,
    mulhi_u_split,
};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};

const EDGES: [i32; 12] = [
    i32::MIN,
    i32::MIN + 1,
    -65537,
    -65536,
    -65535,
    -1,
    0,
    1,
    65535,
    65536,
    i32::MAX - 1,
    i32::MAX,
];

#[test]
fn split_products_match_at_the_edges() {
    for a in EDGES {
        for b in EDGES {
            assert_eq!(
                mulhi_split(a, b),
                ((a as i64 * b as i64) >> 32) as i32,
                "{a} {b}"
            );
            assert_eq!(mulhi(a, b), mulhi_split(a, b));
            assert_eq!(mul_wide_split(a, b), a as i64 * b as i64);
            assert_eq!(mul_wide(a, b), a as i64 * b as i64);
            let round = ((a as i64 * b as i64 + (1 << 31)) >> 32) as i32;
            assert_eq!(mulhi_round_split(a, b), round, "{a} {b}");
            assert_eq!(mulhi_round(a, b), round);
            let (ua, ub) = (a as u32, b as u32);
            assert_eq!(
                mulhi_u_split(ua, ub),
                ((ua as u64 * ub as u64) >> 32) as u32
            );
            assert_eq!(mulhi_u(ua, ub), mulhi_u_split(ua, ub));
            assert_eq!(mul_wide_u_split(ua, ub), ua as u64 * ub as u64);
            assert_eq!(mul_wide_u(ua, ub), ua as u64 * ub as u64);
            for t in [0u32, 1, 0x4000, 0x7FFE, 0x7FFF] {
                let want = ((a as i64 * t as i64) >> 16) as i32;
                assert_eq!(mul_t_split(a, t), want, "{a} {t}");
                assert_eq!(mul_t(a, t), want);
            }
        }
    }
}

/// `shr_held`: exact inside the limit, and the limit to within the low bits outside.
#[test]
fn shr_held_is_exact_inside_and_held_outside() {
    use mccs::q::shr_held;
    for p in [
        0i64,
        1,
        -1,
        1 << 40,
        -(1 << 40),
        (1 << 50) - 1,
        -(1 << 50),
        i64::MAX,
        i64::MIN,
    ] {
        for (got, sh, l) in [
            (shr_held::<20, 31>(p), 20, 31),
            (shr_held::<24, 30>(p), 24, 30),
        ] {
            let exact = p >> sh;
            let limit = 1i64 << l;
            if (-limit..limit).contains(&exact) {
                assert_eq!(got as i64, exact, "{p} >> {sh}");
            } else {
                let held = if exact < 0 { -limit } else { limit - 1 };
                assert!(
                    (got as i64 - held).abs() < 1 << (32 - sh),
                    "{p} >> {sh}: {got}"
                );
            }
        }
    }
}

/// The narrow products (`mul_s`: one operand within ±2¹⁵) wherever their documented
/// conditions hold: the result and `⌊a/2¹⁶⌋ · b · 2^(16 − SH)` within `i32`.
fn check_narrow(a: i32, b: i32) {
    let b = b.clamp(-(1 << 15), 1 << 15);
    for sh in 0..=16u32 {
        let exact = (a as i64 * b as i64) >> sh;
        let piece = ((a >> 16) as i64 * b as i64) << (16 - sh);
        if i32::try_from(exact).is_err() || i32::try_from(piece).is_err() {
            continue;
        }
        assert_eq!(mul_s_by_split(a, b, sh) as i64, exact, "{a} {b} {sh}");
        assert_eq!(mul_s_by(a, b, sh) as i64, exact, "{a} {b} {sh}");
        let fixed = match sh {
            9 => (mul_s::<9>(a, b), mul_s_split::<9>(a, b)),
            11 => (mul_s::<11>(a, b), mul_s_split::<11>(a, b)),
            12 => (mul_s::<12>(a, b), mul_s_split::<12>(a, b)),
            14 => (mul_s::<14>(a, b), mul_s_split::<14>(a, b)),
            15 => (mul_s::<15>(a, b), mul_s_split::<15>(a, b)),
            16 => (mul_s::<16>(a, b), mul_s_split::<16>(a, b)),
            _ => continue,
        };
        assert_eq!(fixed.0 as i64, exact, "{a} {b} {sh}");
        assert_eq!(fixed.1 as i64, exact, "{a} {b} {sh}");
    }
}

#[test]
fn narrow_products_match_at_the_edges() {
    for a in EDGES {
        for b in [-(1 << 15), -32767, -1, 0, 1, 255, 32767, 1 << 15] {
            check_narrow(a, b);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(20_000))]

    #[test]
    fn narrow_products_match(a in any::<i32>(), b in -(1i32 << 15)..=(1 << 15), small in -(1i32 << 24)..(1 << 24)) {
        check_narrow(a, b);
        check_narrow(small, b);
    }

    #[test]
    fn split_products_match(a in any::<i32>(), b in any::<i32>(), t in 0u32..0x8000) {
        prop_assert_eq!(mulhi_split(a, b), ((a as i64 * b as i64) >> 32) as i32);
        prop_assert_eq!(mulhi(a, b), mulhi_split(a, b));
        prop_assert_eq!(mul_wide_split(a, b), a as i64 * b as i64);
        prop_assert_eq!(mul_wide(a, b), a as i64 * b as i64);
        let round = ((a as i64 * b as i64 + (1 << 31)) >> 32) as i32;
        prop_assert_eq!(mulhi_round_split(a, b), round);
        prop_assert_eq!(mulhi_round(a, b), round);
        let (ua, ub) = (a as u32, b as u32);
        prop_assert_eq!(mulhi_u_split(ua, ub), ((ua as u64 * ub as u64) >> 32) as u32);
        prop_assert_eq!(mul_wide_u_split(ua, ub), ua as u64 * ub as u64);
        prop_assert_eq!(mul_wide_u(ua, ub), ua as u64 * ub as u64);
        prop_assert_eq!(mul_t_split(a, t), ((a as i64 * t as i64) >> 16) as i32);
        prop_assert_eq!(mul_t(a, t), mul_t_split(a, t));
    }

    /// The table's product by a segment position: the fraction in the low 15 bits of any
    /// position (the segment index above it dropped), on this core's product and on the
    /// M0's.
    #[test]
    fn tau_products_take_the_low_fifteen_bits(a in any::<i32>(), pos in any::<u32>()) {
        let want = ((a as i64 * (pos & 0x7FFF) as i64) >> 16) as i32;
        prop_assert_eq!(mul_t(a, pos), want);
        prop_assert_eq!(mul_t_split(a, pos & 0x7FFF), want);
    }
}

/// The M0's leading zeros from a byte table (`q::leading_zeros_split`, which the graded
/// corner's octave takes there) are `u32::leading_zeros`: every power of two and its
/// neighbours, every top byte over each byte boundary, and 100,000 random values.
#[test]
fn leading_zeros_split_is_leading_zeros() {
    let mut values = vec![0u32, u32::MAX];
    for b in 0..32 {
        let p = 1u32 << b;
        values.extend([p, p.wrapping_sub(1), p.wrapping_add(1), p | (p >> 1)]);
    }
    for shift in [0, 8, 16, 24] {
        values.extend((0..=255u32).map(|i| i << shift));
        values.extend((0..=255u32).map(|i| (i << shift) | ((1 << shift) - 1)));
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
    values.extend((0..100_000).map(|_| rng.random::<u32>() >> rng.random_range(0..32)));
    for d in values {
        assert_eq!(mccs::q::leading_zeros_split(d), d.leading_zeros(), "{d:#x}");
        assert_eq!(mccs::q::leading_zeros(d), d.leading_zeros(), "{d:#x}");
    }
}
