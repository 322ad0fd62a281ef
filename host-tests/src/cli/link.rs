//! `mccs link`: talk to a device over the host link (docs/link.md). Each subcommand
//! connects, says `Hello` (and refuses a device of another protocol or schema), does its
//! one thing and prints its answer.

use super::patch_args::{PatchArgs, TuningArgs};
use super::replay::{glued_line, header, roam_line, RoamArgs};
use super::table::{build, Domain};
use super::{arg_error, fmt_given, io_error, Backend, CliError};
use crate::link::{Addr, Link};
use crate::paramfile;
use crate::replay::{probe_bits, RoamRow, Row};
use crate::trajectory;
use mccs_link::message::{HelloInfo, NakReason, ReplaySpec, RoamSpec, ToDevice, ToHost};
use mccs_link::{table_bytes, PROTOCOL, SCHEMA};
use std::io::Write;
use std::path::PathBuf;
use std::time::{Duration, Instant};

#[derive(clap::Args, Debug)]
pub(super) struct Args {
    /// The device: unix:PATH, tcp:HOST:PORT, or a serial port's path (115200 baud).
    #[arg(long, value_name = "ADDR")]
    connect: String,
    #[command(subcommand)]
    command: Command,
}

#[derive(clap::Subcommand, Debug)]
enum Command {
    /// One line: `protocol=<v> schema=<hash> core=<c> tick_hz=<n> grid=<N> tissue=<W>x<H>`.
    Hello,
    /// One line: `ticks=.. overruns=.. bad_frames=.. dropped_telemetry=.. armed=..`.
    Status,
    /// Send a tissue: its force table built as `mccs table` builds it, checked by the
    /// device before it is swapped in. Prints `ack tissue=<hash>`; a refusal exits 2.
    Load {
        /// Parameter file (the TOML schema of docs/model.md).
        #[arg(long)]
        params: PathBuf,
        /// Knots: the device's (default: what `hello` says).
        #[arg(long)]
        knots: Option<usize>,
    },
    /// Replay a probe trajectory on the device's solver and tissue: the same CSV as
    /// `mccs replay --backend fixed` with the same options on that tissue.
    Replay(ReplayArgs),
    /// Stream live telemetry as CSV for S seconds.
    Watch {
        /// How long, s (0 … 3600).
        #[arg(long, default_value_t = 1.0)]
        seconds: f64,
        /// Ticks between rows (1 … 1000).
        #[arg(long, default_value_t = 10)]
        every: u16,
    },
    /// Stream the live patch's node positions (for the visuals) as CSV for S seconds:
    /// `seq,tick,node,x_mm,y_mm,z_mm`, one row per node (patch frame).
    Mesh {
        /// How long, s (0 … 3600).
        #[arg(long, default_value_t = 1.0)]
        seconds: f64,
        /// Ticks between meshes (1 … 1000; the device takes at most 60 a second).
        #[arg(long, default_value_t = 17)]
        every: u16,
    },
    /// Move the tissue's origin in the device frame, mm.
    Pose {
        /// X,Y,Z, mm (each within ±100).
        #[arg(long, value_name = "X,Y,Z", allow_negative_numbers = true)]
        origin: String,
    },
    /// Take the device: from now on it renders only while this host talks (docs/link.md).
    Arm,
    /// Force to zero until the next `arm`.
    Disarm,
}

#[derive(clap::Args, Debug)]
struct ReplayArgs {
    /// Probe trajectory, CSV `time_s,x_mm,y_mm,z_mm`.
    #[arg(long)]
    probe: PathBuf,
    #[command(flatten)]
    patch: PatchArgs,
    #[command(flatten)]
    tuning: TuningArgs,
    #[command(flatten)]
    roam: RoamArgs,
}

/// How long the device has to answer (a tissue's check runs its stability estimate:
/// seconds on a small core).
const ANSWER: Duration = Duration::from_secs(30);

