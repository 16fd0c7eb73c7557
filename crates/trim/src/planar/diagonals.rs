//! Canonical diagonals for the co-circular quads of a Delaunay
//! triangulation (meshtrim's addition to the Delaunay path).
//!
//! Four points on one circle can be triangulated either way, and both are
//! Delaunay. Quantised clouds (coordinates on a lattice, as scanners write
//! them) are full of such quads: the lattice's rectangles. Which diagonal a
//! triangulation takes then depends on the last bits of the coordinates,
//! which moving the cloud rounds differently. This pass makes the choice
//! from the points' ids instead: every interior edge that is not a
//! constraint, whose two triangles form a quad co-circular within
//! [`COCIRCULAR`] (relative), is flipped if needed so that the diagonal
//! holds the quad's lowest id. A co-circular polygon of more points ends
//! as the fan from its lowest id, whatever the order of the flips.

use crate::hash::{HashMap, HashSet};

use crate::geom::orientation;

/// Quads whose in-circle determinant is below this, relative to the
/// fourth power of their size, count as co-circular. Far above the rounding
/// of coordinates 10⁵ spacings from the origin (about 10⁻¹⁰ relative),
/// far below the jitter of real samplings.
pub(crate) const COCIRCULAR: f64 = 1e-9;

/// Flips the diagonals of co-circular quads of `faces` (counter-clockwise
/// triangles over `positions`, indexed by vertex id) towards the quad's
/// lowest id, never across an edge of `constraints` (pairs, smaller id
/// first). Returns the number of flips.
pub fn canonical_diagonals(
    positions: &HashMap<u32, [f64; 2]>,
    faces: &mut [[u32; 3]],
    constraints: &HashSet<[u32; 2]>,
) -> usize {
    // Directed edge → the face on its left.
    let mut left: HashMap<[u32; 2], usize> =
        HashMap::with_capacity_and_hasher(3 * faces.len(), Default::default());
    for (f, face) in faces.iter().enumerate() {
        for k in 0..3 {
            left.insert([face[k], face[(k + 1) % 3]], f);
        }
    }
    let mut pending: Vec<[u32; 2]> = left.keys().copied().filter(|e| e[0] < e[1]).collect();
    pending.sort_unstable();
    pending.reverse();
    // Each flip adds an edge at a quad's lowest id; the cap only guards
    // against a cycle that the rule cannot make.
    let mut budget = 4 * faces.len() + 16;
    let mut flips = 0;
    while let Some([a, b]) = pending.pop() {
        if budget == 0 {
            break;
        }
        if constraints.contains(&[a, b]) {
            continue;
        }
        let (Some(&f1), Some(&f2)) = (left.get(&[a, b]), left.get(&[b, a])) else {
            continue;
        };
        let c = third(&faces[f1], a, b);
        let d = third(&faces[f2], b, a);
        let lowest = a.min(b).min(c).min(d);
        if lowest == a || lowest == b {
            continue;
        }
        let [pa, pb, pc, pd] = [a, b, c, d].map(|v| positions[&v]);
        if !cocircular(pa, pb, pc, pd) || !convex(pa, pd, pb, pc) {
            continue;
        }
        // (a, b, c) and (b, a, d) become (a, d, c) and (d, b, c), both
        // counter-clockwise: the quad runs a, d, b, c.
        faces[f1] = [a, d, c];
        faces[f2] = [d, b, c];
        left.remove(&[a, b]);
        left.remove(&[b, a]);
        for (edge, face) in [
            ([a, d], f1),
            ([d, c], f1),
            ([c, a], f1),
            ([d, b], f2),
            ([b, c], f2),
            ([c, d], f2),
        ] {
            left.insert(edge, face);
        }
        for [p, q] in [[a, d], [d, b], [b, c], [c, a]] {
            pending.push([p.min(q), p.max(q)]);
        }
        flips += 1;
        budget -= 1;
    }
    flips
}

/// The vertex of `face` other than `a` and `b`.
fn third(face: &[u32; 3], a: u32, b: u32) -> u32 {
    face.iter()
        .copied()
        .find(|&v| v != a && v != b)
        .unwrap_or(a)
}

/// Are the four points on one circle, within [`COCIRCULAR`]?
pub(crate) fn cocircular(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    // Relative to d, which keeps the determinant's terms small.
    let [u, v, w] = [a, b, c].map(|p| [p[0] - d[0], p[1] - d[1]]);
    let lift = |p: [f64; 2]| p[0] * p[0] + p[1] * p[1];
    let det = u[0] * (v[1] * lift(w) - lift(v) * w[1]) - u[1] * (v[0] * lift(w) - lift(v) * w[0])
        + lift(u) * (v[0] * w[1] - v[1] * w[0]);
    let size = lift(u).max(lift(v)).max(lift(w));
    det.abs() <= COCIRCULAR * size * size
}

