//! The Delaunay path: a mesh built from the cloud itself, bounded by the
//! smoothed loops. The paper's introduction names Delaunay triangulation
//! as one of the two kinds of mesh its edges are for and leaves the method
//! open; this one is meshtrim's.
//!
//! 1. **Projection.** The whole cloud is projected onto its best-fit plane
//!    (PCA of all points, [`fit_plane`]), in the frame's (u, v) axes
//!    relative to the first point, which keeps precision for clouds far
//!    from the origin. Since u × v = n, counter-clockwise in (u, v) is
//!    counter-clockwise seen from the side the plane normal n points to.
//!    *With a view* (the detection's [`View`]) the projection is the
//!    scanner's image instead: a range scan seen from one place is a
//!    height field over it whatever the object's shape, since the scanner
//!    saw each point along its own line of sight, while over the best-fit
//!    plane a real object's scan folds (the bunny's scans: 1.1–1.7 % of the
//!    local normals on edge). Along a direction, the image is the plane
//!    square to it; from a position, the camera's: each point divided by
//!    its depth along the mean line of sight, scaled by the mean depth so
//!    that image lengths at the cloud stay about the cloud's own (the
//!    β-scaled distances below hold), with n towards the scanner, so the
//!    faces face it. A point more than 84° off that axis is
//!    [`DelaunayError::NotInView`].
//! 2. **Height-field check, on the points.** Each point's local normal is
//!    fitted to its 30 nearest neighbours. Where the surface
//!    stands on edge or folds over its plane, local normals turn
//!    perpendicular to the line of sight (n, or from the scanner's
//!    position); if more than [`DelaunayOptions::max_steep_share`] of the
//!    points have |nᵢ·sᵢ| < 0.1, the cloud is rejected with
//!    [`DelaunayError::NotAHeightField`].
//! 3. **Loops made valid.** Each smoothed loop becomes one closed polyline
//!    (each open edge without its last point, the next edge's corner), with
//!    its smoothed 3D positions. In the projection, each vertex closer
//!    than 0.4 β to the last one kept is dropped, as `meshtrim clean` does
//!    with its loops: where a zig-zag border is smoothed its vertices
//!    bunch up, and a segment much shorter than the spacing, opposite a
//!    point a spacing away, makes a sliver. The loops must be simple and
//!    must not touch one another: a loop that crosses itself is repaired
//!    by dropping the vertices of the shorter side of the crossing (a
//!    twist, or a spike that turns straight back), as long as that takes at
//!    most [`DelaunayOptions::max_repair`] of its vertices (and at least 4 may always go).
//!    Where that leaves loops crossing (a twist too long to drop, a small
//!    hole across the outer border, two holes across each other: ragged
//!    real scans have them), every proper crossing is split into a vertex
//!    the loops share, and each loop gets its surface side from the cloud
//!    points near it (`planar/tangle.rs`): the surface is then where the
//!    winding is at least 1, the outer border's inside less every hole.
//!    A loop through another's vertex shares it the same way. Loops that
//!    run along one line and meet give [`DelaunayError::LoopsCross`] (or
//!    [`DelaunayError::LoopNotSimple`] for one loop). spade's exact predicates check every constraint
//!    again before it is added (spade panics on crossing constraints):
//!    what the floating-point repair missed is an error, never a panic.
//! 4. **Which points go in.** A cloud point is inserted when it lies inside
//!    the loops by parity (inside the outer border, outside the holes; with
//!    several outer loops, each patch), or by winding where loops crossed,
//!    and farther than [`DelaunayOptions::exclude`]·βᵢ (0.3) from
//!    every loop in 3D, and than 0.1 βᵢ in the projection. Points closer to
//!    a loop are left out: the loop vertices stand for the border there,
//!    and a point next to a constraint would only make a sliver (or, on
//!    it, split the constraint and change the border's vertex sequence).
//!    The distance is taken in 3D, where the faces are: where the surface
//!    turns steeply away from the projection near its border, a point
//!    close to the loop in the projection lies far from it on the surface,
//!    and its faces are well shaped. *Choice*, measured (the synthetic
//!    cases of `test_delaunay_path`, the real scans of
//!    `test_delaunay_path_on_real_range_scans`): 0.1 β in the projection
//!    and no evening out of the loops left the synthetic meshes' smallest
//!    angles at 4.4–5.7° and 32–146 faces under 5° on each real scan;
//!    with both, 9.9–11.4° and 6–57. 0.4 β gives 12.2–16.2°, but on
//!    bun090 the points it leaves out along its occlusions go with the
//!    faces there (0.50 % of the points then lie farther than two
//!    spacings from the mesh, against 0.39 %). Points that coincide in 2D
//!    are merged by spade (the first kept).
//! 5. **Constrained Delaunay triangulation** (spade, exact predicates): the
//!    points are bulk-loaded, then every loop's vertices are inserted and
//!    its segments added as constraint edges.
//! 6. **Kept faces.** The faces are classified exactly by a flood fill from
//!    the outside that flips parity across every constraint edge: odd faces
//!    (inside the outer border and outside the holes) are kept. Where loops
//!    crossed, the fill adds each constraint's turn of the winding instead
//!    and keeps the faces of winding at least 1; where two holes touch at a
//!    crossing the faces of the smaller fan round it go (a pinch would be a
//!    non-manifold vertex), and so do patches without a cloud point. Co-circular
//!    quads (the lattice rectangles of quantised clouds), where either
//!    diagonal is Delaunay, take the one through their lowest id
//!    ([`canonical_diagonals`]), and the faces are listed in the order of their ids,
//!    so that moving the cloud, which rounds its coordinates, changes
//!    nothing. They are
//!    lifted back to 3D: cloud points keep their exact coordinates, loop
//!    vertices take their smoothed 3D positions. Faces are
//!    counter-clockwise seen from the plane normal's side; so the outer
//!    border runs counter-clockwise and holes clockwise.
//!    **Occlusions.** Where a nearer surface hides a farther one, the
//!    scanner saw the two side by side in its image with no gap between
//!    them, so the loops (traced in the image) do not part them and the
//!    triangulation joins them with a skirt of faces no surface is under.
//!    A face with an edge longer than
//!    [`DelaunayOptions::occlusion_reach`]·β (the larger β at its ends; 4)
//!    that stands within 11.5° of edge-on to the line of sight
//!    (|n_t·s| < 0.2) spans such a depth jump and is dropped, with the
//!    faces of every fan but the largest round a vertex where the drop
//!    pinched the surface. *Choice*, measured on the bunny's scans in
//!    their image: faces with an edge over 10 times the median held 4.6,
//!    5.3 and 6.7 % of bun000's, bun045's and chin's area, every one of
//!    those faces within 11.5° of edge-on, with an edge of 3.9 β or more;
//!    after the drop 0.00–0.03 %. A real surface the scanner saw at a
//!    grazing angle keeps its faces: its samples lie far apart, but so
//!    does β there (face000's longest faces: 1.2–4.4 β). The new border along an occlusion runs
//!    through the outermost samples of each surface; it is not smoothed.
//! 7. **Height-field check, on the triangles.** A lifted counter-clockwise
//!    triangle can never be flipped relative to n (its normal's component
//!    along n is its projected area), so folds show instead as triangles
//!    joining the overlapping sheets, steep to the surface: a triangle is a
//!    misfit when the mean |n_t·nᵥ| over its vertices' local normals is
//!    below 0.5; misfits holding more than
//!    [`DelaunayOptions::max_misfit_share`] of the area give
//!    [`DelaunayError::NotAHeightField`]. The area, not the count: a sliver
//!    between two loops that nearly touch has an arbitrary normal but
//!    covers almost nothing, while a fold's triangles span its sheets.
//!
//! Degenerate faces: a projected Delaunay triangle has a positive area and
//! its lift is never smaller, so no face has zero area. Slivers are
//! prevented (points near loops left out, coincident loop vertices merged)
//! rather than removed, since removing a face would open a hole; faces
//! below 10⁻¹²·β² (β the median resolution) are counted in the
//! report, not removed.

