//! Writing triangle meshes, the format chosen by the file extension.
//!
//! | extension | what is written |
//! |---|---|
//! | `.obj` | `v x y z` with the shortest decimals that read back to the same `f64`, `f a b c` 1-based; vertex colours, normals, texture coordinates and materials |
//! | `.ply` | binary little-endian, `double x y z`, faces as `list uchar int vertex_indices`; normals, colours, texture coordinates, texture images (MeshLab's) and the file's own values |
//! | `.stl` | binary, 80-byte header naming meshtrim, `f32` normals and corners |
//! | `.glb` | binary glTF 2.0, one mesh, one primitive (one per material), `f32` positions, `u32` indices; normals, colours, texture coordinates, materials and the own values `f32` holds as `_NAME` |
//! | `.gltf` | glTF 2.0 JSON with the same data in an embedded base64 data URI |
//!
//! STL and glTF store coordinates as `f32`, so they lose precision beyond
//! about 7 significant digits; OBJ and PLY keep `f64` exactly. glTF
//! stores a mesh far from the origin about its centre, and a mesh that
//! rounding would change (vertices merged, faces flattened or turned) is
//! refused ([`super::f32_rounding`]). Output is
//! written atomically ([`super::atomic::write_atomic`]), and the bytes
//! depend only on the mesh (no dates, no hash-map order). Materials of
//! another format's kind are made the output's
//! ([`super::simple_material`]).

use std::io::Write;
use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};

use super::atomic::write_atomic;
use super::float_text::push_f64_debug;
use super::simple_material::SimpleMaterials;
use super::{
    f32_rounding, gltf_io, show, stl, write_formatted, Materials, Point3, ScalarField,
    VertexAttributes,
};

/// The mesh formats meshtrim writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ, text.
    Obj,
    /// Binary little-endian PLY with double coordinates.
    Ply,
    /// Binary STL.
    Stl,
    /// Binary glTF (GLB).
    Glb,
    /// glTF JSON with an embedded buffer.
    Gltf,
}

