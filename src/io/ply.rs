//! PLY (Stanford polygon file format) reading and writing.
//!
//! A small reader of its own, because the PLY crates are unmaintained. It
//! reads the `ascii`, `binary_little_endian` and `binary_big_endian`
//! encodings with every scalar type, and walks every element of the file in
//! order, so elements before `vertex` (a scanner's `camera`, say) and list
//! properties (faces, `range_grid`) are skipped by their real sizes. From the
//! `vertex` element it keeps x, y, z and, when all three are present, the
//! normal nx, ny, nz; from the `face` element the `vertex_indices` (or
//! `vertex_index`) list, split into triangle fans. Read as a mesh, MeshLab's
//! textured form too: a face's `texcoord` list (u, v per corner) splits
//! the vertices read with two coordinates (`io/corners.rs`), each
//! `comment TextureFile` names an image, and a face's `texnumber` its
//! image ([`PlyTextures`]).
//!
//! # Range grids
//!
//! Single-view range scans (the Stanford bunny's `bun000.ply`, Cyberware
//! data) store connectivity as a `range_grid` element instead of faces:
//! `obj_info num_cols N` and `obj_info num_rows M` in the header, then
//! N·M entries, row by row, each a list of zero or one vertex index (zero:
//! no sample at that pixel). [`read_ply_mesh`] turns the grid into faces
//! when the file has no face element: each 2 × 2 block of entries with all
//! four present gives two triangles, split along the shorter diagonal in
//! 3D, and a block with three present gives one. All triangles have the
//! same orientation in the grid, and that orientation is then chosen for
//! the whole file so that the faces face +z, where the scanner is for
//! these files (the area-weighted sum of the face normals has z > 0; a
//! grid whose faces sum to z < 0 is flipped). A single view sees the side
//! of the object that faces the scanner, so there the outward normal
//! points toward the scanner: on `bun000.ply`, whose pose is the identity
//! in `bun.conf`, the vertex normals of the grid's faces agree in sign
//! with those of the reconstructed, outward-oriented `bun_zipper.ply`
//! (positive volume) at the nearest vertex for 40,234 of 40,245 vertices.
//! On the four bunny scans, counter-clockwise in (column, row) already
//! faces +z; the flip is for grids stored the other way up.
//! [`read_ply`] (point clouds) skips the grid, like any other element.
//!
//! # Reading in parallel
//!
//! The reader walks the file one value at a time, which handles every
//! layout PLY allows (an ASCII record over several lines, lists of any
//! length). The large elements are read at once and in parallel where
//! their layout allows it: the vertices when all their properties are
//! scalars (ASCII: one record per line, parsed in pieces of about 1 MiB;
//! binary: fixed-size records), and faces whose lists all have the same
//! length (triangles, quads; ASCII: a list alone on each line). Any other layout, and a line that is
//! not a record or data that ends early, falls back to the value-at-a-time
//! reading from the element's start; the checks made on what was read at
//! once (finite coordinates, vertex indices) give the same messages. The
//! tests compare the two readings on random files, errors included.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{anyhow, bail, Result};
use byteorder::{BigEndian, ByteOrder, LittleEndian, WriteBytesExt};
use rayon::prelude::*;

use super::{
    capacity, column_triples, columns_of_triples, cut_after_newlines, is_written_name,
    mixed_line_ending, next_line, show, strip_bom, truncated, unit_channel, Colours, HeaderEol,
    Mesh, Point3, ScalarField, PIECE_BYTES,
};

/// A PLY scalar type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scalar {
    /// `char` / `int8`.
    I8,
    /// `uchar` / `uint8`.
    U8,
    /// `short` / `int16`.
    I16,
    /// `ushort` / `uint16`.
    U16,
    /// `int` / `int32`.
    I32,
    /// `uint` / `uint32`.
    U32,
    /// `float` / `float32`.
    F32,
    /// `double` / `float64`.
    F64,
}

