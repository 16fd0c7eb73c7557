//! End-to-end tests of `meshtrim edges`, running the built binary.

use std::path::{Path, PathBuf};
use std::process::Output;

use serde_json::Value;

mod common;
use common::{meshtrim_env, output_bytes, path_str, stderr, BLADE_HOLES as FIXTURE};

/// Points in the fixture (see fixtures/meshes/README.md).
const FIXTURE_POINTS: usize = 7219;

fn meshtrim(args: &[&str]) -> Output {
    meshtrim_env(args, &[])
}

/// Runs `edges` on the fixture into `dir/name` with `extra` arguments;
/// returns the output file's bytes and stdout.
fn run_edges(dir: &Path, name: &str, extra: &[&str]) -> (Vec<u8>, String) {
    let out = dir.join(name);
    let mut args = vec!["edges", FIXTURE, "-o", path_str(&out)];
    args.extend(extra);
    let run = meshtrim(&args);
    assert!(run.status.success(), "{}", stderr(&run));
    let stdout = String::from_utf8(run.stdout).unwrap();
    (std::fs::read(&out).unwrap(), stdout)
}

fn point(v: &Value) -> [f64; 3] {
    let a = v.as_array().expect("a point is an array");
    assert_eq!(a.len(), 3, "{v}");
    [0, 1, 2].map(|i| a[i].as_f64().expect("coordinates are numbers"))
}

fn points(v: &Value) -> Vec<[f64; 3]> {
    v.as_array().unwrap().iter().map(point).collect()
}

/// The keys of a JSON object, sorted.
fn keys_of(v: &Value) -> Vec<&str> {
    let mut keys: Vec<&str> = v
        .as_object()
        .expect("an object")
        .keys()
        .map(String::as_str)
        .collect();
    keys.sort_unstable();
    keys
}

/// Checks the shape and the invariants of a JSON output; returns the loops.
fn check_json(bytes: &[u8], offset: bool) -> Vec<Value> {
    let v: Value = serde_json::from_slice(bytes).unwrap();
    assert_eq!(keys_of(&v), ["loops"]);
    let loops = v["loops"].as_array().unwrap().clone();
    for (n, l) in loops.iter().enumerate() {
        assert_eq!(
            keys_of(l),
            ["boundary_points", "closed", "corners", "edges"]
        );
        assert_eq!(l["closed"], true);
        let members: Vec<usize> = l["boundary_points"]
            .as_array()
            .unwrap()
            .iter()
            .map(|i| i.as_u64().unwrap() as usize)
            .collect();
        assert!(members.len() >= 3, "loop {n}");
        assert!(members.iter().all(|&i| i < FIXTURE_POINTS), "loop {n}");
        let mut unique = members.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), members.len(), "loop {n} repeats a point");
        let corners = points(&l["corners"]);
        let edges = l["edges"].as_array().unwrap();
        assert!(!edges.is_empty(), "loop {n}");
        let edge_points: Vec<Vec<[f64; 3]>> = edges
            .iter()
            .map(|e| {
                assert_eq!(keys_of(e), ["closed", "points"]);
                points(&e["points"])
            })
            .collect();
        assert!(edge_points.iter().all(|p| p.len() >= 2), "loop {n}");
        assert!(
            edge_points
                .iter()
                .flatten()
                .flatten()
                .all(|c| c.is_finite()),
            "loop {n}"
        );
        if corners.is_empty() {
            // One closed edge, all around.
            assert_eq!(edges.len(), 1, "loop {n}");
            assert_eq!(edges[0]["closed"], true, "loop {n}");
        } else {
            // One open edge from each corner to the next, chained, the last
            // back to the first.
            assert_eq!(edges.len(), corners.len(), "loop {n}");
            assert!(edges.iter().all(|e| e["closed"] == false), "loop {n}");
            for (i, e) in edge_points.iter().enumerate() {
                let next = &edge_points[(i + 1) % edge_points.len()];
                assert_eq!(e.last(), next.first(), "loop {n}, edge {i}");
                if !offset {
                    // Without the offset the edges end exactly at the corners.
                    assert_eq!(e[0], corners[i], "loop {n}, edge {i}");
                }
            }
        }
    }
    loops
}

