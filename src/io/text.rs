//! Plain-text point lists: XYZ, TXT, CSV, ASC, PTS.
//!
//! One point per line; the first three fields are x, y and z and any further
//! fields (colour, intensity, normals) are ignored. Fields are separated by
//! whitespace, commas or semicolons. Blank lines and lines starting with `#`
//! are skipped, and the first data line is taken as a header when none of
//! its first three fields is a number; a header with no data line after it
//! is an error naming it.
//!
//! A line holding one whole number alone is a point count, as Leica's PTS
//! files start each scan with one: the points after it, up to the next
//! count or the end, must be that many (a mismatch is an error naming the
//! count's line: a truncated file or a damaged merge).
//!
//! Large files are parsed in parallel, in pieces cut after a `\n` (which
//! always ends a line, alone or in `\r\n`); the points come out in file
//! order and the first error in file order is the one reported, as the
//! serial reading (`read_text_serial`, kept for tests) gives.

use anyhow::{bail, Result};
use rayon::prelude::*;

use super::{cut_after_newlines, lines, show, strip_bom, text_of, Mesh, Point3, PIECE_BYTES};

/// Reads a text point list.
pub fn read_text(bytes: &[u8]) -> Result<Mesh> {
    read_text_in_pieces(bytes, PIECE_BYTES)
}

fn read_text_in_pieces(bytes: &[u8], piece_bytes: usize) -> Result<Mesh> {
    let text = text_of(bytes)?;
    let (header, body, lines_before) = split_header(text);
    let pieces: Vec<Piece> = cut_after_newlines(body, piece_bytes)
        .into_par_iter()
        .map(parse_piece)
        .collect();
    let vertices = join_pieces(pieces, lines_before)?;
    // Otherwise a file of words reads as a header alone and the error,
    // "no points", hides that its one line was not numbers.
    if let Some(i) = header.filter(|_| vertices.is_empty()) {
        bail!(
            "line {i} looks like a header (none of its first three fields is a number) \
             and no line of numbers follows"
        );
    }
    Ok(Mesh {
        vertices,
        ..Mesh::default()
    })
}

/// The header's line number if the first data line is one, the text after
/// it (all of it without a header), and the number of lines before that.
fn split_header(text: &str) -> (Option<usize>, &str, usize) {
    let Some((i, line)) = data_lines(text).next() else {
        return (None, text, 0);
    };
    let mut first = [""; 3];
    let found = read_fields(line, &mut first);
    if !is_header(&first[..found]) {
        return (None, text, 0);
    }
    // The header line's end: after its trimmed content, any trailing
    // blanks, then its line ending.
    let bytes = text.as_bytes();
    let mut end = line.as_ptr() as usize - text.as_ptr() as usize + line.len();
    while end < bytes.len() && bytes[end] != b'\n' && bytes[end] != b'\r' {
        end += 1;
    }
    end += match &bytes[end..] {
        [b'\r', b'\n', ..] => 2,
        [] => 0,
        _ => 1,
    };
    (Some(i), &text[end..], i)
}

/// What one piece of the text holds; line numbers count from its start.
#[derive(Debug, Default)]
struct Piece {
    points: Vec<Point3>,
    /// Point-count lines: (line, count, points before it in this piece).
    counts: Vec<(usize, u64, usize)>,
    lines: usize,
    /// The piece's first error; parsing stops there.
    error: Option<(usize, String)>,
}

fn parse_piece(text: &str) -> Piece {
    let mut piece = Piece::default();
    for raw in lines(text) {
        piece.lines += 1;
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        match parse_line(line) {
            Ok(Line::Point(p)) => piece.points.push(p),
            Ok(Line::Count(n)) => piece.counts.push((piece.lines, n, piece.points.len())),
            Err(e) => {
                piece.error = Some((piece.lines, e));
                break;
            }
        }
    }
    piece
}

/// The pieces' points in order, or the first error in file order; then the
/// point counts checked against the points that follow them.
fn join_pieces(pieces: Vec<Piece>, lines_before: usize) -> Result<Vec<Point3>> {
    let total = pieces.iter().map(|p| p.points.len()).sum();
    let mut points = Vec::with_capacity(total);
    let mut counts = Vec::new();
    let mut line0 = lines_before;
    for piece in pieces {
        if let Some((i, e)) = piece.error {
            bail!("line {}: {e}", line0 + i);
        }
        let before = points.len();
        counts.extend(
            piece
                .counts
                .iter()
                .map(|&(i, n, at)| (line0 + i, n, before + at)),
        );
        points.extend_from_slice(&piece.points);
        line0 += piece.lines;
    }
    for (c, &(line, count, at)) in counts.iter().enumerate() {
        let next = counts.get(c + 1).map_or(points.len(), |&(_, _, at)| at);
        let follow = next - at;
        if u64::try_from(follow) != Ok(count) {
            let points = if count == 1 { "point" } else { "points" };
            bail!(
                "line {line}: the point count says {count} {points}, but {follow} follow \
                 (a truncated file?)"
            );
        }
    }
    Ok(points)
}

