//! The session under a [`crate::Device`]: the writer, the replies and streams the
//! background worker puts together from the device's frames, and the worker itself —
//! one thread, which reads, keeps an armed device alive (a `Keepalive` every
//! [`mccs_link::rates::KEEPALIVE_MS`] of silence) and notices a lost connection (a
//! transport error at once; on a link that cannot tell, no frame for
//! [`LIVENESS`] while armed, after a `Status` asked every [`PROBE`]). It ends with the
//! session (`stop`) or the connection; no thread outlives a `Device`.

use crate::error::{Error, Refusal};
use crate::mesh::{Mesh, MeshAssembly};
use crate::telemetry::TelemetrySample;
use crate::transport::{Reader, Writer};
use mccs_link::{encode, parse, Decoder, ToDevice, ToHost, MAX_FRAME};
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// How often an armed session asks for a `Status` to know the device is there.
pub(crate) const PROBE: Duration = Duration::from_millis(100);
/// No frame for this long from an armed device: the connection is lost.
pub(crate) const LIVENESS: Duration = Duration::from_millis(400);
/// Replies kept for a request that has not asked for them yet.
const MAX_REPLIES: usize = 4096;
/// Telemetry samples a stream holds before it drops.
const STREAM_DEPTH: usize = 4096;

/// What the worker puts together.
pub(crate) struct Shared {
    replies: VecDeque<(u64, ToHost)>,
    seq: u64,
    pub(crate) telemetry: Option<TelemetrySample>,
    streams: Vec<SyncSender<TelemetrySample>>,
    mesh: MeshAssembly,
    pub(crate) latest_mesh: Option<Mesh>,
    lost: Option<String>,
    pub(crate) armed: bool,
    last_tx: Instant,
    last_rx: Instant,
    last_probe: Instant,
    probes: u32,
    pub(crate) bad_frames: u32,
    pub(crate) stream_drops: u32,
}

/// A session with a device.
pub(crate) struct Session {
    pub(crate) addr: String,
    writer: Mutex<Writer>,
    shared: Mutex<Shared>,
    cond: Condvar,
    request: Mutex<()>,
    stop: AtomicBool,
    pub(crate) epoch: Instant,
}

impl Session {
    pub(crate) fn new(addr: String, writer: Writer) -> Arc<Session> {
        let now = Instant::now();
        Arc::new(Session {
            addr,
            writer: Mutex::new(writer),
            shared: Mutex::new(Shared {
                replies: VecDeque::new(),
                seq: 0,
                telemetry: None,
                streams: Vec::new(),
                mesh: MeshAssembly::default(),
                latest_mesh: None,
                lost: None,
                armed: false,
                last_tx: now,
                last_rx: now,
                last_probe: now,
                probes: 0,
                bad_frames: 0,
                stream_drops: 0,
            }),
            cond: Condvar::new(),
            request: Mutex::new(()),
            stop: AtomicBool::new(false),
            epoch: now,
        })
    }

    /// The shared state (a poisoned lock is taken as is: its data stays consistent,
    /// every update is one assignment).
    pub(crate) fn shared(&self) -> MutexGuard<'_, Shared> {
        self.shared.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn lost_error(&self, why: &str) -> Error {
        Error::Lost {
            addr: self.addr.clone(),
            why: why.to_string(),
        }
    }

    /// Sends one message.
    pub(crate) fn send(&self, msg: &ToDevice) -> Result<(), Error> {
        if let Some(why) = &self.shared().lost {
            return Err(self.lost_error(why));
        }
        let mut buf = [0u8; MAX_FRAME];
        let frame = encode(msg, &mut buf).map_err(|e| Error::Unexpected {
            addr: self.addr.clone(),
            what: e.message().to_string(),
        })?;
        let written = {
            let mut w = self.writer.lock().unwrap_or_else(|e| e.into_inner());
            w.write_all(frame).and_then(|()| w.flush())
        };
        let mut s = self.shared();
        match written {
            Ok(()) => {
                s.last_tx = Instant::now();
                Ok(())
            }
            Err(e) => {
                let why = e.to_string();
                s.lost = Some(why.clone());
                drop(s);
                self.cond.notify_all();
                Err(self.lost_error(&why))
            }
        }
    }

