//! What every fuzz target asserts, as functions of the input's bytes: the fuzz targets
//! (`fuzz/fuzz_targets/`, cargo-fuzz on nightly) call them, and so does an ordinary test
//! on stable over the committed inputs (`fuzz/seeds/<target>/`) and whatever a fuzzing
//! run left (`fuzz/corpus/`, `fuzz/artifacts/`), so that a change that breaks a parser's
//! promise fails the test command, not only the next fuzzing. A structured input is
//! built from the bytes as libFuzzer builds it (`Arbitrary::arbitrary_take_rest`); text
//! targets take only UTF-8, as libFuzzer's `&str` inputs do.

use arbitrary::{Arbitrary, Unstructured};
use mccs::arith::{narrow::table_force, ArithTable};
use mccs::{ForceTable, Narrow, Params, RawTable, Strain};
use std::path::Path;

mod link;
pub use link::{link_device, link_host, link_script};

/// A target's check: the input's bytes; a broken promise panics.
pub type Check = fn(&[u8]);

/// The targets, by name, with their checks.
pub const TARGETS: [(&str, Check); 15] = [
    ("param_file", param_file),
    ("fit_data", fit_data),
    ("trajectory", trajectory),
    ("table", table),
    ("encoder_frames", encoder_frames),
    ("link_device", link_device),
    ("demo_summary", demo_summary),
    ("arm_device_file", arm_device_file),
    ("joints", joints),
    ("view_request", view_request),
    ("arm_inputs", arm_inputs),
    ("link_host", link_host),
    ("link_script", link_script),
    ("addr", addr),
    ("tissue_file", tissue_file),
];

/// The longest error line a parser may give: what it says, a line number and a user's
/// text, which it shows through `mccs_client::shown::Shown` (at most 60 characters).
pub const MAX_ERROR_CHARS: usize = 300;

/// A parser's error as the command line prints it: one line that starts with `prefix`,
/// no control character in it (a line break, a carriage return, a terminal's escape),
/// at most [`MAX_ERROR_CHARS`] characters.
fn one_line(e: &str, prefix: &str) {
    assert!(
        e.starts_with(prefix)
            && !e.chars().any(char::is_control)
            && e.chars().count() <= MAX_ERROR_CHARS,
        "{e:?}"
    );
}

/// A parameter file: a one-line error naming the file, or parameters that validate,
/// build a law, and round-trip through the writer.
pub fn param_file(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match crate::paramfile::parse(text, Path::new("fuzz.toml")) {
        Ok(p) => {
            assert!(p.validate().is_ok());
            let law = mccs::Law::new(&p).expect("validated");
            let _ = crate::reference::Reference::new(&p).expect("validated");
            let _ = mccs::ForceTable64::one_placement_unmeasured(&law, -0.5, 0.95);
            let again = crate::paramfile::parse(&crate::paramfile::to_toml(&p), Path::new("x"));
            assert_eq!(again, Ok(p), "round trip");
        }
        Err(e) => {
            one_line(&e.to_string(), "fuzz.toml: ");
        }
    }
}

/// The fit's data: a one-line error naming the file (and row), or rows the models take.
pub fn fit_data(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match crate::fit::parse_data(text, "fuzz.csv") {
        Ok(points) => {
            assert!(points.len() >= 5 && points.len() <= crate::fit::MAX_ROWS);
            for w in points.windows(2) {
                assert!(w[1].0 > w[0].0 && w[1].1 > w[0].1);
            }
            assert!(points.iter().all(|&(e, f)| e > 0.0 && e < 1.0 && f > 0.0));
            let m = crate::fit::metrics(&crate::fit::Fitted::Mccs(Params::TABLE2), &points);
            assert!(m.mean_abs.is_finite());
        }
        Err(e) => {
            one_line(&e.to_string(), "fuzz.csv: ");
        }
    }
}

/// A probe trajectory: a one-line error, or a path whose samples are finite and in range.
pub fn trajectory(data: &[u8]) {
    use crate::trajectory::{parse, MAX_POSITION_MM};
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match parse(text, "fuzz.csv") {
        Ok(t) => {
            let (a, b) = t.span();
            assert!(a.is_finite() && b.is_finite() && b >= a);
            for x in [a, (a + b) / 2.0, b, a - 1.0, b + 1.0] {
                assert!(t
                    .at(x)
                    .iter()
                    .all(|c| c.is_finite() && c.abs() <= MAX_POSITION_MM));
            }
        }
        Err(e) => {
            one_line(&e.to_string(), "fuzz.csv");
        }
    }
}

