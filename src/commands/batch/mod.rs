//! `meshtrim batch INPUTS... --out-dir DIR`: clean or trim many meshes at
//! once.
//!
//! The list of work is fixed first (`plan`): inputs expanded, sorted and
//! de-duplicated, clouds paired, outputs checked, then this run's shard
//! taken. The files then go through a pool of `--jobs` threads, which the
//! library's own parallel loops share, so N jobs means N threads in all.
//! One bad file never stops the batch: its error (or even a panic) becomes
//! its `failed` line and report row, and the exit status says whether any
//! failed.

mod plan;
mod report;

pub use plan::{plan, CloudMatch, Inputs, Job, Shard};
pub use report::{Mode, Outcome, ReportFormat, Row, Status};

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, bail, Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use super::clean::{clean_file, Choices, WRAPS_BELOW};
use super::trim::{trim_file, TrimSettings};
use crate::commands::args::{EdgeFileArgs, StageArgs};
use crate::commands::panic_text;
use crate::console;
use crate::io::edges_out::EdgeFileOptions;
use crate::io::CloudOptions;
use crate::stages::{in_cli_words, millis, Stages};

/// Arguments of `meshtrim batch`.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// Meshes (.stl, .ply, .obj, .gltf, .glb): files, directories (walked
    /// recursively) and glob patterns (quote them: 'scans/*.ply'). A mesh
    /// S.ext is trimmed when a cloud S.cloud.EXT or S.EXT with EXT one of
    /// e57 las laz pcd xyz txt csv asc pts sits beside it, and cleaned
    /// otherwise; clouds are never inputs themselves.
    #[arg(required = true, value_name = "INPUTS")]
    pub inputs: Vec<PathBuf>,
    /// Where the outputs go: the input's path below the directory argument
    /// it was found in (or its file name), same extension (or --to's).
    #[arg(long, value_name = "DIR")]
    pub out_dir: PathBuf,
    /// Write every output in this mesh format (obj, ply, stl, glb, gltf)
    /// instead of its input's: a folder of textured OBJ scans to GLB, or
    /// of PLY to STL for CAM. Texture coordinates and materials are made
    /// the format's, as one command's output to another extension is.
    #[arg(long, value_name = "EXT", value_parser = ["obj", "ply", "stl", "glb", "gltf"])]
    pub to: Option<String>,
    /// Look for the clouds here (mirroring the inputs' sub-directories)
    /// instead of beside the meshes.
    #[arg(long, value_name = "DIR")]
    pub cloud_dir: Option<PathBuf>,
    /// Multiply the clouds' coordinates by this factor before trimming,
    /// for clouds in other units than the meshes: 1000 for clouds in
    /// metres (as E57 files hold them) and meshes in millimetres.
    #[arg(long, value_name = "FACTOR", value_parser = crate::commands::args::parse_scale, allow_hyphen_values = true)]
    pub cloud_scale: Option<f64>,
    /// Files processed at once, and threads in all [default: all cores].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub jobs: Option<u16>,
    /// Write a line per file to FILE.csv or FILE.json.
    #[arg(long, value_name = "FILE.csv|FILE.json")]
    pub report: Option<PathBuf>,
    /// Skip inputs whose output exists, and with --edges-to whose edges
    /// file exists too (resumes an interrupted batch).
    #[arg(long)]
    pub skip_existing: bool,
    /// Process only the K-th of N deterministic shards of the sorted input
    /// list (1-based), e.g. one per machine or array task.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<Shard>,
    /// Repair meshes to clean that are not edge-manifold or consistently
    /// oriented instead of refusing them (as `clean --repair`).
    #[arg(long)]
    pub repair: bool,
    /// Also measure how far each output lies from its scan: for a cleaned
    /// file, as `clean` reports it, the largest distance of its removed
    /// vertices from the output and of the new ones from the input (the
    /// report's removed_max and new_max); for a trimmed file, as `trim`
    /// reports it, the largest and mean distance of its cloud's points
    /// from the output (cloud_max, cloud_mean). A tenth to a third more
    /// time.
    #[arg(long)]
    pub deviation: bool,
    /// Keep each cleaned scan's new border within this distance of its old
    /// one (as `clean --max-deviation`).
    #[arg(long, value_name = "D", value_parser = crate::commands::args::parse_distance, allow_hyphen_values = true)]
    pub max_deviation: Option<f64>,
    /// Close each cleaned scan's holes no wider than W first (as `clean
    /// --fill-holes`).
    #[arg(long, value_name = "W", value_parser = crate::commands::args::parse_distance, allow_hyphen_values = true)]
    pub fill_holes: Option<f64>,
    /// Also write each output's edges, as S.edges.EXT beside the output
    /// S.ext, in this format (json, obj, svg, dxf, step, igs): a cleaned
    /// file's border, as `clean --edges` writes it; the smoothed edges a
    /// trimmed file was cut along, as `trim --edges` writes them.
    #[arg(long, value_name = "EXT", value_parser = ["json", "obj", "svg", "dxf", "step", "igs"])]
    pub edges_to: Option<String>,
    /// Detection and edge options.
    #[command(flatten)]
    pub stages: StageArgs,
    /// The unit declared, DXF splines.
    #[command(flatten)]
    pub file: EdgeFileArgs,
}

