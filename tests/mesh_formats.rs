//! Mesh input and output in every format: round trips through each writer
//! and reader, hand-written STL and glTF files, error messages, and the
//! real meshes of `shared/data`.

mod common;

use std::path::{Path, PathBuf};

use base64::Engine;
use meshtrim::io::{read_cloud, read_mesh, write_mesh, Format, Mesh, MeshInput, Point3};

/// A 6 × 5 grid of vertices with one cell missing (a hole), coordinates
/// that no short decimal or f32 holds exactly, and a little relief.
fn grid_with_hole() -> (Vec<Point3>, Vec<[u32; 3]>) {
    let (nx, ny) = (6u32, 5u32);
    let mut vertices = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let (x, y) = (f64::from(i) / 3.0 + 0.1, f64::from(j) * 0.7 - 1e-3);
            vertices.push([x, y, (x * 1.3).sin() * (y + 0.2).cos() / 7.0]);
        }
    }
    let mut faces = Vec::new();
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            if (i, j) == (2, 2) {
                continue;
            }
            let v = |i: u32, j: u32| j * nx + i;
            faces.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            faces.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    (vertices, faces)
}

fn to_f32(p: &Point3) -> Point3 {
    p.map(|c| f64::from(c as f32))
}

fn faces(mesh: &Mesh) -> &[[u32; 3]] {
    mesh.faces.as_deref().expect("the mesh has faces")
}

fn error(path: &Path) -> String {
    format!("{:#}", read_mesh(path).unwrap_err())
}

#[test]
fn round_trip_through_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let (vertices, triangles) = grid_with_hole();
    for ext in ["obj", "ply", "stl", "glb", "gltf"] {
        let path = dir.path().join(format!("grid.{ext}"));
        write_mesh(&path, &vertices, &triangles).unwrap();
        let first = std::fs::read(&path).unwrap();
        write_mesh(&path, &vertices, &triangles).unwrap();
        assert_eq!(
            std::fs::read(&path).unwrap(),
            first,
            "{ext}: not deterministic"
        );
        let mesh = read_mesh(&path).unwrap_or_else(|e| panic!("{ext}: {e:#}"));
        match ext {
            "obj" | "ply" => {
                assert_eq!(mesh.vertices, vertices, "{ext}");
                assert_eq!(faces(&mesh), triangles, "{ext}");
            }
            "glb" | "gltf" => {
                let expected: Vec<Point3> = vertices.iter().map(to_f32).collect();
                assert_eq!(mesh.vertices, expected, "{ext}");
                assert_eq!(faces(&mesh), triangles, "{ext}");
            }
            _ => {
                // STL: the same triangles, corner by corner, at f32 precision;
                // vertices shared again, numbered by first appearance.
                assert_eq!(faces(&mesh).len(), triangles.len());
                for (got, want) in faces(&mesh).iter().zip(&triangles) {
                    for k in 0..3 {
                        assert_eq!(
                            mesh.vertices[got[k] as usize],
                            to_f32(&vertices[want[k] as usize])
                        );
                    }
                }
                assert_eq!(mesh.vertices.len(), vertices.len());
                assert_eq!(faces(&mesh)[0], [0, 1, 2]);
            }
        }
    }
}

#[test]
fn stl_and_gltf_are_recognised_by_content_under_other_names() {
    let dir = tempfile::tempdir().unwrap();
    let (vertices, triangles) = grid_with_hole();
    for (ext, disguise) in [
        ("stl", "mesh.dat"),
        ("glb", "mesh.bin"),
        ("gltf", "mesh.json"),
    ] {
        let path = dir.path().join(format!("grid.{ext}"));
        write_mesh(&path, &vertices, &triangles).unwrap();
        let other = dir.path().join(disguise);
        std::fs::copy(&path, &other).unwrap();
        let bytes = std::fs::read(&other).unwrap();
        let want = if ext == "stl" {
            MeshInput::Stl
        } else {
            MeshInput::Gltf
        };
        assert_eq!(MeshInput::detect(&other, &bytes).unwrap(), want);
        assert_eq!(read_mesh(&other).unwrap(), read_mesh(&path).unwrap());
    }
}

/// A binary STL's 80-byte header is free text: one that starts like an
/// OBJ or PCD file must still read as STL, as a cloud as well as a mesh
/// (not be sniffed as OBJ or PCD and refused).
#[test]
fn stl_headers_that_look_like_other_formats_read_as_stl() {
    let dir = tempfile::tempdir().unwrap();
    let (vertices, triangles) = grid_with_hole();
    let path = dir.path().join("grid.stl");
    write_mesh(&path, &vertices, &triangles).unwrap();
    let written = std::fs::read(&path).unwrap();
    for banner in [
        "v 2. ScanTool",
        "VERSION 2 ScanTool",
        "FIELDS x y z",
        "# .PCD v0.7",
    ] {
        let mut bytes = format!("{banner:<80}").into_bytes();
        bytes.extend(&written[80..]);
        let path = dir.path().join("banner.STL");
        std::fs::write(&path, &bytes).unwrap();
        let cloud = read_cloud(&path).unwrap_or_else(|e| panic!("{banner}: {e:#}"));
        assert_eq!(cloud.format, Format::MeshVertices, "{banner}");
        assert_eq!(cloud.points, read_mesh(&path).unwrap().vertices, "{banner}");
    }
}

