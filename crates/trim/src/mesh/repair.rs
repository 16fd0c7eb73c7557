//! Zero-area and repeated faces taken out of a mesh, the manifold and the
//! orientation kept (infrastructure of meshtrim's mesh stages; no section
//! of the paper).
//!
//! A face whose area is below 10⁻¹² of the squared bounding-box diagonal
//! gives a CAM system a NaN normal. Screened Poisson leaves a few such
//! faces (tiny triangles where its marching cubes cut a cell at a corner),
//! and a mesh's faces may repeat. Each one is repaired by the smallest
//! change that removes it:
//!
//! - **Tiny or needle faces** (the shortest edge below 1 % of the mesh's
//!   median edge): the shortest edge is collapsed, its second vertex
//!   merged into the first (a border vertex is kept where one is), which
//!   removes the face and its neighbour across that edge. The collapse is
//!   made only where it keeps the mesh manifold: the two vertices' common
//!   neighbours are exactly the faces' opposite vertices (the link
//!   condition), and two border vertices merge only along a border edge.
//! - **Caps** (a vertex on the longest edge, the other edges long): the
//!   longest edge is flipped with the neighbour across it, which splits
//!   that neighbour at the vertex; on the border the cap is dropped.
//! - **Faces that name a vertex twice** are dropped; a face repeated with
//!   the same vertices keeps its first copy, a pair wound opposite ways
//!   (a pocket of no volume) goes.
//!
//! A face whose repair would break the manifold stays, and is counted as
//! left. Faces that are not degenerate are never touched, apart from the
//! one vertex a collapse renames.

use super::rows::file_by_row;
use super::Mesh;
use crate::geom::{cross, dist2, norm2, sub, Point3};
use rayon::prelude::*;

/// Area below which a face is zero-area (degenerate), relative to the
/// squared diagonal of the bounding box of the faces' vertices.
pub const MIN_RELATIVE_AREA: f64 = 1e-12;
/// A face whose shortest edge is below this share of the median edge is
/// collapsed along it.
const SHORT_EDGE: f64 = 0.01;
/// The slot of a vertex whose faces a pass does not list.
const NOT_LISTED: u32 = u32::MAX;
/// Repair passes at most (each repairs every degenerate face whose
/// vertices the pass has not touched yet).
const PASSES: usize = 8;

/// What the repair did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FaceRepair {
    /// Zero-area faces removed by collapsing their shortest edge.
    pub collapsed: usize,
    /// Zero-area faces removed by flipping their longest edge (or dropped
    /// on the border).
    pub flipped: usize,
    /// Faces dropped for naming a vertex twice or repeating another face.
    pub dropped: usize,
    /// Zero-area faces left, where no repair keeps the mesh manifold.
    pub left: usize,
}

impl FaceRepair {
    /// Faces repaired in all.
    pub fn repaired(&self) -> usize {
        self.collapsed + self.flipped + self.dropped
    }
}

/// Repairs the zero-area and repeated faces of `mesh` in place (see the
/// module doc); unused vertices are left for the caller to remove.
pub(crate) fn repair_degenerate_faces(mesh: &mut Mesh) -> FaceRepair {
    repair_listing(mesh, Listing::DegenerateFaces)
}

/// Whose faces a repair pass lists round their vertices.
#[derive(Clone, Copy)]
enum Listing {
    /// The degenerate faces' vertices, which the repairs read.
    DegenerateFaces,
    /// Every vertex: the plain way, the reference for tests.
    #[cfg(test)]
    EveryVertex,
}

fn repair_listing(mesh: &mut Mesh, listing: Listing) -> FaceRepair {
    let mut repair = FaceRepair {
        dropped: drop_repeated_faces(mesh),
        ..FaceRepair::default()
    };
    let min_area = MIN_RELATIVE_AREA * diagonal2(mesh);
    let mut degenerate = degenerate_faces(mesh, min_area);
    if degenerate.is_empty() {
        return repair;
    }
    let short = SHORT_EDGE * median_edge(mesh);
    for _ in 0..PASSES {
        if degenerate.is_empty() {
            break;
        }
        let faces = std::mem::take(&mut mesh.faces);
        let mut pass = Pass::new(&mesh.vertices, faces, &degenerate, listing);
        for f in degenerate {
            pass.repair(f, short, &mut repair);
        }
        mesh.faces = pass.into_faces();
        repair.dropped += drop_repeated_faces(mesh);
        degenerate = degenerate_faces(mesh, min_area);
    }
    repair.left = degenerate.len();
    repair
}

