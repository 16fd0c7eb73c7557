//! Anisotropic sampling correction — meshtrim's extension of the paper.
//!
//! A laser line scanner samples much more densely along its lines than
//! between them. The paper's β then follows the dense direction while the
//! empty circles between lines reach half the line spacing, so plain BPD
//! marks nearly every point. Here each projected neighbourhood gets a
//! *sampling tensor*
//!
//! T = Σ over members j of (e1_j e1_jᵀ + e2_j e2_jᵀ), projected on P_i's plane,
//!
//! where e1_j is member j's vector to its nearest neighbour and e2_j the
//! vector to its nearest neighbour at least 60° away from the line of e1_j,
//! both found once per point in that point's own projected neighbourhood
//! ([`own_sampling_vectors`]). The neighbourhood is then mapped by
//! M = T^(-1/2), scaled to det M = 1, in which the scan lines look evenly
//! spaced; β and both tests run on the mapped points. On isotropic samples T
//! is nearly a multiple of the identity and M nearly the identity, so the
//! paper's behaviour is kept. Because det M = 1, β stays a length: the
//! geometric mean of the spacings along and across the lines.
//!
//! Finding each point's vectors once, in its own neighbourhood, costs O(k)
//! per point instead of O(k²) per neighbourhood, and gives members at the
//! rim of P_i's neighbourhood their true nearest neighbours rather than the
//! nearest ones that happen to be inside it. Each point keeps its vectors
//! as the 3D moment S_j = e1_j e1_jᵀ + e2_j e2_jᵀ ([`sampling_moment`]), so
//! that T = P (Σ S_j) Pᵀ costs one projection per neighbourhood
//! ([`sampling_tensor_of_moments`]; [`sampling_tensor`] projects every
//! vector and is the reference).

use crate::frame::{Frame, Point2};
use crate::geom::{dot, Point3};
use crate::resolution::dist2;
use crate::spatial::neighbours::tie_key;

/// A 2×2 linear map, row-major: `[[a, b], [c, d]]`.
pub type Map2 = [[f64; 2]; 2];

/// The identity map.
pub(crate) const IDENTITY: Map2 = [[1.0, 0.0], [0.0, 1.0]];

/// Applies `m` to `p`.
#[inline]
pub fn apply(m: &Map2, p: Point2) -> Point2 {
    [
        m[0][0] * p[0] + m[0][1] * p[1],
        m[1][0] * p[0] + m[1][1] * p[1],
    ]
}

/// cos²(60°): e2 must make at least this much of an angle with e1's line.
const COS2_MIN_ANGLE: f64 = 0.25;

/// Relative slack of the 60° test, far above rounding (~10⁻¹⁵ near the
/// origin, ~10⁻⁹ a million spacings away) and far below any angle that
/// matters.
const ANGLE_TOLERANCE: f64 = 1e-7;

/// A point's two sampling vectors e1, e2 in 3D, in its own tangent plane;
/// zero where the neighbourhood has none (all members in one direction).
pub type SamplingVectors = [Point3; 2];

/// e1 and e2 of the investigated point `projected[0]` (at the origin) within
/// its projected neighbourhood, lifted back to 3D with the frame's axes.
// Baseline and AVX2 variants, chosen at run time (crate doc, "Vector kernels").
#[multiversion::multiversion(targets("x86_64+avx2"))]
pub fn own_sampling_vectors(projected: &[Point2], frame: &Frame) -> SamplingVectors {
    let lift = |e: Option<Point2>| {
        e.map_or([0.0; 3], |e| {
            [0, 1, 2].map(|a| e[0] * frame.u[a] + e[1] * frame.v[a])
        })
    };
    let e1 = nearest_vector(projected, 0, None);
    let e2 = e1.and_then(|e1| nearest_vector(projected, 0, Some(e1)));
    [lift(e1), lift(e2)]
}

#[cfg(test)]
/// T of P_i's neighbourhood (unnormalised sum): the members' sampling
/// vectors projected on P_i's plane.
pub fn sampling_tensor<'a>(
    frame: &Frame,
    members: impl Iterator<Item = &'a SamplingVectors>,
) -> [f64; 3] {
    let mut t = [0.0; 3];
    for vectors in members {
        for e in vectors {
            add_outer(&mut t, [dot(*e, frame.u), dot(*e, frame.v)]);
        }
    }
    t
}

/// A point's sampling moment S = e1 e1ᵀ + e2 e2ᵀ in 3D (symmetric:
/// xx, xy, xz, yy, yz, zz).
pub type SamplingMoment = [f64; 6];

