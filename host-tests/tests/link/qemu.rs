//! The board firmware in QEMU behind `mccs link` (`scripts/qemu-link.sh`): it answers
//! `hello` within 50 ticks, takes a tissue and replays a path with roaming and friction
//! exactly as the host's fixed replay does, drops every corrupted frame (counted) and
//! keeps its tissue and pose, refuses bad tissues with their reason and no overrun, fades
//! the force of a silent armed host to zero within 120 ticks, and streams telemetry whose
//! gaps are its drops. The figures go out as `LINK` lines (docs/link.md).
//!
//! QEMU takes a while to start and run: the test command runs this test in its own stage
//! (`MCCS_LINK_QEMU=1`); `cargo test` alone skips it, saying so.

use crate::cli::mccs_ok;
use mccs::{ForceTable64, Params};
use mccs_host::link::{Addr, Link};
use mccs_link::message::*;
use mccs_link::{encode, table_bytes, MAX_FRAME};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// QEMU, stopped with the test.
struct Qemu(Child);

impl Drop for Qemu {
    fn drop(&mut self) {
        // The script's process group: the script, QEMU and the decoder.
        let _ = Command::new("kill")
            .args(["--", &format!("-{}", self.0.id())])
            .status();
        let _ = self.0.wait();
    }
}

fn root() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn start(socket: &Path) -> Qemu {
    use std::os::unix::process::CommandExt;
    let log = std::fs::File::create(root().join("target/qemu/link-firmware.log")).unwrap();
    let child = Command::new("bash")
        .arg(root().join("scripts/qemu-link.sh"))
        .arg(socket)
        .current_dir(root())
        .stdin(Stdio::null())
        .stdout(log)
        .stderr(Stdio::inherit())
        .process_group(0)
        .spawn()
        .expect("scripts/qemu-link.sh");
    let qemu = Qemu(child);
    let deadline = Instant::now() + Duration::from_secs(240);
    while !socket.exists() {
        assert!(Instant::now() < deadline, "QEMU's socket never appeared");
        std::thread::sleep(Duration::from_millis(100));
    }
    qemu
}

fn ask(link: &mut Link, msg: &ToDevice, want: impl Fn(&ToHost) -> bool) -> ToHost {
    link.send(msg).unwrap();
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        match link.recv(deadline).unwrap() {
            Some(m) if want(&m) => return m,
            Some(_) => {}
            None => panic!("no answer to {msg:?}"),
        }
    }
}

fn status(link: &mut Link) -> StatusInfo {
    match ask(link, &ToDevice::Status, |m| matches!(m, ToHost::Status(_))) {
        ToHost::Status(s) => s,
        _ => unreachable!(),
    }
}

fn hello(link: &mut Link) -> HelloInfo {
    match ask(link, &ToDevice::Hello, |m| matches!(m, ToHost::Hello(_))) {
        ToHost::Hello(h) => h,
        _ => unreachable!(),
    }
}

/// Waits for the firmware to listen: bytes that reach QEMU's USART before the firmware
/// enables it are dropped, and a loaded host runs QEMU slowly (a first `Status` sent
/// at once went unanswered in CI). Says `Hello` every 200 ms, as `mccs link` does.
fn ready(link: &mut Link) {
    let deadline = Instant::now() + Duration::from_secs(120);
    while Instant::now() < deadline {
        link.send(&ToDevice::Hello).unwrap();
        let until = Instant::now() + Duration::from_millis(200);
        while let Some(m) = link.recv(until).unwrap() {
            if matches!(m, ToHost::Hello(_)) {
                return;
            }
        }
    }
    panic!("the firmware never answered hello");
}

fn frame(msg: &ToDevice) -> Vec<u8> {
    let mut f = [0u8; MAX_FRAME];
    encode(msg, &mut f).unwrap().to_vec()
}

/// Sends a table's bytes (perhaps altered) one chunk at a time (each followed by a
/// status, as `mccs link load` does) and commits; the first refusal or the answer to the
/// commit (the load's other answers, up to a status, read and dropped).
fn load(link: &mut Link, bytes: &[u8], hash: u32) -> ToHost {
    let mut answers = Vec::new();
    let until_status = |link: &mut Link, msg: &ToDevice, answers: &mut Vec<ToHost>| {
        link.send(msg).unwrap();
        link.send(&ToDevice::Status).unwrap();
        let deadline = Instant::now() + Duration::from_secs(30);
        loop {
            match link.recv(deadline).unwrap() {
                Some(ToHost::Status(_)) => return,
                Some(m @ (ToHost::Ack { .. } | ToHost::Nak(_))) => answers.push(m),
                Some(_) => {}
                None => panic!("no status after {msg:?}"),
            }
        }
    };
    let begin = ToDevice::TissueBegin {
        segments: 64,
        len: bytes.len() as u32,
        hash,
    };
    until_status(link, &begin, &mut answers);
    for (i, c) in bytes.chunks(200).enumerate() {
        let chunk = ToDevice::TissueChunk {
            offset: (i * 200) as u32,
            bytes: c,
        };
        until_status(link, &chunk, &mut answers);
    }
    until_status(link, &ToDevice::TissueCommit, &mut answers);
    // A swap is acknowledged once the tick has taken it: wait for it.
    if answers.is_empty() {
        answers.push(ask(link, &ToDevice::Status, |m| {
            matches!(m, ToHost::Ack { .. } | ToHost::Nak(_))
        }));
    }
    answers[0]
}

