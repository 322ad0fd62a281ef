//! A request's replies are all its own: a reply the device sends late for one request
//! never answers the next (`Session::wait_statuses`, a `Status` as a fence). Against a
//! scripted device on a unix socket, which answers as the board's link does but sends
//! some answers late, as a loaded machine did:
//! - an `Arm` gets a `Status` of its own, then the `Status` asked after it: the client
//!   took the second, late, as the next request's answer, and a refused pose came back
//!   `Ok` (the script test's flaky exit 0, seen once in the test command and reproduced
//!   under four CPU hogs in 1 run of 6);
//! - a refused `TissueBegin` is followed by a `Nak(Order)` for each chunk and the commit:
//!   late, they refused the next load.

use mccs_client::{Device, Error, Pose};
use mccs_link::{encode, parse, Decoder, NakReason, StatusInfo, ToDevice, ToHost, MAX_FRAME};
use std::io::{Read, Write};
use std::time::{Duration, Instant};

/// A scripted device on `socket`, serving one connection until it closes: `answer`
/// takes each frame and pushes its answers, to send now or to hold. What it holds goes
/// out when the next frame comes, ahead of that frame's answers, or after 300 ms
/// without one: a reply that arrives late.
fn scripted(
    socket: &std::path::Path,
    mut answer: impl FnMut(ToDevice<'_>, &mut Vec<ToHost>, &mut Vec<ToHost>) + Send + 'static,
) {
    let _ = std::fs::remove_file(socket);
    let listener = std::os::unix::net::UnixListener::bind(socket).unwrap();
    std::thread::spawn(move || {
        let (mut s, _) = listener.accept().unwrap();
        s.set_read_timeout(Some(Duration::from_millis(10))).unwrap();
        let send = |s: &mut std::os::unix::net::UnixStream, msgs: &mut Vec<ToHost>| {
            for m in msgs.drain(..) {
                let mut f = [0u8; MAX_FRAME];
                s.write_all(encode(&m, &mut f).unwrap()).unwrap();
            }
        };
        let (mut decoder, mut buf) = (Decoder::new(), [0u8; 256]);
        let (mut now, mut held, mut held_at) = (Vec::new(), Vec::new(), Instant::now());
        loop {
            let n = match s.read(&mut buf) {
                Ok(0) => return,
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => 0,
                Err(_) => return,
            };
            if held_at.elapsed() >= Duration::from_millis(300) {
                send(&mut s, &mut held);
            }
            for &b in &buf[..n] {
                let Some(Ok(frame)) = decoder.push(b) else {
                    continue;
                };
                let Ok(m) = parse::<ToDevice>(frame) else {
                    continue;
                };
                send(&mut s, &mut held);
                let was_held = held.len();
                answer(m, &mut now, &mut held);
                if held.len() > was_held {
                    held_at = Instant::now();
                }
                send(&mut s, &mut now);
            }
        }
    });
}

fn status(armed: bool) -> ToHost {
    ToHost::Status(StatusInfo {
        armed,
        ..StatusInfo::default()
    })
}

/// A hello as the soft device sends it, and a scratch folder for sockets.
fn hello_and_dir(test: &str) -> (mccs_link::HelloInfo, std::path::PathBuf) {
    let dir = std::env::temp_dir().join(format!("mccs-link-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let dev = mccs_host::link::soft::serve(
        &dir.join(format!("replies-{test}-hello.sock")),
        mccs::ForceTable64::new(&mccs::Params::TABLE2).unwrap(),
    )
    .unwrap();
    let hello = Device::open(dev.addr()).unwrap().info().hello;
    (hello, dir)
}

/// The device answers an `Arm` with a `Status` of its own, then the `Status` asked after
/// it late; a pose outside the workspace with a `Nak`.
#[test]
fn a_late_status_answers_no_later_request() {
    let (hello, dir) = hello_and_dir("arm");
    let socket = dir.join("replies-arm.sock");
    let (mut armed, mut after_arm) = (false, false);
    scripted(&socket, move |m, now, held| match m {
        ToDevice::Hello => now.push(ToHost::Hello(hello)),
        ToDevice::Arm => {
            (armed, after_arm) = (true, true);
            now.push(status(true));
        }
        ToDevice::Disarm => {
            armed = false;
            now.push(status(false));
        }
        ToDevice::Status if std::mem::take(&mut after_arm) => held.push(status(armed)),
        ToDevice::Status => now.push(status(armed)),
        ToDevice::Pose(_) => now.push(ToHost::Nak(NakReason::Pose {
            axis: 2,
            limit: 40 << 24,
        })),
        _ => {}
    });
    let device = Device::open(&format!("unix:{}", socket.display())).unwrap();
    let armed = device.arm_held().unwrap();
    assert!(armed.to_string().contains("armed=1"), "{armed}");
    let outside = Pose::from_mm_deg([0.0, 0.0, 90.0], [0.0; 3]);
    match device.set_pose(outside) {
        Err(Error::Refused { refusal, .. }) => assert!(
            refusal
                .to_string()
                .contains("outside the device's workspace"),
            "{refusal}"
        ),
        other => panic!("a pose outside the workspace came back {other:?}"),
    }
    // Nothing left over either way: the next answers are the next requests'.
    assert!(device.status().unwrap().to_string().contains("armed=1"));
    let disarmed = device.disarm().unwrap();
    assert!(disarmed.to_string().contains("armed=0"), "{disarmed}");
}

/// The device refuses the first load's `TissueBegin` (busy) at once, and the `Nak(Order)`
/// of each chunk and of the commit after it late; the second load it takes (`Ack` on
/// the commit). Without a fence the second load was refused by the first's leftovers.
#[test]
fn a_refused_load_leaves_nothing_to_refuse_the_next() {
    let (hello, dir) = hello_and_dir("load");
    let socket = dir.join("replies-load.sock");
    let (mut loads, mut hash) = (0, 0);
    scripted(&socket, move |m, now, held| match m {
        ToDevice::Hello => now.push(ToHost::Hello(hello)),
        ToDevice::Status => now.push(status(false)),
        ToDevice::TissueBegin(b) => {
            loads += 1;
            hash = b.hash;
            if loads == 1 {
                now.push(ToHost::Nak(NakReason::Busy));
            }
        }
        ToDevice::TissueChunk { .. } | ToDevice::TissueCommit if loads == 1 => {
            held.push(ToHost::Nak(NakReason::Order))
        }
        ToDevice::TissueCommit => now.push(ToHost::Ack { tissue: hash }),
        _ => {}
    });
    let device = Device::open(&format!("unix:{}", socket.display())).unwrap();
    let tissue = mccs_client::Tissue::from_params(&mccs::Params::TABLE2).unwrap();
    match device.load_tissue(&tissue) {
        Err(Error::Refused { refusal, .. }) => {
            assert_eq!(refusal.to_string(), NakReason::Busy.message())
        }
        other => panic!("the first load came back {other:?}"),
    }
    assert_eq!(device.load_tissue(&tissue).unwrap(), tissue.hash());
}

/// A device that ends a replay before its last row (it abandons one whose path does not
/// come within `REPLAY_STARVED_MS`) fails the replay, naming the ticks it ran: its rows
/// came back `Ok`, a replay cut short as if whole.
#[test]
fn a_replay_the_device_ends_early_is_an_error() {
    let (hello, dir) = hello_and_dir("replay");
    let socket = dir.join("replies-replay.sock");
    scripted(&socket, move |m, now, _| match m {
        ToDevice::Hello => now.push(ToHost::Hello(hello)),
        ToDevice::Status => now.push(status(false)),
        ToDevice::ReplayBegin(spec) => now.push(ToHost::ReplayCredit {
            until: spec.samples,
        }),
        ToDevice::ReplayPath { first: 0, .. } => {
            for tick in 0..3 {
                now.push(ToHost::ReplayRow(mccs_link::ReplayRow {
                    tick,
                    ..Default::default()
                }));
            }
            now.push(ToHost::ReplayEnd { ticks: 3 });
        }
        _ => {}
    });
    let device = Device::open(&format!("unix:{}", socket.display())).unwrap();
    let text = "time_s,x_mm,y_mm,z_mm\n0,0,0,0\n0.1,0,0,-1\n";
    let path = mccs_client::trajectory::parse(text, "path.csv").unwrap();
    let spec = super::rig::replay_spec(0, [0.0; 3], None);
    match device.replay(&path, spec, |_| {}) {
        Err(e @ Error::Unexpected { .. }) => assert!(
            e.to_string()
                .contains("ended the replay after 3 of 101 ticks"),
            "{e}"
        ),
        other => panic!(
            "a replay ended after 3 ticks came back {:?}",
            other.map(|r| r.len())
        ),
    }
}
