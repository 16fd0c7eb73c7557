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

/// A caught panic's message, when it has one: what `batch` reports for a
/// file, and what the Python package and the C API return as an internal
/// error rather than unwinding into their callers.
pub fn panic_text(panic: &(dyn std::any::Any + Send)) -> String {
    panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic without a message".to_string())
}
