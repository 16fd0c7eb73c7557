//! Tests of the STL reader.

use super::*;

/// The one-pass reader, kept as the reference that reading in pieces must
/// match.
fn read_ascii_one_pass(bytes: &[u8]) -> Result<Mesh> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        anyhow!(
            "not an ASCII STL (invalid UTF-8 at byte {}) nor a binary one (its size does not \
             match its triangle count)",
            e.valid_up_to()
        )
    })?;
    let mut merger = Merger::new(text.len() / 200);
    let mut state = State::Outside;
    let mut corners: Vec<Point3> = Vec::with_capacity(3);
    let mut facets = 0usize;
    let mut last = 0;
    for (i, line) in lines(text).enumerate() {
        last = i + 1;
        let at = |e: String| anyhow!("line {}: {e}", i + 1);
        let mut words = words(line);
        let Some(keyword) = words.next() else {
            continue;
        };
        let expected = |what: &str| at(format!("expected {what}, found '{}'", line.trim()));
        state = match (state, keyword) {
            (State::Outside, "solid") => State::Solid,
            (State::Outside, _) => return Err(expected("'solid'")),
            (State::Solid, "facet") => {
                if words.next() != Some("normal") {
                    return Err(expected("'facet normal nx ny nz'"));
                }
                State::Facet
            }
            (State::Solid, "endsolid") => State::Outside,
            (State::Solid, _) => return Err(expected("'facet normal' or 'endsolid'")),
            (State::Facet, "outer") if words.next() == Some("loop") => State::Loop,
            (State::Facet, _) => return Err(expected("'outer loop'")),
            (State::Loop, "vertex") => {
                corners.push(parse_xyz(words).map_err(at)?);
                State::Loop
            }
            (State::Loop, "endloop") => {
                if corners.len() != 3 {
                    return Err(at(format!(
                        "facet {facets} has {} vertices, a triangle needs 3",
                        corners.len()
                    )));
                }
                merger.triangle([corners[0], corners[1], corners[2]])?;
                corners.clear();
                facets += 1;
                State::EndLoop
            }
            (State::Loop, _) => return Err(expected("'vertex x y z' or 'endloop'")),
            (State::EndLoop, "endfacet") => State::Solid,
            (State::EndLoop, _) => return Err(expected("'endfacet'")),
        };
    }
    match state {
        State::Outside => Ok(merger.mesh),
        _ => bail!("line {last}: the file ends inside a solid (no 'endsolid' line)"),
    }
}

fn err(bytes: &[u8]) -> String {
    format!("{:#}", read_stl(bytes).unwrap_err())
}

const SQUARE: &str = "solid square\n  facet normal 0 0 1\n    outer loop\n\
    \x20     vertex 0 0 0\n      vertex 1 0 0\n      vertex 1 1 0\n    endloop\n  endfacet\n\
    \x20 facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 1 0\n\
    \x20     vertex 0 1 -0\n    endloop\n  endfacet\nendsolid square\n";

#[test]
fn ascii_merges_equal_corners() {
    let mesh = read_stl(SQUARE.as_bytes()).unwrap();
    assert_eq!(
        mesh.vertices,
        vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., -0.]]
    );
    assert_eq!(mesh.faces.unwrap(), vec![[0, 1, 2], [0, 2, 3]]);
    assert!(looks_ascii(SQUARE.as_bytes()));
}

#[test]
fn binary_round_trip_and_negative_zero() {
    let vertices = vec![[0., 0., 0.], [1., 0., 0.], [1., 1., -0.], [0.1, 1., 0.]];
    let faces = vec![[0, 1, 2], [0, 2, 3]];
    let mut bytes = Vec::new();
    write_stl(&mut bytes, &vertices, &faces).unwrap();
    assert_eq!(bytes.len(), 84 + 2 * 50);
    assert!(bytes.starts_with(b"binary STL written by meshtrim"));
    assert!(is_exact_binary(&bytes));
    let mesh = read_stl(&bytes).unwrap();
    assert_eq!(mesh.vertices[3], [f64::from(0.1f32), 1., 0.]);
    assert_eq!(mesh.faces.unwrap(), faces);
    // The normal of the first triangle is +z.
    assert_eq!(LittleEndian::read_f32(&bytes[84 + 8..]), 1.0);
}