impl MeshFormat {
    /// The format a path's extension names (any case), if any.
    pub fn from_path(path: &Path) -> Option<MeshFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "obj" => MeshFormat::Obj,
            "ply" => MeshFormat::Ply,
            "stl" => MeshFormat::Stl,
            "glb" => MeshFormat::Glb,
            "gltf" => MeshFormat::Gltf,
            _ => return None,
        })
    }

    /// Whether the format stores coordinates as `f32`.
    pub fn is_f32(self) -> bool {
        matches!(self, MeshFormat::Stl | MeshFormat::Glb | MeshFormat::Gltf)
    }

    /// Writes the mesh in this format, with the vertex attributes it can
    /// hold (all but STL hold normals and colours); the mesh must pass
    /// [`check_mesh`].
    pub fn write(
        self,
        w: &mut dyn Write,
        vertices: &[Point3],
        faces: &[[u32; 3]],
        attributes: &VertexAttributes,
    ) -> std::io::Result<()> {
        match self {
            MeshFormat::Obj => write_obj(w, vertices, faces, attributes, None),
            MeshFormat::Ply => write_ply(w, vertices, faces, attributes),
            MeshFormat::Stl => stl::write_stl(w, vertices, faces),
            MeshFormat::Glb => gltf_io::write_glb(w, vertices, faces, attributes),
            MeshFormat::Gltf => gltf_io::write_gltf(w, vertices, faces, attributes),
        }
    }

    /// Whether the format stores vertex normals and colours.
    pub fn holds_normals_and_colours(self) -> bool {
        self != MeshFormat::Stl
    }

    /// Whether the format stores `field` as it is: PLY one whose name is
    /// a word (a header token), glTF one whose values `f32` holds (see
    /// [`gltf_io`]), OBJ and STL none.
    pub fn holds_field(self, field: &ScalarField) -> bool {
        match self {
            MeshFormat::Ply => is_word(&field.name),
            MeshFormat::Glb | MeshFormat::Gltf => gltf_io::holds_field(field),
            MeshFormat::Obj | MeshFormat::Stl => false,
        }
    }

    /// `attributes` split into those this format holds and the names of
    /// the others.
    pub fn split_attributes(self, attributes: VertexAttributes) -> (VertexAttributes, Vec<String>) {
        let VertexAttributes {
            normals,
            colours,
            scalars,
            texcoords,
            materials,
        } = attributes;
        let mut held = VertexAttributes::default();
        let mut not_held = VertexAttributes::default();
        let side = match self.holds_normals_and_colours() {
            true => &mut held,
            false => &mut not_held,
        };
        side.normals = normals;
        side.colours = colours;
        side.texcoords = texcoords;
        let mut left = Vec::new();
        if let Some(materials) = materials {
            let (written, not_written) = self.materials_for(materials);
            match written {
                Ok(materials) => held.materials = Some(materials),
                Err(materials) => not_held.materials = Some(materials),
            }
            left = not_written;
        }
        let (fields, others) = scalars.into_iter().partition(|f| self.holds_field(f));
        held.scalars = fields;
        not_held.scalars = others;
        let mut not_written = not_held.names();
        not_written.extend(left);
        (held, not_written)
    }

    /// Whether the format writes `materials` as they are: its own kind,
    /// or simple materials (OBJ, and PLY when one has an image).
    fn holds_as_they_are(self, materials: &Materials) -> bool {
        match (self, materials) {
            (MeshFormat::Obj, Materials::Obj(_) | Materials::Simple(_))
            | (MeshFormat::Glb | MeshFormat::Gltf, Materials::Gltf(_))
            | (MeshFormat::Ply, Materials::Ply(_)) => true,
            (MeshFormat::Ply, Materials::Simple(simple)) => simple.has_image(),
            _ => false,
        }
    }

    /// `materials` as the format holds them: its own kind as they are,
    /// another's made simple ([`SimpleMaterials`]) and, for glTF, glTF's
    /// from those; `Err` with them when the format holds none (STL, and
    /// PLY, which holds images only, when none has one). And the names of
    /// the parts left out.
    fn materials_for(self, materials: Materials) -> (Result<Materials, Materials>, Vec<String>) {
        if self.holds_as_they_are(&materials) {
            return (Ok(materials), Vec::new());
        }
        let simple = match &materials {
            _ if self == MeshFormat::Stl => return (Err(materials), Vec::new()),
            Materials::Obj(material) => SimpleMaterials::from_obj(material),
            Materials::Gltf(gltf) => SimpleMaterials::from_gltf(gltf),
            Materials::Ply(textures) => SimpleMaterials::from_ply(textures),
            Materials::Simple(simple) => simple.clone(),
        };
        match self {
            MeshFormat::Glb | MeshFormat::Gltf => {
                let (gltf, left) = simple.to_gltf();
                (Ok(Materials::Gltf(gltf)), left)
            }
            MeshFormat::Obj => (Ok(Materials::Simple(simple)), Vec::new()),
            MeshFormat::Ply if simple.has_image() => (Ok(Materials::Simple(simple)), Vec::new()),
            _ => (Err(materials), Vec::new()),
        }
    }
}

/// Writes a triangle mesh to `path`, atomically, in the format its
/// extension names: `.obj`, `.ply`, `.stl`, `.glb` or `.gltf`.
///
/// Fails, naming the file, before anything is written if the extension is
/// unknown, a face refers to a missing vertex, a coordinate is not finite
/// (or, for STL and glTF, does not fit in `f32`, or the whole mesh is below
/// f32's normal range and would be written as zeros), or the format cannot hold
/// the mesh (PLY's `int` indices, STL's `u32` triangle count, glTF's
/// non-empty accessors).
pub fn write_mesh(path: &Path, vertices: &[Point3], faces: &[[u32; 3]]) -> Result<()> {
    write_mesh_with(path, vertices, faces, &VertexAttributes::default())
}

