//! The link's fuzz checks: the device's side on any bytes (`link_device`), the scene's
//! library's side on any bytes from a device (`link_host`), and a scene's script
//! (`link_script`); what a peer's bytes are made of (`chunk_stream`).

use super::one_line;
use mccs::Params;
use std::path::Path;

/// What the fuzzed device says it is: the simulated 1-DOF board, glued, N = 3.
fn fuzzed_device_facts(config: mccs::SolverConfig) -> mccs_firmware::link::Live {
    use mccs_firmware::link::{Live, TickBudget};
    use mccs_link::{ContactKind, Core, DeviceKind};
    Live {
        device: DeviceKind::OneDof,
        simulated: true,
        core: Core::M4f,
        contact: ContactKind::Glued,
        grid: 3,
        spacing: 2.5,
        tissue: [3, 3],
        config,
        workspace: [[-50 << 24; 3], [50 << 24; 3]],
        pose_speed_mm_s: 200,
        pose_turn_deg_s: 180,
        baud: mccs_link::rates::DEFAULT_BAUD,
        budget: TickBudget {
            tick: 84_000,
            base: 10_000,
            per_substep: 5_000,
        },
        narrow: false,
    }
}

/// The device's side of the link on any bytes: the board's own server, link state and
/// glued controller on the N = 3 patch, a tick between polls of at most 64 bytes; no
/// panic; a valid `Hello` after them is answered. The bytes are raw, or after a first
/// `F` chunks each framed or not ([`chunk_stream`]).
pub fn link_device(data: &[u8]) {
    use mccs_firmware::link::{
        Guard, GuardTimes, LinkServer, LinkState, LinkedDevice, Session, Work,
    };
    use mccs_firmware::{Controller, SimulatedDevice};
    use mccs_link::{encode, parse, Decoder, ToDevice, ToHost, MAX_FRAME};
    const N: usize = mccs::topology::standard_capacity(3).0;
    const E: usize = mccs::topology::standard_capacity(3).1;
    static TABLE: std::sync::OnceLock<mccs::ForceTable64> = std::sync::OnceLock::new();
    let table = *TABLE.get_or_init(|| mccs::ForceTable64::new(&Params::TABLE2).expect("Table 2"));
    let config = mccs::SolverConfig::default();
    let live = fuzzed_device_facts(config);
    let state: LinkState<N, 64, mccs::Wide> =
        LinkState::new(Guard::new(GuardTimes::at_rate(1000, 500)));
    let mut work: Box<Work<N, E, 64, mccs::Wide, 16>> = Box::default();
    let mut server = LinkServer::new(&state, &mut work, Session::new(live, table, None), 64);
    let topo = mccs::Topology::<N, E>::standard_patch(3, 2.5).expect("N = 3");
    let solver = mccs::Solver::new(topo, table, &config).expect("Table 2 on N = 3");
    let path = mccs_firmware::indentation_path(1000).expect("the indentation");
    let device = LinkedDevice::new(
        SimulatedDevice::new(path),
        mccs::TissuePose::new(200.0, 180.0, 1000.0),
        solver.max_force(),
    );
    let mut ctl = Controller::new(solver, device, u32::MAX);
    let mut hello = [0u8; MAX_FRAME];
    let hello = encode(&ToDevice::Hello, &mut hello)
        .expect("a frame")
        .to_vec();
    // The bytes as they come, or, after a first byte `F`, chunks each raw or framed
    // (`chunk_stream`), so that a mutated message reaches the session past the CRC.
    let stream = match data.split_first() {
        Some((b'F', rest)) => chunk_stream(rest),
        _ => data.to_vec(),
    };
    let all: Vec<u8> = stream.into_iter().chain([0u8]).chain(hello).collect();
    let mut decoder = Decoder::new();
    let mut answers = Vec::new();
    let mut rx = all.iter().copied();
    let mut left = all.len();
    // Every byte read, then a few polls for the work the bytes started (a replay, a
    // check) to reach the hello.
    for _ in 0..all.len() / 8 + 2000 {
        state.run_tick(&mut ctl);
        let mut chunk: Vec<u8> = rx.by_ref().take(64).collect();
        left -= chunk.len();
        let mut bytes = chunk.drain(..);
        let mut sent = Vec::new();
        server.poll(&mut || bytes.next(), 0, &mut |f| {
            sent.extend_from_slice(f);
            true
        });
        for b in sent {
            if let Some(Ok(p)) = decoder.push(b) {
                answers.push(parse::<ToHost>(p).expect("the device sends messages"));
            }
        }
        if left == 0
            && answers
                .iter()
                .rev()
                .take(64)
                .any(|m| matches!(m, ToHost::Hello(_)))
        {
            return;
        }
    }
    panic!("the hello after the bytes was not answered");
}

