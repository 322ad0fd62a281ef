//! [`mccs::q::hold`] is assembly on the M0 (an in-range value costs a sign extension, a
//! compare and a branch, with no literal bound); this checks it against `i32::clamp`,
//! on the core itself, before anything is measured: for each width the core's
//! arithmetic holds at (the edge vector 24, a spring's force 26, a displacement 30),
//! every value within two of each bound, zero, ±1, `i32::MIN`, `i32::MAX`, and random
//! values at every magnitude. Prints `HOLD core=<c> values=<n> mismatches=<n>`; a
//! mismatch exits with failure. On the M3 and M4F `hold` is `clamp` itself, so there the
//! line shows only that the check runs.

use super::fw_common::exit;
use super::rng::Rng;
use mccs::q::hold;
use mccs_firmware::target::CORE;

/// Random values per width.
const RANDOM: u32 = 20_000;

/// The values `hold::<B>` gets that differ from `clamp`, and how many were tried.
fn check_width<const B: u32>(rng: &mut Rng) -> (u32, u32) {
    let (lo, hi) = (-(1i32 << B), (1i32 << B) - 1);
    let mut tried = 0;
    let mut wrong = 0;
    let mut one = |x: i32| {
        tried += 1;
        wrong += (hold::<B>(x) != x.clamp(lo, hi)) as u32;
    };
    for edge in [lo, hi] {
        for d in -2..=2 {
            one(edge.wrapping_add(d));
        }
    }
    for x in [0, 1, -1, i32::MIN, i32::MAX, i32::MIN + 1, i32::MAX - 1] {
        one(x);
    }
    for _ in 0..RANDOM {
        // The magnitude from 2⁰ to 2³¹.
        let x = rng.next();
        one((x as i32) >> (x & 31));
    }
    (tried, wrong)
}

/// Runs the check and exits with failure on a mismatch.
#[inline(never)]
pub fn check() {
    let mut rng = Rng(0x9E37_79B9);
    let widths = [
        check_width::<24>(&mut rng),
        check_width::<26>(&mut rng),
        check_width::<30>(&mut rng),
    ];
    let values: u32 = widths.iter().map(|w| w.0).sum();
    let mismatches: u32 = widths.iter().map(|w| w.1).sum();
    defmt::println!(
        "HOLD core={=str} values={=u32} mismatches={=u32}",
        CORE.name(),
        values,
        mismatches
    );
    if mismatches != 0 {
        exit(false)
    }
}
