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
//!    below 0.5; more than [`DelaunayOptions::max_misfit_share`] of misfits gives
//!    [`DelaunayError::NotAHeightField`].
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

/// Neighbourhood size of the local normals of the height-field check.
const NORMAL_K: usize = 30;
/// Most points per k-NN run of the local normals (as BPD's runs).
const NORMAL_RUN: usize = 32;
/// A local normal with |nᵢ·n| below this stands on edge over the plane.
const STEEP_COS: f64 = 0.1;
/// A triangle whose normal makes a mean |n_t·nᵥ| below this with its
/// vertices' local normals does not follow the surface.
const MISFIT_COS: f64 = 0.5;
/// Points closer to a loop in the projection than this share of
/// [`DelaunayOptions::exclude`]·β are left out whatever their distance in
/// 3D: on a constraint they would split it.
const IN_PROJECTION: f64 = 1.0 / 3.0;
/// Consecutive loop vertices closer than this many β in the projection
/// are merged (step 3): a much shorter segment than the spacing, opposite
/// a point a spacing away, makes a sliver.
const LOOP_GAP: f64 = 0.4;
/// A face whose unit normal makes |n_t·s| below this with the line of
/// sight s stands nearly edge-on to the scanner (within 11.5°).
const EDGE_ON_COS: f64 = 0.2;

/// Options of the Delaunay path. Shares are fractions (0.01 is 1 %);
/// distances are multiples of the local resolution β, so none depends on
/// the cloud's units.
#[derive(Debug, Clone, PartialEq)]
pub struct DelaunayOptions {
    /// Largest share of the points whose local normal stands on edge over
    /// the best-fit plane (|nᵢ·n| < 0.1) before the cloud is no height
    /// field (step 2). Default 0.01.
    pub max_steep_share: f64,
    /// Largest share of the kept triangles that may not follow the surface
    /// (step 7). Default 0.01.
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
    /// Share of kept triangles not following the surface, %.
    pub misfit_triangles_percent: f64,
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

/// Step 1, **projection**: the cloud's best-fit plane, or with a view the
/// scanner's image, with (u, v) coordinates relative to the first point
/// (or the scanner), which keeps precision for clouds far from the origin.
struct Projection {
    frame: Frame,
    origin: Point3,
    /// For a view from a position: the image is the camera's, each point
    /// divided by its depth along the axis (−`frame.normal`) and scaled by
    /// this, the points' mean depth, so that image lengths at the cloud are
    /// about the cloud's own (the β-scaled distances of steps 3 and 4 hold).
    perspective: Option<f64>,
    /// What the errors call the plane.
    onto: &'static str,
}

const BEST_FIT_PLANE: &str = "the best-fit plane";
const SCANNER_IMAGE: &str = "the scanner's image";

impl Projection {
    /// The plane of all the points (PCA, [`fit_plane`]), or the image of
    /// the detection's view: along a direction, the plane square to it;
    /// from a position, the camera's image about the mean line of sight
    /// to the points, its normal towards the scanner (faces then face
    /// it). Refuses a point beside or behind the scanner's position,
    /// which no camera image holds.
    fn new(cloud: &[Point3], view: Option<View>) -> Result<Self, DelaunayError> {
        match view {
            None => {
                let all: Vec<u32> = (0..cloud.len() as u32).collect();
                Ok(Projection {
                    frame: fit_plane(cloud, &all),
                    origin: cloud[0],
                    perspective: None,
                    onto: BEST_FIT_PLANE,
                })
            }
            Some(View::Along(direction)) => Ok(Projection {
                frame: Frame::of_normal(unit(direction)),
                origin: cloud[0],
                perspective: None,
                onto: SCANNER_IMAGE,
            }),
            Some(View::From(eye)) => {
                let axis = View::camera_axis(eye, cloud);
                let mut depths = 0.0;
                for (index, &p) in cloud.iter().enumerate() {
                    depths += View::camera_depth(sub(p, eye), axis)
                        .ok_or(DelaunayError::NotInView { index })?;
                }
                Ok(Projection {
                    frame: Frame::of_normal(axis.map(|c| -c)),
                    origin: eye,
                    perspective: Some(depths / cloud.len() as f64),
                    onto: SCANNER_IMAGE,
                })
            }
        }
    }

    /// `p` in the image's (u, v) coordinates.
    fn to2(&self, p: Point3) -> [f64; 2] {
        let d = sub(p, self.origin);
        let (u, v) = (dot(d, self.frame.u), dot(d, self.frame.v));
        match self.perspective {
            None => [u, v],
            Some(scale) => {
                let depth = -dot(d, self.frame.normal);
                [scale * u / depth, scale * v / depth]
            }
        }
    }