/// The faces whose area is below `min_area`, ascending.
fn degenerate_faces(mesh: &Mesh, min_area: f64) -> Vec<usize> {
    (0..mesh.faces.len())
        .into_par_iter()
        .filter(|&f| mesh.face_area(f) < min_area)
        .collect()
}

/// Drops faces that name a vertex twice, later copies of a face, and
/// pairs of one face wound both ways; returns how many went. Repeats are
/// found by bucketing the faces by their lowest vertex (a counting sort,
/// several times faster than hashing every face of a large mesh) and
/// comparing within each bucket, in face order.
fn drop_repeated_faces(mesh: &mut Mesh) -> usize {
    let names_three = |f: &[u32; 3]| f[0] != f[1] && f[1] != f[2] && f[0] != f[2];
    let corners = |f: [u32; 3]| {
        let mut key = f;
        key.sort_unstable();
        key
    };
    // Each face filed under its lowest vertex with its sorted corners, so
    // that the buckets sort without reading the faces again.
    let mut buckets = file_by_row(mesh.vertices.len(), &mesh.faces, |i, f, k| {
        (k == 0 && names_three(f)).then(|| {
            let key = corners(*f);
            (key[0], (key, i))
        })
    });
    // Filed in face order, and sorted stably: within equal corners the
    // first copy, the kept one, comes first.
    buckets.sort_each_by_key(|&(key, _)| key);
    let faces = &mesh.faces;
    let dropped: Vec<u32> = buckets
        .start
        .par_windows(2)
        .flat_map_iter(|bucket| {
            let bucket = &buckets.values[bucket[0] as usize..bucket[1] as usize];
            bucket
                .chunk_by(|a, b| a.0 == b.0)
                .flat_map(|group| repeats_dropped(faces, group))
                .collect::<Vec<u32>>()
        })
        .collect();
    let mut keep: Vec<bool> = faces.par_iter().map(names_three).collect();
    for &f in &dropped {
        keep[f as usize] = false;
    }
    let dropped = keep.iter().filter(|&&k| !k).count();
    if dropped > 0 {
        mesh.retain_faces(&keep);
    }
    dropped
}

/// Of faces with the same corners, in face order, those that go: every
/// later copy, and the first too when a copy runs the other way.
fn repeats_dropped(faces: &[[u32; 3]], group: &[([u32; 3], u32)]) -> Vec<u32> {
    let turn = |f: u32| super::lowest_first(faces[f as usize]);
    let first = group[0].1;
    let mut dropped: Vec<u32> = group[1..].iter().map(|&(_, f)| f).collect();
    if dropped.iter().any(|&f| turn(f) != turn(first)) {
        dropped.push(first);
    }
    dropped
}

/// One pass of repairs: faces are edited in place, the removed ones marked
/// and dropped at the end; a face whose vertices an earlier repair of the
/// pass touched waits for the next pass, so each repair sees the faces
/// round it as they are.
///
/// A repair reads the faces round the vertices of the face it repairs
/// only (their stars, edges and neighbours), and a vertex it changes is
/// touched, so no later repair of the pass reads round it. So the faces
/// round a vertex are listed for the degenerate faces' vertices alone: on
/// a mesh of millions of faces with a few hundred to repair, listing them
/// round every vertex cost more than all the repairs.
struct Pass<'a> {
    points: &'a [Point3],
    faces: Vec<[u32; 3]>,
    removed: Vec<bool>,
    /// The live faces round each vertex of a degenerate face (the others'
    /// lists no repair reads): the list of vertex v is `lists[slot[v]]`,
    /// its slot `NOT_LISTED` for the others.
    slot: Vec<u32>,
    lists: Vec<Vec<u32>>,
    touched: Vec<bool>,
}

