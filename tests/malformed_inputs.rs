//! Seeded mutation fuzzing of every reader: valid small files in each
//! format meshtrim reads are truncated, overwritten, spliced and given
//! absurd header numbers, thousands of times, and read back as a cloud and
//! as a mesh. Bad input must give an error naming the file, never a panic,
//! an abort or an allocation sized by a header's claim.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use meshtrim::io::{read_cloud, read_mesh, write_mesh};
use testkit::synthetic::SplitMix64;

/// Mutated copies per seed file.
const MUTATIONS: usize = 4000;

#[test]
fn mutated_files_give_errors_not_panics() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let mut failures = Vec::new();
    let mut errors = 0usize;
    let mut reads = 0usize;
    for (name, bytes) in seed_files(dir.path()) {
        let path = dir.path().join(&name);
        std::fs::write(&path, &bytes).expect("write a seed file");
        // Every seed is a valid cloud; those in a mesh format are valid
        // meshes too (text and PCD files are clouds only).
        assert!(
            matches!(read_as_cloud(&path), Outcome::Read),
            "the seed {name} does not read"
        );
        let mesh_format = ["ply", "obj", "stl", "glb", "gltf"]
            .iter()
            .any(|e| name.ends_with(e));
        if mesh_format {
            assert!(
                matches!(read_as_mesh(&path), Outcome::Read),
                "the seed {name} does not read as a mesh"
            );
        }
        let mut rng = SplitMix64::new(0x5eed ^ bytes.len() as u64);
        for m in 0..MUTATIONS {
            let mutated = mutate(&bytes, &mut rng);
            let path = dir.path().join(format!("m{m}_{name}"));
            std::fs::write(&path, &mutated).expect("write a mutated file");
            for (what, outcome) in [
                ("cloud", read_as_cloud(&path)),
                ("mesh", read_as_mesh(&path)),
            ] {
                reads += 1;
                match outcome {
                    Outcome::Read => {}
                    Outcome::Error(message) => {
                        errors += 1;
                        if !message.contains(&*path.to_string_lossy()) {
                            failures.push(format!(
                                "{name} #{m} as {what}: error without the file name: {message}"
                            ));
                        }
                    }
                    Outcome::Panic(message) => {
                        let kept = dir.path().join(format!("panic_{m}_{name}"));
                        std::fs::copy(&path, &kept).ok();
                        failures.push(format!("{name} #{m} as {what}: panic: {message}"));
                    }
                }
            }
            std::fs::remove_file(&path).ok();
        }
    }
    eprintln!(
        "{reads} reads of mutated files, {errors} errors, {} failures",
        failures.len()
    );
    // Most mutations must be caught: a fuzzer whose inputs all read fine
    // would be testing nothing.
    assert!(
        errors * 4 > reads,
        "only {errors} of {reads} mutated reads failed"
    );
    assert!(
        failures.is_empty(),
        "{} failures, first ones: {:#?}",
        failures.len(),
        &failures[..failures.len().min(10)]
    );
}

