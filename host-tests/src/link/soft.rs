//! A device in software: the firmware's own link session, replayer and guard
//! (`mccs_firmware::link`) behind a unix socket, its ticks counted from the clock
//! (1 kHz). Its live patch stays at rest: its telemetry reads a probe at rest, its mesh
//! the patch's rest positions. What it answers
//! is what the firmware answers, so the CLI's tests run against it where QEMU would be
//! too slow; the tests against the board firmware in QEMU are `tests/link/qemu.rs`.

use mccs::{ForceTable64, Solver, SolverConfig, Topology, Wide};
use mccs_firmware::link::{Effect, Guard, Live, Mesh, Now, Replayer, Session};
use mccs_link::frame::parse;
use mccs_link::{encode, Core, Decoder, ToDevice, ToHost, MAX_FRAME};
use std::io::{Read, Write};
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::Path;
use std::time::{Duration, Instant};

/// The board's capacity: the N = 8 patch.
const NODES: usize = mccs::topology::standard_capacity(8).0;
const EDGES: usize = mccs::topology::standard_capacity(8).1;
/// Buffered path samples.
pub const PATH: usize = 128;

/// Serves connections on `socket` (a new unix socket) one after another in a thread, as
/// one device with `table` live on the standard 5 × 5 patch (its state kept from one
/// connection to the next); returns once it listens.
pub fn serve(socket: &Path, table: ForceTable64) -> std::io::Result<std::thread::JoinHandle<()>> {
    let _ = std::fs::remove_file(socket);
    let listener = UnixListener::bind(socket)?;
    Ok(std::thread::spawn(move || {
        let live = Live {
            core: Core::M4f,
            grid: 5,
            spacing: 2.5,
            config: SolverConfig::default(),
        };
        let rest = Topology::standard_patch(5, 2.5)
            .ok()
            .and_then(|t| Solver::new(t, table, &live.config).ok());
        let Some(rest) = rest else { return };
        let mut device = Device {
            rest: Box::new(rest),
            mesh_every: 0,
            session: Session::<64>::new(live, table),
            replayer: Box::new(Replayer::new(false)),
            guard: Guard::at_rate(1000),
            pose: [0; 3],
            start: Instant::now(),
        };
        for stream in listener.incoming() {
            match stream {
                Ok(s) => run(s, &mut device),
                Err(_) => return,
            }
        }
    }))
}

/// The device's state.
struct Device {
    /// The live patch, at rest.
    rest: Box<Solver<NODES, EDGES, 64, Wide>>,
    /// Ticks between meshes (0: none).
    mesh_every: u32,
    session: Session<64>,
    replayer: Box<Replayer<NODES, EDGES, 64, Wide, PATH>>,
    guard: Guard,
    pose: [i32; 3],
    start: Instant,
}

fn run(mut stream: UnixStream, d: &mut Device) {
    let Device {
        rest,
        mesh_every,
        session,
        replayer,
        guard,
        pose,
        start,
    } = d;
    let mut decoder = Decoder::new();
    let _ = stream.set_read_timeout(Some(Duration::from_millis(1)));
    let mut out: Vec<u8> = Vec::new();
    let mut buf = [0u8; 512];
    let mut last_tick = start.elapsed().as_millis() as u32;
    loop {
        let tick = start.elapsed().as_millis() as u32;
        let n = match stream.read(&mut buf) {
            Ok(0) => return,
            Ok(n) => n,
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) =>
            {
                0
            }
            Err(_) => return,
        };
        let mut send = |m: &ToHost| {
            let mut f = [0u8; MAX_FRAME];
            if let Ok(bytes) = encode(m, &mut f) {
                out.extend_from_slice(bytes);
            }
        };
        for &b in &buf[..n] {
            match decoder.push(b) {
                Some(Ok(payload)) => match parse::<ToDevice>(payload) {
                    Ok(msg) => {
                        guard.frame(tick);
                        let now = Now {
                            ticks: tick,
                            overruns: 0,
                            fault: false,
                            armed: guard.armed(),
                            pose: *pose,
                        };
                        match session.handle(msg, now, replayer, &mut send) {
                            Effect::Arm => guard.arm(tick),
                            Effect::Disarm => guard.disarm(),
                            Effect::Swap { set, tissue } => {
                                session.swapped(*set.table(), tissue, &mut send)
                            }
                            Effect::Pose(p) => *pose = p,
                            Effect::WatchMesh(every) => *mesh_every = every as u32,
                            Effect::None => {}
                        }
                    }
                    Err(_) => session.bad_frame(),
                },
                Some(Err(_)) => session.bad_frame(),
                None => {}
            }
        }
        for _ in 0..32 {
            if !replayer.step(&mut send) {
                break;
            }
        }
        for t in last_tick..=tick {
            let gain = guard.gain(t);
            let flags = if guard.armed() { 4 } else { 0 };
            session.telemetry(t, [0; 3], [0; 3], gain, flags, &mut |m| {
                send(m);
                true
            });
            if *mesh_every != 0 && t % *mesh_every == 0 {
                session.mesh(&Mesh::of(rest, t), &mut |m| {
                    send(m);
                    true
                });
            }
        }
        last_tick = tick + 1;
        if !out.is_empty() {
            if stream.write_all(&out).is_err() {
                return;
            }
            out.clear();
        }
    }
}