/// A peer's bytes for [`link_host`] and [`link_device`]: chunks of `[tag, length, bytes…]` (the last one
/// takes what is left), each sent raw where its tag is even, or as one frame around its
/// bytes (at most [`mccs_link::MAX_PAYLOAD`]) where it is odd, so that the messages'
/// parser is reached past the CRC; then a delimiter.
fn chunk_stream(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut rest = data;
    while let [tag, len, tail @ ..] = rest {
        let n = (*len as usize).min(tail.len());
        let (chunk, next) = tail.split_at(n);
        if tag % 2 == 0 {
            out.extend_from_slice(chunk);
        } else {
            out.extend(frame_around(&chunk[..n.min(mccs_link::MAX_PAYLOAD)]));
        }
        rest = next;
    }
    out.extend_from_slice(rest);
    out.push(0);
    out
}

/// Bytes that postcard writes as they are (a tuple of `u8`s: no length in front).
struct Verbatim<'a>(&'a [u8]);

impl serde::Serialize for Verbatim<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeTuple;
        let mut t = s.serialize_tuple(self.0.len())?;
        for b in self.0 {
            t.serialize_element(b)?;
        }
        t.end()
    }
}

/// `payload` (at most [`mccs_link::MAX_PAYLOAD`] bytes) framed as
/// [`mccs_link::encode`] frames a message: its CRC, COBS and the delimiter.
fn frame_around(payload: &[u8]) -> Vec<u8> {
    let mut out = [0u8; mccs_link::MAX_FRAME];
    mccs_link::encode(&Verbatim(payload), &mut out)
        .expect("a payload that fits")
        .to_vec()
}

/// A hello the library takes: the soft device's, read once.
fn soft_hello() -> mccs_link::HelloInfo {
    static HELLO: std::sync::OnceLock<mccs_link::HelloInfo> = std::sync::OnceLock::new();
    *HELLO.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("mccs-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a temporary folder");
        let table = mccs::ForceTable64::new(&Params::TABLE2).expect("Table 2");
        let soft = crate::link::soft::serve(&dir.join("hello.sock"), table).expect("a soft device");
        let hello = mccs_client::Device::open(soft.addr())
            .expect("its hello")
            .info()
            .hello;
        soft.stop();
        hello
    })
}

/// A device that answers a `Hello` with `hello` and every other request with a `Status`,
/// and sends `bytes` after its first answer; it ends when the host closes.
fn scripted_device(
    listener: std::os::unix::net::UnixListener,
    hello: mccs_link::HelloInfo,
    bytes: Vec<u8>,
) {
    use mccs_link::{encode, parse, Decoder, StatusInfo, ToDevice, ToHost, MAX_FRAME};
    use std::io::{Read, Write};
    let Ok((mut s, _)) = listener.accept() else {
        return;
    };
    let _ = s.set_read_timeout(Some(std::time::Duration::from_secs(30)));
    let (mut decoder, mut buf, mut sent) = (Decoder::new(), [0u8; 256], false);
    while let Ok(n @ 1..) = s.read(&mut buf) {
        for &b in &buf[..n] {
            let Some(Ok(p)) = decoder.push(b) else {
                continue;
            };
            let reply = match parse::<ToDevice>(p) {
                Ok(ToDevice::Hello) => ToHost::Hello(hello),
                _ => ToHost::Status(StatusInfo::default()),
            };
            let mut frame = [0u8; MAX_FRAME];
            let frame = encode(&reply, &mut frame).expect("a frame");
            if s.write_all(frame).is_err() || (!sent && s.write_all(&bytes).is_err()) {
                return;
            }
            sent = true;
        }
    }
}

