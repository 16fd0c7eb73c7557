//! `meshtrim mesh CLOUD OUT`: the Delaunay path. Detect and smooth the
//! cloud's boundary, triangulate the cloud in its best-fit plane with the
//! smoothed loops as constraints (spade), lift back, write, report.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use serde::Serialize;
use trim::{delaunay_mesh_with_report, DelaunayOptions, DelaunayReport, Detection, Edges};

use crate::commands::args::{EdgeFileArgs, StageArgs};
use crate::io::mesh_out::write_mesh_carrying;
use crate::io::{read_cloud_with, CloudOptions, Point3, VertexAttributes};
use crate::report::{shown, write_edges, LoopsFrom};
use crate::stages::{detect_and_reconstruct, millis, Stages};

/// Arguments of `meshtrim mesh`.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// Input point cloud (any format `detect` reads).
    pub cloud: PathBuf,
    /// The mesh: .obj, .ply (binary), .stl (binary), .gltf or .glb.
    /// Missing parent directories are created.
    pub output: PathBuf,
    /// Also write the report as JSON to this file.
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
    /// Also write the smoothed edges that bound the mesh: FILE.json, .obj,
    /// .svg, .dxf, .step or .igs, the bytes `meshtrim edges CLOUD -o FILE` writes with
    /// the same options.
    #[arg(long, value_name = "FILE")]
    pub edges: Option<PathBuf>,
    /// Detection and edge options.
    #[command(flatten)]
    pub stages: StageArgs,
    /// Read only scan N of an E57 file (its 0-based data3D index); by
    /// default every scan is read, each in its pose, merged in the file's
    /// frame.
    #[arg(long, value_name = "N")]
    pub scan: Option<usize>,
    /// The unit declared, DXF splines.
    #[command(flatten)]
    pub file: EdgeFileArgs,
    /// Print the report as one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// What `mesh` prints and `--report` writes.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// The cloud, as given (none in memory).
    pub cloud: Option<String>,
    /// The output, as given (none in memory).
    pub output: Option<String>,
    /// Cloud points read.
    pub points: usize,
    /// Cloud points that are vertices of the output.
    pub points_used: usize,
    /// Cloud points outside the loops (beyond the border or in holes).
    pub points_outside: usize,
    /// Cloud points left out for lying next to a loop (within 0.3 β),
    /// which stands for the border there.
    pub points_near_loop: usize,
    /// Smoothed loops used as constraints.
    pub loops: usize,
    /// How the loops were found (see `meshtrim edges`).
    pub loops_from: LoopsFrom,
    /// Loop vertices dropped to untwist self-crossing loops.
    pub loop_vertices_dropped: usize,
    /// Crossings of smoothed loops split, the surface then taken by
    /// winding.
    pub loop_crossings: usize,
    /// Faces dropped where crossing loops pinched the surface or enclosed
    /// no cloud point.
    pub crossing_faces_dropped: usize,
    /// Faces dropped for spanning a depth jump where a nearer surface
    /// occludes a farther one.
    pub occlusion_faces_dropped: usize,
    /// Diagonals of co-circular quads (quantised clouds) flipped to the
    /// canonical side.
    pub diagonals_flipped: usize,
    /// Output faces.
    pub faces: usize,
    /// Output area.
    pub area: f64,
    /// The cloud's point attributes written to the output ("normals",
    /// "colours"), each vertex's from the nearest point.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub vertex_attributes: Vec<String>,
    /// The cloud's point attributes the output's format cannot hold (STL).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub vertex_attributes_not_written: Vec<String>,
    /// Time of each stage, in milliseconds.
    pub read_ms: f64,
    /// Boundary detection time.
    pub detect_ms: f64,
    /// Edge reconstruction time.
    pub edges_ms: f64,
    /// Triangulation time.
    pub mesh_ms: f64,
    /// Writing time.
    pub write_ms: f64,
}

/// Runs `meshtrim mesh`.
pub fn run(args: &Args) -> Result<()> {
    // Before the (possibly long) work: the output format, the report's
    // name, and neither may overwrite the cloud.
    crate::report::check_outputs(&args.output, args.report.as_deref(), &[&args.cloud])?;
    if let Some(edges) = &args.edges {
        crate::report::check_edges_output(edges, &[&args.cloud])?;
    }
    args.file.check(args.edges.as_deref())?;
    let started = Instant::now();
    let cloud = read_cloud_with(&args.cloud, &CloudOptions { scan: args.scan })?;
    let read_time = started.elapsed();
    let name = args.cloud.display().to_string();
    let Meshed {
        mesh,
        mut report,
        detection,
        edges,
    } = mesh_in_memory(&cloud.points, &args.stages.stages(), true, &name)?;
    let started = Instant::now();
    // The cloud's normals and colours, carried to the vertices from the
    // nearest point (the cloud's own points are the mesh's vertices).
    let attributes = VertexAttributes {
        normals: cloud.normals,
        colours: cloud.colours,
        scalars: cloud.scalars,
        ..VertexAttributes::default()
    };
    let points = trim::Mesh {
        vertices: cloud.points,
        faces: Vec::new(),
    };
    let carried = write_mesh_carrying(&args.output, &mesh, &points, attributes)?;
    report.vertex_attributes = carried.written;
    report.vertex_attributes_not_written = carried.not_written;
    if let Some(path) = &args.edges {
        write_edges(
            path,
            &points.vertices,
            &detection,
            &edges,
            args.file.options(),
        )?;
    }
    report.read_ms = millis(read_time);
    report.write_ms = millis(started.elapsed());
    report.cloud = Some(name);
    report.output = Some(args.output.display().to_string());
    crate::report::emit(&report, args.report.as_deref(), args.json)
}