impl Scalar {
    /// The type a header names, with the sized aliases.
    pub fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    /// The header's name of the type.
    pub fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "char",
            Scalar::U8 => "uchar",
            Scalar::I16 => "short",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            Scalar::U32 => "uint",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }

    /// Whether the type is an integer one.
    pub fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }

    /// Whether this type stores `v`: an integer type exactly, `float`
    /// rounded but within its range, `double` anything.
    pub fn holds(self, v: f64) -> bool {
        let range = match self {
            Scalar::I8 => (i8::MIN.into(), i8::MAX.into()),
            Scalar::U8 => (0.0, u8::MAX.into()),
            Scalar::I16 => (i16::MIN.into(), i16::MAX.into()),
            Scalar::U16 => (0.0, u16::MAX.into()),
            Scalar::I32 => (i32::MIN.into(), i32::MAX.into()),
            Scalar::U32 => (0.0, u32::MAX.into()),
            Scalar::F32 => return !v.is_finite() || (v as f32).is_finite(),
            Scalar::F64 => return true,
        };
        v.fract() == 0.0 && (range.0..=range.1).contains(&v)
    }

    /// Appends `v`, a value this type holds, in little-endian binary.
    pub fn push_le(self, out: &mut Vec<u8>, v: f64) {
        match self {
            Scalar::I8 => out.push(v as i8 as u8),
            Scalar::U8 => out.push(v as u8),
            Scalar::I16 => out.extend((v as i16).to_le_bytes()),
            Scalar::U16 => out.extend((v as u16).to_le_bytes()),
            Scalar::I32 => out.extend((v as i32).to_le_bytes()),
            Scalar::U32 => out.extend((v as u32).to_le_bytes()),
            Scalar::F32 => out.extend((v as f32).to_le_bytes()),
            Scalar::F64 => out.extend(v.to_le_bytes()),
        }
    }

    /// Size in bytes in the binary encodings.
    pub fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    /// Decodes one value from exactly `self.size()` bytes.
    fn decode<B: ByteOrder>(self, b: &[u8]) -> f64 {
        match self {
            Scalar::I8 => f64::from(b[0] as i8),
            Scalar::U8 => f64::from(b[0]),
            Scalar::I16 => f64::from(B::read_i16(b)),
            Scalar::U16 => f64::from(B::read_u16(b)),
            Scalar::I32 => f64::from(B::read_i32(b)),
            Scalar::U32 => f64::from(B::read_u32(b)),
            Scalar::F32 => f64::from(B::read_f32(b)),
            Scalar::F64 => B::read_f64(b),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Ascii,
    BinaryLe,
    BinaryBe,
}

#[derive(Debug, Clone, PartialEq)]
enum Property {
    Scalar {
        name: String,
        ty: Scalar,
    },
    List {
        name: String,
        count: Scalar,
        item: Scalar,
    },
}

impl Property {
    fn name(&self) -> &str {
        match self {
            Property::Scalar { name, .. } | Property::List { name, .. } => name,
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

#[derive(Debug, Clone, PartialEq)]
struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Byte offset of the first byte after `end_header`'s line ending.
    body_start: usize,
    /// Number of header lines, so ASCII body lines can be numbered.
    lines: usize,
    /// `obj_info num_cols` and `obj_info num_rows`, as written; parsed
    /// only when a range grid is read.
    grid_size: [Option<String>; 2],
    /// MeshLab's `comment TextureFile NAME` lines' names, in order.
    texture_files: Vec<String>,
}

/// A PLY's texture images (MeshLab's `comment TextureFile`) and each
/// face's (its `texnumber`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlyTextures {
    /// The images, as paths from the current directory.
    pub files: Vec<PathBuf>,
    /// Each face's image, an index into `files`.
    pub faces: Vec<u32>,
}

/// Reads a PLY file: vertices, optional normals and optional faces. A
/// `range_grid` is skipped: this is the point-cloud reader.
pub fn read_ply(bytes: &[u8]) -> Result<Mesh> {
    read(bytes, false, Some(PIECE_BYTES))
}

/// Reads a PLY file as a mesh: like [`read_ply`], but a file with a
/// `range_grid` and no face element gets the grid's faces (see the module
/// doc).
pub fn read_ply_mesh(bytes: &[u8]) -> Result<Mesh> {
    let mut mesh = read(bytes, true, Some(PIECE_BYTES))?;
    take_texcoords(&mut mesh);
    Ok(mesh)
}

/// MeshLab's per-vertex texture coordinates, `texture_u` and
/// `texture_v`, as the mesh's texture coordinates (which every mesh
/// format writes) rather than two values of the file's own.
fn take_texcoords(mesh: &mut Mesh) {
    let at = |name: &str| mesh.scalars.iter().position(|f| f.name == name);
    let (Some(u), Some(v)) = (at("texture_u"), at("texture_v")) else {
        return;
    };
    // Per-corner coordinates, when the file has them too, were read
    // already (the vertices split by them): they are kept.
    if mesh.texcoords.is_some() {
        mesh.scalars
            .retain(|f| f.name != "texture_u" && f.name != "texture_v");
        return;
    }
    let finite = |c: f64| if c.is_finite() { c } else { 0.0 };
    let uv = mesh.scalars[u]
        .values
        .iter()
        .zip(&mesh.scalars[v].values)
        .map(|(&u, &v)| [finite(u), finite(v)])
        .collect();
    mesh.texcoords = Some(uv);
    mesh.scalars
        .retain(|f| f.name != "texture_u" && f.name != "texture_v");
}

/// `piece_bytes`: the size of the pieces in which the vertex and face
/// elements are parsed (ASCII) or decoded (binary) in parallel; `None`
/// reads them one value at a time, the reference the parallel reading is
/// tested against.
fn read(bytes: &[u8], grid: bool, piece_bytes: Option<usize>) -> Result<Mesh> {
    let bytes = strip_bom(bytes);
    let header = parse_header(bytes)?;
    let body = &bytes[header.body_start..];
    match header.encoding {
        Encoding::Ascii => {
            let text = std::str::from_utf8(body)
                .map_err(|e| anyhow!("the ASCII body is not text (byte {})", e.valid_up_to()))?;
            let mut values = AsciiValues::new(text, header.lines, piece_bytes);
            read_body(&header, &mut values, grid)
        }
        Encoding::BinaryLe => {
            let mut values = BinaryValues::<LittleEndian>::new(body, piece_bytes);
            read_body(&header, &mut values, grid)
        }
        Encoding::BinaryBe => {
            let mut values = BinaryValues::<BigEndian>::new(body, piece_bytes);
            read_body(&header, &mut values, grid)
        }
    }
}

/// Splits off the header and parses it.
fn parse_header(bytes: &[u8]) -> Result<Header> {
    let eol = HeaderEol::of(bytes);
    let end = find_end_header(bytes, eol)
        .ok_or_else(|| anyhow!("malformed PLY header: no 'end_header' line"))?;
    let text = std::str::from_utf8(&bytes[..end.0])
        .map_err(|_| anyhow!("malformed PLY header: it is not ASCII text"))?;
    // Split as find_end_header did.
    let header_lines = eol.text_lines(text);
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut lines = 0;
    let mut grid_size = [None, None];
    let mut texture_files = Vec::new();
    for (i, line) in header_lines.enumerate() {
        lines = i + 1;
        let at = |what: String| anyhow!("malformed PLY header: line {}: {what}", i + 1);
        let words: Vec<&str> = line.split_whitespace().collect();
        let comment = matches!(words.first(), Some(&("comment" | "obj_info")));
        if let Some(e) = mixed_line_ending(line).filter(|_| !comment) {
            return Err(at(e));
        }
        match words.as_slice() {
            ["ply"] if i == 0 => {}
            _ if i == 0 => return Err(at("the file does not start with 'ply'".into())),
            ["format", name, _version] => encoding = Some(parse_encoding(name).map_err(at)?),
            ["obj_info", "num_cols", n] => grid_size[0] = Some(n.to_string()),
            ["obj_info", "num_rows", n] => grid_size[1] = Some(n.to_string()),
            ["comment", "TextureFile", _, ..] => {
                let name = line.trim_start()["comment".len()..].trim_start();
                texture_files.push(name["TextureFile".len()..].trim().to_string());
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            ["element", name, count] => elements.push(Element {
                name: name.to_string(),
                count: count
                    .parse()
                    .map_err(|_| at(format!("'{count}' is not an element count")))?,
                properties: Vec::new(),
            }),
            ["property", rest @ ..] => elements
                .last_mut()
                .ok_or_else(|| at("a property before any element".into()))?
                .properties
                .push(parse_property(rest).map_err(at)?),
            ["end_header"] => break,
            _ => return Err(at(format!("cannot understand '{line}'"))),
        }
    }
    let encoding = encoding.ok_or_else(|| anyhow!("malformed PLY header: no 'format' line"))?;
    Ok(Header {
        encoding,
        elements,
        body_start: end.1,
        lines,
        grid_size,
        texture_files,
    })
}

/// Finds the `end_header` line: (end of its text, start of the body).
/// Every header line ends as the first does (see [`HeaderEol`]), so that
/// the body starts exactly after `end_header`'s own line ending.
fn find_end_header(bytes: &[u8], eol: HeaderEol) -> Option<(usize, usize)> {
    let mut start = 0;
    while let Some((line, next)) = eol.line(bytes, start) {
        if line.trim_ascii() == b"end_header" {
            return Some((start + line.len(), next));
        }
        start = next;
    }
    None
}

fn parse_encoding(name: &str) -> Result<Encoding, String> {
    match name {
        "ascii" => Ok(Encoding::Ascii),
        "binary_little_endian" => Ok(Encoding::BinaryLe),
        "binary_big_endian" => Ok(Encoding::BinaryBe),
        _ => Err(format!("unknown format '{name}'")),
    }
}

fn parse_property(words: &[&str]) -> Result<Property, String> {
    let ty = |name: &str| {
        Scalar::parse(name).ok_or_else(|| format!("unsupported property type '{name}'"))
    };
    match words {
        ["list", count, item, name] => Ok(Property::List {
            name: name.to_string(),
            count: ty(count)?,
            item: ty(item)?,
        }),
        [scalar, name] => Ok(Property::Scalar {
            name: name.to_string(),
            ty: ty(scalar)?,
        }),
        _ => Err(format!("cannot understand 'property {}'", words.join(" "))),
    }
}

/// A source of values, ASCII tokens or binary data.
trait Values {
    /// The next value of type `ty`, or `None` when the data ends.
    fn next(&mut self, ty: Scalar) -> Result<Option<f64>>;
    /// "line N: " for ASCII data, empty for binary data.
    fn line_prefix(&self) -> String;
    /// Marks the start of a record.
    fn begin_record(&mut self) {}
    /// Checks where record `i` of `element`, just read, ended.
    fn end_record(&mut self, _element: &str, _i: usize) -> Result<()> {
        Ok(())
    }
    /// Reads all records of `element`, whose properties are all scalars,
    /// at once and in parallel: for each triple of property indices in
    /// `columns`, that triple's values in every record, in order. `None`,
    /// with nothing read, when the data is not laid out as this handles
    /// (ASCII: one record per line; binary: the data ends early); the
    /// caller then reads the records one value at a time, which gives the
    /// same result or the first error in order.
    fn read_rows(&mut self, element: &Element, columns: &[[usize; 3]]) -> Option<Rows>;
    /// Reads all records of `element`, whose properties are scalars but
    /// for the list at index `list`, at once and in parallel, when every
    /// record's list has the same length n ≥ 3: the lists split into fans
    /// of n − 2 triangles from their first item, in order, as values.
    /// `None`, with nothing read, otherwise (as [`Values::read_rows`]).
    fn read_fans(&mut self, element: &Element, list: usize) -> Option<Fans>;
}

/// Lists read at once by [`Values::read_fans`].
struct Fans {
    /// `len − 2` triangles per list, in order.
    triangles: Vec<[f64; 3]>,
    /// The line of the first record, in ASCII data.
    first_line: Option<usize>,
}

/// Records read at once by [`Values::read_rows`].
struct Rows {
    /// One list per triple of columns asked for.
    triples: Vec<Vec<Point3>>,
    /// The line of the first record, in ASCII data.
    first_line: Option<usize>,
}

/// Whitespace-separated values, numbered by line for messages.
///
/// Values are a stream, so a record may run over several lines, but it
/// must end where a line ends: a record that ends inside a line has a
/// value too many or too few (a line of 4 values for 3 properties would
/// otherwise shift every later vertex by one value, silently).
struct AsciiValues<'a> {
    /// The text after the lines read so far; lines end with `\n`, `\r\n` or
    /// a lone `\r`, as in the other text readers.
    rest: &'a str,
    tokens: std::str::SplitAsciiWhitespace<'a>,
    line: usize,
    /// The current line's text, for counting its values in messages.
    text: &'a str,
    /// Values taken since `begin_record`.
    taken: usize,
    /// The first line of the current record and its text.
    first: (usize, &'a str),
    /// Pieces for [`Values::read_rows`]; `None` turns it off.
    piece_bytes: Option<usize>,
}

impl<'a> AsciiValues<'a> {
    fn new(text: &'a str, header_lines: usize, piece_bytes: Option<usize>) -> Self {
        Self {
            rest: text,
            tokens: "".split_ascii_whitespace(),
            line: header_lines,
            text: "",
            taken: 0,
            first: (header_lines, ""),
            piece_bytes,
        }
    }
}

impl Values for AsciiValues<'_> {
    fn next(&mut self, _ty: Scalar) -> Result<Option<f64>> {
        loop {
            if let Some(token) = self.tokens.next() {
                let value = token
                    .parse::<f64>()
                    .map_err(|_| anyhow!("line {}: '{token}' is not a number", self.line))?;
                if self.taken == 0 {
                    self.first = (self.line, self.text);
                }
                self.taken += 1;
                return Ok(Some(value));
            }
            let Some(line) = next_line(&mut self.rest) else {
                return Ok(None);
            };
            self.line += 1;
            self.text = line;
            self.tokens = line.split_ascii_whitespace();
        }
    }

    fn line_prefix(&self) -> String {
        format!("line {}: ", self.line)
    }

    fn begin_record(&mut self) {
        self.taken = 0;
    }

    fn end_record(&mut self, element: &str, i: usize) -> Result<()> {
        if self.tokens.clone().next().is_none() {
            return Ok(());
        }
        // Records start where a line starts (the one before ended with its
        // line), so the first line's values are all this record's: more
        // than it took on one line, or fewer on a line it ran past.
        let (line, text) = self.first;
        let found = text.split_ascii_whitespace().count();
        bail!(
            "line {line}: {element} {i} has {found} values, expected {}",
            self.taken
        )
    }

    fn read_rows(&mut self, element: &Element, columns: &[[usize; 3]]) -> Option<Rows> {
        let piece_bytes = self.piece_bytes?;
        // A record must start a line; the last one ended with its line.
        if self.tokens.clone().next().is_some() {
            return None;
        }
        let record = LineRecord {
            width: element.properties.len(),
            lead: None,
            columns,
        };
        let count = element.count;
        let (triples, end) = rows_in_pieces(self.rest, count, &record, piece_bytes)?;
        let first_line = Some(self.line + 1);
        self.rest = &self.rest[end..];
        self.line += count;
        Some(Rows {
            triples,
            first_line,
        })
    }

    /// A list alone on each line, all of the first line's length n: read
    /// as records of n + 1 values, the length's column checked.
    fn read_fans(&mut self, element: &Element, _list: usize) -> Option<Fans> {
        let piece_bytes = self.piece_bytes?;
        if element.properties.len() != 1 || self.tokens.clone().next().is_some() {
            return None;
        }
        let mut rest = self.rest;
        let first = next_line(&mut rest)?;
        let len = first.split_ascii_whitespace().next()?.parse::<f64>().ok()?;
        if !(3.0..=MAX_ASCII_LIST).contains(&len) || len.fract() != 0.0 {
            return None;
        }
        // The fans' triangles from the list's first item.
        let n = len as usize;
        let columns: Vec<[usize; 3]> = (1..n - 1).map(|w| [1, w + 1, w + 2]).collect();
        let record = LineRecord {
            width: n + 1,
            lead: Some(len),
            columns: &columns,
        };
        let count = element.count;
        let (mut fans, end) = rows_in_pieces(self.rest, count, &record, piece_bytes)?;
        let first_line = Some(self.line + 1);
        self.rest = &self.rest[end..];
        self.line += count;
        let triangles = match fans.len() {
            1 => fans.pop().unwrap_or_default(),
            _ => (0..count)
                .flat_map(|r| fans.iter().map(move |fan| fan[r]))
                .collect(),
        };
        Some(Fans {
            triangles,
            first_line,
        })
    }
}

/// The longest list [`AsciiValues::read_fans`] reads at once (its values
/// are buffered per line); longer ones are read one value at a time.
const MAX_ASCII_LIST: f64 = 1024.0;

/// Pieces parsed at once by [`rows_in_pieces`]: enough to keep the cores
/// busy, few enough that little is parsed past the element's end.
const PIECES_PER_BATCH: usize = 8;

/// What a line must hold for [`rows_in_pieces`], and what is kept of it.
struct LineRecord<'a> {
    /// Exactly this many numbers.
    width: usize,
    /// The first of them equal to this (a list's length), if given.
    lead: Option<f64>,
    /// The triples of values kept, by index in the line.
    columns: &'a [[usize; 3]],
}

/// The first `count` lines of `text` parsed in parallel as `record`s,
/// keeping the triples of values at its columns; with the byte offset
/// just after the last record's line. `None` when a line before that is
/// not such a record, or the text has fewer lines.
fn rows_in_pieces(
    text: &str,
    count: usize,
    record: &LineRecord,
    piece_bytes: usize,
) -> Option<(Vec<Vec<Point3>>, usize)> {
    let columns = record.columns;
    let mut triples = vec![Vec::with_capacity(capacity(count)); columns.len()];
    if count == 0 {
        return Some((triples, 0));
    }
    let mut rows = 0;
    let pieces = cut_after_newlines(text, piece_bytes);
    for batch in pieces.chunks(PIECES_PER_BATCH) {
        let limit = count - rows;
        let parsed: Vec<PieceRows> = batch
            .par_iter()
            .map(|piece| parse_rows(piece, record, limit))
            .collect();
        for (piece, parsed) in batch.iter().zip(parsed) {
            let take = parsed.rows.min(count - rows);
            for (all, some) in triples.iter_mut().zip(&parsed.triples) {
                all.extend_from_slice(&some[..take]);
            }
            rows += take;
            if rows == count {
                let start = piece.as_ptr() as usize - text.as_ptr() as usize;
                return Some((triples, start + end_of_lines(piece, take)));
            }
            if !parsed.complete {
                return None;
            }
        }
    }
    None
}

/// What [`parse_rows`] found in one piece.
struct PieceRows {
    triples: Vec<Vec<Point3>>,
    rows: usize,
    /// Whether every line of the piece was a record.
    complete: bool,
}

/// Up to `limit` lines of `piece` read as `record`s, stopping at the
/// first line that is not one.
fn parse_rows(piece: &str, record: &LineRecord, limit: usize) -> PieceRows {
    let columns = record.columns;
    let lead = record.lead;
    let mut triples = vec![Vec::new(); columns.len()];
    let mut record = vec![0.0; record.width];
    let mut rest = piece;
    let mut rows = 0;
    let mut complete = false;
    while rows < limit {
        let Some(line) = next_line(&mut rest) else {
            complete = true;
            break;
        };
        if !parse_record(line, &mut record) || lead.is_some_and(|l| record[0] != l) {
            break;
        }
        for (triple, at) in triples.iter_mut().zip(columns) {
            triple.push(at.map(|c| record[c]));
        }
        rows += 1;
    }
    PieceRows {
        triples,
        rows,
        complete,
    }
}

/// Whether `line` holds exactly `record.len()` numbers, read into `record`.
fn parse_record(line: &str, record: &mut [f64]) -> bool {
    let mut tokens = line.split_ascii_whitespace();
    for value in record.iter_mut() {
        match tokens.next().map(str::parse::<f64>) {
            Some(Ok(v)) => *value = v,
            _ => return false,
        }
    }
    tokens.next().is_none()
}

/// The byte offset just after the first `n` lines of `text` and their
/// endings.
fn end_of_lines(text: &str, n: usize) -> usize {
    let mut rest = text;
    for _ in 0..n {
        next_line(&mut rest);
    }
    text.len() - rest.len()
}

/// Where a binary record of fixed-length lists keeps the list's items.
struct ListLayout {
    /// Bytes per record.
    size: usize,
    /// Where the list's length is.
    count_at: usize,
    count: Scalar,
    item: Scalar,
    /// The list's length, the same in every record.
    len: usize,
}

impl ListLayout {
    /// The layout if every record's list is as long as the one in
    /// `first`, the data's first record; `None` when that list has fewer
    /// than 3 items (no triangle) or another property is a list too.
    fn of(
        element: &Element,
        list: usize,
        first: &[u8],
        decode: impl Fn(Scalar, &[u8]) -> f64,
    ) -> Option<Self> {
        let mut size = 0;
        let mut count_at = 0;
        let (mut count, mut item) = (Scalar::U8, Scalar::U8);
        for (k, property) in element.properties.iter().enumerate() {
            match *property {
                Property::Scalar { ty, .. } => size += ty.size(),
                Property::List {
                    count: c, item: i, ..
                } if k == list => {
                    (count_at, count, item) = (size, c, i);
                    size += c.size();
                }
                Property::List { .. } => return None,
            }
        }
        let len = decode(count, first.get(count_at..count_at + count.size())?);
        if !(3.0..=f64::from(u32::MAX)).contains(&len) || len.fract() != 0.0 {
            return None;
        }
        let len = len as usize;
        Some(ListLayout {
            size: size + len.checked_mul(item.size())?,
            count_at,
            count,
            item,
            len,
        })
    }
}

/// Packed binary values in byte order `B`.
struct BinaryValues<'a, B> {
    data: &'a [u8],
    order: std::marker::PhantomData<B>,
    /// The bytes of records [`Values::read_rows`] decodes per parallel
    /// task; with `None` it declines, and records are read one value at a
    /// time (the reference).
    piece_bytes: Option<usize>,
}

