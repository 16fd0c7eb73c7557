//! Wavefront OBJ: `v`, `vt`, `vn` and `f` lines, and the material.
//!
//! A few lines of our own rather than `tobj`: tobj only returns vertices
//! that some face uses (re-indexed per object), so a face-less OBJ point
//! cloud comes back empty, and its errors carry no line numbers. Here every
//! `v` line is a vertex, in file order; `f` lines become triangle fans.
//! Vertex colours, `v x y z r g b` (MeshLab's and trimesh's extension,
//! channels in 0..1), are kept when every `v` line has them.
//!
//! Texture coordinates (`vt`) and normals (`vn`) belong to face corners,
//! so one position may be read with several. Read as a mesh
//! ([`read_obj_mesh`]), a `v` read with two texture coordinates (at a
//! chart's border) or two normals (at a hard edge) becomes one vertex per
//! pair, as glTF and PLY store them; each attribute is kept when every
//! face corner has one. Read as a cloud ([`read_obj`]), the points are the
//! `v` lines. The materials (`mtllib`, `usemtl`) are kept when every face
//! is under a `usemtl`. Groups, smoothing groups, lines and points are
//! ignored.

use std::path::Path;

use anyhow::{anyhow, bail, Result};

use rayon::prelude::*;

use super::{
    cut_after_newlines, lines, show, text_of, unit_channel, Colours, Mesh, ObjMaterial, Point3,
    PIECE_BYTES,
};

use super::corners::{by_value, split_corners, NONE};

/// Reads the vertices and faces of an OBJ file, one vertex per `v` line
/// (a cloud's points).
pub fn read_obj(bytes: &[u8]) -> Result<Mesh> {
    Ok(read_obj_in_pieces(bytes, PIECE_BYTES)?.into_cloud())
}

/// Reads an OBJ file as a mesh: a `v` read with several texture
/// coordinates or normals becomes one vertex per pair (the copies after
/// the `v` lines), each vertex with its own; the material's libraries
/// are named as found from `dir`, the file's directory.
pub fn read_obj_mesh(bytes: &[u8], dir: &Path) -> Result<Mesh> {
    read_obj_in_pieces(bytes, PIECE_BYTES)?.into_mesh(dir)
}

/// Parses pieces of the text in parallel: a first pass counts each
/// piece's `v`, `vt` and `vn` lines, so that a negative reference (counted
/// back from the latest one) resolves as in a one-pass reading; the
/// pieces are joined in order and the error reported is the first in the
/// file.
fn read_obj_in_pieces(bytes: &[u8], piece_bytes: usize) -> Result<ObjText> {
    let text = text_of(bytes)?;
    let pieces = cut_after_newlines(text, piece_bytes);
    let counts: Vec<Counts> = pieces.par_iter().map(|p| element_lines(p)).collect();
    let before: Vec<Counts> = counts
        .iter()
        .scan([0; 3], |total, n| {
            let start = *total;
            *total = std::array::from_fn(|k| total[k] + n[k]);
            Some(start)
        })
        .collect();
    let parsed: Vec<ObjPiece> = pieces
        .into_par_iter()
        .zip(before)
        .map(|(piece, before)| parse_piece(piece, before))
        .collect();
    let mut obj = ObjText::default();
    let mut line0 = 0;
    for piece in parsed {
        if let Some((i, e)) = &piece.error {
            bail!("line {}: {e}", line0 + i);
        }
        line0 += piece.lines;
        obj.append(piece);
    }
    obj.check_indices(text)?;
    Ok(obj)
}

/// Numbers of `v`, `vt` and `vn` lines.
type Counts = [usize; 3];

/// The `v`, `vt` and `vn` lines of a piece of text.
fn element_lines(text: &str) -> Counts {
    let mut counts = [0; 3];
    for line in lines(text) {
        match line.split_whitespace().next() {
            Some("v") => counts[0] += 1,
            Some("vt") => counts[1] += 1,
            Some("vn") => counts[2] += 1,
            _ => {}
        }
    }
    counts
}

