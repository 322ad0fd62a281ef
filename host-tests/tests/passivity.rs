//! The passivity observer (`mccs::passivity`) over arbitrary runs, against its `f64`
//! twin: the trapezoid's work, the credit held out of contact, the deficit forgiven over
//! 4,096 ticks, the trip, and the reset. Its unit tests hold the physical cases (a press
//! held for a minute, a dither, a reversed sign); these hold the arithmetic over the
//! whole input domain, where a wrong shift or an overflow would hide.

use mccs::passivity::WINDOW_SHIFT;
use mccs::{Force, Length, PassivityLimits, PassivityObserver};
use proptest::prelude::*;

/// One tick's input as the fixed point's bits: the probe (Q24 mm) and the force (Q20 N).
#[derive(Clone, Copy, Debug)]
struct Tick {
    probe: [i32; 3],
    force: [i32; 3],
}

/// The observer's rules in `f64` (mJ, mm, N), from its documentation: each tick the
/// energy less the leak of a deficit (`E / 4096`) less the trapezoid's work, held to the
/// credit where the force is zero (the trip is the test's: where the twin's energy
/// passes it).
#[derive(Default)]
struct Twin {
    energy: f64,
    /// The last probe's bits (the observer's own, so that its moves are the same).
    last_probe: [i32; 3],
    last_force: [f64; 3],
}

/// The move a tick, as the observer takes it: the difference of the two probes' bits,
/// saturated to an `i32` (±128 mm).
fn moved(now: i32, last: i32) -> f64 {
    now.saturating_sub(last) as f64 / (1u64 << 24) as f64
}

impl Twin {
    fn tick(&mut self, t: Tick, credit: f64) -> f64 {
        let p = t.probe;
        let f = t.force.map(|b| b as f64 / (1u64 << 20) as f64);
        let dx: [f64; 3] = std::array::from_fn(|i| moved(p[i], self.last_probe[i]));
        let work: f64 = (0..3)
            .map(|i| 0.5 * (self.last_force[i] + f[i]) * dx[i])
            .sum();
        let leak = self.energy.min(0.0) / (1u64 << WINDOW_SHIFT) as f64;
        let ceiling = if t.force == [0; 3] {
            credit
        } else {
            f64::INFINITY
        };
        self.energy = (self.energy - leak - work).min(ceiling);
        self.last_probe = p;
        self.last_force = f;
        // How far the observer may be from the twin after this tick, at most: each force's
        // quarter drops its 2 low bits (2⁻¹⁸ N on the mean, an axis), the work and the
        // leak round down to 2⁻²⁴ mJ each.
        let per_axis = (0..3).map(|i| dx[i].abs() * 2f64.powi(-18)).sum::<f64>();
        per_axis + 2.0 * 2f64.powi(-24)
    }
}

fn fixed(t: Tick) -> ([Length; 3], [Force; 3]) {
    (
        t.probe.map(Length::from_bits),
        t.force.map(Force::from_bits),
    )
}

/// A probe's move of up to `mm` an axis, a tick, and a force of up to `n` an axis, zero
/// (out of contact) on about a third of the ticks.
fn ticks(mm: f64, n: f64, most: usize) -> impl Strategy<Value = Vec<Tick>> {
    let step = (mm * (1u64 << 24) as f64) as i32;
    let force = (n * (1u64 << 20) as f64) as i32;
    prop::collection::vec(
        (
            prop::array::uniform3(-step..=step),
            prop::array::uniform3(-force..=force),
            0u8..3,
        ),
        1..most,
    )
    .prop_map(|steps| {
        let mut probe = [0i32; 3];
        steps
            .into_iter()
            .map(|(dx, f, zero)| {
                // (Held within ±100 mm: the core's tissue; past it the sums saturate.)
                for i in 0..3 {
                    probe[i] = (probe[i] + dx[i]).clamp(-100 << 24, 100 << 24);
                }
                Tick {
                    probe,
                    force: if zero == 0 { [0; 3] } else { f },
                }
            })
            .collect()
    })
}

