//! The codec: the CRC's check value, every message round-trips through a frame, no
//! corruption of a frame is taken for a message, the decoder finds the next frame after
//! any garbage, and the schema's text moves with the messages' encoding (golden bytes).

use mccs_link::frame::parse;
use mccs_link::message::*;
use mccs_link::{crc::crc32, encode, Decoder, FrameError, MAX_FRAME, MAX_PAYLOAD, SCHEMA};
use proptest::prelude::*;

#[test]
fn the_crc_is_crc_32() {
    assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    assert_eq!(crc32(b""), 0);
}

/// One of every message, with every field away from its default.
fn every_message() -> (Vec<ToDevice<'static>>, Vec<ToHost>) {
    static BYTES: [u8; 5] = [1, 0, 2, 0xFF, 0];
    let spec = ReplaySpec {
        grid: 5,
        spacing_mm: 2.5,
        tick_hz: 1000.0,
        node_mass_kg: 0.005,
        spring_damping: 1.0,
        coupling_stiffness: 1.0,
        coupling_damping: 0.5,
        max_force: 10.0,
        symplectic: true,
        narrow: false,
        samples: 7401,
        start: [-15.0, 0.4],
        roaming: Some(RoamSpec {
            tissue_w: 64,
            tissue_h: 63,
            mu_s: 0.6,
            mu_k: 0.4,
            probe_radius: 0.5,
            cap_radius: Some(300.0),
        }),
    };
    let to_device = vec![
        ToDevice::Hello,
        ToDevice::Status,
        ToDevice::Arm,
        ToDevice::Disarm,
        ToDevice::Pose {
            origin: [1, -2, 3 << 24],
        },
        ToDevice::TissueBegin {
            segments: 64,
            len: 1112,
            hash: 0xDEAD_BEEF,
        },
        ToDevice::TissueChunk {
            offset: 200,
            bytes: &BYTES,
        },
        ToDevice::TissueCommit,
        ToDevice::Watch { every: 10 },
        ToDevice::ReplayBegin(spec),
        ToDevice::ReplayPath {
            first: 16,
            points: &BYTES,
        },
        ToDevice::WatchMesh { every: 17 },
    ];
    let to_host = vec![
        ToHost::Hello(HelloInfo {
            protocol: 1,
            schema: SCHEMA,
            core: Core::M4f,
            tick_hz: 1000,
            grid: 8,
            max_grid: 8,
            tissue_w: 8,
            tissue_h: 8,
            knots: 65,
            tissue: 0x1234_5678,
            path_capacity: 256,
        }),
        ToHost::Ack { tissue: 7 },
        ToHost::Nak(NakReason::Option {
            option: SpecOption::Grid,
            limit: 8,
        }),
        ToHost::Status(StatusInfo {
            ticks: 1,
            overruns: 2,
            bad_frames: 3,
            dropped_telemetry: 4,
            armed: true,
            fault: true,
            replaying: true,
            pose: [1, -2, 3],
        }),
        ToHost::Telemetry(Telemetry {
            seq: 1,
            tick: 2,
            probe: [3, -4, 5],
            force: [-6, 7, 8],
            gain: 32768,
            flags: 5,
            dropped: 9,
        }),
        ToHost::ReplayRow(ReplayRow {
            tick: 1,
            force: [i32::MIN, i32::MAX, 0],
            point: [1, 2, 3],
            origin: [-4, 5],
            max_disp: [6, 7, -8],
            flags: 7,
            shifts: 22,
        }),
        ToHost::ReplayCredit { until: 256 },
        ToHost::ReplayEnd { ticks: 7401 },
        // The largest mesh part: every position at its longest encoding.
        ToHost::Mesh(MeshPart {
            seq: u32::MAX,
            tick: u32::MAX,
            first: u16::MAX,
            nodes: u16::MAX,
            positions: [[i32::MIN; 3]; mccs_link::MESH_PART],
        }),
    ];
    (to_device, to_host)
}

fn frame_of<T: serde::Serialize>(msg: &T) -> Vec<u8> {
    let mut out = [0u8; MAX_FRAME];
    encode(msg, &mut out).expect("fits a frame").to_vec()
}

/// Feeds `bytes` to a fresh decoder; the frames' outcomes.
fn decode_all(bytes: &[u8]) -> Vec<Result<Vec<u8>, FrameError>> {
    let mut d = Decoder::new();
    bytes
        .iter()
        .filter_map(|&b| d.push(b).map(|r| r.map(<[u8]>::to_vec)))
        .collect()
}

#[test]
fn every_message_round_trips_through_one_frame() {
    let (dev, host) = every_message();
    for m in &dev {
        let f = frame_of(m);
        assert!(
            f.len() <= MAX_FRAME && !f[..f.len() - 1].contains(&0),
            "{m:?}"
        );
        let out = decode_all(&f);
        assert_eq!(out.len(), 1);
        let payload = out[0].clone().unwrap();
        assert_eq!(&parse::<ToDevice>(&payload).unwrap(), m);
    }
    for m in &host {
        let out = decode_all(&frame_of(m));
        assert_eq!(&parse::<ToHost>(out[0].as_ref().unwrap()).unwrap(), m);
    }
}

