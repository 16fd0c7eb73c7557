//! How the commands hand over their reports: an aligned table or one JSON
//! object on stdout, and optionally the JSON written to a file (atomically).

use std::path::Path;

use anyhow::Result;
use serde::Serialize;

use crate::io::atomic::write_atomic;

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
        println!("{}", serde_json::to_string(report)?);
    } else {
        print!("{}", report.table());
    }
    Ok(())
}

/// Lays out (label, value) rows as the commands print them.
pub fn rows(rows: &[(&str, String)]) -> String {
    rows.iter()
        .map(|(label, value)| format!("{label:<20} {value}\n"))
        .collect()
}
