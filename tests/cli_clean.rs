//! End-to-end tests of `meshtrim clean IN OUT`.

use std::path::Path;

mod common;
use common::{assert_clean_failure, grid_obj, meshtrim};

const JAGGED: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/fixtures/meshes/blade_jagged.stl"
);
const CLOUD: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/fixtures/meshes/blade_small.ply"
);

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

#[test]
fn cleans_the_fixture_and_reports() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sub/clean.ply");
    let report = dir.path().join("report.json");
    let run = meshtrim(&["clean", JAGGED, s(&out), "--report", s(&report)], None);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(stdout.contains("4 in: 4 smoothed"), "{stdout}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(json["loops_in"], 4);
    assert_eq!(json["loops_smoothed"], 4);
    assert_eq!(json["faces_in"], 5768);
    assert!(json["faces_added"].as_u64().unwrap() > 100, "{json}");
    assert!(json["min_angle_new"].as_f64().unwrap() > 10.0, "{json}");
    // The cleaned border is longer-reaching: the smoothed edge passes
    // outside the jagged one at its notches, so the area grows.
    assert!(
        json["area_out"].as_f64() > json["area_in"].as_f64(),
        "{json}"
    );
    let written = meshtrim::io::read_mesh(&out).unwrap();
    let faces = written.faces.unwrap();
    assert_eq!(faces.len() as u64, json["faces_out"].as_u64().unwrap());
    let mesh = trim::Mesh {
        vertices: written.vertices,
        faces,
    };
    assert!(mesh.is_edge_manifold());
    assert_eq!(mesh.boundary_loops().len(), 4);
    // The deviations are the plain measure's, both ways, on the files.
    let read = meshtrim::io::read_mesh(Path::new(JAGGED)).unwrap();
    let input = trim::Mesh {
        vertices: read.vertices,
        faces: read.faces.unwrap(),
    };
    for (key, surface, measured) in [
        ("input_to_output", &mesh, &input),
        ("output_to_input", &input, &mesh),
    ] {
        let plain = trim::surface_deviation_reference(surface, measured);
        let reported = &json[key];
        assert_eq!(reported["vertices"].as_u64(), Some(plain.vertices as u64));
        assert!(plain.vertices > 100, "{key}: {plain:?}");
        let max = reported["max"].as_f64().unwrap();
        assert!(
            (max - plain.max).abs() < 1e-9,
            "{key}: {reported} {plain:?}"
        );
        let mean = reported["mean"].as_f64().unwrap();
        assert!(
            (mean - plain.mean).abs() < 1e-9,
            "{key}: {reported} {plain:?}"
        );
    }
    assert!(
        stdout.contains(
            "removed vertices     up to 0.6877 from the output's surface (mean 0.02907 over 246)"
        ),
        "{stdout}"
    );
    assert!(
        stdout.contains("new vertices         up to 4.026 off the input's surface"),
        "{stdout}"
    );
}

