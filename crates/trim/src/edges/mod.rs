//! Edge reconstruction — the paper's RBS algorithm (section 3): from
//! labelled boundary points to smooth, closed boundary edges.
//!
//! 1. [`cluster`] groups the boundary points into separate boundaries by the
//!    links BPD found between them and thins spurs away;
//! 2. [`order`] turns each group into a closed tour;
//! 3. [`corners`] finds the corners of each loop (section 3.1), which split
//!    it into edges;
//! 4. each edge is smoothed by a spatial low-pass filter (section 3.3);
//! 5. optionally, each smoothed loop is moved out to where the surface
//!    really ends.

pub mod baseline;
pub mod cluster;
pub mod corners;
pub mod offset;
pub mod order;
pub mod smooth;

use crate::cloud::Point3;

/// Options of edge reconstruction.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeOptions {
    /// Move the smoothed edges outward to the estimated physical edge of
    /// the surface (meshtrim's extension; off gives the paper's edges).
    pub offset: bool,
}

impl Default for EdgeOptions {
    fn default() -> Self {
        Self { offset: true }
    }
}

/// One smoothed edge: a polyline between two corners, or a whole loop
/// without corners.
#[derive(Debug, Clone, PartialEq)]
pub struct Edge {
    /// True for a loop without corners (the last point joins the first).
    pub closed: bool,
    /// The smoothed points, in loop order. An open edge starts and ends at
    /// corners, exactly; consecutive edges of a loop share those points.
    pub points: Vec<Point3>,
}

/// One closed boundary: ordered points, corners, and edges.
#[derive(Debug, Clone, PartialEq)]
pub struct Loop {
    /// Indices into the input cloud, in loop order (the loop closes from
    /// the last back to the first).
    pub boundary_points: Vec<u32>,
    /// Positions in `boundary_points` of the corners, ascending.
    pub corners: Vec<usize>,
    /// Edges in loop order: one closed edge when there is no corner,
    /// otherwise one open edge from each corner to the next.
    pub edges: Vec<Edge>,
}

impl Loop {
    /// The corner points (exact input coordinates).
    pub fn corner_points(&self, points: &[Point3]) -> Vec<Point3> {
        self.corners
            .iter()
            .map(|&c| points[self.boundary_points[c] as usize])
            .collect()
    }
}

/// Result of edge reconstruction.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Edges {
    /// The loops, in a deterministic order (by smallest point index).
    pub loops: Vec<Loop>,
    /// Groups of boundary points too small or too thin to close a loop.
    pub dropped_clusters: usize,
    /// Boundary points removed as spurs, strays or isolated points.
    pub thinned_points: usize,
}
