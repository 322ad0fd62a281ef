//! [`Addr`]: where a device is — `unix:PATH` (Unix only), `tcp:HOST:PORT`, or a serial
//! port's path (`/dev/ttyUSB0`, `COM3`).

use std::fmt;

/// Where a device is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Addr {
    /// `unix:PATH`: a unix socket (QEMU's link; Unix only).
    Unix(std::path::PathBuf),
    /// `tcp:HOST:PORT`.
    Tcp(String),
    /// A serial port's path, at the device's baud rate.
    Serial(String),
}

impl Addr {
    /// `unix:PATH`, `tcp:HOST:PORT`, or a serial port; why not, in words.
    pub fn parse(text: &str) -> Result<Addr, &'static str> {
        if let Some(p) = text.strip_prefix("unix:") {
            if p.is_empty() {
                return Err("unix: needs a socket path (unix:/tmp/mccs.sock)");
            }
            if !cfg!(unix) {
                return Err("unix sockets are for Unix hosts: use tcp:HOST:PORT or a serial port");
            }
            return Ok(Addr::Unix(p.into()));
        }
        if let Some(hp) = text.strip_prefix("tcp:") {
            if !hp
                .rsplit_once(':')
                .is_some_and(|(h, p)| !h.is_empty() && p.parse::<u16>().is_ok())
            {
                return Err("tcp: needs HOST:PORT (tcp:localhost:5555)");
            }
            return Ok(Addr::Tcp(hp.into()));
        }
        if text.is_empty() || text.contains(':') && !text.starts_with("COM") {
            return Err("must be unix:PATH, tcp:HOST:PORT or a serial port's path");
        }
        Ok(Addr::Serial(text.into()))
    }
}

impl fmt::Display for Addr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Addr::Unix(p) => write!(f, "unix:{}", p.display()),
            Addr::Tcp(hp) => write!(f, "tcp:{hp}"),
            Addr::Serial(p) => f.write_str(p),
        }
    }
}

impl std::str::FromStr for Addr {
    type Err = &'static str;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Addr::parse(s)
    }
}