/// [`write_mesh`] with per-vertex normals and colours (one per vertex),
/// which every format but STL holds.
pub fn write_mesh_with(
    path: &Path,
    vertices: &[Point3],
    faces: &[[u32; 3]],
    attributes: &VertexAttributes,
) -> Result<()> {
    let format = MeshFormat::from_path(path)
        .ok_or_else(|| {
            let ext = path.extension().map(|e| e.to_string_lossy().into_owned());
            anyhow!(
                "cannot write a mesh as '.{}': the extension must be one of obj, ply, stl, glb, gltf",
                ext.unwrap_or_default()
            )
        })
        .with_context(|| path.display().to_string())?;
    check_mesh(format, vertices, faces).with_context(|| path.display().to_string())?;
    check_attributes(format, vertices.len(), attributes)
        .with_context(|| path.display().to_string())?;
    if let Some(materials) = &attributes.materials {
        materials
            .check(faces.len())
            .with_context(|| path.display().to_string())?;
    }
    // Materials of another format's kind (given from Python) are made
    // this format's here; the CLI's come made by `split_attributes`.
    let converted;
    let attributes = match &attributes.materials {
        Some(materials) if !format.holds_as_they_are(materials) => {
            converted = VertexAttributes {
                materials: format.materials_for(materials.clone()).0.ok(),
                ..attributes.clone()
            };
            &converted
        }
        _ => attributes,
    };
    match (format, &attributes.materials) {
        (MeshFormat::Obj, Some(Materials::Obj(material))) => {
            let used = ObjMaterialLines {
                libraries: super::obj_material::libraries_for_output(path, material)?,
                names: &material.names,
                faces: &material.faces,
            };
            write_atomic(path, |w| {
                write_obj(w, vertices, faces, attributes, Some(&used))
            })
        }
        (MeshFormat::Obj, Some(Materials::Simple(simple))) => {
            let names: Vec<String> = simple.materials.iter().map(|m| m.name.clone()).collect();
            let used = ObjMaterialLines {
                libraries: vec![simple.write_obj_library(path)?],
                names: &names,
                faces: &simple.faces,
            };
            write_atomic(path, |w| {
                write_obj(w, vertices, faces, attributes, Some(&used))
            })
        }
        (MeshFormat::Ply, Some(Materials::Ply(textures))) => {
            let names = super::obj_material::images_for_output(path, &textures.files)?;
            let numbers = (textures.files.len() > 1).then_some(textures.faces.as_slice());
            write_atomic(path, |w| {
                write_ply_with(w, vertices, faces, attributes, (&names, numbers))
            })
        }
        (MeshFormat::Ply, Some(Materials::Simple(simple))) => {
            let (names, numbers) = simple.write_ply_textures(path)?;
            write_atomic(path, |w| {
                write_ply_with(w, vertices, faces, attributes, (&names, numbers.as_deref()))
            })
        }
        _ => write_atomic(path, |w| format.write(w, vertices, faces, attributes)),
    }
}

/// The material lines of an OBJ: `mtllib` names, and the `usemtl` names
/// of the faces.
pub struct ObjMaterialLines<'a> {
    /// The libraries, as the OBJ names them.
    pub libraries: Vec<String>,
    /// The materials' names.
    pub names: &'a [String],
    /// Each face's material, an index into `names`.
    pub faces: &'a [u32],
}