    /// The line of sight through `p` (unit): the plane's normal, or from
    /// the scanner's position.
    fn sight(&self, p: Point3) -> Point3 {
        match self.perspective {
            None => self.frame.normal,
            Some(_) => unit(sub(p, self.origin)),
        }
    }
}

/// Step 2, **local normals**: each point's normal fitted to its
/// 30 nearest neighbours, oriented to the side `plane_normal`
/// points to.
///
/// The search runs over the points in Morton order, as BPD's does (about
/// twice as fast as a k-d tree at 1M points), with ties cut by input
/// index: the same neighbours in the same order as [`NeighbourIndex::new`]
/// gives, so the same normals.
fn local_normals(cloud: &[Point3], plane_normal: Point3) -> Vec<Point3> {
    let grid = MortonGrid::of(cloud);
    let (order, keys) = spatial_order(cloud, &grid);
    let sorted: Vec<Point3> = order.par_iter().map(|&i| cloud[i as usize]).collect();
    let index =
        NeighbourIndex::in_morton_order(&sorted, MortonCells::new(grid, &keys)).with_ranks(&order);
    // Each run's normals written in place, in Morton order.
    let mut by_position = vec![[0.0; 3]; cloud.len()];
    let runs = octree_runs(&keys, NORMAL_RUN);
    let pieces = split_by_runs(&runs, &mut by_position, 1);
    let k = NORMAL_K.min(cloud.len());
    runs.into_par_iter().zip(pieces).for_each_init(
        || (RunScratch::default(), Vec::new()),
        |(scratch, members), (run, out)| {
            members.resize(run.len() * k, 0);
            index.nearest_of_run(run, k, members, scratch);
            for (nb, normal) in members.chunks_exact_mut(k).zip(out) {
                nb.iter_mut().for_each(|q| *q = order[*q as usize]);
                *normal = oriented_normal(cloud, nb, plane_normal);
            }
        },
    );
    // The sorted copy's block is free again for the normals.
    drop(index);
    drop(sorted);
    let mut normals = vec![[0.0; 3]; cloud.len()];
    for (&i, m) in order.iter().zip(by_position) {
        normals[i as usize] = m;
    }
    normals
}

/// The normal of the plane fitted to `members`, on `plane_normal`'s side.
fn oriented_normal(cloud: &[Point3], members: &[u32], plane_normal: Point3) -> Point3 {
    let m = fit_plane(cloud, members).normal;
    if dot(m, plane_normal) < 0.0 {
        m.map(|c| -c)
    } else {
        m
    }
}

/// Step 2, **height-field check on the points**: where the surface stands
/// on edge or folds over its plane, local normals turn perpendicular to
/// the plane normal; more than [`DelaunayOptions::max_steep_share`] of them below
/// 0.1 is [`DelaunayError::NotAHeightField`]. Fills
/// `steep_normals_percent`.
fn check_steep_normals(
    cloud: &[Point3],
    normals: &[Point3],
    plane: &Projection,
    options: &DelaunayOptions,
    report: &mut DelaunayReport,
) -> Result<(), DelaunayError> {
    let n = normals.len();
    let steep = normals
        .iter()
        .zip(cloud)
        .filter(|&(m, &p)| dot(*m, plane.sight(p)).abs() < STEEP_COS)
        .count();
    report.steep_normals_percent = 100.0 * steep as f64 / n as f64;
    if steep as f64 > options.max_steep_share * n as f64 {
        return Err(DelaunayError::NotAHeightField {
            onto: plane.onto,
            percent: report.steep_normals_percent,
            what: "local normals",
            limit: 100.0 * options.max_steep_share,
        });
    }
    Ok(())
}

/// The loops that bound the mesh, valid in the projection.
struct Bounds {
    rings: Vec<Ring>,
    grid: SegmentGrid,
    /// Where loops crossed: each ring's surface side ([`surface_sides`]),
    /// the surface then being where the winding is at least 1. `None`
    /// where no loop crosses: parity says the same without sides.
    sides: Option<Vec<i32>>,
    /// What the errors call the plane.
    onto: &'static str,
}

impl Bounds {
    /// Is the point `p3`, at `p` in the projection, within `reach` of a
    /// loop in 3D, or within [`IN_PROJECTION`]·`reach` of one in the
    /// projection, where it could lie on the constraint? Measured in 3D
    /// because that is where the faces are: where the surface turns
    /// steeply away from the projection near its border, a point close to
    /// the loop in the projection lies far from it on the surface, and its
    /// faces are well shaped.
    fn near_loop(&self, p3: Point3, p: [f64; 2], reach: f64) -> bool {
        self.grid.near(p, IN_PROJECTION * reach)
            || self.grid.near_where(p, reach, |s| {
                let (l, j) = self.grid.owner[s as usize];
                let ring = &self.rings[l as usize];
                let (a, b) = (
                    ring.p3[j as usize],
                    ring.p3[(j as usize + 1) % ring.p3.len()],
                );
                segment_dist2(p3, a, b) < reach * reach
            })
    }

