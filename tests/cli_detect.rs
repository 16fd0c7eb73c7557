//! End-to-end tests of `meshtrim detect`, running the built binary.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use byteorder::{ByteOrder, LittleEndian};

mod common;
use common::{meshtrim_env, output_bytes, path_str, stderr, BLADE_HOLES as FIXTURE};

fn meshtrim(args: &[&str]) -> Output {
    meshtrim_env(args, &[])
}

/// The records of a `detect` PLY output: (x, y, z, boundary, beta).
fn read_labelled_ply(bytes: &[u8]) -> Vec<([f64; 3], u8, f64)> {
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .expect("a PLY header")
        + 11;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    assert!(header.contains(
        "property double x\nproperty double y\nproperty double z\n\
         property uchar boundary\nproperty double beta\n"
    ));
    let body = &bytes[end..];
    assert_eq!(body.len() % 33, 0);
    body.chunks_exact(33)
        .map(|r| {
            let p = [0, 8, 16].map(|o| LittleEndian::read_f64(&r[o..]));
            (p, r[24], LittleEndian::read_f64(&r[25..]))
        })
        .collect()
}

/// The fixture's points, read the same simple way.
fn fixture_points() -> Vec<[f64; 3]> {
    let bytes = std::fs::read(FIXTURE).unwrap();
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    bytes[end..]
        .chunks_exact(24)
        .map(|r| [0, 8, 16].map(|o| LittleEndian::read_f64(&r[o..])))
        .collect()
}

#[test]
fn ply_output_keeps_points_in_order() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("new/sub/labels.ply");
    let run = meshtrim(&["detect", FIXTURE, "-o", path_str(&out)]);
    assert!(run.status.success(), "{}", stderr(&run));
    let records = read_labelled_ply(&std::fs::read(&out).unwrap());
    let input = fixture_points();
    assert_eq!(records.len(), input.len());
    assert!(records.iter().zip(&input).all(|(r, p)| r.0 == *p));
    let boundary = records.iter().filter(|r| r.1 == 1).count();
    assert!(records.iter().all(|r| r.1 <= 1 && r.2 > 0.0));
    assert!(
        boundary > 0 && boundary * 10 < input.len() * 3,
        "{boundary}"
    );
    let text = String::from_utf8(run.stdout).unwrap();
    assert!(
        text.contains(&format!("boundary points      {boundary} (")),
        "{text}"
    );
}

#[test]
fn csv_output_header_and_rows() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("labels.csv");
    let run = meshtrim(&["detect", FIXTURE, "-o", path_str(&out), "--k", "20"]);
    assert!(run.status.success(), "{}", stderr(&run));
    let text = std::fs::read_to_string(&out).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("x,y,z,boundary,beta"));
    let rows: Vec<&str> = lines.collect();
    let input = fixture_points();
    assert_eq!(rows.len(), input.len());
    let first: Vec<f64> = rows[0].split(',').map(|f| f.parse().unwrap()).collect();
    assert_eq!(&first[..3], &input[0]);
}

#[test]
fn json_summary_is_consistent() {
    let run = meshtrim(&["detect", FIXTURE, "--json", "--no-anisotropy"]);
    assert!(run.status.success(), "{}", stderr(&run));
    let v: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    let keys = [
        "file",
        "points",
        "distinct_points",
        "duplicates",
        "dropped_non_finite",
        "boundary_points",
        "beta_min",
        "beta_mean",
        "beta_max",
        "beta_std",
        "read_ms",
        "detect_ms",
        "k",
        "anisotropy",
    ];
    let object = v.as_object().unwrap();
    assert_eq!(object.len(), keys.len());
    assert!(keys.iter().all(|k| object.contains_key(*k)), "{v}");
    let n = |k: &str| v[k].as_f64().unwrap();
    assert_eq!(n("points") as usize, fixture_points().len());
    assert_eq!(n("distinct_points") + n("duplicates"), n("points"));
    assert_eq!(n("dropped_non_finite"), 0.0);
    assert!(n("boundary_points") > 0.0 && n("boundary_points") < n("points"));
    assert!(0.0 < n("beta_min") && n("beta_min") <= n("beta_mean"));
    assert!(n("beta_mean") <= n("beta_max") && n("beta_std") >= 0.0);
    assert_eq!(v["k"], 30);
    assert_eq!(v["anisotropy"], false);
    assert_eq!(v["file"], FIXTURE);
}

