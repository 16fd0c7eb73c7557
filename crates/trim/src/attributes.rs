//! Carrying per-vertex attributes (normals, colours, a file's own values)
//! from a mesh to the mesh made from it: meshtrim's own layer, which the
//! paper does not cover (it works on positions only).
//!
//! Every command that writes a mesh keeps most of its input's vertices as
//! they were and adds a few: where trimming cuts a face, where cleanup's
//! smoothed loops replace a jagged border, where the Delaunay path meshes
//! a cloud. The stages know nothing of attributes, so the carrying is done
//! after them, from the output mesh's positions and faces:
//!
//! - an output vertex at exactly the position of an input vertex is that
//!   vertex ([`VertexSource::Vertex`]), its attributes copied bit for bit.
//!   Where several input vertices share the position (a seam: a hard edge's
//!   split normals, a texture chart's border), the output faces tell them
//!   apart: an output face whose corners are an input face's, in the same
//!   turn, takes that face's vertices, so each side of a seam keeps its
//!   own. A vertex no such face settles (its faces were all cut or are
//!   new) takes the vertex at its position of the input face nearest the
//!   centroid of its first output face, among the faces around the
//!   candidates: a cut face's piece lies on the face it was cut from;
//! - any other lies on or near the input surface, and takes the
//!   barycentric weights of its closest point on the closest input face
//!   ([`VertexSource::Face`]), so a cut vertex on an edge blends that
//!   edge's two ends. The closest face is searched among the faces within
//!   reach: a new vertex is no farther from the surface than along the
//!   output's edges to a kept vertex, so only the faces that meet such
//!   balls are indexed (every face where a vertex has no such path). On
//!   a tie (a vertex on a seam's edge is on the faces of both sides) the
//!   face under the centroid of the vertex's first output face wins, the
//!   face that piece was cut from; then the lower face index;
//! - from an input without faces (a cloud), the nearest input point.
//!
//! Normals are blended in direction and in length (unit ones stay unit);
//! colours and other measured values blended; labels and flags, which a
//! blend would turn into values no vertex had, taken from the nearest
//! corner. The result is a function of the input and output
//! meshes alone, whatever the number of threads.

use parry3d_f64::math::Vector;
use parry3d_f64::query::PointQueryWithLocation;
use parry3d_f64::shape::Triangle;
use std::cmp::Reverse;
use std::collections::hash_map::Entry;

use rayon::prelude::*;

use crate::geom::{cross, dot, norm2, sub, unit, Length, Point3};
use crate::hash::{HashMap, HashSet};
use crate::mesh::Mesh;
use crate::spatial::closest_face::{bounds, FaceIndex, Scratch};
use crate::spatial::PointTree;

mod faces;
mod split;
pub use faces::face_sources;
use split::SeamFaces;
pub use split::{split_sources, SplitSources};

/// Where an output vertex takes its attributes from in the input mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VertexSource {
    /// The input vertex at the same position.
    Vertex(u32),
    /// A point of an input face, as weights of its three corners (summing
    /// to 1, none negative).
    Face {
        /// The input face.
        face: u32,
        /// The weights of `faces[face]`'s corners, in order.
        weights: [f64; 3],
    },
}

/// Where each vertex of `to` takes its attributes from in `from` (see
/// the module doc); the face indices of both must be valid. `None` when
/// `from` has no vertex to take them from (and `to` has vertices).
pub fn vertex_sources(from: &Mesh, to: &Mesh) -> Option<Vec<VertexSource>> {
    sources_and_seams(from, to).map(|(sources, _)| sources)
}

/// [`vertex_sources`], and the input's faces round the positions several
/// input vertices share, if any do.
fn sources_and_seams<'a>(
    from: &'a Mesh,
    to: &Mesh,
) -> Option<(Vec<VertexSource>, Option<SeamFaces<'a>>)> {
    let (same_position, seams) = vertex_at_position(&from.vertices);
    let seams = (!seams.is_empty()).then(|| SeamFaces::new(from, seams));
    let mut exact: Vec<Option<u32>> = to
        .vertices
        .par_iter()
        .map(|p| same_position.get(&bits(p)).copied())
        .collect();
    if let Some(seam_faces) = &seams {
        settle_seams(to, seam_faces, &mut exact);
    }
    if exact.iter().all(Option::is_some) {
        let sources = exact
            .into_iter()
            .flatten()
            .map(VertexSource::Vertex)
            .collect();
        return Some((sources, seams));
    }
    if from.faces.is_empty() {
        return nearest_points(&from.vertices, &to.vertices, &exact).map(|s| (s, seams));
    }
    let first_face = first_faces(to, &exact);
    let diagonal = diagonal(from);
    let tie = TIE * diagonal;
    let index =
        match faces_within_reach(from, &query_balls(from, to, &exact, &first_face), diagonal) {
            Some(near) => FaceIndex::of_faces(from, &near),
            None => FaceIndex::new(from),
        };
    let identity: Vec<u32> = (0..from.faces.len() as u32).collect();
    let labels = index.labels(&identity);
    let sources = to
        .vertices
        .par_iter()
        .zip(&exact)
        .enumerate()
        .map_init(Scratch::default, |scratch, (o, (&p, found))| {
            if let Some(v) = *found {
                return VertexSource::Vertex(v);
            }
            // Every face is within an infinite reach of a finite point.
            let mut nearest = |q: Point3| {
                index
                    .nearest_label(q, f64::INFINITY, &labels, scratch)
                    .unwrap_or(0)
            };
            let closest = nearest(p);
            let face = match first_face.get(&(o as u32)) {
                Some(out) => {
                    let own = nearest(centroid(&to.vertices, *out));
                    own_face_if_as_near(from, p, [closest, own], tie)
                }
                None => closest,
            };
            face_source(from, face, p)
        })
        .collect();
    Some((sources, seams))
}

