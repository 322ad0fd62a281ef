//! [`PassivityObserver`]: the energy the rendered force has put into the hand, watched
//! tick by tick (Hannaford and Ryu's passivity observer, on the probe's coupling). A
//! passive tissue gives back at most what the hand put in: pressed, it takes energy;
//! released, it returns what it stored, less what its damping and friction took. A tissue
//! whose solver has gone unstable, a force rendered with the wrong sign or too stiff a
//! coupling for the delay, puts out more, tick after tick.
//!
//! Each tick the work the force did on the probe over its last move, by the trapezoid
//! `W = ½ (F(k−1) + F(k)) · (x(k) − x(k−1))` (N·mm = mJ), is taken from the energy the
//! observer holds, `E`. The trapezoid, not the force held over the move (`F(k−1)`):
//! positions come in whole encoder counts, and a probe at rest on a count's edge reads a
//! one-count dither; with the held force each flip back and forth counted as output (a
//! spring's `k q²`, the coupling damper's `b q²/T`), and a press held still tripped the
//! observer in 2.5 s where nothing really moved (`tests::a_one_count_dither_…`; on the
//! simulated arm, `tests/arm_dynamics.rs`, a still press did too). The trapezoid counts a
//! dither's flips as nothing, steady motion against a damper as taken in, and a force
//! along the motion as put out.
//!
//! Out of contact (no force) `E` is held to a *credit*: what the hand's input before this
//! contact may pay for (a tissue still settling, a new touch). In contact it is not
//! held, so that a release, which gives back what the press stored, is not taken for
//! output however deep the press went: held to the credit in contact too, a loosely held
//! 0.5 kg hand that hit the simulated arm's tissue at 0.35 m/s, 10 mm deep, tripped the
//! observer on the way back out (`tests/arm_dynamics.rs`'s palpation holds every hand;
//! here, `tests::a_press_deeper_than_the_credit_released_never_trips`). A deficit
//! (`E < 0`) is forgiven over [`WINDOW_SHIFT`]'s 4,096 ticks (the held force's own small
//! activity, rounding). `E < −trip` is energy put out beyond the hand's input: the
//! observer trips, and stays tripped until [`PassivityObserver::reset`]. (A leak of the
//! credit too was tried: it forgets what a slow press stores before the release gives it
//! back, and a passive tissue pressed at 0.5 Hz went 1.5 mJ into deficit.)
//!
//! # Range and cost
//! Forces are ±2,048 N (I12F20) and a move per tick ±128 mm (I8F24, its difference
//! saturated); a tick's work is under 2⁴³ in Q24 mJ, the energy is held to 2³⁶ mJ above
//! and by the leak to 2³² mJ below, so no `i64` here can overflow. Three 32 × 32 → 64
//! multiply-accumulates, shifts, a clamp and a compare a tick: no division, no float, no
//! panic path. The bench's `passivity_observer` case measures it (docs/safety.md quotes
//! it).

use crate::units::{Force, Length};

/// When the observer trips.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PassivityLimits {
    /// The energy below which it trips: minus the trip, Q24 mJ (< 0).
    floor_q24: i64,
    /// Out of contact, the most the hand's past input may pay for later output, Q24 mJ
    /// (≥ 0): what a tissue still settling may give back on the next touch, no more
    /// than needed (a fault at a touch with the credit full puts out `credit + trip`
    /// before it trips). In contact the hand's input is not held to it.
    credit_q24: i64,
}

impl PassivityLimits {
    /// `trip_mj` put out beyond `credit_mj` of earlier input trips it (each held to
    /// 2⁻²⁴ … 2²⁶ mJ; the credit may be 0). Start-up (floating point).
    pub fn new(trip_mj: f64, credit_mj: f64) -> Self {
        let q24 = |mj: f64, least: f64| {
            let q = mj * (1u64 << 24) as f64;
            // (NaN: the least.)
            if q >= least {
                q.min((1u64 << 50) as f64) as i64
            } else {
                least as i64
            }
        };
        Self {
            floor_q24: -q24(trip_mj, 1.0),
            credit_q24: q24(credit_mj, 0.0),
        }
    }

    /// The trip, mJ.
    pub fn trip_mj(&self) -> f64 {
        -self.floor_q24 as f64 / (1u64 << 24) as f64
    }

    /// The credit, mJ.
    pub fn credit_mj(&self) -> f64 {
        self.credit_q24 as f64 / (1u64 << 24) as f64
    }
}

/// A deficit is forgiven by `E >> WINDOW_SHIFT` a tick: over 4,096 ticks (4 s at 1 kHz).
pub const WINDOW_SHIFT: u32 = 12;

