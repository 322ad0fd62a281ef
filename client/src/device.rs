//! [`Device`]: a session with an mccs device that stays alive while the program runs.
//!
//! - [`Device::open`] connects and says hello (again every 200 ms until answered:
//!   bytes sent before the device's link is up are lost), and refuses a device of
//!   another protocol or schema, naming both;
//! - every request waits for its answer with an explicit timeout
//!   ([`Options::answer_timeout`]) and returns the device's refusal as
//!   [`Error::Refused`] with its reason and values;
//! - [`Device::arm`] holds the device armed: the session's one background thread sends
//!   a `Keepalive` whenever the link has been quiet for 25 ms, so the device never sees
//!   silence while the program runs; [`Armed`] disarms when dropped, and so does the
//!   `Device`;
//! - telemetry ([`Device::watch`], [`Device::telemetry`], [`Device::telemetry_stream`])
//!   and the mesh ([`Device::watch_mesh`], [`Device::mesh`]) arrive in the background;
//! - a lost connection is an error within `session::LIVENESS` (400 ms) while armed (at
//!   once where the transport tells), and the background thread ends with it.
//!
//! `Device` is `Send + Sync`: requests from several threads take turns.

use crate::black_box::BlackBox;
use crate::error::Error;
pub use crate::facts::{Info, Status};
use crate::mesh::Mesh;
use crate::session::{worker, Session};
pub use crate::telemetry::TelemetrySample;
use crate::tissue::Tissue;
use crate::transport;
use crate::Addr;
use mccs_link::{HelloInfo, Pose, TissueBegin, ToDevice, ToHost, PROTOCOL, SCHEMA, TISSUE_CHUNK};
use std::sync::mpsc::Receiver;
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// A refusal of a tissue load.
pub(crate) fn tissue_nak(m: &ToHost) -> bool {
    use mccs_link::NakReason as R;
    matches!(
        m,
        ToHost::Nak(
            R::Busy
                | R::Order
                | R::Length
                | R::Hash
                | R::Segments
                | R::Table
                | R::Bound
                | R::Solver
                | R::Budget { .. }
                | R::Stability { .. }
                | R::Friction
        )
    )
}

/// A refusal of a pose.
pub(crate) fn pose_nak(m: &ToHost) -> bool {
    matches!(
        m,
        ToHost::Nak(mccs_link::NakReason::Pose { .. } | mccs_link::NakReason::Rotation)
    )
}

/// A refusal of a replay.
pub(crate) fn replay_nak(m: &ToHost) -> bool {
    use mccs_link::NakReason as R;
    matches!(
        m,
        ToHost::Nak(R::Busy | R::Order | R::NoTissue | R::Option { .. })
    )
}

/// What a load proposes with its tissue.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Proposal {
    /// The substeps computed here, as the device would ([`crate::substeps`]).
    Computed,
    /// None: the device searches (seconds on a small core).
    None,
    /// These.
    Substeps(u16),
}

/// How a session waits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// How long `open` says hello before it gives up.
    pub hello_timeout: Duration,
    /// How long a request waits for its answer.
    pub answer_timeout: Duration,
    /// How long a tissue load waits for the device's check and swap.
    pub load_timeout: Duration,
    /// A serial port's baud rate (the board's default: 1,000,000).
    pub baud: u32,
    /// Propose the substeps with a tissue (computed here as the device would): its
    /// check then takes two runs, not ten.
    pub propose_substeps: bool,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            hello_timeout: Duration::from_secs(10),
            answer_timeout: Duration::from_secs(5),
            load_timeout: Duration::from_secs(30),
            baud: mccs_link::rates::DEFAULT_BAUD,
            propose_substeps: true,
        }
    }
}

/// A session with a device.
pub struct Device {
    session: Arc<Session>,
    worker: Option<JoinHandle<()>>,
    info: Info,
    options: Options,
}

impl Device {
    /// Connects to `addr` (`unix:PATH`, `tcp:HOST:PORT` or a serial port) with the
    /// default [`Options`].
    pub fn open(addr: &str) -> Result<Device, Error> {
        Self::open_with(addr, Options::default())
    }

