//! End-to-end tests of `meshtrim batch`.
//!
//! Trim pairs are the fixture mesh `blade_small_poisson.ply` copied as
//! `S.ply` beside the fixture cloud `blade_small.ply` copied as
//! `S.cloud.ply`; clean inputs are the jagged fixture `blade_jagged.stl`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

const MESH: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/fixtures/meshes/blade_small_poisson.ply"
);
const CLOUD: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/fixtures/meshes/blade_small.ply"
);
const JAGGED: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/fixtures/meshes/blade_jagged.stl"
);
/// Faces of the fixture mesh.
const FACES_IN: u64 = 15909;

/// Runs `meshtrim batch ARGS` in `dir`.
fn batch(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_meshtrim"))
        .arg("batch")
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run meshtrim")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn assert_ok(run: &Output) {
    assert!(run.status.success(), "{}", text(&run.stderr));
}

/// A trim pair `REL.ply` + `REL.cloud.ply` below `dir`.
fn pair(dir: &Path, rel: &str) {
    let mesh = dir.join(format!("{rel}.ply"));
    std::fs::create_dir_all(mesh.parent().unwrap()).unwrap();
    std::fs::copy(MESH, &mesh).unwrap();
    std::fs::copy(CLOUD, dir.join(format!("{rel}.cloud.ply"))).unwrap();
}

/// A file of garbage bytes.
fn garbage(dir: &Path, rel: &str) {
    let path = dir.join(rel);
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    let bytes: Vec<u8> = (0..300u32).map(|i| (i * 97 % 251) as u8).collect();
    std::fs::write(path, bytes).unwrap();
}

fn json_report(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The `input` of each file of a JSON report, in report order.
fn inputs(report: &Value) -> Vec<String> {
    report["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["input"].as_str().unwrap().to_string())
        .collect()
}

/// Every file below `dir`, relative, sorted.
fn files_below(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                out.push(path.strip_prefix(dir).unwrap().to_path_buf());
            }
        }
    }
    out.sort();
    out
}

/// A minimal RFC 4180 reader, for checking the CSV report.
fn parse_csv(text: &str) -> Vec<Vec<String>> {
    let (mut rows, mut row, mut field) = (Vec::new(), Vec::new(), String::new());
    let (mut quoted, mut chars) = (false, text.chars().peekable());
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                field.push('"');
            }
            (true, '"') => quoted = false,
            (true, c) => field.push(c),
            (false, '"') => quoted = true,
            (false, ',') => row.push(std::mem::take(&mut field)),
            (false, '\n') => {
                row.push(std::mem::take(&mut field));
                rows.push(std::mem::take(&mut row));
            }
            (false, c) => field.push(c),
        }
    }
    rows
}

#[test]
fn directories_and_globs_expand_to_sorted_mirrored_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    pair(d, "scans/a");
    pair(d, "scans/sub/b");
    pair(d, "other/c");
    std::fs::write(d.join("scans/notes.md"), "not a mesh").unwrap();
    let run = batch(
        d,
        &[
            "scans",
            "other/*.ply",
            "--out-dir",
            "out",
            "--report",
            "r.json",
        ],
    );
    assert_ok(&run);
    // Clouds are never inputs; sub-directories of a directory argument are
    // mirrored, a glob match goes by its file name.
    assert_eq!(
        files_below(&d.join("out")),
        ["a.ply", "c.ply", "sub/b.ply"].map(PathBuf::from)
    );
    let report = json_report(&d.join("r.json"));
    assert_eq!(
        inputs(&report),
        ["other/c.ply", "scans/a.ply", "scans/sub/b.ply"]
    );
    for file in report["files"].as_array().unwrap() {
        assert_eq!(file["mode"], "trim", "{file}");
        assert_eq!(file["status"], "ok", "{file}");
        assert_eq!(file["loops"], 4, "{file}");
        assert_eq!(file["faces_in"], FACES_IN, "{file}");
    }
    assert_eq!(report["files"][1]["output"], "out/a.ply");
    assert_eq!(report["files"][2]["output"], "out/sub/b.ply");
    let stdout = text(&run.stdout);
    assert!(
        stdout.contains("ok      trim   scans/sub/b.ply  loops=4  faces 15909→"),
        "{stdout}"
    );
    assert!(
        stdout.contains("3 files: 3 ok, 0 failed, 0 skipped"),
        "{stdout}"
    );
    // The same file through a directory and a pattern is one input.
    let again = batch(d, &["scans", "scans/*.ply", "--out-dir", "out2"]);
    assert_ok(&again);
    assert!(text(&again.stdout).contains("2 files: 2 ok"));
}

