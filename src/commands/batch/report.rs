//! What `meshtrim batch` says about each file: the line printed when it
//! finishes and the row of the `--report` file (CSV or JSON).

use std::path::Path;

use anyhow::{bail, Result};
use serde::Serialize;

use crate::io::atomic::write_atomic;
use crate::report::significant;

/// Whether a mesh was cleaned or trimmed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// No cloud beside it: cleaned.
    Clean,
    /// Trimmed along its cloud's boundary.
    Trim,
}

impl Mode {
    /// The name the report uses.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Clean => "clean",
            Mode::Trim => "trim",
        }
    }
}

/// How a file went.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Output written.
    Ok,
    /// Nothing written; `error` says why.
    Failed,
    /// `--skip-existing` and the output was there.
    Skipped,
}

impl Status {
    /// The name the report uses.
    pub fn name(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Failed => "failed",
            Status::Skipped => "skipped",
        }
    }
}

/// The numbers of a file that went through.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outcome {
    /// Boundary loops.
    pub loops: usize,
    /// Input faces.
    pub faces_in: usize,
    /// Output faces.
    pub faces_out: usize,
    /// Reading (mesh and cloud), in milliseconds.
    pub read_ms: f64,
    /// Detection, edges and cutting or cleaning, in milliseconds.
    pub algorithm_ms: f64,
    /// Writing, in milliseconds.
    pub write_ms: f64,
    /// Faces `--repair` removed or turned (none for a trim).
    pub repaired: Option<usize>,
    /// With `--deviation`, for a cleaned file: the largest distances of
    /// the removed vertices from the output and of the new ones from the
    /// input.
    pub deviation: Option<[f64; 2]>,
    /// With `--deviation`, for a trimmed file: the largest and the mean
    /// distance of its cloud's points from the output.
    pub cloud_deviation: Option<[f64; 2]>,
    /// With `--fill-holes`, for a cleaned file: the holes closed.
    pub holes_filled: Option<usize>,
    /// What the user should know about the file (a closed mesh cleaned).
    pub note: Option<&'static str>,
}

/// One file of the batch, as the report lists it. The numbers are absent
/// (empty in CSV, null in JSON) for files that failed or were skipped.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    /// The input mesh.
    pub input: String,
    /// Its output.
    pub output: String,
    /// Cleaned or trimmed.
    pub mode: Mode,
    /// How it went.
    pub status: Status,
    /// Why it failed: the whole error chain.
    pub error: Option<String>,
    /// Boundary loops.
    pub loops: Option<usize>,
    /// Input faces.
    pub faces_in: Option<usize>,
    /// Output faces.
    pub faces_out: Option<usize>,
    /// Reading time, in milliseconds.
    pub read_ms: Option<f64>,
    /// Algorithm time, in milliseconds.
    pub algorithm_ms: Option<f64>,
    /// Writing time, in milliseconds.
    pub write_ms: Option<f64>,
    /// Wall-clock time of the file, in milliseconds.
    pub total_ms: f64,
    /// Faces `--repair` removed or turned to make the mesh manifold and
    /// oriented (cleaned files only).
    pub repaired: Option<usize>,
    /// With `--deviation`, for a cleaned file: the largest distance of its
    /// removed vertices from the output.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub removed_max: Option<f64>,
    /// With `--deviation`, for a cleaned file: the largest distance of its
    /// new vertices from the input.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub new_max: Option<f64>,
    /// With `--deviation`, for a trimmed file: the largest distance of its
    /// cloud's points from the output.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cloud_max: Option<f64>,
    /// With `--deviation`, for a trimmed file: the mean distance of its
    /// cloud's points from the output.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cloud_mean: Option<f64>,
    /// With `--fill-holes`, for a cleaned file: the holes closed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub holes_filled: Option<usize>,
    /// The cloud a trimmed file was paired with (none for a clean, or
    /// when several clouds matched: the error names them).
    pub cloud: Option<String>,
    /// What the user should know about the file, when anything.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<&'static str>,
}

