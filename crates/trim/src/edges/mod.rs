//! Edge reconstruction — the paper's RBS algorithm (section 3): from
//! labelled boundary points to smooth, closed boundary edges.
//!
//! 1. [`cluster`] groups the boundary points into separate boundaries by the
//!    links BPD found between them and thins spurs away;
//! 2. [`order`] turns each group into a closed tour; [`split`] cuts a tour
//!    that jumps across the surface (two borders in one group) into loops
//!    that follow the links. For a range scan whose line of sight is known,
//!    [`trace`] takes the place of both steps: the loops are the border of
//!    the cloud's region in the scan's image plane;
//! 3. [`corners`] finds the corners of each loop (section 3.1), which split
//!    it into edges;
//! 4. each edge is smoothed by a spatial low-pass filter (section 3.3);
//! 5. optionally, each smoothed loop is moved out to where the surface
//!    really ends ([`offset`]); not where a traced loop runs along an
//!    occlusion, where the region ends at the samples themselves.

pub mod cluster;
pub mod corners;
pub mod offset;
pub mod order;
pub mod smooth;
pub mod split;
pub mod trace;

mod border;
pub use border::mesh_border_edges;

use rayon::prelude::*;

use crate::bpd::Detection;
use crate::geom::{dist2, sub, Point3};
use crate::spatial::neighbours::{tie_key, KNearest, NeighbourIndex};

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
    /// The surface's side at each boundary point, which the outward offset
    /// used (empty when the offset is off); trimming reuses it.
    pub sides: Vec<offset::EdgeSide>,
}

impl Loop {
    /// The corner points (exact input coordinates).
    pub fn corner_points(&self, points: &[Point3]) -> Vec<Point3> {
        self.corners
            .iter()
            .map(|&c| points[self.boundary_points[c] as usize])
            .collect()
    }

    /// The loop as one closed polyline: each open edge without its last
    /// point, which is the next edge's first (the corner), so that every
    /// corner appears once, with both of its segments. Each vertex comes
    /// with the position in `boundary_points` of the point it was smoothed
    /// from.
    pub(crate) fn closed_polyline(&self) -> Vec<(Point3, usize)> {
        let n = self.boundary_points.len().max(1);
        let mut polyline = Vec::new();
        for (k, edge) in self.edges.iter().enumerate() {
            let from = self.corners.get(k).copied().unwrap_or(0);
            let take = if edge.closed {
                edge.points.len()
            } else {
                edge.points.len().saturating_sub(1)
            };
            let positions = (from..).map(|j| j % n);
            polyline.extend(edge.points.iter().copied().take(take).zip(positions));
        }
        polyline
    }
}

/// Result of edge reconstruction.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Edges {
    /// The loops, in a deterministic order (by smallest point index).
    pub loops: Vec<Loop>,
    /// Groups of boundary points too small or too thin to close a loop,
    /// and pieces of jumping tours that closed no loop of their own.
    pub dropped_clusters: usize,
    /// Boundary points removed as spurs, strays or isolated points, or
    /// left on no loop when a jumping tour was split.
    pub thinned_points: usize,
    /// How the loops were found.
    pub loops_from: LoopSource,
}

/// How edge reconstruction found the loops.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum LoopSource {
    /// From BPD's links: clustered, toured and split where a tour jumps.
    #[default]
    Links,
    /// Traced in the image plane of the detection's view, the scanner's.
    ScannerImage,
    /// Traced in the image plane of the cloud's own best-fit plane, seen
    /// along its unit `normal` (a cloud without a view whose links leave a
    /// ragged border open).
    OwnPlane {
        /// The plane's normal, the direction the image was seen along.
        normal: Point3,
    },
    /// A mesh's own border, not detected ([`mesh_border_edges`]).
    MeshBorder,
}

impl LoopSource {
    /// A short name: `links`, `scanner_image`, `own_plane` or
    /// `mesh_border`.
    pub fn name(self) -> &'static str {
        match self {
            LoopSource::Links => "links",
            LoopSource::ScannerImage => "scanner_image",
            LoopSource::OwnPlane { .. } => "own_plane",
            LoopSource::MeshBorder => "mesh_border",
        }
    }
}

