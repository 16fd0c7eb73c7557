//! libmeshtrim: meshtrim's C API, declared and documented in
//! `include/meshtrim.h`.
//!
//! Each function runs what the CLI command of the same name runs between
//! reading and writing (`meshtrim::commands::*::*_in_memory`, as the
//! Python package does), so the arrays and the report are the CLI's, bit
//! for bit. This layer only checks and copies the caller's arrays, turns
//! the options into the library's, and hands results and messages back as
//! memory the caller frees through this library.
//!
//! Nothing unwinds into C: every entry point runs under `catch_unwind`,
//! and a panic, which no input should cause, becomes
//! `MESHTRIM_INTERNAL_ERROR` with its message.

mod arrays;
#[cfg(test)]
mod tests;

use std::ffi::{c_char, c_int, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use anyhow::{anyhow, bail, Result};
use cli::commands;
use cli::io::edges_out::{self, step::LengthUnit, EdgeData, EdgeFileOptions, EdgesFormat};
use cli::stages::Stages;
use library::{BpdOptions, EdgeOptions, Mesh, View};

use arrays::{read_faces, read_rows, write_out, OutMesh};

/// Success.
pub const MESHTRIM_OK: c_int = 0;
/// An input or option meshtrim cannot work on.
pub const MESHTRIM_ERROR: c_int = 1;
/// A fault of meshtrim's own (a caught panic).
pub const MESHTRIM_INTERNAL_ERROR: c_int = 2;

/// `MeshtrimOptions::view_kind`: no view.
pub const MESHTRIM_VIEW_NONE: c_int = 0;
/// The scanner looked along `view`.
pub const MESHTRIM_VIEW_ALONG: c_int = 1;
/// The scanner stood at `view`.
pub const MESHTRIM_VIEW_FROM: c_int = 2;

/// `MeshtrimOptions` of the header.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshtrimOptions {
    pub k: u32,
    pub anisotropy: c_int,
    pub offset: c_int,
    pub view_kind: c_int,
    pub view: [f64; 3],
    pub repair: c_int,
    pub max_deviation: f64,
    pub fill_holes: f64,
}

impl Default for MeshtrimOptions {
    /// The CLI's defaults.
    fn default() -> Self {
        Self {
            k: 30,
            anisotropy: 1,
            offset: 1,
            view_kind: MESHTRIM_VIEW_NONE,
            view: [0.0; 3],
            repair: 0,
            max_deviation: 0.0,
            fill_holes: 0.0,
        }
    }
}

impl MeshtrimOptions {
    /// The options behind `options` (the defaults for NULL).
    ///
    /// # Safety
    /// `options` is NULL or points to a `MeshtrimOptions`.
    unsafe fn read(options: *const MeshtrimOptions) -> MeshtrimOptions {
        // SAFETY: the caller's pointer, checked for NULL.
        unsafe { options.as_ref() }.copied().unwrap_or_default()
    }

    /// Detection's and edge reconstruction's options; the view and `k` are
    /// checked by detection itself, in its words.
    fn stages(&self) -> Result<Stages> {
        let view = match self.view_kind {
            MESHTRIM_VIEW_NONE => None,
            MESHTRIM_VIEW_ALONG => Some(View::Along(self.view)),
            MESHTRIM_VIEW_FROM => Some(View::From(self.view)),
            other => bail!(
                "view_kind: {other} is not a view: MESHTRIM_VIEW_NONE (0), \
                 MESHTRIM_VIEW_ALONG (1) or MESHTRIM_VIEW_FROM (2)"
            ),
        };
        Ok(Stages {
            detection: BpdOptions {
                k: self.k as usize,
                anisotropy: self.anisotropy != 0,
                view,
            },
            edges: EdgeOptions {
                offset: self.offset != 0,
            },
        })
    }

    /// `clean`'s own choices: `max_deviation` 0 is no bound and
    /// `fill_holes` 0 closes none; any other value must be a distance.
    fn clean_choices(&self) -> Result<commands::clean::Choices> {
        Ok(commands::clean::Choices {
            repair: self.repair != 0,
            max_deviation: distance_or_none(self.max_deviation, "max_deviation", "no bound")?,
            fill_holes: distance_or_none(self.fill_holes, "fill_holes", "no hole closed")?,
        })
    }
}

