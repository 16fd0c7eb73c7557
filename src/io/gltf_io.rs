//! glTF 2.0 meshes: `.gltf` (JSON) and `.glb` (binary container).
//!
//! The `gltf` crate parses and validates the document; the buffers and the
//! accessors are read here, with every offset and length checked, so a
//! malformed file gives an error naming the accessor instead of a panic.
//!
//! Reading: every node of the node hierarchy that has a mesh contributes all
//! of that mesh's primitives, their `POSITION`s transformed by the node's
//! world matrix (computed in `f64` from the `f32` matrices or translation,
//! rotation and scale). Primitives must have mode `TRIANGLES` (any other
//! mode is an error naming it); indices may be `u8`, `u16` or `u32`, or
//! absent (consecutive triples). Under a world matrix with a negative
//! determinant the triangles' winding is reversed, as the spec says, so
//! the output keeps counter-clockwise front faces. Buffers may be the GLB
//! binary chunk, `data:` URIs (base64) or files beside the `.gltf`.
//! Sparse accessors, quantised positions and Draco compression are not read.
//! Instances are counted before they are read, and a file whose instances
//! would make more than [`MAX_INSTANCED_VERTICES`] or
//! [`MAX_INSTANCED_TRIANGLES`] (beyond what it stores) is refused.
//!
//! Vertex attributes: `NORMAL` (float VEC3, turned by the world matrix's
//! inverse transpose and scaled to unit length), `COLOR_0` (float, or
//! normalised unsigned byte or short, RGB or RGBA) and `TEXCOORD_0`
//! (float, or normalised unsigned byte or short; v turned upwards, as
//! OBJ and PLY store it) are read when every primitive has them in those
//! types (otherwise the mesh is read without them); application-specific
//! scalar attributes (`_NAME`) as the file's own values ([`ScalarField`]);
//! the other attributes (more texture coordinate sets, tangents, joints)
//! are not. Primitives of one node that share every vertex accessor share
//! their vertices. Each face keeps its primitive's material, and the
//! materials, textures, samplers and images are kept to be written again
//! ([`super::gltf_materials`]).
//!
//! Writing: one mesh with one primitive, `f32` positions with the `min` and
//! `max` bounds the spec requires (about the mesh's centre, the node's
//! translation, when the mesh lies far from the origin:
//! [`f32_rounding::storage_origin`]), `u32` indices, and with the vertex
//! attributes given, unit `f32` `NORMAL`s, `COLOR_0` as normalised
//! unsigned bytes RGBA, `f32` `TEXCOORD_0` and the file's own values as
//! `_NAME` ([`holds_field`]); with a glTF input's materials, one primitive
//! per material over those accessors.

use std::borrow::Cow;
use std::collections::HashSet;
use std::io::Write;
use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};
use base64::Engine;
use byteorder::{ByteOrder, LittleEndian};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use super::gltf_materials::{self, NO_MATERIAL};
use super::hash::HashMap;
use super::ply::Scalar;
use super::{
    f32_rounding, is_written_name, show, unit_channel, Colours, Materials, Mesh, Point3,
    ScalarField, VertexAttributes,
};

/// Whether the bytes are a GLB container (the `glTF` magic).
pub fn is_glb(bytes: &[u8]) -> bool {
    bytes.starts_with(b"glTF")
}

/// Whether the bytes look like a glTF JSON document: an object with an
/// `"asset"` key near the start.
pub fn looks_like_json(bytes: &[u8]) -> bool {
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(4096)]);
    head.trim_start().starts_with('{') && head.contains("\"asset\"")
}

/// Reads the triangles of every mesh instance in a glTF or GLB file.
/// `dir` is where relative buffer URIs are resolved (the file's directory).
pub fn read_gltf(bytes: &[u8], dir: &Path) -> Result<Mesh> {
    let gltf = parse(bytes)?;
    let buffers = load_buffers(&gltf, dir)?;
    let instances = instances(&gltf.document)?;
    if instances.is_empty() {
        return Err(no_instances(gltf.document.meshes().len()));
    }
    check_expansion(&instances, &buffers)?;
    let mut mesh = Mesh {
        faces: Some(Vec::new()),
        ..Mesh::default()
    };
    // Each attribute is kept only if every primitive has it.
    let mut normals = Some(Vec::new());
    let mut colours = Some(Colours::default());
    let mut texcoords = Some(Vec::new());
    let mut fields = None;
    let mut face_materials = Vec::new();
    // Where the vertices of each instance's primitives start, by their
    // accessors: primitives that share every vertex accessor (a mesh
    // split by material over one vertex buffer) share their vertices.
    let mut read_at: HashMap<(usize, Vec<(String, usize)>), usize> = HashMap::default();
    for (k, instance) in instances.iter().enumerate() {
        let Instance {
            node,
            mesh: m,
            world,
        } = instance;
        for primitive in m.primitives() {
            let at = || {
                format!(
                    "node {}, mesh {}{}, primitive {}",
                    node.index(),
                    m.index(),
                    m.name().map(|n| format!(" '{n}'")).unwrap_or_default(),
                    primitive.index()
                )
            };
            let mut accessors: Vec<(String, usize)> = primitive
                .attributes()
                .map(|(semantic, accessor)| (format!("{semantic:?}"), accessor.index()))
                .collect();
            accessors.sort();
            let shared = read_at.get(&(k, accessors.clone())).copied();
            let base =
                add_primitive(&primitive, &buffers, world, &mut mesh, shared).with_context(at)?;
            let material = primitive
                .material()
                .index()
                .map_or(NO_MATERIAL, |m| m as u32);
            face_materials.resize(mesh.faces.as_ref().map_or(0, Vec::len), material);
            if shared.is_some() {
                continue;
            }
            read_at.insert((k, accessors), base);
            add_normals(&primitive, &buffers, world, &mut normals).with_context(at)?;
            add_colours(&primitive, &buffers, &mut colours).with_context(at)?;
            add_texcoords(&primitive, &buffers, &mut texcoords).with_context(at)?;
            add_fields(&primitive, &buffers, &mut fields).with_context(at)?;
        }
    }
    mesh.normals = normals;
    mesh.colours = colours;
    mesh.texcoords = texcoords;
    mesh.scalars = fields.unwrap_or_default();
    mesh.materials =
        gltf_materials::read(bytes, &gltf, &buffers, dir, face_materials)?.map(Materials::Gltf);
    Ok(mesh)
}

