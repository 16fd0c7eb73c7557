//! Triangle meshes: validation, area, boundary loops and manifoldness —
//! what trimming, the Delaunay path and cleanup take and give. The paper
//! works on clouds; this is infrastructure of meshtrim's mesh stages.

use crate::hash::HashMap;

use crate::cloud::out_of_range;
use crate::cloud::{MAX_COORDINATE, MIN_LARGEST_COORDINATE};
use crate::error::MeshError;

pub(crate) mod fill;
pub(crate) mod manifold;
pub(crate) mod pinches;
pub(crate) mod repair;
pub(crate) mod rows;
pub(crate) mod seams;
pub(crate) mod topology;
use crate::geom::{add, cross, dot, norm2, sub, Point3};
use topology::EdgeRows;

/// An indexed triangle mesh.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// Vertex positions.
    pub vertices: Vec<Point3>,
    /// Triangles as vertex indices, counter-clockwise seen from outside
    /// (for the meshes meshtrim writes: as oriented in the input).
    pub faces: Vec<[u32; 3]>,
}

/// Refuses finite vertices outside the supported coordinate range (the
/// largest |coordinate| between 10⁻³⁰ and 10⁵⁰): beyond it spade panics or fails and
/// the geometry's squares overflow or underflow.
pub fn check_vertex_range(vertices: &[Point3]) -> Result<(), MeshError> {
    match out_of_range(vertices) {
        Some(largest) => Err(MeshError::OutOfRange {
            largest,
            min: MIN_LARGEST_COORDINATE,
            max: MAX_COORDINATE,
        }),
        None => Ok(()),
    }
}

/// A face's corners rotated to start at its lowest index, keeping their
/// turn: equal for two faces with the same corners in the same turn,
/// different for opposite turns. Gives faces an order of their own ids.
pub fn lowest_first(f: [u32; 3]) -> [u32; 3] {
    let first = (0..3).min_by_key(|&k| f[k]).unwrap_or(0);
    [f[first], f[(first + 1) % 3], f[(first + 2) % 3]]
}

impl Mesh {
    /// Checks indices and coordinates (finite, and within the supported
    /// range: [`check_vertex_range`]).
    pub fn validate(&self) -> Result<(), MeshError> {
        if self.faces.is_empty() {
            return Err(MeshError::NoFaces);
        }
        if let Some(index) = self
            .vertices
            .iter()
            .position(|v| v.iter().any(|c| !c.is_finite()))
        {
            return Err(MeshError::NonFinite { index });
        }
        check_vertex_range(&self.vertices)?;
        for (face, f) in self.faces.iter().enumerate() {
            if let Some(&vertex) = f.iter().find(|&&v| v as usize >= self.vertices.len()) {
                return Err(MeshError::IndexOutOfRange {
                    face,
                    vertex,
                    vertices: self.vertices.len(),
                });
            }
        }
        Ok(())
    }

    /// Area of face `f`.
    pub fn face_area(&self, f: usize) -> f64 {
        0.5 * norm2(self.face_area_vector(f)).sqrt()
    }

    /// Face `f`'s normal times twice its area (the cross product of two
    /// of its sides, in its vertices' order).
    pub(crate) fn face_area_vector(&self, f: usize) -> Point3 {
        let [a, b, c] = self.faces[f].map(|i| self.vertices[i as usize]);
        cross(sub(b, a), sub(c, a))
    }

    /// Total area.
    pub fn area(&self) -> f64 {
        (0..self.faces.len()).map(|f| self.face_area(f)).sum()
    }

    /// The area-weighted mean of the faces' normals, as a unit vector:
    /// for a scan seen from one side, the direction it was seen from
    /// (towards the scanner, the faces' orientation). `None` when the
    /// normals cancel (a closed surface) or there is no area.
    pub fn mean_normal(&self) -> Option<Point3> {
        self.mean_normal_of(0..self.faces.len())
    }

