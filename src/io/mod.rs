//! Reading point clouds and meshes, writing results.
//!
//! [`read_cloud`] picks the reader from the file's content when the content
//! is unambiguous (a PLY or PCD header, OBJ `v` lines) and from its
//! extension otherwise, so a PLY file named `.txt` still reads as PLY.
//! Files named `.stl`, `.glb` or `.gltf` follow the mesh reader's rules
//! ([`MeshInput`]) instead: an STL header is free text and proves nothing.
//!
//! Every error names the file, then where in it (a line for text, an
//! element index for binary data) and what is wrong. Readers never panic on
//! bad input.
//!
//! NaN policy: PCD readers drop points with a non-finite coordinate and count
//! them, because organised PCD clouds mark empty pixels with NaN. In every
//! other format a non-finite coordinate is an error.

pub mod atomic;
mod corners;
pub mod e57;
pub mod edges_out;
pub mod f32_rounding;
pub(crate) mod float_text;
pub mod gltf_io;
pub mod gltf_materials;
mod hash;
pub mod labels;
pub mod las;
pub mod mesh_out;
pub mod obj;
mod obj_material;
pub mod pcd;
pub mod ply;
pub mod simple_material;
pub mod stl;
pub mod text;
mod text_lines;

pub(crate) use text_lines::{
    capacity, cut_after_newlines, is_ascii_space, lines, mixed_line_ending, next_line, show,
    strip_bom, text_of, truncated, words, write_formatted, HeaderEol, PIECE_BYTES,
};

pub use mesh_out::{write_mesh, write_mesh_with, MeshFormat};

use std::path::Path;

use anyhow::{bail, Context, Result};

/// A point in 3D, in the file's own units.
pub type Point3 = [f64; 3];

/// A triangle's normal times twice its area: the cross product of its
/// sides from the first corner.
pub(crate) fn doubled_area([a, b, c]: [Point3; 3]) -> Point3 {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

/// The file formats meshtrim reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Stanford PLY, ASCII or binary.
    Ply,
    /// Point Cloud Library PCD, ASCII, binary or binary_compressed.
    Pcd,
    /// Wavefront OBJ (`v` and `f` lines).
    Obj,
    /// ASPRS LAS 1.0–1.4, or LAZ (its compressed form).
    Las,
    /// ASTM E57 (one or several scans with their poses).
    E57,
    /// One point per line, the first three columns being x, y and z.
    Text,
    /// A mesh format that only meshes use (STL, glTF, GLB): its vertices
    /// are the cloud (a triangulated scan's own samples).
    MeshVertices,
}

impl Format {
    /// Lower-case name, as used in messages.
    pub fn name(self) -> &'static str {
        match self {
            Format::Ply => "ply",
            Format::Pcd => "pcd",
            Format::Obj => "obj",
            Format::Las => "las",
            Format::E57 => "e57",
            Format::Text => "text",
            Format::MeshVertices => "mesh vertices (stl, gltf, glb)",
        }
    }

    /// The format an extension names, if any (any case).
    pub(crate) fn from_extension(ext: &str) -> Option<Format> {
        match ext.to_ascii_lowercase().as_str() {
            "ply" => Some(Format::Ply),
            "pcd" => Some(Format::Pcd),
            "obj" => Some(Format::Obj),
            "las" | "laz" => Some(Format::Las),
            "e57" => Some(Format::E57),
            "xyz" | "txt" | "csv" | "asc" | "pts" => Some(Format::Text),
            _ => None,
        }
    }
}

/// A point cloud as read from a file, in file order.
#[derive(Debug, Clone, PartialEq)]
pub struct Cloud {
    /// The points, all finite.
    pub points: Vec<Point3>,
    /// Per-point normals, when the file has them (PLY nx/ny/nz, PCD
    /// normal_x/normal_y/normal_z).
    pub normals: Option<Vec<Point3>>,
    /// Per-point colours, when the file has them (PLY, OBJ and glTF
    /// vertex colours, E57 and LAS colour, PCD's packed `rgb`/`rgba`).
    pub colours: Option<Colours>,
    /// The file's own per-point values: PLY's other vertex properties,
    /// LAS intensity and classification, E57 intensity, PCD's other
    /// fields.
    pub scalars: Vec<ScalarField>,
    /// Points dropped by the reader: a NaN or infinite coordinate (PCD), or
    /// no position (E57's invalid states).
    pub dropped_non_finite: usize,
    /// The integer grid of a LAS or LAZ file's coordinates, kept so that
    /// labels written as LAS use the same one.
    pub scale_offset: Option<las::ScaleOffset>,
    /// The format the file was read as.
    pub format: Format,
    /// Each point's place in its scanner's image (E57 `rowIndex` and
    /// `columnIndex`), when a scan read has them.
    pub grid: Option<Vec<GridIndex>>,
}

