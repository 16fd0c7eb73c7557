//! Pinches a cut opens: vertices where the faces kept of a mesh touch in
//! more fans than the mesh's own faces did (infrastructure of meshtrim's
//! mesh stages; no section of the paper).
//!
//! Faces round a vertex form one *fan* when they connect through edges at
//! it. A vertex of a manifold surface has one fan; when a cut keeps faces
//! on two sides of a vertex and drops those between (two pieces that meet
//! at one vertex, a support test that drops the piece between them, a cut
//! that touches the zero level at a vertex), the kept surface pinches
//! there: PyMeshLab counts a non-manifold vertex, and a CAM system that
//! walks the border meets a vertex with four border edges. Each such
//! vertex keeps as many fans as the mesh had there: those of the largest
//! kept pieces (faces connected through edges), the larger fan among
//! fans of one piece; the faces of the others go (a piece loses the tip
//! that touched another, usually one to three faces). A pinch the input
//! had is the input's, and stays.

use super::topology::{EdgeRows, Topology};
use super::Mesh;
use crate::geom::UnionFind;
use crate::hash::HashMap;
use std::cell::OnceCell;

/// Labels the faces `star` round vertex `v` by fan: each gets the index
/// (in `star`) of a representative face of its fan.
pub(crate) fn fan_labels(faces: &[[u32; 3]], v: u32, star: &[u32]) -> Vec<u32> {
    let mut fans = UnionFind::new(star.len());
    let mut by_vertex: HashMap<u32, u32> = HashMap::default();
    for (x, &k) in star.iter().enumerate() {
        for &w in faces[k as usize].iter().filter(|&&w| w != v) {
            if let Some(&y) = by_vertex.get(&w) {
                fans.union(x as u32, y);
            } else {
                by_vertex.insert(w, x as u32);
            }
        }
    }
    (0..star.len() as u32).map(|x| fans.find(x)).collect()
}

/// How many fans the labels of [`fan_labels`] make.
fn fan_count(labels: &[u32]) -> usize {
    let mut roots = labels.to_vec();
    roots.sort_unstable();
    roots.dedup();
    roots.len()
}

/// Clears `keep` for the faces of `cut` that pinch the kept surface. `cut`
/// is `input` with faces split and some dropped: its vertices are the
/// input's, then new ones inside input edges (where the input has one
/// fan). At every vertex whose kept faces make more fans than the input
/// has there, the fans of the smaller pieces go (see the module doc),
/// until no vertex pinches that did not. Returns how many faces went.
pub(crate) fn open_new_pinches(input: &Mesh, cut: &Mesh, keep: &mut [bool]) -> usize {
    let mut suspects = kept_border_vertices(cut, keep);
    if suspects.is_empty() {
        return 0;
    }
    let topology = Topology::new(cut);
    // Built only where a vertex has several kept fans (a trim usually has
    // none), from `keep` as it is before any face goes.
    let input_topology = OnceCell::new();
    let piece_size = OnceCell::new();
    let mut dropped = 0;
    while !suspects.is_empty() {
        let mut gone = Vec::new();
        for &v in &suspects {
            let (kept, labels) = kept_fans(cut, &topology, keep, v);
            if fan_count(&labels) < 2 {
                continue;
            }
            // A vertex the cut made lies inside an input edge: one fan.
            let allowed = if (v as usize) < input.vertices.len() {
                let star = input_topology
                    .get_or_init(|| Topology::new(input))
                    .faces_of(v);
                fan_count(&fan_labels(&input.faces, v, star)).max(1)
            } else {
                1
            };
            let piece_size = piece_size.get_or_init(|| kept_piece_sizes(cut, keep));
            gone.extend(fans_beyond(&kept, &labels, piece_size, allowed));
        }
        gone.sort_unstable();
        gone.dedup();
        for &k in &gone {
            keep[k as usize] = false;
        }
        dropped += gone.len();
        suspects = gone.iter().flat_map(|&k| cut.faces[k as usize]).collect();
        suspects.sort_unstable();
        suspects.dedup();
    }
    dropped
}

/// The kept faces round `v` and their fan labels ([`fan_labels`]).
fn kept_fans(mesh: &Mesh, topology: &Topology, keep: &[bool], v: u32) -> (Vec<u32>, Vec<u32>) {
    let kept: Vec<u32> = topology
        .faces_of(v)
        .iter()
        .copied()
        .filter(|&k| keep[k as usize])
        .collect();
    let labels = fan_labels(&mesh.faces, v, &kept);
    (kept, labels)
}

/// For each face, the number of kept faces in its piece (kept faces
/// connected through edges); 0 for a face not kept.
fn kept_piece_sizes(mesh: &Mesh, keep: &[bool]) -> Vec<usize> {
    let mut pieces = UnionFind::new(mesh.faces.len());
    for pair in mesh.sorted_edges().windows(2) {
        let ((a, b, f), (c, d, g)) = (pair[0], pair[1]);
        if (a, b) == (c, d) && keep[f as usize] && keep[g as usize] {
            pieces.union(f, g);
        }
    }
    let root: Vec<u32> = (0..mesh.faces.len() as u32)
        .map(|k| pieces.find(k))
        .collect();
    let mut size = vec![0; mesh.faces.len()];
    for (k, &r) in root.iter().enumerate() {
        size[r as usize] += keep[k] as usize;
    }
    root.iter()
        .zip(keep)
        .map(|(&r, &kept)| if kept { size[r as usize] } else { 0 })
        .collect()
}

