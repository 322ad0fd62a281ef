//! `mccs view`: a live view of a device in the browser (docs/view.md): it takes the
//! port, opens the device's session (or, with `--demo`, starts the host's soft device
//! and opens that), prints the page's address, and serves until it is stopped (Ctrl-C:
//! the device, no longer kept alive, fades within its link timeout).

use super::{arg_error, io_error, CliError};
use crate::link::soft;
use crate::view::View;
use mccs::{ForceTable64, Params};
use std::io::Write;
use std::net::TcpListener;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// A line on stderr if what it guards takes over a second (a device that answers at
/// once, or refuses at once, leaves stderr to the result).
struct SayAfter {
    done: Arc<AtomicBool>,
}

impl SayAfter {
    fn new(line: String) -> Self {
        let done = Arc::new(AtomicBool::new(false));
        let d = done.clone();
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_secs(1));
            if !d.load(Ordering::SeqCst) {
                eprintln!("{line}");
            }
        });
        Self { done }
    }
}

impl Drop for SayAfter {
    fn drop(&mut self) {
        self.done.store(true, Ordering::SeqCst);
    }
}

#[derive(clap::Args, Debug)]
#[command(group(clap::ArgGroup::new("device").required(true).args(["connect", "demo"])))]
pub(super) struct Args {
    /// The device: unix:PATH, tcp:HOST:PORT, or a serial port's path (1,000,000 baud).
    #[arg(long, value_name = "ADDR")]
    connect: Option<String>,
    /// No board: the host's soft device (the arm board's own code on a simulated probe
    /// palpating Table 2's tissue).
    #[arg(long)]
    demo: bool,
    /// The page's port on 127.0.0.1 (0: any free port; the printed address says which).
    #[arg(long, default_value_t = 8765)]
    port: u16,
}

pub(super) fn run(a: Args, out: &mut dyn Write) -> Result<(), CliError> {
    if let Some(addr) = &a.connect {
        mccs_client::Addr::parse(addr).map_err(|e| arg_error("--connect", e))?;
    }
    let listener = TcpListener::bind(("127.0.0.1", a.port)).map_err(|e| {
        let why = match e.kind() {
            std::io::ErrorKind::AddrInUse => {
                "is in use: choose another with --port (0: any free port)".to_string()
            }
            _ => format!("cannot be taken: {e}"),
        };
        arg_error("--port", &format!("127.0.0.1:{} {why}", a.port))
    })?;
    let port = listener
        .local_addr()
        .map_err(|e| CliError::new(format!("--port: {e}")))?
        .port();
    // The soft device lives as long as the view.
    let (_soft, addr) = match &a.connect {
        Some(addr) => (None, addr.clone()),
        None => {
            let table = ForceTable64::new(&Params::TABLE2)
                .map_err(|e| CliError::new(format!("the demo's tissue: {e:?}")))?;
            let soft = soft::serve_tcp("127.0.0.1:0", table)
                .map_err(|e| CliError::new(format!("the demo's soft device: {e}")))?;
            let addr = soft.addr().to_string();
            (Some(soft), addr)
        }
    };
    let device = {
        let _said = SayAfter::new(format!("mccs view: saying hello to {addr} (up to 10 s)"));
        super::link::open(&addr)?
    };
    let view = View::new(device, a.demo).map_err(super::link::device_error)?;
    writeln!(
        out,
        "mccs view: http://127.0.0.1:{port}/ shows {addr}{}; Ctrl-C ends it",
        if a.demo {
            " (the demo's soft device)"
        } else {
            ""
        }
    )
    .and_then(|()| out.flush())
    .map_err(io_error)?;
    view.serve(listener)
        .map_err(|e| CliError::new(format!("mccs view: serving the page: {e}")))
}
