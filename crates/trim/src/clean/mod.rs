//! Border cleanup of triangulated scans — `meshtrim clean` (meshtrim's
//! extension of the paper to meshes whose own vertices are the cloud).
//!
//! Scanner software triangulates the raw samples, so a scan's border runs
//! through the outermost samples and zig-zags between them. The paper's
//! edge reconstruction (section 3) gives the smooth edge those samples
//! stand for; cleaning replaces the jagged border by it:
//!
//! 1. **Border loops.** The mesh's own border (edges used by one face),
//!    chained in face order, gives each boundary already ordered: the
//!    mesh's connectivity replaces BPD's clustering and the travelling-
//!    salesman tour, which can only guess the order the mesh knows. Loops
//!    of fewer than [`MIN_LOOP_POINTS`] vertices (a missing triangle) are
//!    too small to smooth and stay as they are.
//! 2. **Smoothed loops.** Each loop gets its corners (section 3.1), its
//!    FFT-smoothed edges (section 3.3, cut-off following the local β of the
//!    vertices) and, unless switched off, the outward offset to the
//!    physical edge ([`crate::edges::offset`]): the smoothed loop passes
//!    outside the jagged border at its notches and inside it at its spikes.
//!    Vertices closer than [`MIN_GAP`]·β to the previous one are merged.
//! 3. **The band.** Around each loop, the faces within a few rings of its
//!    border (starting at [`FIRST_DEPTH`] rings, grown to [`MAX_DEPTH`]
//!    while the cut reaches the band's rim) are projected along their
//!    area-weighted mean normal (a range scan faces its scanner
//!    everywhere, so its faces stay the right way up even where the band's
//!    best-fit plane is steep). Loops whose bands share a face are handled
//!    together.
//! 4. **What goes.** Within the band, a vertex stays when it lies on the
//!    surface's side of the smoothed loops and farther than [`MARGIN`]·βᵢ
//!    from them (closer, it would only make a sliver against the new
//!    border), and is not a vertex of the old border. Faces with a vertex
//!    that goes, or crossed by a smoothed loop, are removed, and with them
//!    the faces that turn over in the projection and touch them (a
//!    skirt across a depth jump at a silhouette), inside the band.
//! 5. **The gap is filled.** The removed region and the gap between the
//!    old border and the smoothed loops are triangulated again, in the
//!    projection, by a constrained Delaunay triangulation (spade, exact
//!    predicates) of the smoothed loops' vertices, the kept vertices of the
//!    removed faces (not those of turned faces), and, as constraints, the
//!    smoothed loops and the *walls*: the edges where removed faces met
//!    kept ones (and the borders of small loops the band takes in). The
//!    faces between these curves — by a parity flood fill across the
//!    constraints — are the new ones. Where walls cross in the projection
//!    (a fold beside the band), the faces round the crossing go too and
//!    the gap is triangulated again, at most [`WALL_REPAIRS`] times. Where
//!    the gap is wide, Delaunay refinement adds points lifted onto the
//!    unrefined triangles ([`REFINE_ANGLE`]); otherwise every vertex is a
//!    point of the surface already (a mesh vertex or a smoothed loop
//!    vertex), so the new faces follow the surface without any lifting.
//! 6. Unused vertices are removed. Vertices outside the bands keep their
//!    exact coordinates and the faces there are untouched.
//!
//! A loop whose band cannot be replaced safely (its smoothed loop crosses
//! itself by more than [`MAX_UNTWIST`] or crosses another loop or the kept
//! mesh, its walls keep crossing, its cut runs deeper than [`MAX_DEPTH`]
//! rings) is left unchanged and reported, and the other loops of its band
//! are tried again without it. A patch whose faces would meet others at a
//! non-manifold or same-direction edge is dropped the same way, so the
//! output is never a broken mesh. The loops left are tried again on the
//! mesh with the other loops' patches in ([`rounds`]).

mod align;
mod assemble;
mod band;
mod crossing;
mod gap;
mod rounds;
mod strip;
mod tolerance;
mod unfold;

use align::place_along;
use assemble::*;
use band::*;
use gap::*;
use rounds::{replace_in_rounds, Replaced};
use strip::*;
use unfold::refine_strip;

use std::borrow::Cow;
use std::collections::BTreeSet;

use crate::hash::{HashMap, HashSet};

use rayon::prelude::*;
use spade::handles::FixedVertexHandle;
use spade::{
    AngleLimit, Point2 as SpadePoint, PositionInTriangulation, RefinementParameters, Triangulation,
};

use crate::edges::cluster::MIN_LOOP_POINTS;
use crate::edges::loop_with_beta;
use crate::error::{CleanError, MeshError};
use crate::frame::fit_plane;
use crate::geom::{add, cross, dist2, dot, norm2, sub, Point3};
use crate::geom::{orient, orientation};
use crate::mesh::boundary_loops_of;
use crate::mesh::fill::{fill_holes, HolesFilled};
use crate::mesh::manifold::{make_manifold, ManifoldRepair};
use crate::mesh::pinches::open_new_pinches;
use crate::mesh::repair::{repair_degenerate_faces, FaceRepair};
use crate::mesh::seams::{stitch_seams_with, Stitched};
use crate::mesh::topology::{
    check_manifold, check_manifold_with, distinct, manifold_at_a_glance, EdgeRows, Topology,
};
use crate::mesh::{lowest_first, Mesh};
use crate::planar::{
    inside_faces, kept_apart, obstacle, untwist, Cdt, Node, Ring, SegmentGrid, Tangle, STEINER,
};
use crate::resolution::{ByRef, Picked, PointResolution};
use crate::spatial::neighbours::{KNearest, MortonIndex};

