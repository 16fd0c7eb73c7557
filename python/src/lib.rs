//! `meshtrim._meshtrim`: the Python package's native module.
//!
//! Each function runs what the CLI command of the same name runs between
//! reading and writing (`meshtrim::commands::*::*_in_memory`), so the
//! arrays and the report are the CLI's, bit for bit. The Python layer
//! (`python/meshtrim/__init__.py`) checks shapes and converts dtypes; this
//! module takes C-order float64 points and uint32 faces, copies each input
//! once into the library's layout, releases the GIL for the work, and
//! copies each result once into a new numpy array.
//!
//! Errors become `MeshtrimError` (a `ValueError`) with the message the CLI
//! prints after "error: ", in the library's parameter words; a panic, which
//! no input should cause, becomes one too rather than reaching the
//! interpreter.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

use library::{BpdOptions, Detection, Edge, EdgeOptions, Edges, Loop, Mesh, Point3, View};
use meshtrim::commands;
use meshtrim::io::edges_out::{self, step::LengthUnit, EdgeData, EdgeFileOptions, EdgesFormat};
use meshtrim::stages::Stages;
use numpy::ndarray::ArrayView2;
use numpy::{
    PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyList;

pyo3::create_exception!(
    meshtrim,
    MeshtrimError,
    PyValueError,
    "An input meshtrim cannot work on, with the message the CLI prints."
);

/// The options every function shares, as the CLI's flags give them.
struct Options {
    k: usize,
    anisotropy: bool,
    offset: bool,
    view_along: Option<[f64; 3]>,
    view_from: Option<[f64; 3]>,
}

impl Options {
    /// The library's options; the view is checked by detection itself.
    fn stages(&self) -> PyResult<Stages> {
        let view = match (self.view_along, self.view_from) {
            (Some(_), Some(_)) => {
                return Err(MeshtrimError::new_err(
                    "give view_along or view_from, not both",
                ))
            }
            (Some(d), None) => Some(View::Along(d)),
            (None, Some(o)) => Some(View::From(o)),
            (None, None) => None,
        };
        Ok(Stages {
            detection: BpdOptions {
                k: self.k,
                anisotropy: self.anisotropy,
                view,
            },
            edges: EdgeOptions {
                offset: self.offset,
            },
        })
    }
}

/// Runs `work` without the GIL, so that other Python threads run
/// meanwhile; its error or panic becomes a `MeshtrimError`.
fn without_gil<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> anyhow::Result<T> + Send,
) -> PyResult<T> {
    match py.detach(|| catch_unwind(AssertUnwindSafe(work))) {
        Ok(Ok(value)) => Ok(value),
        Ok(Err(error)) => Err(MeshtrimError::new_err(format!("{error:#}"))),
        Err(panic) => Err(MeshtrimError::new_err(format!(
            "internal error: {}",
            commands::panic_text(panic.as_ref())
        ))),
    }
}

/// The rows of an `(n, 3)` array (one copy).
fn rows<T: numpy::Element + Copy, const N: usize>(
    array: &PyReadonlyArray2<'_, T>,
    name: &str,
) -> PyResult<Vec<[T; N]>> {
    rows_or_message(array, name).map_err(MeshtrimError::new_err)
}

/// [`rows`], its error as the message alone.
fn rows_or_message<T: numpy::Element + Copy, const N: usize>(
    array: &PyReadonlyArray2<'_, T>,
    name: &str,
) -> Result<Vec<[T; N]>, String> {
    if array.shape()[1] != N {
        return Err(format!(
            "{name}: expected an array of shape (n, {N}), got {:?}",
            array.shape()
        ));
    }
    Ok(match array.as_slice() {
        Ok(flat) => flat
            .chunks_exact(N)
            .map(|r| std::array::from_fn(|k| r[k]))
            .collect(),
        Err(_) => strided_rows(array.as_array()),
    })
}

fn strided_rows<T: Copy, const N: usize>(view: ArrayView2<'_, T>) -> Vec<[T; N]> {
    view.rows()
        .into_iter()
        .map(|r| std::array::from_fn(|k| r[k]))
        .collect()
}

/// A mesh from its vertex and face arrays.
fn mesh_of(
    vertices: &PyReadonlyArray2<'_, f64>,
    faces: &PyReadonlyArray2<'_, u32>,
) -> PyResult<Mesh> {
    Ok(Mesh {
        vertices: rows(vertices, "vertices")?,
        faces: rows(faces, "faces")?,
    })
}

/// Points as a new `(n, 3)` float64 array.
fn points_array<'py>(py: Python<'py>, points: &[Point3]) -> PyResult<Points<'py>> {
    PyArray1::from_slice(py, points.as_flattened()).reshape([points.len(), 3])
}

/// Faces as a new `(m, 3)` int64 array (numpy's index type).
fn faces_array<'py>(py: Python<'py>, faces: &[[u32; 3]]) -> PyResult<Faces<'py>> {
    let flat: Vec<i64> = faces.as_flattened().iter().map(|&i| i64::from(i)).collect();
    PyArray1::from_vec(py, flat).reshape([faces.len(), 3])
}

