//! Small holes closed: meshtrim's own step before the cleanup (the paper
//! keeps every hole, as a boundary to reconstruct; a scan's occlusion
//! holes a few spacings wide are rather gaps a CAM toolpath should cross).
//!
//! A hole is a border loop no wider than the size asked for (the largest
//! distance between two of its vertices) that is not the outer border of
//! its piece of surface (the piece's longest loop, which is never closed).
//! It is triangulated over its own vertices, with no vertex added, by
//! dynamic programming over the polygon's diagonals (Barequet and Sharir
//! 1995) with Liepa's weight (2003, "Filling holes in meshes", section 3,
//! as CGAL's hole filling uses it; without the refinement and fairing that
//! add vertices): each sub-polygon takes the apex whose triangle, with its
//! sides' own best triangulations, has the smallest largest dihedral
//! angle (against those triangles, and the mesh's faces along the hole),
//! then the least area. Diagonals that are edges of the mesh already, and
//! faces of no area, are not allowed, so the mesh stays manifold and has
//! no zero-area face; a hole that cannot be closed so stays open and is
//! counted. A loop through a vertex twice (holes touching at a pinched
//! vertex) is split there into loops through each vertex once.

use crate::geom::{cross, dot, norm2, sub, Point3};
use crate::hash::{HashMap, HashSet};
use crate::mesh::repair::{diagonal2, MIN_RELATIVE_AREA};
use crate::mesh::{simple_cycles, Mesh};

/// Loops with more vertices than this are no holes to close, whatever
/// their width: the triangulation costs the cube of the count (a hole this
/// many spacings round is no gap to close without new vertices).
pub const MAX_HOLE_VERTICES: usize = 400;

/// What closing the small holes did ([`crate::CleanOptions::fill_holes`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct HolesFilled {
    /// Holes closed.
    pub holes: usize,
    /// Faces added to close them.
    pub faces: usize,
    /// Holes no wider than the size asked for that stay open: every
    /// triangulation would repeat an edge of the mesh or make a face of no
    /// area.
    pub left: usize,
}

/// Closes the holes of `mesh` no wider than `max_width` (in the mesh's
/// units) whose border loops are `borders` ([`Mesh::boundary_loops`]),
/// appending the new faces; the mesh must be edge-manifold and oriented.
pub fn fill_holes(mesh: &mut Mesh, borders: &[Vec<u32>], max_width: f64) -> HolesFilled {
    let holes = holes_to_fill(mesh, borders, max_width);
    let mut filled = HolesFilled::default();
    if holes.is_empty() {
        return filled;
    }
    let on_holes: HashSet<u32> = holes.iter().flat_map(|h| h.iter().copied()).collect();
    let mut edges = MeshEdges::around(mesh, &on_holes);
    let min_area2 = (MIN_RELATIVE_AREA * diagonal2(mesh)).powi(2);
    for hole in holes {
        match triangulate(&mesh.vertices, &hole, &edges, min_area2) {
            Some(faces) => {
                edges.add(&faces);
                filled.holes += 1;
                filled.faces += faces.len();
                mesh.faces.extend(faces);
            }
            None => filled.left += 1,
        }
    }
    filled
}

/// The loops to close, in the order of `borders` (each split into loops
/// through each vertex once): no wider than `max_width`, not the longest
/// loop of their piece, of at most [`MAX_HOLE_VERTICES`].
fn holes_to_fill(mesh: &Mesh, borders: &[Vec<u32>], max_width: f64) -> Vec<Vec<u32>> {
    // Holes touching at a pinched vertex are one loop through it twice.
    let borders: Vec<Vec<u32>> = borders
        .iter()
        .flat_map(|b| simple_cycles(b))
        .filter(|c| c.len() >= 3)
        .collect();
    let borders = &borders[..];
    let piece = loop_pieces(mesh, borders);
    let length: Vec<f64> = borders
        .iter()
        .map(|b| perimeter(&mesh.vertices, b))
        .collect();
    let mut outer: HashMap<usize, usize> = HashMap::default();
    for (l, &p) in piece.iter().enumerate() {
        let longest = outer.entry(p).or_insert(l);
        if length[l] > length[*longest] {
            *longest = l;
        }
    }
    borders
        .iter()
        .enumerate()
        .filter(|&(l, _)| outer[&piece[l]] != l)
        .filter(|(_, b)| width(&mesh.vertices, b) <= max_width)
        .map(|(_, b)| b.clone())
        .collect()
}