const ASCII_STL: &str = "solid tetra  \n\
  facet normal 0 0 -1\n    outer loop\n      vertex 0 0 0\n      vertex 0 1 0\n      vertex 1 0 0\n    endloop\n  endfacet\n\
  facet normal 0 -1 0\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n      vertex 0 0 1\n    endloop\n  endfacet\n\
  facet normal -1 0 0\n    outer loop\n      vertex 0 0 0\n      vertex 0 0 1\n      vertex 0 1 0\n    endloop\n  endfacet\n\
  facet normal 1 1 1\n    outer loop\n      vertex 1 0 0\n      vertex 0 1 0\n      vertex 0 0 1.5e-1\n    endloop\n  endfacet\n\
endsolid tetra\n";

#[test]
fn hand_written_ascii_stl() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["tetra.stl", "tetra.txt"] {
        let path = dir.path().join(name);
        std::fs::write(&path, ASCII_STL).unwrap();
        let mesh = read_mesh(&path).unwrap();
        assert_eq!(
            mesh.vertices,
            vec![
                [0., 0., 0.],
                [0., 1., 0.],
                [1., 0., 0.],
                [0., 0., 1.],
                [0., 0., 0.15]
            ],
            "{name}"
        );
        assert_eq!(
            faces(&mesh),
            [[0, 1, 2], [0, 2, 3], [0, 3, 1], [2, 1, 4]],
            "{name}"
        );
        assert_eq!(mesh.normals, None);
    }
}

#[test]
fn stl_errors() {
    let dir = tempfile::tempdir().unwrap();
    let (vertices, triangles) = grid_with_hole();
    let path = dir.path().join("cut.stl");
    write_mesh(&path, &vertices, &triangles).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..84 + 50 * 7 + 31]).unwrap();
    let e = error(&path);
    assert!(e.starts_with(&path.display().to_string()), "{e}");
    assert!(
        e.ends_with(&format!(
            "binary STL truncated: the header declares {} triangles ({} bytes), the file has {} \
             bytes and ends in triangle 7",
            triangles.len(),
            84 + 50 * triangles.len(),
            84 + 50 * 7 + 31
        )),
        "{e}"
    );

    let bad = dir.path().join("bad.stl");
    std::fs::write(
        &bad,
        ASCII_STL.replace("vertex 0 0 1\n    endloop", "vertex 0 0\n    endloop"),
    )
    .unwrap();
    let e = error(&bad);
    assert!(
        e.ends_with("line 13: a vertex needs x, y and z, found 2 value(s)"),
        "{e}"
    );
    std::fs::write(&bad, ASCII_STL.replace("outer loop", "outer")).unwrap();
    assert!(error(&bad).ends_with("line 3: expected 'outer loop', found 'outer'"));
}

/// A glTF with an embedded buffer: a unit right triangle (u16 indices) as
/// mesh 0, placed by a parent node (translation) and a child node (scale),
/// and instanced again under a mirroring matrix.
fn transformed_gltf(mode: u32) -> String {
    let mut bin = Vec::new();
    for p in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.]] {
        for c in p {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2, 0] {
        bin.extend_from_slice(&i.to_le_bytes()); // the last one is padding
    }
    let data = base64::engine::general_purpose::STANDARD.encode(&bin);
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0, 2, 3]}}],
  "nodes": [
    {{"name": "parent", "translation": [10, 20, 30], "children": [1]}},
    {{"name": "child", "scale": [2, 3, 4], "translation": [1, 0, 0], "mesh": 0}},
    {{"name": "mirror", "matrix": [-1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1], "mesh": 0}},
    {{"name": "turn", "rotation": [0, 0, 0.70710677, 0.70710677], "mesh": 0}}
  ],
  "meshes": [{{"name": "tri", "primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "mode": {mode}}}]}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}},
    {{"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}}
  ],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 36}},
    {{"buffer": 0, "byteOffset": 36, "byteLength": 6}}
  ],
  "buffers": [{{"byteLength": {len}, "uri": "data:application/octet-stream;base64,{data}"}}]
}}"#,
        len = bin.len()
    )
}

