//! TIM2 as the tick ([`TickTimer`]): the counter at 1 MHz, an update every tick.

use stm32f4xx_hal::pac;

/// TIM2, the tick's timer.
pub struct TickTimer(pac::TIM2);

impl TickTimer {
    /// Sets the prescaler and the period; neither counting nor interrupting yet.
    pub fn new(tim: pac::TIM2, psc: u16, arr: u32) -> Self {
        tim.psc().write(|w| w.psc().set(psc));
        tim.arr().write(|w| w.arr().set(arr));
        // Load the prescaler now (an update event), then clear its flag.
        tim.egr().write(|w| w.ug().set_bit());
        tim.sr().write(|w| w.uif().clear());
        Self(tim)
    }

    /// Counts from zero, an update interrupt every tick. (Writing the counter also arms
    /// QEMU's timer model, whose alarm lapses if it expires while disabled.)
    pub fn start(&mut self) {
        self.0.sr().write(|w| w.uif().clear());
        self.0.dier().modify(|_, w| w.uie().set_bit());
        self.0.cr1().modify(|_, w| w.cen().set_bit());
        self.0.cnt().write(|w| w.cnt().set(0));
    }

    /// No more update interrupts (the end of a QEMU run).
    #[cfg(board_run_ends)]
    pub fn stop(&mut self) {
        self.0.dier().modify(|_, w| w.uie().clear_bit());
    }

    /// Clears the update that started this tick.
    pub fn clear(&mut self) {
        self.0.sr().write(|w| w.uif().clear());
    }

    /// Whether the next update fell due.
    pub fn pending(&self) -> bool {
        self.0.sr().read().uif().bit_is_set()
    }

    /// µs since the last update. (QEMU's model does not restart its counter at an
    /// update: 0 there.)
    pub fn count(&self) -> u32 {
        if cfg!(board_qemu) {
            0
        } else {
            self.0.cnt().read().cnt().bits()
        }
    }
}