#[test]
fn output_is_deterministic_across_runs_and_threads() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, threads: &str| {
        output_bytes(
            dir.path(),
            &["detect", FIXTURE, "-o", "{out}"],
            name,
            threads,
        )
    };
    let a = run("a.ply", "2");
    assert_eq!(a, run("b.ply", "2"));
    assert_eq!(a, run("c.ply", "1"));
    let csv = run("a.csv", "1");
    assert_eq!(csv, run("b.csv", "2"));
}

#[test]
fn existing_output_is_replaced_atomically() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("labels.ply");
    std::fs::write(&out, b"old content").unwrap();
    let run = meshtrim(&["detect", FIXTURE, "-o", path_str(&out)]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(std::fs::read(&out).unwrap().starts_with(b"ply\n"));
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["labels.ply"]);
}

/// A reader that has gone away (`meshtrim … | head -c 0`) does not make a
/// command panic: its files are written and it succeeds. The pipe's read
/// end is closed before the run, so every write to stdout fails with a
/// broken pipe (on which `println!` panics).
#[test]
fn a_closed_stdout_pipe_is_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let labels = dir.path().join("labels.csv");
    let edges = dir.path().join("edges.obj");
    let trimmed = dir.path().join("trimmed.ply");
    let mesh = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/meshes/blade_small_poisson.ply"
    );
    let cloud = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/meshes/blade_small.ply"
    );
    let runs: [(&[&str], &Path); 4] = [
        (&["detect", FIXTURE, "-o", path_str(&labels)], &labels),
        (
            &["detect", FIXTURE, "-o", path_str(&labels), "--json"],
            &labels,
        ),
        (&["edges", FIXTURE, "-o", path_str(&edges)], &edges),
        (&[mesh, cloud, path_str(&trimmed)], &trimmed),
    ];
    for (args, output) in runs {
        let _ = std::fs::remove_file(output);
        let (reader, writer) = std::io::pipe().expect("a pipe");
        drop(reader);
        let run = Command::new(env!("CARGO_BIN_EXE_meshtrim"))
            .args(args)
            .stdout(writer)
            .output()
            .expect("the meshtrim binary runs");
        assert!(run.status.success(), "{args:?}: {}", stderr(&run));
        assert!(!stderr(&run).contains("panicked"), "{args:?}");
        assert!(output.is_file(), "{args:?} wrote {}", output.display());
    }
    // A failing run whose stderr is the closed pipe too still exits with 1
    // (a panic would give 101).
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    let missing = dir.path().join("missing.ply");
    let run = Command::new(env!("CARGO_BIN_EXE_meshtrim"))
        .args(["detect", path_str(&missing), "-o", path_str(&labels)])
        .stdout(writer.try_clone().expect("a second write end"))
        .stderr(writer)
        .status()
        .expect("the meshtrim binary runs");
    assert_eq!(run.code(), Some(1));
}

/// Runs `detect` on `input` with an output in a fresh directory, and checks
/// the failure: exit code 1, the file named, the expected words, no panic,
/// no output and nothing else left in the output directory.
fn fails(input: &Path, extra: &[&str], expected: &str) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.ply");
    let mut args = vec!["detect", path_str(input), "-o", path_str(&out)];
    args.extend(extra);
    let run = meshtrim(&args);
    let err = stderr(&run);
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with(&format!("error: {}: ", input.display())),
        "{err}"
    );
    assert!(err.contains(expected), "expected '{expected}' in: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "{err}");
}

/// Writes `bytes` to a file called `name` in a new temporary directory.
fn input_file(name: &str, bytes: &[u8]) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    (dir, path)
}

/// `n` points on a small grid, as text lines.
fn grid_text(n: usize) -> String {
    (0..n)
        .map(|i| format!("{} {} 0\n", i % 10, i / 10))
        .collect()
}

#[test]
fn missing_file() {
    let dir = tempfile::tempdir().unwrap();
    fails(&dir.path().join("absent.ply"), &[], "cannot read");
}

#[test]
fn unknown_extension_and_content() {
    let (_d, path) = input_file("cloud.bin", b"\x00\x01 garbage that is not a cloud\n");
    fails(&path, &[], "unknown format");
}

#[test]
fn truncated_ply() {
    let bytes = std::fs::read(FIXTURE).unwrap();
    let (_d, path) = input_file("cut.ply", &bytes[..bytes.len() - 100]);
    let n = fixture_points().len();
    fails(
        &path,
        &[],
        &format!("expected {n} vertices, file ends after {}", n - 5),
    );
}

#[test]
fn malformed_csv_names_the_line() {
    let mut text = grid_text(40);
    text.push_str("1,2,oops\n");
    let (_d, path) = input_file("bad.csv", text.as_bytes());
    fails(&path, &[], "line 41: 'oops' is not a number");
}

