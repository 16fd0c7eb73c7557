//! The closest face of a triangle mesh to a point, within a distance: the
//! query of the trimming stage's support test (the regions where the
//! cloud's points project are kept), where a million cloud points are
//! projected on a mesh of up to a few million faces.
//!
//! A bounding-volume hierarchy of our own: the faces ordered as a balanced
//! kd-tree over their centroids (median splits on the longest axis, in
//! parallel), groups of `LEAF` consecutive faces as leaves, and each level
//! above pairing consecutive boxes of the level below, so the tree needs
//! no pointers. Building it is several times cheaper than parry's binned
//! SAH hierarchy, which parry builds on one thread and which takes longer
//! than all the projections on a 3M-triangle mesh. The distance to each
//! triangle is parry's exact point-triangle projection; the answer is the
//! face at the smallest distance, the lower index on a tie, tested against
//! parry's `TriMesh` on random meshes.

use parry3d_f64::math::Vector;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Triangle;
use rayon::prelude::*;

use crate::geom::{norm2, Point3};
use crate::mesh::Mesh;

/// Faces per leaf.
const LEAF: usize = 4;

/// An axis-aligned box: lower and upper corners.
type Aabb = (Point3, Point3);

/// Closest-face queries on one mesh.
pub struct FaceIndex {
    /// The triangles, in Morton order.
    triangles: Vec<Triangle>,
    /// The mesh's index of each triangle.
    faces: Vec<u32>,
    /// Boxes, level by level from the leaves (level 0) to the root.
    levels: Vec<Vec<Aabb>>,
}

impl FaceIndex {
    /// Indexes the faces of `mesh` (whose indices must be valid).
    pub fn new(mesh: &Mesh) -> Self {
        let corners = |f: &[u32; 3]| f.map(|v| mesh.vertices[v as usize]);
        // Centroids in f32: they only order the faces (the tree's shape),
        // never decide a distance, and half the bytes move faster.
        let mut items: Vec<([f32; 3], u32)> = mesh
            .faces
            .par_iter()
            .enumerate()
            .map(|(f, face)| {
                let c = corners(face);
                (
                    [0, 1, 2].map(|a| ((c[0][a] + c[1][a] + c[2][a]) / 3.0) as f32),
                    f as u32,
                )
            })
            .collect();
        median_split_order(&mut items);
        let faces: Vec<u32> = items.into_iter().map(|(_, f)| f).collect();
        let triangles: Vec<Triangle> = faces
            .par_iter()
            .map(|&f| {
                let [a, b, c] =
                    corners(&mesh.faces[f as usize]).map(|p| Vector::new(p[0], p[1], p[2]));
                Triangle::new(a, b, c)
            })
            .collect();
        let leaves: Vec<Aabb> = faces
            .par_chunks(LEAF)
            .map(|group| bounds(group.iter().flat_map(|&f| corners(&mesh.faces[f as usize]))))
            .collect();
        let mut levels = if leaves.is_empty() {
            Vec::new()
        } else {
            vec![leaves]
        };
        while levels.last().is_some_and(|l| l.len() > 1) {
            let below = &levels[levels.len() - 1];
            let above = below
                .chunks(2)
                .map(|pair| pair.iter().fold(EMPTY, |acc, b| union(acc, *b)))
                .collect();
            levels.push(above);
        }
        Self {
            triangles,
            faces,
            levels,
        }
    }

    /// The face closest to `p` within `max_dist` (the lower index on a tie).
    pub fn nearest_face(&self, p: Point3, max_dist: f64) -> Option<u32> {
        let query = Vector::new(p[0], p[1], p[2]);
        let mut best: Option<(f64, u32)> = None;
        let mut limit = max_dist;
        let top = self.levels.len().checked_sub(1)?;
        // Depth first, nearer child first; (level, index) pairs.
        let mut stack: Vec<(usize, usize)> = Vec::with_capacity(2 * self.levels.len());
        stack.push((top, 0));
        while let Some((level, i)) = stack.pop() {
            if box_distance(p, self.levels[level][i]) > limit {
                continue;
            }
            if level == 0 {
                for t in i * LEAF..((i + 1) * LEAF).min(self.triangles.len()) {
                    let d = (self.triangles[t].project_local_point(query, false).point - query)
                        .length();
                    let face = self.faces[t];
                    if d <= limit && best.is_none_or(|(bd, bf)| d < bd || (d == bd && face < bf)) {
                        best = Some((d, face));
                        limit = d;
                    }
                }
                continue;
            }
            let below = &self.levels[level - 1];
            let (left, right) = (2 * i, 2 * i + 1);
            if right < below.len() {
                // Push the farther child first so the nearer is searched first.
                let (dl, dr) = (box_distance(p, below[left]), box_distance(p, below[right]));
                if dl <= dr {
                    stack.extend([(level - 1, right), (level - 1, left)]);
                } else {
                    stack.extend([(level - 1, left), (level - 1, right)]);
                }
            } else {
                stack.push((level - 1, left));
            }
        }
        best.map(|b| b.1)
    }
}

