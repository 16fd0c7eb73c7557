//! Smoothed loops as closed polylines, and their repair where they cross
//! themselves in a projection.

use super::SegmentGrid;
use crate::edges::cluster::MIN_LOOP_POINTS;
use crate::edges::Loop;
use crate::geom::{lerp, lerp2, Point3};
use crate::resolution::PointResolution;

/// Consecutive vertices of a ring closer than this many β in the
/// projection are merged: they would make zero-length constraints.
const MERGE: f64 = 1e-6;

/// Why smoothed loops cannot bound a triangulation in a projection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Tangle {
    /// Ring `index` crosses itself, and the repair would drop `dropped` of
    /// its `vertices` vertices.
    SelfCrossing {
        index: usize,
        vertices: usize,
        dropped: usize,
    },
    /// Rings `a` and `b` (a < b) cross or touch.
    Crossing { a: usize, b: usize },
}

/// One smoothed loop as a closed polyline.
#[derive(Debug, Clone, Default)]
pub(crate) struct Ring {
    pub(crate) p3: Vec<Point3>,
    pub(crate) p2: Vec<[f64; 2]>,
    /// The boundary point each vertex was smoothed from.
    pub(crate) reference: Vec<u32>,
    pub(crate) beta: Vec<f64>,
}

impl Ring {
    pub(crate) fn from_loop(lp: &Loop, beta: &(impl PointResolution + ?Sized)) -> Self {
        let mut ring = Ring {
            p3: Vec::new(),
            p2: Vec::new(),
            reference: Vec::new(),
            beta: Vec::new(),
        };
        for (p, position) in lp.closed_polyline() {
            let r = lp.boundary_points.get(position).copied().unwrap_or(0);
            ring.p3.push(p);
            ring.reference.push(r);
            let r = r as usize;
            ring.beta
                .push(if r < beta.len() { beta.beta(r) } else { 0.0 });
        }
        ring
    }

    pub(crate) fn len(&self) -> usize {
        self.p2.len()
    }

    pub(crate) fn retain(&mut self, keep: &[bool]) {
        let mut k = keep.iter();
        self.p3.retain(|_| *k.next().unwrap_or(&true));
        let mut k = keep.iter();
        self.p2.retain(|_| *k.next().unwrap_or(&true));
        let mut k = keep.iter();
        self.reference.retain(|_| *k.next().unwrap_or(&true));
        let mut k = keep.iter();
        self.beta.retain(|_| *k.next().unwrap_or(&true));
    }

    /// Drops each vertex closer than `gap`·β (its own β) to the last one
    /// kept, or at the end to the first, by `distance` between two
    /// vertices: where a zig-zag border is smoothed its vertices bunch up,
    /// and a very short segment opposite a vertex a spacing away makes a
    /// sliver. A ring of fewer than twice [`MIN_LOOP_POINTS`] vertices, or
    /// that would keep fewer than [`MIN_LOOP_POINTS`], stays as it is.
    /// Returns how many went.
    pub(crate) fn even_out(
        &mut self,
        gap: f64,
        distance: impl Fn(&Ring, usize, usize) -> f64,
    ) -> usize {
        let m = self.p3.len();
        if m < 2 * MIN_LOOP_POINTS {
            return 0;
        }
        let mut keep = vec![true; m];
        let mut last = 0;
        for (j, kept) in keep.iter_mut().enumerate().skip(1) {
            let reach = gap * self.beta[j];
            if distance(self, j, last) < reach || distance(self, j, 0) < reach {
                *kept = false;
            } else {
                last = j;
            }
        }
        let dropped = keep.iter().filter(|&&k| !k).count();
        if m - dropped < MIN_LOOP_POINTS {
            return 0;
        }
        self.retain(&keep);
        dropped
    }

    /// [`Ring::even_out`] by the distance in the projection.
    pub(crate) fn even_out_in_projection(&mut self, gap: f64) -> usize {
        self.even_out(gap, |r, i, j| dist2d(r.p2[i], r.p2[j]))
    }

    /// Merges each vertex into its predecessor when they coincide in 2D
    /// (within [`MERGE`]·β); returns how many went.
    pub(crate) fn merge_coincident(&mut self) -> usize {
        let m = self.len();
        let mut keep = vec![true; m];
        let mut last = 0;
        for (j, k) in keep.iter_mut().enumerate().skip(1) {
            if dist2d(self.p2[j], self.p2[last]) <= MERGE * self.beta[j] {
                *k = false;
            } else {
                last = j;
            }
        }
        // The closing segment.
        while last > 0 && dist2d(self.p2[last], self.p2[0]) <= MERGE * self.beta[last] {
            keep[last] = false;
            last = (0..last).rev().find(|&j| keep[j]).unwrap_or(0);
        }
        let dropped = keep.iter().filter(|&&k| !k).count();
        self.retain(&keep);
        dropped
    }

