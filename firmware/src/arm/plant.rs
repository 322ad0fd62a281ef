//! [`Plant`]: a simulated arm behind the board's own joints, driver enable and home
//! input (`haptic-f405 --features sim`), so that the board's main, tick, link and arm
//! device run unchanged in QEMU, where no encoder turns.
//!
//! The plant starts at its home pose with the home input high (the arm homes once the
//! input has been high the debounce's ticks). When the input falls it waits at home
//! [`NUDGE_TICKS`], turning each joint a count a tick the way it is driven (the board's
//! direction check nudges each joint both ways: the counts come back home), then rises
//! in joint space to [`APPROACH_HEIGHT_MM`] above the palpation's
//! first point (a path that stays above the tissue: from the folded home pose, a joint
//! path to a lower point would pass under its surface), comes straight down to that
//! point ([`APPROACH_TICKS`] in all), then its hand follows the demo's palpation on its
//! own clock,
//! over and over: press 1 mm in, slide 30 mm, press to 1.5 mm, slide back, lift off
//! (`crate::palpation_path`, which ends where it starts). The path is converted to
//! joint counts once, when the plant is built — a sample every
//! [`crate::arm::sim::SAMPLE_TICKS`] ticks by `mccs::arm::inverse` — and each tick reads
//! the counts between two samples, as the demo's simulated arm does. The plant follows
//! its path whatever force it is driven with (its loop is open); the duties and the
//! enable it is driven with are recorded.
//!
//! Its parts share the plant through a `&'static` and a critical section (one tick
//! reads and drives them all): [`Plant::joints`].

use crate::arm::device::{Joint, PartFailed};
use crate::arm::sim::{samples_for, SimArmError, SAMPLE_SHIFT, SAMPLE_TICKS};
use crate::probe_path::ProbePath;
use crate::Shared;
use mccs::ArmSpec;

/// Ticks from home to above the palpation's first point.
pub const APPROACH_TICKS: u32 = 1000;
/// Ticks the plant holds its home pose first.
pub const HOME_TICKS: u32 = 64;
/// Ticks the plant then waits at home, its home input low, each joint nudged a count a
/// tick the way a duty over [`NUDGE_MIN_PWM`] drives it (the board's direction check
/// takes 6 × 40 at 1 kHz).
pub const NUDGE_TICKS: u32 = 400;
/// The PWM counts (1 % of [`PLANT_MAX_DUTY`]) over which a duty turns a joint waiting at
/// home.
pub const NUDGE_MIN_PWM: u16 = PLANT_MAX_DUTY / 100;
/// Height above the palpation's first point the rise ends at, mm.
pub const APPROACH_HEIGHT_MM: f64 = 80.0;
/// Ticks of the approach's straight descent (the rest of it is the rise).
pub const DESCENT_TICKS: u32 = 400;
/// The palpation's ticks (4 s at 1 kHz).
pub const PALPATION_TICKS: u32 = 4000;
/// Samples the plant holds: the approach and one palpation.
pub const PLANT_SAMPLES: usize =
    samples_for(HOME_TICKS + APPROACH_TICKS) + samples_for(PALPATION_TICKS);
/// A PWM channel's full scale in the plant (the board's TIM1 at 20 kHz from 168 MHz: 8,400 steps).
pub const PLANT_MAX_DUTY: u16 = 8400;

/// What the plant's parts change each tick.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PlantState {
    /// Ticks read (joint A's read starts a tick).
    pub tick: u32,
    /// The driver is enabled.
    pub enabled: bool,
    /// Each joint's duty (PWM counts) and direction (high: the angle grows).
    pub pwm: [u16; 3],
    /// See `pwm`.
    pub forward: [bool; 3],
    /// Each joint's counts from home, as the nudges turned it.
    pub nudged: [i32; 3],
}