/// A data line: a point, or a point count (a whole number alone).
#[derive(Debug, PartialEq)]
enum Line {
    Point(Point3),
    Count(u64),
}

fn parse_line(line: &str) -> Result<Line, String> {
    let mut first = [""; 3];
    let found = read_fields(line, &mut first);
    if found == 1 && first[0].bytes().all(|b| b.is_ascii_digit()) {
        if let Ok(n) = first[0].parse() {
            return Ok(Line::Count(n));
        }
    }
    parse_point(&first[..found]).map(Line::Point)
}

/// True if the first data line of `bytes` holds at least three numbers, so
/// that a file with an unknown extension can still be read as text.
pub fn looks_numeric(bytes: &[u8]) -> bool {
    let bytes = strip_bom(bytes);
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(4096)]);
    let first = data_lines(&head).next();
    first.is_some_and(|(_, line)| {
        let mut fields = [""; 3];
        read_fields(line, &mut fields) == 3 && fields.iter().all(|f| f.parse::<f64>().is_ok())
    })
}

/// Non-blank, non-comment lines with their 1-based line numbers.
fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    lines(text)
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'))
}

/// The line's first (up to) three fields into `out`; returns how many.
/// Fields are separated by commas, semicolons and whitespace (Unicode's,
/// as `char::is_whitespace` says).
fn read_fields<'a>(line: &'a str, out: &mut [&'a str; 3]) -> usize {
    let mut found = 0;
    if line.is_ascii() {
        // The common case, by bytes: no UTF-8 decoding per character.
        let fields = line
            .as_bytes()
            .split(|&b| is_ascii_separator(b))
            .filter(|f| !f.is_empty());
        for (slot, field) in out.iter_mut().zip(fields) {
            // Every byte of an ASCII line starts a character.
            let start = field.as_ptr() as usize - line.as_ptr() as usize;
            *slot = &line[start..start + field.len()];
            found += 1;
        }
        return found;
    }
    let fields = line
        .split(|c: char| c == ',' || c == ';' || c.is_whitespace())
        .filter(|f| !f.is_empty());
    for (slot, field) in out.iter_mut().zip(fields) {
        *slot = field;
        found += 1;
    }
    found
}

/// The ASCII characters `read_fields` splits at: comma, semicolon and the
/// ASCII characters `char::is_whitespace` accepts.
fn is_ascii_separator(b: u8) -> bool {
    b == b',' || b == b';' || super::is_ascii_space(&b)
}

fn is_header(first: &[&str]) -> bool {
    first.iter().all(|f| f.parse::<f64>().is_err())
}