#[test]
fn gltf_node_transforms_are_applied() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("placed.gltf");
    std::fs::write(&path, transformed_gltf(4)).unwrap();
    let mesh = read_mesh(&path).unwrap();
    // Child: scale (2, 3, 4) then translation (1, 0, 0), then the parent's
    // translation (10, 20, 30).
    assert_eq!(
        mesh.vertices[..3],
        [[11., 20., 30.], [13., 20., 30.], [11., 23., 30.]]
    );
    // The mirror: x negated, and the winding reversed to keep the front.
    assert_eq!(
        mesh.vertices[3..6],
        [[0., 0., 0.], [-1., 0., 0.], [0., 1., 0.]]
    );
    // The quarter turn about z takes x to y and y to -x.
    let turned = [[0., 0., 0.], [0., 1., 0.], [-1., 0., 0.]];
    for (got, want) in mesh.vertices[6..].iter().zip(turned) {
        assert!((0..3).all(|k| (got[k] - want[k]).abs() < 1e-7), "{got:?}");
    }
    assert_eq!(faces(&mesh), [[0, 1, 2], [3, 5, 4], [6, 7, 8]]);
}

#[test]
fn gltf_buffer_beside_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let text = transformed_gltf(4);
    let uri_start = text.find("data:").unwrap();
    let uri_end = uri_start + text[uri_start..].find('"').unwrap();
    let data = text[uri_start..uri_end].split_once(',').unwrap().1;
    let bin = base64::engine::general_purpose::STANDARD
        .decode(data)
        .unwrap();
    std::fs::write(dir.path().join("tri angle.bin"), bin).unwrap();
    let path = dir.path().join("beside.gltf");
    std::fs::write(
        &path,
        format!("{}tri%20angle.bin{}", &text[..uri_start], &text[uri_end..]),
    )
    .unwrap();
    let mesh = read_mesh(&path).unwrap();
    assert_eq!(mesh.vertices.len(), 9);

    std::fs::remove_file(dir.path().join("tri angle.bin")).unwrap();
    let e = error(&path);
    assert!(e.contains("buffer 0: cannot read"), "{e}");
    assert!(e.contains("tri angle.bin"), "{e}");
}

/// A buffer URI may name any file, not only a regular one: a FIFO (whose
/// opening waits for a writer forever), a device that never ends such as
/// `/dev/zero` (reached by an absolute or `..` path; reading it would fill
/// the memory) or a directory must each give an error at once.
#[cfg(unix)]
#[test]
fn gltf_buffer_that_is_not_a_regular_file() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("fifo.bin");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.unwrap().success(), "mkfifo");
    let text = transformed_gltf(4);
    let uri_start = text.find("data:").unwrap();
    let uri_end = uri_start + text[uri_start..].find('"').unwrap();
    for uri in ["fifo.bin", "."] {
        let path = dir.path().join("device.gltf");
        let doc = format!("{}{uri}{}", &text[..uri_start], &text[uri_end..]);
        std::fs::write(&path, doc).unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || tx.send(error(&path)));
        let e = rx
            .recv_timeout(std::time::Duration::from_secs(20))
            .unwrap_or_else(|_| panic!("reading buffer '{uri}' does not end"));
        assert!(e.contains("buffer 0: cannot read"), "{e}");
        assert!(e.ends_with("not a regular file"), "{e}");
    }
}

#[test]
fn gltf_errors() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("lines.gltf");
    std::fs::write(&path, transformed_gltf(1)).unwrap();
    let e = error(&path);
    assert!(
        e.ends_with(
            "node 1, mesh 0 'tri', primitive 0: mode LINES is not supported, only TRIANGLES"
        ),
        "{e}"
    );

    let path = dir.path().join("short.gltf");
    let text = transformed_gltf(4).replace(
        r#""count": 3, "type": "SCALAR""#,
        r#""count": 6, "type": "SCALAR""#,
    );
    std::fs::write(&path, text).unwrap();
    let e = error(&path);
    assert!(
        e.ends_with(
            "accessor 1 (indices): 6 elements from byte 0 do not fit in buffer view 1 (6 bytes)"
        ),
        "{e}"
    );

    let path = dir.path().join("broken.glb");
    std::fs::write(&path, b"glTF\x02\0\0\0junk").unwrap();
    assert!(error(&path).contains("malformed glTF"));
}

