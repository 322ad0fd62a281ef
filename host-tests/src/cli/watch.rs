//! What a simulated run says about itself on stderr (`patch`, `replay`): one line before
//! the first row with what it simulates (the geometry and the solver), and after the
//! last row one counted warning line for each way the probe left what the model
//! represents. stdout stays the CSV.

use super::patch_args::PatchArgs;
use crate::replay::Engine;
use crate::roam::{Shape, Tissue};
use mccs::SolverConfig;
use mccs_client::shown::ShownNumber;

/// The line a run prints before its first row: `mccs <command>: <what it simulates>`.
pub fn setup_line(
    command: &str,
    patch: &PatchArgs,
    tissue: Option<&Tissue>,
    cfg: &SolverConfig,
    substeps: u32,
    coupled: bool,
) -> String {
    let s = patch.spacing;
    let n = patch.grid;
    let side = (n - 1) as f64 * s;
    let patch_part = format!(
        "{n} × {n} nodes ({} × {} mm, {} mm deep)",
        mm(side),
        mm(side),
        mm(s)
    );
    let geometry = match tissue {
        Some(t) => {
            let shape = match t.shape {
                Shape::Flat => "flat".to_string(),
                Shape::Cap { radius } => format!("a cap of radius {} mm", mm(radius)),
            };
            format!(
                "tissue {} × {} nodes at {} mm ({} × {} mm, {shape}), window {patch_part}",
                t.w,
                t.h,
                mm(s),
                mm((t.w - 1) as f64 * s),
                mm((t.h - 1) as f64 * s),
            )
        }
        None => format!("patch {patch_part} at {} mm", mm(s)),
    };
    let engine = match patch.engine() {
        Engine::Reference => "the f64 twin",
        Engine::Wide => "the fixed-point core (wide)",
        Engine::Narrow => "the fixed-point core (narrow, the M0's)",
    };
    let c = &cfg.coupling;
    let probe = if coupled {
        format!(
            "coupling {} N/mm and {} N·s/m, force clamp {} N",
            c.stiffness, c.damping, c.max_force
        )
    } else {
        "the contact node held at the indentation (no coupling)".to_string()
    };
    format!(
        "mccs {command}: {geometry}; {engine}, {} Hz × {substeps} substeps, node mass {} g, spring damping {} N·s/m; {probe}",
        cfg.tick_hz,
        // (The one figure here without an upper limit: `--node-mass 1e300`.)
        ShownNumber(cfg.node_mass * 1000.0),
        cfg.spring_damping,
    )
}

/// A length for a message: at most 3 decimals, no trailing zeros.
fn mm(x: f64) -> String {
    let s = format!("{x:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Ticks on which one thing happened, and the first one's time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Count {
    ticks: u64,
    first: Option<f64>,
}

impl Count {
    fn see(&mut self, happened: bool, time: f64) {
        if happened {
            self.ticks += 1;
            self.first.get_or_insert(time);
        }
    }
}

/// Watches a run's ticks for where the probe leaves what the model represents.
#[derive(Clone, Debug, PartialEq)]
pub struct Watch {
    command: &'static str,
    depth: f64,
    tissue: Option<Tissue>,
    /// Half the sides the probe stays within, mm: the tissue's, or the glued patch's.
    half: (f64, f64),
    clamp: f64,
    below: Count,
    off: Count,
    clamped: Count,
}

impl Watch {
    /// For the standard patch of `grid` nodes a side at `spacing` mm (its depth), on
    /// `tissue` when roaming, with the force clamp `clamp` N.
    pub fn new(
        command: &'static str,
        grid: usize,
        spacing: f64,
        tissue: Option<Tissue>,
        clamp: f64,
    ) -> Self {
        let half = match &tissue {
            Some(t) => t.half_extent(),
            None => {
                let h = (grid - 1) as f64 * spacing / 2.0;
                (h, h)
            }
        };
        Self {
            command,
            depth: spacing,
            tissue,
            half,
            clamp,
            below: Count::default(),
            off: Count::default(),
            clamped: Count::default(),
        }
    }

    /// One tick: the probe at `probe` (mm; the tissue's frame when roaming) and the
    /// device force `force` (N).
    pub fn see(&mut self, time: f64, probe: [f64; 3], force: [f64; 3]) {
        let [x, y, z] = probe;
        let surface = self.tissue.map_or(0.0, |t| {
            let (u, v) = t.project(probe);
            t.height(u, v)
        });
        self.below.see(z < surface - self.depth, time);
        // Off the side only counts while pressing: above the surface there is no force.
        let (hx, hy) = self.half;
        self.off
            .see(z < surface && (x.abs() > hx || y.abs() > hy), time);
        // The clamp holds each axis (glued) or the magnitude (roaming): either at it, to
        // the fixed point's resolution.
        let at = self.clamp * (1.0 - 1e-4);
        let magnitude = (force[0] * force[0] + force[1] * force[1] + force[2] * force[2]).sqrt();
        self.clamped
            .see(magnitude >= at || force.iter().any(|f| f.abs() >= at), time);
    }

    /// One line for each thing that happened, with its count and first time.
    pub fn warnings(&self) -> Vec<String> {
        let mut lines = Vec::new();
        let mut say = |c: &Count, what: String, meaning: &str| {
            if let Some(t) = c.first {
                lines.push(format!(
                    "mccs {}: warning: {what} on {} ticks, first at t = {} s: {meaning}",
                    self.command,
                    c.ticks,
                    fmt_s(t)
                ));
            }
        };
        say(
            &self.below,
            format!(
                "the probe was below the patch's depth ({} mm under the rest surface, where its base is fixed)",
                mm(self.depth)
            ),
            "the model does not represent a press that deep (a deeper patch: a larger --spacing)",
        );
        let (hx, hy) = self.half;
        let (edge, meaning) = match self.tissue {
            Some(_) => (
                "the tissue's edge",
                "the window stops at the edge and the proxy stays on the tissue, pulling the probe back (a larger --tissue)",
            ),
            None => (
                "the patch's side",
                "the contact node is glued to the probe and stretches the patch (--tissue roams a larger tissue)",
            ),
        };
        say(
            &self.off,
            format!(
                "the probe pressed off {edge} (x within ±{} mm, y within ±{} mm)",
                mm(hx),
                mm(hy)
            ),
            meaning,
        );
        say(
            &self.clamped,
            format!("the force was at the clamp ({} N)", self.clamp),
            "the device renders no more than that (--max-force, if it can)",
        );
        lines
    }
}

/// A time for a message, to the millisecond's fraction without float noise.
fn fmt_s(t: f64) -> String {
    let s = format!("{t:.6}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