/// Reconstructs the boundary edges of a cloud from its BPD result: loops,
/// corners and smoothed edges (see the module doc for the steps).
pub fn reconstruct_edges(points: &[Point3], detection: &Detection, options: &EdgeOptions) -> Edges {
    if let Some(traced) = trace::traced_loops(points, detection) {
        return edges_of_traced_loops(points, detection, options, traced, LoopSource::ScannerImage);
    }
    let linked = LinkedTours::new(points, detection);
    if detection.view.is_none() && linked.leave_a_ragged_border() {
        if let Some((normal, traced)) = trace::traced_loops_in_own_plane(points, detection) {
            let source = LoopSource::OwnPlane { normal };
            return edges_of_traced_loops(points, detection, options, traced, source);
        }
    }
    Edges {
        loops: loops_of_tours(points, &detection.beta, linked.tours, options, &[]),
        dropped_clusters: linked.dropped_clusters,
        thinned_points: linked.thinned_points,
        loops_from: LoopSource::Links,
    }
}

/// The share of the linked clusters' points that the tours may leave off
/// every loop before a cloud without a view is traced in its own plane.
/// A tour is cut where it jumps across the surface, and the pieces that
/// close no loop are dropped: a ragged band of boundary points, no single
/// cycle of links, loses a large share. Measured (`cargo run --release
/// --example own_plane`, and `bench_bpd`'s clouds): the synthetic clouds and
/// the benchmark's sheets and line scans (12k to 1M points) 0–3.1 %;
/// lato000 9.7 %, the Kinect blades 16 % and 26 %, face000 26 %, milk.pcd
/// 27 %. (Small clusters dropped whole, round gaps of the sampling inside
/// a surface, do not count: their number grows with the surface's area.)
const MAX_SHARE_LEFT_BY_TOURS: f64 = 0.05;

/// The share of the linked clusters' points that the tours of BPD's links
/// leave on no loop (the limit is 5 %). For the
/// test kit's measurements.
pub fn share_left_by_tours(points: &[Point3], detection: &Detection) -> f64 {
    LinkedTours::new(points, detection).share_left()
}

/// The loops found from BPD's links (input indices, in canonical order),
/// with what was left off them.
struct LinkedTours {
    tours: Vec<Vec<u32>>,
    dropped_clusters: usize,
    thinned_points: usize,
    /// Points of the linked clusters (after thinning).
    clustered: usize,
    /// Of those, the points on no loop.
    off_loops: usize,
}

impl LinkedTours {
    /// Clusters the boundary points by their links, tours each cluster,
    /// and splits the tours that jump.
    fn new(points: &[Point3], detection: &Detection) -> Self {
        let canon = CanonicalBoundary::new(points, detection);
        let clusters = cluster::cluster_boundary(&canon.boundary, &canon.links);
        let tours: Vec<Vec<u32>> = clusters
            .clusters
            .par_iter()
            .zip(&clusters.links)
            .map(|(members, links)| order::closed_tour(&canon.points, members, links))
            .collect();
        // A tour that jumps (a step longer than 3β that no link supports) went
        // across the surface between borders its cluster joins: it is cut at
        // its jumps and the pieces are joined again by supported steps only.
        let split: Vec<(Vec<Vec<u32>>, usize)> = tours
            .into_par_iter()
            .zip(&clusters.links)
            .map(|(tour, links)| split::split_at_jumps(&canon.points, &canon.beta, links, tour))
            .collect();
        let dropped_pieces: usize = split.iter().map(|t| t.1).sum();
        let mut tours: Vec<Vec<u32>> = split.into_iter().flat_map(|t| t.0).collect();
        let filled_only = drop_tours_made_by_fillers(&mut tours, |c| canon.detected[c as usize]);
        tours.sort_unstable();
        let on_loops: std::collections::BTreeSet<u32> = tours.iter().flatten().copied().collect();
        let clustered: usize = clusters.clusters.iter().map(Vec::len).sum();
        let off_loops = clustered - on_loops.len();
        let tours = tours
            .into_iter()
            .map(|tour| tour.iter().map(|&c| canon.input[c as usize]).collect())
            .collect();
        LinkedTours {
            tours,
            dropped_clusters: clusters.dropped_clusters + dropped_pieces + filled_only,
            thinned_points: clusters.thinned_points + off_loops,
            clustered,
            off_loops,
        }
    }

    /// The share of the clustered points on no loop.
    fn share_left(&self) -> f64 {
        self.off_loops as f64 / self.clustered.max(1) as f64
    }

