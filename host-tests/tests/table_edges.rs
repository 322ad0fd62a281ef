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

/// `validate` on `raw` with `edit` made to it.
fn validate_edited(
    mut raw: RawTable<64>,
    edit: &dyn Fn(&mut RawTable<64>),
) -> Result<(), TableError> {
    edit(&mut raw);
    ForceTable::from_raw(raw).validate()
}

/// A lower corner (`tables/steep_kink.rs`, `ForceTable::lower_corner`): the table is
/// valid, each strain at the ends of its pieces takes the piece it belongs to (the line
/// below at `corner_hi`, the corner from one above it up to `strain_lo`, the grid above,
/// the line above from `strain_hi`, anchored at `corner_hi`), and `validate` refuses a corner
/// end between the grid's ends, a coordinate that leaves `[2²⁴, 2³²)` at either end,
/// a corner past the last segment and a line above from a force below −1024 N.
#[test]
fn a_lower_corner_is_valid_and_evaluated_on_its_own_range() {
    static STEEP_KINK: ForceTable<64> = include!("../../tables/steep_kink.rs");
    let t = STEEP_KINK;
    let r = *t.raw();
    assert_eq!(t.validate(), Ok(()));
    assert!(t.lower_corner() && r.corner_hi < r.strain_lo);
    assert_eq!(
        t.corner(),
        Some((
            Strain::from_bits(r.corner_hi + 1),
            Strain::from_bits(r.strain_lo + 1)
        ))
    );
    assert_eq!(
        t.tabulated_range(),
        (
            Strain::from_bits(r.corner_hi),
            Strain::from_bits(r.strain_hi)
        )
    );
    // The line above is anchored at corner_hi, below the table: its force there is the
    // line extrapolated down (at least −1024 N: `validate`).
    let at_end = t.force(Strain::from_bits(r.strain_hi)).to_bits();
    assert!(r.force_hi >= 0 && r.force_hi < at_end);
    // Each piece's ends: the force never decreases across them, and force_within and the
    // narrow lookup agree with force on the cubic pieces.
    let narrow = ArithTable::<64, Narrow>::new(t);
    let ends = [r.corner_hi, r.strain_lo, r.strain_hi];
    for e in ends.iter().flat_map(|&x| [x - 1, x, x + 1]) {
        let e = Strain::from_bits(e);
        let (f, _) = t.force_and_stiffness(e);
        assert_eq!(f, t.force(e));
        assert!(t.force(Strain::from_bits(e.to_bits() + 1)) >= f);
        let (lo, hi) = t.tabulated_range();
        if e > lo && e < hi {
            assert_eq!(table_force(&narrow, e), t.force_within::<26>(e));
        }
    }
    let refused = |edit: &dyn Fn(&mut RawTable<64>)| validate_edited(r, edit);
    assert!(refused(&|x| x.corner_hi = x.strain_lo).is_err());
    assert!(refused(&|x| x.corner_hi = x.strain_hi - 1).is_err());
    // The coordinate reaches 2³² one strain below the corner, 2²⁴ at its end.
    assert!(refused(&|x| x.corner_hi -= 1).is_err());
    assert!(refused(&|x| x.strain_lo += 1).is_err());
    assert!(refused(&|x| x.corner_base = 33).is_err());
    assert!(refused(&|x| x.force_hi = -(1 << 30) - 1).is_err());
}

/// A lower corner graded toward its anchor from above (`tables/near_transition.rs`:
/// a negative `corner_pre`): valid, its range from the law's first kink, and refused
/// with a stiffness scale of the wrong sign or a coordinate past 2³² at its top.
#[test]
fn a_corner_above_its_anchor_is_valid_with_its_own_signs() {
    static NEAR_TRANSITION: ForceTable<64> = include!("../../tables/near_transition.rs");
    let t = NEAR_TRANSITION;
    let r = *t.raw();
    assert_eq!(t.validate(), Ok(()));
    assert!(t.lower_corner() && (r.corner_pre as i32) < 0 && r.corner_scale > 0);
    let refused = |edit: &dyn Fn(&mut RawTable<64>)| validate_edited(r, edit);
    assert!(refused(&|x| x.corner_scale = -x.corner_scale).is_err());
    assert!(refused(&|x| x.strain_lo += 1).is_err());
    assert!(refused(&|x| x.corner_hi -= 1).is_err());
    // Its segments' ranges are ordered and tile the corner from its lower end up.
    let (a, b) = t.corner().unwrap();
    let lsb = 1.0 / (1u64 << 24) as f64;
    let (lo, hi) = (t.corner_segment_range(28), t.corner_segment_range(3));
    assert!(lo.0 < lo.1 && hi.0 < hi.1);
    assert!((lo.0 - a.to_num::<f64>()).abs() < 2.0 * lsb);
    assert!((hi.1 - b.to_num::<f64>()).abs() < 2.0 * lsb);
}

/// A domain ending a hair above the kink left the grid from the kink 17 knots within
/// one strain LSB (and an index scale of 32 bits, on which the narrow arithmetic's
/// derivation overflowed): that placement is refused as too narrow. The builder's best
/// (`ForceTable::with_domain`) then tabulates from the domain's start: a valid table
/// within the product's bound.
#[test]
fn a_domain_narrower_than_its_segments_is_refused() {
    let p = Params::TABLE2;
    let law = mccs::Law::new(&p).unwrap();
    assert_eq!(
        ForceTable::<16>::one_placement_unmeasured(&law, -0.5, 0.2352539063).err(),
        Some(TableError::TooNarrow)
    );
    let best = ForceTable::<16>::with_domain(&p, -0.5, 0.2352539063).unwrap();
    assert_eq!(best.validate(), Ok(()));
    assert!(best.max_error().unwrap().within(&mccs::TableBound::PRODUCT));
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