/// Each loop's piece of surface: faces joined across their edges (a piece
/// pinched to another at a vertex is a piece of its own, whose border is
/// its outer border, not a hole), named by one of its faces.
fn loop_pieces(mesh: &Mesh, borders: &[Vec<u32>]) -> Vec<usize> {
    let mut parent: Vec<usize> = (0..mesh.faces.len()).collect();
    fn root(parent: &mut [usize], mut f: usize) -> usize {
        while parent[f] != f {
            parent[f] = parent[parent[f]];
            f = parent[f];
        }
        f
    }
    let mut along: HashMap<(u32, u32), usize> = HashMap::default();
    for (face, f) in mesh.faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            along.insert((a, b), face);
            if let Some(&other) = along.get(&(b, a)) {
                let (x, y) = (root(&mut parent, face), root(&mut parent, other));
                parent[x.max(y)] = x.min(y);
            }
        }
    }
    borders
        .iter()
        .map(|b| {
            // A loop runs as its faces do: its first edge is one's.
            let face = along.get(&(b[0], b[1 % b.len()])).copied().unwrap_or(0);
            root(&mut parent, face)
        })
        .collect()
}

fn perimeter(points: &[Point3], border: &[u32]) -> f64 {
    let at = |k: usize| points[border[k % border.len()] as usize];
    (0..border.len())
        .map(|k| norm2(sub(at(k + 1), at(k))).sqrt())
        .sum()
}

/// The largest distance between two vertices of `border`; infinite for a
/// loop too long to close.
fn width(points: &[Point3], border: &[u32]) -> f64 {
    if border.len() > MAX_HOLE_VERTICES {
        return f64::INFINITY;
    }
    let mut widest2: f64 = 0.0;
    for (k, &a) in border.iter().enumerate() {
        for &b in &border[k + 1..] {
            widest2 = widest2.max(norm2(sub(points[a as usize], points[b as usize])));
        }
    }
    widest2.sqrt()
}

/// The mesh's edges among the holes' vertices: which exist (undirected),
/// and the normal of the face that runs along each directed one.
struct MeshEdges {
    undirected: HashSet<(u32, u32)>,
    face_normal: HashMap<(u32, u32), Point3>,
}

impl MeshEdges {
    fn around(mesh: &Mesh, on_holes: &HashSet<u32>) -> Self {
        let mut edges = MeshEdges {
            undirected: HashSet::default(),
            face_normal: HashMap::default(),
        };
        for f in &mesh.faces {
            if !f.iter().any(|v| on_holes.contains(v)) {
                continue;
            }
            let normal = face_normal(&mesh.vertices, *f);
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                if on_holes.contains(&a) && on_holes.contains(&b) {
                    edges.undirected.insert((a.min(b), a.max(b)));
                    edges.face_normal.insert((a, b), normal);
                }
            }
        }
        edges
    }

    fn add(&mut self, faces: &[[u32; 3]]) {
        for f in faces {
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                self.undirected.insert((a.min(b), a.max(b)));
            }
        }
    }

    fn exists(&self, a: u32, b: u32) -> bool {
        self.undirected.contains(&(a.min(b), a.max(b)))
    }
}

/// The unit normal of a face (zero for a face of no area).
fn face_normal(points: &[Point3], f: [u32; 3]) -> Point3 {
    let [a, b, c] = f.map(|v| points[v as usize]);
    unit(cross(sub(b, a), sub(c, a)))
}

fn unit(v: Point3) -> Point3 {
    let n = norm2(v).sqrt();
    if n > 0.0 {
        [v[0] / n, v[1] / n, v[2] / n]
    } else {
        [0.0; 3]
    }
}

/// A sub-polygon's best triangulation: its largest dihedral angle (as
/// 1 − cos, which orders angles alike), its area, and the apex of the
/// triangle on its base edge.
#[derive(Clone, Copy)]
struct Best {
    angle: f64,
    area: f64,
    apex: usize,
}

impl Best {
    fn better_than(&self, other: &Best) -> bool {
        (self.angle, self.area) < (other.angle, other.area)
    }
}

