//! `meshtrim detect`: read a cloud, label its boundary points, report.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use serde::Serialize;
use trim::{BpdOptions, Detection, View};

use crate::commands::args::{bpd_options, parse_k, ViewArgs};
use crate::console;
use crate::io::atomic::write_atomic;
use crate::io::labels::{LabelFormat, Labelled};
use crate::io::{read_cloud_with, Cloud, CloudOptions, Format, Point3};
use crate::report::{same_file, shown};
use crate::stages::{detect, millis};

/// Arguments of `meshtrim detect`.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// Input point cloud: .ply, .pcd, .obj, .las/.laz, .e57, .xyz/.txt/.csv/.asc/.pts, or a
    /// mesh (.stl, .gltf, .glb) whose vertices are the cloud.
    pub cloud: PathBuf,
    /// Write the points with their labels: OUT.ply (binary), OUT.csv, or
    /// OUT.las / OUT.laz (extra-bytes fields `boundary` and `beta`; a LAS
    /// input's scale and offset). Missing parent directories are created.
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
    /// Read only scan N of an E57 file (its 0-based data3D index); by
    /// default every scan is read, each in its pose, merged in the file's
    /// frame.
    #[arg(long, value_name = "N")]
    pub scan: Option<usize>,
    /// Print the summary as one JSON object.
    #[arg(long)]
    pub json: bool,
}

impl Args {
    /// Boundary detection's options.
    pub fn bpd_options(&self) -> BpdOptions {
        bpd_options(self.k, self.no_anisotropy, &self.view)
    }
}

/// What `detect` prints: the counts and timings of the paper's Table 1.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// The input file, as given (none in memory).
    pub file: Option<String>,
    /// Points read (after dropping non-finite PCD points).
    pub points: usize,
    /// Points left after merging exact duplicates.
    pub distinct_points: usize,
    /// Points that were exact copies of an earlier one.
    pub duplicates: usize,
    /// Points dropped by the reader: a NaN or infinite coordinate (PCD),
    /// no position (E57's invalid states).
    pub dropped_non_finite: usize,
    /// Points labelled boundary (duplicates counted).
    pub boundary_points: usize,
    /// Smallest local resolution β over all points.
    pub beta_min: f64,
    /// Mean β.
    pub beta_mean: f64,
    /// Largest β.
    pub beta_max: f64,
    /// Standard deviation of β (population).
    pub beta_std: f64,
    /// Time to read the file, in milliseconds.
    pub read_ms: f64,
    /// Time of boundary detection, in milliseconds.
    pub detect_ms: f64,
    /// Neighbourhood size used.
    pub k: usize,
    /// Whether the anisotropy map was on.
    pub anisotropy: bool,
    /// The scanner's line of sight, when given (`--view-along`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub view_along: Option<[f64; 3]>,
    /// The scanner's position, when given (`--view-from`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub view_from: Option<[f64; 3]>,
}

/// Runs `meshtrim detect`.
pub fn run(args: &Args) -> Result<()> {
    // Check the output before the (possibly long) detection.
    let output = args
        .output
        .as_deref()
        .map(|out| check_output(out, &args.cloud))
        .transpose()?;
    let started = Instant::now();
    let cloud = read_cloud_with(&args.cloud, &CloudOptions { scan: args.scan })?;
    let read_time = started.elapsed();
    let name = args.cloud.display().to_string();
    let (detection, mut summary) =
        detect_in_memory(&cloud.points, &args.bpd_options(), true, &name)?;
    if let Some((path, format)) = &output {
        write_labels(path, *format, &args.cloud, &cloud, &detection)?;
    }
    summary.file = Some(name);
    summary.read_ms = millis(read_time);
    summary.dropped_non_finite = cloud.dropped_non_finite;
    if args.json {
        console::print_line(&serde_json::to_string(&summary)?)
    } else {
        let mut text = summary.table();
        if let Some((path, _)) = &output {
            text += &crate::report::rows(&[("output", path.display().to_string())]);
        }
        console::print(&text)
    }
}

/// The output's format; refuses unknown extensions and the input itself.
fn check_output(out: &Path, input: &Path) -> Result<(PathBuf, LabelFormat)> {
    let Some(format) = LabelFormat::from_path(out) else {
        bail!(
            "{}: unsupported output format: use .ply, .csv, .las or .laz",
            out.display()
        );
    };
    if same_file(out, input) {
        bail!("{}: the output would overwrite the input", out.display());
    }
    Ok((out.to_path_buf(), format))
}

