//! Materials carried from one format to another: what OBJ's MTL, glTF
//! and MeshLab's textured PLY all hold, a name, a base colour and a base
//! colour image per material.
//!
//! An OBJ's `newmtl` gives the name, `Kd` (and `d`, or `Tr`) the colour
//! and `map_Kd` the image; a glTF material its `name`,
//! `pbrMetallicRoughness.baseColorFactor` and `baseColorTexture`; a PLY's
//! `comment TextureFile` an image each, named after its file. What the
//! other formats cannot hold is left: MTL's other maps and colours,
//! glTF's metal, roughness, normal, occlusion and emission, and a glTF
//! base colour texture read through a texture coordinate set other than
//! the first (the only one meshtrim carries). The colour multiplies the
//! image, as glTF's factor does; an OBJ material with an image gets white
//! (with its `d`), since OBJ viewers draw `map_Kd` as it is and exporters
//! write a grey `Kd` beside it.
//!
//! Written to a glTF file the materials are metal 0, roughness 1 (a
//! diffuse surface, as MTL's `Kd` describes), `alphaMode` `BLEND` below
//! opacity 1, and each image embedded once; glTF holds PNG and JPEG
//! images only, so another kind is left (the report names it). Written
//! to an OBJ file they are its own `<name>.mtl` and their images are in
//! `<name>_textures/`; to a PLY file, the images in the same folder as
//! `comment TextureFile` lines, the faces of a material without an
//! image given MeshLab's texture number −1.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Result;
use serde_json::{json, Value};

use super::atomic::write_atomic;
use super::gltf_materials::{GltfImage, GltfMaterials, NO_MATERIAL};
use super::{obj_material, ply::PlyTextures, ObjMaterial};

/// Materials any mesh format with materials holds, and each face's.
#[derive(Debug, Clone, PartialEq)]
pub struct SimpleMaterials {
    /// The materials, their names distinct words.
    pub materials: Vec<SimpleMaterial>,
    /// Each face's material, an index into `materials`.
    pub faces: Vec<u32>,
}

/// A name, a base colour (red, green, blue, opacity in 0..1) and an image
/// it multiplies.
#[derive(Debug, Clone, PartialEq)]
pub struct SimpleMaterial {
    /// A word: no white space.
    pub name: String,
    /// Red, green, blue and opacity.
    pub colour: [f64; 4],
    /// The base colour image.
    pub image: Option<Image>,
}

/// A material's image: a file, or bytes read from a glTF file.
#[derive(Debug, Clone, PartialEq)]
pub enum Image {
    /// An image file, as a path from the current directory.
    File(PathBuf),
    /// An image held in memory, and the file name it is written under.
    Embedded {
        /// A file name, its extension the image's kind.
        name: String,
        /// `image/png`, `image/jpeg`, …
        mime_type: String,
        /// The encoded image.
        bytes: Vec<u8>,
    },
}

impl Image {
    /// The name the image is written under.
    fn file_name(&self) -> String {
        match self {
            Image::File(path) => obj_material::file_name(path),
            Image::Embedded { name, .. } => name.clone(),
        }
    }
}

const WHITE: [f64; 4] = [1.0; 4];

impl SimpleMaterial {
    fn new(name: String, colour: [f64; 4], image: Option<Image>) -> Self {
        SimpleMaterial {
            name,
            colour,
            image,
        }
    }
}

impl SimpleMaterials {
    /// An OBJ's materials, from the `newmtl` blocks of its libraries (the
    /// first library defining a name wins; a material no library defines,
    /// or whose library cannot be read, is white without an image).
    pub fn from_obj(material: &ObjMaterial) -> SimpleMaterials {
        let mut defined = BTreeMap::new();
        for library in &material.libraries {
            let Ok(bytes) = std::fs::read(library) else {
                continue;
            };
            let dir = library.parent().unwrap_or(Path::new(""));
            for parsed in mtl_materials(&String::from_utf8_lossy(&bytes), dir) {
                defined.entry(parsed.name.clone()).or_insert(parsed);
            }
        }
        let materials = material
            .names
            .iter()
            .map(|name| {
                defined
                    .get(name)
                    .cloned()
                    .unwrap_or_else(|| SimpleMaterial::new(name.clone(), WHITE, None))
            })
            .collect();
        SimpleMaterials::named(materials, material.faces.clone())
    }

