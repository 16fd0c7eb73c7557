//! Trimming a reconstructed mesh along the cloud's smoothed boundary —
//! meshtrim's third stage (the paper's aim: meshes fit for CAM toolpaths).
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
//! 6. Unused vertices are removed.

use crate::hash::HashMap;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

use crate::bpd::Detection;
use crate::edges::offset::{edge_sides, outward};
use crate::edges::Edges;
use crate::error::MeshError;
use crate::geom::UnionFind;
use crate::geom::{dist2, dot, norm2, sub, Point3};
use crate::mesh::{sorted_edges_of, Mesh};
use crate::spatial::closest_face::FaceIndex;
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
    /// Area of the input mesh.
    pub area_in: f64,
    /// Area of the output mesh.
    pub area_out: f64,
    /// For each smoothed loop: mean and largest distance from the output
    /// border (its vertices) to the loop, and how many border vertices
    /// were measured.
    pub loops: Vec<LoopFit>,
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
) -> Result<(Mesh, TrimReport), MeshError> {
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
    let support = supported_faces(&cut, &beyond, cloud, &detection.beta, options.support)?;
    let keep = support.keep;
    let mut survived = vec![false; mesh.faces.len()];
    for (&o, &k) in origin.iter().zip(&keep) {
        survived[o as usize] |= k;
    }
    let mut kept = cut;
    kept.retain_faces(&keep);
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
        area_in: mesh.area(),
        area_out: kept.area(),
        loops: walls.border_fit(&kept),
    };
    Ok((kept, report))
}

/// What the cut along the cloud's reach removed.
struct OutOfReach {
    /// Faces of the cut mesh dropped.
    faces: usize,
    /// Vertices snapped onto the reach.
    snapped: usize,
}

/// Step 4 of the module doc: cuts `cut` again along the cloud's reach and
/// drops the faces beyond it, except spots smaller than a disc of radius β
/// (their largest β), which the cloud cannot resolve: BPD finds no hole
/// smaller than that, and the Poisson surface pokes that far out of reach
/// in little domes over a scan's crevices. Faces and their origins are
/// those of `cut`'s input mesh.
fn within_reach(cut: Cut, reach: &Reach, snap: f64) -> (Cut, OutOfReach) {
    let excess: Vec<(f64, f64)> = cut
        .mesh
        .vertices
        .par_iter()
        .map(|&v| reach.excess(v))
        .collect();
    let (field, snapped_count) = snapped_field(&excess, snap);
    // Where every loop closed, nothing is out of reach and the cut below
    // would copy `cut` face for face: skip it.
    if field.iter().all(|&g| g <= 0.0) {
        let dropped = OutOfReach {
            faces: 0,
            snapped: snapped_count,
        };
        return (cut, dropped);
    }
    let beta: Vec<f64> = excess.iter().map(|&(_, beta)| beta).collect();
    let Cut {
        mesh: mut second,
        origin: part_of,
        beyond: mut out_of_reach,
        ..
    } = cut_both_sides(&cut.mesh, &field);
    keep_unresolved_spots(&second, &beta, &mut out_of_reach);
    let in_reach: Vec<bool> = out_of_reach.iter().map(|&o| !o).collect();
    second.retain_faces(&in_reach);
    let (origin, beyond) = part_of
        .iter()
        .zip(&in_reach)
        .filter(|(_, &kept)| kept)
        .map(|(&f, _)| (cut.origin[f as usize], cut.beyond[f as usize]))
        .unzip();
    let dropped = OutOfReach {
        faces: out_of_reach.iter().filter(|&&o| o).count(),
        snapped: snapped_count,
    };
    let within = Cut {
        mesh: second,
        origin,
        beyond,
        split: cut.split,
    };
    (within, dropped)
}

