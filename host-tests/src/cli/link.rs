//! `mccs link`: talk to a device over the host link (docs/link.md), through the scene's
//! library (`mccs_client`): each subcommand opens a session (hello, and a device of
//! another protocol or schema refused), does its one thing and prints its answer;
//! `script` runs a scene from a file on one session (`link_script.rs`).

use super::link_script;
use super::patch_args::{PatchArgs, TuningArgs};
use super::replay::{glued_line, header, roam_line, RoamArgs};
use super::{arg_error, fmt_given, io_error, Backend, CliError};
use crate::replay::{RoamRow, Row};
use crate::trajectory;
use mccs_client::pose_text::numbers;
use mccs_client::{Device, Error, Pose, TelemetrySample, Tissue};
use mccs_link::{Flags, ReplaySpec, RoamSpec};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

#[derive(clap::Args, Debug)]
pub(super) struct Args {
    /// The device: unix:PATH, tcp:HOST:PORT, or a serial port's path (1,000,000 baud).
    #[arg(long, value_name = "ADDR")]
    connect: String,
    #[command(subcommand)]
    command: Command,
}

#[derive(clap::Subcommand, Debug)]
enum Command {
    /// One line: what the device is — protocol, schema, device (1dof, arm), simulated,
    /// core, tick_hz, contact (glued, roaming), grid, tissue WxH, spacing_mm, knots,
    /// tissue_hash, friction, substeps, force_clamp_n, workspace_mm, pose_limits, baud,
    /// the least telemetry and mesh periods, the tick's budget and costs.
    Hello,
    /// One line: ticks, overruns, bad_frames, dropped_telemetry, dropped_mesh,
    /// rx_dropped, armed, fault, replaying, checking, gain, pose, rotation_deg.
    Status,
    /// Send a tissue — a parameter file (its force table built as `mccs table` builds
    /// it) or a table's `.bin` (`mccs table --format bin`) — which the device checks
    /// (stability, its tick's budget) before it swaps it in. Prints `ack tissue=<hash>`;
    /// a refusal exits 2 with the device's reason.
    Load {
        /// Parameter file (the TOML schema of docs/model.md) or a table `.bin`.
        #[arg(long, value_name = "FILE")]
        params: PathBuf,
        /// The tissue's friction MU_S,MU_K (a roaming device's; default: keep the live
        /// tissue's).
        #[arg(long, value_name = "MU_S,MU_K")]
        friction: Option<String>,
    },
    /// Replay a probe trajectory on the device's solver and tissue: the same CSV as
    /// `mccs replay --backend fixed` with the same options on that tissue.
    Replay(ReplayArgs),
    /// Stream live telemetry as CSV for S seconds (the columns: docs/link.md).
    Watch {
        /// How long, s (0 … 3600).
        #[arg(long, default_value_t = 1.0)]
        seconds: f64,
        /// Ticks between rows (1 … 1000; the device holds it to its byte budget).
        #[arg(long, default_value_t = 10)]
        every: u16,
    },
    /// Stream the live patch's node positions (for the visuals) as CSV for S seconds:
    /// `seq,tick,node,i,j,x_mm,y_mm,z_mm`, one row per node (tissue frame).
    Mesh {
        /// How long, s (0 … 3600).
        #[arg(long, default_value_t = 1.0)]
        seconds: f64,
        /// Ticks between meshes (1 … 1000; the device holds it to its byte budget).
        #[arg(long, default_value_t = 17)]
        every: u16,
    },
    /// Place the tissue in the device's frame: its origin, mm, and a rotation
    /// RX,RY,RZ in degrees (`Rz Ry Rx`). Prints `pose origin=… rotation=…`; outside the
    /// device's workspace it refuses (exit 2).
    Pose {
        /// X,Y,Z, mm.
        #[arg(long, value_name = "X,Y,Z", allow_negative_numbers = true)]
        origin: String,
        /// RX,RY,RZ, degrees (default 0,0,0).
        #[arg(long, value_name = "RX,RY,RZ", allow_negative_numbers = true)]
        rotation: Option<String>,
    },
    /// Take the device: it renders only while this host talks (docs/link.md). The
    /// command exits at once, and the device fades 100 ms later: hold it with `script`.
    Arm,
    /// Force to zero until the next `arm`.
    Disarm,
    /// What the device kept of its run before its last reset (docs/safety.md, "The
    /// black box"): one line — stopped_by, part, stop_tick, ended_by, end_tick, pc,
    /// reset, reset_flags, ticks — then its last ticks as CSV (tick, count_a … count_c,
    /// fx_n … fz_n, duty_a … duty_c, gain, flags). After a power-on: `blackbox
    /// kept=false`.
    Blackbox,
    /// Run a scene from FILE on one connection (docs/link.md, "Scripts"): hello, status,
    /// load, pose, arm, disarm, telemetry, mesh and wait steps; each step's result on a
    /// line that starts with `# `, the telemetry as one CSV.
    Script {
        /// The script.
        file: PathBuf,
    },
}