/// `--edges FILE` writes the cleaned mesh's border: one loop per border
/// loop of the output as written, through its vertices, each corner
/// shared by the two edges it joins; the fixture's outer border has its
/// four corners, its holes none. A bad edges output is refused before any
/// work.
#[test]
fn edges_are_the_cleaned_border() {
    let dir = tempfile::tempdir().unwrap();
    let (out, edges) = (dir.path().join("clean.ply"), dir.path().join("e.json"));
    let run = meshtrim(&["clean", JAGGED, s(&out), "--edges", s(&edges)], None);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let written = meshtrim::io::read_mesh(&out).unwrap();
    let mesh = trim::Mesh {
        vertices: written.vertices,
        faces: written.faces.unwrap(),
    };
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&edges).unwrap()).unwrap();
    let loops = json["loops"].as_array().unwrap();
    let borders = mesh.boundary_loops();
    assert_eq!(loops.len(), borders.len());
    for (lp, border) in loops.iter().zip(&borders) {
        let points: Vec<u32> = serde_json::from_value(lp["boundary_points"].clone()).unwrap();
        assert_eq!(&points, border);
        // The edges joined, each corner once, are the border's vertices
        // from the first corner on.
        let mut through: Vec<[f64; 3]> = Vec::new();
        for edge in lp["edges"].as_array().unwrap() {
            let p: Vec<[f64; 3]> = serde_json::from_value(edge["points"].clone()).unwrap();
            let closed = edge["closed"].as_bool().unwrap();
            through.extend_from_slice(if closed { &p } else { &p[..p.len() - 1] });
        }
        let corners = lp["corners"].as_array().unwrap();
        let start = corners.first().map_or(0, |c| {
            let c: [f64; 3] = serde_json::from_value(c.clone()).unwrap();
            border
                .iter()
                .position(|&v| mesh.vertices[v as usize] == c)
                .unwrap()
        });
        let n = border.len();
        let expected: Vec<[f64; 3]> = (0..n)
            .map(|j| mesh.vertices[border[(start + j) % n] as usize])
            .collect();
        assert_eq!(through, expected);
    }
    let mut corners: Vec<usize> = loops
        .iter()
        .map(|l| l["corners"].as_array().unwrap().len())
        .collect();
    corners.sort_unstable();
    assert_eq!(corners, [0, 0, 0, 4]);
    for bad in ["e.txt", "e.ply"] {
        let out = dir.path().join("never.ply");
        let run = meshtrim(
            &[
                "clean",
                JAGGED,
                s(&out),
                "--edges",
                s(&dir.path().join(bad)),
            ],
            None,
        );
        assert_clean_failure(
            &run,
            "unsupported output format: use .json, .obj, .svg, .dxf, .step or .igs",
        );
        assert!(!out.exists());
    }
    // An OBJ is a mesh and an edges format: the input is never written.
    let grid = dir.path().join("grid.obj");
    std::fs::write(&grid, grid_obj(30, 1.0, true)).unwrap();
    let before = std::fs::read(&grid).unwrap();
    let run = meshtrim(&["clean", s(&grid), s(&out), "--edges", s(&grid)], None);
    assert_clean_failure(&run, "an output would overwrite this input");
    assert_eq!(std::fs::read(&grid).unwrap(), before);
}

#[test]
fn max_deviation_holds_the_new_border_to_the_old() {
    let dir = tempfile::tempdir().unwrap();
    let (free, held) = (dir.path().join("free.ply"), dir.path().join("held.ply"));
    let report = |out: &Path, extra: &[&str]| {
        let run = meshtrim(
            &[&["clean", JAGGED, s(out), "--json"], extra].concat(),
            None,
        );
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        serde_json::from_slice::<serde_json::Value>(&run.stdout).unwrap()
    };
    let (free, held) = (
        report(&free, &[]),
        report(&held, &["--max-deviation", "1.5"]),
    );
    // Unbounded, the fixture's new border runs up to 4.03 off the scan.
    assert!(
        free["output_to_input"]["max"].as_f64().unwrap() > 4.0,
        "{free}"
    );
    assert!(free.get("max_deviation").is_none() && free.get("vertices_held").is_none());
    assert_eq!(held["max_deviation"], 1.5);
    assert!(held["vertices_held"].as_u64().unwrap() > 0, "{held}");
    assert!(
        held["output_to_input"]["max"].as_f64().unwrap() <= 1.5 + 1e-9,
        "{held}"
    );
    assert!(
        held["input_to_output"]["max"].as_f64().unwrap() <= 1.5 + 1e-9,
        "{held}"
    );
    assert_eq!(held["loops_smoothed"], 4);
    for bad in ["0", "-1", "nan", "inf", "wide"] {
        let run = meshtrim(
            &[
                "clean",
                JAGGED,
                s(&dir.path().join("x.ply")),
                "--max-deviation",
                bad,
            ],
            None,
        );
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{bad}: {stderr}");
        assert!(
            stderr.contains("is not a distance: give a number above zero"),
            "{stderr}"
        );
    }
}