/// The segment grid's cells are no smaller than this many β.
const GRID_CELL: f64 = 0.1;
/// Vertices closer than this many β to a smoothed loop are replaced.
const MARGIN: f64 = 0.5;
/// Largest share of a smoothed loop's vertices that untwisting it may drop
/// (where the low-pass filter pulls the two sides of a deep, narrow notch
/// across each other, the notch is cut off).
const MAX_UNTWIST: f64 = 0.15;
/// Smoothed loops of one band closer than this many β (in its projection)
/// are moved apart to it: the strip between them would have no width.
const LOOP_GAP: f64 = 0.25;
/// Consecutive smoothed loop vertices closer than this many β are merged:
/// where a zig-zag border is smoothed, its vertices bunch up, and a short
/// border segment against interior vertices a spacing away makes a
/// sliver.
const MIN_GAP: f64 = 0.4;
/// Refinement of the gap: new faces' smallest angle aimed at (degrees) …
const REFINE_ANGLE: f64 = 20.0;
/// … leaving faces below this many β² alone.
const REFINE_MIN_AREA: f64 = 0.05;
/// Times the faces round crossing walls are removed before a band gives up.
const WALL_REPAIRS: usize = 8;
/// Vertices farther than this many β from the smoothed loop stay in a
/// strip; a planar patch that removes such a vertex gives way to a strip
/// where one can be made.
const REACH: f64 = 3.0;
/// Vertices beyond [`REACH`]·β a planar patch may remove before it gives
/// way to a strip: a stray vertex at the corner of a notch, not a piece of
/// surface.
const MAX_FAR_REMOVED: usize = 3;
/// Rings of faces around a border the band starts with …
const FIRST_DEPTH: u32 = 3;
/// … and the most it grows to.
const MAX_DEPTH: u32 = 30;
/// Share of a mesh's area facing one direction ([`Mesh::area_facing_one_way`])
/// from which it is taken for a scan seen from one side: measured 0.944–1.0
/// on the range scans, 0.758 on a bust open at its base, 0.545 on the
/// zippered bunny.
pub const SEEN_FROM_ONE_SIDE: f64 = 0.85;

/// Options of the cleanup.
#[derive(Debug, Clone, PartialEq)]
pub struct CleanOptions {
    /// Move the smoothed border out to the estimated physical edge (off
    /// gives the paper's edges, through the border vertices).
    pub offset: bool,
    /// Make the mesh edge-manifold and consistently oriented first
    /// (removing faces from edges of more than two faces, turning faces
    /// wound against their neighbours: see [`ManifoldRepair`]) rather than
    /// refusing it.
    pub repair: bool,
    /// The farthest each smoothed loop vertex may lie from the border
    /// vertex it was smoothed from (in the mesh's units): where it would
    /// lie farther (a notch bridged, a corner cut off), the loop follows
    /// the border at that distance; the points a strip adds when it
    /// refines its faces are held within it of the scan's faces it
    /// replaces, so every new vertex lies within it of the scan. None: as
    /// smooth as β makes it.
    pub max_deviation: Option<f64>,
    /// Close the holes no wider than this (the largest distance between
    /// two of a hole's vertices, in the mesh's units) before the cleanup,
    /// with faces over their own vertices (`mesh/fill.rs`); never a
    /// piece's outer border. None: every hole stays, its border smoothed.
    pub fill_holes: Option<f64>,
}

impl Default for CleanOptions {
    fn default() -> Self {
        Self {
            offset: true,
            repair: false,
            max_deviation: None,
            fill_holes: None,
        }
    }
}

/// Loops left as they were, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct LeftLoops {
    /// Indices of the loops (in the input's border order).
    pub loops: Vec<usize>,
    /// Their numbers of vertices.
    pub vertices: Vec<usize>,
    /// Why they could not be replaced.
    pub reason: LeftReason,
}

/// Why border loops were left unchanged. Each says what in the mesh stands
/// in the way, so that a user can act on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LeftReason {
    /// The faces beside the new border fold over its projection plane
    /// (walls kept crossing after the faces round them were removed).
    Folds,
    /// The loop's smoothed loop crosses itself in the band's projection,
    /// and untwisting it would drop too many of its vertices.
    CrossesItself {
        /// Vertices untwisting would drop.
        dropped: usize,
        /// Vertices of the smoothed loop.
        vertices: usize,
    },
    /// The loop's smoothed loop crosses that of another border.
    CrossesAnotherLoop,
    /// The smoothed border crosses the part of the mesh that stays.
    CrossesKeptMesh,
    /// Two vertices coincide in the band's projection.
    VerticesCoincide,
    /// The smoothed border lies farther from the mesh border than the
    /// band may grow (rings of faces).
    TooFarFromBorder {
        /// The largest band, in rings of faces.
        rings: u32,
    },
    /// The new faces would meet others at a non-manifold edge.
    NonManifold,
    /// The kept mesh's new border beside the smoothed loop does not close
    /// into one loop.
    TangledWall,
    /// The smoothed loop would cut the mesh in two.
    SplitsMesh,
    /// The smoothed loop doubles back on itself on the surface (across a
    /// narrow notch), turning that many of the new faces over.
    DoublesBack {
        /// New faces turned over.
        turned: usize,
        /// New faces.
        faces: usize,
    },
    /// The new faces would reach those of another border.
    MeetsAnotherBorder,
}

