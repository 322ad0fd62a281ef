//! `mccs arm`: the 3-DOF arm's kinematics and torques on the host, in the fixed point the
//! firmware runs (default) or the `f64` twin (docs/arm.md).

use super::{arg_error, io_error, CliError};
use crate::arm::gravity_fit::{self, HeldPose};
use crate::arm::{columns, device_file, ArmTwin};
use mccs::{Arm, Force};
use mccs_client::shown::ShownPath;
use std::io::Write;
use std::path::{Path, PathBuf};

#[derive(clap::Args, Debug)]
pub(super) struct Args {
    #[command(subcommand)]
    command: Command,
}

/// Which arm computes: the `--backend` of `fk` and `torque` (the law's `Backend`
/// names a force table, which the arm's kinematics do not use).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum ArmBackend {
    /// The arm's f64 twin (host only).
    Reference,
    /// The core's fixed-point kinematics and torques, as the firmware computes them.
    Fixed,
}

#[derive(clap::Subcommand, Debug)]
enum Command {
    /// The probe in the device frame, CSV `x_mm,y_mm,z_mm`, for each row of joint counts.
    Fk {
        /// The device file (docs/arm.md; devices/woodenhaptics.toml).
        #[arg(long)]
        device: PathBuf,
        /// A CSV file of joint counts, `count_a,count_b,count_c` a row (whole numbers).
        #[arg(long)]
        counts: PathBuf,
        /// Fixed point, as the firmware computes it, or the f64 twin.
        #[arg(long, value_enum, default_value_t = ArmBackend::Fixed)]
        backend: ArmBackend,
    },
    /// The joints' torques before saturation (Jᵀ F + gravity, N·m) and the duties after
    /// it, CSV `tau_a_nm,tau_b_nm,tau_c_nm,duty_a,duty_b,duty_c`, for each row of counts
    /// and force (N, the tissue's frame).
    Torque {
        /// The device file.
        #[arg(long)]
        device: PathBuf,
        /// A CSV file of counts and forces, `count_a,count_b,count_c,fx_n,fy_n,fz_n` a row.
        #[arg(long)]
        input: PathBuf,
        /// Fixed point, as the firmware computes it, or the f64 twin.
        #[arg(long, value_enum, default_value_t = ArmBackend::Fixed)]
        backend: ArmBackend,
    },
    /// The arm's masses from static poses: prints `GRAVITY upper_arm_mass_kg=…
    /// forearm_mass_kg=… g_b_nmm=… g_c_nmm=… offset_duty_b=… offset_duty_c=…
    /// rms_duty_b=… rms_duty_c=… poses=N`, and with --out writes the device file with
    /// those masses.
    Calibrate {
        /// The device file: its [gravity] section gives the centres of mass and g.
        #[arg(long)]
        device: PathBuf,
        /// CSV `count_a,count_b,count_c,duty_b,duty_c`: at least 8 poses held still,
        /// each with the duties (before the trims, −1 … 1) that hold it.
        #[arg(long)]
        poses: PathBuf,
        /// Write the device file with the fitted masses here (it may be --device).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// The arm's stable region on its simulated body (docs/safety.md): the board's loop
    /// closed through the arm's dynamics, a press held at five depths across a count with
    /// each hand of the range; at each coupling damping, prints `STABLE damping_n_s_m=…
    /// max_coupling_n_mm=… first_unstable=…` (several minutes each on two cores),
    /// and with --out writes the device file's
    /// [stability] section, which `mccs check --device arm` holds couplings to half of.
    Stability {
        /// The device file.
        #[arg(long)]
        device: PathBuf,
        /// The coupling dampings, N·s/m, rising (0 … 1000), comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "0,0.5,1,2,5")]
        damping: Vec<f64>,
        /// Write the device file with the measured [stability] here (it may be --device).
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// The rows of a numeric CSV file with exactly `header` ([`columns::parse`]).
fn rows(path: &Path, header: &[&str]) -> Result<Vec<Vec<f64>>, CliError> {
    let file = ShownPath(path).to_string();
    let text = mccs_client::input::read_text(path, mccs_client::input::DATA_BYTES)
        .map_err(|e| CliError::new(format!("{file}: cannot read: {e}")))?;
    columns::parse(&text, &file, header).map_err(CliError::new)
}

pub(super) fn run(a: Args, out: &mut dyn Write) -> Result<(), CliError> {
    match a.command {
        Command::Fk {
            device,
            counts,
            backend,
        } => fk(&device, &counts, backend, out),
        Command::Torque {
            device,
            input,
            backend,
        } => torque(&device, &input, backend, out),
        Command::Calibrate {
            device,
            poses,
            out: written,
        } => calibrate(&device, &poses, written.as_deref(), out),
        Command::Stability {
            device,
            damping,
            out: written,
        } => stability(&device, &damping, written.as_deref(), out),
    }
}

/// `mccs arm stability`: the region, its lines, and the device file written with it.
fn stability(
    device: &Path,
    dampings: &[f64],
    written: Option<&Path>,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    use crate::arm::closed_loop::{largest_stable, HANDS, HOLDS_PER_HAND};
    use crate::arm::dynamics::BodySpec;
    let spec = device_file::read(device).map_err(CliError::new)?;
    Arm::new(&spec).map_err(|e| arg_error("--device", &e.to_string()))?;
    if let Some(p) = written {
        super::check_writable("--out", p)?;
    }
    let rising = dampings.windows(2).all(|w| w[1] > w[0]);
    if dampings.is_empty()
        || dampings.len() > 16
        || !rising
        || dampings.iter().any(|b| !(0.0..=1000.0).contains(b))
    {
        return Err(arg_error(
            "--damping",
            "must be 1 to 16 dampings, rising, each 0 … 1000 N·s/m",
        ));
    }
    // The arm's stability, not the tick's: any substeps the bound asks for (the board
    // also refuses a coupling whose substeps pass its tick's budget, at start-up).
    let config = haptic_f405::BoardConfig {
        tick_budget: u32::MAX,
        ..haptic_f405::BOARD
    };
    let mut points = Vec::new();
    for &b in dampings {
        eprintln!(
            "mccs arm stability: damping {b} N·s/m: a press held at {HOLDS_PER_HAND} depths across a count with each of {} hands, coupling 0.25 N/mm up by √2 until one hand's is not stable at most of them",
            HANDS.len()
        );
        let (k, why) = largest_stable(&config, &spec, BodySpec::STAND_IN, &HANDS, b, |k| {
            eprintln!("mccs arm stability:   coupling {k:.3} N/mm");
        });
        if k == 0.0 {
            return Err(CliError::new(format!(
                "{}: no coupling is stable at {b} N·s/m: {why}",
                ShownPath(device)
            )));
        }
        writeln!(
            out,
            "STABLE damping_n_s_m={b} max_coupling_n_mm={k:.3} first_unstable=\"{why}\""
        )
        .map_err(io_error)?;
        out.flush().map_err(io_error)?;
        points.push((b, (k * 1000.0).round() / 1000.0));
    }
    if let Some(path) = written {
        let text = mccs_client::input::read_text(device, mccs_client::input::CONFIG_BYTES)
            .map_err(|e| CliError::new(format!("{}: cannot read: {e}", ShownPath(device))))?;
        let region = device_file::StableRegion { points };
        let new = device_file::with_stability(
            &text,
            &region,
            "measured by `mccs arm stability` on the simulated arm (docs/safety.md):\nat each coupling damping, the largest coupling stiffness a held press\nwas stable with; `mccs check --device arm` allows half of it.",
        );
        std::fs::write(path, new)
            .map_err(|e| CliError::new(format!("{}: cannot write: {e}", ShownPath(path))))?;
        eprintln!(
            "mccs: wrote {} with the measured [stability]",
            ShownPath(path)
        );
    }
    Ok(())
}

/// The device file as the fixed-point arm and its `f64` twin.
fn load(device: &Path) -> Result<(Arm, ArmTwin), CliError> {
    let spec = device_file::read(device).map_err(CliError::new)?;
    let arm = Arm::new(&spec).map_err(|e| arg_error("--device", &e.to_string()))?;
    Ok((arm, ArmTwin { spec }))
}

/// `mccs arm fk`.
fn fk(
    device: &Path,
    counts: &Path,
    backend: ArmBackend,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    let (arm, twin) = load(device)?;
    let rows = rows(counts, &["count_a", "count_b", "count_c"])?;
    let mut w = std::io::BufWriter::new(out);
    writeln!(w, "x_mm,y_mm,z_mm").map_err(io_error)?;
    for r in rows {
        let c = [r[0], r[1], r[2]];
        let p = match backend {
            ArmBackend::Fixed => arm.pose(c.map(|x| x as i32)).device_mm(),
            ArmBackend::Reference => twin.fk(twin.angles(c)),
        };
        writeln!(w, "{},{},{}", p[0], p[1], p[2]).map_err(io_error)?;
    }
    w.flush().map_err(io_error)
}

/// `mccs arm torque`.
fn torque(
    device: &Path,
    input: &Path,
    backend: ArmBackend,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    let (arm, twin) = load(device)?;
    let rows = rows(
        input,
        &["count_a", "count_b", "count_c", "fx_n", "fy_n", "fz_n"],
    )?;
    let mut w = std::io::BufWriter::new(out);
    writeln!(w, "tau_a_nm,tau_b_nm,tau_c_nm,duty_a,duty_b,duty_c").map_err(io_error)?;
    for r in rows {
        let c = [r[0], r[1], r[2]];
        let f = [r[3], r[4], r[5]];
        let (tau, duty) = match backend {
            ArmBackend::Fixed => {
                let d = arm.drive(
                    &arm.pose(c.map(|x| x as i32)),
                    f.map(Force::saturating_from_num),
                );
                (
                    d.torque_q8.map(|t| t as f64 / 256.0 / 1000.0),
                    d.duty_q16.map(|x| x as f64 / 65_536.0),
                )
            }
            ArmBackend::Reference => {
                let t = twin.torque(twin.angles(c), f);
                (t.map(|x| x / 1000.0), twin.duties(t).0)
            }
        };
        writeln!(
            w,
            "{},{},{},{},{},{}",
            tau[0], tau[1], tau[2], duty[0], duty[1], duty[2]
        )
        .map_err(io_error)?;
    }
    w.flush().map_err(io_error)
}

/// `mccs arm calibrate`: the fit, its line, and the device file written with it.
fn calibrate(
    device: &Path,
    poses: &Path,
    written: Option<&Path>,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    let spec = device_file::read(device).map_err(CliError::new)?;
    if let Some(p) = written {
        super::check_writable("--out", p)?;
    }
    let rows = rows(
        poses,
        &["count_a", "count_b", "count_c", "duty_b", "duty_c"],
    )?;
    let held: Vec<HeldPose> = rows
        .iter()
        .map(|r| HeldPose {
            counts: [r[0], r[1], r[2]],
            duty: [r[3], r[4]],
        })
        .collect();
    let twin = ArmTwin { spec };
    let fit = gravity_fit::fit(&twin, &held)
        .map_err(|e| CliError::new(format!("{}: {e}", ShownPath(poses))))?;
    writeln!(
        out,
        "GRAVITY upper_arm_mass_kg={:.4} forearm_mass_kg={:.4} g_b_nmm={:.2} g_c_nmm={:.2} offset_duty_b={:.4} offset_duty_c={:.4} rms_duty_b={:.4} rms_duty_c={:.4} poses={}",
        fit.upper_arm_mass_kg,
        fit.forearm_mass_kg,
        fit.coefficients_nmm[0],
        fit.coefficients_nmm[1],
        fit.offset_duty[0],
        fit.offset_duty[1],
        fit.rms_duty[0],
        fit.rms_duty[1],
        held.len()
    )
    .map_err(io_error)?;
    out.flush().map_err(io_error)?;
    if fit.offset_duty.iter().any(|o| o.abs() > 0.01) {
        eprintln!(
            "mccs: warning: the holding duties carry an offset of {:.3} (B) and {:.3} (C) of full duty: measure the joints' trims (docs/arm.md, the locked-rotor sweep)",
            fit.offset_duty[0], fit.offset_duty[1]
        );
    }
    if let Some(path) = written {
        let text = mccs_client::input::read_text(device, mccs_client::input::CONFIG_BYTES)
            .map_err(|e| CliError::new(format!("{}: cannot read: {e}", ShownPath(device))))?;
        let new = gravity_fit::with_masses(&text, &fit).ok_or_else(|| {
            CliError::new(format!(
                "{}: gravity.upper_arm_mass_kg or gravity.forearm_mass_kg: not found to rewrite",
                ShownPath(device)
            ))
        })?;
        std::fs::write(path, new)
            .map_err(|e| CliError::new(format!("{}: cannot write: {e}", ShownPath(path))))?;
        eprintln!("mccs: wrote {} with the fitted masses", ShownPath(path));
    }
    Ok(())
}
