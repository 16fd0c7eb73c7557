//! The support test (step 5): pieces of the cut mesh kept when enough
//! cloud points project onto them, the paper's "regions not supported by
//! the cloud" removed.

use super::*;

/// Which faces of the cut mesh to keep: those of the pieces the cloud
/// supports.
pub(super) struct Support {
    /// Per face of the cut mesh.
    pub(super) keep: Vec<bool>,
    /// Pieces dropped, on either side of the walls.
    pub(super) dropped: usize,
    /// Pieces beyond the walls kept.
    pub(super) restored: usize,
}

/// Which faces of `cut` lie in a piece the cloud supports (see the module
/// doc), or `None` when no piece is. Pieces never cross the walls:
/// `beyond` says each face's side.
pub(super) fn supported_faces(
    cut: &Mesh,
    beyond: &[bool],
    cloud: &[Point3],
    beta: &[f64],
    support: f64,
) -> Option<Support> {
    if cut.faces.is_empty() {
        return None;
    }
    let piece = face_pieces(&cut.faces, beyond);
    let pieces = piece.iter().map(|&p| p as usize + 1).max().unwrap_or(0);
    let projector = FaceIndex::new(cut);
    let of_piece = projector.labels(&piece);
    let mut hits = vec![0usize; pieces];
    let mut cell_area = vec![0.0f64; pieces];
    // Each projection is independent: parallel, then summed in cloud order
    // so the sums do not depend on the thread count. Only the piece a
    // point lands on counts, not the face.
    let landed: Vec<Option<u32>> = query_in_spatial_order(cloud, Scratch::default, |s, i| {
        projector.nearest_label(cloud[i], 2.0 * beta[i], &of_piece, s)
    });
    for (landed_on, &b) in landed.iter().zip(beta) {
        if let Some(k) = landed_on {
            let k = *k as usize;
            hits[k] += 1;
            cell_area[k] += 0.75f64.sqrt() * b * b;
        }
    }
    let mut area = vec![0.0f64; pieces];
    for f in 0..cut.faces.len() {
        area[piece[f] as usize] += cut.face_area(f);
    }
    // Points expected on a piece: its area over the mean cell area of the
    // points that landed on it.
    let keep: Vec<bool> = (0..pieces)
        .map(|k| {
            hits[k] > 0 && hits[k] as f64 >= support * area[k] / (cell_area[k] / hits[k] as f64)
        })
        .collect();
    if !keep.iter().any(|&k| k) {
        return None;
    }
    let mut piece_beyond = vec![false; pieces];
    for (&p, &b) in piece.iter().zip(beyond) {
        piece_beyond[p as usize] = b;
    }
    Some(Support {
        keep: piece.iter().map(|&p| keep[p as usize]).collect(),
        dropped: keep.iter().filter(|&&k| !k).count(),
        restored: (0..pieces).filter(|&k| keep[k] && piece_beyond[k]).count(),
    })
}

/// Connected pieces of faces sharing an edge; piece ids by first face.
///
/// The faces' edges are sorted rather than hashed ([`sorted_edges_of`]);
/// the faces on one edge are joined to its first.
pub(super) fn face_pieces(faces: &[[u32; 3]], beyond: &[bool]) -> Vec<u32> {
    let n = faces.len();
    let edges = sorted_edges_of(faces);
    let mut sets = UnionFind::new(n);
    for same_edge in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        for side in [false, true] {
            let mut on_side = same_edge.iter().filter(|e| beyond[e.2 as usize] == side);
            if let Some(first) = on_side.next() {
                for other in on_side {
                    sets.union(first.2, other.2);
                }
            }
        }
    }
    piece_ids(&mut sets, n)
}

/// [`face_pieces`] with a hash map of edges, the plain way; the reference
/// for tests.
#[cfg(test)]
pub(super) fn face_pieces_reference(faces: &[[u32; 3]], beyond: &[bool]) -> Vec<u32> {
    let n = faces.len();
    let mut sets = UnionFind::new(n);
    let mut first_on_edge: HashMap<(u32, u32, bool), u32> = HashMap::default();
    for (f, face) in faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (face[k], face[(k + 1) % 3]);
            match first_on_edge.entry((a.min(b), a.max(b), beyond[f])) {
                std::collections::hash_map::Entry::Occupied(e) => {
                    sets.union(*e.get(), f as u32);
                }
                std::collections::hash_map::Entry::Vacant(e) => {
                    e.insert(f as u32);
                }
            }
        }
    }
    piece_ids(&mut sets, n)
}

/// Piece ids 0, 1, … in the order of each set's first member.
pub(super) fn piece_ids(sets: &mut UnionFind, n: usize) -> Vec<u32> {
    let mut id = vec![u32::MAX; n];
    let mut next = 0;
    (0..n)
        .map(|f| {
            let r = sets.find(f as u32) as usize;
            if id[r] == u32::MAX {
                id[r] = next;
                next += 1;
            }
            id[r]
        })
        .collect()
}
