//! Seams: a surface stored in pieces that share positions but not
//! vertices. meshtrim's own layer; the paper meshes clouds and has none.
//!
//! A vertex holds one normal, one colour, one texture coordinate, so a
//! file splits its vertices where those change across an edge: a texture
//! chart's border, a hard edge. glTF must (its attributes are per vertex),
//! PLY and OBJ exports often do. Each side of such a seam then runs along
//! the same positions with vertices of its own, and to the edges the seam
//! is a border, which the cleanup would smooth as if the surface ended
//! there. Stitching joins the sides again: where two border edges join
//! the same two positions, running opposite ways, and no other border
//! edge joins them, their ends are one vertex each (the lowest index; the
//! other copies are left out). The attributes stay
//! with the input's vertices; carrying them to the output splits its
//! vertices again where the input's were (`attributes.rs`).
//!
//! *Choices.* Border edges only, in opposite turns, paired one to one:
//! a stitch then never puts a third face on an edge nor turns two faces
//! against each other, so a mesh that was edge-manifold and oriented stays
//! so. Positions must be equal bit for bit (the seam's copies are copies;
//! a gap of any width is a border). A vertex that only touches another at
//! a point (no border edge along it) stays apart, a pinch either way.

use std::borrow::Cow;

use super::topology::EdgeRows;
use super::Mesh;
use crate::geom::UnionFind;
use crate::hash::{HashMap, HashSet};

/// A mesh with its seams stitched ([`stitch_seams`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Stitched<'a> {
    /// The mesh: the copies along each seam one vertex, the lowest index
    /// of them, the others left out; the vertices otherwise in order.
    pub mesh: Cow<'a, Mesh>,
    /// The index in the mesh given of each vertex of `mesh`; `None` when
    /// nothing was stitched (`mesh` is the mesh given).
    pub kept: Option<Vec<u32>>,
    /// The number of edges stitched.
    pub edges: usize,
}

/// `mesh` with its seams stitched (see the module doc); borrowed as it is
/// when it has none.
pub fn stitch_seams(mesh: &Mesh) -> Stitched<'_> {
    stitch_seams_with(mesh, &EdgeRows::new(&mesh.faces))
}

/// [`stitch_seams`] with the mesh's edge rows built. Only border vertices
/// are looked at, so a mesh without seams costs little more than its
/// border.
pub(crate) fn stitch_seams_with<'a>(mesh: &'a Mesh, edges: &EdgeRows) -> Stitched<'a> {
    let unchanged = Stitched {
        mesh: Cow::Borrowed(mesh),
        kept: None,
        edges: 0,
    };
    let border = edges.border();
    let shared = shared_positions(mesh, &border);
    if shared.is_empty() {
        return unchanged;
    }
    let pairs = seam_edge_pairs(mesh, &border, &shared);
    if pairs.is_empty() {
        return unchanged;
    }
    // The smaller root wins each union: each set's root is its lowest copy.
    let mut copies = UnionFind::new(mesh.vertices.len());
    for &((a, b), (c, d)) in &pairs {
        // a → b on one side runs along d → c on the other.
        copies.union(a, d);
        copies.union(b, c);
    }
    let kept: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&v| copies.find(v) == v)
        .collect();
    let mut new_index = vec![0; mesh.vertices.len()];
    for (new, &v) in kept.iter().enumerate() {
        new_index[v as usize] = new as u32;
    }
    let stitched = Mesh {
        vertices: kept.iter().map(|&v| mesh.vertices[v as usize]).collect(),
        faces: mesh
            .faces
            .iter()
            .map(|face| face.map(|v| new_index[copies.find(v) as usize]))
            .collect(),
    };
    Stitched {
        mesh: Cow::Owned(stitched),
        kept: Some(kept),
        edges: pairs.len(),
    }
}

/// The border vertices that share their position (bit for bit) with
/// another border vertex.
fn shared_positions(mesh: &Mesh, border: &HashMap<u32, Vec<u32>>) -> HashSet<u32> {
    let mut at: HashMap<[u64; 3], Vec<u32>> = HashMap::default();
    let ends = border
        .iter()
        .flat_map(|(&a, bs)| bs.iter().map(move |&b| (a, b)));
    for (a, b) in ends {
        for v in [a, b] {
            let copies = at.entry(key(mesh, v)).or_default();
            if !copies.contains(&v) {
                copies.push(v);
            }
        }
    }
    at.into_values()
        .filter(|copies| copies.len() > 1)
        .flatten()
        .collect()
}

fn key(mesh: &Mesh, v: u32) -> [u64; 3] {
    mesh.vertices[v as usize].map(f64::to_bits)
}

/// A directed edge between two vertices.
type Edge = (u32, u32);