#[test]
fn shards_are_disjoint_and_cover_the_sorted_list() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Failing files are cheap, and sharding does not depend on the outcome.
    let names: Vec<String> = (0..7).map(|i| format!("in/f{i}.stl")).collect();
    names.iter().for_each(|n| garbage(d, n));
    let mut union = Vec::new();
    for k in 1..=3 {
        let report = d.join(format!("r{k}.json"));
        let shard = format!("{k}/3");
        let run = batch(
            d,
            &[
                "in",
                "--out-dir",
                "out",
                "--shard",
                &shard,
                "--report",
                report.to_str().unwrap(),
            ],
        );
        assert_eq!(run.status.code(), Some(1), "{}", text(&run.stderr));
        let report = json_report(&report);
        assert_eq!(report["inputs"], 7);
        assert_eq!(report["shard"], shard.as_str());
        let held = inputs(&report);
        let expected: Vec<String> = (0..7)
            .filter(|i| i % 3 == k - 1)
            .map(|i| names[i].clone())
            .collect();
        assert_eq!(held, expected, "shard {k}");
        union.extend(held);
    }
    union.sort();
    assert_eq!(union, names, "every input in exactly one shard");
    let bad = batch(d, &["in", "--out-dir", "out", "--shard", "0/4"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(text(&bad.stderr).contains("K must be between 1 and N"));
}

#[test]
fn two_inputs_with_one_output_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    pair(d, "scans/a/x");
    pair(d, "scans/b/x");
    for args in [["scans/a/x.ply", "scans/b/x.ply"], ["scans/a", "scans/b"]] {
        let run = batch(d, &[args[0], args[1], "--out-dir", "out"]);
        let stderr = text(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{stderr}");
        assert!(
            stderr.contains("scans/a/x.ply and scans/b/x.ply would both be written to out/x.ply"),
            "{stderr}"
        );
        assert!(!d.join("out").exists(), "nothing processed");
    }
    // Through their common directory, sub-directories keep them apart.
    assert_ok(&batch(d, &["scans", "--out-dir", "out"]));
    assert_eq!(
        files_below(&d.join("out")),
        ["a/x.ply", "b/x.ply"].map(PathBuf::from)
    );
}

#[test]
fn an_output_over_an_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    pair(d, "scans/a");
    let run = batch(d, &["scans", "--out-dir", "scans"]);
    let stderr = text(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("would overwrite the input"), "{stderr}");
    assert!(stderr.contains("choose another --out-dir"), "{stderr}");
    assert_eq!(
        std::fs::read(d.join("scans/a.ply")).unwrap(),
        std::fs::read(MESH).unwrap()
    );
}

/// A report over a cloud is refused, and the advice names --report, the
/// option at fault, not --out-dir.
#[test]
fn a_report_over_a_cloud_names_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("scans")).unwrap();
    std::fs::copy(JAGGED, d.join("scans/a.stl")).unwrap();
    std::fs::write(d.join("scans/a.csv"), "0,0,0\n1,0,0\n0,1,0\n").unwrap();
    let run = batch(d, &["scans", "--out-dir", "out", "--report", "scans/a.csv"]);
    let stderr = text(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("scans/a.csv: the report would overwrite the input scans/a.csv"),
        "{stderr}"
    );
    assert!(stderr.contains("choose another --report"), "{stderr}");
    assert!(!stderr.contains("--out-dir"), "{stderr}");
    assert_eq!(
        std::fs::read(d.join("scans/a.csv")).unwrap(),
        b"0,0,0\n1,0,0\n0,1,0\n"
    );
    assert!(!d.join("out").exists(), "nothing processed");
}

#[test]
fn skip_existing_resumes_without_rewriting() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    pair(d, "scans/a");
    pair(d, "scans/b");
    assert_ok(&batch(d, &["scans", "--out-dir", "out"]));
    // As if interrupted after a: b's output missing, a's marked.
    std::fs::remove_file(d.join("out/b.ply")).unwrap();
    std::fs::write(d.join("out/a.ply"), "marker").unwrap();
    let run = batch(
        d,
        &[
            "scans",
            "--out-dir",
            "out",
            "--skip-existing",
            "--report",
            "r.csv",
        ],
    );
    assert_ok(&run);
    assert_eq!(std::fs::read(d.join("out/a.ply")).unwrap(), b"marker");
    assert!(std::fs::read(d.join("out/b.ply"))
        .unwrap()
        .starts_with(b"ply\n"));
    let stdout = text(&run.stdout);
    assert!(
        stdout.contains("skipped trim   scans/a.ply (output exists)"),
        "{stdout}"
    );
    let rows = parse_csv(&std::fs::read_to_string(d.join("r.csv")).unwrap());
    assert_eq!(
        rows[1][..4],
        ["scans/a.ply", "out/a.ply", "trim", "skipped"]
    );
    assert_eq!(rows[2][..4], ["scans/b.ply", "out/b.ply", "trim", "ok"]);
    // With edges files: a job whose mesh was written but not its edges
    // (interrupted between the two) is done again.
    assert_ok(&batch(
        d,
        &["scans", "--out-dir", "edged", "--edges-to", "json"],
    ));
    std::fs::remove_file(d.join("edged/b.edges.json")).unwrap();
    let args = [
        "scans",
        "--out-dir",
        "edged",
        "--edges-to",
        "json",
        "--skip-existing",
    ];
    let stdout = text(&batch(d, &args).stdout);
    assert!(
        stdout.contains("skipped trim   scans/a.ply (output exists)"),
        "{stdout}"
    );
    assert!(stdout.contains("ok      trim   scans/b.ply"), "{stdout}");
    assert!(d.join("edged/b.edges.json").exists());
}

