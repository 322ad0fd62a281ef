//! `JointEncoder`: a quadrature counter (a timer in encoder mode: 16 bits on most STM32
//! timers) read each tick (embedded-hal has no such trait), and [`Extended`], its count
//! carried to 32 bits by the wrapping difference between two reads: exact while a joint
//! moves fewer than 32,768 counts a tick (32.8 million counts per second at 1 kHz; the
//! WoodenHaptics arm's 32,000 counts per joint turn make that 1,024 turns a second).

/// A 16-bit quadrature counter.
pub trait JointEncoder {
    /// A failed read.
    type Error;
    /// The counter now.
    fn read(&mut self) -> Result<u16, Self::Error>;
}

/// A count carried past the counter's 16 bits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Extended {
    last: u16,
    count: i32,
}

impl Extended {
    /// Starting at `count` with the counter at `raw`.
    pub const fn new(raw: u16, count: i32) -> Self {
        Self { last: raw, count }
    }

    /// The count after the counter reads `raw`.
    pub fn update(&mut self, raw: u16) -> i32 {
        let step = raw.wrapping_sub(self.last) as i16;
        self.last = raw;
        self.count = self.count.wrapping_add(step as i32);
        self.count
    }

    /// The count.
    pub fn count(&self) -> i32 {
        self.count
    }

    /// The count is `count` from now (homing).
    pub fn rebase(&mut self, count: i32) {
        self.count = count;
    }
}

/// A counter in memory, for tests and simulations: it reads what was last set, or fails.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MockEncoder {
    /// What the next read returns.
    pub raw: u16,
    /// Whether the next read fails.
    pub fail: bool,
}

impl JointEncoder for MockEncoder {
    type Error = ();
    fn read(&mut self) -> Result<u16, ()> {
        if self.fail {
            Err(())
        } else {
            Ok(self.raw)
        }
    }
}