/// The border edges to stitch, each pair once, in the order of the
/// first's vertices: both ends of each at shared positions, the two
/// running between the same positions opposite ways, and no other border
/// edge between those positions.
fn seam_edge_pairs(
    mesh: &Mesh,
    border: &HashMap<u32, Vec<u32>>,
    shared: &HashSet<u32>,
) -> Vec<(Edge, Edge)> {
    let mut between: HashMap<([u64; 3], [u64; 3]), Vec<Edge>> = HashMap::default();
    let mut starts: Vec<u32> = border.keys().copied().collect();
    starts.sort_unstable();
    for a in starts {
        for &b in &border[&a] {
            if shared.contains(&a) && shared.contains(&b) {
                between
                    .entry((key(mesh, a), key(mesh, b)))
                    .or_default()
                    .push((a, b));
            }
        }
    }
    let mut pairs = Vec::new();
    let mut sorted: Vec<_> = between.iter().collect();
    sorted.sort_unstable_by_key(|(_, edges)| edges[0]);
    for (&(pa, pb), edges) in sorted {
        let Some(back) = between.get(&(pb, pa)) else {
            continue;
        };
        // Each pair once: from the side whose first edge is the lower.
        if let ([one], [other]) = (edges.as_slice(), back.as_slice()) {
            if one < other {
                pairs.push((*one, *other));
            }
        }
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grid of `n` × `n` squares, two triangles each, counter-clockwise
    /// seen from +z; with `split`, the squares right of column `n / 2` get
    /// their own copies of the vertices on that column.
    pub(crate) fn grid(n: u32, split: bool) -> Mesh {
        let at = |i: u32, j: u32| i * (n + 1) + j;
        let mut vertices: Vec<[f64; 3]> = (0..=n)
            .flat_map(|i| (0..=n).map(move |j| [j as f64, i as f64, 0.0]))
            .collect();
        let middle = n / 2;
        let mut copy_of = HashMap::default();
        if split {
            for i in 0..=n {
                copy_of.insert(at(i, middle), vertices.len() as u32);
                vertices.push(vertices[at(i, middle) as usize]);
            }
        }
        let mut faces = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let right = j >= middle;
                let v = |i, j| {
                    let v = at(i, j);
                    match (right, copy_of.get(&v)) {
                        (true, Some(&c)) => c,
                        _ => v,
                    }
                };
                faces.push([v(i, j), v(i, j + 1), v(i + 1, j + 1)]);
                faces.push([v(i, j), v(i + 1, j + 1), v(i + 1, j)]);
            }
        }
        Mesh { vertices, faces }
    }

    #[test]
    fn a_seam_is_stitched_to_the_faces_of_the_whole_surface() {
        let split = grid(6, true);
        let stitched = stitch_seams(&split);
        assert_eq!(stitched.edges, 6);
        assert_eq!(*stitched.mesh, grid(6, false));
        let whole = grid(6, false).vertices.len() as u32;
        assert_eq!(stitched.kept, Some((0..whole).collect()));
        assert_eq!(stitched.mesh.boundary_loops().len(), 1);
    }

    #[test]
    fn a_surface_without_seams_is_borrowed() {
        let mesh = grid(5, false);
        let same = stitch_seams(&mesh);
        assert_eq!((same.edges, same.kept), (0, None));
        assert!(matches!(same.mesh, Cow::Borrowed(_)));
    }

    #[test]
    fn sides_running_the_same_way_are_not_stitched() {
        // The right side turned over: its seam edges run as the left's.
        let mut mesh = grid(4, true);
        let left = mesh.vertices.len() as u32 - 5;
        for face in mesh.faces.iter_mut() {
            if face
                .iter()
                .any(|&v| v >= left || mesh.vertices[v as usize][0] > 2.0)
            {
                face.swap(1, 2);
            }
        }
        let same = stitch_seams(&mesh);
        assert_eq!(same.edges, 0);
        assert_eq!(*same.mesh, mesh);
    }

    #[test]
    fn a_third_border_edge_between_the_same_positions_leaves_the_seam_open() {
        let mut mesh = grid(4, true);
        // A lone triangle on the seam's first edge, turned as the right side.
        let n = mesh.vertices.len() as u32;
        mesh.vertices
            .extend([[2.0, 0.0, 0.0], [2.0, 1.0, 0.0], [3.0, -1.0, 0.0]]);
        mesh.faces.push([n, n + 2, n + 1]);
        let stitched = stitch_seams(&mesh);
        assert_eq!(stitched.edges, 3);
        assert!(stitched.mesh.is_edge_manifold());
        assert_eq!(stitched.mesh.boundary_loops().len(), 2);
    }
}