impl<'a> Pass<'a> {
    /// A pass over the mesh of `points` and `faces` to repair the faces
    /// `degenerate`.
    fn new(
        points: &'a [Point3],
        faces: Vec<[u32; 3]>,
        degenerate: &[usize],
        listing: Listing,
    ) -> Self {
        let mut slot = vec![NOT_LISTED; points.len()];
        let mut lists: Vec<Vec<u32>> = Vec::new();
        let listed_faces: Vec<usize> = match listing {
            Listing::DegenerateFaces => degenerate.to_vec(),
            #[cfg(test)]
            Listing::EveryVertex => (0..faces.len()).collect(),
        };
        for f in listed_faces {
            for v in faces[f] {
                if slot[v as usize] == NOT_LISTED {
                    slot[v as usize] = lists.len() as u32;
                    lists.push(Vec::new());
                }
            }
        }
        for (i, f) in faces.iter().enumerate() {
            for &v in f {
                if let Some(list) = lists.get_mut(slot[v as usize] as usize) {
                    list.push(i as u32);
                }
            }
        }
        Pass {
            points,
            removed: vec![false; faces.len()],
            faces,
            slot,
            lists,
            touched: vec![false; points.len()],
        }
    }

    /// The faces, without the removed ones.
    fn into_faces(self) -> Vec<[u32; 3]> {
        let mut faces = self.faces;
        let mut kept = self.removed.iter().map(|&r| !r);
        faces.retain(|_| kept.next().unwrap_or(true));
        faces
    }

    /// Face `g`, unless removed.
    fn face(&self, g: u32) -> Option<[u32; 3]> {
        (!self.removed[g as usize]).then(|| self.faces[g as usize])
    }

    /// The live faces round `v` (none listed round a vertex of no
    /// degenerate face).
    fn around(&self, v: u32) -> &[u32] {
        self.lists
            .get(self.slot[v as usize] as usize)
            .map_or(&[], |list| list.as_slice())
    }

    /// `v`'s list of faces, if it has one.
    fn around_mut(&mut self, v: u32) -> Option<&mut Vec<u32>> {
        self.lists.get_mut(self.slot[v as usize] as usize)
    }

    /// Lists `g` round `v`, if `v`'s faces are listed.
    fn list(&mut self, v: u32, g: u32) {
        if let Some(list) = self.around_mut(v) {
            list.push(g);
        }
    }

    /// Stops listing `g` round `v`.
    fn unlist(&mut self, v: u32, g: u32) {
        if let Some(list) = self.around_mut(v) {
            list.retain(|&x| x != g);
        }
    }

    /// Repairs face `f` if it is still there and untouched.
    fn repair(&mut self, f: usize, short: f64, repair: &mut FaceRepair) {
        let Some(face) = self.face(f as u32) else {
            return;
        };
        if face.iter().any(|&v| self.touched[v as usize]) {
            return;
        }
        let length = |k: usize| {
            dist2(
                self.points[face[k] as usize],
                self.points[face[(k + 1) % 3] as usize],
            )
        };
        let shortest = (0..3)
            .min_by(|&i, &j| length(i).total_cmp(&length(j)))
            .unwrap_or(0);
        let longest = (0..3)
            .max_by(|&i, &j| length(i).total_cmp(&length(j)))
            .unwrap_or(0);
        if length(shortest).sqrt() < short {
            let (u, v) = (face[shortest], face[(shortest + 1) % 3]);
            if self.collapse(u, v) {
                repair.collapsed += 1;
            }
        } else if self.flip(f, longest) {
            repair.flipped += 1;
        }
    }

    /// The live faces holding both `u` and `v`.
    fn faces_on_edge(&self, u: u32, v: u32) -> Vec<u32> {
        self.around(u)
            .iter()
            .copied()
            .filter(|&g| self.face(g).is_some_and(|f| f.contains(&v)))
            .collect()
    }

