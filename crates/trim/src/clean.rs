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
//! output is never a broken mesh.

use std::borrow::Cow;
use std::collections::BTreeSet;

use crate::hash::{HashMap, HashSet};

use rayon::prelude::*;
use spade::handles::FixedVertexHandle;
use spade::{
    AngleLimit, Point2 as SpadePoint, PositionInTriangulation, RefinementParameters, Triangulation,
};

use crate::edges::cluster::MIN_LOOP_POINTS;
use crate::edges::loop_from_tour;
use crate::error::MeshError;
use crate::frame::fit_plane;
use crate::geom::{cross, dist2, dot, norm2, sub, Point3};
use crate::geom::{median, orient};
use crate::mesh::{lowest_first, Mesh};
use crate::planar::{
    inside_faces, obstacle, untwist, Cdt, Node, Ring, SegmentGrid, Tangle, STEINER,
};
use crate::spatial::neighbours::NeighbourIndex;

/// The segment grid's cells are no smaller than this many β.
const GRID_CELL: f64 = 0.1;
/// Vertices closer than this many β to a smoothed loop are replaced.
const MARGIN: f64 = 0.5;
/// Largest share of a smoothed loop's vertices that untwisting it may drop
/// (where the low-pass filter pulls the two sides of a deep, narrow notch
/// across each other, the notch is cut off).
const MAX_UNTWIST: f64 = 0.15;
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
/// Rings of faces around a border the band starts with …
const FIRST_DEPTH: u32 = 3;
/// … and the most it grows to.
const MAX_DEPTH: u32 = 30;

/// Options of the cleanup.
#[derive(Debug, Clone, PartialEq)]
pub struct CleanOptions {
    /// Move the smoothed border out to the estimated physical edge (off
    /// gives the paper's edges, through the border vertices).
    pub offset: bool,
}

impl Default for CleanOptions {
    fn default() -> Self {
        Self { offset: true }
    }
}

/// Loops left as they were, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct LeftLoops {
    /// Indices of the loops (in the input's border order).
    pub loops: Vec<usize>,
    /// Why they could not be replaced.
    pub reason: String,
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
    /// Input faces that named a vertex twice, dropped before anything else
    /// (see `without_empty_faces`).
    pub slivers_dropped: usize,
    /// Input faces that repeated an earlier face with the same corners in
    /// the same turn, dropped before anything else (see
    /// `without_empty_faces`).
    pub repeated_faces_dropped: usize,
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
    /// Smallest angle of the new faces, in degrees; 0 when no face was
    /// added (`faces_added` is 0).
    pub min_angle_new: f64,
}

/// Replaces the jagged border of `mesh` by its smoothed boundary (see the
/// module doc). `beta` is the local resolution of each vertex (from BPD on
/// the vertices).
pub fn clean_mesh(
    mesh: &Mesh,
    beta: &[f64],
    options: &CleanOptions,
) -> Result<(Mesh, CleanReport), MeshError> {
    mesh.validate()?;
    let faces_in = mesh.faces.len();
    let (kept, dropped) = without_empty_faces(mesh);
    let mesh: &Mesh = &kept;
    check_cleanable(mesh, beta)?;
    let borders = mesh.boundary_loops();
    let rings = smoothed_loops(mesh, beta, &borders, options);
    let report = CleanReport {
        loops_in: borders.len(),
        loops_too_small: rings.iter().filter(|r| r.is_none()).count(),
        faces_in,
        slivers_dropped: dropped.slivers,
        repeated_faces_dropped: dropped.repeats,
        area_in: mesh.area(),
        ..Default::default()
    };
    let mut outcomes = replace_bands(mesh, beta, &borders, &rings);
    let out = assemble_manifold(mesh, &mut outcomes);
    finish(out, &outcomes, report)
}

/// What the cleanup needs of the mesh left once its empty faces are dropped:
/// faces, one β per vertex, every edge used at most twice and never twice
/// the same way.
fn check_cleanable(mesh: &Mesh, beta: &[f64]) -> Result<(), MeshError> {
    if mesh.faces.is_empty() {
        return Err(MeshError::NoFaces);
    }
    if beta.len() != mesh.vertices.len() {
        return Err(MeshError::ResolutionLength {
            values: beta.len(),
            vertices: mesh.vertices.len(),
        });
    }
    check_manifold(mesh)
}

/// Step 2: each border loop smoothed (corners, FFT edges and, with
/// `options.offset`, the outward offset) and evened out, in parallel;
/// None for loops of fewer than [`MIN_LOOP_POINTS`] vertices, too small
/// to smooth.
fn smoothed_loops(
    mesh: &Mesh,
    beta: &[f64],
    borders: &[Vec<u32>],
    options: &CleanOptions,
) -> Vec<Option<Ring>> {
    let index = options.offset.then(|| NeighbourIndex::new(&mesh.vertices));
    borders
        .par_iter()
        .map(|border| {
            (border.len() >= MIN_LOOP_POINTS).then(|| {
                let lp = loop_from_tour(&mesh.vertices, beta, border.clone(), index.as_ref());
                even_out(Ring::from_loop(&lp, beta))
            })
        })
        .collect()
}

/// Steps 3 to 5 for every smoothed loop: its band, what goes and the new
/// faces, one outcome per group of loops whose bands overlap.
fn replace_bands(
    mesh: &Mesh,
    beta: &[f64],
    borders: &[Vec<u32>],
    rings: &[Option<Ring>],
) -> Vec<Outcome> {
    let topology = Topology::new(mesh);
    let context = Context {
        mesh,
        beta,
        borders,
        rings,
        topology: &topology,
        beta_median: median(beta),
    };
    replace_all(&context)
}

/// The input with every patch applied. A safety net: a patch whose faces
/// would make an edge non-manifold (not seen on the test data) is
/// dropped, its loops left, and the rest is assembled again.
fn assemble_manifold(mesh: &Mesh, outcomes: &mut [Outcome]) -> Mesh {
    loop {
        let (out, origin) = assemble(mesh, outcomes);
        let bad = patches_breaking_manifold(&out, &origin);
        if bad.is_empty() {
            return out;
        }
        for g in bad {
            if let Some(patch) = outcomes[g].patch.take() {
                outcomes[g].left.push(LeftLoops {
                    loops: patch.loops,
                    reason: "its new faces would meet others at a non-manifold edge".into(),
                });
            }
        }
    }
}

/// Step 6 and the output's part of the report: what the patches did,
/// unused vertices removed, the result checked, its faces and area.
fn finish(
    mut out: Mesh,
    outcomes: &[Outcome],
    mut report: CleanReport,
) -> Result<(Mesh, CleanReport), MeshError> {
    summarise(outcomes, &out, &mut report);
    out.remove_unused_vertices();
    check_manifold(&out)?;
    report.faces_out = out.faces.len();
    report.area_out = out.area();
    Ok((out, report))
}