pub(super) fn run(a: Args, out: &mut dyn Write) -> Result<(), CliError> {
    let addr = Addr::parse(&a.connect).map_err(|e| arg_error("--connect", &e))?;
    // Arguments are checked before the device is reached.
    if let Command::Replay(r) = &a.command {
        r.patch.check()?;
        if r.patch.backend != Backend::Reference {
            return Err(arg_error(
                "--backend",
                "a link replay runs the device's core: leave it out",
            ));
        }
    }
    let mut link =
        Link::connect(&addr).map_err(|e| arg_error("--connect", &format!("{}: {e}", a.connect)))?;
    let hello = hello(&mut link, &a.connect)?;
    let fail = |e: std::io::Error| CliError::new(format!("{}: {e}", a.connect));
    match a.command {
        Command::Hello => writeln!(
            out,
            "protocol={} schema={:08x} core={} tick_hz={} grid={} tissue={}x{} knots={} tissue_hash={:08x}",
            hello.protocol,
            hello.schema,
            hello.core.name(),
            hello.tick_hz,
            hello.grid,
            hello.tissue_w,
            hello.tissue_h,
            hello.knots,
            hello.tissue
        )
        .map_err(io_error),
        Command::Status => {
            link.send(&ToDevice::Status).map_err(fail)?;
            status_line(&mut link, &a.connect, out)
        }
        Command::Arm | Command::Disarm => {
            let msg = if matches!(a.command, Command::Arm) { ToDevice::Arm } else { ToDevice::Disarm };
            link.send(&msg).map_err(fail)?;
            status_line(&mut link, &a.connect, out)
        }
        Command::Pose { origin } => {
            let v = parse_triple(&origin)
                .filter(|v| v.iter().all(|x| x.is_finite() && x.abs() <= 100.0))
                .ok_or_else(|| arg_error("--origin", "must be X,Y,Z: three numbers of mm, each within ±100"))?;
            let bits = v.map(|x| mccs::Length::from_num(x).to_bits());
            link.send(&ToDevice::Pose { origin: bits }).map_err(fail)?;
            // The status that follows says the pose arrived (frames are in order).
            link.send(&ToDevice::Status).map_err(fail)?;
            expect(&mut link, &a.connect, |m| matches!(m, ToHost::Status(_)))?;
            writeln!(out, "pose origin={},{},{}", fmt_given(v[0]), fmt_given(v[1]), fmt_given(v[2])).map_err(io_error)
        }
        Command::Load { params, knots } => load(&mut link, &a.connect, &hello, &params, knots, out),
        Command::Replay(r) => replay(&mut link, &a.connect, &hello, r, out),
        Command::Watch { seconds, every } => watch(&mut link, &a.connect, seconds, every, out),
        Command::Mesh { seconds, every } => mesh(&mut link, &a.connect, seconds, every, out),
    }
}

/// `X,Y,Z` as three numbers.
fn parse_triple(text: &str) -> Option<[f64; 3]> {
    let v: Vec<f64> = text
        .split(',')
        .map(|x| x.trim().parse().ok())
        .collect::<Option<_>>()?;
    v.try_into().ok()
}

/// Says `Hello` until the device answers (bytes sent before its UART is on are lost),
/// and holds it to this host's protocol and schema.
fn hello(link: &mut Link, addr: &str) -> Result<HelloInfo, CliError> {
    let start = Instant::now();
    let gone = |e: std::io::Error| CliError::new(format!("{addr}: {e}"));
    while start.elapsed() < Duration::from_secs(10) {
        link.send(&ToDevice::Hello).map_err(gone)?;
        let until = Instant::now() + Duration::from_millis(200);
        while let Some(m) = link.recv(until).map_err(gone)? {
            if let ToHost::Hello(h) = m {
                if (h.protocol, h.schema) != (PROTOCOL, SCHEMA) {
                    return Err(CliError::new(format!(
                        "{addr}: the device speaks protocol {} schema {:08x}, this mccs protocol {PROTOCOL} schema {SCHEMA:08x}: update one of them",
                        h.protocol, h.schema
                    )));
                }
                return Ok(h);
            }
        }
    }
    Err(CliError::new(format!("{addr}: no answer to hello in 10 s")))
}

