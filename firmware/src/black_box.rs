//! [`BlackBox`]: the last ticks of a run, what stopped it and the reset that followed,
//! kept where a reset does not clear them, for a post-mortem over the link
//! (`mccs link blackbox`).
//!
//! A board keeps two in memory that no start-up code touches (haptic-f405's
//! `black_box`): the **live** box, which the tick writes each tick ([`BlackBox::record`],
//! a ring of the last `N`) until something stops the device ([`BlackBox::stop`]: the
//! cause, its tick, a HardFault's PC; the ring frozen from then on), and the **last**
//! box, the previous run's, which a boot fills from the live one ([`BlackBox::keep`])
//! before the live one starts again. What a power-on leaves in that memory is noise: a
//! box is believed only with its mark and its indices in range ([`BlackBox::kept`]).
//!
//! Every field is an integer, so that whatever bits memory holds are a box (a stale or
//! noisy one, which the mark rejects); no division in [`BlackBox::record`] (the tick's).

use mccs_link::black_box::{BlackBoxPart, BoxStop, BoxTick, StopCause, BOX_PART};

/// Ticks a board's box keeps (500 ms at 1 kHz): two boxes take 32 KiB of the board's
/// SRAM, which its statics and the main loop's stack leave (docs/safety.md, "The black
/// box").
pub const BLACK_BOX_TICKS: usize = 500;

/// The mark of a box written by this layout ("MCBB", then the layout's version).
const MARK: u32 = 0x4D43_4201;

/// A run's record: a ring of its last `N` ticks, what stopped it, the reset after.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct BlackBox<const N: usize> {
    mark: u32,
    /// The reset's cause as the chip reported it at the boot after the run.
    reset_flags: u32,
    stop: BoxStop,
    /// How the run ended, if a fault handler or a panic ended it (cause 0: not so).
    end: BoxStop,
    /// Nonzero once stopped: the ring no longer moves.
    stopped: u32,
    /// The last tick recorded or not (the ring frozen): the run's last.
    now: u32,
    /// The slot the next tick goes to (`< N`).
    next: u32,
    /// Ticks recorded, at most `N`.
    filled: u32,
    ticks: [BoxTick; N],
}

impl<const N: usize> BlackBox<N> {
    /// An empty box: no run, nothing stopped.
    pub const EMPTY: Self = Self {
        mark: 0,
        reset_flags: 0,
        stop: BoxStop {
            cause: 0,
            part: 0,
            reserved: 0,
            tick: 0,
            pc: 0,
        },
        end: BoxStop {
            cause: 0,
            part: 0,
            reserved: 0,
            tick: 0,
            pc: 0,
        },
        stopped: 0,
        now: 0,
        next: 0,
        filled: 0,
        ticks: [BoxTick {
            tick: 0,
            counts: [0; 3],
            force_mn: [0; 3],
            duty_q15: [0; 3],
            gain: 0,
            flags: 0,
        }; N],
    };

    /// Starts a run's record: marked, empty, not stopped.
    pub fn start(&mut self) {
        self.mark = MARK;
        self.reset_flags = 0;
        self.stop = BoxStop::default();
        self.end = BoxStop::default();
        self.stopped = 0;
        self.now = 0;
        self.next = 0;
        self.filled = 0;
    }

    /// Whether the box holds a record this layout wrote (its mark, and its indices in
    /// range): what is read from memory after a power-on is not.
    pub fn kept(&self) -> bool {
        self.mark == MARK && (self.next as usize) < N.max(1) && self.filled as usize <= N
    }

    /// Keeps one tick, the oldest overwritten; once stopped, only its tick number (the
    /// run's last); nothing unmarked.
    pub fn record(&mut self, tick: BoxTick) {
        self.now = tick.tick;
        if self.stopped != 0 || self.mark != MARK {
            return;
        }
        let at = self.next as usize;
        if let Some(slot) = self.ticks.get_mut(at) {
            *slot = tick;
        }
        self.next = if at + 1 >= N { 0 } else { at as u32 + 1 };
        if (self.filled as usize) < N {
            self.filled += 1;
        }
    }