    /// Is `p` (away from the loops) on the surface?
    fn inside(&self, p: [f64; 2]) -> bool {
        match &self.sides {
            None => self.grid.parity(p),
            Some(sides) => self.grid.winding(p, sides) >= 1,
        }
    }
}

/// Step 3, **loops made valid**: each smoothed loop as a ring projected
/// onto the plane, vertices closer than 0.4 β merged, small self-crossings
/// untwisted ([`untwist`]); where that leaves loops crossing, they are
/// split at their crossings instead ([`untangle`]) and each gets its
/// surface side. Fills `loop_vertices_merged`, `loop_vertices_dropped`
/// and `loop_crossings`.
fn valid_rings(
    edges: &Edges,
    cloud: &[Point3],
    beta: &[f64],
    beta_median: f64,
    plane: &Projection,
    options: &DelaunayOptions,
    report: &mut DelaunayReport,
) -> Result<Bounds, DelaunayError> {
    let mut rings: Vec<Ring> = edges
        .loops
        .iter()
        .map(|lp| Ring::from_loop(lp, beta))
        .collect();
    for ring in rings.iter_mut() {
        ring.p2 = ring.p3.iter().map(|&p| plane.to2(p)).collect();
        report.loop_vertices_merged += ring.merge_coincident();
        report.loop_vertices_merged += ring.even_out_in_projection(LOOP_GAP);
    }
    let min_cell = options.exclude * beta_median;
    let merged = rings.clone();
    match untwist(&mut rings, min_cell, options.max_repair) {
        Ok((grid, dropped)) => {
            report.loop_vertices_dropped += dropped;
            Ok(Bounds {
                rings,
                grid,
                sides: None,
                onto: plane.onto,
            })
        }
        Err(tangle) => untangled(&merged, cloud, beta, plane, min_cell, report)
            .ok_or_else(|| tangle_error(tangle, plane.onto)),
    }
}

/// The loops split at their crossings ([`untangle`]), each with the
/// surface side the cloud points near it vote for; `None` where loops
/// touch or run along each other, which no split resolves.
fn untangled(
    rings: &[Ring],
    cloud: &[Point3],
    beta: &[f64],
    plane: &Projection,
    min_cell: f64,
    report: &mut DelaunayReport,
) -> Option<Bounds> {
    let split = untangle(rings, &SegmentGrid::new(rings, min_cell)).ok()?;
    let grid = SegmentGrid::new(&split.rings, min_cell);
    let votes: Vec<Option<(u32, f64)>> = (0..cloud.len())
        .into_par_iter()
        .map(|i| grid.nearest(plane.to2(cloud[i]), VOTE_REACH * beta[i]))
        .collect();
    let sides = surface_sides(&split.rings, &grid, votes.into_iter().flatten());
    report.loop_crossings = split.crossings;
    Some(Bounds {
        rings: split.rings,
        grid,
        sides: Some(sides),
        onto: plane.onto,
    })
}

fn tangle_error(tangle: Tangle, onto: &'static str) -> DelaunayError {
    match tangle {
        Tangle::SelfCrossing {
            index,
            vertices,
            dropped,
        } => DelaunayError::LoopNotSimple {
            onto,
            index,
            vertices,
            dropped,
        },
        Tangle::Crossing { a, b } => DelaunayError::LoopsCross { onto, a, b },
    }
}

/// Where a cloud point lies relative to the loops (step 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum PointClass {
    /// Inside the loops by parity and away from them: inserted.
    Inside,
    /// Within [`DelaunayOptions::exclude`]·β of a loop: left out, the loop stands for the
    /// border there.
    NearLoop,
    /// Beyond the outer border or in a hole.
    Outside,
}

/// Step 4, **which points go in**: the cloud points inside the loops by
/// parity and farther than [`DelaunayOptions::exclude`]·βᵢ from every loop, as
/// triangulation nodes in cloud order. Points next to a loop would only
/// make slivers, or on it split the constraint and change the border's
/// vertex sequence. Fills `points_near_loop` and `points_outside`.
fn points_inside(
    cloud: &[Point3],
    beta: &[f64],
    plane: &Projection,
    bounds: &Bounds,
    exclude: f64,
    report: &mut DelaunayReport,
) -> Vec<Node> {
    let class: Vec<PointClass> = (0..cloud.len())
        .into_par_iter()
        .map(|i| {
            let p = plane.to2(cloud[i]);
            if bounds.near_loop(cloud[i], p, exclude * beta[i]) {
                PointClass::NearLoop
            } else if bounds.inside(p) {
                PointClass::Inside
            } else {
                PointClass::Outside
            }
        })
        .collect();
    let count = |c: PointClass| class.iter().filter(|&&k| k == c).count();
    report.points_near_loop = count(PointClass::NearLoop);
    report.points_outside = count(PointClass::Outside);
    (0..cloud.len())
        .filter(|&i| class[i] == PointClass::Inside)
        .map(|i| Node::new(plane.to2(cloud[i]), i as u32))
        .collect()
}

/// Step 5, the **constrained Delaunay triangulation** (spade, exact
/// predicates) of the inserted points and the rings, with what its loop
/// vertices stand for. Node ids: cloud points below n, loop vertex j at
/// n + j.
struct LoopCdt {
    cdt: Cdt,
    /// Number of cloud points.
    n: usize,
    /// Smoothed 3D position of each loop vertex.
    loop_p3: Vec<Point3>,
    /// The boundary point each loop vertex was smoothed from.
    loop_ref: Vec<u32>,
    /// The ring each loop vertex belongs to, to name it in errors.
    loop_of: Vec<u32>,
    /// Each ring's vertex handles, in ring order.
    ring_handles: Vec<Vec<FixedVertexHandle>>,
    /// Where loops crossed, the constraint edges' turns of the winding
    /// ([`winding_faces`]); `None` for parity.
    turns: Option<Turns>,
    /// What the errors call the plane.
    onto: &'static str,
}

impl LoopCdt {
    /// Bulk-loads the `nodes`, then inserts every ring's vertices and adds
    /// its segments as constraint edges, outer borders first. A ring vertex
    /// or segment that meets another ring's (or its own) is an error, never
    /// a panic in spade; where loops were split at their crossings, those
    /// crossing vertices and the segments between them are shared. Fills
    /// `points_merged` (nodes spade found coincident, the first kept).
    fn build(
        nodes: Vec<Node>,
        bounds: &Bounds,
        n: usize,
        report: &mut DelaunayReport,
    ) -> Result<Self, DelaunayError> {
        let rings = &bounds.rings;
        let inserted = nodes.len();
        let cdt: Cdt = if nodes.is_empty() {
            Cdt::new()
        } else {
            Cdt::bulk_load(nodes).map_err(|_| DelaunayError::Input(MeshError::NoFaces))?
        };
        report.points_merged = inserted - cdt.num_vertices();
        let mut t = LoopCdt {
            cdt,
            n,
            loop_p3: Vec::new(),
            loop_ref: Vec::new(),
            loop_of: Vec::new(),
            ring_handles: vec![Vec::new(); rings.len()],
            turns: bounds.sides.as_ref().map(|_| Turns::default()),
            onto: bounds.onto,
        };
        for l in largest_first(rings) {
            let handles = t.insert_ring_vertices(l, &rings[l])?;
            let side = bounds.sides.as_ref().map_or(1, |sides| sides[l]);
            t.constrain_ring(l, rings[l].len(), &handles, side)?;
            t.ring_handles[l] = handles;
        }
        Ok(t)
    }

