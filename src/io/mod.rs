//! Reading point clouds and meshes, writing results.
//!
//! [`read_cloud`] picks the reader from the file's content when the content
//! is unambiguous (a PLY or PCD header, OBJ `v` lines) and from its
//! extension otherwise, so a PLY file named `.txt` still reads as PLY.
//! Files named `.stl`, `.glb` or `.gltf` follow the mesh reader's rules
//! ([`MeshInput`]) instead: an STL header is free text and proves nothing.
//!
//! Every error names the file, then where in it (a line for text, an
//! element index for binary data) and what is wrong. Readers never panic on
//! bad input.
//!
//! NaN policy: PCD readers drop points with a non-finite coordinate and count
//! them, because organised PCD clouds mark empty pixels with NaN. In every
//! other format a non-finite coordinate is an error.

pub mod atomic;
pub mod edges_out;
pub(crate) mod float_text;
pub mod gltf_io;
mod hash;
pub mod labels;
pub mod mesh_out;
pub mod obj;
pub mod pcd;
pub mod ply;
pub mod stl;
pub mod text;

pub use mesh_out::{write_mesh, MeshFormat};

use std::path::Path;

use anyhow::{bail, Context, Result};

/// A point in 3D, in the file's own units.
pub type Point3 = [f64; 3];

/// The file formats meshtrim reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Stanford PLY, ASCII or binary.
    Ply,
    /// Point Cloud Library PCD, ASCII, binary or binary_compressed.
    Pcd,
    /// Wavefront OBJ (`v` and `f` lines).
    Obj,
    /// One point per line, the first three columns being x, y and z.
    Text,
    /// A mesh format that only meshes use (STL, glTF, GLB): its vertices
    /// are the cloud (a triangulated scan's own samples).
    MeshVertices,
}

impl Format {
    /// Lower-case name, as used in messages.
    pub fn name(self) -> &'static str {
        match self {
            Format::Ply => "ply",
            Format::Pcd => "pcd",
            Format::Obj => "obj",
            Format::Text => "text",
            Format::MeshVertices => "mesh vertices (stl, gltf, glb)",
        }
    }

    /// The format an extension names, if any.
    fn from_extension(ext: &str) -> Option<Format> {
        match ext.to_ascii_lowercase().as_str() {
            "ply" => Some(Format::Ply),
            "pcd" => Some(Format::Pcd),
            "obj" => Some(Format::Obj),
            "xyz" | "txt" | "csv" | "asc" | "pts" => Some(Format::Text),
            _ => None,
        }
    }
}

/// A point cloud as read from a file, in file order.
#[derive(Debug, Clone, PartialEq)]
pub struct Cloud {
    /// The points, all finite.
    pub points: Vec<Point3>,
    /// Per-point normals, when the file has them (PLY nx/ny/nz, PCD
    /// normal_x/normal_y/normal_z).
    pub normals: Option<Vec<Point3>>,
    /// Points dropped because a coordinate was NaN or infinite (PCD only).
    pub dropped_non_finite: usize,
    /// The format the file was read as.
    pub format: Format,
}

/// A mesh as read from a file: vertices in file order, faces triangulated.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// The vertices, all finite.
    pub vertices: Vec<Point3>,
    /// Per-vertex normals, when the file has them.
    pub normals: Option<Vec<Point3>>,
    /// Triangles as vertex indices, polygons split into fans; `None` when
    /// the file has no face element or `f` lines at all.
    pub faces: Option<Vec<[u32; 3]>>,
}

/// Reads a point cloud, choosing the reader by content and extension.
///
/// Fails, with the file name first in the message, on unreadable or
/// malformed files and on files with no points.
pub fn read_cloud(path: &Path) -> Result<Cloud> {
    read_cloud_inner(path).with_context(|| path.display().to_string())
}

/// Reads a mesh: PLY, OBJ, STL (ASCII or binary), glTF or GLB.
///
/// The faces are `None` if a PLY or OBJ file has none; STL and glTF always
/// give `Some`. A PLY range scan's `range_grid` gives faces (see
/// [`ply`]); [`read_cloud`] ignores it. See [`MeshInput`] for how the
/// reader is chosen.
pub fn read_mesh(path: &Path) -> Result<Mesh> {
    read_mesh_inner(path).with_context(|| path.display().to_string())
}

/// Reads a mesh that must have faces (for the commands that cut or clean
/// one); a file without faces is an error naming the file and `hint`.
pub fn read_mesh_with_faces(path: &Path, hint: &str) -> Result<trim::Mesh> {
    let read = read_mesh(path)?;
    let Some(faces) = read.faces else {
        bail!("{}: the file has no faces: {hint}", path.display());
    };
    Ok(trim::Mesh {
        vertices: read.vertices,
        faces,
    })
}