/// A new `(n, 3)` float64 array.
type Points<'py> = Bound<'py, PyArray2<f64>>;
/// A new `(m, 3)` int64 array.
type Faces<'py> = Bound<'py, PyArray2<i64>>;
/// Boundary labels and β per point.
type Labels<'py> = (Bound<'py, PyArray1<bool>>, Bound<'py, PyArray1<f64>>);
/// A mesh result: its arrays and the report as JSON.
type MeshResult<'py> = (Points<'py>, Faces<'py>, String);

fn mesh_result<'py>(
    py: Python<'py>,
    mesh: &Mesh,
    report: &impl serde::Serialize,
) -> PyResult<MeshResult<'py>> {
    Ok((
        points_array(py, &mesh.vertices)?,
        faces_array(py, &mesh.faces)?,
        to_json(report)?,
    ))
}

fn labels<'py>(py: Python<'py>, detection: &Detection) -> Labels<'py> {
    (
        PyArray1::from_slice(py, &detection.boundary),
        PyArray1::from_slice(py, &detection.beta),
    )
}

fn to_json(value: &impl serde::Serialize) -> PyResult<String> {
    serde_json::to_string(value).map_err(|e| MeshtrimError::new_err(e.to_string()))
}

/// Boundary labels, β per point, and the summary as JSON.
#[pyfunction]
#[pyo3(name = "detect", signature = (points, k, anisotropy, view_along, view_from))]
fn detect_py<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    k: usize,
    anisotropy: bool,
    view_along: Option<[f64; 3]>,
    view_from: Option<[f64; 3]>,
) -> PyResult<(Labels<'py>, String)> {
    let options = Options {
        k,
        anisotropy,
        offset: true,
        view_along,
        view_from,
    };
    let detection_options = options.stages()?.detection;
    let points = rows(&points, "points")?;
    let (detection, summary) = without_gil(py, || {
        commands::detect::detect_in_memory(&points, &detection_options, false, "points")
    })?;
    Ok((labels(py, &detection), to_json(&summary)?))
}

/// One loop as a tuple: (closed, boundary point indices, corners, edges),
/// each edge (closed, points).
type LoopTuple<'py> = (
    bool,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray2<f64>>,
    Vec<(bool, Bound<'py, PyArray2<f64>>)>,
);

/// Labels, β, the loops and the summary as JSON.
#[pyfunction]
#[pyo3(name = "edges", signature = (points, k, anisotropy, offset, view_along, view_from))]
fn edges_py<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    k: usize,
    anisotropy: bool,
    offset: bool,
    view_along: Option<[f64; 3]>,
    view_from: Option<[f64; 3]>,
) -> PyResult<(Labels<'py>, Bound<'py, PyList>, String)> {
    let stages = Options {
        k,
        anisotropy,
        offset,
        view_along,
        view_from,
    }
    .stages()?;
    let points = rows(&points, "points")?;
    let (detection, found, summary) = without_gil(py, || {
        commands::edges::edges_in_memory(&points, &stages, false, "points")
    })?;
    Ok((
        labels(py, &detection),
        loops_list(py, &points, &found)?,
        to_json(&summary)?,
    ))
}

/// The loops of `edges` over `points` as the Python package's tuples:
/// (closed, boundary point indices, corner positions, [(closed, points)]).
fn loops_list<'py>(
    py: Python<'py>,
    points: &[Point3],
    edges: &Edges,
) -> PyResult<Bound<'py, PyList>> {
    let mut loops = Vec::with_capacity(edges.loops.len());
    for l in &edges.loops {
        let indices: Vec<i64> = l.boundary_points.iter().map(|&i| i64::from(i)).collect();
        let mut pieces = Vec::with_capacity(l.edges.len());
        for e in &l.edges {
            pieces.push((e.closed, points_array(py, &e.points)?));
        }
        let looped: LoopTuple = (
            true,
            PyArray1::from_vec(py, indices),
            points_array(py, &l.corner_points(points))?,
            pieces,
        );
        loops.push(looped);
    }
    PyList::new(py, loops)
}

/// The border of a mesh as the loops of `edges`: what `clean --edges`
/// writes of its output.
#[pyfunction]
#[pyo3(signature = (vertices, faces, k, anisotropy))]
fn border_edges<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, u32>,
    k: usize,
    anisotropy: bool,
) -> PyResult<Bound<'py, PyList>> {
    let stages = Options {
        k,
        anisotropy,
        offset: true,
        view_along: None,
        view_from: None,
    }
    .stages()?;
    let mesh = mesh_of(&vertices, &faces)?;
    let found = without_gil(py, || {
        commands::clean::border_curves(&mesh, &stages, "vertices")
    })?;
    loops_list(py, &mesh.vertices, &found)
}

/// The trimmed mesh and the report as JSON.
#[pyfunction]
#[pyo3(name = "trim", signature = (vertices, faces, points, k, anisotropy, offset, view_along, view_from))]
#[allow(clippy::too_many_arguments)] // the CLI's options, as keywords
fn trim_py<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, u32>,
    points: PyReadonlyArray2<'py, f64>,
    k: usize,
    anisotropy: bool,
    offset: bool,
    view_along: Option<[f64; 3]>,
    view_from: Option<[f64; 3]>,
) -> PyResult<MeshResult<'py>> {
    let settings = commands::trim::TrimSettings {
        stages: Options {
            k,
            anisotropy,
            offset,
            view_along,
            view_from,
        }
        .stages()?,
        progress: false,
        cloud: Default::default(),
        cloud_scale: None,
        measure: true,
    };
    let mesh = mesh_of(&vertices, &faces)?;
    let points = rows(&points, "points")?;
    let names = ["mesh".to_string(), "points".to_string()];
    let trimmed = without_gil(py, || {
        commands::trim::trim_in_memory(&mesh, &points, &settings, &names)
    })?;
    mesh_result(py, &trimmed.mesh, &trimmed.report)
}