#[test]
fn json_has_the_outer_loop_and_three_holes() {
    let dir = tempfile::tempdir().unwrap();
    let (bytes, stdout) = run_edges(dir.path(), "edges.json", &[]);
    let loops = check_json(&bytes, true);
    assert_eq!(loops.len(), 4, "{stdout}");
    // The outer border (about 400 points) is the longest loop and has the
    // strip's 4 corners.
    let sizes: Vec<usize> = loops
        .iter()
        .map(|l| l["boundary_points"].as_array().unwrap().len())
        .collect();
    let outer = (0..4).max_by_key(|&i| sizes[i]).unwrap();
    assert!(sizes[outer] > 300, "{sizes:?}");
    assert_eq!(loops[outer]["corners"].as_array().unwrap().len(), 4);
    // The round holes have no corners: one closed edge each.
    for (n, l) in loops.iter().enumerate().filter(|&(n, _)| n != outer) {
        assert_eq!(l["corners"].as_array().unwrap().len(), 0, "hole {n}");
    }
    assert!(stdout.contains("corners              4\n"), "{stdout}");
    assert!(stdout.contains("loops                4\n"), "{stdout}");
    assert!(stdout.contains("offset               on\n"), "{stdout}");
    assert!(stdout.contains("output               "), "{stdout}");
}

#[test]
fn json_without_offset_ends_edges_at_the_corners() {
    let dir = tempfile::tempdir().unwrap();
    let (bytes, stdout) = run_edges(dir.path(), "edges.json", &["--no-offset"]);
    assert_eq!(check_json(&bytes, false).len(), 4);
    assert!(stdout.contains("offset               off\n"), "{stdout}");
    // The offset moves the edges, so the outputs differ.
    let (with_offset, _) = run_edges(dir.path(), "offset.json", &[]);
    assert_ne!(bytes, with_offset);
}

#[test]
fn obj_polylines_match_the_json_edges() {
    let dir = tempfile::tempdir().unwrap();
    let (obj, _) = run_edges(dir.path(), "edges.obj", &[]);
    let (json, _) = run_edges(dir.path(), "edges.json", &[]);
    let loops = check_json(&json, true);
    let text = String::from_utf8(obj).unwrap();
    assert!(text.starts_with("# meshtrim edges\n"), "{text}");
    let mut vertices = 0usize;
    let mut lines = Vec::new();
    let mut groups = Vec::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let c: Vec<f64> = words.map(|w| w.parse().unwrap()).collect();
                assert_eq!(c.len(), 3, "{line}");
                assert!(c.iter().all(|c| c.is_finite()), "{line}");
                vertices += 1;
            }
            Some("l") => lines.push(
                words
                    .map(|w| w.parse::<usize>().unwrap())
                    .collect::<Vec<_>>(),
            ),
            Some("o") => groups.push(words.next().unwrap().to_string()),
            Some("#") | None => {}
            Some(other) => panic!("unexpected OBJ line kind {other}: {line}"),
        }
    }
    let expected: Vec<String> = (0..loops.len()).map(|n| format!("loop_{n}")).collect();
    assert_eq!(groups, expected);
    let edges: Vec<&Value> = loops
        .iter()
        .flat_map(|l| l["edges"].as_array().unwrap())
        .collect();
    assert_eq!(lines.len(), edges.len());
    for (ids, e) in lines.iter().zip(&edges) {
        assert!(ids.iter().all(|&i| 1 <= i && i <= vertices), "{ids:?}");
        let n = e["points"].as_array().unwrap().len();
        let closed = e["closed"] == true;
        assert_eq!(ids.len(), n + usize::from(closed));
        if closed {
            assert_eq!(ids.first(), ids.last());
        }
    }
}

