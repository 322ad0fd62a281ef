//! The Cortex-M0 has no 32 × 32 → 64 multiply: its products are built from 16 × 16
//! pieces (`mccs::q::*_split`). They must give the same bits as the long multiply the
//! other cores use, over the whole input range, so that the host tests (long multiply)
//! also hold for the M0 firmware.

use mccs::q::{
    mul_t, mul_t_split, mul_wide, mul_wide_split, mulhi, mulhi_round, mulhi_round_split,
    mulhi_split, mulhi_u, mulhi_u_split,
};
use proptest::prelude::*;

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

proptest! {
    #![proptest_config(ProptestConfig::with_cases(20_000))]

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
        prop_assert_eq!(mul_t_split(a, t), ((a as i64 * t as i64) >> 16) as i32);
        prop_assert_eq!(mul_t(a, t), mul_t_split(a, t));
    }
}
