//! [`Slot`]: an `Option<T>` that is all zero bytes until first used, so that a `static`
//! one lies in `.bss` and costs no flash for its image (an `Option<T>` static whose `None`
//! is a niche value puts the whole `T` in `.data`: a controller's 8 KB, a replayer's
//! 13 KB).
//!
//! The firmware's one pattern for a `'static` buffer: a `Slot` as a `static mut` local
//! of `#[entry]` or of an interrupt handler, which cortex-m-rt hands over as a safe
//! `&'static mut` (taken once by construction); then [`Slot::option`] (a builder writes
//! `Some` in place, no copy through the stack) or [`Slot::insert`] for the value's
//! `&'static mut`. No `unsafe` at the place of use.

use core::mem::MaybeUninit;

/// An `Option<T>`, zero bytes until first used.
pub struct Slot<T> {
    written: bool,
    value: MaybeUninit<Option<T>>,
}

impl<T> Default for Slot<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T> Slot<T> {
    /// Unused (reads as `None`).
    pub const fn new() -> Self {
        Self {
            written: false,
            value: MaybeUninit::uninit(),
        }
    }

    /// The `Option` it holds (`None` until something is put in).
    pub fn option(&mut self) -> &mut Option<T> {
        if !self.written {
            self.value.write(None);
            self.written = true;
        }
        // SAFETY: written above, or before (`written` is set only after the write).
        unsafe { self.value.assume_init_mut() }
    }

    /// Puts `value` in (dropping the one it held) and returns it.
    pub fn insert(&mut self, value: T) -> &mut T {
        self.option().insert(value)
    }
}

impl<T> Drop for Slot<T> {
    fn drop(&mut self) {
        // The value moves out and drops; the `None` left behind owns nothing.
        drop(self.option().take());
    }
}