    /// [`Mesh::mean_normal`] of the faces `faces` alone.
    pub(crate) fn mean_normal_of(&self, faces: impl IntoIterator<Item = usize>) -> Option<Point3> {
        let sum = faces
            .into_iter()
            .fold([0.0; 3], |sum, f| add(sum, self.face_area_vector(f)));
        let length = norm2(sum).sqrt();
        (length > 0.0 && length.is_finite()).then(|| sum.map(|x| x / length))
    }

    /// The largest share of the area that faces one direction (whose
    /// normals make less than 90° with it), over all directions: 1 for a
    /// surface seen from one side (every face of a single range scan faces
    /// its scanner), about one half for a closed surface, and between for
    /// a surface that wraps round an object with an opening (a cup: 0.6).
    /// The faces' normals are binned on a cube map of
    /// 16² cells per side (a bin counts by its
    /// faces' summed normal, so faces of one bin go to the same side), and
    /// every cell's centre is tried as the direction: linear in the faces,
    /// the share of the best of those directions. A mesh without area
    /// gives 0.
    pub fn area_facing_one_way(&self) -> f64 {
        // Per bin, the sum of its faces' area vectors (each face's normal
        // times twice its area) and their area.
        let mut bins = vec![([0.0; 3], 0.0); 6 * FACING_BINS_PER_SIDE * FACING_BINS_PER_SIDE];
        for f in &self.faces {
            let [a, b, c] = f.map(|i| self.vertices[i as usize]);
            let normal = cross(sub(b, a), sub(c, a));
            let area = norm2(normal).sqrt();
            if area > 0.0 {
                let bin = &mut bins[cube_map_bin(normal)];
                *bin = (add(bin.0, normal), bin.1 + area);
            }
        }
        let bins: Vec<(Point3, f64)> = bins.into_iter().filter(|b| b.1 > 0.0).collect();
        let total: f64 = bins.iter().map(|b| b.1).sum();
        if total == 0.0 {
            return 0.0;
        }
        let facing = |d: Point3| -> f64 {
            bins.iter()
                .filter(|&&(normal, _)| dot(normal, d) > 0.0)
                .map(|&(_, area)| area)
                .sum()
        };
        let best = (0..6 * FACING_BINS_PER_SIDE * FACING_BINS_PER_SIDE)
            .map(|bin| facing(cube_map_direction(bin)))
            .fold(0.0, f64::max);
        best / total
    }

    /// How many faces use each undirected edge (the plain way, for the
    /// tests' references).
    #[cfg(test)]
    pub(crate) fn edge_uses(&self) -> HashMap<(u32, u32), u32> {
        let mut uses = HashMap::default();
        for f in &self.faces {
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        uses
    }

    /// Every edge of every face as (smaller vertex, larger vertex, face),
    /// sorted, so that the faces on one edge are next to each other.
    ///
    /// A counting sort on the smaller vertex (O(edges), no comparisons),
    /// then a sort of each vertex's few edges: several times faster than
    /// sorting or hashing all edges of a large mesh; the same result as
    /// sorting the tuples (tested).
    pub(crate) fn sorted_edges(&self) -> Vec<(u32, u32, u32)> {
        sorted_edges_of(&self.faces)
    }

    /// [`Self::sorted_edges`] by sorting the tuples; the reference for tests.
    #[cfg(test)]
    pub(crate) fn sorted_edges_reference(&self) -> Vec<(u32, u32, u32)> {
        let mut edges: Vec<(u32, u32, u32)> = (0..self.faces.len())
            .flat_map(|f| {
                let face = self.faces[f];
                (0..3).map(move |k| {
                    let (a, b) = (face[k], face[(k + 1) % 3]);
                    (a.min(b), a.max(b), f as u32)
                })
            })
            .collect();
        edges.sort_unstable();
        edges
    }

    /// True if no edge is used by more than two faces.
    pub fn is_edge_manifold(&self) -> bool {
        topology::edge_defects(self).0 == 0
    }

    /// Checks that the mesh is edge-manifold (no edge used by more than two
    /// faces, [`MeshError::NonManifold`]) and consistently oriented (no two
    /// faces run a shared edge the same way, [`MeshError::Misoriented`]):
    /// what trimming and cleanup need of their input, and guarantee of
    /// their output.
    pub fn check_manifold(&self) -> Result<(), MeshError> {
        topology::check_manifold(self)
    }

    /// The border: directed edges (as the faces run) used by one face only,
    /// chained into loops of vertex indices. At a vertex where several
    /// border loops touch, the chaining takes the edges in index order.
    /// The "edge" from a vertex to itself of a face that names it twice
    /// (a zero-area sliver) is no border: it would be a loop of one
    /// vertex, anywhere on the surface.
    pub fn boundary_loops(&self) -> Vec<Vec<u32>> {
        boundary_loops_of(&EdgeRows::new(&self.faces))
    }

    /// [`Self::boundary_loops`] with a hash map of edge uses, the plain way;
    /// the reference for tests.
    #[cfg(test)]
    pub(crate) fn boundary_loops_reference(&self) -> Vec<Vec<u32>> {
        let uses = self.edge_uses();
        let mut next: HashMap<u32, Vec<u32>> = HashMap::default();
        for f in &self.faces {
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                if a != b && uses[&(a.min(b), a.max(b))] == 1 {
                    next.entry(a).or_default().push(b);
                }
            }
        }
        chain_loops(next)
    }

