//! Trimming a reconstructed mesh along the cloud's smoothed boundary —
//! meshtrim's third stage, the use the paper builds its edges for (its
//! introduction and section 4: "the reconstructed boundary edges can be
//! used to trim the Poisson mesh"; how is "out of the scope of this
//! paper", so the method here is meshtrim's).
//!
//! A screened-Poisson mesh wraps an open scan in a closed envelope that
//! bulges past the borders and caps the holes; a Delaunay mesh has jagged
//! borders. The smoothed loops of [`crate::edges`] say where the part ends.
//! The mesh is cut along them and only what the cloud supports is kept:
//!
//! 1. **A signed field whose zero set is the boundary.** Each smoothed loop
//!    is a wall standing on the surface: at every point q of a loop, the
//!    outward direction o(q) lies in the surface's tangent plane (from the
//!    cloud's local plane fit), perpendicular to the loop, away from the
//!    cloud. A mesh vertex v gets f(v) = (v − q)·o(q) for its nearest loop
//!    point q (at a loop vertex, o is the mean of the two segments'
//!    directions; along a segment it is interpolated between its ends', so
//!    f is continuous). f < 0 inside the part, > 0 beyond the border and over
//!    holes. Cutting along the zero level of a field, rather than tracing
//!    the polyline across faces, cannot leave a crack or a dangling piece:
//!    every mesh edge is cut at most once, by one rule, and the cut is as
//!    smooth as the field, which is as smooth as the FFT edge.
//! 2. **Snapping.** A vertex with |f| below [`TrimOptions::snap`] local spacings is
//!    moved onto the cut (f := 0): otherwise the cut would pass a hair's
//!    breadth from it and leave a sliver triangle.
//! 3. **The cut.** Faces with all f ≤ 0 lie inside, faces with all f ≥ 0
//!    beyond the walls, and faces with both signs are split: each crossed
//!    edge gets one new vertex at the linear zero (shared by all faces of
//!    that edge, so no crack opens), and each side's part (a triangle or a
//!    quadrilateral) is triangulated in the face's own vertex order, which
//!    keeps the input orientation.
//! 4. **The cloud's reach.** Where a border did not close into a loop (a
//!    ragged depth-camera border, a loop tour that broke), no wall stands
//!    between the part and the envelope beyond it, and both would fall into
//!    one piece that the cloud supports. So the cut mesh is cut a second
//!    time, the same way, along g(v) = d(v) − [`TrimOptions::reach`]·β: d the distance
//!    to the nearest cloud point, β that point's local resolution. What
//!    lies beyond (g > 0) is out of every cloud point's reach and goes. By
//!    BPD's own rule no point inside the part is that far from the cloud
//!    (an empty circle of radius β would have made its neighbours
//!    boundary), and the smoothed cut lies half a row beyond the boundary
//!    points, so where the loops close this cut rarely touches anything.
//!    Spots out of reach smaller than a disc of radius β stay: the cloud
//!    does not resolve them, and on closed scans the Poisson surface rises
//!    that far out of reach in small domes over crevices.
//! 5. **Keeping what the cloud supports.** The faces of each side fall into
//!    connected pieces (pieces never cross the walls): inside, the part and
//!    on a closed envelope pieces of its far side; beyond, the envelope
//!    past the border, the caps over holes. Each cloud point is projected
//!    on the nearest face of the cut mesh (parry3d, f64); a piece is kept
//!    when at least half as many points project onto it as its area holds
//!    at the cloud's local density (area per point √3/2·β², a hexagonal
//!    packing at spacing β), whichever side it is on. The far side of an
//!    envelope and the caps never receive the points (the scanned surface
//!    is closer), so they go, however close they come. A piece beyond the
//!    walls that the cloud covers is surface: on a closed scan the walls of
//!    small loops (holes, sparse spots) sign vertices far from them too,
//!    and dropping every piece beyond them would take about 30 % of the
//!    zippered bunny with them.
//! 6. **No new pinch.** Where the faces between two kept pieces went, the
//!    pieces may touch at one vertex, which the input did not pinch (a
//!    range grid's slits and skirts leave such pieces on real scans); the
//!    smaller piece's faces round that vertex go
//!    ([`crate::mesh::pinches`]). Then zero-area and repeated faces are
//!    repaired and unused vertices removed.

mod cut;
mod field;
mod placement;
mod support;

use cut::*;
use field::*;
use placement::placement;
use support::*;

use crate::hash::HashMap;

use crate::mesh::pinches::open_new_pinches;
use crate::mesh::repair::{repair_degenerate_faces, FaceRepair};
use crate::spatial::PointTree;
use rayon::prelude::*;

use crate::bpd::Detection;
use crate::edges::offset::{edge_sides, outward};
use crate::edges::Edges;
use crate::error::TrimError;
use crate::geom::UnionFind;
use crate::geom::{dist2, dot, lerp, norm2, sub, Point3};
use crate::mesh::{sorted_edges_of, Mesh};
use crate::spatial::closest_face::{FaceIndex, Scratch};
use crate::spatial::morton::query_in_spatial_order;
use crate::spatial::neighbours::NeighbourIndex;

