//! The input face each output face lies on, for per-face attributes (an
//! OBJ's material): meshtrim's own layer, as the vertices' carrying is.
//!
//! A face kept from the input is that face: the input face with its
//! corners' source vertices in the same turn. Any other face (a piece of a
//! cut face, a new face along a smoothed border) takes, among the input
//! faces its corners read from (the face a corner lies on, the faces round
//! a corner kept as it was), the one nearest its centroid; on a tie the
//! lower index. A face whose corners read nothing of the input's faces (an
//! input without faces) takes none.

use rayon::prelude::*;

use super::{centroid, closest_on_face, VertexSource};
use crate::mesh::topology::Topology;
use crate::mesh::Mesh;

/// For each face of `to`, the face of `from` it lies on (see the module
/// doc), given its vertices' `sources` in `from`
/// ([`super::vertex_sources`], or [`super::split_sources`]' for a split
/// `to`); `None` for a face that reads no input face.
pub fn face_sources(from: &Mesh, to: &Mesh, sources: &[VertexSource]) -> Vec<Option<u32>> {
    let around = Topology::new(from);
    to.faces
        .par_iter()
        .map(|&face| {
            let read = face.map(|v| sources[v as usize]);
            twin(from, &around, read)
                .or_else(|| nearest_read(from, &around, read, centroid(&to.vertices, face)))
        })
        .collect()
}

/// The input face whose corners are the three source vertices, in turn.
fn twin(from: &Mesh, around: &Topology, read: [VertexSource; 3]) -> Option<u32> {
    let [VertexSource::Vertex(a), VertexSource::Vertex(b), VertexSource::Vertex(c)] = read else {
        return None;
    };
    let turns = [[a, b, c], [b, c, a], [c, a, b]];
    around
        .faces_of(a)
        .iter()
        .copied()
        .find(|&f| turns.contains(&from.faces[f as usize]))
}

/// The input face nearest `p` among those the corners read from.
fn nearest_read(
    from: &Mesh,
    around: &Topology,
    read: [VertexSource; 3],
    p: [f64; 3],
) -> Option<u32> {
    read.iter()
        .flat_map(|source| match *source {
            VertexSource::Vertex(v) => around.faces_of(v),
            VertexSource::Face { ref face, .. } => std::slice::from_ref(face),
        })
        .map(|&f| (closest_on_face(from, f, p).0, f))
        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
        .map(|(_, f)| f)
}

/// [`face_sources`] by comparing every face: the twin among all input
/// faces, else the input face nearest the centroid among all of them.
/// The reference the fast one is tested against on meshes where the
/// nearest face is one the corners read.
#[cfg(test)]
fn face_sources_reference(from: &Mesh, to: &Mesh, sources: &[VertexSource]) -> Vec<Option<u32>> {
    to.faces
        .iter()
        .map(|&face| {
            let read = face.map(|v| sources[v as usize]);
            if let [VertexSource::Vertex(a), VertexSource::Vertex(b), VertexSource::Vertex(c)] =
                read
            {
                let turns = [[a, b, c], [b, c, a], [c, a, b]];
                if let Some(f) = from.faces.iter().position(|f| turns.contains(f)) {
                    return Some(f as u32);
                }
            }
            let p = centroid(&to.vertices, face);
            (0..from.faces.len() as u32)
                .map(|f| (closest_on_face(from, f, p).0, f))
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
                .map(|(_, f)| f)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::attributes::vertex_sources;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A wavy grid of `n` × `n` squares, two faces each.
    fn sheet(n: u32, rng: &mut ChaCha8Rng) -> Mesh {
        let mut mesh = crate::mesh::tests::grid(n);
        for p in &mut mesh.vertices {
            p[2] = 0.05 * rng.random::<f64>();
        }
        mesh
    }

    /// Some faces kept (in other turns and order), some split at a random
    /// inner point into three, some dropped: each output face lies on the
    /// face it came from, and the fast search finds what comparing every
    /// face finds.
    #[test]
    fn pieces_lie_on_the_faces_they_came_from() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..20 {
            let from = sheet(rng.random_range(2..7), &mut rng);
            let mut to = Mesh {
                vertices: from.vertices.clone(),
                faces: Vec::new(),
            };
            let mut parent = Vec::new();
            for (f, &[a, b, c]) in from.faces.iter().enumerate() {
                match rng.random_range(0..4) {
                    0 => {}
                    1 => {
                        let w: [f64; 3] = std::array::from_fn(|_| rng.random_range(0.1..1.0));
                        let total: f64 = w.iter().sum();
                        let [pa, pb, pc] = [a, b, c].map(|v| from.vertices[v as usize]);
                        let p = std::array::from_fn(|k| {
                            (w[0] * pa[k] + w[1] * pb[k] + w[2] * pc[k]) / total
                        });
                        let m = to.vertices.len() as u32;
                        to.vertices.push(p);
                        to.faces.extend([[a, b, m], [b, c, m], [c, a, m]]);
                        parent.extend([f as u32; 3]);
                    }
                    turn => {
                        to.faces.push([[a, b, c], [b, c, a], [c, a, b]][turn - 1]);
                        parent.push(f as u32);
                    }
                }
            }
            let sources = vertex_sources(&from, &to).unwrap();
            let found = face_sources(&from, &to, &sources);
            let want: Vec<Option<u32>> = parent.into_iter().map(Some).collect();
            assert_eq!(found, want);
            assert_eq!(face_sources_reference(&from, &to, &sources), want);
        }
    }
}