impl<'a, B> BinaryValues<'a, B> {
    fn new(data: &'a [u8], piece_bytes: Option<usize>) -> Self {
        Self {
            data,
            order: std::marker::PhantomData,
            piece_bytes,
        }
    }
}

impl<B: ByteOrder> Values for BinaryValues<'_, B> {
    fn next(&mut self, ty: Scalar) -> Result<Option<f64>> {
        let size = ty.size();
        if self.data.len() < size {
            return Ok(None);
        }
        let (value, rest) = self.data.split_at(size);
        self.data = rest;
        Ok(Some(ty.decode::<B>(value)))
    }

    fn line_prefix(&self) -> String {
        String::new()
    }

    fn read_rows(&mut self, element: &Element, columns: &[[usize; 3]]) -> Option<Rows> {
        let piece_bytes = self.piece_bytes?;
        let mut fields = Vec::with_capacity(element.properties.len());
        let mut size = 0;
        for property in &element.properties {
            let Property::Scalar { ty, .. } = *property else {
                return None;
            };
            fields.push((size, ty));
            size += ty.size();
        }
        let bytes = element.count.checked_mul(size)?;
        if size == 0 || self.data.len() < bytes {
            return None;
        }
        let (data, rest) = self.data.split_at(bytes);
        self.data = rest;
        let records_per_task = (piece_bytes / size).max(1);
        let triples = columns
            .iter()
            .map(|at| {
                let at = at.map(|c| fields[c]);
                let mut triple = Vec::new();
                data.par_chunks_exact(size)
                    .with_min_len(records_per_task)
                    .map(|record| at.map(|(offset, ty)| ty.decode::<B>(&record[offset..])))
                    .collect_into_vec(&mut triple);
                triple
            })
            .collect();
        Some(Rows {
            triples,
            first_line: None,
        })
    }

    fn read_fans(&mut self, element: &Element, list: usize) -> Option<Fans> {
        let piece_bytes = self.piece_bytes?;
        if element.count == 0 {
            return None;
        }
        let layout = ListLayout::of(element, list, self.data, |ty, b| ty.decode::<B>(b))?;
        let bytes = element.count.checked_mul(layout.size)?;
        let data = self.data.get(..bytes)?;
        let records = || {
            data.par_chunks_exact(layout.size)
                .with_min_len((piece_bytes / layout.size).max(1))
        };
        let count_of = |r: &[u8]| layout.count.decode::<B>(&r[layout.count_at..]);
        if !records().all(|r| count_of(r) == layout.len as f64) {
            return None;
        }
        self.data = &self.data[bytes..];
        let first_item = layout.count_at + layout.count.size();
        let corner = |r: &[u8], k: usize| {
            let at = first_item + k * layout.item.size();
            layout.item.decode::<B>(&r[at..])
        };
        let fan = move |r, w| [corner(r, 0), corner(r, w), corner(r, w + 1)];
        let fans = if layout.len == 3 {
            // Triangles, the usual case: written in place, not gathered.
            let mut fans = Vec::new();
            records().map(|r| fan(r, 1)).collect_into_vec(&mut fans);
            fans
        } else {
            let fan_of = |r| (1..layout.len - 1).map(move |w| fan(r, w));
            records().flat_map_iter(fan_of).collect()
        };
        Some(Fans {
            triangles: fans,
            first_line: None,
        })
    }
}