/// The golden bytes: a message's encoding changed without the schema's text (and so its
/// hash) fails here. Update both together (link/src/schema.rs).
#[test]
fn the_schema_moves_with_the_encoding() {
    let (dev, host) = every_message();
    let mut all = Vec::new();
    for m in &dev {
        all.extend(postcard::to_allocvec(m).unwrap());
    }
    for m in &host {
        all.extend(postcard::to_allocvec(m).unwrap());
    }
    let golden = mccs_link::schema::fnv1a(&all);
    assert_eq!(
        (SCHEMA, golden),
        (0x094e_6f70, 0x6556_82d7),
        "schema {SCHEMA:#010x}, encoding {golden:#010x}"
    );
}

/// Every single-byte corruption (each byte, each of its 255 other values) of every
/// message's frame is dropped as a bad frame, never decoded as a message; truncated and
/// overlong frames too; the next valid frame is taken.
#[test]
fn no_corruption_of_a_frame_is_a_message() {
    let (dev, _) = every_message();
    let next = frame_of(&ToDevice::Status);
    let mut corruptions = 0;
    for m in &dev {
        let f = frame_of(m);
        for i in 0..f.len() {
            for v in 0..=255u8 {
                if v == f[i] {
                    continue;
                }
                let mut bad = f.clone();
                bad[i] = v;
                // (A corrupted delimiter merges the next frame into this one: the frame
                // after that is taken.)
                bad.extend_from_slice(&next);
                bad.extend_from_slice(&next);
                let out = decode_all(&bad);
                // The corrupted frame (perhaps split in two by a new 0x00): never Ok with
                // a message other than the original; the valid frame after it, taken.
                let (last, rest) = out.split_last().unwrap();
                assert_eq!(
                    parse::<ToDevice>(last.as_ref().unwrap()),
                    Ok(ToDevice::Status)
                );
                for p in rest.iter().flatten() {
                    let msg = parse::<ToDevice>(p);
                    assert!(
                        msg.as_ref() == Ok(m) || msg == Ok(ToDevice::Status),
                        "a corruption of {m:?} at byte {i} decodes as {msg:?}"
                    );
                }
                corruptions += 1;
            }
        }
        // Truncated: every prefix, delimited.
        for n in 1..f.len() - 1 {
            let mut t = f[..n].to_vec();
            t.push(0);
            let out = decode_all(&t);
            assert!(out.iter().all(|r| r.is_err()), "{m:?} cut at {n}");
        }
    }
    assert!(corruptions > 10_000);
    // Overlong: more bytes than a frame before a delimiter, then a valid frame.
    let mut long = vec![1u8; MAX_FRAME + 10];
    long.push(0);
    long.extend_from_slice(&next);
    let out = decode_all(&long);
    assert_eq!(out[0], Err(FrameError::TooLong));
    assert_eq!(
        parse::<ToDevice>(out[1].as_ref().unwrap()),
        Ok(ToDevice::Status)
    );
    // A message with bytes left over after it is not a message.
    let mut payload = postcard::to_allocvec(&ToDevice::Arm).unwrap();
    payload.push(0x01);
    assert_eq!(parse::<ToDevice>(&payload), Err(FrameError::Message));
}

#[test]
fn a_message_too_large_for_a_frame_is_refused_when_encoded() {
    let big = [7u8; MAX_PAYLOAD];
    let mut out = [0u8; MAX_FRAME];
    assert_eq!(
        encode(
            &ToDevice::TissueChunk {
                offset: 0,
                bytes: &big
            },
            &mut out
        )
        .err(),
        Some(FrameError::TooLarge)
    );
}

proptest! {
    /// Random bytes never panic the decoder, and a valid frame after them is taken.
    #[test]
    fn garbage_then_a_frame(garbage in proptest::collection::vec(any::<u8>(), 0..1200)) {
        let mut bytes = garbage;
        bytes.push(0);
        bytes.extend_from_slice(&frame_of(&ToDevice::Hello));
        let out = decode_all(&bytes);
        let last = out.last().unwrap().as_ref().unwrap();
        prop_assert_eq!(parse::<ToDevice>(last), Ok(ToDevice::Hello));
    }

    /// Telemetry and replay rows of any values round-trip.
    #[test]
    fn rows_round_trip(v in proptest::array::uniform12(any::<i32>()), t in any::<u32>(), flags in any::<u8>()) {
        let row = ToHost::ReplayRow(ReplayRow {
            tick: t,
            force: [v[0], v[1], v[2]],
            point: [v[3], v[4], v[5]],
            origin: [v[6], v[7]],
            max_disp: [v[8], v[9], v[10]],
            flags,
            shifts: v[11] as u32,
        });
        let out = decode_all(&frame_of(&row));
        prop_assert_eq!(parse::<ToHost>(out[0].as_ref().unwrap()).unwrap(), row);
    }
}