#[test]
fn bad_files_fail_alone_and_the_reports_say_why() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    pair(d, "scans/a");
    pair(d, "scans/z");
    // Garbage with no cloud (clean mode) and with one (trim mode).
    garbage(d, "scans/bad.stl");
    garbage(d, "scans/worse.ply");
    std::fs::copy(CLOUD, d.join("scans/worse.cloud.ply")).unwrap();
    let run = batch(
        d,
        &[
            "scans",
            "--out-dir",
            "out",
            "--report",
            "r.csv",
            "--jobs",
            "2",
        ],
    );
    let (stdout, stderr) = (text(&run.stdout), text(&run.stderr));
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("error: 2 of 4 files failed"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        stdout.contains("failed  clean  scans/bad.stl: "),
        "{stdout}"
    );
    assert!(
        stdout.contains("failed  trim   scans/worse.ply: "),
        "{stdout}"
    );
    // Each failed path is printed once.
    for line in stdout.lines().filter(|l| l.starts_with("failed")) {
        let path = line
            .split_whitespace()
            .nth(2)
            .unwrap()
            .trim_end_matches(':');
        assert_eq!(line.matches(path).count(), 1, "{line}");
    }
    assert!(stdout.contains("4 files: 2 ok, 2 failed, 0 skipped"));
    // The good files are written whole, the bad ones not at all, and no
    // temporary file is left behind.
    assert_eq!(
        files_below(&d.join("out")),
        ["a.ply", "z.ply"].map(PathBuf::from)
    );
    let rows = parse_csv(&std::fs::read_to_string(d.join("r.csv")).unwrap());
    assert_eq!(
        rows[0],
        [
            "input",
            "output",
            "mode",
            "status",
            "error",
            "loops",
            "faces_in",
            "faces_out",
            "read_ms",
            "algorithm_ms",
            "write_ms",
            "total_ms",
            "repaired",
            "cloud",
            "removed_max",
            "new_max",
            "cloud_max",
            "cloud_mean",
            "holes_filled"
        ]
    );
    assert_eq!(rows.len(), 5, "{rows:?}");
    // Not measured without --deviation.
    assert!(rows[1..]
        .iter()
        .all(|r| r[14..19].iter().all(String::is_empty)));
    // The cloud each trimmed file was paired with; none for a clean.
    let clouds: Vec<&str> = rows[1..].iter().map(|r| r[13].as_str()).collect();
    assert_eq!(
        clouds,
        [
            "scans/a.cloud.ply",
            "",
            "scans/worse.cloud.ply",
            "scans/z.cloud.ply"
        ]
    );
    let order: Vec<&str> = rows[1..].iter().map(|r| r[0].as_str()).collect();
    assert_eq!(
        order,
        [
            "scans/a.ply",
            "scans/bad.stl",
            "scans/worse.ply",
            "scans/z.ply"
        ]
    );
    let (a, bad, worse) = (&rows[1], &rows[2], &rows[3]);
    assert_eq!(a[2..8], ["trim", "ok", "", "4", "15909", a[7].as_str()]);
    let faces_out: u64 = a[7].parse().unwrap();
    assert!(faces_out > 0 && faces_out < FACES_IN);
    // Times are numbers, and the total holds its parts (each rounded to
    // 0.1 ms): a trim reads, detects and writes, so it takes some time.
    let ms: Vec<f64> = a[8..12].iter().map(|t| t.parse().unwrap()).collect();
    assert!(ms.iter().all(|t| t.is_finite() && *t >= 0.0), "{a:?}");
    assert!(ms[1] > 0.0 && ms[3] > 0.0, "{a:?}");
    assert!(ms[0] + ms[1] + ms[2] <= ms[3] + 0.2, "{a:?}");
    assert_eq!(bad[2..4], ["clean", "failed"]);
    assert!(!bad[4].is_empty() && bad[5..11].iter().all(String::is_empty));
    assert_eq!(worse[2..4], ["trim", "failed"]);
    // The row names the file; its error says what is wrong with it.
    assert!(worse[4].starts_with("malformed PLY header"), "{worse:?}");
    // The same batch as JSON.
    let run = batch(
        d,
        &[
            "scans",
            "--out-dir",
            "out2",
            "--report",
            "r.json",
            "--jobs",
            "1",
        ],
    );
    assert_eq!(run.status.code(), Some(1));
    let report = json_report(&d.join("r.json"));
    assert_eq!(report["ok"], 2);
    assert_eq!(report["failed"], 2);
    assert_eq!(report["skipped"], 0);
    assert_eq!(inputs(&report), order);
    let files = &report["files"];
    assert_eq!(files[0]["faces_out"], faces_out);
    assert_eq!(files[2]["error"].as_str().unwrap(), worse[4]);
    assert!(files[2]["loops"].is_null());
}

