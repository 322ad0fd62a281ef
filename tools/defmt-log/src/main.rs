//! `defmt-log ELF`: reads a firmware's defmt frames on standard input and prints them
//! decoded, one line each: `println!` frames as they are, log frames after their level
//! (`INFO  …`, `ERROR …`). What `defmt-print -e ELF` prints, built with the workspace (no
//! separate install). Exit 2 with one line when the ELF has no defmt table or a frame is
//! malformed beyond recovery. A malformed frame it recovers from is not dropped in
//! silence: it prints the line `defmt-log: malformed frame skipped` in its place (a
//! frame lost is a log that lies: the M0 bench's stack once overran defmt's encoder and
//! a figure went missing), which the bench treats as a failure.

use defmt_decoder::{DecodeError, Table};
use std::io::{Read, Write};
use std::process::ExitCode;

fn fail(what: &str) -> ExitCode {
    eprintln!("defmt-log: {what}");
    ExitCode::from(2)
}

fn main() -> ExitCode {
    let mut args = std::env::args_os().skip(1);
    let (Some(elf), None) = (args.next(), args.next()) else {
        return fail("usage: defmt-log ELF < FRAMES");
    };
    let bytes = match std::fs::read(&elf) {
        Ok(b) => b,
        Err(e) => return fail(&format!("{}: cannot read: {e}", elf.to_string_lossy())),
    };
    let table = match Table::parse(&bytes) {
        Ok(Some(t)) => t,
        Ok(None) => return fail(&format!("{}: no .defmt data", elf.to_string_lossy())),
        Err(e) => return fail(&format!("{}: {e}", elf.to_string_lossy())),
    };
    let can_recover = table.encoding().can_recover();
    let mut decoder = table.new_stream_decoder();
    let (stdin, stdout) = (std::io::stdin(), std::io::stdout());
    let (mut input, mut out) = (stdin.lock(), stdout.lock());
    let mut buf = [0u8; 4096];
    loop {
        let n = match input.read(&mut buf) {
            Ok(0) => return ExitCode::SUCCESS,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return fail(&format!("stdin: {e}")),
        };
        decoder.received(&buf[..n]);
        loop {
            match decoder.decode() {
                Ok(frame) => {
                    let message = frame.display_message().to_string();
                    let line = match frame.level() {
                        Some(level) => format!("{:<5} {message}", level.as_str().to_uppercase()),
                        None => message,
                    };
                    if writeln!(out, "{line}").and_then(|_| out.flush()).is_err() {
                        return ExitCode::SUCCESS;
                    }
                }
                Err(DecodeError::UnexpectedEof) => break,
                Err(DecodeError::Malformed) if can_recover => {
                    if writeln!(out, "defmt-log: malformed frame skipped")
                        .and_then(|_| out.flush())
                        .is_err()
                    {
                        return ExitCode::SUCCESS;
                    }
                }
                Err(DecodeError::Malformed) => return fail("malformed frame"),
            }
        }
    }
}