/// Runs `meshtrim batch`.
pub fn run(args: &Args) -> Result<()> {
    let report_format = args
        .report
        .as_deref()
        .map(ReportFormat::from_path)
        .transpose()?;
    if args.file.dxf_splines && args.edges_to.as_deref() != Some("dxf") {
        bail!("--dxf-splines writes splines into the edges files: give --edges-to dxf");
    }
    let jobs = plan(&Inputs {
        args: &args.inputs,
        out_dir: &args.out_dir,
        cloud_dir: args.cloud_dir.as_deref(),
        report: args.report.as_deref(),
        to: args.to.as_deref(),
        edges_to: args.edges_to.as_deref(),
    })?;
    let inputs = jobs.len();
    let jobs: Vec<Job> = match args.shard {
        Some(shard) => jobs
            .into_iter()
            .enumerate()
            .filter(|(i, _)| shard.holds(*i))
            .map(|(_, job)| job)
            .collect(),
        None => jobs,
    };
    let started = Instant::now();
    let rows = process_all(&jobs, args)?;
    let totals = report::Totals {
        rows: &rows,
        inputs,
        shard: args.shard.map(|s| format!("{}/{}", s.index, s.count)),
        total_ms: millis(started.elapsed()),
    };
    if let (Some(path), Some(format)) = (&args.report, report_format) {
        totals.write(path, format)?;
    }
    console::print_line(&totals.summary())?;
    let failed = totals.count(Status::Failed);
    if failed > 0 {
        bail!("{failed} of {} files failed", rows.len());
    }
    Ok(())
}

/// Processes the jobs on a pool of `--jobs` threads (default: rayon's, all
/// cores or RAYON_NUM_THREADS), printing a line per file as it finishes;
/// the rows come back in input order.
fn process_all(jobs: &[Job], args: &Args) -> Result<Vec<Row>> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.map_or(0, usize::from))
        .build()
        .context("cannot start the worker threads")?;
    let settings = FileSettings {
        skip_existing: args.skip_existing,
        choices: Choices {
            repair: args.repair,
            max_deviation: args.max_deviation,
            fill_holes: args.fill_holes,
        },
        deviation: args.deviation,
        edges: args.file.options(),
        stages: args.stages.stages(),
        cloud_scale: args.cloud_scale,
    };
    let bar = batch_bar(jobs.len());
    let rows = pool.install(|| {
        jobs.par_iter()
            .map(|job| {
                let row = process(job, &settings);
                // Printed above the bar, which is redrawn below it.
                // Best effort: a failing stdout must not stop the files;
                // the summary below reports it.
                bar.suspend(|| console::print_line(&row.line())).ok();
                bar.inc(1);
                row
            })
            .collect()
    });
    bar.finish_and_clear();
    Ok(rows)
}

/// The batch's one progress bar, on stderr; indicatif hides it when stderr
/// is not a terminal, so logs of scheduled jobs hold only the lines.
fn batch_bar(files: usize) -> ProgressBar {
    let bar = ProgressBar::new(files as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} files, {elapsed} elapsed, {eta} left")
            .expect("the template is valid"),
    );
    bar
}

/// What every file of the batch is told.
struct FileSettings {
    /// Skip a file whose output exists.
    skip_existing: bool,
    /// `--repair` and `--max-deviation`.
    choices: Choices,
    /// Measure how far each output lies from its scan (`--deviation`).
    deviation: bool,
    /// How each job's edges file, if any, is written.
    edges: EdgeFileOptions,
    /// Detection's and edge reconstruction's options.
    stages: Stages,
    /// The clouds' scale factor (`--cloud-scale`).
    cloud_scale: Option<f64>,
}