/// A `.gltf` whose one mesh, `vertices` positions with `indices` u8
/// indices (cycling 0, 1, 2) or none, is placed by `nodes` nodes.
fn instanced_gltf(vertices: usize, indices: Option<usize>, nodes: usize) -> String {
    let mut bin: Vec<u8> = (0..vertices)
        .flat_map(|i| [i as f32, 0.0, 0.0])
        .flat_map(f32::to_le_bytes)
        .collect();
    let positions_len = bin.len();
    bin.extend((0..indices.unwrap_or(0)).map(|i| (i % 3) as u8));
    let (indices_key, index_accessor, index_view) = match indices {
        Some(n) => (
            r#", "indices": 1"#.to_string(),
            format!(
                r#", {{"bufferView": 1, "componentType": 5121, "count": {n}, "type": "SCALAR"}}"#
            ),
            format!(r#", {{"buffer": 0, "byteOffset": {positions_len}, "byteLength": {n}}}"#),
        ),
        None => (String::new(), String::new(), String::new()),
    };
    let data = base64::engine::general_purpose::STANDARD.encode(&bin);
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "nodes": [{nodes}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}{indices_key}}}]}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": {vertices}, "type": "VEC3",
     "min": [0, 0, 0], "max": [{last}, 0, 0]}}{index_accessor}
  ],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": {positions_len}}}{index_view}
  ],
  "buffers": [{{"byteLength": {len}, "uri": "data:application/octet-stream;base64,{data}"}}]
}}"#,
        nodes = vec![r#"{"mesh": 0}"#; nodes].join(", "),
        last = vertices - 1,
        len = bin.len(),
    )
}

/// Every node that uses a mesh gets its own copy of the mesh's vertices,
/// so a file of a few hundred kilobytes can ask for gigabytes: 10,002
/// nodes each placing one 9,999-vertex accessor make 100 million vertices
/// (2.4 GB), and 10,001 nodes each placing 20,000 triangles of one-byte
/// indices 200 million triangles. The totals are counted before anything
/// is allocated, and refused above the documented limits.
#[test]
fn gltf_instancing_beyond_the_limit_is_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("instances.gltf");
    std::fs::write(&path, instanced_gltf(9_999, None, 3)).unwrap();
    assert_eq!(read_mesh(&path).unwrap().vertices.len(), 3 * 9_999);

    std::fs::write(&path, instanced_gltf(9_999, None, 10_002)).unwrap();
    let e = error(&path);
    assert!(
        e.ends_with(
            "the 10002 nodes that use meshes would make 100009998 vertices (the file stores \
             9999), more than the limit of 100000000 (2.4 GB in memory) for instanced meshes; \
             use fewer nodes per mesh, or save the scene flattened (a copy per instance) as PLY \
             or OBJ, which have no such limit"
        ),
        "{e}"
    );

    std::fs::write(&path, instanced_gltf(3, Some(60_000), 10_001)).unwrap();
    let e = error(&path);
    assert!(
        e.contains(
            "the 10001 nodes that use meshes would make 200020000 triangles (the file stores \
             20000), more than the limit of 200000000 (2.4 GB in memory)"
        ),
        "{e}"
    );
}

/// `"uri": ""` in a `.gltf` names no buffer, and the error says so.
/// Joined to the file's directory and read, it would give `cannot read
/// '…/': not a regular file`, or `cannot read '': No such file or
/// directory` for a file in the current directory, which hides that the
/// URI is empty.
#[test]
fn gltf_buffer_with_an_empty_uri() {
    let dir = tempfile::tempdir().unwrap();
    let text = transformed_gltf(4);
    let uri_start = text.find("data:").unwrap();
    let uri_end = uri_start + text[uri_start..].find('"').unwrap();
    let path = dir.path().join("empty-uri.gltf");
    std::fs::write(&path, format!("{}{}", &text[..uri_start], &text[uri_end..])).unwrap();
    let e = error(&path);
    assert!(
        e.ends_with(
            "buffer 0 has an empty URI: it needs the name of a file beside the document or a \
             base64 data: URI"
        ),
        "{e}"
    );
}

/// Buffer URIs are relative references resolved against the document's
/// directory, `..` included (asset pipelines share buffers that way);
/// URIs with a scheme other than `data:` are refused, each with its own
/// message (`file:` is not called a remote URI, and `http:x` without
/// `//` is not read as a file name).
#[test]
fn gltf_buffer_uris_relative_parent_and_schemes() {
    let dir = tempfile::tempdir().unwrap();
    let text = transformed_gltf(4);
    let uri_start = text.find("data:").unwrap();
    let uri_end = uri_start + text[uri_start..].find('"').unwrap();
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(text[uri_start..uri_end].split_once(";base64,").unwrap().1)
        .unwrap();
    std::fs::write(dir.path().join("shared.bin"), &bytes).unwrap();
    std::fs::create_dir(dir.path().join("scene")).unwrap();
    let with_uri = |name: &str, uri: &str| {
        let path = dir.path().join("scene").join(name);
        std::fs::write(
            &path,
            format!("{}{uri}{}", &text[..uri_start], &text[uri_end..]),
        )
        .unwrap();
        path
    };
    let embedded = meshtrim::io::read_mesh(&with_uri("embedded.gltf", &text[uri_start..uri_end]));
    let parent = meshtrim::io::read_mesh(&with_uri("parent.gltf", "../shared.bin"));
    assert_eq!(parent.unwrap(), embedded.unwrap());
    let e = error(&with_uri("file.gltf", "file:///tmp/shared.bin"));
    assert!(
        e.ends_with(
            "buffer 0: file URI 'file:///tmp/shared.bin' is not supported: name the buffer \
             relative to the document (e.g. 'mesh.bin' or '../shared/mesh.bin') or embed it as a \
             base64 data: URI"
        ),
        "{e}"
    );
    for uri in ["http://example.com/a.bin", "ftp:a.bin"] {
        let e = error(&with_uri("remote.gltf", uri));
        assert!(
            e.ends_with(&format!(
                "buffer 0: URI '{uri}' is not supported: only files relative to the document \
                 and base64 data: URIs are read"
            )),
            "{e}"
        );
    }
}