    /// A glTF file's materials; faces without one get a white material
    /// named `default`.
    pub fn from_gltf(gltf: &GltfMaterials) -> SimpleMaterials {
        let images = embedded_names(&gltf.images);
        let mut materials: Vec<_> = gltf
            .materials
            .iter()
            .enumerate()
            .map(|(i, material)| {
                let name = material["name"].as_str().unwrap_or("").to_string();
                let name = if name.trim().is_empty() {
                    format!("material_{i}")
                } else {
                    name
                };
                let pbr = &material["pbrMetallicRoughness"];
                let colour = colour_of(&pbr["baseColorFactor"]).unwrap_or(WHITE);
                let image =
                    base_colour_image(&pbr["baseColorTexture"], gltf).map(|i| images[i].clone());
                SimpleMaterial::new(name, colour, image)
            })
            .collect();
        let mut faces = gltf.faces.clone();
        if faces.contains(&NO_MATERIAL) {
            let default = materials.len() as u32;
            materials.push(SimpleMaterial::new("default".to_string(), WHITE, None));
            for f in faces.iter_mut().filter(|f| **f == NO_MATERIAL) {
                *f = default;
            }
        }
        SimpleMaterials::named(materials, faces)
    }

    /// A PLY's texture files, a white material each, named after its
    /// file; a face numbering no file takes the first, as on reading (a
    /// white `default` without files).
    pub fn from_ply(textures: &PlyTextures) -> SimpleMaterials {
        let mut materials: Vec<SimpleMaterial> = textures
            .files
            .iter()
            .map(|file| {
                let stem = file.file_stem().map(|s| s.to_string_lossy().into_owned());
                let image = Some(Image::File(file.clone()));
                SimpleMaterial::new(stem.unwrap_or_default(), WHITE, image)
            })
            .collect();
        if materials.is_empty() {
            materials.push(SimpleMaterial::new("default".to_string(), WHITE, None));
        }
        let count = textures.files.len() as u32;
        let faces = textures
            .faces
            .iter()
            .map(|&f| if f < count { f } else { 0 })
            .collect();
        SimpleMaterials::named(materials, faces)
    }

    /// Materials with `faces`, their names made distinct words.
    fn named(mut materials: Vec<SimpleMaterial>, faces: Vec<u32>) -> Self {
        let names = distinct_words(materials.iter().map(|m| m.name.as_str()), "material");
        for (material, name) in materials.iter_mut().zip(names) {
            material.name = name;
        }
        SimpleMaterials { materials, faces }
    }

    /// Whether some material has an image.
    pub fn has_image(&self) -> bool {
        self.materials.iter().any(|m| m.image.is_some())
    }