/// Appends the primitive's application-specific scalar attributes
/// (`_NAME`, float or 8- or 16-bit integers) to `fields`: the first
/// primitive names them, and a field goes where a later primitive lacks
/// it or stores it in another type. Normalised integers are read as the
/// fractions they stand for. Other custom attributes (vectors, or a name
/// the writer uses itself) are not read.
fn add_fields(
    primitive: &gltf::Primitive,
    buffers: &[Cow<[u8]>],
    fields: &mut Option<Vec<ScalarField>>,
) -> Result<()> {
    let found: Vec<(String, Scalar, gltf::Accessor)> = primitive
        .attributes()
        .filter_map(|(semantic, accessor)| match semantic {
            gltf::Semantic::Extras(name)
                if !is_written_name(&name) && accessor.dimensions() == Dimensions::Scalar =>
            {
                field_kind(&accessor).map(|kind| (name, kind, accessor))
            }
            _ => None,
        })
        .collect();
    let fields = fields.get_or_insert_with(|| {
        let field = |(name, kind, _): &(String, Scalar, _)| ScalarField {
            name: name.clone(),
            kind: *kind,
            values: Vec::new(),
        };
        found.iter().map(field).collect()
    });
    let in_this = |field: &ScalarField| {
        found
            .iter()
            .find(|(name, kind, _)| *name == field.name && *kind == field.kind)
            .map(|(_, _, accessor)| accessor.clone())
    };
    // A field goes where this primitive lacks it or stores it otherwise.
    fields.retain(|field| in_this(field).is_some());
    for field in fields.iter_mut() {
        let Some(accessor) = in_this(field) else {
            continue;
        };
        let accessor = &accessor;
        let what = format!("_{}", field.name);
        check_count(accessor, primitive, &what)?;
        let size = accessor.data_type().size();
        let (data, stride) = accessor_data(accessor, buffers, size, &what)?;
        let normalized = accessor.normalized();
        let value = |b: &[u8]| match accessor.data_type() {
            DataType::I8 if normalized => (f64::from(b[0] as i8) / 127.0).max(-1.0),
            DataType::U8 if normalized => f64::from(b[0]) / 255.0,
            DataType::I16 if normalized => {
                (f64::from(LittleEndian::read_i16(b)) / 32767.0).max(-1.0)
            }
            DataType::U16 if normalized => f64::from(LittleEndian::read_u16(b)) / 65535.0,
            DataType::I8 => f64::from(b[0] as i8),
            DataType::U8 => f64::from(b[0]),
            DataType::I16 => f64::from(LittleEndian::read_i16(b)),
            DataType::U16 => f64::from(LittleEndian::read_u16(b)),
            DataType::U32 => f64::from(LittleEndian::read_u32(b)),
            DataType::F32 => f64::from(LittleEndian::read_f32(b)),
        };
        field
            .values
            .extend((0..accessor.count()).map(|i| value(&data[i * stride..])));
    }
    Ok(())
}

/// The type a scalar custom attribute's values are kept as.
fn field_kind(accessor: &gltf::Accessor) -> Option<Scalar> {
    if accessor.normalized() {
        return (accessor.data_type() != DataType::F32).then_some(Scalar::F32);
    }
    Some(match accessor.data_type() {
        DataType::I8 => Scalar::I8,
        DataType::U8 => Scalar::U8,
        DataType::I16 => Scalar::I16,
        DataType::U16 => Scalar::U16,
        DataType::U32 => Scalar::U32,
        DataType::F32 => Scalar::F32,
    })
}

/// Whether glTF holds `field` as an application-specific attribute:
/// 8- and 16-bit integers in their own types; the others as `f32`, so
/// their values must be finite, and 32-bit integers within ±2^24, where
/// `f32` holds every integer (a bit mask beyond would change).
pub fn holds_field(field: &ScalarField) -> bool {
    match field.kind {
        Scalar::I8 | Scalar::U8 | Scalar::I16 | Scalar::U16 => true,
        Scalar::I32 | Scalar::U32 => field.values.iter().all(|v| v.abs() <= 16_777_216.0),
        Scalar::F32 | Scalar::F64 => field
            .values
            .iter()
            .all(|&v| v.is_finite() && (v as f32).is_finite()),
    }
}

/// The component type a held field is written as: its own for 8- and
/// 16-bit integers, `FLOAT` for the others.
fn written_component(kind: Scalar) -> (u32, usize) {
    match kind {
        Scalar::I8 => (5120, 1),
        Scalar::U8 => (5121, 1),
        Scalar::I16 => (5122, 2),
        Scalar::U16 => (5123, 2),
        _ => (5126, 4),
    }
}

/// Appends the primitive's `NORMAL`s, turned into world coordinates by
/// the inverse transpose of the world matrix and scaled to unit length,
/// to `normals`; without them, `normals` becomes `None`.
fn add_normals(
    primitive: &gltf::Primitive,
    buffers: &[Cow<[u8]>],
    world: &Matrix,
    normals: &mut Option<Vec<Point3>>,
) -> Result<()> {
    let (Some(list), Some(accessor)) = (normals.as_mut(), primitive.get(&gltf::Semantic::Normals))
    else {
        *normals = None;
        return Ok(());
    };
    // Normals of another type (quantised ones) are not read: the mesh
    // goes without them rather than not at all.
    if accessor.data_type() != DataType::F32 || accessor.dimensions() != Dimensions::Vec3 {
        *normals = None;
        return Ok(());
    }
    check_count(&accessor, primitive, "NORMAL")?;
    let (data, stride) = accessor_data(&accessor, buffers, 12, "NORMAL")?;
    let turn = normal_matrix(world);
    for i in 0..accessor.count() {
        let record = &data[i * stride..];
        let local = [0, 4, 8].map(|o| f64::from(LittleEndian::read_f32(&record[o..])));
        let n = turn.map(|row| row[0] * local[0] + row[1] * local[1] + row[2] * local[2]);
        let length = n.iter().map(|c| c * c).sum::<f64>().sqrt();
        // A zero or non-finite normal stays as it is: the carrying takes
        // a non-finite one as no direction.
        list.push(if length > 0.0 && length.is_finite() {
            n.map(|c| c / length)
        } else {
            n
        });
    }
    Ok(())
}

/// The rows of the matrix that turns normals as the world matrix turns
/// surfaces: its 3×3 part's inverse transpose, up to a positive factor
/// (the cofactor matrix, its sign the determinant's).
fn normal_matrix(m: &Matrix) -> [[f64; 3]; 3] {
    // a[row][col] of the 3×3 part (glTF matrices are column-major).
    let a = |row: usize, col: usize| m[col][row];
    let sign = if determinant3(m) < 0.0 { -1.0 } else { 1.0 };
    let cofactor = |row: usize, col: usize| {
        let (r0, r1) = ((row + 1) % 3, (row + 2) % 3);
        let (c0, c1) = ((col + 1) % 3, (col + 2) % 3);
        sign * (a(r0, c0) * a(r1, c1) - a(r0, c1) * a(r1, c0))
    };
    [0, 1, 2].map(|row| [0, 1, 2].map(|col| cofactor(row, col)))
}

/// Appends the primitive's `COLOR_0` (float, or normalised unsigned byte
/// or short, RGB or RGBA) to `colours`; without it, `colours` becomes
/// `None`.
fn add_colours(
    primitive: &gltf::Primitive,
    buffers: &[Cow<[u8]>],
    colours: &mut Option<Colours>,
) -> Result<()> {
    let (Some(list), Some(accessor)) =
        (colours.as_mut(), primitive.get(&gltf::Semantic::Colors(0)))
    else {
        *colours = None;
        return Ok(());
    };
    // Colours of a type the spec does not allow are not read: the mesh
    // goes without them rather than not at all.
    let channels = match accessor.dimensions() {
        Dimensions::Vec3 => 3,
        Dimensions::Vec4 => 4,
        _ => {
            *colours = None;
            return Ok(());
        }
    };
    let Some((bytes, scale)) = unit_components(&accessor) else {
        *colours = None;
        return Ok(());
    };
    check_count(&accessor, primitive, "COLOR_0")?;
    let (data, stride) = accessor_data(&accessor, buffers, channels * bytes, "COLOR_0")?;
    list.alpha |= channels == 4;
    for i in 0..accessor.count() {
        let record = &data[i * stride..];
        let mut rgba = [1.0; 4];
        for (c, slot) in rgba.iter_mut().enumerate().take(channels) {
            *slot = unit_channel(component(&record[c * bytes..], bytes, scale));
        }
        list.rgba.push(rgba);
    }
    Ok(())
}