fn write_labels(
    path: &Path,
    format: LabelFormat,
    input: &Path,
    cloud: &Cloud,
    detection: &Detection,
) -> Result<()> {
    let data = Labelled {
        points: &cloud.points,
        boundary: &detection.boundary,
        beta: &detection.beta,
        scale_offset: cloud.scale_offset,
        grid: cloud.grid.as_deref(),
        las_source: (cloud.format == Format::Las).then_some(input),
    };
    write_atomic(path, |w| format.write(w, data))
}

/// Labels the boundary points of the cloud `points` in memory: what
/// `meshtrim detect` does between reading and writing, and what the Python
/// package runs. Errors begin with `name` (the file's path, or the
/// argument's name); `progress` shows the bar on a terminal. The summary
/// names no file and has no read time.
pub fn detect_in_memory(
    points: &[Point3],
    options: &BpdOptions,
    progress: bool,
    name: &str,
) -> Result<(Detection, Summary)> {
    let started = Instant::now();
    let detection = detect(points, options, progress).with_context(|| name.to_string())?;
    let summary = Summary::new(points.len(), &detection, options, started.elapsed());
    Ok((detection, summary))
}

impl Summary {
    fn new(points: usize, detection: &Detection, options: &BpdOptions, time: Duration) -> Self {
        let (beta_min, beta_mean, beta_max, beta_std) = stats(&detection.beta);
        let (view_along, view_from) = match options.view {
            Some(View::Along(d)) => (Some(d), None),
            Some(View::From(o)) => (None, Some(o)),
            None => (None, None),
        };
        Summary {
            file: None,
            points,
            distinct_points: points - detection.duplicates,
            duplicates: detection.duplicates,
            dropped_non_finite: 0,
            boundary_points: detection.boundary_count(),
            beta_min,
            beta_mean,
            beta_max,
            beta_std,
            read_ms: 0.0,
            detect_ms: millis(time),
            k: options.k,
            anisotropy: options.anisotropy,
            view_along,
            view_from,
        }
    }

    /// The summary as an aligned two-column table.
    pub fn table(&self) -> String {
        let share = 100.0 * self.boundary_points as f64 / self.points.max(1) as f64;
        let on_off = if self.anisotropy { "on" } else { "off" };
        let rows = [
            ("file", shown(&self.file)),
            ("points", self.points.to_string()),
            ("distinct points", self.distinct_points.to_string()),
            ("duplicates", self.duplicates.to_string()),
            ("dropped invalid", self.dropped_non_finite.to_string()),
            (
                "boundary points",
                format!("{} ({share:.1}%)", self.boundary_points),
            ),
            ("beta min", format!("{:.6}", self.beta_min)),
            ("beta mean", format!("{:.6}", self.beta_mean)),
            ("beta max", format!("{:.6}", self.beta_max)),
            ("beta std", format!("{:.6}", self.beta_std)),
            ("k", self.k.to_string()),
            ("anisotropy", on_off.to_string()),
            ("projection", self.projection()),
            ("read time", format!("{:.1} ms", self.read_ms)),
            ("detect time", format!("{:.1} ms", self.detect_ms)),
        ];
        rows.iter()
            .map(|(label, value)| format!("{label:<20} {value}\n"))
            .collect()
    }
}

impl Summary {
    /// How neighbourhoods were projected: along their normals (the
    /// paper's), or along the scanner's line of sight.
    fn projection(&self) -> String {
        let xyz = |v: [f64; 3]| format!("{},{},{}", v[0], v[1], v[2]);
        match (self.view_along, self.view_from) {
            (Some(d), _) => format!("along the line of sight {}", xyz(d)),
            (None, Some(o)) => format!("along lines of sight from {}", xyz(o)),
            (None, None) => "along each neighbourhood's normal".to_string(),
        }
    }
}

/// Minimum, mean, maximum and population standard deviation.
fn stats(values: &[f64]) -> (f64, f64, f64, f64) {
    let n = values.len().max(1) as f64;
    let min = values.iter().copied().fold(f64::INFINITY, f64::min);
    let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n;
    (min, mean, max, var.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_of_known_values() {
        let (min, mean, max, std) = stats(&[1.0, 3.0, 5.0, 7.0]);
        assert_eq!((min, mean, max), (1.0, 4.0, 7.0));
        assert!((std - 5f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn output_checks() {
        let input = Path::new("Cargo.toml");
        assert!(check_output(Path::new("x.txt"), input).is_err());
        assert!(check_output(Path::new("Cargo.toml"), input).is_err());
        let (_, f) = check_output(Path::new("out/x.CSV"), input).unwrap();
        assert_eq!(f, LabelFormat::Csv);
    }
}
