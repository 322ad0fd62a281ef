//! `mccs view`'s server: one page (`assets/`, served from the binary: no network fetch
//! at run time) that follows a device live, on the loopback. The page gets the device's
//! state as server-sent events (`/events`, [`events`]) and sends the controls as POSTs
//! (`/arm`, `/disarm`, `/pose`, `/load`), which only the page holding the controls may
//! send ([`hub`]: the first page; the others watch). The server holds the device's one
//! session (the scene's library, `mccs_client`): a thread forwards its telemetry and
//! meshes as they come, another asks its status twice a second.

pub mod events;
pub mod http;
pub mod hub;

use events::ViewCounts;
use http::{Refused, Request};
use hub::Hub;
use mccs_client::{Device, Pose, Tissue};
use std::io::Write;
use std::net::{TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

const PAGE: &str = include_str!("assets/view.html");
const SCRIPT: &str = include_str!("assets/view.js");

/// How often the status is asked.
pub const STATUS_EVERY: Duration = Duration::from_millis(500);
/// The telemetry the view asks for, a second (held to the device's byte budget).
pub const TELEMETRY_HZ: u32 = 100;
/// The meshes the view asks for, a second (held to the device's byte budget).
pub const MESH_HZ: u32 = 25;

/// A view of one device.
pub struct View {
    device: Device,
    hub: Hub,
    demo: bool,
    stop: AtomicBool,
}

/// Ticks between two samples at `hz` on a device ticking at `tick_hz`, no fewer than
/// `least` (the device's byte budget).
pub fn every(tick_hz: u32, hz: u32, least: u16) -> u16 {
    let e = (tick_hz / hz.max(1)).clamp(1, 1000) as u16;
    e.max(least)
}

impl View {
    /// A view of `device` (`demo`: the host's soft device, said on the page). Asks for
    /// its telemetry and meshes.
    pub fn new(device: Device, demo: bool) -> Result<Arc<View>, mccs_client::Error> {
        let h = device.info().hello;
        device.watch(every(h.tick_hz, TELEMETRY_HZ, h.telemetry_least_every))?;
        device.watch_mesh(every(h.tick_hz, MESH_HZ, h.mesh_least_every))?;
        let view = Arc::new(View {
            device,
            hub: Hub::default(),
            demo,
            stop: AtomicBool::new(false),
        });
        view.publish_hello(view.device.info());
        Ok(view)
    }

    fn publish_hello(&self, info: &mccs_client::Info) {
        let frame = events::hello(info, self.device.addr(), self.demo);
        self.hub.publish_sticky("hello", frame);
    }

    /// Serves pages on `listener` until [`View::stop`], with the device's threads.
    pub fn serve(self: &Arc<View>, listener: TcpListener) -> std::io::Result<()> {
        let v = self.clone();
        std::thread::Builder::new()
            .name("mccs-view-telemetry".into())
            .spawn(move || v.forward_telemetry())?;
        let v = self.clone();
        std::thread::Builder::new()
            .name("mccs-view-status".into())
            .spawn(move || v.poll_status())?;
        listener.set_nonblocking(true)?;
        while !self.stop.load(Ordering::SeqCst) {
            match listener.accept() {
                Ok((stream, _)) => {
                    let v = self.clone();
                    std::thread::Builder::new()
                        .name("mccs-view-page".into())
                        .spawn(move || v.answer(stream))?;
                }
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                    std::thread::sleep(Duration::from_millis(20))
                }
                Err(e) => return Err(e),
            }
        }
        Ok(())
    }

    /// Ends [`View::serve`] and the device's threads.
    pub fn stop(&self) {
        self.stop.store(true, Ordering::SeqCst);
    }

    /// Telemetry as it comes, and each new mesh.
    fn forward_telemetry(&self) {
        let samples = self.device.telemetry_stream();
        let mut mesh_seq = None;
        while !self.stop.load(Ordering::SeqCst) {
            if let Ok(t) = samples.recv_timeout(Duration::from_millis(20)) {
                self.hub.publish(events::telemetry(&t));
                for t in samples.try_iter() {
                    self.hub.publish(events::telemetry(&t));
                }
            }
            if let Some(m) = self.device.mesh() {
                if mesh_seq != Some(m.seq) {
                    mesh_seq = Some(m.seq);
                    self.hub.publish(events::mesh(&m));
                }
            }
        }
    }

    /// The status every [`STATUS_EVERY`]; a failed session as a `device` event.
    fn poll_status(&self) {
        let mut next = Instant::now();
        while !self.stop.load(Ordering::SeqCst) {
            let now = Instant::now();
            if now < next {
                std::thread::sleep((next - now).min(Duration::from_millis(50)));
                continue;
            }
            next = now + STATUS_EVERY;
            match self.device.status() {
                Ok(s) => {
                    let counts = ViewCounts {
                        bad_frames_in: self.device.bad_frames(),
                        stream_drops: self.device.stream_drops(),
                        pages: self.hub.pages(),
                    };
                    self.hub
                        .publish_sticky("status", events::status(&s, counts));
                }
                Err(e) => self
                    .hub
                    .publish_sticky("device", events::device_error(&e.to_string())),
            }
        }
    }

    /// One connection: its request, and its answer (an event stream for `/events`).
    fn answer(&self, mut stream: TcpStream) {
        let _ = stream.set_nonblocking(false);
        let _ = stream.set_read_timeout(Some(Duration::from_secs(5)));
        let req = match http::read_request(&mut stream) {
            Ok(r) => r,
            Err(Refused { status, why }) => {
                let _ = http::respond(&mut stream, status, "text/plain", why.as_bytes());
                return;
            }
        };
        let _ = match (req.method.as_str(), req.path.as_str()) {
            ("GET", "/") => http::respond(
                &mut stream,
                200,
                "text/html; charset=utf-8",
                PAGE.as_bytes(),
            ),
            ("GET", "/view.js") => http::respond(
                &mut stream,
                200,
                "text/javascript; charset=utf-8",
                SCRIPT.as_bytes(),
            ),
            ("GET", "/events") => self.stream_events(&mut stream),
            ("POST", _) => {
                let (status, body) = self.command(&req);
                http::respond(&mut stream, status, "application/json", body.as_bytes())
            }
            ("GET", _) => http::respond(&mut stream, 404, "text/plain", b"not here"),
            _ => http::respond(&mut stream, 405, "text/plain", b"GET or POST"),
        };
    }

    /// A page's events until it goes (a comment every second finds out).
    fn stream_events(&self, stream: &mut TcpStream) -> std::io::Result<()> {
        let joined = self.hub.join();
        let id = joined.id;
        let result = (|| {
            http::begin_events(&mut *stream)?;
            stream.write_all(events::welcome(id, self.hub.holder()).as_bytes())?;
            self.hub.publish(events::control(self.hub.holder()));
            let mut last = Instant::now();
            while !self.stop.load(Ordering::SeqCst) {
                match joined.events.recv_timeout(Duration::from_millis(100)) {
                    Ok(f) => {
                        stream.write_all(f.as_bytes())?;
                        for f in joined.events.try_iter().take(hub::QUEUE) {
                            stream.write_all(f.as_bytes())?;
                        }
                    }
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
                    Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break,
                }
                if last.elapsed() >= Duration::from_secs(1) {
                    last = Instant::now();
                    let dropped = self.hub.dropped(id);
                    write!(stream, "event: page\ndata: {{\"dropped\":{dropped}}}\n\n")?;
                }
            }
            Ok(())
        })();
        self.hub.leave(id);
        self.hub.publish(events::control(self.hub.holder()));
        result
    }

    /// A control: `(HTTP status, JSON {ok, message})`.
    fn command(&self, req: &Request) -> (u16, String) {
        let answer = |status: u16, ok: bool, message: &str| {
            (
                status,
                serde_json::json!({ "ok": ok, "message": message }).to_string(),
            )
        };
        if !req.page.is_some_and(|p| self.hub.holds(p)) {
            return answer(
                403,
                false,
                "another page holds the controls: this one watches",
            );
        }
        let result = match req.path.as_str() {
            "/arm" => self.device.arm_held().map(|s| s.to_string()),
            "/disarm" => self.device.disarm().map(|s| s.to_string()),
            "/pose" => match pose_of(&req.body) {
                Ok(p) => self.device.set_pose(p).map(|s| s.to_string()),
                Err(why) => return answer(400, false, why),
            },
            "/load" => match tissue_of(&req.body) {
                Ok(t) => self.load(&t),
                Err(why) => return answer(400, false, &why),
            },
            _ => return answer(404, false, "no such control"),
        };
        match result {
            Ok(line) => answer(200, true, &line),
            Err(e) => answer(409, false, &e.to_string()),
        }
    }

    /// Loads `t`, then says the device's new facts.
    fn load(&self, t: &Tissue) -> Result<String, mccs_client::Error> {
        let hash = self.device.load_tissue(t)?;
        // Its facts changed (the tissue's size, hash, friction): hello again.
        let info = self.device.hello()?;
        self.publish_hello(&info);
        Ok(format!("ack tissue={hash:08x}"))
    }
}

