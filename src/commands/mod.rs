//! The commands, one module each: its arguments (`Args`) and its `run`.
//! They share the argument groups of [`args`] and the first stages of
//! `crate::stages`; none knows the others but `batch`, which runs `trim`
//! and `clean` on many files.

pub mod args;
pub mod batch;
pub mod clean;
pub mod detect;
pub mod edges;
pub mod mesh;
pub mod trim;