#[test]
fn fill_holes_closes_the_holes_no_wider_than_asked() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("filled.ply");
    let report = |width: &str| {
        let run = meshtrim(
            &["clean", JAGGED, s(&out), "--fill-holes", width, "--json"],
            None,
        );
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        serde_json::from_slice::<serde_json::Value>(&run.stdout).unwrap()
    };
    // The fixture's three holes are 30-60, 60-100 and 100-200 mm wide.
    for (width, holes, loops) in [("30", 0, 4), ("60", 1, 3), ("100", 2, 2), ("200", 3, 1)] {
        let r = report(width);
        assert_eq!(r["holes_filled"], holes, "{r}");
        assert_eq!(r["holes_not_filled"], 0, "{r}");
        assert_eq!(r["loops_in"], loops, "{r}");
        let written = meshtrim::io::read_mesh(&out).unwrap();
        let mesh = trim::Mesh {
            vertices: written.vertices,
            faces: written.faces.unwrap(),
        };
        mesh.check_manifold().unwrap();
        // The outer border stays, however wide the size.
        assert_eq!(mesh.boundary_loops().len(), loops, "{width}");
    }
    let run = meshtrim(&["clean", JAGGED, s(&out), "--fill-holes", "200"], None);
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(
        text.contains(
            "holes filled         3 up to 200.0 wide, with 67 faces (0 as narrow left open)"
        ),
        "{text}"
    );
    // Without the option the report has no such keys.
    let run = meshtrim(&["clean", JAGGED, s(&out), "--json"], None);
    let plain: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    assert!(plain.get("holes_filled").is_none() && plain.get("fill_holes").is_none());
    for bad in ["0", "-3", "inf"] {
        let run = meshtrim(
            &[
                "clean",
                JAGGED,
                s(&dir.path().join("no.ply")),
                "--fill-holes",
                bad,
            ],
            None,
        );
        assert!(!run.status.success());
        assert!(String::from_utf8_lossy(&run.stderr).contains("--fill-holes"));
    }
    assert!(!dir.path().join("no.ply").exists());
}

#[test]
fn same_bytes_whatever_the_threads() {
    let dir = tempfile::tempdir().unwrap();
    // The fixture, and the fixture with a fin stood on one of its edges,
    // repaired.
    let stl = std::fs::read(JAGGED).unwrap();
    let damaged = fixture_with(dir.path(), "damaged.stl", &[fin_on_first_edge(&stl)]).0;
    for (input, repair) in [
        (Path::new(JAGGED), None),
        (damaged.as_path(), Some("--repair")),
    ] {
        let (a, b) = (dir.path().join("a.stl"), dir.path().join("b.stl"));
        for (out, threads) in [(&a, "1"), (&b, "2")] {
            let mut args = vec!["clean", s(input), s(out), "--json"];
            args.extend(repair);
            let run = meshtrim(&args, Some(threads));
            assert!(
                run.status.success(),
                "{}",
                String::from_utf8_lossy(&run.stderr)
            );
            let json: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
            let repaired = json["crowded_faces_removed"].as_u64().unwrap()
                + json["faces_flipped"].as_u64().unwrap();
            assert_eq!(repaired > 0, repair.is_some(), "{json}");
        }
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    }
}

/// A binary STL triangle standing on the first triangle's first edge,
/// its tip a little off the edge's middle.
fn fin_on_first_edge(stl: &[u8]) -> Vec<u8> {
    let corner = |k: usize| -> [f32; 3] {
        let at = 84 + 12 + 12 * k;
        [0, 4, 8].map(|o| f32::from_le_bytes(stl[at + o..at + o + 4].try_into().unwrap()))
    };
    let (a, b) = (corner(0), corner(1));
    let tip = [0, 1, 2].map(|c| (a[c] + b[c]) / 2.0 + if c == 2 { 0.05 } else { 0.0 });
    let mut triangle = vec![0u8; 50];
    for (k, p) in [a, b, tip].iter().enumerate() {
        for (c, x) in p.iter().enumerate() {
            let at = 12 + 12 * k + 4 * c;
            triangle[at..at + 4].copy_from_slice(&x.to_le_bytes());
        }
    }
    triangle
}

