//! Tests of the PLY reader and writer.

use super::*;
use crate::io::Colours;

fn err(bytes: &[u8]) -> String {
    format!("{:#}", read_ply(bytes).unwrap_err())
}

const ASCII: &str = "ply\nformat ascii 1.0\ncomment test\nobj_info x 1\n\
    element camera 1\nproperty float a\nproperty int b\n\
    element face 2\nproperty list uchar int vertex_indices\n\
    element vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
    property float nx\nproperty float ny\nproperty float nz\nproperty uchar red\n\
    end_header\n\
    0.5 7\n3 0 1 2\n4 0 1 2 3\n\
    0 0 0 0 0 1 255\n1 0 0 0 0 1 0\n1 1 0 0 0 1 0\n0 1 0.25 0 0 1 0\n";

#[test]
fn ascii_with_faces_before_vertices() {
    let mesh = read_ply(ASCII.as_bytes()).unwrap();
    assert_eq!(
        mesh.vertices,
        vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.25]]
    );
    assert_eq!(mesh.normals.unwrap()[3], [0., 0., 1.]);
    assert_eq!(mesh.faces.unwrap(), vec![[0, 1, 2], [0, 1, 2], [0, 2, 3]]);
}

/// A binary file with every scalar type, a list element before the
/// vertices and an unused list property on the vertices.
fn binary<B: ByteOrder>(name: &str) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat {name} 1.0\nelement range_grid 2\nproperty list uchar int vertex_indices\n\
         element vertex 2\nproperty char a\nproperty uchar b\nproperty short c\n\
         property ushort d\nproperty int32 e\nproperty uint f\nproperty float x\n\
         property float64 y\nproperty list ushort double junk\nproperty double z\nend_header\n"
    )
    .into_bytes();
    let mut grid = vec![1u8, 0, 0, 0, 0, 0];
    B::write_i32(&mut grid[1..5], 1);
    out.extend_from_slice(&grid);
    for v in 0..2 {
        let mut rec = vec![0u8; 1 + 1 + 2 + 2 + 4 + 4 + 4 + 8 + 2 + 8 + 8];
        rec[0] = (-3i8) as u8;
        rec[1] = 200;
        B::write_i16(&mut rec[2..4], -300);
        B::write_u16(&mut rec[4..6], 60000);
        B::write_i32(&mut rec[6..10], -70000);
        B::write_u32(&mut rec[10..14], 4_000_000_000);
        B::write_f32(&mut rec[14..18], 1.5 + v as f32);
        B::write_f64(&mut rec[18..26], -2.25);
        B::write_u16(&mut rec[26..28], 1);
        B::write_f64(&mut rec[28..36], 99.0);
        B::write_f64(&mut rec[36..44], 0.1);
        out.extend_from_slice(&rec);
    }
    out
}

#[test]
fn binary_both_byte_orders() {
    for bytes in [
        binary::<LittleEndian>("binary_little_endian"),
        binary::<BigEndian>("binary_big_endian"),
    ] {
        let mesh = read_ply(&bytes).unwrap();
        assert_eq!(mesh.vertices, vec![[1.5, -2.25, 0.1], [2.5, -2.25, 0.1]]);
        assert_eq!(mesh.normals, None);
        assert_eq!(mesh.faces, None);
    }
}

#[test]
fn write_then_read() {
    let points = vec![[0.1, -2.0, 3e-300], [f64::MAX, 0.0, -0.0]];
    let mut bytes = Vec::new();
    write_points(&mut bytes, &points, "round trip").unwrap();
    assert_eq!(read_ply(&bytes).unwrap().vertices, points);
}

#[test]
fn truncated_binary_names_counts() {
    let mut bytes = binary::<LittleEndian>("binary_little_endian");
    bytes.truncate(bytes.len() - 5);
    assert_eq!(err(&bytes), "expected 2 vertices, file ends after 1");
}

#[test]
fn truncated_ascii_names_counts() {
    let text = ASCII.trim_end().rsplit_once('\n').unwrap().0;
    assert_eq!(
        err(text.as_bytes()),
        "expected 4 vertices, file ends after 3"
    );
}

#[test]
fn bad_number_names_line() {
    let text = ASCII.replace("1 1 0 0 0 1 0", "1 abc 0 0 0 1 0");
    assert_eq!(err(text.as_bytes()), "line 24: 'abc' is not a number");
}

#[test]
fn non_finite_names_line_and_vertex() {
    let text = ASCII.replace("1 1 0 0 0 1 0", "1 nan 0 0 0 1 0");
    assert_eq!(
        err(text.as_bytes()),
        "line 24: vertex 2 has a non-finite coordinate (1, NaN, 0)"
    );
}

