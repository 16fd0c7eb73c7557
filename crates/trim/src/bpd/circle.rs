//! The empty-circle test of BPD (section 2 of the paper, eq. 1).
//!
//! The paper: P_i is a boundary point "if there is at least one circle [through
//! P_i and two neighbours] with radius equal or bigger than β_i and if the
//! sphere ... whose centre coincide with the centre of the circle, does not
//! contain any other point of the neighbourhood". meshtrim runs the test in
//! the neighbourhood's best-fit plane (see `docs/bpd.md` for why: in 3D,
//! nearly collinear triples span circles perpendicular to the surface whose
//! spheres are empty, so out-of-plane noise turns interior points into
//! boundary points). A collinear triple spans a circle of infinite radius, a
//! half-plane through P_i: it counts when that half-plane holds no
//! neighbour, i.e. when P_i lies on the convex hull of its neighbourhood.
//!
//! Two implementations give the same answer:
//! - [`empty_circle_reference`] tries all (k-1)(k-2)/2 circles, as eq. 1
//!   counts them, against every other neighbour: O(k³).
//! - [`largest_empty_circle_exceeds`] uses the fact that the empty circles
//!   through P_i and two neighbours are exactly the circumcircles of the
//!   Delaunay triangles at P_i, whose centres are the vertices of P_i's
//!   Voronoi cell. The cell is clipped from a box of half-size L ≥ β by the
//!   bisectors with the neighbours: those within √2·β of P_i first, then the
//!   rest, each group nearest first; it stops as soon as no vertex is β away
//!   from P_i (clipping only shrinks the cell, and the cell does not depend
//!   on the order). The near ones first because on a line scan the nearest
//!   in 3D are P_i's own scan line, whose bisectors leave the cell open
//!   across the lines: the map makes the lines evenly spaced in the plane,
//!   but the neighbours stay in their 3D order. A vertex on
//!   the box means the cell is unbounded (P_i on the hull) or has a vertex
//!   beyond L ≥ β: both are boundary cases of the reference, so the answer
//!   is "some vertex at distance ≥ β". O(k · cell size), no allocation.
//! - [`boundary_links`] gives a boundary point's neighbours along the
//!   boundary from its cell in a box wide enough not to depend on the
//!   plane's axes.

use crate::frame::Point2;

/// Reference circle test: `pts[0]` is P_i at the origin, `pts[1..]` its
/// neighbours (distinct, non-zero). True if an empty circle through P_i and
/// two neighbours has radius ≥ `beta`, or a half-plane through P_i is empty.
pub fn empty_circle_reference(pts: &[Point2], beta: f64) -> bool {
    let nb = &pts[1..];
    if on_hull_reference(nb) {
        return true;
    }
    for j in 0..nb.len() {
        for k in j + 1..nb.len() {
            let Some(c) = circumcentre_with_origin(nb[j], nb[k]) else {
                continue; // collinear: the half-plane case above covers it
            };
            let r2 = c[0] * c[0] + c[1] * c[1];
            if r2 < beta * beta {
                continue;
            }
            let empty = nb.iter().enumerate().all(|(m, &q)| {
                m == j || m == k || {
                    let (dx, dy) = (q[0] - c[0], q[1] - c[1]);
                    dx * dx + dy * dy >= r2 * (1.0 - 1e-12)
                }
            });
            if empty {
                return true;
            }
        }
    }
    false
}

/// True if all points lie in a closed half-plane whose border passes through
/// the origin (the largest angular gap between them is at least π).
pub fn on_hull_reference(nb: &[Point2]) -> bool {
    let mut angles: Vec<f64> = nb.iter().map(|p| p[1].atan2(p[0])).collect();
    angles.sort_by(f64::total_cmp);
    let Some(&first) = angles.first() else {
        return true;
    };
    let mut gap: f64 = first + std::f64::consts::TAU - angles[angles.len() - 1];
    for w in angles.windows(2) {
        gap = gap.max(w[1] - w[0]);
    }
    gap >= std::f64::consts::PI - 1e-12
}

