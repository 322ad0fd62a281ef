//! Any run of the link, end to end, on the arm board's device (`rig.rs`: the board's
//! link server, link state and roaming controller, tick by tick): any interleaving of
//! the host's messages (tissue loads whole, refused or cut short, poses inside and
//! outside the workspace, rotations that are not one, `Arm`, `Disarm`, the streams),
//! frames of noise, silences, a probe anywhere, failed reads and runs of overruns.
//! The link's clock starts at 0, anywhere, or a few thousand ticks before its wrap at
//! 2³². Checked against a model of the protocol's promises (docs/protocol.md), not the
//! device's own state:
//!
//! - **at the actuator**, every tick: the force within the device's clamp; zero once
//!   the host disarmed (until it arms again), once an armed host's silence has run its
//!   timeout and fade, and from a fault on, when the device only calls its safe state;
//!   the link's gain never rising faster than its ramp;
//! - **on the link**: every message answered in order with its documented answer (a
//!   `Status` with the armed flag, fault, pose and bad-frame count the model expects, a
//!   pose's `Nak` exactly where the model refuses it, a load's `Nak`s or, once its
//!   check has run, its `Ack`, one for each load accepted and none for another); after
//!   the run, a `Hello` still answered.
//!
//! Replays run among them, glued on the standard 5-node patch, their path whole or cut
//! short: each begun at once or refused `Busy` (a tissue's check under way), their rows
//! numbered from 0, each end after as many rows as it says, and the last replay's end
//! as its path says (its samples, or those it was sent once it has waited its limit for
//! the next: `rates::REPLAY_STARVED_MS`). `device.rs` holds their rows to the host's
//! replay.

use super::rig::{replay_spec, Rig, P};
use haptic_f405::device::{EDGES, NODES};
use haptic_f405::BOARD;
use mccs::Wide;
use mccs::{Force, ForceTable64, Params};
use mccs_client::Tissue;
use mccs_firmware::Contact;
use mccs_link::scale::GAIN_FULL;
use mccs_link::*;
use proptest::prelude::*;
use std::sync::OnceLock;

/// A message the model knows the answer to.
#[derive(Clone, Debug)]
enum Msg {
    Hello,
    Status,
    Arm,
    Disarm,
    Keepalive,
    /// An origin (mm) and three angles (degrees): `Pose::from_mm_deg`.
    Pose([f64; 3], [f64; 3]),
    /// Any bits, Q24 mm and Q30: an origin mostly outside the workspace, a rotation
    /// almost never a unit quaternion.
    RawPose([i32; 3], [i32; 4]),
    Watch(u16),
    WatchMesh(u16),
    BlackBox(u16),
}

/// A tissue load as a host sends it: begin, chunks, commit, then a `Status` to fence
/// its refusals (as `mccs-client` does).
#[derive(Clone, Copy, Debug)]
enum Load {
    /// A tissue the device runs (Table 2, or a stiffer one).
    Good(bool),
    /// Its hash announced wrong.
    WrongHash,
    /// Committed after half its chunks.
    Cut,
    /// Another knot count announced.
    Segments,
    /// A chunk sent twice.
    Repeated,
    /// Table 2 with friction coefficients (Q16, valid or not).
    Friction(u32, u32),
}

#[derive(Clone, Debug)]
enum Op {
    /// Ticks on time, a poll after each.
    Steps(u32),
    /// Ticks on time with a `Keepalive` every 25 (`rates::KEEPALIVE_MS`): a host that
    /// holds the device armed.
    Attended(u32),
    /// The probe to a point of the device's frame, mm.
    Move([f64; 3]),
    Send(Msg),
    Load(Load),
    /// Bytes that are no frame of the protocol's, then a delimiter.
    Noise(Vec<u8>),
    /// The next read of the probe fails.
    FailRead,
    /// Ticks that overran, in a row.
    Overruns(u32),
    /// A replay of so many samples, the first so many of its path sent.
    Replay(u32, u32),
}