/// Clears `out_of_reach` on each connected spot of such faces whose area
/// is below π β², β the largest at its vertices (`beta`, per vertex of
/// `mesh`'s vertices before the cut: each such face has one). Only the
/// faces out of reach are joined into spots.
fn keep_unresolved_spots(mesh: &Mesh, beta: &[f64], out_of_reach: &mut [bool]) {
    let spot_faces: Vec<usize> = (0..mesh.faces.len()).filter(|&f| out_of_reach[f]).collect();
    let faces: Vec<[u32; 3]> = spot_faces.iter().map(|&f| mesh.faces[f]).collect();
    let spot = face_pieces(&faces, &vec![false; faces.len()]);
    let spots = spot.iter().map(|&p| p as usize + 1).max().unwrap_or(0);
    let mut area = vec![0.0f64; spots];
    let mut largest_beta = vec![0.0f64; spots];
    for (&f, &p) in spot_faces.iter().zip(&spot) {
        let p = p as usize;
        area[p] += mesh.face_area(f);
        for &v in &mesh.faces[f] {
            let b = beta.get(v as usize).copied().unwrap_or(0.0);
            largest_beta[p] = largest_beta[p].max(b);
        }
    }
    for (&f, &p) in spot_faces.iter().zip(&spot) {
        let p = p as usize;
        if area[p] < std::f64::consts::PI * largest_beta[p] * largest_beta[p] {
            out_of_reach[f] = false;
        }
    }
}

/// The field of a cut from each vertex's (value, local spacing), and how
/// many values were snapped to 0: a vertex closer to the cut than `snap`
/// local spacings is moved onto it (f := 0), so that the cut passes
/// through it instead of leaving a sliver beside it.
fn snapped_field(values: &[(f64, f64)], snap: f64) -> (Vec<f64>, usize) {
    let mut snapped = 0;
    let field = values
        .iter()
        .map(|&(f, spacing)| {
            if f != 0.0 && f.abs() < snap * spacing {
                snapped += 1;
                0.0
            } else {
                f
            }
        })
        .collect();
    (field, snapped)
}

/// The cloud's reach: how far from the cloud the kept surface may lie.
struct Reach<'a> {
    beta: &'a [f64],
    /// β's that end the kept surface.
    reach: f64,
    tree: Option<ImmutableKdTree<f64, 3>>,
}

impl<'a> Reach<'a> {
    fn new(cloud: &[Point3], beta: &'a [f64], reach: f64) -> Self {
        Reach {
            beta,
            reach,
            tree: ImmutableKdTree::new_from_slice(cloud).ok(),
        }
    }

    /// g(v) = d − reach·β, with d the distance from v to the nearest cloud
    /// point and β that point's local resolution; and β, which snaps g.
    /// g > 0 where v is out of the cloud's reach.
    fn excess(&self, v: Point3) -> (f64, f64) {
        // kiddo refuses only more points than its item index holds (2⁶⁴):
        // then, as without walls, nothing is cut.
        let Some(tree) = &self.tree else {
            return (-1.0, 0.0);
        };
        let nearest = tree
            .query(&v)
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        let beta = self.beta[nearest.item as usize];
        (nearest.distance.sqrt() - self.reach * beta, beta)
    }
}

/// The smoothed loops as walls: polyline vertices with outward directions
/// and local spacing, indexed for nearest queries.
struct Walls {
    points: Vec<Point3>,
    /// Outward unit direction of the segment from point i to its successor.
    out: Vec<Point3>,
    /// Successor and predecessor of each point in its closed loop.
    next: Vec<u32>,
    prev: Vec<u32>,
    beta: Vec<f64>,
    /// The loop each point belongs to.
    loop_of: Vec<u32>,
    loops: usize,
    tree: Option<ImmutableKdTree<f64, 3>>,
}

