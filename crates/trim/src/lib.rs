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
//! ## Example
//!
//! The scan of a plate with a square hole, as a range scanner gives it: a
//! jittered grid of points, triangulated cell by cell. Its border is
//! detected and smoothed, the cloud meshed inside the smoothed edges, a
//! larger mesh (standing in for a screened-Poisson envelope) trimmed
//! along them, and the scan's own jagged border cleaned.
//!
//! ```
//! use trim::{
//!     clean_mesh, delaunay_mesh, detect_boundary, reconstruct_edges, trim_mesh, BpdOptions,
//!     CleanOptions, DelaunayOptions, EdgeOptions, LocalResolution, Mesh, Point3, TrimOptions,
//! };
//!
//! /// A grid of `columns` × `rows` points `step` apart from `origin`, each
//! /// moved by up to `jitter` in x and y, triangulated cell by cell; nodes
//! /// for which `keep` is false are left out with their cells.
//! fn grid(
//!     (columns, rows): (u32, u32),
//!     origin: Point3,
//!     step: f64,
//!     jitter: f64,
//!     keep: impl Fn(f64, f64) -> bool,
//! ) -> Mesh {
//!     let wobble = |a: u32, b: u32| ((a * 7919 + b * 104_729) % 1000) as f64 / 1000.0 - 0.5;
//!     let mut mesh = Mesh { vertices: Vec::new(), faces: Vec::new() };
//!     let mut index = vec![None; (columns * rows) as usize];
//!     for i in 0..columns {
//!         for j in 0..rows {
//!             let x = origin[0] + step * i as f64 + jitter * wobble(i, j);
//!             let y = origin[1] + step * j as f64 + jitter * wobble(j, i);
//!             if keep(x, y) {
//!                 index[(i * rows + j) as usize] = Some(mesh.vertices.len() as u32);
//!                 mesh.vertices.push([x, y, origin[2]]);
//!             }
//!         }
//!     }
//!     for i in 0..columns - 1 {
//!         for j in 0..rows - 1 {
//!             let at = |a: u32, b: u32| index[(a * rows + b) as usize];
//!             let corners = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
//!             if let [Some(a), Some(b), Some(c), Some(d)] = corners {
//!                 mesh.faces.extend([[a, b, c], [a, c, d]]);
//!             }
//!         }
//!     }
//!     mesh
//! }
//!
//! // The scan: 60 × 40 mm, 1 mm apart, a 10 mm hole in the middle.
//! let outside_hole = |x: f64, y: f64| !((25.0..35.0).contains(&x) && (15.0..25.0).contains(&y));
//! let scan = grid((60, 40), [0.0; 3], 1.0, 0.3, outside_hole);
//! let cloud = &scan.vertices;
//!
//! // Boundary point detection (BPD), then the smoothed edges (RBS): the
//! // outer border and the hole's.
//! let detection = detect_boundary(cloud, &BpdOptions::default())?;
//! let edges = reconstruct_edges(cloud, &detection, &EdgeOptions::default());
//! assert_eq!(edges.loops.len(), 2);
//!
//! // The Delaunay path: the cloud meshed inside its smoothed edges.
//! let meshed = delaunay_mesh(cloud, &detection, &edges, &DelaunayOptions::default())?;
//! assert!(!meshed.faces.is_empty());
//!
//! // Trimming: a mesh that overhangs the scan and covers its hole, as a
//! // Poisson envelope does, cut along the smoothed edges.
//! let envelope = grid((36, 26), [-5.0, -5.0, 0.0], 2.0, 0.0, |_, _| true);
//! let options = TrimOptions::default();
//! let (trimmed, report) = trim_mesh(&envelope, cloud, &detection, &edges, &options)?;
//! assert!(report.faces_split > 0 && trimmed.faces.len() < envelope.faces.len());
//!
//! // Cleanup: the scan's jagged border and hole replaced by their smoothed
//! // edges; β is the local resolution of the scan's own vertices.
//! let beta = LocalResolution::new(&scan.vertices, &BpdOptions::default())?;
//! let (cleaned, report) = clean_mesh(&scan, &beta, &CleanOptions::default())?;
//! assert_eq!(report.loops_smoothed, 2);
//! assert!(!cleaned.faces.is_empty());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
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
pub use edges::{mesh_border_edges, reconstruct_edges, Edge, EdgeOptions, Edges, Loop, LoopSource};
pub use error::{CleanError, CloudError, DelaunayError, MeshError, Placement, TrimError};
pub use frame::{fit_plane, Frame};
pub use geom::rotation_from_quaternion;
pub use mesh::fill::{HolesFilled, MAX_HOLE_VERTICES};
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
