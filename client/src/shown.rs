//! A user's text, names and numbers inside a one-line message: [`Shown`], [`ShownName`],
//! [`ShownPath`], [`ShownNumber`].

use std::fmt;
use std::path::Path;

/// The most characters a message shows of a user's text, its escapes written out; past
/// them, `…`.
pub const SHOWN_CHARS: usize = 60;

/// A user's text (a file's field, header or key, a script's word) as a one-line message
/// shows it: every character Rust's `escape_debug` escapes written escaped (`\n`, `\r`,
/// `\t`, `\u{1b}`, `\u{202e}`, …) but quotes and backslashes, which are shown as they
/// are; at most [`SHOWN_CHARS`] characters so written (an escape counts as its length),
/// then `…` if the text goes on.
/// A quoted CSV field or TOML key may hold a line break, and a file may hold a
/// terminal's escape sequence: neither reaches the terminal, and the message stays one
/// line of bounded length whatever the file holds.
///
/// A field `0.05⏎0.1` is shown `0.05\n0.1`, and 61 nines as 60 and `…` (the tests below
/// hold every character of the first three planes to it).
#[derive(Clone, Copy, Debug)]
pub struct Shown<'a>(pub &'a str);

impl fmt::Display for Shown<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_escaped(f, self.0, SHOWN_CHARS)
    }
}

/// A file's path or a device's address as a one-line message names it: escaped as
/// [`Shown`] escapes, but in full (a name cut short would not say which file). A file
/// `a⏎b.toml` is named `a\nb.toml`, and a terminal's escape sequence in a name is written
/// out (`\u{1b}[31m`), not sent to the terminal.
#[derive(Clone, Copy, Debug)]
pub struct ShownName<'a>(pub &'a str);

impl fmt::Display for ShownName<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_escaped(f, self.0, usize::MAX)
    }
}

/// A path as [`ShownName`] names it; what of it is not Unicode is shown as U+FFFD
/// (`Path::to_string_lossy`).
#[derive(Clone, Copy, Debug)]
pub struct ShownPath<'a>(pub &'a Path);

impl fmt::Display for ShownPath<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_escaped(f, &self.0.to_string_lossy(), usize::MAX)
    }
}

/// `text` escaped (every character `escape_debug` escapes but quotes and backslashes),
/// at most `limit` characters so written, then `…` if it goes on.
fn write_escaped(f: &mut fmt::Formatter<'_>, text: &str, limit: usize) -> fmt::Result {
    let mut shown = 0usize;
    for c in text.chars() {
        let plain = matches!(c, '"' | '\'' | '\\');
        // (An escape counts as the characters it shows: `\u{1b}` is six.)
        shown = shown.saturating_add(if plain { 1 } else { c.escape_debug().len() });
        if shown > limit {
            return f.write_str("…");
        }
        if plain {
            fmt::Write::write_char(f, c)?;
        } else {
            write!(f, "{}", c.escape_debug())?;
        }
    }
    Ok(())
}

/// The longest a [`ShownNumber`] is written in full; past it, in exponent form.
pub const SHOWN_NUMBER_CHARS: usize = 12;

/// A user's number as a one-line message shows it: as Rust writes it (`0.15`, `-3`)
/// where that takes at most [`SHOWN_NUMBER_CHARS`] characters, else in exponent form
/// (`1.071e267`, `1e-300`), where Rust would write every digit (268 of them for
/// `1.071e267`). Either way the shortest that reads back as the same `f64`.
#[derive(Clone, Copy, Debug)]
pub struct ShownNumber(pub f64);

impl fmt::Display for ShownNumber {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let full = self.0.to_string();
        if full.len() <= SHOWN_NUMBER_CHARS {
            f.write_str(&full)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_character_shown_is_a_control_and_at_most_the_limit_are_shown() {
        // Every character of the first planes, alone and in a long run.
        for c in (0u32..0x3_0000).filter_map(char::from_u32) {
            let s = Shown(c.encode_utf8(&mut [0; 4])).to_string();
            assert!(!s.chars().any(char::is_control), "{c:?} shown as {s:?}");
            assert!(!s.contains(['\u{2028}', '\u{2029}', '\u{202e}']), "{c:?}");
        }
        // `ab\n` shows as four characters: 15 of them fill the 60.
        let long = "ab\n".repeat(100);
        let s = Shown(&long).to_string();
        assert!(s.ends_with('…') && !s.contains('\n'), "{s}");
        assert_eq!(s.matches("ab").count(), 15, "{s}");
        assert_eq!(s.chars().count(), SHOWN_CHARS + 1, "{s}");
        // Escapes alone: as many whole ones as fit.
        let s = Shown(&"\u{15}".repeat(100)).to_string();
        assert_eq!(s, format!("{}…", r"\u{15}".repeat(10)));
        // Exactly the limit: all of it, no ellipsis.
        let exact = "x".repeat(SHOWN_CHARS);
        assert_eq!(Shown(&exact).to_string(), exact);
        // Quotes and backslashes as they are.
        assert_eq!(Shown(r#""a"\'b'"#).to_string(), r#""a"\'b'"#);
    }

    #[test]
    fn a_name_is_one_line_and_whole() {
        // A line break and a terminal's escape sequence written out; quotes, backslashes
        // (a Windows path's) and other scripts as they are; no limit on the length.
        let name = "dir/a\nb \u{1b}[31m\"é\"\\x.toml";
        assert_eq!(
            ShownName(name).to_string(),
            r#"dir/a\nb \u{1b}[31m"é"\x.toml"#
        );
        assert_eq!(
            ShownPath(Path::new(name)).to_string(),
            ShownName(name).to_string()
        );
        let long = format!("/{}", "d/".repeat(300));
        assert_eq!(ShownName(&long).to_string(), long);
        for c in (0u32..0x3_0000).filter_map(char::from_u32) {
            let s = ShownName(c.encode_utf8(&mut [0; 4])).to_string();
            assert!(!s.chars().any(char::is_control), "{c:?} shown as {s:?}");
        }
    }

    #[test]
    fn a_number_is_short_and_reads_back_as_itself() {
        for (x, shown) in [
            (0.15, "0.15"),
            (-3.0, "-3"),
            (123456789.5, "123456789.5"),
            (1.071e267, "1.071e267"),
            (1e-300, "1e-300"),
            (f64::MAX, "1.7976931348623157e308"),
            (f64::NAN, "NaN"),
            (f64::NEG_INFINITY, "-inf"),
        ] {
            assert_eq!(ShownNumber(x).to_string(), shown);
        }
        // Every exponent, both signs, an awkward mantissa: at most 24 characters, and
        // the same `f64` read back.
        for k in -1074..=1023 {
            for m in [1.0, -1.0, 1.234_567_890_123_456_7] {
                let x = m * 2f64.powi(k);
                let s = ShownNumber(x).to_string();
                assert!(s.len() <= 24, "{s}");
                assert_eq!(s.parse::<f64>().unwrap(), x, "{s}");
            }
        }
    }
}