/// Everything the band replacement reads.
struct Context<'a> {
    mesh: &'a Mesh,
    beta: &'a [f64],
    borders: &'a [Vec<u32>],
    rings: &'a [Option<Ring>],
    topology: &'a Topology,
    beta_median: f64,
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
}

/// One group's outcome: the band of its replaced loops (to detect bands
/// that overlap), their patch, and the loops that stay, with why.
struct Outcome {
    band: Vec<u32>,
    patch: Option<Patch>,
    left: Vec<LeftLoops>,
}

/// Replaces every smoothable loop, merging loops whose bands overlap until
/// no two bands share a face.
fn replace_all(cx: &Context) -> Vec<Outcome> {
    let mut groups: Vec<Vec<usize>> = (0..cx.rings.len())
        .filter(|&l| cx.rings[l].is_some())
        .map(|l| vec![l])
        .collect();
    let mut outcomes: Vec<Outcome> = groups.par_iter().map(|g| replace_group(cx, g)).collect();
    // Only the merged group is replaced again: the others do not change.
    while let Some((a, b)) = first_overlap(&outcomes) {
        let taken = groups.remove(b);
        outcomes.remove(b);
        groups[a].extend(taken);
        groups[a].sort_unstable();
        outcomes[a] = replace_group(cx, &groups[a]);
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
/// neighbours.
fn replace_group(cx: &Context, group: &[usize]) -> Outcome {
    let mut active = group.to_vec();
    let mut left = Vec::new();
    'attempt: while !active.is_empty() {
        let mut depth = FIRST_DEPTH;
        loop {
            let band = Band::around(cx, &active, depth);
            let failure = match band.replace(cx, &active) {
                Ok(mut patch) => {
                    patch.loops = active;
                    return Outcome {
                        band: band.faces,
                        patch: Some(patch),
                        left,
                    };
                }
                Err(Retry::Grow(_)) if depth < MAX_DEPTH => {
                    depth = (depth * 3 / 2).min(MAX_DEPTH);
                    continue;
                }
                Err(Retry::Grow(culprits)) => Failure {
                    reason: format!(
                        "the smoothed border runs more than {MAX_DEPTH} rings of faces from the mesh border"
                    ),
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
                reason: failure.reason,
            });
            continue 'attempt;
        }
    }
    Outcome {
        band: Vec::new(),
        patch: None,
        left,
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
    reason: String,
    culprits: Vec<usize>,
}

fn leave(reason: impl Into<String>, culprits: Vec<usize>) -> Retry {
    Retry::Leave(Failure {
        reason: reason.into(),
        culprits,
    })
}

/// The faces within some rings of a group's border, projected.
struct Band {
    depth: u32,
    /// Ring distance of each band vertex from the border, and the loop
    /// (position in the group) it is nearest to.
    rings_from_border: HashMap<u32, (u32, usize)>,
    /// Band faces, ascending.
    faces: Vec<u32>,
}

impl Band {
    /// Faces with a vertex less than `depth` rings from the border of the
    /// `group`'s loops.
    fn around(cx: &Context, group: &[usize], depth: u32) -> Band {
        let mut distance: HashMap<u32, (u32, usize)> = HashMap::default();
        for (k, &l) in group.iter().enumerate() {
            for &v in &cx.borders[l] {
                distance.entry(v).or_insert((0, k));
            }
        }
        let mut frontier: Vec<u32> = distance.keys().copied().collect();
        frontier.sort_unstable();
        for d in 1..=depth {
            let mut next = Vec::new();
            for &v in &frontier {
                let origin = distance[&v].1;
                for &f in cx.topology.faces_of(v) {
                    for w in cx.mesh.faces[f as usize] {
                        distance.entry(w).or_insert_with(|| {
                            next.push(w);
                            (d, origin)
                        });
                    }
                }
            }
            next.sort_unstable();
            frontier = next;
        }
        let faces: BTreeSet<u32> = distance
            .iter()
            .filter(|&(_, &(d, _))| d < depth)
            .flat_map(|(&v, _)| cx.topology.faces_of(v).iter().copied())
            .collect();
        Band {
            depth,
            rings_from_border: distance,
            faces: faces.into_iter().collect(),
        }
    }

    /// The patch replacing the group's loops, or why not: the smoothed
    /// loops in the band's projection (steps 2 and 3), what goes (step 4)
    /// and the gap filled (step 5).
    fn replace(&self, cx: &Context, group: &[usize]) -> Result<Patch, Retry> {
        let mesh = cx.mesh;
        let projection = Projection::of(cx, &self.faces);
        let mut rings = projected_rings(cx, group, &projection);
        let (grid, _) = untwist(&mut rings, GRID_CELL * cx.beta_median, MAX_UNTWIST)
            .map_err(|tangle| untwist_failure(tangle, &rings))?;
        let stay = self.staying_vertices(cx, group, &projection, &grid, &rings);
        let removed = self.cut_faces(mesh, &projection, &grid, &stay);
        let turned = self.turned_faces(mesh, &projection);
        let removed = with_turned_neighbours(mesh, removed, &turned, |f| self.is_inner(mesh, f));
        let gap = Gap {
            border_edges: group_border_edges(cx, group),
            folded: turned
                .iter()
                .flat_map(|&f| mesh.faces[f as usize])
                .collect(),
            projection,
            rings,
            stay,
        };
        self.fill_gap(cx, &gap, removed)
    }

    /// Whether each vertex of the band's faces stays: it lies on the
    /// surface's side of the smoothed loops (inside an odd number of them
    /// when one is an outer border, of positive area; an even number when
    /// all are holes), farther than [`MARGIN`]·βᵢ from them (closer, it
    /// would only make a sliver against the new border), and is not a
    /// vertex of the group's old border.
    fn staying_vertices(
        &self,
        cx: &Context,
        group: &[usize],
        projection: &Projection,
        grid: &SegmentGrid,
        rings: &[Ring],
    ) -> HashMap<u32, bool> {
        let mesh = cx.mesh;
        let has_outer = rings.iter().any(|r| r.area() > 0.0);
        let old_border: BTreeSet<u32> = group
            .iter()
            .flat_map(|&l| cx.borders[l].iter().copied())
            .collect();
        let stays = |v: u32| {
            let p = projection.vertex_to2(mesh, v);
            !old_border.contains(&v)
                && grid.parity(p) == has_outer
                && !grid.near(p, MARGIN * cx.beta[v as usize])
        };
        self.faces
            .iter()
            .flat_map(|&f| mesh.faces[f as usize])
            .map(|v| (v, stays(v)))
            .collect()
    }

    /// The band's faces with a vertex that goes, or crossed by a smoothed
    /// loop, ascending.
    fn cut_faces(
        &self,
        mesh: &Mesh,
        projection: &Projection,
        grid: &SegmentGrid,
        stay: &HashMap<u32, bool>,
    ) -> Vec<u32> {
        let p2 = |v: u32| projection.vertex_to2(mesh, v);
        let mut removed = Vec::new();
        for &f in &self.faces {
            let face = mesh.faces[f as usize];
            let all_stay = face.iter().all(|v| stay[v]);
            let crossed =
                all_stay && (0..3).any(|k| grid.crosses(p2(face[k]), p2(face[(k + 1) % 3])));
            if !all_stay || crossed {
                removed.push(f);
            }
        }
        removed
    }

    /// The band's faces that turn over in the projection (a range scan's
    /// skirt across a depth jump at a silhouette, a fold). They go too
    /// when they touch what goes and lie inside the band
    /// ([`with_turned_neighbours`], [`Band::is_inner`]): the gap filling
    /// replaces them by one layer. Kept faces beyond may turn over: the
    /// new faces join them along the walls with opposite edge directions
    /// all the same (the safety net of [`assemble_manifold`] checks it).
    fn turned_faces(&self, mesh: &Mesh, projection: &Projection) -> BTreeSet<u32> {
        self.faces
            .iter()
            .copied()
            .filter(|&f| {
                let [a, b, c] = mesh.faces[f as usize].map(|v| projection.vertex_to2(mesh, v));
                orient(a, b, c) <= 0.0
            })
            .collect()
    }

    /// Whether every vertex of face `f` lies more than two rings inside
    /// the band's rim.
    fn is_inner(&self, mesh: &Mesh, f: u32) -> bool {
        mesh.faces[f as usize]
            .iter()
            .all(|v| self.rings_from_border[v].0 + 2 < self.depth)
    }

    /// Step 5 for the faces `removed`. Where a fold beyond the turned
    /// faces makes two walls cross in the projection, the faces round the
    /// crossing go too, and the gap is triangulated again, a few times at
    /// most ([`WALL_REPAIRS`]).
    fn fill_gap(&self, cx: &Context, gap: &Gap, mut removed: Vec<u32>) -> Result<Patch, Retry> {
        for _ in 0..=WALL_REPAIRS {
            let at_rim = self.loops_reaching_rim(cx.mesh, &removed);
            if !at_rim.is_empty() {
                return Err(Retry::Grow(at_rim.into_iter().collect()));
            }
            match self.triangulate_gap(cx, gap, &removed) {
                Ok(mut patch) => {
                    patch.removed = removed;
                    return Ok(patch);
                }
                Err(Blocked::Walls(vertices)) => {
                    let before = removed.len();
                    removed = self.with_faces_round(cx, removed, &vertices);
                    if removed.len() == before {
                        break;
                    }
                }
                Err(Blocked::Other(retry)) => return Err(retry),
            }
        }
        Err(leave(
            "the mesh folds over the new border's plane beside it",
            Vec::new(),
        ))
    }

    /// The loops (positions in the group) whose cut reaches the band's
    /// rim: a removed face has a vertex `depth` − 1 or more rings from the
    /// border.
    fn loops_reaching_rim(&self, mesh: &Mesh, removed: &[u32]) -> BTreeSet<usize> {
        removed
            .iter()
            .flat_map(|&f| mesh.faces[f as usize])
            .map(|v| self.rings_from_border[&v])
            .filter(|&(d, _)| d + 1 >= self.depth)
            .map(|(_, origin)| origin)
            .collect()
    }

    /// The gap left by the faces `removed`, triangulated: bounded by the
    /// smoothed loops and the walls, with the kept vertices of the removed
    /// faces (not those of the fold's second layer) inside.
    fn triangulate_gap(&self, cx: &Context, gap: &Gap, removed: &[u32]) -> Result<Patch, Blocked> {
        let mesh = cx.mesh;
        let walls = walls(mesh, &self.faces, removed, &gap.border_edges, &gap.stay);
        let free: BTreeSet<u32> = removed
            .iter()
            .flat_map(|&f| mesh.faces[f as usize])
            .filter(|v| gap.stay[v] && !gap.folded.contains(v))
            .collect();
        triangulate(
            mesh,
            &gap.projection,
            &gap.rings,
            &walls,
            &free,
            cx.beta_median,
        )
    }

    /// `removed` and the band's faces round `vertices` (where two walls
    /// cross), ascending.
    fn with_faces_round(&self, cx: &Context, removed: Vec<u32>, vertices: &[u32]) -> Vec<u32> {
        let mut all: BTreeSet<u32> = removed.into_iter().collect();
        all.extend(
            vertices
                .iter()
                .flat_map(|&v| cx.topology.faces_of(v).iter().copied())
                .filter(|&f| self.faces.binary_search(&f).is_ok()),
        );
        all.into_iter().collect()
    }
}

/// What filling one band's gap reads besides the faces removed.
struct Gap {
    projection: Projection,
    /// The smoothed loops, projected and untwisted.
    rings: Vec<Ring>,
    /// Whether each vertex of the band's faces stays.
    stay: HashMap<u32, bool>,
    /// The vertices of turned faces: they belong to a fold's second layer,
    /// so the new faces are made without them.
    folded: BTreeSet<u32>,
    /// The directed edges of the group's old borders.
    border_edges: BTreeSet<(u32, u32)>,
}

/// The group's smoothed loops in the band's projection, with the vertices
/// that coincide there merged.
fn projected_rings(cx: &Context, group: &[usize], projection: &Projection) -> Vec<Ring> {
    group
        .iter()
        .filter_map(|&l| cx.rings[l].as_ref())
        .map(|r| {
            let mut ring = r.clone();
            ring.p2 = ring.p3.iter().map(|&p| projection.to2(p)).collect();
            ring.merge_coincident();
            ring
        })
        .collect()
}

/// The directed edges of the borders of the group's loops.
fn group_border_edges(cx: &Context, group: &[usize]) -> BTreeSet<(u32, u32)> {
    group
        .iter()
        .flat_map(|&l| {
            let b = &cx.borders[l];
            (0..b.len()).map(move |i| (b[i], b[(i + 1) % b.len()]))
        })
        .collect()
}

/// The edges (directed as the removed faces run them) that bound the removed region against what stays: shared with a kept
/// face, or on the border of a loop outside the group.
fn walls(
    mesh: &Mesh,
    band: &[u32],
    removed: &[u32],
    group_border: &BTreeSet<(u32, u32)>,
    stay: &HashMap<u32, bool>,
) -> Vec<[u32; 2]> {
    let removed_set: BTreeSet<u32> = removed.iter().copied().collect();
    let mut uses: HashMap<(u32, u32), Vec<u32>> = HashMap::default();
    for &f in band {
        let face = mesh.faces[f as usize];
        for k in 0..3 {
            let (a, b) = (face[k], face[(k + 1) % 3]);
            uses.entry((a.min(b), a.max(b))).or_default().push(f);
        }
    }
    let mut walls = Vec::new();
    for &f in removed {
        let face = mesh.faces[f as usize];
        for k in 0..3 {
            let (a, b) = (face[k], face[(k + 1) % 3]);
            let others: Vec<u32> = uses[&(a.min(b), a.max(b))]
                .iter()
                .copied()
                .filter(|&g| g != f)
                .collect();
            let wall = match others.first() {
                Some(g) => !removed_set.contains(g),
                // The border of a loop outside the group (too small, or
                // left): it bounds the new faces where it stays, and is
                // absorbed where the new border takes its vertices.
                None => !group_border.contains(&(a, b)) && stay[&a] && stay[&b],
            };
            if wall {
                walls.push([a, b]);
            }
        }
    }
    walls
}

/// The constrained Delaunay triangulation of the band's gap (step 5).
fn triangulate(
    mesh: &Mesh,
    projection: &Projection,
    rings: &[Ring],
    walls: &[[u32; 2]],
    free: &BTreeSet<u32>,
    scale: f64,
) -> Result<Patch, Blocked> {
    let mut gap = GapTriangulation::new(mesh);
    let ring_handles = gap.insert_rings(rings).map_err(Blocked::Other)?;
    gap.insert_mesh_vertices(mesh, projection, walls, free)
        .map_err(Blocked::Other)?;
    gap.constrain_rings(&ring_handles)?;
    gap.constrain_walls(walls)?;
    refine_gap(&mut gap.cdt, mesh, &mut gap.patch, scale);
    Ok(gap.into_patch())
}

/// A gap's triangulation as it is built: its vertices are the smoothed
/// loops' (new vertices of the patch) and mesh vertices, each inserted
/// once under its id.
struct GapTriangulation {
    cdt: Cdt,
    patch: Patch,
    handle_of: HashMap<u32, FixedVertexHandle>,
    /// The mesh's vertex count: ids from here on are the patch's vertices.
    n: u32,
}

impl GapTriangulation {
    fn new(mesh: &Mesh) -> Self {
        GapTriangulation {
            cdt: Cdt::new(),
            patch: Patch::default(),
            handle_of: HashMap::default(),
            n: mesh.vertices.len() as u32,
        }
    }

    /// Inserts vertex `id` at `p`, or gives its handle if it is in. Two
    /// vertices at the same place cannot both be vertices of the new
    /// faces: the loop `ring` is left (or, for a mesh vertex, the group).
    fn insert(
        &mut self,
        p: [f64; 2],
        id: u32,
        ring: Option<usize>,
    ) -> Result<FixedVertexHandle, Retry> {
        if let Some(&h) = self.handle_of.get(&id) {
            return Ok(h);
        }
        if let PositionInTriangulation::OnVertex(_) = self.cdt.locate(crate::planar::point(p)) {
            return Err(coincide(ring));
        }
        let h = self
            .cdt
            .insert(Node::new(p, id))
            .map_err(|_| coincide(ring))?;
        self.handle_of.insert(id, h);
        Ok(h)
    }

    /// Inserts every smoothed loop's vertices as new vertices of the
    /// patch; their handles, loop by loop.
    fn insert_rings(&mut self, rings: &[Ring]) -> Result<Vec<Vec<FixedVertexHandle>>, Retry> {
        let mut ring_handles = Vec::new();
        for (k, ring) in rings.iter().enumerate() {
            let mut hs = Vec::with_capacity(ring.len());
            for (j, &p) in ring.p2.iter().enumerate() {
                let id = self.n + self.patch.vertices.len() as u32;
                self.patch.vertices.push(ring.p3[j]);
                hs.push(self.insert(p, id, Some(k))?);
            }
            ring_handles.push(hs);
        }
        Ok(ring_handles)
    }

    /// Inserts the walls' vertices, then the free vertices, ascending.
    fn insert_mesh_vertices(
        &mut self,
        mesh: &Mesh,
        projection: &Projection,
        walls: &[[u32; 2]],
        free: &BTreeSet<u32>,
    ) -> Result<(), Retry> {
        let wall_vertices: BTreeSet<u32> = walls.iter().flatten().copied().collect();
        for &v in wall_vertices.iter().chain(free) {
            self.insert(projection.vertex_to2(mesh, v), v, None)?;
        }
        Ok(())
    }

    /// Every segment of the smoothed loops as a constraint.
    fn constrain_rings(&mut self, ring_handles: &[Vec<FixedVertexHandle>]) -> Result<(), Blocked> {
        for (k, hs) in ring_handles.iter().enumerate() {
            for j in 0..hs.len() {
                self.constrain(hs[j], hs[(j + 1) % hs.len()], Some(k))?;
            }
        }
        Ok(())
    }

    /// Every wall as a constraint.
    fn constrain_walls(&mut self, walls: &[[u32; 2]]) -> Result<(), Blocked> {
        for w in walls {
            self.constrain(self.handle_of[&w[0]], self.handle_of[&w[1]], None)?;
        }
        Ok(())
    }

    /// Adds the constraint from `a` to `b` unless a vertex or constraint is
    /// in its way: then a smoothed loop's segment (of loop `ring`) leaves
    /// that loop, and a wall reports the vertices involved, so that the
    /// faces round them can go.
    fn constrain(
        &mut self,
        a: FixedVertexHandle,
        b: FixedVertexHandle,
        ring: Option<usize>,
    ) -> Result<(), Blocked> {
        if let Some(other) = obstacle(&self.cdt, a, b) {
            return Err(match ring {
                Some(k) => {
                    Blocked::Other(leave("the smoothed border crosses the kept mesh", vec![k]))
                }
                None => Blocked::Walls(vec![
                    self.cdt.vertex(a).data().id,
                    self.cdt.vertex(b).data().id,
                    other,
                ]),
            });
        }
        self.cdt.add_constraint(a, b);
        Ok(())
    }

    /// The patch with its faces: those between the constraints (the
    /// parity flood fill of [`inside_faces`]), each turned to run
    /// counter-clockwise in the projection, as the band's unturned faces do.
    fn into_patch(mut self) -> Patch {
        for f in inside_faces(&self.cdt) {
            let vs = self.cdt.face(f).vertices();
            let mut ids = vs.map(|v| v.data().id);
            let p = vs.map(|v| {
                let q = v.position();
                [q.x, q.y]
            });
            if orient(p[0], p[1], p[2]) < 0.0 {
                ids.swap(1, 2);
            }
            self.patch.faces.push(ids);
        }
        self.patch
    }
}

/// Two vertices coincide in the projection: the loop `ring` is left, or,
/// without one, the whole group.
fn coincide(ring: Option<usize>) -> Retry {
    leave(
        "two vertices coincide in the projection of the band",
        ring.into_iter().collect(),
    )
}

/// Where the gap is wide and holds no mesh vertex (a deep notch the
/// smoothed border bridges), its triangles would join border vertices far
/// apart in thin slivers: Delaunay refinement (spade, Ruppert/Chew) adds
/// points inside the new faces until their angles reach [`REFINE_ANGLE`].
/// The constraints are never split (a point on a wall would open a crack
/// against the kept face there). Each added point is lifted onto the
/// plane of the unrefined triangle it falls in, whose corners are points
/// of the surface.
fn refine_gap(cdt: &mut Cdt, mesh: &Mesh, patch: &mut Patch, scale: f64) {
    let n = mesh.vertices.len() as u32;
    let before = cdt.clone();
    let parameters = RefinementParameters::<f64>::new()
        .exclude_outer_faces(true)
        .keep_constraint_edges()
        .with_angle_limit(AngleLimit::from_deg(REFINE_ANGLE))
        .with_min_required_area(REFINE_MIN_AREA * scale * scale)
        .with_max_additional_vertices(4 * before.num_vertices() + 16);
    cdt.refine(parameters);
    let position = |id: u32| {
        if id < n {
            mesh.vertices[id as usize]
        } else {
            patch.vertices[(id - n) as usize]
        }
    };
    let added: Vec<(FixedVertexHandle, Point3)> = cdt
        .fixed_vertices()
        .filter(|&h| cdt.vertex(h).data().id == STEINER)
        .map(|h| (h, lift(&before, cdt.vertex(h).position(), &position)))
        .collect();
    for (h, p) in added {
        cdt.vertex_data_mut(h).id = n + patch.vertices.len() as u32;
        patch.vertices.push(p);
    }
}

/// The 3D point of the surface at `p` of the unrefined triangulation: the
/// barycentric blend of its triangle's (or edge's) corners.
fn lift(cdt: &Cdt, p: SpadePoint<f64>, position: &impl Fn(u32) -> Point3) -> Point3 {
    let blend = |ids: &[u32], weights: &[f64]| {
        let mut q = [0.0; 3];
        for (&id, &w) in ids.iter().zip(weights) {
            let x = position(id);
            for c in 0..3 {
                q[c] += w * x[c];
            }
        }
        q
    };
    let along = |e: spade::handles::FixedDirectedEdgeHandle| {
        let edge = cdt.directed_edge(e);
        let (a, b) = (edge.from(), edge.to());
        let (pa, pb) = (a.position(), b.position());
        let d = [pb.x - pa.x, pb.y - pa.y];
        let len2 = d[0] * d[0] + d[1] * d[1];
        let t = if len2 > 0.0 {
            (((p.x - pa.x) * d[0] + (p.y - pa.y) * d[1]) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        blend(&[a.data().id, b.data().id], &[1.0 - t, t])
    };
    match cdt.locate(p) {
        PositionInTriangulation::OnVertex(v) => position(cdt.vertex(v).data().id),
        PositionInTriangulation::OnEdge(e) | PositionInTriangulation::OutsideOfConvexHull(e) => {
            along(e)
        }
        PositionInTriangulation::OnFace(f) => {
            let vs = cdt.face(f).vertices();
            let [a, b, c] = vs.map(|v| {
                let q = v.position();
                [q.x, q.y]
            });
            let area = orient(a, b, c);
            let q = [p.x, p.y];
            let weights = [
                orient(q, b, c) / area,
                orient(a, q, c) / area,
                orient(a, b, q) / area,
            ];
            blend(&vs.map(|v| v.data().id), &weights)
        }
        PositionInTriangulation::NoTriangulation => position(0),
    }
}

/// The best-fit plane of a band, oriented with its faces.
struct Projection {
    origin: Point3,
    u: Point3,
    v: Point3,
}

impl Projection {
    /// Fits the band's plane, oriented so the faces face its normal.
    fn of(cx: &Context, faces: &[u32]) -> Projection {
        let mesh = cx.mesh;
        let origin = mesh.vertices[mesh.faces[faces[0] as usize][0] as usize];
        // The area-weighted mean face normal, not the best-fit plane: a
        // range scan faces its scanner everywhere, so every face projects
        // the right way up along the mean normal even where a band that
        // curves round a silhouette has a best-fit plane at a steep angle.
        let sum = faces.iter().fold([0.0; 3], |acc, &f| {
            let n = face_normal(mesh, f);
            [acc[0] + n[0], acc[1] + n[1], acc[2] + n[2]]
        });
        let length = norm2(sum).sqrt();
        let normal = if length > 0.0 {
            sum.map(|c| c / length)
        } else {
            let members: Vec<u32> = faces.iter().flat_map(|&f| mesh.faces[f as usize]).collect();
            fit_plane(&mesh.vertices, &members).normal
        };
        // Any tangent axis: the coordinate axis least aligned with n.
        let axis = (0..3)
            .min_by(|&a, &b| normal[a].abs().total_cmp(&normal[b].abs()))
            .unwrap_or(0);
        let mut e = [0.0; 3];
        e[axis] = 1.0;
        let u = cross(normal, e);
        let u = u.map(|c| c / norm2(u).sqrt());
        Projection {
            origin,
            u,
            v: cross(normal, u),
        }
    }

    fn to2(&self, p: Point3) -> [f64; 2] {
        let d = sub(p, self.origin);
        [dot(d, self.u), dot(d, self.v)]
    }

    /// The projection of the mesh's vertex `v`.
    fn vertex_to2(&self, mesh: &Mesh, v: u32) -> [f64; 2] {
        self.to2(mesh.vertices[v as usize])
    }
}

fn face_normal(mesh: &Mesh, f: u32) -> Point3 {
    let [a, b, c] = mesh.faces[f as usize].map(|i| mesh.vertices[i as usize]);
    cross(sub(b, a), sub(c, a))
}

/// The input with every patch applied, and for each output face the
/// outcome whose patch made it (`None` for input faces).
fn assemble(mesh: &Mesh, outcomes: &[Outcome]) -> (Mesh, Vec<Option<usize>>) {
    let n = mesh.vertices.len() as u32;
    let mut removed = vec![false; mesh.faces.len()];
    let mut vertices = mesh.vertices.clone();
    let mut new_faces = Vec::new();
    for (g, outcome) in outcomes.iter().enumerate() {
        let Some(patch) = &outcome.patch else {
            continue;
        };
        for &f in &patch.removed {
            removed[f as usize] = true;
        }
        let base = vertices.len() as u32;
        vertices.extend_from_slice(&patch.vertices);
        for face in &patch.faces {
            new_faces.push((g, face.map(|id| if id < n { id } else { base + id - n })));
        }
    }
    let mut faces: Vec<[u32; 3]> = Vec::with_capacity(mesh.faces.len() + new_faces.len());
    let mut origin = Vec::with_capacity(faces.capacity());
    for (f, _) in mesh.faces.iter().zip(&removed).filter(|(_, &r)| !r) {
        faces.push(*f);
        origin.push(None);
    }
    for (g, f) in new_faces {
        faces.push(f);
        origin.push(Some(g));
    }
    (Mesh { vertices, faces }, origin)
}

/// The outcomes whose new faces use an edge more than twice or twice the
/// same way.
fn patches_breaking_manifold(mesh: &Mesh, origin: &[Option<usize>]) -> BTreeSet<usize> {
    let mut bad = BTreeSet::new();
    for_each_edge(mesh, |faces, forward, backward| {
        if forward > 1 || backward > 1 {
            bad.extend(faces.iter().filter_map(|e| origin[e.2 as usize]));
        }
    });
    bad
}

/// Counts what the applied patches did.
fn summarise(outcomes: &[Outcome], out: &Mesh, report: &mut CleanReport) {
    let mut min_angle = f64::INFINITY;
    for outcome in outcomes {
        report.loops_left.extend(outcome.left.iter().cloned());
        if let Some(patch) = &outcome.patch {
            report.loops_smoothed += patch.loops.len();
            report.faces_removed += patch.removed.len();
            report.faces_added += patch.faces.len();
            report.vertices_added += patch.vertices.len();
        }
    }
    let new_faces = &out.faces[out.faces.len() - report.faces_added..];
    for &face in new_faces {
        min_angle = min_angle.min(smallest_angle(&out.vertices, face));
    }
    report.min_angle_new = if min_angle.is_finite() {
        min_angle
    } else {
        0.0
    };
}

/// Smallest angle of a triangle, in degrees.
fn smallest_angle(vertices: &[Point3], face: [u32; 3]) -> f64 {
    let p = face.map(|i| vertices[i as usize]);
    (0..3)
        .map(|k| {
            let (a, b) = (sub(p[(k + 1) % 3], p[k]), sub(p[(k + 2) % 3], p[k]));
            let c = dot(a, b) / (norm2(a) * norm2(b)).sqrt();
            c.clamp(-1.0, 1.0).acos().to_degrees()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Faces dropped before cleaning, by kind.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct DroppedFaces {
    /// Faces that named a vertex twice.
    slivers: usize,
    /// Faces that repeated an earlier one, corners and turn alike.
    repeats: usize,
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
fn without_empty_faces(mesh: &Mesh) -> (Cow<'_, Mesh>, DroppedFaces) {
    let distinct = |f: &[u32; 3]| f[0] != f[1] && f[1] != f[2] && f[2] != f[0];
    let mut seen = HashSet::with_capacity_and_hasher(mesh.faces.len(), Default::default());
    let mut dropped = DroppedFaces::default();
    let keep: Vec<bool> = mesh
        .faces
        .iter()
        .map(|f| {
            if !distinct(f) {
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
        return (Cow::Borrowed(mesh), dropped);
    }
    let mut kept = mesh.clone();
    kept.retain_faces(&keep);
    (Cow::Owned(kept), dropped)
}

/// Edge-manifold with consistent orientation: every undirected edge used
/// at most twice, every directed edge at most once.
fn check_manifold(mesh: &Mesh) -> Result<(), MeshError> {
    let (over, misoriented) = edge_defects(mesh);
    if over > 0 {
        return Err(MeshError::NonManifold { edges: over });
    }
    if misoriented > 0 {
        return Err(MeshError::Misoriented { edges: misoriented });
    }
    Ok(())
}

/// The undirected edges used by more than two faces, and the directed
/// edges used more than once (two faces that meet there turn opposite
/// ways).
fn edge_defects(mesh: &Mesh) -> (usize, usize) {
    let (mut over, mut misoriented) = (0, 0);
    for_each_edge(mesh, |faces, forward, backward| {
        over += usize::from(faces.len() > 2);
        misoriented += usize::from(forward > 1) + usize::from(backward > 1);
    });
    (over, misoriented)
}

/// Calls `visit` for every undirected edge of `mesh` with its entries in
/// [`Mesh::sorted_edges`] (one per use: smaller vertex, larger, face) and
/// how many times faces run along it from the smaller vertex to the
/// larger and back. Sorted edges are a counting sort, several times
/// faster than hashing every edge.
fn for_each_edge(mesh: &Mesh, mut visit: impl FnMut(&[(u32, u32, u32)], usize, usize)) {
    let edges = mesh.sorted_edges();
    for run in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        let (a, b) = (run[0].0, run[0].1);
        let (mut forward, mut backward) = (0, 0);
        for (i, &(_, _, f)) in run.iter().enumerate() {
            // A face holds the edge once per entry; count its turns once.
            if run[..i].iter().any(|e| e.2 == f) {
                continue;
            }
            let face = mesh.faces[f as usize];
            for k in 0..3 {
                let step = (face[k], face[(k + 1) % 3]);
                forward += usize::from(step == (a, b));
                backward += usize::from(a != b && step == (b, a));
            }
        }
        visit(run, forward, backward);
    }
}

/// The faces around each vertex (compressed rows).
struct Topology {
    start: Vec<u32>,
    faces: Vec<u32>,
}

impl Topology {
    fn new(mesh: &Mesh) -> Self {
        let mut count = vec![0u32; mesh.vertices.len() + 1];
        for f in &mesh.faces {
            for &v in f {
                count[v as usize + 1] += 1;
            }
        }
        for i in 1..count.len() {
            count[i] += count[i - 1];
        }
        let mut fill = count.clone();
        let mut faces = vec![0; count[mesh.vertices.len()] as usize];
        for (i, f) in mesh.faces.iter().enumerate() {
            for &v in f {
                faces[fill[v as usize] as usize] = i as u32;
                fill[v as usize] += 1;
            }
        }
        Topology {
            start: count,
            faces,
        }
    }

    /// The faces round vertex `v`; none for a vertex the mesh does not
    /// have (a patch's new smoothed-loop vertex, which a blocked wall can
    /// name).
    fn faces_of(&self, v: u32) -> &[u32] {
        match (self.start.get(v as usize), self.start.get(v as usize + 1)) {
            (Some(&from), Some(&to)) => &self.faces[from as usize..to as usize],
            _ => &[],
        }
    }
}

/// The loop to leave when the smoothed loops cross: the one that crosses
/// itself, or the smaller of two that cross each other.
fn untwist_failure(tangle: Tangle, rings: &[Ring]) -> Retry {
    match tangle {
        Tangle::SelfCrossing {
            index,
            vertices,
            dropped,
        } => leave(
            format!(
                "its smoothed loop crosses itself in the band's projection (untwisting it would drop {dropped} of its {vertices} vertices)"
            ),
            vec![index],
        ),
        Tangle::Crossing { a, b } => {
            let smaller = if rings[a].len() <= rings[b].len() { a } else { b };
            leave(
                "its smoothed loop crosses the smoothed loop of another border",
                vec![smaller],
            )
        }
    }
}

/// `removed` and every turned face connected to it through turned faces
/// (sharing a vertex), ascending.
fn with_turned_neighbours(
    mesh: &Mesh,
    removed: Vec<u32>,
    turned: &BTreeSet<u32>,
    inner: impl Fn(u32) -> bool,
) -> Vec<u32> {
    let mut by_vertex: HashMap<u32, Vec<u32>> = HashMap::default();
    for &f in turned {
        for v in mesh.faces[f as usize] {
            by_vertex.entry(v).or_default().push(f);
        }
    }
    let mut all: BTreeSet<u32> = removed.iter().copied().collect();
    let mut stack = removed;
    while let Some(f) = stack.pop() {
        for v in mesh.faces[f as usize] {
            for &g in by_vertex.get(&v).map_or(&[][..], Vec::as_slice) {
                if inner(g) && all.insert(g) {
                    stack.push(g);
                }
            }
        }
    }
    all.into_iter().collect()
}

/// Drops each smoothed loop vertex closer than [`MIN_GAP`]·β to the last
/// one kept (and, at the end, to the first), so that the new border's
/// segments are not much shorter than the mesh's edges.
fn even_out(mut ring: Ring) -> Ring {
    let m = ring.p3.len();
    if m < 2 * MIN_LOOP_POINTS {
        return ring;
    }
    let mut keep = vec![true; m];
    let mut last = 0;
    for (j, kept) in keep.iter_mut().enumerate().skip(1) {
        let gap = MIN_GAP * ring.beta[j];
        let close = dist2(ring.p3[j], ring.p3[last]).sqrt() < gap;
        let closing = dist2(ring.p3[j], ring.p3[0]).sqrt() < gap;
        if close || closing {
            *kept = false;
        } else {
            last = j;
        }
    }
    if keep.iter().filter(|&&k| k).count() >= MIN_LOOP_POINTS {
        let mut k = keep.iter();
        ring.p3.retain(|_| *k.next().unwrap_or(&true));
        let mut k = keep.iter();
        ring.reference.retain(|_| *k.next().unwrap_or(&true));
        let mut k = keep.iter();
        ring.beta.retain(|_| *k.next().unwrap_or(&true));
    }
    ring
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// [`edge_defects`] by hashing every edge: the plain way, kept as the
    /// reference.
    fn edge_defects_reference(mesh: &Mesh) -> (usize, usize) {
        let mut directed: HashMap<(u32, u32), u32> = HashMap::default();
        let mut undirected: HashMap<(u32, u32), u32> = HashMap::default();
        for f in &mesh.faces {
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                *directed.entry((a, b)).or_insert(0) += 1;
                *undirected.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        (
            undirected.values().filter(|&&c| c > 2).count(),
            directed.values().filter(|&&c| c > 1).count(),
        )
    }

    /// [`patches_breaking_manifold`] by hashing every directed edge: the
    /// plain way, kept as the reference.
    fn patches_breaking_manifold_reference(
        mesh: &Mesh,
        origin: &[Option<usize>],
    ) -> BTreeSet<usize> {
        let mut directed: HashMap<(u32, u32), Vec<usize>> = HashMap::default();
        for (i, f) in mesh.faces.iter().enumerate() {
            for k in 0..3 {
                directed.entry((f[k], f[(k + 1) % 3])).or_default().push(i);
            }
        }
        let mut bad = BTreeSet::new();
        for (&(a, b), faces) in &directed {
            let reverse = directed.get(&(b, a)).map_or(0, Vec::len);
            if faces.len() > 1 || reverse > 1 {
                bad.extend(faces.iter().filter_map(|&i| origin[i]));
            }
        }
        bad
    }

    /// The sorted-edge counts and the patches they blame agree with the
    /// hashed ones on random faces over few vertices: repeated, reversed
    /// and fanned faces, and faces naming a vertex twice or three times.
    #[test]
    fn edge_defects_match_the_reference() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(20);
        for case in 0..2000 {
            let vertices = rng.random_range(3..9u32);
            let faces = (0..rng.random_range(1..25))
                .map(|_| [0; 3].map(|_| rng.random_range(0..vertices)))
                .collect();
            let mesh = Mesh {
                vertices: vec![[0.0; 3]; vertices as usize],
                faces,
            };
            assert_eq!(
                edge_defects(&mesh),
                edge_defects_reference(&mesh),
                "case {case}: {mesh:?}"
            );
            let origin: Vec<Option<usize>> = (0..mesh.faces.len())
                .map(|_| rng.random_bool(0.7).then(|| rng.random_range(0..4)))
                .collect();
            assert_eq!(
                patches_breaking_manifold(&mesh, &origin),
                patches_breaking_manifold_reference(&mesh, &origin),
                "case {case}: {mesh:?}"
            );
        }
    }
    use crate::bpd::{detect_boundary, BpdOptions};
    use spade::{DelaunayTriangulation, Point2 as SpadePoint};
    use testkit::SplitMix64;

    /// A jittered grid of pitch 1 over a disc of radius `r` with a hole of
    /// radius `hole` at the centre, triangulated by Delaunay, keeping the
    /// triangles whose centroid lies in the annulus: a jagged scan border.
    fn jagged_annulus(r: f64, hole: f64, seed: u64) -> Mesh {
        let mut rng = SplitMix64::new(seed);
        let mut points = Vec::new();
        let m = r.ceil() as i64 + 1;
        for j in -m..=m {
            for i in -m..=m {
                let p = [
                    i as f64 + rng.range(-0.3, 0.3),
                    j as f64 + rng.range(-0.3, 0.3),
                ];
                let d = (p[0] * p[0] + p[1] * p[1]).sqrt();
                if d <= r && d >= hole {
                    points.push(p);
                }
            }
        }
        let mut dt: DelaunayTriangulation<SpadePoint<f64>> = DelaunayTriangulation::new();
        for p in &points {
            dt.insert(SpadePoint::new(p[0], p[1])).unwrap();
        }
        let vertices: Vec<Point3> = dt
            .vertices()
            .map(|v| [v.position().x, v.position().y, 0.1 * v.position().x])
            .collect();
        let faces = dt
            .inner_faces()
            .map(|f| f.vertices().map(|v| v.fix().index() as u32))
            .filter(|f| {
                let c = f.iter().fold([0.0, 0.0], |c, &v| {
                    [
                        c[0] + vertices[v as usize][0] / 3.0,
                        c[1] + vertices[v as usize][1] / 3.0,
                    ]
                });
                let d = (c[0] * c[0] + c[1] * c[1]).sqrt();
                d < r && d > hole
            })
            .collect();
        let mut mesh = Mesh { vertices, faces };
        mesh.remove_unused_vertices();
        mesh
    }

    /// Mean and largest distance of the border vertices to the true
    /// circles (radii `r` and `hole`, in the x-y projection; the surface
    /// z = 0.1·x stretches x by under 0.5 %).
    fn border_error(mesh: &Mesh, r: f64, hole: f64) -> (f64, f64) {
        let loops = mesh.boundary_loops();
        let d: Vec<f64> = loops
            .iter()
            .flatten()
            .map(|&v| {
                let p = mesh.vertices[v as usize];
                let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
                (rho - r).abs().min((rho - hole).abs())
            })
            .collect();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        (mean, d.iter().copied().fold(0.0, f64::max))
    }

    fn clean(mesh: &Mesh) -> (Mesh, CleanReport) {
        let detection = detect_boundary(&mesh.vertices, &BpdOptions::default()).unwrap();
        clean_mesh(mesh, &detection.beta, &CleanOptions::default()).unwrap()
    }

    #[test]
    fn a_jagged_annulus_gets_its_circles_back() {
        let mesh = jagged_annulus(20.0, 6.0, 7);
        let (before_mean, _) = border_error(&mesh, 20.0, 6.0);
        let (out, report) = clean(&mesh);
        let (after_mean, after_max) = border_error(&out, 20.0, 6.0);
        assert_eq!(report.loops_in, 2, "{report:?}");
        assert_eq!(report.loops_smoothed, 2, "{report:?}");
        assert_eq!(out.boundary_loops().len(), 2);
        // Measured: 0.20 pitch before, 0.15 after (the jagged border's
        // vertices are on the true circle's side of the samples; its
        // straight edges cut the corners, which vertices alone do not see).
        assert!(
            after_mean < 0.8 * before_mean,
            "before {before_mean}, after {after_mean}"
        );
        assert!(after_mean < 0.2, "after {after_mean}");
        let truth = std::f64::consts::PI * (20.0f64.powi(2) - 6.0f64.powi(2));
        let error = |a: f64| (a - truth).abs() / truth;
        assert!(
            error(report.area_out) < 0.5 * error(report.area_in),
            "{report:?}"
        );
        assert!(after_max < 1.0, "{after_max}");
        assert!(report.min_angle_new > 5.0, "{report:?}");
        check_manifold(&out).unwrap();
    }

    /// A closed surface has no border: it comes back as it was.
    #[test]
    fn a_closed_mesh_is_returned_unchanged() {
        let vertices = vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let faces = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        let mesh = Mesh { vertices, faces };
        let (out, report) = clean_mesh(&mesh, &[1.0; 6], &CleanOptions::default()).unwrap();
        assert_eq!(out, mesh);
        assert_eq!(report.loops_in, 0);
        assert_eq!(report.faces_out, 8);
    }

    /// Misoriented and non-manifold meshes, and resolutions that do not
    /// match the vertices, are clear errors.
    #[test]
    fn bad_topology_is_an_error() {
        let mesh = jagged_annulus(8.0, 3.0, 3);
        assert!(matches!(
            clean_mesh(&mesh, &[1.0; 3], &CleanOptions::default()),
            Err(MeshError::ResolutionLength { values: 3, .. })
        ));
        let mut mesh = jagged_annulus(8.0, 3.0, 3);
        let beta = vec![1.0; mesh.vertices.len()];
        mesh.faces[0].swap(1, 2);
        assert!(matches!(
            clean_mesh(&mesh, &beta, &CleanOptions::default()),
            Err(MeshError::Misoriented { .. })
        ));
        let mut mesh = jagged_annulus(8.0, 3.0, 3);
        let f = mesh.faces[0];
        mesh.vertices.push([0.0, 0.0, 5.0]);
        let apex = mesh.vertices.len() as u32 - 1;
        mesh.faces.push([f[0], f[1], apex]);
        assert!(matches!(
            clean_mesh(
                &mesh,
                &vec![1.0; mesh.vertices.len()],
                &CleanOptions::default()
            ),
            Err(MeshError::NonManifold { .. })
        ));
    }

    /// A jagged annulus, its β, the default options and its cleaned mesh:
    /// what the tests of faces to drop compare against.
    fn annulus_cleaned() -> (Mesh, Vec<f64>, CleanOptions, Mesh) {
        let mesh = jagged_annulus(8.0, 3.0, 3);
        let beta = vec![1.0; mesh.vertices.len()];
        let options = CleanOptions::default();
        let (cleaned, _) = clean_mesh(&mesh, &beta, &options).unwrap();
        (mesh, beta, options, cleaned)
    }

    /// Faces with two equal corners (a binary STL's sliver, merged) are
    /// dropped and counted, neither reported as non-manifold edges nor an
    /// error of their own that stops the cleanup. The rest of the mesh is
    /// cleaned exactly as it would be without them.
    #[test]
    fn faces_naming_a_vertex_twice_are_dropped() {
        let (mesh, beta, options, want) = annulus_cleaned();
        let mut with_slivers = mesh.clone();
        let [a, b, _] = mesh.faces[5];
        let [c, d, _] = mesh.faces[9];
        with_slivers.faces.insert(3, [a, b, a]);
        with_slivers.faces.push([c, d, d]);
        with_slivers.faces.push([c, c, c]);
        let (got, report) = clean_mesh(&with_slivers, &beta, &options).unwrap();
        assert_eq!(got, want);
        assert_eq!(report.slivers_dropped, 3);
        assert_eq!(report.faces_in, mesh.faces.len() + 3);
    }

    /// A face written twice with the same corners in the same turn is
    /// dropped and counted (not read as 3 non-manifold edges); one in the
    /// opposite turn stays, and its edges are still reported.
    #[test]
    fn repeated_faces_are_dropped_when_they_turn_the_same_way() {
        let (mesh, beta, options, want) = annulus_cleaned();
        let mut repeated = mesh.clone();
        let [a, b, c] = mesh.faces[5];
        repeated.faces.push([b, c, a]);
        repeated.faces.push(mesh.faces[9]);
        repeated.faces.push([c, a, b]);
        let (got, report) = clean_mesh(&repeated, &beta, &options).unwrap();
        assert_eq!(got, want);
        assert_eq!(report.repeated_faces_dropped, 3);
        assert_eq!(report.slivers_dropped, 0);
        let mut reversed = mesh.clone();
        reversed.faces.push([a, c, b]);
        assert!(matches!(
            clean_mesh(&reversed, &beta, &options),
            Err(MeshError::NonManifold { .. })
        ));
    }

    /// A mesh of slivers alone has no faces to clean.
    #[test]
    fn a_mesh_of_slivers_alone_has_no_faces() {
        let mesh = Mesh {
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            faces: vec![[0, 1, 1], [2, 2, 0]],
        };
        assert_eq!(
            clean_mesh(&mesh, &[1.0; 3], &CleanOptions::default()).unwrap_err(),
            MeshError::NoFaces
        );
    }
}