use crate::hash::{HashMap, HashSet};

use rayon::prelude::*;
use spade::handles::{FixedFaceHandle, FixedVertexHandle, InnerTag};
use spade::{PositionInTriangulation, Triangulation};

use crate::bpd::{Detection, View};
use crate::edges::Edges;
use crate::error::{DelaunayError, MeshError};
use crate::frame::{fit_plane, Frame};
use crate::geom::{cross, dot, norm2, segment_dist2, sub, unit, Point3};
use crate::mesh::{lowest_first, Mesh};
use crate::spatial::morton::{octree_runs, spatial_order, split_by_runs, MortonCells, MortonGrid};
use crate::spatial::neighbours::{NeighbourIndex, RunScratch};

use crate::geom::median;
use crate::planar::{
    canonical_diagonals, cocircular, inside_faces, obstacle, pinches_opened, point, surface_sides,
    untangle, untwist, winding_faces, Cdt, Node, Ring, SegmentGrid, Tangle, Turns, VOTE_REACH,
};

mod bounds;
mod cdt;
mod height_field;
mod projection;
#[cfg(test)]
mod tests;

use bounds::*;
use cdt::*;
use height_field::*;
use projection::*;

/// Options of the Delaunay path. Shares are fractions (0.01 is 1 %);
/// distances are multiples of the local resolution β, so none depends on
/// the cloud's units.
#[derive(Debug, Clone, PartialEq)]
pub struct DelaunayOptions {
    /// Largest share of the points whose local normal stands on edge over
    /// the best-fit plane (|nᵢ·n| < 0.1) before the cloud is no height
    /// field (step 2). Default 0.01.
    pub max_steep_share: f64,
    /// Largest share of the mesh's area in triangles that do not follow
    /// the surface (step 7). Default 0.01.
    pub max_misfit_share: f64,
    /// Cloud points closer to a loop than this many β (in 3D) are left
    /// out: the loop stands for the border there (step 4). Default 0.3.
    pub exclude: f64,
    /// Largest share of a loop's vertices that untwisting it may drop
    /// (step 3); at least 4 may always go. Default 0.05.
    pub max_repair: f64,
    /// A face nearly edge-on to the line of sight with an edge longer than
    /// this many β (the larger at its two ends) spans a depth jump where a
    /// nearer surface occludes a farther one, and is dropped (step 6).
    /// Default 4; infinity keeps every face.
    pub occlusion_reach: f64,
}