#[test]
fn header_errors() {
    assert!(err(b"ply\nformat ascii 1.0\nelement vertex 1\n").contains("no 'end_header'"));
    assert!(
        err(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\nend_header\n")
            .contains("line 4: unsupported property type 'half'")
    );
    assert!(err(b"ply\nformat weird 1.0\nend_header\n").contains("line 2: unknown format"));
    assert!(err(b"ply\nproperty float x\nend_header\n").contains("line 2: a property before"));
    assert!(
        err(b"ply\nformat ascii 1.0\nelement vertex x\nend_header\n")
            .contains("line 3: 'x' is not an element count")
    );
    assert!(err(b"ply\nformat ascii 1.0\nend_header\n").contains("no vertex element"));
    let no_z = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n";
    assert!(err(no_z).contains("no x, y and z"));
}

#[test]
fn face_index_out_of_range() {
    let text = ASCII.replace("4 0 1 2 3", "4 0 1 2 9");
    assert_eq!(
        err(text.as_bytes()),
        "triangle 2 refers to vertex 9, but there are only 4 vertices"
    );
}

#[test]
fn absurd_counts_are_truncation_not_allocation() {
    let text = "ply\nformat binary_little_endian 1.0\nelement vertex 18446744073709551615\n\
        property float x\nproperty float y\nproperty float z\nend_header\n";
    assert_eq!(
        err(text.as_bytes()),
        "expected 18446744073709551615 vertices, file ends after 0"
    );
}

/// A 3 × 3 range grid, row by row, whose first entry is empty; vertex
/// k of the 8 sits at column k % 3, row k / 3 of the full grid shifted
/// by one, at (column, `dy`·row, a little relief).
fn range_grid(dy: f64, grid: &str) -> String {
    let mut text = String::from(
        "ply\nformat ascii 1.0\nobj_info is_mesh 0\nobj_info num_cols 3\n\
         obj_info num_rows 3\nelement vertex 8\nproperty float x\nproperty float y\n\
         property float z\nelement range_grid 9\n\
         property list uchar int vertex_indices\nend_header\n",
    );
    for k in 1..9 {
        let (c, r) = (k % 3, k / 3);
        text += &format!("{c} {} {}\n", dy * r as f64, 0.1 * (c * r) as f64);
    }
    text + grid
}

const GRID: &str = "0\n1 0\n1 1\n1 2\n1 3\n1 4\n1 5\n1 6\n1 7\n";

fn mesh_err(text: &str) -> String {
    format!("{:#}", read_ply_mesh(text.as_bytes()).unwrap_err())
}

#[test]
fn range_grid_gives_faces_facing_z() {
    for dy in [1.0, -1.0] {
        let mesh = read_ply_mesh(range_grid(dy, GRID).as_bytes()).unwrap();
        let faces = mesh.faces.unwrap();
        // Three full cells of two triangles and one of three entries.
        assert_eq!(faces.len(), 7);
        for f in &faces {
            let [a, b, c] = f.map(|v| mesh.vertices[v as usize]);
            let z = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            assert!(z > 0.0, "{f:?} faces away from +z (dy = {dy})");
        }
        // Every inner edge is used by two faces, the border by one.
        let mut uses = std::collections::HashMap::new();
        for f in &faces {
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        assert_eq!(uses.values().filter(|&&n| n == 1).count(), 7);
        assert!(uses.values().all(|&n| n <= 2));
    }
}

#[test]
fn the_shorter_diagonal_splits_a_cell() {
    let mesh = read_ply_mesh(range_grid(1.0, GRID).as_bytes()).unwrap();
    // Cell (row 1, column 1): corners 3, 4, 7, 6; with the relief
    // 0.1·c·r the diagonal 3–7 (z 0 → 0.4) is longer than 4–6 (0.1, 0.2).
    let faces = mesh.faces.unwrap();
    let has = |a: u32, b: u32| faces.iter().any(|f| f.contains(&a) && f.contains(&b));
    assert!(has(4, 6) && !has(3, 7));
}

#[test]
fn clouds_ignore_the_range_grid() {
    let bad = GRID.replace("1 7\n", "2 7 7\n");
    let cloud = read_ply(range_grid(1.0, &bad).as_bytes()).unwrap();
    assert_eq!((cloud.vertices.len(), cloud.faces), (8, None));
}

#[test]
fn range_grid_errors() {
    let text = range_grid(1.0, &GRID.replace("1 7\n", "2 7 7\n"));
    assert_eq!(
        mesh_err(&text),
        "line 29: range_grid entry 8 lists 2 vertices, at most 1 is allowed"
    );
    let text = range_grid(1.0, &GRID.replace("1 7\n", "1 8\n"));
    assert_eq!(
        mesh_err(&text),
        "range_grid entry 8 refers to vertex 8, but there are only 8 vertices"
    );
    let text = range_grid(1.0, &GRID.replace("1 7\n", "1 -1\n"));
    assert_eq!(
        mesh_err(&text),
        "line 29: range_grid entry 8 has a bad vertex index -1"
    );
    let text = range_grid(1.0, GRID).replace("num_rows 3", "num_rows 4");
    assert_eq!(
        mesh_err(&text),
        "the range_grid has 9 entries, but num_cols × num_rows is 3 × 4"
    );
    let text = range_grid(1.0, GRID).replace("obj_info num_cols 3\n", "");
    assert_eq!(
        mesh_err(&text),
        "the range_grid needs an 'obj_info num_cols' header line"
    );
    let text = range_grid(1.0, GRID).replace("num_cols 3", "num_cols three");
    assert_eq!(mesh_err(&text), "'obj_info num_cols three' is not a count");
}

#[test]
fn faces_win_over_a_range_grid() {
    let text = range_grid(1.0, GRID).replace(
        "end_header",
        "element face 1\nproperty list uchar int vertex_indices\nend_header",
    ) + "3 0 1 2\n";
    assert_eq!(
        read_ply_mesh(text.as_bytes()).unwrap().faces,
        Some(vec![[0, 1, 2]])
    );
}

/// An element without properties and a huge count, before and after
/// the vertices, in both encodings: skipped at once, not by looping
/// 2^64 times.
#[test]
fn elements_without_properties_are_skipped_at_once() {
    let junk = "element junk 18446744073709551615\n";
    let vertex = "element vertex 2\nproperty float x\nproperty float y\nproperty float z\n";
    let mut binary_body = Vec::new();
    [1f32, 2.0, 3.0, 4.0, 5.0, 6.0]
        .iter()
        .for_each(|c| binary_body.extend(c.to_le_bytes()));
    for elements in [format!("{vertex}{junk}"), format!("{junk}{vertex}")] {
        let ascii = format!("ply\nformat ascii 1.0\n{elements}end_header\n1 2 3\n4 5 6\n");
        let mut binary =
            format!("ply\nformat binary_little_endian 1.0\n{elements}end_header\n").into_bytes();
        binary.extend(&binary_body);
        for bytes in [ascii.into_bytes(), binary] {
            // On a thread with a deadline, so a regression fails
            // instead of hanging the test run.
            let (send, receive) = std::sync::mpsc::channel();
            std::thread::spawn(move || send.send(read_ply(&bytes).map(|m| m.vertices)));
            let read = receive.recv_timeout(std::time::Duration::from_secs(20));
            let vertices = read.expect("read in 20 s").unwrap();
            assert_eq!(vertices, vec![[1., 2., 3.], [4., 5., 6.]]);
        }
    }
}

#[test]
fn a_record_must_end_where_its_line_ends() {
    // One value too many, or too few, is an error: read on, it would
    // shift every later vertex.
    let extra = ASCII.replace("1 0 0 0 0 1 0\n", "1 0 0 0 0 1 0 5\n");
    assert_eq!(
        err(extra.as_bytes()),
        "line 23: vertex 1 has 8 values, expected 7"
    );
    let short = ASCII.replace("1 0 0 0 0 1 0\n", "1 0 0 0 0 1\n");
    assert_eq!(
        err(short.as_bytes()),
        "line 23: vertex 1 has 6 values, expected 7"
    );
    let face = ASCII.replace("3 0 1 2\n", "3 0 1 2 3\n");
    assert_eq!(
        err(face.as_bytes()),
        "line 20: face 0 has 5 values, expected 4"
    );
    // Values on the last record's line are checked too.
    let last = ASCII.replace("0 1 0.25 0 0 1 0\n", "0 1 0.25 0 0 1 0 9\n");
    assert_eq!(
        err(last.as_bytes()),
        "line 25: vertex 3 has 8 values, expected 7"
    );
}

#[test]
fn records_split_over_lines_still_read() {
    let split = ASCII
        .replace("4 0 1 2 3\n", "4 0 1\n2 3\n")
        .replace("1 1 0 0 0 1 0\n", "1\n1 0\n\n0 0 1 0\n");
    let (a, b) = (read_ply(split.as_bytes()), read_ply(ASCII.as_bytes()));
    assert_eq!(a.unwrap(), b.unwrap());
}

#[test]
fn a_byte_order_mark_is_skipped() {
    let text = format!("\u{feff}{ASCII}");
    assert_eq!(
        read_ply(text.as_bytes()).unwrap(),
        read_ply(ASCII.as_bytes()).unwrap()
    );
}

/// The vertex element read in pieces of 1–64 bytes gives what one
/// value at a time gives, error messages included, on random texts:
/// records of the wrong width, split over lines, blank lines, bad and
/// non-finite numbers, a camera element before and faces after.
#[test]
fn ascii_vertices_in_pieces_read_as_in_one_pass() {
    let read = |text: &str, pieces| {
        read(text.as_bytes(), false, pieces)
            .map(|m| (m.vertices, m.normals, m.faces))
            .map_err(|e| e.to_string())
    };
    let errors = crate::io::piece_tests::compare_with_one_pass(
        31,
        3000,
        16,
        |below, case| {
            let normals = if case % 2 == 0 {
                "property float nx\nproperty float ny\nproperty double nz\n"
            } else {
                ""
            };
            let camera = ["", "element camera 1\nproperty float a\n"][below(2)];
            let faces = [
                "",
                "element face 2\nproperty list uchar int vertex_indices\n",
            ][below(2)];
            let body = if camera.is_empty() { "" } else { "0.5\n" };
            format!(
                "ply\nformat ascii 1.0\n{camera}element vertex {}\nproperty float x\n\
                 property uchar red\nproperty float y\nproperty float z\n{normals}\
                 {faces}end_header\n{body}",
                below(12)
            )
        },
        |below, l, case| match below(48) {
            0 => String::new(),
            1 => " \t".to_string(),
            2 => "1 2 3".to_string(),
            3 => "1 2 x 4".to_string(),
            4 => "1 nan 3 4 0 0 1".to_string(),
            5 => "1 2 inf 4".to_string(),
            6 => "3 0 1 2".to_string(),
            7 => "1 2".to_string(),
            8 => "3 4 0 0 1 5 6 7 0 0".to_string(),
            _ if case % 2 == 0 => format!("{l} {case} -{} 0.5 0 0 1", below(100)),
            _ => format!("{l} {case} -{} 0.5", below(100)),
        },
        |text| read(text, None),
        |text, piece_bytes| read(text, Some(piece_bytes)),
    );
    assert!(
        (1800..2900).contains(&errors),
        "{errors} errors in 3000 cases"
    );
}

/// Binary vertices decoded in parallel give what one value at a time
/// gives, on random headers and bytes: every scalar type in both byte
/// orders, x, y, z anywhere among the properties, sometimes a list
/// property (which the parallel decoding declines), normals, colours
/// (RGB or RGBA, of one type or, now and then, mixed), faces after,
/// truncated data and non-finite floats (random bit patterns).
#[test]
fn binary_vertices_decoded_in_parallel_as_one_at_a_time() {
    let types = [
        "char", "uchar", "short", "ushort", "int", "uint", "float", "double",
    ];
    let errors = compare_readings(37, false, |below, case| {
        let order = ["binary_little_endian", "binary_big_endian"][case % 2];
        let mut names: Vec<String> = ["x", "y", "z"].map(String::from).to_vec();
        if below(2) == 0 {
            names.extend(["nx", "ny", "nz"].map(String::from));
        }
        let colour_ty = types[below(8)];
        if below(2) == 0 {
            let channels = 3 + below(2);
            names.extend(
                ["red", "green", "blue", "alpha"][..channels]
                    .iter()
                    .map(|c| c.to_string()),
            );
        }
        for extra in 0..below(4) {
            let at = below(names.len() as u64 + 1);
            names.insert(at, format!("extra{extra}"));
        }
        let mut size = 0;
        let mut header = format!("ply\nformat {order} 1.0\nelement vertex {}\n", below(40));
        for name in &names {
            if name.starts_with("extra") && below(8) == 0 {
                header += &format!("property list uchar int {name}\n");
                size += 5;
                continue;
            }
            // Colours share a type in 7 of 8 cases; coordinates and
            // normals are floats in 3 of 4.
            let colour = ["red", "green", "blue", "alpha"].contains(&name.as_str());
            let ty = if colour && below(8) != 0 {
                colour_ty
            } else if name.starts_with("extra") || below(4) == 0 {
                types[below(8)]
            } else {
                ["float", "double"][below(2)]
            };
            size += Scalar::parse(ty).unwrap().size();
            header += &format!("property {ty} {name}\n");
        }
        header += "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
        let mut bytes = header.into_bytes();
        // About as many bytes as the vertices take, sometimes fewer.
        let body = below(40 * size as u64 + 64);
        bytes.extend((0..body).map(|_| if below(4) == 0 { 0 } else { below(256) as u8 }));
        bytes
    });
    assert!(
        (300..2700).contains(&errors),
        "{errors} errors in 3000 cases"
    );
}

/// Reads 3,000 random files, `make(below, case)`, one value at a time
/// and in pieces of 1 byte to 1 MiB, as a mesh (`grid`) or a cloud,
/// and asserts the same outcome, errors included; compared as Debug
/// text, so that NaN normals are equal. Returns how many files failed
/// to read, for the caller to check that both outcomes were tried.
fn compare_readings(
    seed: u64,
    grid: bool,
    mut make: impl FnMut(crate::io::piece_tests::Below, usize) -> Vec<u8>,
) -> usize {
    let mut rng = testkit::synthetic::SplitMix64::new(seed);
    let mut below = |n: u64| (rng.next_u64() % n) as usize;
    let read = |bytes: &[u8], pieces| {
        let mesh = read(bytes, grid, pieces).map(|m| format!("{m:?}"));
        mesh.map_err(|e| e.to_string())
    };
    let mut errors = 0;
    for case in 0..3000 {
        let bytes = make(&mut below, case);
        let want = read(&bytes, None);
        for piece_bytes in [1, 5, 16, 64, PIECE_BYTES] {
            let got = read(&bytes, Some(piece_bytes));
            assert_eq!(got, want, "case {case}, pieces of {piece_bytes} bytes");
        }
        errors += usize::from(want.is_err());
    }
    errors
}

/// `v` in type `ty`, appended to `out` in byte order `B`.
fn encode<B: ByteOrder>(ty: Scalar, v: f64, out: &mut Vec<u8>) {
    let mut b = [0u8; 8];
    match ty {
        Scalar::I8 => b[0] = v as i8 as u8,
        Scalar::U8 => b[0] = v as u8,
        Scalar::I16 => B::write_i16(&mut b, v as i16),
        Scalar::U16 => B::write_u16(&mut b, v as u16),
        Scalar::I32 => B::write_i32(&mut b, v as i32),
        Scalar::U32 => B::write_u32(&mut b, v as u32),
        Scalar::F32 => B::write_f32(&mut b, v as f32),
        Scalar::F64 => B::write_f64(&mut b, v),
    }
    out.extend_from_slice(&b[..ty.size()]);
}

/// A random binary mesh for [`binary_faces_decoded_in_parallel_as_one_at_a_time`].
fn random_binary_mesh<B: ByteOrder>(order: &str, below: &mut dyn FnMut(u64) -> usize) -> Vec<u8> {
    let types = [
        "char", "uchar", "short", "ushort", "int", "uint", "float", "double",
    ];
    let ty = |below: &mut dyn FnMut(u64) -> usize| types[below(8)];
    let vertices = below(12);
    let faces = below(30);
    let mut props = Vec::new();
    for k in 0..below(3) {
        props.push((format!("before{k}"), ty(below)));
    }
    let (count_ty, item_ty) = (
        ["uchar", "ushort", "int", ty(below)][below(4)],
        ["int", "uint", ty(below)][below(3)],
    );
    let list_at = props.len();
    props.push(("vertex_indices".into(), ""));
    for k in 0..below(3) {
        props.insert(list_at + 1, (format!("after{k}"), ty(below)));
    }
    let mut header = format!(
        "ply\nformat {order} 1.0\nelement vertex {vertices}\nproperty float x\n\
         property float y\nproperty float z\nelement face {faces}\n"
    );
    for (name, ty) in &props {
        header += &match *ty {
            "" => format!("property list {count_ty} {item_ty} {name}\n"),
            ty => format!("property {ty} {name}\n"),
        };
    }
    let mut bytes = (header + "end_header\n").into_bytes();
    let header_len = bytes.len();
    for v in 0..vertices * 3 {
        encode::<B>(Scalar::F32, v as f64, &mut bytes);
    }
    let [count_ty, item_ty] = [count_ty, item_ty].map(|t| Scalar::parse(t).unwrap());
    let len = [3, 3, 4, 5, 2][below(5)];
    for _ in 0..faces {
        let n = if below(20) == 0 { below(6) } else { len };
        for (_, ty) in &props {
            if ty.is_empty() {
                encode::<B>(count_ty, n as f64, &mut bytes);
                for _ in 0..n {
                    // Now and then bad or out of range.
                    let v = match below(300) {
                        0 => -1.0,
                        1 => 0.5,
                        2 => vertices as f64,
                        _ => below(vertices.max(1) as u64) as f64,
                    };
                    encode::<B>(item_ty, v, &mut bytes);
                }
            } else {
                encode::<B>(Scalar::parse(ty).unwrap(), below(300) as f64, &mut bytes);
            }
        }
    }
    if below(6) == 0 {
        bytes.truncate(header_len + below((bytes.len() - header_len) as u64 + 1));
    }
    bytes
}

/// Binary faces split into fans in parallel give what one value at a
/// time gives, on random meshes: lists of 3, 4 and 5 items or of
/// varying length, every count and item type, scalars before and
/// after the list, bad and out-of-range indices, truncated data.
#[test]
fn binary_faces_decoded_in_parallel_as_one_at_a_time() {
    let errors = compare_readings(41, true, |below, case| {
        if case % 2 == 0 {
            random_binary_mesh::<LittleEndian>("binary_little_endian", below)
        } else {
            random_binary_mesh::<BigEndian>("binary_big_endian", below)
        }
    });
    assert!(
        (300..2700).contains(&errors),
        "{errors} errors in 3000 cases"
    );
}

/// ASCII faces read at once give what one value at a time gives, on
/// random meshes: lists of 3, 4 or 5 items or of varying length, bad
/// and out-of-range indices, lines split or blank, truncation.
#[test]
fn ascii_faces_in_pieces_read_as_in_one_pass() {
    let errors = compare_readings(47, true, |below, case| {
        let (vertices, faces) = (1 + below(12), below(30));
        let mut text = format!(
            "ply\nformat ascii 1.0\nelement vertex {vertices}\nproperty float x\n\
             property float y\nproperty float z\nelement face {faces}\n\
             property list uchar int vertex_indices\nend_header\n"
        );
        for v in 0..vertices {
            text += &format!("{v} {case} 0.5\n");
        }
        let len = [3, 3, 4, 5][below(4)];
        for _ in 0..faces {
            let n = if below(30) == 0 { below(6) } else { len };
            let items: Vec<String> = (0..n)
                .map(|_| match below(300) {
                    0 => "-1".to_string(),
                    1 => "0.5".to_string(),
                    2 => vertices.to_string(),
                    _ => below(vertices as u64).to_string(),
                })
                .collect();
            let sep = if below(100) == 0 { "\n" } else { " " };
            text += &format!("{n}{sep}{}\n", items.join(" "));
            if below(200) == 0 {
                text += "\n";
            }
        }
        if below(8) == 0 {
            text.truncate(text.len() - below(text.len() as u64 / 4));
        }
        text.into_bytes()
    });
    assert!(
        (300..2700).contains(&errors),
        "{errors} errors in 3000 cases"
    );
}

/// The parallel path itself: it reads exactly the element's lines,
/// whatever follows them, and declines a layout it does not handle.
#[test]
fn rows_in_pieces_reads_exactly_the_elements_lines() {
    let text = "1 2 3\r\n4 5 6\r7 8 9\n3 0 1 2\n";
    for piece_bytes in [1, 4, 64] {
        let record = |columns| LineRecord {
            width: 3,
            lead: None,
            columns,
        };
        let columns = [[2, 0, 1]];
        let (triples, end) = rows_in_pieces(text, 3, &record(&columns), piece_bytes).unwrap();
        assert_eq!(triples, [[[3., 1., 2.], [6., 4., 5.], [9., 7., 8.]]]);
        assert_eq!(&text[end..], "3 0 1 2\n");
        assert_eq!(
            rows_in_pieces(text, 0, &record(&[[0; 3]]), piece_bytes)
                .unwrap()
                .1,
            0
        );
        // A fourth record would be a face line of 4 values; a blank
        // line or a record over two lines is left to the stream reader.
        assert!(rows_in_pieces(text, 4, &record(&[[0; 3]]), piece_bytes).is_none());
        assert!(rows_in_pieces("1 2 3\n\n4 5 6\n", 2, &record(&[[0; 3]]), piece_bytes).is_none());
        assert!(rows_in_pieces("1 2\n3\n", 1, &record(&[[0; 3]]), piece_bytes).is_none());
        // A list's length must be the one given.
        let lists = LineRecord {
            width: 4,
            lead: Some(3.0),
            columns: &[[1, 2, 3]],
        };
        let faces = "3 0 1 2\n3 2 1 0\n4 0 1 2\n";
        let (fans, _) = rows_in_pieces(faces, 2, &lists, piece_bytes).unwrap();
        assert_eq!(fans, [[[0., 1., 2.], [2., 1., 0.]]]);
        assert!(rows_in_pieces(faces, 3, &lists, piece_bytes).is_none());
    }
}

#[test]
fn crlf_header() {
    let text = ASCII.replace('\n', "\r\n");
    assert_eq!(read_ply(text.as_bytes()).unwrap().vertices.len(), 4);
}

/// ASCII vertices with colours, read in pieces, give what one pass gives:
/// RGB or RGBA of every type, values out of range and bad lines.
#[test]
fn ascii_colours_in_pieces_read_as_in_one_pass() {
    let types = ["uchar", "ushort", "float", "int"];
    let errors = compare_readings(41, false, |below, case| {
        let channels = 3 + case % 2;
        let ty = types[below(4)];
        let mut text = format!("ply\nformat ascii 1.0\nelement vertex {}\n", below(20));
        text += "property float x\nproperty float y\nproperty float z\n";
        for name in &["red", "green", "blue", "alpha"][..channels] {
            text += &format!("property {ty} {name}\n");
        }
        text += "end_header\n";
        for v in 0..below(22) {
            let values: Vec<String> = (0..3 + channels)
                .map(|k| match below(60) {
                    0 => "x".to_string(),
                    1 => "-7".to_string(),
                    2 => "1e9".to_string(),
                    _ if k >= 3 => below(256).to_string(),
                    _ => format!("{v}.5"),
                })
                .collect();
            text += &values.join(" ");
            text += "\n";
        }
        text.into_bytes()
    });
    assert!(
        (300..2700).contains(&errors),
        "{errors} errors in 3000 cases"
    );
}

#[test]
fn colours_are_read_by_their_type() {
    let file = |props: &str, row: &str| {
        format!(
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
             property float z\n{props}end_header\n0 0 0 {row}\n"
        )
    };
    let colours = |props: &str, row: &str| read_ply(file(props, row).as_bytes()).unwrap().colours;
    let uchar = "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    assert_eq!(
        colours(uchar, "255 0 51"),
        Some(Colours {
            rgba: vec![[1.0, 0.0, 0.2, 1.0]],
            alpha: false
        })
    );
    let ushort_rgba = "property ushort red\nproperty ushort green\nproperty ushort blue\n\
                       property ushort alpha\n";
    let read = colours(ushort_rgba, "65535 0 0 0").unwrap();
    assert_eq!((read.rgba[0], read.alpha), ([1.0, 0.0, 0.0, 0.0], true));
    let float = "property float diffuse_red\nproperty float diffuse_green\n\
                 property float diffuse_blue\n";
    assert_eq!(
        colours(float, "0.5 2 -1").unwrap().rgba[0],
        [0.5, 1.0, 0.0, 1.0]
    );
    let mixed = "property uchar red\nproperty float green\nproperty uchar blue\n";
    assert_eq!(colours(mixed, "1 0.5 1"), None, "channels of mixed types");
    assert_eq!(colours("property uchar red\n", "255"), None, "red alone");
}

#[test]
fn normals_colours_and_texcoords_written_read_back() {
    let vertices = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let faces = vec![[0, 1, 2]];
    for alpha in [false, true] {
        let attributes = crate::io::VertexAttributes {
            normals: Some(vec![[0.0, 0.0, 1.0], [0.0, 0.5, 0.75], [0.25, 0.0, -1.0]]),
            colours: Some(Colours {
                rgba: vec![
                    [1.0, 0.0, 0.2, 1.0],
                    [0.0, 1.0, 0.4, 0.6],
                    [0.2, 0.4, 0.6, 0.0],
                ],
                alpha,
            }),
            texcoords: Some(vec![[0.0, 1.0], [0.5, 0.25], [1.0, -0.75]]),
            ..Default::default()
        };
        let mut bytes = Vec::new();
        crate::io::mesh_out::write_ply(&mut bytes, &vertices, &faces, &attributes).unwrap();
        let read = read_ply_mesh(&bytes).unwrap();
        assert_eq!(read.vertices, vertices);
        assert_eq!(read.normals, attributes.normals);
        // MeshLab's texture_u and texture_v, read as the coordinates.
        assert_eq!(read.texcoords, attributes.texcoords);
        assert!(read.scalars.is_empty());
        let colours = read.colours.unwrap();
        assert_eq!(colours.alpha, alpha);
        let want = attributes.colours.unwrap().rgba;
        for (got, want) in colours.rgba.iter().zip(&want) {
            let channels = if alpha { 4 } else { 3 };
            assert_eq!(got[..channels], want[..channels]);
        }
    }
}

/// A random vertex element with the file's own values among its
/// positions: 0–7 properties of random types and names (some repeated,
/// one a list), ASCII or binary, its values now and then out of their
/// type's range or the data cut short.
fn random_own_values(below: &mut dyn FnMut(u64) -> usize, binary: bool) -> Vec<u8> {
    let types = [
        "char", "uchar", "short", "ushort", "int", "uint", "float", "double",
    ];
    let names = [
        "quality",
        "flags",
        "confidence",
        "intensity",
        "red",
        "label",
    ];
    let vertices = below(40);
    let mut props: Vec<(String, &str)> = ["x", "y", "z"].map(|n| (n.into(), "float")).into();
    for _ in 0..below(8) {
        let at = below(props.len() as u64 + 1);
        let name = names[below(names.len() as u64)].to_string();
        let ty = if below(12) == 0 { "" } else { types[below(8)] };
        props.insert(at, (name, ty));
    }
    let format = if binary {
        "binary_little_endian"
    } else {
        "ascii"
    };
    let mut text = format!("ply\nformat {format} 1.0\nelement vertex {vertices}\n");
    for (name, ty) in &props {
        text += &match *ty {
            "" => format!("property list uchar int {name}\n"),
            ty => format!("property {ty} {name}\n"),
        };
    }
    let mut bytes = (text + "end_header\n").into_bytes();
    for v in 0..vertices {
        let mut words = Vec::new();
        for (_, ty) in &props {
            let value = match below(40) {
                0 => -3.5,
                1 => 70000.0,
                _ => {
                    (v * 7 % 23) as f64
                        + if ty.starts_with('f') || ty.starts_with('d') {
                            0.25
                        } else {
                            0.0
                        }
                }
            };
            match (*ty, binary) {
                ("", true) => {
                    bytes.push(1);
                    encode::<LittleEndian>(Scalar::I32, 5.0, &mut bytes);
                }
                ("", false) => words.push("1 5".to_string()),
                (ty, true) => encode::<LittleEndian>(Scalar::parse(ty).unwrap(), value, &mut bytes),
                (_, false) => words.push(value.to_string()),
            }
        }
        if !binary {
            bytes.extend(words.join(" ").bytes());
            bytes.push(b'\n');
        }
    }
    if below(8) == 0 {
        let header_end = bytes.len() - bytes.len().min(below(30));
        bytes.truncate(header_end);
    }
    bytes
}

/// Vertices with the file's own values read in pieces (ASCII) or all
/// records at once (binary) give what one value at a time gives.
#[test]
fn own_values_in_pieces_read_as_in_one_pass() {
    for binary in [false, true] {
        let errors = compare_readings(43, false, |below, _| random_own_values(below, binary));
        assert!(errors < 1500, "{errors} errors in 3000 cases");
    }
}

#[test]
fn own_values_are_read_with_their_types() {
    let text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
                property float z\nproperty int flags\nproperty float quality\n\
                property list uchar int ids\nproperty uchar label\nproperty uchar red\n\
                property float quality\nproperty uchar level\nend_header\n\
                0 0 0 7 0.5 2 1 2 3 255 9 2.5\n1 0 0 -1 0.25 0 1 0 2 3\n";
    let mesh = read_ply(text.as_bytes()).unwrap();
    let fields = crate::io::field_rows(&mesh.scalars);
    assert_eq!(
        fields,
        [
            ("flags", Scalar::I32, &[7.0, -1.0][..]),
            ("quality", Scalar::F32, &[0.5, 0.25]),
            ("label", Scalar::U8, &[3.0, 1.0]),
            // A uchar of 2.5 is kept as read, as a double.
            ("level", Scalar::F64, &[2.5, 3.0]),
        ],
        "the list, a `red` alone and the second `quality` are not read"
    );
}

#[test]
fn own_values_written_read_back() {
    let vertices = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let kinds = [
        (Scalar::I8, [-128.0, 0.0, 127.0]),
        (Scalar::U8, [0.0, 1.0, 255.0]),
        (Scalar::I16, [-32768.0, 5.0, 32767.0]),
        (Scalar::U16, [0.0, 7.0, 65535.0]),
        (Scalar::I32, [-2147483648.0, 0.0, 2147483647.0]),
        (Scalar::U32, [0.0, 1.0, 4294967295.0]),
        (Scalar::F32, [0.5, f64::NAN, -1073741824.0]),
        (Scalar::F64, [0.1, f64::INFINITY, 1e300]),
    ];
    let scalars: Vec<ScalarField> = kinds
        .iter()
        .enumerate()
        .map(|(k, (kind, values))| ScalarField {
            name: format!("v{k}"),
            kind: *kind,
            values: values.to_vec(),
        })
        .collect();
    let attributes = crate::io::VertexAttributes {
        scalars: scalars.clone(),
        ..Default::default()
    };
    let mut bytes = Vec::new();
    crate::io::mesh_out::write_ply(&mut bytes, &vertices, &[[0, 1, 2]], &attributes).unwrap();
    let read = read_ply_mesh(&bytes).unwrap();
    // Compared as text: NaN is read back as NaN.
    assert_eq!(format!("{:?}", read.scalars), format!("{scalars:?}"));
}

/// MeshLab's textured PLY: a `texcoord` list per face (u, v per corner)
/// and `comment TextureFile`. A vertex whose corners read two
/// coordinates is split (the copy after the file's vertices), the
/// coordinates kept per vertex; a list without two values per corner
/// keeps none, and a cloud reading ignores them.
#[test]
fn per_corner_texture_coordinates_split_vertices() {
    let text = |second_face: &str| {
        format!(
            "ply\nformat ascii 1.0\ncomment TextureFile skin.png\nelement vertex 4\n\
             property float x\nproperty float y\nproperty float z\nelement face 2\n\
             property list uchar int vertex_indices\nproperty list uchar float texcoord\n\
             end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2 6 0 0 0.5 0 0.5 0.5\n{second_face}\n"
        )
    };
    // Vertex 0 is read with (0, 0) and (0.75, 0): it is split.
    let mesh = read_ply_mesh(text("3 0 2 3 6 0.75 0 0.5 0.5 0 0.5").as_bytes()).unwrap();
    assert_eq!(mesh.vertices.len(), 5);
    assert_eq!(mesh.vertices[4], [0.0; 3]);
    assert_eq!(mesh.faces.unwrap(), vec![[0, 1, 2], [4, 2, 3]]);
    assert_eq!(
        mesh.texcoords.unwrap(),
        vec![[0.0, 0.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5], [0.75, 0.0]]
    );
    let Some(crate::io::Materials::Ply(textures)) = mesh.materials else {
        panic!("no texture files read");
    };
    assert_eq!(
        (textures.files, textures.faces),
        (vec![PathBuf::from("skin.png")], vec![0, 0])
    );
    let short = read_ply_mesh(text("3 0 2 3 4 0.75 0 0.5 0.5").as_bytes()).unwrap();
    assert_eq!((short.vertices.len(), short.texcoords), (4, None));
    let cloud = read_ply(text("3 0 2 3 6 0.75 0 0.5 0.5 0 0.5").as_bytes()).unwrap();
    assert_eq!((cloud.vertices.len(), cloud.texcoords), (4, None));
}

/// MeshLab's `texnumber`: each face's image among the `TextureFile`s,
/// kept per triangle of its fan; a number naming no file (MeshLab's −1)
/// reads the first.
#[test]
fn texture_numbers_name_each_faces_image() {
    let text = "ply\nformat ascii 1.0\ncomment TextureFile a.png\ncomment TextureFile b b.png\n\
                element vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
                element face 3\nproperty list uchar int vertex_indices\n\
                property list uchar float texcoord\nproperty int texnumber\nend_header\n\
                0 0 0\n1 0 0\n1 1 0\n0 1 0\n\
                4 0 1 2 3 8 0 0 1 0 1 1 0 1 1\n3 0 1 2 6 0 0 1 0 1 1 -1\n3 0 2 3 6 0 0 1 1 0 1 7\n";
    let Some(crate::io::Materials::Ply(textures)) =
        read_ply_mesh(text.as_bytes()).unwrap().materials
    else {
        panic!("no texture files read");
    };
    assert_eq!(
        textures.files,
        [PathBuf::from("a.png"), PathBuf::from("b b.png")]
    );
    assert_eq!(textures.faces, vec![1, 1, 0, 0]);
}
