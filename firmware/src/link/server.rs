//! [`LinkServer`]: the main loop's end of the host link, the one message handler of
//! every device — the board and the host's soft device run this same code, so that what
//! a scene meets (answers, ack timing, the mesh clock, the flags) is the same by
//! construction. Each [`LinkServer::poll`]:
//!
//! 1. decodes the bytes received so far (at most [`RX_BYTES_PER_POLL`]), each valid
//!    frame feeding the guard, each message handled by the [`Session`] and its effect
//!    applied to the [`LinkState`] the tick reads;
//! 2. acknowledges a tissue once the tick runs it;
//! 3. runs a slice of its [`Work`]: a replay's rows, or a tissue check's steps (at most
//!    `check_steps` a poll: the board sets them to 5 ms of its core), and hands a checked
//!    tissue to the tick;
//! 4. sends the mesh the tick took, and the telemetry that is due.
//!
//! The tick never waits on it; it never holds the main loop longer than one slice.

use super::check::CheckedTissue;
use super::session::{Effect, Session};
use super::state::{LinkState, Swap};
use super::work::Work;
use mccs::{Arith, ForceTable};
use mccs_link::{encode, parse, Decoder, NakReason, ToDevice, ToHost, MAX_FRAME};

/// Bytes one poll decodes at most (then the rest of its work runs).
pub const RX_BYTES_PER_POLL: usize = 512;
/// Replay rows one poll runs at most.
pub const REPLAY_ROWS_PER_POLL: u32 = 4;

/// A tissue handed to the tick, until it runs it.
struct Pending<const S: usize> {
    table: ForceTable<S>,
    hash: u32,
    friction: Option<mccs::Friction>,
    swaps: u32,
    rejected: u32,
}

/// The main loop's end of the link.
pub struct LinkServer<'a, const N: usize, const E: usize, const S: usize, A: Arith, const P: usize>
{
    state: &'a LinkState<N, S, A>,
    work: &'a mut Work<N, E, S, A, P>,
    session: Session<S>,
    decoder: Decoder,
    pending: Option<Pending<S>>,
    check_steps: u32,
}

impl<'a, const N: usize, const E: usize, const S: usize, A: Arith, const P: usize>
    LinkServer<'a, N, E, S, A, P>
{
    /// The server of `session`, sharing `state` with the tick, its work in `work`; a
    /// tissue check runs `check_steps` steps a poll.
    pub fn new(
        state: &'a LinkState<N, S, A>,
        work: &'a mut Work<N, E, S, A, P>,
        session: Session<S>,
        check_steps: u32,
    ) -> Self {
        Self {
            state,
            work,
            session,
            decoder: Decoder::new(),
            pending: None,
            check_steps: check_steps.max(1),
        }
    }

    /// The session.
    pub fn session(&self) -> &Session<S> {
        &self.session
    }

    /// Whether a tissue is being checked.
    pub fn checking(&self) -> bool {
        self.work.checking()
    }

    /// Everything the link has to do now: `rx` gives the bytes received (`None` when
    /// there are no more), `rx_dropped` counts those the receive queue lost, `tx` sends
    /// one frame (false when it could not: counted as a drop where it matters). Whether
    /// there is more to do.
    pub fn poll(
        &mut self,
        rx: &mut dyn FnMut() -> Option<u8>,
        rx_dropped: u32,
        tx: &mut dyn FnMut(&[u8]) -> bool,
    ) -> bool {
        let mut send = |m: &ToHost| {
            let mut buf = [0u8; MAX_FRAME];
            match encode(m, &mut buf) {
                Ok(frame) => tx(frame),
                Err(_) => false,
            }
        };
        let snap = self.state.snapshot();
        let mut bytes = 0;
        while bytes < RX_BYTES_PER_POLL {
            let Some(b) = rx() else { break };
            bytes += 1;
            let Some(frame) = self.decoder.push(b) else {
                continue;
            };
            let msg = match frame.and_then(parse::<ToDevice>) {
                Ok(m) => m,
                Err(_) => {
                    self.session.bad_frame();
                    continue;
                }
            };
            self.state.frame(snap.ticks);
            let effect = self.session.handle(
                msg,
                &snap,
                self.state.armed(),
                rx_dropped,
                self.work,
                &mut |m| {
                    send(m);
                },
            );
            match effect {
                Effect::None => {}
                Effect::Arm => self.state.arm(snap.ticks),
                Effect::Disarm => self.state.disarm(),
                Effect::Pose(p) => self.state.set_pose(p),
                Effect::WatchMesh(every) => self.state.set_mesh_every(every),
            }
        }
        self.acknowledge(&mut |m| {
            send(m);
        });
        let (worked, checked) = self.work.run(
            snap.ticks,
            REPLAY_ROWS_PER_POLL,
            self.check_steps,
            &mut |m| {
                send(m);
            },
        );
        if let Some(outcome) = checked {
            self.hand_over(outcome, &mut |m| {
                send(m);
            });
        }
        if let Some(mesh) = self.state.take_mesh() {
            self.session.mesh(&mesh, &mut send);
        }
        let snap = self.state.snapshot();
        self.session
            .telemetry(&snap, self.work.checking(), &mut send);
        bytes > 0 || worked
    }

    /// A checked tissue to the tick (acknowledged once it runs it), or the check's
    /// refusal.
    fn hand_over(
        &mut self,
        outcome: Result<CheckedTissue<S, A>, NakReason>,
        out: &mut dyn FnMut(&ToHost),
    ) {
        match outcome {
            Ok(t) => {
                let snap = self.state.snapshot();
                self.pending = Some(Pending {
                    table: *t.set.table(),
                    hash: t.hash,
                    friction: t.friction,
                    swaps: snap.swaps,
                    rejected: snap.rejected_swaps,
                });
                self.state.post_swap(Swap {
                    set: t.set,
                    friction: t.friction,
                });
            }
            Err(r) => out(&ToHost::Nak(r)),
        }
    }

    /// `Ack` once the tick has swapped the tissue in (`Nak` if it refused it).
    fn acknowledge(&mut self, out: &mut dyn FnMut(&ToHost)) {
        let Some(p) = &self.pending else { return };
        let snap = self.state.snapshot();
        if snap.swaps > p.swaps {
            self.session.swapped(p.table, p.hash, p.friction, out);
            self.pending = None;
        } else if snap.rejected_swaps > p.rejected {
            out(&ToHost::Nak(NakReason::Solver));
            self.pending = None;
        }
    }
}
