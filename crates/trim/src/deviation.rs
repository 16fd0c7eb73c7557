//! How far one mesh's vertices lie from another mesh's surface: the
//! one-sided Hausdorff distance over vertices, meshtrim's own measure of
//! how much a stage changed a scan (the paper measures its edges against
//! the cloud, section 4, not the mesh made from them).
//!
//! Cleanup keeps every vertex away from the border bands bit for bit, so
//! of a scan and its cleaned mesh only the vertices of the bands differ:
//! the input's removed vertices (the jagged border, and what the new
//! border cut away) measured against the output tell how far the
//! surface was taken back; the output's new vertices measured against the
//! input tell how far the new surface lies off the scanned one (a gap the
//! smoothed border bridges). A vertex at exactly a vertex of the other
//! mesh (bit for bit) is on its surface and is not measured; every other
//! one takes the distance to its closest point on the other's faces,
//! found as [`crate::vertex_sources`] finds a new vertex's (only the
//! faces within reach of each vertex are indexed, so the cost follows the
//! vertices that moved, not the mesh). Measured over vertices, as MeshLab's
//! Hausdorff filter samples them; a face's interior may lie farther.

use rayon::prelude::*;

use crate::attributes::{
    bits, closest_on_face, diagonal, faces_within_reach, surface_distance_bounds,
    vertex_at_position, Ball,
};
use crate::geom::{norm2, sub, Point3};
use crate::hash::HashMap;
use crate::mesh::Mesh;
use crate::spatial::closest_face::{FaceIndex, Scratch};
use crate::spatial::PointTree;

/// How far the vertices of a mesh lie from a surface.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Deviation {
    /// Vertices not at exactly a vertex of the surface: those measured.
    pub vertices: usize,
    /// The largest distance; 0 when no vertex was measured.
    pub max: f64,
    /// The mean distance over the vertices measured; 0 when none was.
    pub mean: f64,
    /// The vertex at the largest distance (its position), if any was
    /// measured.
    pub at: Option<Point3>,
}

/// How far the vertices of `mesh` lie from the surface of `surface` (see
/// the module doc). The vertices of `mesh`'s faces are measured (a vertex
/// in no face is no part of its surface: a range map's unused samples),
/// or, without faces, every vertex. A `surface` without faces is taken as a cloud: the distance is to
/// its nearest vertex. Both meshes' positions must be finite and their
/// face indices valid (as [`Mesh::validate`] checks); the result is the
/// same whatever the number of threads.
pub fn surface_deviation(surface: &Mesh, mesh: &Mesh) -> Deviation {
    let (at_position, _) = vertex_at_position(&surface.vertices);
    let exact: Vec<Option<u32>> = mesh
        .vertices
        .par_iter()
        .map(|p| at_position.get(&bits(p)).copied())
        .collect();
    drop(at_position);
    let on_faces = used_vertices(mesh);
    let measured: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&v| exact[v as usize].is_none() && on_faces[v as usize])
        .collect();
    let distances = if surface.faces.is_empty() {
        distances_to_points(surface, mesh, &measured)
    } else {
        distances_to_faces(surface, mesh, &exact, &measured)
    };
    summary(&mesh.vertices, &measured, &distances)
}

/// The distance from each measured vertex to its closest face of
/// `surface`, among the faces that meet the ball each vertex's path along
/// `mesh`'s edges to a vertex on the surface bounds (all faces where no
/// path does).
fn distances_to_faces(
    surface: &Mesh,
    mesh: &Mesh,
    exact: &[Option<u32>],
    measured: &[u32],
) -> Vec<f64> {
    let balls = bounded_balls(
        mesh,
        measured,
        &surface_distance_bounds(surface, mesh, exact),
    );
    let index = match faces_within_reach(surface, &balls, diagonal(surface)) {
        Some(near) => FaceIndex::of_faces(surface, &near),
        None => FaceIndex::new(surface),
    };
    let identity: Vec<u32> = (0..surface.faces.len() as u32).collect();
    let labels = index.labels(&identity);
    balls
        .par_iter()
        .map_init(Scratch::default, |scratch, &(p, _)| {
            // Every face is within an infinite reach of a finite point.
            let face = index
                .nearest_label(p, f64::INFINITY, &labels, scratch)
                .unwrap_or(0);
            closest_on_face(surface, face, p).0.sqrt()
        })
        .collect()
}

