//! `meshtrim clean IN OUT`: smooth the jagged border of a triangulated scan.
//! The mesh's own vertices are the cloud: their local resolution comes from
//! BPD's neighbourhoods on them (the resolution pass only), the border loops
//! from the mesh, and the
//! library replaces the border by its smoothed edge.

use std::path::Path;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use serde::Serialize;
use trim::{clean_mesh, CleanOptions, CleanReport};

use crate::commands::args::{EdgeFileArgs, StageArgs};
use crate::io::edges_out::{EdgeData, EdgeFileOptions};
use crate::io::mesh_out::write_mesh_carrying;
use crate::io::read_mesh_with_attributes;
use crate::report::{shown, significant};
use crate::stages::{millis, Stages};

/// Arguments of `meshtrim clean`.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// The mesh: .obj, .ply, .stl, .gltf or .glb.
    pub input: PathBuf,
    /// The cleaned mesh: .obj, .ply (binary), .stl (binary), .gltf or
    /// .glb. Missing parent directories are created.
    pub output: PathBuf,
    /// Also write the report as JSON to this file.
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
    /// Repair a mesh that is not edge-manifold or consistently oriented
    /// instead of refusing it: a face written again the other way goes
    /// (one side kept), then faces on edges of more than two faces
    /// (smallest first, as MeshLab's "Repair non Manifold Edges"), and
    /// faces wound against their neighbours are turned over.
    #[arg(long)]
    pub repair: bool,
    /// Keep the new border within this distance of the old one (in the
    /// mesh's units): where the smoothed border would bridge a notch or
    /// cut off a corner farther than this, it follows the scan's border
    /// at this distance instead.
    #[arg(long, value_name = "D", value_parser = crate::commands::args::parse_distance, allow_hyphen_values = true)]
    pub max_deviation: Option<f64>,
    /// Close the holes no wider than W (the largest distance between two
    /// of a hole's border vertices, in the mesh's units) before smoothing
    /// the borders, with faces over the hole's own vertices; a piece's
    /// outer border is never closed.
    #[arg(long, value_name = "W", value_parser = crate::commands::args::parse_distance, allow_hyphen_values = true)]
    pub fill_holes: Option<f64>,
    /// Also write the cleaned mesh's border as curves: FILE.json, .obj,
    /// .svg, .dxf, .step or .igs, as `meshtrim edges` writes edges. Each
    /// border loop is split at its corners into edges through the border
    /// vertices themselves: the smoothed border where a loop was replaced,
    /// the scan's own where one was left.
    #[arg(long, value_name = "FILE")]
    pub edges: Option<PathBuf>,
    /// Detection and edge options.
    #[command(flatten)]
    pub stages: StageArgs,
    /// The unit declared, DXF splines.
    #[command(flatten)]
    pub file: EdgeFileArgs,
    /// Print the report as one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// The summary of one cleanup (for `batch`).
#[derive(Debug, Clone, PartialEq)]
pub struct CleanOutcome {
    /// Border loops of the input.
    pub loops_in: usize,
    /// Border loops replaced by their smoothed edge.
    pub loops: usize,
    /// Input faces.
    pub faces_in: usize,
    /// Output faces.
    pub faces_out: usize,
    /// Reading time, ms.
    pub read_ms: f64,
    /// Detection and cleanup time, ms.
    pub clean_ms: f64,
    /// Writing time, ms.
    pub write_ms: f64,
    /// The input's largest share of area facing one direction.
    pub area_facing_one_way: f64,
    /// Faces `--repair` removed or turned.
    pub repaired: usize,
    /// When measured: the largest distances of the removed vertices from
    /// the output, and of the new ones from the input (the report's
    /// `input_to_output` and `output_to_input` maxima).
    pub deviation: Option<[f64; 2]>,
    /// With `--fill-holes`: the holes closed.
    pub holes_filled: Option<usize>,
}

/// Below this share of its area facing one direction, a mesh with a
/// border wraps round an object: more likely an envelope cut open than a
/// scan's jagged border, so `clean` says how to trim it instead. Measured
/// (docs/clean.md): one-sided range scans 0.94 and more (bun090, whose
/// faces at its silhouette turn past 90°), meshes round whole objects
/// 0.76 and less (Laurana50k, open at its base; bun_zipper 0.54).
pub const WRAPS_BELOW: f64 = trim::SEEN_FROM_ONE_SIDE;

