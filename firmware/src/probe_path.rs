//! `ProbePath`: a probe trajectory through waypoints, replayed tick by tick in fixed
//! point — the simulated device of the demo firmware and of the tests.
//!
//! Between waypoints the probe moves along a smoothstep `3t² − 2t³` (zero velocity at
//! each waypoint). Per tick: a scan over at most `K` waypoints and four multiplies; the
//! reciprocal of each leg's duration is computed when the path is built.

use mccs::q;
use mccs::units::{from_f64, Length, LEN_FRAC};

/// A waypoint: tick number and probe position (mm, patch frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Waypoint {
    /// Tick at which the probe is here.
    pub tick: u32,
    /// Position, mm.
    pub position: [f64; 3],
}

/// A trajectory through up to `K` waypoints with strictly increasing ticks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ProbePath<const K: usize> {
    ticks: [u32; K],
    points: [[i32; 3]; K],
    /// `2^32 / (tick[i+1] − tick[i])`.
    inv_len: [u64; K],
    len: usize,
}

/// Why a path could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathError {
    /// No waypoint, or more than `K`.
    Count,
    /// Ticks not strictly increasing.
    Order,
    /// A position not finite or beyond ±100 mm.
    Position,
}

impl PathError {
    /// The message: one source for `Display` and the `defmt` impl.
    pub const fn message(&self) -> &'static str {
        match self {
            Self::Count => "path: no waypoint, or too many",
            Self::Order => "path: ticks not increasing",
            Self::Position => "path: a position not finite or beyond ±100 mm",
        }
    }
}

impl core::fmt::Display for PathError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.message())
    }
}

impl<const K: usize> ProbePath<K> {
    /// Builds the path.
    pub fn new(waypoints: &[Waypoint]) -> Result<Self, PathError> {
        if waypoints.is_empty() || waypoints.len() > K {
            return Err(PathError::Count);
        }
        let mut p = Self {
            ticks: [0; K],
            points: [[0; 3]; K],
            inv_len: [0; K],
            len: waypoints.len(),
        };
        for (i, w) in waypoints.iter().enumerate() {
            if w.position.iter().any(|x| !x.is_finite() || x.abs() > 100.0) {
                return Err(PathError::Position);
            }
            if i > 0 && w.tick <= waypoints[i - 1].tick {
                return Err(PathError::Order);
            }
            p.ticks[i] = w.tick;
            p.points[i] = w.position.map(|x| from_f64(x, LEN_FRAC));
            if i > 0 {
                p.inv_len[i - 1] = (1u64 << 32) / (w.tick - waypoints[i - 1].tick) as u64;
            }
        }
        Ok(p)
    }

    /// The last waypoint's tick.
    pub fn end_tick(&self) -> u32 {
        self.ticks
            .get(self.len.wrapping_sub(1))
            .copied()
            .unwrap_or(0)
    }

    /// Probe position at `tick` (before the first waypoint: the first; after the last:
    /// the last).
    pub fn at(&self, tick: u32) -> [Length; 3] {
        let mut out = self.points.first().copied().unwrap_or([0; 3]);
        for i in 0..self.len.min(K) {
            let (Some(&t0), Some(&p0)) = (self.ticks.get(i), self.points.get(i)) else {
                break;
            };
            if tick < t0 {
                break;
            }
            out = p0;
            let (Some(&t1), Some(&p1), Some(&inv)) = (
                self.ticks.get(i + 1),
                self.points.get(i + 1),
                self.inv_len.get(i),
            ) else {
                break;
            };
            if i + 1 < self.len && tick < t1 {
                // t ∈ [0, 1) in Q32, then smoothstep s = t²(3 − 2t) in Q16.
                let t = (((tick - t0) as u64 * inv) >> 16) as i64; // Q16
                let s = (((t * t) >> 16) * ((3 << 16) - 2 * t)) >> 16;
                for k in 0..3 {
                    out[k] = q::sat(p0[k] as i64 + (((p1[k] as i64 - p0[k] as i64) * s) >> 16));
                }
                break;
            }
        }
        out.map(Length::from_bits)
    }
}

/// Builds a path from `(time in s, position in mm)` legs at `tick_hz`.
fn path_of<const K: usize>(
    legs: [(f64, [f64; 3]); K],
    tick_hz: u32,
) -> Result<ProbePath<K>, PathError> {
    ProbePath::new(&legs.map(|(s, position)| Waypoint {
        tick: (s * tick_hz as f64) as u32,
        position,
    }))
}

/// The demo's palpation (tissue frame, mm; the tissue's top at `z = 0`), 4 s at
/// `tick_hz` (waypoint times scale with it): press 1 mm deep at `x = −15` (0.3 s), hold
/// (0.2 s), slide 30 mm along `x` (1.2 s), press to 1.5 mm (0.2 s), hold (0.2 s), slide
/// back (1.2 s), lift (0.3 s), rest (0.4 s). `y = 0.4` keeps the stroke off the grid's
/// node lines.
pub fn palpation_path(tick_hz: u32) -> Result<ProbePath<9>, PathError> {
    const Y: f64 = 0.4;
    path_of(
        [
            (0.0, [-15.0, Y, 1.0]),
            (0.3, [-15.0, Y, -1.0]),
            (0.5, [-15.0, Y, -1.0]),
            (1.7, [15.0, Y, -1.0]),
            (1.9, [15.0, Y, -1.5]),
            (2.1, [15.0, Y, -1.5]),
            (3.3, [-15.0, Y, -1.5]),
            (3.6, [-15.0, Y, 1.0]),
            (4.0, [-15.0, Y, 1.0]),
        ],
        tick_hz,
    )
}

/// An indentation over the glued contact node (patch frame, mm), 2 s at `tick_hz`:
/// approach, press to 1.2 mm below the surface, hold, a 2 mm stroke along `x` (which
/// drags the glued node), release.
pub fn indentation_path(tick_hz: u32) -> Result<ProbePath<7>, PathError> {
    path_of(
        [
            (0.0, [0.0, 0.0, 1.0]),
            (0.3, [0.0, 0.0, 0.0]),
            (0.7, [0.0, 0.0, -1.2]),
            (1.0, [0.0, 0.0, -1.2]),
            (1.5, [2.0, 0.0, -1.2]),
            (1.8, [2.0, 0.0, 1.0]),
            (2.0, [2.0, 0.0, 1.0]),
        ],
        tick_hz,
    )
}