    /// What stopped the run: kept once (the first stop is the one reported), the ring
    /// frozen.
    pub fn stop(&mut self, cause: StopCause, part: u8, tick: u32, pc: u32) {
        if self.stopped != 0 || self.mark != MARK {
            return;
        }
        self.stop = BoxStop {
            cause: cause.code(),
            part,
            reserved: 0,
            tick,
            pc,
        };
        self.stopped = 1;
    }

    /// A fault handler or a panic ends the run with `cause` (a HardFault's `pc`), after
    /// the last tick that ran: kept as how the run ended (the first such), and as its
    /// stop unless a fault stopped it first.
    pub fn end(&mut self, cause: StopCause, pc: u32) {
        if self.mark != MARK || self.end.cause != 0 {
            return;
        }
        let tick = self.now;
        self.end = BoxStop {
            cause: cause.code(),
            part: 0,
            reserved: 0,
            tick,
            pc,
        };
        self.stop(cause, 0, tick, pc);
    }

    /// At a boot: `self` (the last box) becomes `live`'s record, if `live` holds one,
    /// with the reset's cause; then `live` starts again.
    pub fn keep(&mut self, live: &mut Self, reset_flags: u32) {
        if live.kept() {
            // Field by field: the ring by one memcpy.
            self.mark = live.mark;
            self.reset_flags = reset_flags;
            self.stop = live.stop;
            self.end = live.end;
            self.stopped = live.stopped;
            self.now = live.now;
            self.next = live.next;
            self.filled = live.filled;
            self.ticks.copy_from_slice(&live.ticks);
        } else {
            self.mark = 0;
        }
        live.start();
    }

    /// What stopped the run (`StopCause::None` while it runs, or if nothing did).
    pub fn cause(&self) -> StopCause {
        if self.stopped == 0 {
            return StopCause::None;
        }
        StopCause::from_code(self.stop.cause).unwrap_or_default()
    }

    /// The stop as kept.
    pub fn stop_record(&self) -> BoxStop {
        self.stop
    }

    /// How the run ended (`StopCause::None`: not by a fault handler or a panic), and
    /// its record.
    pub fn ended(&self) -> (StopCause, BoxStop) {
        let cause = StopCause::from_code(self.end.cause).unwrap_or_default();
        (cause, self.end)
    }

    /// The reset's cause after the run, as the chip reported it.
    pub fn reset_flags(&self) -> u32 {
        self.reset_flags
    }

    /// Ticks kept.
    pub fn len(&self) -> usize {
        (self.filled as usize).min(N)
    }

    /// Whether no tick is kept.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The `i`-th tick kept, oldest first.
    pub fn tick(&self, i: usize) -> Option<BoxTick> {
        let len = self.len();
        if i >= len {
            return None;
        }
        // The oldest is at `next` once the ring has wrapped, else at 0.
        let oldest = if len == N { self.next as usize } else { 0 };
        let at = oldest + i;
        self.ticks.get(if at >= N { at - N } else { at }).copied()
    }