/// The first message `want` takes, within [`ANSWER`]; a `Nak` is the device's refusal.
fn expect(link: &mut Link, addr: &str, want: impl Fn(&ToHost) -> bool) -> Result<ToHost, CliError> {
    let deadline = Instant::now() + ANSWER;
    let mut told = false;
    let start = Instant::now();
    loop {
        let m = link
            .recv(Instant::now() + Duration::from_secs(2))
            .map_err(|e| CliError::new(format!("{addr}: {e}")))?;
        match m {
            Some(ToHost::Nak(r)) => return Err(nak(addr, r)),
            Some(m) if want(&m) => return Ok(m),
            Some(_) => {}
            None if Instant::now() >= deadline => {
                return Err(CliError::new(format!(
                    "{addr}: no answer in {} s",
                    ANSWER.as_secs()
                )))
            }
            None => {
                if !told {
                    eprintln!(
                        "mccs link: waiting for the device ({} s so far)",
                        start.elapsed().as_secs()
                    );
                    told = true;
                }
            }
        }
    }
}

/// A `Nak` as one line.
fn nak(addr: &str, r: NakReason) -> CliError {
    match r {
        NakReason::Option { option, limit } => {
            use mccs_link::message::SpecOption as O;
            let what = match option {
                O::Grid => format!("the device holds a patch of at most {limit} nodes a side"),
                O::Arith => "the device runs the wide arithmetic only".into(),
                O::CapRadius => "the device roams flat tissues only".into(),
                O::Tissue => format!("the device holds tissues of at most {limit} nodes a side"),
                O::Config => {
                    "the device's solver refused this configuration (its substeps at this rate)"
                        .into()
                }
                _ => format!("beyond the device's limit ({limit})"),
            };
            arg_error(option.flag(), &what)
        }
        r => CliError::new(format!("{addr}: the device refused: {}", r.message())),
    }
}

fn status_line(link: &mut Link, addr: &str, out: &mut dyn Write) -> Result<(), CliError> {
    let ToHost::Status(s) = expect(link, addr, |m| matches!(m, ToHost::Status(_)))? else {
        unreachable!()
    };
    writeln!(
        out,
        "ticks={} overruns={} bad_frames={} dropped_telemetry={} armed={} fault={} pose={},{},{}",
        s.ticks,
        s.overruns,
        s.bad_frames,
        s.dropped_telemetry,
        s.armed as u8,
        s.fault as u8,
        mccs::Length::from_bits(s.pose[0]).to_num::<f64>(),
        mccs::Length::from_bits(s.pose[1]).to_num::<f64>(),
        mccs::Length::from_bits(s.pose[2]).to_num::<f64>(),
    )
    .map_err(io_error)
}

fn load(
    link: &mut Link,
    addr: &str,
    hello: &HelloInfo,
    params: &std::path::Path,
    knots: Option<usize>,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    let knots = knots.unwrap_or(hello.knots as usize);
    if knots != hello.knots as usize {
        return Err(arg_error(
            "--knots",
            &format!("the device takes {} knots (got {knots})", hello.knots),
        ));
    }
    if knots != 65 {
        return Err(arg_error(
            "--knots",
            "this mccs sends 65-knot tables (the device's)",
        ));
    }
    let p = paramfile::read(params)?;
    let table = build::<64>(&p, params, Domain::Default, false, true)?;
    let mut bytes = vec![0u8; table_bytes::len(64)];
    table_bytes::write(&table, &mut bytes);
    let hash = table_bytes::hash(&table);
    let gone = |e: std::io::Error| CliError::new(format!("{addr}: {e}"));
    link.send(&ToDevice::TissueBegin {
        segments: 64,
        len: bytes.len() as u32,
        hash,
    })
    .map_err(gone)?;
    // One chunk at a time: the status after each says the device has taken it (its
    // receive queue is not overrun while it works).
    for (i, c) in bytes.chunks(200).enumerate() {
        link.send(&ToDevice::TissueChunk {
            offset: (i * 200) as u32,
            bytes: c,
        })
        .map_err(gone)?;
        link.send(&ToDevice::Status).map_err(gone)?;
        expect(link, addr, |m| matches!(m, ToHost::Status(_)))?;
    }
    link.send(&ToDevice::TissueCommit).map_err(gone)?;
    match expect(link, addr, |m| matches!(m, ToHost::Ack { .. }))? {
        ToHost::Ack { tissue } if tissue == hash => {
            writeln!(out, "ack tissue={tissue:08x}").map_err(io_error)
        }
        other => Err(CliError::new(format!(
            "{addr}: acknowledged another tissue: {other:?}"
        ))),
    }
}