/// The observer's state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PassivityObserver {
    /// The energy the hand has put in, held to the credit out of contact, Q24 mJ
    /// (negative: put out).
    energy_q24: i64,
    /// The probe at the last tick (zero before the first: its work is 0).
    last_probe: [Length; 3],
    /// A quarter of the force at the last tick, Q20 N (the trapezoid's half, and the
    /// room its products need, taken once).
    last_quarter_force: [i32; 3],
    tripped: bool,
}

/// The most the energy is held to in contact, Q24 mJ (2³⁶ mJ: far past any press; with
/// a tick's work under 2⁴³, nothing here can overflow an `i64`).
const HELD: i64 = 1 << 60;

impl PassivityObserver {
    /// A tick: the probe now and the force rendered from now to the next tick (the same
    /// frame, N and mm). Returns whether the observer has tripped (now or before).
    #[inline(always)]
    pub fn tick(&mut self, probe: [Length; 3], force: [Force; 3], limits: PassivityLimits) -> bool {
        // The work over the last move: the two forces' mean (their quarters' sum: the
        // mean in Q19 N, |f| ≤ 2³⁰) times the move (Q24 mm, |dx| ≤ 2³¹), summed over the
        // axes in Q43 (each product under 2⁶¹, the sum under 2⁶³: one multiply-accumulate
        // an axis), then ≫ 19 = Q24 mJ (|work| < 2⁴³).
        let quarter = force.map(|f| f.to_bits() >> 2);
        let mut work_q43: i64 = 0;
        for i in 0..3 {
            let dx = probe[i]
                .to_bits()
                .saturating_sub(self.last_probe[i].to_bits());
            let f = self.last_quarter_force[i] + quarter[i];
            work_q43 += f as i64 * dx as i64;
        }
        let work_q24 = work_q43 >> 19;
        // Only a deficit is forgiven, slowly (the held force's small activity, the
        // rounding); a credit is not forgotten while the tissue stores it, but held to
        // the limit.
        let leak = self.energy_q24.min(0) >> WINDOW_SHIFT;
        // In contact (a force), all the hand has put in may come back; out of it, no
        // more than the credit.
        let ceiling = if (force[0].to_bits() | force[1].to_bits() | force[2].to_bits()) == 0 {
            limits.credit_q24
        } else {
            HELD
        };
        // (No floor is needed: the leak holds a deficit within 4,097 ticks' work, < 2⁵⁶.)
        self.energy_q24 = (self.energy_q24 - leak - work_q24).min(ceiling);
        self.last_probe = probe;
        self.last_quarter_force = quarter;
        self.tripped |= self.energy_q24 < limits.floor_q24;
        self.tripped
    }

    /// Whether it has tripped.
    pub fn tripped(&self) -> bool {
        self.tripped
    }

    /// The energy the hand has put in, held to the credit out of contact, mJ (negative:
    /// the device put it out).
    pub fn energy_mj(&self) -> f64 {
        self.energy_q24 as f64 / (1u64 << 24) as f64
    }