/// An OBJ's elements as written, the corners' references resolved to
/// 0-based indices.
#[derive(Debug, Clone, PartialEq)]
struct ObjText {
    vertices: Vec<Point3>,
    /// The vertices' colours, until a vertex without one.
    colours: Option<Vec<[f64; 4]>>,
    texcoords: Vec<[f64; 2]>,
    normals: Vec<Point3>,
    /// `Some` once an `f` line is seen, even one that makes no triangle.
    faces: Option<Vec<[u32; 3]>>,
    /// The `vt` of each face's corners ([`NONE`] for none); `None` while
    /// no corner has one.
    corner_texcoords: Option<Vec<[u32; 3]>>,
    /// The `vn` of each face's corners, likewise.
    corner_normals: Option<Vec<[u32; 3]>>,
    /// The `mtllib` lines' file names.
    libraries: Vec<String>,
    /// Each `usemtl`: the number of faces before it, and the name.
    materials: Vec<(usize, String)>,
}

impl Default for ObjText {
    fn default() -> Self {
        ObjText {
            vertices: Vec::new(),
            colours: Some(Vec::new()),
            texcoords: Vec::new(),
            normals: Vec::new(),
            faces: None,
            corner_texcoords: None,
            corner_normals: None,
            libraries: Vec::new(),
            materials: Vec::new(),
        }
    }
}

/// What one piece of an OBJ holds; line numbers count from its start.
#[derive(Default)]
struct ObjPiece {
    text: ObjText,
    lines: usize,
    /// The piece's first error; parsing stops there.
    error: Option<(usize, String)>,
}

/// Parses a piece that follows `before` vertices, texture coordinates
/// and normals.
fn parse_piece(text: &str, before: Counts) -> ObjPiece {
    let mut piece = ObjPiece::default();
    for line in lines(text) {
        piece.lines += 1;
        if let Err(e) = piece.text.parse_line(line, before) {
            piece.error = Some((piece.lines, e.to_string()));
            break;
        }
    }
    piece
}

