//! STL (stereolithography) meshes, ASCII and binary.
//!
//! STL stores every triangle with its own three corner positions and no
//! vertex indices, so the reader merges corners with exactly equal
//! positions (equal as `f64` after reading, so `-0` and `+0` are one
//! vertex) into shared vertices, numbered in order of first appearance.
//! Facet normals are ignored; positions are `f32` in binary files and read
//! as written in ASCII files.
//!
//! ASCII or binary is decided by content: a file whose size is exactly
//! `84 + 50 × n` for the triangle count `n` in its header is binary (even
//! when its header starts with `solid`, as some exporters write), else a
//! file starting with `solid` is ASCII, else it is binary and too short.

use crate::io::hash::HashMap;
use std::io::Write;

use anyhow::{anyhow, bail, Result};
use byteorder::{ByteOrder, LittleEndian, WriteBytesExt};
use rayon::prelude::*;

use super::{
    capacity, cut_after_newlines, lines, show, words, write_formatted, Mesh, Point3, PIECE_BYTES,
};

/// Size of a binary STL's header: 80 bytes of text, a u32 triangle count.
const HEADER: usize = 84;
/// Size of one binary triangle: normal, three corners, u16 attribute.
const RECORD: usize = 50;

/// Whether the bytes are a binary STL whose size matches its declared
/// triangle count exactly (a reliable sign, whatever the extension).
pub fn is_exact_binary(bytes: &[u8]) -> bool {
    bytes.len() >= HEADER && Some(bytes.len()) == binary_size(declared(bytes))
}

/// Whether the bytes start like an ASCII STL: `solid`, then a `facet` line
/// or `endsolid` soon after.
pub fn looks_ascii(bytes: &[u8]) -> bool {
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(1024)]);
    let mut words = head.split_whitespace();
    words.next() == Some("solid")
        && lines(&head)
            .skip(1)
            .map(str::trim_start)
            .any(|l| l.starts_with("facet") || l.starts_with("endsolid"))
}

/// Reads an STL file, ASCII or binary, merging equal corner positions.
pub fn read_stl(bytes: &[u8]) -> Result<Mesh> {
    if is_exact_binary(bytes) {
        return read_binary(bytes);
    }
    if bytes.trim_ascii_start().starts_with(b"solid") {
        return read_ascii(bytes);
    }
    read_binary(bytes)
}

fn declared(bytes: &[u8]) -> u32 {
    LittleEndian::read_u32(&bytes[80..84])
}

fn binary_size(triangles: u32) -> Option<usize> {
    (triangles as usize)
        .checked_mul(RECORD)
        .and_then(|b| b.checked_add(HEADER))
}

/// A position's coordinates as bits, hashed as three words (an array's
/// own `Hash` also writes its length, and hands the words over as bytes).
#[derive(PartialEq, Eq)]
struct PositionKey([u64; 3]);

impl PositionKey {
    fn of(p: Point3) -> Self {
        // Adding +0 turns -0 into +0, so the two (equal as f64) share a key.
        Self(p.map(|c| (c + 0.0).to_bits()))
    }
}

impl std::hash::Hash for PositionKey {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        for word in self.0 {
            state.write_u64(word);
        }
    }
}

/// Shares vertices between corners with equal positions.
struct Merger {
    mesh: Mesh,
    index: HashMap<PositionKey, u32>,
}

impl Merger {
    fn new(triangles: usize) -> Self {
        Self {
            mesh: Mesh {
                vertices: Vec::with_capacity(capacity(triangles / 2)),
                normals: None,
                colours: None,
                faces: Some(Vec::with_capacity(capacity(triangles))),
                ..Mesh::default()
            },
            index: HashMap::with_capacity_and_hasher(capacity(triangles / 2), Default::default()),
        }
    }

    fn vertex(&mut self, p: Point3) -> Result<u32> {
        match self.index.get(&PositionKey::of(p)) {
            Some(&i) => Ok(i),
            None => self.push_new(p, true),
        }
    }

    /// Adds `p` as the next vertex, to the map too when `remember`.
    fn push_new(&mut self, p: Point3, remember: bool) -> Result<u32> {
        let i = u32::try_from(self.mesh.vertices.len())
            .map_err(|_| anyhow!("more than {} distinct vertices", u32::MAX))?;
        self.mesh.vertices.push(p);
        if remember {
            self.index.insert(PositionKey::of(p), i);
        }
        Ok(i)
    }

    fn triangle(&mut self, corners: [Point3; 3]) -> Result<()> {
        let face = [
            self.vertex(corners[0])?,
            self.vertex(corners[1])?,
            self.vertex(corners[2])?,
        ];
        if let Some(faces) = self.mesh.faces.as_mut() {
            faces.push(face);
        }
        Ok(())
    }
}

