//! The command line: one subcommand per pipeline stage.
//!
//! Each subcommand has its own argument struct and `run` function, so adding
//! a stage (edges, mesh, trim, clean, batch) is one enum variant and one
//! match arm.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, Parser, Subcommand};
use trim::{BpdOptions, View};

/// Boundary detection, edge smoothing and trimming of meshes from 3D scans.
///
/// The main job: `meshtrim MESH CLOUD OUT` cuts MESH (reconstructed from
/// CLOUD, e.g. by screened Poisson) along CLOUD's smoothed boundary and
/// writes what the cloud supports to OUT. The subcommands run the stages.
#[derive(Debug, Parser)]
#[command(
    name = "meshtrim",
    version,
    about,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
pub struct Cli {
    /// A stage on its own.
    #[command(subcommand)]
    pub command: Option<Command>,
    /// The main job (`meshtrim MESH CLOUD OUT`), when no subcommand is given.
    #[command(flatten)]
    pub trim: Option<TrimArgs>,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Label the boundary points of a point cloud (BPD) and print a summary.
    Detect(DetectArgs),
    /// Detect the boundary, then group it into closed loops, find their
    /// corners and smooth their edges (the paper's RBS); write the edges.
    Edges(EdgesArgs),
    /// Trim a mesh along its cloud's smoothed boundary (the same as
    /// `meshtrim MESH CLOUD OUT`).
    Trim(TrimArgs),
    /// Mesh the cloud itself: constrained Delaunay triangulation in its
    /// best-fit plane, bounded by the smoothed loops (spade).
    Mesh(MeshArgs),
    /// Smooth the jagged border of a triangulated scan (its own vertices
    /// are the cloud): the border is replaced by the smoothed boundary,
    /// the gap filled with new faces on the surface.
    Clean(CleanArgs),
    /// Clean or trim many meshes at once: files, directories and glob
    /// patterns in, one output each under --out-dir, a line per file and a
    /// summary report.
    Batch(BatchArgs),
}

/// Arguments of `meshtrim batch`.
#[derive(Debug, Clone, Args)]
pub struct BatchArgs {
    /// Meshes (.stl, .ply, .obj, .gltf, .glb): files, directories (walked
    /// recursively) and glob patterns (quote them: 'scans/*.ply'). A mesh
    /// S.ext is trimmed when a cloud S.cloud.EXT or S.EXT with EXT one of
    /// pcd xyz txt csv asc pts sits beside it, and cleaned otherwise;
    /// clouds are never inputs themselves.
    #[arg(required = true, value_name = "INPUTS")]
    pub inputs: Vec<PathBuf>,
    /// Where the outputs go: the input's path below the directory argument
    /// it was found in (or its file name), same extension.
    #[arg(long, value_name = "DIR")]
    pub out_dir: PathBuf,
    /// Look for the clouds here (mirroring the inputs' sub-directories)
    /// instead of beside the meshes.
    #[arg(long, value_name = "DIR")]
    pub cloud_dir: Option<PathBuf>,
    /// Files processed at once, and threads in all [default: all cores].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub jobs: Option<u16>,
    /// Write a line per file to FILE.csv or FILE.json.
    #[arg(long, value_name = "FILE.csv|FILE.json")]
    pub report: Option<PathBuf>,
    /// Skip inputs whose output exists (resumes an interrupted batch).
    #[arg(long)]
    pub skip_existing: bool,
    /// Process only the K-th of N deterministic shards of the sorted input
    /// list (1-based), e.g. one per machine or array task.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<crate::batch::Shard>,
    /// Detection and edge options.
    #[command(flatten)]
    pub stages: Stages,
}