/// The size and scale of an accessor's components when they are floats,
/// or normalised unsigned bytes or shorts (as `COLOR_0` and `TEXCOORD_0`
/// may be); `None` for another type.
fn unit_components(accessor: &gltf::Accessor) -> Option<(usize, f64)> {
    match (accessor.data_type(), accessor.normalized()) {
        (DataType::F32, _) => Some((4, 1.0)),
        (DataType::U8, true) => Some((1, 1.0 / 255.0)),
        (DataType::U16, true) => Some((2, 1.0 / 65535.0)),
        _ => None,
    }
}

/// The component of `size` bytes at the start of `b`, scaled.
fn component(b: &[u8], size: usize, scale: f64) -> f64 {
    match size {
        4 => f64::from(LittleEndian::read_f32(b)) * scale,
        2 => f64::from(LittleEndian::read_u16(b)) * scale,
        _ => f64::from(b[0]) * scale,
    }
}

/// Appends the primitive's `TEXCOORD_0` (float, or normalised unsigned
/// byte or short) to `texcoords`, v turned upwards (1 − v) as OBJ and
/// PLY store it; without it, `texcoords` becomes `None`.
fn add_texcoords(
    primitive: &gltf::Primitive,
    buffers: &[Cow<[u8]>],
    texcoords: &mut Option<Vec<[f64; 2]>>,
) -> Result<()> {
    let (Some(list), Some(accessor)) = (
        texcoords.as_mut(),
        primitive.get(&gltf::Semantic::TexCoords(0)),
    ) else {
        *texcoords = None;
        return Ok(());
    };
    let components = unit_components(&accessor);
    let (Some((bytes, scale)), Dimensions::Vec2) = (components, accessor.dimensions()) else {
        *texcoords = None;
        return Ok(());
    };
    check_count(&accessor, primitive, "TEXCOORD_0")?;
    let (data, stride) = accessor_data(&accessor, buffers, 2 * bytes, "TEXCOORD_0")?;
    for i in 0..accessor.count() {
        let record = &data[i * stride..];
        let [u, v] = [0, bytes].map(|o| component(&record[o..], bytes, scale));
        // A NaN coordinate has no place on the image: the image's corner.
        let finite = |c: f64| if c.is_finite() { c } else { 0.0 };
        list.push([finite(u), 1.0 - finite(v)]);
    }
    Ok(())
}

/// An attribute's accessor must have one element per position.
fn check_count(accessor: &gltf::Accessor, primitive: &gltf::Primitive, what: &str) -> Result<()> {
    let positions = primitive
        .get(&gltf::Semantic::Positions)
        .map_or(0, |p| p.count());
    if accessor.count() != positions {
        bail!(
            "accessor {} ({what}) has {} elements for {positions} positions",
            accessor.index(),
            accessor.count()
        );
    }
    Ok(())
}

/// Why a file without mesh instances has no vertices. Meshes that no node
/// uses are not read: a mesh has no place of its own (its positions are
/// in the frame of the node that uses it), and files keep unused meshes
/// as spares, so reading them where they stand could add geometry that is
/// in no scene.
fn no_instances(meshes: usize) -> anyhow::Error {
    match meshes {
        0 => anyhow!("the file has no meshes"),
        n => anyhow!(
            "no node uses a mesh (the file has {n} mesh{}): glTF places a mesh only \
             through a node that uses it, and meshes that no node uses are not read",
            if n == 1 { "" } else { "es" }
        ),
    }
}

/// A node that places a mesh, and its world matrix.
struct Instance<'a> {
    node: gltf::Node<'a>,
    mesh: gltf::Mesh<'a>,
    world: Matrix,
}

/// The nodes that have a mesh, in depth-first order from the nodes that
/// are nobody's child, with their world matrices. A node with two parents
/// or in a cycle is an error.
fn instances(document: &gltf::Document) -> Result<Vec<Instance<'_>>> {
    let nodes = document.nodes().len();
    let mut has_parent = vec![false; nodes];
    for node in document.nodes() {
        for child in node.children() {
            has_parent[child.index()] = true;
        }
    }
    let mut visited = vec![false; nodes];
    let mut stack: Vec<(gltf::Node, Matrix)> = document
        .nodes()
        .filter(|n| !has_parent[n.index()])
        .map(|n| (n, IDENTITY))
        .collect();
    stack.reverse();
    let mut out = Vec::new();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut visited[node.index()], true) {
            bail!("node {} is reached twice: it has two parents", node.index());
        }
        let world = multiply(&parent, &local_matrix(&node)?);
        let children: Vec<_> = node.children().collect();
        for child in children.into_iter().rev() {
            stack.push((child, world));
        }
        if let Some(mesh) = node.mesh() {
            out.push(Instance { node, mesh, world });
        }
    }
    if let Some(n) = visited.iter().position(|v| !v) {
        bail!("node {n} is in a cycle of the node hierarchy");
    }
    Ok(out)
}

/// Most vertices that instancing may make: 100 million, 2.4 GB as the
/// `f64` x, y, z the reader returns. Every node that uses a mesh gets its
/// own copy of the mesh's vertices, so a file of a few megabytes (one
/// large accessor, thousands of nodes) could otherwise ask for tens of
/// gigabytes. A file that stores more vertices itself is still read whole,
/// as a PLY of that size would be: then the memory follows the file size.
pub const MAX_INSTANCED_VERTICES: usize = 100_000_000;

/// Most triangles that instancing may make: 200 million (a closed mesh has
/// about twice as many triangles as vertices), 2.4 GB as `u32` corners.
/// The same rule as [`MAX_INSTANCED_VERTICES`]; it matters on its own
/// because a `u8` index takes one byte in the file and four in memory.
pub const MAX_INSTANCED_TRIANGLES: usize = 200_000_000;

/// Refuses a file whose instances would make more vertices or triangles
/// than [`MAX_INSTANCED_VERTICES`] and [`MAX_INSTANCED_TRIANGLES`] allow,
/// before anything is allocated for them. Only accessors whose data lies
/// in their buffer count, so the totals are backed by real bytes; a broken
/// accessor gets its own error when its primitive is read.
fn check_expansion(instances: &[Instance], buffers: &[Cow<[u8]>]) -> Result<()> {
    let mut e = Expansion::default();
    for instance in instances {
        for primitive in instance.mesh.primitives() {
            if let Some(counts) = primitive_counts(&primitive, buffers) {
                e.add(&counts);
            }
        }
    }
    let limits = [
        (
            "vertices",
            e.made[0],
            e.stored[0],
            MAX_INSTANCED_VERTICES,
            24,
        ),
        (
            "triangles",
            e.made[1] / 3,
            e.stored[1] / 3,
            MAX_INSTANCED_TRIANGLES,
            12,
        ),
    ];
    for (what, made, stored, cap, bytes) in limits {
        if made > cap.max(stored) {
            bail!(
                "the {} nodes that use meshes would make {made} {what} (the file stores \
                 {stored}), more than the limit of {cap} ({:.1} GB in memory) for instanced \
                 meshes; use fewer nodes per mesh, or save the scene flattened (a copy per \
                 instance) as PLY or OBJ, which have no such limit",
                instances.len(),
                (cap * bytes) as f64 / 1e9
            );
        }
    }
    Ok(())
}