impl ObjText {
    /// Reads one line, after `before` elements of each kind in earlier
    /// pieces.
    fn parse_line(&mut self, line: &str, before: Counts) -> Result<()> {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let (p, colour) = parse_vertex(words)?;
                self.vertices.push(p);
                push_colour(&mut self.colours, colour);
            }
            Some("vt") => self.texcoords.push(parse_texcoord(words)?),
            Some("vn") => self.normals.push(parse_normal(words)?),
            Some("f") => {
                let defined = [
                    before[0] + self.vertices.len(),
                    before[1] + self.texcoords.len(),
                    before[2] + self.normals.len(),
                ];
                let corners = words
                    .map(|w| parse_corner(w, defined))
                    .collect::<Result<Vec<Corner>>>()?;
                self.add_fan(&corners);
            }
            Some("mtllib") => self.libraries.push(rest_of(line, "mtllib")),
            Some("usemtl") => {
                let faces = self.faces.as_ref().map_or(0, Vec::len);
                self.materials.push((faces, rest_of(line, "usemtl")));
            }
            _ => {}
        }
        Ok(())
    }

    /// Adds a polygon as a fan of triangles from its first corner.
    fn add_fan(&mut self, corners: &[Corner]) {
        let faces = self.faces.get_or_insert_with(Vec::new);
        let positions_only = corners.iter().all(|c| c[1] == NONE && c[2] == NONE);
        if positions_only && self.corner_texcoords.is_none() && self.corner_normals.is_none() {
            for w in 1..corners.len().saturating_sub(1) {
                faces.push([corners[0][0], corners[w][0], corners[w + 1][0]]);
            }
            return;
        }
        let before = faces.len();
        for w in 1..corners.len().saturating_sub(1) {
            let fan = [corners[0], corners[w], corners[w + 1]];
            faces.push(fan.map(|c| c[0]));
            for (k, list) in [&mut self.corner_texcoords, &mut self.corner_normals]
                .into_iter()
                .enumerate()
            {
                let refs = fan.map(|c| c[k + 1]);
                if list.is_none() && refs != [NONE; 3] {
                    *list = Some(vec![[NONE; 3]; before + w - 1]);
                }
                if let Some(list) = list {
                    list.push(refs);
                }
            }
        }
    }

    /// Appends a later piece.
    fn append(&mut self, piece: ObjPiece) {
        let more = piece.text;
        let faces_before = self.faces.as_ref().map_or(0, Vec::len);
        let faces_added = more.faces.as_ref().map_or(0, Vec::len);
        self.vertices.extend(more.vertices);
        self.colours = self
            .colours
            .take()
            .zip(more.colours)
            .map(|(mut all, more)| {
                all.extend(more);
                all
            });
        self.texcoords.extend(more.texcoords);
        self.normals.extend(more.normals);
        if let Some(faces) = more.faces {
            self.faces.get_or_insert_with(Vec::new).extend(faces);
        }
        append_corners(
            &mut self.corner_texcoords,
            more.corner_texcoords,
            faces_before,
            faces_added,
        );
        append_corners(
            &mut self.corner_normals,
            more.corner_normals,
            faces_before,
            faces_added,
        );
        self.libraries.extend(more.libraries);
        self.materials.extend(
            more.materials
                .into_iter()
                .map(|(faces, name)| (faces_before + faces, name)),
        );
    }

    /// Positive references may point forward, so they are checked at the
    /// end.
    fn check_indices(&self, text: &str) -> Result<()> {
        let faces = self.faces.as_deref().unwrap_or_default();
        let lists = [
            (Some(faces), self.vertices.len(), "vertex", "vertices"),
            (
                self.corner_texcoords.as_deref(),
                self.texcoords.len(),
                "texture coordinate",
                "texture coordinates",
            ),
            (
                self.corner_normals.as_deref(),
                self.normals.len(),
                "normal",
                "normals",
            ),
        ];
        for (refs, n, one, many) in lists {
            // A vertex is never NONE; the others are where a corner has none.
            let none_allowed = one != "vertex";
            for (t, face) in refs.unwrap_or_default().iter().enumerate() {
                let missing = |&&v: &&u32| !(none_allowed && v == NONE) && v as usize >= n;
                if let Some(&v) = face.iter().find(missing) {
                    // As written: 1-based, and in u64, where u32::MAX + 1 fits.
                    let written = u64::from(v) + 1;
                    let at =
                        line_of_triangle(text, t).map_or(String::new(), |l| format!("line {l}: "));
                    bail!(
                        "{at}triangle {t} refers to {one} {written}, but there are only {n} {many}"
                    );
                }
            }
        }
        Ok(())
    }

    /// The `v` lines as vertices, with the faces as written.
    fn into_cloud(self) -> Mesh {
        let colours = coloured(self.colours, self.vertices.len());
        Mesh {
            vertices: self.vertices,
            colours,
            faces: self.faces,
            ..Mesh::default()
        }
    }

    /// The mesh, its vertices split by the texture coordinates and normals
    /// their corners read (those every corner has).
    fn into_mesh(mut self, dir: &Path) -> Result<Mesh> {
        let material = self.material(dir);
        let Some(mut faces) = self.faces.take() else {
            return Ok(self.into_cloud());
        };
        let complete = |refs: Option<Vec<[u32; 3]>>| {
            refs.filter(|r| !faces.is_empty() && r.iter().flatten().all(|&i| i != NONE))
        };
        let corner_texcoords =
            complete(self.corner_texcoords.take()).map(|refs| by_value(refs, &self.texcoords));
        let corner_normals =
            complete(self.corner_normals.take()).map(|refs| by_value(refs, &self.normals));
        let split = split_corners(
            self.vertices.len(),
            &mut faces,
            corner_texcoords.as_deref(),
            corner_normals.as_deref(),
        )?;
        let colours = coloured(self.colours.take(), self.vertices.len()).map(|c| Colours {
            rgba: split.extend(c.rgba),
            alpha: c.alpha,
        });
        let texcoords = corner_texcoords.map(|_| split.read(&self.texcoords, 0, [0.0; 2]));
        let normals = corner_normals.map(|_| split.read(&self.normals, 1, [0.0; 3]));
        Ok(Mesh {
            vertices: split.extend(self.vertices),
            normals,
            colours,
            texcoords,
            materials: material.map(super::Materials::Obj),
            faces: Some(faces),
            ..Mesh::default()
        })
    }

    /// The faces' materials, when every face is under a `usemtl`.
    fn material(&self, dir: &Path) -> Option<ObjMaterial> {
        let faces = self.faces.as_ref().map_or(0, Vec::len);
        // A `usemtl` is in force up to the next.
        let (first, _) = self.materials.first()?;
        if faces == 0 || *first > 0 {
            return None;
        }
        let ends = self.materials.iter().skip(1).map(|(start, _)| *start);
        let mut names: Vec<String> = Vec::new();
        let mut by_face = Vec::with_capacity(faces);
        for ((start, name), end) in self.materials.iter().zip(ends.chain([faces])) {
            if end > *start {
                let index = match names.iter().position(|n| n == name) {
                    Some(i) => i,
                    None => {
                        names.push(name.clone());
                        names.len() - 1
                    }
                };
                by_face.resize(end, index as u32);
            }
        }
        Some(ObjMaterial {
            libraries: library_paths(&self.libraries, dir),
            names,
            faces: by_face,
        })
    }
}