    /// Connects to `addr` and says hello until the device answers.
    pub fn open_with(addr: &str, options: Options) -> Result<Device, Error> {
        let parsed = Addr::parse(addr).map_err(|why| Error::Address {
            addr: addr.to_string(),
            why,
        })?;
        let (reader, writer) =
            transport::connect(&parsed, options.baud).map_err(|source| Error::Connect {
                addr: addr.to_string(),
                source,
            })?;
        let session = Session::new(addr.to_string(), writer);
        let s = session.clone();
        let worker = std::thread::Builder::new()
            .name("mccs-client".into())
            .spawn(move || worker(s, reader))
            .map_err(|source| Error::Connect {
                addr: addr.to_string(),
                source,
            })?;
        let mut device = Device {
            session,
            worker: Some(worker),
            info: Info {
                hello: HelloInfo {
                    protocol: 0,
                    schema: 0,
                    device: mccs_link::DeviceKind::OneDof,
                    simulated: false,
                    core: mccs_link::Core::M4f,
                    tick_hz: 0,
                    contact: mccs_link::ContactKind::Glued,
                    grid: 0,
                    max_grid: 0,
                    spacing: 0,
                    tissue_w: 0,
                    tissue_h: 0,
                    knots: 0,
                    tissue: 0,
                    friction: mccs_link::Friction { mu_s: 0, mu_k: 0 },
                    substeps: 0,
                    solver: mccs_link::SolverInfo {
                        node_mass_kg: 0.0,
                        spring_damping: 0.0,
                        node_damping: 0.0,
                        coupling_stiffness: 0.0,
                        coupling_damping: 0.0,
                        symplectic: false,
                        max_substeps: 0,
                    },
                    path_capacity: 0,
                    force_clamp: 0,
                    workspace: [[0; 3]; 2],
                    pose_speed_mm_s: 0,
                    pose_turn_deg_s: 0,
                    baud: 0,
                    telemetry_least_every: 0,
                    mesh_least_every: 0,
                    tick_budget: 0,
                    substep_cost: 0,
                    tick_base_cost: 0,
                },
            },
            options,
        };
        device.info = device.say_hello()?;
        Ok(device)
    }

    /// Hello every 200 ms until answered; the device held to this protocol and schema.
    fn say_hello(&self) -> Result<Info, Error> {
        let start = Instant::now();
        let (_turn, from) = self.session.begin();
        while start.elapsed() < self.options.hello_timeout {
            self.session.send(&ToDevice::Hello)?;
            match self
                .session
                .wait(from, "hello", Duration::from_millis(200), |m| {
                    matches!(m, ToHost::Hello(_))
                }) {
                Ok(ToHost::Hello(h)) => {
                    if (h.protocol, h.schema) != (PROTOCOL, SCHEMA) {
                        return Err(Error::Protocol {
                            addr: self.session.addr.clone(),
                            device_protocol: h.protocol,
                            device_schema: h.schema,
                            protocol: PROTOCOL,
                            schema: SCHEMA,
                        });
                    }
                    return Ok(Info { hello: h });
                }
                Ok(_) | Err(Error::Timeout { .. }) => {}
                Err(e) => return Err(e),
            }
        }
        Err(Error::NoAnswer {
            addr: self.session.addr.clone(),
            waited: self.options.hello_timeout,
        })
    }

    /// Its address, as given.
    pub fn addr(&self) -> &str {
        &self.session.addr
    }

    /// What it said of itself when opened.
    pub fn info(&self) -> &Info {
        &self.info
    }

    /// Asks again (its live tissue and substeps change with a load).
    pub fn hello(&self) -> Result<Info, Error> {
        let m = self.request(
            &[ToDevice::Hello],
            "hello",
            self.options.answer_timeout,
            |m| matches!(m, ToHost::Hello(_)),
        )?;
        match m {
            ToHost::Hello(h) => Ok(Info { hello: h }),
            other => Err(self.unexpected(other)),
        }
    }

    /// Its counters and state.
    pub fn status(&self) -> Result<Status, Error> {
        self.status_after(&[])
    }

    /// `msgs`, then a `Status`: its answer, once the device has taken them all (frames
    /// are handled in order), or its refusal of a pose among them.
    fn status_after(&self, msgs: &[ToDevice]) -> Result<Status, Error> {
        let mut all: Vec<ToDevice> = msgs.to_vec();
        all.push(ToDevice::Status);
        let poses = msgs.iter().any(|m| matches!(m, ToDevice::Pose(_)));
        // The device answers an `Arm` and a `Disarm` with a `Status` of its own: every
        // one is this request's (`Session::wait_statuses`).
        let statuses = 1 + msgs
            .iter()
            .filter(|m| matches!(m, ToDevice::Arm | ToDevice::Disarm))
            .count();
        let answer = {
            let (_turn, from) = self.session.begin();
            for m in &all {
                self.session.send(m)?;
            }
            let timeout = self.options.answer_timeout;
            self.session
                .wait_statuses(from, "status", timeout, statuses, |m| poses && pose_nak(m))?
        };
        match answer {
            ToHost::Status(s) => Ok(Status { raw: s }),
            other => Err(self.unexpected(other)),
        }
    }