/// Vertices and triangle corners: those the instances make, and those
/// the file stores (each accessor once).
#[derive(Default)]
struct Expansion {
    made: [usize; 2],
    stored: [usize; 2],
    seen_positions: HashSet<usize>,
    seen_corners: HashSet<(usize, Option<usize>)>,
}

impl Expansion {
    fn add(&mut self, c: &PrimitiveCounts) {
        let add = |total: &mut usize, n: usize| *total = total.saturating_add(n);
        add(&mut self.made[0], c.vertices);
        add(&mut self.made[1], c.corners);
        if self.seen_positions.insert(c.positions) {
            add(&mut self.stored[0], c.vertices);
        }
        if self.seen_corners.insert(c.corner_source) {
            add(&mut self.stored[1], c.corners);
        }
    }
}

/// A primitive's vertex and corner counts and the accessors they come from.
struct PrimitiveCounts {
    positions: usize,
    vertices: usize,
    /// The indices accessor, or `None` for consecutive triples of the
    /// positions.
    corner_source: (usize, Option<usize>),
    corners: usize,
}

/// `None` when an accessor is missing or its data does not lie in its
/// buffer: the primitive's reading reports that.
fn primitive_counts(primitive: &gltf::Primitive, buffers: &[Cow<[u8]>]) -> Option<PrimitiveCounts> {
    let positions = primitive.get(&gltf::Semantic::Positions)?;
    accessor_data(&positions, buffers, 12, "POSITION").ok()?;
    let (corner_source, corners) = match primitive.indices() {
        Some(indices) => {
            // The smallest index size: any index takes at least a byte.
            accessor_data(&indices, buffers, 1, "indices").ok()?;
            ((positions.index(), Some(indices.index())), indices.count())
        }
        None => ((positions.index(), None), positions.count()),
    };
    Some(PrimitiveCounts {
        positions: positions.index(),
        vertices: positions.count(),
        corner_source,
        corners,
    })
}

/// Parses and validates the document. The accessor indices of mesh
/// attributes are checked first, because gltf-json 1.4.1's validation
/// indexes the `POSITION` accessor without a bounds check (and panics).
fn parse(bytes: &[u8]) -> Result<gltf::Gltf> {
    let malformed = |e: gltf::Error| anyhow!("malformed glTF: {e}");
    let raw = gltf::Gltf::from_slice_without_validation(bytes).map_err(malformed)?;
    let blob = raw.blob;
    let json = raw.document.into_json();
    let accessors = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let used = primitive.attributes.values().chain(&primitive.indices);
            if let Some(bad) = used.map(|a| a.value()).find(|&a| a >= accessors) {
                bail!(
                    "malformed glTF: mesh {m}, primitive {p} refers to accessor {bad}, \
                     but there are only {accessors}"
                );
            }
        }
    }
    let document = gltf::Document::from_json(json).map_err(malformed)?;
    Ok(gltf::Gltf { document, blob })
}

/// The bytes of every buffer, checked against its declared length.
fn load_buffers<'a>(gltf: &'a gltf::Gltf, dir: &Path) -> Result<Vec<Cow<'a, [u8]>>> {
    let mut out = Vec::new();
    for buffer in gltf.document.buffers() {
        let i = buffer.index();
        let data: Cow<[u8]> = match buffer.source() {
            gltf::buffer::Source::Bin => Cow::Borrowed(gltf.blob.as_deref().ok_or_else(|| {
                anyhow!("buffer {i} refers to a GLB binary chunk, and there is none")
            })?),
            // An empty relative reference names the document itself (here
            // its directory), which is never the buffer: say what is wrong.
            gltf::buffer::Source::Uri("") => bail!(
                "buffer {i} has an empty URI: it needs the name of a file beside the \
                 document or a base64 data: URI"
            ),
            gltf::buffer::Source::Uri(uri) => Cow::Owned(
                uri_bytes(uri, dir, Some(buffer.length()))
                    .with_context(|| format!("buffer {i}"))?,
            ),
        };
        if data.len() < buffer.length() {
            bail!(
                "buffer {i} has {} bytes, its byteLength says {}",
                data.len(),
                buffer.length()
            );
        }
        out.push(data);
    }
    Ok(out)
}

/// The data a URI names: a base64 `data:` URI, or a file relative to the
/// document's directory `dir` as RFC 3986 resolves it (`../shared/mesh.bin`,
/// as asset pipelines share buffers, and a path-absolute `/data/mesh.bin`
/// name files on this machine). Only a regular file is read, and only its
/// first `length` bytes when given.
pub(crate) fn uri_bytes(uri: &str, dir: &Path, length: Option<usize>) -> Result<Vec<u8>> {
    if uri.starts_with("data:") {
        return decode_data_uri(uri);
    }
    refuse_schemes(uri)?;
    let path = dir.join(percent_decode(uri));
    read_regular_file(&path, length).with_context(|| format!("cannot read '{}'", path.display()))
}

/// A URI with a scheme (RFC 3986: a letter, then letters, digits, `+`,
/// `-` or `.`, then `:`) other than `data:` is not read: `http:` and its
/// kind would need the network, and a `file:` URI, absolute by nature, is
/// refused with the form a portable asset uses instead.
fn refuse_schemes(uri: &str) -> Result<()> {
    let Some((scheme, _)) = uri.split_once(':') else {
        return Ok(());
    };
    let is_scheme = scheme.starts_with(|c: char| c.is_ascii_alphabetic())
        && scheme
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'));
    if !is_scheme {
        return Ok(());
    }
    if scheme.eq_ignore_ascii_case("file") {
        bail!(
            "file URI '{uri}' is not supported: name the buffer relative to the document \
             (e.g. 'mesh.bin' or '../shared/mesh.bin') or embed it as a base64 data: URI"
        );
    }
    bail!("URI '{uri}' is not supported: only files relative to the document and base64 data: URIs are read")
}

/// The first `length` bytes (all when `None`) of an external file, which
/// must be a regular file. The URI comes from the document and may name
/// anything: a FIFO's opening waits for a writer forever, and a device
/// such as `/dev/zero` (an absolute or `..` path) never ends, so reading
/// it would hang or fill the memory. Bytes past `length` are not needed.
fn read_regular_file(path: &Path, length: Option<usize>) -> Result<Vec<u8>> {
    use std::io::Read;
    // Checked before opening: opening a FIFO blocks.
    if !std::fs::metadata(path)?.is_file() {
        bail!("not a regular file");
    }
    let mut data = Vec::new();
    let limit = length.map_or(u64::MAX, |l| l as u64);
    std::fs::File::open(path)?
        .take(limit)
        .read_to_end(&mut data)?;
    Ok(data)
}