impl PlantState {
    /// The duties as the arm device means them, Q16 signed (zero while disabled).
    pub fn duties_q16(&self) -> [i32; 3] {
        core::array::from_fn(|k| {
            if !self.enabled {
                return 0;
            }
            let d = ((self.pwm[k] as i64) << 16) / PLANT_MAX_DUTY as i64;
            if self.forward[k] {
                d as i32
            } else {
                -(d as i32)
            }
        })
    }
}

/// A simulated arm: its path as joint-count samples, and its parts' state.
pub struct Plant {
    samples: [[i32; 3]; PLANT_SAMPLES],
    /// The approach's samples (from home); the palpation's follow.
    approach: usize,
    state: Shared<PlantState>,
}

impl Plant {
    /// The arm of `spec` at home, then approaching and palpating along `palpation`
    /// (the tissue's frame, [`PALPATION_TICKS`] long, ending where it starts).
    /// Start-up code (`f64`).
    pub fn new<const K: usize>(
        spec: &ArmSpec,
        palpation: &ProbePath<K>,
    ) -> Result<Self, SimArmError> {
        let mut samples = [[0i32; 3]; PLANT_SAMPLES];
        let device = |p: [f64; 3]| core::array::from_fn(|k| p[k] + spec.tissue_origin_mm[k]);
        let start = palpation.at(0).map(|c| c.to_num::<f64>());
        let above = [start[0], start[1], start[2] + APPROACH_HEIGHT_MM];
        let home: [i32; 3] = core::array::from_fn(|k| spec.joints[k].home_count);
        let target =
            mccs::arm::inverse::counts(spec, device(above)).ok_or(SimArmError::Unreachable(0))?;
        let approach = samples_for(HOME_TICKS + APPROACH_TICKS);
        let home_samples = (HOME_TICKS >> SAMPLE_SHIFT) as usize;
        let descent = (DESCENT_TICKS >> SAMPLE_SHIFT) as usize;
        let rise = approach - 1 - home_samples - descent;
        let smooth = |t: f64| {
            let t = t.clamp(0.0, 1.0);
            t * t * (3.0 - 2.0 * t)
        };
        for (i, s) in samples.iter_mut().enumerate().take(approach) {
            *s = if i < home_samples + rise {
                // Home, then linear in counts up to above the start.
                let t = smooth(i.saturating_sub(home_samples) as f64 / rise as f64);
                core::array::from_fn(|k| {
                    home[k] + libm::round((target[k] - home[k]) as f64 * t) as i32
                })
            } else {
                // Straight down to the start.
                let t = smooth((i - home_samples - rise) as f64 / descent as f64);
                let p = [
                    start[0],
                    start[1],
                    start[2] + APPROACH_HEIGHT_MM * (1.0 - t),
                ];
                mccs::arm::inverse::counts(spec, device(p))
                    .ok_or(SimArmError::Unreachable(i as u32))?
            };
        }
        let pal = samples_for(PALPATION_TICKS);
        for i in 0..pal {
            let tick = ((i as u32) << SAMPLE_SHIFT).min(PALPATION_TICKS);
            let p = palpation.at(tick).map(|c| c.to_num::<f64>());
            let s = samples.get_mut(approach + i).ok_or(SimArmError::TooLong)?;
            *s = mccs::arm::inverse::counts(spec, device(p))
                .ok_or(SimArmError::Unreachable(tick))?;
        }
        Ok(Self {
            samples,
            approach,
            state: Shared::new(PlantState::default()),
        })
    }