/// The scene's library's side of the link on any bytes from a device (`chunk_stream`),
/// sent after its hello's answer: no thread panics, what the library keeps of it is
/// finite, and an error is one line. Where the bytes hold no message at all (noise on
/// the line), the library drops each frame and counts it as the decoder does, and the
/// next request is answered.
pub fn link_host(data: &[u8]) {
    use mccs_link::{parse, Decoder, ToHost};
    static N: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let hello = soft_hello();
    let bytes = chunk_stream(data);
    let (mut dropped, mut messages) = (0u32, 0usize);
    let mut decoder = Decoder::new();
    for &b in &bytes {
        match decoder.push(b) {
            Some(Ok(p)) if parse::<ToHost>(p).is_ok() => messages += 1,
            Some(_) => dropped += 1,
            None => {}
        }
    }
    let dir = std::env::temp_dir().join(format!("mccs-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let n = N.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let socket = dir.join(format!("host-{n}.sock"));
    let _ = std::fs::remove_file(&socket);
    let listener = std::os::unix::net::UnixListener::bind(&socket).expect("a socket");
    let device = std::thread::spawn(move || scripted_device(listener, hello, bytes));
    let options = mccs_client::Options {
        answer_timeout: std::time::Duration::from_secs(10),
        ..Default::default()
    };
    let d = mccs_client::Device::open_with(&format!("unix:{}", socket.display()), options)
        .expect("the hello is answered before the bytes");
    let status = d.status();
    if messages == 0 {
        assert!(status.is_ok(), "{status:?}");
        assert_eq!(d.bad_frames(), dropped);
    } else if let Err(e) = &status {
        one_line(&e.to_string(), "");
    }
    if let Some(t) = d.telemetry() {
        let all = [t.probe_mm, t.force_n, t.duties, t.proxy_mm];
        assert!(
            all.iter()
                .flatten()
                .chain(&t.window_mm)
                .all(|x| x.is_finite())
                && t.gain.is_finite()
        );
    }
    if let Some(m) = d.mesh() {
        assert!(m
            .nodes
            .iter()
            .flat_map(|n| n.position_mm)
            .all(f64::is_finite));
    }
    drop(d);
    device.join().expect("the device's thread");
    let _ = std::fs::remove_file(&socket);
}

/// A scene's script (`mccs link script`): a one-line error naming the file and a line,
/// or steps each on a line that names it, in order. A `load` reads no file here: its
/// tissue is Table 2's, but for a path that names `missing`, which is an error.
pub fn link_script(data: &[u8]) {
    use crate::cli::link_script::Script;
    static TISSUE: std::sync::OnceLock<mccs_client::Tissue> = std::sync::OnceLock::new();
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let tissue =
        TISSUE.get_or_init(|| mccs_client::Tissue::from_params(&Params::TABLE2).expect("Table 2"));
    let load = |path: &Path| {
        if path.to_string_lossy().contains("missing") {
            Err(format!(
                "{}: cannot read: no such file",
                mccs_client::shown::Shown(&path.to_string_lossy())
            ))
        } else {
            Ok(tissue.clone())
        }
    };
    match Script::parse(text, Path::new("fuzz.txt"), &load) {
        Ok(script) => {
            let lines: Vec<&str> = text.lines().collect();
            let mut last = 0;
            for (n, name) in script.step_names() {
                assert!(n > last && n <= lines.len(), "line {n}");
                let first = lines[n - 1]
                    .split('#')
                    .next()
                    .unwrap_or("")
                    .split_whitespace()
                    .next();
                assert_eq!(first, Some(name), "line {n}");
                last = n;
            }
        }
        Err(e) => {
            assert_eq!(e.status, 2);
            one_line(&e.message, "fuzz.txt:");
        }
    }
}
