//! A glTF file's materials, carried to a glTF output: each face keeps the
//! material of the input face it lies on, and the materials, textures,
//! samplers and images are written again as the input had them.
//!
//! The materials, textures and samplers are copied as the file's JSON
//! (their extensions and extras included, which a typed reading would
//! drop); their indices stay valid because every one is kept, in order.
//! Images are embedded in the output's buffer whatever the input did (a
//! GLB's buffer view, a data URI, a file beside the `.gltf`), so the
//! output stands alone. The extensions the copied JSON uses are declared
//! again (`extensionsUsed`, and `extensionsRequired` where the input
//! required them).

use std::borrow::Cow;
use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};
use serde_json::Value;

/// A face without a material (glTF's default material).
pub const NO_MATERIAL: u32 = u32::MAX;

/// A glTF file's materials and each face's.
#[derive(Debug, Clone, PartialEq)]
pub struct GltfMaterials {
    /// `materials`, `textures` and `samplers`, as the file's JSON.
    pub materials: Vec<Value>,
    /// The textures, as the file's JSON.
    pub textures: Vec<Value>,
    /// The samplers, as the file's JSON.
    pub samplers: Vec<Value>,
    /// The images, with their data.
    pub images: Vec<GltfImage>,
    /// The extensions the file declared used and required.
    pub extensions: [Vec<String>; 2],
    /// Each face's material, an index into `materials`, or
    /// [`NO_MATERIAL`].
    pub faces: Vec<u32>,
}

/// An image a texture samples: its JSON (name, extras) without its source,
/// its media type and its bytes.
#[derive(Debug, Clone, PartialEq)]
pub struct GltfImage {
    /// The image's JSON without `uri`, `bufferView` and `mimeType`.
    pub json: Value,
    /// `image/png`, `image/jpeg`, …
    pub mime_type: String,
    /// The encoded image.
    pub bytes: Vec<u8>,
}

impl GltfMaterials {
    /// The faces grouped by material, in the order of the materials (the
    /// faces without one last), each group in face order.
    pub(crate) fn groups(&self) -> Vec<(u32, Vec<u32>)> {
        let mut groups: std::collections::BTreeMap<u32, Vec<u32>> = Default::default();
        for (f, &m) in self.faces.iter().enumerate() {
            groups.entry(m).or_default().push(f as u32);
        }
        groups.into_iter().collect()
    }
}

