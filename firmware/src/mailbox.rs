//! `Mailbox`: the double buffer between the main loop and the tick interrupt.
//!
//! The main loop builds a new value (a parameter set, a table) at its own pace and
//! [`post`](Mailbox::post)s it; the tick [`take`](Mailbox::take)s it at its start and
//! switches to it between two ticks. The value moves whole inside a critical section, so
//! a tick sees the old value or the new one, never a mix. No `RefCell`: no borrow panic.

use core::cell::{Cell, UnsafeCell};
use core::mem::MaybeUninit;
use critical_section::Mutex;

/// A one-slot mailbox shared between contexts. Empty, it is all zero bytes, so that a
/// `static` mailbox lies in `.bss` and costs no flash for its image (an `Option<T>`
/// whose `None` is a niche value put a parameter set's 1.1 KB in `.data`).
pub struct Mailbox<T> {
    full: Mutex<Cell<bool>>,
    value: UnsafeCell<MaybeUninit<T>>,
}

// SAFETY: `value` is only read or written inside a critical section, and only as `full`
// says (written when empty, read once when full), so the value moves between contexts
// whole, as with `Mutex<Cell<Option<T>>>`.
unsafe impl<T: Send> Sync for Mailbox<T> {}

impl<T> Default for Mailbox<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T> Mailbox<T> {
    /// Empty.
    pub const fn new() -> Self {
        Self {
            full: Mutex::new(Cell::new(false)),
            value: UnsafeCell::new(MaybeUninit::uninit()),
        }
    }

    /// Puts `value` in the slot; returns the value it replaces if that was never taken.
    pub fn post(&self, value: T) -> Option<T> {
        critical_section::with(|cs| {
            let full = self.full.borrow(cs);
            // SAFETY: inside the critical section, so no other context holds the slot;
            // the old value is read (once) only when full, as `post` wrote it.
            let old = unsafe {
                let slot = &mut *self.value.get();
                let old = full.get().then(|| slot.assume_init_read());
                slot.write(value);
                old
            };
            full.set(true);
            old
        })
    }

    /// Takes the value, if any.
    pub fn take(&self) -> Option<T> {
        critical_section::with(|cs| {
            let full = self.full.borrow(cs);
            if !full.get() {
                return None;
            }
            full.set(false);
            // SAFETY: inside the critical section, and full: written by `post`, read once.
            Some(unsafe { (*self.value.get()).assume_init_read() })
        })
    }
}

impl<T> Drop for Mailbox<T> {
    fn drop(&mut self) {
        // A value posted and never taken is dropped with the mailbox.
        drop(self.take());
    }
}

/// A value the tick publishes and the main loop reads (telemetry).
pub struct Shared<T: Copy> {
    cell: Mutex<Cell<T>>,
}

impl<T: Copy> Shared<T> {
    /// Holding `value`.
    pub const fn new(value: T) -> Self {
        Self {
            cell: Mutex::new(Cell::new(value)),
        }
    }

    /// Replaces the value.
    pub fn set(&self, value: T) {
        critical_section::with(|cs| self.cell.borrow(cs).set(value))
    }

    /// The value.
    pub fn get(&self) -> T {
        critical_section::with(|cs| self.cell.borrow(cs).get())
    }

    /// Reads, changes and writes the value in one critical section (no update between
    /// the read and the write is lost); returns what `f` returns.
    pub fn update<R>(&self, f: impl FnOnce(&mut T) -> R) -> R {
        critical_section::with(|cs| {
            let cell = self.cell.borrow(cs);
            let mut v = cell.get();
            let r = f(&mut v);
            cell.set(v);
            r
        })
    }
}