/// Each measured vertex with a distance its closest face lies within:
/// its path's `bounds`, or where it has no path (a piece cut away whole,
/// a vertex in no face) the distance to the nearest vertex that has one
/// plus that one's bound, so that such a vertex does not make every face
/// of the surface a candidate. Unbounded only when no vertex has a path.
fn bounded_balls(mesh: &Mesh, measured: &[u32], bounds: &HashMap<u32, f64>) -> Vec<Ball> {
    let mut pathed: Vec<u32> = bounds.keys().copied().collect();
    pathed.sort_unstable();
    let positions: Vec<Point3> = pathed.iter().map(|&v| mesh.vertices[v as usize]).collect();
    let tree = (!positions.is_empty())
        .then(|| PointTree::new(&positions))
        .flatten();
    measured
        .par_iter()
        .map(|&v| {
            let p = mesh.vertices[v as usize];
            let bound = bounds.get(&v).copied().or_else(|| {
                let (nearest, d2) = tree.as_ref()?.nearest(&p);
                Some(d2.sqrt() + bounds[&pathed[nearest]])
            });
            (p, bound.unwrap_or(f64::INFINITY))
        })
        .collect()
}

/// The distance from each measured vertex to the nearest vertex of
/// `surface` (a cloud).
fn distances_to_points(surface: &Mesh, mesh: &Mesh, measured: &[u32]) -> Vec<f64> {
    let tree = (!surface.vertices.is_empty()).then(|| PointTree::new(&surface.vertices));
    let Some(tree) = tree.flatten() else {
        return Vec::new();
    };
    measured
        .par_iter()
        .map(|&v| {
            let p = mesh.vertices[v as usize];
            let nearest = surface.vertices[tree.nearest(&p).0];
            norm2(sub(nearest, p)).sqrt()
        })
        .collect()
}

/// The deviation of the measured vertices at `distances` (none measured
/// when `distances` is empty: a surface without vertices).
fn summary(vertices: &[Point3], measured: &[u32], distances: &[f64]) -> Deviation {
    let mut deviation = Deviation::default();
    let mut sum = 0.0;
    for (&v, &distance) in measured.iter().zip(distances) {
        deviation.vertices += 1;
        sum += distance;
        if deviation.at.is_none() || distance > deviation.max {
            deviation.max = distance;
            deviation.at = Some(vertices[v as usize]);
        }
    }
    if deviation.vertices > 0 {
        deviation.mean = sum / deviation.vertices as f64;
    }
    deviation
}

/// Whether each vertex is a corner of some face; every vertex when there
/// are no faces (a cloud).
fn used_vertices(mesh: &Mesh) -> Vec<bool> {
    let mut used = vec![mesh.faces.is_empty(); mesh.vertices.len()];
    for &v in mesh.faces.iter().flatten() {
        used[v as usize] = true;
    }
    used
}

fn same_bits(a: Point3, b: Point3) -> bool {
    a.map(f64::to_bits) == b.map(f64::to_bits)
}