/// A ball around a point the closest input face is asked for, holding
/// that face: its centre and radius.
pub(crate) type Ball = (Point3, f64);

/// The points whose closest input face is asked for (each new output
/// vertex, and the centroid of its first output face), each with a
/// radius its closest face lies within: a new vertex's bound from
/// [`surface_distance_bounds`], a centroid's that plus its distance from
/// the vertex.
fn query_balls(
    from: &Mesh,
    to: &Mesh,
    exact: &[Option<u32>],
    first_face: &HashMap<u32, [u32; 3]>,
) -> Vec<Ball> {
    let bounds = surface_distance_bounds(from, to, exact);
    let mut balls = Vec::new();
    for (o, p) in to.vertices.iter().enumerate() {
        if exact[o].is_some() {
            continue;
        }
        // A vertex in no output face has no path to the surface.
        let bound = bounds.get(&(o as u32)).copied().unwrap_or(f64::INFINITY);
        balls.push((*p, bound));
        if let Some(&face) = first_face.get(&(o as u32)) {
            let c = centroid(&to.vertices, face);
            balls.push((c, bound + norm2(sub(c, *p)).sqrt()));
        }
    }
    balls
}

/// For each new output vertex (no exact source), a distance its closest
/// input face lies within: the length of the shortest path along the
/// output's edges to a kept vertex that is a corner of an input face
/// (which lies on the input surface, so a point is no farther from the
/// surface than from it). None (no entry) where no path leads to one.
pub(crate) fn surface_distance_bounds(
    from: &Mesh,
    to: &Mesh,
    exact: &[Option<u32>],
) -> HashMap<u32, f64> {
    let mut on_surface = vec![false; from.vertices.len()];
    for &v in from.faces.iter().flatten() {
        on_surface[v as usize] = true;
    }
    let mut bound: HashMap<u32, f64> = HashMap::default();
    let mut next: Vec<(u32, u32)> = Vec::new();
    for face in &to.faces {
        for k in 0..3 {
            let (a, b) = (face[k], face[(k + 1) % 3]);
            for (v, w) in [(a, b), (b, a)] {
                if exact[v as usize].is_none() {
                    next.push((v, w));
                }
            }
        }
    }
    next.sort_unstable();
    next.dedup();
    // Dijkstra from every kept vertex on the surface at once.
    let mut heap = std::collections::BinaryHeap::new();
    let length =
        |v: u32, w: u32| norm2(sub(to.vertices[v as usize], to.vertices[w as usize])).sqrt();
    for &(v, w) in &next {
        if exact[w as usize].is_some_and(|i| on_surface[i as usize]) {
            heap.push(Reverse((Length(length(v, w)), v)));
        }
    }
    // A vertex's bound is set when it leaves the heap, at its shortest.
    while let Some(Reverse((Length(d), v))) = heap.pop() {
        if bound.contains_key(&v) {
            continue;
        }
        bound.insert(v, d);
        let from_v = next.partition_point(|&(a, _)| a < v);
        for &(_, w) in next[from_v..].iter().take_while(|&&(a, _)| a == v) {
            if exact[w as usize].is_none() && !bound.contains_key(&w) {
                heap.push(Reverse((Length(d + length(v, w)), w)));
            }
        }
    }
    bound
}