/// The faces closing `hole` (its vertices in the order the mesh's faces
/// run along them), wound against that order so that they continue the
/// mesh's orientation; None when no triangulation avoids the mesh's own
/// edges and faces of no area, or the hole passes a vertex twice.
fn triangulate(
    points: &[Point3],
    hole: &[u32],
    edges: &MeshEdges,
    min_area2: f64,
) -> Option<Vec<[u32; 3]>> {
    let n = hole.len();
    let distinct: HashSet<u32> = hole.iter().copied().collect();
    if n < 3 || distinct.len() != n {
        return None;
    }
    let polygon = Polygon {
        points,
        hole,
        edges,
        min_area2,
    };
    let mut best = Table {
        n,
        cells: vec![None; n * n],
    };
    for span in 2..n {
        for i in 0..n - span {
            let j = i + span;
            // The hole's own closing edge is no diagonal; any other pair
            // that is an edge of the mesh already would be doubled.
            if span < n - 1 && edges.exists(hole[i], hole[j]) {
                continue;
            }
            let mut chosen: Option<Best> = None;
            for m in i + 1..j {
                let Some(mut candidate) = polygon.triangle_best(i, m, j, &best) else {
                    continue;
                };
                if span == n - 1 {
                    // The last triangle's base is the hole's closing edge.
                    let normal = polygon.normal(i, m, j);
                    candidate.angle = candidate
                        .angle
                        .max(1.0 - dot(normal, polygon.outside(i, j)));
                }
                if chosen.is_none_or(|c| candidate.better_than(&c)) {
                    chosen = Some(candidate);
                }
            }
            *best.cell(i, j) = chosen;
        }
    }
    let mut faces = Vec::with_capacity(n - 2);
    let mut todo = vec![(0, n - 1)];
    while let Some((i, j)) = todo.pop() {
        if j - i < 2 {
            continue;
        }
        let m = best.get(i, j)?.apex;
        faces.push(polygon.face(i, m, j));
        todo.push((i, m));
        todo.push((m, j));
    }
    Some(faces)
}

/// A hole as the triangulation sees it: positions along it by index.
struct Polygon<'a> {
    points: &'a [Point3],
    hole: &'a [u32],
    edges: &'a MeshEdges,
    min_area2: f64,
}

impl Polygon<'_> {
    /// The face a triangle (i, m, j), i < m < j along the hole, becomes.
    fn face(&self, i: usize, m: usize, j: usize) -> [u32; 3] {
        [self.hole[j], self.hole[m], self.hole[i]]
    }

    fn normal(&self, i: usize, m: usize, j: usize) -> Point3 {
        face_normal(self.points, self.face(i, m, j))
    }

    /// The normal of the mesh's face along the hole's edge i → i + 1 (or
    /// n − 1 → 0).
    fn outside(&self, i: usize, j: usize) -> Point3 {
        let (a, b) = if j == i + 1 { (i, j) } else { (j, i) };
        self.edges
            .face_normal
            .get(&(self.hole[a], self.hole[b]))
            .copied()
            .unwrap_or([0.0; 3])
    }

    /// The best triangulation of sub-polygon (i, j) with apex m over its
    /// base, from the best of (i, m) and (m, j); None when a side has none
    /// or the triangle has no area.
    fn triangle_best(&self, i: usize, m: usize, j: usize, best: &Table) -> Option<Best> {
        let p = |k: usize| self.points[self.hole[k] as usize];
        let twice_area = cross(sub(p(m), p(i)), sub(p(j), p(i)));
        if norm2(twice_area) <= 4.0 * self.min_area2 {
            return None;
        }
        let normal = self.normal(i, m, j);
        let mut angle: f64 = 0.0;
        let mut area = norm2(twice_area).sqrt() / 2.0;
        for (a, b) in [(i, m), (m, j)] {
            let beside = if b == a + 1 {
                self.outside(a, b)
            } else {
                let side = best.get(a, b)?;
                angle = angle.max(side.angle);
                area += side.area;
                self.normal(a, side.apex, b)
            };
            angle = angle.max(1.0 - dot(normal, beside));
        }
        Some(Best {
            angle,
            area,
            apex: m,
        })
    }
}

/// The best triangulation of each sub-polygon (i, j), i < j.
struct Table {
    n: usize,
    cells: Vec<Option<Best>>,
}

impl Table {
    fn get(&self, i: usize, j: usize) -> Option<Best> {
        self.cells[i * self.n + j]
    }

