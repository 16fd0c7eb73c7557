//! Wavefront OBJ: `v` and `f` lines.
//!
//! A few lines of our own rather than `tobj`: tobj only returns vertices
//! that some face uses (re-indexed per object), so a face-less OBJ point
//! cloud comes back empty, and its errors carry no line numbers. Here every
//! `v` line is a vertex, in file order; `f` lines become triangle fans.
//! Vertex colours, `v x y z r g b` (MeshLab's and trimesh's extension,
//! channels in 0..1), are kept when every `v` line has them. Texture
//! coordinates, normals (`vn`, indexed per face corner), groups and
//! materials are ignored.

use anyhow::{anyhow, bail, Result};

use rayon::prelude::*;

use super::{
    cut_after_newlines, lines, show, text_of, unit_channel, Colours, Mesh, Point3, PIECE_BYTES,
};

/// Reads the vertices and faces of an OBJ file.
///
/// Pieces of the text are parsed in parallel: a first pass counts each
/// piece's `v` lines, so that a negative reference (counted back from the
/// latest vertex) resolves as in a one-pass reading; the pieces are joined
/// in order and the error reported is the first in the file.
pub fn read_obj(bytes: &[u8]) -> Result<Mesh> {
    read_obj_in_pieces(bytes, PIECE_BYTES)
}

fn read_obj_in_pieces(bytes: &[u8], piece_bytes: usize) -> Result<Mesh> {
    let text = text_of(bytes)?;
    let pieces = cut_after_newlines(text, piece_bytes);
    let counts: Vec<usize> = pieces.par_iter().map(|p| vertex_lines(p)).collect();
    // The vertices before each piece.
    let before: Vec<usize> = counts
        .iter()
        .scan(0, |total, &n| {
            let start = *total;
            *total += n;
            Some(start)
        })
        .collect();
    let parsed: Vec<ObjPiece> = pieces
        .into_par_iter()
        .zip(before)
        .map(|(piece, before)| parse_piece(piece, before))
        .collect();
    let mut mesh = Mesh::default();
    let mut colours = Some(Vec::new());
    let mut line0 = 0;
    for piece in parsed {
        if let Some((i, e)) = piece.error {
            bail!("line {}: {e}", line0 + i);
        }
        mesh.vertices.extend_from_slice(&piece.vertices);
        colours = colours.zip(piece.colours).map(|(mut all, more)| {
            all.extend(more);
            all
        });
        if let Some(faces) = piece.faces {
            mesh.faces
                .get_or_insert_with(Vec::new)
                .extend_from_slice(&faces);
        }
        line0 += piece.lines;
    }
    check_indices(&mesh, text)?;
    mesh.colours = coloured(colours, mesh.vertices.len());
    Ok(mesh)
}

/// The vertices' colours, when there are vertices and every one has one.
fn coloured(colours: Option<Vec<[f64; 4]>>, vertices: usize) -> Option<Colours> {
    colours
        .filter(|c| vertices > 0 && c.len() == vertices)
        .map(|rgba| Colours { rgba, alpha: false })
}

/// The `v` lines of a piece of text.
fn vertex_lines(text: &str) -> usize {
    lines(text)
        .filter(|line| line.split_whitespace().next() == Some("v"))
        .count()
}

/// What one piece of an OBJ holds; line numbers count from its start.
#[derive(Default)]
struct ObjPiece {
    vertices: Vec<Point3>,
    /// The vertices' colours, until a vertex without one.
    colours: Option<Vec<[f64; 4]>>,
    /// `Some` once an `f` line is seen, even one that makes no triangle.
    faces: Option<Vec<[u32; 3]>>,
    lines: usize,
    /// The piece's first error; parsing stops there.
    error: Option<(usize, String)>,
}

/// Parses a piece that follows `before` vertices.
fn parse_piece(text: &str, before: usize) -> ObjPiece {
    let mut piece = ObjPiece {
        colours: Some(Vec::new()),
        ..ObjPiece::default()
    };
    for line in lines(text) {
        piece.lines += 1;
        let mut words = line.split_whitespace();
        let parsed = match words.next() {
            Some("v") => parse_vertex(words).map(|(p, colour)| {
                piece.vertices.push(p);
                push_colour(&mut piece.colours, colour);
            }),
            Some("f") => {
                let faces = piece.faces.get_or_insert_with(Vec::new);
                parse_face(words, before + piece.vertices.len(), faces)
            }
            _ => Ok(()),
        };
        if let Err(e) = parsed {
            piece.error = Some((piece.lines, e.to_string()));
            break;
        }
    }
    piece
}