impl Walls {
    fn new(cloud: &[Point3], detection: &Detection, edges: &Edges) -> Self {
        // The offset already measured each boundary point's side; without
        // it (offset off) they are measured here.
        let index = edges
            .loops
            .iter()
            .any(|lp| lp.sides.len() != lp.boundary_points.len())
            .then(|| NeighbourIndex::new(cloud));
        let mut w = Walls {
            points: Vec::new(),
            out: Vec::new(),
            next: Vec::new(),
            prev: Vec::new(),
            beta: Vec::new(),
            loop_of: Vec::new(),
            loops: edges.loops.len(),
            tree: None,
        };
        for (l, lp) in edges.loops.iter().enumerate() {
            let measured;
            let sides = match &index {
                Some(index) if lp.sides.len() != lp.boundary_points.len() => {
                    measured = edge_sides(index, &lp.boundary_points);
                    &measured
                }
                _ => &lp.sides,
            };
            let n = lp.boundary_points.len();
            // The loop as one closed polyline: each open edge without its
            // last point, which is the next edge's first (the corner), so
            // that a corner has both of its segments.
            let mut positions = Vec::new();
            for (k, edge) in lp.edges.iter().enumerate() {
                let from = lp.corners.get(k).copied().unwrap_or(0);
                let take = if edge.closed {
                    edge.points.len()
                } else {
                    edge.points.len() - 1
                };
                for (j, &p) in edge.points.iter().take(take).enumerate() {
                    positions.push((from + j) % n);
                    w.points.push(p);
                }
            }
            let start = w.points.len() - positions.len();
            let m = positions.len();
            for (j, &position) in positions.iter().enumerate() {
                w.next.push((start + (j + 1) % m) as u32);
                w.prev.push((start + (j + m - 1) % m) as u32);
                w.beta
                    .push(detection.beta[lp.boundary_points[position] as usize]);
                w.loop_of.push(l as u32);
            }
            for j in 0..m {
                let i = start + j;
                let (a, b) = (w.points[i], w.points[w.next[i] as usize]);
                w.out
                    .push(outward(sub(b, a), a, &sides[positions[j]]).unwrap_or([0.0; 3]));
            }
        }
        if !w.points.is_empty() {
            w.tree = ImmutableKdTree::new_from_slice(&w.points).ok();
        }
        w
    }

    fn nearest_point(&self, v: Point3) -> Option<usize> {
        let tree = self.tree.as_ref()?;
        Some(
            tree.query(&v)
                .nearest_one::<SquaredEuclidean<f64>>()
                .execute()
                .item as usize,
        )
    }

    /// f(v): signed distance from v to the nearest wall (negative inside),
    /// and the local spacing there. With no loop at all, everything is
    /// inside.
    ///
    /// f = (v − q)·o(q) for the nearest point q of the polyline. The
    /// outward direction o and the spacing are interpolated along each
    /// segment between their values at its ends, so both are continuous
    /// along the loop and so is f: a vertex on the border between a
    /// segment's and a polyline vertex's region gets the same value from
    /// either, and rounding (moving the part far from the origin, say)
    /// cannot move the cut by more than it moves the points.
    fn signed_distance(&self, v: Point3) -> (f64, f64) {
        let Some(i) = self.nearest_point(v) else {
            return (-1.0, 0.0);
        };
        // The nearest point on the two segments at the nearest vertex.
        let mut best = (
            dist2(v, self.points[i]),
            self.points[i],
            self.vertex_out(i),
            self.beta[i],
        );
        for (a, b) in [(self.prev[i] as usize, i), (i, self.next[i] as usize)] {
            if a == b {
                continue;
            }
            let (pa, pb) = (self.points[a], self.points[b]);
            let ab = sub(pb, pa);
            let len2 = norm2(ab);
            if len2 == 0.0 {
                continue;
            }
            let t = (dot(sub(v, pa), ab) / len2).clamp(0.0, 1.0);
            let q = lerp(pa, pb, t);
            let d = dist2(v, q);
            if d < best.0 && t > 0.0 && t < 1.0 {
                let out = unit_or(lerp(self.vertex_out(a), self.vertex_out(b), t), self.out[a]);
                let beta = self.beta[a] + t * (self.beta[b] - self.beta[a]);
                best = (d, q, out, beta);
            }
        }
        (dot(sub(v, best.1), best.2), best.3)
    }