/// S of a point's sampling vectors.
pub fn sampling_moment([e1, e2]: &SamplingVectors) -> SamplingMoment {
    let outer = |e: &Point3| {
        [
            e[0] * e[0],
            e[0] * e[1],
            e[0] * e[2],
            e[1] * e[1],
            e[1] * e[2],
            e[2] * e[2],
        ]
    };
    let (a, b) = (outer(e1), outer(e2));
    [0, 1, 2, 3, 4, 5].map(|i| a[i] + b[i])
}

/// [`sampling_tensor`] from the members' moments: projecting each vector on
/// the plane and summing the outer products equals projecting the summed
/// moments once, T = P (Σ S_j) Pᵀ with P's rows the frame's u and v; one
/// projection instead of two per member.
pub fn sampling_tensor_of_moments<'a>(
    frame: &Frame,
    moments: impl Iterator<Item = &'a SamplingMoment>,
) -> [f64; 3] {
    let mut sum = [0.0; 6];
    for m in moments {
        for (s, x) in sum.iter_mut().zip(m) {
            *s += x;
        }
    }
    let [xx, xy, xz, yy, yz, zz] = sum;
    let times = |a: Point3| {
        [
            xx * a[0] + xy * a[1] + xz * a[2],
            xy * a[0] + yy * a[1] + yz * a[2],
            xz * a[0] + yz * a[1] + zz * a[2],
        ]
    };
    let (su, sv) = (times(frame.u), times(frame.v));
    [dot(frame.u, su), dot(frame.u, sv), dot(frame.v, sv)]
}

/// M = T^(-1/2) scaled to unit determinant; the identity if T is singular.
pub fn whitening_map(t: [f64; 3]) -> Map2 {
    let [a, b, c] = t;
    let half_trace = 0.5 * (a + c);
    let disc = (0.25 * (a - c) * (a - c) + b * b).sqrt();
    let (l1, l2) = (half_trace + disc, half_trace - disc);
    // Also catches NaN: a degenerate or non-finite tensor gives no usable map.
    let well_conditioned = l2 > l1 * 1e-12;
    if !well_conditioned {
        return IDENTITY;
    }
    // Unit eigenvector of l1.
    let (vx, vy) = if b.abs() > 1e-300 * (a.abs() + c.abs()) && b != 0.0 {
        let (x, y) = (l1 - c, b);
        let n = (x * x + y * y).sqrt();
        (x / n, y / n)
    } else if a >= c {
        (1.0, 0.0)
    } else {
        (0.0, 1.0)
    };
    // M = s1 v vᵀ + s2 w wᵀ with s_i = l_i^(-1/2), scaled so s1 s2 = 1.
    // Two square roots: the fourth root without a call to pow.
    let scale = (l1 * l2).sqrt().sqrt();
    let (s1, s2) = (scale / l1.sqrt(), scale / l2.sqrt());
    let (wx, wy) = (-vy, vx);
    [
        [s1 * vx * vx + s2 * wx * wx, s1 * vx * vy + s2 * wx * wy],
        [s1 * vx * vy + s2 * wx * wy, s1 * vy * vy + s2 * wy * wy],
    ]
}

/// Vector from `pts[j]` to its nearest other member; with `away_from`, only
/// members whose direction is at least 60° from that vector's line count.
#[inline]
fn nearest_vector(pts: &[Point2], j: usize, away_from: Option<Point2>) -> Option<Point2> {
    let p = pts[j];
    // The best so far by its distance's tie key: near-equal distances tie
    // and the earlier member keeps the place (see `tie_key`); on quantised
    // clouds rounding, not geometry, would otherwise choose.
    let mut best: Option<(u64, Point2)> = None;
    for (m, &q) in pts.iter().enumerate() {
        let d2 = dist2(p, q);
        let key = tie_key(d2);
        if m == j || d2 == 0.0 || best.is_some_and(|(b, _)| key >= b) {
            continue;
        }
        let e = [q[0] - p[0], q[1] - p[1]];
        if let Some(e1) = away_from {
            // "At least 60°" includes 60° within rounding, which
            // quantised (hexagonal) samplings produce exactly.
            let dot = e[0] * e1[0] + e[1] * e1[1];
            let limit = COS2_MIN_ANGLE * (e1[0] * e1[0] + e1[1] * e1[1]) * d2;
            if dot * dot > limit * (1.0 + ANGLE_TOLERANCE) {
                continue;
            }
        }
        best = Some((key, e));
    }
    best.map(|(_, e)| e)
}