/// Arguments of `meshtrim clean`.
#[derive(Debug, Clone, Args)]
pub struct CleanArgs {
    /// The mesh: .obj, .ply, .stl, .gltf or .glb.
    pub input: PathBuf,
    /// The cleaned mesh: .obj, .ply (binary), .stl (binary), .gltf or
    /// .glb. Missing parent directories are created.
    pub output: PathBuf,
    /// Also write the report as JSON to this file.
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
    /// Detection and edge options.
    #[command(flatten)]
    pub stages: Stages,
    /// Print the report as one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// The options of detection and edge reconstruction that every command
/// after `detect` shares.
#[derive(Debug, Clone, PartialEq, Args)]
pub struct Stages {
    /// Neighbourhood size of boundary detection, the point itself included.
    #[arg(long, default_value_t = 30, value_parser = parse_k)]
    pub k: usize,
    /// Use the paper's isotropic detection, without the sampling-tensor map.
    #[arg(long)]
    pub no_anisotropy: bool,
    /// Use the paper's edges, through the boundary points, instead of the
    /// estimated physical edge half a row beyond them.
    #[arg(long)]
    pub no_offset: bool,
    /// Where a range scanner saw the cloud from.
    #[command(flatten)]
    pub view: ViewArgs,
}

impl Stages {
    /// Boundary detection's options.
    pub fn bpd_options(&self) -> BpdOptions {
        bpd_options(self.k, self.no_anisotropy, &self.view)
    }
}

/// Where a range scanner (a depth camera, a laser line or structured-light
/// scanner) saw the cloud from, when it is known. Such scanners err along
/// their line of sight; with it, detection projects each neighbourhood
/// along it instead of along the neighbourhood's normal, so that depth
/// noise and the terraces of a quantised depth do not open gaps where the
/// surface is inclined to the scanner (docs/bpd.md, "Scanner's line of
/// sight").
#[derive(Debug, Clone, Copy, PartialEq, Default, Args)]
pub struct ViewArgs {
    /// The scanner's line of sight as a direction X,Y,Z in the cloud's
    /// frame (either sense), for a distant scanner or a frame whose axis it
    /// looked along, e.g. 0,0,1.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_direction, allow_hyphen_values = true, conflicts_with = "view_from")]
    pub view_along: Option<[f64; 3]>,
    /// The scanner's position X,Y,Z in the cloud's frame (a depth camera's
    /// centre: 0,0,0 for a cloud in the camera's own frame); the line of
    /// sight to each point runs from there.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vector, allow_hyphen_values = true)]
    pub view_from: Option<[f64; 3]>,
}

impl ViewArgs {
    /// The view, if one was given.
    pub fn view(&self) -> Option<View> {
        self.view_along
            .map(View::Along)
            .or(self.view_from.map(View::From))
    }
}

/// Boundary detection's options from the command line's.
fn bpd_options(k: usize, no_anisotropy: bool, view: &ViewArgs) -> BpdOptions {
    BpdOptions {
        k,
        anisotropy: !no_anisotropy,
        view: view.view(),
    }
}

/// `--k`: a whole number of at least [`BpdOptions::MIN_K`]. Checked here,
/// not only by detection, so that a value it would refuse is a usage error
/// before any file is read: a batch used to read and fail every file on it.
fn parse_k(text: &str) -> Result<usize, String> {
    let k: usize = text.parse().map_err(|e| format!("{e}"))?;
    let min = BpdOptions::MIN_K;
    if k < min {
        return Err(format!(
            "k = {k} is too small: boundary detection needs k >= {min} \
             (the point itself and at least {} neighbours)",
            min - 1
        ));
    }
    Ok(k)
}

/// Three finite numbers separated by commas.
fn parse_vector(text: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [x, y, z] = parts.as_slice() else {
        return Err(format!(
            "expected three numbers X,Y,Z separated by commas, got {} part(s)",
            parts.len()
        ));
    };
    let number = |s: &str| match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!("`{s}` is not a finite number")),
        Err(_) => Err(format!("`{s}` is not a number")),
    };
    Ok([number(x)?, number(y)?, number(z)?])
}

/// A line of sight: [`parse_vector`], not zero.
fn parse_direction(text: &str) -> Result<[f64; 3], String> {
    let v = parse_vector(text)?;
    if v == [0.0; 3] {
        return Err("a direction cannot be 0,0,0".into());
    }
    Ok(v)
}