#[test]
fn outputs_are_identical_on_one_and_two_jobs_and_match_meshtrim_trim() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    pair(d, "scans/a");
    pair(d, "scans/sub/b");
    assert_ok(&batch(d, &["scans", "--out-dir", "one", "--jobs", "1"]));
    assert_ok(&batch(d, &["scans", "--out-dir", "two", "--jobs", "2"]));
    let files = files_below(&d.join("one"));
    assert_eq!(files.len(), 2);
    assert_eq!(files, files_below(&d.join("two")));
    for f in &files {
        let (one, two) = (
            std::fs::read(d.join("one").join(f)).unwrap(),
            std::fs::read(d.join("two").join(f)).unwrap(),
        );
        assert!(one == two, "{} differs between --jobs 1 and 2", f.display());
    }
    let single = d.join("single.ply");
    let run = Command::new(env!("CARGO_BIN_EXE_meshtrim"))
        .args([MESH, CLOUD, single.to_str().unwrap()])
        .output()
        .unwrap();
    assert_ok(&run);
    assert!(std::fs::read(single).unwrap() == std::fs::read(d.join("one/a.ply")).unwrap());
}

/// Clean mode: meshes without a cloud are cleaned, the same bytes as
/// `meshtrim clean` writes, on one or two jobs, mixed with trim pairs.
#[test]
fn meshes_without_a_cloud_are_cleaned_like_meshtrim_clean() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("scans/sub")).unwrap();
    std::fs::copy(JAGGED, d.join("scans/j1.stl")).unwrap();
    std::fs::copy(JAGGED, d.join("scans/sub/j2.stl")).unwrap();
    pair(d, "scans/t");
    for jobs in ["1", "2"] {
        let out = format!("out{jobs}");
        let report = format!("r{jobs}.json");
        let run = batch(
            d,
            &[
                "scans",
                "--out-dir",
                &out,
                "--jobs",
                jobs,
                "--report",
                &report,
            ],
        );
        assert_ok(&run);
        let stdout = text(&run.stdout);
        assert_eq!(stdout.matches("ok ").count(), 3, "{stdout}");
        let files = json_report(&d.join(&report))["files"].clone();
        let modes: Vec<(String, String, u64)> = files
            .as_array()
            .unwrap()
            .iter()
            .map(|f| {
                (
                    f["mode"].as_str().unwrap().to_string(),
                    f["status"].as_str().unwrap().to_string(),
                    f["loops"].as_u64().unwrap(),
                )
            })
            .collect();
        assert_eq!(
            modes,
            [
                ("clean".into(), "ok".into(), 4),
                ("clean".into(), "ok".into(), 4),
                ("trim".into(), "ok".into(), 4)
            ]
        );
    }
    let single = d.join("single.stl");
    let run = Command::new(env!("CARGO_BIN_EXE_meshtrim"))
        .args(["clean", JAGGED, single.to_str().unwrap()])
        .output()
        .unwrap();
    assert_ok(&run);
    let single = std::fs::read(single).unwrap();
    for out in [
        "out1/j1.stl",
        "out2/j1.stl",
        "out1/sub/j2.stl",
        "out2/sub/j2.stl",
    ] {
        assert!(std::fs::read(d.join(out)).unwrap() == single, "{out}");
    }
}

/// `--edges-to EXT` writes S.edges.EXT beside each output S.ext: the bytes
/// `meshtrim clean --edges` writes for a cleaned file, `meshtrim trim
/// --edges` for a trimmed one (with `--units` and `--dxf-splines` alike).
/// Two outputs of one stem, whose edges files would be one, are refused
/// before any work, as is `--dxf-splines` without DXF edges.
#[test]
fn edges_to_writes_each_outputs_edges_beside_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("scans")).unwrap();
    std::fs::copy(JAGGED, d.join("scans/j.stl")).unwrap();
    pair(d, "scans/t");
    let single = |args: &[&str]| {
        let run = Command::new(env!("CARGO_BIN_EXE_meshtrim"))
            .args(args)
            .current_dir(d)
            .output()
            .unwrap();
        assert_ok(&run);
    };
    for (ext, flags) in [
        ("json", &[][..]),
        ("dxf", &["--dxf-splines", "--units", "in"][..]),
    ] {
        let out = format!("out_{ext}");
        let run = batch(
            d,
            &[&["scans", "--out-dir", &out, "--edges-to", ext][..], flags].concat(),
        );
        assert_ok(&run);
        let clean_edges = format!("clean.{ext}");
        single(
            &[
                &["clean", JAGGED, "c.stl", "--edges", &clean_edges][..],
                flags,
            ]
            .concat(),
        );
        let trim_edges = format!("trim.{ext}");
        single(
            &[
                &["trim", MESH, CLOUD, "t.ply", "--edges", &trim_edges][..],
                flags,
            ]
            .concat(),
        );
        for (batched, alone) in [
            (format!("{out}/j.edges.{ext}"), clean_edges),
            (format!("{out}/t.edges.{ext}"), trim_edges),
        ] {
            let (batched, alone) = (
                std::fs::read(d.join(&batched)).unwrap(),
                std::fs::read(d.join(&alone)).unwrap(),
            );
            assert!(batched == alone, "{ext}");
        }
    }
    // Two stems alike: their meshes differ, their edges files would not.
    std::fs::copy(d.join("scans/t.ply"), d.join("scans/j.ply")).unwrap();
    let run = batch(
        d,
        &[
            "scans/j.stl",
            "scans/j.ply",
            "--out-dir",
            "two",
            "--edges-to",
            "dxf",
        ],
    );
    assert_eq!(run.status.code(), Some(1), "{}", text(&run.stdout));
    let stderr = text(&run.stderr);
    assert!(
        stderr.contains("would both be written to two/j.edges.dxf"),
        "{stderr}"
    );
    assert!(!d.join("two").exists());
    let run = batch(
        d,
        &[
            "scans/j.stl",
            "--out-dir",
            "three",
            "--edges-to",
            "step",
            "--dxf-splines",
        ],
    );
    assert_eq!(run.status.code(), Some(1));
    assert!(
        text(&run.stderr).contains("give --edges-to dxf"),
        "{}",
        text(&run.stderr)
    );
    assert!(!d.join("three").exists());
}

