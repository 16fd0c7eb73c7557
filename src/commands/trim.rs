//! `meshtrim MESH CLOUD OUT` (also `meshtrim trim ...`): the main job. Read
//! a mesh reconstructed from a scan and the scan's cloud, detect and smooth
//! the cloud's boundary, cut the mesh along it, keep what the cloud
//! supports, write the mesh, report.

use std::path::Path;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use serde::Serialize;
use trim::{trim_mesh, Detection, Edges, LoopFit, TrimOptions, TrimReport};

use crate::commands::args::{
    parse_direction, parse_k, parse_scale, parse_vector, EdgeFileArgs, StageArgs, ViewArgs,
    DXF_SPLINES_HELP, UNITS_HELP, VIEW_ALONG_HELP, VIEW_ALONG_LONG_HELP, VIEW_FROM_HELP,
    VIEW_FROM_LONG_HELP,
};
use crate::commands::clean::Deviation;
use crate::io::edges_out::step::LengthUnit;
use crate::io::edges_out::EdgeFileOptions;
use crate::io::mesh_out::write_mesh_carrying;
use crate::io::{read_cloud_with, read_mesh_with_attributes, CloudOptions, Point3};
use crate::report::{shown, significant, write_edges, LoopsFrom};
use crate::stages::{detect_and_reconstruct, millis, Stages};

/// Arguments of the trimming (`meshtrim MESH CLOUD OUT`).
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
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
    /// Also write the smoothed edges the mesh was cut along: FILE.json,
    /// .obj, .svg, .dxf, .step or .igs, the bytes `meshtrim edges CLOUD -o FILE` writes
    /// with the same options.
    #[arg(long, value_name = "FILE")]
    pub edges: Option<PathBuf>,
    /// Neighbourhood size of boundary detection, the point itself included.
    #[arg(long, default_value_t = 30, value_parser = parse_k)]
    pub k: usize,
    /// Use the paper's isotropic detection, without the sampling-tensor map.
    #[arg(long)]
    pub no_anisotropy: bool,
    /// Use the paper's edges, through the boundary points, instead of the
    /// estimated physical edge half a row beyond them: for clouds whose
    /// outermost samples lie on the edge itself (a mesh's own vertices,
    /// points sampled from CAD).
    #[arg(long)]
    pub no_offset: bool,
    /// The scanner's line of sight (as `ViewArgs`'s, same help).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_direction, allow_hyphen_values = true, conflicts_with = "view_from", help = VIEW_ALONG_HELP, long_help = VIEW_ALONG_LONG_HELP)]
    pub view_along: Option<[f64; 3]>,
    /// The scanner's position (as `ViewArgs`'s, same help).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vector, allow_hyphen_values = true, help = VIEW_FROM_HELP, long_help = VIEW_FROM_LONG_HELP)]
    pub view_from: Option<[f64; 3]>,
    /// Read only scan N of an E57 file (its 0-based data3D index); by
    /// default every scan is read, each in its pose, merged in the file's
    /// frame.
    #[arg(long, value_name = "N")]
    pub scan: Option<usize>,
    /// Multiply the cloud's coordinates by this factor before trimming,
    /// for a cloud in other units than the mesh: 1000 for a cloud in
    /// metres (as E57 files hold them) and a mesh in millimetres.
    #[arg(long, value_name = "FACTOR", value_parser = parse_scale, allow_hyphen_values = true)]
    pub cloud_scale: Option<f64>,
    /// The length unit declared (as `EdgeFileArgs`'s, same help).
    #[arg(long, value_enum, default_value_t = LengthUnit::Mm, help = UNITS_HELP)]
    pub units: LengthUnit,
    /// DXF splines (as `EdgeFileArgs`'s, same help).
    #[arg(long, help = DXF_SPLINES_HELP)]
    pub dxf_splines: bool,
    /// Print the report as one JSON object.
    #[arg(long)]
    pub json: bool,
}

impl Args {
    /// How the edges file is written. (The main job's arguments spell
    /// their groups out: clap cannot tell whether a flattened group inside
    /// the optional top-level arguments was given.)
    pub fn edge_file_args(&self) -> EdgeFileArgs {
        EdgeFileArgs {
            units: self.units,
            dxf_splines: self.dxf_splines,
        }
    }