    /// Outward direction at polyline vertex i: the mean of its segments'.
    fn vertex_out(&self, i: usize) -> Point3 {
        let (a, b) = (self.out[self.prev[i] as usize], self.out[i]);
        unit_or(lerp(a, b, 0.5), b)
    }

    /// Mean and largest distance from the border vertices of `mesh` to the
    /// nearest loop, per loop.
    fn border_fit(&self, mesh: &Mesh) -> Vec<LoopFit> {
        let mut fits = vec![LoopFit::default(); self.loops];
        for border in mesh.boundary_loops() {
            for v in border {
                let p = mesh.vertices[v as usize];
                let Some(i) = self.nearest_point(p) else {
                    continue;
                };
                let d = self.distance_to_polyline(p, i);
                let fit = &mut fits[self.loop_of[i] as usize];
                fit.mean += d;
                fit.max = fit.max.max(d);
                fit.count += 1;
            }
        }
        for fit in fits.iter_mut() {
            if fit.count > 0 {
                fit.mean /= fit.count as f64;
            }
        }
        fits
    }

    fn distance_to_polyline(&self, v: Point3, i: usize) -> f64 {
        let mut best = dist2(v, self.points[i]);
        for (a, b) in [(self.prev[i] as usize, i), (i, self.next[i] as usize)] {
            let (pa, pb) = (self.points[a], self.points[b]);
            let ab = sub(pb, pa);
            let len2 = norm2(ab);
            if len2 > 0.0 {
                let t = (dot(sub(v, pa), ab) / len2).clamp(0.0, 1.0);
                best = best.min(dist2(v, lerp(pa, pb, t)));
            }
        }
        best.sqrt()
    }
}

/// a + t (b − a).
fn lerp(a: Point3, b: Point3, t: f64) -> Point3 {
    [0, 1, 2].map(|c| a[c] + t * (b[c] - a[c]))
}

/// `v` scaled to unit length, or `fallback` when `v` is zero (opposite
/// directions averaged).
fn unit_or(v: Point3, fallback: Point3) -> Point3 {
    let len = norm2(v).sqrt();
    if len > 0.0 {
        v.map(|c| c / len)
    } else {
        fallback
    }
}

/// A mesh cut along the zero level of the field: input vertices first,
/// then one new vertex per crossed edge, shared by all faces of that edge.
struct Cut {
    mesh: Mesh,
    /// The input face of each face.
    origin: Vec<u32>,
    /// Whether each face lies beyond the walls (f ≥ 0) rather than inside
    /// (f ≤ 0).
    beyond: Vec<bool>,
    /// Input faces split by the cut.
    split: usize,
}

impl Cut {
    fn push(&mut self, face: [u32; 3], origin: usize, beyond: bool) {
        self.mesh.faces.push(face);
        self.origin.push(origin as u32);
        self.beyond.push(beyond);
    }
}

/// Splits the faces crossed by the zero level of `field` into their parts
/// on either side; faces on one side are copied whole.
fn cut_both_sides(mesh: &Mesh, field: &[f64]) -> Cut {
    let capacity = mesh.faces.len();
    let mut cut = Cut {
        mesh: Mesh {
            vertices: mesh.vertices.clone(),
            faces: Vec::with_capacity(capacity),
        },
        origin: Vec::with_capacity(capacity),
        beyond: Vec::with_capacity(capacity),
        split: 0,
    };
    let mut crossing: HashMap<(u32, u32), u32> = HashMap::default();
    for (index, face) in mesh.faces.iter().enumerate() {
        let f = face.map(|v| field[v as usize]);
        if f.iter().all(|&x| x <= 0.0) {
            cut.push(*face, index, false);
            continue;
        }
        if f.iter().all(|&x| x >= 0.0) {
            cut.push(*face, index, true);
            continue;
        }
        cut.split += 1;
        // Each side's part: its own corners and the crossings, in the
        // face's vertex order.
        let (mut inside, mut beyond) = (Vec::with_capacity(4), Vec::with_capacity(4));
        for k in 0..3 {
            let (a, b) = (face[k], face[(k + 1) % 3]);
            let (fa, fb) = (f[k], f[(k + 1) % 3]);
            if fa <= 0.0 {
                inside.push(a);
            }
            if fa >= 0.0 {
                beyond.push(a);
            }
            if (fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0) {
                let key = (a.min(b), a.max(b));
                let v = *crossing.entry(key).or_insert_with(|| {
                    let (p, q, fp, fq) = if a < b {
                        (a, b, fa, fb)
                    } else {
                        (b, a, fb, fa)
                    };
                    let t = fp / (fp - fq);
                    let (pp, pq) = (mesh.vertices[p as usize], mesh.vertices[q as usize]);
                    cut.mesh
                        .vertices
                        .push([0, 1, 2].map(|c| pp[c] + t * (pq[c] - pp[c])));
                    (cut.mesh.vertices.len() - 1) as u32
                });
                inside.push(v);
                beyond.push(v);
            }
        }
        for (part, side) in [(inside, false), (beyond, true)] {
            for k in 1..part.len().saturating_sub(1) {
                cut.push([part[0], part[k], part[k + 1]], index, side);
            }
        }
    }
    cut
}

