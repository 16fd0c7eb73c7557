//! End-to-end: a textured OBJ (texture coordinates, two materials, a
//! library naming an image) cleaned by the `meshtrim` binary keeps its
//! texture, its library and image found from the output.

use std::path::{Path, PathBuf};

mod common;
use common::meshtrim;

const JAGGED: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/fixtures/meshes/blade_jagged.stl"
);

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The fixture as an OBJ under `dir/in/scan.obj`: `vt` from x and y, the
/// faces left of the middle under `left`, the others under `right`, and
/// `libraries` as its `mtllib` lines. Returns its path, the welded
/// fixture and the middle x.
fn textured_fixture(dir: &Path, libraries: &[&str]) -> (PathBuf, trim::Mesh, f64) {
    let read = meshtrim::io::read_mesh(Path::new(JAGGED)).unwrap();
    let mesh = trim::Mesh {
        vertices: read.vertices,
        faces: read.faces.unwrap(),
    };
    let mut xs: Vec<f64> = mesh.vertices.iter().map(|p| p[0]).collect();
    xs.sort_by(f64::total_cmp);
    let middle = xs[xs.len() / 2];
    let mut text: String = libraries.iter().map(|l| format!("mtllib {l}\n")).collect();
    for [x, y, z] in &mesh.vertices {
        text += &format!(
            "v {x:?} {y:?} {z:?}\nvt {:?} {:?}\n",
            x / 1000.0,
            y / 1000.0
        );
    }
    let mut material = "";
    for face in &mesh.faces {
        let centre = face
            .iter()
            .map(|&v| mesh.vertices[v as usize][0])
            .sum::<f64>()
            / 3.0;
        let this = if centre > middle { "right" } else { "left" };
        if this != material {
            text += &format!("usemtl {this}\n");
            material = this;
        }
        let [a, b, c] = face.map(|v| v + 1);
        text += &format!("f {a}/{a} {b}/{b} {c}/{c}\n");
    }
    let input = dir.join("in");
    std::fs::create_dir_all(input.join("tex")).unwrap();
    std::fs::write(input.join("scan.obj"), text).unwrap();
    (input.join("scan.obj"), mesh, middle)
}

fn library(dir: &Path) {
    let text = "newmtl left\nKd 1 0 0\nmap_Kd tex/left.png\n\nnewmtl right\nKd 0 0 1\nmap_Kd -bm 1 tex/right.png\n";
    std::fs::write(dir.join("in/scan.mtl"), text).unwrap();
    std::fs::write(dir.join("in/tex/left.png"), b"left image").unwrap();
    std::fs::write(dir.join("in/tex/right.png"), b"right image").unwrap();
}

fn clean(input: &Path, output: &Path) -> String {
    let run = meshtrim(&["clean", s(input), s(output)], None);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    String::from_utf8(run.stdout).unwrap()
}