impl Row {
    /// The line printed when the file is done.
    pub fn line(&self) -> String {
        let secs = self.total_ms / 1000.0;
        let mode = self.mode.name();
        let note = self.note.map(|n| format!("  ({n})")).unwrap_or_default();
        let repaired = match self.repaired {
            Some(n) if n > 0 => format!("  repaired={n}"),
            _ => String::new(),
        };
        let filled = self
            .holes_filled
            .map(|n| format!("  holes filled={n}"))
            .unwrap_or_default();
        let moved = match (
            self.removed_max,
            self.new_max,
            self.cloud_max,
            self.cloud_mean,
        ) {
            (Some(removed), Some(new), _, _) => format!(
                "  moved: removed≤{} new≤{}",
                significant(removed, 4),
                significant(new, 4)
            ),
            (_, _, Some(max), Some(mean)) => format!(
                "  cloud: off≤{} mean {}",
                significant(max, 4),
                significant(mean, 4)
            ),
            _ => String::new(),
        };
        match self.status {
            Status::Ok => format!(
                "ok      {mode:<5}  {}  loops={}  faces {}→{}{filled}{repaired}{moved}  {secs:.2} s{note}",
                self.input,
                self.loops.unwrap_or(0),
                self.faces_in.unwrap_or(0),
                self.faces_out.unwrap_or(0)
            ),
            Status::Failed => format!(
                "failed  {mode:<5}  {}: {}",
                self.input,
                self.error.as_deref().unwrap_or("")
            ),
            Status::Skipped => format!("skipped {mode:<5}  {} (output exists)", self.input),
        }
    }

    /// The row's CSV fields, in [`CSV_HEADER`] order.
    fn csv_fields(&self) -> [String; 19] {
        let opt = |v: Option<String>| v.unwrap_or_default();
        [
            self.input.clone(),
            self.output.clone(),
            self.mode.name().to_string(),
            self.status.name().to_string(),
            opt(self.error.clone()),
            opt(self.loops.map(|v| v.to_string())),
            opt(self.faces_in.map(|v| v.to_string())),
            opt(self.faces_out.map(|v| v.to_string())),
            opt(self.read_ms.map(|v| v.to_string())),
            opt(self.algorithm_ms.map(|v| v.to_string())),
            opt(self.write_ms.map(|v| v.to_string())),
            self.total_ms.to_string(),
            opt(self.repaired.map(|v| v.to_string())),
            opt(self.cloud.clone()),
            opt(self.removed_max.map(|v| v.to_string())),
            opt(self.new_max.map(|v| v.to_string())),
            opt(self.cloud_max.map(|v| v.to_string())),
            opt(self.cloud_mean.map(|v| v.to_string())),
            opt(self.holes_filled.map(|v| v.to_string())),
        ]
    }
}

/// The CSV columns (new ones go last, so that columns read by position
/// keep theirs).
pub const CSV_HEADER: [&str; 19] = [
    "input",
    "output",
    "mode",
    "status",
    "error",
    "loops",
    "faces_in",
    "faces_out",
    "read_ms",
    "algorithm_ms",
    "write_ms",
    "total_ms",
    "repaired",
    "cloud",
    "removed_max",
    "new_max",
    "cloud_max",
    "cloud_mean",
    "holes_filled",
];

/// The report formats, by the file's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReportFormat {
    /// A header line, then a line per file (RFC 4180 quoting).
    Csv,
    /// One object: the counts and `files`, a row per file.
    Json,
}

impl ReportFormat {
    /// The format `path` names, or an error saying which extensions work;
    /// checked before the batch starts.
    pub fn from_path(path: &Path) -> Result<ReportFormat> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        Ok(match ext.to_ascii_lowercase().as_str() {
            "csv" => ReportFormat::Csv,
            "json" => ReportFormat::Json,
            _ => bail!(
                "{}: unknown report format: name it .csv or .json",
                path.display()
            ),
        })
    }
}