#[test]
fn a_cloud_is_not_a_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.ply");
    let run = meshtrim(&["clean", CLOUD, s(&out)], None);
    assert_clean_failure(&run, "has no faces");
    assert!(!out.exists());
}

#[test]
fn the_output_never_overwrites_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.stl");
    std::fs::copy(JAGGED, &input).unwrap();
    let before = std::fs::read(&input).unwrap();
    let run = meshtrim(&["clean", s(&input), s(&input)], None);
    assert_clean_failure(&run, "overwrite");
    assert_eq!(std::fs::read(&input).unwrap(), before);
}

#[test]
fn unknown_output_formats_and_reports_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let run = meshtrim(&["clean", JAGGED, s(&dir.path().join("out.xyz"))], None);
    assert_clean_failure(&run, "unsupported output format");
    let out = dir.path().join("out.stl");
    let report = dir.path().join("r.txt");
    let run = meshtrim(&["clean", JAGGED, s(&out), "--report", s(&report)], None);
    assert_clean_failure(&run, "name it .json");
    assert!(!out.exists());
}

/// `--report R.JSON` is a JSON report like `r.json`: the extension's case
/// does not matter, as for the mesh output.
#[test]
fn an_upper_case_report_extension_is_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let (out, report) = (dir.path().join("OUT.STL"), dir.path().join("R.JSON"));
    let run = meshtrim(&["clean", JAGGED, s(&out), "--report", s(&report)], None);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(json["faces_in"], 5768);
}

#[test]
fn a_non_manifold_mesh_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("fin.obj");
    // A fan of 40 triangles round a centre, plus a third face on one edge.
    let mut text = String::from("v 0 0 0\n");
    for i in 0..40 {
        let a = i as f64 * std::f64::consts::TAU / 40.0;
        text += &format!("v {} {} 0\n", a.cos(), a.sin());
    }
    text += "v 0.5 0 1\n";
    for i in 0..40 {
        text += &format!("f 1 {} {}\n", i + 2, (i + 1) % 40 + 2);
    }
    text += "f 1 2 42\n";
    std::fs::write(&input, text).unwrap();
    let output = dir.path().join("o.obj");
    let run = meshtrim(&["clean", s(&input), s(&output)], None);
    assert_clean_failure(&run, "shared by more than two faces");
    assert!(String::from_utf8_lossy(&run.stderr).contains("clean with --repair"));
    assert!(!output.exists());
    // Repaired as MeshLab's "Repair non Manifold Edges" would: of the three
    // faces on the edge, the smallest (a slice of the fan, 0.08 against
    // the fin's 0.5) goes, and the fan's rim is cleaned.
    let (json, stdout) = repaired(dir.path(), &input, &output);
    assert_eq!(json["crowded_faces_removed"], 1);
    assert_eq!(json["faces_flipped"], 0);
    assert_eq!(json["one_sided_faces_removed"], 0);
    assert!(stdout.contains("1 from edges of 3+ faces"), "{stdout}");
}

/// Runs `meshtrim clean INPUT OUTPUT --repair`, which must succeed; its
/// JSON report and what it printed.
fn repaired(dir: &Path, input: &Path, output: &Path) -> (serde_json::Value, String) {
    let report = dir.join("repaired.json");
    let args = [
        "clean",
        s(input),
        s(output),
        "--repair",
        "--report",
        s(&report),
    ];
    let run = meshtrim(&args, None);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let json = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    (json, String::from_utf8_lossy(&run.stdout).into_owned())
}