/// A point's place in a scanner's image grid: the scan (its `data3D`
/// index), row and column; −1 where the scan has no such index.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GridIndex {
    /// The `data3D` index of the point's scan.
    pub scan: u32,
    /// Row index, or −1.
    pub row: i32,
    /// Column index, or −1.
    pub column: i32,
}

/// A mesh as read from a file: vertices in file order, faces triangulated.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// The vertices, all finite.
    pub vertices: Vec<Point3>,
    /// Per-vertex normals, when the file has them.
    pub normals: Option<Vec<Point3>>,
    /// Per-vertex colours, when the file has them.
    pub colours: Option<Colours>,
    /// The file's own per-vertex values ([`ScalarField`]).
    pub scalars: Vec<ScalarField>,
    /// Per-vertex texture coordinates (u, v), v upwards as OBJ stores it.
    pub texcoords: Option<Vec<[f64; 2]>>,
    /// The faces' materials, in the file's own kind ([`Materials`]).
    pub materials: Option<Materials>,
    /// Triangles as vertex indices, polygons split into fans; `None` when
    /// the file has no face element or `f` lines at all.
    pub faces: Option<Vec<[u32; 3]>>,
}

/// An OBJ's materials: where they are defined, their names, and which
/// each face uses (the texture coordinates index into its images).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ObjMaterial {
    /// The material libraries (`mtllib`), as paths from the current
    /// directory.
    pub libraries: Vec<std::path::PathBuf>,
    /// The materials' names (`usemtl`), in the order first used.
    pub names: Vec<String>,
    /// Each face's material, an index into `names`.
    pub faces: Vec<u32>,
}

/// The faces' materials, each format's own kind, each with a material
/// per face; written as they are to a file of their format, and made
/// [`simple_material::SimpleMaterials`] for another.
#[derive(Debug, Clone, PartialEq)]
pub enum Materials {
    /// An OBJ's `mtllib` and `usemtl`.
    Obj(ObjMaterial),
    /// A glTF's materials, textures, samplers and images.
    Gltf(gltf_materials::GltfMaterials),
    /// A PLY's texture images (MeshLab's `comment TextureFile`).
    Ply(ply::PlyTextures),
    /// Another format's materials, made what every format holds, for an
    /// output of another format than the input's.
    Simple(simple_material::SimpleMaterials),
}

impl Materials {
    /// Each face's material.
    fn faces_mut(&mut self) -> &mut Vec<u32> {
        match self {
            Materials::Obj(m) => &mut m.faces,
            Materials::Gltf(m) => &mut m.faces,
            Materials::Ply(m) => &mut m.faces,
            Materials::Simple(m) => &mut m.faces,
        }
    }

    /// Each face's material.
    pub fn faces(&self) -> &[u32] {
        match self {
            Materials::Obj(m) => &m.faces,
            Materials::Gltf(m) => &m.faces,
            Materials::Ply(m) => &m.faces,
            Materials::Simple(m) => &m.faces,
        }
    }

    /// The number of faces given a material.
    pub fn face_count(&self) -> usize {
        self.faces().len()
    }

    /// Gives the faces `faces` as their materials.
    pub fn set_faces(&mut self, faces: Vec<u32>) {
        *self.faces_mut() = faces;
    }

    /// The materials' names: an OBJ's `usemtl` names, a glTF's material
    /// names (`material_<i>` where one has none), a PLY's texture images'
    /// paths, the simple materials' names.
    pub fn names(&self) -> Vec<String> {
        match self {
            Materials::Obj(m) => m.names.clone(),
            Materials::Gltf(m) => (m.materials.iter().enumerate())
                .map(|(i, json)| match json["name"].as_str() {
                    Some(name) => name.to_string(),
                    None => format!("material_{i}"),
                })
                .collect(),
            Materials::Ply(m) => m.files.iter().map(|f| f.display().to_string()).collect(),
            Materials::Simple(m) => m.materials.iter().map(|m| m.name.clone()).collect(),
        }
    }