impl std::fmt::Display for LeftReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Folds => write!(f, "the mesh folds over the new border's plane beside it"),
            Self::CrossesItself { dropped, vertices } => write!(
                f,
                "its smoothed loop crosses itself in the band's projection (untwisting it would drop {dropped} of its {vertices} vertices)"
            ),
            Self::CrossesAnotherLoop => {
                write!(f, "its smoothed loop crosses the smoothed loop of another border")
            }
            Self::CrossesKeptMesh => write!(f, "the smoothed border crosses the kept mesh"),
            Self::VerticesCoincide => {
                write!(f, "two vertices coincide in the projection of the band")
            }
            Self::TooFarFromBorder { rings } => write!(
                f,
                "the smoothed border runs more than {rings} rings of faces from the mesh border"
            ),
            Self::NonManifold => {
                write!(f, "its new faces would meet others at a non-manifold edge")
            }
            Self::TangledWall => write!(
                f,
                "the mesh's new border beside the smoothed loop does not close into one loop"
            ),
            Self::SplitsMesh => write!(f, "its smoothed loop would cut the mesh in two"),
            Self::DoublesBack { turned, faces } => write!(
                f,
                "its smoothed loop doubles back on itself (a narrow notch): {turned} of {faces} new faces would turn over"
            ),
            Self::MeetsAnotherBorder => {
                write!(f, "its new faces would reach those of another border")
            }
        }
    }
}

/// What the cleanup did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CleanReport {
    /// Border loops of the input.
    pub loops_in: usize,
    /// Loops replaced by their smoothed edge.
    pub loops_smoothed: usize,
    /// Loops too small to smooth (kept as they are).
    pub loops_too_small: usize,
    /// Loops that could not be replaced, with the reason.
    pub loops_left: Vec<LeftLoops>,
    /// Input faces.
    pub faces_in: usize,
    /// Edges where the input's vertices were split but its surface goes
    /// on (a texture chart's border, a hard edge), stitched before
    /// anything else, so that they are not taken for borders
    /// ([`crate::stitch_seams`]).
    pub seam_edges_stitched: usize,
    /// Input faces that named a vertex twice, dropped before anything else
    /// (see `without_empty_faces`).
    pub slivers_dropped: usize,
    /// Input faces that repeated an earlier face with the same corners in
    /// the same turn, dropped before anything else (see
    /// `without_empty_faces`).
    pub repeated_faces_dropped: usize,
    /// What the `repair` option changed to make the mesh edge-manifold and
    /// consistently oriented (nothing without it).
    pub manifold: ManifoldRepair,
    /// Input faces removed (in the bands).
    pub faces_removed: usize,
    /// New faces (the bands triangulated again).
    pub faces_added: usize,
    /// Output faces.
    pub faces_out: usize,
    /// New vertices (on the smoothed loops).
    pub vertices_added: usize,
    /// Area of the input.
    pub area_in: f64,
    /// Area of the output.
    pub area_out: f64,
    /// The input's largest share of area facing one direction
    /// ([`Mesh::area_facing_one_way`]): near 1 for a scan seen from one
    /// side, lower for a surface wrapping round an object.
    pub area_facing_one_way: f64,
    /// Smallest angle of the new faces, in degrees; 0 when no face was
    /// added (`faces_added` is 0).
    pub min_angle_new: f64,
    /// Zero-area faces of the output repaired (those the input had
    /// inside, away from the border); none is written.
    pub repaired: FaceRepair,
    /// Faces dropped where the new border would pinch the surface at a
    /// vertex the input did not pinch (it runs through a neck one vertex
    /// wide): the faces of the smaller piece's fan there.
    pub pinch_faces_dropped: usize,
    /// Smoothed loop vertices moved back to
    /// [`CleanOptions::max_deviation`] from the border they replace.
    pub vertices_held: usize,
    /// Holes closed before the cleanup ([`CleanOptions::fill_holes`]);
    /// `loops_in` counts the loops left after.
    pub holes_filled: HolesFilled,
}

/// Replaces the jagged border of `mesh` by its smoothed boundary (see the
/// module doc). `beta` is the local resolution of each vertex (from BPD on
/// the vertices).
pub fn clean_mesh(
    mesh: &Mesh,
    beta: &(impl PointResolution + ?Sized),
    options: &CleanOptions,
) -> Result<(Mesh, CleanReport), CleanError> {
    clean_with(mesh, &ByRef(beta), options)
}