/// Checks that `format` can hold the mesh, with a message naming the
/// vertex or face at fault.
pub fn check_mesh(format: MeshFormat, vertices: &[Point3], faces: &[[u32; 3]]) -> Result<()> {
    for (i, p) in vertices.iter().enumerate() {
        if p.iter().any(|c| !c.is_finite()) {
            bail!("vertex {i} has a non-finite coordinate {}", show(p));
        }
        if format.is_f32() && p.iter().any(|&c| !(c as f32).is_finite()) {
            bail!(
                "vertex {i} {} does not fit in the f32 coordinates of {}",
                show(p),
                format_name(format)
            );
        }
    }
    if format.is_f32() {
        check_f32_underflow(format, vertices)?;
    }
    for (t, face) in faces.iter().enumerate() {
        if let Some(&v) = face.iter().find(|&&v| v as usize >= vertices.len()) {
            bail!(
                "triangle {t} refers to vertex {v}, but there are only {} vertices",
                vertices.len()
            );
        }
    }
    match format {
        MeshFormat::Stl => f32_rounding::check_rounding("STL", vertices, faces, None, true)?,
        MeshFormat::Glb | MeshFormat::Gltf => {
            let origin = f32_rounding::storage_origin(vertices);
            f32_rounding::check_rounding("glTF", vertices, faces, origin, false)?
        }
        MeshFormat::Obj | MeshFormat::Ply => {}
    }
    match format {
        MeshFormat::Ply if vertices.len() > i32::MAX as usize + 1 => {
            bail!("PLY int vertex indices hold at most 2^31 vertices")
        }
        MeshFormat::Stl if u32::try_from(faces.len()).is_err() => {
            bail!("binary STL holds at most {} triangles", u32::MAX)
        }
        MeshFormat::Glb | MeshFormat::Gltf if vertices.is_empty() || faces.is_empty() => {
            bail!("glTF needs at least one vertex and one triangle (accessors cannot be empty)")
        }
        _ => Ok(()),
    }
}

/// What [`write_mesh_carrying`] did with the input's vertex attributes.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct AttributesWritten {
    /// Written to the output ("normals", "colours", the file's own
    /// values by name).
    pub written: Vec<String>,
    /// Read but not written, the output's format holding none of them
    /// (STL none at all, OBJ no values of the file's own).
    pub not_written: Vec<String>,
}

/// Writes `out`, made from `from` (whose vertices carry `attributes`), to
/// `path` as [`write_mesh_with`] does, with the attributes the format
/// holds carried from `from` ([`VertexAttributes::carried`]); where
/// `from`'s vertices are split along a seam and the format holds one of
/// its attributes, `out`'s are split there too.
pub fn write_mesh_carrying(
    path: &Path,
    out: &trim::Mesh,
    from: &trim::Mesh,
    attributes: VertexAttributes,
) -> Result<AttributesWritten> {
    let (held, not_written) = match MeshFormat::from_path(path) {
        Some(format) => format.split_attributes(attributes),
        // write_mesh_with names the unknown extension.
        None => (VertexAttributes::default(), Vec::new()),
    };
    let carried = held.carried(from, out);
    let out = carried.mesh.as_ref().unwrap_or(out);
    write_mesh_with(path, &out.vertices, &out.faces, &carried.attributes)?;
    Ok(AttributesWritten {
        written: carried.attributes.names(),
        not_written,
    })
}

/// Checks that `format` holds the attributes given, one normal and one
/// colour per vertex, all finite (normals within `f32`'s range for PLY,
/// which stores them as `float`).
fn check_attributes(
    format: MeshFormat,
    vertices: usize,
    attributes: &VertexAttributes,
) -> Result<()> {
    let per_vertex = attributes.normals.is_some()
        || attributes.colours.is_some()
        || attributes.texcoords.is_some();
    if !format.holds_normals_and_colours() && per_vertex {
        bail!(
            "{} holds no vertex normals, colours or texture coordinates: write .ply, .obj, .gltf or .glb",
            format_name(format)
        );
    }
    if let Some(texcoords) = &attributes.texcoords {
        if texcoords.len() != vertices {
            bail!(
                "{} texture coordinates for {vertices} vertices",
                texcoords.len()
            );
        }
        if let Some(i) = texcoords
            .iter()
            .position(|t| !t.iter().all(|c| c.is_finite()))
        {
            bail!(
                "vertex {i} has a non-finite texture coordinate {:?}",
                texcoords[i]
            );
        }
    }
    for field in &attributes.scalars {
        check_field(format, vertices, field)?;
    }
    if let Some(normals) = &attributes.normals {
        if normals.len() != vertices {
            bail!("{} normals for {vertices} vertices", normals.len());
        }
        let fits = |c: &f64| match format {
            MeshFormat::Ply => (*c as f32).is_finite(),
            _ => c.is_finite(),
        };
        if let Some(i) = normals.iter().position(|n| !n.iter().all(fits)) {
            bail!(
                "vertex {i}'s normal {} is not finite in {}",
                show(&normals[i]),
                format_name(format)
            );
        }
    }
    if let Some(colours) = &attributes.colours {
        if colours.rgba.len() != vertices {
            bail!("{} colours for {vertices} vertices", colours.rgba.len());
        }
        if let Some(i) = colours
            .rgba
            .iter()
            .position(|c| c.iter().any(|x| !x.is_finite()))
        {
            bail!("vertex {i} has a non-finite colour {:?}", colours.rgba[i]);
        }
    }
    Ok(())
}

