//! `meshtrim edges`: read a cloud, detect its boundary, reconstruct and
//! smooth its edges, write them, report.

use std::path::Path;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{bail, Result};
use serde::Serialize;
use trim::{Detection, Edges};

use crate::commands::args::{EdgeFileArgs, StageArgs};
use crate::console;
use crate::io::edges_out::{edges_format, EdgesFormat};
use crate::io::{read_cloud_with, CloudOptions, Point3};
use crate::report::{same_file, shown, write_edges, LoopsFrom};
use crate::stages::{detect_and_reconstruct, millis, Stages};

/// Arguments of `meshtrim edges`.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// Input point cloud: .ply, .pcd, .obj, .las/.laz, .e57, .xyz/.txt/.csv/.asc/.pts, or a
    /// mesh (.stl, .gltf, .glb) whose vertices are the cloud.
    pub cloud: PathBuf,
    /// Write the loops and edges: OUT.json (everything), OUT.obj (the
    /// smoothed edges as polylines), OUT.svg (a picture), OUT.dxf (3-D
    /// polylines on layers OUTER and HOLES, corners on CORNERS, for CAD and
    /// CAM; with --dxf-splines also curves), OUT.step (cubic B-spline
    /// curves, in --units) or OUT.igs (the same curves as IGES). Missing
    /// parent directories are created.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
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
    /// Print the summary as one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// What `edges` prints: the counts of each stage and the timings.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// The input file, as given (none in memory).
    pub file: Option<String>,
    /// Points read (after dropping non-finite PCD points).
    pub points: usize,
    /// Points labelled boundary by BPD (duplicates counted).
    pub boundary_points: usize,
    /// Closed boundary loops reconstructed.
    pub loops: usize,
    /// Smoothed edges over all loops (one per loop without corners).
    pub edges: usize,
    /// Corners over all loops.
    pub corners: usize,
    /// Groups of boundary points too small or too thin to close a loop.
    pub dropped_clusters: usize,
    /// Boundary points removed as spurs, strays or isolated points.
    pub thinned_points: usize,
    /// How the loops were found: `links` (BPD's links), `scanner_image`
    /// (traced in the view's image plane) or `own_plane` (traced in the
    /// cloud's own best-fit plane).
    pub loops_from: LoopsFrom,
    /// Time to read the file, in milliseconds.
    pub read_ms: f64,
    /// Time of boundary detection, in milliseconds.
    pub detect_ms: f64,
    /// Time of edge reconstruction (clustering, ordering, corners,
    /// smoothing, offset), in milliseconds.
    pub edges_ms: f64,
    /// Time to write the output (curve fitting included), in milliseconds.
    pub write_ms: f64,
    /// Whether the edges were moved out to the surface's estimated edge.
    pub offset: bool,
}

/// Runs `meshtrim edges`.
pub fn run(args: &Args) -> Result<()> {
    // Check the output before the (possibly long) work.
    check_output(&args.output, &args.cloud)?;
    args.file.check(Some(&args.output))?;
    let started = Instant::now();
    let cloud = read_cloud_with(&args.cloud, &CloudOptions { scan: args.scan })?;
    let read_time = started.elapsed();
    let name = args.cloud.display().to_string();
    let stages = args.stages.stages();
    let (detection, edges, mut summary) = edges_in_memory(&cloud.points, &stages, true, &name)?;
    let started = Instant::now();
    write_edges(
        &args.output,
        &cloud.points,
        &detection,
        &edges,
        args.file.options(),
    )?;
    summary.write_ms = millis(started.elapsed());
    summary.file = Some(name);
    summary.read_ms = millis(read_time);
    if args.json {
        console::print_line(&serde_json::to_string(&summary)?)
    } else {
        let output = crate::report::rows(&[("output", args.output.display().to_string())]);
        console::print(&(summary.table() + &output))
    }
}

/// The output's format; refuses unknown extensions and the input itself.
fn check_output(out: &Path, input: &Path) -> Result<EdgesFormat> {
    let format = edges_format(out)?;
    if same_file(out, input) {
        bail!("{}: the output would overwrite the input", out.display());
    }
    Ok(format)
}