/// [`clean_mesh`] over any [`PointResolution`], compiled once.
fn clean_with(
    mesh: &Mesh,
    beta: &dyn PointResolution,
    options: &CleanOptions,
) -> Result<(Mesh, CleanReport), CleanError> {
    mesh.validate()?;
    check_resolution_length(mesh, beta)?;
    if let Some(max) = options
        .max_deviation
        .filter(|m| !(m.is_finite() && *m > 0.0))
    {
        return Err(CleanError::MaxDeviation(max));
    }
    if let Some(width) = options.fill_holes.filter(|w| !(w.is_finite() && *w > 0.0)) {
        return Err(CleanError::FillHoles(width));
    }
    let faces_in = mesh.faces.len();
    let (kept, dropped, edges) = without_empty_faces(mesh);
    // Seams stitched, so that they do not look like borders; a seam's
    // other copies are left out, so that the loops' neighbourhoods do not
    // hold a point twice.
    let Stitched {
        mesh: stitched,
        kept: stitched_from,
        edges: seam_edges_stitched,
    } = stitch_seams_with(&kept, &edges);
    let picked;
    let beta: &dyn PointResolution = match &stitched_from {
        Some(of) => {
            picked = Picked { all: beta, of };
            &picked
        }
        None => beta,
    };
    let (kept, dropped, edges) = match stitched {
        Cow::Borrowed(_) => (kept, dropped, edges),
        // Two corners of one face may have been stitched together.
        Cow::Owned(stitched) => {
            let (again, more, edges) = without_empty_faces(&stitched);
            let again = Cow::Owned(again.into_owned());
            (again, dropped + more, edges)
        }
    };
    let (kept, edges, manifold) = if options.repair {
        let (repaired, manifold) = make_manifold(&kept);
        let edges = EdgeRows::new(&repaired.faces);
        (Cow::Owned(repaired), edges, manifold)
    } else {
        (kept, edges, ManifoldRepair::default())
    };
    let mesh: &Mesh = &kept;
    check_cleanable(mesh, &edges)?;
    let borders = boundary_loops_of(&edges);
    drop(edges);
    let (area_in, area_facing_one_way) = (mesh.area(), mesh.area_facing_one_way());
    let filled;
    let (mesh, borders, holes_filled) = match options.fill_holes {
        Some(width) => {
            let (with_holes_closed, borders, holes) = close_holes(mesh, borders, width);
            filled = with_holes_closed;
            (&filled, borders, holes)
        }
        None => (mesh, borders, HolesFilled::default()),
    };
    let (rings, vertices_held) = smoothed_loops(mesh, beta, &borders, options);
    let mut report = CleanReport {
        loops_in: borders.len(),
        vertices_held,
        faces_in,
        seam_edges_stitched,
        slivers_dropped: dropped.slivers,
        repeated_faces_dropped: dropped.repeats,
        manifold,
        area_in,
        area_facing_one_way,
        holes_filled,
        ..Default::default()
    };
    // A scan seen from one side was seen along its faces' mean normal.
    let view = (report.area_facing_one_way >= SEEN_FROM_ONE_SIDE)
        .then(|| mesh.mean_normal())
        .flatten();
    let shaping = Shaping {
        view,
        max_deviation: options.max_deviation,
    };
    let replaced = replace_in_rounds(mesh, beta, &borders, &rings, shaping);
    // Small loops a strip absorbed count as replaced.
    report.loops_smoothed = replaced.replaced.iter().filter(|&&r| r).count();
    report.loops_too_small = (0..borders.len())
        .filter(|&l| rings[l].is_none() && !replaced.replaced[l])
        .count();
    let (out, mut report) = finish(mesh, replaced, report)?;
    for left in &mut report.loops_left {
        left.vertices = left.loops.iter().map(|&l| borders[l].len()).collect();
    }
    Ok((out, report))
}

/// `mesh` with its holes no wider than `width` closed, its border loops
/// after, and what was closed.
fn close_holes(
    mesh: &Mesh,
    borders: Vec<Vec<u32>>,
    width: f64,
) -> (Mesh, Vec<Vec<u32>>, HolesFilled) {
    let mut filled = mesh.clone();
    let holes = fill_holes(&mut filled, &borders, width);
    let borders = if holes.holes > 0 {
        filled.boundary_loops()
    } else {
        borders
    };
    (filled, borders, holes)
}

/// What the cleanup needs of the mesh left once its empty faces are dropped:
/// faces, every edge used at most twice and never twice the same way.
fn check_cleanable(mesh: &Mesh, edges: &EdgeRows) -> Result<(), CleanError> {
    if mesh.faces.is_empty() {
        return Err(MeshError::NoFaces.into());
    }
    Ok(check_manifold_with(mesh, edges)?)
}

/// One β per vertex of the mesh given.
fn check_resolution_length(mesh: &Mesh, beta: &dyn PointResolution) -> Result<(), CleanError> {
    if beta.len() != mesh.vertices.len() {
        return Err(CleanError::ResolutionLength {
            values: beta.len(),
            vertices: mesh.vertices.len(),
        });
    }
    Ok(())
}

/// Step 2: each border loop smoothed (corners, FFT edges and, with
/// `options.offset`, the outward offset), held within
/// `options.max_deviation` of its border, and evened out, in parallel;
/// None for loops of fewer than [`MIN_LOOP_POINTS`] vertices, too small
/// to smooth. Also how many vertices the bound held back.
fn smoothed_loops(
    mesh: &Mesh,
    beta: &dyn PointResolution,
    borders: &[Vec<u32>],
    options: &CleanOptions,
) -> (Vec<Option<Ring>>, usize) {
    let index = options.offset.then(|| MortonIndex::new(&mesh.vertices));
    let smoothed: Vec<Option<(Ring, usize)>> = borders
        .par_iter()
        .map(|border| {
            (border.len() >= MIN_LOOP_POINTS).then(|| {
                // β is found here for the border's vertices: on every
                // thread, as one loop is often most of the border.
                let loop_beta = border.par_iter().map(|&v| beta.beta(v as usize)).collect();
                let index = index.as_ref().map(|i| i as &dyn KNearest);
                let lp = loop_with_beta(&mesh.vertices, loop_beta, border.clone(), index);
                let mut ring = Ring::from_loop(&lp, beta);
                let held = options.max_deviation.map_or(0, |max| {
                    tolerance::keep_within(&mut ring.p3, &ring.reference, &mesh.vertices, max)
                });
                (even_out(ring), held)
            })
        })
        .collect();
    let held = smoothed.iter().flatten().map(|(_, held)| held).sum();
    (
        smoothed
            .into_iter()
            .map(|s| s.map(|(ring, _)| ring))
            .collect(),
        held,
    )
}