#[test]
fn svg_draws_the_cloud_loops_and_edges() {
    let dir = tempfile::tempdir().unwrap();
    let (svg, _) = run_edges(dir.path(), "edges.svg", &[]);
    let (json, stdout) = run_edges(dir.path(), "edges.json", &["--json"]);
    let summary: Value = serde_json::from_str(&stdout).unwrap();
    let loops = check_json(&json, true);
    let text = String::from_utf8(svg).unwrap();
    assert!(text.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""));
    assert!(text.ends_with("</svg>\n"));
    assert_eq!(text.matches("<g ").count(), text.matches("</g>").count());
    // Every boundary point is a circle; every raw loop and every edge a
    // polyline; the interior points are dots.
    let boundary = summary["boundary_points"].as_u64().unwrap() as usize;
    assert_eq!(text.matches("<circle ").count(), boundary);
    let edges = summary["edges"].as_u64().unwrap() as usize;
    assert_eq!(text.matches("<polyline ").count(), loops.len() + edges);
    assert_eq!(text.matches("h0").count(), FIXTURE_POINTS - boundary);
    assert!(text.len() < 400_000, "{}", text.len());
}

#[test]
fn json_summary_has_the_documented_keys() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("e.obj");
    let started = std::time::Instant::now();
    let run = meshtrim(&["edges", FIXTURE, "-o", path_str(&out), "--json"]);
    let wall_ms = started.elapsed().as_secs_f64() * 1e3;
    assert!(run.status.success(), "{}", stderr(&run));
    let v: Value = serde_json::from_slice(&run.stdout).unwrap();
    let keys = [
        "file",
        "points",
        "boundary_points",
        "loops",
        "edges",
        "corners",
        "dropped_clusters",
        "thinned_points",
        "loops_from",
        "read_ms",
        "detect_ms",
        "edges_ms",
        "write_ms",
        "offset",
    ];
    let mut keys = keys.to_vec();
    keys.sort_unstable();
    assert_eq!(keys_of(&v), keys, "{v}");
    assert_eq!(v["file"], FIXTURE);
    assert_eq!(v["points"], FIXTURE_POINTS);
    assert_eq!(v["loops"], 4);
    assert_eq!(v["loops_from"], "links");
    assert_eq!(v["offset"], true);
    let n = |k: &str| v[k].as_f64().unwrap();
    assert!(n("boundary_points") > 0.0 && n("boundary_points") < n("points"));
    assert!(n("edges") >= n("loops") && n("corners") >= 4.0);
    // Detection and edges of 2,800 points take some time (reading and
    // writing may round to 0 at 0.1 ms); the parts are in milliseconds, so
    // together they fit in the process's own wall time.
    assert!(n("detect_ms") > 0.0 && n("edges_ms") > 0.0, "{v}");
    let parts = ["read_ms", "detect_ms", "edges_ms", "write_ms"].map(n);
    assert!(parts.iter().all(|&ms| ms >= 0.0), "{v}");
    assert!(parts.iter().sum::<f64>() < wall_ms, "{v} in {wall_ms} ms");
}

#[test]
fn outputs_are_deterministic_across_runs_and_threads() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, threads: &str| {
        output_bytes(
            dir.path(),
            &["edges", FIXTURE, "-o", "{out}"],
            name,
            threads,
        )
    };
    let a = run("a.json", "2");
    assert_eq!(a, run("b.json", "2"));
    assert_eq!(a, run("c.json", "1"));
    assert_eq!(run("a.obj", "1"), run("b.obj", "2"));
    assert_eq!(run("a.svg", "1"), run("b.svg", "2"));
}

#[test]
fn existing_output_is_replaced_atomically() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("edges.obj");
    std::fs::write(&out, b"old content").unwrap();
    let run = meshtrim(&["edges", FIXTURE, "-o", path_str(&out)]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(std::fs::read(&out)
        .unwrap()
        .starts_with(b"# meshtrim edges\n"));
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["edges.obj"]);
}

