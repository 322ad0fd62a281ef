//! The table builder's arguments (any spring scale, domain and knot count) and any raw
//! table: a typed error or a valid table, its measured error, the bound's verdict, and
//! every evaluation, in both arithmetics, without a panic.
#![no_main]
use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use mccs::arith::{narrow::table_force, ArithTable};
use mccs::{ForceTable, Narrow, Params, RawTable, Strain};

#[derive(Arbitrary, Debug)]
struct Input {
    scales: [f64; 11],
    from: f64,
    to: f64,
    knots: u8,
    raw: ([i32; 10], [u32; 3], [[i32; 4]; 16], [i32; 7]),
    strains: Vec<i32>,
}

fn evaluate<const S: usize>(t: &ForceTable<S>, strains: &[i32]) {
    let narrow = ArithTable::<S, Narrow>::new(*t);
    for &e in strains.iter().chain(&[i32::MIN, i32::MAX, 0]) {
        let e = Strain::from_bits(e);
        let _ = t.force_and_stiffness(e);
        let _ = t.force(e);
        let _ = t.force_within::<26>(e);
        let _ = table_force(&narrow, e);
    }
}

fn build<const S: usize>(p: &Params, from: f64, to: f64, strains: &[i32]) {
    if let Ok(t) = ForceTable::<S>::with_domain(p, from, to) {
        assert_eq!(t.validate(), Ok(()));
        evaluate(&t, strains);
        // The measurement of its error, and the refusal against the product's bound.
        if let Ok(law) = mccs::Law::new(p) {
            let m = t.measured(&law, from, to).max_error();
            assert!(m.is_some_and(|e| e.force >= 0.0 && e.stiffness >= 0.0));
            let bounded = ForceTable::<S>::with_bound(p, from, to, &mccs::TableBound::PRODUCT);
            assert!(matches!(bounded, Ok(_) | Err(mccs::TableError::BoundNotMet { .. })));
        }
    }
}

fuzz_target!(|i: Input| {
    let mut p = Params::TABLE2;
    for (k, s) in mccs::ParamKey::ALL.iter().zip(i.scales) {
        if let Some(v) = k.get(&p) {
            k.set(&mut p, v * s);
        }
    }
    match i.knots % 4 {
        0 => build::<16>(&p, i.from, i.to, &i.strains),
        1 => build::<32>(&p, i.from, i.to, &i.strains),
        2 => build::<64>(&p, i.from, i.to, &i.strains),
        _ => build::<128>(&p, i.from, i.to, &i.strains),
    }
    let (a, b, segments, c) = i.raw;
    let raw = RawTable {
        strain_lo: a[0],
        strain_hi: a[1],
        index_pre: b[0],
        index_scale: b[1],
        anchor_lo: a[2],
        force_lo: a[3],
        stiffness_lo: a[4],
        slope_lo: a[9],
        force_hi: a[5],
        // Half of them within ±2¹⁹, where the line above's slope is Q28.
        stiffness_hi: if a[7] & 1 == 0 { a[6] >> 12 } else { a[6] },
        slope_hi: c[6],
        shift: b[2],
        stiff_scale: a[7],
        stiff_post: a[8],
        corner_hi: c[0],
        corner_anchor: c[1],
        corner_pre: c[2] as u32,
        corner_base: c[3] as u32,
        corner_scale: c[4],
        corner_post: c[5],
        err_force_ppb: b[0],
        err_stiffness_ppb: b[1],
        segments,
    };
    let t = ForceTable::from_raw(raw);
    let _ = t.validate();
    let _ = t.max_stiffness();
    evaluate(&t, &i.strains);
});