fn read_binary(bytes: &[u8]) -> Result<Mesh> {
    if bytes.len() < HEADER {
        bail!(
            "not an STL file: it does not start with 'solid' (ASCII) and at {} bytes is \
             shorter than a binary STL's {HEADER}-byte header",
            bytes.len()
        );
    }
    let n = declared(bytes);
    let complete = (bytes.len() - HEADER) / RECORD;
    if (complete as u64) < u64::from(n) {
        bail!(
            "binary STL truncated: the header declares {n} triangles ({} bytes), the file has {} \
             bytes and ends in triangle {complete}",
            binary_size(n).map_or_else(|| "too many".to_string(), |s| s.to_string()),
            bytes.len()
        );
    }
    // Bytes after the last triangle (padding some exporters add) are ignored.
    let records = &bytes[HEADER..HEADER + n as usize * RECORD];
    read_records_in_pieces(records, triangles_per_piece(n as usize))
}

/// Reads the triangle records in pieces of `per_piece` triangles, each
/// merged on its own thread, then joined.
fn read_records_in_pieces(records: &[u8], per_piece: usize) -> Result<Mesh> {
    let pieces: Vec<Result<Merger>> = records
        .par_chunks(per_piece * RECORD)
        .enumerate()
        .map(|(j, piece)| merge_binary_piece(piece, j * per_piece))
        .collect();
    // The first bad triangle's message, whichever piece was read first.
    join_pieces(pieces.into_iter().collect::<Result<_>>()?)
}

/// Triangles below which an STL is merged in one piece.
const MIN_PIECE_TRIANGLES: usize = 1 << 16;

/// How many of `triangles` each thread merges: one piece per thread,
/// one piece for few triangles.
fn triangles_per_piece(triangles: usize) -> usize {
    triangles
        .div_ceil(rayon::current_num_threads())
        .max(MIN_PIECE_TRIANGLES)
}

/// The triangle records of one piece, the first being triangle `first`,
/// with their corners merged within the piece.
fn merge_binary_piece(records: &[u8], first: usize) -> Result<Merger> {
    let mut merger = Merger::new(records.len() / RECORD);
    for (t, record) in records.chunks_exact(RECORD).enumerate() {
        let corner = |k: usize| -> Point3 {
            let at = 12 + 12 * k;
            [0, 4, 8].map(|o| f64::from(LittleEndian::read_f32(&record[at + o..])))
        };
        let corners = [corner(0), corner(1), corner(2)];
        if let Some(p) = corners.iter().find(|p| p.iter().any(|c| !c.is_finite())) {
            bail!(
                "triangle {} has a non-finite coordinate {}",
                first + t,
                show(p)
            );
        }
        merger.triangle(corners)?;
    }
    Ok(merger)
}

/// Pieces merged each within itself, joined in order: a piece's vertices,
/// in its own order of first appearance, take the number of an equal
/// vertex of an earlier piece or the next new one. That is the numbering
/// one merger over all the triangles gives, however the triangles were
/// cut into pieces.
fn join_pieces(pieces: Vec<Merger>) -> Result<Mesh> {
    let mut pieces = pieces.into_iter();
    let Some(mut all) = pieces.next() else {
        return Ok(Merger::new(0).mesh);
    };
    let pieces: Vec<Merger> = pieces.collect();
    let vertices = |p: &Merger| p.mesh.vertices.len();
    all.mesh.vertices.reserve(pieces.iter().map(vertices).sum());
    // All but the last piece's new vertices go into the map.
    all.index
        .reserve(pieces.iter().rev().skip(1).map(vertices).sum());
    let faces: usize = pieces
        .iter()
        .map(|p| p.mesh.faces.as_ref().map_or(0, Vec::len))
        .sum();
    if let Some(all_faces) = all.mesh.faces.as_mut() {
        all_faces.reserve(faces);
    }
    let count = pieces.len();
    for (j, piece) in pieces.into_iter().enumerate() {
        // Looked up on every thread: the map only grows between pieces.
        let found: Vec<Option<u32>> = piece
            .mesh
            .vertices
            .par_iter()
            .with_min_len(PIECE_LOOKUPS)
            .map(|&p| all.index.get(&PositionKey::of(p)).copied())
            .collect();
        // The last piece's new vertices need no place in the map.
        let remember = j + 1 < count;
        let numbers = found
            .into_iter()
            .zip(&piece.mesh.vertices)
            .map(|(found, &p)| found.map_or_else(|| all.push_new(p, remember), Ok))
            .collect::<Result<Vec<u32>>>()?;
        if let (Some(faces), Some(new)) = (all.mesh.faces.as_mut(), &piece.mesh.faces) {
            faces.par_extend(new.par_iter().map(|f| f.map(|v| numbers[v as usize])));
        }
    }
    Ok(all.mesh)
}