/// Files that could make a reader panic, hang or misread them, with what
/// the error must say. Each is read as a cloud on a thread with a
/// deadline, so a hang fails the test instead of stalling it.
#[test]
fn known_bad_files_give_clear_errors() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let mut failures = Vec::new();
    for (name, bytes, expected) in known_bad_files() {
        let path = dir.path().join(name);
        std::fs::write(&path, &bytes).expect("write a bad file");
        let (send, receive) = std::sync::mpsc::channel();
        let read_path = path.clone();
        std::thread::spawn(move || send.send(read_as_cloud(&read_path)));
        let problem = match receive.recv_timeout(std::time::Duration::from_secs(20)) {
            Err(_) => "no answer in 20 s".to_string(),
            Ok(Outcome::Read) => "read without an error".to_string(),
            Ok(Outcome::Panic(message)) => format!("panic: {message}"),
            Ok(Outcome::Error(message)) => {
                let named = message.starts_with(&*path.to_string_lossy());
                if named && message.contains(expected) {
                    continue;
                }
                format!("error {message:?} does not name the file or say {expected:?}")
            }
        };
        failures.push(format!("{name}: {problem}"));
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The bad files of [`known_bad_files_give_clear_errors`]: name, bytes and
/// a part of the expected message.
fn known_bad_files() -> Vec<(&'static str, Vec<u8>, &'static str)> {
    let pcd = |counts: &str, data: &str, body: &[u8]| {
        let mut out = format!("FIELDS x y z\nCOUNT {counts}\nPOINTS 2\nDATA {data}\n").into_bytes();
        out.extend(body);
        out
    };
    let floats: Vec<u8> = [1f32, 2.0, 3.0, 4.0]
        .iter()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    // The same 16 bytes LZF-packed as one literal run, behind the sizes.
    let mut lzf_block = [17u32, 16].map(u32::to_le_bytes).concat();
    lzf_block.push(15);
    lzf_block.extend(&floats);
    let z0 = "line 2: COUNT 0 for field 'z'";
    // An element without properties and a huge count, then vertices
    // with a bad number: reaching that error needs the element skipped.
    let hang = "ply\nformat ascii 1.0\nelement junk 18446744073709551615\nelement vertex 2\n\
        property float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n4 x 6\n";
    let shifted = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n\
        property float y\nproperty float z\nend_header\n1 2 3 4\n5 6 7\n";
    vec![
        (
            "shifted.ply",
            shifted.into(),
            "line 8: vertex 0 has 4 values, expected 3",
        ),
        ("hang.ply", hang.into(), "line 10: 'x' is not a number"),
        ("c0.pcd", pcd("1 1 0", "ascii", b"1 2\n3 4\n"), z0),
        ("c0b.pcd", pcd("1 1 0", "binary", &floats), z0),
        ("c0c.pcd", pcd("1 1 0", "binary_compressed", &lzf_block), z0),
        (
            "c00.pcd",
            pcd("0 0 0", "binary", b"abcdefgh"),
            "COUNT 0 for field 'x'",
        ),
        (
            "cbig.pcd",
            pcd("1 1 18446744073709551615", "binary", &[b'x'; 100]),
            "line 2: COUNT 18446744073709551615",
        ),
        (
            "wh.pcd",
            b"FIELDS x y z\nWIDTH 4294967296\nHEIGHT 4294967296\nDATA ascii\n1 2 3\n".to_vec(),
            "line 4: WIDTH 4294967296 × HEIGHT 4294967296 is too many points",
        ),
    ]
}

enum Outcome {
    Read,
    Error(String),
    Panic(String),
}

fn read_as_cloud(path: &Path) -> Outcome {
    guarded(|| read_cloud(path).map(|_| ()))
}

fn read_as_mesh(path: &Path) -> Outcome {
    guarded(|| read_mesh(path).map(|_| ()))
}

fn guarded(read: impl FnOnce() -> anyhow::Result<()>) -> Outcome {
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let result = catch_unwind(AssertUnwindSafe(read));
    std::panic::set_hook(previous);
    match result {
        Ok(Ok(())) => Outcome::Read,
        Ok(Err(e)) => Outcome::Error(format!("{e:#}")),
        Err(payload) => Outcome::Panic(
            payload
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default(),
        ),
    }
}

/// Small valid files of every format and encoding, with their names (the
/// extension picks the reader, as on the command line).
fn seed_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let (vertices, faces) = small_mesh();
    let mut seeds = Vec::new();
    // The writers' own formats: binary PLY, OBJ, binary STL, GLB, glTF.
    for ext in ["ply", "obj", "stl", "glb", "gltf"] {
        let path = dir.join(format!("seed.{ext}"));
        write_mesh(&path, &vertices, &faces).expect("write a seed mesh");
        seeds.push((
            format!("written.{ext}"),
            std::fs::read(&path).expect("read it back"),
        ));
    }
    seeds.push((
        "ascii.ply".into(),
        ascii_ply(&vertices, &faces).into_bytes(),
    ));
    seeds.push(("big_endian.ply".into(), big_endian_ply(&vertices)));
    seeds.push(("range_grid.ply".into(), range_grid_ply().into_bytes()));
    seeds.push((
        "ascii.stl".into(),
        ascii_stl(&vertices, &faces).into_bytes(),
    ));
    seeds.push(("cloud.xyz".into(), text_cloud(&vertices, " ").into_bytes()));
    seeds.push((
        "cloud.csv".into(),
        format!("x,y,z\n{}", text_cloud(&vertices, ",")).into_bytes(),
    ));
    // Leica PTS: a point count before the points, here two scans.
    let (first, second) = vertices.split_at(vertices.len() / 2);
    seeds.push((
        "scan.pts".into(),
        format!(
            "{}\n{}{}\n{}",
            first.len(),
            text_cloud(first, " "),
            second.len(),
            text_cloud(second, " ")
        )
        .into_bytes(),
    ));
    seeds.push(("ascii.pcd".into(), pcd(&vertices, "ascii")));
    seeds.push(("binary.pcd".into(), pcd(&vertices, "binary")));
    seeds.push(("compressed.pcd".into(), pcd(&vertices, "binary_compressed")));
    seeds
}