    /// Keeps the faces whose entry in `keep` is true, in order; vertices
    /// stay as they are.
    pub fn retain_faces(&mut self, keep: &[bool]) {
        let mut flags = keep.iter();
        self.faces
            .retain(|_| flags.next().copied().unwrap_or(false));
    }

    /// Drops vertices no face uses, keeping the others in order.
    pub fn remove_unused_vertices(&mut self) {
        let mut new_index = vec![u32::MAX; self.vertices.len()];
        for f in &self.faces {
            for &v in f {
                new_index[v as usize] = 0;
            }
        }
        let mut kept = Vec::new();
        for (i, slot) in new_index.iter_mut().enumerate() {
            if *slot == 0 {
                *slot = kept.len() as u32;
                kept.push(self.vertices[i]);
            }
        }
        for f in self.faces.iter_mut() {
            *f = f.map(|v| new_index[v as usize]);
        }
        self.vertices = kept;
    }
}

/// A closed walk split into simple cycles where it passes a vertex twice
/// (a region pinched at a vertex between two of its stretches; holes
/// touching at a vertex), each cycle in the walk's order.
pub(crate) fn simple_cycles(walk: &[u32]) -> Vec<Vec<u32>> {
    let mut cycles = Vec::new();
    let mut path: Vec<u32> = Vec::with_capacity(walk.len());
    let mut at: HashMap<u32, usize> = HashMap::default();
    for &v in walk {
        if let Some(&first) = at.get(&v) {
            let cycle = path.split_off(first + 1);
            for w in &cycle {
                at.remove(w);
            }
            let mut closed = vec![v];
            closed.extend(cycle);
            cycles.push(closed);
        } else {
            at.insert(v, path.len());
            path.push(v);
        }
    }
    cycles.push(path);
    cycles
}

/// [`Mesh::boundary_loops`] of a mesh whose directed edges are built.
pub(crate) fn boundary_loops_of(edges: &EdgeRows) -> Vec<Vec<u32>> {
    chain_loops(edges.border())
}

/// Chains border edges (`next[a]` holds every b of an edge a → b) into
/// loops, taking the edges at a vertex in index order.
fn chain_loops(mut next: HashMap<u32, Vec<u32>>) -> Vec<Vec<u32>> {
    for v in next.values_mut() {
        v.sort_unstable();
    }
    let mut starts: Vec<u32> = next.keys().copied().collect();
    starts.sort_unstable();
    let mut loops = Vec::new();
    for start in starts {
        while let Some(first) = next.get_mut(&start).and_then(|v| v.pop()) {
            let mut chain = vec![start];
            let mut at = first;
            while at != start {
                chain.push(at);
                match next.get_mut(&at).and_then(|v| v.pop()) {
                    Some(b) => at = b,
                    None => break, // an open chain: non-manifold input
                }
            }
            loops.push(chain);
        }
    }
    loops
}