/// Is the quad p, q, r, s (in this order) strictly convex and
/// counter-clockwise?
fn convex(p: [f64; 2], q: [f64; 2], r: [f64; 2], s: [f64; 2]) -> bool {
    orientation(p, q, r) > 0.0
        && orientation(q, r, s) > 0.0
        && orientation(r, s, p) > 0.0
        && orientation(s, p, q) > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A w × h lattice of unit squares, each split along the diagonal that
    /// `pick` chooses; ids row by row.
    fn lattice(
        w: u32,
        h: u32,
        pick: impl Fn(u32, u32) -> bool,
    ) -> (HashMap<u32, [f64; 2]>, Vec<[u32; 3]>) {
        let id = |i: u32, j: u32| j * (w + 1) + i;
        let positions = (0..=h)
            .flat_map(|j| (0..=w).map(move |i| (id(i, j), [f64::from(i), f64::from(j)])))
            .collect();
        let mut faces = Vec::new();
        for j in 0..h {
            for i in 0..w {
                let [p, q, r, s] = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
                if pick(i, j) {
                    faces.extend([[p, q, r], [p, r, s]]);
                } else {
                    faces.extend([[p, q, s], [q, r, s]]);
                }
            }
        }
        (positions, faces)
    }

    fn canonical(mut faces: Vec<[u32; 3]>) -> Vec<[u32; 3]> {
        for f in faces.iter_mut() {
            *f = crate::mesh::lowest_first(*f);
        }
        faces.sort_unstable();
        faces
    }

    #[test]
    fn any_diagonals_of_a_lattice_end_the_same() {
        let (positions, mut a) = lattice(6, 4, |i, j| (i + j) % 2 == 0);
        let (_, mut b) = lattice(6, 4, |i, j| (i * 7 + j * 3) % 5 < 2);
        let none = HashSet::default();
        canonical_diagonals(&positions, &mut a, &none);
        canonical_diagonals(&positions, &mut b, &none);
        assert_eq!(canonical(a.clone()), canonical(b));
        // Every face stays counter-clockwise.
        for f in &a {
            let [x, y, z] = f.map(|v| positions[&v]);
            assert!(orientation(x, y, z) > 0.0, "{f:?} is not counter-clockwise");
        }
    }

    #[test]
    fn a_cocircular_polygon_ends_as_the_fan_from_its_lowest_id() {
        // Eight points on a circle, ids shuffled round it, triangulated as
        // a zig-zag strip.
        let ids = [5u32, 2, 7, 0, 4, 1, 6, 3];
        let positions: HashMap<u32, [f64; 2]> = ids
            .iter()
            .enumerate()
            .map(|(k, &id)| {
                let a = std::f64::consts::TAU * k as f64 / 8.0;
                (id, [10.0 * a.cos(), 10.0 * a.sin()])
            })
            .collect();
        // Counter-clockwise strip over positions 0..8 round the circle.
        let strip = [
            [0, 1, 7],
            [1, 6, 7],
            [1, 2, 6],
            [2, 5, 6],
            [2, 3, 5],
            [3, 4, 5],
        ];
        let mut faces: Vec<[u32; 3]> = strip.iter().map(|t| t.map(|k| ids[k])).collect();
        canonical_diagonals(&positions, &mut faces, &HashSet::default());
        assert_eq!(faces.len(), 6);
        assert!(faces.iter().all(|f| f.contains(&0)), "{faces:?}");
    }

    #[test]
    fn constraints_and_non_cocircular_quads_stay() {
        let (mut positions, faces) = lattice(1, 1, |_, _| false);
        // The diagonal 1–2 does not hold the lowest id 0: a flip, unless it
        // is a constraint or the quad is not co-circular.
        let mut flipped = faces.clone();
        assert_eq!(
            canonical_diagonals(&positions, &mut flipped, &HashSet::default()),
            1
        );
        let mut kept = faces.clone();
        let constraint: HashSet<[u32; 2]> = [[1, 2]].into_iter().collect();
        assert_eq!(canonical_diagonals(&positions, &mut kept, &constraint), 0);
        assert_eq!(kept, faces);
        positions.insert(3, [1.0, 1.001]);
        let mut kept = faces.clone();
        assert_eq!(
            canonical_diagonals(&positions, &mut kept, &HashSet::default()),
            0
        );
    }
}