    /// The joint counts at `tick`: home (nudged by `nudged` while it waits there), the
    /// approach, then the palpation over and over; linear between two samples, to the
    /// nearest count.
    pub fn counts(&self, tick: u32, nudged: [i32; 3]) -> [i32; 3] {
        if tick < HOME_TICKS + NUDGE_TICKS {
            let home = self.samples[0];
            return core::array::from_fn(|k| home[k].wrapping_add(nudged[k]));
        }
        let tick = tick - NUDGE_TICKS;
        let lead = HOME_TICKS + APPROACH_TICKS;
        let (base, t) = if tick < lead {
            (0, tick)
        } else {
            (self.approach, (tick - lead) % PALPATION_TICKS)
        };
        let i = base + (t >> SAMPLE_SHIFT) as usize;
        let frac = (t & (SAMPLE_TICKS - 1)) as i64;
        let (Some(a), Some(b)) = (self.samples.get(i), self.samples.get(i + 1)) else {
            return self.samples.get(i).copied().unwrap_or([0; 3]);
        };
        core::array::from_fn(|k| {
            let step = (b[k] as i64 - a[k] as i64) * frac + (SAMPLE_TICKS / 2) as i64;
            (a[k] as i64 + (step >> SAMPLE_SHIFT)) as i32
        })
    }

    /// Its parts' state now.
    pub fn state(&self) -> PlantState {
        self.state.get()
    }

    /// Its three joints, its driver enable and its home input, for the arm device.
    pub fn joints(
        &'static self,
    ) -> (
        (PlantJoint<0>, PlantJoint<1>, PlantJoint<2>),
        PlantEnable,
        PlantHome,
    ) {
        (
            (PlantJoint(self), PlantJoint(self), PlantJoint(self)),
            PlantEnable(self),
            PlantHome(self),
        )
    }
}

/// Joint `J` of a [`Plant`].
#[derive(Clone, Copy)]
pub struct PlantJoint<const J: usize>(&'static Plant);

impl<const J: usize> Joint for PlantJoint<J> {
    fn read(&mut self) -> Result<u16, PartFailed> {
        let (tick, nudged) = self.0.state.update(|s| {
            let t = s.tick;
            if J == 0 {
                s.tick = s.tick.saturating_add(1);
            }
            let waiting = (HOME_TICKS..HOME_TICKS + NUDGE_TICKS).contains(&t);
            if waiting && s.enabled && s.pwm[J] > NUDGE_MIN_PWM {
                // Waiting at home: a count the way the duty drives (not the gravity
                // compensation's few counts once a nudge has turned a joint).
                s.nudged[J] += if s.forward[J] { 1 } else { -1 };
            }
            (t, s.nudged)
        });
        let counts = self.0.counts(tick, nudged);
        // A 16-bit counter, as a timer in encoder mode reads.
        Ok(counts.get(J).copied().unwrap_or(0) as u16)
    }

    fn duty(&mut self, duty: u16) -> Result<(), PartFailed> {
        self.0.state.update(|s| {
            if let Some(p) = s.pwm.get_mut(J) {
                *p = duty.min(PLANT_MAX_DUTY);
            }
        });
        Ok(())
    }

    fn direction(&mut self, forward: bool) -> Result<(), PartFailed> {
        self.0.state.update(|s| {
            if let Some(f) = s.forward.get_mut(J) {
                *f = forward;
            }
        });
        Ok(())
    }

    fn max_duty(&self) -> u16 {
        PLANT_MAX_DUTY
    }
}

/// A [`Plant`]'s driver enable.
pub struct PlantEnable(&'static Plant);

impl embedded_hal::digital::ErrorType for PlantEnable {
    type Error = core::convert::Infallible;
}

impl embedded_hal::digital::OutputPin for PlantEnable {
    fn set_low(&mut self) -> Result<(), Self::Error> {
        self.0.state.update(|s| s.enabled = false);
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), Self::Error> {
        self.0.state.update(|s| s.enabled = true);
        Ok(())
    }
}

/// A [`Plant`]'s home input: high while the plant holds its home pose.
pub struct PlantHome(&'static Plant);

impl embedded_hal::digital::ErrorType for PlantHome {
    type Error = core::convert::Infallible;
}

impl embedded_hal::digital::InputPin for PlantHome {
    fn is_high(&mut self) -> Result<bool, Self::Error> {
        Ok(self.0.state.get().tick <= HOME_TICKS)
    }
    fn is_low(&mut self) -> Result<bool, Self::Error> {
        self.is_high().map(|h| !h)
    }
}