/// `X,Y,Z,RX,RY,RZ` (mm, degrees) as a pose.
pub fn pose_of(body: &[u8]) -> Result<Pose, &'static str> {
    const WHAT: &str = "a pose is X,Y,Z,RX,RY,RZ: six numbers, mm and degrees";
    let text = std::str::from_utf8(body).map_err(|_| WHAT)?;
    mccs_client::pose_text::pose(text).ok_or(WHAT)
}

/// A parameter file's text (the TOML of docs/model.md) as a tissue; why not, in one
/// line.
pub fn tissue_of(body: &[u8]) -> Result<Tissue, String> {
    let text = std::str::from_utf8(body).map_err(|_| "the file is not UTF-8 text".to_string())?;
    let params = mccs_client::paramfile::parse(text, std::path::Path::new("the file"))
        .map_err(|e| e.to_string())?;
    Tissue::from_params(&params).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pose_is_six_finite_numbers() {
        assert!(pose_of(b"1,2,3,0,0,90").is_ok());
        for bad in [
            &b"1,2,3"[..],
            b"1,2,3,0,0,x",
            b"1,2,3,0,0,NaN",
            b"1,2,3,0,0,inf",
            b"\xff",
        ] {
            assert!(pose_of(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn a_parameter_file_that_breaks_a_rule_is_one_line() {
        let e = tissue_of(b"[mccs]\nnot toml at all =").unwrap_err();
        assert!(!e.contains('\n'), "{e}");
        assert!(tissue_of(b"\xff\xfe").is_err());
    }

    #[test]
    fn the_rates_hold_to_the_budget() {
        assert_eq!(every(1000, 100, 1), 10);
        assert_eq!(every(1000, 100, 17), 17);
        assert_eq!(every(1000, 0, 1), 1000);
        assert_eq!(every(100, 1000, 1), 1);
    }
}