/// One record's values: scalars by property index (lists hold NaN there),
/// and the items of the one list property the caller asked for.
#[derive(Default)]
struct Record {
    scalars: Vec<f64>,
    list: Vec<f64>,
    /// The items of a second list asked for ([`read_element_lists`]).
    second: Vec<f64>,
}

/// What the body reader keeps from an element.
enum Role {
    /// The vertex element's columns the reader keeps.
    Vertex(VertexColumns),
    /// Index of the vertex index list property, and of MeshLab's
    /// per-corner texture coordinates (`texcoord`, u and v per corner).
    Face {
        list: usize,
        texcoord: Option<usize>,
        /// MeshLab's per-face texture number.
        texnumber: Option<usize>,
    },
    /// Index of a range grid's vertex index list property.
    RangeGrid {
        list: usize,
    },
    Skip,
}

fn read_body(header: &Header, values: &mut dyn Values, grid: bool) -> Result<Mesh> {
    let mut mesh = Mesh::default();
    // MeshLab's per-corner texture coordinates and per-face texture
    // numbers, read with a mesh only.
    let mut corner_texcoords = None;
    let mut texture_numbers = None;
    let mut vertex_count = None;
    let mut range_grid = None;
    for element in &header.elements {
        match role_of(element, grid)? {
            Role::Vertex(columns) => {
                if vertex_count.is_some() {
                    bail!("the file has two vertex elements");
                }
                vertex_count = Some(element.count);
                read_vertices(element, values, &columns, &mut mesh)?;
            }
            Role::Face {
                list,
                texcoord: Some(texcoord),
                texnumber,
            } if grid => {
                let faces = mesh.faces.get_or_insert_with(Vec::new);
                let read =
                    read_textured_faces(element, values, [list, texcoord], texnumber, faces)?;
                corner_texcoords = Some(read.texcoords);
                texture_numbers = read.numbers;
            }
            Role::Face { list, .. } => {
                let faces = mesh.faces.get_or_insert_with(Vec::new);
                read_faces(element, values, list, faces)?;
            }
            Role::RangeGrid { list } => {
                if range_grid.is_some() {
                    bail!("the file has two range_grid elements");
                }
                range_grid = Some(read_range_grid(element, values, list)?);
            }
            Role::Skip => skip_element(element, values)?,
        }
    }
    let vertex_count = vertex_count.ok_or_else(|| anyhow!("the file has no vertex element"))?;
    check_face_indices(mesh.faces.as_deref(), vertex_count)?;
    if let Some(entries) = range_grid {
        let [cols, rows] = grid_size(header, entries.len())?;
        check_grid_indices(&entries, vertex_count)?;
        if mesh.faces.is_none() {
            mesh.faces = Some(grid_faces(&entries, cols, rows, &mesh.vertices));
        }
    }
    if let Some(uv) = corner_texcoords {
        split_by_texcoords(&mut mesh, uv)?;
    }
    if grid && !header.texture_files.is_empty() {
        let files: Vec<PathBuf> = header.texture_files.iter().map(PathBuf::from).collect();
        let count = mesh.faces.as_ref().map_or(0, Vec::len);
        // A face's texture number names one of the files; any other (as
        // MeshLab's -1 for none) reads the first.
        let faces = match texture_numbers {
            Some(numbers) if numbers.len() == count => numbers
                .into_iter()
                .map(|n| if n < files.len() as u32 { n } else { 0 })
                .collect(),
            _ => vec![0; count],
        };
        mesh.materials = Some(super::Materials::Ply(PlyTextures { files, faces }));
    }
    Ok(mesh)
}