/// The Delaunay mesh of a cloud and the report as JSON.
#[pyfunction]
#[pyo3(name = "mesh", signature = (points, k, anisotropy, offset, view_along, view_from))]
fn mesh_py<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    k: usize,
    anisotropy: bool,
    offset: bool,
    view_along: Option<[f64; 3]>,
    view_from: Option<[f64; 3]>,
) -> PyResult<MeshResult<'py>> {
    let stages = Options {
        k,
        anisotropy,
        offset,
        view_along,
        view_from,
    }
    .stages()?;
    let points = rows(&points, "points")?;
    let meshed = without_gil(py, || {
        commands::mesh::mesh_in_memory(&points, &stages, false, "points")
    })?;
    mesh_result(py, &meshed.mesh, &meshed.report)
}

/// The cleaned mesh and the report as JSON.
#[pyfunction]
#[pyo3(name = "clean", signature = (vertices, faces, k, anisotropy, offset, view_along, view_from, repair, max_deviation, fill_holes))]
#[allow(clippy::too_many_arguments)] // the CLI's options, as keywords
fn clean_py<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, u32>,
    k: usize,
    anisotropy: bool,
    offset: bool,
    view_along: Option<[f64; 3]>,
    view_from: Option<[f64; 3]>,
    repair: bool,
    max_deviation: Option<f64>,
    fill_holes: Option<f64>,
) -> PyResult<MeshResult<'py>> {
    for (name, value) in [("max_deviation", max_deviation), ("fill_holes", fill_holes)] {
        if let Some(d) = value.filter(|d| !(d.is_finite() && *d > 0.0)) {
            return Err(MeshtrimError::new_err(format!(
                "{name}: {d} is not a distance: give a number above zero, in the mesh's units"
            )));
        }
    }
    let choices = commands::clean::Choices {
        repair,
        max_deviation,
        fill_holes,
    };
    let stages = Options {
        k,
        anisotropy,
        offset,
        view_along,
        view_from,
    }
    .stages()?;
    let mesh = mesh_of(&vertices, &faces)?;
    let (out, report) = without_gil(py, || {
        commands::clean::clean_in_memory(&mesh, &stages, choices, "mesh")
    })?;
    mesh_result(py, &out, &report)
}

/// A cloud's points, normals and colours (RGBA in 0..1, and whether the
/// file had an alpha channel) and the file's own values, read as every command reads a cloud
/// (`scan`: one scan of an E57 file, as `--scan`).
#[pyfunction]
#[pyo3(signature = (path, scan=None))]
fn read_cloud(
    py: Python<'_>,
    path: PathBuf,
    scan: Option<usize>,
) -> PyResult<AttributedPoints<'_>> {
    let options = meshtrim::io::CloudOptions { scan };
    let cloud = without_gil(py, || meshtrim::io::read_cloud_with(&path, &options))?;
    let (normals, colours, alpha) =
        attribute_arrays(py, cloud.normals.as_deref(), cloud.colours.as_ref())?;
    let fields = field_arrays(py, &cloud.scalars);
    Ok((
        points_array(py, &cloud.points)?,
        normals,
        colours,
        alpha,
        fields,
    ))
}

/// A file's own per-vertex values: name, PLY type name and the values.
type FieldArrays<'py> = Vec<(String, &'static str, Bound<'py, PyArray1<f64>>)>;

/// The file's own values as new float64 arrays, with their names and
/// types.
fn field_arrays<'py>(py: Python<'py>, fields: &[meshtrim::io::ScalarField]) -> FieldArrays<'py> {
    fields
        .iter()
        .map(|f| {
            (
                f.name.clone(),
                f.kind.name(),
                PyArray1::from_slice(py, &f.values),
            )
        })
        .collect()
}

/// The file's own values from (name, PLY type name, values) triples.
fn fields_of(
    fields: Vec<(String, String, PyReadonlyArray1<'_, f64>)>,
) -> PyResult<Vec<meshtrim::io::ScalarField>> {
    fields
        .into_iter()
        .map(|(name, kind, values)| {
            let kind = meshtrim::io::ply::Scalar::parse(&kind).ok_or_else(|| {
                MeshtrimError::new_err(format!("scalars['{name}']: no PLY type '{kind}'"))
            })?;
            if name.is_empty() || name.contains(|c: char| c.is_whitespace()) {
                return Err(MeshtrimError::new_err(format!(
                    "scalars: the name '{name}' must be a word, without spaces"
                )));
            }
            Ok(meshtrim::io::ScalarField {
                name,
                kind,
                values: values.as_array().to_vec(),
            })
        })
        .collect()
}

/// A new `(n, 4)` float64 array of colours, RGBA in 0..1.
type ColourArray<'py> = Bound<'py, PyArray2<f64>>;
/// Normals, colours and whether the file had an alpha channel.
type AttributeArrays<'py> = (Option<Points<'py>>, Option<ColourArray<'py>>, bool);
/// Points or vertices with their normals, colours (RGBA in 0..1) and
/// whether the file had an alpha channel.
type AttributedPoints<'py> = (
    Points<'py>,
    Option<Points<'py>>,
    Option<ColourArray<'py>>,
    bool,
    FieldArrays<'py>,
);