#[test]
fn too_few_points() {
    let (_d, path) = input_file("few.xyz", grid_text(12).as_bytes());
    fails(&path, &[], "12 distinct points");
}

#[test]
fn all_points_identical() {
    let (_d, path) = input_file("same.xyz", "1 2 3\n".repeat(50).as_bytes());
    fails(&path, &[], "degenerate");
}

/// A `--k` below 4 is a usage error (exit 2) before any file is read, in
/// every command: not an error of detection after reading the input
/// (exit 1), nor, in a batch, one that every file is read and fails on.
#[test]
fn k_too_small_is_a_usage_error() {
    let missing = "no-such-input.ply";
    for args in [
        vec!["detect", missing, "--k", "3"],
        vec!["edges", missing, "-o", "e.json", "--k", "0"],
        vec!["trim", missing, missing, "t.ply", "--k", "2"],
        vec![missing, missing, "t.ply", "--k", "1"],
        vec!["mesh", missing, "m.ply", "--k", "3"],
        vec!["clean", missing, "c.ply", "--k", "3"],
        vec!["batch", missing, "--out-dir", "out", "--k", "3"],
    ] {
        let run = meshtrim(&args);
        let err = stderr(&run);
        assert_eq!(run.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("is too small: boundary detection needs k >= 4"),
            "{err}"
        );
    }
    let run = meshtrim(&["detect", FIXTURE, "--k", "4", "--json"]);
    assert!(run.status.success(), "{}", stderr(&run));
}

#[test]
fn bad_output_extension_is_refused_before_reading() {
    let run = meshtrim(&["detect", FIXTURE, "-o", "labels.txt"]);
    assert_eq!(run.status.code(), Some(1));
    assert!(stderr(&run).starts_with("error: labels.txt: unsupported output format"));
    assert!(!Path::new("labels.txt").exists());
}

/// A scanner's line of sight or position changes the projection, is
/// reported (table and JSON), and bad values are usage errors naming the
/// problem.
#[test]
fn scanner_view_is_used_reported_and_checked() {
    let json = |extra: &[&str]| {
        let mut args = vec!["detect", FIXTURE, "--json"];
        args.extend(extra);
        let run = meshtrim(&args);
        assert!(run.status.success(), "{}", stderr(&run));
        serde_json::from_slice::<serde_json::Value>(&run.stdout).unwrap()
    };
    let paper = json(&[]);
    assert!(paper.get("view_along").is_none() && paper.get("view_from").is_none());
    let along = json(&["--view-along", "0.3,-0.2,1"]);
    assert_eq!(along["view_along"], serde_json::json!([0.3, -0.2, 1.0]));
    let from = json(&["--view-from=-50,20,300"]);
    assert_eq!(from["view_from"], serde_json::json!([-50.0, 20.0, 300.0]));
    // The fixture is a curved panel: a slanted line of sight moves some labels.
    assert_ne!(paper["beta_mean"], along["beta_mean"]);
    let table = meshtrim(&["detect", FIXTURE, "--view-along", "0,0,1"]);
    assert!(String::from_utf8_lossy(&table.stdout)
        .contains("projection           along the line of sight 0,0,1"));
    for (args, expected) in [
        (vec!["--view-along", "0,0,0"], "a direction cannot be 0,0,0"),
        (vec!["--view-along", "1,2"], "expected three numbers X,Y,Z"),
        (vec!["--view-from", "1,2,x"], "`x` is not a number"),
        (
            vec!["--view-from", "1,inf,2"],
            "`inf` is not a finite number",
        ),
        (
            vec!["--view-along", "0,0,1", "--view-from", "0,0,0"],
            "cannot be used with",
        ),
    ] {
        let mut all = vec!["detect", FIXTURE];
        all.extend(&args);
        let run = meshtrim(&all);
        assert_eq!(run.status.code(), Some(2), "{args:?}");
        assert!(
            stderr(&run).contains(expected),
            "{args:?}: {}",
            stderr(&run)
        );
    }
}

#[test]
fn usage_errors_exit_2() {
    assert_eq!(meshtrim(&["detect"]).status.code(), Some(2));
    assert_eq!(
        meshtrim(&["detect", FIXTURE, "--k", "x"]).status.code(),
        Some(2)
    );
    assert_eq!(meshtrim(&["frobnicate"]).status.code(), Some(2));
}