#[test]
fn binary_with_solid_header_is_binary() {
    let mut bytes = Vec::new();
    write_stl(
        &mut bytes,
        &[[0.; 3], [1., 0., 0.], [0., 1., 0.]],
        &[[0, 1, 2]],
    )
    .unwrap();
    bytes[..6].copy_from_slice(b"solid ");
    assert_eq!(read_stl(&bytes).unwrap().vertices.len(), 3);
}

#[test]
fn truncated_binary_names_the_triangle() {
    let mut bytes = Vec::new();
    let v = [[0.; 3], [1., 0., 0.], [0., 1., 0.]];
    write_stl(&mut bytes, &v, &[[0, 1, 2]; 5]).unwrap();
    bytes.truncate(84 + 3 * 50 + 20);
    assert_eq!(
        err(&bytes),
        "binary STL truncated: the header declares 5 triangles (334 bytes), the file has \
         254 bytes and ends in triangle 3"
    );
    assert!(err(b"tiny").contains("shorter than a binary STL's 84-byte header"));
}

/// Lines read in pieces of 1–64 bytes give what the one-pass reading
/// gives, error messages included, on random texts: solids of whole
/// facets, with now and then a bad vertex (too few or many numbers, a
/// word, NaN), a missing or stray line, tabs, vertical tabs and Unicode
/// spaces between words.
#[test]
fn vertex_lines_in_pieces_read_as_in_one_pass() {
    let facet = [
        "facet normal 0 0 1",
        " outer loop",
        "  vertex",
        "  vertex",
        "  vertex",
        " endloop",
        "endfacet",
        "endsolid t",
        "solid t",
    ];
    let spaces = [" ", "\t", "\u{b}", "\u{3000}", "  "];
    let errors = crate::io::piece_tests::compare_with_one_pass(
        59,
        3000,
        40,
        |_, _| "solid t\n".to_string(),
        |below, l, case| {
            let line = match below(40) {
                0 => [
                    "vertex 1 2",
                    "vertex 1 x 3",
                    "vertex 1 2 3 4",
                    "vertex nan 0 0",
                ][below(4)]
                .to_string(),
                1 => ["", "endloop", "vertex 1 2 3", "facet normal 0 0 1"][below(4)].to_string(),
                _ => facet[l % facet.len()].to_string(),
            };
            if !line.ends_with("vertex") {
                return line;
            }
            let sep = spaces[below(5)];
            format!("{line}{sep}{l}.5{sep}{case}{sep}-{}", below(1000))
        },
        |text| read_ascii_one_pass(text.as_bytes()).map_err(|e| e.to_string()),
        |text, piece_bytes| {
            read_ascii_in_pieces(text.as_bytes(), piece_bytes).map_err(|e| e.to_string())
        },
    );
    assert!(
        (1500..2990).contains(&errors),
        "{errors} errors in 3000 cases"
    );
}

#[test]
fn ascii_errors_name_the_line() {
    let bad = SQUARE.replace("vertex 1 0 0", "vertex 1 x 0");
    assert_eq!(err(bad.as_bytes()), "line 5: 'x' is not a number");
    let bad = SQUARE.replace("    endloop\n  endfacet\nendsolid", "    endloop\nendsolid");
    assert_eq!(
        err(bad.as_bytes()),
        "line 15: expected 'endfacet', found 'endsolid square'"
    );
    let bad = SQUARE.replacen("      vertex 1 1 0\n", "", 1);
    assert_eq!(
        err(bad.as_bytes()),
        "line 6: facet 0 has 2 vertices, a triangle needs 3"
    );
    let cut = &SQUARE[..SQUARE.find("endsolid").unwrap()];
    assert_eq!(
        err(cut.as_bytes()),
        "line 15: the file ends inside a solid (no 'endsolid' line)"
    );
    let bad = SQUARE.replace("vertex 0 1 -0", "vertex 0 1 nan");
    assert_eq!(
        err(bad.as_bytes()),
        "line 13: non-finite coordinate (0, 1, NaN)"
    );
}