    fn cell(&mut self, i: usize, j: usize) -> &mut Option<Best> {
        &mut self.cells[i * self.n + j]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::tests::grid;

    /// A grid with the faces round the vertices `gone` removed (each a
    /// hole of up to 8 vertices round it), its z lifted by `lift`.
    fn holed(n: u32, gone: &[u32], lift: impl Fn(Point3) -> f64) -> Mesh {
        let mut mesh = grid(n);
        mesh.faces.retain(|f| !f.iter().any(|v| gone.contains(v)));
        for p in &mut mesh.vertices {
            p[2] = lift(*p);
        }
        mesh.remove_unused_vertices();
        mesh
    }

    #[test]
    fn a_hole_narrow_enough_is_closed_and_the_outer_border_never() {
        // Vertex 4 + 4·9 = 40 of a 8 × 8 grid: a hole of 6 vertices, 2√2
        // wide.
        let mut mesh = holed(8, &[40], |_| 0.0);
        let borders = mesh.boundary_loops();
        assert_eq!(borders.len(), 2);
        let faces_before = mesh.faces.len();
        let filled = fill_holes(&mut mesh, &borders, 2.9);
        assert_eq!(
            filled,
            HolesFilled {
                holes: 1,
                faces: 4,
                left: 0
            }
        );
        assert_eq!(mesh.faces.len(), faces_before + 4);
        assert_eq!(mesh.boundary_loops().len(), 1);
        mesh.check_manifold().expect("manifold and oriented");
        // Flat and facing +z, as the grid's faces.
        for f in &mesh.faces[faces_before..] {
            assert!(face_normal(&mesh.vertices, *f)[2] > 0.999_999);
        }
        // However wide the size, the outer border stays.
        let borders = mesh.boundary_loops();
        assert_eq!(fill_holes(&mut mesh, &borders, 1e9), HolesFilled::default());
    }

    #[test]
    fn a_loop_through_a_vertex_twice_is_two_loops() {
        assert_eq!(
            simple_cycles(&[1, 2, 3, 4, 2, 5, 6]),
            vec![vec![2, 3, 4], vec![1, 2, 5, 6]]
        );
        assert_eq!(simple_cycles(&[1, 2, 3]), vec![vec![1, 2, 3]]);
        assert_eq!(
            simple_cycles(&[1, 2, 3, 2, 4, 5]),
            vec![vec![2, 3], vec![1, 2, 4, 5]]
        );
    }

    #[test]
    fn a_hole_wider_than_the_size_stays() {
        let mut mesh = holed(8, &[40], |_| 0.0);
        let borders = mesh.boundary_loops();
        let faces_before = mesh.faces.len();
        assert_eq!(fill_holes(&mut mesh, &borders, 2.8), HolesFilled::default());
        assert_eq!(mesh.faces.len(), faces_before);
    }

    #[test]
    fn a_curved_hole_follows_its_surface() {
        // Two holes on a dome: each closed facing the way the faces round
        // it face.
        let dome = |p: Point3| 4.0 - 0.05 * ((p[0] - 6.0).powi(2) + (p[1] - 6.0).powi(2));
        let mut mesh = holed(12, &[2 + 13 * 3, 3 + 13 * 3, 8 + 13 * 8], dome);
        let borders = mesh.boundary_loops();
        assert_eq!(borders.len(), 3);
        let faces_before = mesh.faces.len();
        let filled = fill_holes(&mut mesh, &borders, 4.0);
        assert_eq!((filled.holes, filled.left), (2, 0));
        mesh.check_manifold().expect("manifold and oriented");
        // Against the dome's own normal at each new face's centre.
        for &f in &mesh.faces[faces_before..] {
            let [a, b, c] = f.map(|v| mesh.vertices[v as usize]);
            let (x, y) = ((a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0);
            let dome_normal = unit([0.1 * (x - 6.0), 0.1 * (y - 6.0), 1.0]);
            let along = dot(face_normal(&mesh.vertices, f), dome_normal);
            assert!(along > 0.99, "{f:?}: {along}");
        }
    }

    #[test]
    fn a_hole_whose_diagonals_are_all_edges_stays_open() {
        // A tetrahedron without one face: its hole's only triangulation is
        // that face, whose edges all exist, which is allowed (they are the
        // hole's own); a square hole whose one diagonal exists must take
        // the other.
        let mut tetrahedron = Mesh {
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
            faces: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3]],
        };
        let borders = tetrahedron.boundary_loops();
        let filled = fill_holes(&mut tetrahedron, &borders, 10.0);
        // The mesh is one piece with one loop: its outer border.
        assert_eq!(filled, HolesFilled::default());
        // Two squares 0-1-2-3 joined along a "handle" face using diagonal
        // 0-2: the hole 0-1-2-3 must be split along 1-3.
        let edges = MeshEdges {
            undirected: [(0, 2)].into_iter().collect(),
            face_normal: HashMap::default(),
        };
        let points = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let faces = triangulate(&points, &[0, 1, 2, 3], &edges, 0.0).expect("one way left");
        for f in &faces {
            assert!(f.contains(&1) && f.contains(&3), "{faces:?}");
        }
        let both = MeshEdges {
            undirected: [(0, 2), (1, 3)].into_iter().collect(),
            face_normal: HashMap::default(),
        };
        assert!(triangulate(&points, &[0, 1, 2, 3], &both, 0.0).is_none());
        // A hole through one vertex twice is left.
        assert!(triangulate(&points, &[0, 1, 2, 0, 3], &edges, 0.0).is_none());
    }

