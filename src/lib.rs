//! # meshtrim, the command-line side
//!
//! Everything that touches files or the terminal lives here; the algorithms
//! live in the `trim` library crate, which does no I/O.
//!
//! - [`io`] reads point clouds and meshes (PLY, PCD, OBJ, XYZ/CSV text) and
//!   writes results atomically.
//! - [`cli`] defines the command line and runs its subcommands.
//! - [`detect`] is the `meshtrim detect` subcommand.
//! - [`edges`] is the `meshtrim edges` subcommand.
//! - [`clean_cmd`] is `meshtrim clean`.
//! - [`batch`] is `meshtrim batch`: many meshes at once.
//! - [`console`] prints summaries to stdout; a closed pipe is not an error.
//! - [`alloc`] tunes the memory allocator for repeated large buffers.

pub mod alloc;
pub mod batch;
pub mod clean_cmd;
pub mod cli;
pub mod console;
pub mod detect;
pub mod edges;
pub mod io;
pub mod mesh_cmd;
pub mod report;
pub mod trim;