/// Centre of the circle through the origin, `a` and `b`; None if collinear.
fn circumcentre_with_origin(a: Point2, b: Point2) -> Option<Point2> {
    let d = 2.0 * (a[0] * b[1] - a[1] * b[0]);
    let (na, nb) = (a[0] * a[0] + a[1] * a[1], b[0] * b[0] + b[1] * b[1]);
    let scale = na.max(nb);
    if d.abs() <= 1e-12 * scale {
        return None;
    }
    Some([(na * b[1] - nb * a[1]) / d, (nb * a[0] - na * b[0]) / d])
}

/// Neighbours within √NEAR·β of P_i clip the cell first. On the 12k
/// benchmark's line scan the circle test took 52.1M instructions with one
/// pass, 30.0M / 31.8M / 36.7M with NEAR = 1.5 / 2 / 3; on the isotropic
/// sheet 25.8M, 27.3M / 26.2M / 26.0M.
const NEAR: f64 = 2.0;

/// Label of a cell edge that lies on the initial box, not on a bisector.
const BOX_EDGE: u32 = u32::MAX;

/// Reusable buffers for [`largest_empty_circle_exceeds`]: the cell as a
/// convex polygon, each vertex with the label of the edge that leaves it
/// (the neighbour whose bisector it lies on, or `BOX_EDGE`).
#[derive(Default, Debug, Clone)]
pub struct CellScratch {
    poly: Vec<(Point2, u32)>,
    next: Vec<(Point2, u32)>,
}

/// Fast circle test: is some vertex of P_i's Voronoi cell (clipped to a box
/// of half-size `max(2·max|q|, 2β)`) at least `beta` from P_i?
///
/// `nb` are the neighbours relative to P_i, nearest first.
// Baseline and AVX2 variants, chosen at run time (crate doc, "Vector kernels").
#[multiversion::multiversion(targets("x86_64+avx2"))]
pub fn largest_empty_circle_exceeds(nb: &[Point2], beta: f64, s: &mut CellScratch) -> bool {
    let beta2 = beta * beta;
    // The largest squared vertex distance so far.
    let mut far2 = s.start_at_box((2.0 * reach(nb)).max(2.0 * beta));
    let near2 = NEAR * beta2;
    for near_pass in [true, false] {
        for (j, &q) in nb.iter().enumerate() {
            let q2 = q[0] * q[0] + q[1] * q[1];
            // The bisector x·q = |q|²/2 cannot cut a cell within radius |q|/2.
            if (q2 <= near2) != near_pass || 0.25 * q2 >= far2 {
                continue;
            }
            far2 = s.clip_by(q, q2, j);
            if far2 < beta2 {
                return false;
            }
        }
    }
    far2 >= beta2
}

/// The neighbours (indices into `nb`, relative to P_i as for
/// [`largest_empty_circle_exceeds`]) joined to P_i by an empty circle of
/// radius ≥ `beta` — those whose Voronoi edge with P_i reaches `beta` from
/// P_i. They are P_i's neighbours *along the boundary* (the edges of the
/// α-shape with α = β), which edge reconstruction uses to cluster and
/// order boundary points. Sorted, without repeats.
///
/// `s` must hold the cell of a true answer of
/// [`largest_empty_circle_exceeds`] for the same `nb` and `beta` (such a
/// cell is complete: every neighbour has clipped it). When no edge of it
/// lies on the test's box, it is P_i's whole cell and is read as it is.
/// Otherwise it is clipped afresh from a box `LINK_BOX` times wider: for
/// a point on the hull the cell is unbounded, and its edges that lie
/// between the test's box and that box's corners (all farther than β)
/// would be kept or lost with the box's turn in the plane, so the links
/// would turn with the plane's axes. In the wide box only edges more than
/// 2²⁰ neighbourhood radii away could still be, which needs three
/// neighbours collinear to within a millionth of the radius without being
/// collinear.
pub fn boundary_links(nb: &[Point2], beta: f64, s: &mut CellScratch, out: &mut Vec<u32>) {
    if s.poly.iter().any(|&(_, label)| label == BOX_EDGE) {
        clip_wide(nb, beta, s);
    }
    out.clear();
    let beta2 = beta * beta;
    let norm2 = |v: Point2| v[0] * v[0] + v[1] * v[1];
    for t in 0..s.poly.len() {
        let (a, label) = s.poly[t];
        let (b, _) = s.poly[(t + 1) % s.poly.len()];
        // Distance to P_i along a segment is largest at an end.
        if label != BOX_EDGE && norm2(a).max(norm2(b)) >= beta2 {
            out.push(label);
        }
    }
    out.sort_unstable();
    out.dedup();
}

