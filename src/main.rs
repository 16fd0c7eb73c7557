//! `meshtrim`: parse the command line, run, report errors as one line.

use std::io::Write;
use std::process::ExitCode;

use clap::Parser;
use meshtrim::cli::{run, Cli};

fn main() -> ExitCode {
    meshtrim::alloc::keep_freed_memory();
    // Usage errors exit with 2 inside `parse`.
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // `{:#}` joins the context chain: "error: FILE: what went wrong".
            // Written, not `eprintln!`ed: a closed stderr pipe must not turn
            // the error into a panic; the exit code still says it failed.
            let _ = writeln!(std::io::stderr(), "error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
