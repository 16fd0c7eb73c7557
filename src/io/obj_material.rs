//! An OBJ output's material: its libraries and images found from the
//! output.
//!
//! An OBJ names its material libraries (`mtllib`) relative to itself, and
//! most readers (MeshLab, trimesh) look for a library's images relative
//! to the OBJ too, not to the library; trimesh refuses any that lies
//! outside the OBJ's directory. So an output written beside the input's
//! libraries names them as they are; an output written elsewhere gets its
//! own library beside it, `<name>.mtl` (the input's libraries' text), and
//! a copy of each image in a directory of its own, `<name>_textures/`, at
//! the same path below it when the image was below the library's, else by
//! its file name: outputs written side by side (a batch) never share or
//! overwrite an image. The input's files are never modified. A PLY's
//! texture files follow the same rule ([`images_for_output`]).

use std::path::{Component, Path, PathBuf};

use anyhow::{bail, Context, Result};

use super::atomic::write_atomic;
use super::ObjMaterial;

/// The `mtllib` names an output OBJ at `path` writes for `material`,
/// after writing its own library and images when it needs them.
pub(crate) fn libraries_for_output(path: &Path, material: &ObjMaterial) -> Result<Vec<String>> {
    let out_dir = absolute_dir(path);
    let beside = material
        .libraries
        .iter()
        .all(|library| absolute_dir(library) == out_dir);
    if beside {
        return Ok(material.libraries.iter().map(|l| file_name(l)).collect());
    }
    let own = path.with_extension("mtl");
    if let Some(input) = material.libraries.iter().find(|l| same_file(l, &own)) {
        bail!(
            "{}: the output's material library would replace the input's {}: write the output to another name or directory",
            own.display(),
            input.display()
        );
    }
    // The images go into a directory of the output's own, so outputs
    // written side by side (a batch) never share or overwrite one.
    let folder = own_folder(path);
    let mut text = String::new();
    // A library that cannot be read is named as it was: the reader of the
    // output finds it missing, as it found the input's.
    let mut missing = Vec::new();
    for library in &material.libraries {
        match std::fs::read(library) {
            Ok(bytes) => {
                let from = absolute_dir(library);
                let library_text = String::from_utf8_lossy(&bytes);
                let copied = rebased(&library_text, |image| {
                    copy_image(&from, image, &out_dir, &folder)
                });
                text.push_str(&copied?);
            }
            Err(_) => missing.push(file_name(library)),
        }
    }
    if missing.len() == material.libraries.len() {
        return Ok(missing);
    }
    write_atomic(&own, |w| w.write_all(text.as_bytes()))?;
    Ok([file_name(&own)].into_iter().chain(missing).collect())
}

/// The names an output at `path` gives `images` (a PLY's texture files):
/// their file names when they are in the output's directory, else the
/// names of their copies in the output's own folder (see the module doc).
pub(crate) fn images_for_output(path: &Path, images: &[PathBuf]) -> Result<Vec<String>> {
    let out_dir = absolute_dir(path);
    if images.iter().all(|image| absolute_dir(image) == out_dir) {
        return Ok(images.iter().map(|image| file_name(image)).collect());
    }
    let folder = own_folder(path);
    images
        .iter()
        .map(|image| copy_image(&absolute_dir(image), &file_name(image), &out_dir, &folder))
        .collect()
}

/// The folder an output's copied images go in: `<name>_textures`.
pub(super) fn own_folder(path: &Path) -> String {
    let stem = path
        .file_stem()
        .map_or(String::new(), |s| s.to_string_lossy().into_owned());
    format!("{stem}_textures")
}

/// Copies the image a library in `from` names as `image` into the
/// directory `folder` of `out_dir`, and returns its name from `out_dir`:
/// `folder/` then the same relative path when the image is below `from`,
/// else its file name. A missing image is named as it was.
pub(super) fn copy_image(from: &Path, image: &str, out_dir: &Path, folder: &str) -> Result<String> {
    let source = normalised(&from.join(image));
    if !source.is_file() {
        return Ok(image.to_string());
    }
    let below = Path::new(image)
        .components()
        .all(|c| matches!(c, Component::Normal(_) | Component::CurDir));
    let name = match below {
        true => format!("{folder}/{}", image.replace('\\', "/")),
        false => format!("{folder}/{}", file_name(&source)),
    };
    copy_file(&source, &out_dir.join(&name))?;
    Ok(name)
}

/// Copies the image `source` to `target` (nothing to do when they are
/// one file).
pub(super) fn copy_file(source: &Path, target: &Path) -> Result<()> {
    if same_file(source, target) {
        return Ok(());
    }
    let bytes = std::fs::read(source)
        .with_context(|| format!("cannot read the texture image {}", source.display()))?;
    write_atomic(target, |w| w.write_all(&bytes))
}

fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// A library's text with each image (the last word of a `map_…`, `bump`,
/// `disp`, `decal`, `refl` or `norm` line) renamed by `rename`.
fn rebased(text: &str, mut rename: impl FnMut(&str) -> Result<String>) -> Result<String> {
    let mut out = String::with_capacity(text.len());
    for line in super::lines(text) {
        let mut words = line.split_whitespace();
        let keyword = words.next().unwrap_or("");
        let names_image = keyword.starts_with("map_")
            || ["bump", "disp", "decal", "refl", "norm"].contains(&keyword);
        match words.last() {
            Some(image) if names_image => {
                let start = line.rfind(image).unwrap_or(line.len());
                out.push_str(&line[..start]);
                out.push_str(&rename(image)?);
            }
            _ => out.push_str(line),
        }
        out.push('\n');
    }
    Ok(out)
}

/// The absolute directory a file is in.
pub(super) fn absolute_dir(file: &Path) -> PathBuf {
    let dir = file.parent().unwrap_or(Path::new(""));
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    normalised(dir)
}

/// An absolute path without `.` and with `..` applied to the parts
/// before it (as written, without following links).
fn normalised(path: &Path) -> PathBuf {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut out = PathBuf::new();
    for component in absolute.components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

pub(super) fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn image_names_replaced_options_kept() {
        let text = "newmtl m\nKd 1 1 1\nmap_Kd -s 1 1 1 tex/a.png\r\nbump b.png\nmap_Ka\n";
        let renamed = rebased(text, |image| Ok(format!("<{image}>"))).unwrap();
        assert_eq!(
            renamed,
            "newmtl m\nKd 1 1 1\nmap_Kd -s 1 1 1 <tex/a.png>\nbump <b.png>\nmap_Ka\n"
        );
    }

    #[test]
    fn images_copied_into_the_outputs_folder() {
        let dir = tempfile::tempdir().unwrap();
        let (input, output) = (dir.path().join("in"), dir.path().join("out"));
        std::fs::create_dir_all(input.join("tex")).unwrap();
        std::fs::write(input.join("tex/a.png"), b"A").unwrap();
        std::fs::write(dir.path().join("b.png"), b"B").unwrap();
        let copy = |image: &str| copy_image(&input, image, &output, "scan_textures").unwrap();
        assert_eq!(copy("tex/a.png"), "scan_textures/tex/a.png");
        assert_eq!(
            std::fs::read(output.join("scan_textures/tex/a.png")).unwrap(),
            b"A"
        );
        // Outside the library's directory: by its file name.
        assert_eq!(copy("../b.png"), "scan_textures/b.png");
        assert_eq!(
            std::fs::read(output.join("scan_textures/b.png")).unwrap(),
            b"B"
        );
        // Missing: named as it was, nothing written.
        assert_eq!(copy("c.png"), "c.png");
        assert!(!output.join("scan_textures/c.png").exists());
    }
}
