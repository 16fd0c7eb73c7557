//! Anisotropic sampling correction — meshtrim's extension of the paper.
//!
//! A laser line scanner samples much more densely along its lines than
//! between them. The paper's β then follows the dense direction while the
//! empty circles between lines reach half the line spacing, so plain BPD
//! marks nearly every point. Here each projected neighbourhood gets a
//! *sampling tensor*
//!
//! T = Σ over members j of S_j, projected on P_i's plane,
//!
//! where S_j is member j's *sampling moment*: e1 e1ᵀ + e2⊥ e2⊥ᵀ, e1 the
//! vector to its nearest neighbour and e2⊥ the part across e1's line of
//! the vector to its nearest neighbour at least 60° from that line, found
//! once per point in that point's own projected neighbourhood
//! ([`own_sampling_moment`]). The neighbourhood is
//! then mapped by M = T^(-1/2), scaled to det M = 1, in which the scan
//! lines look evenly spaced; β and both tests run on the mapped points. On
//! isotropic samples T is nearly a multiple of the identity and M nearly
//! the identity, so the paper's behaviour is kept. Because det M = 1, β
//! stays a length: the geometric mean of the spacings along and across the
//! lines.
//!
//! # A moment continuous in the points
//!
//! "The nearest neighbour" is a discrete choice: where two neighbours are
//! about as near (every neighbour of a lattice point, two of a blue-noise
//! point), noise a fraction of a percent of the spacing switches e1 or e2
//! from one to the other, S_j jumps, and so do M, β and the marginal
//! labels. S_j therefore blends: every neighbour whose squared distance is
//! within a factor (1 + [`BLEND_REACH`])² of the nearest one's is an e1,
//! weighted by a bump that is 1 at the nearest and falls smoothly to 0 at
//! the reach; for each such e1 the e2 candidates are blended the same way,
//! their squared distance divided by the square of a gate that is 0 within
//! 50° of e1's line, 1 beyond 70° and smooth between (the 60° rule as a
//! ramp), and each e2 counts by its part across e1's line (on a line scan,
//! the neighbours straight across and a step along both give the line
//! spacing). Where one neighbour is clearly the nearest, S_j is
//! e1 e1ᵀ + e2⊥ e2⊥ᵀ; where several tie, their weighted mean. Every step is
//! continuous, so a small move of the points moves S_j a little and never
//! switches it (docs/bpd.md, "Anisotropic sampling", has what it does to
//! the label flips under noise).
//!
//! Finding each point's moment once, in its own neighbourhood, costs O(k)
//! per point and per blended e1 instead of O(k²) per neighbourhood, and
//! gives members at the rim of P_i's neighbourhood their true nearest
//! neighbours rather than the nearest ones that happen to be inside it.
//! Each point keeps S_j in 3D, so that T = P (Σ S_j) Pᵀ costs one
//! projection per neighbourhood ([`sampling_tensor_of_moments`]).

use crate::frame::{Frame, Point2};
use crate::geom::{dot, Point3};

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

/// How far beyond the nearest neighbour the blends of e1 and of e2 reach,
/// relative to its distance: neighbours up to 35 % farther than the nearest
/// share the role. 0.25, 0.35 and 0.5 score alike on the sampling sweep
/// (docs/bpd.md); at 0.5 one first-row point of the variable-density blade
/// flips at 70 % noise.
pub const BLEND_REACH: f64 = 0.35;

/// cos² of the angles from e1's line at which the e2 gate starts to open
/// (50°) and is fully open (70°).
const GATE_COS2: (f64, f64) = (0.413_175_911_166_535, 0.116_977_778_440_511);

/// A point's sampling moment S = e1 e1ᵀ + e2⊥ e2⊥ᵀ in 3D (symmetric:
/// xx, xy, xz, yy, yz, zz).
pub type SamplingMoment = [f64; 6];

/// Buffers of [`own_sampling_moment`], kept between calls.
#[derive(Debug, Default)]
pub struct MomentScratch {
    offsets: Vec<Point2>,
    norm2: Vec<f64>,
    gated: Vec<f64>,
}

/// S of the investigated point `projected[0]` (blended, see the module doc)
/// within its projected neighbourhood, lifted to 3D with the frame's axes.
/// Zero when every member coincides with the point.
pub fn own_sampling_moment(
    projected: &[Point2],
    frame: &Frame,
    scratch: &mut MomentScratch,
) -> SamplingMoment {
    let [a, b, c] = fast_planar_sampling_moment(projected, scratch);
    let (u, v) = (frame.u, frame.v);
    let entry =
        |p: usize, q: usize| a * u[p] * u[q] + b * (u[p] * v[q] + v[p] * u[q]) + c * v[p] * v[q];
    [
        entry(0, 0),
        entry(0, 1),
        entry(0, 2),
        entry(1, 1),
        entry(1, 2),
        entry(2, 2),
    ]
}