    /// The recurrence of [`triangulate`] written top down, plainly: the
    /// best triangulation of (i, j) tried over every apex, recursing into
    /// both sides; None where a diagonal is an edge of the mesh.
    fn reference(
        points: &[Point3],
        hole: &[u32],
        edges: &MeshEdges,
        (i, j): (usize, usize),
    ) -> Option<(f64, f64, Vec<[u32; 3]>)> {
        let n = hole.len();
        if j - i < 2 {
            return Some((0.0, 0.0, Vec::new()));
        }
        if j - i < n - 1 && edges.exists(hole[i], hole[j]) {
            return None;
        }
        let normal_beside = |a: usize, b: usize, inner: &[[u32; 3]]| -> Point3 {
            if b == a + 1 {
                edges
                    .face_normal
                    .get(&(hole[a], hole[b]))
                    .copied()
                    .unwrap_or([0.0; 3])
            } else {
                // The sub-polygon's own triangle on its base (a, b): its
                // first face.
                face_normal(points, inner[0])
            }
        };
        let mut chosen: Option<(f64, f64, Vec<[u32; 3]>)> = None;
        for m in i + 1..j {
            let (Some(left), Some(right)) = (
                reference(points, hole, edges, (i, m)),
                reference(points, hole, edges, (m, j)),
            ) else {
                continue;
            };
            let face = [hole[j], hole[m], hole[i]];
            let [a, b, c] = face.map(|v| points[v as usize]);
            let twice = norm2(cross(sub(b, a), sub(c, a))).sqrt();
            if twice == 0.0 {
                continue;
            }
            let normal = face_normal(points, face);
            let mut angle = left.0.max(right.0);
            angle = angle.max(1.0 - dot(normal, normal_beside(i, m, &left.2)));
            angle = angle.max(1.0 - dot(normal, normal_beside(m, j, &right.2)));
            if j - i == n - 1 {
                let closing = edges
                    .face_normal
                    .get(&(hole[j], hole[i]))
                    .copied()
                    .unwrap_or([0.0; 3]);
                angle = angle.max(1.0 - dot(normal, closing));
            }
            let area = left.1 + right.1 + twice / 2.0;
            if chosen.as_ref().is_none_or(|c| (angle, area) < (c.0, c.1)) {
                let mut faces = vec![face];
                faces.extend(left.2);
                faces.extend(right.2);
                chosen = Some((angle, area, faces));
            }
        }
        chosen
    }

    #[test]
    fn the_triangulation_is_the_references() {
        // Random bumpy polygons of 3 to 9 vertices, with a random face
        // outside along each edge and some diagonals taken by the mesh
        // already: the same faces as the plain top-down recurrence. (Liepa's
        // recurrence, as CGAL's hole filling uses it, weighs a diagonal's
        // dihedral against the sides' own best triangulations: it is not
        // the best of all triangulations for the largest angle.)
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut random = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for n in 3..=9usize {
            for _ in 0..30 {
                let points: Vec<Point3> = (0..n)
                    .map(|k| {
                        let t = std::f64::consts::TAU * (k as f64 + 0.4 * random()) / n as f64;
                        let r = 1.0 + 0.5 * random();
                        // Wound clockwise seen from +z, so the fill faces +z.
                        [r * t.cos(), -r * t.sin(), 0.6 * (random() - 0.5)]
                    })
                    .collect();
                let hole: Vec<u32> = (0..n as u32).collect();
                let mut edges = MeshEdges {
                    undirected: HashSet::default(),
                    face_normal: HashMap::default(),
                };
                for k in 0..n as u32 {
                    let tilt = unit([0.3 * (random() - 0.5), 0.3 * (random() - 0.5), 1.0]);
                    edges.face_normal.insert((k, (k + 1) % n as u32), tilt);
                    let other = (k + 2 + (random() * n as f64) as u32) % n as u32;
                    if random() < 0.15 && other != k {
                        edges.undirected.insert((k.min(other), k.max(other)));
                    }
                }
                let ours = triangulate(&points, &hole, &edges, 0.0);
                let plain = reference(&points, &hole, &edges, (0, n - 1)).map(|r| r.2);
                let sorted = |faces: Option<Vec<[u32; 3]>>| {
                    faces.map(|mut f| {
                        f.sort_unstable();
                        f
                    })
                };
                assert_eq!(sorted(ours), sorted(plain), "n {n}");
            }
        }
    }
}
