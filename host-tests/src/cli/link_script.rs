//! `mccs link script FILE`: a scene in a file, run on one session (docs/link.md,
//! "Scripts"). One step a line, `#` to the end of a line a comment:
//!
//! | step | what it does | what it prints |
//! |---|---|---|
//! | `hello` | asks the device what it is | `# ` and the hello line |
//! | `status` | asks its counters | `# ` and the status line |
//! | `load FILE [friction=MUS,MUK]` | a tissue from a parameter `.toml` or a table `.bin` | `# ack tissue=…` |
//! | `pose X,Y,Z[,RX,RY,RZ]` | places the tissue (mm; degrees, `Rz Ry Rx`) | `# pose origin=… rotation=…` |
//! | `arm`, `disarm` | holds the device armed (across steps) or releases it | `# ` and the status line |
//! | `telemetry on [every=N]`, `telemetry off` | streams telemetry | `# telemetry every=N` |
//! | `mesh on [every=N]`, `mesh off` | streams meshes | `# mesh every=N`, then `# mesh seq=… tick=… nodes=…` for each |
//! | `wait SECONDS` | waits (0 … 3600 s), the streams flowing | `# waited S` |
//!
//! The telemetry rows received while telemetry is on are one CSV (`t_s`, seconds since
//! the script started, then `mccs link watch`'s columns), its header printed once; rows
//! keep coming while any step runs (a load does not pause the stream). The file is read
//! and checked whole before the device is reached: a bad line is exit 2 with its line
//! number; a refusal at run time is exit 2 with the step's line number, after a disarm.

use super::link::{device_error, pose_line, telemetry_row, with_friction, TELEMETRY_COLUMNS};
use super::{io_error, CliError};
use mccs_client::pose_text::{self, numbers};
use mccs_client::shown::Shown;
use mccs_client::shown::ShownPath;
use mccs_client::{Device, Pose, Tissue};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// One step.
#[derive(Debug)]
enum Step {
    Hello,
    Status,
    Load(Tissue),
    Pose(Pose),
    Arm,
    Disarm,
    Telemetry(u16),
    Mesh(u16),
    Wait(f64),
}

/// A script, checked.
pub(crate) struct Script {
    file: PathBuf,
    steps: Vec<(usize, Step)>,
}

/// `FILE:LINE: what`.
fn at(file: &Path, line: usize, what: impl std::fmt::Display) -> CliError {
    CliError::new(format!("{}:{line}: {what}", ShownPath(file)))
}

/// `every=N` (1 … 1000), or `default`.
fn every(words: &[&str], default: u16) -> Result<u16, String> {
    match words {
        [] => Ok(default),
        [w] => w
            .strip_prefix("every=")
            .and_then(|n| n.parse::<u16>().ok())
            .filter(|n| (1..=1000).contains(n))
            .ok_or_else(|| format!("'{}': expected every=N, N of 1 … 1000 ticks", Shown(w))),
        _ => Err("expected at most every=N".into()),
    }
}

/// What a script's `load FILE` reads: the tissue at a path (resolved as the step says),
/// or why not in one line.
pub(crate) type Loader<'a> = &'a dyn Fn(&Path) -> Result<Tissue, String>;

impl Script {
    /// Reads and checks `file`: every step, its arguments and its files.
    pub(super) fn read(file: &Path) -> Result<Script, CliError> {
        let text = mccs_client::input::read_text(file, mccs_client::input::CONFIG_BYTES)
            .map_err(|e| CliError::new(format!("{}: cannot read: {e}", ShownPath(file))))?;
        Self::parse(&text, file, &|path| {
            Tissue::from_file(path).map_err(|e| e.to_string())
        })
    }

