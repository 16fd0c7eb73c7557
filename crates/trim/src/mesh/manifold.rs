//! Edges shared by more than two faces, and faces wound against their
//! neighbours, repaired: the mesh made edge-manifold and consistently
//! oriented, as MeshLab's "Repair non Manifold Edges" (by removing faces)
//! and "Re-Orient all faces coherently" make it (infrastructure of
//! meshtrim's mesh stages; no section of the paper).
//!
//! STL stores each triangle on its own, so software that stitches scanned
//! patches or exports a model triangle by triangle often leaves a few edges
//! with three or more faces (a fin, a strip laid twice) or faces turned the
//! wrong way; the cleanup needs every edge used at most twice and run
//! opposite ways by its two faces.
//!
//! 1. **Surfaces written twice.** A face with the corners of an earlier
//!    one in the opposite turn (an exporter that wrote a patch once each
//!    way, or a double-sided shell) goes, the first copy staying: the
//!    turn is settled in step 3. Left in, each such edge has four faces,
//!    and taking them smallest first leaves faces of both copies, then
//!    pockets of no volume (a double-sided scan loses every face).
//! 2. **Edges of more than two faces.** The faces on such edges are taken
//!    smallest first (by area, then index) and each is removed while one
//!    of its edges still has more than two faces: MeshLab's rule (vcglib's
//!    `RemoveNonManifoldFace`), which keeps the larger faces, usually the
//!    surface's own, and drops what was stitched onto them.
//! 3. **Orientation.** Each piece (faces joined through edges of two faces)
//!    is walked from its lowest face, breadth first, and every face is
//!    turned to agree with the face it was reached from. A piece then keeps
//!    the turn most of its area had: where a few faces were wound the wrong
//!    way, those are the ones turned.
//! 4. **One-sided pieces.** Where a face reached another way still
//!    disagrees (a piece with one side, as a Möbius strip), the smaller face
//!    of that edge is removed, which leaves every other edge agreeing.
//!
//! Vertices stay as they are (and in number), so whatever was computed per
//! vertex still applies.

use std::collections::VecDeque;

use super::Mesh;
use crate::hash::{HashMap, HashSet};

/// What [`CleanOptions::repair`](crate::CleanOptions::repair) changed to
/// make a mesh edge-manifold and consistently oriented.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ManifoldRepair {
    /// Faces removed for repeating an earlier face's corners in the
    /// opposite turn (a surface written twice, once each way).
    pub double_sided_faces_removed: usize,
    /// Faces removed from edges shared by more than two faces.
    pub crowded_faces_removed: usize,
    /// Faces turned over to agree with their neighbours.
    pub faces_flipped: usize,
    /// Faces removed where no turn agrees with every neighbour.
    pub one_sided_faces_removed: usize,
}

impl ManifoldRepair {
    /// Faces removed or turned in all.
    pub fn changed(&self) -> usize {
        self.double_sided_faces_removed
            + self.crowded_faces_removed
            + self.faces_flipped
            + self.one_sided_faces_removed
    }
}

/// `mesh` (whose faces each name three vertices) made edge-manifold and
/// consistently oriented: see the module doc.
pub(crate) fn make_manifold(mesh: &Mesh) -> (Mesh, ManifoldRepair) {
    let mut out = mesh.clone();
    let mut keep = vec![true; out.faces.len()];
    let double_sided = remove_second_copies(&out, &mut keep);
    out.retain_faces(&keep);
    let mut keep = vec![true; out.faces.len()];
    let crowded = remove_faces_on_crowded_edges(&out, &mut keep);
    out.retain_faces(&keep);
    let orientation = orient(&out);
    let mut keep = vec![true; out.faces.len()];
    for &f in &orientation.one_sided {
        keep[f as usize] = false;
    }
    let mut flipped = 0;
    for (face, (&turn, &kept)) in out.faces.iter_mut().zip(orientation.turn.iter().zip(&keep)) {
        if turn && kept {
            face.swap(1, 2);
            flipped += 1;
        }
    }
    out.retain_faces(&keep);
    let repair = ManifoldRepair {
        double_sided_faces_removed: double_sided,
        crowded_faces_removed: crowded,
        faces_flipped: flipped,
        one_sided_faces_removed: orientation.one_sided.len(),
    };
    (out, repair)
}

/// Step 1: clears `keep` for every face with the corners of an earlier
/// one (in either turn); returns how many.
fn remove_second_copies(mesh: &Mesh, keep: &mut [bool]) -> usize {
    let mut seen = HashSet::default();
    let mut removed = 0;
    for (f, face) in mesh.faces.iter().enumerate() {
        let mut corners = *face;
        corners.sort_unstable();
        if !seen.insert(corners) {
            keep[f] = false;
            removed += 1;
        }
    }
    removed
}