    /// Checks there is a material per face (of `faces`), each one of
    /// those given (a PLY's texture number may name none: it reads the
    /// first; a glTF face may have none).
    pub fn check(&self, faces: usize) -> anyhow::Result<()> {
        let face_materials = self.faces();
        let count = match self {
            Materials::Obj(m) => m.names.len(),
            Materials::Gltf(m) => m.materials.len(),
            Materials::Ply(_) => usize::MAX,
            Materials::Simple(m) => m.materials.len(),
        };
        if face_materials.len() != faces {
            anyhow::bail!("{} face materials for {faces} faces", face_materials.len());
        }
        let none = self.none();
        let named = |m: u32| (m as usize) < count || (m == none && self.none_allowed());
        if let Some(f) = face_materials.iter().position(|&m| !named(m)) {
            anyhow::bail!(
                "face {f}'s material is {}, but there are only {count} materials",
                face_materials[f]
            );
        }
        Ok(())
    }

    /// Whether a face may have no material.
    fn none_allowed(&self) -> bool {
        matches!(self, Materials::Gltf(_))
    }

    /// The material of a face on no input face.
    fn none(&self) -> u32 {
        match self {
            Materials::Gltf(_) => gltf_materials::NO_MATERIAL,
            Materials::Obj(_) | Materials::Ply(_) | Materials::Simple(_) => 0,
        }
    }

    /// The materials of `to`'s faces, made from `from` (whose faces these
    /// are), its vertices' `sources` in `from`: each face takes the
    /// material of the input face it lies on ([`trim::face_sources`]).
    pub fn carried(
        &self,
        from: &trim::Mesh,
        to: &trim::Mesh,
        sources: &[trim::VertexSource],
    ) -> Materials {
        let mut out = self.clone();
        let faces = out.faces_mut();
        *faces = carried_face_values(faces, from, to, sources, self.none());
        out
    }
}

/// Per-face values of `from` at the faces of `to`, made from it (its
/// vertices' `sources` in `from`): each face the value of the input face
/// it lies on ([`trim::face_sources`]), `none` where it lies on none.
/// When `from`'s faces all have one value, so do `to`'s, with no search.
fn carried_face_values(
    values: &[u32],
    from: &trim::Mesh,
    to: &trim::Mesh,
    sources: &[trim::VertexSource],
    none: u32,
) -> Vec<u32> {
    if let Some(&first) = values.first() {
        if values.iter().all(|&v| v == first) {
            return vec![first; to.faces.len()];
        }
    }
    trim::face_sources(from, to, sources)
        .into_iter()
        .map(|f| f.map_or(none, |f| values[f as usize]))
        .collect()
}

/// Vertex colours as read: red, green, blue and alpha in 0..1.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Colours {
    /// One per vertex; alpha 1 where the file has none.
    pub rgba: Vec<[f64; 4]>,
    /// Whether the file had an alpha channel (written back only then).
    pub alpha: bool,
}

/// A per-vertex value of the file's own, which meshtrim has no other use
/// for: MeshLab's `quality` (screened Poisson's density) and `flags`, a
/// scanner's `confidence` or `intensity`, a CloudCompare scalar field.
/// Carried to the output as the file stores it.
#[derive(Debug, Clone, PartialEq)]
pub struct ScalarField {
    /// The property's name in the file.
    pub name: String,
    /// The type the file stores it as, which the output keeps.
    pub kind: ply::Scalar,
    /// One per vertex, each a value `kind` holds ([`ply::Scalar::holds`]).
    pub values: Vec<f64>,
}

impl ScalarField {
    /// A field read as `kind`, kept as `double` (exactly as read) when a
    /// value does not fit `kind` (an ASCII file's `2.5` in an integer
    /// property).
    pub(crate) fn read_as(name: String, kind: ply::Scalar, values: Vec<f64>) -> ScalarField {
        let kind = match values.iter().all(|&v| kind.holds(v)) {
            true => kind,
            false => ply::Scalar::F64,
        };
        ScalarField { name, kind, values }
    }