/// What `clean` prints and `--report` writes.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// Input and output, as given (none in memory).
    pub input: Option<String>,
    /// The output.
    pub output: Option<String>,
    /// Vertices of the input.
    pub vertices: usize,
    /// Border loops of the input.
    pub loops_in: usize,
    /// Loops replaced by their smoothed edge.
    pub loops_smoothed: usize,
    /// Loops too small to smooth (fewer than four vertices), kept.
    pub loops_too_small: usize,
    /// Loops left unchanged, with the reason.
    pub loops_left: Vec<LeftLoops>,
    /// Input faces.
    pub faces_in: usize,
    /// Edges where the input's vertices were split but its surface goes
    /// on (a texture chart's border, a hard edge), stitched so that they
    /// are not cleaned as borders.
    pub seam_edges_stitched: usize,
    /// Input faces that named a vertex twice (no area), dropped.
    pub slivers_dropped: usize,
    /// Input faces that repeated an earlier one (same corners, same turn),
    /// dropped.
    pub repeated_faces_dropped: usize,
    /// With `--repair`: faces removed for repeating another's corners in
    /// the opposite turn (a surface written twice, once each way).
    pub double_sided_faces_removed: usize,
    /// With `--repair`: faces removed from edges of more than two faces.
    pub crowded_faces_removed: usize,
    /// With `--repair`: faces turned over to agree with their neighbours.
    pub faces_flipped: usize,
    /// With `--repair`: faces removed where no turn agrees with every
    /// neighbour (a one-sided piece).
    pub one_sided_faces_removed: usize,
    /// Zero-area faces of the output repaired (inside the mesh, away
    /// from the border bands).
    pub zero_area_faces_repaired: usize,
    /// Zero-area faces left where no repair keeps the mesh manifold.
    pub zero_area_faces_left: usize,
    /// Faces dropped where the new border would pinch the surface at a
    /// vertex the input did not pinch.
    pub pinch_faces_dropped: usize,
    /// Input faces removed in the border bands.
    pub faces_removed: usize,
    /// New faces.
    pub faces_added: usize,
    /// Output faces.
    pub faces_out: usize,
    /// New vertices (on the smoothed border).
    pub vertices_added: usize,
    /// Smallest angle of the new faces, degrees; 0 when no face was added.
    pub min_angle_new: f64,
    /// Area of the input.
    pub area_in: f64,
    /// Area of the output.
    pub area_out: f64,
    /// The input's largest share of area that faces one direction: near 1
    /// for a scan seen from one side, lower for a surface wrapping round
    /// an object (see [`WRAPS_BELOW`]).
    pub area_facing_one_way: f64,
    /// How far the input's vertices not in the output (the jagged border,
    /// and what the new border cut away) lie from the output's surface
    /// (by `batch` only with `--deviation`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub input_to_output: Option<Deviation>,
    /// How far the output's new vertices lie from the input's surface:
    /// where the new border runs out past the old border vertices, or
    /// bridges a notch (by `batch` only with `--deviation`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub output_to_input: Option<Deviation>,
    /// `--max-deviation`, when given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_deviation: Option<f64>,
    /// `--fill-holes`, when given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fill_holes: Option<f64>,
    /// With `--fill-holes`: holes closed, faces added to close them, and
    /// holes narrow enough that stay open (every way of closing them
    /// would repeat an edge or make a face of no area).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub holes_filled: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub faces_filling: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub holes_not_filled: Option<usize>,
    /// With `--max-deviation`: smoothed border vertices held back to that
    /// distance from the old border.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vertices_held: Option<usize>,
    /// The input's vertex attributes written to the output ("normals",
    /// "colours"), carried to the new vertices from the input's surface.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub vertex_attributes: Vec<String>,
    /// The input's vertex attributes the output's format cannot hold (STL).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub vertex_attributes_not_written: Vec<String>,
    /// Reading time, ms.
    pub read_ms: f64,
    /// Local resolution (β of every vertex) time, ms.
    pub resolution_ms: f64,
    /// Border replacement time, ms.
    pub clean_ms: f64,
    /// Time to measure the two deviations, ms.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub deviation_ms: Option<f64>,
    /// Writing time, ms.
    pub write_ms: f64,
}

/// How far the vertices of one mesh lie from the other's surface
/// ([`trim::surface_deviation`]).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Deviation {
    /// Vertices measured: those not at a vertex of the other mesh.
    pub vertices: usize,
    /// The largest distance (0 when none was measured).
    pub max: f64,
    /// The mean distance over the vertices measured.
    pub mean: f64,
    /// The farthest vertex, if any was measured.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub at: Option<[f64; 3]>,
}