/// The material libraries `mtllib` lines name, found from `dir`: a line
/// names one file when one by its whole text exists (a name with spaces),
/// else a file per word, as the format has it.
fn library_paths(lines: &[String], dir: &Path) -> Vec<std::path::PathBuf> {
    let mut paths = Vec::new();
    for line in lines {
        let whole = dir.join(line);
        if whole.is_file() {
            paths.push(whole);
        } else {
            paths.extend(line.split_whitespace().map(|name| dir.join(name)));
        }
    }
    paths
}

/// Appends a piece's corner references, filling [`NONE`] for the faces
/// of the side that has none.
fn append_corners(
    all: &mut Option<Vec<[u32; 3]>>,
    more: Option<Vec<[u32; 3]>>,
    faces_before: usize,
    faces_added: usize,
) {
    match (all.as_mut(), more) {
        (Some(all), Some(more)) => all.extend(more),
        (Some(all), None) => all.resize(faces_before + faces_added, [NONE; 3]),
        (None, Some(more)) => {
            let mut list = vec![[NONE; 3]; faces_before];
            list.extend(more);
            *all = Some(list);
        }
        (None, None) => {}
    }
}

/// The rest of a line after its keyword, trimmed: a file or material name
/// may hold spaces.
fn rest_of(line: &str, keyword: &str) -> String {
    let line = line.trim_start();
    line[keyword.len()..].trim().to_string()
}

/// The vertices' colours, when there are vertices and every one has one.
fn coloured(colours: Option<Vec<[f64; 4]>>, vertices: usize) -> Option<Colours> {
    colours
        .filter(|c| vertices > 0 && c.len() == vertices)
        .map(|rgba| Colours { rgba, alpha: false })
}

/// The line of the `f` line that gave triangle `t`, found again by counting
/// each face's fan (only on this error path, so nothing is kept per face).
fn line_of_triangle(text: &str, t: usize) -> Option<usize> {
    let mut before = 0;
    for (i, line) in lines(text).enumerate() {
        let mut words = line.split_whitespace();
        if words.next() == Some("f") {
            before += words.count().saturating_sub(2);
            if before > t {
                return Some(i + 1);
            }
        }
    }
    None
}