    /// The field at the sources: blended where `kind` is a float (a
    /// measurement), from the nearest corner where it is an integer (a
    /// label, flags or a count, which a blend would turn into values no
    /// vertex had).
    fn carried(&self, from: &trim::Mesh, sources: &[trim::VertexSource]) -> ScalarField {
        let values = if self.kind.is_integer() {
            trim::carry_nearest_corner(from, sources, &self.values)
        } else {
            trim::carry_values(from, sources, &self.values)
        };
        ScalarField {
            name: self.name.clone(),
            kind: self.kind,
            values,
        }
    }
}

/// Columns in triples, as the readers read values three at a time (the
/// last padded with its last column).
pub(crate) fn column_triples(columns: &[usize]) -> Vec<[usize; 3]> {
    columns
        .chunks(3)
        .map(|c| [c[0], c[1.min(c.len() - 1)], c[c.len() - 1]])
        .collect()
}

/// The `count` columns read by [`column_triples`], one `Vec` each.
pub(crate) fn columns_of_triples(triples: &[Vec<Point3>], count: usize) -> Vec<Vec<f64>> {
    (0..count)
        .map(|k| triples[k / 3].iter().map(|t| t[k % 3]).collect())
        .collect()
}

/// Whether the mesh writer gives a property of its own this name: such a
/// property is never read as a file's own value (a PLY `red` that is not
/// part of a colour is dropped, rather than written twice).
pub(crate) fn is_written_name(name: &str) -> bool {
    [
        "x", "y", "z", "nx", "ny", "nz", "red", "green", "blue", "alpha",
    ]
    .contains(&name)
}

/// Fields as (name, type, values), for tests to compare at a glance.
#[cfg(test)]
pub(crate) fn field_rows(fields: &[ScalarField]) -> Vec<(&str, ply::Scalar, &[f64])> {
    fields
        .iter()
        .map(|f| (f.name.as_str(), f.kind, f.values.as_slice()))
        .collect()
}

/// A colour channel already scaled to 0..1 by its type, clamped there; a
/// NaN (of a float channel) reads as 0, so colours are always in 0..1.
pub(crate) fn unit_channel(c: f64) -> f64 {
    if c.is_nan() {
        0.0
    } else {
        c.clamp(0.0, 1.0)
    }
}

/// The per-vertex attributes a mesh file holds besides positions, which
/// the commands that write a mesh carry to it
/// ([`trim::vertex_sources`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct VertexAttributes {
    /// Unit (or as read) normals, one per vertex.
    pub normals: Option<Vec<Point3>>,
    /// Colours, one per vertex.
    pub colours: Option<Colours>,
    /// The file's own values, one per vertex each.
    pub scalars: Vec<ScalarField>,
    /// Texture coordinates (u, v), one per vertex.
    pub texcoords: Option<Vec<[f64; 2]>>,
    /// The faces' materials, which the texture coordinates index into,
    /// written to outputs of their format.
    pub materials: Option<Materials>,
}

/// Attributes carried to a mesh ([`VertexAttributes::carried`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Carried {
    /// The mesh with its vertices split along the input's seams; `None`
    /// when none is (the mesh the attributes were carried to).
    pub mesh: Option<trim::Mesh>,
    /// The attributes, one per vertex of that mesh.
    pub attributes: VertexAttributes,
}

impl VertexAttributes {
    /// Whether there is nothing to carry.
    pub fn is_empty(&self) -> bool {
        self.normals.is_none()
            && self.colours.is_none()
            && self.scalars.is_empty()
            && self.texcoords.is_none()
            && self.materials.is_none()
    }