/// Normals and colours as new arrays, and whether the colours had alpha.
fn attribute_arrays<'py>(
    py: Python<'py>,
    normals: Option<&[Point3]>,
    colours: Option<&meshtrim::io::Colours>,
) -> PyResult<AttributeArrays<'py>> {
    let normals = normals.map(|n| points_array(py, n)).transpose()?;
    let (colours, alpha) = match colours {
        Some(c) => {
            let flat = PyArray1::from_slice(py, c.rgba.as_flattened());
            (Some(flat.reshape([c.rgba.len(), 4])?), c.alpha)
        }
        None => (None, false),
    };
    Ok((normals, colours, alpha))
}

/// A mesh as read: vertices, faces, normals, colours (RGBA in 0..1),
/// whether the file had an alpha channel, and the file's own values.
type MeshRead<'py> = (
    Points<'py>,
    Faces<'py>,
    Option<Points<'py>>,
    Option<ColourArray<'py>>,
    bool,
    FieldArrays<'py>,
    Option<Bound<'py, PyArray2<f64>>>,
    Option<MaterialOut<'py>>,
);

/// A mesh's materials as read: an OBJ's libraries' paths, the names and
/// each face's index into the names; another format's as an object.
#[derive(IntoPyObject)]
enum MaterialOut<'py> {
    Obj(Vec<PathBuf>, Vec<String>, Bound<'py, PyArray1<u32>>),
    File(FileMaterials),
}

/// A material as `write_mesh` takes it: an OBJ's (libraries, names,
/// faces), or another format's as `read_mesh` gave it.
#[derive(FromPyObject)]
enum MaterialIn<'py> {
    File(PyRef<'py, FileMaterials>),
    Obj(Vec<PathBuf>, Vec<String>, PyReadonlyArray1<'py, u32>),
}

impl MaterialIn<'_> {
    /// The number of faces it gives a material.
    fn face_count(&self) -> usize {
        match self {
            MaterialIn::File(m) => m.materials.face_count(),
            MaterialIn::Obj(_, _, faces) => faces.len(),
        }
    }

    fn into_materials(self) -> meshtrim::io::Materials {
        match self {
            MaterialIn::File(m) => m.materials.clone(),
            MaterialIn::Obj(libraries, names, faces) => {
                meshtrim::io::Materials::Obj(meshtrim::io::ObjMaterial {
                    libraries,
                    names,
                    faces: faces.as_array().to_vec(),
                })
            }
        }
    }
}

/// A glTF file's materials (with their images) or a PLY file's texture
/// images, as read with its mesh: carried and written by
/// `write_mesh_carrying` and `write_mesh` as the CLI writes them.
#[pyclass(frozen, module = "meshtrim._meshtrim")]
struct FileMaterials {
    materials: meshtrim::io::Materials,
}

#[pymethods]
impl FileMaterials {
    /// "gltf" or "ply".
    #[getter]
    fn kind(&self) -> &'static str {
        match self.materials {
            meshtrim::io::Materials::Gltf(_) => "gltf",
            _ => "ply",
        }
    }

    /// The materials' names (glTF's, `material_<i>` where none is given),
    /// or the texture images' paths (PLY).
    #[getter]
    fn names(&self) -> Vec<String> {
        self.materials.names()
    }

    /// Each face's material, an index into `names` (glTF's faces without
    /// a material 4294967295).
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        PyArray1::from_slice(py, self.materials.faces())
    }

    /// The same materials with `faces` as each face's.
    fn with_faces(&self, faces: PyReadonlyArray1<'_, u32>) -> FileMaterials {
        let mut materials = self.materials.clone();
        materials.set_faces(faces.as_array().to_vec());
        FileMaterials { materials }
    }

    fn __repr__(&self) -> String {
        format!(
            "FileMaterials(kind={:?}, names={:?}, faces=<{} faces>)",
            self.kind(),
            self.names(),
            self.materials.face_count()
        )
    }
}