/// Faces wound against their neighbours (an exporter that lost some
/// triangles' turn): refused, naming `--repair`; with it they are turned
/// back, and the output has the bytes of the grid cleaned as it was.
#[test]
fn faces_wound_the_wrong_way_are_turned_back_with_repair() {
    let dir = tempfile::tempdir().unwrap();
    let grid = grid_obj(24, 1.0, true);
    let mut flipped = 0;
    let wrong: String = grid
        .lines()
        .enumerate()
        .map(
            |(i, line)| match line.split_whitespace().collect::<Vec<_>>()[..] {
                ["f", a, b, c] if i % 7 == 0 => {
                    flipped += 1;
                    format!("f {a} {c} {b}\n")
                }
                _ => format!("{line}\n"),
            },
        )
        .collect();
    let (right_path, wrong_path) = (dir.path().join("grid.obj"), dir.path().join("wrong.obj"));
    std::fs::write(&right_path, grid).unwrap();
    std::fs::write(&wrong_path, wrong).unwrap();
    let (want, got) = (dir.path().join("want.ply"), dir.path().join("got.ply"));
    let run = meshtrim(&["clean", s(&wrong_path), s(&got)], None);
    assert_clean_failure(&run, "run the same way by both their faces");
    assert!(String::from_utf8_lossy(&run.stderr).contains("clean with --repair"));
    let run = meshtrim(&["clean", s(&right_path), s(&want)], None);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let (json, _) = repaired(dir.path(), &wrong_path, &got);
    assert_eq!(std::fs::read(&want).unwrap(), std::fs::read(&got).unwrap());
    assert!(flipped > 100, "{flipped}");
    assert_eq!(json["faces_flipped"], flipped);
    assert_eq!(json["crowded_faces_removed"], 0);
}

/// A mesh of nothing but triangles written once each way (each pair a
/// pocket of no volume, which the output's repair removes): a clear error,
/// not an empty file written with success.
#[test]
fn a_mesh_the_repairs_empty_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("pockets.obj");
    let mut text = String::new();
    for t in 0..40u32 {
        // Scattered triangles, far enough apart to give every vertex a
        // neighbourhood of its own.
        let (x, y) = (f64::from(t % 8) * 3.0, f64::from(t / 8) * 3.0);
        text += &format!(
            "v {x} {y} 0\nv {} {y} 0.3\nv {x} {} 0.6\n",
            x + 1.0,
            y + 1.0
        );
    }
    for t in 0..40u32 {
        let a = 3 * t + 1;
        text += &format!("f {a} {} {}\nf {a} {} {}\n", a + 1, a + 2, a + 2, a + 1);
    }
    std::fs::write(&input, text).unwrap();
    let output = dir.path().join("o.obj");
    let run = meshtrim(&["clean", s(&input), s(&output)], None);
    assert_clean_failure(
        &run,
        "no face would be left: the repairs remove all 80 faces",
    );
    assert!(!output.exists());
}

#[test]
fn a_truncated_file_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("cut.stl");
    let bytes = std::fs::read(JAGGED).unwrap();
    std::fs::write(&input, &bytes[..bytes.len() / 2]).unwrap();
    let out = dir.path().join("o.stl");
    let run = meshtrim(&["clean", s(&input), s(&out)], None);
    assert_clean_failure(&run, "cut.stl");
    assert!(!out.exists());
}

/// Coordinates beyond the supported range (|coordinate| up to 1e50, the
/// largest at least 1e-30) are refused with the range, not a panic in
/// spade (1e90) or a wrong verdict; inside it the scale changes nothing.
#[test]
fn coordinates_out_of_range_are_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let run_at = |scale: f64| {
        let input = dir.path().join(format!("grid{scale:e}.obj"));
        std::fs::write(&input, grid_obj(20, scale, true)).unwrap();
        let out = dir.path().join(format!("out{scale:e}.obj"));
        (
            meshtrim(&["clean", s(&input), s(&out), "--json"], None),
            out,
        )
    };
    for scale in [1e90, 1e60, 1e-35, 1e-60] {
        let (run, out) = run_at(scale);
        assert_clean_failure(&run, "the largest |coordinate| is");
        assert_clean_failure(&run, "between 1e-30 and 1e50");
        assert!(!out.exists());
    }
    let faces = |scale| {
        let (run, _) = run_at(scale);
        let json: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
        (json["faces_out"].clone(), json["loops_smoothed"].clone())
    };
    assert_eq!(faces(1e45), faces(1.0));
    assert_eq!(faces(1e-28), faces(1.0));
}