fn read_cloud_inner(path: &Path) -> Result<Cloud> {
    let bytes = std::fs::read(path).context("cannot read")?;
    let format = cloud_format(path, &bytes)?;
    let cloud = match format {
        Format::MeshVertices => from_mesh(parse_mesh(path, &bytes)?, format),
        Format::Ply => from_mesh(ply::read_ply(&bytes)?, format),
        Format::Obj => from_mesh(obj::read_obj(&bytes)?, format),
        Format::Pcd => pcd::read_pcd(&bytes)?,
        Format::Text => from_mesh(text::read_text(&bytes)?, format),
    };
    if cloud.points.is_empty() {
        bail!("no points in the file ({} format)", format.name());
    }
    Ok(cloud)
}

/// The reader for a cloud: [`detect_format`], except that the mesh-only
/// extensions `.stl`, `.glb` and `.gltf` go to the mesh reader's rules, as
/// in [`read_mesh`]. A binary STL's 80-byte header is free text, so one
/// starting `v ` or `VERSION` would otherwise be sniffed as OBJ or PCD.
fn cloud_format(path: &Path, bytes: &[u8]) -> Result<Format> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if ["stl", "glb", "gltf"].contains(&ext.to_ascii_lowercase().as_str()) {
        return Ok(match MeshInput::detect(path, bytes)? {
            MeshInput::Ply => Format::Ply,
            MeshInput::Obj => Format::Obj,
            MeshInput::Stl | MeshInput::Gltf => Format::MeshVertices,
        });
    }
    let error = match detect_format(path, bytes) {
        Ok(format) => return Ok(format),
        Err(error) => error,
    };
    // A triangulated scan (STL, glTF) is a cloud too: its vertices.
    match MeshInput::detect(path, bytes) {
        Ok(MeshInput::Stl | MeshInput::Gltf) => Ok(Format::MeshVertices),
        _ => Err(error),
    }
}

fn read_mesh_inner(path: &Path) -> Result<Mesh> {
    let bytes = std::fs::read(path).context("cannot read")?;
    parse_mesh(path, &bytes)
}

/// Parses a mesh file's bytes (`path` for its extension and, for glTF,
/// the directory of its buffers).
fn parse_mesh(path: &Path, bytes: &[u8]) -> Result<Mesh> {
    let mesh = match MeshInput::detect(path, bytes)? {
        MeshInput::Ply => ply::read_ply_mesh(bytes)?,
        MeshInput::Obj => obj::read_obj(bytes)?,
        MeshInput::Stl => stl::read_stl(bytes)?,
        MeshInput::Gltf => {
            let dir = path.parent().unwrap_or(Path::new(""));
            gltf_io::read_gltf(bytes, dir)?
        }
    };
    if mesh.vertices.is_empty() {
        bail!("no vertices in the file");
    }
    Ok(mesh)
}

/// The mesh readers, as [`read_mesh`] chooses them.
///
/// In order: the GLB magic `glTF` and a PLY header are recognised by
/// content; then the extensions `.stl`, `.glb` and `.gltf` decide (ASCII
/// or binary STL by content); then a binary STL whose size matches its
/// triangle count, an ASCII STL (`solid` then `facet`) and glTF JSON (an
/// object with `"asset"`) are recognised by content; then the point-cloud
/// rules of [`detect_format`] give PLY or OBJ.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshInput {
    /// Stanford PLY.
    Ply,
    /// Wavefront OBJ.
    Obj,
    /// STL, ASCII or binary.
    Stl,
    /// glTF 2.0, JSON or GLB.
    Gltf,
}

impl MeshInput {
    /// Chooses the mesh reader for a file, or fails naming the extension.
    pub fn detect(path: &Path, bytes: &[u8]) -> Result<MeshInput> {
        if gltf_io::is_glb(bytes) {
            return Ok(MeshInput::Gltf);
        }
        if sniff(bytes) == Some(Format::Ply) {
            return Ok(MeshInput::Ply);
        }
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        match ext.to_ascii_lowercase().as_str() {
            "stl" => return Ok(MeshInput::Stl),
            "glb" | "gltf" => return Ok(MeshInput::Gltf),
            _ => {}
        }
        if stl::is_exact_binary(bytes) || stl::looks_ascii(bytes) {
            return Ok(MeshInput::Stl);
        }
        if gltf_io::looks_like_json(bytes) {
            return Ok(MeshInput::Gltf);
        }
        match detect_format(path, bytes) {
            Ok(Format::Ply) => Ok(MeshInput::Ply),
            Ok(Format::Obj) => Ok(MeshInput::Obj),
            Ok(other) => bail!(
                "a mesh must be PLY, OBJ, STL, glTF or GLB, this is a {} point cloud",
                other.name()
            ),
            Err(_) => bail!(
                "unknown mesh format: the extension '{ext}' is not one of ply, obj, stl, gltf, \
                 glb, and the content is not recognised as any of them"
            ),
        }
    }
}