/// A glTF whose meshes no node uses, or with no meshes at all, has nothing
/// to read; each case has its own error, not `no vertices in the file`,
/// which reads like a mesh without vertices.
#[test]
fn gltf_without_mesh_instances_says_why() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("unused.gltf");
    let unused =
        instanced_gltf(3, None, 1).replace(r#""nodes": [{"mesh": 0}]"#, r#""nodes": [{}]"#);
    std::fs::write(&path, unused).unwrap();
    let e = error(&path);
    assert!(
        e.ends_with(
            "no node uses a mesh (the file has 1 mesh): glTF places a mesh only through a node \
             that uses it, and meshes that no node uses are not read"
        ),
        "{e}"
    );
    assert!(format!("{:#}", read_cloud(&path).unwrap_err()).ends_with("are not read"));

    let path = dir.path().join("empty.gltf");
    std::fs::write(&path, r#"{"asset": {"version": "2.0"}}"#).unwrap();
    assert!(error(&path).ends_with("the file has no meshes"));
}

/// glTF rotations are unit quaternions. One of length 2, read as it
/// stands, would distort the mesh instead of turning it (the rotation
/// formula assumes a unit quaternion), so it is an error naming the node,
/// while one within rounding of unit length is normalised.
#[test]
fn gltf_rotation_must_be_a_unit_quaternion() {
    let dir = tempfile::tempdir().unwrap();
    let with_rotation = |q: &str| {
        instanced_gltf(3, None, 1).replace(
            r#""nodes": [{"mesh": 0}]"#,
            &format!(r#""nodes": [{{"mesh": 0, "rotation": [{q}]}}]"#),
        )
    };
    let path = dir.path().join("long.gltf");
    std::fs::write(&path, with_rotation("0, 0, 0, 2")).unwrap();
    let e = error(&path);
    assert!(e.contains("node 0") && e.contains("has length 2"), "{e}");
    // A quarter turn about z, written with f32 rounding: read as the unit
    // quaternion, so (2, 0, 0) lands at (0, 2, 0) to within rounding.
    let path = dir.path().join("turned.gltf");
    let h = std::f64::consts::FRAC_1_SQRT_2 * 1.0002;
    std::fs::write(&path, with_rotation(&format!("0, 0, {h}, {h}"))).unwrap();
    let mesh = read_mesh(&path).unwrap();
    let p = mesh.vertices[2];
    assert!(
        p[0].abs() < 1e-6 && (p[1] - 2.0).abs() < 1e-6 && p[2].abs() < 1e-6,
        "{p:?}"
    );
}

/// PLY and PCD headers whose lines end with a lone carriage return
/// (classic Mac OS) read without `no 'end_header' line` or `no DATA line`,
/// and such a PLY is recognised under another extension too. Binary
/// data follows a header and may start with a `\n` byte (here the first
/// byte of x), which must not be taken for the end of a `\r\n`.
#[test]
fn ply_and_pcd_headers_with_lone_carriage_returns() {
    let dir = tempfile::tempdir().unwrap();
    let read = |name: &str, bytes: &[u8]| {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        read_cloud(&path)
    };
    // x's little-endian bytes start with 0x0a, a '\n'.
    let x = f32::from_bits(0x3f80_000a);
    let points = [[f64::from(x), 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 0.5]];
    let ply_header = |format: &str| {
        format!(
            "ply\nformat {format} 1.0\ncomment lone CR\nelement vertex 3\nproperty float x\n\
             property float y\nproperty float z\nend_header\n"
        )
    };
    let pcd_header = |data: &str| {
        format!(
            "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n\
             WIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA {data}\n"
        )
    };
    let ascii: String = points
        .iter()
        .map(|p| format!("{} {} {}\n", p[0], p[1], p[2]))
        .collect();
    let binary: Vec<u8> = points
        .iter()
        .flatten()
        .flat_map(|&c| (c as f32).to_le_bytes())
        .collect();
    assert_eq!(binary[0], b'\n');
    for (eol, tag) in [("\n", "lf"), ("\r\n", "crlf"), ("\r", "cr")] {
        // ASCII bodies end their lines alike; binary bodies are bytes.
        let text = ascii.replace('\n', eol).into_bytes();
        let files = [
            ("ply", ply_header("ascii"), &text),
            ("ply", ply_header("binary_little_endian"), &binary),
            ("pcd", pcd_header("ascii"), &text),
            ("pcd", pcd_header("binary"), &binary),
        ];
        for (i, (ext, header, body)) in files.into_iter().enumerate() {
            let mut bytes = header.replace('\n', eol).into_bytes();
            bytes.extend(body);
            // A .dat name: the format is recognised by content.
            let cloud = read(&format!("{tag}_{i}.dat"), &bytes);
            let cloud = cloud.unwrap_or_else(|e| panic!("{tag} {i}: {e:#}"));
            assert_eq!(cloud.format.name(), ext, "{tag} {i}");
            assert_eq!(cloud.points, points, "{tag} {i}");
        }
    }
    // Line numbers count lone carriage returns, in the header and after.
    let bad = ply_header("ascii").replace('\n', "\r") + "1 2 3\r4 x 6\r7 8 9\r";
    let e = format!("{:#}", read("bad.ply", bad.as_bytes()).unwrap_err());
    assert!(e.ends_with("line 10: 'x' is not a number"), "{e}");
    let bad = pcd_header("ascii").replace('\n', "\r") + "1 2 3\r4 x 6\r7 8 9\r";
    let e = format!("{:#}", read("bad.pcd", bad.as_bytes()).unwrap_err());
    assert!(e.ends_with("line 12: 'x' is not a number"), "{e}");
}

/// A PLY or PCD header whose first line ends with `\n` and a later one
/// with a lone `\r` is an error naming that header line. Run into the
/// next, the line would make a PCD `FIELDS` line take the `SIZE` and
/// `TYPE` lines' words for 11 field names and fail on the data (`line 7:
/// expected 11 values, found 3`). A lone `\r` in a comment is left alone.
#[test]
fn ply_and_pcd_headers_with_mixed_line_endings() {
    let dir = tempfile::tempdir().unwrap();
    let message = "a lone carriage return inside the line: every header line must end as the \
                   first does, and the first ends with a newline";
    let pcd = "VERSION .7\n# a\rcomment\nFIELDS x y z\rSIZE 4 4 4\rTYPE F F F\nWIDTH 1\n\
               HEIGHT 1\nDATA ascii\n1 2 3\n";
    let ply = "ply\r\nformat ascii 1.0\r\ncomment a\rcomment\r\nelement vertex 1\r\
               property float x\r\nproperty float y\r\nproperty float z\r\nend_header\r\n1 2 3\r\n";
    for (name, text, line) in [("mixed.pcd", pcd, 3), ("mixed.ply", ply, 4)] {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let e = format!("{:#}", read_cloud(&path).unwrap_err());
        assert!(
            e.ends_with(&format!("header: line {line}: {message}")),
            "{e}"
        );
    }
}

/// Lines ended by a lone carriage return (classic Mac OS, Excel for Mac's
/// "CSV (Macintosh)") read like lines ended by a newline. Read as one long
/// line, an OBJ mesh would be one vertex and no faces, a text cloud one
/// point (the other values ignored as extra fields), and an ASCII STL
/// would "end inside a solid".
#[test]
fn lone_carriage_returns_end_lines() {
    let dir = tempfile::tempdir().unwrap();
    let (v, f) = grid_with_hole();
    let obj: String = v
        .iter()
        .map(|p| format!("v {} {} {}\n", p[0], p[1], p[2]))
        .chain(
            f.iter()
                .map(|t| format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1)),
        )
        .collect();
    let csv: String = v
        .iter()
        .map(|p| format!("{},{},{}\n", p[0], p[1], p[2]))
        .collect();
    let stl_path = dir.path().join("lf.stl");
    write_mesh(&stl_path, &v, &f).unwrap();
    let stl: String = std::iter::once("solid cr\n".to_string())
        .chain(f.iter().map(|t| {
            let corner = |i: u32| {
                let p = to_f32(&v[i as usize]);
                format!("vertex {} {} {}\n", p[0], p[1], p[2])
            };
            format!(
                "facet normal 0 0 0\nouter loop\n{}{}{}endloop\nendfacet\n",
                corner(t[0]),
                corner(t[1]),
                corner(t[2])
            )
        }))
        .chain(std::iter::once("endsolid cr\n".to_string()))
        .collect();
    for (name, text) in [
        ("m.obj", obj),
        ("c.csv", format!("x,y,z\n{csv}")),
        ("c.xyz", csv.replace(',', " ")),
        ("m.stl", stl),
    ] {
        let lf = dir.path().join(format!("lf_{name}"));
        let cr = dir.path().join(format!("cr_{name}"));
        std::fs::write(&lf, &text).unwrap();
        std::fs::write(&cr, text.replace('\n', "\r")).unwrap();
        let lf_cloud = read_cloud(&lf).unwrap().points;
        assert_eq!(lf_cloud.len(), 30, "{name}");
        assert_eq!(read_cloud(&cr).unwrap().points, lf_cloud, "{name}");
        if name.starts_with("m.") {
            assert_eq!(read_mesh(&cr).unwrap(), read_mesh(&lf).unwrap(), "{name}");
        }
    }
    // Line numbers count lone carriage returns too.
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 1 2 3\r\nv 4 5 6\rv 1 x 3\r").unwrap();
    assert!(
        error(&bad).ends_with("line 3: 'x' is not a number"),
        "{}",
        error(&bad)
    );
}

#[test]
fn obj_and_ply_face_index_out_of_range() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("bad.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 7\n").unwrap();
    assert!(error(&obj).ends_with("triangle 1 refers to vertex 7, but there are only 3 vertices"));

    let ply = dir.path().join("bad.ply");
    std::fs::write(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n\
         0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 5\n",
    )
    .unwrap();
    assert!(error(&ply).ends_with("triangle 1 refers to vertex 5, but there are only 3 vertices"));
}