/// Vertices a thread looks up at a time when pieces are joined.
const PIECE_LOOKUPS: usize = 4096;

/// Where the ASCII reader is in the `solid` grammar.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// Before `solid` or after `endsolid`.
    Outside,
    /// Inside a solid, between facets.
    Solid,
    /// After `facet normal …`, before `outer loop`.
    Facet,
    /// After `outer loop`, reading `vertex` lines.
    Loop,
    /// After `endloop`, before `endfacet`.
    EndLoop,
}

fn read_ascii(bytes: &[u8]) -> Result<Mesh> {
    read_ascii_in_pieces(bytes, PIECE_BYTES)
}

/// Reads an ASCII STL whose lines are read in parallel pieces of about
/// `piece_bytes` (first words, and vertices parsed), then walked in order
/// through the `solid` grammar.
fn read_ascii_in_pieces(bytes: &[u8], piece_bytes: usize) -> Result<Mesh> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        anyhow!(
            "not an ASCII STL (invalid UTF-8 at byte {}) nor a binary one (its size does not \
             match its triangle count)",
            e.valid_up_to()
        )
    })?;
    let pieces: Vec<Lines> = cut_after_newlines(text, piece_bytes)
        .into_par_iter()
        .map(Lines::read)
        .collect();
    // Each vertex line takes the next point, in any state, so that the
    // points stay with their lines.
    let mut vertices = pieces.iter().flat_map(Lines::vertices);
    let lines_read = pieces
        .iter()
        .flat_map(|piece| piece.kinds.iter().copied())
        .map(|kind| {
            (
                kind,
                (kind == Kind::Vertex).then(|| vertices.next()).flatten(),
            )
        });
    let triangles = walk(text, lines_read)?;
    merge_in_pieces(&triangles, triangles_per_piece(triangles.len()))
}

/// Triangles merged in pieces of `per_piece`, each on its own thread,
/// then joined: the mesh one merger over all of them gives.
fn merge_in_pieces(triangles: &[[Point3; 3]], per_piece: usize) -> Result<Mesh> {
    let pieces: Vec<Result<Merger>> = triangles
        .par_chunks(per_piece.max(1))
        .map(|piece| {
            let mut merger = Merger::new(piece.len());
            piece.iter().try_for_each(|&t| merger.triangle(t))?;
            Ok(merger)
        })
        .collect();
    join_pieces(pieces.into_iter().collect::<Result<_>>()?)
}

/// What the grammar needs of a piece's lines, read once: each line's first
/// word, and the `vertex` lines' points (or what is wrong with them).
struct Lines {
    kinds: Vec<Kind>,
    points: Vec<Point3>,
    /// (index among the piece's vertex lines, message), in order.
    errors: Vec<(usize, String)>,
}

impl Lines {
    fn read(piece: &str) -> Lines {
        let mut read = Lines {
            kinds: Vec::new(),
            points: Vec::new(),
            errors: Vec::new(),
        };
        for line in lines(piece) {
            let mut words = words(line);
            let kind = Kind::of(words.next(), &mut words);
            if kind == Kind::Vertex {
                let p = parse_xyz(words).unwrap_or_else(|e| {
                    read.errors.push((read.points.len(), e));
                    [0.0; 3]
                });
                read.points.push(p);
            }
            read.kinds.push(kind);
        }
        read
    }

    /// The vertex lines' points in order, or what is wrong with them.
    fn vertices(&self) -> impl Iterator<Item = Result<Point3, String>> + '_ {
        let mut errors = self.errors.iter().peekable();
        self.points
            .iter()
            .enumerate()
            .map(move |(k, &p)| match errors.next_if(|e| e.0 == k) {
                Some((_, e)) => Err(e.clone()),
                None => Ok(p),
            })
    }
}

/// A line's first word, as far as the grammar cares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Blank,
    Solid,
    /// `facet`, and whether `normal` follows.
    Facet(bool),
    /// `outer`, and whether `loop` follows.
    Outer(bool),
    Vertex,
    EndLoop,
    EndFacet,
    EndSolid,
    Other,
}

impl Kind {
    fn of<'a>(first: Option<&str>, rest: &mut impl Iterator<Item = &'a str>) -> Kind {
        match first {
            None => Kind::Blank,
            Some("solid") => Kind::Solid,
            Some("facet") => Kind::Facet(rest.next() == Some("normal")),
            Some("outer") => Kind::Outer(rest.next() == Some("loop")),
            Some("vertex") => Kind::Vertex,
            Some("endloop") => Kind::EndLoop,
            Some("endfacet") => Kind::EndFacet,
            Some("endsolid") => Kind::EndSolid,
            Some(_) => Kind::Other,
        }
    }
}

