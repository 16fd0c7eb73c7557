//! How the commands hand over their reports: an aligned table or one JSON
//! object on stdout, and optionally the JSON written to a file (atomically).

use std::path::Path;

use anyhow::Result;
use serde::Serialize;
use trim::LoopSource;

use crate::console;
use crate::io::atomic::write_atomic;
use crate::io::edges_out::EdgeFileOptions;

/// How edge reconstruction found the loops, as the reports give it: in
/// JSON by its name (`links`, `scanner_image`, `own_plane`), in the
/// tables in words.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LoopsFrom(pub LoopSource);

impl LoopsFrom {
    /// The JSON name.
    pub fn name(self) -> &'static str {
        self.0.name()
    }

    /// The tables' words, with the direction the own plane was seen along.
    pub fn shown(self) -> String {
        match self.0 {
            LoopSource::Links => "BPD's links".to_string(),
            LoopSource::ScannerImage => "the scanner's image plane".to_string(),
            LoopSource::OwnPlane { normal: [x, y, z] } => {
                format!("the cloud's own plane, seen along {x:.3},{y:.3},{z:.3}")
            }
            LoopSource::MeshBorder => "the mesh's border".to_string(),
        }
    }
}

impl Serialize for LoopsFrom {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name())
    }
}

/// A command's report that can print itself as a two-column table.
pub trait Table {
    /// The report as an aligned two-column table.
    fn table(&self) -> String;
}

/// Writes `report` as pretty JSON to `file` when given, then prints it to
/// stdout: as one JSON object when `json`, otherwise as its table.
pub fn emit<R: Serialize + Table>(report: &R, file: Option<&Path>, json: bool) -> Result<()> {
    if let Some(path) = file {
        let text = serde_json::to_string_pretty(report)?;
        write_atomic(path, |w| w.write_all(text.as_bytes()))?;
    }
    if json {
        console::print_line(&serde_json::to_string(report)?)
    } else {
        console::print(&report.table())
    }
}

/// Adds the report's row on the input's vertex attributes before the
/// times: those written (carried as `how` says) and those the output's
/// format cannot hold; no row when the input had none.
pub fn add_attributes_row(
    rows: &mut Vec<(&str, String)>,
    [written, not_written]: [&[String]; 2],
    how: &str,
) {
    let written = (!written.is_empty()).then(|| format!("{} ({how})", written.join(", ")));
    let not_written = (!not_written.is_empty()).then(|| {
        format!(
            "{} not written: the output's format does not hold them",
            not_written.join(", ")
        )
    });
    let row = match (written, not_written) {
        (None, None) => return,
        (Some(row), None) | (None, Some(row)) => row,
        (Some(written), Some(not_written)) => format!("{written}; {not_written}"),
    };
    let at = rows
        .iter()
        .position(|(label, _)| *label == "read time")
        .unwrap_or(rows.len());
    rows.insert(at, ("vertex attributes", row));
}

/// Lays out (label, value) rows as the commands print them.
pub fn rows(rows: &[(&str, String)]) -> String {
    rows.iter()
        .map(|(label, value)| format!("{label:<20} {value}\n"))
        .collect()
}

/// Refuses, before any work, an unknown mesh output format, a report not
/// named `.json` (any case), and an output or report that would overwrite one of the
/// `inputs`.
pub fn check_outputs(output: &Path, report: Option<&Path>, inputs: &[&Path]) -> Result<()> {
    use anyhow::bail;
    if crate::io::MeshFormat::from_path(output).is_none() {
        bail!(
            "{}: unsupported output format: use .obj, .ply, .stl, .gltf or .glb",
            output.display()
        );
    }
    if let Some(report) = report {
        // Any case, as mesh outputs, -o and batch reports accept.
        let json = report.extension().and_then(|e| e.to_str());
        if !json.is_some_and(|e| e.eq_ignore_ascii_case("json")) {
            bail!("{}: the report is JSON: name it .json", report.display());
        }
    }
    for input in inputs {
        let overwrites = |out: &Path| same_file(out, input);
        if overwrites(output) || report.is_some_and(overwrites) {
            bail!("{}: an output would overwrite this input", input.display());
        }
    }
    Ok(())
}

/// Refuses, before any work, an edges output (`--edges`) of an unknown
/// format or that would overwrite one of the `inputs`.
pub fn check_edges_output(path: &Path, inputs: &[&Path]) -> Result<()> {
    crate::io::edges_out::edges_format(path)?;
    if let Some(input) = inputs.iter().find(|input| same_file(path, input)) {
        anyhow::bail!("{}: an output would overwrite this input", input.display());
    }
    Ok(())
}

/// Writes the smoothed edges of the cloud `points` to `path` (atomically),
/// in the format its extension names: what `meshtrim edges -o` writes.
pub fn write_edges(
    path: &Path,
    points: &[crate::io::Point3],
    detection: &trim::Detection,
    edges: &trim::Edges,
    options: EdgeFileOptions,
) -> Result<()> {
    let data = crate::io::edges_out::EdgeData {
        points,
        boundary: &detection.boundary,
        edges,
        options,
    };
    crate::io::edges_out::write_file(path, data)
}

/// True when `a` and `b` name the same existing file (an output must never
/// overwrite an input).
pub(crate) fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// A file name of a report, or "(in memory)" for the Python package's.
pub(crate) fn shown(name: &Option<String>) -> String {
    name.clone().unwrap_or_else(|| "(in memory)".to_string())
}

/// `x` in plain decimal notation with `digits` significant digits: a
/// distance reads the same way in millimetres and in metres.
pub(crate) fn significant(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor() as i64;
    let decimals = (digits as i64 - 1 - magnitude).max(0) as usize;
    format!("{x:.decimals$}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits_in_plain_notation() {
        assert_eq!(significant(1.0443, 4), "1.044");
        assert_eq!(significant(0.0012345, 3), "0.00123");
        assert_eq!(significant(1234.5, 3), "1234");
        assert_eq!(significant(0.0, 4), "0");
    }

    #[test]
    fn the_report_extension_is_json_in_any_case() {
        let (out, input) = (Path::new("o.ply"), Path::new("Cargo.toml"));
        for name in ["r.json", "r.JSON", "R.Json"] {
            assert!(check_outputs(out, Some(Path::new(name)), &[input]).is_ok());
        }
        for name in ["r.txt", "r", "r.jsonl"] {
            let refused = check_outputs(out, Some(Path::new(name)), &[input]);
            assert!(refused.unwrap_err().to_string().contains("name it .json"));
        }
    }
}
