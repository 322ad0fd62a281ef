//! The main loop's end of the host link (docs/link.md): USART2 at the board's baud rate,
//! its receive interrupt queueing the bytes, and [`HostLink`], which hands them to the
//! firmware's one link server ([`LinkServer`]: the same code as the host's soft device)
//! and writes its frames (transmit polled: QEMU 7.2 models no TXE interrupt; a 248-byte
//! frame takes 2.5 ms at 1 Mbaud). Everything it shares with the tick goes through the
//! [`BoardLink`] it is handed; the tick never waits on it.

use crate::variant::LinkPins;
use haptic_f405::config::BOARD;
use haptic_f405::device::{EDGES, NODES};
use haptic_f405::tissue::SEGMENTS;
use heapless::spsc::{Consumer, Producer, Queue};
use mccs::Wide;
use mccs_firmware::link::{LinkServer, LinkState, Session, Work};
use mccs_firmware::{Mailbox, Shared};
use stm32f4xx_hal::pac::{self, interrupt};
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::rcc::Clocks;
use stm32f4xx_hal::serial::{Rx, Tx};

/// Path samples a replay buffers.
pub const PATH: usize = 128;
/// Bytes the receive interrupt queues for the main loop: more than a replay's credit of
/// path samples in frames (128 × 12 B and their framing), and more than the frames that
/// arrive during one slice of a tissue check (5 ms at 1 Mbaud: 500 bytes).
pub const RX_QUEUE: usize = 2048;

/// What the tick and the main loop share for the link.
pub type BoardLink = LinkState<NODES, SEGMENTS, Wide>;
/// The main loop's work: a replay or a tissue check.
pub type BoardWork = Work<NODES, EDGES, SEGMENTS, Wide, PATH>;

/// USART2's receiver and the queue's producer, for its interrupt.
static LINK_RX: Mailbox<(Rx<pac::USART2>, Producer<'static, u8>)> = Mailbox::new();
/// Bytes the queue could not take (reported in the status).
static RX_DROPPED: Shared<u32> = Shared::new(0);

/// Why the link could not start.
#[derive(Clone, Copy, Debug)]
pub enum LinkStartError {
    /// The clock cannot make the baud rate.
    Baud,
}

/// The main loop's end of the host link.
pub struct HostLink {
    tx: Tx<pac::USART2>,
    rx: Consumer<'static, u8>,
    server: LinkServer<'static, NODES, EDGES, SEGMENTS, Wide, PATH>,
}

impl HostLink {
    /// USART2 on `pins` at the board's baud rate, its receive interrupt feeding `queue`;
    /// the server of `session` sharing `state` with the tick, its work in `work`.
    pub fn start(
        usart: pac::USART2,
        pins: LinkPins,
        clocks: &Clocks,
        queue: &'static mut Queue<u8, RX_QUEUE>,
        state: &'static BoardLink,
        work: &'static mut BoardWork,
        session: Session<SEGMENTS>,
    ) -> Result<Self, LinkStartError> {
        let serial = usart
            .serial(
                pins,
                stm32f4xx_hal::serial::Config::default().baudrate(BOARD.baud.bps()),
                clocks,
            )
            .map_err(|_| LinkStartError::Baud)?;
        let (tx, mut rx) = serial.split();
        rx.listen();
        let (producer, consumer) = queue.split();
        let _ = LINK_RX.post((rx, producer));
        Ok(Self {
            tx,
            rx: consumer,
            server: LinkServer::new(state, work, session, BOARD.check_steps_per_poll),
        })
    }

    /// Everything the link has to do now; whether there is more.
    pub fn poll(&mut self) -> bool {
        let (rx, tx) = (&mut self.rx, &mut self.tx);
        self.server
            .poll(&mut || rx.dequeue(), RX_DROPPED.get(), &mut |frame| {
                for &b in frame {
                    let _ = nb::block!(embedded_hal_nb::serial::Write::write(tx, b));
                }
                true
            })
            || self.rx.ready()
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