/// Checks one of the file's own values: one per vertex, each one its
/// type holds, and a format that holds it.
fn check_field(format: MeshFormat, vertices: usize, field: &ScalarField) -> Result<()> {
    let name = &field.name;
    if field.values.len() != vertices {
        bail!(
            "{} values of '{name}' for {vertices} vertices",
            field.values.len()
        );
    }
    if let Some(i) = field.values.iter().position(|&v| !field.kind.holds(v)) {
        bail!(
            "vertex {i}'s '{name}' value {} is not a {} value",
            field.values[i],
            field.kind.name()
        );
    }
    if !format.holds_field(field) {
        let why = match format {
            MeshFormat::Ply => "whose property names are words (no spaces, not empty)",
            MeshFormat::Glb | MeshFormat::Gltf => {
                "whose values must be finite and, for 32-bit integers, within ±2^24 (f32): write .ply"
            }
            MeshFormat::Obj | MeshFormat::Stl => {
                "which holds no per-vertex values of a file's own: write .ply"
            }
        };
        bail!(
            "'{name}' cannot be written to {}, {why}",
            format_name(format)
        );
    }
    Ok(())
}

/// Whether `name` is one PLY header token: printable ASCII, no spaces.
fn is_word(name: &str) -> bool {
    !name.is_empty() && name.bytes().all(|b| b.is_ascii_graphic())
}