fn ops() -> impl Strategy<Value = Vec<Op>> {
    let mm = || -90.0f64..90.0;
    let msg = prop_oneof![
        1 => Just(Msg::Hello),
        3 => Just(Msg::Status),
        2 => Just(Msg::Arm),
        1 => Just(Msg::Disarm),
        3 => Just(Msg::Keepalive),
        3 => ([mm(), mm(), mm()], [-400.0f64..400.0, -400.0f64..400.0, -400.0f64..400.0])
            .prop_map(|(o, a)| Msg::Pose(o, a)),
        1 => any::<([i32; 3], [i32; 4])>().prop_map(|(o, q)| Msg::RawPose(o, q)),
        // Mostly inside the workspace (±60 mm against ±50), a unit quaternion moved by
        // up to 2⁻⁹ on each component: either side of the device's 2⁻¹⁰ on `|q|²`.
        2 => ([mm(), mm(), mm()], [-400.0f64..400.0, -400.0f64..400.0, -400.0f64..400.0],
              prop::array::uniform4(-(1i32 << 21)..1 << 21))
            .prop_map(|(o, a, d)| {
                let mut p = Pose::from_mm_deg(o.map(|c| c * 2.0 / 3.0), a);
                for k in 0..4 {
                    p.rotation[k] = p.rotation[k].saturating_add(d[k]);
                }
                Msg::RawPose(p.origin, p.rotation)
            }),
        1 => any::<u16>().prop_map(Msg::Watch),
        1 => any::<u16>().prop_map(Msg::WatchMesh),
        1 => any::<u16>().prop_map(Msg::BlackBox),
    ];
    let load = prop_oneof![
        3 => any::<bool>().prop_map(Load::Good),
        1 => Just(Load::WrongHash),
        1 => Just(Load::Cut),
        1 => Just(Load::Segments),
        1 => Just(Load::Repeated),
        2 => (0u32..3 << 16, 0u32..3 << 16).prop_map(|(s, k)| Load::Friction(s, k)),
    ];
    // Faults are rare (a run ends its force at the first), and the probe mostly in
    // reach of the tissue's surface (`z = 0`) so that the gain, once ramped, renders.
    let op = prop_oneof![
        16 => (1u32..40).prop_map(Op::Steps),
        3 => (100u32..600).prop_map(Op::Steps),
        4 => (100u32..1000).prop_map(Op::Attended),
        8 => [mm(), mm(), -12.0f64..6.0].prop_map(Op::Move),
        2 => [mm(), mm(), -40.0f64..40.0].prop_map(Op::Move),
        24 => msg.prop_map(Op::Send),
        2 => load.prop_map(Op::Load),
        4 => prop::collection::vec(1u8..=255, 0..40).prop_map(Op::Noise),
        1 => Just(Op::FailRead),
        1 => (1u32..12).prop_map(Op::Overruns),
        1 => (0u32..=P as u32).prop_map(|n| Op::Replay(n, n)),
        1 => (0u32..=P as u32, 0u32..=P as u32).prop_map(|(n, f)| Op::Replay(n, f.min(n))),
    ];
    prop::collection::vec(op, 1..64)
}

/// What the model expects of the guard.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Held {
    /// Never armed.
    Standalone,
    /// Armed; the tick of its last frame.
    Armed(u32),
    /// Disarmed: zero force until `Arm`.
    Disarmed,
    /// A frame came as the silence ran out: fading or not, the model cannot say.
    Unsure,
}

/// One answer the model expects, in order.
#[derive(Clone, Debug)]
enum Answer {
    Hello,
    /// `armed` where the model knows it.
    Status {
        armed: Option<bool>,
        fault: FaultReason,
        pose: Pose,
        bad_frames: u32,
    },
    BlackBox,
    Nak(NakReason),
    /// A load's `Nak`s, then its fence's `Status`: the first `Nak` is `refused`, or
    /// `Busy` (a check under way); none where it is taken, whose `Ack` follows.
    Load {
        refused: Option<NakReason>,
        hash: u32,
    },
    /// A replay's begin and path (in so many pieces), then a `Status` as a fence: no
    /// `Nak`, or `Busy` and an `Order` for each piece.
    Replay {
        pieces: usize,
    },
}

