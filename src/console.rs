//! Standard output for summaries, reports and batch lines.
//!
//! `println!` panics when the reader of a pipe has gone away
//! (`meshtrim … --json | head -c 0`, a viewer closed early). The files a
//! command writes are its product and are complete by then; only the
//! summary has nowhere to go. So a broken pipe is not an error here: the
//! text is dropped and the command finishes (exit 0 if the job succeeded).
//! Any other failure to write (a full disk behind a redirection) is an
//! error naming standard output.

use std::io::{self, Write};

use anyhow::{Context, Result};

/// Writes `text` to standard output (see the module doc for a broken pipe).
pub fn print(text: &str) -> Result<()> {
    let mut out = io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() == io::ErrorKind::BrokenPipe => Ok(()),
        written => written.context("writing to standard output"),
    }
}

/// [`print()`] with a line break after `line`.
pub fn print_line(line: &str) -> Result<()> {
    print(&format!("{line}\n"))
}