    /// Inserts the vertices of ring `l`, refusing one that lands on an
    /// existing vertex or on a constraint edge; returns their handles.
    fn insert_ring_vertices(
        &mut self,
        l: usize,
        ring: &Ring,
    ) -> Result<Vec<FixedVertexHandle>, DelaunayError> {
        let mut handles = Vec::with_capacity(ring.p2.len());
        for j in 0..ring.p2.len() {
            let id = (self.n + self.loop_p3.len()) as u32;
            let position = point(ring.p2[j]);
            match self.cdt.locate(position) {
                PositionInTriangulation::OnVertex(h) if self.is_shared_crossing(h, position) => {
                    handles.push(h);
                    continue;
                }
                PositionInTriangulation::OnVertex(h) => {
                    let other = self.cdt.vertex(h).data().id;
                    return Err(self.crossing(l, ring.len(), other));
                }
                PositionInTriangulation::OnEdge(e)
                    if self.cdt.is_constraint_edge(e.as_undirected()) =>
                {
                    let other = self.cdt.directed_edge(e).from().data().id;
                    return Err(self.crossing(l, ring.len(), other));
                }
                _ => {}
            }
            let h = self
                .cdt
                .insert(Node::new(ring.p2[j], id))
                .map_err(|_| DelaunayError::Input(MeshError::NonFinite { index: 0 }))?;
            self.loop_p3.push(ring.p3[j]);
            self.loop_ref.push(ring.reference[j]);
            self.loop_of.push(l as u32);
            handles.push(h);
        }
        Ok(handles)
    }

    /// Where loops were split at their crossings, is `h` a loop vertex at
    /// exactly `position`: a crossing another loop inserted first?
    fn is_shared_crossing(&self, h: FixedVertexHandle, position: spade::Point2<f64>) -> bool {
        let v = self.cdt.vertex(h);
        self.turns.is_some() && v.data().id as usize >= self.n && v.position() == position
    }

    /// Adds the closed polyline through `handles` (ring `l`, of `vertices`
    /// vertices, its surface on the side `side`) as constraint edges,
    /// checking each first with exact predicates: spade panics on crossing
    /// constraints. Where loops were split at their crossings, a segment
    /// two loops share is added once and each turn of the winding noted.
    fn constrain_ring(
        &mut self,
        l: usize,
        vertices: usize,
        handles: &[FixedVertexHandle],
        side: i32,
    ) -> Result<(), DelaunayError> {
        let m = handles.len();
        for j in 0..m {
            let (a, b) = (handles[j], handles[(j + 1) % m]);
            if let Some(turns) = self.turns.as_mut() {
                // Crossing a → b from its right to its left, the winding
                // gains the ring's side.
                let (key, turn) = if a < b {
                    ((a, b), side)
                } else {
                    ((b, a), -side)
                };
                *turns.entry(key).or_default() += turn;
                let shared = self
                    .cdt
                    .get_edge_from_neighbors(a, b)
                    .is_some_and(|e| e.is_constraint_edge());
                if shared {
                    continue;
                }
            }
            if let Some(other) = obstacle(&self.cdt, a, b) {
                return Err(self.crossing(l, vertices, other));
            }
            self.cdt.add_constraint(a, b);
        }
        Ok(())
    }

    /// The error for ring `l` meeting the vertex `other` ([`crossing`]).
    fn crossing(&self, l: usize, vertices: usize, other: u32) -> DelaunayError {
        crossing(l, vertices, other, self.n, &self.loop_of, self.onto)
    }

    /// Step 6, **kept faces, lifted**: the odd faces ([`inside_faces`]),
    /// counter-clockwise seen from the plane normal's side, co-circular
    /// quads given their canonical diagonal ([`canonical_diagonals`]) and listed in
    /// the order of their ids, so that moving the cloud, which rounds its
    /// coordinates, changes nothing. Lifted back to 3D: cloud points keep
    /// their exact coordinates, loop vertices take their smoothed 3D
    /// positions. Returns the mesh and, per vertex, the cloud point it is
    /// or was smoothed from. Fills `diagonals_flipped`, `points_used` and
    /// `loops`.
    fn lift(
        &self,
        jumps: &DepthJumps,
        report: &mut DelaunayReport,
    ) -> Result<(Mesh, Vec<u32>), DelaunayError> {
        let cloud = jumps.cloud;
        // Jittered and real float clouds have no co-circular quad: the
        // flip pass, which indexes every edge and needs every position, is
        // skipped without changing its result (it flips only where a quad
        // is co-circular).
        let flips_possible = self.has_cocircular_quad();
        let KeptFaces {
            mut faces,
            positions,
            mut used,
        } = self.kept_faces(flips_possible);
        if self.turns.is_some() {
            report.crossing_faces_dropped = pinches_opened(&mut faces, used.len(), self.n, self.n);
        }
        let spans = self.across_occlusions(&faces, jumps);
        report.occlusion_faces_dropped = spans.iter().filter(|&&s| s).count();
        if report.occlusion_faces_dropped > 0 {
            let mut k = 0;
            faces.retain(|_| {
                k += 1;
                !spans[k - 1]
            });
            // Where the dropped faces met at a vertex, the surface may
            // pinch there now, at a cloud point as well as a loop vertex.
            report.occlusion_faces_dropped += pinches_opened(&mut faces, used.len(), self.n, 0);
        }
        if self.turns.is_some() || report.occlusion_faces_dropped > 0 {
            used.fill(false);
            faces
                .iter()
                .flatten()
                .for_each(|&id| used[id as usize] = true);
        }
        report.diagonals_flipped = if flips_possible {
            canonical_diagonals(&positions, &mut faces, &self.constraint_pairs())
        } else {
            0
        };
        sort_faces(&mut faces);
        let (out_index, vertices, reference) = self.number_vertices(cloud, &used);
        report.points_used = out_index[..self.n]
            .iter()
            .filter(|&&s| s != u32::MAX)
            .count();
        let mesh = Mesh {
            vertices,
            faces: faces
                .iter()
                .map(|f| f.map(|id| out_index[id as usize]))
                .collect(),
        };
        report.loops = self.ring_vertices(&out_index);
        mesh.validate()?;
        Ok((mesh, reference))
    }