    fn unexpected(&self, m: ToHost) -> Error {
        Error::Unexpected {
            addr: self.session.addr.clone(),
            what: format!("an answer this client did not ask for: {m:?}"),
        }
    }

    /// The black box the device kept of its run before its last reset, read a part at a
    /// time (`progress` is told the ticks read and their total after each part).
    pub fn black_box(&self, mut progress: impl FnMut(usize, usize)) -> Result<BlackBox, Error> {
        let mut b = BlackBox::default();
        loop {
            let first = u16::try_from(b.ticks.len()).unwrap_or(u16::MAX);
            let part = match self.request(
                &[ToDevice::BlackBox { first }],
                "blackbox",
                self.options.answer_timeout,
                |m| matches!(m, ToHost::BlackBox(_)),
            )? {
                ToHost::BlackBox(p) => p,
                other => return Err(self.unexpected(other)),
            };
            if !part.kept {
                return Ok(BlackBox::default());
            }
            let left = b.take(&part).map_err(|what| Error::Unexpected {
                addr: self.session.addr.clone(),
                what,
            })?;
            progress(b.ticks.len(), part.ticks as usize);
            if left == 0 {
                return Ok(b);
            }
        }
    }

    /// Sends `msgs` in order and waits for the answer `want` takes.
    fn request(
        &self,
        msgs: &[ToDevice],
        what: &'static str,
        timeout: Duration,
        want: impl Fn(&ToHost) -> bool,
    ) -> Result<ToHost, Error> {
        let (_turn, from) = self.session.begin();
        for m in msgs {
            self.session.send(m)?;
        }
        self.session.wait(from, what, timeout, want)
    }

    /// Loads `tissue`: its bytes in chunks, then the commit; returns its hash once the
    /// device runs it (its `Ack`), or the device's refusal with its reason. The live
    /// tissue renders while the device checks the new one, and other requests (a status,
    /// a pose) are answered meanwhile.
    pub fn load_tissue(&self, tissue: &Tissue) -> Result<u32, Error> {
        let p = if self.options.propose_substeps {
            Proposal::Computed
        } else {
            Proposal::None
        };
        self.load_tissue_proposing(tissue, p)
    }

    /// [`Device::load_tissue`] with what it proposes.
    pub fn load_tissue_proposing(&self, tissue: &Tissue, proposal: Proposal) -> Result<u32, Error> {
        let substeps = match proposal {
            Proposal::Computed => {
                crate::substeps::for_device(&self.info.hello, tissue).unwrap_or(0)
            }
            Proposal::None => 0,
            Proposal::Substeps(n) => n as u32,
        };
        let begin = ToDevice::TissueBegin(TissueBegin {
            segments: tissue.segments(),
            len: tissue.bytes().len() as u32,
            hash: tissue.hash(),
            friction: tissue.friction(),
            substeps: substeps.min(u16::MAX as u32) as u16,
        });
        let from = {
            let (_turn, from) = self.session.begin();
            self.session.send(&begin)?;
            for (i, chunk) in tissue.bytes().chunks(TISSUE_CHUNK).enumerate() {
                self.session.send(&ToDevice::TissueChunk {
                    offset: (i * TISSUE_CHUNK) as u32,
                    bytes: chunk,
                })?;
            }
            self.session.send(&ToDevice::TissueCommit)?;
            // A fence: every refusal of the frames above comes before its answer, and is
            // taken here, so that none is left over to refuse a later load (a refused
            // `TissueBegin` is followed by a `Nak(Order)` for each chunk and the commit).
            self.session.send(&ToDevice::Status)?;
            let timeout = self.options.answer_timeout;
            self.session
                .wait_statuses(from, "the tissue load", timeout, 1, tissue_nak)?;
            from
        };
        // (The turn is free while the device checks: other requests go on.)
        match self
            .session
            .wait(from, "the tissue load", self.options.load_timeout, |m| {
                matches!(m, ToHost::Ack { .. }) || tissue_nak(m)
            })? {
            ToHost::Ack { tissue: hash } if hash == tissue.hash() => Ok(hash),
            other => Err(self.unexpected(other)),
        }
    }