/// `--to` writes every output in one format: the bytes `meshtrim clean`
/// and `meshtrim trim` write to that extension; two inputs of one stem
/// that would share an output are refused before any work; an unknown
/// format is a usage error.
#[test]
fn to_writes_every_output_in_one_format() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("scans/sub")).unwrap();
    std::fs::copy(JAGGED, d.join("scans/sub/j.stl")).unwrap();
    pair(d, "scans/t");
    assert_ok(&batch(d, &["scans", "--out-dir", "out", "--to", "glb"]));
    assert_eq!(
        files_below(&d.join("out")),
        ["sub/j.glb", "t.glb"].map(PathBuf::from)
    );
    let single = |args: &[&str], name: &str| {
        let out = d.join(name);
        let mut args = args.to_vec();
        args.push(out.to_str().unwrap());
        assert_ok(
            &Command::new(env!("CARGO_BIN_EXE_meshtrim"))
                .args(&args)
                .output()
                .unwrap(),
        );
        std::fs::read(out).unwrap()
    };
    let cleaned = single(&["clean", JAGGED], "clean.glb");
    assert!(std::fs::read(d.join("out/sub/j.glb")).unwrap() == cleaned);
    let trimmed = single(&[MESH, CLOUD], "trim.glb");
    assert!(std::fs::read(d.join("out/t.glb")).unwrap() == trimmed);

    // j.ply beside j.stl: both to j.stl.
    std::fs::copy(MESH, d.join("scans/sub/j.ply")).unwrap();
    let run = batch(d, &["scans/sub", "--out-dir", "again", "--to", "stl"]);
    let stderr = text(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("would both be written to again/j.stl"),
        "{stderr}"
    );
    assert!(!d.join("again").exists(), "nothing processed");

    let run = batch(d, &["scans", "--out-dir", "out", "--to", "xyz"]);
    assert_eq!(run.status.code(), Some(2), "{}", text(&run.stderr));
}

#[test]
fn deviation_reports_how_far_each_output_lies_from_its_scan() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("scans")).unwrap();
    std::fs::copy(JAGGED, d.join("scans/j.stl")).unwrap();
    pair(d, "scans/t");
    let args = ["scans", "--out-dir", "out", "--deviation", "--report"];
    let run = batch(d, &[&args[..], &["r.csv"]].concat());
    assert_ok(&run);
    let clean = Command::new(env!("CARGO_BIN_EXE_meshtrim"))
        .args(["clean", JAGGED, d.join("c.stl").to_str().unwrap(), "--json"])
        .output()
        .unwrap();
    assert_ok(&clean);
    let cleaned: serde_json::Value = serde_json::from_slice(&clean.stdout).unwrap();
    let trim = Command::new(env!("CARGO_BIN_EXE_meshtrim"))
        .args([
            "trim",
            MESH,
            CLOUD,
            d.join("t.ply").to_str().unwrap(),
            "--json",
        ])
        .output()
        .unwrap();
    assert_ok(&trim);
    let trimmed: serde_json::Value = serde_json::from_slice(&trim.stdout).unwrap();
    let rows = parse_csv(&std::fs::read_to_string(d.join("r.csv")).unwrap());
    let (j, t) = (&rows[1], &rows[2]);
    assert_eq!(
        (j[0].as_str(), t[0].as_str()),
        ("scans/j.stl", "scans/t.ply")
    );
    // The cleaned file's are `clean`'s maxima, the trimmed file's are
    // `trim`'s cloud_to_output; each has none of the other's.
    for (column, key) in [(14, "input_to_output"), (15, "output_to_input")] {
        let reported: f64 = j[column].parse().unwrap();
        assert_eq!(reported, cleaned[key]["max"].as_f64().unwrap(), "{key}");
        assert!(t[column].is_empty(), "{t:?}");
    }
    for (column, key) in [(16, "max"), (17, "mean")] {
        let reported: f64 = t[column].parse().unwrap();
        let single = trimmed["cloud_to_output"][key].as_f64().unwrap();
        assert_eq!(reported, single, "{key}");
        assert!(reported > 0.0 && j[column].is_empty(), "{j:?}");
    }
    let stdout = text(&run.stdout);
    assert!(
        stdout.contains("faces 5768→5759  moved: removed≤0.6877 new≤4.026  "),
        "{stdout}"
    );
    // The trimmed file's line shows both to four significant digits.
    let line = stdout.lines().find(|l| l.contains("scans/t.ply")).unwrap();
    let shown = line
        .split("  cloud: off≤")
        .nth(1)
        .unwrap_or_else(|| panic!("{line}"));
    let mut numbers = shown.split_whitespace();
    let max: f64 = numbers.next().unwrap().parse().unwrap();
    assert_eq!(numbers.next(), Some("mean"), "{line}");
    let mean: f64 = numbers.next().unwrap().parse().unwrap();
    for (shown, column) in [(max, 16), (mean, 17)] {
        let reported: f64 = t[column].parse().unwrap();
        assert!((shown - reported).abs() <= 5e-4 * reported, "{line}");
    }
    let run = batch(d, &[&args[..], &["r.json"]].concat());
    assert_ok(&run);
    let report = json_report(&d.join("r.json"));
    let files = &report["files"];
    assert_eq!(files[0]["new_max"], cleaned["output_to_input"]["max"]);
    assert!(files[1].get("new_max").is_none(), "{}", files[1]);
    assert_eq!(files[1]["cloud_max"], trimmed["cloud_to_output"]["max"]);
    assert!(files[0].get("cloud_max").is_none(), "{}", files[0]);
    // --max-deviation: the bytes `clean --max-deviation` writes.
    let held = ["scans/j.stl", "--out-dir", "held", "--max-deviation", "1.5"];
    assert_ok(&batch(d, &held));
    let single = d.join("held.stl");
    let run = Command::new(env!("CARGO_BIN_EXE_meshtrim"))
        .args([
            "clean",
            JAGGED,
            single.to_str().unwrap(),
            "--max-deviation",
            "1.5",
        ])
        .output()
        .unwrap();
    assert_ok(&run);
    let (from_batch, from_clean) = (d.join("held/j.stl"), single);
    assert!(std::fs::read(from_batch).unwrap() == std::fs::read(from_clean).unwrap());
    assert!(
        std::fs::read(d.join("held/j.stl")).unwrap() != std::fs::read(d.join("out/j.stl")).unwrap()
    );
    // --fill-holes: the bytes `clean --fill-holes` writes, and the holes
    // closed in the report and on the file's line.
    let filled = ["scans/j.stl", "--out-dir", "filled", "--fill-holes", "100"];
    let run = batch(d, &[&filled[..], &["--report", "f.json"]].concat());
    assert_ok(&run);
    assert_eq!(
        json_report(&d.join("f.json"))["files"][0]["holes_filled"],
        2
    );
    assert!(String::from_utf8_lossy(&run.stdout).contains("  holes filled=2  "));
    let single = d.join("filled.stl");
    let args = [
        "clean",
        JAGGED,
        single.to_str().unwrap(),
        "--fill-holes",
        "100",
    ];
    assert_ok(
        &Command::new(env!("CARGO_BIN_EXE_meshtrim"))
            .args(args)
            .output()
            .unwrap(),
    );
    assert!(std::fs::read(d.join("filled/j.stl")).unwrap() == std::fs::read(&single).unwrap());
    assert!(
        std::fs::read(d.join("filled/j.stl")).unwrap()
            != std::fs::read(d.join("out/j.stl")).unwrap()
    );
}