/// Which faces of the cut mesh to keep: those of the pieces the cloud
/// supports.
struct Support {
    /// Per face of the cut mesh.
    keep: Vec<bool>,
    /// Pieces dropped, on either side of the walls.
    dropped: usize,
    /// Pieces beyond the walls kept.
    restored: usize,
}

/// Which faces of `cut` lie in a piece the cloud supports (see the module
/// doc). Pieces never cross the walls: `beyond` says each face's side.
fn supported_faces(
    cut: &Mesh,
    beyond: &[bool],
    cloud: &[Point3],
    beta: &[f64],
    support: f64,
) -> Result<Support, MeshError> {
    if cut.faces.is_empty() {
        return Err(MeshError::Unsupported);
    }
    let piece = face_pieces(&cut.faces, beyond);
    let pieces = piece.iter().map(|&p| p as usize + 1).max().unwrap_or(0);
    let projector = FaceIndex::new(cut);
    let mut hits = vec![0usize; pieces];
    let mut cell_area = vec![0.0f64; pieces];
    // Each projection is independent: parallel, then summed in cloud order
    // so the sums do not depend on the thread count.
    let landed: Vec<Option<u32>> = cloud
        .par_iter()
        .zip(beta)
        .map(|(p, &b)| projector.nearest_face(*p, 2.0 * b))
        .collect();
    for (face, &b) in landed.iter().zip(beta) {
        if let Some(face) = face {
            let k = piece[*face as usize] as usize;
            hits[k] += 1;
            cell_area[k] += 0.75f64.sqrt() * b * b;
        }
    }
    let mut area = vec![0.0f64; pieces];
    for f in 0..cut.faces.len() {
        area[piece[f] as usize] += cut.face_area(f);
    }
    // Points expected on a piece: its area over the mean cell area of the
    // points that landed on it.
    let keep: Vec<bool> = (0..pieces)
        .map(|k| {
            hits[k] > 0 && hits[k] as f64 >= support * area[k] / (cell_area[k] / hits[k] as f64)
        })
        .collect();
    if !keep.iter().any(|&k| k) {
        return Err(MeshError::Unsupported);
    }
    let mut piece_beyond = vec![false; pieces];
    for (&p, &b) in piece.iter().zip(beyond) {
        piece_beyond[p as usize] = b;
    }
    Ok(Support {
        keep: piece.iter().map(|&p| keep[p as usize]).collect(),
        dropped: keep.iter().filter(|&&k| !k).count(),
        restored: (0..pieces).filter(|&k| keep[k] && piece_beyond[k]).count(),
    })
}

