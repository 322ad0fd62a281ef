//! Progress lines on stderr for the runs that can take long (`fit`, `patch`, `replay`):
//! a person at a terminal hears from the command every [`period`] once it has run that
//! long, and a short run prints nothing.

use std::time::{Duration, Instant};

/// The period of the progress lines: 2 s, or `MCCS_PROGRESS_MS` milliseconds when that
/// is set (the tests' shorter period).
pub fn period() -> Duration {
    std::env::var("MCCS_PROGRESS_MS")
        .ok()
        .and_then(|v| v.parse::<u64>().ok())
        .map_or(Duration::from_secs(2), Duration::from_millis)
}

/// When a run's next progress line is due.
#[derive(Debug)]
pub struct Ticker {
    started: Instant,
    next: Duration,
    period: Duration,
}

impl Ticker {
    /// From now, every [`period`].
    pub fn new() -> Self {
        Self::every(period())
    }

    /// From now, every `period`.
    pub fn every(period: Duration) -> Self {
        Self {
            started: Instant::now(),
            next: period,
            period,
        }
    }

    /// The time since the start when a line is due (a period has passed since the last
    /// one, or the start), else `None`.
    pub fn due(&mut self) -> Option<Duration> {
        self.due_at(self.started.elapsed())
    }

    /// [`Ticker::due`] at `elapsed` since the start.
    fn due_at(&mut self, elapsed: Duration) -> Option<Duration> {
        if elapsed < self.next {
            return None;
        }
        self.next = elapsed + self.period;
        Some(elapsed)
    }
}

/// A simulated run's progress: `mccs <command>: T of TOTAL s simulated, S s so far`,
/// every [`period`].
#[derive(Debug)]
pub struct Simulated {
    command: &'static str,
    total_s: f64,
    ticker: Ticker,
}

impl Simulated {
    /// For `command` (its name in the lines), simulating `total_s` seconds.
    pub fn new(command: &'static str, total_s: f64) -> Self {
        Self {
            command,
            total_s,
            ticker: Ticker::new(),
        }
    }

    /// At simulated time `t_s`: the line, when one is due.
    pub fn at(&mut self, t_s: f64) {
        if let Some(line) = self.line(t_s) {
            eprintln!("{line}");
        }
    }

    fn line(&mut self, t_s: f64) -> Option<String> {
        let so_far = self.ticker.due()?;
        Some(format!(
            "mccs {}: {:.1} of {:.1} s simulated, {:.0} s so far",
            self.command,
            t_s,
            self.total_s,
            so_far.as_secs_f64()
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_is_due_once_per_period_from_the_first() {
        let mut t = Ticker::every(Duration::from_secs(2));
        let at = |s: f64| Duration::from_secs_f64(s);
        let due: Vec<bool> = [0.0, 1.9, 2.0, 2.5, 3.9, 4.1, 4.2, 9.0, 9.5]
            .map(|s| t.due_at(at(s)).is_some())
            .to_vec();
        assert_eq!(
            due,
            [false, false, true, false, false, true, false, true, false]
        );
    }

    #[test]
    fn a_line_names_the_command_and_the_times() {
        let mut p = Simulated {
            command: "replay",
            total_s: 600.0,
            ticker: Ticker::every(Duration::ZERO),
        };
        let line = p.line(123.456).unwrap();
        assert!(
            line.starts_with("mccs replay: 123.5 of 600.0 s simulated, ")
                && line.ends_with(" s so far"),
            "{line}"
        );
    }
}