/// The JSON report.
#[derive(Debug, Serialize)]
struct JsonReport<'a> {
    /// Inputs of the whole batch, all shards.
    inputs: usize,
    /// `K/N` when one shard was processed.
    shard: Option<String>,
    ok: usize,
    failed: usize,
    skipped: usize,
    /// Wall-clock time of the batch, in milliseconds.
    total_ms: f64,
    /// The files of this run, in input order.
    files: &'a [Row],
}

/// The batch as a whole, for the report and the summary line.
pub struct Totals<'a> {
    /// The files processed, in input order.
    pub rows: &'a [Row],
    /// Inputs of the whole batch, all shards.
    pub inputs: usize,
    /// The shard, as given.
    pub shard: Option<String>,
    /// Wall-clock time, in milliseconds.
    pub total_ms: f64,
}

impl Totals<'_> {
    /// Files with `status`.
    pub fn count(&self, status: Status) -> usize {
        self.rows.iter().filter(|r| r.status == status).count()
    }

    /// Writes the report atomically to `path` in `format`.
    pub fn write(&self, path: &Path, format: ReportFormat) -> Result<()> {
        let bytes = match format {
            ReportFormat::Csv => csv(self.rows).into_bytes(),
            ReportFormat::Json => {
                let report = JsonReport {
                    inputs: self.inputs,
                    shard: self.shard.clone(),
                    ok: self.count(Status::Ok),
                    failed: self.count(Status::Failed),
                    skipped: self.count(Status::Skipped),
                    total_ms: self.total_ms,
                    files: self.rows,
                };
                let mut json = serde_json::to_vec_pretty(&report)?;
                json.push(b'\n');
                json
            }
        };
        write_atomic(path, |w| w.write_all(&bytes))
    }

    /// The closing line: counts and speed.
    pub fn summary(&self) -> String {
        let secs = self.total_ms / 1000.0;
        let done = self.count(Status::Ok) + self.count(Status::Failed);
        let shard = match &self.shard {
            Some(s) => format!(" (shard {s} of {} inputs)", self.inputs),
            None => String::new(),
        };
        let files = if self.rows.len() == 1 {
            "file"
        } else {
            "files"
        };
        format!(
            "{} {files}{shard}: {} ok, {} failed, {} skipped in {secs:.1} s ({:.2} files/s)",
            self.rows.len(),
            self.count(Status::Ok),
            self.count(Status::Failed),
            self.count(Status::Skipped),
            done as f64 / secs.max(1e-9)
        )
    }
}

/// The CSV report. Written by hand: a few columns and RFC 4180 quoting
/// are a few lines, not worth a dependency.
fn csv(rows: &[Row]) -> String {
    let mut out = CSV_HEADER.join(",") + "\n";
    for row in rows {
        let fields: Vec<String> = row.csv_fields().iter().map(|f| csv_field(f)).collect();
        out += &fields.join(",");
        out.push('\n');
    }
    out
}

/// A CSV field, quoted (quotes doubled) when it holds a comma, a quote or a
/// line break, so error messages and odd file names survive.
fn csv_field(field: &str) -> String {
    if field.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", field.replace('"', "\"\""))
    } else {
        field.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_quoting() {
        assert_eq!(csv_field("plain.ply"), "plain.ply");
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"x\"\nthen"), "\"say \"\"x\"\"\nthen\"");
    }

    #[test]
    fn report_format_by_extension() {
        assert_eq!(
            ReportFormat::from_path(Path::new("r.CSV")).unwrap(),
            ReportFormat::Csv
        );
        let e = ReportFormat::from_path(Path::new("r.txt")).unwrap_err();
        assert!(e.to_string().contains(".csv or .json"), "{e}");
    }
}
