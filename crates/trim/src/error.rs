//! Error types of the algorithm library: the input cloud's and mesh's, and
//! one per stage that can fail (trimming, the Delaunay path, cleanup;
//! detection's is the cloud's, and edge reconstruction cannot fail).
//!
//! Every variant says what was wrong with the input and, where it applies,
//! which element, in the library's terms (its parameters, not a command
//! line's flags). Internal invariants are `debug_assert!`s, never errors.

use thiserror::Error;

/// Why a point cloud was rejected before boundary detection.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum CloudError {
    /// A coordinate is NaN or infinite. Readers drop or report such points
    /// before they reach the library; this catches what they let through.
    #[error("point {index} has a non-finite coordinate ({x}, {y}, {z})")]
    NonFinite {
        /// Index of the first offending point in the input slice.
        index: usize,
        /// Its coordinates.
        x: f64,
        /// Its coordinates.
        y: f64,
        /// Its coordinates.
        z: f64,
    },
    /// More points than 32-bit indices address.
    #[error("the cloud has {count} points; meshtrim indexes points with 32 bits and handles at most {max}")]
    TooManyPoints {
        /// Points given.
        count: usize,
        /// Largest supported count.
        max: usize,
    },
    /// The neighbourhood size is too small for the tests to mean anything.
    #[error("k = {k} is too small: boundary detection needs k >= {min} (the point itself and at least {} neighbours)", min - 1)]
    KTooSmall {
        /// Requested neighbourhood size.
        k: usize,
        /// Smallest accepted value.
        min: usize,
    },
    /// A scanner view direction that is zero or not finite, or a scanner
    /// position that is not finite.
    #[error("the scanner view {what} ({x}, {y}, {z}) is not usable: {why}")]
    BadView {
        /// "direction" or "position".
        what: &'static str,
        /// Its components.
        x: f64,
        /// Its components.
        y: f64,
        /// Its components.
        z: f64,
        /// What is wrong with it.
        why: &'static str,
    },
    /// Fewer distinct points than one neighbourhood holds.
    #[error("the cloud has {distinct} distinct points ({total} in all), fewer than the neighbourhood size k = {k}; lower k or use a denser cloud")]
    TooFewPoints {
        /// Points after merging exact duplicates.
        distinct: usize,
        /// Points given.
        total: usize,
        /// Requested neighbourhood size.
        k: usize,
    },
    /// The coordinates are too large or too small for the geometry's f64
    /// arithmetic (see `cloud::MAX_COORDINATE`).
    #[error("the coordinates are out of the supported range: the largest |coordinate| is {largest:.2e}, and meshtrim needs it between {min:e} and {max:e} (beyond, squared distances and the triangulation overflow or underflow); change the units")]
    OutOfRange {
        /// The largest |coordinate|.
        largest: f64,
        /// Smallest accepted largest |coordinate| (0 aside).
        min: f64,
        /// Largest accepted |coordinate|.
        max: f64,
    },
    /// The cloud has no points at all.
    #[error("the cloud has no points")]
    NoPoints,
    /// All points coincide or lie on one line: there is no surface.
    #[error("the cloud is degenerate: all {distinct} distinct points lie on {what}, so it has no surface and no boundary")]
    Degenerate {
        /// Number of distinct points.
        distinct: usize,
        /// "one point" or "one line".
        what: &'static str,
    },
    /// The points lie along a line or a curve, up to rounding or noise
    /// well below their spacing: the neighbourhoods have no second
    /// dimension.
    #[error("the cloud has no surface: its {distinct} distinct points lie along a line or a curve (a single line profile?); its neighbourhoods are {thickness:.3} as wide as they are long at the median, where a surface's are 0.1 or more (a scan's 0.7 or more)")]
    NoSurface {
        /// Number of distinct points.
        distinct: usize,
        /// Median neighbourhood width over length.
        thickness: f64,
    },
}