/// Keeps a vertex's colour, or drops them all at the first vertex
/// without one.
fn push_colour(colours: &mut Option<Vec<[f64; 4]>>, colour: Option<[f64; 4]>) {
    match (colours.as_mut(), colour) {
        (Some(list), Some(c)) => list.push(c),
        _ => *colours = None,
    }
}

/// `v x y z [w | r g b]`: the first three numbers, and the colour when
/// exactly three more numbers follow (clamped to 0..1).
fn parse_vertex<'a>(words: impl Iterator<Item = &'a str>) -> Result<(Point3, Option<[f64; 4]>)> {
    let mut words = words.peekable();
    let p: Point3 = parse_numbers(&mut words, "a vertex needs x, y and z")?;
    if p.iter().any(|c| !c.is_finite()) {
        bail!("non-finite coordinate {}", show(&p));
    }
    let rest: Vec<f64> = words.take(4).map_while(|w| w.parse().ok()).collect();
    let colour = match rest[..] {
        [r, g, b] if [r, g, b].iter().all(|c| c.is_finite()) => {
            let [r, g, b] = [r, g, b].map(unit_channel);
            Some([r, g, b, 1.0])
        }
        _ => None,
    };
    Ok((p, colour))
}

/// `vt u [v [w]]`: u and v (0 when absent), finite.
fn parse_texcoord<'a>(mut words: impl Iterator<Item = &'a str>) -> Result<[f64; 2]> {
    let u: [f64; 1] = parse_numbers(&mut words, "a texture coordinate needs u")?;
    let v = match words.next() {
        Some(word) => parse_number(word)?,
        None => 0.0,
    };
    let uv = [u[0], v];
    if uv.iter().any(|c| !c.is_finite()) {
        bail!("non-finite texture coordinate ({}, {})", uv[0], uv[1]);
    }
    Ok(uv)
}

/// `vn x y z`; a non-finite normal is kept (carried as no direction).
fn parse_normal<'a>(mut words: impl Iterator<Item = &'a str>) -> Result<Point3> {
    parse_numbers(&mut words, "a normal needs x, y and z")
}

/// The first `N` words as numbers; `needs` says what is missing.
fn parse_numbers<'a, const N: usize>(
    words: &mut impl Iterator<Item = &'a str>,
    needs: &str,
) -> Result<[f64; N]> {
    let mut values = [0.0; N];
    for (k, c) in values.iter_mut().enumerate() {
        let word = words
            .next()
            .ok_or_else(|| anyhow!("{needs}, found {k} value(s)"))?;
        *c = parse_number(word)?;
    }
    Ok(values)
}

fn parse_number(word: &str) -> Result<f64> {
    word.parse()
        .map_err(|_| anyhow!("'{word}' is not a number"))
}

/// A face corner's `v`, `vt` and `vn`, 0-based ([`NONE`] where absent).
type Corner = [u32; 3];

/// A face corner `v`, `v/vt`, `v//vn` or `v/vt/vn`, each 1-based or
/// negative (counted back from the latest of its kind, `defined` of each
/// so far).
fn parse_corner(word: &str, defined: Counts) -> Result<Corner> {
    // Most corners are a vertex alone.
    if !word.contains('/') {
        return Ok([reference(word, word, defined[0], 0)?, NONE, NONE]);
    }
    let mut parts = word.split('/');
    let mut corner = [NONE; 3];
    for k in 0..3 {
        match parts.next() {
            Some("") if k > 0 => {}
            Some(part) => corner[k] = reference(part, word, defined[k], k)?,
            None if k > 0 => {}
            None => bail!("'{word}' is not a vertex reference"),
        }
    }
    if parts.next().is_some() {
        bail!("'{word}' is not a vertex reference");
    }
    Ok(corner)
}

/// What a corner's references refer to, by their place in it.
const KINDS: [&str; 3] = ["vertex", "texture coordinate", "normal"];

