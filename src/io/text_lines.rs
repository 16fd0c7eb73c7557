//! Helpers of the text readers and writers: lines with any line end,
//! ASCII words, byte counts and messages about them.

use anyhow::Result;

use super::Point3;

/// Describes a truncated element list: "expected 40256 vertices, file ends
/// after 1234".
pub(crate) fn truncated(expected: usize, what: &str, got: usize) -> anyhow::Error {
    anyhow::anyhow!(
        "expected {expected} {}, file ends after {got}",
        plural(what)
    )
}

/// Plural of an element name, for messages.
pub(crate) fn plural(what: &str) -> String {
    match what {
        "vertex" => "vertices".to_string(),
        w if w.ends_with('s') => w.to_string(),
        w => format!("{w}s"),
    }
}

/// Capacity to reserve for `count` records announced by a header: a
/// header can claim anything, so reserve at most a million and let the
/// vector grow past that only as real data arrives.
pub(crate) fn capacity(count: usize) -> usize {
    count.min(1 << 20)
}

/// `bytes` without a leading UTF-8 byte order mark, which Windows editors
/// write and which would otherwise stick to the first word (`\u{feff}1`).
pub(crate) fn strip_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes)
}

/// The file as UTF-8 text, without a leading byte order mark; the mark is
/// dropped after decoding so that byte offsets in messages stay the file's.
pub(crate) fn text_of(bytes: &[u8]) -> Result<&str> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        anyhow::anyhow!(
            "not a text file (invalid UTF-8 at byte {})",
            e.valid_up_to()
        )
    })?;
    Ok(text.strip_prefix('\u{feff}').unwrap_or(text))
}

/// Writes `n` records of text, record i formatted by `format(out, i)`.
///
/// Formatting floats is most of the work of a text output (about 0.4 s a
/// million CSV lines on one thread), so records are formatted in parallel
/// pieces, a window of pieces at a time (a bounded buffer, not the whole
/// file), and written in order: the bytes one thread would write.
pub(crate) fn write_formatted(
    w: &mut dyn std::io::Write,
    n: usize,
    format: impl Fn(&mut Vec<u8>, usize) + Sync,
) -> std::io::Result<()> {
    write_formatted_in_pieces(w, n, FORMAT_PIECE, FORMAT_WINDOW, format)
}

/// Records per piece of [`write_formatted`], and pieces formatted at once
/// (some 40 MB of text).
pub(super) const FORMAT_PIECE: usize = 8192;
pub(super) const FORMAT_WINDOW: usize = 64;

pub(super) fn write_formatted_in_pieces(
    w: &mut dyn std::io::Write,
    n: usize,
    piece: usize,
    window: usize,
    format: impl Fn(&mut Vec<u8>, usize) + Sync,
) -> std::io::Result<()> {
    use rayon::prelude::*;
    let pieces: Vec<_> = (0..n)
        .step_by(piece)
        .map(|start| start..(start + piece).min(n))
        .collect();
    for window in pieces.chunks(window) {
        let texts: Vec<Vec<u8>> = window
            .par_iter()
            .map(|range| {
                // Sized by the first record, so that the text seldom grows.
                let mut text = Vec::new();
                for i in range.clone() {
                    format(&mut text, i);
                    if i == range.start {
                        text.reserve(text.len() * range.len() * 9 / 8);
                    }
                }
                text
            })
            .collect();
        for text in texts {
            w.write_all(&text)?;
        }
    }
    Ok(())
}

/// Bytes per piece of text parsed in parallel ([`cut_after_newlines`]): a
/// million-point file parses in about 50 pieces, a small one in one.
pub(crate) const PIECE_BYTES: usize = 1 << 20;

/// `text` cut into pieces of about `piece_bytes`, each ending just after a
/// `\n` (the last one wherever the text ends). A `\n` ends a line whether
/// alone or in `\r\n`, so every piece starts a line, and [`lines`] numbers
/// a piece's lines as it numbers them in the whole text.
pub(crate) fn cut_after_newlines(text: &str, piece_bytes: usize) -> Vec<&str> {
    let mut pieces = Vec::new();
    let mut rest = text;
    while rest.len() > piece_bytes {
        match memchr::memchr(b'\n', &rest.as_bytes()[piece_bytes..]) {
            Some(i) => {
                let (piece, after) = rest.split_at(piece_bytes + i + 1);
                pieces.push(piece);
                rest = after;
            }
            None => break,
        }
    }
    pieces.push(rest);
    pieces
}

/// The lines of a text, ended by `\n`, `\r\n` or a lone `\r`, without their
/// ends. `str::lines` does not end a line at a lone `\r` (classic Mac OS,
/// Excel for Mac's "CSV (Macintosh)"), so such a file would read as one
/// line: an OBJ as one vertex, a point list as one point with the rest
/// taken for extra fields. Otherwise the same as `str::lines`.
pub(crate) fn lines(text: &str) -> impl Iterator<Item = &str> {
    let mut rest = text;
    std::iter::from_fn(move || next_line(&mut rest))
}