fn from_mesh(mesh: Mesh, format: Format) -> Cloud {
    Cloud {
        points: mesh.vertices,
        normals: mesh.normals,
        dropped_non_finite: 0,
        format,
    }
}

/// Chooses the reader for a file.
///
/// The PLY and PCD headers and OBJ `v` lines are recognised whatever the
/// extension says, because files get renamed. Otherwise the extension
/// decides, and a file with an unknown extension is read as text if its
/// first data line holds at least three numbers.
pub fn detect_format(path: &Path, bytes: &[u8]) -> Result<Format> {
    if let Some(format) = sniff(bytes) {
        return Ok(format);
    }
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if let Some(format) = Format::from_extension(ext) {
        return Ok(format);
    }
    if text::looks_numeric(bytes) {
        return Ok(Format::Text);
    }
    bail!(
        "unknown format: the extension '{ext}' is not one of ply, pcd, obj, xyz, txt, csv, asc, pts, \
         and the content is neither a PLY, PCD or OBJ header nor lines of numbers"
    )
}

/// Recognises a format from the start of the file, if it is unambiguous.
fn sniff(bytes: &[u8]) -> Option<Format> {
    let bytes = strip_bom(bytes);
    // `ply\r` covers `ply\r\n` and a lone `\r` (classic Mac OS).
    if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r") {
        return Some(Format::Ply);
    }
    // Only the start matters; a lossy view copes with binary data after it.
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(4096)]);
    // The PCD banner is a comment line, but a telling one.
    let telling = |l: &&str| !l.is_empty() && (!l.starts_with('#') || is_pcd_banner(l));
    let first = lines(&head).map(str::trim).find(telling)?;
    if is_pcd_banner(first) || first.starts_with("VERSION") || first.starts_with("FIELDS") {
        return Some(Format::Pcd);
    }
    let obj_line = |l: &str| l.starts_with("v ") || l.starts_with("v\t");
    if lines(&head).map(str::trim_start).any(obj_line) {
        return Some(Format::Obj);
    }
    None
}

fn is_pcd_banner(line: &str) -> bool {
    line.starts_with("# .PCD")
}

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
const FORMAT_PIECE: usize = 8192;
const FORMAT_WINDOW: usize = 64;

fn write_formatted_in_pieces(
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

/// Test support for the readers that parse text in pieces.
#[cfg(test)]
pub(crate) mod piece_tests {
    use std::fmt::Debug;

    /// A seeded draw: `below(n)` is a number under n.
    pub(crate) type Below<'a> = &'a mut dyn FnMut(u64) -> usize;

    /// Reads `cases` seeded random texts in one pass (`one_pass`) and in
    /// pieces of 1, 5, 16 and 64 bytes (`in_pieces`), and asserts the same
    /// outcome, error messages included. Text `case` is `start(below,
    /// case)`, then up to `max_lines` lines, line `l` being `line(below, l,
    /// case)` ended at random by `\n`, `\r\n` or `\r`. Returns how many
    /// texts failed to read, for the caller to check that both outcomes
    /// were tried.
    pub(crate) fn compare_with_one_pass<T: PartialEq + Debug>(
        seed: u64,
        cases: usize,
        max_lines: u64,
        start: impl Fn(Below, usize) -> String,
        line: impl Fn(Below, usize, usize) -> String,
        one_pass: impl Fn(&str) -> Result<T, String>,
        in_pieces: impl Fn(&str, usize) -> Result<T, String>,
    ) -> usize {
        let mut rng = testkit::synthetic::SplitMix64::new(seed);
        let mut below = |n: u64| (rng.next_u64() % n) as usize;
        let ends = ["\n", "\r\n", "\r"];
        let mut errors = 0;
        for case in 0..cases {
            let mut text = start(&mut below, case);
            for l in 0..below(max_lines) {
                text += &line(&mut below, l, case);
                text += ends[below(3)];
            }
            let want = one_pass(&text);
            for piece_bytes in [1, 5, 16, 64] {
                let got = in_pieces(&text, piece_bytes);
                assert_eq!(got, want, "pieces of {piece_bytes} bytes: {text:?}");
            }
            errors += usize::from(want.is_err());
        }
        errors
    }
}

#[cfg(test)]
mod tests {
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
}
