//! The `mccs` command-line tool. Every failure is a [`CliError`]: one line, exit status 2.

use crate::paramfile;
use crate::reference::Reference;
use clap::{Parser, Subcommand, ValueEnum};
use mccs::{ForceTable, Params, Strain, TableError};
use std::io::Write;
use std::path::{Path, PathBuf};

/// One-line error for the user; the process exits with status 2.
#[derive(Debug, Clone, PartialEq)]
pub struct CliError(pub String);

impl std::fmt::Display for CliError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl From<paramfile::ParamFileError> for CliError {
    fn from(e: paramfile::ParamFileError) -> Self {
        CliError(e.to_string())
    }
}

fn arg_error(arg: &str, what: &str) -> CliError {
    CliError(format!("{arg}: {what}"))
}

/// Multi-component conical spring soft tissue: curves, tables and patch runs.
#[derive(Parser, Debug)]
#[command(name = "mccs", version)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// How a force is evaluated.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    /// The f64 reference law (host only).
    Reference,
    /// The no_std core's fixed-point table, as the firmware evaluates it.
    Fixed,
}

/// The fixed-point solver's spring arithmetic (`mccs::spring`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArithArg {
    /// 32 × 32 → 64 products: the M3/M4F firmware.
    Wide,
    /// One 16-bit operand per product: the M0 firmware.
    Narrow,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Print F(ε) and dF/dε as CSV `strain,force_n,stiffness_n` for ε = FROM, FROM+STEP, … ≤ TO.
    Curve {
        /// Parameter file (MODEL.md's TOML schema).
        #[arg(long)]
        params: PathBuf,
        /// First strain (may be negative: tension).
        #[arg(long, allow_negative_numbers = true)]
        from: f64,
        /// Last strain (inclusive when reached).
        #[arg(long, allow_negative_numbers = true)]
        to: f64,
        /// Strain step, > 0.
        #[arg(long, allow_negative_numbers = true)]
        step: f64,
        /// Evaluation backend.
        #[arg(long, value_enum, default_value_t = Backend::Reference)]
        backend: Backend,
        /// Knots of the fixed-point table (17, 33, 65 or 129; `--backend fixed` only).
        #[arg(long, default_value_t = 65)]
        knots: usize,
    },
    /// Emit the fixed-point force table as Rust source for `include!`.
    Table {
        /// Parameter file (MODEL.md's TOML schema).
        #[arg(long)]
        params: PathBuf,
        /// Knots: 17, 33, 65 or 129.
        #[arg(long, default_value_t = 65)]
        knots: usize,
        /// Lower end of the strain domain.
        #[arg(long, allow_negative_numbers = true, default_value_t = mccs::table::DEFAULT_DOMAIN.0)]
        from: f64,
        /// Upper end of the strain domain.
        #[arg(long, allow_negative_numbers = true, default_value_t = mccs::table::DEFAULT_DOMAIN.1)]
        to: f64,
        /// Write here instead of standard output.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Fit models to compression data (CSV `strain,force_n`) and compare them: one line
    /// `FIT model=<name> mean_abs=<f> max_abs=<f> mse=<f>` per model.
    Fit {
        /// Data file, CSV with the header `strain,force_n`.
        #[arg(long)]
        data: PathBuf,
        /// mccs, mcs, ms or all.
        #[arg(long, default_value = "all")]
        model: String,
        /// Write the fitted MCCS parameters here (MODEL.md's TOML schema).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Draw the data and the fitted curves here (SVG).
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Print the shipped synthetic demo data set (`params/demo-data.csv`): the Table 2
    /// MCCS law at 40 forces to 1 N, strains with 1 % Gaussian noise (seed 2020).
    DemoData,
    /// Run the firmware's demo on the host (the same code, fixed point) and print its
    /// SUMMARY line; with `--check LOG`, compare a firmware log's SUMMARY line with it.
    Demo {
        /// Which core's demo: m4f, m3 or m0.
        #[arg(long, default_value = "m4f")]
        core: String,
        /// A decoded firmware log to check: exit 1 unless its SUMMARY has overruns=0 and
        /// the same ticks, and steady and max force within 1 % of the host's.
        #[arg(long)]
        check: Option<PathBuf>,
    },
    /// Indent the standard patch: ramp the contact node down to DEPTH over the first half
    /// of the run, hold it there, and print CSV `time_s,reaction_n` per tick.
    Patch {
        /// Parameter file (MODEL.md's TOML schema).
        #[arg(long)]
        params: PathBuf,
        /// Surface nodes per side, N (3 … 40; 3 … 12 with `--backend fixed`).
        #[arg(long)]
        grid: usize,
        /// Grid spacing, mm.
        #[arg(long, allow_negative_numbers = true)]
        spacing: f64,
        /// Indentation depth, mm (0 … spacing).
        #[arg(long, allow_negative_numbers = true)]
        indent: f64,
        /// Solver: the f64 twin or the no_std fixed-point core.
        #[arg(long, value_enum)]
        backend: Backend,
        /// Spring arithmetic of the fixed-point core (`--backend fixed` only).
        #[arg(long, value_enum, default_value_t = ArithArg::Wide)]
        arith: ArithArg,
        /// Tick rate, Hz.
        #[arg(long, default_value_t = 1000.0, allow_negative_numbers = true)]
        rate: f64,
        /// Length of the run, s.
        #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
        duration: f64,
    },
}

/// Largest number of rows `curve` prints.
pub const MAX_ROWS: usize = 10_000_000;

/// Runs the parsed command, writing its output to `out`.
pub fn run(cli: Cli, out: &mut dyn Write) -> Result<(), CliError> {
    match cli.command {
        Command::Curve {
            params,
            from,
            to,
            step,
            backend,
            knots,
        } => {
            let p = paramfile::read(&params)?;
            let strains = strain_grid(from, to, step)?;
            let rows = match backend {
                Backend::Reference => {
                    let r = Reference::new(&p).map_err(|e| file_error(&params, e))?;
                    strains
                        .iter()
                        .map(|&e| (e, r.force(e), r.stiffness(e)))
                        .collect::<Vec<_>>()
                }
                Backend::Fixed => {
                    with_table!(knots, &p, &params, mccs::table::DEFAULT_DOMAIN, |t| {
                        fixed_curve(&t, &strains)
                    })
                }
            };
            write_curve(out, &rows)
        }
        Command::Fit {
            data,
            model,
            out: dest,
            plot,
        } => {
            use crate::fit::{self, ModelKind};
            let kinds: Vec<ModelKind> = match model.as_str() {
                "all" => ModelKind::ALL.to_vec(),
                name => vec![ModelKind::ALL
                    .into_iter()
                    .find(|k| k.name() == name)
                    .ok_or_else(|| arg_error("--model", "must be mccs, mcs, ms or all"))?],
            };
            if dest.is_some() && !kinds.contains(&ModelKind::Mccs) {
                return Err(arg_error(
                    "--out",
                    "needs the mccs model (--model mccs or all)",
                ));
            }
            let points = fit::read_data(&data).map_err(|e| CliError(e.to_string()))?;
            let mut fits = Vec::new();
            for kind in kinds {
                let f = fit::fit(kind, &points).ok_or_else(|| {
                    CliError(format!(
                        "{}: the {} model could not be fitted",
                        data.display(),
                        kind.name()
                    ))
                })?;
                let m = f.metrics;
                writeln!(
                    out,
                    "FIT model={} mean_abs={:.6} max_abs={:.6} mse={:.3e}",
                    kind.name(),
                    m.mean_abs,
                    m.max_abs,
                    m.mse
                )
                .map_err(io_error)?;
                fits.push(f);
            }
            let mccs_params = fits.iter().find_map(|f| match f.model {
                fit::Fitted::Mccs(p) => Some(p),
                _ => None,
            });
            if let (Some(path), Some(p)) = (dest, mccs_params) {
                let text = format!(
                    "# MCCS parameters fitted by `mccs fit` to {}\n{}",
                    data.display(),
                    paramfile::to_toml(&p)
                );
                std::fs::write(&path, text)
                    .map_err(|e| CliError(format!("{}: cannot write: {e}", path.display())))?;
            }
            if let Some(path) = plot {
                let title = format!("{}: fitted models", data.display());
                fit::plot(&path, &points, &fits, &title)
                    .map_err(|e| CliError(format!("{}: cannot draw: {e}", path.display())))?;
            }
            Ok(())
        }
        Command::DemoData => out
            .write_all(crate::fit::to_csv(&crate::fit::demo_data()).as_bytes())
            .map_err(io_error),
        Command::Demo { core, check } => {
            let spec = mccs::demo::spec(&core)
                .ok_or_else(|| arg_error("--core", "must be m4f, m3 or m0"))?;
            let host =
                mccs::demo::run_on_host(&spec).map_err(|e| CliError(format!("demo: {e:?}")))?;
            let line = format!(
                "SUMMARY ticks={} overruns={} max_force_n={} steady_force_n={}",
                host.ticks, host.overruns, host.max_force, host.steady_force
            );
            match check {
                None => writeln!(out, "{line}").map_err(io_error),
                Some(log) => check_demo_log(&log, &host, &line, out),
            }
        }
        Command::Patch {
            params,
            grid,
            spacing,
            indent,
            backend,
            arith,
            rate,
            duration,
        } => {
            let p = paramfile::read(&params)?;
            if arith != ArithArg::Wide && backend != Backend::Fixed {
                return Err(arg_error("--arith", "only with --backend fixed"));
            }
            let mut run = PatchRun::new(grid, spacing, indent, backend, rate, duration)?;
            run.arith = arith;
            let rows = run.reactions(&p, &params)?;
            let mut w = csv::Writer::from_writer(out);
            let err = |e: csv::Error| CliError(format!("stdout: {e}"));
            w.write_record(["time_s", "reaction_n"]).map_err(err)?;
            for (t, r) in rows {
                w.write_record([fmt_strain(t), r.to_string()])
                    .map_err(err)?;
            }
            w.flush().map_err(io_error)
        }
        Command::Table {
            params,
            knots,
            from,
            to,
            out: dest,
        } => {
            let p = paramfile::read(&params)?;
            let header = format!(
                "// Generated by `mccs table --params {} --knots {knots} --from {from:?} --to {to:?}`. Do not edit.\n",
                params.display()
            );
            let src = with_table!(knots, &p, &params, (from, to), |t| render_table(
                &header, &t
            ));
            match dest {
                Some(path) => std::fs::write(&path, src)
                    .map_err(|e| CliError(format!("{}: cannot write: {e}", path.display()))),
                None => out.write_all(src.as_bytes()).map_err(io_error),
            }
        }
    }
}

/// Builds a `ForceTable` with the segment count for `knots` and runs `$body` on it.
macro_rules! with_table {
    ($knots:expr, $p:expr, $file:expr, $domain:expr, |$t:ident| $body:expr) => {{
        let (from, to) = $domain;
        match $knots {
            17 => {
                let $t = table::<16>($p, $file, from, to)?;
                $body
            }
            33 => {
                let $t = table::<32>($p, $file, from, to)?;
                $body
            }
            65 => {
                let $t = table::<64>($p, $file, from, to)?;
                $body
            }
            129 => {
                let $t = table::<128>($p, $file, from, to)?;
                $body
            }
            _ => return Err(arg_error("--knots", "must be 17, 33, 65 or 129")),
        }
    }};
}
use with_table;

fn table<const S: usize>(
    p: &Params,
    file: &Path,
    from: f64,
    to: f64,
) -> Result<ForceTable<S>, CliError> {
    for (name, v) in [("--from", from), ("--to", to)] {
        if !v.is_finite() || v.abs() >= 127.0 {
            return Err(arg_error(name, "must be a finite strain within ±127"));
        }
    }
    if from >= to {
        return Err(arg_error("--to", "must be > --from"));
    }
    let law = mccs::Law::new(p).map_err(|e| file_error(file, e))?;
    ForceTable::<S>::from_law(&law, from, to).map_err(|e| match e {
        TableError::NoNonlinearPhase if to <= law.strain_t() => arg_error(
            "--to",
            &format!(
                "must exceed {:.6}, where this spring's law stops being linear",
                law.strain_t()
            ),
        ),
        TableError::NoNonlinearPhase => arg_error(
            "--from",
            &format!(
                "must be below {:.6}, where this spring's cone is solid",
                law.strain_c()
            ),
        ),
        TableError::TooNarrow => arg_error(
            "--from/--to",
            "the nonlinear phase inside them is too narrow for this many knots",
        ),
        other => CliError(format!("{}: {other}", file.display())),
    })
}

fn file_error(file: &Path, e: mccs::ParamError) -> CliError {
    CliError(format!("{}: {e}", file.display()))
}

fn io_error(e: std::io::Error) -> CliError {
    CliError(format!("stdout: {e}"))
}

/// The strains `from + i·step ≤ to`, validated.
pub fn strain_grid(from: f64, to: f64, step: f64) -> Result<Vec<f64>, CliError> {
    for (name, v) in [("--from", from), ("--to", to), ("--step", step)] {
        if !v.is_finite() {
            return Err(arg_error(name, "must be a finite number"));
        }
    }
    if step <= 0.0 {
        return Err(arg_error("--step", "must be > 0"));
    }
    if to < from {
        return Err(arg_error("--to", "must be >= --from"));
    }
    let count = ((to - from) / step * (1.0 + 1e-12) + 1e-9).floor() + 1.0;
    if count > MAX_ROWS as f64 {
        return Err(arg_error("--step", "too small: more than 10,000,000 rows"));
    }
    // Rounded to 12 decimals, so that the printed strain is the one evaluated.
    Ok((0..count as usize)
        .map(|i| {
            let e = from + i as f64 * step;
            fmt_strain(e).parse().unwrap_or(e)
        })
        .collect())
}

fn fixed_curve<const S: usize>(t: &ForceTable<S>, strains: &[f64]) -> Vec<(f64, f64, f64)> {
    strains
        .iter()
        .map(|&e| {
            let (f, k) = t.force_and_stiffness(Strain::saturating_from_num(e));
            (e, f.to_num::<f64>(), k.to_num::<f64>())
        })
        .collect()
}

fn write_curve(out: &mut dyn Write, rows: &[(f64, f64, f64)]) -> Result<(), CliError> {
    let mut w = csv::Writer::from_writer(out);
    let err = |e: csv::Error| CliError(format!("stdout: {e}"));
    w.write_record(["strain", "force_n", "stiffness_n"])
        .map_err(err)?;
    for (e, f, k) in rows {
        w.write_record([fmt_strain(*e), f.to_string(), k.to_string()])
            .map_err(err)?;
    }
    w.flush().map_err(io_error)
}

/// A grid strain with the float noise of `from + i·step` removed (12 decimals at most).
fn fmt_strain(e: f64) -> String {
    let s = format!("{e:.12}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// Renders a table as a Rust expression for `include!`, preceded by `header`.
pub fn render_table<const S: usize>(header: &str, t: &ForceTable<S>) -> String {
    let r = t.raw();
    let mut s = String::from(header);
    s.push_str("// Formats: strains Q24, forces Q20 N, stiffnesses Q16 N per unit strain.\n");
    s.push_str(&format!(
        "mccs::ForceTable::<{S}>::from_raw(mccs::RawTable {{\n"
    ));
    for (name, v) in [
        ("strain_lo", r.strain_lo as i64),
        ("strain_hi", r.strain_hi as i64),
        ("index_pre", r.index_pre as i64),
        ("index_scale", r.index_scale as i64),
        ("anchor_lo", r.anchor_lo as i64),
        ("force_lo", r.force_lo as i64),
        ("stiffness_lo", r.stiffness_lo as i64),
        ("force_hi", r.force_hi as i64),
        ("stiffness_hi", r.stiffness_hi as i64),
        ("shift", r.shift as i64),
        ("stiff_scale", r.stiff_scale as i64),
        ("stiff_post", r.stiff_post as i64),
    ] {
        s.push_str(&format!("    {name}: {v},\n"));
    }
    s.push_str("    segments: [\n");
    for c in &r.segments {
        s.push_str(&format!(
            "        [{}, {}, {}, {}],\n",
            c[0], c[1], c[2], c[3]
        ));
    }
    s.push_str("    ],\n})\n");
    s
}

/// A validated `mccs patch` run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchRun {
    grid: usize,
    spacing: f64,
    depth: f64,
    backend: Backend,
    /// The fixed backend's spring arithmetic.
    pub arith: ArithArg,
    rate: f64,
    ticks: usize,
}

/// Largest grid per backend.
const MAX_GRID_REFERENCE: usize = 40;
const MAX_GRID_FIXED: usize = 12;
/// Capacities of the fixed backend's solver: N = 12 has 101 node slots and 558 springs.
const FIXED_NODES: usize = 101;
const FIXED_EDGES: usize = 558;

impl PatchRun {
    /// Checks the arguments; each error names its argument.
    pub fn new(
        grid: usize,
        spacing: f64,
        depth: f64,
        backend: Backend,
        rate: f64,
        duration: f64,
    ) -> Result<Self, CliError> {
        let max_grid = match backend {
            Backend::Reference => MAX_GRID_REFERENCE,
            Backend::Fixed => MAX_GRID_FIXED,
        };
        if !(3..=max_grid).contains(&grid) {
            return Err(arg_error(
                "--grid",
                &format!("must be 3 … {max_grid} for this backend"),
            ));
        }
        if !(spacing.is_finite() && spacing > 0.0 && spacing * grid as f64 <= 100.0) {
            return Err(arg_error(
                "--spacing",
                "must be > 0 mm, with grid × spacing ≤ 100 mm",
            ));
        }
        if !(depth.is_finite() && (0.0..=spacing).contains(&depth)) {
            return Err(arg_error("--indent", "must be 0 … spacing mm"));
        }
        if !(rate.is_finite() && (1.0..=100_000.0).contains(&rate) && rate.fract() == 0.0) {
            return Err(arg_error(
                "--rate",
                "must be a whole number of Hz, 1 … 100000",
            ));
        }
        if !(duration.is_finite() && duration > 0.0 && duration <= 60.0) {
            return Err(arg_error("--duration", "must be > 0 and ≤ 60 s"));
        }
        let ticks = (duration * rate).round() as usize;
        if ticks < 2 {
            return Err(arg_error("--duration", "must cover at least 2 ticks"));
        }
        Ok(Self {
            grid,
            spacing,
            depth,
            backend,
            arith: ArithArg::Wide,
            rate,
            ticks,
        })
    }

    /// Depth commanded at tick `i` (0-based): a ramp over the first half, then held.
    fn depth_at(&self, i: usize) -> f64 {
        let ramp = (self.ticks / 2).max(1);
        self.depth * ((i + 1) as f64 / ramp as f64).min(1.0)
    }

    /// `(time_s, reaction_n)` per tick of the fixed-point core in arithmetic `A`.
    fn fixed_reactions<A: mccs::spring::Arith>(
        &self,
        topo: mccs::Topology<FIXED_NODES, FIXED_EDGES>,
        table: mccs::ForceTable64,
        cfg: &mccs::SolverConfig,
        arith: A,
    ) -> Result<Vec<(f64, f64)>, mccs::SolverError> {
        let mut s = mccs::Solver::with_arith(topo, table, cfg, arith)?;
        Ok((0..self.ticks)
            .map(|i| {
                let z = mccs::Length::from_num(-self.depth_at(i));
                let r = s.step_held([mccs::Length::ZERO, mccs::Length::ZERO, z]);
                ((i + 1) as f64 / self.rate, r[2].to_num::<f64>())
            })
            .collect())
    }

    /// `(time_s, reaction_n)` per tick.
    pub fn reactions(&self, p: &Params, file: &Path) -> Result<Vec<(f64, f64)>, CliError> {
        let cfg = mccs::SolverConfig {
            tick_hz: self.rate,
            ..mccs::SolverConfig::default()
        };
        let table = table::<64>(
            p,
            file,
            mccs::table::DEFAULT_DOMAIN.0,
            mccs::table::DEFAULT_DOMAIN.1,
        )?;
        let too_stiff = |e: mccs::SolverError| {
            match e {
            mccs::SolverError::TooManySubsteps { needed } => arg_error(
                "--rate",
                &format!("this spring needs {needed} substeps per tick at this rate (at most 64): lower it"),
            ),
            other => CliError(format!("{}: {other}", file.display())),
        }
        };
        let time = |i: usize| (i + 1) as f64 / self.rate;
        match self.backend {
            Backend::Fixed => {
                let topo = mccs::Topology::<FIXED_NODES, FIXED_EDGES>::standard_patch(
                    self.grid,
                    self.spacing,
                )
                .map_err(|e| arg_error("--grid", &e.to_string()))?;
                match self.arith {
                    ArithArg::Wide => self.fixed_reactions(topo, table, &cfg, mccs::spring::Wide),
                    ArithArg::Narrow => {
                        self.fixed_reactions(topo, table, &cfg, mccs::spring::Narrow)
                    }
                }
                .map_err(too_stiff)
            }
            Backend::Reference => {
                let law = Reference::new(p).map_err(|e| file_error(file, e))?;
                let mesh = crate::patch::Mesh::standard(self.grid, self.spacing);
                let mut tc = crate::patch::TwinConfig::from_solver(&cfg, 0);
                let k_max = reference_max_stiffness(&law);
                let n = crate::patch::substeps(&mesh, k_max, &tc)
                    .ok_or_else(|| too_stiff(mccs::SolverError::NoDamping))?;
                if n > cfg.max_substeps {
                    return Err(too_stiff(mccs::SolverError::TooManySubsteps { needed: n }));
                }
                tc.substeps = n;
                let mut twin = crate::patch::Twin::new(mesh, law, tc);
                Ok((0..self.ticks)
                    .map(|i| (time(i), twin.step_held([0.0, 0.0, -self.depth_at(i)])[2]))
                    .collect())
            }
        }
    }
}

/// The law's largest tangent stiffness over the default strain domain (N per unit strain).
pub fn reference_max_stiffness(law: &Reference) -> f64 {
    let (lo, hi) = mccs::table::DEFAULT_DOMAIN;
    (0..=1000)
        .map(|i| law.stiffness(lo + (hi - lo) * i as f64 / 1000.0))
        .fold(0.0, f64::max)
}

/// A firmware SUMMARY line, parsed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FirmwareSummary {
    /// Ticks run.
    pub ticks: u32,
    /// Ticks over budget.
    pub overruns: u32,
    /// Largest force, N.
    pub max_force: f64,
    /// Steady force, N.
    pub steady_force: f64,
}

/// Parses the last `SUMMARY ticks=… overruns=… max_force_n=… steady_force_n=…` line.
pub fn parse_summary(log: &str) -> Option<FirmwareSummary> {
    let line = log
        .lines()
        .rev()
        .find(|l| l.trim_start().starts_with("SUMMARY "))?;
    let field = |name: &str| -> Option<&str> {
        line.split_whitespace()
            .find_map(|kv| kv.strip_prefix(name).and_then(|v| v.strip_prefix('=')))
    };
    Some(FirmwareSummary {
        ticks: field("ticks")?.parse().ok()?,
        overruns: field("overruns")?.parse().ok()?,
        max_force: field("max_force_n")?.parse().ok()?,
        steady_force: field("steady_force_n")?.parse().ok()?,
    })
}

fn check_demo_log(
    log: &Path,
    host: &mccs::demo::Summary,
    host_line: &str,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    let text = std::fs::read_to_string(log)
        .map_err(|e| CliError(format!("{}: cannot read: {e}", log.display())))?;
    let fw = parse_summary(&text)
        .ok_or_else(|| CliError(format!("{}: no SUMMARY line", log.display())))?;
    let within = |a: f64, b: f64| (a - b).abs() <= 0.01 * b.abs();
    let ok = fw.overruns == 0
        && fw.ticks == host.ticks
        && within(fw.steady_force, host.steady_force as f64)
        && within(fw.max_force, host.max_force as f64);
    writeln!(out, "host:     {host_line}").map_err(io_error)?;
    writeln!(
        out,
        "firmware: SUMMARY ticks={} overruns={} max_force_n={} steady_force_n={}",
        fw.ticks, fw.overruns, fw.max_force, fw.steady_force
    )
    .map_err(io_error)?;
    if ok {
        writeln!(out, "demo check: ok").map_err(io_error)
    } else {
        Err(CliError(format!(
            "{}: SUMMARY does not match the host (needs overruns=0, the same ticks, forces within 1 %)",
            log.display()
        )))
    }
}