/// The device under test and what the model expects of it.
struct Model<C: Contact<NODES, EDGES, 64, Wide>> {
    rig: Rig<C>,
    /// The arm board's roaming contact (or the 1-DOF board's glued one).
    roaming: bool,
    held: Held,
    /// The first fault (latched).
    fault: FaultReason,
    overruns_in_row: u32,
    /// The last pose the device took.
    pose: Pose,
    /// Frames of noise sent.
    bad_frames: u32,
    /// The answers due, in order.
    answers: Vec<Answer>,
    /// The link's gain at the last tick, Q15.
    gain: u16,
    /// The link's clock: its start, a tick more each tick, wrapping.
    clock: u32,
    /// The last `Watch` on: when it was handled and its period, ticks.
    watch: Option<(u32, u32)>,
    /// The guard's timeout and fade at the board's rate, ticks.
    timeout: u32,
    fade: u32,
    /// The replays sent, in order: their samples and the samples of their path sent.
    replays: Vec<(u32, u32)>,
}

fn tissues() -> &'static [Tissue; 2] {
    static T: OnceLock<[Tissue; 2]> = OnceLock::new();
    T.get_or_init(|| {
        let stiffer = mccs_host::paramfile::read(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../params/table2-stiffer.toml"
        )))
        .unwrap();
        [
            Tissue::from_params(&Params::TABLE2).unwrap(),
            Tissue::from_params(&stiffer).unwrap(),
        ]
    })
}

fn table2() -> ForceTable64 {
    static T: OnceLock<ForceTable64> = OnceLock::new();
    *T.get_or_init(|| ForceTable64::new(&Params::TABLE2).unwrap())
}

/// The magnitude of a force, in its bits (Q20 N).
fn bits_norm(f: [Force; 3]) -> f64 {
    f.iter()
        .map(|c| (c.to_bits() as f64).powi(2))
        .sum::<f64>()
        .sqrt()
}

impl<C: Contact<NODES, EDGES, 64, Wide>> Model<C> {
    fn new(rig: Rig<C>, roaming: bool) -> Self {
        let times = mccs_firmware::link::GuardTimes::at_rate(BOARD.tick_hz, BOARD.ramp_ms);
        Self {
            clock: rig.state.snapshot().ticks,
            rig,
            roaming,
            held: Held::Standalone,
            fault: FaultReason::None,
            overruns_in_row: 0,
            pose: Pose::IDENTITY,
            bad_frames: 0,
            answers: Vec::new(),
            gain: 0,
            watch: None,
            timeout: times.timeout,
            fade: times.fade,
            replays: Vec::new(),
        }
    }

    /// The link's clock after the last tick, as the model counts it.
    fn now(&self) -> u32 {
        self.clock
    }

    /// One tick (on time or not), its actuator and gain checked, then a poll.
    fn step(&mut self, overran: bool) {
        let faulted = self.fault != FaultReason::None;
        let (written, safe) = {
            let p = self.rig.probe();
            (p.rendered.len(), p.safe_states)
        };
        self.rig.tick();
        self.clock = self.clock.wrapping_add(1);
        assert_eq!(
            self.rig.state.snapshot().ticks,
            self.clock,
            "the link's clock"
        );
        if overran {
            self.rig.ctl.note_overrun();
            self.overruns_in_row += 1;
        } else {
            self.rig.ctl.note_on_time();
            self.overruns_in_row = 0;
        }
        if let Held::Armed(last) = self.held {
            if self.now().wrapping_sub(last) > self.timeout + self.fade + 2 {
                self.held = Held::Disarmed;
            }
        }
        self.check_actuator(faulted, written, safe);
        let probe = self.rig.probe();
        if std::mem::take(&mut probe.fail) && self.fault == FaultReason::None {
            self.fault = FaultReason::Read;
        }
        if overran
            && self.overruns_in_row >= BOARD.max_overruns_in_row
            && self.fault == FaultReason::None
        {
            self.fault = FaultReason::Overruns;
        }
        self.check_gain();
        self.rig.poll();
    }

