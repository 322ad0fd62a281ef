//! A force table as the bytes a tissue load carries: the [`RawTable`]'s header fields in
//! their declaration order, then its segments, each value an `i32` little-endian
//! ([`HEADER_WORDS`] + 4 per segment: 1,112 bytes at 65 knots). The hash names a tissue
//! in `Ack` and `Hello`: FNV-1a over those bytes.
//!
//! The field order is written once, in `fields!`: [`write()`], [`hash()`] and the
//! [`Assembler`] that a device fills as the bytes arrive all read it from there.

use mccs::fnv::Fnv1a;
use mccs::{ForceTable, RawTable};

/// The header's fields in wire order, each with how its `i32` word maps to the field.
macro_rules! fields {
    ($apply:ident) => {
        $apply! {
            strain_lo: i32,
            strain_hi: i32,
            index_pre: u32,
            index_scale: u32,
            anchor_lo: i32,
            force_lo: i32,
            stiffness_lo: i32,
            slope_lo: i32,
            force_hi: i32,
            stiffness_hi: i32,
            slope_hi: i32,
            shift: u32,
            stiff_scale: i32,
            stiff_post: i32,
            corner_hi: i32,
            corner_anchor: i32,
            corner_pre: u32,
            corner_base: u32,
            corner_scale: i32,
            corner_post: i32,
            err_force_ppb: u32,
            err_stiffness_ppb: u32
        }
    };
}

macro_rules! count {
    ($($f:ident: $t:ty),*) => { [$(stringify!($f)),*].len() };
}

/// The header's 4-byte fields.
pub const HEADER_WORDS: usize = fields!(count);

macro_rules! to_words {
    ($($f:ident: $t:ty),*) => {
        /// The header's fields, in order, as `i32` bits.
        fn header<const S: usize>(r: &RawTable<S>) -> [i32; HEADER_WORDS] {
            [$(r.$f as i32),*]
        }
    };
}
fields!(to_words);

macro_rules! from_words_fn {
    ($($f:ident: $t:ty),*) => {
        /// The table of these words: the header's fields in order, and the segments.
        pub fn from_words<const S: usize>(h: &[i32; HEADER_WORDS], segments: [[i32; 4]; S]) -> RawTable<S> {
            let mut words = h.iter();
            RawTable {
                $($f: words.next().copied().unwrap_or(0) as $t,)*
                segments,
            }
        }
    };
}
fields!(from_words_fn);

/// The bytes of a table of `S` segments.
pub const fn len(segments: usize) -> usize {
    4 * (HEADER_WORDS + 4 * segments)
}

/// Every word of `table` in wire order.
fn words<const S: usize>(table: &ForceTable<S>) -> impl Iterator<Item = i32> + '_ {
    let r = table.raw();
    header(r)
        .into_iter()
        .chain(r.segments.iter().flat_map(|s| s.iter().copied()))
}

/// Writes `table` into `out` (at least [`len`]`(S)` bytes); returns the bytes written.
pub fn write<const S: usize>(table: &ForceTable<S>, out: &mut [u8]) -> usize {
    let mut n = 0;
    for (w, slot) in words(table).zip(out.chunks_exact_mut(4)) {
        slot.copy_from_slice(&w.to_le_bytes());
        n += 4;
    }
    n
}

/// The table in `bytes`, unchecked (the caller validates it); `None` if `bytes` is not
/// [`len`]`(S)` long.
pub fn read<const S: usize>(bytes: &[u8]) -> Option<RawTable<S>> {
    if bytes.len() != len(S) {
        return None;
    }
    let mut a = Assembler::<S>::new();
    for &b in bytes {
        a.push(b);
    }
    a.finish()
}

/// A table's hash: FNV-1a over its bytes, fed a word at a time (no buffer).
pub fn hash<const S: usize>(table: &ForceTable<S>) -> u32 {
    let mut h = Fnv1a::new();
    for w in words(table) {
        h.update(&w.to_le_bytes());
    }
    h.value()
}

/// The hash of bytes as they arrive ([`hash`] of the table they hold).
pub fn hash_bytes(bytes: &[u8]) -> u32 {
    mccs::fnv::fnv1a(bytes)
}

/// A table's bytes put together as they arrive, a byte at a time, with their running
/// hash: what a device keeps of a load in progress (no buffer of the bytes themselves).
#[derive(Clone, Debug)]
pub struct Assembler<const S: usize> {
    header: [i32; HEADER_WORDS],
    segments: [[i32; 4]; S],
    got: usize,
    hash: Fnv1a,
}

impl<const S: usize> Default for Assembler<S> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const S: usize> Assembler<S> {
    /// No bytes yet.
    pub const fn new() -> Self {
        Self {
            header: [0; HEADER_WORDS],
            segments: [[0; 4]; S],
            got: 0,
            hash: Fnv1a::new(),
        }
    }

    /// Bytes taken so far.
    pub fn received(&self) -> usize {
        self.got
    }

    /// The hash of the bytes so far.
    pub fn hash(&self) -> u32 {
        self.hash.value()
    }

    /// Takes the next byte; false (and the byte dropped) past [`len`]`(S)`.
    pub fn push(&mut self, b: u8) -> bool {
        let i = self.got;
        let (word, shift) = (i / 4, 8 * (i % 4));
        let slot = if let Some(h) = self.header.get_mut(word) {
            h
        } else {
            let k = word - HEADER_WORDS;
            match self.segments.get_mut(k / 4) {
                Some(s) => &mut s[k % 4],
                None => return false,
            }
        };
        *slot |= ((b as u32) << shift) as i32;
        self.hash = self.hash.byte(b);
        self.got += 1;
        true
    }

    /// The table, once every byte has arrived.
    pub fn finish(&self) -> Option<RawTable<S>> {
        (self.got == len(S)).then(|| from_words(&self.header, self.segments))
    }
}
