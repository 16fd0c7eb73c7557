//! Plain-text point lists: XYZ, TXT, CSV, ASC, PTS.
//!
//! One point per line; the first three fields are x, y and z and any further
//! fields (colour, intensity, normals) are ignored. Fields are separated by
//! whitespace, commas or semicolons. Blank lines and lines starting with `#`
//! are skipped, and the first data line is taken as a header when none of
//! its first three fields is a number; a header with no data line after it
//! is an error naming it.

use anyhow::{bail, Result};

use super::{lines, show, strip_bom, text_of, Mesh, Point3};

/// Reads a text point list.
pub fn read_text(bytes: &[u8]) -> Result<Mesh> {
    let text = text_of(bytes)?;
    let mut vertices = Vec::new();
    let mut first = true;
    let mut header = None;
    for (i, line) in data_lines(text) {
        let fields: Vec<&str> = fields(line).collect();
        if std::mem::take(&mut first) && is_header(&fields) {
            header = Some(i);
            continue;
        }
        vertices.push(parse_point(&fields).map_err(|e| anyhow::anyhow!("line {i}: {e}"))?);
    }
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

/// True if the first data line of `bytes` holds at least three numbers, so
/// that a file with an unknown extension can still be read as text.
pub fn looks_numeric(bytes: &[u8]) -> bool {
    let bytes = strip_bom(bytes);
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(4096)]);
    let first = data_lines(&head).next();
    first.is_some_and(|(_, line)| {
        let fields: Vec<&str> = fields(line).collect();
        fields.len() >= 3 && fields[..3].iter().all(|f| f.parse::<f64>().is_ok())
    })
}

/// Non-blank, non-comment lines with their 1-based line numbers.
fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    lines(text)
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'))
}

fn fields(line: &str) -> impl Iterator<Item = &str> {
    line.split(|c: char| c == ',' || c == ';' || c.is_whitespace())
        .filter(|f| !f.is_empty())
}

fn is_header(fields: &[&str]) -> bool {
    fields.iter().take(3).all(|f| f.parse::<f64>().is_err())
}

fn parse_point(fields: &[&str]) -> Result<Point3> {
    if fields.len() < 3 {
        bail!("expected x, y and z, found {} field(s)", fields.len());
    }
    let mut p: Point3 = [0.0; 3];
    for (c, field) in p.iter_mut().zip(fields) {
        *c = field
            .parse()
            .map_err(|_| anyhow::anyhow!("'{field}' is not a number"))?;
    }
    if p.iter().any(|c| !c.is_finite()) {
        bail!("non-finite coordinate {}", show(&p));
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
    fn numeric_sniffing() {
        assert!(looks_numeric(b"# c\n1 2 3\n"));
        assert!(!looks_numeric(b"x y z\n1 2 3\n"));
        assert!(!looks_numeric(b"1 2\n"));
    }
}