    /// These attributes, of `from`'s vertices, at the vertices of `to`, a
    /// mesh made from it: copied where a vertex was kept, blended from the
    /// closest point of `from` elsewhere, with `to`'s vertices split where
    /// `from`'s are along a seam, so that each side keeps its own (see
    /// [`trim::split_sources`]). A non-finite normal is carried as zero (no
    /// direction). Empty when there is nothing to carry or `from` has no
    /// vertex.
    pub fn carried(&self, from: &trim::Mesh, to: &trim::Mesh) -> Carried {
        if self.is_empty() {
            return Carried::default();
        }
        let Some(split) = trim::split_sources(from, to) else {
            return Carried::default();
        };
        let mesh = split.split_mesh(to);
        let mut attributes = self.at_sources(from, &split.sources);
        let out = mesh.as_ref().unwrap_or(to);
        attributes.materials = self
            .materials
            .as_ref()
            .map(|materials| materials.carried(from, out, &split.sources));
        Carried { mesh, attributes }
    }

    /// These attributes at `sources` in `from`, but the materials (which
    /// are the faces').
    fn at_sources(&self, from: &trim::Mesh, sources: &[trim::VertexSource]) -> VertexAttributes {
        VertexAttributes {
            normals: self.normals.as_ref().map(|normals| {
                // A file's NaN normal has no direction: zero, so that it
                // blends as none and the output stays writable.
                let finite: Vec<Point3> = normals
                    .iter()
                    .map(|n| match n.iter().all(|c| c.is_finite()) {
                        true => *n,
                        false => [0.0; 3],
                    })
                    .collect();
                trim::carry_normals(from, sources, &finite)
            }),
            colours: self.colours.as_ref().map(|colours| Colours {
                rgba: trim::carry(from, sources, &colours.rgba),
                alpha: colours.alpha,
            }),
            scalars: self
                .scalars
                .iter()
                .map(|field| field.carried(from, sources))
                .collect(),
            texcoords: self
                .texcoords
                .as_ref()
                .map(|texcoords| trim::carry(from, sources, texcoords)),
            materials: None,
        }
    }

    /// The names of what there is, for reports: "normals", "colours",
    /// "texture coordinates", "material", then the file's own values by
    /// their names.
    pub fn names(&self) -> Vec<String> {
        let mut names = Vec::new();
        if self.normals.is_some() {
            names.push("normals".to_string());
        }
        if self.colours.is_some() {
            names.push("colours".to_string());
        }
        if self.texcoords.is_some() {
            names.push("texture coordinates".to_string());
        }
        if self.materials.is_some() {
            names.push("material".to_string());
        }
        names.extend(self.scalars.iter().map(|field| field.name.clone()));
        names
    }
}

/// Reads a point cloud, choosing the reader by content and extension.
///
/// Fails, with the file name first in the message, on unreadable or
/// malformed files and on files with no points.
pub fn read_cloud(path: &Path) -> Result<Cloud> {
    read_cloud_with(path, &CloudOptions::default())
}

/// How a cloud file is read, beyond its format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CloudOptions {
    /// Read only this scan (the 0-based `data3D` index) of an E57 file;
    /// `None` merges them all. An error for the other formats.
    pub scan: Option<usize>,
}

/// [`read_cloud`] with `options`.
pub fn read_cloud_with(path: &Path, options: &CloudOptions) -> Result<Cloud> {
    read_cloud_inner(path, options).with_context(|| path.display().to_string())
}

/// Reads a mesh: PLY, OBJ, STL (ASCII or binary), glTF or GLB.
///
/// The faces are `None` if a PLY or OBJ file has none; STL and glTF always
/// give `Some`. A PLY range scan's `range_grid` gives faces (see
/// [`ply`]); [`read_cloud`] ignores it. See [`MeshInput`] for how the
/// reader is chosen.
pub fn read_mesh(path: &Path) -> Result<Mesh> {
    read_mesh_inner(path).with_context(|| path.display().to_string())
}

/// Reads a mesh that must have faces (for the commands that cut or clean
/// one); a file without faces is an error naming the file and `hint`.
pub fn read_mesh_with_faces(path: &Path, hint: &str) -> Result<trim::Mesh> {
    Ok(read_mesh_with_attributes(path, hint)?.0)
}

/// [`read_mesh_with_faces`], with the vertices' normals, colours and the
/// file's own values.
pub fn read_mesh_with_attributes(
    path: &Path,
    hint: &str,
) -> Result<(trim::Mesh, VertexAttributes)> {
    let read = read_mesh(path)?;
    let Some(faces) = read.faces else {
        bail!("{}: the file has no faces: {hint}", path.display());
    };
    let attributes = VertexAttributes {
        normals: read.normals,
        colours: read.colours,
        scalars: read.scalars,
        texcoords: read.texcoords,
        materials: read.materials,
    };
    let mesh = trim::Mesh {
        vertices: read.vertices,
        faces,
    };
    Ok((mesh, attributes))
}