/// What [`read_textured_faces`] reads besides the faces.
struct TexturedFaces {
    /// The texture coordinates of each triangle's corners, `None` when a
    /// face's list does not hold two per corner (then none is kept).
    texcoords: Option<Vec<[f64; 2]>>,
    /// Each triangle's texture number, when the faces have one (−1 and
    /// other non-indices as `u32::MAX`).
    numbers: Option<Vec<u32>>,
}

/// Reads faces with MeshLab's `texcoord` list (u, v per corner) and,
/// when given, its `texnumber`, each polygon split into a fan as
/// [`read_faces`] does.
fn read_textured_faces(
    element: &Element,
    values: &mut dyn Values,
    lists: [usize; 2],
    texnumber: Option<usize>,
    faces: &mut Vec<[u32; 3]>,
) -> Result<TexturedFaces> {
    let mut uv = Some(Vec::new());
    let mut numbers = texnumber.map(|_| Vec::new());
    read_element_lists(element, values, lists, |i, record| {
        let corners: Vec<u32> = record
            .list
            .iter()
            .map(|&v| face_index(i, v))
            .collect::<Result<_>>()?;
        let texcoords = &record.second;
        if texcoords.len() != 2 * corners.len() {
            uv = None;
        }
        let at = |k: usize| [texcoords[2 * k], texcoords[2 * k + 1]];
        let number = texnumber.map(|k| whole_u32(record.scalars[k]).unwrap_or(u32::MAX));
        for w in 1..corners.len().saturating_sub(1) {
            faces.push([corners[0], corners[w], corners[w + 1]]);
            if let Some(uv) = uv.as_mut() {
                uv.extend([at(0), at(w), at(w + 1)]);
            }
            if let (Some(numbers), Some(n)) = (numbers.as_mut(), number) {
                numbers.push(n);
            }
        }
        Ok(())
    })?;
    Ok(TexturedFaces {
        texcoords: uv,
        numbers,
    })
}

