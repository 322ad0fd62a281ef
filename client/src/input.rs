//! A user's file read whole, to a limit: a file past it (a wrong file picked, or a
//! device such as `/dev/zero`, which never ends) is refused once the limit is read,
//! not read into memory until memory runs out.

use std::io::{Error, ErrorKind, Read};
use std::path::Path;

/// A configuration's limit, 1 MiB: a parameter file, a device file, a link script, a
/// table's `.bin` (each a few kB).
pub const CONFIG_BYTES: u64 = 1 << 20;

/// A data file's limit, 256 MiB: a trajectory, a fit's data, the arm's CSV inputs, a
/// firmware's log (a million rows of 256 characters; over two hours of a probe's
/// positions at 1 kHz).
pub const DATA_BYTES: u64 = 256 << 20;

/// `path`'s bytes, at most `limit`; a file past it is an [`ErrorKind::InvalidData`]
/// error that says the limit ("the file is larger than 1 MiB").
pub fn read_bytes(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    let mut data = Vec::new();
    std::fs::File::open(path)?
        .take(limit.saturating_add(1))
        .read_to_end(&mut data)?;
    if data.len() as u64 > limit {
        return Err(Error::new(
            ErrorKind::InvalidData,
            format!("the file is larger than {} MiB", limit >> 20),
        ));
    }
    Ok(data)
}

/// `path`'s text, at most `limit` bytes of UTF-8 (as [`std::fs::read_to_string`] says
/// when it is not).
pub fn read_text(path: &Path, limit: u64) -> std::io::Result<String> {
    String::from_utf8(read_bytes(path, limit)?)
        .map_err(|_| Error::new(ErrorKind::InvalidData, "stream did not contain valid UTF-8"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_past_its_limit_is_refused_at_the_limit() {
        let dir = std::env::temp_dir().join(format!("mccs-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("two-mib.txt");
        std::fs::write(&f, vec![b'a'; 2 << 20]).unwrap();
        assert_eq!(read_text(&f, 2 << 20).unwrap().len(), 2 << 20);
        let e = read_text(&f, CONFIG_BYTES).unwrap_err();
        assert_eq!(
            (e.kind(), e.to_string()),
            (
                ErrorKind::InvalidData,
                "the file is larger than 1 MiB".into()
            )
        );
        std::fs::write(&f, b"\xff").unwrap();
        assert_eq!(
            read_text(&f, CONFIG_BYTES).unwrap_err().to_string(),
            std::fs::read_to_string(&f).unwrap_err().to_string()
        );
        std::fs::remove_file(&f).unwrap();
    }

    /// A file that never ends is refused after its limit.
    #[cfg(unix)]
    #[test]
    fn a_device_that_never_ends_is_refused() {
        let e = read_bytes(Path::new("/dev/zero"), CONFIG_BYTES).unwrap_err();
        assert_eq!(e.to_string(), "the file is larger than 1 MiB");
    }
}
