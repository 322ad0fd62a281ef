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

/// The demo trajectory: 2 s of approach, press, hold, stroke and release over the
/// contact node, at `tick_hz` (waypoint times scale with it). Depth 1.2 mm below the
/// surface, stroke 2 mm along `x`.
pub fn demo_path(tick_hz: u32) -> Result<ProbePath<7>, PathError> {
    // (time in s, position in mm)
    const LEGS: [(f64, [f64; 3]); 7] = [
        (0.0, [0.0, 0.0, 1.0]),
        (0.3, [0.0, 0.0, 0.0]),
        (0.7, [0.0, 0.0, -1.2]),
        (1.0, [0.0, 0.0, -1.2]),
        (1.5, [2.0, 0.0, -1.2]),
        (1.8, [2.0, 0.0, 1.0]),
        (2.0, [2.0, 0.0, 1.0]),
    ];
    ProbePath::new(&LEGS.map(|(s, position)| Waypoint {
        tick: (s * tick_hz as f64) as u32,
        position,
    }))
}