/// The vertices on the border of the kept faces (ascending): a vertex
/// inside them has one fan.
fn kept_border_vertices(mesh: &Mesh, keep: &[bool]) -> Vec<u32> {
    if keep.iter().all(|&k| k) {
        return EdgeRows::new(&mesh.faces).border_vertices();
    }
    let kept: Vec<[u32; 3]> = mesh
        .faces
        .iter()
        .zip(keep)
        .filter(|(_, &k)| k)
        .map(|(&f, _)| f)
        .collect();
    EdgeRows::new(&kept).border_vertices()
}

/// The faces `kept` (round one vertex, in fans by `labels`) of the fans
/// beyond the `allowed` number: those of the smaller pieces, then the
/// smaller fans.
fn fans_beyond(kept: &[u32], labels: &[u32], piece_size: &[usize], allowed: usize) -> Vec<u32> {
    // Per fan (by its representative): its piece's size and its own.
    let mut sizes: HashMap<u32, (usize, usize)> = HashMap::default();
    for (&k, &r) in kept.iter().zip(labels) {
        let entry = sizes.entry(r).or_insert((piece_size[k as usize], 0));
        entry.1 += 1;
    }
    if sizes.len() <= allowed {
        return Vec::new();
    }
    // Largest first; among equals the fan whose representative comes
    // first in the star.
    let mut fans: Vec<(u32, (usize, usize))> = sizes.into_iter().collect();
    fans.sort_unstable_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    let staying: Vec<u32> = fans[..allowed].iter().map(|&(r, _)| r).collect();
    kept.iter()
        .zip(labels)
        .filter(|(_, r)| !staying.contains(r))
        .map(|(&k, _)| k)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::tests::grid;

    fn fans_round(mesh: &Mesh, keep: &[bool], v: u32) -> usize {
        let kept: Vec<u32> = (0..mesh.faces.len() as u32)
            .filter(|&k| keep[k as usize] && mesh.faces[k as usize].contains(&v))
            .collect();
        fan_count(&fan_labels(&mesh.faces, v, &kept))
    }

    /// A straightforward count of the kept mesh's pinched vertices, the
    /// input's subtracted.
    fn new_pinches(mesh: &Mesh, keep: &[bool]) -> usize {
        let all = vec![true; mesh.faces.len()];
        (0..mesh.vertices.len() as u32)
            .filter(|&v| fans_round(mesh, keep, v) > fans_round(mesh, &all, v))
            .count()
    }

    #[test]
    fn two_pieces_meeting_at_a_vertex_keep_the_larger() {
        // A 4 × 4 grid of squares (two triangles each); keep the lower
        // left 2 × 2 block and the upper right one: they touch at the
        // centre vertex only.
        let mesh = grid(4);
        let centre = 2 * 5 + 2;
        let keep: Vec<bool> = (0..mesh.faces.len())
            .map(|k| {
                let (col, row) = ((k / 2) % 4, (k / 2) / 4);
                (col < 2 && row < 2) || (col >= 2 && row >= 2 && !(col == 3 && row == 3))
            })
            .collect();
        assert_eq!(new_pinches(&mesh, &keep), 1);
        let mut opened = keep.clone();
        let dropped = open_new_pinches(&mesh, &mesh, &mut opened);
        assert!(dropped > 0);
        assert_eq!(new_pinches(&mesh, &opened), 0);
        // The smaller piece (3 squares) lost its faces at the centre; the
        // larger (4 squares) is whole.
        let lower_left = (0..mesh.faces.len()).filter(|&k| keep[k] && (k / 2) % 4 < 2);
        assert!(lower_left.into_iter().all(|k| opened[k]));
        assert!(fans_round(&mesh, &opened, centre) <= 1);
    }

    #[test]
    fn random_subsets_are_left_without_new_pinches() {
        let mesh = grid(9);
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        for case in 0..200 {
            let share = 0.3 + 0.5 * (case % 5) as f64 / 4.0;
            let mut keep: Vec<bool> = (0..mesh.faces.len())
                .map(|_| {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    (state % 1000) as f64 / 1000.0 < share
                })
                .collect();
            let before: Vec<bool> = keep.clone();
            let dropped = open_new_pinches(&mesh, &mesh, &mut keep);
            assert_eq!(new_pinches(&mesh, &keep), 0, "case {case}");
            // Only kept faces went, and each went for a reason.
            assert_eq!(
                dropped,
                (0..keep.len()).filter(|&k| before[k] && !keep[k]).count()
            );
            assert!((0..keep.len()).all(|k| before[k] || !keep[k]));
            if new_pinches(&mesh, &before) == 0 {
                assert_eq!(dropped, 0, "case {case}");
            }
        }
    }
}