/// Cleaned into another directory: the output's own library with the
/// images copied into its own folder, each face under its side's
/// material, a `vt` per vertex; the input's files untouched.
#[test]
fn a_textured_obj_keeps_its_materials_library_and_images() {
    let dir = tempfile::tempdir().unwrap();
    let (input, _, middle) = textured_fixture(dir.path(), &["scan.mtl"]);
    library(dir.path());
    let before = std::fs::read(&input).unwrap();
    let output = dir.path().join("out/cleaned.obj");
    let report = clean(&input, &output);
    assert!(
        report.contains("vertex attributes    texture coordinates, material"),
        "{report}"
    );
    assert_eq!(std::fs::read(&input).unwrap(), before);
    let out = dir.path().join("out");
    let images = out.join("cleaned_textures/tex");
    assert_eq!(
        std::fs::read(images.join("left.png")).unwrap(),
        b"left image"
    );
    assert_eq!(
        std::fs::read(images.join("right.png")).unwrap(),
        b"right image"
    );
    let mtl = std::fs::read_to_string(out.join("cleaned.mtl")).unwrap();
    assert!(
        mtl.contains("map_Kd -bm 1 cleaned_textures/tex/right.png\n"),
        "{mtl}"
    );
    let text = std::fs::read_to_string(&output).unwrap();
    assert!(text.contains("\nmtllib cleaned.mtl\n"), "{}", &text[..200]);

    // Read back as a mesh: every face's material is its side's, but for
    // a few new faces laid across the middle (measured: none).
    let written = meshtrim::io::read_mesh(&output).unwrap();
    let Some(meshtrim::io::Materials::Obj(material)) = &written.materials else {
        panic!("no OBJ materials read back");
    };
    assert_eq!(material.libraries, vec![out.join("cleaned.mtl")]);
    let across = faces_across(&written, middle, |f| {
        &material.names[material.faces[f] as usize]
    });
    assert!(across <= 4, "{across} faces on the other side's material");
    // The texture coordinates are still x / 1000 and y / 1000 on kept
    // vertices (new ones blend their face's; measured 2,757 of 2,998 exact).
    let uv = written.texcoords.unwrap();
    let exact = written
        .vertices
        .iter()
        .zip(&uv)
        .filter(|(p, t)| **t == [p[0] / 1000.0, p[1] / 1000.0])
        .count();
    assert!(exact > written.vertices.len() * 9 / 10, "{exact}");
}

/// How many faces of `mesh` lie on the other side of `middle` than the
/// name `side_of` gives each (its material's, or its image's) says.
fn faces_across<'a>(
    mesh: &meshtrim::io::Mesh,
    middle: f64,
    side_of: impl Fn(usize) -> &'a str,
) -> usize {
    let faces = mesh.faces.as_ref().unwrap();
    let mut across = 0;
    for (f, face) in faces.iter().enumerate() {
        let centre = face
            .iter()
            .map(|&v| mesh.vertices[v as usize][0])
            .sum::<f64>()
            / 3.0;
        let side = if centre > middle { "right" } else { "left" };
        across += usize::from(!side_of(f).contains(side));
    }
    across
}

/// Cleaned to PLY and to GLB, the OBJ's materials are made the output
/// format's: PLY's texture files (each face's number naming its side's
/// image, copied into the output's folder) and glTF's materials (named
/// as the MTL's, the PNG image embedded). The other image is no PNG or
/// JPEG, which glTF cannot hold: the report names it.
#[test]
fn a_textured_obj_converted_keeps_each_faces_image() {
    let dir = tempfile::tempdir().unwrap();
    let (input, _, middle) = textured_fixture(dir.path(), &["scan.mtl"]);
    library(dir.path());
    let png = b"\x89PNG\r\n\x1a\n left image";
    std::fs::write(dir.path().join("in/tex/left.png"), png).unwrap();
    let out = dir.path().join("out");

    let report = clean(&input, &out.join("scan.ply"));
    assert!(
        report.contains("vertex attributes    texture coordinates, material"),
        "{report}"
    );
    let written = meshtrim::io::read_mesh(&out.join("scan.ply")).unwrap();
    let Some(meshtrim::io::Materials::Ply(textures)) = &written.materials else {
        panic!("no PLY texture files read back");
    };
    let images = out.join("scan_textures");
    let mut files = textures.files.clone();
    files.sort();
    assert_eq!(files, [images.join("left.png"), images.join("right.png")]);
    assert_eq!(
        std::fs::read(images.join("right.png")).unwrap(),
        b"right image"
    );
    let files = |f: usize| textures.files[textures.faces[f] as usize].to_str().unwrap();
    let across = faces_across(&written, middle, files);
    assert!(across <= 4, "{across} faces on the other side's image");

    let report = clean(&input, &out.join("scan.glb"));
    assert!(
        report.contains(
            "texture image right.png not written: the output's format does not hold them"
        ),
        "{report}"
    );
    let written = meshtrim::io::read_mesh(&out.join("scan.glb")).unwrap();
    let Some(meshtrim::io::Materials::Gltf(gltf)) = &written.materials else {
        panic!("no glTF materials read back");
    };
    let names: Vec<&str> = gltf
        .materials
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    let mut sorted = names.clone();
    sorted.sort();
    assert_eq!(sorted, ["left", "right"]);
    // The left material's image only, in the buffer.
    let left = names.iter().position(|&n| n == "left").unwrap();
    let texture = &gltf.materials[left]["pbrMetallicRoughness"]["baseColorTexture"];
    assert_eq!(texture["index"], 0);
    assert_eq!(gltf.images.len(), 1);
    assert_eq!(gltf.images[0].bytes, png);
    let across = faces_across(&written, middle, |f| names[gltf.faces[f] as usize]);
    assert!(across <= 4, "{across} faces on the other side's material");
}

