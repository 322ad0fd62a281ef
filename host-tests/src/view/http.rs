//! Just enough HTTP/1.1 for one page on the loopback: a request's line, the headers it
//! uses and its body ([`read_request`]), and whole responses ([`respond`]). Each
//! connection carries one request (`Connection: close`). What a browser may send that
//! this does not take is refused with a status, never a panic: a head over
//! [`MAX_HEAD`] bytes (431), a body over [`MAX_BODY`] (413), a request that is not
//! HTTP (400).

use std::io::{BufRead, BufReader, Read, Write};

/// The largest request head taken, bytes.
pub const MAX_HEAD: usize = 16 * 1024;
/// The largest body taken (a parameter file), bytes.
pub const MAX_BODY: usize = 256 * 1024;

/// A request.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Request {
    /// `GET`, `POST`, …
    pub method: String,
    /// The path, without its query.
    pub path: String,
    /// `X-Mccs-Page`: the page's id the events gave it.
    pub page: Option<u64>,
    /// The body.
    pub body: Vec<u8>,
}

/// Why a request was not taken: the status to answer with and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Refused {
    /// The HTTP status.
    pub status: u16,
    /// Why, for the body.
    pub why: &'static str,
}

const fn refused(status: u16, why: &'static str) -> Refused {
    Refused { status, why }
}

/// Reads one request from `stream`.
pub fn read_request(stream: impl Read) -> Result<Request, Refused> {
    let mut r = BufReader::new(stream.take((MAX_HEAD + MAX_BODY) as u64));
    let mut head = 0usize;
    let mut line = String::new();
    let mut next_line = |r: &mut BufReader<_>, line: &mut String| -> Result<(), Refused> {
        line.clear();
        let n = r
            .read_line(line)
            .map_err(|_| refused(400, "not a request"))?;
        head += n;
        if head > MAX_HEAD {
            return Err(refused(431, "the request's head is too long"));
        }
        if n == 0 {
            return Err(refused(400, "the request ended early"));
        }
        Ok(())
    };
    next_line(&mut r, &mut line)?;
    let mut parts = line.split_whitespace();
    let (Some(method), Some(target), Some(version)) = (parts.next(), parts.next(), parts.next())
    else {
        return Err(refused(400, "not a request line"));
    };
    if !version.starts_with("HTTP/1.") {
        return Err(refused(400, "not HTTP/1"));
    }
    let method = method.to_string();
    let path = target.split('?').next().unwrap_or("").to_string();
    let (mut len, mut page) = (0usize, None);
    loop {
        next_line(&mut r, &mut line)?;
        let l = line.trim_end();
        if l.is_empty() {
            break;
        }
        let Some((k, v)) = l.split_once(':') else {
            return Err(refused(400, "a header without a colon"));
        };
        let v = v.trim();
        if k.eq_ignore_ascii_case("content-length") {
            len = v
                .parse()
                .map_err(|_| refused(400, "a bad Content-Length"))?;
        } else if k.eq_ignore_ascii_case("x-mccs-page") {
            page = v.parse().ok();
        }
    }
    if len > MAX_BODY {
        return Err(refused(413, "the body is over 256 KiB"));
    }
    let mut body = vec![0; len];
    r.read_exact(&mut body)
        .map_err(|_| refused(400, "the body ended early"))?;
    Ok(Request {
        method,
        path,
        page,
        body,
    })
}

/// The reason phrase of the statuses used here.
fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        413 => "Content Too Large",
        431 => "Request Header Fields Too Large",
        503 => "Service Unavailable",
        _ => "Error",
    }
}

/// A whole response: `status`, its content type and body; the connection closes.
pub fn respond(
    mut w: impl Write,
    status: u16,
    content_type: &str,
    body: &[u8],
) -> std::io::Result<()> {
    write!(
        w,
        "HTTP/1.1 {status} {}\r\nContent-Type: {content_type}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
        reason(status),
        body.len()
    )?;
    w.write_all(body)?;
    w.flush()
}

/// The head of an event stream (server-sent events); its events follow.
pub fn begin_events(mut w: impl Write) -> std::io::Result<()> {
    w.write_all(
        b"HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
    )?;
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_post_with_its_page_and_body_reads_whole() {
        let raw = b"POST /pose?x=1 HTTP/1.1\r\nHost: a\r\nX-Mccs-Page: 7\r\nContent-Length: 5\r\n\r\n1,2,3";
        let r = read_request(&raw[..]).unwrap();
        assert_eq!(r.method, "POST");
        assert_eq!(r.path, "/pose");
        assert_eq!(r.page, Some(7));
        assert_eq!(r.body, b"1,2,3");
    }

    #[test]
    fn what_is_not_a_request_is_refused_with_a_status() {
        let cases: [(&[u8], u16); 6] = [
            (b"", 400),
            (b"GET\r\n\r\n", 400),
            (b"GET / SPDY/3\r\n\r\n", 400),
            (b"GET / HTTP/1.1\r\nNoColon\r\n\r\n", 400),
            (b"POST / HTTP/1.1\r\nContent-Length: 10\r\n\r\nabc", 400),
            (b"POST / HTTP/1.1\r\nContent-Length: 999999999\r\n\r\n", 413),
        ];
        for (raw, status) in cases {
            let e = read_request(raw).unwrap_err();
            assert_eq!(e.status, status, "{:?}", String::from_utf8_lossy(raw));
        }
        let long = format!("GET / HTTP/1.1\r\nX: {}\r\n\r\n", "a".repeat(MAX_HEAD));
        assert_eq!(read_request(long.as_bytes()).unwrap_err().status, 431);
    }

    #[test]
    fn a_response_says_its_length_and_closes() {
        let mut out = Vec::new();
        respond(&mut out, 403, "application/json", b"{}").unwrap();
        let text = String::from_utf8(out).unwrap();
        assert!(text.starts_with("HTTP/1.1 403 Forbidden\r\n"), "{text}");
        assert!(text.contains("Content-Length: 2\r\n") && text.ends_with("\r\n\r\n{}"));
    }
}