    /// What the tick wrote to the actuator (the probe's record from `written` on), or
    /// its safe state (called more than `safe` times).
    fn check_actuator(&mut self, faulted: bool, written: usize, safe: u32) {
        let now = self.now();
        let (roaming, held) = (self.roaming, self.held);
        let probe = self.rig.probe();
        let wrote = &probe.rendered[written..];
        if faulted {
            assert!(
                wrote.is_empty(),
                "tick {now}: a force written after a fault"
            );
            assert!(
                probe.safe_states > safe,
                "tick {now}: no safe state after a fault"
            );
            return;
        }
        let Some(&f) = wrote.last() else {
            assert!(probe.fail, "tick {now}: nothing written, no fault");
            return;
        };
        assert_eq!(wrote.len(), 1, "tick {now}");
        // The clamp: on the force's size where the contact roams, on each axis where it
        // is glued (docs/solver.md), in the device's frame.
        let clamp = Force::from_num(BOARD.max_force).to_bits() as f64;
        let size = if roaming {
            bits_norm(f)
        } else {
            f.iter()
                .map(|c| c.to_bits().unsigned_abs() as f64)
                .fold(0.0, f64::max)
        };
        assert!(
            size <= clamp + 4.0,
            "tick {now}: {f:?} past the clamp of {} N",
            BOARD.max_force
        );
        assert!(
            held != Held::Disarmed || f == [Force::ZERO; 3],
            "tick {now}: {f:?} while {held:?}"
        );
    }

    /// The link's gain: never rising faster than its ramp, zero while disarmed.
    fn check_gain(&mut self) {
        let now = self.now();
        let gain = self.rig.state.snapshot().gain;
        let ramp_step = (GAIN_FULL as u32).div_ceil(BOARD.tick_hz * BOARD.ramp_ms / 1000) as u16;
        assert!(
            gain <= self.gain.saturating_add(ramp_step),
            "tick {now}: the gain {} → {gain}",
            self.gain
        );
        assert!(
            self.held != Held::Disarmed || gain == 0,
            "tick {now}: gain {gain} disarmed"
        );
        self.gain = gain;
    }

    /// Sends frames and steps until the device has read them all (each is handled by
    /// the end of the last step).
    fn send(&mut self, msgs: &[ToDevice]) {
        for m in msgs {
            self.rig.send(m);
        }
        while self.rig.queued() > 0 {
            self.step(false);
        }
    }

    /// A valid frame handled at the last poll.
    fn framed(&mut self) {
        let now = self.now();
        if let Held::Armed(last) = self.held {
            self.held = if now.wrapping_sub(last) + 2 >= self.timeout {
                Held::Unsure
            } else {
                Held::Armed(now)
            };
        }
    }

    fn status(&self, armed: Option<bool>) -> Answer {
        let known = match self.held {
            Held::Standalone | Held::Disarmed => Some(false),
            Held::Armed(_) => Some(true),
            Held::Unsure => None,
        };
        Answer::Status {
            armed: armed.or(known),
            fault: self.fault,
            pose: self.pose,
            bad_frames: self.bad_frames,
        }
    }