    /// The materials as a glTF file holds them, and the names of the
    /// images left out (neither PNG nor JPEG, or not readable).
    pub fn to_gltf(&self) -> (GltfMaterials, Vec<String>) {
        let mut images: Vec<GltfImage> = Vec::new();
        // Each image met, and its index in `images` (`None`: left out).
        let mut embedded: Vec<(&Image, Option<usize>)> = Vec::new();
        let mut left = Vec::new();
        let materials = self
            .materials
            .iter()
            .map(|material| {
                let mut pbr = json!({
                    "baseColorFactor": material.colour,
                    "metallicFactor": 0.0,
                    "roughnessFactor": 1.0,
                });
                if let Some(image) = &material.image {
                    let seen = embedded.iter().find(|(seen, _)| *seen == image);
                    let index = match seen {
                        Some(&(_, index)) => index,
                        None => {
                            let index = gltf_image(image).map(|image| {
                                images.push(image);
                                images.len() - 1
                            });
                            embedded.push((image, index));
                            if index.is_none() {
                                left.push(image.file_name());
                            }
                            index
                        }
                    };
                    if let Some(index) = index {
                        pbr["baseColorTexture"] = json!({ "index": index });
                    }
                }
                let mut out = json!({ "name": material.name, "pbrMetallicRoughness": pbr });
                if material.colour[3] < 1.0 {
                    out["alphaMode"] = "BLEND".into();
                }
                out
            })
            .collect();
        // One texture per image, sampled as glTF's default sampler does
        // (repeat, as OBJ viewers do).
        let textures = (0..images.len()).map(|i| json!({ "source": i })).collect();
        let gltf = GltfMaterials {
            materials,
            textures,
            samplers: Vec::new(),
            images,
            extensions: Default::default(),
            faces: self.faces.clone(),
        };
        let left = left
            .into_iter()
            .map(|name| format!("texture image {name}"))
            .collect();
        (gltf, left)
    }

    /// Writes the material library of an OBJ output at `path`,
    /// `<name>.mtl`, with its images in `<name>_textures/`, and returns
    /// the library's name as the OBJ's `mtllib` gives it.
    pub(crate) fn write_obj_library(&self, path: &Path) -> Result<String> {
        let library = path.with_extension("mtl");
        let names = self.write_images(path)?;
        let mut text = String::from("# written by meshtrim\n");
        for (material, image) in self.materials.iter().zip(&names) {
            let [r, g, b, opacity] = material.colour;
            text.push_str(&format!("\nnewmtl {}\nKd {r} {g} {b}\n", material.name));
            if opacity < 1.0 {
                text.push_str(&format!("d {opacity}\n"));
            }
            if let Some(image) = image {
                text.push_str(&format!("map_Kd {image}\n"));
            }
        }
        write_atomic(&library, |w| w.write_all(text.as_bytes()))?;
        Ok(obj_material::file_name(&library))
    }

    /// Writes the images of a PLY output at `path` into `<name>_textures/`
    /// and returns their names as its `comment TextureFile` lines give
    /// them, and each face's texture number (−1, as `u32::MAX`, for a
    /// material without an image); `None` when every face has the one
    /// image.
    pub(crate) fn write_ply_textures(
        &self,
        path: &Path,
    ) -> Result<(Vec<String>, Option<Vec<u32>>)> {
        let mut files: Vec<String> = Vec::new();
        let numbers: Vec<u32> = self
            .write_images(path)?
            .into_iter()
            .map(|image| match image {
                Some(name) => match files.iter().position(|f| *f == name) {
                    Some(at) => at as u32,
                    None => {
                        files.push(name);
                        files.len() as u32 - 1
                    }
                },
                None => u32::MAX,
            })
            .collect();
        let faces: Vec<u32> = self.faces.iter().map(|&m| numbers[m as usize]).collect();
        let one_image = files.len() == 1 && faces.iter().all(|&n| n == 0);
        Ok((files, (!one_image).then_some(faces)))
    }

    /// Writes each material's image into the folder of an output at
    /// `path`, each image once, under distinct names, and returns the
    /// names the output gives them (an image file that is missing named
    /// as it was).
    fn write_images(&self, path: &Path) -> Result<Vec<Option<String>>> {
        let out_dir = obj_material::absolute_dir(path);
        let folder = obj_material::own_folder(path);
        let mut written: Vec<(&Image, String)> = Vec::new();
        let mut taken = std::collections::BTreeSet::new();
        let mut names = Vec::with_capacity(self.materials.len());
        for image in self.materials.iter().map(|m| m.image.as_ref()) {
            let Some(image) = image else {
                names.push(None);
                continue;
            };
            if let Some((_, name)) = written.iter().find(|(seen, _)| *seen == image) {
                names.push(Some(name.clone()));
                continue;
            }
            let name = format!(
                "{folder}/{}",
                distinct_file_name(&image.file_name(), &mut taken)
            );
            match image {
                Image::File(file) if !file.is_file() => {
                    names.push(Some(image.file_name()));
                    continue;
                }
                Image::File(file) => obj_material::copy_file(file, &out_dir.join(&name))?,
                Image::Embedded { bytes, .. } => {
                    write_atomic(&out_dir.join(&name), |w| w.write_all(bytes))?
                }
            }
            written.push((image, name.clone()));
            names.push(Some(name));
        }
        Ok(names)
    }
}