/// Why a mesh was rejected.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MeshError {
    /// A face refers to a vertex that does not exist.
    #[error("face {face} refers to vertex {vertex}, but the mesh has {vertices} vertices")]
    IndexOutOfRange {
        /// Index of the face.
        face: usize,
        /// The bad vertex index.
        vertex: u32,
        /// Number of vertices.
        vertices: usize,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {index} has a non-finite coordinate")]
    NonFinite {
        /// Index of the vertex.
        index: usize,
    },
    /// The coordinates are too large or too small for the geometry's f64
    /// arithmetic and spade (see `cloud::MAX_COORDINATE`).
    #[error("the coordinates are out of the supported range: the largest |coordinate| is {largest:.2e}, and meshtrim needs it between {min:e} and {max:e} (beyond, squared distances and the triangulation overflow or underflow); change the units")]
    OutOfRange {
        /// The largest |coordinate|.
        largest: f64,
        /// Smallest accepted largest |coordinate| (0 aside).
        min: f64,
        /// Largest accepted |coordinate|.
        max: f64,
    },
    /// The mesh has no faces.
    #[error("the mesh has no faces")]
    NoFaces,
    /// Some edges are shared by more than two faces.
    #[error("{edges} edges are shared by more than two faces; the mesh must be edge-manifold (repair it first, e.g. MeshLab's \"Repair non Manifold Edges\")")]
    NonManifold {
        /// How many such edges.
        edges: usize,
    },
    /// Neighbouring faces run their shared edge the same way.
    #[error("{edges} edges are run the same way by both their faces; the faces must be consistently oriented (re-orient them first, e.g. MeshLab's \"Re-Orient all faces coherently\")")]
    Misoriented {
        /// How many such edges.
        edges: usize,
    },
}

/// Why trimming failed.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TrimError {
    /// The mesh is not one trimming can cut.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// Nothing of the mesh lies where the cloud is; where the cloud lies
    /// against the mesh says what to check.
    #[error("no part of the mesh is supported by the cloud: {0}")]
    Unsupported(Placement),
}

/// Where a cloud lies against a mesh: what a trim that found nothing of
/// the mesh supported tells the user to check. A cloud in other units than
/// its mesh (a scanner's E57 file holds metres, the STL made from it often
/// millimetres) or in another frame is the usual cause.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Placement {
    /// Scaled by a unit ratio, the cloud lies on the mesh: the cloud's
    /// coordinates times `factor` are the mesh's units.
    Units {
        /// The factor, a ratio of two units (1000, 1/1000, 25.4, …).
        factor: f64,
        /// The two units, the cloud's first.
        units: (&'static str, &'static str),
    },
    /// The cloud's bounding-box diagonal is `ratio` times the mesh's, more
    /// than three times larger or smaller, and no unit ratio explains it.
    Scaled {
        /// Cloud diagonal over mesh diagonal.
        ratio: f64,
    },
    /// Of similar size, but the bounding boxes do not meet.
    Apart {
        /// Distance between the boxes' centres.
        distance: f64,
        /// The mesh's bounding-box diagonal.
        mesh_diagonal: f64,
    },
    /// The bounding boxes overlap.
    Overlapping,
}

/// A ratio to four decimals without trailing zeros, a fraction below 1
/// written 1/x: 1000, 1/1000, 39.3701.
fn ratio_text(ratio: f64) -> String {
    let (r, inverse) = if ratio >= 1.0 {
        (ratio, false)
    } else {
        (1.0 / ratio, true)
    };
    let digits = format!("{r:.4}");
    let text = digits.trim_end_matches('0').trim_end_matches('.');
    if inverse {
        format!("1/{text}")
    } else {
        text.to_string()
    }
}

impl std::fmt::Display for Placement {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Placement::Units { factor, units } => {
                let factor = ratio_text(factor);
                write!(
                    f,
                    "the cloud looks to be in {} and the mesh in {} (scaled by {factor}, the \
                     cloud lies on the mesh): scale the cloud by {factor}",
                    units.0, units.1
                )
            }
            Placement::Scaled { ratio } => {
                let (factor, size) = if ratio < 1.0 {
                    (1.0 / ratio, "smaller")
                } else {
                    (ratio, "larger")
                };
                write!(
                    f,
                    "the cloud's bounding box is {factor:.3} times {size} than the mesh's: is \
                     the cloud the one the mesh was reconstructed from, in the same units?"
                )
            }
            Placement::Apart {
                distance,
                mesh_diagonal,
            } => write!(
                f,
                "the cloud's bounding box does not meet the mesh's (their centres {distance:.4} \
                 apart, the mesh's diagonal {mesh_diagonal:.4}): give the cloud in the mesh's frame"
            ),
            Placement::Overlapping => f.write_str(
                "is the cloud the one the mesh was reconstructed from, in the same units and pose?",
            ),
        }
    }
}