/// The input faces that may be the closest to a ball's centre: those
/// whose bounding box meets some ball (each face ever closest to a centre
/// is among them, as it lies within the ball), and faces larger than a
/// grid cell, kept unasked. `None` when the balls are too large for a
/// list to pay (one unbounded, or wider than a quarter of the input's
/// diagonal, or so many wide ones that listing them costs more than the
/// faces): then every face.
pub(crate) fn faces_within_reach(from: &Mesh, balls: &[Ball], diagonal: f64) -> Option<Vec<u32>> {
    // Rounding in the bounds and in the distances: a hair more reach.
    let reach = |r: f64| r * (1.0 + 1e-6) + 1e-9 * diagonal;
    let mut reaches: Vec<f64> = balls.iter().map(|b| reach(b.1)).collect();
    let widest = reaches.iter().copied().fold(0.0, f64::max);
    if !(widest.is_finite() && widest > 0.0 && widest <= 0.25 * diagonal) {
        return None;
    }
    // Cells twice the median reach: a few wide balls (a vertex whose path
    // to the surface is long) span many cells rather than making every
    // cell hold every ball. A face no more than `margin` from its box's
    // centre to any side that meets a ball has that centre within the
    // ball's box grown by `margin`: each ball is listed in the cells that
    // grown box overlaps, and a face looks in its centre's cell only.
    let middle = reaches.len() / 2;
    let median = *reaches.select_nth_unstable_by(middle, f64::total_cmp).1;
    let size = 2.0 * median;
    let margin = median;
    let cell_of = |p: Point3| p.map(|c| (c / size).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::default();
    let mut listed = 0usize;
    for (b, &(centre, r)) in balls.iter().enumerate() {
        let grown = reach(r) + margin;
        let lo = cell_of(centre.map(|c| c - grown));
        let hi = cell_of(centre.map(|c| c + grown));
        let cells: i64 = (0..3).map(|k| hi[k] - lo[k] + 1).product();
        listed += cells as usize;
        if listed > from.faces.len().max(1 << 16) {
            return None;
        }
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    grid.entry([x, y, z]).or_default().push(b);
                }
            }
        }
    }
    let near = |face: &[u32; 3]| {
        let (low, high) = bounds(face.iter().map(|&v| from.vertices[v as usize]));
        if (0..3).any(|k| high[k] - low[k] > 2.0 * margin) {
            return true;
        }
        let middle = [0, 1, 2].map(|k| 0.5 * (low[k] + high[k]));
        let meets = |&b: &usize| {
            let (centre, r) = balls[b];
            let gap = [0, 1, 2].map(|k| (low[k] - centre[k]).max(centre[k] - high[k]).max(0.0));
            norm2(gap) <= reach(r) * reach(r)
        };
        grid.get(&cell_of(middle))
            .is_some_and(|bs| bs.iter().any(meets))
    };
    Some(
        (0..from.faces.len() as u32)
            .into_par_iter()
            .filter(|&f| near(&from.faces[f as usize]))
            .collect(),
    )
}

/// How much farther than the closest face (relative to the input's
/// bounding diagonal) the face of a new vertex's own output face may be
/// and still be taken: rounding, as a vertex on a seam's edge lies on the
/// faces of both sides.
const TIE: f64 = 1e-9;

/// The face a new vertex takes: `own`, the input face under the centroid
/// of its first output face (the face that face is a piece of), when `p`
/// is as near it as to `closest` (within `tie`); else `closest`. On a
/// seam's edge both sides are nearest, and the piece says which.
fn own_face_if_as_near(from: &Mesh, p: Point3, [closest, own]: [u32; 2], tie: f64) -> u32 {
    let distance = |f: u32| closest_on_face(from, f, p).0.sqrt();
    if own != closest && distance(own) <= distance(closest) + tie {
        own
    } else {
        closest
    }
}

/// The length of the diagonal of the mesh's bounding box (a mesh with
/// faces has vertices, so the box is not empty).
pub(crate) fn diagonal(mesh: &Mesh) -> f64 {
    let (low, high) = bounds(mesh.vertices.iter().copied());
    norm2(sub(high, low)).sqrt()
}

/// The first output face at each output vertex without an exact source
/// (a few, along the new border: a map rather than a slot per vertex).
fn first_faces(to: &Mesh, exact: &[Option<u32>]) -> HashMap<u32, [u32; 3]> {
    let mut first = HashMap::default();
    for &face in &to.faces {
        for v in face {
            if exact[v as usize].is_none() {
                first.entry(v).or_insert(face);
            }
        }
    }
    first
}

/// A face's corner positions, from corner `k` on in the face's turn.
type Corners = [[u64; 3]; 3];

fn corners_from(vertices: &[Point3], face: [u32; 3], k: usize) -> Corners {
    std::array::from_fn(|j| bits(&vertices[face[(k + j) % 3] as usize]))
}

/// Gives the output vertices at a seam's positions (`seams`: positions
/// several input vertices share) their own input vertex (see the module
/// doc): by an input face with the same corners in the same turn (the
/// first output face and the first input face settle it), else by the
/// input face nearest their first output face's centroid.
fn settle_seams(to: &Mesh, seam_faces: &SeamFaces, exact: &mut [Option<u32>]) {
    // Looked up once per vertex, in parallel, rather than per face corner.
    let output_on_seam: Vec<bool> = to
        .vertices
        .par_iter()
        .map(|p| seam_faces.is_seam(p))
        .collect();
    let mut settled = vec![false; to.vertices.len()];
    let mut first_face: HashMap<u32, [u32; 3]> = HashMap::default();
    for &face in &to.faces {
        for k in 0..3 {
            let v = face[k];
            if settled[v as usize] || !output_on_seam[v as usize] {
                continue;
            }
            first_face.entry(v).or_insert(face);
            if let Some(input) = seam_faces.twin(&corners_from(&to.vertices, face, k)) {
                exact[v as usize] = Some(input);
                settled[v as usize] = true;
            }
        }
    }
    for (v, face) in first_face {
        if !settled[v as usize] {
            let position = bits(&to.vertices[v as usize]);
            let faces = seam_faces.around(&position);
            if let Some(input) = nearest_corner(
                seam_faces.from,
                faces,
                position,
                centroid(&to.vertices, face),
            ) {
                exact[v as usize] = Some(input);
            }
        }
    }
}