/// Detects the boundary of the cloud `points` and reconstructs its
/// smoothed edges, in memory: what `meshtrim edges` does between reading
/// and writing, and what the Python package runs. Errors begin with `name`
/// (the file's path, or the argument's name); `progress` shows detection's
/// bar on a terminal. The summary names no file and has no read time.
pub fn edges_in_memory(
    points: &[Point3],
    stages: &Stages,
    progress: bool,
    name: &str,
) -> Result<(Detection, Edges, Summary)> {
    let (detection, edges, times) = detect_and_reconstruct(points, stages, progress, name)?;
    let summary = Summary::new(points.len(), &detection, &edges, stages, times);
    Ok((detection, edges, summary))
}

impl Summary {
    fn new(
        points: usize,
        detection: &Detection,
        edges: &Edges,
        stages: &Stages,
        [detect, reconstruct]: [Duration; 2],
    ) -> Self {
        Summary {
            file: None,
            points,
            boundary_points: detection.boundary_count(),
            loops: edges.loops.len(),
            edges: edges.loops.iter().map(|l| l.edges.len()).sum(),
            corners: edges.loops.iter().map(|l| l.corners.len()).sum(),
            dropped_clusters: edges.dropped_clusters,
            thinned_points: edges.thinned_points,
            loops_from: LoopsFrom(edges.loops_from),
            read_ms: 0.0,
            detect_ms: millis(detect),
            edges_ms: millis(reconstruct),
            write_ms: 0.0,
            offset: stages.edges.offset,
        }
    }

    /// The summary as an aligned two-column table.
    pub fn table(&self) -> String {
        let share = 100.0 * self.boundary_points as f64 / self.points.max(1) as f64;
        let on_off = if self.offset { "on" } else { "off" };
        let rows = [
            ("file", shown(&self.file)),
            ("points", self.points.to_string()),
            (
                "boundary points",
                format!("{} ({share:.1}%)", self.boundary_points),
            ),
            ("loops", self.loops.to_string()),
            ("edges", self.edges.to_string()),
            ("corners", self.corners.to_string()),
            ("dropped clusters", self.dropped_clusters.to_string()),
            ("thinned points", self.thinned_points.to_string()),
            ("loops from", self.loops_from.shown()),
            ("offset", on_off.to_string()),
            ("read time", format!("{:.1} ms", self.read_ms)),
            ("detect time", format!("{:.1} ms", self.detect_ms)),
            ("edges time", format!("{:.1} ms", self.edges_ms)),
            ("write time", format!("{:.1} ms", self.write_ms)),
        ];
        rows.iter()
            .map(|(label, value)| format!("{label:<20} {value}\n"))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use trim::LoopSource;

    #[test]
    fn output_checks() {
        let input = Path::new("Cargo.toml");
        assert!(check_output(Path::new("x.ply"), input).is_err());
        assert!(check_output(Path::new("x"), input).is_err());
        let err = check_output(Path::new("x.txt"), input).unwrap_err();
        assert_eq!(
            err.to_string(),
            "x.txt: unsupported output format: use .json, .obj, .svg, .dxf, .step or .igs"
        );
        assert_eq!(
            check_output(Path::new("out/e.SVG"), input).unwrap(),
            EdgesFormat::Svg
        );
        assert_eq!(
            check_output(Path::new("e.json"), input).unwrap(),
            EdgesFormat::Json
        );
    }

    #[test]
    fn table_rows() {
        let s = Summary {
            file: Some("a.ply".into()),
            points: 200,
            boundary_points: 20,
            loops: 2,
            edges: 5,
            corners: 4,
            dropped_clusters: 1,
            thinned_points: 3,
            loops_from: LoopsFrom(LoopSource::OwnPlane {
                normal: [0.0, 0.6, 0.8],
            }),
            read_ms: 1.0,
            detect_ms: 2.5,
            edges_ms: 0.25,
            write_ms: 0.5,
            offset: false,
        };
        let t = s.table();
        assert!(t.contains("boundary points      20 (10.0%)\n"), "{t}");
        assert!(t.contains("offset               off\n"), "{t}");
        assert!(t.contains("write time           0.5 ms\n"), "{t}");
        assert!(
            t.contains(
                "loops from           the cloud's own plane, seen along 0.000,0.600,0.800\n"
            ),
            "{t}"
        );
        assert_eq!(t.lines().count(), 14);
    }
}