/// Why the Delaunay path could not mesh a cloud. All but [`Self::Input`]
/// say the cloud is no height field over its best-fit plane, where screened
/// Poisson and [`trim_mesh`](crate::trim_mesh) still work.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum DelaunayError {
    /// The cloud's coordinates, or too few points to triangulate.
    #[error(transparent)]
    Input(#[from] MeshError),
    /// The cloud is not a height field over the plane it is projected
    /// onto: the Delaunay path, which triangulates in that projection,
    /// cannot mesh it.
    #[error("the surface folds over {onto} ({percent:.1}% of the {what} on edge or facing away from it, at most {limit}% allowed), so a mesh built in that projection would be broken; mesh it with screened Poisson and trim that mesh instead")]
    NotAHeightField {
        /// The plane: "its best-fit plane" or "the scanner's image".
        onto: &'static str,
        /// Share of the offending elements, in percent.
        percent: f64,
        /// What was measured: "local normals" or "triangles' area".
        what: &'static str,
        /// Largest accepted share, in percent.
        limit: f64,
    },
    /// With a view from a position, a point lies beside or behind the
    /// scanner: no camera image holds it.
    #[error("point {index} lies beside or behind the scanner's position (more than 84° off the camera's axis), so no camera image holds the cloud; check the view's position")]
    NotInView {
        /// Its index in the cloud.
        index: usize,
    },
    /// A smoothed loop crosses itself in the projection, and neither
    /// removing the twisted stretch nor splitting it at the crossing
    /// resolves it.
    #[error("smoothed loop {index} crosses itself in the projection onto {onto} (repairing it would drop {dropped} of its {vertices} vertices); the surface may fold over its plane there: mesh it with screened Poisson and trim that mesh instead")]
    LoopNotSimple {
        /// The plane: "the best-fit plane" or "the scanner's image".
        onto: &'static str,
        /// Index of the loop in the edges.
        index: usize,
        /// Its vertices.
        vertices: usize,
        /// Vertices a repair would have dropped.
        dropped: usize,
    },
    /// Two smoothed loops touch (or run along each other) in the
    /// projection, where no split at a crossing resolves them.
    #[error("smoothed loops {a} and {b} cross or touch in the projection onto {onto}; the surface may fold over its plane there: mesh it with screened Poisson and trim that mesh instead")]
    LoopsCross {
        /// The plane: "the best-fit plane" or "the scanner's image".
        onto: &'static str,
        /// Index of one loop in the edges.
        a: usize,
        /// Index of the other.
        b: usize,
    },
}

/// Why cleanup failed.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum CleanError {
    /// The mesh is not one cleanup can work on.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The local resolutions given do not match the vertices.
    #[error("{values} local resolutions given for {vertices} vertices")]
    ResolutionLength {
        /// Values given.
        values: usize,
        /// Vertices of the mesh.
        vertices: usize,
    },
    /// Every face of the mesh is one the cleanup's repairs remove (pairs of
    /// one triangle wound both ways, which enclose no volume; faces of no
    /// area), so nothing would be written.
    #[error("no face would be left: the repairs remove all {faces} faces (triangles written once each way, pockets of no volume, or faces of no area)")]
    NothingLeft {
        /// Faces of the mesh.
        faces: usize,
    },
    /// The bound on how far the border may move is not a positive number.
    #[error("max_deviation must be a positive finite distance, got {0}")]
    MaxDeviation(f64),
    /// The width of the holes to close is not a positive number.
    #[error("fill_holes must be a positive finite width, got {0}")]
    FillHoles(f64),
}