/// (`--backend` is `mccs replay`'s, shared through `PatchArgs`: here the device's core
/// runs, so it is left out of the help, and any value but its default is refused; the
/// grid's and arithmetic's help name the device's limits, not that flag.)
#[derive(clap::Args, Debug)]
#[command(mut_arg("backend", |a| a.hide(true)))]
#[command(mut_arg("grid", |a| a.help("Surface nodes per side, N (3 … the device's `grid` in `mccs link hello`)")))]
#[command(mut_arg("arith", |a| a.help("Arithmetic of the device's core (it runs one, `core` in `mccs link hello`, and refuses the other)")))]
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

pub(super) fn run(a: Args, out: &mut dyn Write) -> Result<(), CliError> {
    // Arguments and files are checked before the device is reached.
    mccs_client::Addr::parse(&a.connect).map_err(|e| arg_error("--connect", e))?;
    match &a.command {
        Command::Replay(r) => {
            if r.patch.backend != Backend::Reference {
                return Err(arg_error(
                    "--backend",
                    "a link replay runs the device's core: leave it out",
                ));
            }
            // The device runs the fixed-point core: its arguments are checked as
            // `mccs replay --backend fixed`'s (`--arith` among them).
            PatchArgs {
                backend: Backend::Fixed,
                ..r.patch
            }
            .check()?;
        }
        Command::Watch { seconds, every } | Command::Mesh { seconds, every } => {
            stream_args(*seconds, *every)?
        }
        Command::Script { file } => {
            // Read and checked whole before the device is reached.
            let script = link_script::Script::read(file)?;
            let device = open(&a.connect)?;
            return script.run(&device, out);
        }
        _ => {}
    }
    let pose = match &a.command {
        Command::Pose { origin, rotation } => Some(pose_of(origin, rotation.as_deref())?),
        _ => None,
    };
    let tissue = match &a.command {
        Command::Load { params, friction } => {
            Some(tissue_of(params, friction.as_deref(), "--friction")?)
        }
        _ => None,
    };
    let device = open(&a.connect)?;
    let fail = |e: Error| device_error(e);
    match a.command {
        Command::Hello => writeln!(out, "{}", device.info()).map_err(io_error),
        Command::Status => writeln!(out, "{}", device.status().map_err(fail)?).map_err(io_error),
        Command::Arm => writeln!(out, "{}", device.arm_held().map_err(fail)?).map_err(io_error),
        Command::Disarm => writeln!(out, "{}", device.disarm().map_err(fail)?).map_err(io_error),
        Command::Blackbox => black_box(&device, out),
        Command::Pose { .. } => {
            let p = pose.unwrap_or(Pose::IDENTITY);
            device.set_pose(p).map_err(fail)?;
            writeln!(out, "{}", pose_line(&p)).map_err(io_error)
        }
        Command::Load { .. } => {
            let t = tissue.ok_or_else(|| CliError::new("no tissue"))?;
            let hash = device.load_tissue(&t).map_err(fail)?;
            writeln!(out, "ack tissue={hash:08x}").map_err(io_error)
        }
        Command::Replay(r) => replay(&device, r, out),
        Command::Watch { seconds, every } => watch(&device, seconds, every, out),
        Command::Mesh { seconds, every } => mesh(&device, seconds, every, out),
        Command::Script { .. } => Ok(()),
    }
}