/// Steps 3 to 5 for every smoothed loop: its band, what goes and the new
/// faces, one outcome per group of loops whose bands overlap, and the mesh
/// with every patch applied.
fn replace_bands(
    mesh: &Mesh,
    beta: &dyn PointResolution,
    borders: &[Vec<u32>],
    rings: &[Option<Ring>],
    shaping: Shaping,
    beta_median: f64,
) -> (Vec<Outcome>, Mesh) {
    let topology = Topology::new(mesh);
    let context = Context {
        mesh,
        beta,
        borders,
        rings,
        topology: &topology,
        beta_median,
        view: shaping.view,
        max_deviation: shaping.max_deviation,
    };
    let mut outcomes = replace_all(&context);
    replace_left_by_strips(&context, &mut outcomes);
    let out = assemble_manifold(&context, &mut outcomes);
    (outcomes, out)
}

/// The loops the planar way left, replaced by strips (see [`strip`]).
/// A strip whose faces would reach a planar patch's takes the place of
/// that patch, whose loops are made strips in turn: a border that wraps
/// round the object matters more than the holes beside it, and a strip
/// keeps clear of the borders it does not absorb. Loops are taken in
/// order, so the result does not depend on the threads.
fn replace_left_by_strips(cx: &Context, outcomes: &mut Vec<Outcome>) {
    let mut queue: BTreeSet<usize> = outcomes
        .iter()
        .flat_map(|o| o.left.iter().flat_map(|x| x.loops.iter().copied()))
        .collect();

    let far_reaching: BTreeSet<usize> = outcomes
        .iter()
        .filter_map(|o| o.patch.as_ref().filter(|p| p.reaches_far))
        .flat_map(|p| p.loops.iter().copied())
        .collect();
    let mut first: HashMap<usize, Result<Strip, StripFailure>> = {
        let replaced = replaced_loops(cx.rings.len(), outcomes);
        let loops: Vec<usize> = queue.iter().copied().collect();
        loops
            .par_iter()
            .map(|&l| (l, replace_by_strip(cx, l, &replaced)))
            .collect()
    };
    queue.extend(far_reaching);
    let mut reasons: HashMap<usize, LeftReason> = HashMap::default();
    while let Some(l) = queue.pop_first() {
        match strip_in_place_of_planar(cx, outcomes, l, first.remove(&l)) {
            StripOutcome::AlreadyReplaced => {}
            StripOutcome::Left(reason) => {
                reasons.insert(l, reason);
            }
            StripOutcome::Taken { strip, demoted } => {
                queue.extend(demoted.into_iter().filter(|&k| k != l));
                for &k in &strip.patch.loops {
                    reasons.remove(&k);
                }
                outcomes.push(Outcome {
                    band: strip.footprint,
                    patch: Some(strip.patch),
                    left: Vec::new(),
                    strip: true,
                });
            }
        }
    }
    relist_left(cx, outcomes, reasons);
}

/// What became of one loop's strip.
enum StripOutcome {
    /// Another strip absorbed the loop.
    AlreadyReplaced,
    /// The loop stays, for this reason.
    Left(LeftReason),
    /// The strip is taken, in place of the planar patches that replaced
    /// the loops `demoted`.
    Taken { strip: Strip, demoted: Vec<usize> },
}

