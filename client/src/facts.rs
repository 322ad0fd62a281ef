//! [`Info`] and [`Status`]: what a device says of itself (its hello) and its counters,
//! in units, each with the one line `mccs link hello` and `mccs link status` print.

use mccs_link::{scale, HelloInfo, StatusInfo};
use std::fmt;

/// What a device says of itself (its hello).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Info {
    /// The hello, as the device sent it.
    pub hello: HelloInfo,
}

impl Info {
    /// The live tissue's friction `(mu_s, mu_k)`.
    pub fn friction(&self) -> (f64, f64) {
        self.hello.friction.values()
    }

    /// The largest force it renders on any axis, N.
    pub fn force_clamp_n(&self) -> f64 {
        scale::newtons(self.hello.force_clamp)
    }

    /// Where a pose's origin may be, mm: the low corner, then the high one.
    pub fn workspace_mm(&self) -> [[f64; 3]; 2] {
        self.hello.workspace.map(|c| c.map(scale::mm))
    }

    /// The patch's spacing, mm.
    pub fn spacing_mm(&self) -> f64 {
        scale::mm(self.hello.spacing)
    }
}

impl fmt::Display for Info {
    /// One line: `protocol=… schema=… device=… …` (`mccs link hello` prints it).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let h = &self.hello;
        let [lo, hi] = self.workspace_mm();
        let (mu_s, mu_k) = self.friction();
        write!(
            f,
            "protocol={} schema={:08x} device={} simulated={} core={} tick_hz={} contact={} grid={} tissue={}x{} spacing_mm={} knots={} tissue_hash={:08x} friction={},{} substeps={} force_clamp_n={} workspace_mm={},{},{}..{},{},{} pose_limits={}mm/s,{}deg/s baud={} telemetry_every>={} mesh_every>={} tick_budget={} substep_cost={} tick_base_cost={}",
            h.protocol,
            h.schema,
            h.device.name(),
            h.simulated as u8,
            h.core.name(),
            h.tick_hz,
            h.contact.name(),
            h.grid,
            h.tissue_w,
            h.tissue_h,
            self.spacing_mm(),
            h.knots,
            h.tissue,
            short(mu_s),
            short(mu_k),
            h.substeps,
            self.force_clamp_n(),
            lo[0],
            lo[1],
            lo[2],
            hi[0],
            hi[1],
            hi[2],
            h.pose_speed_mm_s,
            h.pose_turn_deg_s,
            h.baud,
            h.telemetry_least_every,
            h.mesh_least_every,
            h.tick_budget,
            h.substep_cost,
            h.tick_base_cost
        )
    }
}

/// `x` to 4 decimals, trailing zeros dropped (a Q16 coefficient as it was given).
fn short(x: f64) -> String {
    let s = format!("{x:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s.is_empty() || s == "-" {
        "0".into()
    } else {
        s.into()
    }
}

/// The device's counters and state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Status {
    /// As the device sent them.
    pub raw: StatusInfo,
}

impl Status {
    /// The pose's origin the host last set, mm.
    pub fn pose_origin_mm(&self) -> [f64; 3] {
        self.raw.pose.origin_mm()
    }
}

impl fmt::Display for Status {
    /// One line: `ticks=… overruns=… …` (`mccs link status` prints it).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = &self.raw;
        let o = self.pose_origin_mm();
        let a = s.pose.angles_deg();
        write!(
            f,
            "ticks={} overruns={} bad_frames={} dropped_telemetry={} dropped_mesh={} rx_dropped={} armed={} fault={} replaying={} checking={} gain={} pose={},{},{} rotation_deg={:.3},{:.3},{:.3}",
            s.ticks,
            s.overruns,
            s.bad_frames,
            s.dropped_telemetry,
            s.dropped_mesh,
            s.rx_dropped,
            s.armed as u8,
            s.fault.name(),
            s.replaying as u8,
            s.checking as u8,
            scale::gain(s.gain),
            o[0],
            o[1],
            o[2],
            a[0],
            a[1],
            a[2]
        )
    }
}