/// The plain [`surface_deviation`] the fast one is tested against: every
/// vertex of `mesh`'s faces not at a vertex of `surface` against every
/// face of `surface` (or, without faces, every vertex).
pub fn surface_deviation_reference(surface: &Mesh, mesh: &Mesh) -> Deviation {
    let on_faces = used_vertices(mesh);
    let mut measured = Vec::new();
    let mut distances = Vec::new();
    for (v, p) in mesh.vertices.iter().enumerate() {
        if !on_faces[v] || surface.vertices.iter().any(|q| same_bits(*q, *p)) {
            continue;
        }
        let nearest2 = if surface.faces.is_empty() {
            let to_points = surface.vertices.iter().map(|q| norm2(sub(*q, *p)));
            to_points.fold(f64::INFINITY, f64::min)
        } else {
            let to_faces =
                (0..surface.faces.len() as u32).map(|f| closest_on_face(surface, f, *p).0);
            to_faces.fold(f64::INFINITY, f64::min)
        };
        // Infinite only against a surface without vertices: none measured.
        if nearest2.is_finite() {
            measured.push(v as u32);
            distances.push(nearest2.sqrt());
        }
    }
    summary(&mesh.vertices, &measured, &distances)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// The carrying tests' jittered grid sheet of `n` × `n` vertices,
    /// its height scaled by `height`.
    fn sheet(n: usize, height: f64, seed: u64) -> Mesh {
        let mut mesh = crate::attributes::tests::sheet(n, seed);
        mesh.vertices.iter_mut().for_each(|p| p[2] *= height);
        mesh
    }

    #[test]
    fn a_mesh_does_not_deviate_from_itself() {
        let mesh = sheet(8, 1.0, 1);
        assert_eq!(surface_deviation(&mesh, &mesh), Deviation::default());
    }

    #[test]
    fn a_vertex_in_no_face_is_not_measured_but_a_clouds_points_are() {
        let flat = sheet(5, 0.0, 3);
        let mut with_stray = flat.clone();
        with_stray.vertices.push([2.0, 2.0, 50.0]);
        assert_eq!(surface_deviation(&flat, &with_stray), Deviation::default());
        let cloud = Mesh {
            vertices: with_stray.vertices.clone(),
            faces: Vec::new(),
        };
        let d = surface_deviation(&flat, &cloud);
        assert_eq!((d.vertices, d.max, d.at), (1, 50.0, Some([2.0, 2.0, 50.0])));
    }

    #[test]
    fn a_vertex_lifted_off_a_flat_sheet_is_as_far_as_it_was_lifted() {
        let flat = sheet(6, 0.0, 2);
        let mut lifted = flat.clone();
        // An inner vertex: its closest point on the flat sheet is below it.
        let v = 2 * 6 + 3;
        lifted.vertices[v][2] += 0.25;
        let d = surface_deviation(&flat, &lifted);
        assert_eq!(d.vertices, 1);
        assert!(
            (d.max - 0.25).abs() < 1e-12 && (d.mean - 0.25).abs() < 1e-12,
            "{d:?}"
        );
        assert_eq!(d.at, Some(lifted.vertices[v]));
        // Back the other way, the vertices round it are measured against
        // faces that rise to it.
        let back = surface_deviation(&lifted, &flat);
        assert_eq!(back.vertices, 1);
        assert!(back.max > 0.0 && back.max < 0.25, "{back:?}");
    }

    /// Random sheets with some vertices moved and some faces cut away:
    /// the fast deviation is the plain one, both ways.
    #[test]
    fn matches_the_reference_on_random_edits() {
        for seed in 0..40u64 {
            let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
            let n = rng.random_range(3..9);
            let from = sheet(n, rng.random_range(0.0..2.0), seed);
            let mut to = from.clone();
            for p in to.vertices.iter_mut() {
                if rng.random_bool(0.2) {
                    let scale = rng.random_range(0.01..3.0);
                    p.iter_mut()
                        .for_each(|c| *c += rng.random_range(-scale..scale));
                }
            }
            let keep = rng.random_range(0.3..1.0);
            to.faces.retain(|_| rng.random_bool(keep));
            for (surface, mesh) in [(&from, &to), (&to, &from)] {
                let fast = surface_deviation(surface, mesh);
                let plain = surface_deviation_reference(surface, mesh);
                assert_eq!(fast.vertices, plain.vertices, "seed {seed}");
                assert!(
                    (fast.max - plain.max).abs() <= 1e-7,
                    "seed {seed}: {fast:?} {plain:?}"
                );
                assert!(
                    (fast.mean - plain.mean).abs() <= 1e-7,
                    "seed {seed}: {fast:?} {plain:?}"
                );
            }
        }
    }
}