fn replay(
    link: &mut Link,
    addr: &str,
    hello: &HelloInfo,
    r: ReplayArgs,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    let cfg = r.tuning.config(r.patch.rate)?;
    let roaming = r.roam.roaming(&r.patch)?;
    let traj = trajectory::read(&r.probe).map_err(|e| CliError::new(e.to_string()))?;
    let ticks: Vec<(f64, [f64; 3])> = traj.ticks(r.patch.rate).collect();
    if r.patch.grid > hello.max_grid as usize {
        return Err(arg_error(
            "--grid",
            &format!(
                "the device holds a patch of at most {} nodes a side",
                hello.max_grid
            ),
        ));
    }
    let spec = ReplaySpec {
        grid: r.patch.grid as u8,
        spacing_mm: r.patch.spacing,
        tick_hz: r.patch.rate,
        node_mass_kg: cfg.node_mass,
        spring_damping: cfg.spring_damping,
        coupling_stiffness: cfg.coupling.stiffness,
        coupling_damping: cfg.coupling.damping,
        max_force: cfg.coupling.max_force,
        symplectic: r.patch.integrator == super::IntegratorArg::SymplecticDamped,
        narrow: r.patch.arith == Some(super::ArithArg::Narrow),
        samples: ticks.len() as u32,
        start: [ticks[0].1[0], ticks[0].1[1]],
        roaming: roaming.map(|ro| RoamSpec {
            tissue_w: ro.tissue.w as u8,
            tissue_h: ro.tissue.h as u8,
            mu_s: ro.friction.mu_s,
            mu_k: ro.friction.mu_k,
            probe_radius: ro.probe_radius,
            cap_radius: match ro.tissue.shape {
                crate::roam::Shape::Flat => None,
                crate::roam::Shape::Cap { radius } => Some(radius),
            },
        }),
    };
    let gone = |e: std::io::Error| CliError::new(format!("{addr}: {e}"));
    link.send(&ToDevice::ReplayBegin(spec)).map_err(gone)?;
    let ToHost::ReplayCredit { mut until } =
        expect(link, addr, |m| matches!(m, ToHost::ReplayCredit { .. }))?
    else {
        unreachable!()
    };
    let mut w = std::io::BufWriter::new(out);
    writeln!(w, "{}", header(roaming.is_some())).map_err(io_error)?;
    let mut sent = 0usize;
    let mut got = 0usize;
    let mut last = Instant::now();
    while got < ticks.len() {
        while sent < ticks.len() && (sent as u32) < until {
            let n = (until as usize - sent).min(16).min(ticks.len() - sent);
            let points: Vec<u8> = ticks[sent..sent + n]
                .iter()
                .flat_map(|(_, p)| {
                    probe_bits(*p)
                        .into_iter()
                        .flat_map(|c| c.to_bits().to_le_bytes())
                })
                .collect();
            link.send(&ToDevice::ReplayPath {
                first: sent as u32,
                points: &points,
            })
            .map_err(gone)?;
            sent += n;
        }
        match link
            .recv(Instant::now() + Duration::from_millis(500))
            .map_err(gone)?
        {
            Some(ToHost::ReplayRow(row)) => {
                let k = row.tick as usize;
                let (t, p) = *ticks.get(k).ok_or_else(|| {
                    CliError::new(format!("{addr}: a row for tick {k}, past the path"))
                })?;
                let line = if roaming.is_some() {
                    roam_line(&RoamRow::of_raw(t, p, &row))
                } else {
                    glued_line(&Row::of_raw(t, p, &row))
                };
                writeln!(w, "{line}").map_err(io_error)?;
                got += 1;
                last = Instant::now();
            }
            Some(ToHost::ReplayCredit { until: u }) => until = u,
            Some(ToHost::ReplayEnd { .. }) => break,
            Some(ToHost::Nak(r)) => return Err(nak(addr, r)),
            Some(_) => {}
            None if last.elapsed() > ANSWER => {
                return Err(CliError::new(format!(
                    "{addr}: the replay stopped at tick {got} of {}",
                    ticks.len()
                )))
            }
            None => {}
        }
    }
    w.flush().map_err(io_error)
}