fn read_cloud_inner(path: &Path, options: &CloudOptions) -> Result<Cloud> {
    let bytes = std::fs::read(path).context("cannot read")?;
    let format = cloud_format(path, &bytes)?;
    if let (Some(n), false) = (options.scan, format == Format::E57) {
        bail!(
            "scan {n} asked for, but scans are numbered in E57 files only; this is a {} file",
            format.name()
        );
    }
    let cloud = match format {
        Format::MeshVertices => from_mesh(parse_mesh(path, &bytes)?, format),
        Format::Ply => from_mesh(ply::read_ply(&bytes)?, format),
        Format::Obj => from_mesh(obj::read_obj(&bytes)?, format),
        Format::Pcd => pcd::read_pcd(&bytes)?,
        Format::Text => from_mesh(text::read_text(&bytes)?, format),
        Format::Las => las::read_las(bytes)?,
        Format::E57 => e57::read_e57(bytes, options.scan)?,
    };
    if cloud.points.is_empty() {
        bail!("no points in the file ({} format)", format.name());
    }
    Ok(cloud)
}

/// The reader for a cloud: [`detect_format`], except that the mesh-only
/// extensions `.stl`, `.glb` and `.gltf` go to the mesh reader's rules, as
/// in [`read_mesh`]. A binary STL's 80-byte header is free text, so one
/// starting `v ` or `VERSION` would otherwise be sniffed as OBJ or PCD.
fn cloud_format(path: &Path, bytes: &[u8]) -> Result<Format> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if ["stl", "glb", "gltf"].contains(&ext.to_ascii_lowercase().as_str()) {
        return Ok(match MeshInput::detect(path, bytes)? {
            MeshInput::Ply => Format::Ply,
            MeshInput::Obj => Format::Obj,
            MeshInput::Stl | MeshInput::Gltf => Format::MeshVertices,
        });
    }
    let error = match detect_format(path, bytes) {
        Ok(format) => return Ok(format),
        Err(error) => error,
    };
    // A triangulated scan (STL, glTF) is a cloud too: its vertices.
    match MeshInput::detect(path, bytes) {
        Ok(MeshInput::Stl | MeshInput::Gltf) => Ok(Format::MeshVertices),
        _ => Err(error),
    }
}

fn read_mesh_inner(path: &Path) -> Result<Mesh> {
    let bytes = std::fs::read(path).context("cannot read")?;
    parse_mesh(path, &bytes)
}

/// Parses a mesh file's bytes (`path` for its extension and, for glTF,
/// the directory of its buffers).
fn parse_mesh(path: &Path, bytes: &[u8]) -> Result<Mesh> {
    let mesh = match MeshInput::detect(path, bytes)? {
        MeshInput::Ply => {
            let mut mesh = ply::read_ply_mesh(bytes)?;
            let dir = path.parent().unwrap_or(Path::new(""));
            if let Some(Materials::Ply(textures)) = mesh.materials.as_mut() {
                textures.files.iter_mut().for_each(|f| *f = dir.join(&*f));
            }
            mesh
        }
        MeshInput::Obj => obj::read_obj_mesh(bytes, path.parent().unwrap_or(Path::new("")))?,
        MeshInput::Stl => stl::read_stl(bytes)?,
        MeshInput::Gltf => {
            let dir = path.parent().unwrap_or(Path::new(""));
            gltf_io::read_gltf(bytes, dir)?
        }
    };
    if mesh.vertices.is_empty() {
        bail!("no vertices in the file");
    }
    Ok(mesh)
}

/// The mesh readers, as [`read_mesh`] chooses them.
///
/// In order: the GLB magic `glTF` and a PLY header are recognised by
/// content; then the extensions `.stl`, `.glb` and `.gltf` decide (ASCII
/// or binary STL by content); then a binary STL whose size matches its
/// triangle count, an ASCII STL (`solid` then `facet`) and glTF JSON (an
/// object with `"asset"`) are recognised by content; then the point-cloud
/// rules of [`detect_format`] give PLY or OBJ.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshInput {
    /// Stanford PLY.
    Ply,
    /// Wavefront OBJ.
    Obj,
    /// STL, ASCII or binary.
    Stl,
    /// glTF 2.0, JSON or GLB.
    Gltf,
}

