//! The caller's arrays in, meshtrim's meshes out.
//!
//! Inputs are checked (NULL only with a count of 0, a size that fits in
//! memory, face indices within the vertices) and copied once into the
//! library's rows. Outputs are boxed slices handed to the caller as raw
//! pointers, with their row counts, and taken back by [`free`]; an empty
//! array is NULL.

use std::ffi::{c_char, CString};

use anyhow::{bail, Result};
use library::Mesh;

/// `MeshtrimMesh` of the header.
#[repr(C)]
#[derive(Debug)]
pub struct OutMesh {
    pub vertices: *mut f64,
    pub vertex_count: usize,
    pub faces: *mut u32,
    pub face_count: usize,
    pub report_json: *mut c_char,
}

impl OutMesh {
    /// No arrays, no report.
    pub const EMPTY: OutMesh = OutMesh {
        vertices: std::ptr::null_mut(),
        vertex_count: 0,
        faces: std::ptr::null_mut(),
        face_count: 0,
        report_json: std::ptr::null_mut(),
    };
}

/// The caller's `count` rows of three values at `data`, copied.
///
/// # Safety
/// `data` is NULL or holds `count` rows of three values.
pub unsafe fn read_rows<T: Copy>(data: *const T, count: usize, name: &str) -> Result<Vec<[T; 3]>> {
    let values = checked_len::<T>(data.is_null(), count, name)?;
    if values == 0 {
        return Ok(Vec::new());
    }
    // SAFETY: non-NULL, and the caller's array holds `values` values, a
    // size `checked_len` found addressable.
    let flat = unsafe { std::slice::from_raw_parts(data, values) };
    Ok(flat
        .chunks_exact(3)
        .map(|row| [row[0], row[1], row[2]])
        .collect())
}

/// The caller's faces, each index checked against `vertex_count`.
///
/// # Safety
/// As [`read_rows`].
pub unsafe fn read_faces(
    data: *const u32,
    count: usize,
    vertex_count: usize,
) -> Result<Vec<[u32; 3]>> {
    // SAFETY: as documented above.
    let faces = unsafe { read_rows(data, count, "faces")? };
    for (face, corners) in faces.iter().enumerate() {
        if let Some(&vertex) = corners.iter().find(|&&v| v as usize >= vertex_count) {
            bail!("faces: face {face} refers to vertex {vertex}, but there are {vertex_count} vertices");
        }
    }
    Ok(faces)
}

/// The number of values in `count` rows of three, refused when the array
/// is NULL with rows, or larger than memory can address.
fn checked_len<T>(null: bool, count: usize, name: &str) -> Result<usize> {
    if null && count > 0 {
        bail!("{name}: NULL, but its count is {count}");
    }
    match count.checked_mul(3 * size_of::<T>()) {
        Some(bytes) if bytes <= isize::MAX as usize => Ok(3 * count),
        _ => bail!("{name}: a count of {count} rows is larger than memory can hold"),
    }
}

/// `out`, emptied: every pointer NULL and every count 0, so that it is
/// empty on failure and safe to free either way.
///
/// # Safety
/// `out` is NULL or valid for a write.
pub unsafe fn emptied<'a>(out: *mut OutMesh) -> Result<&'a mut OutMesh> {
    // SAFETY: as documented above.
    let Some(out) = (unsafe { out.as_mut() }) else {
        bail!("out: NULL: give a MeshtrimMesh for the result");
    };
    *out = OutMesh::EMPTY;
    Ok(out)
}

/// Hands `mesh` and its `report` to the caller through `out`.
pub fn write_out(out: &mut OutMesh, mesh: Mesh, report: String) {
    out.vertex_count = mesh.vertices.len();
    out.face_count = mesh.faces.len();
    out.vertices = into_raw(flatten(mesh.vertices));
    out.faces = into_raw(flatten(mesh.faces));
    out.report_json = CString::new(report).map_or(std::ptr::null_mut(), CString::into_raw);
}

fn flatten<T: Copy>(rows: Vec<[T; 3]>) -> Vec<T> {
    rows.into_iter().flatten().collect()
}

/// The values as a raw pointer the caller holds (NULL when empty); taken
/// back by [`from_raw`] with the same length.
fn into_raw<T>(values: Vec<T>) -> *mut T {
    if values.is_empty() {
        return std::ptr::null_mut();
    }
    Box::into_raw(values.into_boxed_slice()).cast()
}

/// Takes back what [`into_raw`] gave for `len` values.
///
/// # Safety
/// `data` is NULL or came from [`into_raw`] with `len` values.
unsafe fn from_raw<T>(data: *mut T, len: usize) {
    if !data.is_null() {
        // SAFETY: as documented above.
        drop(unsafe { Box::from_raw(std::ptr::slice_from_raw_parts_mut(data, len)) });
    }
}

/// Frees what [`write_out`] gave and empties `mesh`.
///
/// # Safety
/// `mesh` was filled by [`write_out`] or emptied by [`emptied`].
pub unsafe fn free(mesh: &mut OutMesh) {
    // SAFETY: as documented above; the counts are the rows given.
    unsafe {
        from_raw(mesh.vertices, 3 * mesh.vertex_count);
        from_raw(mesh.faces, 3 * mesh.face_count);
        if !mesh.report_json.is_null() {
            drop(CString::from_raw(mesh.report_json));
        }
    }
    *mesh = OutMesh::EMPTY;
}