#[test]
fn an_unknown_report_format_is_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    pair(d, "scans/a");
    let run = batch(d, &["scans", "--out-dir", "out", "--report", "r.txt"]);
    let stderr = text(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("r.txt: unknown report format: name it .csv or .json"),
        "{stderr}"
    );
    assert!(!d.join("out").exists());
}

#[test]
fn missing_inputs_and_clouds_given_as_inputs_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    pair(d, "scans/a");
    for (arg, says) in [
        ("nope.ply", "nope.ply: cannot read"),
        ("scans/*.stl", "matches no mesh file"),
        ("scans/a.cloud.ply", "not a mesh input"),
    ] {
        let run = batch(d, &[arg, "--out-dir", "out"]);
        let stderr = text(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{stderr}");
        assert!(stderr.contains(says), "{arg}: {stderr}");
    }
}

#[test]
fn cloud_dir_mirrors_the_inputs_and_two_clouds_for_one_mesh_fail_that_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for rel in ["scans/sub/a.ply", "scans/sub/b.ply"] {
        std::fs::create_dir_all(d.join("scans/sub")).unwrap();
        std::fs::copy(MESH, d.join(rel)).unwrap();
    }
    std::fs::create_dir_all(d.join("clouds/sub")).unwrap();
    std::fs::copy(CLOUD, d.join("clouds/sub/a.cloud.ply")).unwrap();
    std::fs::copy(CLOUD, d.join("clouds/sub/b.cloud.ply")).unwrap();
    std::fs::write(d.join("clouds/sub/b.xyz"), "0 0 0\n").unwrap();
    let run = batch(
        d,
        &[
            "scans",
            "--cloud-dir",
            "clouds",
            "--out-dir",
            "out",
            "--report",
            "r.json",
        ],
    );
    assert_eq!(run.status.code(), Some(1), "{}", text(&run.stderr));
    let report = json_report(&d.join("r.json"));
    let a = &report["files"][0];
    assert_eq!((&a["mode"], &a["status"]), (&"trim".into(), &"ok".into()));
    let b = &report["files"][1];
    assert_eq!(b["status"], "failed");
    assert_eq!(
        b["error"],
        "several clouds match this mesh (clouds/sub/b.cloud.ply, clouds/sub/b.xyz): keep one"
    );
    assert_eq!(files_below(&d.join("out")), [PathBuf::from("sub/a.ply")]);
}