/// `link blackbox`: the record's line (the part by its name, as the board's log names
/// it), then its ticks as CSV; progress on stderr every second while it reads.
fn black_box(device: &Device, out: &mut dyn Write) -> Result<(), CliError> {
    let mut said = Instant::now();
    let b = device
        .black_box(|read, total| {
            if said.elapsed() >= Duration::from_secs(1) {
                eprintln!("mccs link blackbox: {read} of {total} ticks read");
                said = Instant::now();
            }
        })
        .map_err(device_error)?;
    // The part by the name the board's log gives it (its code in the box).
    let part = haptic_f405::device::DevicePart::from_code(b.head.part)
        .map_or("none".to_string(), |p| format!("\"{}\"", p.name()));
    writeln!(out, "{}", b.line(&part)).map_err(io_error)?;
    if b.kept() {
        writeln!(out, "{}", mccs_client::BlackBox::CSV_HEADER).map_err(io_error)?;
        for t in &b.ticks {
            writeln!(out, "{}", mccs_client::BlackBox::csv_row(t)).map_err(io_error)?;
        }
    }
    Ok(())
}

/// How long `open` waits for the device's hello before it says that it waits.
const SAY_WAITING: Duration = Duration::from_secs(4);

/// Opens the device; every failure one line (exit 2). A device that has not answered
/// its hello within [`SAY_WAITING`] (another host holds it, or it is not one) gets a
/// line saying the command waits for it, and for how long at most.
pub(super) fn open(addr: &str) -> Result<Device, CliError> {
    let (opened, waiting) = std::sync::mpsc::channel::<()>();
    let name = mccs_client::shown::ShownName(addr).to_string();
    let most = mccs_client::Options::default().hello_timeout.as_secs();
    let say = std::thread::spawn(move || {
        if waiting.recv_timeout(SAY_WAITING) == Err(std::sync::mpsc::RecvTimeoutError::Timeout) {
            eprintln!(
                "mccs: waiting for {name} to answer hello ({most} s at most; a view or a scene may hold it)"
            );
        }
    });
    let device = Device::open(addr);
    drop(opened);
    let _ = say.join();
    device.map_err(|e| match e {
        Error::Address { .. } | Error::Connect { .. } => arg_error("--connect", &e.to_string()),
        e => device_error(e),
    })
}

/// A session's error as one line (exit 2).
pub(super) fn device_error(e: Error) -> CliError {
    CliError::new(e.to_string())
}

/// The pose of `--origin` and `--rotation`.
fn pose_of(origin: &str, rotation: Option<&str>) -> Result<Pose, CliError> {
    let o = numbers::<3>(origin)
        .ok_or_else(|| arg_error("--origin", "must be X,Y,Z: three numbers of mm"))?;
    let r = match rotation {
        None => [0.0; 3],
        Some(t) => numbers::<3>(t)
            .ok_or_else(|| arg_error("--rotation", "must be RX,RY,RZ: three numbers of degrees"))?,
    };
    Ok(Pose::from_mm_deg(o, r))
}

/// `pose origin=X,Y,Z rotation=RX,RY,RZ`, as the device holds it.
pub(super) fn pose_line(p: &Pose) -> String {
    let o = p.origin_mm();
    let a = p.angles_deg();
    format!(
        "pose origin={},{},{} rotation={:.3},{:.3},{:.3}",
        fmt_given(o[0]),
        fmt_given(o[1]),
        fmt_given(o[2]),
        a[0],
        a[1],
        a[2]
    )
}

/// A tissue from a file (`.bin` or parameters) with friction `MU_S,MU_K` if given.
pub(super) fn tissue_of(
    file: &Path,
    friction: Option<&str>,
    arg: &str,
) -> Result<Tissue, CliError> {
    let t = Tissue::from_file(file).map_err(|e| CliError::new(e.to_string()))?;
    with_friction(t, friction, arg)
}

/// `t` with `friction` (`MU_S,MU_K`, for the argument `arg`), where one is given.
pub(super) fn with_friction(
    t: Tissue,
    friction: Option<&str>,
    arg: &str,
) -> Result<Tissue, CliError> {
    match friction {
        None => Ok(t),
        Some(f) => {
            let [mu_s, mu_k] =
                numbers::<2>(f).ok_or_else(|| arg_error(arg, "must be MU_S,MU_K: two numbers"))?;
            t.with_friction(mu_s, mu_k)
                .map_err(|e| arg_error(arg, &e.to_string()))
        }
    }
}