#[test]
fn the_board_firmware_in_qemu_serves_the_link() {
    if std::env::var("MCCS_LINK_QEMU").as_deref() != Ok("1") {
        eprintln!("skipped: the board firmware in QEMU runs in the test command's link-qemu stage (MCCS_LINK_QEMU=1)");
        return;
    }
    let socket = std::env::temp_dir().join(format!("mccs-qemu-link-{}.sock", std::process::id()));
    let _qemu = start(&socket);
    let addr = format!("unix:{}", socket.display());
    let mut link = Link::connect(&Addr::parse(&addr).unwrap()).unwrap();
    ready(&mut link);

    // Hello within 50 ticks: the ticks between a status before and one after.
    let s0 = status(&mut link);
    let h = hello(&mut link);
    let s1 = status(&mut link);
    assert!(
        s1.ticks - s0.ticks <= 50,
        "hello took {} ticks",
        s1.ticks - s0.ticks
    );
    assert_eq!(
        (h.protocol, h.schema, h.knots),
        (mccs_link::PROTOCOL, mccs_link::SCHEMA, 65)
    );
    println!("LINK case=hello round_trip_ticks={}", s1.ticks - s0.ticks);
    // QEMU's socket takes one client at a time: the CLI's, now.
    drop(link);

    // A tissue, then a roaming replay with friction: the host's fixed replay, exactly.
    let stiffer = "params/table2-stiffer.toml";
    let t0 = Instant::now();
    let ack = String::from_utf8(
        mccs_ok(&["link", "--connect", &addr, "load", "--params", stiffer]).stdout,
    )
    .unwrap();
    let load_s = t0.elapsed().as_secs_f64();
    let p = mccs_host::paramfile::read(&root().join(stiffer)).unwrap();
    let hash = table_bytes::hash(&ForceTable64::new(&p).unwrap());
    assert_eq!(ack.trim(), format!("ack tissue={hash:08x}"));
    let args = [
        "--probe",
        "params/stroke.csv",
        "--tissue",
        "64,64",
        "--friction",
        "0.6,0.4",
    ];
    let t0 = Instant::now();
    let dev = mccs_ok(&[&["link", "--connect", &addr, "replay"][..], &args].concat()).stdout;
    let replay_s = t0.elapsed().as_secs_f64();
    let host = mccs_ok(
        &[
            &["replay", "--params", stiffer, "--backend", "fixed"][..],
            &args,
        ]
        .concat(),
    )
    .stdout;
    assert!(
        dev == host,
        "the device's replay differs from the host's fixed replay"
    );
    let rows = dev.iter().filter(|&&b| b == b'\n').count() - 1;
    println!(
        "LINK case=replay rows={rows} seconds={replay_s:.1} rows_per_s={:.0} load_seconds={load_s:.2}",
        rows as f64 / replay_s
    );

    let mut link = Link::connect(&Addr::parse(&addr).unwrap()).unwrap();
    hello(&mut link);

    // Every byte of a valid frame corrupted in turn, a truncated and an overlong frame,
    // random bytes: each dropped and counted; the tissue and pose unchanged; the next
    // valid frame taken.
    let pose = ToDevice::Pose {
        origin: [1 << 24, -(2 << 24), 0],
    };
    link.send(&pose).unwrap();
    let before = status(&mut link);
    assert_eq!(before.pose, [1 << 24, -(2 << 24), 0]);
    let good = frame(&ToDevice::Pose {
        origin: [5 << 24, 5 << 24, 5 << 24],
    });
    let mut sent_bad = 0;
    for i in 0..good.len() - 1 {
        let mut bad = good.clone();
        bad[i] ^= 0x10;
        if bad[i] == 0 {
            bad[i] = 0x55;
        }
        link.send_raw(&bad).unwrap();
        sent_bad += 1;
    }
    link.send_raw(&good[..good.len() / 2]).unwrap();
    link.send_raw(&[0]).unwrap();
    link.send_raw(&vec![7u8; 400]).unwrap();
    link.send_raw(&[0]).unwrap();
    let noise: Vec<u8> = (0..2000u32)
        .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8 | 1)
        .collect();
    link.send_raw(&noise).unwrap();
    link.send_raw(&[0]).unwrap();
    sent_bad += 3;
    let after = status(&mut link);
    assert!(
        after.bad_frames - before.bad_frames >= sent_bad,
        "{} bad frames counted of {sent_bad}",
        after.bad_frames - before.bad_frames
    );
    assert_eq!(
        after.pose, before.pose,
        "a corrupted frame moved the tissue"
    );
    assert_eq!(
        hello(&mut link).tissue,
        hash,
        "a corrupted frame changed the tissue"
    );
    println!(
        "LINK case=corruption frames={sent_bad} counted={}",
        after.bad_frames - before.bad_frames
    );

    // Bad tissues: refused with their reason, the old one kept, no overrun.
    let table = ForceTable64::new(&p).unwrap();
    let mut bytes = vec![0u8; table_bytes::len(64)];
    table_bytes::write(&table, &mut bytes);
    let law = mccs::Law::new(&Params::TABLE2).unwrap();
    let unmeasured = ForceTable64::one_placement_unmeasured(&law, -0.5, 0.95).unwrap();
    let mut over = vec![0u8; table_bytes::len(64)];
    table_bytes::write(&unmeasured, &mut over);
    let kink = mccs_host::paramfile::read(&root().join("params/steep-kink.toml")).unwrap();
    let foreign = ForceTable64::new(&kink).unwrap();
    let mut foreign_bytes = vec![0u8; table_bytes::len(64)];
    table_bytes::write(&foreign, &mut foreign_bytes);
    let cases: [(&[u8], u32, NakReason); 4] = [
        (&over, table_bytes::hash(&unmeasured), NakReason::Bound),
        (
            &foreign_bytes,
            table_bytes::hash(&foreign),
            NakReason::Solver,
        ),
        (&bytes[..bytes.len() - 4], hash, NakReason::Length),
        (&bytes, hash ^ 1, NakReason::Hash),
    ];
    for (b, h, reason) in cases {
        assert_eq!(load(&mut link, b, h), ToHost::Nak(reason));
    }
    assert_eq!(
        hello(&mut link).tissue,
        hash,
        "a refused tissue replaced the old"
    );
    assert_eq!(status(&mut link).overruns, 0);

    // Armed, then silent: the force's gain is zero within 120 ticks of the last frame;
    // `Arm` resumes it.
    link.send(&ToDevice::Watch { every: 1 }).unwrap();
    let armed = match ask(&mut link, &ToDevice::Arm, |m| {
        matches!(m, ToHost::Status(_))
    }) {
        ToHost::Status(s) => s.ticks,
        _ => unreachable!(),
    };
    let deadline = Instant::now() + Duration::from_secs(20);
    // (A telemetry's `tick` counts the ticks run: the tick it describes is `tick − 1`;
    // the status's `ticks` is the count when the frame was taken.)
    let zero_at = loop {
        match link.recv(deadline).unwrap() {
            Some(ToHost::Telemetry(t)) if t.tick > armed && t.gain == 0 => break t.tick - 1,
            Some(_) => {}
            None => panic!("the gain never reached zero"),
        }
    };
    assert!(
        zero_at - armed <= 120,
        "zero {} ticks after the last frame",
        zero_at - armed
    );
    println!("LINK case=silence zero_after_ticks={}", zero_at - armed);
    link.send(&ToDevice::Arm).unwrap();
    let resumed = loop {
        match link.recv(deadline).unwrap() {
            Some(ToHost::Telemetry(t)) if t.gain == 32768 => break true,
            Some(_) => {}
            None => break false,
        }
    };
    assert!(resumed, "Arm did not resume the force");
    link.send(&ToDevice::Disarm).unwrap();

    // Live telemetry for 2 s of the host's clock: no overrun; the sequence's gaps are the
    // drops the device counted.
    link.send(&ToDevice::Watch { every: 1 }).unwrap();
    let end = Instant::now() + Duration::from_secs(2);
    let mut got: Vec<Telemetry> = Vec::new();
    while let Some(m) = link.recv(end).unwrap() {
        if let ToHost::Telemetry(t) = m {
            got.push(t);
        }
    }
    link.send(&ToDevice::Watch { every: 0 }).unwrap();
    let first = got.first().expect("no telemetry");
    let last = got.last().unwrap();
    let gaps: u32 = got.windows(2).map(|w| w[1].seq - w[0].seq - 1).sum();
    assert_eq!(gaps, last.dropped - first.dropped, "gaps against drops");
    assert_eq!(status(&mut link).overruns, 0);
    println!(
        "LINK case=telemetry messages={} ticks={} dropped={}",
        got.len(),
        last.tick - first.tick,
        last.dropped - first.dropped
    );

    // The mesh for the visuals, through the CLI: every free node of the N = 8 patch once
    // a mesh, near its rest position (the live device is in its safe state in QEMU: its
    // patch barely moved), at most 60 meshes a second of the device's ticks.
    drop(link);
    let (meshes, worst, free) = super::mesh_run(&addr, "1", 8);
    assert!(meshes.len() >= 3, "{} meshes", meshes.len());
    assert!(worst < 0.5, "a node {worst} mm from rest");
    let ticks: Vec<u32> = meshes.values().map(|(t, _)| *t).collect();
    println!(
        "LINK case=mesh meshes={} nodes={free} least_ticks_apart={}",
        meshes.len(),
        ticks.windows(2).map(|w| w[1] - w[0]).min().unwrap_or(0)
    );
}