/// P_i's cell clipped by all neighbours from the box of [`LINK_BOX`] ×
/// max(reach, β).
fn clip_wide(nb: &[Point2], beta: f64, s: &mut CellScratch) {
    let mut far2 = s.start_at_box(LINK_BOX * reach(nb).max(beta));
    for (j, &q) in nb.iter().enumerate() {
        let q2 = q[0] * q[0] + q[1] * q[1];
        // The bisector x·q = |q|²/2 cannot cut a cell within radius |q|/2.
        if 0.25 * q2 < far2 {
            far2 = s.clip_by(q, q2, j);
        }
    }
}

/// The largest distance of the neighbours from P_i.
fn reach(nb: &[Point2]) -> f64 {
    nb.iter()
        .map(|q| q[0] * q[0] + q[1] * q[1])
        .fold(0.0, f64::max)
        .sqrt()
}

impl CellScratch {
    /// The cell set to the square of half-size `l` round P_i, all its edges
    /// on the box; returns its largest squared vertex distance.
    fn start_at_box(&mut self, l: f64) -> f64 {
        self.poly.clear();
        self.poly.extend_from_slice(&[
            ([-l, -l], BOX_EDGE),
            ([l, -l], BOX_EDGE),
            ([l, l], BOX_EDGE),
            ([-l, l], BOX_EDGE),
        ]);
        2.0 * l * l
    }

    /// The cell clipped by the bisector with neighbour `j` at `q` (|q|² =
    /// `q2`); returns its largest squared vertex distance.
    // Always inlined: as a call it cost the 12k benchmark 1.5M
    // instructions (341.5M against 339.9M).
    #[inline(always)]
    fn clip_by(&mut self, q: Point2, q2: f64, j: usize) -> f64 {
        clip(&self.poly, q, 0.5 * q2, j as u32, &mut self.next);
        std::mem::swap(&mut self.poly, &mut self.next);
        self.poly
            .iter()
            .map(|(v, _)| v[0] * v[0] + v[1] * v[1])
            .fold(0.0, f64::max)
    }
}

/// How much wider than the neighbourhood [`boundary_links`]' box is: 2²⁰,
/// far beyond any Voronoi vertex of a noisy neighbourhood, and close
/// enough that the vertices near P_i keep about 10⁻⁹ of their precision
/// relative to the neighbourhood's radius.
const LINK_BOX: f64 = 1_048_576.0;