    fn message(&mut self, m: &Msg) {
        let pose = |p: Pose| ToDevice::Pose(p);
        let frame = match m {
            Msg::Hello => ToDevice::Hello,
            Msg::Status => ToDevice::Status,
            Msg::Arm => ToDevice::Arm,
            Msg::Disarm => ToDevice::Disarm,
            Msg::Keepalive => ToDevice::Keepalive,
            Msg::Pose(o, a) => pose(Pose::from_mm_deg(*o, *a)),
            Msg::RawPose(o, q) => pose(Pose {
                origin: *o,
                rotation: *q,
            }),
            Msg::Watch(every) => ToDevice::Watch { every: *every },
            Msg::WatchMesh(every) => ToDevice::WatchMesh { every: *every },
            Msg::BlackBox(first) => ToDevice::BlackBox { first: *first },
        };
        self.send(&[frame]);
        self.framed();
        match (m, frame) {
            (Msg::Hello, _) => self.answers.push(Answer::Hello),
            (Msg::Status, _) => self.answers.push(self.status(None)),
            (Msg::Arm, _) => {
                self.held = Held::Armed(self.now());
                self.answers.push(self.status(Some(true)));
            }
            (Msg::Disarm, _) => {
                self.held = Held::Disarmed;
                self.answers.push(self.status(Some(false)));
            }
            (Msg::BlackBox(_), _) => self.answers.push(Answer::BlackBox),
            (Msg::Watch(every), _) => {
                let least = rates::telemetry_least_every(BOARD.tick_hz, BOARD.baud) as u32;
                self.watch = (*every != 0).then(|| (self.now(), (*every as u32).max(least)));
            }
            (_, ToDevice::Pose(p)) => match refusal(&p) {
                Some(r) => self.answers.push(Answer::Nak(r)),
                None => self.pose = p,
            },
            _ => {}
        }
    }

    fn load(&mut self, load: Load) {
        let t = &tissues()[matches!(load, Load::Good(true)) as usize];
        let bytes = t.bytes();
        let hash = if matches!(load, Load::WrongHash) {
            t.hash() ^ 1
        } else {
            t.hash()
        };
        let friction = match load {
            Load::Friction(mu_s, mu_k) => Some(Friction { mu_s, mu_k }),
            _ => t.friction(),
        };
        let mut frames = vec![ToDevice::TissueBegin(TissueBegin {
            segments: if matches!(load, Load::Segments) {
                32
            } else {
                t.segments()
            },
            len: bytes.len() as u32,
            hash,
            friction,
            substeps: 0,
        })];
        let chunks: Vec<&[u8]> = bytes.chunks(TISSUE_CHUNK).collect();
        let sent = if matches!(load, Load::Cut) {
            chunks.len() / 2
        } else {
            chunks.len()
        };
        for (i, c) in chunks.iter().enumerate().take(sent) {
            frames.push(ToDevice::TissueChunk {
                offset: (i * TISSUE_CHUNK) as u32,
                bytes: c,
            });
            if matches!(load, Load::Repeated) && i == 1 {
                frames.push(ToDevice::TissueChunk {
                    offset: (i * TISSUE_CHUNK) as u32,
                    bytes: c,
                });
            }
        }
        frames.push(ToDevice::TissueCommit);
        frames.push(ToDevice::Status);
        self.send(&frames);
        self.framed();
        // Why the device refuses it, as docs/protocol.md says (§7).
        let refused = match load {
            Load::Good(_) => None,
            Load::WrongHash => Some(NakReason::Hash),
            Load::Cut => Some(NakReason::Length),
            Load::Segments => Some(NakReason::Segments),
            Load::Repeated => Some(NakReason::Order),
            Load::Friction(mu_s, mu_k) => {
                (!self.roaming || mu_s > 2 << 16 || mu_k > mu_s).then_some(NakReason::Friction)
            }
        };
        self.answers.push(Answer::Load { refused, hash });
    }

