//! `meshtrim`: parse the command line, run the command, report errors as
//! one line. The only place that knows every command.

use std::io::Write;
use std::process::ExitCode;

use anyhow::Result;
use clap::Parser;
use meshtrim::cli::{Cli, Command};
use meshtrim::commands::{batch, clean, detect, edges, mesh, trim};

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
            let message = meshtrim::stages::in_cli_words(&format!("{e:#}"));
            let _ = writeln!(std::io::stderr(), "error: {message}");
            ExitCode::FAILURE
        }
    }
}

/// Runs the chosen command.
fn run(cli: Cli) -> Result<()> {
    match (cli.command, cli.trim) {
        (Some(Command::Detect(args)), _) => detect::run(&args),
        (Some(Command::Edges(args)), _) => edges::run(&args),
        (Some(Command::Trim(args)), _) | (None, Some(args)) => trim::run(&args),
        (Some(Command::Mesh(args)), _) => mesh::run(&args),
        (Some(Command::Clean(args)), _) => clean::run(&args),
        (Some(Command::Batch(args)), _) => batch::run(&args),
        (None, None) => {
            anyhow::bail!("nothing to do: give MESH CLOUD OUT, or a subcommand (see --help)")
        }
    }
}