fn centroid(vertices: &[Point3], face: [u32; 3]) -> Point3 {
    let [a, b, c] = face.map(|v| vertices[v as usize]);
    [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0)
}

/// The vertex at `position` of the face among `faces` nearest `p` (the
/// lower index on a tie).
fn nearest_corner(from: &Mesh, faces: &[u32], position: [u64; 3], p: Point3) -> Option<u32> {
    let nearest = faces
        .iter()
        .map(|&f| (closest_on_face(from, f, p).0, f))
        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))?
        .1;
    from.faces[nearest as usize]
        .into_iter()
        .find(|&v| bits(&from.vertices[v as usize]) == position)
}

/// [`vertex_sources`] by comparing every vertex and face: the reference
/// it is tested against.
#[doc(hidden)]
pub fn vertex_sources_reference(from: &Mesh, to: &Mesh) -> Vec<VertexSource> {
    (0..to.vertices.len())
        .map(|o| {
            let p = to.vertices[o];
            let at_p: Vec<u32> = (0..from.vertices.len() as u32)
                .filter(|&v| bits(&from.vertices[v as usize]) == bits(&p))
                .collect();
            if let Some(&first) = at_p.first() {
                let settled = (at_p.len() > 1)
                    .then(|| same_face_corner(from, to, o as u32))
                    .flatten();
                return VertexSource::Vertex(settled.unwrap_or(first));
            }
            if from.faces.is_empty() {
                let nearest = (0..from.vertices.len())
                    .min_by(|&a, &b| {
                        let da = norm2(sub(from.vertices[a], p));
                        let db = norm2(sub(from.vertices[b], p));
                        da.total_cmp(&db)
                    })
                    .unwrap_or(0);
                return VertexSource::Vertex(nearest as u32);
            }
            let nearest = |q: Point3| {
                (0..from.faces.len())
                    .map(|f| (closest_on_face(from, f as u32, q).0, f as u32))
                    .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
                    .map_or(0, |(_, f)| f)
            };
            let closest = nearest(p);
            let face = match to.faces.iter().find(|out| out.contains(&(o as u32))) {
                Some(out) => {
                    let own = nearest(centroid(&to.vertices, *out));
                    let tie = TIE * diagonal(from);
                    own_face_if_as_near(from, p, [closest, own], tie)
                }
                None => closest,
            };
            face_source(from, face, p)
        })
        .collect()
}

/// The input vertex at output vertex `o`'s corner of the first input face
/// whose corners, in turn, are those of the first output face at `o` that
/// has such a twin; else the corner at `o`'s position of the input face
/// nearest the centroid of the first output face at `o`.
fn same_face_corner(from: &Mesh, to: &Mesh, o: u32) -> Option<u32> {
    let at_o = |out: &[u32; 3]| out.iter().position(|&v| v == o);
    let twin = to.faces.iter().find_map(|&out| {
        let key = corners_from(&to.vertices, out, at_o(&out)?);
        from.faces.iter().find_map(|&face| {
            (0..3)
                .find(|&j| corners_from(&from.vertices, face, j) == key)
                .map(|j| face[j])
        })
    });
    if twin.is_some() {
        return twin;
    }
    let first = to.faces.iter().find(|out| at_o(out).is_some())?;
    let position = bits(&to.vertices[o as usize]);
    let around: Vec<u32> = (0..from.faces.len() as u32)
        .filter(|&f| {
            from.faces[f as usize]
                .iter()
                .any(|&v| bits(&from.vertices[v as usize]) == position)
        })
        .collect();
    nearest_corner(from, &around, position, centroid(&to.vertices, *first))
}

/// Each source's value: `vertex(v)` from a kept vertex, `face(corners,
/// weights)` from a point of a face.
fn at_sources<T: Send>(
    from: &Mesh,
    sources: &[VertexSource],
    vertex: impl Fn(u32) -> T + Sync,
    face: impl Fn([u32; 3], [f64; 3]) -> T + Sync,
) -> Vec<T> {
    sources
        .par_iter()
        .map(|source| match *source {
            VertexSource::Vertex(v) => vertex(v),
            VertexSource::Face { face: f, weights } => face(from.faces[f as usize], weights),
        })
        .collect()
}