fn parse_point(fields: &[&str]) -> Result<Point3, String> {
    if fields.len() < 3 {
        return Err(format!(
            "expected x, y and z, found {} field(s)",
            fields.len()
        ));
    }
    let mut p: Point3 = [0.0; 3];
    for (c, field) in p.iter_mut().zip(fields) {
        *c = field
            .parse()
            .map_err(|_| format!("'{field}' is not a number"))?;
    }
    if p.iter().any(|c| !c.is_finite()) {
        return Err(format!("non-finite coordinate {}", show(&p)));
    }
    Ok(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<Vec<Point3>> {
        read_text(text.as_bytes()).map(|m| m.vertices)
    }

    #[test]
    fn separators_header_comments() {
        let text = "# scan\nx,y,z,intensity\n\n1,2,3,9\n4;5;6\n 7 \t8 9 1 1 1\n-1e-3, 2.5 ,3\n";
        let points = read(text).unwrap();
        assert_eq!(
            points,
            vec![[1., 2., 3.], [4., 5., 6.], [7., 8., 9.], [-1e-3, 2.5, 3.]]
        );
    }

    #[test]
    fn round_trip_exact() {
        let points = vec![[0.1, 1.0 / 3.0, -7e-310], [1e300, -0.0, 2.0]];
        let text: String = points
            .iter()
            .map(|p| format!("{} {} {}\n", p[0], p[1], p[2]))
            .collect();
        assert_eq!(read(&text).unwrap(), points);
    }

    #[test]
    fn errors_name_the_line() {
        let e = read("1 2 3\n\n4 abc 6\n").unwrap_err().to_string();
        assert_eq!(e, "line 3: 'abc' is not a number");
        let e = read("1 2 3\n4 5\n").unwrap_err().to_string();
        assert_eq!(e, "line 2: expected x, y and z, found 2 field(s)");
        let e = read("1 2 3\n4 nan 6\n").unwrap_err().to_string();
        assert_eq!(e, "line 2: non-finite coordinate (4, NaN, 6)");
        let e = read("x y z\na b c\n").unwrap_err().to_string();
        assert_eq!(e, "line 2: 'a' is not a number");
        let e = read("# notes\nhello world foo\n").unwrap_err().to_string();
        assert_eq!(
            e,
            "line 2 looks like a header (none of its first three fields is a number) \
             and no line of numbers follows"
        );
    }

    #[test]
    fn a_byte_order_mark_is_not_part_of_the_first_field() {
        let points = read("\u{feff}1,2,3\n4,5,6\n").unwrap();
        assert_eq!(points, vec![[1., 2., 3.], [4., 5., 6.]]);
        assert_eq!(read("\u{feff}x,y,z\n1,2,3\n").unwrap(), vec![[1., 2., 3.]]);
        assert!(looks_numeric("\u{feff}1 2 3\n".as_bytes()));
        // Offsets in messages stay the file's, mark included.
        let e = read_text(b"\xef\xbb\xbf1 2 \xff").unwrap_err().to_string();
        assert_eq!(e, "not a text file (invalid UTF-8 at byte 7)");
    }

    #[test]
    fn pts_point_counts_are_read_and_checked() {
        // Leica PTS: a count line, then "x y z intensity r g b" lines; a
        // file may hold several scans, each after its own count.
        let pts = "2\n1 2 3 -100 10 20 30\n4 5 6 -90 10 20 30\n1\r\n7 8 9 0 0 0 0\r\n";
        assert_eq!(
            read(pts).unwrap(),
            vec![[1., 2., 3.], [4., 5., 6.], [7., 8., 9.]]
        );
        let e = read("1\n").unwrap_err().to_string();
        assert_eq!(
            e,
            "line 1: the point count says 1 point, but 0 follow (a truncated file?)"
        );
        let e = read("3\n1 2 3\n4 5 6\n").unwrap_err().to_string();
        assert_eq!(
            e,
            "line 1: the point count says 3 points, but 2 follow (a truncated file?)"
        );
        let e = read("1\n1 2 3\n\n# next scan\n2\n4 5 6\n")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "line 5: the point count says 2 points, but 1 follow (a truncated file?)"
        );
        // A number too large for a count, or signed, is a short point line.
        let e = read("1 2 3\n99999999999999999999999\n")
            .unwrap_err()
            .to_string();
        assert_eq!(e, "line 2: expected x, y and z, found 1 field(s)");
        let e = read("1 2 3\n-4\n").unwrap_err().to_string();
        assert_eq!(e, "line 2: expected x, y and z, found 1 field(s)");
    }

    /// The straightforward one-pass reading the piecewise one must match:
    /// points, the first error and the count checks, line numbers included.
    fn read_text_serial(bytes: &[u8]) -> Result<Vec<Point3>> {
        let text = text_of(bytes)?;
        let mut points = Vec::new();
        let mut counts = Vec::new();
        let mut header = None;
        let first_line = data_lines(text).next().map_or(0, |(j, _)| j);
        for (i, line) in data_lines(text) {
            let mut first = [""; 3];
            let found = read_fields(line, &mut first);
            if i == first_line && is_header(&first[..found]) {
                header = Some(i);
                continue;
            }
            match parse_line(line) {
                Ok(Line::Point(p)) => points.push(p),
                Ok(Line::Count(n)) => counts.push((i, n, points.len())),
                Err(e) => bail!("line {i}: {e}"),
            }
        }
        for (c, &(line, count, at)) in counts.iter().enumerate() {
            let follow = counts.get(c + 1).map_or(points.len(), |&(_, _, at)| at) - at;
            if follow as u64 != count {
                let points = if count == 1 { "point" } else { "points" };
                bail!(
                    "line {line}: the point count says {count} {points}, but {follow} follow \
                     (a truncated file?)"
                );
            }
        }
        if let Some(i) = header.filter(|_| points.is_empty()) {
            bail!(
                "line {i} looks like a header (none of its first three fields is a number) \
                 and no line of numbers follows"
            );
        }
        Ok(points)
    }

    /// Random texts (every line ending, blanks, comments, headers, counts,
    /// bad lines, non-ASCII separators) read in pieces of a few bytes give
    /// what the one-pass reading gives.
    #[test]
    fn pieces_read_as_one_pass_does() {
        let outcome = |r: Result<Vec<Point3>>| r.map_err(|e| e.to_string());
        let errors = crate::io::piece_tests::compare_with_one_pass(
            17,
            3000,
            30,
            |_, _| String::new(),
            |below, l, case| match below(40) {
                0 => "x,y,z".to_string(),
                1 => String::new(),
                2 => "# comment 1 2 3".to_string(),
                3 => format!("{}", below(4)),
                4 => "1 2".to_string(),
                5 => "1 abc 3".to_string(),
                6 => "1\u{a0}2\u{3000}3".to_string(),
                7 => " 4;5 ,6 \t".to_string(),
                8 => "1 nan 3".to_string(),
                _ => format!("{} {},{} 9", l, below(1000), case),
            },
            |text| outcome(read_text_serial(text.as_bytes())),
            |text, piece_bytes| {
                outcome(read_text_in_pieces(text.as_bytes(), piece_bytes).map(|m| m.vertices))
            },
        );
        // Both outcomes are exercised.
        assert!(
            (500..2500).contains(&errors),
            "{errors} errors in 3000 cases"
        );
    }

    #[test]
    fn numeric_sniffing() {
        assert!(looks_numeric(b"# c\n1 2 3\n"));
        assert!(!looks_numeric(b"x y z\n1 2 3\n"));
        assert!(!looks_numeric(b"1 2\n"));
    }
}
