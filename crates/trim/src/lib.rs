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
//!
//! ## Vector kernels
//!
//! The per-neighbourhood kernels of detection (k-NN selection, plane fit
//! and projection, sampling vectors, β, both tests) carry
//! `#[multiversion(targets("x86_64+avx2"))]`: each is compiled twice, for
//! baseline x86-64 and for AVX2, and the first call picks the variant the
//! CPU runs. The binary still runs on any x86-64 and uses 4-wide vectors
//! where it can. Both variants give the same bits: they use only IEEE
//! operations that round exactly (add, multiply, divide, square root,
//! comparisons), and Rust never fuses a multiply and an add on its own, so
//! no FMA is emitted (checked: the detect CSVs of the 17 real scans in
//! `../shared/data` are byte-identical to a baseline-only build's).

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
pub mod hash;
pub mod mesh;
pub mod morton;
pub mod neighbours;
pub mod resolution;
pub mod synthetic;
pub mod trimming;

pub use bpd::{detect_boundary, BpdOptions, Detection};
pub use cloud::Point3;
pub use error::{CloudError, MeshError};