impl From<trim::Deviation> for Deviation {
    fn from(d: trim::Deviation) -> Self {
        Deviation {
            vertices: d.vertices,
            max: d.max,
            mean: d.mean,
            at: d.at,
        }
    }
}

impl Deviation {
    /// "up to MAX (mean MEAN over N)", or "none" when nothing was measured.
    pub(crate) fn shown(&self, what: &str) -> String {
        if self.vertices == 0 {
            return "none".to_string();
        }
        format!(
            "up to {} {what} (mean {} over {})",
            significant(self.max, 4),
            significant(self.mean, 4),
            self.vertices
        )
    }
}

/// Loops left unchanged.
#[derive(Debug, Clone, Serialize)]
pub struct LeftLoops {
    /// Their indices among the input's border loops.
    pub loops: Vec<usize>,
    /// Their numbers of vertices.
    pub vertices: Vec<usize>,
    /// Why.
    pub reason: String,
}

/// Runs `meshtrim clean`.
pub fn run(args: &Args) -> Result<()> {
    crate::report::check_outputs(&args.output, args.report.as_deref(), &[&args.input])?;
    if let Some(edges) = &args.edges {
        crate::report::check_edges_output(edges, &[&args.input])?;
    }
    args.file.check(args.edges.as_deref())?;
    let job = Job {
        stages: &args.stages.stages(),
        choices: Choices {
            repair: args.repair,
            max_deviation: args.max_deviation,
            fill_holes: args.fill_holes,
        },
        measured: true,
        edges: args
            .edges
            .as_deref()
            .map(|path| (path, args.file.options())),
    };
    let report = clean(
        &args.input,
        &args.output,
        &job,
        "`clean` smooths the border of a mesh",
    )?;
    crate::report::emit(&report, args.report.as_deref(), args.json)
}

/// Cleans one file without printing (the unit of `batch`); `choices` as
/// `clean`'s; `measured`: whether the deviations are measured (they cost
/// about a tenth of a small file's time); `edges`: where to write the
/// output's border, and how. `no_faces` is the advice for a file without
/// faces.
pub fn clean_file(
    input: &Path,
    output: &Path,
    stages: &Stages,
    (choices, measured, edges): (Choices, bool, Option<(&Path, EdgeFileOptions)>),
    no_faces: &str,
) -> Result<CleanOutcome> {
    crate::report::check_outputs(output, None, &[input])?;
    let job = Job {
        stages,
        choices,
        measured,
        edges,
    };
    let r = clean(input, output, &job, no_faces)?;
    Ok(CleanOutcome {
        loops_in: r.loops_in,
        loops: r.loops_smoothed,
        faces_in: r.faces_in,
        faces_out: r.faces_out,
        read_ms: r.read_ms,
        clean_ms: ((r.resolution_ms + r.clean_ms) * 10.0).round() / 10.0,
        write_ms: r.write_ms,
        area_facing_one_way: r.area_facing_one_way,
        repaired: r.repaired(),
        deviation: r
            .input_to_output
            .zip(r.output_to_input)
            .map(|(removed, new)| [removed.max, new.max]),
        holes_filled: r.holes_filled,
    })
}

/// What `clean` is asked for beyond detection's options.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Choices {
    /// `--repair`.
    pub repair: bool,
    /// `--max-deviation`.
    pub max_deviation: Option<f64>,
    /// `--fill-holes`.
    pub fill_holes: Option<f64>,
}

/// How to clean one file.
struct Job<'a> {
    stages: &'a Stages,
    choices: Choices,
    /// Whether the deviations between input and output are measured.
    measured: bool,
    /// Where to write the output's border as curves, and how.
    edges: Option<(&'a Path, EdgeFileOptions)>,
}

/// Reads, finds the local resolution, cleans, writes.
fn clean(input: &Path, output: &Path, job: &Job, no_faces: &str) -> Result<Report> {
    let started = Instant::now();
    let (mesh, attributes) = read_mesh_with_attributes(input, no_faces)?;
    let read_time = started.elapsed();
    let name = input.display().to_string();
    let (out, mut report) = unmeasured(&mesh, job.stages, job.choices, &name)?;
    if job.measured {
        report.measure(&mesh, &out);
    }
    let border = job
        .edges
        .map(|(path, options)| border_curves(&out, job.stages, &name).map(|e| (e, path, options)))
        .transpose()?;
    let started = Instant::now();
    let carried = write_mesh_carrying(output, &out, &mesh, attributes)?;
    report.vertex_attributes = carried.written;
    report.vertex_attributes_not_written = carried.not_written;
    if let Some((border, path, options)) = border {
        write_border(path, &out, &border, options)?;
    }
    report.read_ms = millis(read_time);
    report.write_ms = millis(started.elapsed());
    report.input = Some(name);
    report.output = Some(output.display().to_string());
    Ok(report)
}