/// Positive references may point forward, so they are checked at the end.
fn check_indices(mesh: &Mesh, text: &str) -> Result<()> {
    let n = mesh.vertices.len();
    for (t, face) in mesh.faces.as_deref().unwrap_or_default().iter().enumerate() {
        if let Some(&v) = face.iter().find(|&&v| v as usize >= n) {
            // As written: 1-based, and in u64, where u32::MAX + 1 fits.
            let written = u64::from(v) + 1;
            let at = line_of_triangle(text, t).map_or(String::new(), |l| format!("line {l}: "));
            bail!("{at}triangle {t} refers to vertex {written}, but there are only {n} vertices");
        }
    }
    Ok(())
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
    let mut p: Point3 = [0.0; 3];
    for (k, c) in p.iter_mut().enumerate() {
        let word = words
            .next()
            .ok_or_else(|| anyhow!("a vertex needs x, y and z, found {k} value(s)"))?;
        *c = word
            .parse()
            .map_err(|_| anyhow!("'{word}' is not a number"))?;
    }
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

/// `f a b c ...`, each corner `v`, `v/vt`, `v//vn` or `v/vt/vn`, 1-based or
/// negative (counted back from the latest vertex); 0-based on return.
fn parse_face<'a>(
    words: impl Iterator<Item = &'a str>,
    defined: usize,
    faces: &mut Vec<[u32; 3]>,
) -> Result<()> {
    let corners = words
        .map(|w| corner_index(w, defined))
        .collect::<Result<Vec<u32>>>()?;
    for w in 1..corners.len().saturating_sub(1) {
        faces.push([corners[0], corners[w], corners[w + 1]]);
    }
    Ok(())
}

fn corner_index(word: &str, defined: usize) -> Result<u32> {
    let v = word.split('/').next().unwrap_or_default();
    let n: i64 = v
        .parse()
        .map_err(|_| anyhow!("'{word}' is not a vertex reference"))?;
    let index = if n < 0 { defined as i64 + n } else { n - 1 };
    if n == 0 || index < 0 || index > i64::from(u32::MAX) {
        bail!("face refers to vertex {n}, which does not exist");
    }
    Ok(index as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one-pass reading the pieces must match.
    fn read_obj_serial(bytes: &[u8]) -> Result<Mesh> {
        let text = text_of(bytes)?;
        let mut mesh = Mesh::default();
        let mut colours = Some(Vec::new());
        for (i, line) in lines(text).enumerate() {
            let mut words = line.split_whitespace();
            let at = |e: anyhow::Error| anyhow!("line {}: {e}", i + 1);
            match words.next() {
                Some("v") => {
                    let (p, colour) = parse_vertex(words).map_err(at)?;
                    mesh.vertices.push(p);
                    push_colour(&mut colours, colour);
                }
                Some("f") => {
                    let faces = mesh.faces.get_or_insert_with(Vec::new);
                    parse_face(words, mesh.vertices.len(), faces).map_err(at)?;
                }
                _ => {}
            }
        }
        check_indices(&mesh, text)?;
        mesh.colours = coloured(colours, mesh.vertices.len());
        Ok(mesh)
    }

    /// Random OBJ texts (negative and forward references, polygons,
    /// comments, every line ending, bad lines) read in pieces of a few
    /// bytes give what the one-pass reading gives.
    #[test]
    fn pieces_read_as_one_pass_does() {
        let outcome = |m: Result<Mesh>| {
            m.map(|m| (m.vertices, m.faces, m.colours))
                .map_err(|e| e.to_string())
        };
        let errors = crate::io::piece_tests::compare_with_one_pass(
            41,
            2000,
            25,
            |_, _| String::new(),
            |below, l, case| match below(16) {
                // Coloured in most texts, so that some keep their colours.
                _ if case % 3 > 0 && below(40) > 0 => {
                    format!("v {l} {case} {} 0.{} 1 0", below(9), below(10))
                }
                0 => "# comment".to_string(),
                1 => "vn 0 0 1".to_string(),
                2 => "v 1 x 3".to_string(),
                3 => format!("f {} {} {}", below(6) + 1, below(6) + 1, below(6) + 1),
                4 => format!("f -1 -{} 1/2/3 {}//4", below(4) + 1, below(5) + 1),
                5 => "f 1 0 2".to_string(),
                6 => "f 1 2".to_string(),
                7 => String::new(),
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
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1 2//3 3/4/5 -1\nf 1 2 3\n";
        let mesh = read_obj(text.as_bytes()).unwrap();
        assert_eq!(mesh.faces.unwrap(), vec![[0, 1, 2], [0, 2, 3], [0, 1, 2]]);
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