/// Orders faces (centroid, index) as a balanced kd-tree over their
/// centroids: the first half (a whole number of leaves, a power of two)
/// goes left of the median along the longest axis, recursively. The
/// hierarchy's levels then pair exactly these halves, so its boxes are as
/// tight as a median-split tree's. Ties go by face index, so the order does
/// not depend on the threads.
fn median_split_order(items: &mut [([f32; 3], u32)]) {
    let n = items.len();
    if n <= LEAF {
        return;
    }
    let capacity = n.div_ceil(LEAF).next_power_of_two() * LEAF;
    let mid = capacity / 2;
    let (low, high) = bounds(items.iter().map(|i| i.0.map(f64::from)));
    let axis = (0..3)
        .max_by(|&a, &b| (high[a] - low[a]).total_cmp(&(high[b] - low[b])))
        .unwrap_or(0);
    items.select_nth_unstable_by(mid, |a, b| {
        a.0[axis].total_cmp(&b.0[axis]).then(a.1.cmp(&b.1))
    });
    let (left, right) = items.split_at_mut(mid);
    if n > 20_000 {
        rayon::join(|| median_split_order(left), || median_split_order(right));
    } else {
        median_split_order(left);
        median_split_order(right);
    }
}

const EMPTY: Aabb = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);

fn union(a: Aabb, b: Aabb) -> Aabb {
    (
        [0, 1, 2].map(|k| a.0[k].min(b.0[k])),
        [0, 1, 2].map(|k| a.1[k].max(b.1[k])),
    )
}

/// The bounding box of `points`.
fn bounds(points: impl Iterator<Item = Point3>) -> Aabb {
    points.fold(EMPTY, |acc, p| union(acc, (p, p)))
}

/// Distance from `p` to the box (0 inside).
fn box_distance(p: Point3, (low, high): Aabb) -> f64 {
    let gap = [0, 1, 2].map(|a| (low[a] - p[a]).max(p[a] - high[a]).max(0.0));
    norm2(gap).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d_f64::query::PointQueryWithLocation;
    use parry3d_f64::shape::TriMesh;
    use rand::{RngExt, SeedableRng};

    /// A wavy sheet and, above it, a second sheet (an envelope's far side),
    /// with jittered vertices so that faces differ in size.
    fn two_sheets(seed: u64, side: u32) -> Mesh {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut mesh = Mesh::default();
        for layer in 0..2 {
            let base = mesh.vertices.len() as u32;
            for i in 0..=side {
                for j in 0..=side {
                    let (x, y) = (
                        i as f64 + rng.random_range(-0.3..0.3),
                        j as f64 + rng.random_range(-0.3..0.3),
                    );
                    let z = (0.3 * x).sin() + 1.5 * layer as f64;
                    mesh.vertices.push([x, y, z]);
                }
            }
            let at = |i: u32, j: u32| base + i * (side + 1) + j;
            for i in 0..side {
                for j in 0..side {
                    mesh.faces.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                    mesh.faces.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
        mesh
    }

    #[test]
    fn matches_parry_on_random_points() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        for seed in 0..4 {
            let mesh = two_sheets(seed, 24);
            let index = FaceIndex::new(&mesh);
            let vertices = mesh
                .vertices
                .iter()
                .map(|v| Vector::new(v[0], v[1], v[2]))
                .collect();
            let parry = TriMesh::new(vertices, mesh.faces.clone()).unwrap();
            let distance_to = |p: Point3, f: u32| {
                let [a, b, c] = mesh.faces[f as usize]
                    .map(|v| mesh.vertices[v as usize])
                    .map(|q| Vector::new(q[0], q[1], q[2]));
                let q = Vector::new(p[0], p[1], p[2]);
                (Triangle::new(a, b, c).project_local_point(q, false).point - q).length()
            };
            for _ in 0..2000 {
                let p = [
                    rng.random_range(-2.0..26.0),
                    rng.random_range(-2.0..26.0),
                    rng.random_range(-1.5..3.0),
                ];
                let max_dist = rng.random_range(0.05..1.5);
                let ours = index.nearest_face(p, max_dist);
                let q = Vector::new(p[0], p[1], p[2]);
                let theirs = parry
                    .project_local_point_and_get_location_with_max_dist(q, false, max_dist)
                    .map(|(_, (face, _))| face);
                match (ours, theirs) {
                    (None, None) => {}
                    (Some(a), Some(b)) => {
                        // The same face, or one just as close (a tie).
                        let (da, db) = (distance_to(p, a), distance_to(p, b));
                        assert!(da <= db, "{p:?}: face {a} at {da}, parry's {b} at {db}");
                        assert!(a == b || da == db, "{p:?}: {a} vs {b}");
                    }
                    other => {
                        // Only at the edge of max_dist can one find and the
                        // other not.
                        let f = other.0.or(other.1).unwrap();
                        let d = distance_to(p, f);
                        assert!(
                            (d - max_dist).abs() < 1e-9,
                            "{p:?}: {other:?}, {d} vs {max_dist}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn empty_and_single_face_meshes() {
        let none = FaceIndex::new(&Mesh::default());
        assert_eq!(none.nearest_face([0.0; 3], 1.0), None);
        let one = Mesh {
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            faces: vec![[0, 1, 2]],
        };
        let index = FaceIndex::new(&one);
        assert_eq!(index.nearest_face([0.2, 0.2, 0.5], 1.0), Some(0));
        assert_eq!(index.nearest_face([0.2, 0.2, 1.5], 1.0), None);
    }
}
