//! The events a page gets, as server-sent events with JSON data: `welcome` (its id and
//! who holds the controls), `control` (the holder changed), `hello` (the device's
//! facts), `t` (a telemetry sample), `mesh` (the live patch and its triangles),
//! `status` (the device's counters, and this view's own drops) and `device` (the
//! session failed: the device is gone or silent). Units as the client's: mm, N, s.

use super::hub::Frame;
use mccs_client::{Flags, Info, Mesh, Status, TelemetrySample};
use serde_json::{json, Value};

/// One event: `event: KIND`, its data on one line, and the blank line.
pub fn frame(kind: &str, data: &Value) -> Frame {
    format!("event: {kind}\ndata: {data}\n\n").into()
}

/// `welcome`: the page's id, and which page holds the controls.
pub fn welcome(id: u64, holder: Option<u64>) -> Frame {
    frame("welcome", &json!({ "id": id, "holder": holder }))
}

/// `control`: the page that holds the controls now.
pub fn control(holder: Option<u64>) -> Frame {
    frame("control", &json!({ "holder": holder }))
}

/// `hello`: the device's facts (`line`: as `mccs link hello` prints them).
pub fn hello(info: &Info, addr: &str, demo: bool) -> Frame {
    let h = &info.hello;
    let flags: Vec<&str> = Flags::ALL.iter().map(|(_, name)| *name).collect();
    let (mu_s, mu_k) = info.friction();
    frame(
        "hello",
        &json!({
            "line": info.to_string(),
            "addr": addr,
            "demo": demo,
            "device": h.device.name(),
            "simulated": h.simulated,
            "contact": h.contact.name(),
            "tick_hz": h.tick_hz,
            "grid": h.grid,
            "tissue": [h.tissue_w, h.tissue_h],
            "spacing_mm": info.spacing_mm(),
            "friction": [mu_s, mu_k],
            "force_clamp_n": info.force_clamp_n(),
            "workspace_mm": info.workspace_mm(),
            "flags": flags,
        }),
    )
}

/// `t`: a telemetry sample (`time_s`: when it arrived, since the session opened).
pub fn telemetry(t: &TelemetrySample) -> Frame {
    frame(
        "t",
        &json!({
            "seq": t.seq,
            "tick": t.tick,
            "time_s": t.received.as_secs_f64(),
            "probe": t.probe_mm,
            "force": t.force_n,
            "gain": t.gain,
            "flags": t.flags.0,
            "fault": t.fault.name(),
            "proxy": t.proxy_mm,
            "window": t.window_mm,
            "dropped": t.dropped,
        }),
    )
}

/// `mesh`: the free nodes `[i, j, x, y, z]` and the triangles between them.
pub fn mesh(m: &Mesh) -> Frame {
    let nodes: Vec<[f64; 5]> = m
        .nodes
        .iter()
        .map(|n| {
            let [x, y, z] = n.position_mm;
            [n.grid[0] as f64, n.grid[1] as f64, x, y, z]
        })
        .collect();
    frame(
        "mesh",
        &json!({
            "seq": m.seq,
            "tick": m.tick,
            "origin": m.origin_mm,
            "nodes": nodes,
            "triangles": m.triangles(),
        }),
    )
}

/// What this view counts of the link beside the device's status.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ViewCounts {
    /// Frames from the device the session dropped (bad CRC, COBS or message).
    pub bad_frames_in: u32,
    /// Telemetry the session's stream dropped (this view fell behind).
    pub stream_drops: u32,
    /// Pages watching.
    pub pages: usize,
}

/// `status`: the device's counters (`line`: as `mccs link status` prints them), and
/// this view's.
pub fn status(s: &Status, v: ViewCounts) -> Frame {
    let r = &s.raw;
    frame(
        "status",
        &json!({
            "line": s.to_string(),
            "ticks": r.ticks,
            "overruns": r.overruns,
            "bad_frames": r.bad_frames,
            "dropped_telemetry": r.dropped_telemetry,
            "dropped_mesh": r.dropped_mesh,
            "rx_dropped": r.rx_dropped,
            "armed": r.armed,
            "fault": r.fault.name(),
            "checking": r.checking,
            "gain": mccs_link::scale::gain(r.gain),
            "pose": s.pose_origin_mm(),
            "rotation_deg": r.pose.angles_deg(),
            "bad_frames_in": v.bad_frames_in,
            "stream_drops": v.stream_drops,
            "pages": v.pages,
        }),
    )
}

/// `device`: the session failed, in one line.
pub fn device_error(message: &str) -> Frame {
    frame("device", &json!({ "error": message }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_event_is_one_data_line_of_json() {
        let f = frame("x", &json!({ "line": "a\nb" }));
        assert_eq!(&*f, "event: x\ndata: {\"line\":\"a\\nb\"}\n\n");
    }
}