/// `value` as a distance, None for 0 (`zero` says what 0 means).
fn distance_or_none(value: f64, name: &str, zero: &str) -> Result<Option<f64>> {
    if value == 0.0 {
        return Ok(None);
    }
    if !(value.is_finite() && value > 0.0) {
        bail!(
            "{name}: {value} is not a distance: give a number above zero, \
             in the mesh's units, or 0 for {zero}"
        );
    }
    Ok(Some(value))
}

/// `meshtrim_version`: the crate's version, NUL-terminated.
#[no_mangle]
pub extern "C" fn meshtrim_version() -> *const c_char {
    const VERSION: &CStr =
        match CStr::from_bytes_with_nul(concat!(env!("CARGO_PKG_VERSION"), "\0").as_bytes()) {
            Ok(version) => version,
            Err(_) => panic!("the version has no NUL inside"),
        };
    VERSION.as_ptr()
}

/// `meshtrim_default_options`.
#[no_mangle]
pub extern "C" fn meshtrim_default_options() -> MeshtrimOptions {
    MeshtrimOptions::default()
}

/// `meshtrim_detect`.
///
/// # Safety
/// As the header states: `points` holds `point_count` rows, `boundary`
/// has room for `point_count` bytes, `beta` (unless NULL) for
/// `point_count` doubles; `options`, `report_json` and `error` are NULL or
/// valid.
#[no_mangle]
pub unsafe extern "C" fn meshtrim_detect(
    points: *const f64,
    point_count: usize,
    options: *const MeshtrimOptions,
    boundary: *mut u8,
    beta: *mut f64,
    report_json: *mut *mut c_char,
    error: *mut *mut c_char,
) -> c_int {
    // SAFETY (whole body): the caller's pointers, as documented above.
    run(error, || unsafe {
        set_string(report_json, None);
        let options = MeshtrimOptions::read(options);
        let points = read_rows(points, point_count, "points")?;
        let detection_options = options.stages()?.detection;
        if boundary.is_null() && point_count > 0 {
            bail!("boundary: NULL, but there are {point_count} points to label");
        }
        let (detection, summary) =
            commands::detect::detect_in_memory(&points, &detection_options, false, "points")?;
        if point_count > 0 {
            let labels = std::slice::from_raw_parts_mut(boundary, point_count);
            for (label, &is_boundary) in labels.iter_mut().zip(&detection.boundary) {
                *label = u8::from(is_boundary);
            }
            if !beta.is_null() {
                std::slice::from_raw_parts_mut(beta, point_count).copy_from_slice(&detection.beta);
            }
        }
        set_string(report_json, Some(json(&summary)?));
        Ok(())
    })
}

/// `meshtrim_edges`.
///
/// # Safety
/// As the header states: `points` holds `point_count` rows, `path` is a
/// NUL-terminated string, `units` is NULL or one; `options`, `report_json`
/// and `error` are NULL or valid.
#[no_mangle]
#[allow(clippy::too_many_arguments)] // the header's signature
pub unsafe extern "C" fn meshtrim_edges(
    points: *const f64,
    point_count: usize,
    options: *const MeshtrimOptions,
    path: *const c_char,
    units: *const c_char,
    dxf_splines: c_int,
    report_json: *mut *mut c_char,
    error: *mut *mut c_char,
) -> c_int {
    // SAFETY (whole body): the caller's pointers, as documented above.
    run(error, || unsafe {
        set_string(report_json, None);
        let options = MeshtrimOptions::read(options);
        let (path, file_options) = edges_file(path, units, dxf_splines)?;
        let stages = options.stages()?;
        let points = read_rows(points, point_count, "points")?;
        let (detection, edges, summary) =
            commands::edges::edges_in_memory(&points, &stages, false, "points")?;
        let data = EdgeData {
            points: &points,
            boundary: &detection.boundary,
            edges: &edges,
            options: file_options,
        };
        edges_out::write_file(path, data)?;
        set_string(report_json, Some(json(&summary)?));
        Ok(())
    })
}

