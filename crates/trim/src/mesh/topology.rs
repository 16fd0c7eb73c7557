//! Mesh topology: edge uses counted by sorting, the manifold and
//! orientation check, and the faces round each vertex.

use super::Mesh;
use crate::error::MeshError;

/// Edge-manifold with consistent orientation: every undirected edge used
/// at most twice, every directed edge at most once.
pub(crate) fn check_manifold(mesh: &Mesh) -> Result<(), MeshError> {
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

/// The faces around each vertex (compressed rows).
pub(crate) struct Topology {
    pub(crate) start: Vec<u32>,
    pub(crate) faces: Vec<u32>,
}

impl Topology {
    pub(crate) fn new(mesh: &Mesh) -> Self {
        let mut count = vec![0u32; mesh.vertices.len() + 1];
        for f in &mesh.faces {
            for &v in f {
                count[v as usize + 1] += 1;
            }
        }
        for i in 1..count.len() {
            count[i] += count[i - 1];
        }
        let mut fill = count.clone();
        let mut faces = vec![0; count[mesh.vertices.len()] as usize];
        for (i, f) in mesh.faces.iter().enumerate() {
            for &v in f {
                faces[fill[v as usize] as usize] = i as u32;
                fill[v as usize] += 1;
            }
        }
        Topology {
            start: count,
            faces,
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
