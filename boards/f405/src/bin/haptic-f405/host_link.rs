//! The main loop's end of the host link (docs/link.md): USART2's receive interrupt queues
//! the bytes; [`HostLink::poll`] decodes them, answers (transmit polled: QEMU 7.2 models
//! no TXE interrupt), runs replays on its own solver, and hands the tick what it must see
//! — the guard's arm and disarm, the pose, a checked tissue — through the shared state and
//! the swap mailbox. The tick never waits on the link.

use crate::firmware::{LINK, MESH, SWAP, TELEMETRY};
use haptic_f405::config::BOARD;
use haptic_f405::device::{EDGES, NODES, SPACING_MM};
use haptic_f405::tissue::TISSUE;
use heapless::spsc::{Consumer, Producer};
use mccs::{ForceTable, Wide};
use mccs_firmware::link::{Effect, Live, Now, Replayer, Session};
use mccs_firmware::{Mailbox, Shared};
use mccs_link::{frame::parse, Core, Decoder, ToDevice, ToHost, MAX_FRAME};
use stm32f4xx_hal::pac::{self, interrupt};
use stm32f4xx_hal::serial::{Rx, Tx};

/// Path samples a replay buffers.
const PATH: usize = 128;
/// Bytes the receive interrupt queues for the main loop: more than a replay's credit of
/// path samples in frames (128 × 12 B and their framing), and more than a tissue chunk
/// while the main loop checks a tissue (the host waits for each chunk's status).
pub(crate) const RX_QUEUE: usize = 2048;

/// USART2's receiver and the queue's producer, for its interrupt.
pub(crate) static LINK_RX: Mailbox<(Rx<pac::USART2>, Producer<'static, u8>)> = Mailbox::new();
/// Bytes the queue could not take.
static RX_DROPPED: Shared<u32> = Shared::new(0);

/// The main loop's end of the host link.
pub(crate) struct HostLink {
    tx: Tx<pac::USART2>,
    rx: Consumer<'static, u8>,
    decoder: Decoder,
    session: Session<{ haptic_f405::tissue::SEGMENTS }>,
    replayer: &'static mut Replayer<NODES, EDGES, { haptic_f405::tissue::SEGMENTS }, Wide, PATH>,
    /// A swap posted: its table, hash and the tick's swap count before it.
    pending: Option<(ForceTable<{ haptic_f405::tissue::SEGMENTS }>, u32, u32, u32)>,
}

impl HostLink {
    pub(crate) fn new(tx: Tx<pac::USART2>, rx: Consumer<'static, u8>) -> Self {
        // In `.bss` (an initialised 13 KB static would take its image in flash), and
        // written once here.
        static mut REPLAYER: core::mem::MaybeUninit<
            Replayer<NODES, EDGES, { haptic_f405::tissue::SEGMENTS }, Wide, PATH>,
        > = core::mem::MaybeUninit::uninit();
        let live = Live {
            core: Core::M4f,
            grid: BOARD.grid,
            spacing: SPACING_MM,
            config: BOARD.solver(),
        };
        Self {
            tx,
            rx,
            decoder: Decoder::new(),
            session: Session::new(live, TISSUE),
            // SAFETY: the one reference to REPLAYER, taken once in the main loop, and
            // initialised before it is read.
            replayer: unsafe { (*core::ptr::addr_of_mut!(REPLAYER)).write(Replayer::new(false)) },
            pending: None,
        }
    }

    /// Everything the link has to do now; whether there is more.
    pub(crate) fn poll(&mut self) -> bool {
        let t = TELEMETRY.get();
        let mut now = Now {
            ticks: t.run.ticks,
            overruns: t.run.overruns,
            fault: t.run.fault.is_some(),
            armed: LINK.guard.get().armed(),
            pose: LINK.pose.get(),
        };
        let tx = &mut self.tx;
        let mut send = |m: &ToHost| {
            let mut buf = [0u8; MAX_FRAME];
            if let Ok(frame) = mccs_link::encode(m, &mut buf) {
                for &b in frame {
                    let _ = nb::block!(embedded_hal_nb::serial::Write::write(tx, b));
                }
            }
        };
        let mut bytes = 0;
        while let Some(b) = self.rx.dequeue() {
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
            LINK.guard.update(|g| g.frame(now.ticks));
            match self.session.handle(msg, now, self.replayer, &mut send) {
                Effect::None => {}
                Effect::Arm => LINK.guard.update(|g| g.arm(now.ticks)),
                Effect::Disarm => LINK.guard.update(|g| g.disarm()),
                Effect::Pose(origin) => {
                    LINK.pose.set(origin);
                    now.pose = origin;
                }
                Effect::Swap { set, tissue } => {
                    self.pending = Some((*set.table(), tissue, t.run.swaps, t.run.rejected_swaps));
                    LINK.post_swap(&SWAP, set);
                }
                Effect::WatchMesh(every) => LINK.mesh.set(every),
            }
            if bytes >= 512 {
                break;
            }
        }
        if let Some((table, tissue, swaps, rejected)) = self.pending {
            let t = TELEMETRY.get();
            if t.run.swaps > swaps {
                self.session.swapped(table, tissue, &mut send);
                self.pending = None;
            } else if t.run.rejected_swaps > rejected {
                send(&ToHost::Nak(mccs_link::NakReason::Solver));
                self.pending = None;
            }
        }
        if let Some(mesh) = MESH.take() {
            self.session.mesh(&mesh, &mut |m| {
                send(m);
                true
            });
        }
        let mut stepped = 0;
        while stepped < 4 && self.replayer.step(&mut send) {
            stepped += 1;
        }
        let flags = (t.run.force != [mccs::Force::ZERO; 3]) as u8
            | ((now.armed as u8) << 2)
            | ((now.fault as u8) << 3);
        self.session.telemetry(
            t.run.ticks,
            t.probe,
            t.run.force.map(|f| f.to_bits()),
            t.gain,
            flags,
            &mut |m| {
                send(m);
                true
            },
        );
        bytes > 0 || stepped > 0 || self.rx.ready()
    }
}

#[interrupt]
fn USART2() {
    static mut RX: Option<(Rx<pac::USART2>, Producer<'static, u8>)> = None;
    if RX.is_none() {
        *RX = LINK_RX.take();
    }
    let Some((rx, producer)) = RX.as_mut() else {
        return;
    };
    while let Ok(b) = embedded_hal_nb::serial::Read::read(rx) {
        if producer.enqueue(b).is_err() {
            RX_DROPPED.update(|n| *n = n.saturating_add(1));
        }
    }
}