fn replay(device: &Device, r: ReplayArgs, out: &mut dyn Write) -> Result<(), CliError> {
    let cfg = r.tuning.config(r.patch.rate)?;
    let roaming = r.roam.roaming(&r.patch)?;
    let traj = trajectory::read(&r.probe).map_err(|e| CliError::new(e.to_string()))?;
    let hello = &device.info().hello;
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
        samples: 0,
        start: [0.0; 2],
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
    let mut w = std::io::BufWriter::new(out);
    let mut failed = None;
    let mut started = false;
    let rows = device.replay(&traj, spec, |t| {
        if failed.is_some() {
            return;
        }
        // The header once the device has taken the replay: a refusal prints no CSV.
        if !started {
            started = true;
            if let Err(e) = writeln!(w, "{}", header(roaming.is_some())) {
                failed = Some(e);
                return;
            }
        }
        let line = if roaming.is_some() {
            roam_line(&RoamRow::of_raw(t.time_s, t.probe_mm, &t.row))
        } else {
            glued_line(&Row::of_raw(t.time_s, t.probe_mm, &t.row))
        };
        if let Err(e) = writeln!(w, "{line}") {
            failed = Some(e);
        }
    });
    if let Some(e) = failed {
        return Err(io_error(e));
    }
    rows.map_err(|e| match e.refusal() {
        Some(mccs_link::NakReason::Option { option, .. }) => {
            arg_error(option.flag(), &e.to_string())
        }
        _ => device_error(e),
    })?;
    if !started {
        writeln!(w, "{}", header(roaming.is_some())).map_err(io_error)?;
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

/// The telemetry CSV's columns (`watch`; a script's rows add `t_s` in front).
pub(super) const TELEMETRY_COLUMNS: &str = "seq,tick,x_mm,y_mm,z_mm,fx_n,fy_n,fz_n,gain,contact,slipping,armed,fault,clamped,homed,at_limit,checking,thermal,fault_reason,duty_a,duty_b,duty_c,proxy_x_mm,proxy_y_mm,proxy_z_mm,dropped";

/// A telemetry sample as a row of [`TELEMETRY_COLUMNS`].
pub(super) fn telemetry_row(t: &TelemetrySample) -> String {
    let bit = |f: Flags| t.flags.contains(f) as u8;
    format!(
        "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
        t.seq,
        t.tick,
        t.probe_mm[0],
        t.probe_mm[1],
        t.probe_mm[2],
        t.force_n[0],
        t.force_n[1],
        t.force_n[2],
        t.gain,
        bit(Flags::CONTACT),
        bit(Flags::SLIPPING),
        bit(Flags::ARMED),
        bit(Flags::FAULT),
        bit(Flags::CLAMPED),
        bit(Flags::HOMED),
        bit(Flags::AT_LIMIT),
        bit(Flags::CHECKING),
        bit(Flags::THERMAL),
        t.fault.name(),
        t.duties[0],
        t.duties[1],
        t.duties[2],
        t.proxy_mm[0],
        t.proxy_mm[1],
        t.proxy_mm[2],
        t.dropped
    )
}

fn watch(device: &Device, seconds: f64, every: u16, out: &mut dyn Write) -> Result<(), CliError> {
    let rx = device.telemetry_stream();
    device.watch(every).map_err(device_error)?;
    let mut w = std::io::BufWriter::new(out);
    writeln!(w, "{TELEMETRY_COLUMNS}").map_err(io_error)?;
    let end = Instant::now() + Duration::from_secs_f64(seconds);
    while let Some(left) = end.checked_duration_since(Instant::now()) {
        match rx.recv_timeout(left.min(Duration::from_millis(50))) {
            Ok(t) => writeln!(w, "{}", telemetry_row(&t)).map_err(io_error)?,
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
            Err(_) => break,
        }
    }
    device.watch(0).map_err(device_error)?;
    w.flush().map_err(io_error)
}

fn mesh(device: &Device, seconds: f64, every: u16, out: &mut dyn Write) -> Result<(), CliError> {
    device.watch_mesh(every).map_err(device_error)?;
    let mut w = std::io::BufWriter::new(out);
    writeln!(w, "seq,tick,node,i,j,x_mm,y_mm,z_mm").map_err(io_error)?;
    let end = Instant::now() + Duration::from_secs_f64(seconds);
    let mut last = None;
    while Instant::now() < end {
        if let Some(m) = device.mesh().filter(|m| Some(m.seq) != last) {
            last = Some(m.seq);
            for (k, n) in m.nodes.iter().enumerate() {
                let p = n.position_mm;
                writeln!(
                    w,
                    "{},{},{},{},{},{},{},{}",
                    m.seq, m.tick, k, n.grid[0], n.grid[1], p[0], p[1], p[2]
                )
                .map_err(io_error)?;
            }
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    device.watch_mesh(0).map_err(device_error)?;
    w.flush().map_err(io_error)
}