/// The `solid` grammar over the file's lines, in order: each line's kind,
/// with its point (or what is wrong with it) for a `vertex` line; messages
/// quote a wrong line from `text`. Gives the facets' corners in order.
fn walk(
    text: &str,
    lines_read: impl Iterator<Item = (Kind, Option<Result<Point3, String>>)>,
) -> Result<Vec<[Point3; 3]>> {
    let mut triangles = Vec::with_capacity(text.len() / 250);
    let mut state = State::Outside;
    let mut corners: Vec<Point3> = Vec::with_capacity(3);
    let mut facets = 0usize;
    let mut last = 0;
    for (i, (kind, vertex)) in lines_read.enumerate() {
        last = i + 1;
        let at = |e: String| anyhow!("line {}: {e}", i + 1);
        let expected = |what: &str| {
            let found = lines(text).nth(i).unwrap_or_default().trim();
            at(format!("expected {what}, found '{found}'"))
        };
        state = match (state, kind, vertex) {
            (_, Kind::Blank, _) => state,
            (State::Outside, Kind::Solid, _) => State::Solid,
            (State::Outside, _, _) => return Err(expected("'solid'")),
            (State::Solid, Kind::Facet(true), _) => State::Facet,
            (State::Solid, Kind::Facet(false), _) => {
                return Err(expected("'facet normal nx ny nz'"))
            }
            (State::Solid, Kind::EndSolid, _) => State::Outside,
            (State::Solid, _, _) => return Err(expected("'facet normal' or 'endsolid'")),
            (State::Facet, Kind::Outer(true), _) => State::Loop,
            (State::Facet, _, _) => return Err(expected("'outer loop'")),
            (State::Loop, Kind::Vertex, Some(p)) => {
                corners.push(p.map_err(at)?);
                State::Loop
            }
            (State::Loop, Kind::EndLoop, _) => {
                if corners.len() != 3 {
                    return Err(at(format!(
                        "facet {facets} has {} vertices, a triangle needs 3",
                        corners.len()
                    )));
                }
                triangles.push([corners[0], corners[1], corners[2]]);
                corners.clear();
                facets += 1;
                State::EndLoop
            }
            (State::Loop, _, _) => return Err(expected("'vertex x y z' or 'endloop'")),
            (State::EndLoop, Kind::EndFacet, _) => State::Solid,
            (State::EndLoop, _, _) => return Err(expected("'endfacet'")),
        };
    }
    match state {
        State::Outside => Ok(triangles),
        _ => bail!("line {last}: the file ends inside a solid (no 'endsolid' line)"),
    }
}

fn parse_xyz<'a>(mut words: impl Iterator<Item = &'a str>) -> Result<Point3, String> {
    let mut p: Point3 = [0.0; 3];
    for (k, c) in p.iter_mut().enumerate() {
        let word = words
            .next()
            .ok_or_else(|| format!("a vertex needs x, y and z, found {k} value(s)"))?;
        *c = word
            .parse()
            .map_err(|_| format!("'{word}' is not a number"))?;
    }
    if let Some(extra) = words.next() {
        return Err(format!(
            "unexpected '{extra}' after the vertex's x, y and z"
        ));
    }
    if p.iter().any(|c| !c.is_finite()) {
        return Err(format!("non-finite coordinate {}", show(&p)));
    }
    Ok(p)
}

/// Writes a binary STL: an 80-byte header naming meshtrim, the triangle
/// count, then per triangle its unit normal (from the corners, by the
/// right-hand rule; zero for a degenerate triangle) and corners as `f32`.
///
/// The caller checks that the face indices are in range, that there are
/// at most `u32::MAX` faces and that the coordinates fit in `f32`.
pub fn write_stl(
    w: &mut dyn Write,
    vertices: &[Point3],
    faces: &[[u32; 3]],
) -> std::io::Result<()> {
    let mut header = [b' '; 80];
    let title = b"binary STL written by meshtrim";
    header[..title.len()].copy_from_slice(title);
    w.write_all(&header)?;
    let count = u32::try_from(faces.len()).map_err(std::io::Error::other)?;
    w.write_u32::<LittleEndian>(count)?;
    write_formatted(w, faces.len(), |out, f| {
        let [a, b, c] = faces[f].map(|v| vertices[v as usize]);
        for n in unit_normal(a, b, c) {
            out.extend((n as f32).to_le_bytes());
        }
        for p in [a, b, c] {
            for coordinate in p {
                out.extend((coordinate as f32).to_le_bytes());
            }
        }
        out.extend([0, 0]);
    })
}

fn unit_normal(a: Point3, b: Point3, c: Point3) -> Point3 {
    let n = super::doubled_area([a, b, c]);
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len > 0.0 && len.is_finite() {
        n.map(|x| x / len)
    } else {
        [0.0; 3]
    }
}

#[cfg(test)]
mod tests;