/// Loop `l`'s strip (`attempt`, when made already), made again in place
/// of every planar patch it reaches, and of its own planar patch when that
/// reaches far ([`Patch::reaches_far`]). Those patches are taken out only
/// when the strip is taken.
fn strip_in_place_of_planar(
    cx: &Context,
    outcomes: &mut [Outcome],
    l: usize,
    mut attempt: Option<Result<Strip, StripFailure>>,
) -> StripOutcome {
    let mut taken_out: Vec<(usize, Patch, Vec<u32>)> = Vec::new();
    let own_far_patch = outcomes.iter().position(|o| {
        o.patch
            .as_ref()
            .is_some_and(|p| p.reaches_far && p.loops.contains(&l) && !holds_longer_loop(cx, p, l))
    });
    if let Some(o) = own_far_patch {
        if let Some(patch) = outcomes[o].patch.take() {
            taken_out.push((o, patch, std::mem::take(&mut outcomes[o].band)));
        }
    }
    let result = loop {
        let replaced = replaced_loops(cx.rings.len(), outcomes);
        if replaced[l] {
            break StripOutcome::AlreadyReplaced;
        }
        let strip = attempt
            .take()
            .unwrap_or_else(|| replace_by_strip(cx, l, &replaced));
        let conflict = match &strip {
            Ok(strip) => conflicting_outcomes(outcomes, strip),
            Err(StripFailure::MeetsReplaced(other)) => outcomes
                .iter()
                .position(|o| o.patch.as_ref().is_some_and(|p| p.loops.contains(other)))
                .into_iter()
                .collect(),
            Err(_) => Vec::new(),
        };
        let planar: Vec<usize> = conflict
            .iter()
            .copied()
            .filter(|&o| !outcomes[o].strip)
            .collect();
        let outranked = planar.iter().any(|&o| {
            outcomes[o]
                .patch
                .as_ref()
                .is_some_and(|p| holds_longer_loop(cx, p, l))
        });
        if planar.is_empty() || planar.len() < conflict.len() || outranked {
            break match strip {
                Err(failure) => StripOutcome::Left(failure.reason()),
                Ok(_) if !conflict.is_empty() => StripOutcome::Left(LeftReason::MeetsAnotherBorder),
                Ok(strip) => StripOutcome::Taken {
                    strip,
                    demoted: Vec::new(),
                },
            };
        }
        for o in planar {
            if let Some(patch) = outcomes[o].patch.take() {
                taken_out.push((o, patch, std::mem::take(&mut outcomes[o].band)));
            }
        }
    };
    match result {
        StripOutcome::Taken { strip, .. } => StripOutcome::Taken {
            strip,
            demoted: taken_out
                .into_iter()
                .flat_map(|(_, patch, _)| patch.loops)
                .collect(),
        },
        other => {
            for (o, patch, band) in taken_out {
                outcomes[o].patch = Some(patch);
                outcomes[o].band = band;
            }
            other
        }
    }
}

/// Whether `patch` replaces a border longer (in vertices) than loop `l`:
/// a strip takes the place of a planar patch only for a border at least
/// as long as any the patch replaces, since the planar patch's borders
/// may find no strip (a hole's strip would otherwise trade an outer
/// border's planar patch for itself).
fn holds_longer_loop(cx: &Context, patch: &Patch, l: usize) -> bool {
    let length = cx.borders[l].len();
    patch.loops.iter().any(|&k| cx.borders[k].len() > length)
}

/// The outcomes' lists of loops left, once the strips are in: replaced
/// loops dropped, the strip's reason where one was tried, and the loops of
/// planar patches a strip took the place of that no strip could replace.
fn relist_left(cx: &Context, outcomes: &mut [Outcome], reasons: HashMap<usize, LeftReason>) {
    let replaced = replaced_loops(cx.rings.len(), outcomes);
    let mut listed: Vec<bool> = vec![false; cx.rings.len()];
    for outcome in outcomes.iter_mut() {
        outcome
            .left
            .retain(|x| x.loops.iter().any(|&k| !replaced[k]));
        for entry in outcome.left.iter_mut() {
            entry.loops.retain(|&k| !replaced[k]);
            for &k in &entry.loops {
                listed[k] = true;
            }
            if let Some(reason) = entry.loops.iter().find_map(|k| reasons.get(k)) {
                entry.reason = *reason;
            }
        }
    }
    let mut demoted: Vec<(usize, LeftReason)> = reasons
        .into_iter()
        .filter(|&(k, _)| !listed[k] && !replaced[k])
        .collect();
    demoted.sort_unstable_by_key(|&(k, _)| k);
    if let Some(outcome) = outcomes.first_mut() {
        outcome
            .left
            .extend(demoted.into_iter().map(|(k, reason)| LeftLoops {
                loops: vec![k],
                vertices: Vec::new(),
                reason,
            }));
    }
}

/// Which of the `count` loops the outcomes' patches replace (absorbed
/// ones included).
fn replaced_loops(count: usize, outcomes: &[Outcome]) -> Vec<bool> {
    let mut replaced = vec![false; count];
    for patch in outcomes.iter().filter_map(|o| o.patch.as_ref()) {
        for &l in &patch.loops {
            replaced[l] = true;
        }
    }
    replaced
}

/// The outcomes whose patches the strip's faces would reach: they remove
/// a face that shares a vertex with one the strip removes (sharing a
/// vertex goes both ways, so the strip's footprint tells it).
fn conflicting_outcomes(outcomes: &[Outcome], strip: &Strip) -> Vec<usize> {
    let footprint: HashSet<u32> = strip.footprint.iter().copied().collect();
    outcomes
        .iter()
        .enumerate()
        .filter(|(_, o)| {
            o.patch
                .as_ref()
                .is_some_and(|p| p.removed.iter().any(|f| footprint.contains(f)))
        })
        .map(|(o, _)| o)
        .collect()
}

/// The input with every patch applied. A planar group whose
/// patch makes an edge non-manifold once every patch is in is replaced
/// again with each patch checked by itself ([`band::where_patch_breaks`]):
/// the loops where it breaks are left, the others tried again without
/// them, and strips are tried again for the loops left. Only such groups:
/// a patch may lie on faces another patch removes, which the check by
/// itself cannot see. A safety net last: a patch that still breaks an edge
/// (not seen on the test data) is dropped, its loops left.
fn assemble_manifold(cx: &Context, outcomes: &mut Vec<Outcome>) -> Mesh {
    let mut remade = BTreeSet::new();
    loop {
        let (out, origin) = assemble(cx.mesh, outcomes);
        let bad = patches_breaking_manifold(&out, &origin);
        if bad.is_empty() {
            return out;
        }
        let again: Vec<usize> = bad
            .iter()
            .copied()
            .filter(|&g| !outcomes[g].strip && remade.insert(g))
            .collect();
        for &g in &again {
            if let Some(patch) = outcomes[g].patch.take() {
                let mut checked = replace_group(cx, &patch.loops, true);
                checked.left.splice(0..0, outcomes[g].left.drain(..));
                outcomes[g] = checked;
            }
        }
        if !again.is_empty() {
            replace_left_by_strips(cx, outcomes);
            continue;
        }
        for g in bad {
            if let Some(patch) = outcomes[g].patch.take() {
                outcomes[g].left.push(LeftLoops {
                    loops: patch.loops,
                    vertices: Vec::new(),
                    reason: LeftReason::NonManifold,
                });
            }
        }
    }
}