/// The border of the cleaned mesh `out` as edges: its loops split at their
/// corners, found at the output vertices' own local resolution (`stages`'
/// detection options). Errors begin with `name`.
pub fn border_curves(out: &trim::Mesh, stages: &Stages, name: &str) -> Result<trim::Edges> {
    let beta = trim::LocalResolution::new(&out.vertices, &stages.detection)
        .with_context(|| format!("{name}: the border's local resolution"))?;
    Ok(trim::mesh_border_edges(out, &beta))
}

/// Writes the border `edges` of the cleaned mesh `out` to `path`, as
/// `meshtrim edges -o` writes edges (the SVG marks the border vertices).
pub fn write_border(
    path: &Path,
    out: &trim::Mesh,
    edges: &trim::Edges,
    options: EdgeFileOptions,
) -> Result<()> {
    let mut on_border = vec![false; out.vertices.len()];
    for v in edges.loops.iter().flat_map(|l| &l.boundary_points) {
        on_border[*v as usize] = true;
    }
    let data = EdgeData {
        points: &out.vertices,
        boundary: &on_border,
        edges,
        options,
    };
    crate::io::edges_out::write_file(path, data)
}

/// Cleans `mesh` in memory: everything `meshtrim clean` does between
/// reading and writing (`choices` as its options), the deviations
/// included, and what the Python package runs. Errors begin with `name`
/// (the file's path, or the argument's name). The report names no file
/// and has no read or write time.
pub fn clean_in_memory(
    mesh: &trim::Mesh,
    stages: &Stages,
    choices: Choices,
    name: &str,
) -> Result<(trim::Mesh, Report)> {
    let (out, mut report) = unmeasured(mesh, stages, choices, name)?;
    report.measure(mesh, &out);
    Ok((out, report))
}

/// [`clean_in_memory`] without the deviations.
fn unmeasured(
    mesh: &trim::Mesh,
    stages: &Stages,
    choices: Choices,
    name: &str,
) -> Result<(trim::Mesh, Report)> {
    let repair = choices.repair;
    let started = Instant::now();
    // Only β is needed: the mesh knows its border (BPD's labels would be
    // thrown away). On a large mesh it is found only where the cleanup
    // reads it, near the borders.
    let beta = trim::LocalResolution::new(&mesh.vertices, &stages.detection)
        .with_context(|| format!("{name}: the mesh's vertices"))?;
    let resolution_time = started.elapsed();
    let started = Instant::now();
    let options = CleanOptions {
        offset: stages.edges.offset,
        repair,
        max_deviation: choices.max_deviation,
        fill_holes: choices.fill_holes,
    };
    let (out, cleaned) = clean_mesh(mesh, &beta, &options)
        .map_err(|e| refused_unless_repaired(e, repair))
        .with_context(|| name.to_string())?;
    let mut report = Report::new(
        mesh.vertices.len(),
        &cleaned,
        [resolution_time, started.elapsed()],
    );
    if choices.max_deviation.is_some() {
        report.max_deviation = choices.max_deviation;
        report.vertices_held = Some(cleaned.vertices_held);
    }
    if choices.fill_holes.is_some() {
        report.fill_holes = choices.fill_holes;
        report.holes_filled = Some(cleaned.holes_filled.holes);
        report.faces_filling = Some(cleaned.holes_filled.faces);
        report.holes_not_filled = Some(cleaned.holes_filled.left);
    }
    Ok((out, report))
}

/// A mesh refused for its edges is told of the `repair` option, which
/// would have made it manifold and oriented (the CLI says `--repair`).
fn refused_unless_repaired(error: trim::CleanError, repair: bool) -> anyhow::Error {
    use trim::{CleanError, MeshError};
    match error {
        CleanError::Mesh(MeshError::NonManifold { .. } | MeshError::Misoriented { .. })
            if !repair =>
        {
            anyhow::anyhow!("{error}; {REPAIR_ADVICE}")
        }
        _ => error.into(),
    }
}