/// A closed mesh has no border to clean: nothing is replaced, and the
/// report says there is no new face instead of a smallest angle of 0°.
#[test]
fn a_closed_mesh_is_written_unchanged_and_reports_no_new_angle() {
    let dir = tempfile::tempdir().unwrap();
    let (input, out) = (dir.path().join("cylinder.obj"), dir.path().join("out.obj"));
    std::fs::write(&input, cylinder_obj(true)).unwrap();
    let run = meshtrim(&["clean", s(&input), s(&out)], None);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(stdout.contains("0 removed, 0 new"), "{stdout}");
    assert!(stdout.contains("none (no new faces)"), "{stdout}");
    assert!(stdout.contains("removed vertices     none"), "{stdout}");
    assert!(stdout.contains("new vertices         none"), "{stdout}");
    assert!(
        stdout.contains("warning              no border: a closed mesh has nothing to clean"),
        "{stdout}"
    );
    let (before, after) = (
        meshtrim::io::read_mesh(&input).unwrap(),
        meshtrim::io::read_mesh(&out).unwrap(),
    );
    assert_eq!(after.vertices, before.vertices);
    assert_eq!(after.faces, before.faces);
}

/// A cylinder of 24 sides and 8 rings, faces outward, its top capped by a
/// fan and its bottom too when `bottom_cap`.
fn cylinder_obj(bottom_cap: bool) -> String {
    let (sides, rings) = (24u32, 8u32);
    let mut text = String::new();
    for r in 0..rings {
        for k in 0..sides {
            let a = std::f64::consts::TAU * f64::from(k) / f64::from(sides);
            text += &format!("v {} {} {}\n", a.cos(), a.sin(), 0.3 * f64::from(r));
        }
    }
    let (bottom, top) = (rings * sides + 1, rings * sides + 2);
    text += &format!("v 0 0 0\nv 0 0 {}\n", 0.3 * f64::from(rings - 1));
    let at = |r: u32, k: u32| r * sides + k % sides + 1;
    for r in 0..rings - 1 {
        for k in 0..sides {
            text += &format!("f {} {} {}\n", at(r, k), at(r, k + 1), at(r + 1, k + 1));
            text += &format!("f {} {} {}\n", at(r, k), at(r + 1, k + 1), at(r + 1, k));
        }
    }
    for k in 0..sides {
        if bottom_cap {
            text += &format!("f {bottom} {} {}\n", at(0, k + 1), at(0, k));
        }
        text += &format!("f {top} {} {}\n", at(rings - 1, k), at(rings - 1, k + 1));
    }
    text
}

/// A closed surface cut open (a cylinder without its bottom cap): cleaned,
/// with a warning that it wraps round an object and how to trim an
/// envelope instead; the jagged scan gets no warning.
#[test]
fn an_envelope_cut_open_is_cleaned_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let (input, out) = (dir.path().join("cup.obj"), dir.path().join("out.obj"));
    std::fs::write(&input, cylinder_obj(false)).unwrap();
    let run = meshtrim(&["clean", s(&input), s(&out), "--json"], None);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    // The open end's ring faces away from the cap: the wall's far half.
    let share = json["area_facing_one_way"].as_f64().unwrap();
    assert!(share > 0.5 && share < 0.75, "{json}");
    let run = meshtrim(&["clean", s(&input), s(&out)], None);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        stdout.contains("warning              the surface wraps round an object")
            && stdout.contains("trim it with its cloud instead: meshtrim MESH CLOUD OUT"),
        "{stdout}"
    );
    let run = meshtrim(&["clean", JAGGED, s(&out)], None);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success() && !stdout.contains("warning"),
        "{stdout}"
    );
}

