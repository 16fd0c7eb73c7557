//! End-to-end tests of the main job, `meshtrim MESH CLOUD OUT`.

use std::path::{Path, PathBuf};

mod common;
use common::{assert_clean_failure, grid_obj, meshtrim, path_str, stderr};
use meshtrim::io::Point3;

const MESH: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/fixtures/meshes/blade_small_poisson.ply"
);
const CLOUD: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/fixtures/meshes/blade_small.ply"
);

fn temp_dir() -> tempfile::TempDir {
    tempfile::tempdir().expect("temporary directory")
}

/// Runs meshtrim with `args` (which ask for `--json`), asserts that it
/// succeeded and returns the JSON it printed.
fn succeeds_with_json(args: &[&str]) -> serde_json::Value {
    let run = meshtrim(args, None);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_slice(&run.stdout).unwrap()
}

fn path(dir: &Path, name: &str) -> PathBuf {
    dir.join(name)
}

#[test]
fn trims_the_fixture_and_reports() {
    let dir = temp_dir();
    let out = path(dir.path(), "sub/trimmed.ply");
    let report = path(dir.path(), "report.json");
    let run = meshtrim(
        &[
            MESH,
            CLOUD,
            out.to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
        ],
        None,
    );
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(
        text.contains("faces in / out") && text.contains("loops"),
        "{text}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(json["loops"], 4, "outer border and three holes: {json}");
    assert_eq!(json["border_to_edge"].as_array().unwrap().len(), 4);
    let (faces_in, faces_out) = (
        json["faces_in"].as_u64().unwrap(),
        json["faces_out"].as_u64().unwrap(),
    );
    assert!(faces_out > 0 && faces_out < faces_in, "{json}");
    assert!(
        json["area_out"].as_f64().unwrap() < json["area_in"].as_f64().unwrap() / 2.0,
        "the envelope's far side must go"
    );
    // Every cloud point is measured against the output (none lies at one
    // of the envelope's vertices): the scan's fit to the reconstruction.
    let fit = &json["cloud_to_output"];
    assert_eq!(fit["vertices"], json["points"], "{fit}");
    let (mean, max) = (fit["mean"].as_f64().unwrap(), fit["max"].as_f64().unwrap());
    assert!(0.0 < mean && mean < max, "{fit}");
    assert!(text.contains("cloud points"), "{text}");
    for key in [
        "read_ms",
        "detect_ms",
        "edges_ms",
        "trim_ms",
        "deviation_ms",
        "write_ms",
        "faces_split",
        "pieces_dropped",
        "pieces_restored",
        "faces_out_of_reach",
        "pinch_faces_dropped",
    ] {
        assert!(json.get(key).is_some(), "missing {key}");
    }
}

#[test]
fn the_trim_subcommand_is_the_same_job_and_output_is_deterministic() {
    let dir = temp_dir();
    let a = path(dir.path(), "a.obj");
    let b = path(dir.path(), "b.obj");
    assert!(meshtrim(&[MESH, CLOUD, a.to_str().unwrap()], Some("1"))
        .status
        .success());
    assert!(
        meshtrim(&["trim", MESH, CLOUD, b.to_str().unwrap()], Some("2"))
            .status
            .success()
    );
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn every_mesh_format_is_written() {
    let dir = temp_dir();
    for ext in ["obj", "ply", "stl", "glb", "gltf"] {
        let out = path(dir.path(), &format!("t.{ext}"));
        let run = meshtrim(&[MESH, CLOUD, out.to_str().unwrap()], None);
        assert!(
            run.status.success(),
            "{ext}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
        assert!(std::fs::metadata(&out).unwrap().len() > 0, "{ext}");
    }
}

#[test]
fn bad_inputs_fail_cleanly_and_write_nothing() {
    let dir = temp_dir();
    let out = path(dir.path(), "out.ply");
    let o = out.to_str().unwrap();
    assert_clean_failure(
        &meshtrim(
            &[MESH, CLOUD, &path(dir.path(), "out.xyz").to_string_lossy()],
            None,
        ),
        "out.xyz",
    );
    assert_clean_failure(&meshtrim(&["missing.ply", CLOUD, o], None), "missing.ply");
    assert_clean_failure(&meshtrim(&[MESH, "missing.xyz", o], None), "missing.xyz");
    // Both read at once; the mesh's error comes first, as if it were read
    // first.
    let both = meshtrim(&["missing.ply", "missing.xyz", o], None);
    assert_clean_failure(&both, "missing.ply");
    assert!(!String::from_utf8_lossy(&both.stderr).contains("missing.xyz"));
    // A cloud given as the mesh: it has no faces.
    assert_clean_failure(&meshtrim(&[CLOUD, CLOUD, o], None), "blade_small.ply");
    // A cloud far away from the mesh supports none of it.
    let moved = path(dir.path(), "moved.xyz");
    let text: String = (0..200)
        .map(|i| {
            format!(
                "{} {} {}\n",
                1e6 + (i % 20) as f64,
                1e6 + (i / 20) as f64,
                1e6 + 0.01 * ((i * 7) % 5) as f64
            )
        })
        .collect();
    std::fs::write(&moved, text).unwrap();
    assert_clean_failure(
        &meshtrim(&[MESH, moved.to_str().unwrap(), o], None),
        "supported",
    );
    assert!(!out.exists(), "no output on failure");
}

#[test]
fn an_output_naming_an_input_is_refused() {
    let dir = temp_dir();
    let mesh = path(dir.path(), "mesh.ply");
    std::fs::copy(MESH, &mesh).unwrap();
    let before = std::fs::read(&mesh).unwrap();
    assert_clean_failure(
        &meshtrim(
            &[mesh.to_str().unwrap(), CLOUD, mesh.to_str().unwrap()],
            None,
        ),
        "mesh.ply",
    );
    assert_eq!(std::fs::read(&mesh).unwrap(), before);
}

/// `meshtrim mesh` refuses, before reading, an output or a report that
/// would replace its cloud, and a report not named .json.
#[test]
fn the_delaunay_path_never_overwrites_its_cloud() {
    let dir = temp_dir();
    let cloud = path(dir.path(), "c.ply");
    std::fs::copy(CLOUD, &cloud).unwrap();
    // A text cloud may have any extension, .json included.
    let json_cloud = path(dir.path(), "c.json");
    std::fs::write(&json_cloud, "0 0 0\n1 0 0\n0 1 0\n").unwrap();
    let out = path(dir.path(), "o.ply");
    let (c, j, o) = (
        cloud.to_str().unwrap(),
        json_cloud.to_str().unwrap(),
        out.to_str().unwrap(),
    );
    let runs: [(&[&str], &str); 4] = [
        (
            &["mesh", c, c],
            "c.ply: an output would overwrite this input",
        ),
        (&["mesh", c, o, "--report", c], "name it .json"),
        (
            &["mesh", j, o, "--report", j],
            "c.json: an output would overwrite",
        ),
        (&["mesh", c, o, "--report", "r.txt"], "name it .json"),
    ];
    for (args, message) in runs {
        assert_clean_failure(&meshtrim(args, None), message);
    }
    assert_eq!(
        std::fs::read(&cloud).unwrap(),
        std::fs::read(CLOUD).unwrap()
    );
    assert_eq!(
        std::fs::read(&json_cloud).unwrap(),
        b"0 0 0\n1 0 0\n0 1 0\n"
    );
    assert!(!out.exists());
}

#[test]
fn the_delaunay_path_meshes_the_cloud_and_refuses_a_folded_surface() {
    let dir = temp_dir();
    let out = path(dir.path(), "delaunay.ply");
    let json = succeeds_with_json(&["mesh", CLOUD, out.to_str().unwrap(), "--json"]);
    assert_eq!(json["loops"], 4, "{json}");
    assert!(json["faces"].as_u64().unwrap() > 1000, "{json}");
    // A cylinder patch covering 300° of arc folds over any plane.
    let folded = path(dir.path(), "folded.xyz");
    let text: String = (0..120 * 30)
        .map(|i| {
            let (a, z) = (
                (i % 120) as f64 / 120.0 * 300f64.to_radians(),
                (i / 120) as f64 * 0.26,
            );
            format!("{} {} {}\n", 10.0 * a.cos(), 10.0 * a.sin(), z)
        })
        .collect();
    std::fs::write(&folded, text).unwrap();
    let out = path(dir.path(), "folded.ply");
    assert_clean_failure(
        &meshtrim(
            &["mesh", folded.to_str().unwrap(), out.to_str().unwrap()],
            None,
        ),
        "folded.xyz",
    );
    assert!(!out.exists());
    // The scanner placed inside the cloud: no camera image holds it.
    let run = meshtrim(
        &[
            "mesh",
            CLOUD,
            out.to_str().unwrap(),
            "--view-from",
            "277,0,9",
        ],
        None,
    );
    assert_clean_failure(&run, "beside or behind the scanner's position");
    assert!(String::from_utf8_lossy(&run.stderr).contains("check --view-from"));
    assert!(!out.exists());
}

/// The main job takes the stage options without a subcommand.
#[test]
fn the_main_job_takes_the_stage_options() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.ply");
    let run = meshtrim(
        &[
            MESH,
            CLOUD,
            out.to_str().unwrap(),
            "--no-offset",
            "--k",
            "20",
            "--view-along",
            "0.1,0,1",
            "--json",
        ],
        None,
    );
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(out.exists());
    let both = meshtrim(
        &[
            MESH,
            CLOUD,
            out.to_str().unwrap(),
            "--view-along",
            "0,0,1",
            "--view-from",
            "0,0,0",
        ],
        None,
    );
    assert_eq!(both.status.code(), Some(2));
}

#[test]
fn the_delaunay_path_gives_the_same_faces_for_a_moved_quantised_cloud() {
    // A plate with a square hole on an exact lattice (every cell a
    // co-circular quad), as written at the origin and 1000 units away.
    let dir = temp_dir();
    let lattice = |shift: f64| -> String {
        (0..40 * 30)
            .map(|k| (k % 40, k / 40))
            .filter(|&(i, j)| !((15..22).contains(&i) && (10..17).contains(&j)))
            .map(|(i, j)| {
                format!(
                    "{} {} {}\n",
                    f64::from(i) * 0.5 + shift,
                    f64::from(j) * 0.5 + shift,
                    shift
                )
            })
            .collect()
    };
    let mut meshes = Vec::new();
    for (name, shift) in [("here", 0.0), ("there", 1000.0)] {
        let cloud = path(dir.path(), &format!("{name}.xyz"));
        std::fs::write(&cloud, lattice(shift)).unwrap();
        let out = path(dir.path(), &format!("{name}.ply"));
        let json = succeeds_with_json(&[
            "mesh",
            cloud.to_str().unwrap(),
            out.to_str().unwrap(),
            "--json",
        ]);
        assert_eq!(json["loops"], 2, "{json}");
        meshes.push(meshtrim::io::read_mesh(&out).unwrap());
    }
    let (here, there) = (&meshes[0], &meshes[1]);
    assert!(here.faces.as_ref().is_some_and(|f| f.len() > 1000));
    assert_eq!(here.faces, there.faces);
    assert_eq!(here.vertices.len(), there.vertices.len());
    for (a, b) in here.vertices.iter().zip(&there.vertices) {
        assert!(
            (0..3).all(|k| (a[k] + 1000.0 - b[k]).abs() < 1e-6),
            "{a:?} {b:?}"
        );
    }
}

/// The Delaunay path and detection refuse clouds beyond the supported
/// coordinate range by naming it, instead of "the mesh has no faces" (1e60,
/// beyond spade's range), a folded surface (1e-60, flushed to zero by
/// spade) or a line or point (1e160, 1e-300: squares overflow or
/// underflow); inside it the scale changes nothing.
#[test]
fn clouds_out_of_range_are_a_clear_error() {
    let dir = temp_dir();
    let run_at = |command: &str, scale: f64| {
        let cloud = path(dir.path(), &format!("grid{scale:e}.obj"));
        std::fs::write(&cloud, grid_obj(20, scale, false)).unwrap();
        let out = path(dir.path(), "out.ply");
        let out = out.to_str().unwrap();
        let args = match command {
            "mesh" => vec!["mesh", cloud.to_str().unwrap(), out, "--json"],
            _ => vec!["detect", cloud.to_str().unwrap(), "--json"],
        };
        meshtrim(&args, None)
    };
    for (command, scale) in [
        ("mesh", 1e60),
        ("mesh", 1e-60),
        ("detect", 1e160),
        ("detect", 1e-300),
    ] {
        let run = run_at(command, scale);
        assert_clean_failure(&run, "the largest |coordinate| is");
        assert_clean_failure(&run, "between 1e-30 and 1e50");
    }
    // A mesh out of range for an in-range cloud: the error names the mesh.
    let mesh = path(dir.path(), "far.obj");
    std::fs::write(&mesh, grid_obj(20, 1e60, true)).unwrap();
    let out = path(dir.path(), "out.ply");
    let run = meshtrim(
        &[mesh.to_str().unwrap(), CLOUD, out.to_str().unwrap()],
        None,
    );
    assert_clean_failure(
        &run,
        "far.obj: the coordinates are out of the supported range",
    );
    assert!(!out.exists());
    let faces = |scale| {
        let json: serde_json::Value =
            serde_json::from_slice(&run_at("mesh", scale).stdout).unwrap();
        json["faces"].clone()
    };
    assert_eq!(faces(1e45), faces(1.0));
    assert_eq!(faces(1e-28), faces(1.0));
}

/// `meshtrim` alone prints the help (the main job's usage and every
/// command), not only the main job's missing arguments, and exits 2.
#[test]
fn bare_meshtrim_prints_the_help() {
    let run = meshtrim(&[], None);
    assert_eq!(run.status.code(), Some(2));
    let help = String::from_utf8_lossy(&run.stderr);
    assert!(
        help.contains("meshtrim [OPTIONS] <MESH> <CLOUD> <OUTPUT>"),
        "{help}"
    );
    for command in ["detect", "edges", "trim", "mesh", "clean", "batch"] {
        assert!(
            help.contains(&format!("\n  {command} ")),
            "{command}: {help}"
        );
    }
}

/// The view options have one help, the same wherever they are taken, and
/// `--help` says why a scanner's line of sight matters.
#[test]
fn the_view_options_are_explained_once_for_every_command() {
    let help_of = |args: &[&str]| {
        let run = meshtrim(args, None);
        assert!(run.status.success(), "{}", stderr(&run));
        String::from_utf8_lossy(&run.stdout).into_owned()
    };
    let why = "err along their line of sight";
    let paragraph = |help: &str, option: &str| {
        let start = help
            .find(option)
            .unwrap_or_else(|| panic!("{option}: {help}"));
        help[start..]
            .split("\n      --")
            .next()
            .unwrap()
            .to_string()
    };
    let detect = help_of(&["detect", "--help"]);
    for args in [
        vec!["--help"],
        vec!["trim", "--help"],
        vec!["edges", "--help"],
        vec!["mesh", "--help"],
    ] {
        let help = help_of(&args);
        for option in ["--view-along", "--view-from"] {
            let text = paragraph(&help, option);
            assert!(text.contains(why), "{args:?} {option}: {text}");
            assert_eq!(text, paragraph(&detect, option), "{args:?} {option}");
        }
    }
}

/// The summary says how its face counts relate.
#[test]
fn the_summary_says_how_the_face_counts_relate() {
    let dir = temp_dir();
    let out = path(dir.path(), "out.ply");
    let run = meshtrim(&[MESH, CLOUD, out.to_str().unwrap()], None);
    assert!(run.status.success(), "{}", stderr(&run));
    let summary = String::from_utf8_lossy(&run.stdout);
    for line in [
        "faces split          803 by the border (their inner parts kept)",
        "faces removed        4429 whole (beyond the border, in dropped pieces or out of reach)",
        "pieces dropped       4 (no cloud support; their faces are among those removed)",
        "faces out of reach   3140 parts of faces no cloud point reaches, dropped",
    ] {
        assert!(summary.contains(line), "{line}: {summary}");
    }
}

/// The fixture cloud scaled by `factor`, as XYZ text in `dir`.
fn scaled_cloud(dir: &Path, factor: f64) -> PathBuf {
    let cloud = meshtrim::io::read_cloud(Path::new(CLOUD)).unwrap();
    let text: String = cloud
        .points
        .iter()
        .map(|p| {
            format!(
                "{:e} {:e} {:e}\n",
                p[0] * factor,
                p[1] * factor,
                p[2] * factor
            )
        })
        .collect();
    let file = path(dir, &format!("cloud_{factor}.xyz"));
    std::fs::write(&file, text).unwrap();
    file
}

/// A cloud in other units than its mesh (metres against the Poisson
/// mesh's millimetres, as a scanner's E57 file holds them) supports
/// nothing: the error names the units and the flag that scales the cloud,
/// and nothing is written; with the flag, the trim is the cloud's in the
/// mesh's units. A ratio no two units have is not taken for one, though the
/// Poisson envelope, larger than its cloud, spans ten times the cloud
/// scaled by 1/7, and 70 % of those points scaled by 10 pass within reach
/// of it.
#[test]
fn a_cloud_in_other_units_is_named_so() {
    let dir = temp_dir();
    let out = path(dir.path(), "out.ply");
    let o = out.to_str().unwrap();
    let metres = scaled_cloud(dir.path(), 0.001);
    let run = meshtrim(&[MESH, metres.to_str().unwrap(), o], None);
    assert_clean_failure(
        &run,
        "no part of the mesh is supported by the cloud: the cloud looks to be in metres and the \
         mesh in millimetres (scaled by 1000, the cloud lies on the mesh): scale the cloud with \
         --cloud-scale 1000",
    );
    // Scaled back, the cloud trims as in the mesh's units: the same bytes
    // (halved and doubled, so that no rounding enters).
    let halved = scaled_cloud(dir.path(), 0.5);
    let scaled = path(dir.path(), "scaled.ply");
    let report = path(dir.path(), "scaled.json");
    let run = meshtrim(
        &[
            MESH,
            halved.to_str().unwrap(),
            scaled.to_str().unwrap(),
            "--cloud-scale",
            "2",
            "--report",
            report.to_str().unwrap(),
        ],
        None,
    );
    assert!(run.status.success(), "{}", stderr(&run));
    let same = scaled_cloud(dir.path(), 1.0);
    let direct = path(dir.path(), "direct.ply");
    let run = meshtrim(
        &[MESH, same.to_str().unwrap(), direct.to_str().unwrap()],
        None,
    );
    assert!(run.status.success(), "{}", stderr(&run));
    let (a, b) = (
        std::fs::read(&scaled).unwrap(),
        std::fs::read(&direct).unwrap(),
    );
    assert!(
        a == b,
        "the scaled cloud's trim differs from the cloud's own"
    );
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    assert_eq!(report["cloud_scale"], 2.0);
    let sevenths = scaled_cloud(dir.path(), 1.0 / 7.0);
    let run = meshtrim(&[MESH, sevenths.to_str().unwrap(), o], None);
    assert_clean_failure(
        &run,
        "the cloud's bounding box is 10.133 times smaller than the mesh's",
    );
    assert!(!stderr(&run).contains("scaled by"), "{}", stderr(&run));
    assert!(!out.exists());
}

/// A scale factor must be a number above zero.
#[test]
fn a_cloud_scale_must_be_above_zero() {
    let dir = temp_dir();
    let out = path(dir.path(), "out.ply");
    for bad in ["0", "-1000", "nan", "inf", "mm"] {
        let run = meshtrim(
            &[MESH, CLOUD, out.to_str().unwrap(), "--cloud-scale", bad],
            None,
        );
        assert_eq!(run.status.code(), Some(2), "{bad}: {}", stderr(&run));
        assert!(
            stderr(&run).contains("give a number above zero, e.g. 1000"),
            "{bad}: {}",
            stderr(&run)
        );
    }
    assert!(!out.exists());
}

/// The fixture's mesh and cloud moved to UTM-like coordinates (half a
/// million east, four million north, as a georeferenced scan's), where
/// `f32` steps by 0.25: PLY and OBJ keep the trim to `f64`; glTF stores it
/// about its centre and keeps it to 10⁻⁴ (the mesh is 930 across); STL
/// would merge vertices and flatten faces, so it is refused, the file
/// named and nothing written.
#[test]
fn a_mesh_far_from_the_origin_keeps_its_shape_or_is_refused() {
    const UTM: Point3 = [512_345.0, 4_123_456.0, 250.0];
    let dir = temp_dir();
    let mut mesh = meshtrim::io::read_mesh(Path::new(MESH)).unwrap();
    let faces = mesh.faces.take().unwrap();
    let away = |p: &Point3| -> Point3 { std::array::from_fn(|k| p[k] + UTM[k]) };
    let vertices: Vec<Point3> = mesh.vertices.iter().map(away).collect();
    let mesh = path(dir.path(), "mesh.ply");
    meshtrim::io::write_mesh(&mesh, &vertices, &faces).unwrap();
    let cloud = meshtrim::io::read_cloud(Path::new(CLOUD)).unwrap();
    let text: String = (cloud.points.iter().map(away))
        .map(|p| format!("{:e} {:e} {:e}\n", p[0], p[1], p[2]))
        .collect();
    let cloud = path(dir.path(), "cloud.xyz");
    std::fs::write(&cloud, text).unwrap();
    let trim_to = |name: &str| {
        let out = path(dir.path(), name);
        let run = meshtrim(&[path_str(&mesh), path_str(&cloud), path_str(&out)], None);
        (out, run)
    };
    let here = path(dir.path(), "here.ply");
    let run = meshtrim(&[MESH, CLOUD, path_str(&here)], None);
    assert!(run.status.success(), "{}", stderr(&run));
    let here = meshtrim::io::read_mesh(&here).unwrap();
    for (name, tolerance) in [("far.ply", 1e-8), ("far.obj", 1e-8), ("far.glb", 1e-4)] {
        let (out, run) = trim_to(name);
        assert!(run.status.success(), "{name}: {}", stderr(&run));
        let far = meshtrim::io::read_mesh(&out).unwrap();
        assert_eq!(far.faces, here.faces, "{name}");
        for (a, b) in here.vertices.iter().zip(&far.vertices) {
            let off = (0..3).fold(0.0f64, |m, k| m.max((a[k] + UTM[k] - b[k]).abs()));
            assert!(off < tolerance, "{name}: {a:?} {b:?}");
        }
    }
    let (out, run) = trim_to("far.stl");
    assert_clean_failure(&run, "far.stl: STL stores coordinates as f32");
    let message = stderr(&run);
    assert!(message.contains("rounding merges vertex"), "{message}");
    assert!(
        message.contains("or .glb (f32 about the mesh's centre)"),
        "{message}"
    );
    assert!(!out.exists());
}