/// Step 2: clears `keep` for faces taken off edges of more than two faces,
/// smallest first; returns how many.
fn remove_faces_on_crowded_edges(mesh: &Mesh, keep: &mut [bool]) -> usize {
    let mut uses: HashMap<(u32, u32), usize> = HashMap::default();
    let mut candidates = Vec::new();
    for run in mesh
        .sorted_edges()
        .chunk_by(|x, y| (x.0, x.1) == (y.0, y.1))
    {
        if run.len() > 2 {
            uses.insert((run[0].0, run[0].1), run.len());
            candidates.extend(run.iter().map(|e| e.2));
        }
    }
    candidates.sort_unstable();
    candidates.dedup();
    let area: HashMap<u32, f64> = candidates
        .iter()
        .map(|&f| (f, mesh.face_area(f as usize)))
        .collect();
    candidates.sort_by(|f, g| area[f].total_cmp(&area[g]).then(f.cmp(g)));
    let mut removed = 0;
    for f in candidates {
        let edges = undirected_edges(mesh.faces[f as usize]);
        if edges.iter().any(|e| uses.get(e).is_some_and(|&n| n > 2)) {
            keep[f as usize] = false;
            removed += 1;
            for e in &edges {
                if let Some(n) = uses.get_mut(e) {
                    *n -= 1;
                }
            }
        }
    }
    removed
}

fn undirected_edges(face: [u32; 3]) -> [(u32, u32); 3] {
    [0, 1, 2].map(|k| {
        let (a, b) = (face[k], face[(k + 1) % 3]);
        (a.min(b), a.max(b))
    })
}

/// Steps 3 and 4: which faces to turn, and which to remove.
struct Orientation {
    turn: Vec<bool>,
    one_sided: Vec<u32>,
}

/// No neighbour across an edge (a border, or an edge of more faces).
const NONE: u32 = u32::MAX;

/// Turns every piece's faces to agree across its edges of two faces,
/// keeping the turn most of the piece's area had.
fn orient(mesh: &Mesh) -> Orientation {
    let neighbours = neighbours_across_edges(mesh);
    let n = mesh.faces.len();
    let mut turn = vec![false; n];
    let mut reached = vec![false; n];
    let mut disagreeing = Vec::new();
    for root in 0..n {
        if reached[root] {
            continue;
        }
        reached[root] = true;
        let mut piece = vec![root];
        let mut queue = VecDeque::from([root]);
        while let Some(f) = queue.pop_front() {
            for &(g, same_way) in neighbours[f].iter().filter(|(g, _)| *g != NONE) {
                let g = g as usize;
                // Two faces agree when they run their edge opposite ways.
                let wanted = turn[f] ^ same_way;
                if !reached[g] {
                    reached[g] = true;
                    turn[g] = wanted;
                    piece.push(g);
                    queue.push_back(g);
                } else if turn[g] != wanted && f < g {
                    disagreeing.push((f, g));
                }
            }
        }
        keep_the_turn_of_most_area(mesh, &piece, &mut turn);
    }
    let mut gone = vec![false; n];
    let mut one_sided = Vec::new();
    for (f, g) in disagreeing {
        if gone[f] || gone[g] {
            continue;
        }
        let smaller = if mesh.face_area(g) < mesh.face_area(f) {
            g
        } else {
            f
        };
        gone[smaller] = true;
        one_sided.push(smaller as u32);
    }
    one_sided.sort_unstable();
    Orientation { turn, one_sided }
}

/// Turns the whole piece back where its turned faces hold more than half
/// its area.
fn keep_the_turn_of_most_area(mesh: &Mesh, piece: &[usize], turn: &mut [bool]) {
    let (mut turned, mut total) = (0.0, 0.0);
    for &f in piece {
        let area = mesh.face_area(f);
        total += area;
        if turn[f] {
            turned += area;
        }
    }
    if turned > 0.5 * total {
        for &f in piece {
            turn[f] = !turn[f];
        }
    }
}

/// For each face, the face across each of its edges that exactly two
/// faces use, and whether the two run that edge the same way.
fn neighbours_across_edges(mesh: &Mesh) -> Vec<[(u32, bool); 3]> {
    let mut neighbours = vec![[(NONE, false); 3]; mesh.faces.len()];
    for run in mesh
        .sorted_edges()
        .chunk_by(|x, y| (x.0, x.1) == (y.0, y.1))
    {
        let &[(a, b, f), (_, _, g)] = run else {
            continue;
        };
        if f == g {
            continue;
        }
        let same_way = runs_forward(mesh.faces[f as usize], a, b)
            == runs_forward(mesh.faces[g as usize], a, b);
        for (x, y) in [(f, g), (g, f)] {
            if let Some(slot) = neighbours[x as usize].iter_mut().find(|s| s.0 == NONE) {
                *slot = (y, same_way);
            }
        }
    }
    neighbours
}