    /// The cloud point id `id` stands for: itself, or the boundary point a
    /// loop vertex was smoothed from.
    fn reference(&self, id: u32) -> u32 {
        match (id as usize).checked_sub(self.n) {
            None => id,
            Some(j) => self.loop_ref[j],
        }
    }

    /// The 3D position of id `id`.
    fn position(&self, id: u32, cloud: &[Point3]) -> Point3 {
        match (id as usize).checked_sub(self.n) {
            None => cloud[id as usize],
            Some(j) => self.loop_p3[j],
        }
    }

    /// Step 6, **occlusions**: per face, does it span a depth jump: an
    /// edge longer than [`DelaunayOptions::occlusion_reach`] times the
    /// resolution at both its ends, on a face nearly edge-on to the line of
    /// sight (|n_t·s| < 0.2)?
    fn across_occlusions(&self, faces: &[[u32; 3]], jumps: &DepthJumps) -> Vec<bool> {
        if jumps.reach.is_infinite() {
            return vec![false; faces.len()];
        }
        faces
            .par_iter()
            .map(|f| {
                let p = f.map(|id| self.position(id, jumps.cloud));
                let r = f.map(|id| self.reference(id) as usize);
                let long = (0..3).any(|k| {
                    let (a, b) = (k, (k + 1) % 3);
                    let reach = jumps.reach * jumps.beta[r[a]].max(jumps.beta[r[b]]);
                    norm2(sub(p[b], p[a])) > reach * reach
                });
                long && {
                    let nt = unit(cross(sub(p[1], p[0]), sub(p[2], p[0])));
                    let centroid = [0, 1, 2].map(|c| (p[0][c] + p[1][c] + p[2][c]) / 3.0);
                    dot(nt, jumps.plane.sight(centroid)).abs() < EDGE_ON_COS
                }
            })
            .collect()
    }

    /// Each ring's vertices as output numbers, in ring order; those the
    /// output does not use (where loops crossed) are left out, and rings
    /// with none.
    fn ring_vertices(&self, out_index: &[u32]) -> Vec<Vec<u32>> {
        self.ring_handles
            .iter()
            .map(|hs| {
                hs.iter()
                    .map(|&h| out_index[self.cdt.vertex(h).data().id as usize])
                    .filter(|&v| v != u32::MAX)
                    .collect::<Vec<u32>>()
            })
            .filter(|vertices| !vertices.is_empty())
            .collect()
    }

    /// The faces on the surface: odd by parity, or of winding at least 1
    /// where loops crossed.
    fn surface_faces(&self) -> Vec<FixedFaceHandle<InnerTag>> {
        match &self.turns {
            None => inside_faces(&self.cdt),
            Some(turns) => winding_faces(&self.cdt, turns),
        }
    }

    /// The faces on the surface ([`LoopCdt::surface_faces`]),
    /// counter-clockwise.
    fn kept_faces(&self, with_positions: bool) -> KeptFaces {
        let kept = self.surface_faces();
        let mut faces: Vec<[u32; 3]> = Vec::with_capacity(kept.len());
        let mut positions = HashMap::default();
        let mut used = vec![false; self.n + self.loop_p3.len()];
        for f in kept {
            let vs = self.cdt.face(f).vertices();
            let mut ids = vs.map(|v| v.data().id);
            let p = vs.map(|v| v.position());
            let orient =
                (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
            if orient < 0.0 {
                ids.swap(1, 2);
            }
            faces.push(ids);
            for (id, p) in vs.map(|v| v.data().id).into_iter().zip(p) {
                used[id as usize] = true;
                if with_positions {
                    positions.insert(id, [p.x, p.y]);
                }
            }
        }
        KeptFaces {
            faces,
            positions,
            used,
        }
    }

    /// Whether some edge that is not a constraint has two triangles whose
    /// quad is co-circular, tested exactly as [`canonical_diagonals`] tests
    /// its first edges (ids a < b, c left of a → b, d left of b → a): if
    /// none is, that pass flips nothing. Faces outside the loops are
    /// tested too, so this can only say yes more often.
    fn has_cocircular_quad(&self) -> bool {
        let at = |v: FixedVertexHandle| {
            let p = self.cdt.vertex(v).position();
            [p.x, p.y]
        };
        self.cdt.undirected_edges().any(|edge| {
            if edge.is_constraint_edge() {
                return false;
            }
            let mut forward = edge.as_directed();
            if forward.from().data().id > forward.to().data().id {
                forward = forward.rev();
            }
            let (Some(c), Some(d)) = (forward.opposite_vertex(), forward.rev().opposite_vertex())
            else {
                return false;
            };
            let [a, b] = [forward.from().fix(), forward.to().fix()];
            cocircular(at(a), at(b), at(c.fix()), at(d.fix()))
        })
    }

    /// The rings' segments as id pairs, smaller id first: diagonals that
    /// are constraints never flip.
    fn constraint_pairs(&self) -> HashSet<[u32; 2]> {
        self.ring_handles
            .iter()
            .flat_map(|hs| {
                (0..hs.len()).map(|j| {
                    let [a, b] =
                        [hs[j], hs[(j + 1) % hs.len()]].map(|h| self.cdt.vertex(h).data().id);
                    [a.min(b), a.max(b)]
                })
            })
            .collect()
    }

    /// Output numbers for the `used` ids, in id order (so cloud points in
    /// cloud order, then loop vertices): returns, per id, its output number
    /// (u32::MAX if unused), and the output vertices with the cloud points
    /// they are or were smoothed from.
    fn number_vertices(
        &self,
        cloud: &[Point3],
        used: &[bool],
    ) -> (Vec<u32>, Vec<Point3>, Vec<u32>) {
        let mut out_index = vec![u32::MAX; used.len()];
        let mut vertices = Vec::new();
        let mut reference = Vec::new();
        for (id, slot) in out_index.iter_mut().enumerate() {
            if used[id] {
                *slot = vertices.len() as u32;
                vertices.push(self.position(id as u32, cloud));
                reference.push(self.reference(id as u32));
            }
        }
        (out_index, vertices, reference)
    }
}

/// What step 6 needs to find the faces that span an occlusion.
struct DepthJumps<'a> {
    cloud: &'a [Point3],
    beta: &'a [f64],
    plane: &'a Projection,
    /// [`DelaunayOptions::occlusion_reach`].
    reach: f64,
}