/// Beside the input's library, the output names it and writes nothing
/// else; a library that cannot be read is named as it was.
#[test]
fn beside_its_library_the_output_shares_it() {
    let dir = tempfile::tempdir().unwrap();
    let (input, _, _) = textured_fixture(dir.path(), &["scan.mtl"]);
    library(dir.path());
    let output = dir.path().join("in/cleaned.obj");
    clean(&input, &output);
    let text = std::fs::read_to_string(&output).unwrap();
    assert!(text.contains("\nmtllib scan.mtl\n"));
    assert!(!dir.path().join("in/cleaned.mtl").exists());

    let (input, _, _) = textured_fixture(dir.path(), &["nowhere.mtl"]);
    let output = dir.path().join("elsewhere/cleaned.obj");
    clean(&input, &output);
    let text = std::fs::read_to_string(&output).unwrap();
    assert!(text.contains("\nmtllib nowhere.mtl\n"));
    assert!(!dir.path().join("elsewhere/cleaned.mtl").exists());
}

/// An output whose own library would be one of the input's is refused,
/// naming both, and nothing is written.
#[test]
fn the_input_library_is_never_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let (input, _, _) = textured_fixture(dir.path(), &["cleaned.mtl", "../other/b.mtl"]);
    std::fs::create_dir_all(dir.path().join("other")).unwrap();
    std::fs::write(dir.path().join("in/cleaned.mtl"), "newmtl left\n").unwrap();
    std::fs::write(dir.path().join("other/b.mtl"), "newmtl right\n").unwrap();
    let output = dir.path().join("in/cleaned.obj");
    let run = meshtrim(&["clean", s(&input), s(&output)], None);
    assert_eq!(run.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("the output's material library would replace the input's"),
        "{stderr}"
    );
    assert!(!output.exists());
    assert_eq!(
        std::fs::read_to_string(dir.path().join("in/cleaned.mtl")).unwrap(),
        "newmtl left\n"
    );
}

/// Two textured scans whose images have the same names, cleaned into one
/// directory (as a batch writes them): each output keeps its own images.
#[test]
fn outputs_side_by_side_keep_their_own_images() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    for (name, bytes) in [("a", &b"image of a"[..]), ("b", &b"image of b"[..])] {
        let scan = dir.path().join(name);
        let (input, _, _) = textured_fixture(&scan, &["scan.mtl"]);
        library(&scan);
        std::fs::write(scan.join("in/tex/left.png"), bytes).unwrap();
        clean(&input, &out.join(format!("{name}.obj")));
    }
    for (name, bytes) in [("a", &b"image of a"[..]), ("b", &b"image of b"[..])] {
        let mtl = std::fs::read_to_string(out.join(format!("{name}.mtl"))).unwrap();
        let image = format!("{name}_textures/tex/left.png");
        assert!(mtl.contains(&format!("map_Kd {image}\n")), "{mtl}");
        assert_eq!(std::fs::read(out.join(image)).unwrap(), bytes);
    }
}