    /// Forgets everything: not tripped, no energy, no last tick (after the device's
    /// safe state, before force comes back).
    pub fn reset(&mut self) {
        *self = Self::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mm(x: f64) -> Length {
        Length::from_num(x)
    }
    fn n(x: f64) -> Force {
        Force::from_num(x)
    }
    const LIMITS: PassivityLimits = PassivityLimits {
        floor_q24: -(2 << 24),
        credit_q24: 10 << 24,
    };

    /// A tissue of `k` N/mm and the patch's 1 N·s/m under the probe (z < 0 in the
    /// tissue), its force held over each 1 ms tick, pressed and released by a hand moving
    /// sinusoidally `depth` mm deep, `hz` times a second; the lowest energy seen.
    fn press(o: &mut PassivityObserver, k: f64, depth: f64, hz: f64, seconds: f64) -> (bool, f64) {
        let ticks = (seconds * 1000.0) as usize;
        let w = 2.0 * core::f64::consts::PI * hz;
        let mut lowest = 0.0f64;
        for t in 0..ticks {
            let s = t as f64 / 1000.0;
            let z = -depth * (0.5 - 0.5 * (w * s).cos());
            let v = -depth * 0.5 * w * (w * s).sin();
            let f = if z < 0.0 { -k * z - 0.001 * v } else { 0.0 };
            if o.tick([mm(0.0), mm(0.0), mm(z)], [n(0.0), n(0.0), n(f)], LIMITS) {
                return (true, o.energy_mj());
            }
            lowest = lowest.min(o.energy_mj());
        }
        (false, lowest)
    }

    #[test]
    fn a_passive_tissue_pressed_for_a_minute_never_trips() {
        // 0.5 N/mm, 4 mm deep (8 mJ stored at the bottom) at 0.5, 2 and 5 Hz; and the
        // force clamp's 3 N held 6 mm deep (9 mJ), slowly.
        for hz in [0.5, 2.0, 5.0] {
            let mut o = PassivityObserver::default();
            let (tripped, lowest) = press(&mut o, 0.5, 4.0, hz, 60.0);
            assert!(!tripped && lowest > -1.0, "{hz} Hz: lowest {lowest} mJ");
        }
        let mut o = PassivityObserver::default();
        let (tripped, lowest) = press(&mut o, 0.5, 6.0, 0.5, 30.0);
        assert!(!tripped && lowest > -1.0, "lowest {lowest} mJ");
    }

    /// A probe at rest on an encoder count's edge (64 µm) reads a dither, flipping every
    /// 3 to 7 ticks, for a minute; the force a 2 N/mm spring and a 2 N·s/m damper (on
    /// the one-tick difference) render from it, pressed 1 mm deep. Nothing really moves:
    /// it never trips. (Counted with the force held over each move, it tripped in 2.5 s.)
    #[test]
    fn a_one_count_dither_under_a_held_press_never_trips() {
        let (q, k, b) = (0.064, 2.0, 0.002);
        let mut o = PassivityObserver::default();
        let mut z = -1.0;
        let mut last = z;
        let mut lowest = 0.0f64;
        for t in 0..60_000u32 {
            if t % (3 + (t / 7) % 5) == 0 {
                z = if z < -1.0 + q / 2.0 { -1.0 + q } else { -1.0 };
            }
            let f = -k * z - b * (z - last) * 1000.0;
            last = z;
            let tripped = o.tick([mm(0.0), mm(0.0), mm(z)], [n(0.0), n(0.0), n(f)], LIMITS);
            assert!(!tripped, "tick {t}: {} mJ", o.energy_mj());
            lowest = lowest.min(o.energy_mj());
        }
        assert!(lowest > -0.1, "lowest {lowest} mJ");
    }

    /// A press deeper than the credit: 3 N held over 10 mm stores 30 mJ; the release
    /// gives 25 mJ back (the tissue's damping kept 5). In contact nothing is held to
    /// the credit: it never trips. (Held to the 10 mJ credit, it tripped 5 mm into the
    /// release.)
    #[test]
    fn a_press_deeper_than_the_credit_released_never_trips() {
        let mut o = PassivityObserver::default();
        let z = [n(0.0), n(0.0)];
        for t in 0..=100 {
            let at = [mm(0.0), mm(0.0), mm(-0.1 * t as f64)];
            assert!(!o.tick(at, [z[0], z[1], n(3.0)], LIMITS));
        }
        for t in (0..=100).rev() {
            let at = [mm(0.0), mm(0.0), mm(-0.1 * t as f64)];
            let tripped = o.tick(at, [z[0], z[1], n(2.5)], LIMITS);
            assert!(
                !tripped,
                "{} mm out: {} mJ",
                10.0 - 0.1 * t as f64,
                o.energy_mj()
            );
        }
        assert!((o.energy_mj() - 5.0).abs() < 0.1, "{}", o.energy_mj());
    }

    #[test]
    fn a_force_that_pushes_along_the_motion_trips_and_a_reset_forgets() {
        // A negative damper, F = +b v (b = 0.05 N·s/mm), on a hand moving 2 mm at 2 Hz:
        // about 16 mW out, sustained.
        let mut o = PassivityObserver::default();
        let z = |t: f64| -2.0 * (2.0 * core::f64::consts::PI * 2.0 * t).sin();
        let mut tripped_at = None;
        for t in 0..3000 {
            let s = t as f64 / 1000.0;
            let v = (z(s + 0.0005) - z(s - 0.0005)) * 1000.0; // mm/s
            if o.tick(
                [mm(0.0), mm(0.0), mm(z(s))],
                [n(0.0), n(0.0), n(0.05 * v)],
                LIMITS,
            ) {
                tripped_at = Some(t);
                break;
            }
        }
        assert!(tripped_at.is_some_and(|t| t < 1500), "{tripped_at:?}");
        o.reset();
        assert!(!o.tripped() && o.energy_mj() == 0.0);
    }

    /// A hand (0.2 kg, held 1 mm into the tissue by its own 0.2 N/mm and 2 N·s/m) on a
    /// tissue of 0.5 N/mm rendered with its sign reversed: the device pulls the hand in,
    /// faster and faster. `credit` mJ put in before: where it trips, (ms, mm deep).
    fn reversed_sign(credit: f64) -> Option<(usize, f64)> {
        let (m, k_hand, c_hand, k) = (0.2, 200.0, 2.0, 500.0); // kg, N/m, N·s/m, N/m
        let (mut z, mut v) = (-0.001f64, 0.0f64); // m, m/s
        let mut o = PassivityObserver::default();
        o.tick([mm(0.0); 3], [n(-credit), n(0.0), n(0.0)], LIMITS);
        o.tick(
            [mm(1.0), mm(0.0), mm(0.0)],
            [n(-credit), n(0.0), n(0.0)],
            LIMITS,
        );
        let dt = 1e-3;
        for t in 0..1000 {
            let device = if z < 0.0 { k * z } else { 0.0 }; // reversed: pulls in, N
            let hand = -k_hand * (z + 0.001) - c_hand * v;
            let at = [mm(1.0), mm(0.0), mm(z * 1e3)];
            if o.tick(at, [n(0.0), n(0.0), n(device)], LIMITS) {
                return Some((t, -z * 1e3));
            }
            // The force held over the tick (semi-implicit Euler, 10 steps a tick).
            for _ in 0..10 {
                v += (device + hand) / m * dt / 10.0;
                z += v * dt / 10.0;
            }
        }
        None
    }

    #[test]
    fn a_reversed_sign_pulling_a_hand_in_trips_within_50_ms_and_20_mm() {
        let (ms, depth) = reversed_sign(0.0).expect("trips");
        std::println!("PASSIVITY case=reversed_sign start=rest trip_ms={ms} depth_mm={depth:.1}");
        assert!(ms <= 50 && depth < 20.0, "{ms} ms, {depth} mm");
        // With the credit full (10 mJ put in just before): later, deeper.
        let (ms, depth) = reversed_sign(10.0).expect("trips");
        std::println!(
            "PASSIVITY case=reversed_sign start=credit_full trip_ms={ms} depth_mm={depth:.1}"
        );
        assert!(ms <= 80 && depth < 20.0, "{ms} ms, {depth} mm");
    }

    #[test]
    fn the_credit_is_held_to_its_bound_and_a_deficit_is_forgiven_over_the_window() {
        let mut o = PassivityObserver::default();
        let x = |mm_x: f64| [mm(mm_x), mm(0.0), mm(0.0)];
        let fx = |n_x: f64| [n(n_x), n(0.0), n(0.0)];
        // 8 mJ put in (pushed 4 mm against 2 N), then 40 mJ more: in contact, all 48 mJ
        // are held (a release may give them back); out of contact, the credit, 10 mJ.
        o.tick(x(0.0), fx(-2.0), LIMITS);
        o.tick(x(4.0), fx(-2.0), LIMITS);
        assert!((o.energy_mj() - 8.0).abs() < 1e-3, "{}", o.energy_mj());
        o.tick(x(4.0), fx(-4.0), LIMITS);
        o.tick(x(14.0), fx(-4.0), LIMITS);
        assert!((o.energy_mj() - 48.0).abs() < 1e-3, "{}", o.energy_mj());
        o.tick(x(14.0), fx(0.0), LIMITS);
        assert!((o.energy_mj() - 10.0).abs() < 1e-3, "{}", o.energy_mj());
        // Resting, the credit stays (the tissue may still hold it).
        for _ in 0..10_000 {
            o.tick(x(14.0), fx(0.0), LIMITS);
        }
        assert!((o.energy_mj() - 10.0).abs() < 1e-3, "{}", o.energy_mj());
        // 11.5 mJ out: 1.5 beyond the credit, under the trip; forgiven over the window.
        o.tick(x(14.0), fx(1.15), LIMITS);
        assert!(!o.tick(x(24.0), fx(1.15), LIMITS));
        assert!((o.energy_mj() + 1.5).abs() < 1e-3, "{}", o.energy_mj());
        for _ in 0..40_000 {
            o.tick(x(24.0), fx(0.0), LIMITS);
        }
        assert!(o.energy_mj().abs() < 0.01, "{}", o.energy_mj());
        // Then 3 mJ out at once: trips.
        o.tick(x(24.0), fx(1.5), LIMITS);
        assert!(o.tick(x(26.0), fx(1.5), LIMITS));
    }

    #[test]
    fn extremes_saturate_and_never_panic() {
        let mut o = PassivityObserver::default();
        for (x, f) in [
            (Length::MAX, Force::MAX),
            (Length::MIN, Force::MAX),
            (Length::MAX, Force::MIN),
        ] {
            o.tick([x; 3], [f; 3], LIMITS);
        }
        assert!(o.tripped());
        let e = o.energy_mj();
        assert!(e.is_finite() && e.abs() <= (HELD as f64) / (1u64 << 24) as f64);
    }

    #[test]
    fn limits_from_millijoules() {
        let l = PassivityLimits::new(2.0, 10.0);
        assert_eq!(l, LIMITS);
        assert_eq!((l.trip_mj(), l.credit_mj()), (2.0, 10.0));
        let odd = PassivityLimits::new(-1.0, f64::NAN);
        assert_eq!((odd.floor_q24, odd.credit_q24), (-1, 0));
        let huge = PassivityLimits::new(1e300, 1e300);
        assert_eq!((huge.floor_q24, huge.credit_q24), (-(1 << 50), 1 << 50));
    }
}