/// What [`refused_unless_repaired`] adds, in the library's words.
const REPAIR_ADVICE: &str =
    "or clean with repair on, which removes faces from edges of more than two and turns faces to agree";

impl Report {
    fn new(vertices: usize, r: &CleanReport, [resolution, clean]: [Duration; 2]) -> Self {
        Report {
            input: None,
            output: None,
            vertices,
            loops_in: r.loops_in,
            loops_smoothed: r.loops_smoothed,
            loops_too_small: r.loops_too_small,
            loops_left: r
                .loops_left
                .iter()
                .map(|l| LeftLoops {
                    loops: l.loops.clone(),
                    vertices: l.vertices.clone(),
                    reason: l.reason.to_string(),
                })
                .collect(),
            faces_in: r.faces_in,
            seam_edges_stitched: r.seam_edges_stitched,
            slivers_dropped: r.slivers_dropped,
            repeated_faces_dropped: r.repeated_faces_dropped,
            double_sided_faces_removed: r.manifold.double_sided_faces_removed,
            crowded_faces_removed: r.manifold.crowded_faces_removed,
            faces_flipped: r.manifold.faces_flipped,
            one_sided_faces_removed: r.manifold.one_sided_faces_removed,
            zero_area_faces_repaired: r.repaired.repaired(),
            zero_area_faces_left: r.repaired.left,
            pinch_faces_dropped: r.pinch_faces_dropped,
            faces_removed: r.faces_removed,
            faces_added: r.faces_added,
            faces_out: r.faces_out,
            vertices_added: r.vertices_added,
            min_angle_new: r.min_angle_new,
            area_in: r.area_in,
            area_out: r.area_out,
            area_facing_one_way: r.area_facing_one_way,
            input_to_output: None,
            output_to_input: None,
            max_deviation: None,
            vertices_held: None,
            fill_holes: None,
            holes_filled: None,
            faces_filling: None,
            holes_not_filled: None,
            deviation_ms: None,
            vertex_attributes: Vec::new(),
            vertex_attributes_not_written: Vec::new(),
            read_ms: 0.0,
            resolution_ms: millis(resolution),
            clean_ms: millis(clean),
            write_ms: 0.0,
        }
    }
}

impl Report {
    /// Measures how far each of `input` and `output` lies from the other.
    fn measure(&mut self, input: &trim::Mesh, output: &trim::Mesh) {
        let started = Instant::now();
        self.input_to_output = Some(trim::surface_deviation(output, input).into());
        self.output_to_input = Some(trim::surface_deviation(input, output).into());
        self.deviation_ms = Some(millis(started.elapsed()));
    }

    /// What to do instead, when the mesh is not a scan's border to clean.
    fn warning(&self) -> Option<String> {
        if self.loops_in == 0 {
            return Some(
                "no border: a closed mesh has nothing to clean; to trim a \
                 reconstruction's envelope, give it its cloud: meshtrim MESH CLOUD OUT"
                    .to_string(),
            );
        }
        (self.area_facing_one_way < WRAPS_BELOW).then(|| {
            format!(
                "the surface wraps round an object (no direction sees more than {:.0}% of \
                 its area, where a one-sided scan shows nearly all of it to its scanner): \
                 if it is a reconstruction's envelope cut open, trim it with its cloud \
                 instead: meshtrim MESH CLOUD OUT",
                100.0 * self.area_facing_one_way
            )
        })
    }

    /// Faces `--repair` removed or turned.
    fn repaired(&self) -> usize {
        self.double_sided_faces_removed
            + self.crowded_faces_removed
            + self.faces_flipped
            + self.one_sided_faces_removed
    }

    /// The smallest angle of the new faces, or "none" when there are none
    /// (the number is then 0, which would read as a degenerate face).
    fn smallest_new_angle(&self) -> String {
        if self.faces_added == 0 {
            "none (no new faces)".to_string()
        } else {
            format!("{:.1}°", self.min_angle_new)
        }
    }
}

