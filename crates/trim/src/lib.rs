//! # meshtrim's algorithm library
//!
//! Pure functions over points and meshes: no file I/O, no printing. The
//! pipeline follows Mineo, Pierce and Summan (2019), "Novel algorithms for 3D
//! surface point cloud boundary detection and edge reconstruction":
//!
//! ```text
//! cloud ─→ neighbours ─→ BPD ─→ edges ─┬─→ trim      (a reconstructed mesh cut along the edges)
//!                                      ├─→ Delaunay  (a mesh of the cloud itself, bounded by them)
//!                                      └─→ clean     (a scan's own jagged border replaced by them)
//! ```
//!
//! 1. **The cloud** is validated (finite, in range, not on a point or a
//!    line) and exact duplicates are merged.
//! 2. **Neighbours**: the k nearest neighbours of every point, in a
//!    Morton-ordered k-d tree (section 2). [`NeighbourIndex`] gives them.
//! 3. **Boundary point detection** ([`detect_boundary`], section 2, eqs.
//!    1–5): each neighbourhood's best-fit plane ([`fit_plane`]), the local
//!    resolution β_i = μ_i + 2σ_i, meshtrim's anisotropy map (which undoes
//!    anisotropic sampling), then the empty-circle test and the
//!    surrounding-path test. No threshold to tune. The result is a
//!    [`Detection`]: labels, β, and the boundary links.
//! 4. **Edge reconstruction** ([`reconstruct_edges`], section 3, the
//!    paper's RBS): boundary points grouped into closed [`Loop`]s, ordered,
//!    split at corners, each [`Edge`] smoothed by a spatial-FFT low-pass
//!    filter whose cut-off follows β (eqs. 6–8), then moved out to the
//!    estimated physical edge (meshtrim's extension).
//! 5. Then one of three ways to a mesh with a smooth border:
//!    - **Trimming** ([`trim_mesh`]): a mesh reconstructed from the cloud
//!      (screened Poisson) is cut exactly along the smoothed loops, and what
//!      the cloud does not support is removed.
//!    - **The Delaunay path** ([`delaunay_mesh`]): a constrained Delaunay
//!      triangulation of the cloud in its best-fit plane, bounded by the
//!      smoothed loops (spade).
//!    - **Cleanup** ([`clean_mesh`]): a triangulated scan, whose own
//!      vertices are the cloud, gets its jagged border replaced by the
//!      smoothed one, the gap filled with new faces on the surface.
//!
//! Every stage has an options struct whose `Default` is the paper's method
//! with meshtrim's extensions, and returns a report of what it did. Errors
//! say what is wrong with the input in the library's terms (parameters,
//! not command-line flags).
//!
//! ## Vector kernels
//!
//! The per-neighbourhood kernels of detection (k-NN selection, plane fit
//! and projection, sampling vectors, β, both tests) carry
//! `#[multiversion(targets("x86_64+avx2"))]`: each is compiled twice, for
//! baseline x86-64 and for AVX2, and the first call picks the variant the
//! CPU runs. Both variants give the same bits: they use only IEEE
//! operations that round exactly (add, multiply, divide, square root,
//! comparisons), and Rust never fuses a multiply and an add on its own, so
//! no FMA is emitted.

mod anisotropy;
mod attributes;
mod bpd;
mod bspline;
mod clean;
mod cloud;
mod delaunay;
mod deviation;
mod edges;
mod error;
mod frame;
mod geom;
mod hash;
mod mesh;
mod planar;
mod resolution;
mod spatial;

mod trimming;

#[doc(hidden)]
pub use attributes::vertex_sources_reference;
pub use attributes::{
    carry, carry_nearest_corner, carry_normals, carry_values, face_sources, split_sources,
    vertex_sources, SplitSources, VertexSource,
};
/// The plain detector the fast one is tested against (same labels).
#[doc(hidden)]
pub use bpd::detect_boundary_reference;
pub use bpd::{
    detect_boundary, detect_boundary_with_progress, local_resolution, BpdOptions, Decision,
    Detection, LocalResolution, View,
};
pub use bspline::{interpolate as interpolate_bspline, BSpline};
pub use clean::{clean_mesh, CleanOptions, CleanReport, LeftLoops, LeftReason, SEEN_FROM_ONE_SIDE};
pub use cloud::Point3;
pub use delaunay::{delaunay_mesh, delaunay_mesh_with_report, DelaunayOptions, DelaunayReport};
/// The plain deviation the fast one is tested against (same distances).
#[doc(hidden)]
pub use deviation::surface_deviation_reference;
pub use deviation::{surface_deviation, Deviation};
pub use edges::{reconstruct_edges, Edge, EdgeOptions, Edges, Loop, LoopSource};
pub use error::{CleanError, CloudError, DelaunayError, MeshError, Placement, TrimError};
pub use frame::{fit_plane, Frame};
pub use geom::rotation_from_quaternion;
pub use mesh::manifold::ManifoldRepair;
pub use mesh::repair::{FaceRepair, MIN_RELATIVE_AREA};
pub use mesh::seams::{stitch_seams, Stitched};
pub use mesh::{check_vertex_range, Mesh};
pub use resolution::PointResolution;
pub use spatial::neighbours::NeighbourIndex;
pub use trimming::{trim_mesh, LoopFit, TrimOptions, TrimReport};

/// Steps of detection and edge reconstruction the test kit looks into
/// (which mechanism flips a label under noise; which steps of a tour jump
/// across the surface, by the rule that cuts tours; the measures that
/// decide whether a cloud is traced in its own plane). Not part of the API:
/// they change with the algorithm.
#[doc(hidden)]
pub mod internals {
    pub use crate::anisotropy::own_sampling_vectors;
    pub use crate::edges::share_left_by_tours;
    pub use crate::edges::split::supported as step_is_supported;
    pub use crate::edges::trace::own_plane_layered_share;
    pub use crate::frame::project;
}