    /// Raw bytes to the device (tests' corrupted frames).
    pub(crate) fn send_raw(&self, bytes: &[u8]) -> Result<(), Error> {
        let mut w = self.writer.lock().unwrap_or_else(|e| e.into_inner());
        w.write_all(bytes)
            .and_then(|()| w.flush())
            .map_err(|e| self.lost_error(&e.to_string()))
    }

    /// One request at a time: its turn (to send), and the reply number from which its
    /// answers count.
    pub(crate) fn begin(&self) -> (MutexGuard<'_, ()>, u64) {
        let turn = self.request.lock().unwrap_or_else(|e| e.into_inner());
        let from = self.shared().seq;
        (turn, from)
    }

    /// The answers of a request that ends in `statuses` `Status` replies (its own
    /// `Status` last, after the one the device sends for each `Arm` and `Disarm`), within
    /// `timeout`: waits for every one of them, so that none is left over to answer a
    /// later request as if it were its own (the device answers in order, so the last is
    /// a fence behind everything the request caused), then takes them, and the replies
    /// before the last that `refused` takes, from the replies. The first refusal, if
    /// any, as [`Error::Refused`]; else the first `Status` (an `Arm`'s or a `Disarm`'s
    /// own, where the request has one).
    pub(crate) fn wait_statuses(
        &self,
        from: u64,
        what: &'static str,
        timeout: Duration,
        statuses: usize,
        refused: impl Fn(&ToHost) -> bool,
    ) -> Result<ToHost, Error> {
        let ours = |(n, m): &(u64, ToHost)| *n >= from && matches!(m, ToHost::Status(_));
        self.wait_until(what, timeout, |replies| {
            let (fence, _) = replies
                .iter()
                .enumerate()
                .filter(|(_, r)| ours(r))
                .nth(statuses.saturating_sub(1))?;
            let take: Vec<usize> = (0..=fence)
                .filter(|&i| ours(&replies[i]) || (replies[i].0 >= from && refused(&replies[i].1)))
                .collect();
            // (From the back, so that each index still names its reply.)
            let mut taken: Vec<ToHost> = take
                .iter()
                .rev()
                .filter_map(|&i| replies.remove(i).map(|(_, m)| m))
                .collect();
            taken.reverse();
            // The first refusal, else the first `Status`.
            let i = taken
                .iter()
                .position(|m| matches!(m, ToHost::Nak(_)))
                .unwrap_or(0);
            (i < taken.len()).then(|| taken.swap_remove(i))
        })
    }

    /// The first reply numbered `from` or later that `want` takes, within `timeout`;
    /// `want` takes the refusals that answer this request (a `Nak` it takes is returned
    /// as [`Error::Refused`]); what it leaves stays for other requests.
    pub(crate) fn wait(
        &self,
        from: u64,
        what: &'static str,
        timeout: Duration,
        want: impl Fn(&ToHost) -> bool,
    ) -> Result<ToHost, Error> {
        self.wait_until(what, timeout, |replies| {
            let i = replies.iter().position(|(n, m)| *n >= from && want(m))?;
            replies.remove(i).map(|(_, m)| m)
        })
    }

