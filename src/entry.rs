//! Out-of-line entry points into the per-tick arithmetic, so that a benchmark can count
//! the instructions of exactly one call (QEMU `-icount`, or DWT on hardware). They add
//! nothing but the call itself.

use crate::{Force, ForceTable64, Stiffness, Strain};

/// One [`ForceTable64::force_and_stiffness`] evaluation, never inlined.
#[inline(never)]
pub fn force_and_stiffness(table: &ForceTable64, strain: Strain) -> (Force, Stiffness) {
    table.force_and_stiffness(strain)
}

/// One [`ForceTable64::force`] evaluation, never inlined.
#[inline(never)]
pub fn force(table: &ForceTable64, strain: Strain) -> Force {
    table.force(strain)
}