/// Cells per side of a cube face in [`Mesh::area_facing_one_way`]'s normal
/// bins: 16 gives bins about 6° wide.
const FACING_BINS_PER_SIDE: usize = 16;

/// The cube-map cell of the direction `n` (not zero): the cube face of its
/// largest coordinate, then the cell of the other two divided by it.
fn cube_map_bin(n: Point3) -> usize {
    let axis = (0..3)
        .max_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs()))
        .unwrap_or(0);
    let side = 2 * axis + usize::from(n[axis] < 0.0);
    let cell = |c: f64| {
        let t = (c / n[axis].abs() + 1.0) / 2.0;
        ((t * FACING_BINS_PER_SIDE as f64) as usize).min(FACING_BINS_PER_SIDE - 1)
    };
    let [u, v] = [(axis + 1) % 3, (axis + 2) % 3].map(|k| cell(n[k]));
    (side * FACING_BINS_PER_SIDE + u) * FACING_BINS_PER_SIDE + v
}

/// The unit direction through the centre of cube-map cell `bin`.
fn cube_map_direction(bin: usize) -> Point3 {
    let cells = FACING_BINS_PER_SIDE;
    let (side, u, v) = (bin / (cells * cells), (bin / cells) % cells, bin % cells);
    let axis = side / 2;
    let centre = |cell: usize| 2.0 * (cell as f64 + 0.5) / cells as f64 - 1.0;
    let mut d = [0.0; 3];
    d[axis] = if side % 2 == 0 { 1.0 } else { -1.0 };
    d[(axis + 1) % 3] = centre(u);
    d[(axis + 2) % 3] = centre(v);
    let length = norm2(d).sqrt();
    d.map(|c| c / length)
}

/// How many rows filing the edges of `faces` under their smaller vertex
/// takes: sized by the largest index the faces name, so a face that names
/// a vertex past the end (an invalid mesh, which `validate` reports)
/// still gets its edges instead of a panic.
pub(crate) fn rows_for_vertices_of(faces: &[[u32; 3]]) -> usize {
    faces.iter().flatten().max().map_or(0, |&v| v as usize + 1)
}

/// The edge `k` of `face` filed under its smaller vertex: (smaller,
/// larger, whether the face runs it from the larger).
pub(crate) fn edge_by_smaller_vertex(face: &[u32; 3], k: usize) -> (u32, u32, bool) {
    let (a, b) = (face[k], face[(k + 1) % 3]);
    (a.min(b), a.max(b), a > b)
}

