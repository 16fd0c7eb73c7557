//! The top-level parser: `meshtrim MESH CLOUD OUT`, or one subcommand.
//!
//! Each command owns its arguments (`commands::*::Args`); this module only
//! assembles them, and only `main` imports it.

use clap::{Parser, Subcommand};

use crate::commands::{batch, clean, detect, edges, mesh, trim};

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
    subcommand_negates_reqs = true,
    arg_required_else_help = true
)]
pub struct Cli {
    /// A stage on its own.
    #[command(subcommand)]
    pub command: Option<Command>,
    /// The main job (`meshtrim MESH CLOUD OUT`), when no subcommand is given.
    #[command(flatten)]
    pub trim: Option<trim::Args>,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Label the boundary points of a point cloud (BPD) and print a summary.
    Detect(detect::Args),
    /// Detect the boundary, then group it into closed loops, find their
    /// corners and smooth their edges (the paper's RBS); write the edges.
    Edges(edges::Args),
    /// Trim a mesh along its cloud's smoothed boundary (the same as
    /// `meshtrim MESH CLOUD OUT`).
    Trim(trim::Args),
    /// Mesh the cloud itself: constrained Delaunay triangulation in its
    /// best-fit plane, bounded by the smoothed loops (spade).
    Mesh(mesh::Args),
    /// Smooth the jagged border of a triangulated scan (its own vertices
    /// are the cloud): the border is replaced by the smoothed boundary,
    /// the gap filled with new faces on the surface.
    Clean(clean::Args),
    /// Clean or trim many meshes at once: files, directories and glob
    /// patterns in, one output each under --out-dir, a line per file and a
    /// summary report.
    Batch(batch::Args),
}