/// One 1-based or negative reference to the `defined` elements of kind
/// `k` ([`KINDS`]) so far; 0-based on return.
fn reference(part: &str, word: &str, defined: usize, k: usize) -> Result<u32> {
    let n: i64 = part
        .parse()
        .map_err(|_| anyhow!("'{word}' is not a vertex reference"))?;
    let index = if n < 0 { defined as i64 + n } else { n - 1 };
    // A vertex may be u32::MAX (and is then found missing with the
    // count); for the others it stands for "none".
    let last = if k == 0 { u32::MAX } else { u32::MAX - 1 };
    if n == 0 || index < 0 || index > i64::from(last) {
        bail!("face refers to {} {n}, which does not exist", KINDS[k]);
    }
    Ok(index as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one-pass reading the pieces must match.
    fn read_obj_serial(bytes: &[u8]) -> Result<ObjText> {
        let text = text_of(bytes)?;
        let mut obj = ObjText::default();
        for (i, line) in lines(text).enumerate() {
            obj.parse_line(line, [0; 3])
                .map_err(|e| anyhow!("line {}: {e}", i + 1))?;
        }
        obj.check_indices(text)?;
        Ok(obj)
    }

    /// Random OBJ texts (negative and forward references, polygons,
    /// comments, every line ending, bad lines) read in pieces of a few
    /// bytes give what the one-pass reading gives.
    #[test]
    fn pieces_read_as_one_pass_does() {
        let outcome = |m: Result<ObjText>| m.map_err(|e| e.to_string());
        let errors = crate::io::piece_tests::compare_with_one_pass(
            41,
            2000,
            25,
            |_, _| String::new(),
            |below, l, case| match below(18) {
                // Coloured in most texts, so that some keep their colours.
                _ if case % 3 > 0 && below(40) > 0 => {
                    format!("v {l} {case} {} 0.{} 1 0", below(9), below(10))
                }
                0 => "# comment".to_string(),
                1 => format!("vn 0 0 {}", below(3)),
                2 => "v 1 x 3".to_string(),
                3 => format!("f {} {} {}", below(6) + 1, below(6) + 1, below(6) + 1),
                4 => format!("f -1 -{} 1/2/3 {}//-1", below(4) + 1, below(5) + 1),
                5 => "f 1 0 2".to_string(),
                6 => "f 1 2".to_string(),
                7 => String::new(),
                8 => format!("vt 0.{} {}", below(10), below(2)),
                9 => format!("usemtl m{}", below(2)),
                10 => format!("mtllib lib{}.mtl", below(2)),
                11 => format!("f 1/{} -1/-1 2/-{}/1", below(3) + 1, below(3) + 1),
                _ => format!("v {l} {case} {}", below(9)),
            },
            |text| outcome(read_obj_serial(text.as_bytes())),
            |text, piece_bytes| outcome(read_obj_in_pieces(text.as_bytes(), piece_bytes)),
        );
        assert!(
            (400..1600).contains(&errors),
            "{errors} errors in 2000 cases"
        );
    }

    #[test]
    fn colours_kept_when_every_vertex_has_one() {
        let coloured = read_obj(b"v 0 0 0 1 0.5 0\nv 1 0 0 2 -1 0.25\nf 1 2 1\n").unwrap();
        assert_eq!(
            coloured.colours,
            Some(Colours {
                rgba: vec![[1.0, 0.5, 0.0, 1.0], [1.0, 0.0, 0.25, 1.0]],
                alpha: false
            })
        );
        for partly in ["v 0 0 0 1 0.5 0\nv 1 0 0\n", "v 0 0 0 1 0.5 0\nv 1 0 0 1\n"] {
            assert_eq!(
                read_obj(partly.as_bytes()).unwrap().colours,
                None,
                "{partly}"
            );
        }
    }

    #[test]
    fn faceless_cloud_keeps_every_vertex() {
        let mesh = read_obj(b"# cloud\nv 1 2 3\nv 4 5 6 1 0 0\nvn 0 0 1\nv 7 8 9\n").unwrap();
        assert_eq!(
            mesh.vertices,
            vec![[1., 2., 3.], [4., 5., 6.], [7., 8., 9.]]
        );
        assert_eq!(mesh.faces, None);
    }

    #[test]
    fn faces_all_corner_forms() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvn 0 0 1\n\
                    f 1/1 2//1 3/2/1 -1\nf 1 2 3\n";
        let mesh = read_obj(text.as_bytes()).unwrap();
        assert_eq!(mesh.faces.unwrap(), vec![[0, 1, 2], [0, 2, 3], [0, 1, 2]]);
    }

    fn mesh(text: &str) -> Mesh {
        read_obj_mesh(text.as_bytes(), Path::new("dir")).unwrap()
    }

    const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

    #[test]
    fn a_vertex_read_with_two_texture_coordinates_is_split() {
        // Vertex 1 and 3 are on a chart's border: the second face reads
        // them with other coordinates.
        let m = mesh(&format!(
            "{SQUARE}vt 0 0\nvt 1 0\nvt 1 1\nvt 5 5\nvt 6 6\nf 1/1 2/2 3/3\nf 1/4 3/5 4/4\n"
        ));
        assert_eq!(m.vertices.len(), 6);
        assert_eq!(m.vertices[4..], [[0.0; 3], [1.0, 1.0, 0.0]]);
        assert_eq!(m.faces.unwrap(), vec![[0, 1, 2], [4, 5, 3]]);
        let uv = m.texcoords.unwrap();
        assert_eq!(
            uv,
            vec![[0., 0.], [1., 0.], [1., 1.], [5., 5.], [5., 5.], [6., 6.]]
        );
        assert_eq!(m.normals, None);
    }

    #[test]
    fn equal_values_under_other_indices_do_not_split() {
        let m = mesh(&format!(
            "{SQUARE}vn 0 0 1\nvn 0 0 1\nvt 0 0\nf 1/1/1 2/1/1 3/1/1\nf 1/1/2 3/1/2 4/1/2\n"
        ));
        assert_eq!(m.vertices.len(), 4);
        assert_eq!(m.normals.unwrap(), vec![[0.0, 0.0, 1.0]; 4]);
        assert_eq!(m.texcoords.unwrap(), vec![[0.0, 0.0]; 4]);
    }

    #[test]
    fn flat_normals_split_every_shared_vertex() {
        let m = mesh(&format!(
            "{SQUARE}vn 0 0 1\nvn 0 1 0\nf 1//1 2//1 3//1\nf 1//2 3//2 4//2\n"
        ));
        assert_eq!(m.faces.unwrap(), vec![[0, 1, 2], [4, 5, 3]]);
        let normals = m.normals.unwrap();
        assert_eq!(normals[4], [0.0, 1.0, 0.0]);
        assert_eq!(m.texcoords, None);
    }

    #[test]
    fn an_attribute_some_corner_lacks_is_dropped_and_splits_nothing() {
        let m = mesh(&format!(
            "{SQUARE}vt 0 0\nvt 1 1\nf 1/1 2/1 3/1\nf 1/2 3 4\n"
        ));
        assert_eq!(m.vertices.len(), 4);
        assert_eq!(m.texcoords, None);
        // A vertex no face uses reads (0, 0).
        let m = mesh(&format!("{SQUARE}v 9 9 9\nvt 0.5 1\nf 1/1 2/1 3/1\n"));
        assert_eq!(m.texcoords.unwrap()[3..], [[0.0, 0.0], [0.0, 0.0]]);
        // As a cloud, the points are the `v` lines, whatever the corners.
        let cloud =
            read_obj(format!("{SQUARE}vt 0 0\nvt 1 1\nf 1/1 2/1 3/1\nf 1/2 3/1 4/1\n").as_bytes());
        assert_eq!(cloud.unwrap().vertices.len(), 4);
    }

    #[test]
    fn the_materials_are_kept_when_every_face_has_one() {
        let faces = "f 1 2 3\nf 1 3 4\n";
        let with = |text: &str| match mesh(&format!("{SQUARE}mtllib a.mtl\n{text}")).materials {
            Some(crate::io::Materials::Obj(material)) => Some(material),
            _ => None,
        };
        let material = with(&format!("g x\nusemtl skin\n{faces}usemtl skin\n")).unwrap();
        assert_eq!(material.names, vec!["skin"]);
        assert_eq!(material.faces, vec![0, 0]);
        assert_eq!(material.libraries, vec![Path::new("dir/a.mtl")]);
        // A material switched to and back before any face, or named
        // after the last, is not used.
        let material = with(
            "usemtl a\nusemtl skin\nf 1 2 3 4\nusemtl b\nf 1 3 4\nusemtl skin\nf 1 2 3\nusemtl c\n",
        );
        let material = material.unwrap();
        assert_eq!(material.names, vec!["skin", "b"]);
        assert_eq!(material.faces, vec![0, 0, 1, 0]);
        assert_eq!(with("f 1 2 3\nusemtl b\nf 1 3 4\n"), None);
        assert_eq!(with(faces), None);
    }

    #[test]
    fn texture_and_normal_references_are_checked() {
        let e = |t: &str| {
            read_obj(format!("{SQUARE}{t}").as_bytes())
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            e("vt 0 0\nf 1/1 2/2 3/1\n"),
            "line 6: triangle 0 refers to texture coordinate 2, but there are only 1 texture coordinates"
        );
        assert_eq!(
            e("f 1//-1 2 3\n"),
            "line 5: face refers to normal -1, which does not exist"
        );
        assert_eq!(e("vt x\n"), "line 5: 'x' is not a number");
        assert_eq!(
            e("vt\n"),
            "line 5: a texture coordinate needs u, found 0 value(s)"
        );
        assert_eq!(
            e("vt 0 inf\n"),
            "line 5: non-finite texture coordinate (0, inf)"
        );
        assert_eq!(
            e("f 1/1/1/1 2 3\n"),
            "line 5: '1/1/1/1' is not a vertex reference"
        );
    }

    #[test]
    fn a_byte_order_mark_is_skipped() {
        let mesh = read_obj("\u{feff}v 1 2 3\nv 4 5 6\n".as_bytes()).unwrap();
        assert_eq!(mesh.vertices, vec![[1., 2., 3.], [4., 5., 6.]]);
    }

    #[test]
    fn a_reference_past_u32_is_named_as_written() {
        let e = |t: &str| read_obj(t.as_bytes()).unwrap_err().to_string();
        // The reference as written, though it does not fit in u32 once
        // 1-based (not wrapped to "vertex 0"); the line of a later fan.
        assert_eq!(
            e("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 1\n# c\nf 1 2 4294967296\n"),
            "line 6: triangle 2 refers to vertex 4294967296, but there are only 3 vertices"
        );
    }

    #[test]
    fn errors_name_the_line() {
        let e = |t: &str| read_obj(t.as_bytes()).unwrap_err().to_string();
        assert_eq!(e("v 1 2 3\nv 1 x 3\n"), "line 2: 'x' is not a number");
        assert_eq!(
            e("v 1 2\n"),
            "line 1: a vertex needs x, y and z, found 2 value(s)"
        );
        assert_eq!(
            e("v 1 2 inf\n"),
            "line 1: non-finite coordinate (1, 2, inf)"
        );
        assert_eq!(
            e("v 1 2 3\nf 1 2 3\n"),
            "line 2: triangle 0 refers to vertex 2, but there are only 1 vertices"
        );
        assert_eq!(
            e("v 1 2 3\nf 1 -2 1\n"),
            "line 2: face refers to vertex -2, which does not exist"
        );
    }
}
