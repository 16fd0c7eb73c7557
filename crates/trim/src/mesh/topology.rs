//! Mesh topology: edge uses counted by sorting, the manifold and
//! orientation check, and the faces round each vertex.

use super::rows::file_by_row;
use super::{edge_by_smaller_vertex, rows_for_vertices_of, Mesh};
use crate::error::MeshError;
use crate::hash::HashMap;

/// Edge-manifold with consistent orientation: every undirected edge used
/// at most twice, every directed edge at most once.
pub(crate) fn check_manifold(mesh: &Mesh) -> Result<(), MeshError> {
    check_manifold_with(mesh, &EdgeRows::new(&mesh.faces))
}

/// [`check_manifold`] with the mesh's edge rows already built: a mesh
/// [`manifold_at_a_glance`] passes without counting each edge's uses, the
/// costly part on a large mesh; otherwise the defects are counted to say
/// how many.
pub(crate) fn check_manifold_with(mesh: &Mesh, edges: &EdgeRows) -> Result<(), MeshError> {
    if manifold_at_a_glance(mesh, edges) {
        return Ok(());
    }
    let (over, misoriented) = edge_defects(mesh);
    if over > 0 {
        return Err(MeshError::NonManifold { edges: over });
    }
    if misoriented > 0 {
        return Err(MeshError::Misoriented { edges: misoriented });
    }
    Ok(())
}

/// The undirected edges used by more than two faces, and the directed
/// edges used more than once (two faces that meet there turn opposite
/// ways).
pub(crate) fn edge_defects(mesh: &Mesh) -> (usize, usize) {
    let (mut over, mut misoriented) = (0, 0);
    for_each_edge(mesh, |faces, forward, backward| {
        over += usize::from(faces.len() > 2);
        misoriented += usize::from(forward > 1) + usize::from(backward > 1);
    });
    (over, misoriented)
}

/// Calls `visit` for every undirected edge of `mesh` with its entries in
/// [`Mesh::sorted_edges`] (one per use: smaller vertex, larger, face) and
/// how many times faces run along it from the smaller vertex to the
/// larger and back. Sorted edges are a counting sort, several times
/// faster than hashing every edge.
pub(crate) fn for_each_edge(mesh: &Mesh, mut visit: impl FnMut(&[(u32, u32, u32)], usize, usize)) {
    let edges = mesh.sorted_edges();
    for run in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        let (a, b) = (run[0].0, run[0].1);
        let (mut forward, mut backward) = (0, 0);
        for (i, &(_, _, f)) in run.iter().enumerate() {
            // A face holds the edge once per entry; count its turns once.
            if run[..i].iter().any(|e| e.2 == f) {
                continue;
            }
            let face = mesh.faces[f as usize];
            for k in 0..3 {
                let step = (face[k], face[(k + 1) % 3]);
                forward += usize::from(step == (a, b));
                backward += usize::from(a != b && step == (b, a));
            }
        }
        visit(run, forward, backward);
    }
}

/// Whether every face has three distinct vertices and no edge is run
/// twice the same way: each edge is then run at most once each way, so
/// used at most twice, consistently (and no face repeats another in the
/// same turn).
pub(crate) fn manifold_at_a_glance(mesh: &Mesh, edges: &EdgeRows) -> bool {
    edges.no_edge_run_twice() && mesh.faces.iter().all(|&f| distinct(f))
}

/// Whether a face names three different vertices.
pub(crate) fn distinct(f: [u32; 3]) -> bool {
    f[0] != f[1] && f[1] != f[2] && f[2] != f[0]
}

/// Every face's edges, each under its smaller vertex (compressed rows,
/// each sorted): an entry holds the larger vertex and whether the face
/// runs the edge from the larger to the smaller. A counting sort over the
/// faces, with no face lookups afterwards: the uses of an edge lie side by
/// side, forward before backward, which is all the manifold check and the
/// border need of a mesh of millions of faces.
pub(crate) struct EdgeRows {
    start: Vec<u32>,
    entries: Vec<u64>,
}

impl EdgeRows {
    /// The edges of `faces`, each filed under its smaller vertex.
    pub(crate) fn new(faces: &[[u32; 3]]) -> Self {
        let mut rows = file_by_row(rows_for_vertices_of(faces), faces, |_, face, k| {
            let (low, high, backwards) = edge_by_smaller_vertex(face, k);
            Some((low, (u64::from(high) << 1) | u64::from(backwards)))
        });
        rows.sort_each_by_key(|&entry| entry);
        EdgeRows {
            start: rows.start,
            entries: rows.values,
        }
    }

    /// Each row: its smaller vertex and its entries.
    fn rows(&self) -> impl Iterator<Item = (u32, &[u64])> {
        self.start
            .windows(2)
            .enumerate()
            .map(|(low, w)| (low as u32, &self.entries[w[0] as usize..w[1] as usize]))
    }

    /// Whether no two faces run the same edge the same way.
    pub(crate) fn no_edge_run_twice(&self) -> bool {
        self.rows()
            .all(|(_, row)| row.windows(2).all(|p| p[0] != p[1]))
    }

