//! A force table as Rust source for `include!`: what `mccs table` writes.

use mccs::ForceTable;

/// Renders a table as a Rust expression for `include!`, preceded by `header`; `points`,
/// the law's named strains if known (its solid point `Δ(F_C)`, a preload's kink
/// `Δ(P)`, its first kink), name the end a graded corner is graded toward (one of them,
/// or the domain's end).
pub fn render_table<const S: usize>(
    header: &str,
    t: &ForceTable<S>,
    points: &[(f64, &str)],
) -> String {
    let r = t.raw();
    let mut s = String::from(header);
    s.push_str("// Formats: strains Q24, forces Q20 N, stiffnesses Q16 N per unit strain.\n");
    let (lo, hi) = t.tabulated_range();
    match t.corner() {
        Some((a, b)) => {
            // The end it is graded toward: its upper (the exclusive end, within a few strain
            // LSBs of its last knot), or its lower where it lies above its anchor (a
            // negative `corner_pre`).
            let end = if (r.corner_pre as i32) < 0 { a } else { b }.to_num::<f64>();
            let near = 4.0 * mccs::Strain::DELTA.to_num::<f64>();
            let toward = match points.iter().find(|(e, _)| (end - e).abs() <= near) {
                Some((_, name)) => name,
                None if points.is_empty() => "their end",
                None => "the domain's end",
            };
            let (used, graded) = (t.segments_used(), t.corner_segments());
            s.push_str(&if t.lower_corner() {
                format!(
                    "// Layout: {graded} segments graded toward {toward} over [{a}, {b}), then {used} uniform over [{b}, {hi}).\n"
                )
            } else {
                format!(
                    "// Layout: {used} segments uniform over [{lo}, {a}), then {graded} graded toward {toward} over [{a}, {b}).\n"
                )
            })
        }
        None => s.push_str(&format!(
            "// Layout: {} segments uniform over [{lo}, {hi}).\n",
            t.segments_used()
        )),
    }
    s.push_str(&format!(
        "mccs::ForceTable::<{S}>::from_raw(mccs::RawTable {{\n"
    ));
    for (name, v) in [
        ("strain_lo", r.strain_lo as i64),
        ("strain_hi", r.strain_hi as i64),
        ("index_pre", r.index_pre as i64),
        ("index_scale", r.index_scale as i64),
        ("anchor_lo", r.anchor_lo as i64),
        ("force_lo", r.force_lo as i64),
        ("stiffness_lo", r.stiffness_lo as i64),
        ("slope_lo", r.slope_lo as i64),
        ("force_hi", r.force_hi as i64),
        ("stiffness_hi", r.stiffness_hi as i64),
        ("slope_hi", r.slope_hi as i64),
        ("shift", r.shift as i64),
        ("stiff_scale", r.stiff_scale as i64),
        ("stiff_post", r.stiff_post as i64),
        ("corner_hi", r.corner_hi as i64),
        ("corner_anchor", r.corner_anchor as i64),
        ("corner_pre", r.corner_pre as i64),
        ("corner_base", r.corner_base as i64),
        ("corner_scale", r.corner_scale as i64),
        ("corner_post", r.corner_post as i64),
        ("err_force_ppb", r.err_force_ppb as i64),
        ("err_stiffness_ppb", r.err_stiffness_ppb as i64),
    ] {
        s.push_str(&format!("    {name}: {v},\n"));
    }
    s.push_str("    segments: [\n");
    for c in &r.segments {
        s.push_str(&format!(
            "        [{}, {}, {}, {}],\n",
            c[0], c[1], c[2], c[3]
        ));
    }
    s.push_str("    ],\n})\n");
    s
}