/// The fixture with `extra` binary STL triangles appended, written to
/// `dir/name`; returns its path and the fixture's triangle count.
fn fixture_with(dir: &Path, name: &str, extra: &[Vec<u8>]) -> (std::path::PathBuf, u32) {
    let mut stl = std::fs::read(JAGGED).unwrap();
    let count = u32::from_le_bytes(stl[80..84].try_into().unwrap());
    for triangle in extra {
        stl.extend_from_slice(triangle);
    }
    stl[80..84].copy_from_slice(&(count + extra.len() as u32).to_le_bytes());
    let path = dir.join(name);
    std::fs::write(&path, &stl).unwrap();
    (path, count)
}

/// Cleans the fixture and `input`; returns `input`'s JSON report after
/// checking that both outputs have the same bytes.
fn cleaned_like_the_fixture(dir: &Path, input: &Path) -> serde_json::Value {
    let (want, got) = (dir.join("want.stl"), dir.join("got.stl"));
    let report = dir.join("report.json");
    for run in [
        meshtrim(&["clean", JAGGED, s(&want)], None),
        meshtrim(&["clean", s(input), s(&got), "--report", s(&report)], None),
    ] {
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
    }
    assert_eq!(std::fs::read(&want).unwrap(), std::fs::read(&got).unwrap());
    serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap()
}

/// A binary STL sliver whose two corners coincide (one face naming a vertex
/// twice once the reader merges them) is dropped and counted; the rest is
/// cleaned to the same bytes as the file without it.
#[test]
fn an_stl_sliver_with_two_equal_corners_is_dropped_and_counted() {
    let dir = tempfile::tempdir().unwrap();
    let stl = std::fs::read(JAGGED).unwrap();
    // The first triangle again, its third corner moved onto its second.
    let mut sliver = stl[84..134].to_vec();
    let second_corner = sliver[24..36].to_vec();
    sliver[36..48].copy_from_slice(&second_corner);
    let (input, count) = fixture_with(dir.path(), "sliver.stl", &[sliver]);
    let json = cleaned_like_the_fixture(dir.path(), &input);
    assert_eq!(json["slivers_dropped"], 1);
    assert_eq!(json["repeated_faces_dropped"], 0);
    assert_eq!(json["faces_in"], u64::from(count) + 1);
}

/// A triangle written twice is dropped and counted, not an error that
/// stops the cleanup ("3 edges are shared by more than two faces").
#[test]
fn an_stl_triangle_written_twice_is_dropped_and_counted() {
    let dir = tempfile::tempdir().unwrap();
    let stl = std::fs::read(JAGGED).unwrap();
    let triangle = |t: usize| stl[84 + 50 * t..134 + 50 * t].to_vec();
    let (input, count) = fixture_with(dir.path(), "twice.stl", &[triangle(100), triangle(7)]);
    let json = cleaned_like_the_fixture(dir.path(), &input);
    assert_eq!(json["repeated_faces_dropped"], 2);
    assert_eq!(json["slivers_dropped"], 0);
    assert_eq!(json["faces_in"], u64::from(count) + 2);
}

/// Two corners of the fixture thrown far off (the sign and exponent bytes
/// of their x flipped, as a damaged file would): a wall of one band's gap
/// then runs into the smoothed loop itself, and the vertex in its way is
/// one of the loop's new vertices, which the mesh does not have. That
/// must not panic (an index out of bounds, found by mutating the
/// fixtures): the two loops around the thrown corners are left as they
/// are, with the reason (the strip tried after the planar way finds their
/// smoothed loops doubling back round the thrown corners).
#[test]
fn a_wall_blocked_by_the_smoothed_loop_leaves_the_loop() {
    let dir = tempfile::tempdir().unwrap();
    let mut stl = std::fs::read(JAGGED).unwrap();
    // The top byte of x: triangle 4,738's second corner, 4,750's third.
    stl[237_011] = 170;
    stl[237_623] = 8;
    let input = dir.path().join("thrown.stl");
    std::fs::write(&input, &stl).unwrap();
    let output = dir.path().join("out.ply");
    let run = meshtrim(&["clean", s(&input), s(&output)], None);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        stdout.contains("4 smoothed, 0 too small, 2 left"),
        "{stdout}"
    );
    assert_eq!(stdout.matches("left unchanged").count(), 2, "{stdout}");
    assert!(output.exists());
}