/// `values` (one per input vertex) at each source: copied from a vertex,
/// blended by a face's weights.
pub fn carry<const N: usize>(
    from: &Mesh,
    sources: &[VertexSource],
    values: &[[f64; N]],
) -> Vec<[f64; N]> {
    at_sources(
        from,
        sources,
        |v| values[v as usize],
        |corners, weights| {
            std::array::from_fn(|c| {
                (0..3)
                    .map(|k| weights[k] * values[corners[k] as usize][c])
                    .sum()
            })
        },
    )
}

/// One value per input vertex at each source: copied from a vertex;
/// from a face, blended by the weights of the corners that weigh
/// anything, so a corner the point is not on (weight 0) adds nothing, not
/// even a NaN (a file's "no value"), which a blend it is part of keeps.
pub fn carry_values(from: &Mesh, sources: &[VertexSource], values: &[f64]) -> Vec<f64> {
    at_sources(
        from,
        sources,
        |v| values[v as usize],
        |corners, weights| {
            (0..3)
                .filter(|&k| weights[k] != 0.0)
                .map(|k| weights[k] * values[corners[k] as usize])
                .sum()
        },
    )
}

/// One value per input vertex at each source, never blended: copied from
/// a vertex; from a face, its corner of the largest weight (the first of
/// equals). For values a blend would turn into ones no vertex had:
/// labels, flags, counts.
pub fn carry_nearest_corner<T: Copy + Send + Sync>(
    from: &Mesh,
    sources: &[VertexSource],
    values: &[T],
) -> Vec<T> {
    at_sources(
        from,
        sources,
        |v| values[v as usize],
        |corners, weights| {
            let heaviest = (1..3).fold(
                0,
                |best, k| {
                    if weights[k] > weights[best] {
                        k
                    } else {
                        best
                    }
                },
            );
            values[corners[heaviest] as usize]
        },
    )
}

/// Normals (one per input vertex) at each source: copied from a vertex;
/// from a face, the direction of the corners' normals blended by the
/// weights, at the length their lengths blend to (so unit normals give
/// unit ones, and a file's unnormalised normals, such as screened
/// Poisson's gradients, keep lengths of their kind). Where the corners'
/// normals cancel, the face's own normal turned to their side.
pub fn carry_normals(from: &Mesh, sources: &[VertexSource], normals: &[Point3]) -> Vec<Point3> {
    let blended = carry(from, sources, normals);
    let lengths: Vec<[f64; 1]> = normals.iter().map(|n| [norm2(*n).sqrt()]).collect();
    let blended_lengths = carry(from, sources, &lengths);
    blended
        .into_par_iter()
        .zip(blended_lengths)
        .zip(sources)
        .map(|((n, [length]), source)| match *source {
            VertexSource::Vertex(_) => n,
            VertexSource::Face { face, .. } => {
                let direction = if norm2(n) > 1e-12 * length * length {
                    unit(n)
                } else {
                    face_normal(from, face, normals)
                };
                direction.map(|c| c * length)
            }
        })
        .collect()
}

/// Exact bit patterns of a position (so -0.0 and 0.0 differ, as they do
/// in the files).
pub(crate) fn bits(p: &Point3) -> [u64; 3] {
    p.map(f64::to_bits)
}

/// The first input vertex at each position, and the positions several
/// input vertices share.
pub(crate) fn vertex_at_position(
    vertices: &[Point3],
) -> (HashMap<[u64; 3], u32>, HashSet<[u64; 3]>) {
    let mut map = HashMap::default();
    map.reserve(vertices.len());
    let mut shared = HashSet::default();
    for (v, p) in vertices.iter().enumerate() {
        let key = bits(p);
        match map.entry(key) {
            Entry::Occupied(_) => {
                shared.insert(key);
            }
            Entry::Vacant(slot) => {
                slot.insert(v as u32);
            }
        }
    }
    (map, shared)
}

/// Sources from a cloud: the exact match, else the nearest point (ties
/// to kiddo's choice, which is fixed for a given input).
fn nearest_points(
    points: &[Point3],
    to: &[Point3],
    exact: &[Option<u32>],
) -> Option<Vec<VertexSource>> {
    if points.is_empty() {
        return None;
    }
    let tree = PointTree::new(points)?;
    let sources = to
        .par_iter()
        .zip(exact)
        .map(|(p, found)| VertexSource::Vertex(found.unwrap_or_else(|| tree.nearest(p).0 as u32)))
        .collect();
    Some(sources)
}

fn triangle(from: &Mesh, face: u32) -> Triangle {
    let [a, b, c] = from.faces[face as usize]
        .map(|v| from.vertices[v as usize])
        .map(|p| Vector::new(p[0], p[1], p[2]));
    Triangle::new(a, b, c)
}