/// Connected pieces of faces sharing an edge; piece ids by first face.
///
/// The faces' edges are sorted rather than hashed ([`sorted_edges_of`]);
/// the faces on one edge are joined to its first.
fn face_pieces(faces: &[[u32; 3]], beyond: &[bool]) -> Vec<u32> {
    let n = faces.len();
    let edges = sorted_edges_of(faces);
    let mut sets = UnionFind::new(n);
    for same_edge in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        for side in [false, true] {
            let mut on_side = same_edge.iter().filter(|e| beyond[e.2 as usize] == side);
            if let Some(first) = on_side.next() {
                for other in on_side {
                    sets.union(first.2, other.2);
                }
            }
        }
    }
    piece_ids(&mut sets, n)
}

/// [`face_pieces`] with a hash map of edges, the plain way; the reference
/// for tests.
#[cfg(test)]
fn face_pieces_reference(faces: &[[u32; 3]], beyond: &[bool]) -> Vec<u32> {
    let n = faces.len();
    let mut sets = UnionFind::new(n);
    let mut first_on_edge: HashMap<(u32, u32, bool), u32> = HashMap::default();
    for (f, face) in faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (face[k], face[(k + 1) % 3]);
            match first_on_edge.entry((a.min(b), a.max(b), beyond[f])) {
                std::collections::hash_map::Entry::Occupied(e) => {
                    sets.union(*e.get(), f as u32);
                }
                std::collections::hash_map::Entry::Vacant(e) => {
                    e.insert(f as u32);
                }
            }
        }
    }
    piece_ids(&mut sets, n)
}