    /// The detection and edge options (spelled out, as above).
    pub fn stage_args(&self) -> StageArgs {
        StageArgs {
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

/// What the trimming prints and `--report` writes.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// Input mesh, cloud and output, as given (none in memory).
    pub mesh: Option<String>,
    /// The cloud.
    pub cloud: Option<String>,
    /// The output.
    pub output: Option<String>,
    /// The factor the cloud was scaled by (`--cloud-scale`), if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cloud_scale: Option<f64>,
    /// Cloud points read.
    pub points: usize,
    /// Boundary points found by BPD.
    pub boundary_points: usize,
    /// Smoothed boundary loops the mesh was cut along.
    pub loops: usize,
    /// How the loops were found (see `meshtrim edges`).
    pub loops_from: LoopsFrom,
    /// Input faces.
    pub faces_in: usize,
    /// Output faces.
    pub faces_out: usize,
    /// Input faces crossed by the boundary and split.
    pub faces_split: usize,
    /// Input faces removed whole.
    pub faces_removed: usize,
    /// Pieces of the cut mesh dropped for lack of cloud support (e.g. the
    /// far side of a Poisson envelope, the caps over holes).
    pub pieces_dropped: usize,
    /// Pieces beyond the cut kept because the cloud supports them (on a
    /// closed scan, surface behind the walls of small loops).
    pub pieces_restored: usize,
    /// Vertices snapped onto the cut to avoid slivers.
    pub vertices_snapped: usize,
    /// Parts of faces dropped because no cloud point lies within reach
    /// (2 local resolutions): envelope that no wall cut off.
    pub faces_out_of_reach: usize,
    /// Kept faces dropped where two kept pieces would touch at one vertex
    /// the input did not pinch.
    pub pinch_faces_dropped: usize,
    /// Zero-area or repeated faces of the output repaired (screened
    /// Poisson leaves a few tiny triangles).
    pub faces_repaired: usize,
    /// Zero-area faces left where no repair keeps the mesh manifold.
    pub zero_area_faces_left: usize,
    /// Area of the input mesh.
    pub area_in: f64,
    /// Area of the output mesh.
    pub area_out: f64,
    /// Per smoothed loop: mean and largest distance from the output border
    /// to it, in the cloud's units (once scaled by `cloud_scale`).
    pub border_to_edge: Vec<BorderFit>,
    /// How far the cloud's points lie from the output's surface: the fit
    /// of the reconstruction to the scan where it is kept, and the scan
    /// the trimming cut away. Its `vertices` are the points measured:
    /// those at exactly an output vertex lie on it and are not counted.
    /// A batch's trimmed files are measured with `--deviation`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cloud_to_output: Option<Deviation>,
    /// The mesh's vertex attributes written to the output ("normals",
    /// "colours"), carried to the new vertices from the mesh's surface.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub vertex_attributes: Vec<String>,
    /// The mesh's vertex attributes the output's format cannot hold (STL).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub vertex_attributes_not_written: Vec<String>,
    /// Time of each stage, in milliseconds.
    pub read_ms: f64,
    /// Boundary detection time.
    pub detect_ms: f64,
    /// Edge reconstruction time.
    pub edges_ms: f64,
    /// Cutting and classification time.
    pub trim_ms: f64,
    /// Time to measure `cloud_to_output`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub deviation_ms: Option<f64>,
    /// Writing time.
    pub write_ms: f64,
}

/// How closely the output border follows one smoothed loop.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct BorderFit {
    /// Mean distance.
    pub mean: f64,
    /// Largest distance.
    pub max: f64,
    /// Border vertices measured.
    pub vertices: usize,
}

/// What trimming one mesh is told, beside its paths.
#[derive(Debug, Clone)]
pub struct TrimSettings {
    /// Detection's and edge reconstruction's options.
    pub stages: Stages,
    /// Whether detection may show its own progress bar (not in a batch,
    /// which has one bar for all files).
    pub progress: bool,
    /// How the cloud is read (which scan of an E57 file).
    pub cloud: CloudOptions,
    /// The factor the cloud's coordinates are multiplied by once read, to
    /// the mesh's units.
    pub cloud_scale: Option<f64>,
    /// Whether the cloud's distance from the output is measured.
    pub measure: bool,
}

/// Runs the trimming.
pub fn run(args: &Args) -> Result<()> {
    check_paths(args)?;
    let settings = TrimSettings {
        stages: args.stage_args().stages(),
        progress: true,
        cloud: CloudOptions { scan: args.scan },
        cloud_scale: args.cloud_scale,
        measure: true,
    };
    let report = trim_file(
        &args.mesh,
        &args.cloud,
        &args.output,
        args.edges
            .as_deref()
            .map(|path| (path, args.edge_file_args().options())),
        &settings,
    )?;
    crate::report::emit(&report, args.report.as_deref(), args.json)
}

/// Trims the mesh at `mesh_path` along the boundary of the cloud at
/// `cloud_path` and writes it (atomically) to `output`; prints nothing, so
/// `meshtrim batch` can run it on many files at once. With `edges_output`,
/// also writes the smoothed edges there (in that unit, for STEP). The caller checks the paths (see
/// `check_paths`).
pub fn trim_file(
    mesh_path: &Path,
    cloud_path: &Path,
    output: &Path,
    edges_output: Option<(&Path, EdgeFileOptions)>,
    settings: &TrimSettings,
) -> Result<Report> {
    // The two files are read at once (a binary PLY's reader runs on one
    // thread); the mesh's error, if any, is reported first, as if it were
    // read first.
    let started = Instant::now();
    let (mesh, cloud) = rayon::join(
        || read_mesh_with_attributes(mesh_path, "give a mesh (the cloud goes second)"),
        || read_cloud_with(cloud_path, &settings.cloud),
    );
    let (mesh, attributes) = mesh?;
    let mut cloud = cloud?;
    if let Some(factor) = settings.cloud_scale {
        for p in &mut cloud.points {
            *p = p.map(|c| c * factor);
        }
    }
    let read_time = started.elapsed();
    let names = [mesh_path, cloud_path].map(|p| p.display().to_string());
    let Trimmed {
        mesh: out,
        mut report,
        detection,
        edges,
    } = trim_in_memory(&mesh, &cloud.points, settings, &names)?;
    let started = Instant::now();
    let carried = write_mesh_carrying(output, &out, &mesh, attributes)?;
    if let Some((path, options)) = edges_output {
        write_edges(path, &cloud.points, &detection, &edges, options)?;
    }
    report.read_ms = millis(read_time);
    report.write_ms = millis(started.elapsed());
    report.mesh = Some(names[0].clone());
    report.cloud = Some(names[1].clone());
    report.cloud_scale = settings.cloud_scale;
    report.output = Some(output.display().to_string());
    report.vertex_attributes = carried.written;
    report.vertex_attributes_not_written = carried.not_written;
    Ok(report)
}

/// A trim in memory: the mesh, the report, and the detection and edges it
/// was cut along.
pub struct Trimmed {
    /// The trimmed mesh.
    pub mesh: trim::Mesh,
    /// The report, without file names or read and write times.
    pub report: Report,
    /// The cloud's boundary points.
    pub detection: Detection,
    /// The smoothed loops the mesh was cut along.
    pub edges: Edges,
}

/// Trims `mesh` along the smoothed boundary of the cloud `points`, in
/// memory: everything [`trim_file`] does between reading and writing, and
/// what the Python package runs. Errors begin with what `names` call the
/// mesh and the cloud (their paths, or the arguments' names). The report
/// names no file and has no read or write time.
pub fn trim_in_memory(
    mesh: &trim::Mesh,
    points: &[Point3],
    settings: &TrimSettings,
    [mesh_name, cloud_name]: &[String; 2],
) -> Result<Trimmed> {
    // Checked before detection, so the error names the mesh: the
    // library's own check reports "MESH with CLOUD".
    trim::check_vertex_range(&mesh.vertices).with_context(|| mesh_name.clone())?;
    let (detection, edges, [detect_time, edges_time]) =
        detect_and_reconstruct(points, &settings.stages, settings.progress, cloud_name)?;
    let started = Instant::now();
    let (out, trimmed) = trim_mesh(mesh, points, &detection, &edges, &TrimOptions::default())
        .with_context(|| format!("{mesh_name} with {cloud_name}"))?;
    let trim_time = started.elapsed();
    let mut report = Report::new(
        points.len(),
        detection.boundary_count(),
        &trimmed,
        LoopsFrom(edges.loops_from),
        [detect_time, edges_time, trim_time],
    );
    if settings.measure {
        report.measure(points, &out);
    }
    Ok(Trimmed {
        mesh: out,
        report,
        detection,
        edges,
    })
}

/// Refuses unknown output formats and outputs that would overwrite an
/// input, before any work.
fn check_paths(args: &Args) -> Result<()> {
    let inputs = [args.mesh.as_path(), args.cloud.as_path()];
    crate::report::check_outputs(&args.output, args.report.as_deref(), &inputs)?;
    if let Some(edges) = &args.edges {
        crate::report::check_edges_output(edges, &inputs)?;
    }
    args.edge_file_args().check(args.edges.as_deref())
}

impl Report {
    fn new(
        points: usize,
        boundary_points: usize,
        r: &TrimReport,
        loops_from: LoopsFrom,
        [detect, edges, trim]: [Duration; 3],
    ) -> Self {
        let fit = |l: &LoopFit| BorderFit {
            mean: l.mean,
            max: l.max,
            vertices: l.count,
        };
        Report {
            mesh: None,
            cloud: None,
            cloud_scale: None,
            output: None,
            points,
            boundary_points,
            loops: r.loops.len(),
            loops_from,
            faces_in: r.faces_in,
            faces_out: r.faces_out,
            faces_split: r.faces_split,
            faces_removed: r.faces_removed,
            pieces_dropped: r.pieces_dropped,
            pieces_restored: r.pieces_restored,
            vertices_snapped: r.vertices_snapped,
            faces_out_of_reach: r.faces_out_of_reach,
            pinch_faces_dropped: r.pinch_faces_dropped,
            faces_repaired: r.repaired.repaired(),
            zero_area_faces_left: r.repaired.left,
            area_in: r.area_in,
            area_out: r.area_out,
            border_to_edge: r.loops.iter().map(fit).collect(),
            cloud_to_output: None,
            vertex_attributes: Vec::new(),
            vertex_attributes_not_written: Vec::new(),
            read_ms: 0.0,
            detect_ms: millis(detect),
            edges_ms: millis(edges),
            trim_ms: millis(trim),
            deviation_ms: None,
            write_ms: 0.0,
        }
    }