/// Any bits at all: positions and forces over their whole range, jumps of 256 mm.
fn any_ticks() -> impl Strategy<Value = Vec<Tick>> {
    prop::collection::vec(
        (
            prop::array::uniform3(prop_oneof![any::<i32>(), Just(i32::MIN), Just(i32::MAX)]),
            prop::array::uniform3(prop_oneof![
                any::<i32>(),
                Just(i32::MIN),
                Just(i32::MAX),
                Just(0)
            ]),
        ),
        1..200,
    )
    .prop_map(|v| {
        v.into_iter()
            .map(|(probe, force)| Tick { probe, force })
            .collect()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1024))]

    /// Over a run of realistic moves (2 mm an axis a tick: 2 m/s) and forces (±50 N),
    /// the energy is the twin's within the rounding the observer's documentation names,
    /// summed over the ticks; it trips where the twin is clearly below the trip, never
    /// where the twin is clearly above it; and once tripped it stays so.
    #[test]
    fn the_observer_follows_its_f64_twin(
        run in ticks(2.0, 50.0, 400),
        trip in 0.01f64..50.0,
        credit in 0.0f64..50.0,
    ) {
        let limits = PassivityLimits::new(trip, credit);
        let (trip, credit) = (limits.trip_mj(), limits.credit_mj());
        let (mut o, mut twin) = (PassivityObserver::default(), Twin::default());
        let (mut bound, mut was_tripped) = (0.0f64, false);
        let (mut surely, mut maybe) = (false, false);
        for (k, &t) in run.iter().enumerate() {
            let (p, f) = fixed(t);
            let tripped = o.tick(p, f, limits);
            bound += twin.tick(t, credit);
            let (e, w) = (o.energy_mj(), twin.energy);
            prop_assert!((e - w).abs() <= bound + 1e-9, "tick {}: {} against the twin's {} (bound {})", k, e, w, bound);
            if t.force == [0; 3] {
                prop_assert!(e <= credit, "tick {}: {} out of contact, over the credit {}", k, e, credit);
            }
            surely |= w < -trip - bound;
            maybe |= w < -trip + bound;
            prop_assert!(!surely || tripped, "tick {}: the twin at {} is past the trip {}", k, w, trip);
            prop_assert!(!tripped || maybe, "tick {}: tripped where the twin, {}, never neared -{}", k, w, trip);
            prop_assert!(!was_tripped || tripped, "tick {}: untripped without a reset", k);
            prop_assert_eq!(tripped, o.tripped());
            was_tripped = tripped;
        }
    }

    /// Over any bits at all, it never overflows (these tests build with overflow checks:
    /// an overflow would panic), its energy stays within what its documentation bounds
    /// (2³⁶ mJ above; below, a deficit the leak holds within 4,097 ticks' largest work,
    /// 2⁵⁶ in Q24), and a reset makes it a new observer: the same run after it gives the
    /// same energy, tick for tick.
    #[test]
    fn any_input_is_bounded_and_a_reset_forgets(
        run in any_ticks(),
        trip in 0.0f64..1e6,
        credit in 0.0f64..1e6,
    ) {
        let limits = PassivityLimits::new(trip, credit);
        let mut o = PassivityObserver::default();
        let mut energies = Vec::with_capacity(run.len());
        for &t in &run {
            let (p, f) = fixed(t);
            o.tick(p, f, limits);
            let e = o.energy_mj();
            prop_assert!(e <= 2f64.powi(36) && e >= -(2f64.powi(56 - 24)), "{}", e);
            energies.push(e);
        }
        o.reset();
        prop_assert_eq!(o, PassivityObserver::default());
        for (k, &t) in run.iter().enumerate() {
            let (p, f) = fixed(t);
            o.tick(p, f, limits);
            prop_assert_eq!(o.energy_mj(), energies[k], "tick {} after the reset", k);
        }
    }
}
