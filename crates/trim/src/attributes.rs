//! Carrying per-vertex attributes (normals, colours) from a mesh to the
//! mesh made from it: meshtrim's own layer, which the paper does not cover
//! (it works on positions only).
//!
//! Every command that writes a mesh keeps most of its input's vertices as
//! they were and adds a few: where trimming cuts a face, where cleanup's
//! smoothed loops replace a jagged border, where the Delaunay path meshes
//! a cloud. The stages know nothing of attributes, so the carrying is done
//! after them, from positions alone:
//!
//! - an output vertex at exactly the position of an input vertex is that
//!   vertex ([`VertexSource::Vertex`]), its attributes copied bit for bit;
//!   the first such input vertex when several share the position;
//! - any other lies on or near the input surface, and takes the
//!   barycentric weights of its closest point on the closest input face
//!   ([`VertexSource::Face`]; the lower face index on a tie), so a cut
//!   vertex on an edge blends that edge's two ends;
//! - from an input without faces (a cloud), the nearest input point.
//!
//! Normals are blended in direction and in length (unit ones stay unit);
//! colours blended.
//! Positions decide everything, so the result does not depend on how a
//! stage numbered its vertices, nor on the number of threads.

use parry3d_f64::math::Vector;
use parry3d_f64::query::PointQueryWithLocation;
use parry3d_f64::shape::Triangle;
use rayon::prelude::*;

use crate::geom::{cross, dot, norm2, sub, unit, Point3};
use crate::hash::HashMap;
use crate::mesh::Mesh;
use crate::spatial::closest_face::{FaceIndex, Scratch};
use crate::spatial::PointTree;

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

/// Where each of `to` takes its attributes from in `from` (see the module
/// doc); `from`'s face indices must be valid. `None` when `from` has no
/// vertex to take them from (and `to` is not empty).
pub fn vertex_sources(from: &Mesh, to: &[Point3]) -> Option<Vec<VertexSource>> {
    let same_position = vertex_at_position(&from.vertices);
    let exact: Vec<Option<u32>> = to
        .par_iter()
        .map(|p| same_position.get(&bits(p)).copied())
        .collect();
    if exact.iter().all(Option::is_some) {
        return Some(
            exact
                .into_iter()
                .flatten()
                .map(VertexSource::Vertex)
                .collect(),
        );
    }
    if from.faces.is_empty() {
        return nearest_points(&from.vertices, to, &exact);
    }
    let index = FaceIndex::new(from);
    let identity: Vec<u32> = (0..from.faces.len() as u32).collect();
    let labels = index.labels(&identity);
    let sources = to
        .par_iter()
        .zip(&exact)
        .map_init(Scratch::default, |scratch, (&p, found)| match *found {
            Some(v) => VertexSource::Vertex(v),
            None => {
                // Every face is within an infinite reach of a finite point.
                let face = index.nearest_label(p, f64::INFINITY, &labels, scratch);
                face_source(from, face.unwrap_or(0), p)
            }
        })
        .collect();
    Some(sources)
}

/// [`vertex_sources`] by comparing every face: the reference it is tested
/// against.
#[doc(hidden)]
pub fn vertex_sources_reference(from: &Mesh, to: &[Point3]) -> Vec<VertexSource> {
    to.iter()
        .map(|p| {
            if let Some(v) = from.vertices.iter().position(|q| bits(q) == bits(p)) {
                return VertexSource::Vertex(v as u32);
            }
            if from.faces.is_empty() {
                let nearest = (0..from.vertices.len())
                    .min_by(|&a, &b| {
                        let da = norm2(sub(from.vertices[a], *p));
                        let db = norm2(sub(from.vertices[b], *p));
                        da.total_cmp(&db)
                    })
                    .unwrap_or(0);
                return VertexSource::Vertex(nearest as u32);
            }
            let nearest = (0..from.faces.len())
                .map(|f| (closest_on_face(from, f as u32, *p).0, f as u32))
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
                .map(|(_, f)| f)
                .unwrap_or(0);
            face_source(from, nearest, *p)
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
    sources
        .par_iter()
        .map(|source| match *source {
            VertexSource::Vertex(v) => values[v as usize],
            VertexSource::Face { face, weights } => {
                let corners = from.faces[face as usize];
                std::array::from_fn(|c| {
                    (0..3)
                        .map(|k| weights[k] * values[corners[k] as usize][c])
                        .sum()
                })
            }
        })
        .collect()
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
fn bits(p: &Point3) -> [u64; 3] {
    p.map(f64::to_bits)
}

/// The first input vertex at each position.
fn vertex_at_position(vertices: &[Point3]) -> HashMap<[u64; 3], u32> {
    let mut map = HashMap::default();
    map.reserve(vertices.len());
    for (v, p) in vertices.iter().enumerate() {
        map.entry(bits(p)).or_insert(v as u32);
    }
    map
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
fn closest_on_face(from: &Mesh, face: u32, p: Point3) -> (f64, [f64; 3]) {
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
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// A jittered grid sheet, its height a wave.
    fn sheet(n: usize, seed: u64) -> Mesh {
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
        let sources = vertex_sources(&mesh, &[mesh.vertices[5], midpoint]).unwrap();
        assert_eq!(sources[0], VertexSource::Vertex(5));
        let colours: Vec<[f64; 1]> = (0..mesh.vertices.len()).map(|v| [v as f64]).collect();
        let carried = carry(&mesh, &sources, &colours);
        assert_eq!(carried[0], [5.0]);
        // The midpoint of face 0's first edge, vertices 0 and 1.
        assert!((carried[1][0] - 0.5).abs() < 1e-12, "{:?}", carried[1]);
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
        let sources = vertex_sources(&mesh, &[[0.25, 0.25, 0.0], [0.0, 0.0, 0.0]]).unwrap();
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
        let midpoint = vertex_sources(&mesh, &[[0.5, 0.0, 0.0]]).unwrap();
        assert_eq!(
            carry_normals(&mesh, &midpoint, &cancelling)[0],
            [0.0, 0.0, 1.0]
        );
    }

    #[test]
    fn a_cloud_gives_its_nearest_point() {
        let cloud = Mesh {
            vertices: vec![[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]],
            faces: Vec::new(),
        };
        let to = [[1.0, 0.0, 0.0], [9.0, 1.0, 0.0], [10.0, 0.0, 0.0]];
        let expected = [0, 1, 1].map(VertexSource::Vertex).to_vec();
        assert_eq!(vertex_sources(&cloud, &to), Some(expected.clone()));
        assert_eq!(vertex_sources(&Mesh::default(), &to), None);
        assert_eq!(vertex_sources_reference(&cloud, &to), expected);
    }
}
