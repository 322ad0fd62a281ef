//! The largest standard patch the `f32` and `f64` peers (`mccs_firmware::float_patch`: the
//! same table, damping and integrator, lengths by square root) run at 1 kHz within half
//! a tick, in the same run as the fixed point's `case=largest_patch_1khz`: each peer's
//! substep measured on the N × N patch at N = 3, 4, … (pressed as the substep cases press
//! it), times the substeps the fixed-point solver's stability bound takes for that patch,
//! until a tick passes half a tick. Prints `BENCH core=<c> case=largest_patch_1khz_<f32|f64>
//! n= substeps= instructions= next_n= next_instructions=`: the largest N that fits (0:
//! not even N = 3) and its tick, and the first N that does not and its tick (0 where
//! this core does not measure it). Measured, not bounded over every state as the fixed
//! point's is (a peer's spring has no costlier paths to charge: its table lookup and
//! holds take the same few branches everywhere).
//!
//! Up to N = 10 on the M4F; on the M0 at N = 3 only, where neither peer fits (its 16 KiB
//! of RAM hold no larger peer beside the bench's own); not on the M3, whose bench fills
//! its 256 KiB of flash (these two peers' patches overflowed it by 8,420 bytes): its
//! peers' substep at N = 5 (`substep_n5_f32`, `_f64`) alone is over half its tick.

use super::cases;
use super::harness::Harness;
use super::report::Steps;
use mccs::ForceTable64;
use mccs_firmware::float_patch::Real;
use mccs_firmware::target::{Core, CORE};

/// Half a 1 kHz tick at the core's estimated clock, instructions.
const HALF_TICK: u32 = CORE.clock_estimate().0 * 1_000_000 / 2_000;

/// One peer's tick on the N × N patch, less the harness's empty call per substep, and its
/// substeps (`None` where this core does not measure N).
#[inline(never)]
fn tick<T: Real>(
    h: &Harness,
    steps: &Steps,
    table: &ForceTable64,
    empty: u32,
    n: u32,
) -> Option<(u32, u32)> {
    let s = steps.substeps(n, 1_000)?;
    let one = match n {
        3 => cases::float::<T, 2, 9>(h, 3, s, table),
        4 if CORE == Core::M4F => cases::float::<T, 5, 30>(h, 4, s, table),
        5 if CORE == Core::M4F => cases::float::<T, 10, 61>(h, 5, s, table),
        6 if CORE == Core::M4F => cases::float::<T, 17, 102>(h, 6, s, table),
        7 if CORE == Core::M4F => cases::float::<T, 26, 153>(h, 7, s, table),
        8 if CORE == Core::M4F => cases::float::<T, 37, 214>(h, 8, s, table),
        9 if CORE == Core::M4F => cases::float::<T, 50, 285>(h, 9, s, table),
        10 if CORE == Core::M4F => cases::float::<T, 65, 366>(h, 10, s, table),
        _ => return None,
    };
    Some((one.saturating_sub(empty).saturating_mul(s), s))
}

/// The peer `T`'s largest patch, printed as `case`.
#[inline(never)]
fn largest<T: Real>(h: &Harness, steps: &Steps, table: &ForceTable64, empty: u32, case: &str) {
    let (mut fits, mut next) = ((0, 0, 0), (0, 0));
    for n in 3..=10 {
        let Some((tick, substeps)) = tick::<T>(h, steps, table, empty, n) else {
            break;
        };
        if tick > HALF_TICK {
            next = (n, tick);
            break;
        }
        fits = (n, substeps, tick);
    }
    defmt::println!(
        "BENCH core={=str} case={=str} n={=u32} substeps={=u32} instructions={=u32} next_n={=u32} next_instructions={=u32}",
        CORE.name(),
        case,
        fits.0,
        fits.1,
        fits.2,
        next.0,
        next.1
    );
}

/// Both peers' largest patches (none on the M3: module docs).
pub fn largest_patches(h: &Harness, steps: &Steps, table: &ForceTable64, empty: u32) {
    if CORE == Core::M3 {
        return;
    }
    largest::<f32>(h, steps, table, empty, "largest_patch_1khz_f32");
    largest::<f64>(h, steps, table, empty, "largest_patch_1khz_f64");
}
