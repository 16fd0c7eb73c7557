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
//!
//! The support test needs only the *piece* of the closest face, not the
//! face: [`FaceIndex::nearest_label`] takes a label per face, and each node
//! of the hierarchy knows whether all its faces share one. Once a face
//! within reach is found, a node whose faces all carry its label is set
//! aside unsearched: whatever face it holds, nearer or not, the answer's
//! label stays. Only if a face with another label becomes the nearest are
//! the set-aside nodes it could lose to searched after all. Most points
//! lie inside one piece, whose subtrees then go unsearched. The search
//! starts at the leaf of the last answer, and the support test asks in
//! Morton order, so that leaf is usually near: on a 5M-face mesh a query
//! weighs 15 boxes where the face search weighed 42.

use parry3d_f64::math::Vector;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Triangle;
use rayon::prelude::*;

use crate::geom::{norm2, Point3};
use crate::mesh::Mesh;

/// Faces per leaf.
const LEAF: usize = 4;

/// An axis-aligned box: lower and upper corners.
pub(crate) type Aabb = (Point3, Point3);

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
        let all: Vec<u32> = (0..mesh.faces.len() as u32).collect();
        Self::of_faces(mesh, &all)
    }

    /// Indexes the faces of `mesh` listed in `faces` (valid face indices,
    /// each once): queries answer among them, by the mesh's face indices
    /// (so ties go to the lower one, as over the whole mesh).
    pub fn of_faces(mesh: &Mesh, faces: &[u32]) -> Self {
        let corners = |f: &[u32; 3]| f.map(|v| mesh.vertices[v as usize]);
        // Centroids in f32: they only order the faces (the tree's shape),
        // never decide a distance, and half the bytes move faster.
        let mut items: Vec<([f32; 3], u32)> = faces
            .par_iter()
            .map(|&f| {
                let c = corners(&mesh.faces[f as usize]);
                (
                    [0, 1, 2].map(|a| ((c[0][a] + c[1][a] + c[2][a]) / 3.0) as f32),
                    f,
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
        // From the triangles, which lie in leaf order: the mesh's faces
        // and vertices would be read at random once more.
        let leaves: Vec<Aabb> = triangles
            .par_chunks(LEAF)
            .map(|group| {
                bounds(
                    group
                        .iter()
                        .flat_map(|t| [t.a, t.b, t.c].map(|v| [v.x, v.y, v.z])),
                )
            })
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

    /// The face closest to `p` within `max_dist` (the lower index on a
    /// tie), searched box by box: the reference for
    /// [`FaceIndex::nearest_label`].
    #[cfg(test)]
    pub fn nearest_face(&self, p: Point3, max_dist: f64) -> Option<u32> {
        let query = Vector::new(p[0], p[1], p[2]);
        let mut best: Option<(f64, u32)> = None;
        let mut limit = max_dist;
        let top = self.levels.len().checked_sub(1)?;
        // Depth first, nearer child first; (level, index) pairs.
        let mut stack: Vec<(usize, usize)> = Vec::with_capacity(2 * self.levels.len());
        stack.push((top, 0));
        while let Some((level, i)) = stack.pop() {
            if farther_than(p, self.levels[level][i], limit) {
                continue;
            }
            if level == 0 {
                self.search_leaf(query, i, &mut best, &mut limit);
                continue;
            }
            self.push_children(p, level, i, &mut stack);
        }
        best.map(|b| b.1)
    }
}

/// A label per face (its piece, say), and per node of a [`FaceIndex`]
/// the label all its faces share, or [`MIXED`].
pub struct FaceLabels<'a> {
    /// The label of each face, by the mesh's face index.
    of_face: &'a [u32],
    /// Node labels, level by level as the index's boxes.
    levels: Vec<Vec<u32>>,
}

/// A label search's state, kept from one query to the next: its stacks,
/// rather than allocated for each query, and the last answer's leaf.
#[derive(Default)]
pub struct Scratch {
    stack: Vec<(usize, usize)>,
    set_aside: Vec<(usize, usize)>,
    /// The leaf of the last answer.
    last_leaf: Option<usize>,
}

/// The label of a node whose faces carry more than one.
const MIXED: u32 = u32::MAX;

impl FaceLabels<'_> {
    fn common(a: u32, b: u32) -> u32 {
        if a == b {
            a
        } else {
            MIXED
        }
    }
}

impl FaceIndex {
    /// The node labels of `labels`, one per face of the indexed mesh (no
    /// label may be `u32::MAX`).
    pub fn labels<'a>(&self, labels: &'a [u32]) -> FaceLabels<'a> {
        let leaves: Vec<u32> = self
            .faces
            .par_chunks(LEAF)
            .map(|group| {
                group
                    .iter()
                    .map(|&f| labels[f as usize])
                    .reduce(FaceLabels::common)
                    .unwrap_or(MIXED)
            })
            .collect();
        let mut levels = vec![leaves];
        for level in 1..self.levels.len() {
            let above = levels[level - 1]
                .chunks(2)
                .map(|pair| {
                    pair.iter()
                        .copied()
                        .reduce(FaceLabels::common)
                        .unwrap_or(MIXED)
                })
                .collect();
            levels.push(above);
        }
        FaceLabels {
            of_face: labels,
            levels,
        }
    }

    /// The label of the face closest to `p` within `max_dist` (the lower
    /// index on a tie): `labels.of_face[nearest_face(p, max_dist)]`, found
    /// with nodes of the nearest face's label set aside (see the module
    /// doc).
    pub fn nearest_label(
        &self,
        p: Point3,
        max_dist: f64,
        labels: &FaceLabels,
        scratch: &mut Scratch,
    ) -> Option<u32> {
        let query = Vector::new(p[0], p[1], p[2]);
        let top = self.levels.len().checked_sub(1)?;
        let mut best: Option<(f64, u32)> = None;
        let mut limit = max_dist;
        let Scratch {
            stack,
            set_aside,
            last_leaf,
        } = scratch;
        stack.clear();
        set_aside.clear();
        // The leaf of the last query's answer first: queries in spatial
        // order land near each other, and a face found at once lets whole
        // subtrees of its label be set aside from the root down.
        let mut best_leaf = None;
        if let Some(leaf) = last_leaf.filter(|&leaf| leaf < self.levels[0].len()) {
            if self.search_leaf(query, leaf, &mut best, &mut limit) {
                best_leaf = Some(leaf);
            }
        }
        stack.push((top, 0));
        loop {
            while let Some((level, i)) = stack.pop() {
                let node_label = labels.levels[level][i];
                if best.is_some_and(|(_, face)| node_label == labels.of_face[face as usize]) {
                    set_aside.push((level, i));
                    continue;
                }
                if farther_than(p, self.levels[level][i], limit) {
                    continue;
                }
                if level == 0 {
                    if self.search_leaf(query, i, &mut best, &mut limit) {
                        best_leaf = Some(i);
                    }
                    continue;
                }
                self.push_children(p, level, i, stack);
            }
            // The nodes set aside under another label than the nearest
            // face's now, and near enough to hold a face at least as near,
            // are searched after all.
            let Some((_, face)) = best else { break };
            let label = labels.of_face[face as usize];
            set_aside.retain(|&(level, i)| {
                let reopen = labels.levels[level][i] != label
                    && !farther_than(p, self.levels[level][i], limit);
                if reopen {
                    stack.push((level, i));
                }
                !reopen
            });
            if stack.is_empty() {
                break;
            }
        }
        if best_leaf.is_some() {
            *last_leaf = best_leaf;
        }
        best.map(|(_, face)| labels.of_face[face as usize])
    }

    /// Weighs the faces of leaf `i`: a face within `limit` nearer than
    /// `best` (or as near, with a lower index) becomes `best`, and its
    /// distance the limit. Whether one did.
    fn search_leaf(
        &self,
        query: Vector,
        i: usize,
        best: &mut Option<(f64, u32)>,
        limit: &mut f64,
    ) -> bool {
        let mut improved = false;
        for t in i * LEAF..((i + 1) * LEAF).min(self.triangles.len()) {
            let d = (self.triangles[t].project_local_point(query, false).point - query).length();
            let face = self.faces[t];
            if d <= *limit && best.is_none_or(|(bd, bf)| d < bd || (d == bd && face < bf)) {
                *best = Some((d, face));
                *limit = d;
                improved = true;
            }
        }
        improved
    }

    /// Pushes the children of node `i` of `level` onto `stack`, the nearer
    /// last so that it is searched first.
    fn push_children(&self, p: Point3, level: usize, i: usize, stack: &mut Vec<(usize, usize)>) {
        let below = &self.levels[level - 1];
        let (left, right) = (2 * i, 2 * i + 1);
        if right < below.len() {
            let (dl, dr) = (
                box_distance2(p, below[left]),
                box_distance2(p, below[right]),
            );
            if dl <= dr {
                stack.extend([(level - 1, right), (level - 1, left)]);
            } else {
                stack.extend([(level - 1, left), (level - 1, right)]);
            }
        } else {
            stack.push((level - 1, left));
        }
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
    let (low, high) = centroid_bounds(items);
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

/// The bounding box of the centroids, widened to f64 (exactly: the
/// comparisons pick values, and f32 widens without rounding). A plain
/// loop of comparisons in f32: this pass runs on every node of every
/// level, and folding f64 boxes made the median splits of 5M faces take
/// 0.48–0.54 s (now 0.27–0.32 s).
fn centroid_bounds(items: &[([f32; 3], u32)]) -> Aabb {
    let mut low = [f32::INFINITY; 3];
    let mut high = [f32::NEG_INFINITY; 3];
    for (c, _) in items {
        for a in 0..3 {
            if c[a] < low[a] {
                low[a] = c[a];
            }
            if c[a] > high[a] {
                high[a] = c[a];
            }
        }
    }
    (low.map(f64::from), high.map(f64::from))
}

const EMPTY: Aabb = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);