#[cfg(test)]
fn add_outer(t: &mut [f64; 3], e: Point2) {
    t[0] += e[0] * e[0];
    t[1] += e[0] * e[1];
    t[2] += e[1] * e[1];
}

#[cfg(test)]
mod tests {
    use super::*;

    /// T of a planar point set, every point's vectors found in the whole set.
    fn planar_tensor(pts: &[Point2]) -> [f64; 3] {
        let mut t = [0.0; 3];
        for j in 0..pts.len() {
            let e1 = nearest_vector(pts, j, None);
            let e2 = e1.and_then(|e1| nearest_vector(pts, j, Some(e1)));
            for e in [e1, e2].into_iter().flatten() {
                add_outer(&mut t, e);
            }
        }
        t
    }

    fn det(m: &Map2) -> f64 {
        m[0][0] * m[1][1] - m[0][1] * m[1][0]
    }

    #[test]
    fn line_scan_becomes_isotropic() {
        // Lines 4 apart along y at 30°, points 1 apart along each line.
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let pts: Vec<Point2> = (0..35)
            .map(|i| {
                let (a, b) = ((i % 7) as f64 - 3.0, ((i / 7) as f64 - 2.0) * 4.0);
                [c * a - s * b, s * a + c * b]
            })
            .collect();
        let m = whitening_map(planar_tensor(&pts));
        assert!((det(&m) - 1.0).abs() < 1e-12);
        let along = apply(&m, [c, s]);
        let across = apply(&m, [-s * 4.0, c * 4.0]);
        let (la, lc) = (along[0].hypot(along[1]), across[0].hypot(across[1]));
        assert!(
            (la - 2.0).abs() < 1e-9 && (lc - 2.0).abs() < 1e-9,
            "{la} {lc}"
        );
    }

    #[test]
    fn own_vectors_lift_to_the_tangent_plane() {
        let frame = Frame {
            u: [0.0, 1.0, 0.0],
            v: [0.0, 0.0, 1.0],
            normal: [1.0, 0.0, 0.0],
        };
        let pts = [[0.0, 0.0], [1.0, 0.1], [0.2, 3.0], [-5.0, 0.0]];
        let [e1, e2] = own_sampling_vectors(&pts, &frame);
        assert_eq!(e1, [0.0, 1.0, 0.1]);
        assert_eq!(e2, [0.0, 0.2, 3.0]);
        let t = sampling_tensor(&frame, [[e1, e2]].iter());
        assert_eq!(
            t,
            [
                1.0 * 1.0 + 0.2 * 0.2,
                1.0 * 0.1 + 0.2 * 3.0,
                0.1 * 0.1 + 3.0 * 3.0
            ]
        );
    }

    /// Projecting the summed moments gives the tensor of the projected
    /// vectors, to rounding, on random frames and vectors.
    #[test]
    fn tensor_of_moments_is_the_tensor_of_projections() {
        let mut rng = testkit::SplitMix64::new(9);
        for _ in 0..2000 {
            let mut r = || [0; 3].map(|_| rng.range(-2.0, 2.0));
            let unit = |a: Point3| {
                let l = dot(a, a).sqrt();
                a.map(|c| c / l)
            };
            let n = unit(r());
            let u = unit(crate::geom::cross(n, r()));
            let frame = Frame {
                u,
                v: crate::geom::cross(n, u),
                normal: n,
            };
            let members: Vec<SamplingVectors> = (0..30).map(|_| [r(), r()]).collect();
            let plain = sampling_tensor(&frame, members.iter());
            let moments: Vec<SamplingMoment> = members.iter().map(sampling_moment).collect();
            let fast = sampling_tensor_of_moments(&frame, moments.iter());
            let size = plain[0].abs() + plain[2].abs();
            for (a, b) in plain.iter().zip(&fast) {
                assert!((a - b).abs() <= 1e-13 * size, "{plain:?} {fast:?}");
            }
        }
    }

    #[test]
    fn square_grid_maps_to_itself() {
        let pts: Vec<Point2> = (0..36).map(|i| [(i % 6) as f64, (i / 6) as f64]).collect();
        let m = whitening_map(planar_tensor(&pts));
        for (r, e) in m.iter().zip(IDENTITY.iter()) {
            for (x, y) in r.iter().zip(e.iter()) {
                assert!((x - y).abs() < 1e-12);
            }
        }
    }
}