/// Step 6 and the output's part of the report: what the patches did,
/// the pinches they made opened, unused vertices removed, the result
/// checked, its faces and area.
fn finish(
    input: &Mesh,
    replaced: Replaced,
    mut report: CleanReport,
) -> Result<(Mesh, CleanReport), CleanError> {
    summarise(input, &replaced, &mut report);
    let mut out = replaced.mesh;
    let mut keep = vec![true; out.faces.len()];
    report.pinch_faces_dropped = open_new_pinches(input, &out, &mut keep);
    out.retain_faces(&keep);
    report.repaired = repair_degenerate_faces(&mut out);
    if out.faces.is_empty() {
        return Err(CleanError::NothingLeft {
            faces: report.faces_in,
        });
    }
    out.remove_unused_vertices();
    check_manifold(&out)?;
    report.faces_out = out.faces.len();
    report.area_out = out.area();
    Ok((out, report))
}

/// Everything the band replacement reads.
struct Context<'a> {
    mesh: &'a Mesh,
    beta: &'a dyn PointResolution,
    borders: &'a [Vec<u32>],
    rings: &'a [Option<Ring>],
    topology: &'a Topology,
    beta_median: f64,
    /// The direction a scan seen from one side was seen along; `None` for
    /// a surface that wraps round an object.
    view: Option<Point3>,
    /// [`CleanOptions::max_deviation`].
    max_deviation: Option<f64>,
}

/// What the strips need to know of the scan and the options, beyond the
/// loops: the direction a scan seen from one side was seen along (`None`
/// for a surface that wraps round an object), and
/// [`CleanOptions::max_deviation`].
#[derive(Debug, Clone, Copy)]
struct Shaping {
    view: Option<Point3>,
    max_deviation: Option<f64>,
}

/// The new faces of one band.
#[derive(Debug, Default)]
struct Patch {
    /// Loops it replaces.
    loops: Vec<usize>,
    /// Input faces it removes.
    removed: Vec<u32>,
    /// New vertices (smoothed loop vertices).
    vertices: Vec<Point3>,
    /// New faces: ids below the mesh's vertex count are input vertices,
    /// the others `vertex count + index into vertices`.
    faces: Vec<[u32; 3]>,
    /// Whether it removes vertices farther than [`REACH`]·β from its
    /// smoothed loops (more than [`MAX_FAR_REMOVED`]): the band's projection
    /// took surface that turns away beyond a silhouette for a fold to cut. A strip, which needs no
    /// projection, takes its place where one can be made.
    reaches_far: bool,
}

/// One group's outcome: the band of its replaced loops (to detect bands
/// that overlap), their patch, and the loops that stay, with why.
struct Outcome {
    band: Vec<u32>,
    patch: Option<Patch>,
    left: Vec<LeftLoops>,
    /// Whether the patch is a strip.
    strip: bool,
}

/// Replaces every smoothable loop, merging loops whose bands overlap until
/// no two bands share a face.
fn replace_all(cx: &Context) -> Vec<Outcome> {
    let mut groups: Vec<Vec<usize>> = (0..cx.rings.len())
        .filter(|&l| cx.rings[l].is_some())
        .map(|l| vec![l])
        .collect();
    let mut outcomes: Vec<Outcome> = groups
        .par_iter()
        .map(|g| replace_group(cx, g, false))
        .collect();
    // Only the merged group is replaced again: the others do not change.
    while let Some((a, b)) = first_overlap(&outcomes) {
        let taken = groups.remove(b);
        outcomes.remove(b);
        groups[a].extend(taken);
        groups[a].sort_unstable();
        outcomes[a] = replace_group(cx, &groups[a], false);
    }
    outcomes
}

/// Two outcomes whose bands share a face (indices, a < b).
fn first_overlap(outcomes: &[Outcome]) -> Option<(usize, usize)> {
    let mut owner: HashMap<u32, usize> = HashMap::default();
    for (g, outcome) in outcomes.iter().enumerate() {
        for &f in &outcome.band {
            if let Some(&other) = owner.get(&f) {
                return Some((other, g));
            }
            owner.insert(f, g);
        }
    }
    None
}