#[test]
fn degenerate_normal_is_zero() {
    assert_eq!(unit_normal([0.; 3], [1., 0., 0.], [2., 0., 0.]), [0.; 3]);
}

/// Binary records read in pieces of 1–9 triangles number the vertices as
/// one merger over all of them does, and name the same bad triangle, on
/// random triangle soups drawn from a few positions (so that corners
/// repeat within and across pieces, `-0` among them).
#[test]
fn binary_pieces_read_as_one_merger() {
    let mut rng = testkit::synthetic::SplitMix64::new(61);
    let mut below = |n: u64| (rng.next_u64() % n) as usize;
    let pool: [[f32; 3]; 7] = [
        [0., 0., 0.],
        [-0., 0., 0.],
        [1., 0., 0.],
        [0., 1., 2.5],
        [1., 1., -1.],
        [3., 0., 0.25],
        [0., 0., -0.],
    ];
    let mut errors = 0;
    for _ in 0..2000 {
        let triangles = below(40);
        let mut records = Vec::with_capacity(triangles * RECORD);
        for _ in 0..triangles {
            records.extend([0u8; 12]);
            for _ in 0..3 {
                let mut p = pool[below(pool.len() as u64)];
                if below(300) == 0 {
                    p[below(3)] = f32::NAN;
                }
                p.iter().for_each(|c| records.extend(c.to_le_bytes()));
            }
            records.extend([0u8; 2]);
        }
        let one = merge_binary_piece(&records, 0).map(|m| (m.mesh.vertices, m.mesh.faces));
        let one = one.map_err(|e| e.to_string());
        for per_piece in 1..10 {
            let pieces = read_records_in_pieces(&records, per_piece)
                .map(|m| (m.vertices, m.faces))
                .map_err(|e| e.to_string());
            match (&pieces, &one) {
                (Ok((v, f)), Ok((w, g))) => {
                    assert_eq!(f, g, "faces, pieces of {per_piece}");
                    let bits = |v: &Vec<Point3>| -> Vec<[u64; 3]> {
                        v.iter().map(|p| p.map(f64::to_bits)).collect()
                    };
                    assert_eq!(bits(v), bits(w), "vertices, pieces of {per_piece}");
                }
                _ => assert_eq!(pieces, one, "pieces of {per_piece}"),
            }
        }
        errors += usize::from(one.is_err());
    }
    assert!(
        (100..1000).contains(&errors),
        "{errors} errors in 2000 cases"
    );
}

/// Triangles merged in pieces of 1–9 number the vertices as one merger
/// over all of them does, on random triangle soups drawn from a few
/// positions (`-0` among them), as the ASCII reader merges its facets.
#[test]
fn triangles_merged_in_pieces_as_one_merger() {
    let mut rng = testkit::synthetic::SplitMix64::new(62);
    let mut below = |n: u64| (rng.next_u64() % n) as usize;
    let pool: [Point3; 6] = [
        [0., 0., 0.],
        [-0., 0., 0.],
        [1., 0., 0.],
        [0., 1., 2.5],
        [1e-300, 1., -1.],
        [0., 0., -0.],
    ];
    for _ in 0..2000 {
        let triangles: Vec<[Point3; 3]> = (0..below(40))
            .map(|_| [0; 3].map(|_| pool[below(pool.len() as u64)]))
            .collect();
        let mut one = Merger::new(0);
        for &t in &triangles {
            one.triangle(t).unwrap();
        }
        let bits =
            |v: &[Point3]| -> Vec<[u64; 3]> { v.iter().map(|p| p.map(f64::to_bits)).collect() };
        for per_piece in 1..10 {
            let pieces = merge_in_pieces(&triangles, per_piece).unwrap();
            assert_eq!(pieces.faces, one.mesh.faces, "faces, pieces of {per_piece}");
            assert_eq!(
                bits(&pieces.vertices),
                bits(&one.mesh.vertices),
                "vertices, pieces of {per_piece}"
            );
        }
    }
}
