//! `Mailbox`: the double buffer between the main loop and the tick interrupt.
//!
//! The main loop builds a new value (a parameter set, a table) at its own pace and
//! [`post`](Mailbox::post)s it; the tick [`take`](Mailbox::take)s it at its start and
//! switches to it between two ticks. The value moves whole inside a critical section, so
//! a tick sees the old value or the new one, never a mix. No `RefCell`: no borrow panic.

use core::cell::Cell;
use critical_section::Mutex;

/// A one-slot mailbox shared between contexts.
pub struct Mailbox<T> {
    slot: Mutex<Cell<Option<T>>>,
}

impl<T> Default for Mailbox<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T> Mailbox<T> {
    /// Empty.
    pub const fn new() -> Self {
        Self {
            slot: Mutex::new(Cell::new(None)),
        }
    }

    /// Puts `value` in the slot; returns the value it replaces if that was never taken.
    pub fn post(&self, value: T) -> Option<T> {
        critical_section::with(|cs| self.slot.borrow(cs).replace(Some(value)))
    }

    /// Takes the value, if any.
    pub fn take(&self) -> Option<T> {
        critical_section::with(|cs| self.slot.borrow(cs).take())
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
}