/// `name`, or when `taken` has it, `<stem>_<n>.<extension>` for the
/// first `n` it has not; then taken.
fn distinct_file_name(name: &str, taken: &mut std::collections::BTreeSet<String>) -> String {
    let (stem, extension) = match name.rsplit_once('.') {
        Some((stem, extension)) => (stem, format!(".{extension}")),
        None => (name, String::new()),
    };
    let mut candidate = name.to_string();
    let mut n = 1;
    while !taken.insert(candidate.clone()) {
        candidate = format!("{stem}_{n}{extension}");
        n += 1;
    }
    candidate
}

/// The materials an MTL library's text defines: each `newmtl`'s name,
/// colour and `map_Kd` image (a path from `dir`, the library's
/// directory).
fn mtl_materials(text: &str, dir: &Path) -> Vec<SimpleMaterial> {
    struct Block {
        name: String,
        kd: Option<[f64; 3]>,
        opacity: Option<f64>,
        transparency: Option<f64>,
        image: Option<String>,
    }
    let mut blocks: Vec<Block> = Vec::new();
    for line in super::lines(text) {
        let line = line.trim();
        let mut words = line.split_whitespace();
        let keyword = words.next().unwrap_or("").to_ascii_lowercase();
        if keyword == "newmtl" {
            blocks.push(Block {
                name: line["newmtl".len()..].trim().to_string(),
                kd: None,
                opacity: None,
                transparency: None,
                image: None,
            });
            continue;
        }
        let Some(block) = blocks.last_mut() else {
            continue;
        };
        let rest: Vec<&str> = words.collect();
        // The line's numbers, when every word is a finite one.
        let numbers: Vec<f64> = rest
            .iter()
            .map_while(|w| w.parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect();
        let numbers = if numbers.len() == rest.len() {
            numbers
        } else {
            Vec::new()
        };
        match keyword.as_str() {
            "kd" => match numbers[..] {
                [r, g, b] => block.kd = Some([r, g, b]),
                [grey] => block.kd = Some([grey; 3]),
                _ => {}
            },
            "d" => block.opacity = numbers.first().copied(),
            "tr" => block.transparency = numbers.first().copied(),
            "map_kd" => block.image = rest.last().map(|w| w.to_string()),
            _ => {}
        }
    }
    blocks
        .into_iter()
        .map(|block| {
            let opacity = block
                .opacity
                .or(block.transparency.map(|t| 1.0 - t))
                .unwrap_or(1.0)
                .clamp(0.0, 1.0);
            let image = block.image.map(|image| Image::File(dir.join(image)));
            let [r, g, b] = match image {
                Some(_) => [1.0; 3],
                None => block.kd.unwrap_or([1.0; 3]).map(|c| c.clamp(0.0, 1.0)),
            };
            SimpleMaterial::new(block.name, [r, g, b, opacity], image)
        })
        .collect()
}

/// A glTF colour factor: four numbers, each held to 0..1.
fn colour_of(value: &Value) -> Option<[f64; 4]> {
    let items = value.as_array()?;
    let numbers: Vec<f64> = items.iter().filter_map(Value::as_f64).collect();
    let colour = <[f64; 4]>::try_from(numbers).ok()?;
    Some(colour.map(|c| c.clamp(0.0, 1.0)))
}

/// The image a glTF material's `baseColorTexture` samples through the
/// first texture coordinate set, as an index into `gltf.images`.
fn base_colour_image(texture_info: &Value, gltf: &GltfMaterials) -> Option<usize> {
    let texture = texture_info["index"].as_u64()? as usize;
    if texture_info["texCoord"].as_u64().unwrap_or(0) != 0 {
        return None;
    }
    let source = gltf.textures.get(texture)?["source"].as_u64()? as usize;
    (source < gltf.images.len()).then_some(source)
}

/// The glTF images as images written under file names: each image's
/// `name` (made a distinct file name) or `image_<i>`, with the extension
/// of its kind.
fn embedded_names(images: &[GltfImage]) -> Vec<Image> {
    let stems: Vec<String> = images
        .iter()
        .map(|image| {
            let name = image.json["name"].as_str().unwrap_or("");
            let name = name.rsplit_once('.').map_or(name, |(stem, _)| stem);
            name.chars()
                .map(
                    |c| match c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                        true => c,
                        false => '_',
                    },
                )
                .collect()
        })
        .collect();
    let stems = distinct_words(stems.iter().map(String::as_str), "image");
    images
        .iter()
        .zip(stems)
        .map(|(image, stem)| {
            let extension = image.mime_type.rsplit('/').next().unwrap_or("bin");
            let extension = if extension == "jpeg" {
                "jpg"
            } else {
                extension
            };
            Image::Embedded {
                name: format!("{stem}.{extension}"),
                mime_type: image.mime_type.clone(),
                bytes: image.bytes.clone(),
            }
        })
        .collect()
}