    /// Whether the tours leave more than [`MAX_SHARE_LEFT_BY_TOURS`] of
    /// the clustered points off every loop.
    fn leave_a_ragged_border(&self) -> bool {
        self.share_left() > MAX_SHARE_LEFT_BY_TOURS
    }
}

/// Corners and smoothed edges of the loops traced in a scan's image plane
/// ([`trace`]). As with tours, a loop needs [`cluster::MIN_LOOP_POINTS`]
/// points that BPD labelled boundary; the loops are numbered, started and
/// oriented by their points' geometry (see [`CanonicalBoundary`]).
fn edges_of_traced_loops(
    points: &[Point3],
    detection: &Detection,
    options: &EdgeOptions,
    traced: trace::Traced,
    loops_from: LoopSource,
) -> Edges {
    let trace::Traced {
        loops: mut traced,
        occluding,
    } = traced;
    // Points on a traced loop that BPD labelled interior close it as gap
    // fillers close a tour.
    let dropped = drop_tours_made_by_fillers(&mut traced, |i| detection.boundary[i as usize]);
    let (traced, on_loops) = in_geometric_order(points, traced);
    let thinned = (0..points.len() as u32)
        .filter(|i| detection.boundary[*i as usize] && on_loops.binary_search(i).is_err())
        .count();
    Edges {
        loops: loops_of_tours(points, &detection.beta, traced, options, &occluding),
        dropped_clusters: dropped,
        thinned_points: thinned,
        loops_from,
    }
}

/// The loops (input indices) each started and oriented by the geometric
/// numbering of their points ([`geometric_order`], as tours are by
/// [`order::canonical`]), listed by their smallest number; and the points
/// on them, sorted by index.
fn in_geometric_order(points: &[Point3], loops: Vec<Vec<u32>>) -> (Vec<Vec<u32>>, Vec<u32>) {
    let mut on_loops: Vec<u32> = loops.iter().flatten().copied().collect();
    on_loops.sort_unstable();
    on_loops.dedup();
    let by_number = geometric_order(points, on_loops.clone());
    let mut number = vec![0u32; on_loops.len()];
    for (c, i) in by_number.iter().enumerate() {
        if let Ok(at) = on_loops.binary_search(i) {
            number[at] = c as u32;
        }
    }
    let number_of = |i: &u32| on_loops.binary_search(i).map_or(u32::MAX, |at| number[at]);
    let mut numbered: Vec<Vec<u32>> = loops
        .into_iter()
        .map(|tour| order::canonical(tour.iter().map(number_of).collect()))
        .collect();
    numbered.sort_unstable();
    let loops = numbered
        .into_iter()
        .map(|tour| tour.into_iter().map(|c| by_number[c as usize]).collect())
        .collect();
    (loops, on_loops)
}

/// Each closed tour (input indices, in loop order) made a loop by
/// [`loop_with_beta`], with the outward offset when `options` asks for it,
/// held back at the points `occluding` marks (per input point; empty for
/// none).
fn loops_of_tours(
    points: &[Point3],
    beta: &[f64],
    tours: Vec<Vec<u32>>,
    options: &EdgeOptions,
    occluding: &[bool],
) -> Vec<Loop> {
    let index = options.offset.then(|| NeighbourIndex::new(points));
    tours
        .into_par_iter()
        .map(|tour| {
            let held = if occluding.is_empty() {
                Vec::new()
            } else {
                tour.iter().map(|&i| occluding[i as usize]).collect()
            };
            let loop_beta = tour.iter().map(|&i| beta[i as usize]).collect();
            let index = index.as_ref().map(|i| i as &dyn KNearest);
            loop_held_at_occlusions(points, loop_beta, tour, index, held)
        })
        .collect()
}

/// `members` (input indices) in the order of their geometry: by squared
/// distance from their centroid in [`tie_key`] bins, then by input index.
fn geometric_order(points: &[Point3], mut members: Vec<u32>) -> Vec<u32> {
    let n = members.len().max(1) as f64;
    let mut centre = [0.0; 3];
    for &i in &members {
        for (c, x) in centre.iter_mut().zip(points[i as usize]) {
            *c += x / n;
        }
    }
    members.sort_by_cached_key(|&i| (tie_key(dist2(points[i as usize], centre)), i));
    members
}