    /// The part of the box from tick `first` on, as the link carries it (an unkept box:
    /// `kept` false, the rest zero).
    pub fn part(&self, first: u16) -> BlackBoxPart {
        if !self.kept() {
            return BlackBoxPart::default();
        }
        let mut part_ticks = [BoxTick::default(); BOX_PART];
        for (k, t) in part_ticks.iter_mut().enumerate() {
            if let Some(tick) = self.tick(first as usize + k) {
                *t = tick;
            }
        }
        let (stop, (end, end_at)) = (self.stop, self.ended());
        BlackBoxPart {
            kept: true,
            reset_flags: self.reset_flags,
            cause: self.cause(),
            part: stop.part,
            tick: stop.tick,
            end,
            end_tick: end_at.tick,
            pc: end_at.pc,
            ticks: self.len() as u16,
            first,
            part_ticks,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tick(t: u32) -> BoxTick {
        BoxTick {
            tick: t,
            counts: [t as i32, -(t as i32), 7],
            ..BoxTick::default()
        }
    }

    #[test]
    fn the_ring_keeps_the_last_n_ticks_oldest_first_until_stopped() {
        let mut live = BlackBox::<5>::EMPTY;
        live.record(tick(1));
        assert!(live.is_empty(), "an unstarted box records nothing");
        live.start();
        for t in 0..3 {
            live.record(tick(t));
        }
        assert_eq!(
            (0..3)
                .map(|i| live.tick(i).unwrap().tick)
                .collect::<Vec<_>>(),
            [0, 1, 2]
        );
        for t in 3..12 {
            live.record(tick(t));
        }
        assert_eq!(live.len(), 5);
        assert_eq!(
            (0..5)
                .map(|i| live.tick(i).unwrap().tick)
                .collect::<Vec<_>>(),
            [7, 8, 9, 10, 11]
        );
        assert_eq!(live.tick(5), None);
        assert_eq!(live.cause(), StopCause::None);
        live.stop(StopCause::Read, 3, 11, 0);
        live.stop(StopCause::Overruns, 0, 12, 0);
        live.record(tick(12));
        assert_eq!(live.tick(4).unwrap().tick, 11, "frozen at the stop");
        assert_eq!(live.cause(), StopCause::Read, "the first stop stays");
        // A HardFault later ends the run: kept as its end, with its PC and tick; the
        // stop stays the first.
        live.end(StopCause::HardFault, 0x0800_1234);
        live.end(StopCause::Panic, 0);
        let p = live.part(0);
        assert_eq!((p.cause, p.part, p.tick), (StopCause::Read, 3, 11));
        assert_eq!(
            (p.end, p.end_tick, p.pc),
            (StopCause::HardFault, 12, 0x0800_1234)
        );
        assert_eq!(live.len(), 5, "the ring stayed frozen");
        // A handler that is the first stop is both.
        let mut other = BlackBox::<5>::EMPTY;
        other.start();
        other.record(tick(0));
        other.end(StopCause::UsageFault, 0);
        assert_eq!(
            (other.cause(), other.stop_record().tick),
            (StopCause::UsageFault, 0)
        );
    }

    #[test]
    fn a_boot_keeps_the_live_record_as_the_last_and_starts_again() {
        let (mut last, mut live) = (BlackBox::<5>::EMPTY, BlackBox::<5>::EMPTY);
        // A power-on: nothing marked, nothing kept.
        last.keep(&mut live, 0x0C00_0000);
        assert!(!last.kept());
        assert!(!last.part(0).kept);
        for t in 0..7 {
            live.record(tick(t));
        }
        live.stop(StopCause::Read, 12, 6, 0);
        last.keep(&mut live, 0x2000_0000);
        assert!(last.kept() && live.kept() && live.is_empty());
        let p = last.part(3);
        assert_eq!(
            (p.cause, p.part, p.tick, p.reset_flags),
            (StopCause::Read, 12, 6, 0x2000_0000)
        );
        assert_eq!((p.ticks, p.first), (5, 3));
        assert_eq!(p.part_ticks.map(|t| t.tick), [5, 6, 0, 0]);
        // The next boot without a stop: the run kept, nothing stopped it.
        live.record(tick(0));
        last.keep(&mut live, 0);
        assert_eq!((last.cause(), last.len()), (StopCause::None, 1));
    }

    #[test]
    fn noise_in_memory_is_not_a_record() {
        // Any bits: the mark wrong, or the indices out of range.
        let mut b = BlackBox::<5>::EMPTY;
        b.start();
        b.next = 5;
        assert!(!b.kept());
        b.next = 0;
        b.filled = 6;
        assert!(!b.kept());
        b.filled = 5;
        b.stopped = 1;
        b.stop.cause = 200;
        assert!(b.kept());
        assert_eq!(b.cause(), StopCause::None, "an unknown cause reads as none");
    }

    #[test]
    fn a_part_fits_one_frame_at_its_largest() {
        let mut part = BlackBoxPart {
            kept: true,
            reset_flags: u32::MAX,
            cause: StopCause::UsageFault,
            part: u8::MAX,
            tick: u32::MAX,
            pc: u32::MAX,
            ticks: u16::MAX,
            first: u16::MAX,
            ..BlackBoxPart::default()
        };
        part.part_ticks = [BoxTick {
            tick: u32::MAX,
            counts: [i32::MIN; 3],
            force_mn: [i16::MIN; 3],
            duty_q15: [i16::MIN; 3],
            gain: u16::MAX,
            flags: u16::MAX,
        }; BOX_PART];
        let mut out = [0u8; mccs_link::MAX_FRAME];
        let n = mccs_link::encode(&mccs_link::ToHost::BlackBox(part), &mut out);
        assert!(n.is_ok(), "{n:?}");
    }
}