/// PLY files as Poisson reconstruction (`value`) and MeshLab (`quality`)
/// write them: extra vertex properties are skipped.
#[test]
fn ply_extra_vertex_properties_are_ignored() {
    let dir = tempfile::tempdir().unwrap();
    let (vertices, triangles) = grid_with_hole();
    let header = |format: &str| {
        format!(
            "ply\nformat {format} 1.0\ncomment generated like PoissonRecon / MeshLab\n\
             element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
             property float value\nproperty uchar red\nproperty float quality\n\
             element face {}\nproperty list uchar int vertex_indices\nend_header\n",
            vertices.len(),
            triangles.len()
        )
    };
    let mut ascii = header("ascii");
    let mut binary = header("binary_little_endian").into_bytes();
    for (i, p) in vertices.iter().enumerate() {
        let p = p.map(|c| c as f32);
        let q = p.map(f64::from); // the f32 values, written exactly
        ascii += &format!(
            "{} {} {} {} 200 {}\n",
            q[0],
            q[1],
            q[2],
            i as f32 * 0.5,
            -1.25
        );
        for c in [p[0], p[1], p[2], i as f32 * 0.5] {
            binary.extend_from_slice(&c.to_le_bytes());
        }
        binary.push(200);
        binary.extend_from_slice(&(-1.25f32).to_le_bytes());
    }
    for f in &triangles {
        ascii += &format!("3 {} {} {}\n", f[0], f[1], f[2]);
        binary.push(3);
        for v in f {
            binary.extend_from_slice(&(*v as i32).to_le_bytes());
        }
    }
    let expected: Vec<Point3> = vertices.iter().map(to_f32).collect();
    for (name, bytes) in [("ascii.ply", ascii.into_bytes()), ("binary.ply", binary)] {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let mesh = read_mesh(&path).unwrap();
        assert_eq!(mesh.vertices, expected, "{name}");
        assert_eq!(faces(&mesh), triangles, "{name}");
    }
}