/// Runs `edges` on `input` with an output in a fresh directory, and checks
/// the failure: exit code 1, `error: NAMED: `, the expected words, no panic,
/// and nothing left in the output directory.
fn fails(input: &Path, out_name: &str, named: &Path, expected: &str) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join(out_name);
    let run = meshtrim(&["edges", path_str(input), "-o", path_str(&out)]);
    let err = stderr(&run);
    assert_eq!(run.status.code(), Some(1), "{err}");
    let named = if named == Path::new("OUT") {
        out.clone()
    } else {
        named.to_path_buf()
    };
    assert!(
        err.starts_with(&format!("error: {}: ", named.display())),
        "{err}"
    );
    assert!(err.contains(expected), "expected '{expected}' in: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "{err}");
}

/// Writes `bytes` to a file called `name` in a new temporary directory.
fn input_file(name: &str, bytes: &[u8]) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    (dir, path)
}

#[test]
fn unknown_output_extension_is_refused_before_reading() {
    // The input does not exist: the output is checked first.
    let dir = tempfile::tempdir().unwrap();
    let absent = dir.path().join("absent.ply");
    fails(
        &absent,
        "edges.ply",
        Path::new("OUT"),
        "unsupported output format",
    );
    fails(
        &absent,
        "edges",
        Path::new("OUT"),
        "use .json, .obj, .svg, .dxf, .step or .igs",
    );
}

#[test]
fn missing_input() {
    let dir = tempfile::tempdir().unwrap();
    let absent = dir.path().join("absent.ply");
    fails(&absent, "edges.json", &absent, "cannot read");
}

#[test]
fn too_few_points() {
    let text: String = (0..12)
        .map(|i| format!("{} {} 0\n", i % 4, i / 4))
        .collect();
    let (_d, path) = input_file("few.xyz", text.as_bytes());
    fails(&path, "edges.svg", &path, "12 distinct points");
}

#[test]
fn output_naming_the_input_is_refused() {
    let (_d, path) = input_file("cloud.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    let run = meshtrim(&["edges", path_str(&path), "-o", path_str(&path)]);
    assert_eq!(run.status.code(), Some(1));
    assert!(stderr(&run).contains("the output would overwrite the input"));
    assert_eq!(
        std::fs::read(&path).unwrap(),
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\n"
    );
}

#[test]
fn usage_errors_exit_2() {
    // The output is required.
    assert_eq!(meshtrim(&["edges", FIXTURE]).status.code(), Some(2));
    assert_eq!(
        meshtrim(&["edges", FIXTURE, "-o", "x.json", "--k", "x"])
            .status
            .code(),
        Some(2)
    );
}

/// The summary says how the loops were found: milk.pcd's ragged border,
/// which BPD's links leave open, traced in the cloud's own best-fit plane
/// by default and in the camera's image plane with its view; the fixture's
/// clean borders by the links (see `json_summary_keys`).
#[test]
fn the_summary_says_how_the_loops_were_found() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("e.json");
    let milk = "fixtures/scans/pcl_test/milk.pcd";
    for (view, expected, words) in [
        (&[][..], "own_plane", "the cloud's own plane, seen along "),
        (
            &["--view-from", "0,0,0"][..],
            "scanner_image",
            "the scanner's image plane",
        ),
    ] {
        let mut args = vec!["edges", milk, "-o", path_str(&out)];
        args.extend_from_slice(view);
        let run = meshtrim(&[args.clone(), vec!["--json"]].concat());
        assert!(run.status.success(), "{}", stderr(&run));
        let v: Value = serde_json::from_slice(&run.stdout).unwrap();
        assert_eq!(v["loops_from"], expected, "{v}");
        let table = String::from_utf8(meshtrim(&args).stdout).unwrap();
        assert!(
            table.contains(&format!("loops from           {words}")),
            "{table}"
        );
    }
}