    /// Signed area in 2D (positive counter-clockwise).
    pub(crate) fn area(&self) -> f64 {
        let m = self.len();
        let o = self.p2.first().copied().unwrap_or([0.0; 2]);
        (0..m)
            .map(|j| {
                let (a, b) = (self.p2[j], self.p2[(j + 1) % m]);
                (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
            })
            .sum::<f64>()
            * 0.5
    }
}

pub(super) fn dist2d(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

/// Repairs self-crossing loops and checks that the loops do not meet;
/// returns the segment grid of the valid loops (cells no smaller than
/// `min_cell`) and how many vertices the repairs dropped. A loop that
/// crosses itself loses the vertices of the shorter side of the crossing
/// (a twist, or a spike that turns straight back), as long as that takes
/// at most `max_repair` of its vertices (4 may always go).
pub(crate) fn untwist(
    rings: &mut [Ring],
    min_cell: f64,
    max_repair: f64,
) -> Result<(SegmentGrid, usize), Tangle> {
    let original: Vec<usize> = rings.iter().map(Ring::len).collect();
    let mut dropped = vec![0usize; rings.len()];
    loop {
        for (l, ring) in rings.iter().enumerate() {
            if ring.len() < 3 {
                return Err(Tangle::SelfCrossing {
                    index: l,
                    vertices: original[l],
                    dropped: original[l] - ring.len(),
                });
            }
        }
        let grid = SegmentGrid::new(rings, min_cell);
        let Some((s, t)) = grid.first_crossing() else {
            return Ok((grid, dropped.iter().sum()));
        };
        let ((l, i), (k, j)) = (grid.owner[s as usize], grid.owner[t as usize]);
        if l != k {
            return Err(Tangle::Crossing {
                a: l.min(k) as usize,
                b: l.max(k) as usize,
            });
        }
        let l = l as usize;
        let m = rings[l].len();
        let (i, j) = (i.min(j) as usize, i.max(j) as usize);
        // Drop vertices i+1..=j, or j+1..=i round the end: the fewer.
        let mut keep = vec![true; m];
        if j - i <= m - (j - i) {
            keep[i + 1..=j].iter_mut().for_each(|k| *k = false);
        } else {
            keep[j + 1..].iter_mut().for_each(|k| *k = false);
            keep[..=i].iter_mut().for_each(|k| *k = false);
        }
        let gone = keep.iter().filter(|&&k| !k).count();
        dropped[l] += gone;
        let limit = ((max_repair * original[l] as f64) as usize).max(4);
        if dropped[l] > limit {
            return Err(Tangle::SelfCrossing {
                index: l,
                vertices: original[l],
                dropped: dropped[l],
            });
        }
        rings[l].retain(&keep);
    }
}

/// The rings with every vertex that lies closer than `gap`·β (in the
/// projection) to another ring's segment moved away from it to that
/// distance, or None when none is that close. Two smoothed borders that
/// nearly touch (a small hole's loop against the outer border's, where
/// little surface parts them) leave a strip of no width between them,
/// and its faces are caps: on the MeshLab face scan one of 0.29° where a
/// hole's vertex lay 0.017 β from the outer loop. A vertex moves along
/// the way from its nearest point on the other ring, in 3D by the same
/// share (the projection is affine, so the two stay one point); a vertex
/// right on the other ring (no way to tell which side) stays.
pub(crate) fn kept_apart(rings: &[Ring], grid: &SegmentGrid, gap: f64) -> Option<Vec<Ring>> {
    let mut moved = rings.to_vec();
    let mut any = false;
    for (l, ring) in rings.iter().enumerate() {
        for i in 0..ring.len() {
            let (p2, p3, reach) = (ring.p2[i], ring.p3[i], gap * ring.beta[i]);
            let other_ring = |s: u32| grid.owner[s as usize].0 as usize != l;
            let Some((s, t)) = grid.nearest_where(p2, reach, other_ring) else {
                continue;
            };
            let (k, j) = grid.owner[s as usize];
            let other = &rings[k as usize];
            let next = (j as usize + 1) % other.len();
            let q2 = lerp2(other.p2[j as usize], other.p2[next], t);
            let distance = dist2d(p2, q2);
            if distance == 0.0 {
                continue;
            }
            let q3 = lerp(other.p3[j as usize], other.p3[next], t);
            let share = reach / distance;
            moved[l].p2[i] = [0, 1].map(|c| q2[c] + share * (p2[c] - q2[c]));
            moved[l].p3[i] = [0, 1, 2].map(|c| q3[c] + share * (p3[c] - q3[c]));
            any = true;
        }
    }
    any.then_some(moved)
}

/// A ring through `p2` in the plane z = 0, β 1 (for tests).
#[cfg(test)]
pub(crate) fn flat_ring(p2: Vec<[f64; 2]>) -> Ring {
    Ring {
        p3: p2.iter().map(|p| [p[0], p[1], 0.0]).collect(),
        reference: vec![0; p2.len()],
        beta: vec![1.0; p2.len()],
        p2,
    }
}

#[cfg(test)]
mod tests {
    use super::flat_ring as ring;
    use super::*;

    #[test]
    fn loops_that_nearly_touch_are_moved_apart() {
        // An outer square of side 10 and a small diamond hole inside whose
        // left tip lies 0.01 from the square's left side, between two of
        // its vertices; the square tilted in 3D (z = x), so the move must
        // keep p3 over p2.
        let mut outer = ring(square([0.0, 0.0], 10.0, 4));
        outer.p3 = outer.p2.iter().map(|p| [p[0], p[1], p[0]]).collect();
        let mut hole = ring(vec![[0.01, 6.25], [1.0, 5.25], [2.0, 6.25], [1.0, 7.25]]);
        hole.p3 = hole.p2.iter().map(|p| [p[0], p[1], p[0]]).collect();
        let rings = vec![outer, hole];
        let grid = SegmentGrid::new(&rings, 0.1);
        let moved = kept_apart(&rings, &grid, 0.25).expect("the tip is 0.01 from the side");
        assert_eq!(
            moved[0].p2, rings[0].p2,
            "the square's vertices are far from the hole"
        );
        let tip = moved[1].p2[0];
        assert!(
            (tip[0] - 0.25).abs() < 1e-12 && (tip[1] - 6.25).abs() < 1e-12,
            "{tip:?}"
        );
        assert!(
            (moved[1].p3[0][2] - 0.25).abs() < 1e-12,
            "{:?}",
            moved[1].p3[0]
        );
        assert_eq!(moved[1].p2[1..], rings[1].p2[1..]);
        // Apart already: nothing moves.
        assert!(kept_apart(&moved, &SegmentGrid::new(&moved, 0.1), 0.25).is_none());
    }

    /// A square of side `s` at `o`, 4·k vertices counter-clockwise.
    fn square(o: [f64; 2], s: f64, k: usize) -> Vec<[f64; 2]> {
        let t = |i: usize| s * i as f64 / k as f64;
        let mut p = Vec::new();
        p.extend((0..k).map(|i| [o[0] + t(i), o[1]]));
        p.extend((0..k).map(|i| [o[0] + s, o[1] + t(i)]));
        p.extend((0..k).map(|i| [o[0] + s - t(i), o[1] + s]));
        p.extend((0..k).map(|i| [o[0], o[1] + s - t(i)]));
        p
    }

    /// Vertices closer than the gap to the last one kept go; the ring's
    /// first vertex and a small ring stay.
    #[test]
    fn evening_out_drops_bunched_vertices() {
        let mut p = square([0.0, 0.0], 4.0, 4);
        // Two vertices bunched after the first corner, one before the first.
        p.insert(1, [0.1, 0.0]);
        p.insert(2, [0.3, 0.0]);
        p.push([0.0, 0.2]);
        let mut r = ring(p);
        assert_eq!(r.even_out_in_projection(0.4), 3);
        assert_eq!(r.p2, square([0.0, 0.0], 4.0, 4));
        let mut small = ring(vec![[0.0, 0.0], [0.1, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        assert_eq!(small.even_out_in_projection(0.4), 0);
        assert_eq!(small.len(), 4);
    }

    #[test]
    fn a_small_twist_is_untwisted() {
        let mut p = square([0.0, 0.0], 10.0, 20);
        // A bow tie: segments 4→5 and 6→7 cross.
        p[5] = [3.0, 0.5];
        p[6] = [2.0, 0.5];
        let mut rings = vec![ring(p)];
        let (grid, dropped) = untwist(&mut rings, 0.1, 0.05).unwrap();
        assert!(grid.first_crossing().is_none());
        assert_eq!(dropped, 2);
        assert!(grid.parity([5.0, 5.0]) && !grid.parity([11.0, 5.0]));
    }

    #[test]
    fn a_figure_eight_is_not_repaired() {
        let mut p = square([0.0, 0.0], 10.0, 20);
        // Swap the top side's x: the loop crosses itself in the middle.
        for q in p.iter_mut().skip(40).take(20) {
            q[0] = 10.0 - q[0];
        }
        let mut rings = vec![ring(p)];
        assert!(matches!(
            untwist(&mut rings, 0.1, 0.05),
            Err(Tangle::SelfCrossing { index: 0, .. })
        ));
    }

    #[test]
    fn crossing_loops_are_reported() {
        let mut rings = vec![
            ring(square([0.0, 0.0], 10.0, 10)),
            ring(square([8.0, 8.0], 5.0, 5)),
        ];
        assert!(matches!(
            untwist(&mut rings, 0.1, 0.05),
            Err(Tangle::Crossing { a: 0, b: 1 })
        ));
    }

    #[test]
    fn parity_sees_holes_and_patches() {
        let rings = vec![
            ring(square([0.0, 0.0], 10.0, 10)),
            ring(square([3.0, 3.0], 4.0, 4)),
            ring(square([20.0, 0.0], 5.0, 5)),
        ];
        let grid = SegmentGrid::new(&rings, 0.1);
        assert!(grid.parity([1.0, 1.0]));
        assert!(!grid.parity([5.0, 5.0]));
        assert!(!grid.parity([15.0, 1.0]));
        assert!(grid.parity([22.0, 2.0]));
        assert!(grid.near([10.05, 5.0], 0.1) && !grid.near([10.2, 5.0], 0.1));
    }
}
