//! The link's force gain (`mccs_firmware::link::Guard`) over arbitrary runs: any
//! interleaving of ticks in and out of contact, frames, `Arm`, `Disarm` and restarted
//! ramps, at any times (a ramp or fade of zero ticks included), from a tick counter
//! that wraps. Each of its module's promises is checked at every tick; the example run
//! beside it (`device::force_comes_on_gently_…`) gives the figures at 1 kHz.

use mccs_firmware::link::{Guard, GuardTimes};
use mccs_link::scale::GAIN_FULL;
use proptest::prelude::*;

/// What happens between two ticks, then the tick.
#[derive(Clone, Copy, Debug)]
enum Event {
    /// `n` ticks, the probe in contact or not (a host's silence, where it is armed).
    Ticks {
        n: u32,
        contact: bool,
    },
    /// A valid frame from the host.
    Frame,
    Arm,
    Disarm,
    /// Homing done, or a fault cleared.
    Restart,
}

fn events() -> impl Strategy<Value = Vec<Event>> {
    let event = prop_oneof![
        12 => any::<bool>().prop_map(|contact| Event::Ticks { n: 1, contact }),
        2 => (2u32..400, any::<bool>()).prop_map(|(n, contact)| Event::Ticks { n, contact }),
        6 => Just(Event::Frame),
        1 => Just(Event::Arm),
        1 => Just(Event::Disarm),
        1 => Just(Event::Restart),
    ];
    prop::collection::vec(event, 1..1500)
}

/// The most a gain rises in a tick, after a ramp of `ticks` ticks (at least one).
fn ramp_step(ticks: u32) -> u16 {
    GAIN_FULL.div_ceil(ticks.max(1) as u16).max(1)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// At every tick: the gain within 0 … full; it rises by at most a ramp's step, and
    /// not at all while the probe has stayed in the tissue since the ramp began (after
    /// a start, an `Arm` from zero, a `Disarm` or a restart); it is zero while disarmed;
    /// and an armed host's silence brings it to zero and disarms the device within the
    /// timeout and the fade of its last frame.
    #[test]
    fn the_gain_keeps_the_guard_s_promises(
        run in events(),
        timeout in 0u32..150,
        fade in 0u32..40,
        ramp in 0u32..600,
        start in prop_oneof![Just(0u32), Just(u32::MAX - 1500), any::<u32>()],
    ) {
        let times = GuardTimes { timeout, fade, ramp };
        let mut g = Guard::new(times);
        let (rise, fade_ticks) = (ramp_step(ramp), GAIN_FULL.div_ceil(ramp_step(fade)) as u32);
        let mut now = start;
        let mut last = 0u16;
        // The model's facts: a host holds it armed; its last frame or `Arm`; whether the
        // probe has left the tissue since the ramp began; disarmed by the host.
        let (mut armed, mut heard, mut released, mut disarmed) = (false, start, false, false);
        let mut fading_from: Option<u16> = None;
        for (k, e) in run.iter().enumerate() {
            match *e {
                Event::Frame => {
                    g.frame(now);
                    heard = now;
                }
                Event::Arm => {
                    if fading_from.is_some() {
                        released = true;
                    }
                    g.arm(now);
                    (armed, heard, disarmed, fading_from) = (true, now, false, None);
                }
                Event::Disarm => {
                    g.disarm();
                    (armed, released, disarmed, fading_from) = (false, false, true, None);
                    last = 0;
                }
                Event::Restart => {
                    g.restart_ramp();
                    released = false;
                    last = 0;
                }
                Event::Ticks { n, contact } => for _ in 0..n {
                    let silent = now.wrapping_sub(heard);
                    if armed && silent > timeout && fading_from.is_none() {
                        fading_from = Some(last);
                    }
                    let was_released = released;
                    released |= !contact && fading_from.is_none() && !disarmed;
                    let gain = g.gain(now, contact);
                    prop_assert!(gain <= GAIN_FULL, "event {}: {}", k, gain);
                    prop_assert!(gain <= last.saturating_add(rise), "event {}: {} -> {} (step {})", k, last, gain, rise);
                    if !was_released && contact {
                        prop_assert!(gain <= last, "event {}: rose in contact, {} -> {}", k, last, gain);
                    }
                    if disarmed {
                        prop_assert_eq!(gain, 0, "event {}: disarmed", k);
                    }
                    if fading_from.is_some() {
                        prop_assert!(gain <= last, "event {}: rose while fading", k);
                    }
                    if armed && silent > timeout + fade_ticks {
                        prop_assert_eq!(gain, 0, "event {}: {} ticks silent", k, silent);
                        prop_assert!(!g.armed(), "event {}: still armed after {} ticks", k, silent);
                    }
                    if fading_from.is_some() && gain == 0 {
                        (armed, disarmed, fading_from) = (false, true, None);
                        released = false;
                    }
                    prop_assert_eq!(g.armed(), armed, "event {}", k);
                    last = gain;
                    now = now.wrapping_add(1);
                },
            }
        }
    }
}