    /// Measures how far the cloud's `points` lie from the `output` mesh.
    fn measure(&mut self, points: &[Point3], output: &trim::Mesh) {
        let started = Instant::now();
        let cloud = trim::Mesh {
            vertices: points.to_vec(),
            faces: Vec::new(),
        };
        self.cloud_to_output = Some(trim::surface_deviation(output, &cloud).into());
        self.deviation_ms = Some(millis(started.elapsed()));
    }
}

impl crate::report::Table for Report {
    fn table(&self) -> String {
        let worst = self
            .border_to_edge
            .iter()
            .map(|f| f.max)
            .fold(0.0, f64::max);
        let mut rows = vec![
            ("mesh", shown(&self.mesh)),
            (
                "cloud",
                format!(
                    "{} ({} points, {} boundary){}",
                    shown(&self.cloud),
                    self.points,
                    self.boundary_points,
                    self.cloud_scale
                        .map(|f| format!(", scaled by {f}"))
                        .unwrap_or_default()
                ),
            ),
            ("loops", self.loops.to_string()),
            ("loops from", self.loops_from.shown()),
            (
                "faces in / out",
                format!("{} / {}", self.faces_in, self.faces_out),
            ),
            (
                "faces split",
                format!(
                    "{} by the border (their inner parts kept)",
                    self.faces_split
                ),
            ),
            (
                "faces removed",
                format!(
                    "{} whole (beyond the border, in dropped pieces or out of reach)",
                    self.faces_removed
                ),
            ),
            (
                "pieces dropped",
                format!(
                    "{} (no cloud support; their faces are among those removed)",
                    self.pieces_dropped
                ),
            ),
            (
                "pieces restored",
                format!(
                    "{} (beyond the border, kept: the cloud supports them)",
                    self.pieces_restored
                ),
            ),
            (
                "faces out of reach",
                format!(
                    "{} parts of faces no cloud point reaches, dropped",
                    self.faces_out_of_reach
                ),
            ),
            (
                "pinches opened",
                format!(
                    "{} faces dropped where kept pieces touched at one vertex",
                    self.pinch_faces_dropped
                ),
            ),
            ("faces repaired", self.faces_repaired.to_string()),
            (
                "area in / out",
                format!("{:.6} / {:.6}", self.area_in, self.area_out),
            ),
            (
                "border to edge, max",
                format!(
                    "{} ({})",
                    significant(worst, 4),
                    match self.cloud_scale {
                        Some(_) => "the mesh's units: the cloud's, scaled",
                        None => "the cloud's units",
                    }
                ),
            ),
            ("read time", format!("{:.1} ms", self.read_ms)),
            ("detect time", format!("{:.1} ms", self.detect_ms)),
            ("edges time", format!("{:.1} ms", self.edges_ms)),
            ("trim time", format!("{:.1} ms", self.trim_ms)),
            ("write time", format!("{:.1} ms", self.write_ms)),
            ("output", shown(&self.output)),
        ];
        if let Some(d) = self.cloud_to_output {
            let after_border = 1 + rows
                .iter()
                .position(|r| r.0 == "border to edge, max")
                .unwrap_or(0);
            rows.insert(
                after_border,
                ("cloud points", d.shown("from the output's surface")),
            );
        }
        if let Some(ms) = self.deviation_ms {
            let after_trim = 1 + rows.iter().position(|r| r.0 == "trim time").unwrap_or(0);
            rows.insert(after_trim, ("deviation time", format!("{ms:.1} ms")));
        }
        let attributes = [&self.vertex_attributes, &self.vertex_attributes_not_written];
        crate::report::add_attributes_row(
            &mut rows,
            attributes.map(Vec::as_slice),
            "kept vertices' as read, new ones' from the mesh's surface",
        );
        crate::report::rows(&rows)
    }
}