/// The boundary points renumbered 0, 1, … in an order of their own
/// geometry, in which edge reconstruction works: so every tie-break, each
/// tour's start and direction and the order of the loops follow the points,
/// not the order in which the cloud was written (the edges of a shuffled
/// cloud are the same), nor where it sits (the order is by squared distance
/// from the boundary points' centroid in [`tie_key`] bins, which a rigid
/// motion does not change; equal bins, e.g. the symmetric points of a
/// quantised cloud, go by input index).
struct CanonicalBoundary {
    /// Input index of each renumbered point.
    input: Vec<u32>,
    /// Their positions and local resolutions.
    points: Vec<Point3>,
    beta: Vec<f64>,
    /// All true: every renumbered point is a boundary point.
    boundary: Vec<bool>,
    /// Whether BPD labelled it boundary (false for a gap filler).
    detected: Vec<bool>,
    /// BPD's links between them, renumbered, smaller first, sorted.
    links: Vec<[u32; 2]>,
}

impl CanonicalBoundary {
    fn new(points: &[Point3], detection: &Detection) -> Self {
        let fillers = gap_fillers(detection);
        let input = geometric_order(
            points,
            (0..points.len() as u32)
                .filter(|&i| detection.boundary[i as usize] || fillers[i as usize])
                .collect(),
        );
        let mut renumbered = vec![u32::MAX; points.len()];
        for (c, &i) in input.iter().enumerate() {
            renumbered[i as usize] = c as u32;
        }
        let mut links: Vec<[u32; 2]> = detection
            .links
            .iter()
            .map(|&[a, b]| (renumbered[a as usize], renumbered[b as usize]))
            .filter(|&(a, b)| a != u32::MAX && b != u32::MAX)
            .map(|(a, b)| [a.min(b), a.max(b)])
            .collect();
        links.sort_unstable();
        links.dedup();
        Self {
            points: input.iter().map(|&i| points[i as usize]).collect(),
            beta: input.iter().map(|&i| detection.beta[i as usize]).collect(),
            boundary: vec![true; input.len()],
            detected: input
                .iter()
                .map(|&i| detection.boundary[i as usize])
                .collect(),
            input,
            links,
        }
    }
}

/// Interior-labelled points that close an open chain of the border (true
/// at their index).
///
/// BPD links a boundary point to the neighbours that its empty circles of
/// radius ≥ β touch. Each boundary point has at least two such links, but
/// a linked neighbour is sometimes labelled interior: its own test, in its
/// own plane and with its own β, found no circle as large. The chain of
/// links between boundary points then stops there, and clustering, which
/// keeps only closed chains, drops the whole border (on clean single-row
/// borders, e.g. a range scan's, nearly every chain end is such a link).
/// A neighbour that an open end links to and that at least one more
/// boundary point links to lies on the border as its neighbours see it: it
/// joins the boundary for edge reconstruction. Where no chain is open,
/// nothing changes.
fn gap_fillers(detection: &Detection) -> Vec<bool> {
    let boundary = &detection.boundary;
    let mut boundary_degree = vec![0u32; boundary.len()];
    for &[a, b] in &detection.links {
        if boundary[a as usize] && boundary[b as usize] {
            boundary_degree[a as usize] += 1;
            boundary_degree[b as usize] += 1;
        }
    }
    let mut linked_from_boundary = vec![0u32; boundary.len()];
    let mut closes_an_end = vec![false; boundary.len()];
    for &[a, b] in &detection.links {
        for (from, to) in [(a as usize, b as usize), (b as usize, a as usize)] {
            if boundary[from] && !boundary[to] {
                linked_from_boundary[to] += 1;
                closes_an_end[to] |= boundary_degree[from] == 1;
            }
        }
    }
    closes_an_end
        .iter()
        .zip(&linked_from_boundary)
        .map(|(&end, &links)| end && links >= 2)
        .collect()
}

/// Drops the tours with fewer than [`cluster::MIN_LOOP_POINTS`] points that
/// BPD labelled boundary (`detected`, asked of each point as the tours
/// number it); returns how many.
///
/// Gap fillers close a border that BPD found; they do not make one. In a
/// jittered cloud a gap of the sampling at the resolution limit sometimes
/// has two of the points round it labelled boundary (their own β is a
/// little below the gap's empty circle) and two not: the fillers then close
/// the four into a loop round a hole that is not there, and trimming or
/// meshing would cut it out (the 100k benchmark sheet has one, the 1M
/// sheet five). The paper's smallest hole is found by four points, so a
/// loop needs four detected ones.
fn drop_tours_made_by_fillers(tours: &mut Vec<Vec<u32>>, detected: impl Fn(u32) -> bool) -> usize {
    let before = tours.len();
    tours.retain(|tour| {
        let found = tour.iter().filter(|&&c| detected(c)).count();
        found >= cluster::MIN_LOOP_POINTS
    });
    before - tours.len()
}