/// A vertex index read as a float, checked.
fn face_index(face: usize, v: f64) -> Result<u32> {
    whole_u32(v).ok_or_else(|| anyhow!("face {face} has a bad vertex index {v}"))
}

/// A value read as a float that is a whole `u32` (an index, a count).
fn whole_u32(v: f64) -> Option<u32> {
    (v.fract() == 0.0 && (0.0..=f64::from(u32::MAX)).contains(&v)).then_some(v as u32)
}

/// The mesh's vertices split by the texture coordinates their corners
/// read (`uv`, three per triangle), as the OBJ reader splits them, the
/// coordinates kept per vertex; a non-finite one reads as 0. Nothing when
/// `uv` is `None`.
fn split_by_texcoords(mesh: &mut Mesh, uv: Option<Vec<[f64; 2]>>) -> Result<()> {
    let (Some(uv), Some(faces)) = (uv, mesh.faces.as_mut()) else {
        return Ok(());
    };
    let uv: Vec<[f64; 2]> = uv
        .into_iter()
        .map(|t| t.map(|c| if c.is_finite() { c } else { 0.0 }))
        .collect();
    let refs: Vec<[u32; 3]> = (0..faces.len() as u32)
        .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
        .collect();
    let refs = super::corners::by_value(refs, &uv);
    let split = super::corners::split_corners(mesh.vertices.len(), faces, Some(&refs), None)?;
    mesh.vertices = split.extend(std::mem::take(&mut mesh.vertices));
    mesh.normals = mesh.normals.take().map(|n| split.extend(n));
    if let Some(colours) = mesh.colours.as_mut() {
        colours.rgba = split.extend(std::mem::take(&mut colours.rgba));
    }
    for field in &mut mesh.scalars {
        field.values = split.extend(std::mem::take(&mut field.values));
    }
    mesh.texcoords = Some(split.read(&uv, 0, [0.0; 2]));
    Ok(())
}

/// Reads past an element the caller does not use. One without properties
/// holds no data, so there is nothing to read: walking its records would
/// consume nothing, and a header can claim 2^64 of them.
fn skip_element(element: &Element, values: &mut dyn Values) -> Result<()> {
    if element.properties.is_empty() {
        return Ok(());
    }
    read_element(element, values, None, |_, _| Ok(()))
}

fn role_of(element: &Element, grid: bool) -> Result<Role> {
    let find = |name: &str| {
        element
            .properties
            .iter()
            .position(|p| matches!(p, Property::Scalar { name: n, .. } if n == name))
    };
    match element.name.as_str() {
        "vertex" => {
            let xyz = match (find("x"), find("y"), find("z")) {
                (Some(x), Some(y), Some(z)) => [x, y, z],
                _ => bail!("the vertex element has no x, y and z properties"),
            };
            let normal = match (find("nx"), find("ny"), find("nz")) {
                (Some(x), Some(y), Some(z)) => Some([x, y, z]),
                _ => None,
            };
            let colour = colour_columns(element, &find);
            let scalars = scalar_columns(element, xyz, normal, colour);
            Ok(Role::Vertex(VertexColumns {
                xyz,
                normal,
                colour,
                scalars,
            }))
        }
        "face" => {
            let list = element.properties.iter().position(|p| {
                matches!(p, Property::List { .. })
                    && matches!(p.name(), "vertex_indices" | "vertex_index")
            });
            let texcoord = element
                .properties
                .iter()
                .position(|p| matches!(p, Property::List { .. }) && p.name() == "texcoord");
            let texnumber = find("texnumber");
            Ok(list.map_or(Role::Skip, |list| Role::Face {
                list,
                texcoord,
                texnumber,
            }))
        }
        "range_grid" if grid => {
            let list = element.properties.iter().position(|p| {
                matches!(p, Property::List { .. })
                    && matches!(p.name(), "vertex_indices" | "vertex_index")
            });
            Ok(list.map_or(Role::Skip, |list| Role::RangeGrid { list }))
        }
        _ => Ok(Role::Skip),
    }
}

/// The vertex element's columns the reader keeps.
struct VertexColumns {
    xyz: [usize; 3],
    normal: Option<[usize; 3]>,
    colour: Option<ColourColumns>,
    /// The other scalar properties, the file's own values.
    scalars: Vec<usize>,
}

/// The vertex element's scalar properties that are not its position,
/// normal or colour: the file's own values, the first of each name.
fn scalar_columns(
    element: &Element,
    xyz: [usize; 3],
    normal: Option<[usize; 3]>,
    colour: Option<ColourColumns>,
) -> Vec<usize> {
    let mut taken: Vec<usize> = xyz
        .into_iter()
        .chain(normal.into_iter().flatten())
        .collect();
    if let Some(colour) = colour {
        taken.extend(colour.rgb.into_iter().chain(colour.alpha));
    }
    let mut names = Vec::new();
    let mut columns = Vec::new();
    for (k, property) in element.properties.iter().enumerate() {
        let Property::Scalar { name, .. } = property else {
            continue;
        };
        if taken.contains(&k) || is_written_name(name) || names.contains(&name) {
            continue;
        }
        names.push(name);
        columns.push(k);
    }
    columns
}

/// The file's own values as read ([`ScalarField::read_as`]).
fn scalar_fields(element: &Element, columns: &[usize], values: Vec<Vec<f64>>) -> Vec<ScalarField> {
    columns
        .iter()
        .zip(values)
        .filter_map(|(&k, values)| match element.properties[k] {
            Property::Scalar { ref name, ty } => {
                Some(ScalarField::read_as(name.clone(), ty, values))
            }
            // scalar_columns keeps scalar properties only.
            Property::List { .. } => None,
        })
        .collect()
}

/// A vertex colour's columns: red, green, blue, and alpha if there is
/// one, with the factor that brings the properties' type to 0..1.
#[derive(Clone, Copy)]
struct ColourColumns {
    rgb: [usize; 3],
    alpha: Option<usize>,
    scale: f64,
}

impl ColourColumns {
    /// Red, green, blue and alpha in 0..1 (alpha 1 where there is none).
    fn rgba(&self, rgb: Point3, alpha: Option<f64>) -> [f64; 4] {
        let unit = |c: f64| unit_channel(c * self.scale);
        let [r, g, b] = rgb.map(unit);
        [r, g, b, alpha.map_or(1.0, unit)]
    }
}

