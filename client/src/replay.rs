//! A probe path replayed on a device's own solver ([`Device::replay`]): the patch and
//! solver asked for ([`mccs_link::ReplaySpec`]), the path streamed as the device grants
//! credit, one row per tick — the same rows as `mccs replay --backend fixed` with the
//! same options computes on the host.

use crate::error::Error;
use crate::session::Session;
use crate::trajectory::Trajectory;
use crate::Device;
use mccs_link::replay::PathPoint;
use mccs_link::{ReplayRow, ReplaySpec, ToDevice, ToHost};
use std::time::{Duration, Instant};

/// One replayed tick: the sample's time and position, and the device's row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReplayedTick {
    /// The sample's time, s.
    pub time_s: f64,
    /// The probe, mm.
    pub probe_mm: [f64; 3],
    /// What the device computed.
    pub row: ReplayRow,
}

/// The probe sample `p` (mm) as the core's lengths (saturated at ±128 mm): what the
/// fixed-point engines step on, on the host and on a device.
pub fn probe_bits(p: [f64; 3]) -> [mccs::Length; 3] {
    p.map(mccs::Length::saturating_from_num)
}

impl Device {
    /// Replays `path` sampled at `spec.tick_hz` on the device (`spec.samples` and
    /// `spec.start` are filled from the path); the rows in tick order. `on_row` sees each
    /// row as it arrives (a long replay's progress).
    pub fn replay(
        &self,
        path: &Trajectory,
        mut spec: ReplaySpec,
        mut on_row: impl FnMut(&ReplayedTick),
    ) -> Result<Vec<ReplayedTick>, Error> {
        let ticks: Vec<(f64, [f64; 3])> = path.ticks(spec.tick_hz).collect();
        let Some(first) = ticks.first() else {
            return Ok(Vec::new());
        };
        spec.samples = ticks.len() as u32;
        spec.start = [first.1[0], first.1[1]];
        let s = self.session();
        let (_turn, from) = s.begin();
        s.send(&ToDevice::ReplayBegin(spec))?;
        let answer = self.options().answer_timeout;
        let mut until = match s.wait(from, "the replay's start", answer, |m| {
            matches!(m, ToHost::ReplayCredit { .. }) || crate::device::replay_nak(m)
        })? {
            ToHost::ReplayCredit { until } => until,
            _ => 0,
        };
        let mut rows = Vec::with_capacity(ticks.len());
        let (mut sent, mut last) = (0usize, Instant::now());
        while rows.len() < ticks.len() {
            sent = send_path(s, &ticks, sent, until)?;
            let m = s.wait(from, "a replay row", Duration::from_millis(500), |m| {
                matches!(
                    m,
                    ToHost::ReplayRow(_) | ToHost::ReplayCredit { .. } | ToHost::ReplayEnd { .. }
                ) || crate::device::replay_nak(m)
            });
            match m {
                Ok(ToHost::ReplayRow(row)) => {
                    let k = row.tick as usize;
                    let (time_s, probe_mm) = *ticks.get(k).ok_or_else(|| Error::Unexpected {
                        addr: self.addr().to_string(),
                        what: format!("a row for tick {k}, past the path"),
                    })?;
                    let t = ReplayedTick {
                        time_s,
                        probe_mm,
                        row,
                    };
                    on_row(&t);
                    rows.push(t);
                    last = Instant::now();
                }
                Ok(ToHost::ReplayCredit { until: u }) => until = u,
                // The end before the last row (the loop ends on it): the device
                // abandoned the replay, its path late past `REPLAY_STARVED_MS`.
                Ok(ToHost::ReplayEnd { ticks: ran }) => {
                    return Err(Error::Unexpected {
                        addr: self.addr().to_string(),
                        what: format!(
                            "the device ended the replay after {ran} of {} ticks: the path did not come within {} ms",
                            ticks.len(),
                            mccs_link::rates::REPLAY_STARVED_MS
                        ),
                    })
                }
                Ok(_) => break,
                Err(Error::Timeout { .. }) if last.elapsed() < self.options().load_timeout => {}
                Err(Error::Timeout { .. }) => {
                    return Err(Error::Timeout {
                        addr: self.addr().to_string(),
                        what: "the replay's next row",
                        waited: self.options().load_timeout,
                    })
                }
                Err(e) => return Err(e),
            }
        }
        Ok(rows)
    }
}

/// The path's samples from `sent` up to the credit `until`, in frames of at most
/// [`PathPoint::PER_FRAME`]; the samples sent after them.
fn send_path(
    s: &Session,
    ticks: &[(f64, [f64; 3])],
    mut sent: usize,
    until: u32,
) -> Result<usize, Error> {
    while sent < ticks.len() && (sent as u32) < until {
        let n = (until as usize - sent)
            .min(PathPoint::PER_FRAME)
            .min(ticks.len() - sent);
        let points: Vec<u8> = ticks[sent..sent + n]
            .iter()
            .flat_map(|(_, p)| PathPoint(probe_bits(*p).map(|c| c.to_bits())).to_bytes())
            .collect();
        s.send(&ToDevice::ReplayPath {
            first: sent as u32,
            points: &points,
        })?;
        sent += n;
    }
    Ok(sent)
}