    /// Checks `text`, the script `file`: every step and its arguments, each `load`'s
    /// tissue through `load`.
    pub(crate) fn parse(text: &str, file: &Path, load: Loader) -> Result<Script, CliError> {
        let mut steps = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let n = i + 1;
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let words: Vec<&str> = line.split_whitespace().collect();
            let step = Self::step(file, &words, load).map_err(|why| at(file, n, why))?;
            steps.push((n, step));
        }
        Ok(Script {
            file: file.to_path_buf(),
            steps,
        })
    }

    /// The steps, each as its line number and its name.
    pub(crate) fn step_names(&self) -> impl Iterator<Item = (usize, &'static str)> + '_ {
        self.steps.iter().map(|(n, s)| {
            let name = match s {
                Step::Hello => "hello",
                Step::Status => "status",
                Step::Load(_) => "load",
                Step::Pose(_) => "pose",
                Step::Arm => "arm",
                Step::Disarm => "disarm",
                Step::Telemetry(_) => "telemetry",
                Step::Mesh(_) => "mesh",
                Step::Wait(_) => "wait",
            };
            (*n, name)
        })
    }

    fn step(file: &Path, words: &[&str], load: Loader) -> Result<Step, String> {
        let rest = &words[1..];
        let none = |s: Step| {
            if rest.is_empty() {
                Ok(s)
            } else {
                Err(format!("'{}' takes no argument", Shown(words[0])))
            }
        };
        match words[0] {
            "hello" => none(Step::Hello),
            "status" => none(Step::Status),
            "arm" => none(Step::Arm),
            "disarm" => none(Step::Disarm),
            "load" => {
                let [name, opts @ ..] = rest else {
                    return Err("load FILE [friction=MUS,MUK]".into());
                };
                let path = file.parent().unwrap_or(Path::new("")).join(name);
                let path = if Path::new(name).is_absolute() || !path.exists() {
                    PathBuf::from(name)
                } else {
                    path
                };
                let friction = match opts {
                    [] => None,
                    [f] => Some(
                        f.strip_prefix("friction=")
                            .ok_or_else(|| format!("'{}': expected friction=MUS,MUK", Shown(f)))?,
                    ),
                    _ => return Err("load FILE [friction=MUS,MUK]".into()),
                };
                let tissue = load(&path)?;
                with_friction(tissue, friction, "friction")
                    .map(Step::Load)
                    .map_err(|e| e.message)
            }
            "pose" => {
                let pose = match rest {
                    [p] => pose_text::pose(p)
                        .or_else(|| numbers::<3>(p).map(|o| Pose::from_mm_deg(o, [0.0; 3]))),
                    _ => None,
                };
                let what = "pose X,Y,Z[,RX,RY,RZ]: three or six numbers (mm, degrees)";
                Ok(Step::Pose(pose.ok_or(what)?))
            }
            "telemetry" | "mesh" => {
                let on = match rest.first().copied() {
                    Some("on") => every(&rest[1..], if words[0] == "mesh" { 17 } else { 10 })?,
                    Some("off") if rest.len() == 1 => 0,
                    _ => return Err(format!("{0} on [every=N] | {0} off", words[0])),
                };
                Ok(if words[0] == "mesh" {
                    Step::Mesh(on)
                } else {
                    Step::Telemetry(on)
                })
            }
            "wait" => match rest {
                [s] => s
                    .parse::<f64>()
                    .ok()
                    .filter(|s| s.is_finite() && (0.0..=3600.0).contains(s))
                    .map(Step::Wait)
                    .ok_or_else(|| "wait SECONDS: 0 … 3600".into()),
                _ => Err("wait SECONDS: 0 … 3600".into()),
            },
            other => Err(format!(
                "unknown step '{}' (hello, status, load, pose, arm, disarm, telemetry, mesh, wait)",
                Shown(other)
            )),
        }
    }

    /// Runs the steps on `device`, writing to `out`; the telemetry rows from a thread of
    /// their own meanwhile.
    pub(super) fn run(&self, device: &Device, out: &mut dyn Write) -> Result<(), CliError> {
        let start = device.elapsed();
        let lines: Arc<Mutex<Vec<String>>> = Arc::new(Mutex::new(Vec::new()));
        let done = Arc::new(AtomicBool::new(false));
        let rows = device.telemetry_stream();
        let (l, d) = (lines.clone(), done.clone());
        // The rows go to a buffer the main thread flushes: `out` is not `Send`.
        let printer = std::thread::spawn(move || {
            let mut header = false;
            while !d.load(Ordering::SeqCst) {
                if let Ok(t) = rows.recv_timeout(Duration::from_millis(20)) {
                    let t_s = t.received.saturating_sub(start).as_secs_f64();
                    let mut l = l.lock().unwrap_or_else(|e| e.into_inner());
                    if !header {
                        l.push(format!("t_s,{TELEMETRY_COLUMNS}"));
                        header = true;
                    }
                    l.push(format!("{t_s:.4},{}", telemetry_row(&t)));
                }
            }
        });
        let result = self.steps(device, out, &lines);
        done.store(true, Ordering::SeqCst);
        let _ = printer.join();
        flush(out, &lines)?;
        if result.is_err() && device.armed() {
            let _ = device.disarm();
        }
        result
    }

    fn steps(
        &self,
        device: &Device,
        out: &mut dyn Write,
        lines: &Mutex<Vec<String>>,
    ) -> Result<(), CliError> {
        let mut mesh_on = false;
        let mut last_mesh = None;
        for (n, step) in &self.steps {
            let fail = |e: mccs_client::Error| at(&self.file, *n, device_error(e));
            let say = |text: String| {
                lines
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push(format!("# {text}"))
            };
            match step {
                Step::Hello => say(device.hello().map_err(fail)?.to_string()),
                Step::Status => say(device.status().map_err(fail)?.to_string()),
                Step::Arm => say(device.arm_held().map_err(fail)?.to_string()),
                Step::Disarm => say(device.disarm().map_err(fail)?.to_string()),
                Step::Load(t) => say(format!(
                    "ack tissue={:08x}",
                    device.load_tissue(t).map_err(fail)?
                )),
                Step::Pose(p) => {
                    device.set_pose(*p).map_err(fail)?;
                    say(pose_line(p));
                }
                Step::Telemetry(every) => {
                    device.watch(*every).map_err(fail)?;
                    let least = device.info().hello.telemetry_least_every;
                    say(format!(
                        "telemetry every={}",
                        if *every == 0 { 0 } else { (*every).max(least) }
                    ));
                }
                Step::Mesh(every) => {
                    device.watch_mesh(*every).map_err(fail)?;
                    mesh_on = *every != 0;
                    let least = device.info().hello.mesh_least_every;
                    say(format!(
                        "mesh every={}",
                        if *every == 0 { 0 } else { (*every).max(least) }
                    ));
                }
                Step::Wait(s) => {
                    let end = Instant::now() + Duration::from_secs_f64(*s);
                    while Instant::now() < end {
                        std::thread::sleep(Duration::from_millis(20));
                        if mesh_on {
                            if let Some(m) = device.mesh().filter(|m| Some(m.seq) != last_mesh) {
                                last_mesh = Some(m.seq);
                                say(format!(
                                    "mesh seq={} tick={} nodes={}",
                                    m.seq,
                                    m.tick,
                                    m.nodes.len()
                                ));
                            }
                        }
                        flush(out, lines)?;
                    }
                    say(format!("waited {s}"));
                }
            }
            flush(out, lines)?;
        }
        Ok(())
    }
}

/// Writes the lines gathered so far.
fn flush(out: &mut dyn Write, lines: &Mutex<Vec<String>>) -> Result<(), CliError> {
    let taken = std::mem::take(&mut *lines.lock().unwrap_or_else(|e| e.into_inner()));
    for l in taken {
        writeln!(out, "{l}").map_err(io_error)?;
    }
    out.flush().map_err(io_error)
}
