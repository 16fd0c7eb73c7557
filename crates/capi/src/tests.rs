//! The entry points called as C calls them: results equal the commands'
//! in-memory halves, and bad input gives a status and a message, never a
//! panic. (`tests/python/test_c_api.py` compiles a C program against the
//! header and the built library.)

use super::*;
use std::ptr::{null, null_mut};

fn fixture(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/meshes")
        .join(name)
}

fn jagged_scan() -> Mesh {
    cli::io::read_mesh_with_faces(&fixture("blade_jagged.stl"), "a scan").expect("the fixture")
}

fn cloud() -> Vec<[f64; 3]> {
    cli::io::read_cloud(&fixture("blade_small.ply"))
        .expect("the fixture")
        .points
}

/// The message behind `error`, freed.
fn message(error: *mut c_char) -> String {
    assert!(!error.is_null(), "a failure gives a message");
    // SAFETY: a string of ours, freed once.
    let text = unsafe { CStr::from_ptr(error) }
        .to_string_lossy()
        .into_owned();
    unsafe { meshtrim_string_free(error) };
    text
}

/// The mesh behind `out`, copied, and `out` freed.
fn taken(out: &mut OutMesh) -> (Mesh, String) {
    // SAFETY: filled by an entry point with these counts.
    let mesh = unsafe {
        Mesh {
            vertices: arrays::read_rows(out.vertices, out.vertex_count, "out").expect("rows"),
            faces: arrays::read_rows(out.faces, out.face_count, "out").expect("rows"),
        }
    };
    let report = message(out.report_json);
    out.report_json = null_mut();
    unsafe { meshtrim_mesh_free(out) };
    assert!(out.vertices.is_null() && out.faces.is_null() && out.vertex_count == 0);
    (mesh, report)
}

fn clean_c(mesh: &Mesh, options: Option<&MeshtrimOptions>) -> Result<(Mesh, String), String> {
    let mut out = OutMesh::EMPTY;
    let mut error = null_mut();
    let options = options.map_or(null(), |o| o as *const _);
    // SAFETY: the mesh's own arrays with their counts.
    let status = unsafe {
        meshtrim_clean(
            mesh.vertices.as_flattened().as_ptr(),
            mesh.vertices.len(),
            mesh.faces.as_flattened().as_ptr(),
            mesh.faces.len(),
            options,
            &mut out,
            &mut error,
        )
    };
    match status {
        MESHTRIM_OK => {
            assert!(error.is_null());
            Ok(taken(&mut out))
        }
        MESHTRIM_ERROR => {
            assert!(out.vertices.is_null() && out.report_json.is_null());
            Err(message(error))
        }
        other => panic!("status {other}: {}", message(error)),
    }
}

#[test]
fn defaults_are_the_clis() {
    let options = meshtrim_default_options();
    let stages = options.stages().expect("valid");
    assert_eq!(stages.detection, BpdOptions::default());
    assert!(stages.edges.offset);
    let choices = options.clean_choices().expect("valid");
    assert!(!choices.repair && choices.max_deviation.is_none() && choices.fill_holes.is_none());
    // SAFETY: a static NUL-terminated string.
    let version = unsafe { CStr::from_ptr(meshtrim_version()) };
    assert_eq!(version.to_str(), Ok(env!("CARGO_PKG_VERSION")));
}

#[test]
fn clean_gives_the_commands_mesh_and_report() {
    let scan = jagged_scan();
    let options = MeshtrimOptions {
        max_deviation: 0.8,
        fill_holes: 60.0,
        ..Default::default()
    };
    let (out, report) = clean_c(&scan, Some(&options)).expect("cleaned");
    let stages = options.stages().expect("valid");
    let choices = options.clean_choices().expect("valid");
    let (expected, expected_report) =
        commands::clean::clean_in_memory(&scan, &stages, choices, "mesh").expect("cleaned");
    assert_eq!(out.vertices, expected.vertices);
    assert_eq!(out.faces, expected.faces);
    let report: serde_json::Value = serde_json::from_str(&report).expect("JSON");
    let expected_report = serde_json::to_value(&expected_report).expect("JSON");
    assert_eq!(report["loops_smoothed"], expected_report["loops_smoothed"]);
    assert_eq!(report["faces_out"], expected_report["faces_out"]);
    assert!(report["loops_smoothed"].as_u64() > Some(0), "{report}");
    assert_eq!(report["holes_filled"], 1, "{report}");
}