impl crate::report::Table for Report {
    fn table(&self) -> String {
        let left: usize = self.loops_left.iter().map(|l| l.loops.len()).sum();
        let mut rows = vec![
            (
                "input",
                format!("{} ({} vertices)", shown(&self.input), self.vertices),
            ),
            (
                "loops",
                format!(
                    "{} in: {} smoothed, {} too small, {} left",
                    self.loops_in, self.loops_smoothed, self.loops_too_small, left
                ),
            ),
            (
                "faces in / out",
                format!("{} / {}", self.faces_in, self.faces_out),
            ),
            (
                "faces replaced",
                format!("{} removed, {} new", self.faces_removed, self.faces_added),
            ),
            ("smallest new angle", self.smallest_new_angle()),
            (
                "area in / out",
                format!("{:.6} / {:.6}", self.area_in, self.area_out),
            ),
            ("read time", format!("{:.1} ms", self.read_ms)),
            ("resolution time", format!("{:.1} ms", self.resolution_ms)),
            ("clean time", format!("{:.1} ms", self.clean_ms)),
            ("write time", format!("{:.1} ms", self.write_ms)),
            ("output", shown(&self.output)),
        ];
        if let Some(ms) = self.deviation_ms {
            let after_clean = 1 + rows.iter().position(|r| r.0 == "clean time").unwrap_or(0);
            rows.insert(after_clean, ("deviation time", format!("{ms:.1} ms")));
        }
        let deviations = [
            (
                "removed vertices",
                self.input_to_output,
                "from the output's surface",
            ),
            (
                "new vertices",
                self.output_to_input,
                "off the input's surface",
            ),
        ];
        let after_area = 1 + rows
            .iter()
            .position(|r| r.0 == "area in / out")
            .unwrap_or(0);
        for (at, (label, deviation, what)) in deviations.into_iter().enumerate() {
            if let Some(d) = deviation {
                rows.insert(after_area + at, (label, d.shown(what)));
            }
        }
        if let (Some(max), Some(held)) = (self.max_deviation, self.vertices_held) {
            let held = format!(
                "{} ({held} smoothed border vertices held back to it)",
                significant(max, 4)
            );
            rows.insert(after_area, ("max deviation", held));
        }
        if let (Some(width), Some(holes), Some(faces), Some(open)) = (
            self.fill_holes,
            self.holes_filled,
            self.faces_filling,
            self.holes_not_filled,
        ) {
            let filled = format!(
                "{holes} up to {} wide, with {faces} faces ({open} as narrow left open)",
                significant(width, 4)
            );
            rows.insert(1, ("holes filled", filled));
        }
        let attributes = [&self.vertex_attributes, &self.vertex_attributes_not_written];
        crate::report::add_attributes_row(
            &mut rows,
            attributes.map(Vec::as_slice),
            "kept vertices' as read, new ones' from the input's surface",
        );
        if self.zero_area_faces_repaired + self.zero_area_faces_left > 0 {
            rows.insert(
                3,
                (
                    "zero-area faces",
                    format!(
                        "{} repaired, {} left",
                        self.zero_area_faces_repaired, self.zero_area_faces_left
                    ),
                ),
            );
        }
        if self.pinch_faces_dropped > 0 {
            rows.insert(
                3,
                (
                    "pinches opened",
                    format!(
                        "{} faces dropped where the new border met itself at a vertex",
                        self.pinch_faces_dropped
                    ),
                ),
            );
        }
        if self.repaired() > 0 {
            rows.insert(
                3,
                (
                    "repaired",
                    format!(
                        "{} faces removed as second sides, {} from edges of 3+ faces, {} turned \
                         over, {} removed from one-sided pieces",
                        self.double_sided_faces_removed,
                        self.crowded_faces_removed,
                        self.faces_flipped,
                        self.one_sided_faces_removed
                    ),
                ),
            );
        }
        if self.repeated_faces_dropped > 0 {
            rows.insert(
                3,
                (
                    "repeats dropped",
                    format!(
                        "{} (faces written twice, same turn)",
                        self.repeated_faces_dropped
                    ),
                ),
            );
        }
        if self.seam_edges_stitched > 0 {
            rows.insert(
                3,
                (
                    "seams stitched",
                    format!(
                        "{} edges (vertices split along them, the surface whole)",
                        self.seam_edges_stitched
                    ),
                ),
            );
        }
        if self.slivers_dropped > 0 {
            rows.insert(
                3,
                (
                    "slivers dropped",
                    format!("{} (faces naming a vertex twice)", self.slivers_dropped),
                ),
            );
        }
        if let Some(warning) = self.warning() {
            rows.push(("warning", warning));
        }
        for l in &self.loops_left {
            rows.push((
                "left unchanged",
                format!(
                    "loops {:?} ({:?} vertices): {}",
                    l.loops, l.vertices, l.reason
                ),
            ));
        }
        crate::report::rows(&rows)
    }
}