/// The table builder's arguments and any raw table.
#[derive(Arbitrary, Debug)]
struct TableInput {
    scales: [f64; 11],
    from: f64,
    to: f64,
    knots: u8,
    raw: ([i32; 10], [u32; 3], [[i32; 4]; 16], [i32; 7]),
    strains: Vec<i32>,
}

fn evaluate<const S: usize>(t: &ForceTable<S>, strains: &[i32]) {
    let narrow = ArithTable::<S, Narrow>::new(*t);
    for &e in strains.iter().chain(&[i32::MIN, i32::MAX, 0]) {
        let e = Strain::from_bits(e);
        let _ = t.force_and_stiffness(e);
        let _ = t.force(e);
        let _ = t.force_within::<26>(e);
        let _ = table_force(&narrow, e);
    }
}

fn build<const S: usize>(p: &Params, from: f64, to: f64, strains: &[i32]) {
    if let Ok(t) = ForceTable::<S>::with_domain(p, from, to) {
        assert_eq!(t.validate(), Ok(()));
        evaluate(&t, strains);
        if let Ok(law) = mccs::Law::new(p) {
            let m = t.measured(&law, from, to).max_error();
            assert!(m.is_some_and(|e| e.force >= 0.0 && e.stiffness >= 0.0));
            let bounded = ForceTable::<S>::with_bound(p, from, to, &mccs::TableBound::PRODUCT);
            assert!(matches!(
                bounded,
                Ok(_) | Err(mccs::TableError::BoundNotMet { .. })
            ));
        }
    }
}

/// The table builder on any spring scale, domain and knot count, and any raw table: a
/// typed error or a valid table, its measured error, the bound's verdict, and every
/// evaluation in both arithmetics, without a panic.
pub fn table(data: &[u8]) {
    let Ok(i) = TableInput::arbitrary_take_rest(Unstructured::new(data)) else {
        return;
    };
    let mut p = Params::TABLE2;
    for (k, s) in mccs::ParamKey::ALL.iter().zip(i.scales) {
        if let Some(v) = k.get(&p) {
            k.set(&mut p, v * s);
        }
    }
    match i.knots % 4 {
        0 => build::<16>(&p, i.from, i.to, &i.strains),
        1 => build::<32>(&p, i.from, i.to, &i.strains),
        2 => build::<64>(&p, i.from, i.to, &i.strains),
        _ => build::<128>(&p, i.from, i.to, &i.strains),
    }
    let (a, b, segments, c) = i.raw;
    let raw = RawTable {
        strain_lo: a[0],
        strain_hi: a[1],
        index_pre: b[0],
        index_scale: b[1],
        anchor_lo: a[2],
        force_lo: a[3],
        stiffness_lo: a[4],
        slope_lo: a[9],
        force_hi: a[5],
        // Half of them within ±2¹⁹, where the line above's slope is Q28.
        stiffness_hi: if a[7] & 1 == 0 { a[6] >> 12 } else { a[6] },
        slope_hi: c[6],
        shift: b[2],
        stiff_scale: a[7],
        stiff_post: a[8],
        corner_hi: c[0],
        corner_anchor: c[1],
        corner_pre: c[2] as u32,
        corner_base: c[3] as u32,
        corner_scale: c[4],
        corner_post: c[5],
        err_force_ppb: b[0],
        err_stiffness_ppb: b[1],
        segments,
    };
    let t = ForceTable::from_raw(raw);
    let _ = t.validate();
    let _ = t.max_stiffness();
    evaluate(&t, &i.strains);
}

/// The encoder driver's input: its mounting and a stream of response frames.
#[derive(Arbitrary, Debug)]
struct EncoderInput {
    zero: u16,
    mm_per_count: f64,
    max_step: u16,
    diag_every: u16,
    max_travel_counts: u32,
    frames: Vec<Option<u16>>,
}

/// An SPI bus answering with the frames given (`None`: a failed transfer).
struct Frames(std::vec::IntoIter<Option<u16>>);

impl embedded_hal::spi::ErrorType for Frames {
    type Error = embedded_hal::spi::ErrorKind;
}