/// The squared distance from `p` to `face`, and the weights of its
/// closest point there.
pub(crate) fn closest_on_face(from: &Mesh, face: u32, p: Point3) -> (f64, [f64; 3]) {
    let query = Vector::new(p[0], p[1], p[2]);
    let (projection, location) =
        triangle(from, face).project_local_point_and_get_location(query, false);
    let d = projection.point - query;
    let weights = location
        .barycentric_coordinates()
        .map(|w| w.map(|x| x.clamp(0.0, 1.0)))
        .filter(|w| w.iter().all(|x| x.is_finite()) && w.iter().sum::<f64>() > 0.0)
        .map_or([1.0, 0.0, 0.0], |w| {
            let total: f64 = w.iter().sum();
            w.map(|x| x / total)
        });
    (d.length_squared(), weights)
}

fn face_source(from: &Mesh, face: u32, p: Point3) -> VertexSource {
    VertexSource::Face {
        face,
        weights: closest_on_face(from, face, p).1,
    }
}

/// The unit normal of `face`, on the side of its corners' normals (the
/// first corner's normal as it is if the face has no area).
fn face_normal(from: &Mesh, face: u32, normals: &[Point3]) -> Point3 {
    let [a, b, c] = from.faces[face as usize];
    let [pa, pb, pc] = [a, b, c].map(|v| from.vertices[v as usize]);
    let n = cross(sub(pb, pa), sub(pc, pa));
    if norm2(n) == 0.0 {
        return normals[a as usize];
    }
    let side: f64 = [a, b, c].iter().map(|&v| dot(n, normals[v as usize])).sum();
    let n = unit(n);
    if side < 0.0 {
        n.map(|x| -x)
    } else {
        n
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// Points without faces, as the mesh to carry attributes to.
    fn points(vertices: &[Point3]) -> Mesh {
        Mesh {
            vertices: vertices.to_vec(),
            faces: Vec::new(),
        }
    }

    /// A jittered grid sheet, its height a wave.
    pub(crate) fn sheet(n: usize, seed: u64) -> Mesh {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let mut vertices = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let x = i as f64 + rng.random_range(-0.3..0.3);
                let y = j as f64 + rng.random_range(-0.3..0.3);
                vertices.push([x, y, (0.4 * x).sin() + 0.2 * y]);
            }
        }
        let mut faces = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let v = (j * n + i) as u32;
                let n = n as u32;
                faces.push([v, v + 1, v + n + 1]);
                faces.push([v, v + n + 1, v + n]);
            }
        }
        Mesh { vertices, faces }
    }

    #[test]
    fn kept_vertices_are_copied_and_new_ones_blend_their_face() {
        let mesh = sheet(4, 1);
        let [a, b, _] = mesh.faces[0].map(|v| mesh.vertices[v as usize]);
        let midpoint = [0, 1, 2].map(|c| 0.5 * (a[c] + b[c]));
        let sources = vertex_sources(&mesh, &points(&[mesh.vertices[5], midpoint])).unwrap();
        assert_eq!(sources[0], VertexSource::Vertex(5));
        let colours: Vec<[f64; 1]> = (0..mesh.vertices.len()).map(|v| [v as f64]).collect();
        let carried = carry(&mesh, &sources, &colours);
        assert_eq!(carried[0], [5.0]);
        // The midpoint of face 0's first edge, vertices 0 and 1.
        assert!((carried[1][0] - 0.5).abs() < 1e-12, "{:?}", carried[1]);
    }

    #[test]
    fn values_blend_without_weightless_corners_and_labels_take_the_nearest() {
        let mesh = Mesh {
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            faces: vec![[0, 1, 2]],
        };
        let to = [[0.6, 0.0, 0.0], [0.1, 0.2, 0.0], [0.0, 1.0, 0.0]];
        let sources = vertex_sources(&mesh, &points(&to)).unwrap();
        let values = carry_values(&mesh, &sources, &[1.0, 3.0, f64::NAN]);
        // On the edge 0-1, away from the NaN corner: 0.4 · 1 + 0.6 · 3.
        assert!((values[0] - 2.2).abs() < 1e-12, "{values:?}");
        assert!(values[1].is_nan(), "a blend with a NaN corner is NaN");
        assert!(values[2].is_nan(), "a kept vertex keeps its value");
        let labels = carry_nearest_corner(&mesh, &sources, &[10u8, 20, 30]);
        assert_eq!(labels, [20, 10, 30]);
    }

    #[test]
    fn fast_sources_match_the_reference_on_random_points() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        for seed in 0..5 {
            let mesh = sheet(12, seed);
            let mut to: Vec<Point3> = (0..300)
                .map(|_| {
                    [
                        rng.random_range(-2.0..13.0),
                        rng.random_range(-2.0..13.0),
                        rng.random_range(-2.0..3.0),
                    ]
                })
                .collect();
            to.extend(mesh.vertices.iter().step_by(7));
            let to = points(&to);
            let fast = vertex_sources(&mesh, &to).unwrap();
            let reference = vertex_sources_reference(&mesh, &to);
            // Carrying the positions themselves gives each source's point:
            // the closest point of the surface, whichever face on a tie.
            let fast_points = carry(&mesh, &fast, &mesh.vertices);
            let reference_points = carry(&mesh, &reference, &mesh.vertices);
            for (i, (f, r)) in fast_points.iter().zip(&reference_points).enumerate() {
                let gap = norm2(sub(*f, *r)).sqrt();
                assert!(gap < 1e-9, "seed {seed}, point {i}: {f:?} against {r:?}");
            }
            for (f, r) in fast.iter().zip(&reference) {
                if let VertexSource::Vertex(_) = r {
                    assert_eq!(f, r);
                }
            }
        }
    }

    #[test]
    fn normals_keep_their_lengths_and_cancelling_ones_take_the_face_normal() {
        let mesh = Mesh {
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            faces: vec![[0, 1, 2]],
        };
        let sources =
            vertex_sources(&mesh, &points(&[[0.25, 0.25, 0.0], [0.0, 0.0, 0.0]])).unwrap();
        let tilted = [0.6, 0.0, 0.8];
        let unit_normals = carry_normals(&mesh, &sources, &[[0.0, 0.0, 1.0], tilted, tilted]);
        let length = norm2(unit_normals[0]).sqrt();
        assert!(
            (length - 1.0).abs() < 1e-15,
            "unit normals blend to a unit one: {length}"
        );
        assert_eq!(unit_normals[1], [0.0, 0.0, 1.0]);
        let long = [[0.0, 0.0, 2.0], [0.0, 0.0, 6.0], [0.0, 0.0, 6.0]];
        let carried = carry_normals(&mesh, &sources, &long);
        // Weights 0.5, 0.25, 0.25: the lengths blend to 4.
        assert_eq!(carried[0], [0.0, 0.0, 4.0]);
        assert_eq!(
            carried[1], long[0],
            "a kept vertex keeps its normal as it was"
        );
        let cancelling = [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.0, 0.0, 0.0]];
        let midpoint = vertex_sources(&mesh, &points(&[[0.5, 0.0, 0.0]])).unwrap();
        assert_eq!(
            carry_normals(&mesh, &midpoint, &cancelling)[0],
            [0.0, 0.0, 1.0]
        );
    }

    /// A sheet whose faces right of x = 5 have their own copies of their
    /// vertices (a seam down the middle, and the originals of the right
    /// half left unused, first at their positions); the output is the
    /// sheet with its faces and vertices shuffled. Every output vertex
    /// finds the input vertex its faces used, on either side of the seam,
    /// as the reference does.
    #[test]
    fn each_side_of_a_seam_keeps_its_own_vertices() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let mut mesh = sheet(10, 5);
        let n = mesh.vertices.len() as u32;
        let right: Vec<bool> = mesh
            .faces
            .iter()
            .map(|f| f.iter().map(|&v| mesh.vertices[v as usize][0]).sum::<f64>() > 15.0)
            .collect();
        mesh.vertices.extend_from_within(..);
        for (face, &right) in mesh.faces.iter_mut().zip(&right) {
            if right {
                *face = face.map(|v| v + n);
            }
        }
        // The output: vertices in a random order, faces renumbered and
        // turned to start at another corner.
        let mut order: Vec<u32> = (0..mesh.vertices.len() as u32).collect();
        for i in (1..order.len()).rev() {
            order.swap(i, rng.random_range(0..=i));
        }
        let mut new_index = vec![0; order.len()];
        for (new, &old) in order.iter().enumerate() {
            new_index[old as usize] = new as u32;
        }
        let out = Mesh {
            vertices: order.iter().map(|&v| mesh.vertices[v as usize]).collect(),
            faces: mesh
                .faces
                .iter()
                .rev()
                .map(|f| [f[1], f[2], f[0]].map(|v| new_index[v as usize]))
                .collect(),
        };
        let fast = vertex_sources(&mesh, &out).unwrap();
        assert_eq!(fast, vertex_sources_reference(&mesh, &out));
        for face in &out.faces {
            for &v in face {
                assert_eq!(fast[v as usize], VertexSource::Vertex(order[v as usize]));
            }
        }
    }

    /// The seamed sheet with every face cut in three at its centroid, so
    /// that no output face has an input twin: each seam vertex takes the
    /// vertex of the face its first piece was cut from.
    #[test]
    fn a_seam_whose_faces_were_all_cut_keeps_its_sides() {
        let mut mesh = sheet(8, 6);
        let n = mesh.vertices.len() as u32;
        mesh.vertices.extend_from_within(..);
        for face in mesh.faces.iter_mut() {
            if face
                .iter()
                .map(|&v| mesh.vertices[v as usize][0])
                .sum::<f64>()
                > 12.0
            {
                *face = face.map(|v| v + n);
            }
        }
        let mut out = mesh.clone();
        out.faces.clear();
        for &[a, b, c] in &mesh.faces {
            let m = out.vertices.len() as u32;
            out.vertices.push(centroid(&mesh.vertices, [a, b, c]));
            out.faces.extend([[a, b, m], [b, c, m], [c, a, m]]);
        }
        let fast = vertex_sources(&mesh, &out).unwrap();
        assert_eq!(fast, vertex_sources_reference(&mesh, &out));
        // A used vertex is itself; an unused copy, in no face, the first
        // vertex at its position.
        let used: HashSet<u32> = mesh.faces.iter().flatten().copied().collect();
        for v in 0..mesh.vertices.len() as u32 {
            let want = if used.contains(&v) { v } else { v % n };
            assert_eq!(fast[v as usize], VertexSource::Vertex(want), "vertex {v}");
        }
    }

    /// Two triangles on either side of a seam, each with its own copies
    /// of the seam's ends (face 0 left, face 1 right). A new vertex on the
    /// seam's edge is on both; the piece of the right face it belongs to
    /// gives it the right face, though face 0 has the lower index.
    #[test]
    fn a_new_vertex_on_a_seam_takes_its_pieces_face() {
        let seam = [[0.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        let mesh = Mesh {
            vertices: vec![
                seam[0],
                seam[1],
                [-1.0, 1.0, 0.0],
                seam[0],
                [1.0, 1.0, 0.0],
                seam[1],
            ],
            faces: vec![[0, 1, 2], [3, 4, 5]],
        };
        // The right face cut along y = 1: its lower piece, with the cut's
        // vertex on the seam at (0, 1, 0) and one on its other edge.
        let out = Mesh {
            vertices: vec![seam[0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            faces: vec![[0, 1, 2]],
        };
        for sources in [
            vertex_sources(&mesh, &out).unwrap(),
            vertex_sources_reference(&mesh, &out),
        ] {
            assert_eq!(sources[0], VertexSource::Vertex(3));
            assert!(
                matches!(sources[2], VertexSource::Face { face: 1, .. }),
                "{sources:?}"
            );
        }
    }

    /// The sheet with the vertices within a disc moved off the surface by
    /// up to 0.3 in each direction (as a smoothed border's vertices lie
    /// near it): new vertices whose closest faces are searched among the
    /// faces within reach of their kept neighbours only. The faces are
    /// fewer than all, hold each query's closest face, and the sources
    /// are the reference's.
    #[test]
    fn faces_within_reach_hold_every_closest_face() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        for seed in 0..4 {
            let mesh = sheet(30, seed);
            let mut out = mesh.clone();
            let centre = [rng.random_range(5.0..24.0), rng.random_range(5.0..24.0)];
            for p in out.vertices.iter_mut() {
                if (p[0] - centre[0]).hypot(p[1] - centre[1]) < 2.5 {
                    *p = p.map(|c| c + rng.random_range(-0.3..0.3));
                }
            }
            let fast = vertex_sources(&mesh, &out).unwrap();
            let reference = vertex_sources_reference(&mesh, &out);
            let gap = |f: &[Point3], r: &[Point3]| {
                f.iter()
                    .zip(r)
                    .map(|(a, b)| norm2(sub(*a, *b)))
                    .fold(0.0, f64::max)
            };
            let points = [&fast, &reference].map(|s| carry(&mesh, s, &mesh.vertices));
            assert!(gap(&points[0], &points[1]) < 1e-18, "seed {seed}");

            let exact: Vec<Option<u32>> = fast
                .iter()
                .map(|s| match s {
                    VertexSource::Vertex(v) => Some(*v),
                    VertexSource::Face { .. } => None,
                })
                .collect();
            let balls = query_balls(&mesh, &out, &exact, &first_faces(&out, &exact));
            let near = faces_within_reach(&mesh, &balls, diagonal(&mesh)).unwrap();
            assert!(near.len() < mesh.faces.len() / 4, "{} faces", near.len());
            for (centre, _) in balls {
                let closest = (0..mesh.faces.len() as u32)
                    .min_by(|&a, &b| {
                        let d = |f| closest_on_face(&mesh, f, centre).0;
                        d(a).total_cmp(&d(b)).then(a.cmp(&b))
                    })
                    .unwrap();
                assert!(near.binary_search(&closest).is_ok(), "seed {seed}");
            }
        }
    }

    #[test]
    fn a_cloud_gives_its_nearest_point() {
        let cloud = Mesh {
            vertices: vec![[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]],
            faces: Vec::new(),
        };
        let to = points(&[[1.0, 0.0, 0.0], [9.0, 1.0, 0.0], [10.0, 0.0, 0.0]]);
        let expected = [0, 1, 1].map(VertexSource::Vertex).to_vec();
        assert_eq!(vertex_sources(&cloud, &to), Some(expected.clone()));
        assert_eq!(vertex_sources(&Mesh::default(), &to), None);
        assert_eq!(vertex_sources_reference(&cloud, &to), expected);
    }
}