/// [`planar_sampling_moment`] with each member's squared distance found
/// once, the gate computed without branches, and the gated distances kept
/// between the two passes over the e2 candidates: the same weights up to
/// rounding.
// Baseline and AVX2 variants, chosen at run time (crate doc, "Vector kernels").
#[multiversion::multiversion(targets("x86_64+avx2"))]
fn fast_planar_sampling_moment(pts: &[Point2], s: &mut MomentScratch) -> [f64; 3] {
    let origin = pts[0];
    s.offsets.clear();
    s.norm2.clear();
    for q in &pts[1..] {
        let e = [q[0] - origin[0], q[1] - origin[1]];
        let n = norm2(e);
        if n > 0.0 {
            s.offsets.push(e);
            s.norm2.push(n);
        }
    }
    let nearest = s.norm2.iter().copied().fold(f64::INFINITY, f64::min);
    if !nearest.is_finite() {
        return [0.0; 3];
    }
    let reach2 = (1.0 + BLEND_REACH) * (1.0 + BLEND_REACH);
    let mut moment = [0.0; 3];
    let mut total = 0.0;
    for (&e1, &n1) in s.offsets.iter().zip(&s.norm2) {
        if n1 >= reach2 * nearest {
            continue;
        }
        let weight = blend_weight(n1, nearest);
        let mut m = fast_across_moment(&s.offsets, &s.norm2, &mut s.gated, e1, n1);
        add_outer(&mut m, e1);
        add_scaled(&mut moment, m, weight);
        total += weight;
    }
    moment.map(|m| m / total)
}

/// [`across_moment`] over the offsets and their squared lengths.
#[inline(always)]
fn fast_across_moment(
    offsets: &[Point2],
    norm2s: &[f64],
    gated: &mut Vec<f64>,
    e1: Point2,
    n1: f64,
) -> [f64; 3] {
    let (closed, open) = GATE_COS2;
    gated.clear();
    // Branch-free, so that the loop runs in vector lanes: a closed gate
    // divides by zero, which gives the infinite distance it should.
    gated.extend(offsets.iter().zip(norm2s).map(|(e, &n)| {
        let dot = e[0] * e1[0] + e[1] * e1[1];
        let both = n * n1;
        let t = ((closed * both - dot * dot) / ((closed - open) * both)).clamp(0.0, 1.0);
        let gate = t * t * (3.0 - 2.0 * t);
        n / (gate * gate)
    }));
    let nearest = gated
        .iter()
        .fold(f64::INFINITY, |m, &g| if g < m { g } else { m });
    let mut moment = [0.0; 3];
    if !nearest.is_finite() {
        return moment;
    }
    let reach2 = (1.0 + BLEND_REACH) * (1.0 + BLEND_REACH);
    let mut total = 0.0;
    for (&e, &g) in offsets.iter().zip(gated.iter()) {
        if g < reach2 * nearest {
            let weight = blend_weight(g, nearest);
            let mut m = [0.0; 3];
            add_outer(&mut m, across_part(e, e1));
            add_scaled(&mut moment, m, weight);
            total += weight;
        }
    }
    moment.map(|m| m / total)
}

/// The blended S of `pts[0]` in the plane, as `[xx, xy, yy]`: the plain
/// form of the module doc's rule, the reference for the fast one.
#[cfg(test)]
fn planar_sampling_moment(pts: &[Point2]) -> [f64; 3] {
    let origin = pts[0];
    let offsets = || {
        pts[1..]
            .iter()
            .map(move |q| [q[0] - origin[0], q[1] - origin[1]])
            .filter(|&e| norm2(e) > 0.0)
    };
    let Some(nearest) = offsets().map(norm2).min_by(f64::total_cmp) else {
        return [0.0; 3];
    };
    let mut moment = [0.0; 3];
    let mut total = 0.0;
    for e1 in offsets() {
        let weight = blend_weight(norm2(e1), nearest);
        if weight > 0.0 {
            let mut s = across_moment(offsets(), e1);
            add_outer(&mut s, e1);
            add_scaled(&mut moment, s, weight);
            total += weight;
        }
    }
    moment.map(|m| m / total)
}

#[cfg(test)]
/// The blended e2 e2ᵀ for one e1, of the candidates' parts across e1's
/// line: the candidates weighted by their squared distance over their
/// squared gate, against the smallest such value; zero when no neighbour
/// lies 50° or more from e1's line.
fn across_moment(offsets: impl Iterator<Item = Point2> + Clone, e1: Point2) -> [f64; 3] {
    let gated = |e: Point2| {
        let gate = across_gate(e, e1);
        if gate > 0.0 {
            norm2(e) / (gate * gate)
        } else {
            f64::INFINITY
        }
    };
    let nearest = offsets.clone().map(gated).fold(f64::INFINITY, f64::min);
    let mut moment = [0.0; 3];
    if !nearest.is_finite() {
        return moment;
    }
    let mut total = 0.0;
    for e in offsets {
        let weight = blend_weight(gated(e), nearest);
        if weight > 0.0 {
            let mut s = [0.0; 3];
            add_outer(&mut s, across_part(e, e1));
            add_scaled(&mut moment, s, weight);
            total += weight;
        }
    }
    moment.map(|m| m / total)
}