/// Arguments of `meshtrim mesh`.
#[derive(Debug, Clone, Args)]
pub struct MeshArgs {
    /// Input point cloud (any format `detect` reads).
    pub cloud: PathBuf,
    /// The mesh: .obj, .ply (binary), .stl (binary), .gltf or .glb.
    /// Missing parent directories are created.
    pub output: PathBuf,
    /// Also write the report as JSON to this file.
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
    /// Detection and edge options.
    #[command(flatten)]
    pub stages: Stages,
    /// Print the report as one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of the trimming (`meshtrim MESH CLOUD OUT`).
#[derive(Debug, Clone, Args)]
pub struct TrimArgs {
    /// The mesh to trim: .obj, .ply, .stl, .gltf or .glb.
    #[arg(required = true)]
    pub mesh: PathBuf,
    /// The point cloud the mesh was reconstructed from (any cloud format
    /// `detect` reads).
    #[arg(required = true)]
    pub cloud: PathBuf,
    /// The trimmed mesh: .obj, .ply (binary), .stl (binary), .gltf or .glb.
    /// Missing parent directories are created.
    #[arg(required = true)]
    pub output: PathBuf,
    /// Also write the report as JSON to this file.
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
    /// Neighbourhood size of boundary detection, the point itself included.
    #[arg(long, default_value_t = 30, value_parser = parse_k)]
    pub k: usize,
    /// Use the paper's isotropic detection, without the sampling-tensor map.
    #[arg(long)]
    pub no_anisotropy: bool,
    /// Use the paper's edges, through the boundary points, instead of the
    /// estimated physical edge half a row beyond them.
    #[arg(long)]
    pub no_offset: bool,
    /// The scanner's line of sight X,Y,Z (see `meshtrim detect --help`).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_direction, allow_hyphen_values = true, conflicts_with = "view_from")]
    pub view_along: Option<[f64; 3]>,
    /// The scanner's position X,Y,Z (see `meshtrim detect --help`).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vector, allow_hyphen_values = true)]
    pub view_from: Option<[f64; 3]>,
    /// Print the report as one JSON object.
    #[arg(long)]
    pub json: bool,
}

impl TrimArgs {
    /// The detection and edge options. (The main job's arguments spell
    /// them out: clap cannot tell whether a flattened group inside the
    /// optional top-level arguments was given.)
    pub fn stages(&self) -> Stages {
        Stages {
            k: self.k,
            no_anisotropy: self.no_anisotropy,
            no_offset: self.no_offset,
            view: ViewArgs {
                view_along: self.view_along,
                view_from: self.view_from,
            },
        }
    }
}

/// Arguments of `meshtrim detect`.
#[derive(Debug, Clone, Args)]
pub struct DetectArgs {
    /// Input point cloud: .ply, .pcd, .obj, .xyz/.txt/.csv/.asc/.pts, or a
    /// mesh (.stl, .gltf, .glb) whose vertices are the cloud.
    pub cloud: PathBuf,
    /// Write the points with their labels: OUT.ply (binary) or OUT.csv.
    /// Missing parent directories are created.
    #[arg(short, long, value_name = "OUT")]
    pub output: Option<PathBuf>,
    /// Neighbourhood size, the point itself included.
    #[arg(long, default_value_t = 30, value_parser = parse_k)]
    pub k: usize,
    /// Use the paper's isotropic tests, without the sampling-tensor map.
    #[arg(long)]
    pub no_anisotropy: bool,
    /// Where a range scanner saw the cloud from.
    #[command(flatten)]
    pub view: ViewArgs,
    /// Print the summary as one JSON object.
    #[arg(long)]
    pub json: bool,
}

impl DetectArgs {
    /// Boundary detection's options.
    pub fn bpd_options(&self) -> BpdOptions {
        bpd_options(self.k, self.no_anisotropy, &self.view)
    }
}

/// Arguments of `meshtrim edges`.
#[derive(Debug, Clone, Args)]
pub struct EdgesArgs {
    /// Input point cloud: .ply, .pcd, .obj, .xyz/.txt/.csv/.asc/.pts, or a
    /// mesh (.stl, .gltf, .glb) whose vertices are the cloud.
    pub cloud: PathBuf,
    /// Write the loops and edges: OUT.json (everything), OUT.obj (the
    /// smoothed edges as polylines) or OUT.svg (a picture). Missing parent
    /// directories are created.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Detection and edge options.
    #[command(flatten)]
    pub stages: Stages,
    /// Print the summary as one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// Runs the chosen subcommand.
pub fn run(cli: Cli) -> Result<()> {
    match (cli.command, cli.trim) {
        (Some(Command::Detect(args)), _) => crate::detect::run(&args),
        (Some(Command::Edges(args)), _) => crate::edges::run(&args),
        (Some(Command::Trim(args)), _) | (None, Some(args)) => crate::trim::run(&args),
        (Some(Command::Mesh(args)), _) => crate::mesh_cmd::run(&args),
        (Some(Command::Clean(args)), _) => crate::clean_cmd::run(&args),
        (Some(Command::Batch(args)), _) => crate::batch::run(&args),
        (None, None) => {
            anyhow::bail!("nothing to do: give MESH CLOUD OUT, or a subcommand (see --help)")
        }
    }
}