fn union(a: Aabb, b: Aabb) -> Aabb {
    (
        [0, 1, 2].map(|k| a.0[k].min(b.0[k])),
        [0, 1, 2].map(|k| a.1[k].max(b.1[k])),
    )
}

/// The bounding box of `points` (inside out, lower corner +∞, when there
/// are none).
pub(crate) fn bounds(points: impl Iterator<Item = Point3>) -> Aabb {
    points.fold(EMPTY, |acc, p| union(acc, (p, p)))
}

/// Squared distance from `p` to the box (0 inside).
fn box_distance2(p: Point3, (low, high): Aabb) -> f64 {
    let gap = [0, 1, 2].map(|a| (low[a] - p[a]).max(p[a] - high[a]).max(0.0));
    norm2(gap)
}

/// Whether the box lies farther than `limit` from `p`. Squares are
/// compared (a square root per box was a sixth of a query), with the
/// limit's square widened by a few units in the last place, so that a box
/// whose rounded distance is within the limit is never left out: a box
/// searched in vain costs little, one left out could change the answer.
fn farther_than(p: Point3, b: Aabb, limit: f64) -> bool {
    box_distance2(p, b) > limit * limit * (1.0 + 1e-12)
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

    /// The label search gives the label of the reference's face, for
    /// labels in patches (pieces) and labels at random, points anywhere and
    /// on vertices and edges (ties), with one scratch over queries in
    /// random order (so the last answer's leaf is rarely the right one).
    #[test]
    fn nearest_label_is_the_label_of_the_nearest_face() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        for seed in 0..4 {
            let mesh = two_sheets(seed, 20);
            let index = FaceIndex::new(&mesh);
            let patches: Vec<u32> = mesh
                .faces
                .iter()
                .map(|f| {
                    let c = mesh.vertices[f[0] as usize];
                    (c[0] / 7.0) as u32 + 3 * (c[2] > 1.0) as u32
                })
                .collect();
            let at_random: Vec<u32> = (0..mesh.faces.len())
                .map(|_| rng.random_range(0..3))
                .collect();
            let mut points: Vec<(Point3, f64)> = Vec::new();
            for _ in 0..1500 {
                let p = [
                    rng.random_range(-2.0..22.0),
                    rng.random_range(-2.0..22.0),
                    rng.random_range(-1.5..3.0),
                ];
                points.push((p, rng.random_range(0.05..1.5)));
            }
            for v in mesh.vertices.iter().step_by(3) {
                points.push((*v, 0.5));
            }
            for f in mesh.faces.iter().step_by(5) {
                let (a, b) = (mesh.vertices[f[0] as usize], mesh.vertices[f[1] as usize]);
                points.push(([0, 1, 2].map(|k| 0.5 * (a[k] + b[k])), 0.5));
            }
            for labels in [&patches, &at_random] {
                let tagged = index.labels(labels);
                let mut scratch = Scratch::default();
                for &(p, max_dist) in &points {
                    let expected = index.nearest_face(p, max_dist).map(|f| labels[f as usize]);
                    let found = index.nearest_label(p, max_dist, &tagged, &mut scratch);
                    assert_eq!(found, expected, "{p:?} within {max_dist}");
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
