//! The host's end of the link (docs/link.md): a connection to a device over a unix
//! socket, TCP or a serial port ([`Link`]), and a device in software ([`soft`]) that runs
//! the firmware's own session and replayer, for tests without QEMU.

pub mod soft;

use mccs_link::frame::parse;
use mccs_link::{encode, Decoder, ToDevice, ToHost, MAX_FRAME};
use std::collections::VecDeque;
use std::io::{Read, Write};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Where a device is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Addr {
    /// `unix:PATH`.
    Unix(PathBuf),
    /// `tcp:HOST:PORT`.
    Tcp(String),
    /// A serial port's path (`/dev/ttyUSB0`, `COM3`).
    Serial(String),
}

impl Addr {
    /// `unix:PATH`, `tcp:HOST:PORT`, or a serial port.
    pub fn parse(text: &str) -> Result<Addr, String> {
        if let Some(p) = text.strip_prefix("unix:") {
            if p.is_empty() {
                return Err("unix: needs a socket path (unix:/tmp/mccs.sock)".into());
            }
            return Ok(Addr::Unix(p.into()));
        }
        if let Some(hp) = text.strip_prefix("tcp:") {
            if !hp
                .rsplit_once(':')
                .is_some_and(|(h, p)| !h.is_empty() && p.parse::<u16>().is_ok())
            {
                return Err("tcp: needs HOST:PORT (tcp:localhost:5555)".into());
            }
            return Ok(Addr::Tcp(hp.into()));
        }
        if text.is_empty() || text.contains(':') && !text.starts_with("COM") {
            return Err("must be unix:PATH, tcp:HOST:PORT or a serial port's path".into());
        }
        Ok(Addr::Serial(text.into()))
    }
}

/// A connection to a device.
pub struct Link {
    stream: Box<dyn StreamBox>,
    decoder: Decoder,
    pending: VecDeque<ToHost>,
    /// Frames from the device the host dropped (bad CRC, COBS, message).
    pub bad_frames: u32,
}

/// How long a read waits before the caller checks its own deadline.
const POLL: Duration = Duration::from_millis(20);

impl Link {
    /// Connects to `addr`.
    pub fn connect(addr: &Addr) -> std::io::Result<Link> {
        let stream: Box<dyn StreamBox> = match addr {
            Addr::Unix(p) => {
                let s = std::os::unix::net::UnixStream::connect(p)?;
                s.set_read_timeout(Some(POLL))?;
                Box::new(s)
            }
            Addr::Tcp(hp) => {
                let s = std::net::TcpStream::connect(hp)?;
                s.set_read_timeout(Some(POLL))?;
                s.set_nodelay(true)?;
                Box::new(s)
            }
            Addr::Serial(path) => Box::new(
                serialport::new(path, 115_200)
                    .timeout(POLL)
                    .open()
                    .map_err(std::io::Error::other)?,
            ),
        };
        Ok(Link::over(stream))
    }

    /// Over any byte stream whose reads time out (for tests).
    pub fn over(stream: Box<dyn StreamBox>) -> Link {
        Link {
            stream,
            decoder: Decoder::new(),
            pending: VecDeque::new(),
            bad_frames: 0,
        }
    }

    /// Sends one message.
    pub fn send(&mut self, msg: &ToDevice) -> std::io::Result<()> {
        let mut buf = [0u8; MAX_FRAME];
        let frame = encode(msg, &mut buf).map_err(|e| std::io::Error::other(e.message()))?;
        self.stream.write_all(frame)?;
        self.stream.flush()
    }

    /// The next message from the device, or `None` at `deadline`.
    pub fn recv(&mut self, deadline: Instant) -> std::io::Result<Option<ToHost>> {
        let mut buf = [0u8; 512];
        loop {
            if let Some(m) = self.pending.pop_front() {
                return Ok(Some(m));
            }
            if Instant::now() >= deadline {
                return Ok(None);
            }
            let n = match self.stream.read(&mut buf) {
                Ok(0) => {
                    return Err(std::io::Error::new(
                        std::io::ErrorKind::UnexpectedEof,
                        "the device closed the link",
                    ))
                }
                Ok(n) => n,
                Err(e)
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                    ) =>
                {
                    continue
                }
                Err(e) => return Err(e),
            };
            for &b in &buf[..n] {
                match self.decoder.push(b) {
                    Some(Ok(payload)) => match parse::<ToHost>(payload) {
                        Ok(m) => self.pending.push_back(m),
                        Err(_) => self.bad_frames += 1,
                    },
                    Some(Err(_)) => self.bad_frames += 1,
                    None => {}
                }
            }
        }
    }

    /// Raw bytes to the device (the tests' corrupted frames).
    pub fn send_raw(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.stream.write_all(bytes)?;
        self.stream.flush()
    }
}

/// A byte stream for [`Link::over`].
pub trait StreamBox: Read + Write + Send {}
impl<T: Read + Write + Send> StreamBox for T {}
