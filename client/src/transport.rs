//! The byte stream to a device, split into a reader (its reads time out, so that the
//! session's worker can keep time) and a writer: a unix socket (`cfg(unix)`), TCP or a
//! serial port.

use crate::addr::Addr;
use std::io::{Read, Write};
use std::time::Duration;

/// A read side whose reads time out.
pub(crate) type Reader = Box<dyn Read + Send>;
/// A write side.
pub(crate) type Writer = Box<dyn Write + Send>;

/// How long a read waits before the worker checks its clock.
pub(crate) const POLL: Duration = Duration::from_millis(5);

/// Connects to `addr` (a serial port at `baud`).
pub(crate) fn connect(addr: &Addr, baud: u32) -> std::io::Result<(Reader, Writer)> {
    match addr {
        #[cfg(unix)]
        Addr::Unix(p) => {
            let s = std::os::unix::net::UnixStream::connect(p)?;
            s.set_read_timeout(Some(POLL))?;
            let w = s.try_clone()?;
            Ok((Box::new(s), Box::new(w)))
        }
        #[cfg(not(unix))]
        Addr::Unix(_) => Err(std::io::Error::new(
            std::io::ErrorKind::Unsupported,
            "unix sockets are for Unix hosts",
        )),
        Addr::Tcp(hp) => {
            let s = std::net::TcpStream::connect(hp)?;
            s.set_read_timeout(Some(POLL))?;
            s.set_nodelay(true)?;
            let w = s.try_clone()?;
            Ok((Box::new(s), Box::new(w)))
        }
        Addr::Serial(path) => {
            let p = serialport::new(path, baud)
                .timeout(POLL)
                .open()
                .map_err(std::io::Error::other)?;
            let w = p.try_clone().map_err(std::io::Error::other)?;
            Ok((Box::new(p), Box::new(w)))
        }
    }
}