/// Options of trimming. The defaults are the measured ones of
/// docs/trimming.md; each is a multiple of the local resolution β or a
/// share, so none depends on the cloud's units.
#[derive(Debug, Clone, PartialEq)]
pub struct TrimOptions {
    /// Vertices closer to the cut than this many local spacings are moved
    /// onto it, so that the cut passes through them instead of leaving a
    /// sliver beside them (step 2 of the module doc). Default 0.1.
    pub snap: f64,
    /// The kept surface ends this many local resolutions β from the cloud
    /// (step 4): as far as a cloud point's projection reaches in the
    /// support test (step 5), beyond which no point can support a face.
    /// On the Poisson trims of the real scans whose loops close, the kept
    /// surface lies within 2β of the cloud except for 0.02–0.1 % of its
    /// area, along the smoothed cut. Default 2.
    pub reach: f64,
    /// A piece of the cut mesh is kept when the cloud points projecting
    /// onto it reach this share of what its area holds (step 5). Default
    /// 0.5.
    pub support: f64,
}

impl Default for TrimOptions {
    fn default() -> Self {
        Self {
            snap: 0.1,
            reach: 2.0,
            support: 0.5,
        }
    }
}

/// What trimming did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrimReport {
    /// Faces of the input mesh.
    pub faces_in: usize,
    /// Faces of the output.
    pub faces_out: usize,
    /// Input faces crossed by the boundary and split.
    pub faces_split: usize,
    /// Input faces dropped whole (beyond the border, over holes, or in
    /// unsupported pieces).
    pub faces_removed: usize,
    /// Pieces of the cut mesh dropped for lack of cloud support (on
    /// either side of the walls).
    pub pieces_dropped: usize,
    /// Pieces beyond the walls kept because the cloud supports them (on a
    /// closed scan, surface behind the walls of small loops).
    pub pieces_restored: usize,
    /// Vertices snapped onto the cut.
    pub vertices_snapped: usize,
    /// Parts of faces dropped because no cloud point lies within reach of
    /// them (see [`TrimOptions::reach`]): envelope that no wall cuts off, where a
    /// border did not close into a loop.
    pub faces_out_of_reach: usize,
    /// Kept faces dropped where the kept surface would pinch to a vertex
    /// the input did not pinch (two kept pieces touching at one vertex
    /// once the faces between them went): the faces of the smaller
    /// piece's fan there.
    pub pinch_faces_dropped: usize,
    /// Area of the input mesh.
    pub area_in: f64,
    /// Area of the output mesh.
    pub area_out: f64,
    /// For each smoothed loop: mean and largest distance from the output
    /// border (its vertices) to the loop, and how many border vertices
    /// were measured.
    pub loops: Vec<LoopFit>,
    /// Zero-area and repeated faces of the output repaired (screened
    /// Poisson leaves a few tiny triangles); none is written.
    pub repaired: FaceRepair,
}

/// How closely the output border follows one smoothed loop.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LoopFit {
    /// Mean distance from the border vertices nearest this loop to it.
    pub mean: f64,
    /// Largest such distance.
    pub max: f64,
    /// Border vertices measured.
    pub count: usize,
}

/// Cuts `mesh` along the smoothed loops of `edges` (reconstructed from
/// `cloud` with `detection`) and keeps what the cloud supports.
pub fn trim_mesh(
    mesh: &Mesh,
    cloud: &[Point3],
    detection: &Detection,
    edges: &Edges,
    options: &TrimOptions,
) -> Result<(Mesh, TrimReport), TrimError> {
    mesh.validate()?;
    let walls = Walls::new(cloud, detection, edges);
    let to_walls: Vec<(f64, f64)> = mesh
        .vertices
        .par_iter()
        .map(|&v| walls.signed_distance(v))
        .collect();
    let (field, mut snapped_count) = snapped_field(&to_walls, options.snap);
    // The cut runs on one thread; the cloud's tree for the second cut is
    // built on the other meanwhile.
    let (first_cut, reach) = rayon::join(
        || cut_both_sides(mesh, &field),
        || Reach::new(cloud, &detection.beta, options.reach),
    );
    let faces_split = first_cut.split;
    let (
        Cut {
            mesh: cut,
            origin,
            beyond,
            ..
        },
        out_of_reach,
    ) = within_reach(first_cut, &reach, options.snap);
    snapped_count += out_of_reach.snapped;
    let support = supported_faces(&cut, &beyond, cloud, &detection.beta, options.support)
        .ok_or_else(|| {
            let placement = placement(mesh, cloud, &detection.beta, options.reach);
            TrimError::Unsupported(placement)
        })?;
    let mut keep = support.keep;
    let pinch_faces_dropped = open_new_pinches(mesh, &cut, &mut keep);
    let mut survived = vec![false; mesh.faces.len()];
    for (&o, &k) in origin.iter().zip(&keep) {
        survived[o as usize] |= k;
    }
    let mut kept = cut;
    kept.retain_faces(&keep);
    let repaired = repair_degenerate_faces(&mut kept);
    kept.remove_unused_vertices();
    let report = TrimReport {
        faces_in: mesh.faces.len(),
        faces_out: kept.faces.len(),
        faces_split,
        faces_removed: survived.iter().filter(|&&s| !s).count(),
        pieces_dropped: support.dropped,
        pieces_restored: support.restored,
        vertices_snapped: snapped_count,
        faces_out_of_reach: out_of_reach.faces,
        pinch_faces_dropped,
        area_in: mesh.area(),
        area_out: kept.area(),
        loops: walls.border_fit(&kept),
        repaired,
    };
    Ok((kept, report))
}

#[cfg(test)]
mod tests;