/// A mesh's vertices, faces and vertex attributes, read as `trim` and
/// `clean` read a mesh.
#[pyfunction]
fn read_mesh(py: Python<'_>, path: PathBuf) -> PyResult<MeshRead<'_>> {
    let hint = "read it with read_cloud";
    let (mesh, attributes) =
        without_gil(py, || meshtrim::io::read_mesh_with_attributes(&path, hint))?;
    let (normals, colours, alpha) = attribute_arrays(
        py,
        attributes.normals.as_deref(),
        attributes.colours.as_ref(),
    )?;
    let texcoords = attributes
        .texcoords
        .as_ref()
        .map(|t| PyArray1::from_slice(py, t.as_flattened()).reshape([t.len(), 2]))
        .transpose()?;
    // An OBJ's materials as arrays and names; another format's as an
    // object the writers take back.
    let material = match attributes.materials {
        Some(meshtrim::io::Materials::Obj(m)) => {
            let faces = PyArray1::from_vec(py, m.faces);
            Some(MaterialOut::Obj(m.libraries, m.names, faces))
        }
        Some(materials) => Some(MaterialOut::File(FileMaterials { materials })),
        None => None,
    };
    Ok((
        points_array(py, &mesh.vertices)?,
        faces_array(py, &mesh.faces)?,
        normals,
        colours,
        alpha,
        field_arrays(py, &attributes.scalars),
        texcoords,
        material,
    ))
}

/// Writes a mesh as the CLI writes its outputs (format by extension,
/// atomically), with per-vertex normals, colours (RGB or RGBA in 0..1)
/// and values of the file's own (name, PLY type name, values) when given.
#[pyfunction]
#[pyo3(signature = (path, vertices, faces, normals, colours, scalars, texcoords, material))]
#[allow(clippy::too_many_arguments)]
fn write_mesh(
    py: Python<'_>,
    path: PathBuf,
    vertices: PyReadonlyArray2<'_, f64>,
    faces: PyReadonlyArray2<'_, u32>,
    normals: Option<PyReadonlyArray2<'_, f64>>,
    colours: Option<PyReadonlyArray2<'_, f64>>,
    scalars: Vec<(String, String, PyReadonlyArray1<'_, f64>)>,
    texcoords: Option<PyReadonlyArray2<'_, f64>>,
    material: Option<MaterialIn<'_>>,
) -> PyResult<()> {
    let mesh = mesh_of(&vertices, &faces)?;
    let attributes = attributes_of(normals, colours, scalars, texcoords, material)?;
    without_gil(py, || {
        meshtrim::io::write_mesh_with(&path, &mesh.vertices, &mesh.faces, &attributes)
    })
}

/// Writes the mesh `vertices`, `faces`, made from `from_vertices`,
/// `from_faces` (whose vertices carry `normals`, `colours` and `scalars`),
/// as the CLI writes its outputs: the attributes the format holds carried
/// to it. The names of those written and of those not written.
#[pyfunction]
#[pyo3(signature = (path, vertices, faces, from_vertices, from_faces, normals, colours, scalars, texcoords, material))]
#[allow(clippy::too_many_arguments)]
fn write_mesh_carrying(
    py: Python<'_>,
    path: PathBuf,
    vertices: PyReadonlyArray2<'_, f64>,
    faces: PyReadonlyArray2<'_, u32>,
    from_vertices: PyReadonlyArray2<'_, f64>,
    from_faces: PyReadonlyArray2<'_, u32>,
    normals: Option<PyReadonlyArray2<'_, f64>>,
    colours: Option<PyReadonlyArray2<'_, f64>>,
    scalars: Vec<(String, String, PyReadonlyArray1<'_, f64>)>,
    texcoords: Option<PyReadonlyArray2<'_, f64>>,
    material: Option<MaterialIn<'_>>,
) -> PyResult<(Vec<String>, Vec<String>)> {
    let out = mesh_of(&vertices, &faces)?;
    let from = mesh_of(&from_vertices, &from_faces)?;
    if let Some(material) = &material {
        if material.face_count() != from.faces.len() {
            return Err(MeshtrimError::new_err(format!(
                "material: {} face materials for {} source faces",
                material.face_count(),
                from.faces.len()
            )));
        }
    }
    let attributes = attributes_of(normals, colours, scalars, texcoords, material)?;
    let written = without_gil(py, || {
        meshtrim::io::mesh_out::write_mesh_carrying(&path, &out, &from, attributes)
    })?;
    Ok((written.written, written.not_written))
}

/// The attributes `write_mesh` and `write_mesh_carrying` take, checked.
fn attributes_of(
    normals: Option<PyReadonlyArray2<'_, f64>>,
    colours: Option<PyReadonlyArray2<'_, f64>>,
    scalars: Vec<(String, String, PyReadonlyArray1<'_, f64>)>,
    texcoords: Option<PyReadonlyArray2<'_, f64>>,
    material: Option<MaterialIn<'_>>,
) -> PyResult<meshtrim::io::VertexAttributes> {
    let materials = material.map(MaterialIn::into_materials);
    Ok(meshtrim::io::VertexAttributes {
        normals: normals.map(|n| rows(&n, "normals")).transpose()?,
        colours: colours.map(|c| colours_of(&c)).transpose()?,
        scalars: fields_of(scalars)?,
        texcoords: texcoords.map(|t| rows(&t, "texcoords")).transpose()?,
        materials,
    })
}

/// Colours from an `(n, 3)` or `(n, 4)` array in 0..1 (alpha 1 when
/// there are three columns).
fn colours_of(array: &PyReadonlyArray2<'_, f64>) -> PyResult<meshtrim::io::Colours> {
    let width = array.shape()[1];
    if width != 3 && width != 4 {
        return Err(MeshtrimError::new_err(format!(
            "colours: expected an array of shape (n, 3) or (n, 4), got {:?}",
            array.shape()
        )));
    }
    let rgba = array
        .as_array()
        .rows()
        .into_iter()
        .map(|r| std::array::from_fn(|c| if c < width { r[c] } else { 1.0 }))
        .collect();
    Ok(meshtrim::io::Colours {
        rgba,
        alpha: width == 4,
    })
}

/// Per-vertex `values` (`(n, k)`, one row per vertex of the mesh
/// `vertices`, `faces`) carried to the vertices `to` of a mesh made from
/// it (`to_faces`, which tell a seam's sides apart), as the CLI carries
/// normals and colours: a kept vertex's row copied, a new one's blended
/// from its closest point on the surface (or taken from the nearest point
/// when there are no faces). With `normals` (`k` = 3) the rows are
/// blended as normals (direction and length); with `nearest` (labels,
/// flags) not blended but taken from the corner of the largest weight.
#[pyfunction]
#[pyo3(signature = (vertices, faces, values, to, to_faces, normals, nearest))]
#[allow(clippy::too_many_arguments)]
fn carry<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, u32>,
    values: PyReadonlyArray2<'py, f64>,
    to: PyReadonlyArray2<'py, f64>,
    to_faces: PyReadonlyArray2<'py, u32>,
    normals: bool,
    nearest: bool,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (from, to) = mesh_pair(&vertices, &faces, &to, &to_faces)?;
    let table = Table::new(&values, normals, nearest, from.vertices.len())?;
    let carried = without_gil(py, || {
        let Some(sources) = library::vertex_sources(&from, &to) else {
            anyhow::bail!("vertices: there are none to carry values from");
        };
        Ok(table.carried(&from, &sources))
    })?;
    table.array(py, carried, to.vertices.len())
}

/// Per-vertex values to carry, by columns, and how: blended, as normals,
/// or from the nearest corner.
struct Table {
    columns: Vec<Vec<f64>>,
    normals: bool,
    nearest: bool,
}

impl Table {
    /// `values`, one row per vertex of a mesh of `vertices` vertices,
    /// checked (three columns for normals).
    fn new(
        values: &PyReadonlyArray2<'_, f64>,
        normals: bool,
        nearest: bool,
        vertices: usize,
    ) -> PyResult<Table> {
        let [rows_in, width] = [values.shape()[0], values.shape()[1]];
        if rows_in != vertices {
            return Err(MeshtrimError::new_err(format!(
                "values: {rows_in} rows for {vertices} vertices"
            )));
        }
        if normals && width != 3 {
            return Err(MeshtrimError::new_err(format!(
                "values: normals have 3 columns, these have {width}"
            )));
        }
        let columns = (0..width)
            .map(|c| values.as_array().column(c).to_vec())
            .collect();
        Ok(Table {
            columns,
            normals,
            nearest,
        })
    }

    /// The values at `sources` in `from`, row after row.
    fn carried(&self, from: &Mesh, sources: &[library::VertexSource]) -> Vec<f64> {
        if self.normals {
            let rows: Vec<Point3> = (0..from.vertices.len())
                .map(|i| [0, 1, 2].map(|c| self.columns[c][i]))
                .collect();
            return library::carry_normals(from, sources, &rows)
                .as_flattened()
                .to_vec();
        }
        let carried: Vec<Vec<f64>> = self
            .columns
            .iter()
            .map(|column| match self.nearest {
                true => library::carry_nearest_corner(from, sources, column),
                false => library::carry_values(from, sources, column),
            })
            .collect();
        (0..sources.len())
            .flat_map(|i| carried.iter().map(move |column| column[i]))
            .collect()
    }

    /// `rows` carried rows as an `(rows, k)` array.
    fn array<'py>(
        &self,
        py: Python<'py>,
        carried: Vec<f64>,
        rows: usize,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        PyArray1::from_vec(py, carried).reshape([rows, self.columns.len()])
    }
}

/// Checks that each named mesh's faces name its vertices.
fn check_faces<const N: usize>(meshes: [(&str, &Mesh); N]) -> PyResult<()> {
    for (name, mesh) in meshes {
        let count = mesh.vertices.len();
        if let Some(&v) = mesh.faces.iter().flatten().find(|&&v| v as usize >= count) {
            return Err(MeshtrimError::new_err(format!(
                "{name}: vertex {v} does not exist ({count} vertices)"
            )));
        }
    }
    Ok(())
}

/// The meshes `from` (`vertices`, `faces`) and `to` (`to`, `to_faces`),
/// their faces checked.
fn mesh_pair(
    vertices: &PyReadonlyArray2<'_, f64>,
    faces: &PyReadonlyArray2<'_, u32>,
    to: &PyReadonlyArray2<'_, f64>,
    to_faces: &PyReadonlyArray2<'_, u32>,
) -> PyResult<(Mesh, Mesh)> {
    let from = mesh_of(vertices, faces)?;
    let to = Mesh {
        vertices: rows(to, "to")?,
        faces: rows(to_faces, "to_faces")?,
    };
    check_faces([("faces", &from), ("to_faces", &to)])?;
    Ok((from, to))
}

/// The mesh `to`, `to_faces` made from `vertices`, `faces`, with its
/// vertices split where the input's are along a seam, as the CLI writes
/// its outputs (the copies after its vertices; the same mesh when none
/// is), each of `tables` (per-vertex values: `(values, normals,
/// nearest)` as `carry` takes them) carried to it, and for each of its
/// faces the input face it lies on (−1 for none), all by the sources the
/// CLI carries its attributes by.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn split_seams<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, u32>,
    to: PyReadonlyArray2<'py, f64>,
    to_faces: PyReadonlyArray2<'py, u32>,
    tables: Vec<(PyReadonlyArray2<'py, f64>, bool, bool)>,
) -> PyResult<(
    Points<'py>,
    Faces<'py>,
    Vec<Bound<'py, PyArray2<f64>>>,
    Bound<'py, PyArray1<i64>>,
)> {
    let (from, to) = mesh_pair(&vertices, &faces, &to, &to_faces)?;
    let tables = tables
        .iter()
        .map(|(values, normals, nearest)| {
            Table::new(values, *normals, *nearest, from.vertices.len())
        })
        .collect::<PyResult<Vec<_>>>()?;
    let (split, carried, face_sources) = without_gil(py, || {
        let Some(split) = library::split_sources(&from, &to) else {
            anyhow::bail!("vertices: there are none to take seams from");
        };
        let mesh = split.split_mesh(&to).unwrap_or(to);
        let carried: Vec<Vec<f64>> = tables
            .iter()
            .map(|table| table.carried(&from, &split.sources))
            .collect();
        let face_sources = match from.faces.is_empty() {
            true => vec![None; mesh.faces.len()],
            false => library::face_sources(&from, &mesh, &split.sources),
        };
        Ok((mesh, carried, face_sources))
    })?;
    let arrays = tables
        .iter()
        .zip(carried)
        .map(|(table, carried)| table.array(py, carried, split.vertices.len()))
        .collect::<PyResult<Vec<_>>>()?;
    Ok((
        points_array(py, &split.vertices)?,
        faces_array(py, &split.faces)?,
        arrays,
        face_index_array(py, face_sources),
    ))
}

/// For each face of `to`, `to_faces` (made from `vertices`, `faces`), the
/// input face it lies on (`library::face_sources`), −1 for none.
#[pyfunction]
fn face_sources<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, u32>,
    to: PyReadonlyArray2<'py, f64>,
    to_faces: PyReadonlyArray2<'py, u32>,
) -> PyResult<Bound<'py, PyArray1<i64>>> {
    let (from, to) = mesh_pair(&vertices, &faces, &to, &to_faces)?;
    if from.faces.is_empty() {
        return Err(MeshtrimError::new_err(
            "faces: there are none to take values from",
        ));
    }
    let sources = without_gil(py, || {
        let Some(sources) = library::vertex_sources(&from, &to) else {
            anyhow::bail!("vertices: there are none to take values from");
        };
        Ok(library::face_sources(&from, &to, &sources))
    })?;
    Ok(face_index_array(py, sources))
}