impl Default for DelaunayOptions {
    fn default() -> Self {
        Self {
            max_steep_share: 0.01,
            max_misfit_share: 0.01,
            exclude: 0.3,
            max_repair: 0.05,
            occlusion_reach: 4.0,
        }
    }
}
/// Faces smaller than this many β² are counted as degenerate.
const DEGENERATE: f64 = 1e-12;

/// What the Delaunay path did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DelaunayReport {
    /// Cloud points given.
    pub points_in: usize,
    /// Cloud points that are vertices of the output.
    pub points_used: usize,
    /// Cloud points outside the loops (beyond the border or in holes).
    pub points_outside: usize,
    /// Cloud points left out for lying within [`DelaunayOptions::exclude`]·β of a loop.
    pub points_near_loop: usize,
    /// Cloud points merged with another that projects to the same spot.
    pub points_merged: usize,
    /// Loop vertices merged with their predecessor: closer than 0.4 β to
    /// it in the projection (step 3).
    pub loop_vertices_merged: usize,
    /// Loop vertices dropped to untwist self-crossing loops.
    pub loop_vertices_dropped: usize,
    /// Places where smoothed loops cross or touch (one another or
    /// themselves) that were split, the surface then taken by winding
    /// (step 3).
    pub loop_crossings: usize,
    /// Faces dropped where loops crossed: round a vertex where the surface
    /// pinched, or in a patch without a cloud point (step 6).
    pub crossing_faces_dropped: usize,
    /// Faces dropped for spanning a depth jump where a nearer surface
    /// occludes a farther one (step 6), with those that would have pinched
    /// a vertex.
    pub occlusion_faces_dropped: usize,
    /// Share of local normals standing on edge (|nᵢ·n| < 0.1), %.
    pub steep_normals_percent: f64,
    /// Share of the mesh's area in triangles not following the surface, %.
    pub misfit_area_percent: f64,
    /// Faces below 10⁻¹²·β² (kept, counted).
    pub degenerate_faces: usize,
    /// Diagonals of co-circular quads flipped to their canonical side (the
    /// one through the quad's lowest id).
    pub diagonals_flipped: usize,
    /// For each smoothed loop, its vertices in the output, in loop order.
    /// Loops that cross are split at their crossings first (step 3), each
    /// lobe a loop, and list only the vertices the output uses.
    pub loops: Vec<Vec<u32>>,
    /// Unit normal of the best-fit plane; faces are counter-clockwise seen
    /// from its side.
    pub plane_normal: Point3,
    /// Area of the output.
    pub area: f64,
}

