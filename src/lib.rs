//! # meshtrim, the command-line side
//!
//! Everything that touches files or the terminal lives here; the algorithms
//! live in the `trim` library crate, which does no I/O.
//!
//! - [`io`] reads point clouds and meshes (PLY, PCD, OBJ, STL, glTF,
//!   XYZ/CSV text) and writes results atomically.
//! - [`commands`]: one module per command (`detect`, `edges`, `trim`,
//!   `mesh`, `clean`, `batch`), each with its own arguments and `run`.
//! - [`cli`] assembles the commands' arguments into the top-level parser;
//!   only `main` uses it.
//! - `stages` turns the shared options into the library's and runs the
//!   first stages (read, detect) for every command; `report` and
//!   `console` print and write reports.
//! - [`alloc`] tunes the memory allocator for repeated large buffers.

pub mod alloc;
pub mod cli;
pub mod commands;
mod console;
pub mod io;
mod report;
pub mod stages;