/// The colour properties of a vertex element, `red green blue [alpha]`
/// (or `diffuse_red …`), all of one type: 8-bit integers are read as
/// 0..255, 16-bit ones as 0..65535, 32-bit ones as 0..255 (as some
/// writers use `int` for bytes), floats as 0..1.
fn colour_columns(
    element: &Element,
    find: &dyn Fn(&str) -> Option<usize>,
) -> Option<ColourColumns> {
    let named = |prefix: &str| {
        let rgb = ["red", "green", "blue"].map(|c| find(&format!("{prefix}{c}")));
        let [Some(r), Some(g), Some(b)] = rgb else {
            return None;
        };
        Some(([r, g, b], find(&format!("{prefix}alpha"))))
    };
    let (rgb, alpha) = named("").or_else(|| named("diffuse_"))?;
    let ty = |k: usize| match element.properties[k] {
        Property::Scalar { ty, .. } => ty,
        Property::List { item, .. } => item,
    };
    let first = ty(rgb[0]);
    if rgb.iter().chain(&alpha).any(|&k| ty(k) != first) {
        return None;
    }
    let scale = match first {
        Scalar::F32 | Scalar::F64 => 1.0,
        Scalar::I16 | Scalar::U16 => 1.0 / 65535.0,
        _ => 1.0 / 255.0,
    };
    Some(ColourColumns { rgb, alpha, scale })
}

fn read_vertices(
    element: &Element,
    values: &mut dyn Values,
    columns: &VertexColumns,
    mesh: &mut Mesh,
) -> Result<()> {
    let VertexColumns {
        xyz,
        normal,
        colour,
        ref scalars,
    } = *columns;
    if element
        .properties
        .iter()
        .all(|p| matches!(p, Property::Scalar { .. }))
    {
        let alpha = colour.and_then(|c| c.alpha).map(|a| [a; 3]);
        let triples: Vec<[usize; 3]> = std::iter::once(xyz)
            .chain(normal)
            .chain(colour.map(|c| c.rgb))
            .chain(alpha)
            .chain(column_triples(scalars))
            .collect();
        if let Some(rows) = values.read_rows(element, &triples) {
            return vertices_from_rows(element, rows, columns, mesh);
        }
    }
    mesh.vertices.reserve(capacity(element.count));
    let mut normals = normal.map(|_| Vec::with_capacity(capacity(element.count)));
    let mut colours = colour.map(|_| Vec::with_capacity(capacity(element.count)));
    let mut own = vec![Vec::with_capacity(capacity(element.count)); scalars.len()];
    read_element(element, values, None, |i, record| {
        let p = xyz.map(|k| record.scalars[k]);
        if p.iter().any(|c| !c.is_finite()) {
            bail!("vertex {i} has a non-finite coordinate {}", show(&p));
        }
        mesh.vertices.push(p);
        if let (Some(n), Some(out)) = (normal, normals.as_mut()) {
            out.push(n.map(|k| record.scalars[k]));
        }
        if let (Some(c), Some(out)) = (colour, colours.as_mut()) {
            let rgb = c.rgb.map(|k| record.scalars[k]);
            out.push(c.rgba(rgb, c.alpha.map(|k| record.scalars[k])));
        }
        for (out, &k) in own.iter_mut().zip(scalars) {
            out.push(record.scalars[k]);
        }
        Ok(())
    })?;
    mesh.scalars = scalar_fields(element, scalars, own);
    mesh.normals = normals;
    mesh.colours = colours.map(|rgba| Colours {
        rgba,
        alpha: colour.is_some_and(|c| c.alpha.is_some()),
    });
    Ok(())
}

/// The vertices (and normals, colours and the file's own values) of
/// records read at once; the same checks and messages as
/// [`read_vertices`]'s.
fn vertices_from_rows(
    element: &Element,
    rows: Rows,
    columns: &VertexColumns,
    mesh: &mut Mesh,
) -> Result<()> {
    let mut triples = rows.triples.into_iter();
    mesh.vertices = triples.next().unwrap_or_default();
    if columns.normal.is_some() {
        mesh.normals = triples.next();
    }
    if let Some(colour) = columns.colour {
        let rgb = triples.next().unwrap_or_default();
        let alpha = colour.alpha.and_then(|_| triples.next());
        let rgba = match alpha {
            Some(alpha) => rgb
                .iter()
                .zip(&alpha)
                .map(|(&c, a)| colour.rgba(c, Some(a[0])))
                .collect(),
            None => rgb.iter().map(|&c| colour.rgba(c, None)).collect(),
        };
        mesh.colours = Some(Colours {
            rgba,
            alpha: colour.alpha.is_some(),
        });
    }
    let own: Vec<Vec<Point3>> = triples.collect();
    let own = columns_of_triples(&own, columns.scalars.len());
    mesh.scalars = scalar_fields(element, &columns.scalars, own);
    let non_finite = |p: &Point3| p.iter().any(|c| !c.is_finite());
    if let Some(i) = mesh.vertices.iter().position(non_finite) {
        let line = rows
            .first_line
            .map_or(String::new(), |l| format!("line {}: ", l + i));
        bail!(
            "{line}vertex {i} has a non-finite coordinate {}",
            show(&mesh.vertices[i])
        );
    }
    Ok(())
}

fn read_faces(
    element: &Element,
    values: &mut dyn Values,
    list: usize,
    faces: &mut Vec<[u32; 3]>,
) -> Result<()> {
    if let Some(fans) = values.read_fans(element, list) {
        return faces_from_fans(&fans, element.count, faces);
    }
    faces.reserve(capacity(element.count));
    read_element(element, values, Some(list), |i, record| {
        let corners = record.list.iter().map(|&v| face_index(i, v));
        let corners: Vec<u32> = corners.collect::<Result<_>>()?;
        // A fan from the first corner; faces with fewer than three corners
        // enclose nothing and are dropped.
        for w in 1..corners.len().saturating_sub(1) {
            faces.push([corners[0], corners[w], corners[w + 1]]);
        }
        Ok(())
    })
}

/// The faces of lists read at once, `count` lists of equal length split
/// into fans; the same checks and messages as [`read_faces`]'s (the fans
/// visit each list's items in order, so the first bad one is found
/// first).
fn faces_from_fans(fans: &Fans, count: usize, faces: &mut Vec<[u32; 3]>) -> Result<()> {
    let (first_line, fans) = (fans.first_line, &fans.triangles);
    let is_bad = |v: &f64| whole_u32(*v).is_none();
    if let Some(t) = fans.par_iter().position_first(|c| c.iter().any(is_bad)) {
        let face = t / (fans.len() / count);
        let v = fans[t].iter().copied().find(is_bad).unwrap_or_default();
        let line = first_line.map_or(String::new(), |l| format!("line {}: ", l + face));
        bail!("{line}face {face} has a bad vertex index {v}");
    }
    faces.par_extend(fans.par_iter().map(|c| c.map(|v| v as u32)));
    Ok(())
}

/// A grid entry with no sample.
const NO_SAMPLE: u32 = u32::MAX;