fn decode_data_uri(uri: &str) -> Result<Vec<u8>> {
    let (_, data) = uri
        .split_once(";base64,")
        .ok_or_else(|| anyhow!("only base64 data URIs are supported"))?;
    base64::engine::general_purpose::STANDARD
        .decode(data.trim())
        .map_err(|e| anyhow!("bad base64 in the data URI: {e}"))
}

/// Undoes `%XX` escapes in a relative URI; other bytes are kept.
fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            if let (Some(h), Some(l)) = (hex(bytes[i + 1]), hex(bytes[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// A column-major 4×4 matrix, as glTF stores them.
type Matrix = [[f64; 4]; 4];

const IDENTITY: Matrix = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

fn local_matrix(node: &gltf::Node) -> Result<Matrix> {
    Ok(match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => matrix.map(|c| c.map(f64::from)),
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            let [t, s] = [translation, scale].map(|v| v.map(f64::from));
            let [x, y, z, w] =
                unit_rotation(rotation).with_context(|| format!("node {}", node.index()))?;
            // The unit quaternion's rotation matrix, columns scaled by s.
            let r = [
                [
                    1.0 - 2.0 * (y * y + z * z),
                    2.0 * (x * y + z * w),
                    2.0 * (x * z - y * w),
                ],
                [
                    2.0 * (x * y - z * w),
                    1.0 - 2.0 * (x * x + z * z),
                    2.0 * (y * z + x * w),
                ],
                [
                    2.0 * (x * z + y * w),
                    2.0 * (y * z - x * w),
                    1.0 - 2.0 * (x * x + y * y),
                ],
            ];
            [
                [r[0][0] * s[0], r[0][1] * s[0], r[0][2] * s[0], 0.0],
                [r[1][0] * s[1], r[1][1] * s[1], r[1][2] * s[1], 0.0],
                [r[2][0] * s[2], r[2][1] * s[2], r[2][2] * s[2], 0.0],
                [t[0], t[1], t[2], 1.0],
            ]
        }
    })
}

/// How far a rotation quaternion's length may be from 1 and still be read
/// (as the unit quaternion of its direction): the rounding of f32
/// components written by exporters, with room to spare.
const QUATERNION_TOLERANCE: f64 = 1e-3;

/// A node's rotation as a unit quaternion (x, y, z, w). glTF requires unit
/// quaternions; the rotation matrix formula assumes one, and for any other
/// it distorts the mesh instead of turning it, silently. Lengths within
/// [`QUATERNION_TOLERANCE`] of 1 are normalised; others are an error.
fn unit_rotation(rotation: [f32; 4]) -> Result<[f64; 4]> {
    let q = rotation.map(f64::from);
    let length = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    // Written so that a NaN length (an infinite component) fails too.
    let unit = (length - 1.0).abs() <= QUATERNION_TOLERANCE;
    if !unit {
        bail!(
            "the rotation quaternion {q:?} has length {length}: glTF requires a unit quaternion \
             (within {QUATERNION_TOLERANCE} here)"
        );
    }
    Ok(q.map(|c| c / length))
}

fn multiply(a: &Matrix, b: &Matrix) -> Matrix {
    let mut out = [[0.0; 4]; 4];
    for (col, out_col) in out.iter_mut().enumerate() {
        for (row, value) in out_col.iter_mut().enumerate() {
            *value = (0..4).map(|k| a[k][row] * b[col][k]).sum();
        }
    }
    out
}

fn apply(m: &Matrix, p: [f64; 3]) -> Point3 {
    let mut out = [0.0; 3];
    for (row, value) in out.iter_mut().enumerate() {
        *value = m[0][row] * p[0] + m[1][row] * p[1] + m[2][row] * p[2] + m[3][row];
    }
    out
}

fn determinant3(m: &Matrix) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2])
        - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
        + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2])
}

fn mode_name(mode: Mode) -> &'static str {
    match mode {
        Mode::Points => "POINTS",
        Mode::Lines => "LINES",
        Mode::LineLoop => "LINE_LOOP",
        Mode::LineStrip => "LINE_STRIP",
        Mode::Triangles => "TRIANGLES",
        Mode::TriangleStrip => "TRIANGLE_STRIP",
        Mode::TriangleFan => "TRIANGLE_FAN",
    }
}

fn add_primitive(
    primitive: &gltf::Primitive,
    buffers: &[Cow<[u8]>],
    world: &Matrix,
    mesh: &mut Mesh,
    shared: Option<usize>,
) -> Result<usize> {
    if primitive.mode() != Mode::Triangles {
        bail!(
            "mode {} is not supported, only TRIANGLES",
            mode_name(primitive.mode())
        );
    }
    let positions = primitive
        .get(&gltf::Semantic::Positions)
        .ok_or_else(|| anyhow!("no POSITION attribute"))?;
    if positions.data_type() != DataType::F32
        || positions.dimensions() != Dimensions::Vec3
        || positions.normalized()
    {
        bail!(
            "accessor {} (POSITION) is {:?} {:?}, only float VEC3 positions are supported",
            positions.index(),
            positions.data_type(),
            positions.dimensions()
        );
    }
    let count = positions.count();
    if let Some(base) = shared {
        add_faces(primitive, buffers, world, base, count, mesh)?;
        return Ok(base);
    }
    let base = mesh.vertices.len();
    let new_total = base
        .checked_add(count)
        .filter(|&n| n <= u32::MAX as usize + 1)
        .ok_or_else(|| anyhow!("more than {} vertices in all", u32::MAX))?;
    let (data, stride) = accessor_data(&positions, buffers, 12, "POSITION")?;
    mesh.vertices.reserve(count);
    for i in 0..count {
        let record = &data[i * stride..];
        let local = [0, 4, 8].map(|o| f64::from(LittleEndian::read_f32(&record[o..])));
        let p = apply(world, local);
        if p.iter().any(|c| !c.is_finite()) {
            bail!(
                "POSITION {i} is non-finite in world coordinates: {}",
                show(&p)
            );
        }
        mesh.vertices.push(p);
    }
    debug_assert_eq!(mesh.vertices.len(), new_total);
    add_faces(primitive, buffers, world, base, count, mesh)?;
    Ok(base)
}

/// Appends the primitive's triangles, its `count` vertices being the
/// mesh's from `base` on.
fn add_faces(
    primitive: &gltf::Primitive,
    buffers: &[Cow<[u8]>],
    world: &Matrix,
    base: usize,
    count: usize,
    mesh: &mut Mesh,
) -> Result<()> {
    let corners: Vec<u32> = match primitive.indices() {
        Some(indices) => read_indices(&indices, buffers, count)?,
        None => (0..count as u32).collect(),
    };
    if !corners.chunks_exact(3).remainder().is_empty() {
        bail!(
            "{} triangle corners, which is not a multiple of 3",
            corners.len()
        );
    }
    let flip = determinant3(world) < 0.0;
    let faces = mesh.faces.get_or_insert_with(Vec::new);
    faces.reserve(corners.len() / 3);
    for t in corners.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|v| v + base as u32);
        faces.push(if flip { [a, c, b] } else { [a, b, c] });
    }
    Ok(())
}