/// `part.ply` without faces beside `part.stl` is the STL's cloud (a cloud
/// with the same stem and a cloud extension): the STL is trimmed with it
/// and the PLY is not an input. A PLY with faces beside an STL is a mesh of
/// its own: both are cleaned.
#[test]
fn a_same_stem_ply_without_faces_is_the_cloud() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("scans")).unwrap();
    let poisson = meshtrim::io::read_mesh(Path::new(MESH)).unwrap();
    meshtrim::io::write_mesh(
        &d.join("scans/part.stl"),
        &poisson.vertices,
        poisson.faces.as_ref().unwrap(),
    )
    .unwrap();
    std::fs::copy(CLOUD, d.join("scans/part.ply")).unwrap();
    std::fs::copy(JAGGED, d.join("scans/other.stl")).unwrap();
    let jagged = meshtrim::io::read_mesh(Path::new(JAGGED)).unwrap();
    meshtrim::io::write_mesh(
        &d.join("scans/other.ply"),
        &jagged.vertices,
        jagged.faces.as_ref().unwrap(),
    )
    .unwrap();
    let run = batch(d, &["scans", "--out-dir", "out", "--report", "r.json"]);
    assert_ok(&run);
    let files = json_report(&d.join("r.json"))["files"].clone();
    let rows: Vec<(String, String)> = files
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            let input = f["input"].as_str().unwrap();
            let name = Path::new(input).file_name().unwrap().to_str().unwrap();
            (name.to_string(), f["mode"].as_str().unwrap().to_string())
        })
        .collect();
    assert_eq!(
        rows,
        [
            ("other.ply".to_string(), "clean".to_string()),
            ("other.stl".to_string(), "clean".to_string()),
            ("part.stl".to_string(), "trim".to_string()),
        ]
    );
}

/// The closing line counts one file as "1 file".
#[test]
fn one_file_is_counted_in_the_singular() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("scans")).unwrap();
    std::fs::copy(JAGGED, d.join("scans/a.stl")).unwrap();
    let run = batch(d, &["scans", "--out-dir", "out"]);
    assert_ok(&run);
    let stdout = text(&run.stdout);
    assert!(
        stdout.contains("\n1 file: 1 ok, 0 failed, 0 skipped"),
        "{stdout}"
    );
}

/// A cloud named so that it pairs with no mesh is taken for a mesh to
/// clean: its line says what it looks like and how to name it.
#[test]
fn a_misnamed_cloud_is_told_how_to_pair() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("scans")).unwrap();
    std::fs::copy(MESH, d.join("scans/blade.ply")).unwrap();
    std::fs::copy(CLOUD, d.join("scans/blade_cloud.ply")).unwrap();
    let run = batch(d, &["scans", "--out-dir", "out"]);
    assert_eq!(run.status.code(), Some(1));
    let stdout = text(&run.stdout);
    let line = stdout
        .lines()
        .find(|l| l.contains("blade_cloud.ply"))
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!(
        line.starts_with("failed  clean  scans/blade_cloud.ply: "),
        "{line}"
    );
    assert!(line.contains("looks like a point cloud"), "{line}");
    assert!(line.contains("S.cloud.EXT"), "{line}");
    assert_eq!(line.matches("blade_cloud.ply").count(), 1, "{line}");
}

/// A closed mesh given to clean (a Poisson envelope without its cloud)
/// is copied, and its line says there was no border to clean.
#[test]
fn a_closed_mesh_cleaned_is_noted() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("scans")).unwrap();
    std::fs::write(d.join("scans/envelope.obj"), sphere_obj(12, 16)).unwrap();
    let run = batch(d, &["scans", "--out-dir", "out"]);
    assert_ok(&run);
    let stdout = text(&run.stdout);
    assert!(
        stdout.contains("ok      clean  scans/envelope.obj  loops=0")
            && stdout.contains("(no border: a closed mesh has nothing to clean"),
        "{stdout}"
    );
}

/// A closed mesh cut open (a sphere without its south pole's fan) given to
/// clean: cleaned, and its line says it wraps round an object and how to
/// trim an envelope instead; a one-sided scan beside it gets no such note.
#[test]
fn an_envelope_cut_open_cleaned_is_noted() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("scans")).unwrap();
    let cut: String = sphere_obj(12, 16)
        .lines()
        .filter(|l| !(l.starts_with("f 2 ")))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(d.join("scans/envelope.obj"), cut).unwrap();
    std::fs::copy(JAGGED, d.join("scans/scan.stl")).unwrap();
    let run = batch(d, &["scans", "--out-dir", "out"]);
    assert_ok(&run);
    let stdout = text(&run.stdout);
    let line = |name: &str| {
        stdout
            .lines()
            .find(|l| l.contains(name))
            .unwrap_or_else(|| panic!("{stdout}"))
            .to_string()
    };
    let envelope = line("envelope.obj");
    assert!(
        envelope.starts_with("ok      clean  scans/envelope.obj  loops=1"),
        "{envelope}"
    );
    assert!(
        envelope.contains("(it wraps round an object, as an envelope cut open does")
            && envelope.contains("S.cloud.EXT"),
        "{envelope}"
    );
    let scan = line("scan.stl");
    assert!(!scan.contains('('), "{scan}");
}