#[test]
fn unknown_extensions() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mesh.dat");
    std::fs::write(&path, "hello\n").unwrap();
    let e = error(&path);
    assert!(
        e.ends_with(
            "unknown mesh format: the extension 'dat' is not one of ply, obj, stl, gltf, glb, \
             and the content is not recognised as any of them"
        ),
        "{e}"
    );

    let (vertices, triangles) = grid_with_hole();
    let out = dir.path().join("mesh.off");
    let e = format!("{:#}", write_mesh(&out, &vertices, &triangles).unwrap_err());
    assert!(
        e.ends_with(
            "cannot write a mesh as '.off': the extension must be one of obj, ply, stl, glb, gltf"
        ),
        "{e}"
    );
    // A bad mesh is refused before anything is written.
    let out = dir.path().join("bad.ply");
    let e = format!(
        "{:#}",
        write_mesh(&out, &vertices, &[[0, 1, 99]]).unwrap_err()
    );
    assert!(
        e.ends_with("triangle 0 refers to vertex 99, but there are only 30 vertices"),
        "{e}"
    );
    assert!(!out.exists());
}

fn real(rel: &str) -> PathBuf {
    common::shared_data(rel)
}

/// Every prefix of a valid file (and a few corrupted bytes) gives a result
/// or an error, never a panic.
#[test]
fn damaged_files_never_panic() {
    let dir = tempfile::tempdir().unwrap();
    let (vertices, triangles) = grid_with_hole();
    for ext in ["stl", "glb", "gltf", "ply", "obj"] {
        let path = dir.path().join(format!("whole.{ext}"));
        write_mesh(&path, &vertices, &triangles).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let cut = dir.path().join(format!("cut.{ext}"));
        for len in (0..bytes.len()).step_by(11) {
            std::fs::write(&cut, &bytes[..len]).unwrap();
            let _ = read_mesh(&cut);
            let mut flipped = bytes.clone();
            flipped[len] ^= 0x5a;
            std::fs::write(&cut, &flipped).unwrap();
            let _ = read_mesh(&cut);
        }
    }
}