#[test]
fn detect_labels_and_beta_are_the_commands() {
    let points = cloud();
    let n = points.len();
    let (mut boundary, mut beta) = (vec![7u8; n], vec![f64::NAN; n]);
    let (mut report, mut error) = (null_mut(), null_mut());
    // SAFETY: arrays of n rows and n values.
    let status = unsafe {
        meshtrim_detect(
            points.as_flattened().as_ptr(),
            n,
            null(),
            boundary.as_mut_ptr(),
            beta.as_mut_ptr(),
            &mut report,
            &mut error,
        )
    };
    assert_eq!(status, MESHTRIM_OK);
    let report = message(report);
    let (expected, _) =
        commands::detect::detect_in_memory(&points, &BpdOptions::default(), false, "points")
            .expect("detected");
    let labels: Vec<bool> = boundary.iter().map(|&b| b == 1).collect();
    assert!(boundary.iter().all(|&b| b <= 1));
    assert_eq!(labels, expected.boundary);
    assert_eq!(beta, expected.beta);
    assert!(report.contains("\"boundary_points\""), "{report}");
}

#[test]
fn trim_and_mesh_give_the_commands_meshes() {
    let envelope = cli::io::read_mesh_with_faces(&fixture("blade_small_poisson.ply"), "a mesh")
        .expect("the fixture");
    let points = cloud();
    let settings = commands::trim::TrimSettings {
        stages: MeshtrimOptions::default().stages().expect("valid"),
        progress: false,
        cloud: Default::default(),
        cloud_scale: None,
        measure: true,
    };
    let names = ["mesh".to_string(), "points".to_string()];
    let expected =
        commands::trim::trim_in_memory(&envelope, &points, &settings, &names).expect("trimmed");
    let (mut out, mut error) = (OutMesh::EMPTY, null_mut());
    // SAFETY: the arrays with their counts.
    let status = unsafe {
        meshtrim_trim(
            envelope.vertices.as_flattened().as_ptr(),
            envelope.vertices.len(),
            envelope.faces.as_flattened().as_ptr(),
            envelope.faces.len(),
            points.as_flattened().as_ptr(),
            points.len(),
            null(),
            &mut out,
            &mut error,
        )
    };
    assert_eq!(status, MESHTRIM_OK);
    let (trimmed, _) = taken(&mut out);
    assert_eq!(trimmed.vertices, expected.mesh.vertices);
    assert_eq!(trimmed.faces, expected.mesh.faces);

    let expected =
        commands::mesh::mesh_in_memory(&points, &settings.stages, false, "points").expect("meshed");
    // SAFETY: the cloud's rows.
    let status = unsafe {
        meshtrim_mesh(
            points.as_flattened().as_ptr(),
            points.len(),
            null(),
            &mut out,
            &mut error,
        )
    };
    assert_eq!(status, MESHTRIM_OK);
    let (meshed, _) = taken(&mut out);
    assert_eq!(meshed.vertices, expected.mesh.vertices);
    assert_eq!(meshed.faces, expected.mesh.faces);
}