#[test]
fn nan_in_text_is_an_error_with_its_line() {
    let mut text = grid_text(40);
    text.push_str("1 NaN 3\n");
    let (_d, path) = input_file("nan.xyz", text.as_bytes());
    fails(&path, &[], "line 41: non-finite coordinate (1, NaN, 3)");
}

#[test]
fn nan_in_pcd_is_dropped_and_counted() {
    let mut text = format!("FIELDS x y z\nPOINTS 42\nDATA ascii\n{}", grid_text(40));
    text.push_str("nan nan nan\n1 inf 2\n");
    let (_d, path) = input_file("organised.pcd", text.as_bytes());
    let run = meshtrim(&["detect", path_str(&path), "--json", "--k", "10"]);
    assert!(run.status.success(), "{}", stderr(&run));
    let v: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    assert_eq!(v["points"], 40);
    assert_eq!(v["dropped_non_finite"], 2);
}

/// A triangulated scan is a cloud too: `detect` reads an STL's vertices
/// (shared, as the STL reader merges them).
#[test]
fn an_stl_scan_is_read_as_its_vertices() {
    let stl = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/meshes/blade_jagged.stl"
    );
    let out = meshtrim(&["detect", stl, "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["points"], 3003, "{json}");
    assert!(json["boundary_points"].as_u64().unwrap() > 200, "{json}");
}

/// A Leica PTS export of the fixture (a count line, then x y z intensity
/// r g b, CRLF) reads as the same cloud, with the same labels; cut short,
/// its count names the truncation.
#[test]
fn pts_files_with_point_counts() {
    let points = fixture_points();
    let mut pts = format!("{}\r\n", points.len());
    for p in &points {
        pts += &format!("{} {} {} -1234 120 130 140\r\n", p[0], p[1], p[2]);
    }
    let (dir, path) = input_file("scan.pts", pts.as_bytes());
    let from_pts = dir.path().join("pts.ply");
    let from_ply = dir.path().join("ply.ply");
    for (input, out) in [(path_str(&path), &from_pts), (FIXTURE, &from_ply)] {
        let run = meshtrim(&["detect", input, "-o", path_str(out)]);
        assert!(run.status.success(), "{}", stderr(&run));
    }
    assert!(std::fs::read(&from_pts).unwrap() == std::fs::read(&from_ply).unwrap());

    let cut: String = pts
        .lines()
        .take(points.len() - 3)
        .map(|l| format!("{l}\n"))
        .collect();
    let (_d, path) = input_file("cut.pts", cut.as_bytes());
    fails(
        &path,
        &[],
        &format!(
            "line 1: the point count says {} points, but {} follow (a truncated file?)",
            points.len(),
            points.len() - 4
        ),
    );
}

/// A cloud large enough that each text reader cuts it into several pieces
/// (its files are 3–4 MB, the pieces 1 MiB) gives the same output as its
/// binary PLY: XYZ, PTS, ASCII PCD, OBJ and ASCII PLY (also with a face
/// element, whose lines are read in pieces too); and binary and compressed
/// PCD, decoded in parallel.
#[test]
fn large_text_clouds_read_in_pieces_as_the_binary_ply() {
    // A gently curved sheet, 260 × 240 points, jittered (seeded).
    let mut rng = testkit::synthetic::SplitMix64::new(12345);
    let mut jitter = || rng.range(-0.15, 0.15);
    let points: Vec<[f64; 3]> = (0..260 * 240)
        .map(|i| {
            let (u, v) = ((i % 260) as f64 + jitter(), (i / 260) as f64 + jitter());
            [
                u * 0.731,
                v * 0.731,
                0.002 * (u - 130.0) * (v - 120.0) / 10.0,
            ]
        })
        .collect();
    let n = points.len();
    let line = |p: &[f64; 3]| format!("{} {} {}", p[0], p[1], p[2]);
    let mut ply = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {n}\n\
         property double x\nproperty double y\nproperty double z\nend_header\n"
    )
    .into_bytes();
    for p in &points {
        for c in p {
            ply.extend_from_slice(&c.to_le_bytes());
        }
    }
    let lines = |prefix: &str, suffix: &str| -> String {
        points
            .iter()
            .map(|p| format!("{prefix}{}{suffix}\n", line(p)))
            .collect()
    };
    // The grid's triangles, for a PLY mesh whose vertices are the cloud.
    let faces: String = (0..259 * 239)
        .map(|c| (c % 259 + c / 259 * 260) as usize)
        .flat_map(|i| [[i, i + 1, i + 261], [i, i + 261, i + 260]])
        .map(|[a, b, c]| format!("3 {a} {b} {c}\n"))
        .collect();
    let ascii_ply = |faces_header: &str, faces: &str| {
        format!(
            "ply\nformat ascii 1.0\nelement vertex {n}\nproperty double x\n\
             property double y\nproperty double z\n{faces_header}end_header\n{}{faces}",
            lines("", "")
        )
    };
    let faces_header = format!(
        "element face {}\nproperty list uchar int vertex_indices\n",
        2 * 259 * 239
    );
    let pcd_head = |fields: &str, sizes: &str, data: &str| {
        let count = fields.split(' ').count();
        let (types, counts) = (vec!["F"; count].join(" "), vec!["1"; count].join(" "));
        format!(
            "VERSION .7\nFIELDS {fields}\nSIZE {sizes}\nTYPE {types}\nCOUNT {counts}\n\
             WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA {data}\n"
        )
    };
    let mut binary_pcd = pcd_head("x y z", "8 8 8", "binary").into_bytes();
    binary_pcd.extend(points.iter().flatten().flat_map(|c| c.to_le_bytes()));
    // binary_compressed stores each field's values together; an intensity
    // of zeros gives LZF something to pack (random doubles do not shrink).
    let mut by_field: Vec<u8> = (0..3)
        .flat_map(|k| points.iter().flat_map(move |p| p[k].to_le_bytes()))
        .collect();
    by_field.resize(by_field.len() + 4 * n, 0);
    let packed = lzf::compress(&by_field).unwrap();
    let head = pcd_head("x y z intensity", "8 8 8 4", "binary_compressed");
    let mut compressed_pcd = head.into_bytes();
    compressed_pcd.extend((packed.len() as u32).to_le_bytes());
    compressed_pcd.extend((by_field.len() as u32).to_le_bytes());
    compressed_pcd.extend(packed);
    let files = [
        ("cloud.ply", ply),
        ("ascii.ply", ascii_ply("", "").into_bytes()),
        (
            "ascii_mesh.ply",
            ascii_ply(&faces_header, &faces).into_bytes(),
        ),
        ("binary.pcd", binary_pcd),
        ("compressed.pcd", compressed_pcd),
        ("cloud.xyz", lines("", "").into_bytes()),
        (
            "cloud.pts",
            format!("{n}\r\n{}", lines("", " 0 10 20 30")).into_bytes(),
        ),
        (
            "cloud.pcd",
            (pcd_head("x y z", "8 8 8", "ascii") + &lines("", "")).into_bytes(),
        ),
        ("cloud.obj", lines("v ", "").into_bytes()),
    ];
    let dir = tempfile::tempdir().unwrap();
    let mut outputs = Vec::new();
    for (name, bytes) in &files {
        let text = !matches!(*name, "cloud.ply" | "binary.pcd" | "compressed.pcd");
        assert!(!text || bytes.len() > 3 << 20, "{name}: {}", bytes.len());
        let input = dir.path().join(name);
        std::fs::write(&input, bytes).unwrap();
        let out = dir.path().join(format!("{name}.out.ply"));
        let run = meshtrim(&["detect", path_str(&input), "-o", path_str(&out)]);
        assert!(run.status.success(), "{name}: {}", stderr(&run));
        outputs.push(std::fs::read(out).unwrap());
    }
    let labelled = read_labelled_ply(&outputs[0]);
    assert_eq!(labelled.len(), n);
    assert!(labelled.iter().any(|r| r.1 == 1) && labelled.iter().any(|r| r.1 == 0));
    for ((name, _), out) in files.iter().zip(&outputs).skip(1) {
        assert!(
            out == &outputs[0],
            "{name} gives another output than the binary PLY"
        );
    }
}

/// A run that fails leaves an existing output as it was and no temporary
/// file beside it; an output where nothing can be written (its directory
/// is a file) is a clear error naming it, and nothing is written.
#[test]
fn a_failing_run_leaves_the_existing_output_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("labels.csv");
    std::fs::write(&out, b"earlier result").unwrap();
    let (_d, bad) = input_file("bad.xyz", b"1 2 3\n4 five 6\n");
    let run = meshtrim(&["detect", path_str(&bad), "-o", path_str(&out)]);
    assert_eq!(run.status.code(), Some(1), "{}", stderr(&run));
    assert_eq!(std::fs::read(&out).unwrap(), b"earlier result");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);

    let target = out.join("labels.csv");
    let run = meshtrim(&["detect", FIXTURE, "-o", path_str(&target)]);
    let err = stderr(&run);
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert!(err.contains(&out.display().to_string()), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(std::fs::read(&out).unwrap(), b"earlier result");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}
