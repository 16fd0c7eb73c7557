//! # meshtrim's test tooling
//!
//! Not shipped: a dev-dependency of the library's and the binary's tests,
//! and the home of the examples that tabulate measured results. Everything
//! here is deterministic from a seed and does no I/O.
//!
//! - [`synthetic`]: clouds sampled on known surfaces over known regions,
//!   with their true boundaries; [`synthetic::jagged`] turns them into
//!   meshes with jagged borders, as triangulated scans have.
//! - [`evaluate`]: boundary detections scored against the truth
//!   (precision, recall, the ideal first layer).
//! - [`edge_metrics`]: smoothed edges scored against the true border.
//! - [`baseline`]: simpler edge smoothers the RBS filter is compared with.
//! - [`SplitMix64`]: the seeded generator all of them use, so the same
//!   seed gives the same cloud on every platform.

pub mod baseline;
pub mod edge_metrics;
pub mod evaluate;
pub mod synthetic;
pub mod vec3;

pub use synthetic::SplitMix64;