/// Piece ids 0, 1, … in the order of each set's first member.
fn piece_ids(sets: &mut UnionFind, n: usize) -> Vec<u32> {
    let mut id = vec![u32::MAX; n];
    let mut next = 0;
    (0..n)
        .map(|f| {
            let r = sets.find(f as u32) as usize;
            if id[r] == u32::MAX {
                id[r] = next;
                next += 1;
            }
            id[r]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// Walls along a regular `n`-gon of radius `r` in the plane z = 0,
    /// each segment's outward direction its own in-plane normal, the local
    /// spacing growing round the loop.
    fn polygon_walls(n: usize, r: f64) -> Walls {
        let points: Vec<Point3> = (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                [r * a.cos(), r * a.sin(), 0.0]
            })
            .collect();
        let out = (0..n)
            .map(|k| {
                let d = sub(points[(k + 1) % n], points[k]);
                let len = norm2(d).sqrt();
                [d[1] / len, -d[0] / len, 0.0]
            })
            .collect();
        Walls {
            tree: ImmutableKdTree::new_from_slice(&points).ok(),
            points,
            out,
            next: (0..n).map(|k| ((k + 1) % n) as u32).collect(),
            prev: (0..n).map(|k| ((k + n - 1) % n) as u32).collect(),
            beta: (0..n).map(|k| 1.0 + 0.1 * k as f64).collect(),
            loop_of: vec![0; n],
            loops: 1,
        }
    }

    #[test]
    fn the_field_and_the_spacing_are_continuous_near_the_wall() {
        // Sharp turns (a hexagon) make the vertex regions wide. On a fine
        // grid over one corner and its two segments, within 0.2 of the
        // wall, neighbouring samples may differ in f by at most their
        // distance (f is 1-Lipschitz where the nearest point moves
        // continuously), and in spacing by far less than the 0.1 step
        // between the corners' spacings. (Inside a convex corner the
        // nearest point jumps from one segment to the other, but so close
        // to the corner that the spacing barely differs.)
        let walls = polygon_walls(6, 10.0);
        let step = 4e-3;
        let at = |i: i32, j: i32| [4.0 + i as f64 * step, -1.5 + j as f64 * step, 0.3];
        let (mut largest_jump, mut band_samples) = (0.0_f64, 0);
        for i in 0..1875 {
            for j in 0..2750 {
                let (f0, s0) = walls.signed_distance(at(i, j));
                if f0.abs() >= 0.2 {
                    continue;
                }
                band_samples += 1;
                for (f, s) in [
                    walls.signed_distance(at(i + 1, j)),
                    walls.signed_distance(at(i, j + 1)),
                ] {
                    largest_jump = largest_jump.max((f - f0).abs());
                    assert!(
                        (s - s0).abs() < 0.02,
                        "spacing jumps from {s0} to {s} at {:?}",
                        at(i, j)
                    );
                }
            }
        }
        assert!(band_samples > 100_000, "{band_samples}");
        assert!(
            largest_jump <= step * (1.0 + 1e-9),
            "f jumps by {largest_jump}"
        );
    }

    /// A grid of quads split into triangles with random faces left out (so
    /// it falls into pieces), and a few faces repeated on one edge.
    fn random_grid_mesh(seed: u64, side: u32) -> Mesh {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let at = |i: u32, j: u32| i * (side + 1) + j;
        let vertices = (0..=side)
            .flat_map(|i| (0..=side).map(move |j| [i as f64, j as f64, 0.0]))
            .collect();
        let mut faces = Vec::new();
        for i in 0..side {
            for j in 0..side {
                if rng.random_range(0.0..1.0) < 0.45 {
                    faces.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                }
                if rng.random_range(0.0..1.0) < 0.45 {
                    faces.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
        let extra: Vec<[u32; 3]> = faces.iter().step_by(17).copied().collect();
        faces.extend(extra);
        Mesh { vertices, faces }
    }

    /// The reach's field by kiddo's tree equals the plain one: the nearest
    /// point by scanning them all, its β, g = d − 2β.
    #[test]
    fn the_reach_matches_a_scan_of_every_point() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(21);
        for _ in 0..20 {
            let cloud: Vec<Point3> = (0..500)
                .map(|_| [0, 1, 2].map(|_| rng.random_range(-10.0..10.0)))
                .collect();
            let beta: Vec<f64> = (0..cloud.len())
                .map(|_| rng.random_range(0.1..2.0))
                .collect();
            let reach = Reach::new(&cloud, &beta, 2.0);
            for _ in 0..200 {
                let v = [0, 1, 2].map(|_| rng.random_range(-15.0..15.0));
                let (d2, nearest) = cloud
                    .iter()
                    .enumerate()
                    .map(|(i, &p)| (dist2(v, p), i))
                    .min_by(|a, b| a.0.total_cmp(&b.0))
                    .unwrap();
                let want = (d2.sqrt() - 2.0 * beta[nearest], beta[nearest]);
                assert_eq!(reach.excess(v), want, "at {v:?}");
            }
        }
    }

    #[test]
    fn sorted_edges_give_the_pieces_of_the_hash_map() {
        for seed in 0..20 {
            let mesh = random_grid_mesh(seed, 30);
            // Faces on either side of the walls never join; one side
            // only is the plain case.
            let sides: Vec<bool> = (0..mesh.faces.len())
                .map(|f| seed % 2 == 1 && f % 3 == 0)
                .collect();
            let pieces = face_pieces(&mesh.faces, &sides);
            assert_eq!(
                pieces,
                face_pieces_reference(&mesh.faces, &sides),
                "seed {seed}"
            );
            // Not one piece: the test sees the joining at work.
            assert!(pieces.iter().max() > Some(&3), "seed {seed}");
        }
    }

    #[test]
    fn counting_sort_of_edges_matches_sorting() {
        for seed in 0..20 {
            let mut mesh = random_grid_mesh(seed, 25);
            assert_eq!(
                mesh.sorted_edges(),
                mesh.sorted_edges_reference(),
                "seed {seed}"
            );
            // An index past the vertices: no panic, the same edges.
            mesh.faces.push([0, 1, mesh.vertices.len() as u32 + 5]);
            assert_eq!(
                mesh.sorted_edges(),
                mesh.sorted_edges_reference(),
                "seed {seed}"
            );
        }
    }

    #[test]
    fn sorted_edges_give_the_border_of_the_hash_map() {
        for seed in 0..20 {
            let mesh = random_grid_mesh(seed, 30);
            let loops = mesh.boundary_loops();
            assert!(loops.len() > 3, "seed {seed}");
            assert_eq!(loops, mesh.boundary_loops_reference(), "seed {seed}");
        }
    }
}