/// `meshtrim_border_edges`.
///
/// # Safety
/// As the header states: each array holds its count of rows, `path` is a
/// NUL-terminated string, `units` is NULL or one; `options` and `error`
/// are NULL or valid.
#[no_mangle]
#[allow(clippy::too_many_arguments)] // the header's signature
pub unsafe extern "C" fn meshtrim_border_edges(
    vertices: *const f64,
    vertex_count: usize,
    faces: *const u32,
    face_count: usize,
    options: *const MeshtrimOptions,
    path: *const c_char,
    units: *const c_char,
    dxf_splines: c_int,
    error: *mut *mut c_char,
) -> c_int {
    // SAFETY (whole body): the caller's pointers, as documented above.
    run(error, || unsafe {
        let options = MeshtrimOptions::read(options);
        let (path, file_options) = edges_file(path, units, dxf_splines)?;
        let stages = options.stages()?;
        let mesh = read_mesh(vertices, vertex_count, faces, face_count)?;
        mesh.validate()
            .map_err(|e| anyhow!("vertices and faces: {e}"))?;
        let border = commands::clean::border_curves(&mesh, &stages, "vertices")?;
        commands::clean::write_border(path, &mesh, &border, file_options)
    })
}

/// The caller's edges file and how it is written, checked before any
/// work.
///
/// # Safety
/// `path` and `units` are NULL or NUL-terminated.
unsafe fn edges_file<'a>(
    path: *const c_char,
    units: *const c_char,
    dxf_splines: c_int,
) -> Result<(&'a Path, EdgeFileOptions)> {
    // SAFETY: as documented above.
    let (path, units) = unsafe { (text(path, "path")?, text(units, "units")?) };
    let path = Path::new(path.ok_or_else(|| anyhow!("path: NULL"))?);
    Ok((path, edge_file_options(path, units, dxf_splines != 0)?))
}

/// How an edges file at `path` is written; its format and the options
/// checked before any work.
fn edge_file_options(
    path: &Path,
    units: Option<&str>,
    dxf_splines: bool,
) -> Result<EdgeFileOptions> {
    edges_out::edges_format(path)?;
    let units = match units {
        None => LengthUnit::default(),
        Some(name) => LengthUnit::from_name(name)
            .ok_or_else(|| anyhow!("units: {name:?} is not a length unit: mm, m or in"))?,
    };
    if dxf_splines && EdgesFormat::from_path(path) != Some(EdgesFormat::Dxf) {
        bail!(
            "{}: dxf_splines writes splines into a .dxf file, and this is not one",
            path.display()
        );
    }
    Ok(EdgeFileOptions { units, dxf_splines })
}

/// `meshtrim_trim`.
///
/// # Safety
/// As the header states: each array holds its count of rows; `out` is
/// valid; `options` and `error` are NULL or valid.
#[no_mangle]
#[allow(clippy::too_many_arguments)] // the header's signature
pub unsafe extern "C" fn meshtrim_trim(
    vertices: *const f64,
    vertex_count: usize,
    faces: *const u32,
    face_count: usize,
    points: *const f64,
    point_count: usize,
    options: *const MeshtrimOptions,
    out: *mut OutMesh,
    error: *mut *mut c_char,
) -> c_int {
    // SAFETY (whole body): the caller's pointers, as documented above.
    run(error, || unsafe {
        let out = arrays::emptied(out)?;
        let options = MeshtrimOptions::read(options);
        let settings = commands::trim::TrimSettings {
            stages: options.stages()?,
            progress: false,
            cloud: Default::default(),
            cloud_scale: None,
            measure: true,
        };
        let mesh = read_mesh(vertices, vertex_count, faces, face_count)?;
        let points = read_rows(points, point_count, "points")?;
        let names = ["mesh".to_string(), "points".to_string()];
        let trimmed = commands::trim::trim_in_memory(&mesh, &points, &settings, &names)?;
        write_out(out, trimmed.mesh, json(&trimmed.report)?);
        Ok(())
    })
}

/// `meshtrim_mesh`.
///
/// # Safety
/// As the header states: `points` holds `point_count` rows; `out` is
/// valid; `options` and `error` are NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn meshtrim_mesh(
    points: *const f64,
    point_count: usize,
    options: *const MeshtrimOptions,
    out: *mut OutMesh,
    error: *mut *mut c_char,
) -> c_int {
    // SAFETY (whole body): the caller's pointers, as documented above.
    run(error, || unsafe {
        let out = arrays::emptied(out)?;
        let stages = MeshtrimOptions::read(options).stages()?;
        let points = read_rows(points, point_count, "points")?;
        let meshed = commands::mesh::mesh_in_memory(&points, &stages, false, "points")?;
        write_out(out, meshed.mesh, json(&meshed.report)?);
        Ok(())
    })
}

