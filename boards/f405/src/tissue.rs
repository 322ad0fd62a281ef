//! The board's tissue: the force table the firmware runs, as `mccs table` emits it, in
//! `boards/f405/tissue.rs` (the paper's Table 2 spring, `params/table2.toml`, 65 knots, as
//! shipped). One constant for the firmware and its tests. To put your own tissue on the
//! board, emit its table over that file, with any knot count `mccs table` takes (17, 33,
//! 65 or 129): the table's type, and so the controller's, follow from what the file holds
//! (docs/firmware.md, "Your own tissue on the board").

use mccs::ForceTable;

/// The segment count of a table (its knots less one).
pub const fn segments<const S: usize>(_: &ForceTable<S>) -> usize {
    S
}

/// The emitted table, as an expression.
macro_rules! emitted {
    () => {
        include!("../tissue.rs")
    };
}

/// Segments of the board's table (its knots less one): read off the emitted table's type.
pub const SEGMENTS: usize = segments(&emitted!());

/// The board's force table.
pub type TissueTable = ForceTable<SEGMENTS>;

/// The board's tissue.
pub static TISSUE: TissueTable = emitted!();