fn read_indices(
    indices: &gltf::Accessor,
    buffers: &[Cow<[u8]>],
    vertices: usize,
) -> Result<Vec<u32>> {
    let size = match (indices.data_type(), indices.dimensions()) {
        (DataType::U8, Dimensions::Scalar) => 1,
        (DataType::U16, Dimensions::Scalar) => 2,
        (DataType::U32, Dimensions::Scalar) => 4,
        (t, d) => bail!(
            "accessor {} (indices) is {t:?} {d:?}, indices must be an unsigned scalar",
            indices.index()
        ),
    };
    let (data, stride) = accessor_data(indices, buffers, size, "indices")?;
    let mut out = Vec::with_capacity(indices.count());
    for i in 0..indices.count() {
        let b = &data[i * stride..];
        let v = match size {
            1 => u32::from(b[0]),
            2 => u32::from(LittleEndian::read_u16(b)),
            _ => LittleEndian::read_u32(b),
        };
        if v as usize >= vertices {
            bail!(
                "index {i} (triangle {}) refers to vertex {v}, but the primitive has only {vertices} vertices",
                i / 3
            );
        }
        out.push(v);
    }
    Ok(out)
}

/// The bytes of an accessor from its first element on, and its stride,
/// with every element (`size` bytes each) checked to lie inside the view.
fn accessor_data<'b>(
    accessor: &gltf::Accessor,
    buffers: &'b [Cow<[u8]>],
    size: usize,
    what: &str,
) -> Result<(&'b [u8], usize)> {
    let a = accessor.index();
    if accessor.sparse().is_some() {
        bail!("accessor {a} ({what}) is sparse, which is not supported");
    }
    let view = accessor
        .view()
        .ok_or_else(|| anyhow!("accessor {a} ({what}) has no buffer view"))?;
    let buffer = &buffers[view.buffer().index()];
    let view_data = view
        .offset()
        .checked_add(view.length())
        .and_then(|end| buffer.get(view.offset()..end))
        .ok_or_else(|| {
            anyhow!(
                "buffer view {} (bytes {}..+{}) lies outside buffer {} ({} bytes)",
                view.index(),
                view.offset(),
                view.length(),
                view.buffer().index(),
                buffer.len()
            )
        })?;
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        bail!(
            "buffer view {} has a byteStride of {stride}, less than the {size}-byte elements of accessor {a}",
            view.index()
        );
    }
    let count = accessor.count();
    let needed = match count {
        0 => Some(accessor.offset()),
        n => (n - 1)
            .checked_mul(stride)
            .and_then(|b| b.checked_add(size))
            .and_then(|b| b.checked_add(accessor.offset())),
    };
    match needed {
        Some(n) if n <= view_data.len() => Ok((&view_data[accessor.offset()..], stride)),
        _ => bail!(
            "accessor {a} ({what}): {count} elements from byte {} do not fit in buffer view {} ({} bytes)",
            accessor.offset(),
            view.index(),
            view_data.len()
        ),
    }
}

