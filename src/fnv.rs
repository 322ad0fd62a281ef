//! FNV-1a, 32 bits: the project's one hash — a topology's fingerprint
//! ([`crate::Topology::fingerprint`]), and on the link a tissue's table bytes (`Ack`,
//! `Hello`, the `.bin` file's header) and the schema — as a value fed in pieces
//! ([`Fnv1a`]) or over a slice in one call ([`fnv1a`], also at compile time).

/// The offset basis.
const BASIS: u32 = 0x811C_9DC5;
/// The prime.
const PRIME: u32 = 0x0100_0193;

/// FNV-1a of `bytes`.
pub const fn fnv1a(bytes: &[u8]) -> u32 {
    let mut h = Fnv1a::new();
    let mut i = 0;
    while i < bytes.len() {
        h = h.byte(bytes[i]);
        i += 1;
    }
    h.value()
}

/// An FNV-1a hash fed a byte at a time (a table arriving in pieces, or written a word
/// at a time with no buffer).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fnv1a(u32);

impl Default for Fnv1a {
    fn default() -> Self {
        Self::new()
    }
}

impl Fnv1a {
    /// Nothing fed yet.
    pub const fn new() -> Self {
        Self(BASIS)
    }

    /// With one more byte.
    #[must_use]
    pub const fn byte(self, b: u8) -> Self {
        Self((self.0 ^ b as u32).wrapping_mul(PRIME))
    }

    /// Feeds `bytes`.
    pub fn update(&mut self, bytes: &[u8]) {
        for &b in bytes {
            *self = self.byte(b);
        }
    }

    /// The hash so far.
    pub const fn value(self) -> u32 {
        self.0
    }
}