/// Corners, smoothed edges and (with `index`, the cloud's neighbour index)
/// the outward offset of one closed tour of boundary points (indices into
/// `points`, in loop order), given β of the tour's points (`loop_beta`, in
/// its order). Used on the border loops of a mesh, whose order the mesh
/// itself gives.
pub(crate) fn loop_with_beta(
    points: &[Point3],
    loop_beta: Vec<f64>,
    tour: Vec<u32>,
    index: Option<&dyn KNearest>,
) -> Loop {
    loop_held_at_occlusions(points, loop_beta, tour, index, Vec::new())
}

/// [`loop_with_beta`], the offset held back where `occluding` (per tour
/// point; empty for none) says the loop runs along an occlusion
/// ([`offset::hold_at_occlusions`]).
fn loop_held_at_occlusions(
    points: &[Point3],
    loop_beta: Vec<f64>,
    tour: Vec<u32>,
    index: Option<&dyn KNearest>,
    occluding: Vec<bool>,
) -> Loop {
    let loop_points: Vec<Point3> = tour.iter().map(|&i| points[i as usize]).collect();
    let corners = corners::find_corners(&loop_points, &loop_beta);
    let mut edges = smoothed_edges(&loop_points, &loop_beta, &corners);
    let mut sides = index.map_or_else(Vec::new, |index| offset::edge_sides(index, &tour));
    if !occluding.is_empty() {
        offset::hold_at_occlusions(&mut sides, &occluding);
    }
    if !sides.is_empty() {
        move_edges_outward(&mut edges, &corners, &sides);
    }
    Loop {
        boundary_points: tour,
        corners,
        edges,
        sides,
    }
}

/// Splits a loop at its corners and smooths each piece (section 3.3).
fn smoothed_edges(loop_points: &[Point3], beta: &[f64], corners: &[usize]) -> Vec<Edge> {
    if corners.is_empty() {
        return vec![Edge {
            closed: true,
            points: smooth::smooth_closed_edge(loop_points, beta),
        }];
    }
    between_corners(loop_points.len(), corners)
        .map(|range| {
            let piece: Vec<Point3> = range.iter().map(|&j| loop_points[j]).collect();
            let piece_beta: Vec<f64> = range.iter().map(|&j| beta[j]).collect();
            Edge {
                closed: false,
                points: smooth::smooth_open_edge(&piece, &piece_beta),
            }
        })
        .collect()
}

/// The positions of a closed loop of `n` points from each of its
/// `corners` (ascending, at least one) to the next, both included,
/// wrapping round: one run per edge.
fn between_corners(n: usize, corners: &[usize]) -> impl Iterator<Item = Vec<usize>> + '_ {
    (0..corners.len()).map(move |k| {
        let (from, to) = (corners[k], corners[(k + 1) % corners.len()]);
        let len = (to + n - from) % n;
        let len = if len == 0 { n } else { len };
        (0..=len).map(|j| (from + j) % n).collect()
    })
}