/// How far the vertices of `vertices`, `faces` lie from the surface
/// `surface`, `surface_faces` (`library::surface_deviation`), as the
/// JSON `clean`'s report gives.
#[pyfunction]
fn deviation<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, u32>,
    surface: PyReadonlyArray2<'py, f64>,
    surface_faces: PyReadonlyArray2<'py, u32>,
) -> PyResult<String> {
    let (mesh, surface) = mesh_pair(&vertices, &faces, &surface, &surface_faces)?;
    for (name, m) in [("vertices", &mesh), ("surface_vertices", &surface)] {
        if let Some(v) = m
            .vertices
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(MeshtrimError::new_err(format!(
                "{name}: vertex {v} has a coordinate that is not finite"
            )));
        }
    }
    let measured = without_gil(py, || Ok(library::surface_deviation(&surface, &mesh)))?;
    to_json(&commands::clean::Deviation::from(measured))
}

/// Face indices as an array, −1 for none.
fn face_index_array(py: Python<'_>, faces: Vec<Option<u32>>) -> Bound<'_, PyArray1<i64>> {
    let indices = faces.into_iter().map(|f| f.map_or(-1, i64::from)).collect();
    PyArray1::from_vec(py, indices)
}

/// The batch's list of work, as `meshtrim batch INPUTS --out-dir OUT_DIR
/// [--cloud-dir CLOUD_DIR] [--to EXT]` makes it before processing anything: per mesh
/// (sorted by path), its output and the clouds paired with it (none:
/// cleaned; one: trimmed with it; several: the batch fails that mesh).
#[pyfunction]
#[pyo3(signature = (inputs, out_dir, cloud_dir=None, to=None, edges_to=None))]
fn batch_plan(
    py: Python<'_>,
    inputs: Vec<PathBuf>,
    out_dir: PathBuf,
    cloud_dir: Option<PathBuf>,
    to: Option<String>,
    edges_to: Option<String>,
) -> PyResult<Vec<PlannedJob>> {
    let jobs = without_gil(py, || {
        commands::batch::plan(&commands::batch::Inputs {
            args: &inputs,
            out_dir: &out_dir,
            cloud_dir: cloud_dir.as_deref(),
            report: None,
            to: to.as_deref(),
            edges_to: edges_to.as_deref(),
        })
    })?;
    Ok(jobs
        .into_iter()
        .map(|job| {
            let clouds = match job.cloud {
                commands::batch::CloudMatch::None => Vec::new(),
                commands::batch::CloudMatch::One(cloud) => vec![cloud],
                commands::batch::CloudMatch::Several(clouds) => clouds,
            };
            (job.input, job.output, clouds, job.edges)
        })
        .collect())
}

/// One job of [`batch_plan`]: input, output, clouds, edges file.
type PlannedJob = (PathBuf, PathBuf, Vec<PathBuf>, Option<PathBuf>);

/// A loop as Python passes it back: boundary point indices, corner
/// positions, edges (closed, points).
type LoopIn<'py> = (
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray2<'py, f64>,
    Vec<(bool, PyReadonlyArray2<'py, f64>)>,
);

/// Writes loops to an edges file as `meshtrim edges -o` does (format by
/// extension, atomically). `boundary` marks the SVG's boundary points.
#[pyfunction]
#[pyo3(name = "write_edges", signature = (path, points, boundary, loops, units, dxf_splines))]
fn write_edges_py(
    py: Python<'_>,
    path: PathBuf,
    points: PyReadonlyArray2<'_, f64>,
    boundary: PyReadonlyArray1<'_, bool>,
    loops: Vec<LoopIn<'_>>,
    units: &str,
    dxf_splines: bool,
) -> PyResult<()> {
    let points = rows(&points, "points")?;
    let boundary = boundary.as_array().to_vec();
    if boundary.len() != points.len() {
        return Err(MeshtrimError::new_err(format!(
            "boundary: {} labels for {} points",
            boundary.len(),
            points.len()
        )));
    }
    let units = LengthUnit::from_name(units).ok_or_else(|| {
        MeshtrimError::new_err(format!(
            "units: {units:?} is not a length unit: mm, m or in"
        ))
    })?;
    if dxf_splines && EdgesFormat::from_path(&path) != Some(EdgesFormat::Dxf) {
        return Err(MeshtrimError::new_err(format!(
            "{}: dxf_splines writes splines into a .dxf file, and this is not one",
            path.display()
        )));
    }
    let edges = Edges {
        loops: loops
            .iter()
            .enumerate()
            .map(|(i, l)| loop_of(&points, l).map_err(|e| format!("edges[{i}].{e}")))
            .collect::<Result<_, _>>()
            .map_err(MeshtrimError::new_err)?,
        ..Edges::default()
    };
    let data = EdgeData {
        points: &points,
        boundary: &boundary,
        edges: &edges,
        options: EdgeFileOptions { units, dxf_splines },
    };
    without_gil(py, || edges_out::write_file(&path, data))
}

/// A library loop from its Python parts: the indices checked against the
/// cloud, each corner found among the loop's boundary points (in order),
/// the edge points finite. Errors name the part.
fn loop_of(points: &[Point3], (indices, corners, edges): &LoopIn<'_>) -> Result<Loop, String> {
    let mut boundary_points = Vec::with_capacity(indices.len());
    for (j, &i) in indices.as_array().iter().enumerate() {
        match u32::try_from(i) {
            Ok(index) if (index as usize) < points.len() => boundary_points.push(index),
            _ => {
                return Err(format!(
                    "boundary_points[{j}]: {i} is not a point of the cloud ({} points)",
                    points.len()
                ))
            }
        }
    }
    let corner_points = rows_or_message(corners, "corners")?;
    let mut positions = Vec::with_capacity(corner_points.len());
    let mut from = 0;
    for (c, corner) in corner_points.iter().enumerate() {
        let at = (from..boundary_points.len())
            .find(|&j| points[boundary_points[j] as usize] == *corner)
            .ok_or_else(|| format!("corners[{c}]: not one of the loop's boundary points (after the previous corner)"))?;
        positions.push(at);
        from = at + 1;
    }
    let mut pieces = Vec::with_capacity(edges.len());
    for (e, (closed, array)) in edges.iter().enumerate() {
        let points = rows_or_message(array, "points").map_err(|err| format!("edges[{e}].{err}"))?;
        if points.iter().flatten().any(|c| !c.is_finite()) {
            return Err(format!("edges[{e}].points: a coordinate is not finite"));
        }
        pieces.push(Edge {
            closed: *closed,
            points,
        });
    }
    Ok(Loop {
        boundary_points,
        corners: positions,
        edges: pieces,
        sides: Vec::new(),
    })
}

#[pymodule]
fn _meshtrim(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("MeshtrimError", m.py().get_type::<MeshtrimError>())?;
    m.add_function(wrap_pyfunction!(detect_py, m)?)?;
    m.add_function(wrap_pyfunction!(edges_py, m)?)?;
    m.add_function(wrap_pyfunction!(border_edges, m)?)?;
    m.add_function(wrap_pyfunction!(trim_py, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_py, m)?)?;
    m.add_function(wrap_pyfunction!(clean_py, m)?)?;
    m.add_function(wrap_pyfunction!(read_cloud, m)?)?;
    m.add_function(wrap_pyfunction!(read_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(write_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(write_mesh_carrying, m)?)?;
    m.add_function(wrap_pyfunction!(write_edges_py, m)?)?;
    m.add_function(wrap_pyfunction!(batch_plan, m)?)?;
    m.add_function(wrap_pyfunction!(carry, m)?)?;
    m.add_class::<FileMaterials>()?;
    m.add_function(wrap_pyfunction!(split_seams, m)?)?;
    m.add_function(wrap_pyfunction!(face_sources, m)?)?;
    m.add_function(wrap_pyfunction!(deviation, m)?)?;
    Ok(())
}
