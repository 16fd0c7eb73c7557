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

pub use plan::{CloudMatch, Job, Shard};
pub use report::{Mode, Outcome, ReportFormat, Row, Status};

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::time::Instant;

use anyhow::{anyhow, bail, Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use crate::clean_cmd::clean_file;
use crate::cli::BatchArgs;
use crate::console;
use crate::detect::millis;
use crate::trim::{trim_file, TrimSettings};

/// Runs `meshtrim batch`.
pub fn run(args: &BatchArgs) -> Result<()> {
    let report_format = args
        .report
        .as_deref()
        .map(ReportFormat::from_path)
        .transpose()?;
    let jobs = plan::plan(&plan::Inputs {
        args: &args.inputs,
        out_dir: &args.out_dir,
        cloud_dir: args.cloud_dir.as_deref(),
        report: args.report.as_deref(),
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
fn process_all(jobs: &[Job], args: &BatchArgs) -> Result<Vec<Row>> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.map_or(0, usize::from))
        .build()
        .context("cannot start the worker threads")?;
    let bar = batch_bar(jobs.len());
    let rows = pool.install(|| {
        jobs.par_iter()
            .map(|job| {
                let row = process(job, args);
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

/// One file, whatever happens: skipped, done, failed, or panicked (the
/// panic is caught and reported as the file's failure).
fn process(job: &Job, args: &BatchArgs) -> Row {
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
    };
    if args.skip_existing && job.output.exists() {
        return row;
    }
    let result = catch_unwind(AssertUnwindSafe(|| work(job, args)))
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
        }
        Err(e) => {
            row.status = Status::Failed;
            row.error = Some(format!("{e:#}"));
        }
    }
    row.total_ms = millis(started.elapsed());
    row
}

/// Cleans or trims one file, writing its output atomically.
fn work(job: &Job, args: &BatchArgs) -> Result<Outcome> {
    match &job.cloud {
        CloudMatch::None => {
            let o = clean_file(&job.input, &job.output, &args.stages)?;
            Ok(Outcome {
                loops: o.loops,
                faces_in: o.faces_in,
                faces_out: o.faces_out,
                read_ms: o.read_ms,
                algorithm_ms: o.clean_ms,
                write_ms: o.write_ms,
            })
        }
        CloudMatch::One(cloud) => {
            let settings = TrimSettings {
                detection: args.stages.bpd_options(),
                no_offset: args.stages.no_offset,
                progress: false,
            };
            let r = trim_file(&job.input, cloud, &job.output, &settings)?;
            Ok(Outcome {
                loops: r.loops,
                faces_in: r.faces_in,
                faces_out: r.faces_out,
                read_ms: r.read_ms,
                algorithm_ms: ((r.detect_ms + r.edges_ms + r.trim_ms) * 10.0).round() / 10.0,
                write_ms: r.write_ms,
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

/// A panic's message, when it has one.
fn panic_text(panic: &(dyn std::any::Any + Send)) -> String {
    panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic without a message".to_string())
}