/// Whether `face` runs its edge {a, b} from a to b.
fn runs_forward(face: [u32; 3], a: u32, b: u32) -> bool {
    (0..3).any(|k| (face[k], face[(k + 1) % 3]) == (a, b))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::tests::grid;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn a_fin_on_an_edge_is_removed_and_the_surface_kept() {
        let mut mesh = grid(4);
        // A small face standing on an interior edge of the grid.
        let (a, b) = (mesh.faces[10][0], mesh.faces[10][1]);
        mesh.vertices.push([0.5, 0.5, 0.1]);
        let tip = mesh.vertices.len() as u32 - 1;
        mesh.vertices[tip as usize] = {
            let (p, q) = (mesh.vertices[a as usize], mesh.vertices[b as usize]);
            [(p[0] + q[0]) / 2.0, (p[1] + q[1]) / 2.0, 0.1]
        };
        mesh.faces.push([a, b, tip]);
        assert!(mesh.check_manifold().is_err());
        let (out, repair) = make_manifold(&mesh);
        assert_eq!(repair.crowded_faces_removed, 1);
        assert_eq!(repair.faces_flipped + repair.one_sided_faces_removed, 0);
        assert_eq!(out.faces, grid(4).faces);
        assert_eq!(out.vertices.len(), mesh.vertices.len());
    }

    #[test]
    fn a_surface_written_twice_keeps_one_copy() {
        // Every face of a grid again the other way: a double-sided shell.
        let original = grid(6);
        let mut mesh = original.clone();
        mesh.faces
            .extend(original.faces.iter().map(|f| [f[0], f[2], f[1]]));
        assert!(mesh.check_manifold().is_err());
        let (out, repair) = make_manifold(&mesh);
        assert_eq!(repair.double_sided_faces_removed, original.faces.len());
        assert_eq!(repair.changed(), original.faces.len(), "{repair:?}");
        assert_eq!(out.faces, original.faces);
    }

    #[test]
    fn faces_wound_the_wrong_way_are_turned_back() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for case in 0..50 {
            let original = grid(8);
            let mut mesh = original.clone();
            // Fewer than half the faces (and of the area): the rest wins.
            let wrong: Vec<usize> = (0..mesh.faces.len())
                .filter(|_| rng.random_range(0.0..1.0) < 0.3)
                .collect();
            for &f in &wrong {
                mesh.faces[f].swap(0, 1);
            }
            let (out, repair) = make_manifold(&mesh);
            assert_eq!(repair.faces_flipped, wrong.len(), "{case}");
            assert_eq!(
                repair.crowded_faces_removed + repair.one_sided_faces_removed,
                0
            );
            out.check_manifold().unwrap();
            // The same faces, each turned back (its corners in another order).
            for (f, (got, want)) in out.faces.iter().zip(&original.faces).enumerate() {
                assert_eq!(
                    crate::mesh::lowest_first(*got),
                    crate::mesh::lowest_first(*want),
                    "{case}: face {f}"
                );
            }
        }
    }

    #[test]
    fn a_one_sided_strip_loses_a_face_and_is_oriented() {
        // A Möbius strip: a ring of 8 quads whose last one joins the first
        // with a half twist.
        let n = 8u32;
        let vertices: Vec<_> = (0..2 * n)
            .map(|i| {
                let t = (i % n) as f64 / n as f64 * std::f64::consts::TAU;
                let r = 2.0 + if i < n { -0.5 } else { 0.5 } * (t / 2.0).cos();
                let z = if i < n { -0.5 } else { 0.5 } * (t / 2.0).sin();
                [r * t.cos(), r * t.sin(), z]
            })
            .collect();
        let mut faces = Vec::new();
        for i in 0..n {
            let (a, b, c, d) = if i + 1 < n {
                (i, i + 1, n + i + 1, n + i)
            } else {
                (i, n, 0, n + i) // the twist: inner joins outer
            };
            faces.push([a, b, c]);
            faces.push([a, c, d]);
        }
        let mesh = Mesh { vertices, faces };
        let (out, repair) = make_manifold(&mesh);
        assert_eq!(repair.one_sided_faces_removed, 1, "{repair:?}");
        out.check_manifold().unwrap();
    }

    #[test]
    fn random_soups_come_out_manifold_and_oriented() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut repaired = 0;
        for case in 0..2000 {
            let vertices: Vec<_> = (0..7)
                .map(|_| [0; 3].map(|_| rng.random_range(-1.0..1.0)))
                .collect();
            let faces: Vec<[u32; 3]> = (0..rng.random_range(1..12))
                .map(|_| loop {
                    let f = [0; 3].map(|_| rng.random_range(0..7u32));
                    if crate::mesh::topology::distinct(f) {
                        break f;
                    }
                })
                .collect();
            let mesh = Mesh { vertices, faces };
            let (out, repair) = make_manifold(&mesh);
            out.check_manifold()
                .unwrap_or_else(|e| panic!("{case}: {e}: {mesh:?} -> {out:?}"));
            // Only removals and turns: every face out is a face in, maybe turned.
            let faces_in: Vec<[u32; 3]> = mesh.faces.iter().map(|&f| sorted(f)).collect();
            assert!(
                out.faces.iter().all(|&f| faces_in.contains(&sorted(f))),
                "{case}"
            );
            let removed = repair.double_sided_faces_removed
                + repair.crowded_faces_removed
                + repair.one_sided_faces_removed;
            assert_eq!(out.faces.len() + removed, mesh.faces.len(), "{case}");
            repaired += usize::from(repair.changed() > 0);
        }
        assert!(repaired > 500, "{repaired}");
    }

    fn sorted(mut f: [u32; 3]) -> [u32; 3] {
        f.sort_unstable();
        f
    }
}
