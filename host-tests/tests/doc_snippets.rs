//! Every Rust snippet in README.md and docs/ compiled and run: each is copied here
//! verbatim inside the code that gives it its context (its variables, a function that
//! returns a `Result` for its `?`), and `every_rust_snippet_in_the_docs_is_here` holds
//! each doc block to a copy in this file, line for line (indentation aside). A snippet
//! edited in a doc and not here, or one that no longer compiles, fails the tests.

use mccs::{Flat, ForceTable64, Params, ProxyConfig, Solver, SolverConfig, Topology, WindowConfig};
use mccs_firmware::{indentation_path, Controller, Roaming, SimulatedDevice};
use std::error::Error;
use std::path::{Path, PathBuf};

/// docs/cli.md, "`table`".
#[test]
#[rustfmt::skip]
fn cli_md_an_included_table() {
    static TABLE2: mccs::ForceTable64 = include!("../../tables/table2.rs");
    assert_eq!(TABLE2.raw(), ForceTable64::new(&Params::TABLE2).unwrap().raw());
}

/// docs/solver.md, its first example.
#[test]
#[rustfmt::skip]
fn solver_md_a_patch_in_five_lines() -> Result<(), Box<dyn Error>> {
    use mccs::{ForceTable64, Length, Params, Solver, SolverConfig, Topology};
    let topo = Topology::<10, 61>::standard_patch(5, 2.5)?;          // N = 5, 2.5 mm
    let table = ForceTable64::new(&Params::TABLE2)?;
    let mut solver = Solver::new(topo, table, &SolverConfig::default())?;
    let force = solver.step([Length::ZERO, Length::ZERO, Length::from_num(-0.5)]); // N per axis
    assert!(force[2] >= mccs::Force::ZERO);
    Ok(())
}

/// docs/firmware.md, "The contact: glued or roaming".
#[test]
#[rustfmt::skip]
fn firmware_md_a_roaming_controller() -> Result<(), Box<dyn Error>> {
    let topo = Topology::<10, 61>::standard_patch(5, 2.5)?;
    let mut solver = Solver::new(topo, ForceTable64::new(&Params::TABLE2)?, &SolverConfig::default())?;
    let device = SimulatedDevice::new(indentation_path(1000).map_err(|e| e.to_string())?);
    let (x0, y0) = (0.0, 0.0);
    let proxy = solver.proxy(&ProxyConfig { grid: 5, spacing: 2.5, mu_s: 0.6, mu_k: 0.4, probe_radius: 0.0 })?;
    let window = solver.window(&WindowConfig { tissue_w: 64, tissue_h: 64, hysteresis: 0.1 }, &Flat, &proxy, x0, y0)?;
    let ctl = Controller::with_contact(solver, Roaming::new(proxy, window), device, u32::MAX);
    let mut ctl = ctl;
    for _ in 0..10 {
        ctl.tick(None);
    }
    Ok(())
}

/// docs/link.md, "A scene in Rust", against the device in software.
#[test]
#[rustfmt::skip]
fn link_md_a_scene() -> Result<(), Box<dyn Error>> {
    let socket = std::env::temp_dir().join(format!("mccs-doc-scene-{}.sock", std::process::id()));
    let _device = mccs_host::link::soft::serve(&socket, ForceTable64::new(&Params::TABLE2)?)?;
    let addr = &format!("unix:{}", socket.display());
use mccs_client::{Device, Pose, Tissue};
use std::time::{Duration, Instant};
let device = Device::open(addr)?;                       // hello, with retries
println!("{}", device.info());                          // what it is, its limits
device.load_tissue(&Tissue::from_params(&mccs::Params::TABLE2)?.with_friction(0.6, 0.4)?)?;
device.watch(16)?;                                      // about 60 Hz at 1 kHz
let armed = device.arm()?;                              // kept alive by the library
let start = Instant::now();
while start.elapsed() < Duration::from_secs(1) {
    let breath = 2.0 * (start.elapsed().as_secs_f64() * 1.5).sin(); // mm
    device.set_pose(Pose::from_mm_deg([0.0, 0.0, breath], [0.0; 3]))?;
    if let Some(t) = device.telemetry() {
        println!("tick {} force {:.3} N", t.tick, t.force_n[2]);
    }
    std::thread::sleep(Duration::from_millis(16));
}
armed.disarm()?;                                        // or drop it
    Ok(())
}

/// README.md and every page under docs/.
pub fn doc_pages() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut pages = vec![root.join("README.md")];
    let mut dirs = vec![root.join("docs")];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "md") {
                pages.push(path);
            }
        }
    }
    pages.sort();
    pages
}

/// The fenced blocks of `text` whose info string is `lang`, as trimmed lines.
fn blocks(text: &str, lang: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let mut current: Option<Vec<String>> = None;
    for line in text.lines() {
        let t = line.trim();
        match &mut current {
            Some(block) if t.starts_with("```") => {
                out.push(std::mem::take(block));
                current = None;
            }
            Some(block) => block.push(t.to_string()),
            None if t == format!("```{lang}") => current = Some(Vec::new()),
            None => {}
        }
    }
    out
}

#[test]
fn every_rust_snippet_in_the_docs_is_here() {
    let here: Vec<String> = include_str!("doc_snippets.rs")
        .lines()
        .map(|l| l.trim().to_string())
        .collect();
    let mut seen = 0;
    for page in doc_pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for block in blocks(&text, "rust") {
            seen += 1;
            let found = here.windows(block.len()).any(|w| w == block.as_slice());
            assert!(
                found,
                "{}: this Rust snippet is not compiled by host-tests/tests/doc_snippets.rs \
                 (copy it there, verbatim, in code that runs it):\n{}",
                page.display(),
                block.join("\n")
            );
        }
    }
    assert!(seen >= 3, "{seen} Rust snippets found: the scan is broken");
}
