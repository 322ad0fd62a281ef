//! A device in software: the arm board's own link server, session, guard and tick
//! (`mccs_firmware::link`, the board's `BoardConfig` and roaming contact) on a simulated
//! probe that palpates the tissue over and over (the demo's palpation, 4 s a round), at
//! 1 kHz of the host's clock, behind a unix socket or a TCP port. What it answers is
//! what the board answers — the same code — so the CLI's and the client's tests run
//! against it where QEMU would be too slow (the tests against the board firmware in QEMU
//! are `tests/link/qemu.rs`).

use haptic_f405::device::{linked, roaming, BoardRoaming, EDGES, NODES, SPACING_MM};
use haptic_f405::BOARD;
use mccs::{Force, ForceTable64, Length, Solver, Topology, Wide};
use mccs_firmware::link::session::LastRun;
use mccs_firmware::link::{
    Guard, GuardTimes, LinkServer, LinkState, LinkedDevice, Live, Session, Work,
};
use mccs_firmware::{Controller, HapticDevice, ProbePath};
use mccs_link::StopCause;
use mccs_link::{ContactKind, Core, DeviceKind};
use std::collections::VecDeque;
use std::io::{Read, Write};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Path samples a replay buffers (the board's).
pub const PATH: usize = 128;
/// The palpation's ticks, a round.
const ROUND: u32 = 4000;

/// The soft device's probe: the demo's palpation, over and over.
struct Palpating {
    path: ProbePath<9>,
    tick: u32,
}

impl HapticDevice for Palpating {
    type Error = core::convert::Infallible;
    fn read_position(&mut self) -> Result<[Length; 3], Self::Error> {
        let p = self.path.at(self.tick % ROUND);
        self.tick = self.tick.wrapping_add(1);
        Ok(p)
    }
    fn write_force(&mut self, _force: [Force; 3]) -> Result<(), Self::Error> {
        Ok(())
    }
    fn safe_state(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
}

type SoftController = Controller<LinkedDevice<Palpating>, NODES, EDGES, 64, Wide, BoardRoaming>;

/// A byte stream to one host.
trait Stream: Read + Write + Send {}
impl<T: Read + Write + Send> Stream for T {}

/// Where the soft device listens.
enum Listener {
    #[cfg(unix)]
    Unix(std::os::unix::net::UnixListener),
    Tcp(std::net::TcpListener),
}

impl Listener {
    fn accept(&self) -> Option<Box<dyn Stream>> {
        match self {
            #[cfg(unix)]
            Listener::Unix(l) => l.accept().ok().map(|(s, _)| {
                let _ = s.set_nonblocking(true);
                Box::new(s) as Box<dyn Stream>
            }),
            Listener::Tcp(l) => l.accept().ok().map(|(s, _)| {
                let _ = s.set_nonblocking(true);
                let _ = s.set_nodelay(true);
                Box::new(s) as Box<dyn Stream>
            }),
        }
    }
}

/// A soft device running in a thread until [`SoftDevice::stop`] or drop.
pub struct SoftDevice {
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
    addr: String,
}

impl SoftDevice {
    /// Its address (`unix:PATH` or `tcp:HOST:PORT`).
    pub fn addr(&self) -> &str {
        &self.addr
    }

    /// Stops it.
    pub fn stop(mut self) {
        self.halt();
    }

    fn halt(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for SoftDevice {
    fn drop(&mut self) {
        self.halt();
    }
}

/// Serves hosts on `socket` (a new unix socket) one after another, as one device with
/// `table` live (its state kept from one connection to the next); returns once it
/// listens. It stops with the test process.
#[cfg(unix)]
pub fn serve(socket: &Path, table: ForceTable64) -> std::io::Result<SoftDevice> {
    let _ = std::fs::remove_file(socket);
    let l = std::os::unix::net::UnixListener::bind(socket)?;
    l.set_nonblocking(true)?;
    spawn(
        Listener::Unix(l),
        table,
        format!("unix:{}", socket.display()),
    )
}

/// Serves hosts on TCP `host:port` (port 0: any free port; the address says which).
pub fn serve_tcp(host_port: &str, table: ForceTable64) -> std::io::Result<SoftDevice> {
    let l = std::net::TcpListener::bind(host_port)?;
    l.set_nonblocking(true)?;
    let addr = format!("tcp:{}", l.local_addr()?);
    spawn(Listener::Tcp(l), table, addr)
}

fn spawn(listener: Listener, table: ForceTable64, addr: String) -> std::io::Result<SoftDevice> {
    let stop = Arc::new(AtomicBool::new(false));
    let s = stop.clone();
    let thread = std::thread::Builder::new()
        .name("mccs-soft-device".into())
        .spawn(move || run(listener, table, &s))?;
    Ok(SoftDevice {
        stop,
        thread: Some(thread),
        addr,
    })
}

/// The device as its hello describes it: the arm board, simulated.
fn live() -> Live {
    Live {
        device: DeviceKind::Arm,
        simulated: true,
        core: Core::M4f,
        contact: ContactKind::Roaming,
        grid: BOARD.grid,
        spacing: SPACING_MM,
        tissue: BOARD.tissue_nodes.map(|n| n as u8),
        config: BOARD.solver(),
        workspace: BOARD.workspace_q24(),
        pose_speed_mm_s: BOARD.pose_speed_mm_s,
        pose_turn_deg_s: BOARD.pose_turn_deg_s,
        baud: BOARD.baud,
        budget: BOARD.budget(),
        narrow: false,
    }
}

/// What the soft device says of its "last run" (it has none: a fixture, so that `mccs
/// link blackbox` has a record to read): its palpation's first [`LAST_RUN_TICKS`] ticks,
/// recorded as the board records a tick, stopped there as if its encoder's frames had
/// failed (a read fault), then ended by a HardFault at PC `0x0800_1234`, and kept
/// through a watchdog's reset (IWDG). Made once a table, kept for the process (a
/// static: every soft device on that table shares it).
pub fn last_run(table: ForceTable64) -> &'static LastRun {
    static RUNS: std::sync::Mutex<Vec<(ForceTable64, &'static LastRun)>> =
        std::sync::Mutex::new(Vec::new());
    let mut runs = RUNS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, run)) = runs.iter().find(|(t, _)| *t == table) {
        return run;
    }
    let run = record_last_run(table);
    runs.push((table, run));
    run
}

fn record_last_run(table: ForceTable64) -> &'static LastRun {
    use haptic_f405::black_box::{record, tick_record};
    use haptic_f405::device::DevicePart;
    let mut live = Box::new(LastRun::EMPTY);
    live.start();
    if let Some(mut ctl) = controller(table) {
        ctl.device_mut().set_gain(mccs_link::scale::GAIN_FULL);
        for _ in 0..LAST_RUN_TICKS {
            ctl.tick(None);
            let (run, status) = (ctl.telemetry(), ctl.device().status());
            let counts = ctl
                .device()
                .probe()
                .map(|x| (x.to_num::<f64>() * 1000.0) as i32);
            let tick = tick_record(&run, &status, counts, ctl.device().gain());
            record(&mut live, tick, run.fault, None);
        }
    }
    live.stop(
        StopCause::Read,
        DevicePart::Encoder.code(),
        LAST_RUN_TICKS - 1,
        0,
    );
    live.record(mccs_link::BoxTick {
        tick: LAST_RUN_TICKS + 99,
        ..Default::default()
    });
    live.end(StopCause::HardFault, 0x0800_1234);
    let mut last = Box::new(LastRun::EMPTY);
    last.keep(&mut live, 1 << 29);
    Box::leak(last)
}

/// The ticks of the soft device's "last run" ([`last_run`]).
pub const LAST_RUN_TICKS: u32 = 600;

fn controller(table: ForceTable64) -> Option<Box<SoftController>> {
    let topo = Topology::standard_patch(BOARD.grid, SPACING_MM).ok()?;
    let mut solver = Solver::new(topo, table, &BOARD.solver()).ok()?;
    let contact = roaming(&BOARD, &mut solver).ok()?;
    let device = Palpating {
        path: mccs_firmware::palpation_path(BOARD.tick_hz).ok()?,
        tick: 0,
    };
    let mut c = Controller::with_contact(solver, contact, linked(&BOARD, device), u32::MAX);
    c.set_overrun_limit(BOARD.max_overruns_in_row);
    Some(Box::new(c))
}

fn run(listener: Listener, table: ForceTable64, stop: &AtomicBool) {
    let Some(mut ctl) = controller(table) else {
        return;
    };
    let state: LinkState<NODES, 64, Wide> = LinkState::new(Guard::new(GuardTimes::at_rate(
        BOARD.tick_hz,
        BOARD.ramp_ms,
    )));
    let mut work: Box<Work<NODES, EDGES, 64, Wide, PATH>> = Box::default();
    let friction = mccs::Friction::new(BOARD.mu_s, BOARD.mu_k).ok();
    let session = Session::new(live(), table, friction).with_black_box(last_run(table));
    let mut server = LinkServer::new(&state, &mut work, session, BOARD.check_steps_per_poll);
    let start = Instant::now();
    let mut ticks: u64 = 0;
    let mut stream: Option<Box<dyn Stream>> = None;
    let mut rx: VecDeque<u8> = VecDeque::new();
    let mut buf = [0u8; 4096];
    while !stop.load(Ordering::SeqCst) {
        if stream.is_none() {
            stream = listener.accept();
            rx.clear();
        }
        if let Some(s) = stream.as_mut() {
            match s.read(&mut buf) {
                Ok(0) => stream = None,
                Ok(n) => rx.extend(&buf[..n]),
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {}
                Err(_) => stream = None,
            }
        }
        // The ticks due by the host's clock (at most 100 at once, after a stall).
        let due = (start.elapsed().as_micros() as u64 * BOARD.tick_hz as u64) / 1_000_000;
        let mut ran = 0;
        while ticks < due && ran < 100 {
            state.run_tick(&mut ctl);
            ctl.note_on_time();
            ticks += 1;
            ran += 1;
        }
        if ticks < due {
            ticks = due;
        }
        let mut out: Vec<u8> = Vec::new();
        let busy = server.poll(&mut || rx.pop_front(), 0, &mut |frame| {
            out.extend_from_slice(frame);
            true
        });
        if let Some(s) = stream.as_mut() {
            if !out.is_empty() && write_all(s, &out).is_err() {
                stream = None;
            }
        }
        if !busy && rx.is_empty() {
            std::thread::sleep(Duration::from_micros(200));
        }
    }
}

/// Writes all of `bytes` to a non-blocking stream.
fn write_all(s: &mut Box<dyn Stream>, mut bytes: &[u8]) -> std::io::Result<()> {
    let deadline = Instant::now() + Duration::from_secs(2);
    while !bytes.is_empty() {
        match s.write(bytes) {
            Ok(0) => return Err(std::io::ErrorKind::WriteZero.into()),
            Ok(n) => bytes = &bytes[n..],
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                if Instant::now() > deadline {
                    return Err(e);
                }
                std::thread::sleep(Duration::from_micros(100));
            }
            Err(e) => return Err(e),
        }
    }
    s.flush()
}