    /// The edges one face uses (the edge {a, a} of a face that names a
    /// vertex twice included), as that face runs them.
    fn used_once(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.rows().flat_map(|(low, row)| {
            row.chunk_by(|x, y| x >> 1 == y >> 1)
                .filter(|uses| uses.len() == 1)
                .map(move |uses| {
                    let high = (uses[0] >> 1) as u32;
                    if uses[0] & 1 == 1 {
                        (high, low)
                    } else {
                        (low, high)
                    }
                })
        })
    }

    /// The border edges a → b (a ≠ b) as their faces run them: `next[a]`
    /// holds the b's.
    pub(crate) fn border(&self) -> HashMap<u32, Vec<u32>> {
        let mut next: HashMap<u32, Vec<u32>> = HashMap::default();
        for (a, b) in self.used_once().filter(|(a, b)| a != b) {
            next.entry(a).or_default().push(b);
        }
        next
    }

    /// The vertices of edges one face uses, ascending.
    pub(crate) fn border_vertices(&self) -> Vec<u32> {
        let mut border: Vec<u32> = self.used_once().flat_map(|(a, b)| [a, b]).collect();
        border.sort_unstable();
        border.dedup();
        border
    }
}

/// The faces around each vertex (compressed rows).
pub(crate) struct Topology {
    pub(crate) start: Vec<u32>,
    pub(crate) faces: Vec<u32>,
}

impl Topology {
    pub(crate) fn new(mesh: &Mesh) -> Self {
        let rows = file_by_row(mesh.vertices.len(), &mesh.faces, |f, face, k| {
            Some((face[k], f))
        });
        Topology {
            start: rows.start,
            faces: rows.values,
        }
    }

    /// The faces round vertex `v`; none for a vertex the mesh does not
    /// have (a patch's new smoothed-loop vertex, which a blocked wall can
    /// name).
    pub(crate) fn faces_of(&self, v: u32) -> &[u32] {
        match (self.start.get(v as usize), self.start.get(v as usize + 1)) {
            (Some(&from), Some(&to)) => &self.faces[from as usize..to as usize],
            _ => &[],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// [`check_manifold`] by counting every edge's uses.
    fn check_manifold_reference(mesh: &Mesh) -> Result<(), MeshError> {
        match edge_defects(mesh) {
            (0, 0) => Ok(()),
            (0, misoriented) => Err(MeshError::Misoriented { edges: misoriented }),
            (over, _) => Err(MeshError::NonManifold { edges: over }),
        }
    }

    /// A few faces over six vertices: repeats, turns both ways, fans of
    /// three faces on an edge and faces naming a vertex twice all come up.
    fn random_soup(rng: &mut ChaCha8Rng) -> Mesh {
        let vertices = vec![[0.0; 3]; 6];
        let faces = (0..rng.random_range(1..9))
            .map(|_| [0; 3].map(|_| rng.random_range(0..6u32)))
            .collect();
        Mesh { vertices, faces }
    }

    fn border_vertices_reference(mesh: &Mesh) -> Vec<u32> {
        let mut border: Vec<u32> = mesh
            .edge_uses()
            .into_iter()
            .filter(|&(_, uses)| uses == 1)
            .flat_map(|((a, b), _)| [a, b])
            .collect();
        border.sort_unstable();
        border.dedup();
        border
    }

    fn some_edge_run_twice_reference(mesh: &Mesh) -> bool {
        let mut runs: HashMap<(u32, u32), usize> = HashMap::default();
        for f in &mesh.faces {
            for k in 0..3 {
                *runs.entry((f[k], f[(k + 1) % 3])).or_default() += 1;
            }
        }
        runs.values().any(|&n| n > 1)
    }

    #[test]
    fn edge_rows_agree_with_counting_every_edge() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let (mut passed, mut failed) = (0, 0);
        for case in 0..3000 {
            let mesh = random_soup(&mut rng);
            let rows = EdgeRows::new(&mesh.faces);
            let checked = check_manifold(&mesh);
            assert_eq!(checked, check_manifold_reference(&mesh), "{case}: {mesh:?}");
            assert_eq!(
                rows.no_edge_run_twice(),
                !some_edge_run_twice_reference(&mesh),
                "{case}: {mesh:?}"
            );
            assert_eq!(
                rows.border_vertices(),
                border_vertices_reference(&mesh),
                "{case}"
            );
            assert_eq!(
                mesh.boundary_loops(),
                mesh.boundary_loops_reference(),
                "{case}"
            );
            if checked.is_ok() {
                passed += 1;
            } else {
                failed += 1;
            }
        }
        // Both outcomes, many times: the fast path and the counting.
        assert!(
            passed > 300 && failed > 300,
            "{passed} passed, {failed} failed"
        );
    }

    #[test]
    fn an_index_past_the_vertices_gets_its_row() {
        let rows = EdgeRows::new(&[[0, 1, 9]]);
        assert_eq!(rows.border_vertices(), vec![0, 1, 9]);
    }
}