/// The first line of `rest` as [`lines`] splits it, with `rest` moved past
/// it and its ending; `None` when `rest` is empty.
pub(crate) fn next_line<'a>(rest: &mut &'a str) -> Option<&'a str> {
    if rest.is_empty() {
        return None;
    }
    let text: &'a str = rest;
    let (line, after) = match memchr::memchr2(b'\n', b'\r', text.as_bytes()) {
        Some(i) if text[i..].starts_with("\r\n") => (&text[..i], &text[i + 2..]),
        Some(i) => (&text[..i], &text[i + 1..]),
        None => (text, ""),
    };
    *rest = after;
    Some(line)
}

/// The words of a line, split at whitespace as `str::split_whitespace`
/// splits (Unicode's, as `char::is_whitespace` says), by bytes when the
/// line is ASCII: no UTF-8 decoding per character.
pub(crate) fn words(line: &str) -> Words<'_> {
    if line.is_ascii() {
        Words::Ascii(line)
    } else {
        Words::Unicode(line.split_whitespace())
    }
}

/// The ASCII characters `char::is_whitespace` accepts: vertical tab
/// included, unlike `u8::is_ascii_whitespace`.
pub(crate) fn is_ascii_space(b: &u8) -> bool {
    b.is_ascii_whitespace() || *b == 0x0b
}

/// The iterator of [`words`].
pub(crate) enum Words<'a> {
    /// The rest of an ASCII line.
    Ascii(&'a str),
    Unicode(std::str::SplitWhitespace<'a>),
}

impl<'a> Iterator for Words<'a> {
    type Item = &'a str;

    fn next(&mut self) -> Option<&'a str> {
        match self {
            Words::Ascii(rest) => {
                let bytes = rest.as_bytes();
                let start = bytes.iter().position(|b| !is_ascii_space(b))?;
                let len = bytes[start..].iter().position(is_ascii_space);
                let end = len.map_or(bytes.len(), |len| start + len);
                // Every byte of an ASCII line starts a character.
                let word = &rest[start..end];
                *rest = &rest[end..];
                Some(word)
            }
            Words::Unicode(split) => split.next(),
        }
    }
}

/// How the lines of a PLY or PCD header end, as its first line ends: `\n`
/// (after an optional `\r`) or a lone `\r` (classic Mac OS).
///
/// A header cannot be split like text ([`lines`]): binary data follows it,
/// and it may start with a `\n` byte, which after a header line ending in
/// `\r` would be taken for the rest of a `\r\n`. Taking the ending of the
/// first line for the whole header finds the header's end exactly.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum HeaderEol {
    /// `\n` or `\r\n`.
    Newline,
    /// A lone `\r`.
    Return,
}

impl HeaderEol {
    /// The ending of the first line of `bytes`; `Newline` when there is no
    /// line ending at all.
    pub(crate) fn of(bytes: &[u8]) -> HeaderEol {
        match bytes.iter().position(|&b| b == b'\n' || b == b'\r') {
            Some(i) if bytes[i] == b'\r' && bytes.get(i + 1) != Some(&b'\n') => HeaderEol::Return,
            _ => HeaderEol::Newline,
        }
    }

    /// The byte that ends a line.
    pub(crate) fn byte(self) -> u8 {
        match self {
            HeaderEol::Newline => b'\n',
            HeaderEol::Return => b'\r',
        }
    }

    /// The next line of `bytes` from `start`: its text, without the ending
    /// (and a `\r` before a `\n`), and where the line after it starts;
    /// `None` when the bytes end before a line ending.
    pub(crate) fn line(self, bytes: &[u8], start: usize) -> Option<(&[u8], usize)> {
        let len = bytes[start..].iter().position(|&b| b == self.byte())?;
        let line = &bytes[start..start + len];
        let line = match self {
            HeaderEol::Newline => line.strip_suffix(b"\r").unwrap_or(line),
            HeaderEol::Return => line,
        };
        Some((line, start + len + 1))
    }

    /// [`HeaderEol::line`], or else the rest of `bytes` as a last line
    /// without an ending.
    pub(crate) fn line_or_rest(self, bytes: &[u8], start: usize) -> (&[u8], usize) {
        self.line(bytes, start)
            .unwrap_or((&bytes[start..], bytes.len()))
    }

    /// The lines of a header's text, split as [`HeaderEol::line`] splits
    /// bytes (the last line needs no ending).
    pub(crate) fn text_lines(self, text: &str) -> impl Iterator<Item = &str> {
        let newline = self == HeaderEol::Newline;
        text.split(char::from(self.byte())).map(move |l| {
            if newline {
                l.strip_suffix('\r').unwrap_or(l)
            } else {
                l
            }
        })
    }
}

/// Whether a PLY or PCD header line holds a `\r` that ends no line: the
/// header's first line ended with `\n`, so a later line ended by a lone
/// `\r` ran into the next one, which would be misread (a PCD `FIELDS`
/// line taking the `SIZE` line's words for field names).
pub(crate) fn mixed_line_ending(line: &str) -> Option<String> {
    line.trim_end_matches('\r').contains('\r').then(|| {
        "a lone carriage return inside the line: every header line must end as the \
         first does, and the first ends with a newline"
            .to_string()
    })
}

/// Formats a point for messages, keeping NaN and inf readable.
pub(crate) fn show(p: &Point3) -> String {
    format!("({}, {}, {})", p[0], p[1], p[2])
}
