//! [`Rng`]: the random states of the bench's checks, the same on every run.

/// A xorshift generator (Marsaglia's 13, 17, 5) from a nonzero seed.
pub(crate) struct Rng(pub(crate) u32);

impl Rng {
    /// The next 32 random bits.
    pub(crate) fn next(&mut self) -> u32 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.0 = x;
        x
    }

    /// A value within about `±2^bits` (`bits` ≤ 31).
    pub(crate) fn within(&mut self, bits: u32) -> i32 {
        (self.next() as i32) >> (31 - bits.min(31))
    }

    /// Uniform in `[lo, hi)`.
    pub(crate) fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next() as f64 / 4_294_967_296.0)
    }
}