/// The part of `e` perpendicular to `e1`: the spacing across e1's line.
/// On a line scan the neighbours on the next line, straight across or a
/// step along, all give the line spacing, so blending them keeps T exact.
#[inline(always)]
fn across_part(e: Point2, e1: Point2) -> Point2 {
    let along = (e[0] * e1[0] + e[1] * e1[1]) / norm2(e1);
    [e[0] - along * e1[0], e[1] - along * e1[1]]
}

/// 1 at `nearest` (a squared distance), falling smoothly (C¹) to 0 at
/// (1 + [`BLEND_REACH`])² times it.
#[inline(always)]
fn blend_weight(d2: f64, nearest: f64) -> f64 {
    let span = (1.0 + BLEND_REACH) * (1.0 + BLEND_REACH) - 1.0;
    let x = (d2 / nearest - 1.0) / span;
    if x < 1.0 {
        (1.0 - x) * (1.0 - x)
    } else {
        0.0
    }
}

/// How much `e` counts as across `e1`'s line: 0 within 50° of it, 1 beyond
/// 70°, a smoothstep in cos² between.
#[cfg(test)]
fn across_gate(e: Point2, e1: Point2) -> f64 {
    let dot = e[0] * e1[0] + e[1] * e1[1];
    let cos2 = dot * dot / (norm2(e) * norm2(e1));
    let (closed, open) = GATE_COS2;
    let t = ((closed - cos2) / (closed - open)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[inline(always)]
fn norm2(e: Point2) -> f64 {
    e[0] * e[0] + e[1] * e[1]
}

#[inline(always)]
fn add_scaled(sum: &mut [f64; 3], s: [f64; 3], weight: f64) {
    for (m, x) in sum.iter_mut().zip(s) {
        *m += weight * x;
    }
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

#[inline(always)]
fn add_outer(t: &mut [f64; 3], e: Point2) {
    t[0] += e[0] * e[0];
    t[1] += e[0] * e[1];
    t[2] += e[1] * e[1];
}

#[cfg(test)]
mod tests {
    use super::*;

    /// T of a planar point set, every point's moment found in the whole set.
    fn planar_tensor(pts: &[Point2]) -> [f64; 3] {
        let mut t = [0.0; 3];
        for j in 0..pts.len() {
            let mut own_first = pts.to_vec();
            own_first.swap(0, j);
            add_scaled(&mut t, planar_sampling_moment(&own_first), 1.0);
        }
        t
    }

    fn det(m: &Map2) -> f64 {
        m[0][0] * m[1][1] - m[0][1] * m[1][0]
    }

    fn moment_distance(a: [f64; 3], b: [f64; 3]) -> f64 {
        a.iter().zip(&b).map(|(x, y)| (x - y).abs()).sum()
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

    /// One clearly nearest neighbour and one clearly nearest across: the
    /// moment is e1 e1ᵀ + e2⊥ e2⊥ᵀ, lifted with the frame's axes.
    #[test]
    fn own_moment_lifts_to_the_tangent_plane() {
        let frame = Frame {
            u: [0.0, 1.0, 0.0],
            v: [0.0, 0.0, 1.0],
            normal: [1.0, 0.0, 0.0],
        };
        let pts = [[0.0, 0.0], [1.0, 0.0], [0.2, 3.0], [-5.0, 0.0]];
        let s = own_sampling_moment(&pts, &frame, &mut MomentScratch::default());
        assert_eq!(s, [0.0, 0.0, 0.0, 1.0, 0.0, 9.0]);
    }

    /// Where six neighbours tie for nearest, moving one by 10⁻⁶ of the
    /// spacing either way moves the moment by about as little. (A discrete
    /// choice of the nearest would turn e1 by 60° at −10⁻⁶.)
    #[test]
    fn moment_moves_little_where_neighbours_tie() {
        let hexagon = |nudge: f64| -> Vec<Point2> {
            let mut pts = vec![[0.0, 0.0]];
            pts.extend((0..6).map(|k| {
                let a = (k as f64 * 60.0 + 7.0).to_radians();
                let r = if k == 1 { 1.0 + nudge } else { 1.0 };
                [r * a.cos(), r * a.sin()]
            }));
            pts.extend([[2.1, 0.3], [-1.7, 1.9], [0.4, -2.2]]);
            pts
        };
        let base = planar_sampling_moment(&hexagon(0.0));
        for nudge in [1e-6, -1e-6] {
            let moved = planar_sampling_moment(&hexagon(nudge));
            assert!(moment_distance(base, moved) < 1e-5, "{base:?} {moved:?}");
        }
    }

    /// Random neighbourhoods moved by 10⁻⁹: the moment moves by at most a
    /// few 10⁻⁸ of its size (continuity), and it is finite and symmetric
    /// positive semi-definite.
    #[test]
    fn moment_is_continuous_on_random_neighbourhoods() {
        let mut rng = testkit::SplitMix64::new(5);
        for _ in 0..2000 {
            let n = 4 + (rng.unit() * 30.0) as usize;
            let mut pts: Vec<Point2> = vec![[0.0, 0.0]];
            pts.extend((1..n).map(|_| [rng.range(-3.0, 3.0), rng.range(-3.0, 3.0)]));
            let base = planar_sampling_moment(&pts);
            for p in pts.iter_mut().skip(1) {
                *p = [p[0] + rng.range(-1e-9, 1e-9), p[1] + rng.range(-1e-9, 1e-9)];
            }
            let moved = planar_sampling_moment(&pts);
            let size = base[0] + base[2];
            assert!(
                base[0] >= 0.0
                    && base[2] >= 0.0
                    && base[1] * base[1] <= base[0] * base[2] * (1.0 + 1e-12)
            );
            assert!(
                moment_distance(base, moved) <= 1e-6 * size,
                "{base:?} {moved:?}"
            );
        }
    }

    /// The fast moment equals the plain rule's to rounding, on random
    /// neighbourhoods, jittered lattices (many ties) and line scans.
    #[test]
    fn fast_moment_matches_the_reference() {
        let mut rng = testkit::SplitMix64::new(11);
        let mut scratch = MomentScratch::default();
        for case in 0..3000 {
            let n = 2 + (rng.unit() * 40.0) as usize;
            let pts: Vec<Point2> = match case % 3 {
                0 => (0..n)
                    .map(|_| [rng.range(-3.0, 3.0), rng.range(-3.0, 3.0)])
                    .collect(),
                1 => (0..n)
                    .map(|i| {
                        let (c, r) = ((i % 6) as f64, (i / 6) as f64);
                        let j = 0.02 * rng.range(-1.0, 1.0);
                        [c + 0.5 * (r % 2.0) + j, 0.866 * r + j]
                    })
                    .collect(),
                _ => (0..n)
                    .map(|i| {
                        [
                            (i % 7) as f64 * 0.25,
                            (i / 7) as f64 + rng.range(-0.05, 0.05),
                        ]
                    })
                    .collect(),
            };
            let plain = planar_sampling_moment(&pts);
            let fast = fast_planar_sampling_moment(&pts, &mut scratch);
            let size = plain[0] + plain[2];
            assert!(
                moment_distance(plain, fast) <= 1e-12 * size.max(1e-300),
                "case {case}: {plain:?} {fast:?}"
            );
        }
    }

    #[test]
    fn a_point_with_all_neighbours_on_it_has_no_moment() {
        let mut scratch = MomentScratch::default();
        for moment in [planar_sampling_moment, |p: &[Point2]| {
            fast_planar_sampling_moment(p, &mut MomentScratch::default())
        }] {
            assert_eq!(moment(&[[1.0, 2.0]; 5]), [0.0; 3]);
            // Collinear neighbours: e1 only, no e2 across.
            let line = [[0.0, 0.0], [1.0, 0.0], [-1.0, 0.0], [2.0, 0.0]];
            assert_eq!(moment(&line), [1.0, 0.0, 0.0]);
        }
        assert_eq!(
            fast_planar_sampling_moment(&[[0.0, 0.0]], &mut scratch),
            [0.0; 3]
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
            let members: Vec<[Point3; 2]> = (0..30).map(|_| [r(), r()]).collect();
            let mut plain = [0.0; 3];
            for e in members.iter().flatten() {
                add_outer(&mut plain, [dot(*e, frame.u), dot(*e, frame.v)]);
            }
            let moments: Vec<SamplingMoment> = members.iter().map(outer_sum).collect();
            let fast = sampling_tensor_of_moments(&frame, moments.iter());
            let size = plain[0].abs() + plain[2].abs();
            for (a, b) in plain.iter().zip(&fast) {
                assert!((a - b).abs() <= 1e-13 * size, "{plain:?} {fast:?}");
            }
        }
    }

    /// e eᵀ + f fᵀ of two 3D vectors, in the moment's layout.
    fn outer_sum([e, f]: &[Point3; 2]) -> SamplingMoment {
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
        let (a, b) = (outer(e), outer(f));
        [0, 1, 2, 3, 4, 5].map(|i| a[i] + b[i])
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