    /// Waits, within `timeout`, until `take` takes its answer from the replies (a `Nak`
    /// is returned as [`Error::Refused`]), or the connection is lost.
    fn wait_until(
        &self,
        what: &'static str,
        timeout: Duration,
        mut take: impl FnMut(&mut VecDeque<(u64, ToHost)>) -> Option<ToHost>,
    ) -> Result<ToHost, Error> {
        let deadline = Instant::now() + timeout;
        let mut s = self.shared();
        loop {
            if let Some(m) = take(&mut s.replies) {
                return match m {
                    ToHost::Nak(r) => Err(Error::Refused {
                        addr: self.addr.clone(),
                        refusal: Refusal(r),
                    }),
                    m => Ok(m),
                };
            }
            if let Some(why) = &s.lost {
                return Err(self.lost_error(why));
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(Error::Timeout {
                    addr: self.addr.clone(),
                    what,
                    waited: timeout,
                });
            }
            s = self
                .cond
                .wait_timeout(s, deadline - now)
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
    }

    /// A telemetry stream from now.
    pub(crate) fn subscribe(&self) -> Receiver<TelemetrySample> {
        let (tx, rx) = std::sync::mpsc::sync_channel(STREAM_DEPTH);
        self.shared().streams.push(tx);
        rx
    }

    /// Ends the worker.
    pub(crate) fn stop(&self) {
        self.stop.store(true, Ordering::SeqCst);
    }

    /// Takes one message from the device.
    fn take(&self, msg: ToHost) {
        let mut s = self.shared();
        match msg {
            ToHost::Telemetry(t) => {
                let sample = TelemetrySample::from_raw(&t, self.epoch.elapsed());
                s.telemetry = Some(sample);
                let mut dropped = 0;
                s.streams.retain(|tx| match tx.try_send(sample) {
                    Ok(()) => true,
                    Err(TrySendError::Full(_)) => {
                        dropped += 1;
                        true
                    }
                    Err(TrySendError::Disconnected(_)) => false,
                });
                s.stream_drops = s.stream_drops.saturating_add(dropped);
            }
            ToHost::Mesh(part) => {
                if let Some(m) = s.mesh.add(&part) {
                    s.latest_mesh = Some(m);
                }
            }
            ToHost::Status(_) if s.probes > 0 => s.probes -= 1,
            m => {
                let n = s.seq;
                s.seq += 1;
                s.replies.push_back((n, m));
                if s.replies.len() > MAX_REPLIES {
                    s.replies.pop_front();
                }
            }
        }
        drop(s);
        self.cond.notify_all();
    }

    fn lose(&self, why: String) {
        self.shared().lost = Some(why);
        self.cond.notify_all();
    }
}

/// The worker: reads and decodes, keeps an armed device alive, notices a loss.
pub(crate) fn worker(session: Arc<Session>, mut reader: Reader) {
    let mut decoder = Decoder::new();
    let mut buf = [0u8; 1024];
    let keepalive = Duration::from_millis(mccs_link::rates::KEEPALIVE_MS as u64);
    while !session.stop.load(Ordering::SeqCst) {
        match reader.read(&mut buf) {
            Ok(0) => return session.lose("the device closed the link".into()),
            Ok(n) => {
                session.shared().last_rx = Instant::now();
                for &b in &buf[..n] {
                    match decoder.push(b) {
                        Some(Ok(payload)) => match parse::<ToHost>(payload) {
                            Ok(m) => session.take(m),
                            Err(_) => session.shared().bad_frames += 1,
                        },
                        Some(Err(_)) => session.shared().bad_frames += 1,
                        None => {}
                    }
                }
            }
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock
                        | std::io::ErrorKind::TimedOut
                        | std::io::ErrorKind::Interrupted
                ) => {}
            Err(e) => return session.lose(e.to_string()),
        }
        let (armed, idle, silent, probe_due) = {
            let s = session.shared();
            (
                s.armed,
                s.last_tx.elapsed(),
                s.last_rx.elapsed(),
                s.last_probe.elapsed() >= PROBE,
            )
        };
        if !armed {
            continue;
        }
        if silent > LIVENESS {
            return session.lose(format!(
                "no frame from the device in {} ms while armed",
                silent.as_millis()
            ));
        }
        let msg = if probe_due {
            let mut s = session.shared();
            s.last_probe = Instant::now();
            s.probes += 1;
            Some(ToDevice::Status)
        } else if idle >= keepalive {
            Some(ToDevice::Keepalive)
        } else {
            None
        };
        if let Some(m) = msg {
            if session.send(&m).is_err() {
                return;
            }
        }
    }
}
