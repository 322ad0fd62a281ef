//! The force table off the happy path: any raw table (what `include!` and `from_raw`
//! accept) evaluates without a panic in both arithmetics, and the builder either refuses
//! a domain with a typed error or emits a table that passes `validate`.

use mccs::arith::narrow::table_force;
use mccs::arith::ArithTable;
use mccs::{ForceTable, Narrow, Params, RawTable, Strain, TableError};
use proptest::prelude::*;

fn any_raw() -> impl Strategy<Value = RawTable<16>> {
    (
        (
            any::<i32>(),
            any::<i32>(),
            any::<u32>(),
            any::<u32>(),
            any::<i32>(),
        ),
        (
            any::<i32>(),
            any::<i32>(),
            any::<i32>(),
            any::<i32>(),
            any::<u32>(),
        ),
        (any::<i32>(), any::<i32>()),
        prop::array::uniform16(prop::array::uniform4(any::<i32>())),
        // The graded corner: half of the tables have one, with any contents.
        (
            any::<bool>(),
            any::<i32>(),
            any::<i32>(),
            any::<u32>(),
            any::<u32>(),
            any::<i32>(),
            any::<i32>(),
            any::<i32>(),
            // (And the line above's force slope.)
            any::<i32>(),
        ),
    )
        .prop_map(|(a, b, c, segments, g)| RawTable {
            strain_lo: a.0,
            strain_hi: a.1,
            index_pre: a.2,
            index_scale: a.3,
            anchor_lo: a.4,
            force_lo: b.0,
            // Half of them within ±2¹⁹, where the line below's slope is Q28.
            stiffness_lo: if c.0 & 1 == 0 { b.1 >> 12 } else { b.1 },
            slope_lo: g.7,
            force_hi: b.2,
            // And half of them within ±2¹⁹, where the line above's slope is Q28.
            stiffness_hi: if c.1 & 1 == 0 { b.3 >> 12 } else { b.3 },
            slope_hi: g.8,
            shift: b.4,
            stiff_scale: c.0,
            stiff_post: c.1,
            corner_hi: if g.0 { g.1 } else { a.1 },
            corner_anchor: g.2,
            corner_pre: g.3,
            corner_base: g.4,
            corner_scale: g.5,
            corner_post: g.6,
            err_force_ppb: c.0 as u32,
            err_stiffness_ppb: c.1 as u32,
            segments,
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Arbitrary contents (the fuzz target's regression too): every evaluation, and the
    /// narrow arithmetic's derived data, run without a panic.
    #[test]
    fn any_raw_table_evaluates_without_panic(raw in any_raw(), strains in prop::array::uniform8(any::<i32>())) {
        let t = ForceTable::from_raw(raw);
        let narrow = ArithTable::<16, Narrow>::new(t);
        let ends = [i32::MIN, i32::MAX, raw.strain_lo, raw.strain_hi, raw.corner_hi, raw.corner_anchor];
        for e in strains.into_iter().chain(ends) {
            let e = Strain::from_bits(e);
            let _ = t.force(e);
            let _ = t.force_and_stiffness(e);
            let _ = t.force_within::<26>(e);
            let _ = table_force(&narrow, e);
        }
        let _ = t.max_stiffness();
        let _ = t.validate();
    }
}

/// A raw table of no segments (`ForceTable<0>`: `mccs table` never emits one, and
/// `validate` refuses it) still evaluates without a panic: its lines, zeros between.
/// Before, a strain between its ends indexed an empty array.
#[test]
fn a_table_of_no_segments_evaluates_without_panic() {
    let raw = RawTable::<0> {
        strain_lo: -(1 << 22),
        strain_hi: 1 << 23,
        index_pre: 1 << 8,
        index_scale: 1 << 20,
        anchor_lo: 0,
        force_lo: 0,
        stiffness_lo: 1 << 16,
        slope_lo: 1 << 28,
        force_hi: 1 << 20,
        stiffness_hi: 1 << 17,
        slope_hi: 1 << 29,
        shift: 0,
        stiff_scale: 1 << 20,
        stiff_post: 1,
        corner_hi: 1 << 23,
        corner_anchor: 0,
        corner_pre: 0,
        corner_base: 0,
        corner_scale: 0,
        corner_post: 1,
        err_force_ppb: 0,
        err_stiffness_ppb: 0,
        segments: [],
    };
    let t = ForceTable::from_raw(raw);
    assert!(t.validate().is_err());
    let narrow = ArithTable::<0, Narrow>::new(t);
    for bits in [i32::MIN, -(1 << 22), 0, 1 << 20, 1 << 23, i32::MAX] {
        let e = Strain::from_bits(bits);
        let (f, _) = t.force_and_stiffness(e);
        assert_eq!(f, t.force(e));
        let _ = t.force_within::<26>(e);
        let _ = table_force(&narrow, e);
    }
    assert_eq!(t.force(Strain::from_bits(0)).to_bits(), 0);
    let _ = t.max_stiffness();
    assert_eq!(t.segments_used(), 0);
}

/// The repro: a domain ending a hair above the kink left 17 knots within one
/// strain LSB (and an index scale of 32 bits, on which the narrow arithmetic's
/// derivation overflowed). Such a domain is now refused as too narrow.
#[test]
fn a_domain_narrower_than_its_segments_is_refused() {
    let p = Params::TABLE2;
    assert_eq!(
        ForceTable::<16>::with_domain(&p, -0.5, 0.2352539063).err(),
        Some(TableError::TooNarrow)
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    /// The builder's arguments around the kink, the solid point and the format's edges:
    /// a typed error, or a table that passes `validate` and whose narrow derivation and
    /// evaluation run.
    #[test]
    fn the_builder_refuses_or_builds_a_valid_table(
        from in prop_oneof![-130.0f64..130.0, 0.2352f64..0.2353, Just(-0.5)],
        width in prop_oneof![1e-9f64..1e-6, 1e-6f64..1.0, 1.0f64..300.0],
    ) {
        let p = Params::TABLE2;
        let to = from + width;
        match ForceTable::<16>::with_domain(&p, from, to) {
            Ok(t) => {
                prop_assert_eq!(t.validate(), Ok(()));
                let narrow = ArithTable::<16, Narrow>::new(t);
                let (lo, hi) = t.tabulated_range();
                for e in [lo, hi, Strain::ZERO, Strain::MAX, Strain::MIN] {
                    let _ = table_force(&narrow, e);
                }
            }
            Err(e) => prop_assert!(!e.to_string().is_empty()),
        }
    }
}