/// A colour channel in 0..1 as a byte (clamped).
pub(crate) fn channel_byte(c: f64) -> u8 {
    (c.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Refuses a mesh too small for `f32`: when its largest |coordinate| is
/// below f32's smallest normal number, every coordinate becomes 0 or a
/// subnormal with a few bits, so the file would hold a point or a
/// distorted shape (a mesh at 1e-50 would be all (0, 0, 0)). Single
/// tiny coordinates in a larger mesh are fine: their rounding stays below
/// f32's precision at the mesh's size.
fn check_f32_underflow(format: MeshFormat, vertices: &[Point3]) -> Result<()> {
    let largest = |p: &Point3| p.iter().fold(0.0, |m: f64, c| m.max(c.abs()));
    let Some((i, p)) = vertices
        .iter()
        .enumerate()
        .max_by(|(_, p), (_, q)| largest(p).total_cmp(&largest(q)))
    else {
        return Ok(());
    };
    let m = largest(p);
    if m > 0.0 && m < f64::from(f32::MIN_POSITIVE) {
        bail!(
            "the mesh's largest |coordinate| is {m:e} (vertex {i}), below f32's smallest \
             normal number ({:e}), so {} would store its vertices as 0 or with a few bits: \
             write .ply or .obj (f64) instead",
            f32::MIN_POSITIVE,
            format_name(format)
        );
    }
    Ok(())
}

fn format_name(format: MeshFormat) -> &'static str {
    match format {
        MeshFormat::Obj => "OBJ",
        MeshFormat::Ply => "PLY",
        MeshFormat::Stl => "STL",
        MeshFormat::Glb | MeshFormat::Gltf => "glTF",
    }
}

/// OBJ: a comment, the material's `mtllib` lines, `v` lines (Rust's
/// shortest round-trip decimals, with an exponent for very large or small
/// values; with colours, `v x y z r g b` as MeshLab and trimesh write
/// them, each channel a multiple of 1/255), `vt` and `vn` lines, one per
/// vertex, then the `f` lines (a `usemtl` before each run of faces of
/// one material), 1-based, each corner's
/// texture coordinate and normal those of its vertex (`f a/a/a …`,
/// `f a/a …`, `f a//a …` or `f a b c`).
pub fn write_obj(
    w: &mut dyn Write,
    vertices: &[Point3],
    faces: &[[u32; 3]],
    attributes: &VertexAttributes,
    material: Option<&ObjMaterialLines>,
) -> std::io::Result<()> {
    writeln!(
        w,
        "# meshtrim mesh: {} vertices, {} triangles",
        vertices.len(),
        faces.len()
    )?;
    for library in material.iter().flat_map(|m| &m.libraries) {
        writeln!(w, "mtllib {library}")?;
    }
    let colours = attributes.colours.as_ref();
    super::write_formatted(w, vertices.len(), |out, i| {
        out.push(b'v');
        for c in vertices[i] {
            out.push(b' ');
            push_f64_debug(out, c);
        }
        if let Some(colours) = colours {
            for c in &colours.rgba[i][..3] {
                out.push(b' ');
                push_f64_debug(out, f64::from(channel_byte(*c)) / 255.0);
            }
        }
        out.push(b'\n');
    })?;
    if let Some(texcoords) = &attributes.texcoords {
        write_vectors(w, "vt", texcoords)?;
    }
    if let Some(normals) = &attributes.normals {
        write_vectors(w, "vn", normals)?;
    }
    let corner = match (attributes.texcoords.is_some(), attributes.normals.is_some()) {
        (true, true) => |out: &mut Vec<u8>, v: u64| write!(out, " {v}/{v}/{v}"),
        (true, false) => |out: &mut Vec<u8>, v: u64| write!(out, " {v}/{v}"),
        (false, true) => |out: &mut Vec<u8>, v: u64| write!(out, " {v}//{v}"),
        (false, false) => |out: &mut Vec<u8>, v: u64| write!(out, " {v}"),
    };
    super::write_formatted(w, faces.len(), |out, i| {
        if let Some(material) = material {
            let this = material.faces[i];
            if i == 0 || material.faces[i - 1] != this {
                // Writing into a Vec cannot fail.
                let _ = writeln!(out, "usemtl {}", material.names[this as usize]);
            }
        }
        out.push(b'f');
        for v in faces[i] {
            // Writing into a Vec cannot fail.
            let _ = corner(out, u64::from(v) + 1);
        }
        out.push(b'\n');
    })
}

/// One line per vector: `keyword x y …` in shortest round-trip decimals.
fn write_vectors<const N: usize>(
    w: &mut dyn Write,
    keyword: &str,
    vectors: &[[f64; N]],
) -> std::io::Result<()> {
    super::write_formatted(w, vectors.len(), |out, i| {
        out.extend_from_slice(keyword.as_bytes());
        for c in vectors[i] {
            out.push(b' ');
            push_f64_debug(out, c);
        }
        out.push(b'\n');
    })
}

/// PLY, binary little-endian: `double x y z`, `float nx ny nz`, `uchar`
/// colours, `float texture_u texture_v` (MeshLab's names) and the file's
/// own values in their own types, as given; then
/// the faces as `list uchar int vertex_indices` (the list type most
/// readers expect).
pub fn write_ply(
    w: &mut dyn Write,
    vertices: &[Point3],
    faces: &[[u32; 3]],
    attributes: &VertexAttributes,
) -> std::io::Result<()> {
    write_ply_with(w, vertices, faces, attributes, (&[], None))
}

/// [`write_ply`] with MeshLab's `comment TextureFile` lines naming
/// `textures`, and then, with texture coordinates, each face's corners'
/// as MeshLab's `list uchar float texcoord` (which MeshLab draws the
/// texture by), and each face's texture number (`int texnumber`) when
/// given.
fn write_ply_with(
    w: &mut dyn Write,
    vertices: &[Point3],
    faces: &[[u32; 3]],
    attributes: &VertexAttributes,
    (textures, numbers): (&[String], Option<&[u32]>),
) -> std::io::Result<()> {
    let mut properties = String::from("property double x\nproperty double y\nproperty double z\n");
    if attributes.normals.is_some() {
        properties.push_str("property float nx\nproperty float ny\nproperty float nz\n");
    }
    if let Some(colours) = &attributes.colours {
        properties.push_str("property uchar red\nproperty uchar green\nproperty uchar blue\n");
        if colours.alpha {
            properties.push_str("property uchar alpha\n");
        }
    }
    if attributes.texcoords.is_some() {
        // MeshLab's names.
        properties.push_str("property float texture_u\nproperty float texture_v\n");
    }
    for field in &attributes.scalars {
        properties.push_str(&format!("property {} {}\n", field.kind.name(), field.name));
    }
    let comments: String = textures
        .iter()
        .map(|name| format!("comment TextureFile {name}\n"))
        .collect();
    let wedges = match &attributes.texcoords {
        Some(texcoords) if !textures.is_empty() => Some(texcoords),
        _ => None,
    };
    let mut face_properties = String::from("property list uchar int vertex_indices\n");
    if wedges.is_some() {
        face_properties.push_str("property list uchar float texcoord\n");
    }
    if numbers.is_some() {
        face_properties.push_str("property int texnumber\n");
    }
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment written by meshtrim\n{comments}\
         element vertex {}\n{properties}\
         element face {}\n{face_properties}end_header\n",
        vertices.len(),
        faces.len()
    )?;
    // Face indices are written as int: every vertex index must fit.
    if let Some(last) = vertices.len().checked_sub(1) {
        i32::try_from(last).map_err(std::io::Error::other)?;
    }
    write_formatted(w, vertices.len(), |out, i| {
        for c in vertices[i] {
            out.extend(c.to_le_bytes());
        }
        if let Some(normals) = &attributes.normals {
            for c in normals[i] {
                out.extend((c as f32).to_le_bytes());
            }
        }
        if let Some(colours) = &attributes.colours {
            let channels = if colours.alpha { 4 } else { 3 };
            out.extend(colours.rgba[i][..channels].iter().map(|&c| channel_byte(c)));
        }
        if let Some(texcoords) = &attributes.texcoords {
            for c in texcoords[i] {
                out.extend((c as f32).to_le_bytes());
            }
        }
        for field in &attributes.scalars {
            field.kind.push_le(out, field.values[i]);
        }
    })?;
    write_formatted(w, faces.len(), |out, i| {
        out.push(3);
        for v in faces[i] {
            out.extend((v as i32).to_le_bytes());
        }
        if let Some(texcoords) = wedges {
            out.push(6);
            for v in faces[i] {
                for c in texcoords[v as usize] {
                    out.extend((c as f32).to_le_bytes());
                }
            }
        }
        if let Some(numbers) = numbers {
            out.extend((numbers[i] as i32).to_le_bytes());
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions() {
        let f = |p: &str| MeshFormat::from_path(Path::new(p));
        assert_eq!(f("a/b.OBJ"), Some(MeshFormat::Obj));
        assert_eq!(f("b.ply"), Some(MeshFormat::Ply));
        assert_eq!(f("b.Stl"), Some(MeshFormat::Stl));
        assert_eq!(f("b.glb"), Some(MeshFormat::Glb));
        assert_eq!(f("b.gltf"), Some(MeshFormat::Gltf));
        assert_eq!(f("b.xyz"), None);
        assert_eq!(f("b"), None);
    }

    #[test]
    fn obj_text_is_shortest_round_trip() {
        let mut out = Vec::new();
        let v = [[0.1, -2.0, 1e300], [1.0 / 3.0, -0.0, 5e-324]];
        write_obj(
            &mut out,
            &v,
            &[[0, 1, 0]],
            &VertexAttributes::default(),
            None,
        )
        .unwrap();
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "# meshtrim mesh: 2 vertices, 1 triangles\nv 0.1 -2.0 1e300\n\
             v 0.3333333333333333 -0.0 5e-324\nf 1 2 1\n"
        );
    }

    #[test]
    fn ply_reads_back_exactly() {
        let v = vec![[0.1, -2.0, 1e300], [1.0 / 3.0, -0.0, 5e-324], [1., 2., 3.]];
        let f = vec![[0, 1, 2], [2, 1, 0]];
        let mut out = Vec::new();
        write_ply(&mut out, &v, &f, &VertexAttributes::default()).unwrap();
        let mesh = super::super::ply::read_ply(&out).unwrap();
        assert_eq!(mesh.vertices, v);
        assert_eq!(mesh.faces.unwrap(), f);
    }

    #[test]
    fn checks_name_the_fault() {
        let e = |format, v: &[Point3], f: &[[u32; 3]]| {
            check_mesh(format, v, f).unwrap_err().to_string()
        };
        let v = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 1e300]];
        assert_eq!(
            e(MeshFormat::Obj, &v, &[[0, 1, 3]]),
            "triangle 0 refers to vertex 3, but there are only 3 vertices"
        );
        let stl = e(MeshFormat::Stl, &v, &[[0, 1, 2]]);
        assert!(stl.starts_with("vertex 2 (0, 1, 1000"), "{stl}");
        assert!(
            stl.ends_with("does not fit in the f32 coordinates of STL"),
            "{stl}"
        );
        assert!(check_mesh(MeshFormat::Ply, &v, &[[0, 1, 2]]).is_ok());
        assert!(e(MeshFormat::Glb, &v[..2], &[]).contains("at least one"));
        // A mesh below f32's normal range would be written as zeros.
        let tiny = v.map(|p| p.map(|c| c * 1e-50));
        for format in [MeshFormat::Stl, MeshFormat::Glb, MeshFormat::Gltf] {
            let msg = e(format, &tiny[..2], &[[0, 1, 1]]);
            assert!(
                msg.contains("largest |coordinate| is 1e-50 (vertex 1)"),
                "{msg}"
            );
            assert!(msg.contains("write .ply or .obj"), "{msg}");
        }
        assert!(check_mesh(MeshFormat::Obj, &tiny[..2], &[[0, 1, 1]]).is_ok());
        // A tiny coordinate in a mesh of ordinary size is only rounded.
        let small = [[1e-50, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert!(check_mesh(MeshFormat::Stl, &small, &[[0, 1, 2]]).is_ok());
        // 0.1 apart 4·10⁶ from the origin, where f32 steps by 0.25: STL
        // would merge the vertices; glTF stores them about their centre.
        let far = [[0.0, 4e6, 0.0], [1.0, 4e6, 0.0], [0.0, 4e6 + 0.1, 0.0]];
        let stl = e(MeshFormat::Stl, &far, &[[0, 1, 2]]);
        assert!(stl.contains("flattens 1 face to zero area"), "{stl}");
        assert!(check_mesh(MeshFormat::Glb, &far, &[[0, 1, 2]]).is_ok());
        assert!(check_mesh(MeshFormat::Ply, &far, &[[0, 1, 2]]).is_ok());
        let nan = [[0.0, f64::NAN, 0.0]];
        assert_eq!(
            e(MeshFormat::Ply, &nan, &[]),
            "vertex 0 has a non-finite coordinate (0, NaN, 0)"
        );
    }
}