/// A 4 × 4 grid of vertices, slightly bent, and its 18 triangles.
fn small_mesh() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let vertices = (0..16)
        .map(|i| {
            let (x, y) = ((i % 4) as f64, (i / 4) as f64);
            [x, y, 0.1 * x * y]
        })
        .collect();
    let mut faces = Vec::new();
    for r in 0..3u32 {
        for c in 0..3u32 {
            let a = r * 4 + c;
            faces.push([a, a + 1, a + 5]);
            faces.push([a, a + 5, a + 4]);
        }
    }
    (vertices, faces)
}

fn ascii_ply(vertices: &[[f64; 3]], faces: &[[u32; 3]]) -> String {
    let mut s = format!(
        "ply\nformat ascii 1.0\ncomment made by a test\nobj_info scanner 1\n\
         element camera 1\nproperty float view_px\nproperty float view_py\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\nproperty uchar red\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n1 2\n",
        vertices.len(),
        faces.len()
    );
    for v in vertices {
        s += &format!("{} {} {} 0 0 1 200\n", v[0], v[1], v[2]);
    }
    for f in faces {
        s += &format!("3 {} {} {}\n", f[0], f[1], f[2]);
    }
    s
}

fn big_endian_ply(vertices: &[[f64; 3]]) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat binary_big_endian 1.0\nelement vertex {}\nproperty double x\n\
         property double y\nproperty double z\nproperty int confidence\nend_header\n",
        vertices.len()
    )
    .into_bytes();
    for v in vertices {
        v.iter().for_each(|c| out.extend(c.to_be_bytes()));
        out.extend(7i32.to_be_bytes());
    }
    out
}

/// A 3 × 3 range grid with one missing sample, as Stanford's range scans.
fn range_grid_ply() -> String {
    let mut s = String::from(
        "ply\nformat ascii 1.0\nobj_info num_cols 3\nobj_info num_rows 3\n\
         element vertex 8\nproperty float x\nproperty float y\nproperty float z\n\
         element range_grid 9\nproperty list uchar int vertex_indices\nend_header\n",
    );
    for i in 0..8 {
        s += &format!("{} {} 0.5\n", i % 3, i / 3);
    }
    for cell in 0..9 {
        s += &match cell {
            0..=3 => format!("1 {cell}\n"),
            4 => "0\n".to_string(),
            _ => format!("1 {}\n", cell - 1),
        };
    }
    s
}

fn ascii_stl(vertices: &[[f64; 3]], faces: &[[u32; 3]]) -> String {
    let mut s = String::from("solid test\n");
    for f in faces {
        s += "facet normal 0 0 1\nouter loop\n";
        for &i in f {
            let v = vertices[i as usize];
            s += &format!("vertex {} {} {}\n", v[0], v[1], v[2]);
        }
        s += "endloop\nendfacet\n";
    }
    s + "endsolid test\n"
}