/// A closed UV sphere: `rings` latitudes between the poles, `sectors`
/// longitudes, faces turning outward.
fn sphere_obj(rings: usize, sectors: usize) -> String {
    use std::f64::consts::PI;
    let mut obj = String::from("v 0 0 1\nv 0 0 -1\n");
    for r in 1..=rings {
        let theta = PI * r as f64 / (rings + 1) as f64;
        for s in 0..sectors {
            let phi = 2.0 * PI * s as f64 / sectors as f64;
            let (x, y, z) = (
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            obj += &format!("v {x} {y} {z}\n");
        }
    }
    // OBJ indices are 1-based: the poles are 1 and 2, ring r's sector s is
    // 3 + (r - 1)·sectors + s.
    let at = |r: usize, s: usize| 3 + (r - 1) * sectors + s % sectors;
    for s in 0..sectors {
        obj += &format!("f 1 {} {}\n", at(1, s), at(1, s + 1));
        obj += &format!("f 2 {} {}\n", at(rings, s + 1), at(rings, s));
        for r in 1..rings {
            let (a, b, c, d) = (at(r, s), at(r + 1, s), at(r + 1, s + 1), at(r, s + 1));
            obj += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
        }
    }
    obj
}

/// More shards than inputs: each input still in exactly one shard, the
/// empty shards succeed with nothing to do; and shards run at the same
/// time into one `--out-dir` (as the README's GNU parallel example does),
/// with trim pairs, give the outputs of one unsharded run, byte for byte.
#[test]
fn shards_beyond_the_inputs_and_at_the_same_time_into_one_directory() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for rel in ["in/a", "in/b", "in/sub/c"] {
        pair(d, rel);
    }
    let whole = batch(d, &["in", "--out-dir", "whole"]);
    assert_ok(&whole);
    let n = 5;
    let shards: Vec<_> = (1..=n)
        .map(|k| {
            Command::new(env!("CARGO_BIN_EXE_meshtrim"))
                .args(["batch", "in", "--out-dir", "sharded", "--shard"])
                .arg(format!("{k}/{n}"))
                .current_dir(d)
                .spawn()
                .expect("run meshtrim")
        })
        .collect();
    for mut child in shards {
        assert!(child.wait().unwrap().success());
    }
    let (whole_files, sharded_files) = (
        files_below(&d.join("whole")),
        files_below(&d.join("sharded")),
    );
    assert_eq!(whole_files.len(), 3, "{whole_files:?}");
    assert_eq!(whole_files, sharded_files);
    for f in &whole_files {
        assert!(
            std::fs::read(d.join("whole").join(f)).unwrap()
                == std::fs::read(d.join("sharded").join(f)).unwrap(),
            "{f:?} differs"
        );
    }
}

/// A mesh whose faces are not all wound one way fails alone without
/// `--repair` (its error names the flag), and is cleaned with it, as
/// `meshtrim clean --repair` cleans it.
#[test]
fn repair_lets_a_mesh_wound_both_ways_through() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("scans")).unwrap();
    std::fs::copy(JAGGED, d.join("scans/right.stl")).unwrap();
    // Every fifth triangle's last two corners swapped.
    let mut stl = std::fs::read(JAGGED).unwrap();
    let count = u32::from_le_bytes(stl[80..84].try_into().unwrap()) as usize;
    for t in (0..count).step_by(5) {
        let at = 84 + 50 * t;
        let second: Vec<u8> = stl[at + 24..at + 36].to_vec();
        stl.copy_within(at + 36..at + 48, at + 24);
        stl[at + 36..at + 48].copy_from_slice(&second);
    }
    std::fs::write(d.join("scans/wrong.stl"), &stl).unwrap();
    let run = batch(
        d,
        &["scans", "--out-dir", "plain", "--report", "plain.json"],
    );
    assert!(!run.status.success());
    let files = json_report(&d.join("plain.json"))["files"].clone();
    assert_eq!(files[0]["status"], "ok");
    assert_eq!(files[1]["status"], "failed");
    let error = files[1]["error"].as_str().unwrap();
    assert!(error.contains("clean with --repair"), "{error}");
    let run = batch(
        d,
        &[
            "scans",
            "--out-dir",
            "fixed",
            "--repair",
            "--report",
            "fixed.csv",
        ],
    );
    assert_ok(&run);
    // The file repaired says how many faces were turned; the other none.
    let turned = count.div_ceil(5);
    assert!(
        text(&run.stdout).contains(&format!("repaired={turned}")),
        "{}",
        text(&run.stdout)
    );
    let rows = parse_csv(&std::fs::read_to_string(d.join("fixed.csv")).unwrap());
    assert_eq!(rows[0][12], "repaired");
    assert_eq!([&rows[1][12], &rows[2][12]], ["0", &turned.to_string()]);
    let single = d.join("single.stl");
    let run = Command::new(env!("CARGO_BIN_EXE_meshtrim"))
        .args([
            "clean",
            "scans/wrong.stl",
            single.to_str().unwrap(),
            "--repair",
        ])
        .current_dir(d)
        .output()
        .unwrap();
    assert_ok(&run);
    assert!(std::fs::read(d.join("fixed/wrong.stl")).unwrap() == std::fs::read(single).unwrap());
}