/// A stream's `--seconds` (0 … 3600) and `--every` (1 … 1000 ticks).
fn stream_args(seconds: f64, every: u16) -> Result<(), CliError> {
    if !(seconds.is_finite() && (0.0..=3600.0).contains(&seconds)) {
        return Err(arg_error("--seconds", "must be 0 … 3600"));
    }
    if !(1..=1000).contains(&every) {
        return Err(arg_error("--every", "must be 1 … 1000 ticks"));
    }
    Ok(())
}

/// A stream for `seconds`: `start` sent, `header` printed, each message through `row`
/// (which prints the lines it makes of it), then `stop` sent.
#[allow(clippy::too_many_arguments)]
fn stream(
    link: &mut Link,
    addr: &str,
    seconds: f64,
    every: u16,
    (start, stop): (ToDevice, ToDevice),
    header: &str,
    out: &mut dyn Write,
    mut row: impl FnMut(&ToHost, &mut dyn Write) -> std::io::Result<()>,
) -> Result<(), CliError> {
    stream_args(seconds, every)?;
    let gone = |e: std::io::Error| CliError::new(format!("{addr}: {e}"));
    link.send(&start).map_err(gone)?;
    let mut w = std::io::BufWriter::new(out);
    writeln!(w, "{header}").map_err(io_error)?;
    let end = Instant::now() + Duration::from_secs_f64(seconds);
    while let Some(m) = link.recv(end).map_err(gone)? {
        row(&m, &mut w).map_err(io_error)?;
    }
    link.send(&stop).map_err(gone)?;
    w.flush().map_err(io_error)
}

fn watch(
    link: &mut Link,
    addr: &str,
    seconds: f64,
    every: u16,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    let header = "seq,tick,x_mm,y_mm,z_mm,fx_n,fy_n,fz_n,gain,contact,slipping,armed,fault,dropped";
    let watch = |every| ToDevice::Watch { every };
    stream(
        link,
        addr,
        seconds,
        every,
        (watch(every), watch(0)),
        header,
        out,
        |m, w| {
            let ToHost::Telemetry(t) = m else {
                return Ok(());
            };
            let mm = |b: i32| mccs::Length::from_bits(b).to_num::<f64>();
            let n = |b: i32| mccs::Force::from_bits(b).to_num::<f64>();
            writeln!(
                w,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                t.seq,
                t.tick,
                mm(t.probe[0]),
                mm(t.probe[1]),
                mm(t.probe[2]),
                n(t.force[0]),
                n(t.force[1]),
                n(t.force[2]),
                t.gain as f64 / 32768.0,
                t.flags & 1,
                (t.flags >> 1) & 1,
                (t.flags >> 2) & 1,
                (t.flags >> 3) & 1,
                t.dropped
            )
        },
    )
}

fn mesh(
    link: &mut Link,
    addr: &str,
    seconds: f64,
    every: u16,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    let header = "seq,tick,node,x_mm,y_mm,z_mm";
    let watch = |every| ToDevice::WatchMesh { every };
    stream(
        link,
        addr,
        seconds,
        every,
        (watch(every), watch(0)),
        header,
        out,
        |m, w| {
            let ToHost::Mesh(part) = m else {
                return Ok(());
            };
            let mm = |b: i32| mccs::Length::from_bits(b).to_num::<f64>();
            let count = (part.nodes.saturating_sub(part.first) as usize).min(part.positions.len());
            for (k, p) in part.positions[..count].iter().enumerate() {
                writeln!(
                    w,
                    "{},{},{},{},{},{}",
                    part.seq,
                    part.tick,
                    part.first as usize + k,
                    mm(p[0]),
                    mm(p[1]),
                    mm(p[2])
                )?;
            }
            Ok(())
        },
    )
}