/// The faces step 6 keeps, before their diagonals are made canonical.
struct KeptFaces {
    /// Counter-clockwise id triples.
    faces: Vec<[u32; 3]>,
    /// The 2D position of every id they use (empty unless asked for).
    positions: HashMap<u32, [f64; 2]>,
    /// Per id, whether they use it.
    used: Vec<bool>,
}

/// Ring indices, the largest by area first: the outer borders go in
/// before the holes they hold.
fn largest_first(rings: &[Ring]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..rings.len()).collect();
    order.sort_by(|&a, &b| rings[b].area().abs().total_cmp(&rings[a].area().abs()));
    order
}

/// Faces in an order of their own ids (the triangulation's internal
/// order depends on its history), each starting at its lowest id.
fn sort_faces(faces: &mut [[u32; 3]]) {
    for f in faces.iter_mut() {
        *f = lowest_first(*f);
    }
    faces.sort_unstable();
}

/// Step 7, **height-field check on the triangles**: a lifted
/// counter-clockwise triangle can never be flipped relative to the plane
/// normal, so folds show instead as triangles joining the overlapping
/// sheets, steep to the surface. More than [`DelaunayOptions::max_misfit_share`] of misfits
/// ([`is_misfit`]) is [`DelaunayError::NotAHeightField`]. Fills
/// `degenerate_faces` (below 10⁻¹²·β², counted, not removed) and
/// `misfit_triangles_percent`.
fn check_triangles(
    mesh: &Mesh,
    reference: &[u32],
    normals: &[Point3],
    beta_median: f64,
    onto: &'static str,
    options: &DelaunayOptions,
    report: &mut DelaunayReport,
) -> Result<(), DelaunayError> {
    let mut misfits = 0;
    for face in &mesh.faces {
        let [a, b, c] = face.map(|v| mesh.vertices[v as usize]);
        let nt = cross(sub(b, a), sub(c, a));
        let len = norm2(nt).sqrt();
        if 0.5 * len <= DEGENERATE * beta_median * beta_median {
            report.degenerate_faces += 1;
        }
        // The local normals of the points the face's vertices stand for.
        let vertex_normals = face.map(|v| normals[reference[v as usize] as usize]);
        if is_misfit(nt, len, vertex_normals) {
            misfits += 1;
        }
    }
    report.misfit_triangles_percent = 100.0 * misfits as f64 / mesh.faces.len() as f64;
    if misfits as f64 > options.max_misfit_share * mesh.faces.len() as f64 {
        return Err(DelaunayError::NotAHeightField {
            onto,
            percent: report.misfit_triangles_percent,
            what: "triangles",
            limit: 100.0 * options.max_misfit_share,
        });
    }
    Ok(())
}

/// Does a triangle with normal `nt` (unnormalised, of length `len`) not
/// follow the surface: a mean |n_t·nᵥ| over its vertices' local normals
/// below 0.5? A zero-area triangle counts as one.
fn is_misfit(nt: Point3, len: f64, vertex_normals: [Point3; 3]) -> bool {
    if len == 0.0 {
        return true;
    }
    let fit: f64 = vertex_normals
        .iter()
        .map(|&m| dot(nt, m).abs() / len)
        .sum::<f64>()
        / 3.0;
    fit < MISFIT_COS
}