#[test]
fn bad_meshes_and_options_are_errors_with_messages() {
    let scan = jagged_scan();
    let mut bad_index = scan.clone();
    bad_index.faces[5][1] = scan.vertices.len() as u32;
    let e = clean_c(&bad_index, None).unwrap_err();
    assert!(e.contains("faces: face 5 refers to vertex"), "{e}");

    let mut not_finite = scan.clone();
    not_finite.vertices[3][2] = f64::NAN;
    let e = clean_c(&not_finite, None).unwrap_err();
    assert!(e.contains("point 3 has a non-finite coordinate"), "{e}");

    let no_faces = Mesh {
        vertices: scan.vertices.clone(),
        faces: Vec::new(),
    };
    assert!(clean_c(&no_faces, None).is_err());

    let options = |o: MeshtrimOptions| clean_c(&scan, Some(&o)).unwrap_err();
    let e = options(MeshtrimOptions {
        k: 2,
        ..Default::default()
    });
    assert!(e.contains("k = 2 is too small"), "{e}");
    let e = options(MeshtrimOptions {
        view_kind: 7,
        ..Default::default()
    });
    assert!(e.starts_with("view_kind: 7 is not a view"), "{e}");
    let e = options(MeshtrimOptions {
        view_kind: MESHTRIM_VIEW_ALONG,
        view: [0.0; 3],
        ..Default::default()
    });
    assert!(
        e.contains("the scanner view") && e.contains("is not usable"),
        "{e}"
    );
    for d in [-1.0, f64::NAN, f64::INFINITY] {
        let e = options(MeshtrimOptions {
            max_deviation: d,
            ..Default::default()
        });
        assert!(e.starts_with("max_deviation: "), "{e}");
        let e = options(MeshtrimOptions {
            fill_holes: d,
            ..Default::default()
        });
        assert!(e.starts_with("fill_holes: "), "{e}");
    }
}

#[test]
fn null_arrays_only_with_nothing_in_them() {
    let mut error = null_mut();
    let mut out = OutMesh::EMPTY;
    // SAFETY: NULL arrays with counts: refused before any read.
    let status = unsafe { meshtrim_clean(null(), 10, null(), 0, null(), &mut out, &mut error) };
    assert_eq!(status, MESHTRIM_ERROR);
    assert_eq!(message(error), "vertices: NULL, but its count is 10");
    // SAFETY: NULL with no rows is an empty array.
    let status = unsafe { meshtrim_mesh(null(), 0, null(), &mut out, &mut error) };
    assert_eq!(status, MESHTRIM_ERROR);
    assert!(!message(error).is_empty());
    // A count no memory holds.
    let one = [0.0f64; 3];
    let status =
        unsafe { meshtrim_mesh(one.as_ptr(), usize::MAX / 8, null(), &mut out, &mut error) };
    assert_eq!(status, MESHTRIM_ERROR);
    assert!(message(error).contains("larger than memory can hold"));
    // No place for the result.
    let status = unsafe { meshtrim_mesh(one.as_ptr(), 1, null(), null_mut(), &mut error) };
    assert_eq!(status, MESHTRIM_ERROR);
    assert!(message(error).starts_with("out: NULL"));
    // No place for the labels.
    let points = cloud();
    let status = unsafe {
        meshtrim_detect(
            points.as_flattened().as_ptr(),
            points.len(),
            null(),
            null_mut(),
            null_mut(),
            null_mut(),
            &mut error,
        )
    };
    assert_eq!(status, MESHTRIM_ERROR);
    assert!(message(error).starts_with("boundary: NULL"));
    // A NULL error slot is allowed: the status alone tells.
    let status = unsafe { meshtrim_clean(null(), 10, null(), 0, null(), &mut out, null_mut()) };
    assert_eq!(status, MESHTRIM_ERROR);
    // Frees of nothing.
    unsafe {
        meshtrim_mesh_free(null_mut());
        meshtrim_mesh_free(&mut out);
        meshtrim_string_free(null_mut());
    }
}