/// Keeps the part of convex polygon `poly` where x·n <= h
/// (Sutherland–Hodgman); the new edge along x·n = h gets `label`.
fn clip(poly: &[(Point2, u32)], n: Point2, h: f64, label: u32, out: &mut Vec<(Point2, u32)>) {
    out.clear();
    let side = |p: Point2| p[0] * n[0] + p[1] * n[1] - h;
    for i in 0..poly.len() {
        let (a, edge) = poly[i];
        let (b, _) = poly[(i + 1) % poly.len()];
        let (sa, sb) = (side(a), side(b));
        if sa <= 0.0 {
            out.push((a, edge));
        }
        if (sa < 0.0 && sb > 0.0) || (sa > 0.0 && sb < 0.0) {
            let t = sa / (sa - sb);
            let cut = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
            // Leaving the half-plane, the cell continues along the new
            // bisector; entering it, along the rest of the old edge.
            out.push((cut, if sa < 0.0 { label } else { edge }));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{PI, TAU};

    fn grid_around(skip: impl Fn(f64, f64) -> bool) -> Vec<Point2> {
        let mut pts = vec![[0.0, 0.0]];
        for i in -3..=3 {
            for j in -3..=3 {
                let (x, y) = (i as f64, j as f64);
                if (i, j) != (0, 0) && !skip(x, y) {
                    pts.push([x, y]);
                }
            }
        }
        pts[1..].sort_by(|a, b| (a[0].hypot(a[1])).total_cmp(&b[0].hypot(b[1])));
        pts
    }

    #[test]
    fn interior_grid_point_has_no_big_empty_circle() {
        let pts = grid_around(|_, _| false);
        let mut s = CellScratch::default();
        assert!(!empty_circle_reference(&pts, 1.0));
        assert!(!largest_empty_circle_exceeds(&pts[1..], 1.0, &mut s));
    }

    #[test]
    fn point_beside_a_hole_has_one() {
        // Remove a 2×2 block next to the origin: a hole of radius ~1.
        let pts = grid_around(|x, y| (1.0..=2.0).contains(&x) && (0.0..=1.0).contains(&y));
        let mut s = CellScratch::default();
        assert!(empty_circle_reference(&pts, 1.0));
        assert!(largest_empty_circle_exceeds(&pts[1..], 1.0, &mut s));
    }

    #[test]
    fn boundary_links_run_along_the_border() {
        // Straight border y = 0 with the cloud below: P_i's neighbours along
        // the border are (±1, 0).
        let pts = grid_around(|_, y| y > 0.0);
        let mut s = CellScratch::default();
        assert!(largest_empty_circle_exceeds(&pts[1..], 1.0, &mut s));
        let mut out = Vec::new();
        boundary_links(&pts[1..], 1.0, &mut s, &mut out);
        let found: Vec<Point2> = out.iter().map(|&j| pts[1 + j as usize]).collect();
        assert_eq!(found.len(), 2, "{found:?}");
        assert!(found.contains(&[1.0, 0.0]) && found.contains(&[-1.0, 0.0]));
    }

    #[test]
    fn point_on_a_straight_border_is_on_the_hull() {
        let pts = grid_around(|_, y| y > 0.0);
        let mut s = CellScratch::default();
        assert!(on_hull_reference(&pts[1..]));
        assert!(empty_circle_reference(&pts, 1.0));
        assert!(largest_empty_circle_exceeds(&pts[1..], 1.0, &mut s));
    }

    /// The links do not depend on how the plane's axes turn: the same
    /// neighbourhood turned by any angle has the same boundary neighbours.
    #[test]
    fn links_do_not_turn_with_the_axes() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(21);
        let mut s = CellScratch::default();
        let (mut first, mut turned) = (Vec::new(), Vec::new());
        let mut checked = 0;
        for case in 0..3000 {
            // A border point: neighbours on one side of a wavy border,
            // nearest first.
            let mut nb: Vec<Point2> = (0..29)
                .map(|_| {
                    let r = rng.random_range(0.1..1.0f64).sqrt();
                    let t = rng.random_range(-PI..0.0);
                    [r * t.cos(), r * t.sin() + 0.15 * (3.0 * r * t.cos()).sin()]
                })
                .collect();
            nb.sort_by(|a, b| (a[0].hypot(a[1])).total_cmp(&b[0].hypot(b[1])));
            let beta = [0.2, 0.35, 0.5][case % 3];
            if !largest_empty_circle_exceeds(&nb, beta, &mut s) {
                continue;
            }
            boundary_links(&nb, beta, &mut s, &mut first);
            let angle = rng.random_range(0.0..TAU);
            let (c, sn) = (angle.cos(), angle.sin());
            let rotated: Vec<Point2> = nb
                .iter()
                .map(|p| [c * p[0] - sn * p[1], sn * p[0] + c * p[1]])
                .collect();
            assert!(largest_empty_circle_exceeds(&rotated, beta, &mut s));
            boundary_links(&rotated, beta, &mut s, &mut turned);
            assert_eq!(first, turned, "case {case}, turned by {angle}");
            checked += 1;
        }
        assert!(checked > 1000, "only {checked} border points");
    }
}