/// The error for loop `l` meeting the vertex `other` (a vertex id).
fn crossing(
    l: usize,
    vertices: usize,
    other: u32,
    n: usize,
    loop_of: &[u32],
    onto: &'static str,
) -> DelaunayError {
    let b = (other as usize)
        .checked_sub(n)
        .and_then(|j| loop_of.get(j))
        .map_or(l, |&b| b as usize);
    if b == l {
        DelaunayError::LoopNotSimple {
            onto,
            index: l,
            vertices,
            dropped: 0,
        }
    } else {
        DelaunayError::LoopsCross {
            onto,
            a: b.min(l),
            b: b.max(l),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planar::pinched_faces;
    use rand::{RngExt, SeedableRng};

    /// The straightforward local normals: one query a point, each on its
    /// own, in input order (no Morton runs).
    fn local_normals_reference(cloud: &[Point3], plane_normal: Point3) -> Vec<Point3> {
        let index = NeighbourIndex::new(cloud);
        let mut nb = Vec::new();
        (0..cloud.len())
            .map(|i| {
                index.nearest(i, NORMAL_K, &mut nb);
                oriented_normal(cloud, &nb, plane_normal)
            })
            .collect()
    }

    /// The Morton-run search gives the reference's normals bit for bit, on
    /// wavy sheets with quantised coordinates (ties at every distance) and
    /// repeated points, and on clouds smaller than a neighbourhood.
    #[test]
    fn local_normals_match_the_reference() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for case in 0..12 {
            let n = [5, 29, 30, 31, 400, 3000][case % 6];
            let step = if case < 6 { 0.0 } else { 0.25 };
            let mut cloud: Vec<Point3> = (0..n)
                .map(|_| {
                    let (x, y): (f64, f64) =
                        (rng.random_range(0.0..20.0), rng.random_range(0.0..20.0));
                    let p = [x, y, (0.3 * x).sin() + 0.1 * y];
                    if step > 0.0 {
                        p.map(|c: f64| (c / step).round() * step)
                    } else {
                        p
                    }
                })
                .collect();
            for i in 0..n / 10 {
                cloud.push(cloud[(7 * i) % n]);
            }
            let up = [0.0, 0.0, 1.0];
            assert_eq!(
                local_normals(&cloud, up),
                local_normals_reference(&cloud, up),
                "case {case}"
            );
        }
    }

    /// A circle of `m` vertices round `c` of radius `r`, counter-clockwise
    /// or not, as a smoothed loop of the cloud (each vertex smoothed from
    /// the nearest cloud point).
    fn circle(cloud: &[Point3], c: [f64; 2], r: f64, m: usize, ccw: bool) -> crate::edges::Loop {
        let sense = if ccw { 1.0 } else { -1.0 };
        let points: Vec<Point3> = (0..m)
            .map(|j| {
                let t = sense * std::f64::consts::TAU * j as f64 / m as f64;
                [c[0] + r * t.cos(), c[1] + r * t.sin(), 0.0]
            })
            .collect();
        let nearest = |p: Point3| {
            (0..cloud.len())
                .min_by(|&a, &b| norm2(sub(cloud[a], p)).total_cmp(&norm2(sub(cloud[b], p))))
                .unwrap_or(0) as u32
        };
        crate::edges::Loop {
            boundary_points: points.iter().map(|&p| nearest(p)).collect(),
            corners: Vec::new(),
            edges: vec![crate::edges::Edge {
                closed: true,
                points,
            }],
            sides: Vec::new(),
        }
    }

    /// A 30 × 30 grid of spacing 0.5, jittered by up to 0.1, on the wave
    /// z = `bump`·sin(0.7x).
    /// A 30 × 30 jittered sheet, bumped by `bump`·sin(0.7 x), and its
    /// detection.
    fn detected_sheet(rng: &mut rand_chacha::ChaCha8Rng, bump: f64) -> (Vec<Point3>, Detection) {
        let mut cloud = Vec::new();
        for i in 0..30 {
            for j in 0..30 {
                let jitter = [0, 1].map(|_| rng.random_range(-0.1..0.1));
                let (x, y) = (i as f64 * 0.5 + jitter[0], j as f64 * 0.5 + jitter[1]);
                cloud.push([x, y, bump * (x * 0.7).sin()]);
            }
        }
        let detection =
            crate::bpd::detect_boundary(&cloud, &crate::bpd::BpdOptions::default()).unwrap();
        (cloud, detection)
    }

    /// Edges of a random number of circles over the sheet, of random
    /// centres, radii, vertex counts and senses.
    fn random_circles(
        rng: &mut rand_chacha::ChaCha8Rng,
        cloud: &[Point3],
        count: std::ops::Range<usize>,
        radius: std::ops::Range<f64>,
    ) -> Edges {
        let loops = (0..rng.random_range(count))
            .map(|_| {
                let c = [rng.random_range(2.0..13.0), rng.random_range(2.0..13.0)];
                let (r, m) = (rng.random_range(radius.clone()), rng.random_range(4..40));
                circle(cloud, c, r, m, rng.random_bool(0.5))
            })
            .collect();
        Edges {
            loops,
            ..Default::default()
        }
    }

    /// A point near a loop in the projection but far from it in 3D, where
    /// the surface turns steeply away near its border, goes in; one near
    /// it in 3D, or on it in the projection, stays out.
    #[test]
    fn points_are_left_out_near_a_loop_by_their_distance_in_3d() {
        // A square loop of side 4 in the plane z = 0, β 1.
        let ring = crate::planar::flat_ring(vec![[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]);
        let bounds = Bounds {
            grid: SegmentGrid::new(std::slice::from_ref(&ring), 0.1),
            rings: vec![ring],
            sides: None,
            onto: BEST_FIT_PLANE,
        };
        let reach = 0.3;
        // 0.2 inside the bottom edge in the projection.
        let p = [2.0, 0.2];
        assert!(bounds.near_loop([2.0, 0.2, 0.0], p, reach));
        assert!(!bounds.near_loop([2.0, 0.2, 0.5], p, reach));
        // 0.05 inside: on the constraint for spade's purposes, whatever
        // its depth.
        assert!(bounds.near_loop([2.0, 0.05, 5.0], [2.0, 0.05], reach));
        assert!(!bounds.near_loop([2.0, 1.0, 0.0], [2.0, 1.0], reach));
    }

    /// A disc of radius 9 with three holes where no point was sampled:
    /// one across the border, two overlapping each other. The smoothed
    /// loops cross four times; the mesh is the disc less the holes, one
    /// manifold piece with two borders, whichever way each loop runs.
    #[test]
    fn loops_that_cross_bound_the_surface_by_winding() {
        let holes = [([18.0, 10.0], 2.0), ([8.0, 10.0], 1.6), ([10.0, 10.0], 1.6)];
        let in_hole = |p: [f64; 2], slack: f64| {
            holes
                .iter()
                .any(|(c, r)| (p[0] - c[0]).hypot(p[1] - c[1]) < r - slack)
        };
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let mut cloud = Vec::new();
        for i in 0..=48 {
            for j in 0..=48 {
                let p = [
                    i as f64 * 0.42 + rng.random_range(-0.05..0.05),
                    j as f64 * 0.42 + rng.random_range(-0.05..0.05),
                ];
                if (p[0] - 10.0).hypot(p[1] - 10.0) < 8.9 && !in_hole(p, -0.1) {
                    cloud.push([p[0], p[1], 0.0]);
                }
            }
        }
        let detection =
            crate::bpd::detect_boundary(&cloud, &crate::bpd::BpdOptions::default()).unwrap();
        for senses in [[false, true, false, true], [true, false, true, false]] {
            let mut loops = vec![circle(&cloud, [10.0, 10.0], 9.0, 120, senses[0])];
            for ((c, r), ccw) in holes.iter().zip(&senses[1..]) {
                loops.push(circle(&cloud, *c, *r, 40, *ccw));
            }
            let edges = Edges {
                loops,
                ..Default::default()
            };
            let (mesh, report) =
                delaunay_mesh_with_report(&cloud, &detection, &edges, &DelaunayOptions::default())
                    .unwrap();
            assert_eq!(report.loop_crossings, 4, "{senses:?}");
            mesh.check_manifold().unwrap();
            for f in 0..mesh.faces.len() {
                let [a, b, c] = mesh.faces[f].map(|v| mesh.vertices[v as usize]);
                let centre = [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0];
                assert!(!in_hole(centre, 0.0), "{senses:?}: face {f} in a hole");
                assert!((centre[0] - 10.0).hypot(centre[1] - 10.0) < 9.0);
            }
            assert_eq!(mesh.boundary_loops().len(), 2, "{senses:?}");
            // The disc less the holes, by the midpoint rule.
            let step = 0.02;
            let cells = (0..1000 * 1000)
                .filter(|k| {
                    let p = [(k % 1000) as f64 + 0.5, (k / 1000) as f64 + 0.5].map(|c| c * step);
                    (p[0] - 10.0).hypot(p[1] - 10.0) < 9.0 && !in_hole(p, 0.0)
                })
                .count();
            let expected = cells as f64 * step * step;
            assert!(
                (mesh.area() - expected).abs() < 0.01 * expected,
                "{} {expected}",
                mesh.area()
            );
        }
    }

    /// The flood fill's faces (parity where no loop crosses, winding where
    /// loops cross) are those a ray cast over the loops keeps at the
    /// face's centroid, the straightforward reference: on random circles
    /// that cross one another and themselves, each run either way, over a
    /// jittered grid.
    #[test]
    fn the_filled_faces_match_a_ray_cast_at_every_centroid() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let (cloud, detection) = detected_sheet(&mut rng, 0.0);
        let beta_median = median(&detection.beta);
        let plane = Projection::new(&cloud, None).unwrap();
        let (mut crossed, mut compared) = (0, 0);
        for case in 0..60 {
            let edges = random_circles(&mut rng, &cloud, 1..6, 1.0..6.0);
            let options = DelaunayOptions::default();
            let mut report = DelaunayReport::default();
            let Ok(bounds) = valid_rings(
                &edges,
                &cloud,
                &detection.beta,
                beta_median,
                &plane,
                &options,
                &mut report,
            ) else {
                continue;
            };
            let nodes = points_inside(
                &cloud,
                &detection.beta,
                &plane,
                &bounds,
                options.exclude,
                &mut report,
            );
            let Ok(t) = LoopCdt::build(nodes, &bounds, cloud.len(), &mut report) else {
                continue;
            };
            crossed += usize::from(bounds.sides.is_some());
            let kept: HashSet<_> = t.surface_faces().into_iter().collect();
            for f in t.cdt.fixed_inner_faces() {
                let p = t.cdt.face(f).vertices().map(|v| v.position());
                let centre = [
                    (p[0].x + p[1].x + p[2].x) / 3.0,
                    (p[0].y + p[1].y + p[2].y) / 3.0,
                ];
                if bounds.grid.near(centre, 1e-9 * beta_median) {
                    continue;
                }
                compared += 1;
                assert_eq!(kept.contains(&f), bounds.inside(centre), "case {case}");
            }
        }
        assert!(crossed >= 20 && compared > 10_000, "{crossed} {compared}");
    }

    /// Whatever random circles bound it (crossing one another and
    /// themselves, touching, nested), the Delaunay path gives a clear
    /// error or a mesh that is manifold at every edge and vertex, whose
    /// every vertex is a cloud point or on a loop.
    #[test]
    fn random_loops_give_an_error_or_a_manifold_mesh() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
        let (cloud, detection) = detected_sheet(&mut rng, 0.05);
        let (mut meshed, mut crossed) = (0, 0);
        for case in 0..80 {
            let edges = random_circles(&mut rng, &cloud, 1..7, 0.3..7.0);
            let options = DelaunayOptions::default();
            let Ok((mesh, report)) =
                delaunay_mesh_with_report(&cloud, &detection, &edges, &options)
            else {
                continue;
            };
            meshed += 1;
            crossed += usize::from(report.loop_crossings > 0);
            mesh.check_manifold().unwrap();
            let pinched = pinched_faces(&mesh.faces, mesh.vertices.len(), 0);
            assert!(pinched.is_empty(), "case {case}: a pinched vertex");
        }
        assert!(meshed >= 40 && crossed >= 20, "{meshed} {crossed}");
    }
}