/// `meshtrim_clean`.
///
/// # Safety
/// As the header states: each array holds its count of rows; `out` is
/// valid; `options` and `error` are NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn meshtrim_clean(
    vertices: *const f64,
    vertex_count: usize,
    faces: *const u32,
    face_count: usize,
    options: *const MeshtrimOptions,
    out: *mut OutMesh,
    error: *mut *mut c_char,
) -> c_int {
    // SAFETY (whole body): the caller's pointers, as documented above.
    run(error, || unsafe {
        let out = arrays::emptied(out)?;
        let options = MeshtrimOptions::read(options);
        let choices = options.clean_choices()?;
        let stages = options.stages()?;
        let mesh = read_mesh(vertices, vertex_count, faces, face_count)?;
        let (cleaned, report) = commands::clean::clean_in_memory(&mesh, &stages, choices, "mesh")?;
        write_out(out, cleaned, json(&report)?);
        Ok(())
    })
}

/// `meshtrim_mesh_free`.
///
/// # Safety
/// `mesh` is NULL or a mesh this library filled (or emptied).
#[no_mangle]
pub unsafe extern "C" fn meshtrim_mesh_free(mesh: *mut OutMesh) {
    // A free must not unwind either; it cannot fail on a mesh of ours.
    let _ = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: as documented above.
        if let Some(mesh) = unsafe { mesh.as_mut() } {
            unsafe { arrays::free(mesh) };
        }
    }));
}

/// `meshtrim_string_free`.
///
/// # Safety
/// `text` is NULL or a string this library gave.
#[no_mangle]
pub unsafe extern "C" fn meshtrim_string_free(text: *mut c_char) {
    if !text.is_null() {
        // SAFETY: made by `CString::into_raw` (`set_string`).
        drop(unsafe { CString::from_raw(text) });
    }
}

/// The mesh of the caller's vertex and face arrays.
///
/// # Safety
/// Each array holds its count of rows (or is NULL with a count of 0).
unsafe fn read_mesh(
    vertices: *const f64,
    vertex_count: usize,
    faces: *const u32,
    face_count: usize,
) -> Result<Mesh> {
    // SAFETY: as documented above.
    unsafe {
        Ok(Mesh {
            vertices: read_rows(vertices, vertex_count, "vertices")?,
            faces: read_faces(faces, face_count, vertex_count)?,
        })
    }
}

/// Runs `work`, turning its error or panic into a status and a message in
/// `*error` (NULL on success).
fn run(error: *mut *mut c_char, work: impl FnOnce() -> Result<()>) -> c_int {
    let (status, message) = match catch_unwind(AssertUnwindSafe(work)) {
        Ok(Ok(())) => (MESHTRIM_OK, None),
        Ok(Err(e)) => (MESHTRIM_ERROR, Some(format!("{e:#}"))),
        Err(panic) => {
            let text = commands::panic_text(panic.as_ref());
            (
                MESHTRIM_INTERNAL_ERROR,
                Some(format!("internal error: {text}")),
            )
        }
    };
    // SAFETY: the caller's `error`, NULL or valid (every entry point's
    // contract).
    unsafe { set_string(error, message) };
    status
}

/// Stores `text` (or NULL) in `*slot` when `slot` is not NULL. A NUL
/// inside the text, which no message or report has, ends it there.
///
/// # Safety
/// `slot` is NULL or valid for a write.
unsafe fn set_string(slot: *mut *mut c_char, text: Option<String>) {
    if slot.is_null() {
        return;
    }
    let raw = text.map_or(std::ptr::null_mut(), |text| {
        let end = text.find('\0').unwrap_or(text.len());
        CString::new(&text[..end]).map_or(std::ptr::null_mut(), CString::into_raw)
    });
    // SAFETY: as documented above.
    unsafe { *slot = raw };
}

/// The caller's NUL-terminated UTF-8 string `name`, None for NULL.
///
/// # Safety
/// `text` is NULL or NUL-terminated.
unsafe fn text<'a>(text: *const c_char, name: &str) -> Result<Option<&'a str>> {
    if text.is_null() {
        return Ok(None);
    }
    // SAFETY: as documented above.
    let bytes = unsafe { CStr::from_ptr(text) };
    bytes
        .to_str()
        .map(Some)
        .map_err(|e| anyhow!("{name}: not UTF-8 ({e})"))
}

fn json(value: &impl serde::Serialize) -> Result<String> {
    Ok(serde_json::to_string(value)?)
}