    fn noise(&mut self, bytes: &[u8]) {
        // Counted as the link's decoder counts it (an empty frame is no frame).
        let mut d = Decoder::new();
        for &b in bytes.iter().chain([&0u8]) {
            match d.push(b) {
                Some(Ok(f)) => {
                    let m = parse::<ToDevice>(f);
                    assert!(
                        m.is_err(),
                        "noise that passed the CRC-32 (one in 2³²): {m:?}"
                    );
                    self.bad_frames += 1;
                }
                Some(Err(_)) => self.bad_frames += 1,
                None => {}
            }
        }
        self.rig.send_raw(bytes);
        self.rig.send_raw(&[0]);
        while self.rig.queued() > 0 {
            self.step(false);
        }
    }

    fn run(&mut self, op: &Op) {
        match op {
            Op::Steps(n) => (0..*n).for_each(|_| self.step(false)),
            Op::Attended(n) => {
                for _ in 0..n / 25 {
                    self.message(&Msg::Keepalive);
                    (0..24).for_each(|_| self.step(false));
                }
            }
            Op::Move(at) => self.rig.probe().at = *at,
            Op::Send(m) => self.message(m),
            Op::Load(l) => self.load(*l),
            Op::Noise(b) => self.noise(b),
            Op::FailRead => {
                self.rig.probe().fail = true;
                self.step(false);
            }
            Op::Overruns(n) => (0..*n).for_each(|_| self.step(true)),
            Op::Replay(samples, fed) => self.replay(*samples, *fed),
        }
    }

    /// A replay of `samples` on the standard patch, the first `fed` of its path sent (the
    /// probe at the tissue's surface, then pressing in), then a `Status`.
    fn replay(&mut self, samples: u32, fed: u32) {
        let mut frames = vec![ToDevice::ReplayBegin(replay_spec(samples, [0.0; 3], None))];
        let points: Vec<[u8; 12]> = (0..fed)
            .map(|k| replay::PathPoint([0, 0, -(k as i32) << 18]).to_bytes())
            .collect();
        let pieces: Vec<Vec<u8>> = points
            .chunks(replay::PathPoint::PER_FRAME)
            .map(|c| c.concat())
            .collect();
        for (i, piece) in pieces.iter().enumerate() {
            frames.push(ToDevice::ReplayPath {
                first: (i * replay::PathPoint::PER_FRAME) as u32,
                points: piece,
            });
        }
        frames.push(ToDevice::Status);
        self.send(&frames);
        self.framed();
        self.replays.push((samples, fed));
        self.answers.push(Answer::Replay {
            pieces: pieces.len(),
        });
    }
}

/// Why the device refuses `p`, as docs/protocol.md says: each axis of the origin against
/// the workspace in turn, then `|q|²` against 1 within 2⁻¹⁰ (in `i128`).
fn refusal(p: &Pose) -> Option<NakReason> {
    let [lo, hi] = BOARD.workspace_q24();
    for axis in 0..3 {
        let o = p.origin[axis];
        if o < lo[axis] || o > hi[axis] {
            let limit = if o < lo[axis] { lo[axis] } else { hi[axis] };
            return Some(NakReason::Pose {
                axis: axis as u8,
                limit,
            });
        }
    }
    let n2: i128 = p.rotation.iter().map(|&c| (c as i128).pow(2)).sum();
    ((n2 - (1i128 << 60)).abs() > 1i128 << 50).then_some(NakReason::Rotation)
}

