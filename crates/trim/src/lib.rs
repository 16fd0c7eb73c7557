//! # meshtrim's algorithm library
//!
//! Pure functions over points and meshes, no file I/O and no printing. The
//! pipeline follows Mineo, Pierce and Summan (2019), "Novel algorithms for 3D
//! surface point cloud boundary detection and edge reconstruction":
//!
//! 1. [`cloud`] validates the input and merges exact duplicates.
//! 2. [`neighbours`] finds the k nearest neighbours of every point (section 2).
//! 3. [`frame`] fits the best plane of each neighbourhood (PCA) and projects
//!    it to 2D; [`anisotropy`] undoes anisotropic sampling (meshtrim's
//!    extension); [`resolution`] gives the local resolution β_i = μ_i + 2σ_i.
//! 4. [`bpd`] labels boundary points: the empty-circle test, then the
//!    surrounding-path test (section 2, eqs. 1–5).
//!
//! Edge reconstruction (section 3) and trimming build on these.

pub mod anisotropy;
pub mod bpd;
pub mod clean;
pub mod closest_face;
pub mod cloud;
pub mod delaunay;
pub mod edge_metrics;
pub mod edges;
pub mod error;
pub mod evaluate;
pub mod frame;
pub mod mesh;
pub mod neighbours;
pub mod resolution;
pub mod synthetic;
pub mod trimming;

pub use bpd::{detect_boundary, BpdOptions, Detection};
pub use cloud::Point3;
pub use error::{CloudError, MeshError};