    /// Places the tissue: its origin (mm) and rotation in the device's frame. Returns
    /// once the device has taken it (its status), or its refusal (outside the
    /// workspace, not a unit quaternion). The device moves toward it at its slew limits.
    pub fn set_pose(&self, pose: Pose) -> Result<Status, Error> {
        self.status_after(&[ToDevice::Pose(pose)])
    }

    /// Arms the device and holds it armed until [`Armed`] is dropped or
    /// [`Device::disarm`]: keepalives go out from the session's thread meanwhile. The
    /// force ramps up once the probe is out of contact.
    pub fn arm(&self) -> Result<Armed<'_>, Error> {
        self.arm_held()?;
        Ok(Armed { device: self })
    }

    /// Arms the device and holds it armed until [`Device::disarm`] (or the `Device` is
    /// dropped); its status.
    pub fn arm_held(&self) -> Result<Status, Error> {
        let s = self.status_after(&[ToDevice::Arm])?;
        self.session.shared().armed = true;
        Ok(s)
    }

    /// Disarms: force to zero at once; the keepalives stop.
    pub fn disarm(&self) -> Result<Status, Error> {
        self.session.shared().armed = false;
        self.status_after(&[ToDevice::Disarm])
    }

    /// Whether this session holds the device armed.
    pub fn armed(&self) -> bool {
        self.session.shared().armed
    }

    /// Telemetry every `every` ticks (0: none; the device holds it to its byte budget,
    /// `Info::hello.telemetry_least_every`).
    pub fn watch(&self, every: u16) -> Result<(), Error> {
        self.status_after(&[ToDevice::Watch { every }]).map(|_| ())
    }

    /// The latest telemetry sample, if any arrived.
    pub fn telemetry(&self) -> Option<TelemetrySample> {
        self.session.shared().telemetry
    }

    /// Every telemetry sample from now (the stream drops what its reader leaves over
    /// 4,096 behind: [`Device::stream_drops`]).
    pub fn telemetry_stream(&self) -> Receiver<TelemetrySample> {
        self.session.subscribe()
    }

    /// Samples the streams dropped.
    pub fn stream_drops(&self) -> u32 {
        self.session.shared().stream_drops
    }

    /// A mesh every `every` ticks (0: none; held to the byte budget,
    /// `Info::hello.mesh_least_every`).
    pub fn watch_mesh(&self, every: u16) -> Result<(), Error> {
        self.status_after(&[ToDevice::WatchMesh { every }])
            .map(|_| ())
    }

    /// The latest whole mesh, if any arrived.
    pub fn mesh(&self) -> Option<Mesh> {
        self.session.shared().latest_mesh.clone()
    }

    /// Frames from the device this session dropped (a bad CRC, COBS or message).
    pub fn bad_frames(&self) -> u32 {
        self.session.shared().bad_frames
    }

    /// Time since the session opened.
    pub fn elapsed(&self) -> Duration {
        self.session.epoch.elapsed()
    }

    /// Raw bytes to the device (tests: corrupted frames, floods).
    pub fn send_raw(&self, bytes: &[u8]) -> Result<(), Error> {
        self.session.send_raw(bytes)
    }

    /// The session (for the replay).
    pub(crate) fn session(&self) -> &Session {
        &self.session
    }

    /// The waits.
    pub fn options(&self) -> &Options {
        &self.options
    }
}

impl Drop for Device {
    /// Disarms if armed, then ends the session's thread.
    fn drop(&mut self) {
        if self.armed() {
            let _ = self.disarm();
        }
        self.session.stop();
        if let Some(w) = self.worker.take() {
            let _ = w.join();
        }
    }
}

/// A device held armed: dropped, it disarms.
pub struct Armed<'a> {
    device: &'a Device,
}

impl Armed<'_> {
    /// The device.
    pub fn device(&self) -> &Device {
        self.device
    }

    /// Disarms now, with the device's answer.
    pub fn disarm(self) -> Result<Status, Error> {
        let d = self.device;
        std::mem::forget(self);
        d.disarm()
    }
}

impl Drop for Armed<'_> {
    fn drop(&mut self) {
        let _ = self.device.disarm();
    }
}