/// A Delaunay mesh made in memory, with the detection and the edges that
/// bound it.
pub struct Meshed {
    /// The mesh.
    pub mesh: trim::Mesh,
    /// The report, without file names or read and write times.
    pub report: Report,
    /// The cloud's boundary points.
    pub detection: Detection,
    /// The smoothed loops that bound the mesh.
    pub edges: Edges,
}

/// Meshes the cloud `points` in memory (detection, edges, the constrained
/// Delaunay triangulation): everything `meshtrim mesh` does between reading
/// and writing, and what the Python package runs. Errors begin with `name`
/// (the file's path, or the argument's name); `progress` shows detection's
/// bar on a terminal. The report names no file and has no read or write
/// time.
pub fn mesh_in_memory(
    points: &[Point3],
    stages: &Stages,
    progress: bool,
    name: &str,
) -> Result<Meshed> {
    let (detection, edges, [detect_time, edges_time]) =
        detect_and_reconstruct(points, stages, progress, name)?;
    let started = Instant::now();
    let (mesh, made) =
        delaunay_mesh_with_report(points, &detection, &edges, &DelaunayOptions::default())
            .with_context(|| name.to_string())?;
    let times = [detect_time, edges_time, started.elapsed()];
    let loops_from = LoopsFrom(edges.loops_from);
    let report = Report::new(points.len(), mesh.faces.len(), &made, loops_from, times);
    Ok(Meshed {
        mesh,
        report,
        detection,
        edges,
    })
}

impl Report {
    fn new(
        points: usize,
        faces: usize,
        made: &DelaunayReport,
        loops_from: LoopsFrom,
        [detect, edges, mesh]: [Duration; 3],
    ) -> Self {
        Report {
            cloud: None,
            output: None,
            points,
            points_used: made.points_used,
            points_outside: made.points_outside,
            points_near_loop: made.points_near_loop,
            loops: made.loops.len(),
            loops_from,
            loop_vertices_dropped: made.loop_vertices_dropped,
            loop_crossings: made.loop_crossings,
            crossing_faces_dropped: made.crossing_faces_dropped,
            occlusion_faces_dropped: made.occlusion_faces_dropped,
            diagonals_flipped: made.diagonals_flipped,
            faces,
            area: made.area,
            vertex_attributes: Vec::new(),
            vertex_attributes_not_written: Vec::new(),
            read_ms: 0.0,
            detect_ms: millis(detect),
            edges_ms: millis(edges),
            mesh_ms: millis(mesh),
            write_ms: 0.0,
        }
    }
}

impl crate::report::Table for Report {
    fn table(&self) -> String {
        let mut rows = vec![
            (
                "cloud",
                format!("{} ({} points)", shown(&self.cloud), self.points),
            ),
            ("points used", self.points_used.to_string()),
            ("points outside", self.points_outside.to_string()),
            ("points on a loop", self.points_near_loop.to_string()),
            ("loops", self.loops.to_string()),
            ("loops from", self.loops_from.shown()),
            ("loop crossings", self.loop_crossings.to_string()),
            ("faces", self.faces.to_string()),
            (
                "occlusion faces dropped",
                self.occlusion_faces_dropped.to_string(),
            ),
            ("diagonals flipped", self.diagonals_flipped.to_string()),
            ("area", format!("{:.6}", self.area)),
            ("read time", format!("{:.1} ms", self.read_ms)),
            ("detect time", format!("{:.1} ms", self.detect_ms)),
            ("edges time", format!("{:.1} ms", self.edges_ms)),
            ("mesh time", format!("{:.1} ms", self.mesh_ms)),
            ("write time", format!("{:.1} ms", self.write_ms)),
            ("output", shown(&self.output)),
        ];
        let attributes = [&self.vertex_attributes, &self.vertex_attributes_not_written];
        crate::report::add_attributes_row(
            &mut rows,
            attributes.map(Vec::as_slice),
            "each vertex's from the nearest cloud point",
        );
        crate::report::rows(&rows)
    }
}
