//! The batch's list of work: which files are inputs, where each output
//! goes, which cloud (if any) each mesh is trimmed with, and which shard
//! this run takes. Everything here is decided before any file is
//! processed, and decided the same way on every machine, so the shards of
//! one command line never overlap or miss a file.

use std::collections::{HashMap, HashSet};
use std::ffi::OsStr;
use std::io::ErrorKind;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use anyhow::{bail, Context, Result};

use crate::io::Format;

/// Extensions of mesh inputs (any case).
const MESH_EXTENSIONS: [&str; 5] = ["stl", "ply", "obj", "gltf", "glb"];

/// One mesh of the batch.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Job {
    /// The mesh, as found (the argument, or below a directory argument).
    pub input: PathBuf,
    /// Where its output goes.
    pub output: PathBuf,
    /// Where its edges go, when asked for: `S.edges.EXT` beside the
    /// output `S.ext`.
    pub edges: Option<PathBuf>,
    /// The cloud it is trimmed with.
    pub cloud: CloudMatch,
}

/// The clouds found for a mesh.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CloudMatch {
    /// None: the mesh is cleaned.
    None,
    /// One: the mesh is trimmed with it.
    One(PathBuf),
    /// Several (sorted): the mesh fails, as the choice would be a guess.
    Several(Vec<PathBuf>),
}

/// The K-th of N shards (1-based) of the sorted input list: the inputs at
/// 0-based positions i with i % N == K - 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// K, from 1 to N.
    pub index: usize,
    /// N, at least 1.
    pub count: usize,
}

impl FromStr for Shard {
    type Err = String;

    fn from_str(s: &str) -> Result<Shard, String> {
        let Some((k, n)) = s.split_once('/') else {
            return Err(format!("'{s}': expected K/N, e.g. 2/8"));
        };
        let number = |x: &str| x.trim().parse::<usize>();
        let (Ok(index), Ok(count)) = (number(k), number(n)) else {
            return Err(format!("'{s}': K and N must be whole numbers, e.g. 2/8"));
        };
        if count == 0 {
            return Err(format!("'{s}': N must be at least 1"));
        }
        if index < 1 || index > count {
            return Err(format!("'{s}': K must be between 1 and N"));
        }
        Ok(Shard { index, count })
    }
}

impl Shard {
    /// Whether the input at 0-based position `i` of the sorted list is in
    /// this shard.
    pub fn holds(self, i: usize) -> bool {
        i % self.count == self.index - 1
    }
}

/// What the plan is made from: the batch's path arguments.
pub struct Inputs<'a> {
    /// Files, directories and glob patterns.
    pub args: &'a [PathBuf],
    /// The output directory.
    pub out_dir: &'a Path,
    /// Where clouds are looked for instead of beside the meshes.
    pub cloud_dir: Option<&'a Path>,
    /// The report file, checked against the inputs too.
    pub report: Option<&'a Path>,
    /// The outputs' extension (a mesh format's) instead of the inputs'.
    pub to: Option<&'a str>,
    /// The edges files' extension, when each output's edges are written.
    pub edges_to: Option<&'a str>,
}