/// Replaces one group of loops, growing the band while the cut reaches
/// its rim. A loop that cannot be replaced (its band folds, its smoothed
/// loop crosses itself or the kept mesh) is left as it is and the others
/// are tried again without it, so one bad border does not spoil its
/// neighbours. With `check`, a patch that would break the manifold by
/// itself is such a failure too.
fn replace_group(cx: &Context, group: &[usize], check: bool) -> Outcome {
    let mut active = group.to_vec();
    let mut left = Vec::new();
    'attempt: while !active.is_empty() {
        let mut depth = FIRST_DEPTH;
        loop {
            let band = Band::around(cx, &active, depth);
            let failure = match band.replace(cx, &active, check) {
                Ok(mut patch) => {
                    patch.loops = active;
                    return Outcome {
                        band: band.faces,
                        patch: Some(patch),
                        left,
                        strip: false,
                    };
                }
                Err(Retry::Grow(_)) if depth < MAX_DEPTH => {
                    depth = (depth * 3 / 2).min(MAX_DEPTH);
                    continue;
                }
                Err(Retry::Grow(culprits)) => Failure {
                    reason: LeftReason::TooFarFromBorder { rings: MAX_DEPTH },
                    culprits,
                },
                Err(Retry::Leave(failure)) => failure,
            };
            let mut culprits: Vec<usize> = failure
                .culprits
                .iter()
                .filter_map(|&k| active.get(k).copied())
                .collect();
            culprits.sort_unstable();
            culprits.dedup();
            if culprits.is_empty() {
                culprits = active.clone();
            }
            active.retain(|l| !culprits.contains(l));
            left.push(LeftLoops {
                loops: culprits,
                vertices: Vec::new(),
                reason: failure.reason,
            });
            continue 'attempt;
        }
    }
    Outcome {
        band: Vec::new(),
        patch: None,
        left,
        strip: false,
    }
}

/// Why the gap could not be triangulated: walls crossing (with the mesh
/// vertices involved), or anything else.
enum Blocked {
    Walls(Vec<u32>),
    Other(Retry),
}

/// Why a band could not be replaced as it is.
enum Retry {
    /// The cut reaches the band's rim: take more rings. Holds the loops
    /// (positions in the group) whose cut reaches it.
    Grow(Vec<usize>),
    /// Some loops must stay.
    Leave(Failure),
}

/// Why some loops stay: `culprits` are positions in the group (empty when
/// the whole group is concerned).
struct Failure {
    reason: LeftReason,
    culprits: Vec<usize>,
}

fn leave(reason: LeftReason, culprits: Vec<usize>) -> Retry {
    Retry::Leave(Failure { reason, culprits })
}

/// Faces dropped before cleaning, by kind.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct DroppedFaces {
    /// Faces that named a vertex twice.
    slivers: usize,
    /// Faces that repeated an earlier one, corners and turn alike.
    repeats: usize,
}

impl std::ops::Add for DroppedFaces {
    type Output = DroppedFaces;
    fn add(self, more: DroppedFaces) -> DroppedFaces {
        DroppedFaces {
            slivers: self.slivers + more.slivers,
            repeats: self.repeats + more.repeats,
        }
    }
}

/// `mesh` without the faces that add no surface, and how many there were.
///
/// - A face that names a vertex twice (a binary STL's sliver whose two
///   corners coincide becomes one once its vertices are merged) has no
///   area and no border of its own: the faces on either side of it already
///   share its one real edge. Kept, that edge would count twice and read
///   as non-manifold.
/// - A face that repeats an earlier one with the same corners in the same
///   turn (a triangle written twice, as exporters that concatenate patches
///   do) covers the same surface again. Kept, each of its edges would
///   count three times and read as non-manifold. The first copy stays.
///
/// Both are dropped, as MeshLab's "Remove Zero Area Faces" and "Remove
/// Duplicate Faces" would, and counted in the report. Faces of three
/// distinct but collinear vertices stay (they hold the surface together),
/// and so does a face that repeats another's corners in the opposite turn:
/// which of the two agrees with its neighbours is not known here, so the
/// mesh stays as it is and its edges are reported as non-manifold.
/// Returns the edges of the faces that stay, for the manifold check and
/// the border.
fn without_empty_faces(mesh: &Mesh) -> (Cow<'_, Mesh>, DroppedFaces, EdgeRows) {
    let edges = EdgeRows::new(&mesh.faces);
    // A face repeated in the same turn runs its edges twice: where no edge
    // is run twice and every face has three vertices, none goes (the usual
    // case, without hashing every face).
    if manifold_at_a_glance(mesh, &edges) {
        return (Cow::Borrowed(mesh), DroppedFaces::default(), edges);
    }
    let mut seen = HashSet::with_capacity_and_hasher(mesh.faces.len(), Default::default());
    let mut dropped = DroppedFaces::default();
    let keep: Vec<bool> = mesh
        .faces
        .iter()
        .map(|f| {
            if !distinct(*f) {
                dropped.slivers += 1;
                false
            } else if !seen.insert(lowest_first(*f)) {
                dropped.repeats += 1;
                false
            } else {
                true
            }
        })
        .collect();
    if dropped == DroppedFaces::default() {
        return (Cow::Borrowed(mesh), dropped, edges);
    }
    let mut kept = mesh.clone();
    kept.retain_faces(&keep);
    let edges = EdgeRows::new(&kept.faces);
    (Cow::Owned(kept), dropped, edges)
}

/// Drops each smoothed loop vertex closer than [`MIN_GAP`]·β (in 3D) to
/// the last one kept (and, at the end, to the first), so that the new
/// border's segments are not much shorter than the mesh's edges.
fn even_out(mut ring: Ring) -> Ring {
    ring.even_out(MIN_GAP, |r, i, j| dist2(r.p3[i], r.p3[j]).sqrt());
    ring
}

#[cfg(test)]
mod tests;