/// The device's answers held to the model's, in order; the acknowledgements and the
/// replays' streams apart. Whether each replay was begun, in order.
fn check_answers(out: &[ToHost], want: &[Answer]) -> Vec<bool> {
    let mut got = out
        .iter()
        .filter(|m| {
            !matches!(
                m,
                ToHost::Telemetry(_)
                    | ToHost::Mesh(_)
                    | ToHost::Ack { .. }
                    | ToHost::ReplayCredit { .. }
                    | ToHost::ReplayRow(_)
                    | ToHost::ReplayEnd { .. }
            )
        })
        .peekable();
    let mut begun = Vec::new();
    let mut acks_due = Vec::new();
    for (i, w) in want.iter().enumerate() {
        let next = got.next();
        let fail = || format!("answer {i}: {next:?}, expected {w:?}");
        match (w, next) {
            (Answer::Hello, Some(ToHost::Hello(_)))
            | (Answer::BlackBox, Some(ToHost::BlackBox(_))) => {}
            (Answer::Nak(r), Some(ToHost::Nak(n))) => assert_eq!(r, n, "{}", fail()),
            (
                Answer::Status {
                    armed,
                    fault,
                    pose,
                    bad_frames,
                },
                Some(ToHost::Status(s)),
            ) => {
                if let Some(a) = armed {
                    assert_eq!(s.armed, *a, "{}: armed", fail());
                }
                assert_eq!(
                    (s.fault, s.pose, s.bad_frames),
                    (*fault, *pose, *bad_frames),
                    "{}",
                    fail()
                );
            }
            (Answer::Load { refused, hash }, first) => {
                let naks = naks_to_fence(first, &mut got, &fail());
                match (refused, naks.first()) {
                    (None, None) => acks_due.push(*hash),
                    (_, Some(NakReason::Busy)) => {}
                    (Some(r), Some(n)) => assert_eq!(r, n, "{}: {naks:?}", fail()),
                    _ => panic!("{}: {naks:?}", fail()),
                }
            }
            (Answer::Replay { pieces }, first) => {
                let naks = naks_to_fence(first, &mut got, &fail());
                let busy: Vec<NakReason> = std::iter::once(NakReason::Busy)
                    .chain(std::iter::repeat_n(NakReason::Order, *pieces))
                    .collect();
                assert!(naks.is_empty() || naks == busy, "{}: {naks:?}", fail());
                begun.push(naks.is_empty());
            }
            _ => panic!("{}", fail()),
        }
    }
    let rest: Vec<_> = got.collect();
    assert!(rest.is_empty(), "answers no message asked for: {rest:?}");
    let acks: Vec<u32> = out
        .iter()
        .filter_map(|m| match m {
            ToHost::Ack { tissue } => Some(*tissue),
            _ => None,
        })
        .collect();
    assert_eq!(acks, acks_due, "the acknowledgements");
    begun
}

/// The `Nak`s from `first` on, then the fence's `Status` (a load's or a replay's).
fn naks_to_fence<'a>(
    first: Option<&'a ToHost>,
    got: &mut impl Iterator<Item = &'a ToHost>,
    at: &str,
) -> Vec<NakReason> {
    let mut naks = Vec::new();
    let mut m = first;
    while let Some(ToHost::Nak(r)) = m {
        naks.push(*r);
        m = got.next();
    }
    assert!(matches!(m, Some(ToHost::Status(_))), "{at}: then {m:?}");
    naks
}

/// The replays' rows and ends: a replay's rows numbered from 0, each end after as many
/// rows as it says (or none: a replay begun and abandoned before a row is not seen
/// until its end); the last replay begun, `last` (its samples and the samples of its
/// path sent), ended last, after its path's rows.
fn check_replays(out: &[ToHost], last: Option<(u32, u32)>) {
    let stream: Vec<&ToHost> = out
        .iter()
        .filter(|m| matches!(m, ToHost::ReplayRow(_) | ToHost::ReplayEnd { .. }))
        .collect();
    let mut rows = 0;
    for m in &stream {
        match m {
            ToHost::ReplayRow(r) => {
                assert!(r.tick == rows || r.tick == 0, "row {} after {rows}", r.tick);
                rows = r.tick + 1;
            }
            ToHost::ReplayEnd { ticks } => {
                assert!(
                    *ticks == rows || *ticks == 0,
                    "an end of {ticks} after {rows} rows"
                );
                rows = 0;
            }
            _ => unreachable!(),
        }
    }
    let Some((samples, fed)) = last else {
        return;
    };
    // Its whole path, or what it was sent once it waited its limit for the next.
    let ran = fed.min(samples);
    let tail = stream.len().checked_sub(ran as usize + 1);
    let tail = tail.map(|t| &stream[t..]);
    let want: Vec<Option<u32>> = (0..ran).map(Some).chain([None]).collect();
    let seen: Option<Vec<Option<u32>>> = tail.map(|t| {
        t.iter()
            .map(|m| match m {
                ToHost::ReplayRow(r) => Some(r.tick),
                _ => None,
            })
            .collect()
    });
    assert_eq!(
        seen.as_ref(),
        Some(&want),
        "the last replay ({samples} samples, {fed} sent)"
    );
    assert!(
        matches!(stream.last(), Some(ToHost::ReplayEnd { ticks }) if *ticks == ran),
        "the last replay's end: {:?}, {ran} ticks",
        stream.last()
    );
}

