//! The cut (steps 3 and 4): every face crossed by the field's zero level
//! split exactly along it, the faces beyond dropped, and what the cloud's
//! reach cuts off.

use super::*;

/// A mesh cut along the zero level of the field: input vertices first,
/// then one new vertex per crossed edge, shared by all faces of that edge.
pub(super) struct Cut {
    pub(super) mesh: Mesh,
    /// The input face of each face.
    pub(super) origin: Vec<u32>,
    /// Whether each face lies beyond the walls (f ≥ 0) rather than inside
    /// (f ≤ 0).
    pub(super) beyond: Vec<bool>,
    /// Input faces split by the cut.
    pub(super) split: usize,
}

impl Cut {
    pub(super) fn push(&mut self, face: [u32; 3], origin: usize, beyond: bool) {
        self.mesh.faces.push(face);
        self.origin.push(origin as u32);
        self.beyond.push(beyond);
    }
}

/// Splits the faces crossed by the zero level of `field` into their parts
/// on either side; faces on one side are copied whole.
pub(super) fn cut_both_sides(mesh: &Mesh, field: &[f64]) -> Cut {
    let capacity = mesh.faces.len();
    let mut cut = Cut {
        mesh: Mesh {
            vertices: mesh.vertices.clone(),
            faces: Vec::with_capacity(capacity),
        },
        origin: Vec::with_capacity(capacity),
        beyond: Vec::with_capacity(capacity),
        split: 0,
    };
    let mut crossing: HashMap<(u32, u32), u32> = HashMap::default();
    for (index, face) in mesh.faces.iter().enumerate() {
        let f = face.map(|v| field[v as usize]);
        if f.iter().all(|&x| x <= 0.0) {
            cut.push(*face, index, false);
            continue;
        }
        if f.iter().all(|&x| x >= 0.0) {
            cut.push(*face, index, true);
            continue;
        }
        cut.split += 1;
        // Each side's part: its own corners and the crossings, in the
        // face's vertex order.
        let (mut inside, mut beyond) = (Vec::with_capacity(4), Vec::with_capacity(4));
        for k in 0..3 {
            let (a, b) = (face[k], face[(k + 1) % 3]);
            let (fa, fb) = (f[k], f[(k + 1) % 3]);
            if fa <= 0.0 {
                inside.push(a);
            }
            if fa >= 0.0 {
                beyond.push(a);
            }
            if (fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0) {
                let key = (a.min(b), a.max(b));
                let v = *crossing.entry(key).or_insert_with(|| {
                    let (p, q, fp, fq) = if a < b {
                        (a, b, fa, fb)
                    } else {
                        (b, a, fb, fa)
                    };
                    let t = fp / (fp - fq);
                    let (pp, pq) = (mesh.vertices[p as usize], mesh.vertices[q as usize]);
                    cut.mesh
                        .vertices
                        .push([0, 1, 2].map(|c| pp[c] + t * (pq[c] - pp[c])));
                    (cut.mesh.vertices.len() - 1) as u32
                });
                inside.push(v);
                beyond.push(v);
            }
        }
        for (part, side) in [(inside, false), (beyond, true)] {
            for k in 1..part.len().saturating_sub(1) {
                cut.push([part[0], part[k], part[k + 1]], index, side);
            }
        }
    }
    cut
}

/// What the cut along the cloud's reach removed.
pub(super) struct OutOfReach {
    /// Faces of the cut mesh dropped.
    pub(super) faces: usize,
    /// Vertices snapped onto the reach.
    pub(super) snapped: usize,
}

/// Step 4 of the module doc: cuts `cut` again along the cloud's reach and
/// drops the faces beyond it, except spots smaller than a disc of radius β
/// (their largest β), which the cloud cannot resolve: BPD finds no hole
/// smaller than that, and the Poisson surface pokes that far out of reach
/// in little domes over a scan's crevices. Faces and their origins are
/// those of `cut`'s input mesh.
pub(super) fn within_reach(cut: Cut, reach: &Reach, snap: f64) -> (Cut, OutOfReach) {
    let excess: Vec<(f64, f64)> = cut
        .mesh
        .vertices
        .par_iter()
        .map(|&v| reach.excess(v))
        .collect();
    let (field, snapped_count) = snapped_field(&excess, snap);
    // Where every loop closed, nothing is out of reach and the cut below
    // would copy `cut` face for face: skip it.
    if field.iter().all(|&g| g <= 0.0) {
        let dropped = OutOfReach {
            faces: 0,
            snapped: snapped_count,
        };
        return (cut, dropped);
    }
    let beta: Vec<f64> = excess.iter().map(|&(_, beta)| beta).collect();
    let Cut {
        mesh: mut second,
        origin: part_of,
        beyond: mut out_of_reach,
        ..
    } = cut_both_sides(&cut.mesh, &field);
    keep_unresolved_spots(&second, &beta, &mut out_of_reach);
    let in_reach: Vec<bool> = out_of_reach.iter().map(|&o| !o).collect();
    second.retain_faces(&in_reach);
    let (origin, beyond) = part_of
        .iter()
        .zip(&in_reach)
        .filter(|(_, &kept)| kept)
        .map(|(&f, _)| (cut.origin[f as usize], cut.beyond[f as usize]))
        .unzip();
    let dropped = OutOfReach {
        faces: out_of_reach.iter().filter(|&&o| o).count(),
        snapped: snapped_count,
    };
    let within = Cut {
        mesh: second,
        origin,
        beyond,
        split: cut.split,
    };
    (within, dropped)
}

/// Clears `out_of_reach` on each connected spot of such faces whose area
/// is below π β², β the largest at its vertices (`beta`, per vertex of
/// `mesh`'s vertices before the cut: each such face has one). Only the
/// faces out of reach are joined into spots.
pub(super) fn keep_unresolved_spots(mesh: &Mesh, beta: &[f64], out_of_reach: &mut [bool]) {
    let spot_faces: Vec<usize> = (0..mesh.faces.len()).filter(|&f| out_of_reach[f]).collect();
    let faces: Vec<[u32; 3]> = spot_faces.iter().map(|&f| mesh.faces[f]).collect();
    let spot = face_pieces(&faces, &vec![false; faces.len()]);
    let spots = spot.iter().map(|&p| p as usize + 1).max().unwrap_or(0);
    let mut area = vec![0.0f64; spots];
    let mut largest_beta = vec![0.0f64; spots];
    for (&f, &p) in spot_faces.iter().zip(&spot) {
        let p = p as usize;
        area[p] += mesh.face_area(f);
        for &v in &mesh.faces[f] {
            let b = beta.get(v as usize).copied().unwrap_or(0.0);
            largest_beta[p] = largest_beta[p].max(b);
        }
    }
    for (&f, &p) in spot_faces.iter().zip(&spot) {
        let p = p as usize;
        if area[p] < std::f64::consts::PI * largest_beta[p] * largest_beta[p] {
            out_of_reach[f] = false;
        }
    }
}
