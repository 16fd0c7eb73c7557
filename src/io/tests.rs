//! Tests of the dispatch and the text helpers.

use super::text_lines::{plural, write_formatted_in_pieces, FORMAT_PIECE, FORMAT_WINDOW};
use super::*;

/// `words` splits as `str::split_whitespace` does, on random lines of
/// letters, every ASCII control and space character, and a few
/// non-ASCII ones (a no-break space, an ideographic space, an é).
#[test]
fn words_split_as_split_whitespace_does() {
    let mut rng = testkit::synthetic::SplitMix64::new(61);
    let alphabet: Vec<char> = (0u8..=32)
        .map(char::from)
        .chain(['a', 'b', '1', '.', '-', '\u{a0}', '\u{3000}', 'é', '\u{7f}'])
        .collect();
    for _ in 0..20_000 {
        let len = (rng.next_u64() % 12) as usize;
        let line: String = (0..len)
            .map(|_| alphabet[(rng.next_u64() % alphabet.len() as u64) as usize])
            .collect();
        let ours: Vec<&str> = words(&line).collect();
        let std: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(ours, std, "{line:?}");
    }
}

#[test]
fn content_beats_extension() {
    let p = Path::new("cloud.txt");
    assert_eq!(
        detect_format(p, b"ply\nformat ascii 1.0\n").unwrap(),
        Format::Ply
    );
    let pcd = b"# .PCD v0.7 - Point Cloud Data\nVERSION 0.7\n";
    assert_eq!(detect_format(p, pcd).unwrap(), Format::Pcd);
    assert_eq!(
        detect_format(p, b"VERSION 0.7\nFIELDS x y z\n").unwrap(),
        Format::Pcd
    );
    let obj = b"# comment\nv 1 2 3\nv 4 5 6\n";
    assert_eq!(detect_format(p, obj).unwrap(), Format::Obj);
}

#[test]
fn extension_then_numbers_then_error() {
    assert_eq!(
        detect_format(Path::new("a.CSV"), b"x,y,z\n").unwrap(),
        Format::Text
    );
    assert_eq!(
        detect_format(Path::new("a.dat"), b"1 2 3\n").unwrap(),
        Format::Text
    );
    let err = detect_format(Path::new("a.dat"), b"hello world\n").unwrap_err();
    assert!(err.to_string().contains("unknown format"), "{err}");
}

#[test]
fn a_byte_order_mark_does_not_hide_the_content() {
    let dat = Path::new("a.dat");
    let bom = |s: &str| format!("\u{feff}{s}").into_bytes();
    let format = |s: &str| detect_format(dat, &bom(s)).unwrap();
    assert_eq!(format("ply\nformat ascii 1.0\n"), Format::Ply);
    assert_eq!(format("# .PCD v0.7\nVERSION 0.7\n"), Format::Pcd);
    assert_eq!(format("v 1 2 3\n"), Format::Obj);
    assert_eq!(format("1 2 3\n"), Format::Text);
}

#[test]
fn formatting_in_parallel_pieces_is_the_one_thread_text() {
    use std::io::Write;
    let format = |out: &mut Vec<u8>, i: usize| {
        writeln!(out, "{},{:?}", i, i as f64 / 7.0).unwrap();
    };
    for n in [0, 1, 1000] {
        let mut want = Vec::new();
        for i in 0..n {
            format(&mut want, i);
        }
        for (piece, window) in [(1, 1), (7, 3), (64, 2), (FORMAT_PIECE, FORMAT_WINDOW)] {
            let mut got = Vec::new();
            write_formatted_in_pieces(&mut got, n, piece, window, format).unwrap();
            assert!(
                got == want,
                "{n} records, pieces of {piece}, windows of {window}"
            );
        }
    }
}

#[test]
fn lines_end_at_any_line_ending() {
    fn all(t: &str) -> Vec<&str> {
        lines(t).collect()
    }
    // Without a lone \r, the same as str::lines.
    for t in ["", "a", "a\n", "a\r\nb", "\n\nb\n", "a\r\n\r\n"] {
        assert_eq!(all(t), t.lines().collect::<Vec<_>>(), "{t:?}");
    }
    assert_eq!(all("a\rb\r\rc\r\nd\n"), ["a", "b", "", "c", "d"]);
}

#[test]
fn header_lines_end_as_the_first_does() {
    use HeaderEol::{Newline, Return};
    assert_eq!(HeaderEol::of(b"ply\nformat\r"), Newline);
    assert_eq!(HeaderEol::of(b"ply\r\nformat\r"), Newline);
    assert_eq!(HeaderEol::of(b"ply\rformat\r\n"), Return);
    assert_eq!(HeaderEol::of(b"ply"), Newline);
    // A binary body's first byte may be \n: it is not the line's.
    let bytes = b"ply\rend_header\r\n\x01";
    assert_eq!(Return.line(bytes, 4), Some((&b"end_header"[..], 15)));
    assert_eq!(Newline.line(b"a\r\nb", 0), Some((&b"a"[..], 3)));
    assert_eq!(Newline.line(b"a\r\nb", 3), None);
}

#[test]
fn plural_names() {
    assert_eq!(plural("vertex"), "vertices");
    assert_eq!(plural("face"), "faces");
    assert_eq!(plural("points"), "points");
}