/// The image as a glTF file embeds it: PNG or JPEG (known by its first
/// bytes); `None` for another kind or a file that cannot be read.
fn gltf_image(image: &Image) -> Option<GltfImage> {
    let bytes = match image {
        Image::File(path) => std::fs::read(path).ok()?,
        Image::Embedded { bytes, .. } => bytes.clone(),
    };
    let mime_type = if bytes.starts_with(b"\x89PNG") {
        "image/png"
    } else if bytes.starts_with(b"\xff\xd8\xff") {
        "image/jpeg"
    } else {
        return None;
    };
    let stem = image.file_name();
    let stem = stem
        .rsplit_once('.')
        .map_or(stem.as_str(), |(stem, _)| stem);
    Some(GltfImage {
        json: json!({ "name": stem }),
        mime_type: mime_type.to_string(),
        bytes,
    })
}

/// `names` made distinct words: white space replaced by `_`, an empty
/// name `<fallback>_<i>`, a name met before given `_<i>` (its index).
fn distinct_words<'a>(names: impl Iterator<Item = &'a str>, fallback: &str) -> Vec<String> {
    let mut seen = std::collections::BTreeSet::new();
    names
        .enumerate()
        .map(|(i, name)| {
            let word: String = name
                .trim()
                .chars()
                .map(|c| if c.is_whitespace() { '_' } else { c })
                .collect();
            let mut word = if word.is_empty() {
                format!("{fallback}_{i}")
            } else {
                word
            };
            while !seen.insert(word.clone()) {
                word = format!("{word}_{i}");
            }
            word
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const PNG: &[u8] = b"\x89PNG\r\n\x1a\n rest of a png";

    fn material(name: &str, colour: [f64; 4], image: Option<Image>) -> SimpleMaterial {
        SimpleMaterial::new(name.to_string(), colour, image)
    }

    #[test]
    fn mtl_blocks_give_name_colour_opacity_and_image() {
        let text = "# lib\nKd 0 1 0\nnewmtl plain red\nKd 1 0 0\nTr 0.25\n\
                    NEWMTL textured\nkd 0.4 0.4 0.4\nd 0.5\nmap_Kd -s 1 1 1 tex/a b.png\n\
                    newmtl grey\nKd 0.5\nd nan\n\nnewmtl odd\nKd 1 nan 0\nd 2\nnewmtl held\nKd 2 0.5 -1\n";
        let parsed = mtl_materials(text, Path::new("lib"));
        let names: Vec<&str> = parsed.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["plain red", "textured", "grey", "odd", "held"]);
        let colour_and_image = |m: &SimpleMaterial| (m.colour, m.image.clone());
        assert_eq!(colour_and_image(&parsed[0]), ([1.0, 0.0, 0.0, 0.75], None));
        // An image's material is white: viewers draw `map_Kd` as it is.
        // The image is the line's last word, from the library's directory.
        let image = Some(Image::File(Path::new("lib").join("b.png")));
        assert_eq!(colour_and_image(&parsed[1]), ([1.0, 1.0, 1.0, 0.5], image));
        assert_eq!(colour_and_image(&parsed[2]), ([0.5, 0.5, 0.5, 1.0], None));
        // A colour not finite is none; out of range, held to 0..1.
        assert_eq!(colour_and_image(&parsed[3]), (WHITE, None));
        assert_eq!(colour_and_image(&parsed[4]), ([1.0, 0.5, 0.0, 1.0], None));
    }

    #[test]
    fn names_are_made_distinct_words() {
        let names = distinct_words(["a b", "", "a_b", "c", "c"].into_iter(), "material");
        assert_eq!(names, ["a_b", "material_1", "a_b_2", "c", "c_4"]);
        let mut taken = Default::default();
        let names: Vec<String> = ["t.png", "t.png", "t.png", "t"]
            .iter()
            .map(|n| distinct_file_name(n, &mut taken))
            .collect();
        assert_eq!(names, ["t.png", "t_1.png", "t_2.png", "t"]);
    }

    fn gltf_image(name: Option<&str>, mime_type: &str, bytes: &[u8]) -> GltfImage {
        GltfImage {
            json: name.map_or(json!({}), |name| json!({ "name": name })),
            mime_type: mime_type.to_string(),
            bytes: bytes.to_vec(),
        }
    }

    #[test]
    fn gltf_materials_give_base_colour_and_image() {
        let gltf = GltfMaterials {
            materials: vec![
                json!({ "name": "skin", "pbrMetallicRoughness": {
                    "baseColorFactor": [0.5, 0.25, 1.0, 1.0], "baseColorTexture": { "index": 1 } } }),
                // Read through the second coordinate set: not carried.
                json!({ "pbrMetallicRoughness": { "baseColorTexture": { "index": 0, "texCoord": 1 } } }),
            ],
            textures: vec![json!({ "source": 1 }), json!({ "source": 0 })],
            samplers: Vec::new(),
            images: vec![
                gltf_image(Some("scan skin.png"), "image/jpeg", b"jpeg"),
                gltf_image(None, "image/png", PNG),
            ],
            extensions: Default::default(),
            faces: vec![0, NO_MATERIAL, 1],
        };
        let simple = SimpleMaterials::from_gltf(&gltf);
        let embedded = |name: &str, mime_type: &str, bytes: &[u8]| Image::Embedded {
            name: name.to_string(),
            mime_type: mime_type.to_string(),
            bytes: bytes.to_vec(),
        };
        assert_eq!(
            simple.materials,
            [
                material(
                    "skin",
                    [0.5, 0.25, 1.0, 1.0],
                    Some(embedded("scan_skin.jpg", "image/jpeg", b"jpeg"))
                ),
                material("material_1", WHITE, None),
                material("default", WHITE, None),
            ]
        );
        assert_eq!(simple.faces, [0, 2, 1]);
    }

    #[test]
    fn gltf_output_embeds_png_and_jpeg_once_and_names_the_others() {
        let dir = tempfile::tempdir().unwrap();
        let (png, tga) = (dir.path().join("a.png"), dir.path().join("b.tga"));
        std::fs::write(&png, PNG).unwrap();
        std::fs::write(&tga, b"\0\0\x02 targa").unwrap();
        let simple = SimpleMaterials {
            materials: vec![
                material("a", WHITE, Some(Image::File(png.clone()))),
                material("glass", [0.2, 0.4, 0.6, 0.5], Some(Image::File(png))),
                material("b", WHITE, Some(Image::File(tga))),
                material(
                    "missing",
                    WHITE,
                    Some(Image::File(dir.path().join("c.png"))),
                ),
            ],
            faces: vec![3, 2, 1, 0],
        };
        let (gltf, left) = simple.to_gltf();
        assert_eq!(left, ["texture image b.tga", "texture image c.png"]);
        assert_eq!(gltf.images, [gltf_image(Some("a"), "image/png", PNG)]);
        assert_eq!(gltf.textures, [json!({ "source": 0 })]);
        let texture =
            |m: usize| gltf.materials[m]["pbrMetallicRoughness"]["baseColorTexture"].clone();
        assert_eq!(texture(0), json!({ "index": 0 }));
        assert_eq!(texture(1), json!({ "index": 0 }));
        assert_eq!(texture(2), Value::Null);
        assert_eq!(gltf.materials[1]["alphaMode"], "BLEND");
        assert_eq!(gltf.materials[0]["alphaMode"], Value::Null);
        assert_eq!(
            gltf.materials[1]["pbrMetallicRoughness"]["baseColorFactor"],
            json!([0.2, 0.4, 0.6, 0.5])
        );
        assert_eq!(gltf.faces, simple.faces);
    }

    #[test]
    fn images_written_once_each_under_distinct_names() {
        let dir = tempfile::tempdir().unwrap();
        for sub in ["x", "y"] {
            std::fs::create_dir_all(dir.path().join(sub)).unwrap();
            std::fs::write(dir.path().join(sub).join("t.png"), sub).unwrap();
        }
        let file = |sub: &str| Some(Image::File(dir.path().join(sub).join("t.png")));
        let simple = SimpleMaterials {
            materials: vec![
                material("m0", WHITE, file("x")),
                material("m1", WHITE, None),
                material("m2", WHITE, file("y")),
                material("m3", WHITE, file("x")),
                material("m4", WHITE, file("z")),
            ],
            faces: vec![0, 1, 2, 3, 4, 0],
        };
        let out = dir.path().join("out/scan.ply");
        let (files, numbers) = simple.write_ply_textures(&out).unwrap();
        // A missing image is named as it was.
        assert_eq!(
            files,
            ["scan_textures/t.png", "scan_textures/t_1.png", "t.png"]
        );
        let read = |name: &str| std::fs::read_to_string(dir.path().join("out").join(name)).unwrap();
        assert_eq!(read("scan_textures/t.png"), "x");
        assert_eq!(read("scan_textures/t_1.png"), "y");
        // Without an image: MeshLab's −1.
        assert_eq!(numbers.unwrap(), [0, u32::MAX, 1, 0, 2, 0]);

        let library = simple
            .write_obj_library(&dir.path().join("out/scan.obj"))
            .unwrap();
        assert_eq!(library, "scan.mtl");
        let text = read("scan.mtl");
        assert!(
            text.contains("newmtl m2\nKd 1 1 1\nmap_Kd scan_textures/t_1.png\n"),
            "{text}"
        );
        assert!(text.contains("newmtl m1\nKd 1 1 1\n\n"), "{text}");
    }

    #[test]
    fn one_image_on_every_face_needs_no_numbers() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("t.png"), PNG).unwrap();
        let simple = SimpleMaterials {
            materials: vec![material(
                "m",
                WHITE,
                Some(Image::File(dir.path().join("t.png"))),
            )],
            faces: vec![0, 0],
        };
        let (files, numbers) = simple
            .write_ply_textures(&dir.path().join("scan.ply"))
            .unwrap();
        assert_eq!(
            (files, numbers),
            (vec!["scan_textures/t.png".to_string()], None)
        );
    }
}