    /// The vertices sharing a face with `x`, ascending, without repeats.
    fn neighbours(&self, x: u32) -> Vec<u32> {
        let mut out: Vec<u32> = self
            .around(x)
            .iter()
            .filter_map(|&g| self.face(g))
            .flatten()
            .filter(|&y| y != x)
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Is `x` on the border (an edge of one face), or at a non-manifold
    /// edge (`None`)?
    fn on_border(&self, x: u32) -> Option<bool> {
        let mut border = false;
        for y in self.neighbours(x) {
            match self.faces_on_edge(x, y).len() {
                1 => border = true,
                2 => {}
                _ => return None,
            }
        }
        Some(border)
    }

    /// Collapses edge (u, v) if that keeps the mesh manifold and turns no
    /// face over.
    fn collapse(&mut self, u: u32, v: u32) -> bool {
        let (Some(border_u), Some(border_v)) = (self.on_border(u), self.on_border(v)) else {
            return false;
        };
        let shared = self.faces_on_edge(u, v);
        if border_u && border_v && shared.len() != 1 {
            return false;
        }
        // The border vertex stays where one is; otherwise the lower index.
        let (keep, gone) = match (border_u, border_v) {
            (false, true) => (v, u),
            (true, false) => (u, v),
            _ => (u.min(v), u.max(v)),
        };
        let mut opposite: Vec<u32> = shared
            .iter()
            .filter_map(|&g| self.face(g))
            .flatten()
            .filter(|&w| w != u && w != v)
            .collect();
        opposite.sort_unstable();
        let common: Vec<u32> = {
            let of_keep = self.neighbours(keep);
            self.neighbours(gone)
                .into_iter()
                .filter(|w| of_keep.binary_search(w).is_ok())
                .collect()
        };
        if common != opposite || self.turns_over(keep, gone) {
            return false;
        }
        let round_gone = self
            .around_mut(gone)
            .map(std::mem::take)
            .unwrap_or_default();
        for g in round_gone {
            let Some(face) = self.face(g) else {
                continue;
            };
            if face.contains(&keep) {
                self.remove_face(g);
            } else {
                self.faces[g as usize] = face.map(|w| if w == gone { keep } else { w });
                self.list(keep, g);
            }
        }
        self.touch_round(keep);
        self.touched[gone as usize] = true;
        true
    }

    /// Would moving `gone` onto `keep` turn a face round `gone` over?
    fn turns_over(&self, keep: u32, gone: u32) -> bool {
        self.around(gone).iter().any(|&g| {
            let Some(face) = self.face(g) else {
                return false;
            };
            if face.contains(&keep) {
                return false;
            }
            let before = normal(face.map(|w| self.points[w as usize]));
            let after =
                normal(face.map(|w| self.points[if w == gone { keep } else { w } as usize]));
            crate::geom::dot(before, after) < 0.0
        })
    }

    /// Flips the edge of face `f` that starts at its corner `k` (its
    /// longest) with the face across it, which the opposite vertex splits;
    /// on the border, drops `f`.
    fn flip(&mut self, f: usize, k: usize) -> bool {
        let Some(face) = self.face(f as u32) else {
            return false;
        };
        let (a, b, c) = (face[k], face[(k + 1) % 3], face[(k + 2) % 3]);
        let across: Vec<u32> = self
            .faces_on_edge(a, b)
            .into_iter()
            .filter(|&g| g as usize != f)
            .collect();
        match across.as_slice() {
            [] => {
                // Dropping the cap puts `c` on the border: only if it is
                // not on it already, or it would pinch the surface there.
                if self.on_border(c) != Some(false) {
                    return false;
                }
                self.remove_face(f as u32);
                for w in [a, b, c] {
                    self.touched[w as usize] = true;
                }
                true
            }
            &[g] => {
                let Some(other) = self.face(g) else {
                    return false;
                };
                let Some(j) = (0..3).find(|&j| other[j] == b && other[(j + 1) % 3] == a) else {
                    return false;
                };
                let d = other[(j + 2) % 3];
                if d == c || self.neighbours(c).binary_search(&d).is_ok() {
                    return false;
                }
                self.faces[f] = [b, c, d];
                self.faces[g as usize] = [c, a, d];
                self.unlist(a, f as u32);
                self.list(d, f as u32);
                self.unlist(b, g);
                self.list(c, g);
                for w in [a, b, c, d] {
                    self.touched[w as usize] = true;
                }
                true
            }
            _ => false,
        }
    }

    fn remove_face(&mut self, g: u32) {
        if let Some(face) = self.face(g) {
            self.removed[g as usize] = true;
            for w in face {
                self.unlist(w, g);
            }
        }
    }

    /// Marks `x` and every vertex of the faces round it.
    fn touch_round(&mut self, x: u32) {
        self.touched[x as usize] = true;
        let round: Vec<u32> = self
            .around(x)
            .iter()
            .filter_map(|&g| self.face(g))
            .flatten()
            .collect();
        for w in round {
            self.touched[w as usize] = true;
        }
    }
}

/// A face's (unnormalised) normal.
fn normal(p: [Point3; 3]) -> Point3 {
    cross(sub(p[1], p[0]), sub(p[2], p[0]))
}

/// The squared diagonal of the bounding box of the faces' vertices.
pub(crate) fn diagonal2(mesh: &Mesh) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for f in &mesh.faces {
        for &v in f {
            let p = mesh.vertices[v as usize];
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    if lo[0] > hi[0] {
        return 0.0;
    }
    norm2(sub(hi, lo))
}

/// The median length of the faces' edges (each face's three counted; the
/// upper median of an even count), 0 without faces and 1 without a finite
/// length. Squared lengths are ranked and one square root taken: the
/// square root keeps their order.
fn median_edge(mesh: &Mesh) -> f64 {
    if mesh.faces.is_empty() {
        return 0.0;
    }
    let mut squares: Vec<f64> = mesh
        .faces
        .par_iter()
        .flat_map_iter(|f| (0..3).map(move |k| (f[k], f[(k + 1) % 3])))
        .map(|(u, v)| dist2(mesh.vertices[u as usize], mesh.vertices[v as usize]))
        .filter(|d| d.is_finite())
        .collect();
    if squares.is_empty() {
        return 1.0;
    }
    let mid = squares.len() / 2;
    squares.select_nth_unstable_by(mid, f64::total_cmp).1.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hash::HashMap;
    use crate::mesh::tests::grid;

    /// [`drop_repeated_faces`] with a hash map of every face, the plain
    /// way: the reference the bucketed one is tested against.
    fn drop_repeated_faces_reference(mesh: &mut Mesh) -> usize {
        let mut first: HashMap<[u32; 3], (usize, [u32; 3])> = HashMap::default();
        let mut keep = vec![true; mesh.faces.len()];
        for (i, &f) in mesh.faces.iter().enumerate() {
            if f[0] == f[1] || f[1] == f[2] || f[0] == f[2] {
                keep[i] = false;
                continue;
            }
            let mut key = f;
            key.sort_unstable();
            match first.get(&key) {
                None => {
                    first.insert(key, (i, f));
                }
                Some(&(j, g)) => {
                    keep[i] = false;
                    if super::super::lowest_first(g) != super::super::lowest_first(f) {
                        keep[j] = false;
                    }
                }
            }
        }
        let dropped = keep.iter().filter(|&&k| !k).count();
        mesh.retain_faces(&keep);
        dropped
    }

    /// The bucketed repeats equal the hashed ones on random faces over few
    /// vertices: repeats, reverses, triples, slivers.
    #[test]
    fn repeated_faces_match_the_reference() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for case in 0..2000 {
            let vertices = rng.random_range(3..8u32);
            let faces: Vec<[u32; 3]> = (0..rng.random_range(1..30))
                .map(|_| [0; 3].map(|_| rng.random_range(0..vertices)))
                .collect();
            let mesh = Mesh {
                vertices: vec![[0.0; 3]; vertices as usize],
                faces,
            };
            let (mut fast, mut plain) = (mesh.clone(), mesh.clone());
            assert_eq!(
                drop_repeated_faces(&mut fast),
                drop_repeated_faces_reference(&mut plain),
                "case {case}: {mesh:?}"
            );
            assert_eq!(fast.faces, plain.faces, "case {case}: {mesh:?}");
        }
    }

    /// The same on a mesh large enough to be bucketed on every thread:
    /// copies, reverses and rotations of random faces among 90,000.
    #[test]
    fn repeated_faces_match_the_reference_on_every_thread() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(12);
        let vertices = 5_000u32;
        let mut faces: Vec<[u32; 3]> = (0..80_000)
            .map(|_| [0; 3].map(|_| rng.random_range(0..vertices)))
            .collect();
        for _ in 0..10_000 {
            let [a, b, c] = faces[rng.random_range(0..faces.len())];
            let again = [[a, b, c], [c, b, a], [b, c, a], [a, c, b]];
            let at = rng.random_range(0..=faces.len());
            faces.insert(at, again[rng.random_range(0..4)]);
        }
        let mesh = Mesh {
            vertices: vec![[0.0; 3]; vertices as usize],
            faces,
        };
        let mut plain = mesh.clone();
        let dropped = drop_repeated_faces_reference(&mut plain);
        assert!(dropped > 10_000, "{dropped}");
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut fast = mesh.clone();
            assert_eq!(pool.install(|| drop_repeated_faces(&mut fast)), dropped);
            assert_eq!(fast.faces, plain.faces, "{threads} threads");
        }
    }

    fn zero_area_faces(mesh: &Mesh) -> usize {
        let min_area = MIN_RELATIVE_AREA * diagonal2(mesh);
        (0..mesh.faces.len())
            .filter(|&f| mesh.face_area(f) < min_area)
            .count()
    }

    /// A vertex moved next to its neighbour makes the two faces on their
    /// edge needles; collapsing the edge removes both, keeps the grid's
    /// area, its single border and its orientation.
    #[test]
    fn needles_are_collapsed() {
        for (i, j) in [(2, 2), (0, 2), (3, 0)] {
            let mut mesh = grid(5);
            let v = (j * 6 + i) as usize;
            let p = mesh.vertices[v];
            mesh.vertices[v] = [p[0] + 1.0 - 1e-13, p[1], 0.0];
            let area = mesh.area();
            assert!(zero_area_faces(&mesh) > 0);
            let repair = repair_degenerate_faces(&mut mesh);
            assert!(repair.collapsed > 0 && repair.left == 0, "{repair:?}");
            assert_eq!(zero_area_faces(&mesh), 0);
            mesh.check_manifold().unwrap();
            assert_eq!(mesh.boundary_loops().len(), 1);
            assert!((mesh.area() - area).abs() < 1e-6);
        }
    }

    /// A cap (a vertex on the opposite edge) is flipped with the face
    /// across that edge, which the vertex then splits.
    #[test]
    fn caps_are_flipped() {
        let (a, b, c, d, e) = (0, 1, 2, 3, 4);
        let mut mesh = Mesh {
            vertices: vec![
                [0.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [1.0, -1.0, 0.0],
            ],
            faces: vec![[a, b, c], [b, a, e], [c, b, d], [a, c, d]],
        };
        mesh.check_manifold().unwrap();
        let repair = repair_degenerate_faces(&mut mesh);
        assert_eq!(repair.flipped, 1, "{repair:?}");
        assert_eq!(zero_area_faces(&mesh), 0);
        assert_eq!(mesh.faces.len(), 4);
        mesh.check_manifold().unwrap();
        assert!((mesh.area() - 2.0).abs() < 1e-12);
    }

    /// On the border a cap is dropped: the border then runs through its
    /// middle vertex.
    #[test]
    fn border_caps_are_dropped() {
        let mut mesh = Mesh {
            vertices: vec![
                [0.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
            ],
            faces: vec![[0, 1, 2], [2, 1, 3], [0, 2, 3]],
        };
        let repair = repair_degenerate_faces(&mut mesh);
        assert_eq!(repair.flipped, 1, "{repair:?}");
        assert_eq!(mesh.faces, vec![[2, 1, 3], [0, 2, 3]]);
    }

    /// Faces naming a vertex twice go; a repeated face keeps its first
    /// copy; a face and its reverse both go.
    #[test]
    fn repeated_faces_are_dropped() {
        let mut mesh = grid(2);
        let first = mesh.faces[0];
        mesh.faces.push(first);
        mesh.faces.push([first[1], first[2], first[0]]);
        mesh.faces.push([4, 4, 5]);
        let repair = repair_degenerate_faces(&mut mesh);
        assert_eq!(repair.dropped, 3, "{repair:?}");
        assert_eq!(mesh.faces, grid(2).faces);
        let mut pocket = grid(2);
        let f = pocket.faces[3];
        pocket.faces.push([f[0], f[2], f[1]]);
        assert_eq!(repair_degenerate_faces(&mut pocket).dropped, 2);
        assert_eq!(pocket.faces.len(), grid(2).faces.len() - 1);
    }

    /// The unit grid of `n` × `n` squares, its vertices moved by up to 0.2
    /// in x and y.
    fn jittered_grid(n: u32, rng: &mut impl rand::Rng) -> Mesh {
        use rand::RngExt;
        let mut mesh = grid(n);
        for p in mesh.vertices.iter_mut() {
            p[0] += rng.random_range(-0.2..0.2);
            p[1] += rng.random_range(-0.2..0.2);
        }
        mesh
    }

    /// Faces listed round the degenerate faces' vertices only give the
    /// repairs of faces listed round every vertex, on jittered grids with
    /// needles and caps made at random, borders included.
    #[test]
    fn repairs_match_the_reference_listing() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(12);
        let mut repaired = 0;
        for case in 0..300 {
            let mut mesh = jittered_grid(7, &mut rng);
            for _ in 0..rng.random_range(1..6) {
                let f = mesh.faces[rng.random_range(0..mesh.faces.len())];
                let (u, v, w) = (f[0] as usize, f[1] as usize, f[2] as usize);
                let (a, b) = (mesh.vertices[u], mesh.vertices[v]);
                mesh.vertices[w] = if rng.random_bool(0.5) {
                    // A needle: w onto u.
                    [a[0] + 1e-13, a[1], a[2]]
                } else {
                    // A cap: w onto the middle of u v.
                    [
                        0.5 * (a[0] + b[0]),
                        0.5 * (a[1] + b[1]),
                        0.5 * (a[2] + b[2]),
                    ]
                };
            }
            let mut reference = mesh.clone();
            let expected = repair_listing(&mut reference, Listing::EveryVertex);
            let found = repair_degenerate_faces(&mut mesh);
            assert_eq!(found, expected, "case {case}");
            assert_eq!(mesh.faces, reference.faces, "case {case}");
            repaired += found.collapsed + found.flipped;
        }
        assert!(repaired > 300, "{repaired}");
    }

    /// Random interior vertices of a jittered grid moved onto a
    /// neighbour: every zero-area face goes, and the mesh stays manifold
    /// and oriented. Needles between two border vertices across a corner
    /// would pinch the border if collapsed: they are left, counted, and
    /// the mesh stays manifold (the last assertion of each case).
    #[test]
    fn random_needles_are_all_repaired() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut interior_cases = 0;
        for case in 0..200 {
            let n = 8;
            let mut mesh = jittered_grid(n, &mut rng);
            let interior = |v: u32| {
                let (i, j) = (v % (n + 1), v / (n + 1));
                i > 0 && i < n && j > 0 && j < n
            };
            let moves = rng.random_range(1..4);
            let mut moved = 0;
            let mut all_interior = true;
            while moved < moves {
                let f = mesh.faces[rng.random_range(0..mesh.faces.len())];
                let (u, v) = (f[0], f[1]);
                all_interior &= interior(u) && interior(v);
                let q = mesh.vertices[u as usize];
                mesh.vertices[v as usize] = [q[0] + 1e-13, q[1], q[2]];
                moved += 1;
            }
            let before = zero_area_faces(&mesh);
            let repair = repair_degenerate_faces(&mut mesh);
            assert_eq!(
                zero_area_faces(&mesh),
                repair.left,
                "case {case}: {repair:?}"
            );
            if all_interior {
                interior_cases += 1;
                assert_eq!(repair.left, 0, "case {case}: {repair:?}");
                assert!(
                    repair.collapsed > 0 || before == 0,
                    "case {case}: {repair:?}"
                );
            }
            mesh.check_manifold()
                .unwrap_or_else(|e| panic!("case {case}: {e} {repair:?}"));
        }
        assert!(interior_cases > 50, "{interior_cases}");
    }
}