/// The whole batch (every shard), sorted by input path: expands the
/// arguments, pairs meshes with clouds and refuses, before any work, two
/// inputs sharing an output and outputs that would overwrite an input.
pub fn plan(inputs: &Inputs) -> Result<Vec<Job>> {
    if let Some(extension) = inputs.to {
        if !MESH_EXTENSIONS.contains(&extension.to_ascii_lowercase().as_str()) {
            bail!("cannot write meshes as '.{extension}': the extension must be one of obj, ply, stl, glb, gltf");
        }
    }
    if let Some(extension) = inputs.edges_to {
        let named = Path::new("edges").with_extension(extension);
        if crate::io::edges_out::EdgesFormat::from_path(&named).is_none() {
            bail!("cannot write edges as '.{extension}': the extension must be one of json, obj, svg, dxf, step, igs");
        }
    }
    if let Some(dir) = inputs.cloud_dir {
        if !dir.is_dir() {
            bail!("{}: --cloud-dir is not a directory", dir.display());
        }
    }
    let found = expand(inputs.args, inputs.out_dir)?;
    let mut clouds = CloudIndex::default();
    let jobs = found
        .into_iter()
        .map(|f| {
            let cloud = clouds.find(&f, inputs.cloud_dir)?;
            let mut output = inputs.out_dir.join(&f.rel);
            if let Some(extension) = inputs.to {
                output.set_extension(extension);
            }
            Ok(Job {
                input: f.path,
                edges: inputs.edges_to.map(|ext| edges_beside(&output, ext)),
                output,
                cloud,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    check_collisions(&jobs)?;
    check_overwrites(&jobs, inputs.report)?;
    Ok(jobs)
}

/// The edges file of the output `S.ext`: `S.edges.EXT`, beside it.
fn edges_beside(output: &Path, extension: &str) -> PathBuf {
    let stem = output.file_stem().unwrap_or(output.as_os_str());
    let mut name = stem.to_os_string();
    name.push(format!(".edges.{extension}"));
    output.with_file_name(name)
}

/// A mesh input found from an argument, with its output path relative to
/// the output directory.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
struct Found {
    path: PathBuf,
    rel: PathBuf,
}

/// Expands every argument, then sorts by path and drops second names of
/// one file (the same file through two arguments), so the list depends on
/// the set of arguments, not their order.
fn expand(args: &[PathBuf], out_dir: &Path) -> Result<Vec<Found>> {
    // Outputs of an earlier run must not become inputs when the output
    // directory is inside an input directory.
    let skip = out_dir.canonicalize().ok();
    let mut found = Vec::new();
    for arg in args {
        found.extend(expand_one(arg, skip.as_deref())?);
    }
    found.sort();
    let mut seen = HashSet::new();
    found.retain(|f| seen.insert(f.path.canonicalize().unwrap_or_else(|_| f.path.clone())));
    if found.is_empty() {
        bail!("no mesh files (.stl, .ply, .obj, .gltf, .glb) found in the inputs");
    }
    Ok(found)
}

/// One argument: an existing directory is walked, an existing file must be
/// a mesh, anything else must be a glob pattern that matches a mesh.
fn expand_one(arg: &Path, skip: Option<&Path>) -> Result<Vec<Found>> {
    match std::fs::metadata(arg) {
        Ok(m) if m.is_dir() => {
            let mut found = Vec::new();
            walk(arg, arg, skip, &mut found)?;
            Ok(found)
        }
        Ok(_) => {
            if !is_mesh_input(arg) {
                bail!(
                    "{}: not a mesh input: meshes end in .stl, .ply, .obj, .gltf or .glb, and \
                     STEM.cloud.EXT names a cloud",
                    arg.display()
                );
            }
            Ok(vec![Found {
                path: arg.to_path_buf(),
                rel: file_name(arg),
            }])
        }
        Err(e) if e.kind() == ErrorKind::NotFound && is_pattern(arg) => expand_glob(arg, skip),
        Err(e) => Err(e).with_context(|| format!("{}: cannot read", arg.display())),
    }
}

/// Walks `dir` recursively in name order, collecting mesh inputs with
/// their paths relative to `root`. Symbolic links to files are followed,
/// to directories not (a link can make a cycle). A sub-directory that is
/// the output directory `skip` is left out (the root itself is not: then
/// the outputs would overwrite the inputs, which the plan refuses).
fn walk(dir: &Path, root: &Path, skip: Option<&Path>, found: &mut Vec<Found>) -> Result<()> {
    let entries = std::fs::read_dir(dir)
        .and_then(|d| d.collect::<std::io::Result<Vec<_>>>())
        .with_context(|| format!("{}: cannot read the directory", dir.display()))?;
    let mut paths: Vec<_> = entries.iter().map(|e| e.path()).collect();
    paths.sort();
    for path in paths {
        let kind = std::fs::symlink_metadata(&path)
            .with_context(|| format!("{}: cannot read", path.display()))?
            .file_type();
        if kind.is_dir() {
            if skip.is_none() || path.canonicalize().ok().as_deref() != skip {
                walk(&path, root, skip, found)?;
            }
        } else if (kind.is_file() || path.is_file()) && is_mesh_input(&path) && !paired_cloud(&path)
        {
            let rel = path.strip_prefix(root).unwrap_or(&path).to_path_buf();
            found.push(Found { path, rel });
        }
    }
    Ok(())
}

/// The meshes a glob pattern matches outside the output directory (so a
/// second run does not take the first one's outputs for inputs); a
/// pattern matching none is an error, as it is most likely a typo.
fn expand_glob(pattern: &Path, skip: Option<&Path>) -> Result<Vec<Found>> {
    let text = pattern
        .to_str()
        .with_context(|| format!("{}: not valid UTF-8", pattern.display()))?;
    let paths = glob::glob(text).with_context(|| format!("{text}: bad glob pattern"))?;
    let (mut found, mut outputs) = (Vec::new(), 0);
    for path in paths {
        let path = path.with_context(|| format!("{text}: cannot read a match"))?;
        if !path.is_file() || !is_mesh_input(&path) || paired_cloud(&path) {
            continue;
        }
        if skip.is_some_and(|s| path.canonicalize().is_ok_and(|p| p.starts_with(s))) {
            outputs += 1;
        } else {
            let rel = file_name(&path);
            found.push(Found { path, rel });
        }
    }
    if found.is_empty() {
        bail!(
            "{text}: no such file, and as a glob pattern it matches no mesh file{}",
            match outputs {
                0 => String::new(),
                n => format!(" outside --out-dir ({n} inside)"),
            }
        );
    }
    Ok(found)
}

fn is_pattern(arg: &Path) -> bool {
    arg.to_string_lossy().contains(['*', '?', '['])
}

fn file_name(path: &Path) -> PathBuf {
    PathBuf::from(path.file_name().unwrap_or(path.as_os_str()))
}

fn extension(path: &Path) -> String {
    path.extension()
        .and_then(OsStr::to_str)
        .unwrap_or("")
        .to_ascii_lowercase()
}

/// A mesh input has a mesh extension and is not named as a cloud.
fn is_mesh_input(path: &Path) -> bool {
    MESH_EXTENSIONS.contains(&extension(path).as_str()) && cloud_stem(path).is_none()
}

/// The stem of the mesh a cloud file belongs to, if `path` names a cloud:
/// `STEM.cloud.EXT` (EXT any cloud format) or `STEM.EXT` (EXT a format
/// only clouds have); `.cloud` and EXT in any case.
fn cloud_stem(path: &Path) -> Option<&str> {
    // The cloud reader's own extensions, so that every format it reads
    // pairs; PLY and OBJ name meshes too.
    let format = Format::from_extension(&extension(path))?;
    let cloud_only = !matches!(format, Format::Ply | Format::Obj);
    let stem = path.file_stem()?.to_str()?;
    let cut = stem.len().saturating_sub(".cloud".len());
    match stem.get(cut..) {
        Some(tail) if tail.eq_ignore_ascii_case(".cloud") && cut > 0 => Some(&stem[..cut]),
        _ if cloud_only => Some(stem),
        _ => None,
    }
}

/// A `.ply` or `.obj` file that sits beside a mesh of the same stem with
/// another mesh extension (`part.ply` beside `part.stl`) and holds no
/// faces is that mesh's cloud, not an input: a cloud with the same stem
/// and a cloud extension. Only the header (PLY) or the lines (OBJ) are
/// read.
fn paired_cloud(path: &Path) -> bool {
    let ext = extension(path);
    if !matches!(ext.as_str(), "ply" | "obj") || cloud_stem(path).is_some() {
        return false;
    }
    let has_mesh_sibling = MESH_EXTENSIONS.iter().filter(|&&e| e != ext).any(|e| {
        [e.to_string(), e.to_ascii_uppercase()]
            .iter()
            .any(|e| path.with_extension(e).is_file())
    });
    has_mesh_sibling && !has_faces(path, &ext)
}

/// True if a PLY header declares faces (or a range grid) or an OBJ file
/// has an `f` line; unreadable files count as meshes (they fail later,
/// with their own error).
fn has_faces(path: &Path, ext: &str) -> bool {
    use std::io::{BufRead, BufReader};
    let Ok(file) = std::fs::File::open(path) else {
        return true;
    };
    let mut lines = BufReader::new(file).split(b'\n');
    if ext == "obj" {
        // The OBJ reader's rule: a line whose first word is `f`, lines
        // ended by \n, \r\n or a lone \r.
        return lines
            .map_while(std::result::Result::ok)
            .any(|l| l.split(|&b| b == b'\r').any(is_face_line));
    }
    for line in lines
        .by_ref()
        .take(10_000)
        .map_while(std::result::Result::ok)
    {
        let text = String::from_utf8_lossy(&line);
        let words: Vec<&str> = text.split_whitespace().collect();
        match words.as_slice() {
            ["end_header"] => return false,
            ["element", "face" | "range_grid", count]
                if count.parse::<u64>().map_or(true, |n| n > 0) =>
            {
                return true;
            }
            _ => {}
        }
    }
    true
}

/// An OBJ line whose first word is `f`, indented or not.
fn is_face_line(line: &[u8]) -> bool {
    line.split(u8::is_ascii_whitespace).find(|w| !w.is_empty()) == Some(b"f")
}

/// The clouds of each directory looked in, listed once (a batch of
/// thousands of meshes in one directory must not list it thousands of
/// times).
#[derive(Default)]
struct CloudIndex {
    dirs: HashMap<PathBuf, HashMap<String, Vec<PathBuf>>>,
}

impl CloudIndex {
    /// The clouds of a mesh: beside it, or in the cloud directory below
    /// the mesh's sub-directory.
    fn find(&mut self, mesh: &Found, cloud_dir: Option<&Path>) -> Result<CloudMatch> {
        let dir = match cloud_dir {
            Some(d) => d.join(mesh.rel.parent().unwrap_or(Path::new(""))),
            None => mesh.path.parent().unwrap_or(Path::new("")).to_path_buf(),
        };
        let Some(stem) = mesh.path.file_stem().and_then(OsStr::to_str) else {
            return Ok(CloudMatch::None);
        };
        let clouds = match self.dirs.entry(dir) {
            std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => {
                let listed = list_clouds(e.key())?;
                e.insert(listed)
            }
        };
        Ok(match clouds.get(stem).map(Vec::as_slice) {
            None | Some([]) => CloudMatch::None,
            Some([one]) => CloudMatch::One(one.clone()),
            Some(several) => CloudMatch::Several(several.to_vec()),
        })
    }
}

/// The cloud files of a directory by the stem they belong to, sorted; a
/// missing directory has none.
fn list_clouds(dir: &Path) -> Result<HashMap<String, Vec<PathBuf>>> {
    let listing = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let entries = match std::fs::read_dir(listing) {
        Err(e) if e.kind() == ErrorKind::NotFound => return Ok(HashMap::new()),
        other => other
            .and_then(|d| d.collect::<std::io::Result<Vec<_>>>())
            .with_context(|| format!("{}: cannot read the directory", listing.display()))?,
    };
    let mut clouds: HashMap<String, Vec<PathBuf>> = HashMap::new();
    for entry in entries {
        let name = PathBuf::from(entry.file_name());
        let path = dir.join(&name);
        let stem = cloud_stem(&name).or_else(|| {
            paired_cloud(&path)
                .then(|| name.file_stem().and_then(OsStr::to_str))
                .flatten()
        });
        if let Some(stem) = stem {
            clouds.entry(stem.to_string()).or_default().push(path);
        }
    }
    clouds.values_mut().for_each(|v| v.sort());
    Ok(clouds)
}

/// Two inputs writing one output would lose one of them: refused,
/// naming both.
fn check_collisions(jobs: &[Job]) -> Result<()> {
    let mut outputs: HashMap<&Path, &Path> = HashMap::new();
    for job in jobs {
        if let Some(first) = outputs.insert(&job.output, &job.input) {
            bail!(
                "{} and {} would both be written to {}: give them in separate batches, or \
                 give a directory holding both (its sub-directories are mirrored)",
                first.display(),
                job.input.display(),
                job.output.display()
            );
        }
    }
    for job in jobs {
        let Some(edges) = &job.edges else { continue };
        if let Some(first) = outputs.insert(edges, &job.input) {
            bail!(
                "{} and {} would both be written to {} (an edges file is S.edges.EXT beside \
                 the output S.ext): give them in separate batches",
                first.display(),
                job.input.display(),
                edges.display()
            );
        }
    }
    Ok(())
}

/// No output (nor the report) may be an input or a cloud: refused by
/// comparing canonical paths of the outputs that exist already.
fn check_overwrites(jobs: &[Job], report: Option<&Path>) -> Result<()> {
    let canonical = |p: &Path| p.canonicalize().ok();
    let mut inputs = HashMap::new();
    for job in jobs {
        let clouds = match &job.cloud {
            CloudMatch::None => &[][..],
            CloudMatch::One(c) => std::slice::from_ref(c),
            CloudMatch::Several(v) => v.as_slice(),
        };
        for path in std::iter::once(&job.input).chain(clouds) {
            if let Some(c) = canonical(path) {
                inputs.insert(c, path);
            }
        }
    }
    // The advice names the option that chose the path at fault.
    let outputs = jobs.iter().flat_map(|j| {
        let edges = j.edges.as_deref().map(|e| (e, "edges file", "--out-dir"));
        std::iter::once((j.output.as_path(), "output", "--out-dir")).chain(edges)
    });
    let report = report.map(|r| (r, "report", "--report"));
    for (out, what, option) in outputs.chain(report) {
        if let Some(input) = canonical(out).and_then(|c| inputs.get(&c)) {
            bail!(
                "{}: the {what} would overwrite the input {}: choose another {option}",
                out.display(),
                input.display()
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_partition() {
        let s: Shard = "2/3".parse().unwrap();
        assert_eq!(s, Shard { index: 2, count: 3 });
        let held: Vec<usize> = (0..8).filter(|&i| s.holds(i)).collect();
        assert_eq!(held, [1, 4, 7]);
        for bad in ["0/4", "5/4"] {
            let e = bad.parse::<Shard>().unwrap_err();
            assert!(e.contains("K must be between 1 and N"), "{e}");
        }
        assert!("1/0".parse::<Shard>().unwrap_err().contains("at least 1"));
        assert!("3".parse::<Shard>().unwrap_err().contains("K/N"));
        assert!("a/b".parse::<Shard>().unwrap_err().contains("whole"));
    }

    #[test]
    fn clouds_and_meshes_by_name() {
        let stem = |s: &str| cloud_stem(Path::new(s)).map(str::to_string);
        assert_eq!(stem("a/blade.cloud.ply"), Some("blade".into()));
        assert_eq!(stem("blade.CLOUD.PCD"), Some("blade".into()));
        assert_eq!(stem("blade.xyz"), Some("blade".into()));
        assert_eq!(stem("b.pcd"), Some("b".into()));
        assert_eq!(stem("part.e57"), Some("part".into()));
        assert_eq!(stem("part.LAZ"), Some("part".into()));
        assert_eq!(stem("part.cloud.las"), Some("part".into()));
        assert_eq!(stem("blade.ply"), None);
        assert_eq!(stem("blade.cloud.stl"), None);
        assert_eq!(stem(".cloud.ply"), None);
        assert!(is_mesh_input(Path::new("x/blade.PLY")));
        assert!(is_mesh_input(Path::new("blade.cloud.stl")));
        assert!(!is_mesh_input(Path::new("blade.cloud.ply")));
        assert!(!is_mesh_input(Path::new("blade.xyz")));
    }

    #[test]
    fn edges_files_sit_beside_their_outputs() {
        let beside = |out: &str, ext: &str| edges_beside(Path::new(out), ext);
        assert_eq!(
            beside("out/a/part.stl", "dxf"),
            Path::new("out/a/part.edges.dxf")
        );
        assert_eq!(
            beside("out/part.v2.ply", "step"),
            Path::new("out/part.v2.edges.step")
        );
        assert_eq!(beside("out/part", "json"), Path::new("out/part.edges.json"));
    }

    /// An OBJ beside a mesh of its stem is that mesh's cloud only if the
    /// OBJ reader finds no face in it. Face lines that are indented, or
    /// ended by a lone \r, count too; missed, they would leave the mesh
    /// taken for a cloud, not processed, and its sibling trimmed by it
    /// instead of cleaned.
    #[test]
    fn obj_faces_are_found_as_the_reader_finds_them() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("part.stl"), b"").unwrap();
        let obj = dir.path().join("part.obj");
        for (text, cloud) in [
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\n", true),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", false),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\n  f 1 2 3\n", false),
            ("v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r", false),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\n# f 1 2 3\nfo 1\n", true),
        ] {
            std::fs::write(&obj, text).unwrap();
            assert_eq!(paired_cloud(&obj), cloud, "{text:?}");
        }
    }
}