/// [`Mesh::sorted_edges`] of a list of faces (which need not be a whole
/// mesh's: the faces of one part of it, say).
pub fn sorted_edges_of(faces: &[[u32; 3]]) -> Vec<(u32, u32, u32)> {
    let mut rows = rows::file_by_row(rows_for_vertices_of(faces), faces, |f, face, k| {
        let (low, high, _) = edge_by_smaller_vertex(face, k);
        Some((low, (low, high, f)))
    });
    // Filed in face order, so each vertex's edges are sorted by face
    // already; a stable sort by the larger vertex finishes.
    rows.sort_each_by_key(|&(_, high, _)| high);
    rows.values
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// An n × n grid of unit squares, two triangles each, counter-clockwise.
    pub(crate) fn grid(n: u32) -> Mesh {
        let vertices = (0..=n)
            .flat_map(|j| (0..=n).map(move |i| [i as f64, j as f64, 0.0]))
            .collect();
        let at = |i: u32, j: u32| j * (n + 1) + i;
        let faces = (0..n)
            .flat_map(|j| {
                (0..n).flat_map(move |i| {
                    [
                        [at(i, j), at(i + 1, j), at(i + 1, j + 1)],
                        [at(i, j), at(i + 1, j + 1), at(i, j + 1)],
                    ]
                })
            })
            .collect();
        Mesh { vertices, faces }
    }

    /// A closed box: its 12 faces, outward.
    fn cube() -> Mesh {
        let vertices = (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
            .collect();
        let faces = vec![
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        Mesh { vertices, faces }
    }

    #[test]
    fn area_facing_one_way_tells_one_side_from_wrapping_round() {
        // A flat grid and the same grid bent into a half cylinder (seen
        // from one side): all of it.
        assert_eq!(grid(8).area_facing_one_way(), 1.0);
        let mut half_cylinder = grid(8);
        for v in &mut half_cylinder.vertices {
            let angle = 0.95 * std::f64::consts::PI * (v[0] / 8.0 - 0.5);
            *v = [angle.sin(), v[1], angle.cos()];
        }
        assert_eq!(half_cylinder.area_facing_one_way(), 1.0);
        // A closed box: three sides of six at best.
        let share = |m: &Mesh| m.area_facing_one_way();
        assert!((share(&cube()) - 0.5).abs() < 1e-12, "{}", share(&cube()));
        // Open at the top, a cup: the bottom and two walls of five.
        let mut cup = cube();
        cup.faces.retain(|f| !f.iter().all(|&v| v >= 4));
        assert!((share(&cup) - 0.6).abs() < 1e-12);
        assert_eq!(Mesh::default().area_facing_one_way(), 0.0);
    }

    #[test]
    fn every_cube_map_bin_holds_its_own_direction() {
        for bin in 0..6 * FACING_BINS_PER_SIDE * FACING_BINS_PER_SIDE {
            assert_eq!(cube_map_bin(cube_map_direction(bin)), bin);
        }
    }

    #[test]
    fn grid_has_one_border_loop_and_its_area() {
        let m = grid(4);
        assert!(m.validate().is_ok());
        assert!((m.area() - 16.0).abs() < 1e-12);
        assert!(m.is_edge_manifold());
        let loops = m.boundary_loops();
        assert_eq!(loops.len(), 1);
        assert_eq!(loops[0].len(), 16);
    }

    /// A face that names a vertex twice has an "edge" from that vertex to
    /// itself, used once: it is no border. Taken for one, it would make a
    /// loop of one interior vertex, which the trim report would measure as
    /// a border vertex far from every smoothed edge.
    #[test]
    fn an_edge_from_a_vertex_to_itself_is_no_border() {
        let inner = 2 * 5 + 2;
        for extra in [[inner, inner, inner + 1], [inner + 1, inner, inner]] {
            let mut m = grid(4);
            m.faces.push(extra);
            assert_eq!(m.boundary_loops(), grid(4).boundary_loops());
            assert_eq!(m.boundary_loops_reference(), grid(4).boundary_loops());
        }
    }

    #[test]
    fn bad_indices_and_values_are_errors() {
        let mut m = grid(1);
        m.faces[1][2] = 9;
        assert!(matches!(
            m.validate(),
            Err(MeshError::IndexOutOfRange {
                face: 1,
                vertex: 9,
                ..
            })
        ));
        let mut m = grid(1);
        m.vertices[2][0] = f64::NAN;
        assert_eq!(m.validate(), Err(MeshError::NonFinite { index: 2 }));
        // Beyond the supported range, spade panics and squares overflow.
        for scale in [1e90, 1e-60] {
            let mut m = grid(2);
            m.vertices.iter_mut().flatten().for_each(|c| *c *= scale);
            assert!(matches!(m.validate(), Err(MeshError::OutOfRange { .. })));
        }
    }

    #[test]
    fn unused_vertices_are_dropped() {
        let mut m = grid(2);
        m.faces.truncate(2);
        m.remove_unused_vertices();
        assert_eq!(m.vertices.len(), 4);
        assert!(m.validate().is_ok());
    }
}