impl MeshInput {
    /// Chooses the mesh reader for a file, or fails naming the extension.
    pub fn detect(path: &Path, bytes: &[u8]) -> Result<MeshInput> {
        if gltf_io::is_glb(bytes) {
            return Ok(MeshInput::Gltf);
        }
        if sniff(bytes) == Some(Format::Ply) {
            return Ok(MeshInput::Ply);
        }
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        match ext.to_ascii_lowercase().as_str() {
            "stl" => return Ok(MeshInput::Stl),
            "glb" | "gltf" => return Ok(MeshInput::Gltf),
            _ => {}
        }
        if stl::is_exact_binary(bytes) || stl::looks_ascii(bytes) {
            return Ok(MeshInput::Stl);
        }
        if gltf_io::looks_like_json(bytes) {
            return Ok(MeshInput::Gltf);
        }
        match detect_format(path, bytes) {
            Ok(Format::Ply) => Ok(MeshInput::Ply),
            Ok(Format::Obj) => Ok(MeshInput::Obj),
            Ok(other) => bail!(
                "a mesh must be PLY, OBJ, STL, glTF or GLB, this is a {} point cloud",
                other.name()
            ),
            Err(_) => bail!(
                "unknown mesh format: the extension '{ext}' is not one of ply, obj, stl, gltf, \
                 glb, and the content is not recognised as any of them"
            ),
        }
    }
}

fn from_mesh(mesh: Mesh, format: Format) -> Cloud {
    Cloud {
        points: mesh.vertices,
        normals: mesh.normals,
        colours: mesh.colours,
        scalars: mesh.scalars,
        dropped_non_finite: 0,
        format,
        scale_offset: None,
        grid: None,
    }
}

/// Chooses the reader for a file.
///
/// The PLY and PCD headers and OBJ `v` lines are recognised whatever the
/// extension says, because files get renamed. Otherwise the extension
/// decides, and a file with an unknown extension is read as text if its
/// first data line holds at least three numbers.
pub fn detect_format(path: &Path, bytes: &[u8]) -> Result<Format> {
    if let Some(format) = sniff(bytes) {
        return Ok(format);
    }
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if let Some(format) = Format::from_extension(ext) {
        return Ok(format);
    }
    if text::looks_numeric(bytes) {
        return Ok(Format::Text);
    }
    bail!(
        "unknown format: the extension '{ext}' is not one of ply, pcd, obj, las, laz, e57, xyz, txt, \
         csv, asc, pts, and the content is neither a PLY, PCD, OBJ, LAS or E57 header nor lines \
         of numbers"
    )
}

/// Recognises a format from the start of the file, if it is unambiguous.
fn sniff(bytes: &[u8]) -> Option<Format> {
    if las::is_las(bytes) {
        return Some(Format::Las);
    }
    if e57::is_e57(bytes) {
        return Some(Format::E57);
    }
    let bytes = strip_bom(bytes);
    // `ply\r` covers `ply\r\n` and a lone `\r` (classic Mac OS).
    if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r") {
        return Some(Format::Ply);
    }
    // Only the start matters; a lossy view copes with binary data after it.
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(4096)]);
    // The PCD banner is a comment line, but a telling one.
    let telling = |l: &&str| !l.is_empty() && (!l.starts_with('#') || is_pcd_banner(l));
    let first = lines(&head).map(str::trim).find(telling)?;
    if is_pcd_banner(first) || first.starts_with("VERSION") || first.starts_with("FIELDS") {
        return Some(Format::Pcd);
    }
    let obj_line = |l: &str| l.starts_with("v ") || l.starts_with("v\t");
    if lines(&head).map(str::trim_start).any(obj_line) {
        return Some(Format::Obj);
    }
    None
}

fn is_pcd_banner(line: &str) -> bool {
    line.starts_with("# .PCD")
}

#[cfg(test)]
mod piece_tests;
#[cfg(test)]
mod tests;