/// A binary range scan: a 3 × 2 grid whose last entry is empty, over five
/// vertices; `last` is the fifth entry's vertex index.
fn range_scan(last: i32) -> Vec<u8> {
    let mut bytes = b"ply\nformat binary_little_endian 1.0\nobj_info num_cols 3\n\
        obj_info num_rows 2\nelement vertex 5\nproperty float x\nproperty float y\n\
        property float z\nelement range_grid 6\nproperty list uchar int vertex_indices\n\
        end_header\n"
        .to_vec();
    for p in [
        [0f32, 0., 0.],
        [1., 0., 0.],
        [2., 0., 0.],
        [0., 1., 0.],
        [1., 1., 0.],
    ] {
        for c in p {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    for v in [0, 1, 2, 3, last] {
        bytes.push(1);
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes.push(0);
    bytes
}

#[test]
fn range_scans_read_as_meshes() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scan.ply");
    std::fs::write(&path, range_scan(4)).unwrap();
    let mesh = read_mesh(&path).unwrap();
    // A full cell (two triangles) and a cell with three entries.
    assert_eq!(faces(&mesh).len(), 3);
    let cloud = meshtrim::io::read_cloud(&path).unwrap();
    assert_eq!(cloud.points.len(), 5);

    std::fs::write(&path, range_scan(5)).unwrap();
    let e = error(&path);
    assert!(e.starts_with(&path.display().to_string()), "{e}");
    assert!(
        e.ends_with("range_grid entry 4 refers to vertex 5, but there are only 5 vertices"),
        "{e}"
    );
    // The cloud reader skips the grid, good or bad.
    assert_eq!(meshtrim::io::read_cloud(&path).unwrap().points.len(), 5);

    // Damaged copies give errors, never panics.
    let bytes = range_scan(4);
    for len in 0..bytes.len() {
        std::fs::write(&path, &bytes[..len]).unwrap();
        let _ = read_mesh(&path);
        let mut flipped = bytes.clone();
        flipped[len] ^= 0x5a;
        std::fs::write(&path, &flipped).unwrap();
        let _ = read_mesh(&path);
    }
}

/// Tests on the real scans that are not shipped in `fixtures/` (their
/// licences do not allow it): run wherever `../shared/data` is, skipped by
/// `scripts/test.sh` elsewhere, and required in CI.
mod shared_data {
    use super::*;

    #[test]
    fn real_bunny_reads_and_round_trips() {
        let mesh = read_mesh(&real("stanford_bunny/bun_zipper.ply")).unwrap();
        assert_eq!(mesh.vertices.len(), 35_947);
        assert_eq!(faces(&mesh).len(), 69_451);
        let dir = tempfile::tempdir().unwrap();
        for ext in ["obj", "ply", "stl", "glb"] {
            let path = dir.path().join(format!("bunny.{ext}"));
            write_mesh(&path, &mesh.vertices, faces(&mesh)).unwrap();
            let back = read_mesh(&path).unwrap();
            assert_eq!(faces(&back).len(), 69_451, "{ext}");
            if ext == "obj" || ext == "ply" {
                // Written without its attributes (confidence, intensity).
                let expected = Mesh {
                    normals: None,
                    scalars: Vec::new(),
                    ..mesh.clone()
                };
                assert!(back == expected, "{ext}: the mesh differs");
            }
            if ext == "glb" {
                let expected: Vec<Point3> = mesh.vertices.iter().map(to_f32).collect();
                assert!(back.vertices == expected, "glb: positions differ");
            }
            if ext == "stl" {
                // Corner by corner at f32 precision (shared vertices renumbered).
                let same = faces(&back).iter().zip(faces(&mesh)).all(|(g, w)| {
                    (0..3).all(|k| {
                        back.vertices[g[k] as usize] == to_f32(&mesh.vertices[w[k] as usize])
                    })
                });
                assert!(same, "stl: triangles differ");
            }
        }
    }

    #[test]
    fn real_meshlab_scan_reads() {
        let mesh = read_mesh(&real("meshlab_scans/face000.ply")).unwrap();
        assert_eq!(faces(&mesh).len(), 166_259);
        let n = mesh.vertices.len();
        assert!(faces(&mesh).iter().flatten().all(|&v| (v as usize) < n));
    }
}