fn text_cloud(vertices: &[[f64; 3]], separator: &str) -> String {
    vertices
        .iter()
        .map(|v| format!("{}{separator}{}{separator}{}\n", v[0], v[1], v[2]))
        .collect()
}

fn pcd(vertices: &[[f64; 3]], data: &str) -> Vec<u8> {
    let n = vertices.len();
    let mut out = format!(
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\n\
         COUNT 1 1 1 1\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA {data}\n"
    )
    .into_bytes();
    let fields = |v: &[f64; 3]| [v[0] as f32, v[1] as f32, v[2] as f32, 0.5];
    match data {
        "ascii" => vertices.iter().for_each(|v| {
            let f = fields(v);
            out.extend(format!("{} {} {} {}\n", f[0], f[1], f[2], f[3]).bytes());
        }),
        "binary" => vertices
            .iter()
            .for_each(|v| fields(v).iter().for_each(|c| out.extend(c.to_le_bytes()))),
        _ => {
            // binary_compressed: the fields one after another, LZF-packed.
            let mut soa = Vec::new();
            for k in 0..4 {
                vertices
                    .iter()
                    .for_each(|v| soa.extend(fields(v)[k].to_le_bytes()));
            }
            let packed = lzf::compress(&soa).unwrap_or_else(|_| soa.clone());
            out.extend((packed.len() as u32).to_le_bytes());
            out.extend((soa.len() as u32).to_le_bytes());
            out.extend(packed);
        }
    }
    out
}

/// One random damage to `bytes`: the kinds a disk, a transfer or a
/// careless script cause, plus the numbers a header can lie with.
fn mutate(bytes: &[u8], rng: &mut SplitMix64) -> Vec<u8> {
    let mut out = bytes.to_vec();
    let at = |rng: &mut SplitMix64, len: usize| below(rng, len.max(1));
    match below(rng, 7) {
        0 => out.truncate(at(rng, bytes.len())),
        1 => {
            for _ in 0..=below(rng, 4) {
                let i = at(rng, out.len());
                out[i] = rng.next_u64() as u8;
            }
        }
        2 => {
            const TELLING: &[u8] = b"\0\xff9-.e \n\t,+nN";
            let i = at(rng, out.len());
            out[i] = TELLING[below(rng, TELLING.len())];
        }
        3 => {
            let (i, n) = (at(rng, out.len()), 1 + below(rng, 16));
            out.drain(i..(i + n).min(out.len()));
        }
        4 => {
            let i = at(rng, out.len());
            let junk: Vec<u8> = (0..1 + below(rng, 8))
                .map(|_| rng.next_u64() as u8)
                .collect();
            out.splice(i..i, junk);
        }
        5 => {
            // A number in the text (header counts, sizes, coordinates)
            // replaced by an absurd one.
            const ABSURD: [&str; 8] = [
                "4294967295",
                "-1",
                "0",
                "1e308",
                "nan",
                "99999999999",
                "2147483648",
                "65536",
            ];
            let digits: Vec<usize> = (0..out.len())
                .filter(|&i| out[i].is_ascii_digit())
                .collect();
            if !digits.is_empty() {
                let start = digits[below(rng, digits.len())];
                let end = (start..out.len())
                    .find(|&i| !out[i].is_ascii_digit())
                    .unwrap_or(out.len());
                out.splice(start..end, ABSURD[below(rng, ABSURD.len())].bytes());
            }
        }
        _ => {
            // A line repeated (a header line twice, a record twice).
            let i = at(rng, out.len());
            let start = out[..i]
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |p| p + 1);
            let end = out[i..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(out.len(), |p| i + p + 1);
            let line = out[start..end].to_vec();
            out.splice(start..start, line);
        }
    }
    out
}

/// A uniform draw in 0..n (0 for n = 0) from the seeded generator: the
/// fuzzing is the same on every run, so a failure reproduces.
fn below(rng: &mut SplitMix64, n: usize) -> usize {
    (rng.next_u64() % n.max(1) as u64) as usize
}