#[test]
fn edges_files_are_checked_before_any_work() {
    let points = cloud();
    let dir = std::env::temp_dir().join(format!("meshtrim-capi-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let write = |name: &str, units: Option<&str>, splines: c_int| {
        let path = CString::new(dir.join(name).to_str().expect("UTF-8")).expect("no NUL");
        let units = units.map(|u| CString::new(u).expect("no NUL"));
        let mut error = null_mut();
        // SAFETY: the cloud's rows and NUL-terminated strings.
        let status = unsafe {
            meshtrim_edges(
                points.as_flattened().as_ptr(),
                points.len(),
                null(),
                path.as_ptr(),
                units.as_ref().map_or(null(), |u| u.as_ptr()),
                splines,
                null_mut(),
                &mut error,
            )
        };
        (status != MESHTRIM_OK).then(|| message(error))
    };
    let e = write("e.txt", None, 0).expect("refused");
    assert!(e.contains("e.txt") && e.contains("unsupported"), "{e}");
    let e = write("e.step", Some("furlongs"), 0).expect("refused");
    assert_eq!(e, "units: \"furlongs\" is not a length unit: mm, m or in");
    let e = write("e.step", None, 1).expect("refused");
    assert!(e.ends_with("dxf_splines writes splines into a .dxf file, and this is not one"));
    assert!(!dir.join("e.step").exists());
    assert_eq!(write("e.step", Some("in"), 0), None);
    assert!(std::fs::read_to_string(dir.join("e.step"))
        .expect("written")
        .contains("INCH"));
    std::fs::remove_dir_all(&dir).expect("removed");
}

#[test]
fn border_edges_are_the_commands_border() {
    let scan = jagged_scan();
    let stages = MeshtrimOptions::default().stages().expect("valid");
    let (cleaned, _) = commands::clean::clean_in_memory(&scan, &stages, Default::default(), "mesh")
        .expect("cleaned");
    let dir = std::env::temp_dir().join(format!("meshtrim-capi-border-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let write = |mesh: &Mesh, name: &str| {
        let path = CString::new(dir.join(name).to_str().expect("UTF-8")).expect("no NUL");
        let mut error = null_mut();
        // SAFETY: the mesh's rows and a NUL-terminated path.
        let status = unsafe {
            meshtrim_border_edges(
                mesh.vertices.as_flattened().as_ptr(),
                mesh.vertices.len(),
                mesh.faces.as_flattened().as_ptr(),
                mesh.faces.len(),
                null(),
                path.as_ptr(),
                null(),
                0,
                &mut error,
            )
        };
        (status != MESHTRIM_OK).then(|| message(error))
    };
    assert_eq!(write(&cleaned, "ours.json"), None);
    let border = commands::clean::border_curves(&cleaned, &stages, "vertices").expect("border");
    let theirs = dir.join("theirs.json");
    commands::clean::write_border(&theirs, &cleaned, &border, EdgeFileOptions::default())
        .expect("written");
    let ours = std::fs::read(dir.join("ours.json")).expect("written");
    assert_eq!(ours, std::fs::read(&theirs).expect("written"));
    assert!(!border.loops.is_empty());
    let no_faces = Mesh {
        vertices: cleaned.vertices.clone(),
        faces: Vec::new(),
    };
    let e = write(&no_faces, "none.json").expect("refused");
    assert!(e.starts_with("vertices and faces: "), "{e}");
    assert!(!dir.join("none.json").exists());
    std::fs::remove_dir_all(&dir).expect("removed");
}

/// The structs' layouts as the header's C gives them
/// (`test_c_api.py::test_the_header_compiles_as_cpp` asserts the C side's).
#[test]
fn layouts_are_the_headers() {
    use std::mem::{offset_of, size_of};
    let options = [
        offset_of!(MeshtrimOptions, k),
        offset_of!(MeshtrimOptions, anisotropy),
        offset_of!(MeshtrimOptions, offset),
        offset_of!(MeshtrimOptions, view_kind),
        offset_of!(MeshtrimOptions, view),
        offset_of!(MeshtrimOptions, repair),
        offset_of!(MeshtrimOptions, max_deviation),
        offset_of!(MeshtrimOptions, fill_holes),
        size_of::<MeshtrimOptions>(),
    ];
    assert_eq!(options, [0, 4, 8, 12, 16, 40, 48, 56, 64]);
    let mesh = [
        offset_of!(OutMesh, vertices),
        offset_of!(OutMesh, vertex_count),
        offset_of!(OutMesh, faces),
        offset_of!(OutMesh, face_count),
        offset_of!(OutMesh, report_json),
        size_of::<OutMesh>(),
    ];
    assert_eq!(mesh, [0, 8, 16, 24, 32, 40]);
}
