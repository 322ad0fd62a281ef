//! `mccs view` on the command line: what it refuses before any page is served (an
//! unreachable device, a port in use, no device named), each in one line with exit 2,
//! and what it serves (the page, its script, the events, a control refused to a page
//! that does not hold the controls). The page in a browser: tests/browser/view.py.

use super::{assert_one_line_error, mccs};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::process::{Child, Command, Stdio};

#[test]
fn an_unreachable_device_is_one_line_before_any_page() {
    // Port 1 on the loopback: nothing listens.
    let out = mccs(&["view", "--connect", "tcp:127.0.0.1:1", "--port", "0"]);
    assert_one_line_error(&out, &["--connect", "127.0.0.1:1"]);
    let out = mccs(&["view", "--connect", "tcp:nowhere", "--port", "0"]);
    assert_one_line_error(&out, &["--connect", "HOST:PORT"]);
}

#[test]
fn a_port_in_use_is_one_line_naming_it() {
    let taken = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    let out = mccs(&["view", "--demo", "--port", &port]);
    assert_one_line_error(&out, &["--port", &format!("127.0.0.1:{port}"), "in use"]);
}

/// A port past `u16`: clap's range in words (`0 … 65535`), as every number's range is
/// said (`--every` of `link watch` and `mesh` the same).
#[test]
fn a_port_past_its_range_says_the_range_in_words() {
    let out = mccs(&["view", "--demo", "--port", "99999"]);
    super::assert_usage_error(&out, &["--port", "99999 is not in 0 … 65535"]);
}

#[test]
fn a_view_needs_one_device() {
    for args in [
        &["view"][..],
        &["view", "--demo", "--connect", "tcp:127.0.0.1:1"],
    ] {
        let out = mccs(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(String::from_utf8_lossy(&out.stderr).starts_with("mccs: "));
    }
}

/// `mccs view --demo --port 0`, and the address it printed.
fn demo_view() -> (Child, String) {
    view(&["--demo"])
}

/// `mccs view ARGS --port 0`, and the address it printed.
fn view(args: &[&str]) -> (Child, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_mccs"))
        .arg("view")
        .args(args)
        .args(["--port", "0"])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let addr = line
        .split("http://")
        .nth(1)
        .and_then(|a| a.split('/').next())
        .unwrap_or_else(|| panic!("no address in {line:?}"))
        .to_string();
    (child, addr)
}

/// The events of a page until one of `kind` arrives (its data line), within `seconds`.
fn events_until(addr: &str, kind: &str, seconds: u64) -> String {
    let mut events = TcpStream::connect(addr).unwrap();
    events
        .set_read_timeout(Some(std::time::Duration::from_secs(seconds)))
        .unwrap();
    events.write_all(b"GET /events HTTP/1.1\r\n\r\n").unwrap();
    let mut r = BufReader::new(events);
    let want = format!("event: {kind}\n");
    let mut last = String::new();
    loop {
        let mut l = String::new();
        assert!(r.read_line(&mut l).unwrap_or(0) > 0, "no {kind} event");
        if last == want {
            return l;
        }
        last = l;
    }
}

/// One request; the whole answer.
fn http(addr: &str, request: &str) -> String {
    let mut s = TcpStream::connect(addr).unwrap();
    s.write_all(request.as_bytes()).unwrap();
    let mut answer = String::new();
    s.read_to_string(&mut answer).unwrap();
    answer
}

#[test]
fn the_demo_serves_its_page_its_events_and_refuses_a_watcher_s_control() {
    let (mut child, addr) = demo_view();
    let page = http(&addr, "GET / HTTP/1.1\r\n\r\n");
    assert!(page.starts_with("HTTP/1.1 200 OK") && page.contains("<title>mccs view</title>"));
    let script = http(&addr, "GET /view.js HTTP/1.1\r\n\r\n");
    assert!(script.contains("text/javascript") && script.contains("new EventSource('/events')"));
    assert!(http(&addr, "GET /nope HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 404"));
    assert!(http(&addr, "PUT / HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 405"));
    // The first page holds the controls; a request naming no page, or another, is refused.
    let mut events = TcpStream::connect(&addr).unwrap();
    events.write_all(b"GET /events HTTP/1.1\r\n\r\n").unwrap();
    let mut r = BufReader::new(events);
    let mut seen = String::new();
    while !(seen.contains("event: hello") && seen.contains("event: t\n")) {
        let mut l = String::new();
        assert!(r.read_line(&mut l).unwrap() > 0, "the events ended: {seen}");
        seen.push_str(&l);
    }
    assert!(
        seen.contains("event: welcome\ndata: {\"holder\":1,\"id\":1}"),
        "{seen}"
    );
    let refused = http(
        &addr,
        "POST /arm HTTP/1.1\r\nX-Mccs-Page: 2\r\nContent-Length: 0\r\n\r\n",
    );
    assert!(
        refused.starts_with("HTTP/1.1 403") && refused.contains("this one watches"),
        "{refused}"
    );
    let bad = http(
        &addr,
        "POST /pose HTTP/1.1\r\nX-Mccs-Page: 1\r\nContent-Length: 5\r\n\r\n1,2,3",
    );
    assert!(
        bad.starts_with("HTTP/1.1 400") && bad.contains("six numbers"),
        "{bad}"
    );
    let far = "POST /pose HTTP/1.1\r\nX-Mccs-Page: 1\r\nContent-Length: 13\r\n\r\n900,0,0,0,0,0";
    let far = http(&addr, far);
    assert!(
        far.starts_with("HTTP/1.1 409") && far.contains("\"ok\":false"),
        "{far}"
    );
    let armed = http(
        &addr,
        "POST /arm HTTP/1.1\r\nX-Mccs-Page: 1\r\nContent-Length: 0\r\n\r\n",
    );
    assert!(
        armed.starts_with("HTTP/1.1 200") && armed.contains("armed=1"),
        "{armed}"
    );
    child.kill().unwrap();
    child.wait().unwrap();
}

#[test]
fn a_device_lost_while_serving_is_an_event_and_the_view_goes_on() {
    let dir = std::env::temp_dir().join(format!("mccs-view-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let socket = dir.join("lost.sock");
    let table = mccs::ForceTable64::new(&mccs::Params::TABLE2).unwrap();
    let soft = mccs_host::link::soft::serve(&socket, table).unwrap();
    let (mut child, addr) = view(&["--connect", soft.addr()]);
    assert!(events_until(&addr, "status", 10).contains("\"armed\":false"));
    soft.stop();
    let lost = events_until(&addr, "device", 20);
    assert!(lost.starts_with("data: {\"error\":"), "{lost}");
    // The page is still served.
    assert!(http(&addr, "GET / HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 200"));
    child.kill().unwrap();
    child.wait().unwrap();
}