/// The glTF JSON document and binary buffer of one mesh (the buffer
/// without a URI: the GLB binary chunk, or `.gltf`'s data URI set by
/// [`write_gltf`]). Normals, when given,
/// are written as unit `f32` vectors (as the spec requires: a zero one as
/// +z); colours as `COLOR_0`, normalised unsigned bytes RGBA; texture
/// coordinates as `f32` `TEXCOORD_0`, v turned down the image.
fn document(
    vertices: &[Point3],
    faces: &[[u32; 3]],
    attributes: &VertexAttributes,
) -> (serde_json::Value, Vec<u8>) {
    let mut bin = Vec::with_capacity(12 * (vertices.len() + faces.len()));
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    let origin = f32_rounding::storage_origin(vertices);
    for p in vertices {
        for (k, c) in f32_rounding::stored(p, origin).into_iter().enumerate() {
            min[k] = min[k].min(c);
            max[k] = max[k].max(c);
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    let mut accessors = vec![serde_json::json!({
        "bufferView": 0, "componentType": 5126, "count": vertices.len(), "type": "VEC3",
        "min": min.map(f64::from), "max": max.map(f64::from)
    })];
    let mut views = vec![serde_json::json!({
        "buffer": 0, "byteOffset": 0, "byteLength": bin.len(), "target": 34962
    })];
    let mut primitive_attributes = serde_json::json!({ "POSITION": 0 });
    let mut add_view = |bin: &Vec<u8>, start: usize, target: u32, stride: Option<usize>| {
        let mut view = serde_json::json!({
            "buffer": 0, "byteOffset": start, "byteLength": bin.len() - start, "target": target
        });
        if let Some(stride) = stride {
            view["byteStride"] = stride.into();
        }
        views.push(view);
        views.len() - 1
    };
    if let Some(normals) = &attributes.normals {
        let start = bin.len();
        for n in normals {
            for c in unit_normal(*n) {
                bin.extend_from_slice(&c.to_le_bytes());
            }
        }
        let view = add_view(&bin, start, 34962, None);
        primitive_attributes["NORMAL"] = accessors.len().into();
        accessors.push(serde_json::json!({
            "bufferView": view, "componentType": 5126, "count": vertices.len(), "type": "VEC3"
        }));
    }
    if let Some(colours) = &attributes.colours {
        let start = bin.len();
        for rgba in &colours.rgba {
            bin.extend(rgba.iter().map(|&c| super::mesh_out::channel_byte(c)));
        }
        let view = add_view(&bin, start, 34962, None);
        primitive_attributes["COLOR_0"] = accessors.len().into();
        accessors.push(serde_json::json!({
            "bufferView": view, "componentType": 5121, "normalized": true,
            "count": vertices.len(), "type": "VEC4"
        }));
    }
    if let Some(texcoords) = &attributes.texcoords {
        let start = bin.len();
        for &[u, v] in texcoords {
            // glTF's v runs down the image.
            for c in [u, 1.0 - v] {
                bin.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        let view = add_view(&bin, start, 34962, None);
        primitive_attributes["TEXCOORD_0"] = accessors.len().into();
        accessors.push(serde_json::json!({
            "bufferView": view, "componentType": 5126, "count": vertices.len(), "type": "VEC2"
        }));
    }
    for field in &attributes.scalars {
        // Each element starts on 4 bytes, as the spec requires of vertex
        // attributes: 8- and 16-bit values are padded to a stride of 4.
        let (component, size) = written_component(field.kind);
        let start = bin.len();
        for &v in &field.values {
            if component == 5126 {
                bin.extend((v as f32).to_le_bytes());
            } else {
                field.kind.push_le(&mut bin, v);
                bin.resize(bin.len() + 4 - size, 0);
            }
        }
        let view = add_view(&bin, start, 34962, (size < 4).then_some(4));
        primitive_attributes[format!("_{}", field.name)] = accessors.len().into();
        accessors.push(serde_json::json!({
            "bufferView": view, "componentType": component, "count": vertices.len(),
            "type": "SCALAR"
        }));
    }
    // One primitive per material (the faces grouped), or one for all.
    let gltf_materials = match &attributes.materials {
        Some(Materials::Gltf(materials)) => Some(materials),
        _ => None,
    };
    let groups = match gltf_materials {
        Some(materials) => materials.groups(),
        None => vec![(NO_MATERIAL, (0..faces.len() as u32).collect())],
    };
    let mut primitives = Vec::new();
    for (material, group) in groups {
        let start = bin.len();
        for &f in &group {
            for v in faces[f as usize] {
                bin.extend_from_slice(&v.to_le_bytes());
            }
        }
        let indices_view = add_view(&bin, start, 34963, None);
        let mut primitive = serde_json::json!({
            "attributes": primitive_attributes, "indices": accessors.len(), "mode": 4
        });
        if material != NO_MATERIAL {
            primitive["material"] = material.into();
        }
        primitives.push(primitive);
        accessors.push(serde_json::json!({
            "bufferView": indices_view, "componentType": 5125, "count": 3 * group.len(),
            "type": "SCALAR"
        }));
    }
    let mut node = serde_json::json!({ "mesh": 0 });
    if let Some(origin) = origin {
        node["translation"] = origin.into();
    }
    let mut json = serde_json::json!({
        "asset": { "version": "2.0", "generator": "meshtrim" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [node],
        "meshes": [{ "primitives": primitives }],
        "accessors": accessors,
    });
    if let Some(materials) = gltf_materials {
        gltf_materials::write(materials, &mut json, &mut views, &mut bin);
    }
    json["bufferViews"] = views.into();
    json["buffers"] = serde_json::json!([{ "byteLength": bin.len() }]);
    (json, bin)
}

/// A normal as the unit `f32` vector glTF requires (+z for a zero one).
fn unit_normal(n: Point3) -> [f32; 3] {
    let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if length > 0.0 && length.is_finite() {
        n.map(|c| (c / length) as f32)
    } else {
        [0.0, 0.0, 1.0]
    }
}

fn empty_error(vertices: &[Point3], faces: &[[u32; 3]]) -> std::io::Result<()> {
    if vertices.is_empty() || faces.is_empty() {
        return Err(std::io::Error::other(
            "glTF needs at least one vertex and one triangle (accessors cannot be empty)",
        ));
    }
    Ok(())
}

/// Writes a `.glb`: a JSON chunk (padded with spaces) and a binary chunk.
///
/// The caller checks the face indices and that coordinates fit in `f32`.
pub fn write_glb(
    w: &mut dyn Write,
    vertices: &[Point3],
    faces: &[[u32; 3]],
    attributes: &VertexAttributes,
) -> std::io::Result<()> {
    empty_error(vertices, faces)?;
    let (json, bin) = document(vertices, faces, attributes);
    let mut json = serde_json::to_vec(&json).map_err(std::io::Error::other)?;
    json.resize(json.len().next_multiple_of(4), b' ');
    // The binary data is a multiple of 4 bytes already (f32, u32 and
    // four bytes of colour per vertex).
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let total = u32::try_from(total).map_err(|_| std::io::Error::other("GLB larger than 4 GiB"))?;
    w.write_all(b"glTF")?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&total.to_le_bytes())?;
    w.write_all(&(json.len() as u32).to_le_bytes())?;
    w.write_all(b"JSON")?;
    w.write_all(&json)?;
    w.write_all(&(bin.len() as u32).to_le_bytes())?;
    w.write_all(b"BIN\0")?;
    w.write_all(&bin)
}

/// Writes a `.gltf`: JSON with the buffer embedded as a base64 data URI.
///
/// The caller checks the face indices and that coordinates fit in `f32`.
pub fn write_gltf(
    w: &mut dyn Write,
    vertices: &[Point3],
    faces: &[[u32; 3]],
    attributes: &VertexAttributes,
) -> std::io::Result<()> {
    empty_error(vertices, faces)?;
    let (mut json, bin) = document(vertices, faces, attributes);
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    json["buffers"][0]["uri"] = uri.into();
    serde_json::to_writer_pretty(&mut *w, &json).map_err(std::io::Error::other)?;
    w.write_all(b"\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> (Vec<Point3>, Vec<[u32; 3]>) {
        (
            vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.5]],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    /// The mesh written as GLB and as glTF, each read back.
    fn written_and_read(v: &[Point3], f: &[[u32; 3]], attributes: &VertexAttributes) -> [Mesh; 2] {
        [true, false].map(|glb| {
            let mut bytes = Vec::new();
            if glb {
                write_glb(&mut bytes, v, f, attributes).unwrap();
                assert_eq!(bytes.len() % 4, 0);
            } else {
                write_gltf(&mut bytes, v, f, attributes).unwrap();
            }
            read_gltf(&bytes, Path::new(".")).unwrap()
        })
    }

    /// A mesh 4·10⁶ from the origin, where f32 steps by 0.25, is stored
    /// about its centre (the node's translation) and reads back to f32's
    /// precision over its own size; one near the origin has no
    /// translation.
    #[test]
    fn a_mesh_far_from_the_origin_keeps_its_precision() {
        let (v, f) = square();
        let far: Vec<Point3> = v
            .iter()
            .map(|p| [p[0] * 0.01 + 512_345.678, p[1] * 0.01 + 4_123_456.789, p[2]])
            .collect();
        for mesh in written_and_read(&far, &f, &VertexAttributes::default()) {
            assert_eq!(mesh.faces.as_deref(), Some(f.as_slice()));
            for (p, q) in far.iter().zip(&mesh.vertices) {
                assert!((0..3).all(|k| (p[k] - q[k]).abs() < 1e-8), "{p:?} {q:?}");
            }
        }
        let mut bytes = Vec::new();
        write_gltf(&mut bytes, &far, &f, &VertexAttributes::default()).unwrap();
        let json: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
        let origin = &json["nodes"][0]["translation"];
        assert_eq!(origin[1].as_f64(), Some(4_123_456.75), "{origin}");
        bytes.clear();
        write_gltf(&mut bytes, &v, &f, &VertexAttributes::default()).unwrap();
        let json: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
        assert_eq!(json["nodes"][0], serde_json::json!({ "mesh": 0 }));
    }

    /// Materials, textures, samplers and an image (its bytes embedded)
    /// written and read back as they were, the faces grouped by material
    /// (one primitive each, those without one last); an extension is
    /// declared again only where the JSON names it.
    #[test]
    fn materials_round_trip() {
        use serde_json::json;
        let v = vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]];
        let f = vec![[0, 1, 2], [0, 2, 3], [1, 2, 3], [0, 1, 3]];
        let materials = gltf_materials::GltfMaterials {
            materials: vec![
                json!({"name": "a", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}),
                json!({"name": "b", "extensions": {"KHR_materials_unlit": {}}}),
            ],
            textures: vec![json!({"source": 0, "sampler": 0})],
            samplers: vec![json!({"magFilter": 9729})],
            images: vec![gltf_materials::GltfImage {
                json: json!({"name": "picture"}),
                mime_type: "image/png".to_string(),
                bytes: b"\x89PNG, three bytes short".to_vec(),
            }],
            extensions: [
                vec![
                    "KHR_materials_unlit".into(),
                    "KHR_draco_mesh_compression".into(),
                ],
                Vec::new(),
            ],
            faces: vec![1, NO_MATERIAL, 0, 1],
        };
        let attributes = VertexAttributes {
            materials: Some(Materials::Gltf(materials.clone())),
            ..VertexAttributes::default()
        };
        for mesh in written_and_read(&v, &f, &attributes) {
            assert_eq!(mesh.faces.unwrap(), vec![f[2], f[0], f[3], f[1]]);
            let Some(Materials::Gltf(read)) = mesh.materials else {
                panic!("no glTF materials read back");
            };
            assert_eq!(read.faces, vec![0, 1, 1, NO_MATERIAL]);
            assert_eq!(read.materials, materials.materials);
            assert_eq!(read.textures, materials.textures);
            assert_eq!(read.samplers, materials.samplers);
            assert_eq!(read.images, materials.images);
            assert_eq!(
                read.extensions,
                [vec!["KHR_materials_unlit".to_string()], Vec::new()]
            );
        }
    }

    #[test]
    fn glb_and_gltf_round_trip() {
        let (v, f) = square();
        for glb in [true, false] {
            let mut bytes = Vec::new();
            if glb {
                write_glb(&mut bytes, &v, &f, &VertexAttributes::default()).unwrap();
                assert!(is_glb(&bytes));
                assert_eq!(bytes.len() % 4, 0);
            } else {
                write_gltf(&mut bytes, &v, &f, &VertexAttributes::default()).unwrap();
                assert!(looks_like_json(&bytes));
            }
            let mesh = read_gltf(&bytes, Path::new(".")).unwrap();
            assert_eq!(mesh.vertices, v);
            assert_eq!(mesh.faces.unwrap(), f);
        }
    }

    #[test]
    fn normals_colours_and_texcoords_round_trip() {
        let (v, f) = square();
        let attributes = VertexAttributes {
            normals: Some(vec![
                [0.0, 0.0, 2.0],
                [0.0, 0.0, 0.0],
                [0.6, 0.0, 0.8],
                [0.0, -1.0, 0.0],
            ]),
            colours: Some(Colours {
                rgba: vec![[1.0, 0.0, 0.2, 1.0]; 4],
                alpha: true,
            }),
            // Exact in f32, and once turned (1 - v) and back.
            texcoords: Some(vec![[0.0, 0.0], [0.5, 0.25], [1.0, 0.75], [-2.0, 3.0]]),
            ..VertexAttributes::default()
        };
        for mesh in written_and_read(&v, &f, &attributes) {
            let normals = mesh.normals.unwrap();
            // Written as unit f32 vectors; a zero normal as +z.
            let want = [
                [0.0, 0.0, 1.0],
                [0.0, 0.0, 1.0],
                [0.6, 0.0, 0.8],
                [0.0, -1.0, 0.0],
            ];
            for (got, want) in normals.iter().zip(want) {
                assert!((0..3).all(|k| (got[k] - want[k]).abs() < 1e-7), "{got:?}");
            }
            assert_eq!(mesh.colours, attributes.colours);
            assert_eq!(mesh.texcoords, attributes.texcoords);
        }
    }

    /// The file's own values as `_NAME` attributes: 8- and 16-bit
    /// integers in their types (padded to 4 bytes), the others as `f32`,
    /// which a 32-bit integer beyond 2^24 or a NaN does not go into.
    #[test]
    fn own_values_round_trip() {
        let (v, f) = square();
        let field = |name: &str, kind, values: [f64; 4]| ScalarField {
            name: name.into(),
            kind,
            values: values.into(),
        };
        let scalars = vec![
            field("label", Scalar::U8, [0.0, 1.0, 255.0, 3.0]),
            field("offset", Scalar::I16, [-32768.0, 0.0, 5.0, 32767.0]),
            field("flags", Scalar::I32, [0.0, -16777216.0, 16777216.0, 3.0]),
            field("quality", Scalar::F64, [0.1, -2.5, 1e10, 0.0]),
        ];
        for held in &scalars {
            assert!(holds_field(held), "{}", held.name);
        }
        let attributes = VertexAttributes {
            scalars: scalars.clone(),
            ..VertexAttributes::default()
        };
        for mesh in written_and_read(&v, &f, &attributes) {
            let mut read = mesh.scalars;
            read.sort_by(|a, b| a.name.cmp(&b.name));
            let kinds: Vec<_> = read.iter().map(|f| (f.name.as_str(), f.kind)).collect();
            assert_eq!(
                kinds,
                [
                    ("flags", Scalar::F32),
                    ("label", Scalar::U8),
                    ("offset", Scalar::I16),
                    ("quality", Scalar::F32)
                ]
            );
            for got in &read {
                let want = scalars.iter().find(|w| w.name == got.name).unwrap();
                let rounded: Vec<f64> = want.values.iter().map(|&v| f64::from(v as f32)).collect();
                assert_eq!(got.values, rounded, "{}", got.name);
            }
        }
        let beyond = field("flags", Scalar::U32, [0.0, 16777217.0, 0.0, 0.0]);
        assert!(!holds_field(&beyond));
        assert!(!holds_field(&field(
            "q",
            Scalar::F32,
            [0.0, f64::NAN, 0.0, 0.0]
        )));
    }

    /// A node's matrix turns normals by its inverse transpose: under a
    /// non-uniform scale a slanted normal tilts the other way from the
    /// surface, and a mirror keeps it on the face's front.
    #[test]
    fn normals_follow_the_node_matrix() {
        let stretch: Matrix = [
            [2.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ];
        let n = normal_matrix(&stretch);
        let slanted = [1.0, 0.0, 1.0];
        let turned = n.map(|row| row[0] * slanted[0] + row[1] * slanted[1] + row[2] * slanted[2]);
        // The plane x + z = 0 becomes x/2 + z = 0: its normal (1/2, 0, 1).
        assert!((turned[0] / turned[2] - 0.5).abs() < 1e-12, "{turned:?}");
        let mut mirror = IDENTITY;
        mirror[2][2] = -1.0;
        let n = normal_matrix(&mirror);
        let up = n.map(|row| row[2]);
        assert_eq!(up, [0.0, 0.0, -1.0], "a mirrored +z normal points down");
    }

    #[test]
    fn matrix_product_is_column_major() {
        let mut translate = IDENTITY;
        translate[3] = [1.0, 2.0, 3.0, 1.0];
        let mut scale = IDENTITY;
        scale[0][0] = 2.0;
        // Scale first, then translate.
        let m = multiply(&translate, &scale);
        assert_eq!(apply(&m, [1.0, 1.0, 1.0]), [3.0, 3.0, 4.0]);
        assert_eq!(determinant3(&m), 2.0);
    }

    #[test]
    fn percent_escapes() {
        assert_eq!(percent_decode("my%20mesh.bin"), "my mesh.bin");
        assert_eq!(percent_decode("a%2"), "a%2");
        assert_eq!(percent_decode("100%"), "100%");
    }

    #[test]
    fn empty_meshes_are_refused() {
        let mut out = Vec::new();
        assert!(write_glb(&mut out, &[], &[], &VertexAttributes::default()).is_err());
    }
}