impl embedded_hal::spi::SpiDevice<u8> for Frames {
    fn transaction(
        &mut self,
        ops: &mut [embedded_hal::spi::Operation<'_, u8>],
    ) -> Result<(), Self::Error> {
        let frame = self
            .0
            .next()
            .flatten()
            .ok_or(embedded_hal::spi::ErrorKind::Other)?;
        for op in ops {
            if let embedded_hal::spi::Operation::Transfer(rx, _) = op {
                let b = frame.to_be_bytes();
                for (k, r) in rx.iter_mut().enumerate() {
                    *r = b[k % 2];
                }
            }
        }
        Ok(())
    }
}

/// The encoder driver on any frames and mounting: no panic, every position within its
/// travel unless the driver says it is out of travel.
pub fn encoder_frames(data: &[u8]) {
    use mccs_firmware::drivers::as5047p::{As5047p, EncoderConfig};
    let Ok(i) = EncoderInput::arbitrary_take_rest(Unstructured::new(data)) else {
        return;
    };
    let n = i.frames.len();
    let config = EncoderConfig {
        zero: i.zero,
        mm_per_count: i.mm_per_count,
        max_step: i.max_step,
        diag_every: i.diag_every,
        max_travel_counts: i.max_travel_counts,
    };
    // Within its travel, the position is at most the travel (the Q30 scale's error and
    // the Q24 position's LSB under 1e-3 mm), over any turns.
    let limit = (i.max_travel_counts.min(1 << 24) as f64) * i.mm_per_count.abs().min(0.01) + 1e-3;
    let mut enc = As5047p::new(Frames(i.frames.into_iter()), config);
    for _ in 0..n {
        if let Ok(z) = enc.read() {
            assert!(
                enc.out_of_travel() || z.to_num::<f64>().abs() <= limit,
                "{z}"
            );
        }
    }
    let _ = enc.errors();
}

/// A firmware's SUMMARY line: what parses prints and parses again the same.
pub fn demo_summary(data: &[u8]) {
    let Ok(line) = std::str::from_utf8(data) else {
        return;
    };
    if let Some(s) = crate::cli::parse_summary(line) {
        let mut again = format!(
            "SUMMARY ticks={} overruns={} max_force_n={} steady_force_n={} window_shifts={}",
            s.ticks, s.overruns, s.max_force, s.steady_force, s.window_shifts
        );
        if let Some(arm) = s.arm {
            let [a, b, c] = arm.steady_duty;
            again += &format!(
                " steady_duty_a={a} steady_duty_b={b} steady_duty_c={c} max_duty={}",
                arm.max_duty
            );
        }
        let t = crate::cli::parse_summary(&again).expect("a printed summary parses");
        assert_eq!(t.ticks, s.ticks);
        assert_eq!(t.window_shifts, s.window_shifts);
        assert!(t.max_force.to_bits() == s.max_force.to_bits() || s.max_force.is_nan());
        assert_eq!(t.arm.is_some(), s.arm.is_some());
        if let (Some(x), Some(y)) = (t.arm, s.arm) {
            assert!(x.max_duty.to_bits() == y.max_duty.to_bits() || y.max_duty.is_nan());
        }
    }
}

/// An arm's device file: a one-line error, or an arm that validates, builds and drives.
pub fn arm_device_file(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match crate::arm::device_file::parse(text, Path::new("fuzz.toml")) {
        Ok(spec) => {
            assert!(spec.validate().is_ok());
            let arm = mccs::Arm::new(&spec).expect("validated");
            let pose = arm.pose(arm.home_counts());
            let drive = arm.drive(&pose, [mccs::Force::from_num(1); 3]);
            assert!(drive.duty_q16.iter().all(|d| d.abs() <= 65_536));
        }
        Err(e) => one_line(&e, "fuzz.toml"),
    }
}

/// A recorded arm motion: a one-line error, or rows in time order with whole counts.
pub fn joints(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match crate::arm::joints::parse(text, "fuzz.csv") {
        Ok(rows) => {
            assert!(rows.windows(2).all(|w| w[1].0 > w[0].0));
            assert!(rows.iter().all(|r| r.1.iter().all(|c| c.fract() == 0.0)));
            let arm = mccs::Arm::new(&mccs_firmware::arm::device::WOODENHAPTICS).expect("valid");
            let ticks = crate::arm::joints::ticks(&rows, 10.0, &arm);
            assert!(!ticks.is_empty());
        }
        Err(e) => one_line(&e, "fuzz.csv"),
    }
}

/// The arm's CSV inputs (`mccs arm fk --counts`, `calibrate --poses`): a one-line error,
/// or rows of the kinds their columns say, on which the fixed-point pose and the gravity
/// fit give finite figures or one line why not.
pub fn arm_inputs(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let spec = mccs_firmware::arm::device::WOODENHAPTICS;
    let counts = ["count_a", "count_b", "count_c"];
    match crate::arm::columns::parse(text, "fuzz.csv", &counts) {
        Ok(rows) => {
            let arm = mccs::Arm::new(&spec).expect("valid");
            for r in rows {
                let c = [r[0], r[1], r[2]];
                assert!(c
                    .iter()
                    .all(|x| x.fract() == 0.0 && x.abs() <= i32::MAX as f64));
                let pose = arm.pose(c.map(|x| x as i32));
                let d = arm.drive(&pose, [mccs::Force::from_num(1); 3]);
                assert!(d.duty_q16.iter().all(|x| x.abs() <= 65_536));
            }
        }
        Err(e) => one_line(&e, "fuzz.csv"),
    }
    let held = ["count_a", "count_b", "count_c", "duty_b", "duty_c"];
    match crate::arm::columns::parse(text, "fuzz.csv", &held) {
        Ok(rows) => {
            let poses: Vec<_> = rows
                .iter()
                .map(|r| crate::arm::gravity_fit::HeldPose {
                    counts: [r[0], r[1], r[2]],
                    duty: [r[3], r[4]],
                })
                .collect();
            let twin = crate::arm::ArmTwin {
                spec: mccs::ArmSpec {
                    gravity: Some(mccs::GravitySpec {
                        upper_arm_mass_kg: 0.17,
                        upper_arm_com_mm: 51.0,
                        forearm_mass_kg: 0.11,
                        forearm_com_mm: 91.0,
                        g: 9.81,
                    }),
                    ..spec
                },
            };
            match crate::arm::gravity_fit::fit(&twin, &poses) {
                Ok(f) => {
                    assert!(f.upper_arm_mass_kg.is_finite() && f.upper_arm_mass_kg >= 0.0);
                    assert!(f.forearm_mass_kg.is_finite() && f.forearm_mass_kg >= 0.0);
                    assert!(f
                        .rms_duty
                        .iter()
                        .chain(&f.offset_duty)
                        .all(|x| x.is_finite()));
                }
                Err(e) => one_line(&e, ""),
            }
        }
        Err(e) => one_line(&e, "fuzz.csv"),
    }
}

/// A request to `mccs view` (any bytes from a browser): refused with a status the server
/// answers (400, 413, 431), or a request whose body fits; its body as a pose and as a
/// parameter file is a pose, a tissue, or one line why not.
pub fn view_request(data: &[u8]) {
    use crate::view::http::{read_request, MAX_BODY};
    match read_request(data) {
        Ok(r) => {
            assert!(r.body.len() <= MAX_BODY && !r.path.contains('?'));
            if let Err(why) = crate::view::pose_of(&r.body) {
                one_line(why, "");
            }
            if let Err(why) = crate::view::tissue_of(&r.body) {
                one_line(&why, "");
            }
        }
        Err(e) => assert!([400, 413, 431].contains(&e.status), "{e:?}"),
    }
}

/// A device's address (`--connect`, `Device::open`): one that reads back as itself, or
/// a reason, and the client's error naming the address on one line (escaped, in full).
pub fn addr(data: &[u8]) {
    use mccs_client::Addr;
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match Addr::parse(text) {
        Ok(a) => {
            assert_eq!(a.to_string(), text);
            match &a {
                Addr::Unix(p) => assert!(!p.as_os_str().is_empty()),
                Addr::Tcp(hp) => assert!(hp.rsplit_once(':').is_some()),
                Addr::Serial(p) => assert!(!p.is_empty()),
            }
        }
        Err(why) => {
            one_line(why, "");
            let e = mccs_client::Error::Address {
                addr: text.into(),
                why,
            };
            let line = e.to_string();
            assert!(!line.chars().any(char::is_control), "{line:?}");
        }
    }
}

/// A tissue file (`mccs table --format bin`, a scene's `Tissue::from_bin`): a typed
/// reason on one line, or a tissue that writes back as the same bytes.
pub fn tissue_file(data: &[u8]) {
    match mccs_client::Tissue::from_bin(data) {
        Ok(t) => {
            assert_eq!(t.to_bin(), data);
            assert_eq!(
                t.bytes().len(),
                mccs_link::table_bytes::len(t.segments().into())
            );
            assert_eq!(mccs_link::table_bytes::hash_bytes(t.bytes()), t.hash());
        }
        Err(e) => one_line(&e.to_string(), ""),
    }
}