/// One file, whatever happens: skipped, done, failed, or panicked (the
/// panic is caught and reported as the file's failure).
fn process(job: &Job, settings: &FileSettings) -> Row {
    let started = Instant::now();
    let mode = match job.cloud {
        CloudMatch::None => Mode::Clean,
        _ => Mode::Trim,
    };
    let mut row = Row {
        input: job.input.display().to_string(),
        output: job.output.display().to_string(),
        mode,
        status: Status::Skipped,
        error: None,
        loops: None,
        faces_in: None,
        faces_out: None,
        read_ms: None,
        algorithm_ms: None,
        write_ms: None,
        total_ms: 0.0,
        repaired: None,
        removed_max: None,
        new_max: None,
        cloud_max: None,
        cloud_mean: None,
        holes_filled: None,
        cloud: match &job.cloud {
            CloudMatch::One(cloud) => Some(cloud.display().to_string()),
            _ => None,
        },
        note: None,
    };
    let done = job.output.exists() && job.edges.as_deref().is_none_or(Path::exists);
    if settings.skip_existing && done {
        return row;
    }
    let result = catch_unwind(AssertUnwindSafe(|| work(job, settings)))
        .unwrap_or_else(|panic| Err(anyhow!("internal error: {}", panic_text(&*panic))));
    match result {
        Ok(o) => {
            row.status = Status::Ok;
            row.loops = Some(o.loops);
            row.faces_in = Some(o.faces_in);
            row.faces_out = Some(o.faces_out);
            row.read_ms = Some(o.read_ms);
            row.algorithm_ms = Some(o.algorithm_ms);
            row.write_ms = Some(o.write_ms);
            row.repaired = o.repaired;
            [row.removed_max, row.new_max] = o.deviation.map_or([None; 2], |d| d.map(Some));
            [row.cloud_max, row.cloud_mean] = o.cloud_deviation.map_or([None; 2], |d| d.map(Some));
            row.holes_filled = o.holes_filled;
            row.note = o.note;
        }
        Err(e) => {
            row.status = Status::Failed;
            // The line names the file already: the chain need not again.
            let chain = in_cli_words(&format!("{e:#}"));
            let prefix = format!("{}: ", row.input);
            row.error = Some(chain.strip_prefix(&prefix).unwrap_or(&chain).to_string());
        }
    }
    row.total_ms = millis(started.elapsed());
    row
}

/// A file without faces among the meshes is most likely a cloud misnamed.
const NO_FACES: &str = "it looks like a point cloud: to trim the mesh S.EXT with it, name it \
     S.cloud.EXT beside the mesh (or S.EXT with EXT one of e57 las laz pcd xyz txt csv asc pts)";

/// A cleaned mesh without a border: nothing was smoothed.
const CLOSED: &str = "no border: a closed mesh has nothing to clean; to trim a Poisson \
     envelope, put its cloud S.cloud.EXT beside it";

/// A cleaned mesh wrapping round an object: perhaps an envelope cut open.
const WRAPS: &str = "it wraps round an object, as an envelope cut open does: to trim a \
     reconstruction's envelope instead, put its cloud S.cloud.EXT beside it";

/// Cleans (repairing it first with `--repair`) or trims one file, writing
/// its output atomically.
fn work(job: &Job, settings: &FileSettings) -> Result<Outcome> {
    let FileSettings {
        choices,
        deviation,
        edges,
        ref stages,
        cloud_scale,
        ..
    } = *settings;
    let edges = job.edges.as_deref().map(|path| (path, edges));
    match &job.cloud {
        CloudMatch::None => {
            let o = clean_file(
                &job.input,
                &job.output,
                stages,
                (choices, deviation, edges),
                NO_FACES,
            )?;
            Ok(Outcome {
                loops: o.loops,
                faces_in: o.faces_in,
                faces_out: o.faces_out,
                read_ms: o.read_ms,
                algorithm_ms: o.clean_ms,
                write_ms: o.write_ms,
                repaired: Some(o.repaired),
                deviation: o.deviation,
                cloud_deviation: None,
                holes_filled: o.holes_filled,
                note: if o.loops_in == 0 {
                    Some(CLOSED)
                } else {
                    (o.area_facing_one_way < WRAPS_BELOW).then_some(WRAPS)
                },
            })
        }
        CloudMatch::One(cloud) => {
            let settings = TrimSettings {
                stages: stages.clone(),
                progress: false,
                cloud: CloudOptions::default(),
                cloud_scale,
                measure: deviation,
            };
            let r = trim_file(&job.input, cloud, &job.output, edges, &settings)?;
            Ok(Outcome {
                loops: r.loops,
                faces_in: r.faces_in,
                faces_out: r.faces_out,
                read_ms: r.read_ms,
                algorithm_ms: ((r.detect_ms + r.edges_ms + r.trim_ms) * 10.0).round() / 10.0,
                write_ms: r.write_ms,
                repaired: None,
                deviation: None,
                cloud_deviation: r.cloud_to_output.map(|d| [d.max, d.mean]),
                holes_filled: None,
                note: None,
            })
        }
        CloudMatch::Several(clouds) => {
            let names: Vec<String> = clouds.iter().map(|c| c.display().to_string()).collect();
            bail!(
                "several clouds match this mesh ({}): keep one",
                names.join(", ")
            )
        }
    }
}