/// Builds a mesh from the cloud itself, bounded by the smoothed loops.
pub fn delaunay_mesh(
    cloud: &[Point3],
    detection: &Detection,
    edges: &Edges,
    options: &DelaunayOptions,
) -> Result<Mesh, DelaunayError> {
    delaunay_mesh_with_report(cloud, detection, edges, options).map(|(mesh, _)| mesh)
}

/// [`delaunay_mesh`], with what it did. The steps are those of the module
/// doc.
pub fn delaunay_mesh_with_report(
    cloud: &[Point3],
    detection: &Detection,
    edges: &Edges,
    options: &DelaunayOptions,
) -> Result<(Mesh, DelaunayReport), DelaunayError> {
    check_input(cloud, detection)?;
    let n = cloud.len();
    let beta = &detection.beta;
    let beta_median = median(beta);
    let mut report = DelaunayReport {
        points_in: n,
        ..Default::default()
    };
    let plane = Projection::new(cloud, detection.view)?;
    report.plane_normal = plane.frame.normal;
    let normals = local_normals(cloud, plane.frame.normal);
    check_steep_normals(cloud, &normals, &plane, options, &mut report)?;
    if edges.loops.is_empty() {
        return Err(MeshError::NoFaces.into());
    }
    let bounds = valid_rings(
        edges,
        cloud,
        beta,
        beta_median,
        &plane,
        options,
        &mut report,
    )?;
    let nodes = points_inside(cloud, beta, &plane, &bounds, options.exclude, &mut report);
    let triangulation = LoopCdt::build(nodes, &bounds, n, &mut report)?;
    let jumps = DepthJumps {
        cloud,
        beta,
        plane: &plane,
        reach: options.occlusion_reach,
    };
    let (mesh, reference) = triangulation.lift(&jumps, &mut report)?;
    check_triangles(
        &mesh,
        &reference,
        &normals,
        beta_median,
        plane.onto,
        options,
        &mut report,
    )?;
    report.area = mesh.area();
    Ok((mesh, report))
}

/// Refuses what spade cannot take or no mesh can be made of: non-finite
/// coordinates, coordinates beyond spade's range (checked before spade,
/// which panics or refuses points there), fewer than 3 points, or a β
/// count other than one per point.
fn check_input(cloud: &[Point3], detection: &Detection) -> Result<(), DelaunayError> {
    if let Some(index) = cloud.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        return Err(MeshError::NonFinite { index }.into());
    }
    crate::mesh::check_vertex_range(cloud)?;
    if cloud.len() < 3 || detection.beta.len() != cloud.len() {
        return Err(MeshError::NoFaces.into());
    }
    Ok(())
}
