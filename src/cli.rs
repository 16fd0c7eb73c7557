//! The command line: one subcommand per pipeline stage.
//!
//! Each subcommand has its own argument struct and `run` function, so adding
//! a stage (edges, mesh, trim, clean, batch) is one enum variant and one
//! match arm.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, Parser, Subcommand};

/// Boundary detection, edge smoothing and trimming of meshes from 3D scans.
#[derive(Debug, Parser)]
#[command(name = "meshtrim", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Label the boundary points of a point cloud (BPD) and print a summary.
    Detect(DetectArgs),
    /// Detect the boundary, then group it into closed loops, find their
    /// corners and smooth their edges (the paper's RBS); write the edges.
    Edges(EdgesArgs),
}

/// Arguments of `meshtrim detect`.
#[derive(Debug, Clone, Args)]
pub struct DetectArgs {
    /// Input point cloud: .ply, .pcd, .obj, .xyz/.txt/.csv/.asc/.pts.
    pub cloud: PathBuf,
    /// Write the points with their labels: OUT.ply (binary) or OUT.csv.
    /// Missing parent directories are created.
    #[arg(short, long, value_name = "OUT")]
    pub output: Option<PathBuf>,
    /// Neighbourhood size, the point itself included.
    #[arg(long, default_value_t = 30)]
    pub k: usize,
    /// Use the paper's isotropic tests, without the sampling-tensor map.
    #[arg(long)]
    pub no_anisotropy: bool,
    /// Print the summary as one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `meshtrim edges`.
#[derive(Debug, Clone, Args)]
pub struct EdgesArgs {
    /// Input point cloud: .ply, .pcd, .obj, .xyz/.txt/.csv/.asc/.pts.
    pub cloud: PathBuf,
    /// Write the loops and edges: OUT.json (everything), OUT.obj (the
    /// smoothed edges as polylines) or OUT.svg (a picture). Missing parent
    /// directories are created.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Neighbourhood size of boundary detection, the point itself included.
    #[arg(long, default_value_t = 30)]
    pub k: usize,
    /// Use the paper's isotropic detection tests, without the
    /// sampling-tensor map.
    #[arg(long)]
    pub no_anisotropy: bool,
    /// Keep the smoothed edges where the boundary points are (the paper's
    /// edges) instead of moving them out to the surface's estimated edge.
    #[arg(long)]
    pub no_offset: bool,
    /// Print the summary as one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// Runs the chosen subcommand.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Detect(args) => crate::detect::run(&args),
        Command::Edges(args) => crate::edges::run(&args),
    }
}