/// Moves every edge out to the estimated physical edge; corners move to
/// where the moved edges meet, and stay shared by consecutive edges.
fn move_edges_outward(edges: &mut [Edge], corners: &[usize], sides: &[offset::EdgeSide]) {
    let n = sides.len();
    if corners.is_empty() {
        offset::move_outward(&mut edges[0].points, true, sides);
        return;
    }
    // The sides of each edge's points, and the outward normals at its ends.
    let mut end_normals = Vec::with_capacity(edges.len());
    for (k, edge) in edges.iter_mut().enumerate() {
        let from = corners[k];
        let edge_sides: Vec<offset::EdgeSide> = (0..edge.points.len())
            .map(|j| sides[(from + j) % n])
            .collect();
        let m = edge.points.len();
        let first = offset::outward(
            sub(edge.points[1], edge.points[0]),
            edge.points[0],
            &edge_sides[0],
        );
        let last = offset::outward(
            sub(edge.points[m - 1], edge.points[m - 2]),
            edge.points[m - 1],
            &edge_sides[m - 1],
        );
        end_normals.push((first, last));
        offset::move_outward(&mut edge.points, false, &edge_sides);
    }
    // Corner k ends edge k−1 and starts edge k.
    for k in 0..edges.len() {
        let previous = (k + edges.len() - 1) % edges.len();
        let (Some(n_in), Some(n_out)) = (end_normals[previous].1, end_normals[k].0) else {
            continue;
        };
        let shift = offset::corner_shift(sides[corners[k]].offset, n_in, n_out);
        let corner = edges[k].points[0];
        let moved = [0, 1, 2].map(|c| corner[c] + shift[c]);
        edges[k].points[0] = moved;
        let last = edges[previous].points.len() - 1;
        edges[previous].points[last] = moved;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bpd::Decision;

    /// A ring of 16 boundary points linked to their neighbours, one of
    /// them labelled interior (`gap`, when given): its two neighbours
    /// still link to it, as BPD does when their circles touch it.
    fn ring(gap: Option<usize>) -> (Vec<Point3>, Detection) {
        ring_of(16, gap.as_slice(), &[])
    }

    /// A ring of `n` points linked to their neighbours and by `chords`,
    /// those at `gaps` labelled interior.
    fn ring_of(n: usize, gaps: &[usize], chords: &[[u32; 2]]) -> (Vec<Point3>, Detection) {
        let points: Vec<Point3> = (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                [10.0 * a.cos(), 10.0 * a.sin(), 0.0]
            })
            .collect();
        let boundary: Vec<bool> = (0..n).map(|i| !gaps.contains(&i)).collect();
        let mut links: Vec<[u32; 2]> = (0..n as u32)
            .map(|i| [i, (i + 1) % n as u32])
            .chain(chords.iter().copied())
            .map(|[a, b]| [a.min(b), a.max(b)])
            .collect();
        links.sort_unstable();
        let detection = Detection {
            decision: boundary
                .iter()
                .map(|&b| {
                    if b {
                        Decision::EmptyCircle
                    } else {
                        Decision::Interior
                    }
                })
                .collect(),
            boundary,
            beta: vec![3.0; n],
            duplicates: 0,
            links,
            view: None,
            reach: Vec::new(),
        };
        (points, detection)
    }

    /// One interior-labelled point in a border's chain of links closes it
    /// again instead of losing the whole border; a closed border gets no
    /// filler.
    #[test]
    fn an_interior_point_linked_from_an_open_end_closes_the_border() {
        let options = EdgeOptions { offset: false };
        let (points, whole) = ring(None);
        assert!(gap_fillers(&whole).iter().all(|&f| !f));
        let closed = reconstruct_edges(&points, &whole, &options);
        assert_eq!(closed.loops.len(), 1);
        assert_eq!(closed.loops[0].boundary_points.len(), 16);
        let (points, broken) = ring(Some(5));
        let fillers = gap_fillers(&broken);
        assert_eq!(fillers.iter().filter(|&&f| f).count(), 1);
        assert!(fillers[5]);
        let healed = reconstruct_edges(&points, &broken, &options);
        assert_eq!(healed.loops.len(), 1, "{healed:?}");
        assert_eq!(healed.loops[0].boundary_points.len(), 16);
        assert!(healed.loops[0].boundary_points.contains(&5));
    }

    /// A gap of the sampling with two of its four points labelled boundary
    /// (linked across it) and two not: the fillers would close the four
    /// into a loop round a hole that is not there. It is dropped and
    /// counted; four detected points round a gap stay a loop (the paper's
    /// smallest hole).
    #[test]
    fn fillers_do_not_make_a_loop_of_their_own() {
        let options = EdgeOptions { offset: false };
        let (points, half) = ring_of(4, &[1, 3], &[[0, 2]]);
        assert_eq!(gap_fillers(&half).iter().filter(|&&f| f).count(), 2);
        let edges = reconstruct_edges(&points, &half, &options);
        assert!(edges.loops.is_empty(), "{edges:?}");
        assert_eq!(edges.dropped_clusters, 1);
        assert_eq!(edges.thinned_points, 4);
        let (points, hole) = ring_of(4, &[], &[[0, 2]]);
        let edges = reconstruct_edges(&points, &hole, &options);
        assert_eq!(edges.loops.len(), 1, "{edges:?}");
        assert_eq!(edges.loops[0].boundary_points.len(), 4);
    }
}