/// The fixture written as a triangle soup (each face with its own three
/// `v` lines, as a flat-shaded export stores it): every inner edge is a
/// seam. It is cleaned to the fixture's own output, the report counting
/// every inner edge stitched.
#[test]
fn a_triangle_soup_is_cleaned_as_the_welded_scan() {
    let dir = tempfile::tempdir().unwrap();
    let (soup, mesh) = soup_of_the_fixture(dir.path(), |_| None);
    let json = cleaned_like_the_fixture(dir.path(), &soup);
    let border: usize = mesh.boundary_loops().iter().map(Vec::len).sum();
    let inner_edges = (3 * mesh.faces.len() - border) / 2;
    assert_eq!(json["seam_edges_stitched"], inner_edges as u64);
    let run = meshtrim(&["clean", s(&soup), s(&dir.path().join("again.stl"))], None);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        stdout.contains(&format!("seams stitched       {inner_edges} edges")),
        "{stdout}"
    );
}

/// The soup with a colour per face (flat shading): cleaned to PLY, the
/// output is split again where the soup was, so every face kept keeps its
/// own colour at its three corners.
#[test]
fn each_face_of_a_flat_shaded_soup_keeps_its_colour() {
    let dir = tempfile::tempdir().unwrap();
    let colour = |f: usize| [f % 251, (f / 251) % 251, 7].map(|c| c as f64 / 255.0);
    let (soup, mesh) = soup_of_the_fixture(dir.path(), |f| Some(colour(f)));
    let out = dir.path().join("out.ply");
    let run = meshtrim(&["clean", s(&soup), s(&out)], None);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let written = meshtrim::io::read_mesh(&out).unwrap();
    let rgba = written.colours.unwrap().rgba;
    let key = |p: [f64; 3]| p.map(f64::to_bits);
    let mut face_of: std::collections::HashMap<[[u64; 3]; 3], usize> = Default::default();
    for (f, face) in mesh.faces.iter().enumerate() {
        let mut corners = face.map(|v| key(mesh.vertices[v as usize]));
        corners.sort_unstable();
        face_of.insert(corners, f);
    }
    let mut kept = 0;
    for face in written.faces.unwrap() {
        let mut corners = face.map(|v| key(written.vertices[v as usize]));
        corners.sort_unstable();
        if let Some(&f) = face_of.get(&corners) {
            kept += 1;
            for v in face {
                let [r, g, b, _] = rgba[v as usize];
                let bytes = |c: [f64; 3]| c.map(|x| (x * 255.0).round() as u8);
                assert_eq!(bytes([r, g, b]), bytes(colour(f)), "face {f}");
            }
        }
    }
    assert!(kept > 4000, "{kept} faces kept");
}

/// Writes the fixture as an OBJ triangle soup, each face's corners given
/// `colour(face)` if any; returns its path and the welded fixture.
fn soup_of_the_fixture(
    dir: &Path,
    colour: impl Fn(usize) -> Option<[f64; 3]>,
) -> (std::path::PathBuf, trim::Mesh) {
    let read = meshtrim::io::read_mesh(Path::new(JAGGED)).unwrap();
    let mesh = trim::Mesh {
        vertices: read.vertices,
        faces: read.faces.unwrap(),
    };
    let mut text = String::new();
    for (f, face) in mesh.faces.iter().enumerate() {
        for &v in face {
            let [x, y, z] = mesh.vertices[v as usize];
            text += &match colour(f) {
                Some([r, g, b]) => format!("v {x:?} {y:?} {z:?} {r:?} {g:?} {b:?}\n"),
                None => format!("v {x:?} {y:?} {z:?}\n"),
            };
        }
    }
    for f in 0..mesh.faces.len() {
        text += &format!("f {} {} {}\n", 3 * f + 1, 3 * f + 2, 3 * f + 3);
    }
    let path = dir.join("soup.obj");
    std::fs::write(&path, text).unwrap();
    (path, mesh)
}