/// The materials of a glTF file whose document is `gltf` (its raw bytes
/// `bytes`, its buffers `buffers`, its directory `dir`), with `faces`,
/// each face's material; `None` when the file has no material.
pub(crate) fn read(
    bytes: &[u8],
    gltf: &gltf::Gltf,
    buffers: &[Cow<[u8]>],
    dir: &Path,
    faces: Vec<u32>,
) -> Result<Option<GltfMaterials>> {
    if gltf.document.materials().len() == 0 || faces.iter().all(|&m| m == NO_MATERIAL) {
        return Ok(None);
    }
    let json = raw_json(bytes)?;
    let list = |key: &str| match json.get(key) {
        Some(Value::Array(items)) => items.clone(),
        _ => Vec::new(),
    };
    let names = |key: &str| -> Vec<String> {
        list(key)
            .into_iter()
            .filter_map(|v| v.as_str().map(str::to_string))
            .collect()
    };
    let raw_images = list("images");
    let images = gltf
        .document
        .images()
        .map(|image| {
            let raw = raw_images
                .get(image.index())
                .cloned()
                .unwrap_or(Value::Null);
            read_image(&image, raw, buffers, dir)
                .with_context(|| format!("image {}", image.index()))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(Some(GltfMaterials {
        materials: list("materials"),
        textures: list("textures"),
        samplers: list("samplers"),
        images,
        extensions: [names("extensionsUsed"), names("extensionsRequired")],
        faces,
    }))
}

/// The document's JSON as written: a GLB's JSON chunk, or the file.
fn raw_json(bytes: &[u8]) -> Result<Value> {
    let text: Cow<[u8]> = if super::gltf_io::is_glb(bytes) {
        gltf::Glb::from_slice(bytes)
            .map_err(|e| anyhow!("malformed glTF: {e}"))?
            .json
    } else {
        Cow::Borrowed(bytes)
    };
    serde_json::from_slice(&text).map_err(|e| anyhow!("malformed glTF: {e}"))
}

fn read_image(
    image: &gltf::Image,
    raw: Value,
    buffers: &[Cow<[u8]>],
    dir: &Path,
) -> Result<GltfImage> {
    let (bytes, mime_type) = match image.source() {
        gltf::image::Source::View { view, mime_type } => {
            let buffer = &buffers[view.buffer().index()];
            let end = view.offset().checked_add(view.length());
            let data = end
                .and_then(|end| buffer.get(view.offset()..end))
                .ok_or_else(|| {
                    anyhow!("buffer view {} does not fit in its buffer", view.index())
                })?;
            (data.to_vec(), mime_type.to_string())
        }
        gltf::image::Source::Uri { uri, mime_type } => {
            let bytes = super::gltf_io::uri_bytes(uri, dir, None)?;
            let mime = match mime_type {
                Some(m) => m.to_string(),
                None => mime_of(uri, &bytes)?,
            };
            (bytes, mime)
        }
    };
    let json = match raw {
        Value::Object(mut fields) => {
            for key in ["uri", "bufferView", "mimeType"] {
                fields.remove(key);
            }
            Value::Object(fields)
        }
        _ => Value::Object(Default::default()),
    };
    Ok(GltfImage {
        json,
        mime_type,
        bytes,
    })
}

/// An image's media type from its first bytes, else its URI's extension.
fn mime_of(uri: &str, bytes: &[u8]) -> Result<String> {
    let by_content = [
        (&b"\x89PNG"[..], "image/png"),
        (&b"\xff\xd8\xff"[..], "image/jpeg"),
    ];
    if let Some((_, mime)) = by_content
        .iter()
        .find(|(magic, _)| bytes.starts_with(magic))
    {
        return Ok(mime.to_string());
    }
    let ext = uri.rsplit('.').next().unwrap_or("").to_ascii_lowercase();
    Ok(match ext.as_str() {
        "png" => "image/png",
        "jpg" | "jpeg" => "image/jpeg",
        "webp" => "image/webp",
        "ktx2" => "image/ktx2",
        _ => bail!("the image's media type is neither given nor known from '{uri}'"),
    }
    .to_string())
}

/// Adds the materials to a document being written: its images as buffer
/// views at the end of `bin` (each from a multiple of 4 bytes), and the
/// JSON of the materials, textures, samplers, images and the extensions
/// they use.
pub(crate) fn write(
    materials: &GltfMaterials,
    json: &mut Value,
    views: &mut Vec<Value>,
    bin: &mut Vec<u8>,
) {
    let mut images = Vec::new();
    for image in &materials.images {
        bin.resize(bin.len().next_multiple_of(4), 0);
        let start = bin.len();
        bin.extend_from_slice(&image.bytes);
        views.push(serde_json::json!({
            "buffer": 0, "byteOffset": start, "byteLength": image.bytes.len()
        }));
        let mut fields = image.json.clone();
        fields["bufferView"] = (views.len() - 1).into();
        fields["mimeType"] = image.mime_type.clone().into();
        images.push(fields);
    }
    bin.resize(bin.len().next_multiple_of(4), 0);
    let copied = [
        ("materials", &materials.materials),
        ("textures", &materials.textures),
        ("samplers", &materials.samplers),
    ];
    for (key, list) in copied {
        if !list.is_empty() {
            json[key] = Value::Array(list.clone());
        }
    }
    if !images.is_empty() {
        json["images"] = Value::Array(images);
    }
    // An extension is declared again when the copied JSON names it.
    let text = serde_json::to_string(&json).unwrap_or_default();
    for (key, names) in ["extensionsUsed", "extensionsRequired"]
        .into_iter()
        .zip(&materials.extensions)
    {
        let named: Vec<&String> = names
            .iter()
            .filter(|name| text.contains(&format!("\"{name}\"")))
            .collect();
        if !named.is_empty() {
            json[key] = serde_json::json!(named);
        }
    }
}