proptest! {
    // 32 runs in the test command (2.5 s); `PROPTEST_CASES` for a long run
    // (`scripts/long.sh`).
    #![proptest_config(ProptestConfig::with_cases(crate::common::cases(32, 1)))]

    #[test]
    fn any_run_keeps_the_actuator_and_the_answers_to_the_protocol(
        roaming in any::<bool>(),
        clock in prop_oneof![Just(0u32), u32::MAX - 4000..=u32::MAX, any::<u32>()],
        ops in ops(),
    ) {
        if roaming {
            run(Model::new(Rig::roaming_from(table2(), clock), true), &ops)?;
        } else {
            run(Model::new(Rig::glued_from(table2(), clock), false), &ops)?;
        }
    }
}

/// `ops` on the device, then what is left: its checks run out, then a hello; the
/// answers checked.
fn run<C: Contact<NODES, EDGES, 64, Wide>>(
    mut model: Model<C>,
    ops: &[Op],
) -> Result<(), TestCaseError> {
    for op in ops {
        model.run(op);
    }
    // What is left: the checks run out, then a hello.
    let mut spare = 20_000;
    while model.rig.server.checking() && spare > 0 {
        model.step(false);
        spare -= 1;
    }
    prop_assert!(spare > 0, "a tissue check never ended");
    // And a replay's rows, or its wait for a path that does not come.
    if !model.replays.is_empty() {
        let limit = BOARD.tick_hz * rates::REPLAY_STARVED_MS / 1000;
        for _ in 0..limit + P as u32 + 2 {
            model.step(false);
        }
    }
    model.message(&Msg::Hello);
    for _ in 0..3 {
        model.step(false);
    }
    let begun = check_answers(&model.rig.out, &model.answers);
    let last = model
        .replays
        .iter()
        .zip(&begun)
        .filter(|(_, b)| **b)
        .map(|(r, _)| *r)
        .next_back();
    check_replays(&model.rig.out, last);
    check_telemetry(&model);
    Ok(())
}

/// The telemetry stream: numbered without a gap (the rig's main loop polls every tick
/// and sends whatever it is given: nothing is dropped), and, where a `Watch` is on,
/// still coming at its period at the end of the run, the clock's wrap included.
fn check_telemetry<C: Contact<NODES, EDGES, 64, Wide>>(model: &Model<C>) {
    let samples: Vec<&Telemetry> = model
        .rig
        .out
        .iter()
        .filter_map(|m| match m {
            ToHost::Telemetry(t) => Some(t),
            _ => None,
        })
        .collect();
    for w in samples.windows(2) {
        assert_eq!(w[1].seq, w[0].seq.wrapping_add(1), "a gap: {:?}", w);
    }
    let now = model.now();
    if let Some((from, every)) = model.watch {
        if now.wrapping_sub(from) > 2 * every + 2 {
            let last = samples.last().map(|t| t.tick);
            assert!(
                last.is_some_and(|t| now.wrapping_sub(t) <= every + 1),
                "at tick {now}, the last sample {last:?} of a watch every {every} ticks"
            );
        }
    }
}
