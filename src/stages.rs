//! The options of all stages, as the library takes them; boundary
//! detection with a progress bar on a terminal, which every command that
//! works from a cloud runs first; and the library's error messages in the
//! command line's words.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::Context;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use trim::{reconstruct_edges, BpdOptions, CloudError, Detection, EdgeOptions, Edges};

use crate::io::Point3;

/// The options of detection and edge reconstruction, as the library takes
/// them: what a command (or each file of a batch) runs with.
#[derive(Debug, Clone, PartialEq)]
pub struct Stages {
    /// Boundary detection's options.
    pub detection: BpdOptions,
    /// Edge reconstruction's options.
    pub edges: EdgeOptions,
}

/// BPD on `points`, with the progress bar or without.
pub(crate) fn detect(
    points: &[Point3],
    options: &BpdOptions,
    progress: bool,
) -> Result<Detection, CloudError> {
    if progress {
        detect_with_progress(points, options)
    } else {
        trim::detect_boundary(points, options)
    }
}

/// The cloud's boundary and its smoothed edges, each stage timed: what
/// `edges`, `trim` and `mesh` run first. A detection error begins with
/// `name` (the cloud's file, or the argument's name).
pub(crate) fn detect_and_reconstruct(
    points: &[Point3],
    stages: &Stages,
    progress: bool,
    name: &str,
) -> anyhow::Result<(Detection, Edges, [Duration; 2])> {
    let started = Instant::now();
    let detection =
        detect(points, &stages.detection, progress).with_context(|| name.to_string())?;
    let detect_time = started.elapsed();
    let started = Instant::now();
    let edges = reconstruct_edges(points, &detection, &stages.edges);
    Ok((detection, edges, [detect_time, started.elapsed()]))
}

/// Milliseconds, rounded to 0.1 ms.
pub(crate) fn millis(d: Duration) -> f64 {
    (d.as_secs_f64() * 1e4).round() / 10.0
}

/// BPD with a progress bar on stderr. The bar appears only once the run has
/// taken a second, so quick runs print nothing, and indicatif hides it when
/// stderr is not a terminal.
fn detect_with_progress(points: &[Point3], options: &BpdOptions) -> Result<Detection, CloudError> {
    // The library counts distinct points, not known before it merges
    // duplicates; the bar's length is all points, so with duplicates it stops
    // short of full, and it is cleared at the end anyway.
    let bar =
        ProgressBar::with_draw_target(Some(points.len() as u64), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("detecting boundary {bar:40} {pos}/{len} points, {eta} left")
            .expect("the template is valid"),
    );
    let started = Instant::now();
    let shown = AtomicBool::new(false);
    let progress = |done: usize| {
        if started.elapsed() > Duration::from_secs(1) && !shown.swap(true, Ordering::Relaxed) {
            bar.set_draw_target(ProgressDrawTarget::stderr());
        }
        bar.set_position(done as u64);
    };
    let result = trim::detect_boundary_with_progress(points, options, &progress);
    bar.finish_and_clear();
    result
}

/// An error message in the command line's words. The library (and the
/// Python package, which passes its messages on) advises in terms of its
/// parameters and functions: lower k, trim a Poisson mesh instead; on the
/// command line they are the flag `--k` and the command
/// `meshtrim MESH CLOUD OUT`. Applied where the CLI prints an error.
pub fn in_cli_words(message: &str) -> String {
    message
        .replace("lower k or", "lower --k or")
        .replace(
            "trim that mesh instead",
            "use `meshtrim MESH CLOUD OUT` instead",
        )
        .replace("check the view's position", "check --view-from")
        .replace("clean with repair on", "clean with --repair")
        .replace("scale the cloud by ", "scale the cloud with --cloud-scale ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use trim::DelaunayError;

    /// Every library message that advises a parameter or another stage
    /// gets the flag or the command that sets it.
    #[test]
    fn advice_names_the_flag_and_the_command() {
        let few = CloudError::TooFewPoints {
            distinct: 5,
            total: 6,
            k: 30,
        };
        assert!(in_cli_words(&few.to_string()).ends_with("; lower --k or use a denser cloud"));
        let behind = DelaunayError::NotInView { index: 3 };
        assert!(in_cli_words(&behind.to_string()).ends_with("; check --view-from"));
        let metres = trim::TrimError::Unsupported(trim::Placement::Units {
            factor: 1000.0,
            units: ("metres", "millimetres"),
        });
        assert!(in_cli_words(&metres.to_string())
            .ends_with("): scale the cloud with --cloud-scale 1000"));
        let folds = [
            DelaunayError::NotAHeightField {
                onto: "the best-fit plane",
                percent: 2.0,
                what: "triangles",
                limit: 1.0,
            },
            DelaunayError::LoopNotSimple {
                onto: "the best-fit plane",
                index: 0,
                vertices: 10,
                dropped: 4,
            },
            DelaunayError::LoopsCross {
                onto: "the scanner's image",
                a: 0,
                b: 1,
            },
        ];
        for error in folds {
            let words = in_cli_words(&error.to_string());
            assert!(
                words.ends_with(
                    "mesh it with screened Poisson and use `meshtrim MESH CLOUD OUT` instead"
                ),
                "{words}"
            );
        }
    }
}
