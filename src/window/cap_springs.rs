//! A window over a cap: its rest heights (moved at a shift, the entering row or column
//! the cap's) and its springs' rest geometry from them, in fixed point.

use super::{unpack_ends, Window};
use crate::q::{self, mul_wide, sat, V3};
use crate::shape::{Cap, Shape};
use crate::units::DIR_FRAC;

impl<const EDGES: usize, Sh: Shape> Window<EDGES, Sh> {
    /// The rest heights from the cap (start-up): node `(a, b)` of the window at its
    /// corner. A window too large for its heights' slots is refused (`None`).
    pub(crate) fn fill_heights(&mut self, cap: &Cap) -> Option<()> {
        let n = self.n;
        if (n * n) as usize > EDGES {
            return None;
        }
        for a in 0..n {
            for b in 0..n {
                let z = cap.height(self.corner[0] + a, self.corner[1] + b);
                *self.heights.get_mut((a * n + b) as usize)? = z;
            }
        }
        Some(())
    }

    /// Rest height of the window's surface node `(a, b)` (Q24 mm; 0 off the window).
    #[inline(always)]
    pub(crate) fn rest_height(&self, a: i32, b: i32) -> i32 {
        self.heights
            .get((a * self.n + b) as usize)
            .copied()
            .unwrap_or(0)
    }

    /// Spring `e`'s rest geometry `(dir, 1/l0)` (Q23, Q31 per mm) on a cap from its
    /// packed ends and the window's rest heights, in spacings so that every square fits
    /// `i64`: the horizontal offsets are whole spacings, the vertical one `Δz/s` by a
    /// product by `1/s`; `s/l0` by one reciprocal square root (within 2e-8).
    pub(crate) fn spring_geometry(&self, e: usize) -> (V3, i32) {
        let [a, b] = unpack_ends(self.ends.get(e).copied().unwrap_or(0));
        // (da, db) = (0, 0): a vertical spring, from a surface node to the base node a
        // spacing straight below it (or the other way): its geometry is the flat patch's.
        if a[0] == b[0] && a[1] == b[1] {
            let down = if b[2] > a[2] { -1 } else { 1 };
            return ([0, 0, down << DIR_FRAC], self.inv_s.saturating_mul(2));
        }
        let z = |k: [i32; 3]| {
            self.rest_height(k[0], k[1])
                .saturating_sub(k[2].wrapping_mul(self.spacing))
        };
        // Offsets in spacings, Q28 (|Δz| ≤ 128 mm over s ≥ 1 mm: the squares sum within
        // i64). Every product is rounded to nearest, symmetrically: a spring computed from
        // its other end is its exact negation (a continued spring may run the other way),
        // and a unit direction's length stays within rounding of one (no strain at rest).
        let dz = z(b).saturating_sub(z(a));
        // The horizontal offsets are whole spacings (−1, 0 or 1): their squares are exact.
        let (da, db) = (b[0] - a[0], b[1] - a[1]);
        let ds_z = sat(round_shr(mul_wide(dz, self.inv_s), 26));
        let flat2 = ((da * da + db * db) as i64) << 56;
        let (y, e) = q::rsqrt(flat2 + mul_wide(ds_z, ds_z));
        // s/l0 = y 2^(e/2 − 34) (the sum is Q56), in Q30: y >> (4 − e/2); l0 ≥ s: e ≤ 6.
        let sl = round_shr(y as i64, 4u32.saturating_sub(e >> 1).max(1)) as i32;
        // 1/l0 = (s/l0)(1/s): Q30 · Q30 = Q60, Q31 after >> 29; 1 mm is held at i32::MAX.
        let inv_len = sat(round_shr(mul_wide(sl, self.inv_s), 29));
        // dir = (Δ/s)(s/l0): Q28 · Q30 = Q58, Q23 after >> 35 (a whole spacing: sl >> 7).
        let whole = |d: i32| d.wrapping_mul(round_shr(sl as i64, 7) as i32);
        let dir = [whole(da), whole(db), sat(round_shr(mul_wide(ds_z, sl), 35))];
        (dir, inv_len)
    }
}

/// `x / 2^sh` rounded to nearest, halves away from zero (`sh` ≥ 1): odd in `x`.
fn round_shr(x: i64, sh: u32) -> i64 {
    let m = (x.unsigned_abs() + (1 << (sh - 1))) >> sh;
    if x < 0 {
        -(m as i64)
    } else {
        m as i64
    }
}

/// A window's rest heights (its side `n`, its corner `corner`) at a shift along `d`
/// (one axis), before the corner moves: height
/// `(a, b)` at `a n + b` takes `(a, b) + d`'s (whole rows move along x, each row's
/// heights along y, in the direction of the shift: every source is read before it is
/// overwritten), and the entering row or column is the cap's. (Indexed loops:
/// `copy_within` would leave a panic path in the tick.)
pub(super) fn move_heights<const EDGES: usize>(
    heights: &mut [i32; EDGES],
    cap: &Cap,
    n: i32,
    corner: [i32; 2],
    d: [i32; 2],
) {
    let nu = n.max(0) as usize;
    let nn = nu * nu;
    let h = &mut *heights;
    let mut take = |to: usize, from: usize| {
        if let Some(&z) = h.get(from) {
            if let Some(slot) = h.get_mut(to) {
                *slot = z;
            }
        }
    };
    match d {
        [1, 0] => (0..nn.saturating_sub(nu)).for_each(|i| take(i, i + nu)),
        [-1, 0] => (nu..nn).rev().for_each(|i| take(i, i - nu)),
        [0, 1] => (0..nn).step_by(nu.max(1)).for_each(|r| {
            (r..r + nu.saturating_sub(1)).for_each(|i| take(i, i + 1));
        }),
        _ => (0..nn).step_by(nu.max(1)).for_each(|r| {
            (r + 1..r + nu).rev().for_each(|i| take(i, i - 1));
        }),
    }
    for k in 0..n {
        let (a, b) = match d {
            [1, 0] => (n - 1, k),
            [-1, 0] => (0, k),
            [0, 1] => (k, n - 1),
            _ => (k, 0),
        };
        let z = cap.height(corner[0] + a + d[0], corner[1] + b + d[1]);
        if let Some(h) = heights.get_mut((a * n + b) as usize) {
            *h = z;
        }
    }
}