/// The range grid's entries, [`NO_SAMPLE`] where the list is empty.
fn read_range_grid(element: &Element, values: &mut dyn Values, list: usize) -> Result<Vec<u32>> {
    let mut entries = Vec::with_capacity(capacity(element.count));
    read_element(element, values, Some(list), |i, record| {
        let entry = match record.list.as_slice() {
            [] => NO_SAMPLE,
            &[v] if v.fract() == 0.0 && (0.0..f64::from(NO_SAMPLE)).contains(&v) => v as u32,
            &[v] => bail!("range_grid entry {i} has a bad vertex index {v}"),
            more => bail!(
                "range_grid entry {i} lists {} vertices, at most 1 is allowed",
                more.len()
            ),
        };
        entries.push(entry);
        Ok(())
    })?;
    Ok(entries)
}

/// The grid's [columns, rows] from the header, checked against its size.
fn grid_size(header: &Header, entries: usize) -> Result<[usize; 2]> {
    let mut size = [0usize; 2];
    for (k, name) in ["num_cols", "num_rows"].into_iter().enumerate() {
        let text = header.grid_size[k]
            .as_deref()
            .ok_or_else(|| anyhow!("the range_grid needs an 'obj_info {name}' header line"))?;
        size[k] = text
            .parse()
            .map_err(|_| anyhow!("'obj_info {name} {text}' is not a count"))?;
    }
    let [cols, rows] = size;
    if cols.checked_mul(rows) != Some(entries) {
        bail!("the range_grid has {entries} entries, but num_cols × num_rows is {cols} × {rows}");
    }
    Ok(size)
}

fn check_grid_indices(entries: &[u32], vertices: usize) -> Result<()> {
    let bad = |&v: &u32| v != NO_SAMPLE && v as usize >= vertices;
    if let Some(i) = entries.iter().position(bad) {
        bail!(
            "range_grid entry {i} refers to vertex {}, but there are only {vertices} vertices",
            entries[i]
        );
    }
    Ok(())
}

/// Triangles of a range grid (see the module doc), facing +z.
fn grid_faces(entries: &[u32], cols: usize, rows: usize, vertices: &[Point3]) -> Vec<[u32; 3]> {
    let mut faces = Vec::new();
    for r in 0..rows.saturating_sub(1) {
        for c in 0..cols.saturating_sub(1) {
            let at = |r: usize, c: usize| entries[r * cols + c];
            // Counter-clockwise in (column, row): the same turn for every cell.
            let quad = [at(r, c), at(r, c + 1), at(r + 1, c + 1), at(r + 1, c)];
            cell_faces(quad, vertices, &mut faces);
        }
    }
    if facing_z(&faces, vertices) < 0.0 {
        for f in &mut faces {
            f.swap(1, 2);
        }
    }
    faces
}

/// The triangles of one grid cell, its corners in cyclic order.
fn cell_faces(quad: [u32; 4], vertices: &[Point3], faces: &mut Vec<[u32; 3]>) {
    let present: Vec<u32> = quad.into_iter().filter(|&v| v != NO_SAMPLE).collect();
    match *present.as_slice() {
        [a, b, c] => faces.push([a, b, c]),
        [a, b, c, d] => {
            let len2 = |i: u32, j: u32| {
                let (p, q) = (vertices[i as usize], vertices[j as usize]);
                (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>()
            };
            if len2(a, c) <= len2(b, d) {
                faces.extend([[a, b, c], [a, c, d]]);
            } else {
                faces.extend([[a, b, d], [b, c, d]]);
            }
        }
        _ => {}
    }
}

/// The z component of the faces' area-weighted normal sum (twice).
fn facing_z(faces: &[[u32; 3]], vertices: &[Point3]) -> f64 {
    faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|v| vertices[v as usize]);
            (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        })
        .sum()
}

fn check_face_indices(faces: Option<&[[u32; 3]]>, vertices: usize) -> Result<()> {
    for (t, face) in faces.unwrap_or_default().iter().enumerate() {
        if let Some(&v) = face.iter().find(|&&v| v as usize >= vertices) {
            bail!("triangle {t} refers to vertex {v}, but there are only {vertices} vertices");
        }
    }
    Ok(())
}

/// Reads every record of `element`, handing each to `keep` with its index.
fn read_element(
    element: &Element,
    values: &mut dyn Values,
    wanted_list: Option<usize>,
    keep: impl FnMut(usize, &Record) -> Result<()>,
) -> Result<()> {
    read_records(element, values, [wanted_list, None], keep)
}

/// [`read_element`] keeping the items of two lists, the second's in
/// [`Record::second`].
fn read_element_lists(
    element: &Element,
    values: &mut dyn Values,
    [first, second]: [usize; 2],
    keep: impl FnMut(usize, &Record) -> Result<()>,
) -> Result<()> {
    read_records(element, values, [Some(first), Some(second)], keep)
}

fn read_records(
    element: &Element,
    values: &mut dyn Values,
    wanted: [Option<usize>; 2],
    mut keep: impl FnMut(usize, &Record) -> Result<()>,
) -> Result<()> {
    let mut record = Record::default();
    for i in 0..element.count {
        values.begin_record();
        if !read_record(element, values, wanted, &mut record)? {
            return Err(truncated(element.count, &element.name, i));
        }
        values.end_record(&element.name, i)?;
        keep(i, &record).map_err(|e| anyhow!("{}{e}", values.line_prefix()))?;
    }
    Ok(())
}

/// Reads one record; false if the data ended before it was complete.
fn read_record(
    element: &Element,
    values: &mut dyn Values,
    [wanted_list, second_list]: [Option<usize>; 2],
    record: &mut Record,
) -> Result<bool> {
    record.scalars.clear();
    record.list.clear();
    record.second.clear();
    for (k, property) in element.properties.iter().enumerate() {
        match *property {
            Property::Scalar { ty, .. } => match values.next(ty)? {
                Some(v) => record.scalars.push(v),
                None => return Ok(false),
            },
            Property::List { count, item, .. } => {
                record.scalars.push(f64::NAN);
                let Some(n) = values.next(count)? else {
                    return Ok(false);
                };
                let n = list_len(n, element, values)?;
                for _ in 0..n {
                    let Some(v) = values.next(item)? else {
                        return Ok(false);
                    };
                    if wanted_list == Some(k) {
                        record.list.push(v);
                    } else if second_list == Some(k) {
                        record.second.push(v);
                    }
                }
            }
        }
    }
    Ok(true)
}

fn list_len(n: f64, element: &Element, values: &dyn Values) -> Result<usize> {
    if let Some(n) = whole_u32(n) {
        Ok(n as usize)
    } else {
        bail!(
            "{}a {} has a bad list length {n}",
            values.line_prefix(),
            element.name
        )
    }
}

/// Writes points as a binary little-endian PLY with double x, y, z.
pub fn write_points(w: &mut dyn Write, points: &[Point3], comment: &str) -> std::io::Result<()> {
    writeln!(w, "ply\nformat binary_little_endian 1.0\ncomment {comment}")?;
    writeln!(w, "element vertex {}", points.len())?;
    writeln!(w, "property double x\nproperty double y\nproperty double z")?;
    writeln!(w, "end_header")?;
    for p in points {
        for &c in p {
            w.write_f64::<LittleEndian>(c)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
