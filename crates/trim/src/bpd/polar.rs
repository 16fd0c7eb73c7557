//! The surrounding-path test of BPD (section 2 of the paper, eqs. 2–5).
//!
//! "P_i is a boundary point if it is not possible to find a path that
//! surrounds it and passes through the neighbour points." In the projected
//! (and anisotropy-mapped) neighbourhood, with P_i at the pole:
//!
//! - polar coordinates (R_j, θ_j) of the neighbours;
//! - the angular sector spanned by them runs from θ_min to θ_max, taken as
//!   the complement of the largest empty angular gap (so the sector holds
//!   every neighbour and θ_max − θ_min < 2π);
//! - meshtrim's rule: when that gap is under 60°, P_i is surrounded (the
//!   neighbours in angular order wind once round it) and no path is
//!   linked (`SURROUNDED_BELOW_GAP`);
//! - normalisation, eqs. 2–3: r_j = (R_j − R_min)/(R_max − R_min),
//!   ϑ_j = (θ_j − θ_min)/(θ_max − θ_min) (r_j = 0 when all R_j are equal);
//! - start point, eq. 4: the minimum of γ_j = r_j + |ϑ_j − ϑ_bis| with
//!   ϑ_bis = ½, the bisector of the sector;
//! - linking, eq. 5: γ_p = r_p + c·|Δϑ_p|, where Δϑ_p is the angle from the
//!   last linked point to p taken the short way round (circularly, in
//!   (−π, π], divided by the sector width) and c = −1 when p keeps the
//!   direction of the previous step, +1 when it reverses it. As printed,
//!   (ϑ_p − ϑ_last)·c, the factor c cancels (both directions get −|Δϑ|·sgn of
//!   the previous step) and non-circular differences can never wind 2π; the
//!   magnitude form is the reading that does what the text says c is for:
//!   "any anti-clockwise rotation is penalised". The first step has no
//!   direction to keep, so it takes γ_p = r_p + |Δϑ_p|, the nearest point in
//!   angle and radius, like eq. 4;
//! - α = Σ Δθ and τ = Σ |Δθ| over the steps; linking stops when no
//!   neighbour is left or τ > 2π; P_i is a boundary point iff |α| < 2π.
//!
//! Ties, within `TIE` (10⁻⁹) (quantised clouds make angles, gaps and costs
//! exactly equal, and rounding must not choose): γ goes to the lower
//! neighbour index (neighbours are sorted by distance, then rank); equal
//! largest gaps to the sector starting first counting round from the
//! nearest neighbour; a half turn keeps the previous direction; a path
//! winding exactly 2π counts as surrounding P_i. So the result is
//! deterministic and does not move with the cloud (`docs/bpd.md`, "Ties
//! and duplicates").

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

use crate::frame::Point2;

/// Reusable buffers for [`surrounding_path_is_open`].
#[derive(Default, Debug, Clone)]
pub struct PolarScratch {
    theta: Vec<f64>,
    r: Vec<f64>,
    sector: SectorScratch,
    /// 0 for neighbours still free, +∞ for linked ones.
    blocked: Vec<f64>,
    cost: Vec<f64>,
}

/// Runs the surrounding-path test on neighbours `nb` (relative to P_i,
/// non-zero). Returns true when no path surrounds P_i: a boundary point.
// Baseline and AVX2 variants, chosen at run time (crate doc, "Vector kernels").
#[multiversion::multiversion(targets("x86_64+avx2"))]
pub fn surrounding_path_is_open(nb: &[Point2], s: &mut PolarScratch) -> bool {
    if nb.len() < 2 {
        return true;
    }
    s.theta.clear();
    s.theta.extend(nb.iter().map(|p| atan2(p[1], p[0])));
    let (theta_min, width) = occupied_sector(&s.theta, &mut s.sector);
    if width <= 0.0 {
        return true;
    }
    // A gap of exactly 60° (hexagonal quantised samplings) goes to the
    // linking, whatever the rounding.
    if TAU - width < SURROUNDED_BELOW_GAP - TIE {
        return false;
    }
    linked_path_is_open(nb, theta_min, width, s)
}

/// Eqs. 2–5 on neighbours whose angles are in `s.theta` and occupy the
/// sector from `theta_min`, `width` wide: links a path greedily from the
/// start point and says whether it fails to wind once round P_i.
// Always inlined: its loop is the one the AVX2 variant of the caller is for.
#[inline(always)]
fn linked_path_is_open(nb: &[Point2], theta_min: f64, width: f64, s: &mut PolarScratch) -> bool {
    // Radii into `r` first, normalised in place below (eq. 2). Local
    // coordinates are small and finite, so the plain formula cannot overflow.
    s.r.clear();
    s.r.extend(nb.iter().map(|p| (p[0] * p[0] + p[1] * p[1]).sqrt()));
    let (r_min, r_max) = s.r.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| {
        (if r < lo { r } else { lo }, if r > hi { r } else { hi })
    });
    let r_span = r_max - r_min;
    for r in s.r.iter_mut() {
        *r = if r_span > 0.0 {
            (*r - r_min) / r_span
        } else {
            0.0
        };
    }
    // Eq. 4: start nearest the pole and the sector's bisector.
    let normalised = |t: f64| wrap_positive(t - theta_min) / width;
    s.cost.clear();
    s.cost
        .extend((0..nb.len()).map(|j| s.r[j] + (normalised(s.theta[j]) - 0.5).abs()));
    let start = argmin(&s.cost);
    // Linked points are blocked by an infinite cost, so the costs of a
    // step are one branch-free loop over all neighbours, which vectorises.
    s.blocked.clear();
    s.blocked.resize(nb.len(), 0.0);
    s.blocked[start] = f64::INFINITY;
    s.cost.resize(nb.len(), 0.0);
    // A multiplication per cost instead of a division (eq. 5's Δϑ).
    let per_width = 1.0 / width;
    let (mut last, mut previous_turn) = (start, 0.0f64);
    let (mut alpha, mut tau) = (0.0f64, 0.0f64);
    for _ in 1..nb.len() {
        let theta_last = s.theta[last];
        for (((cost, &theta), &r), &blocked) in
            s.cost.iter_mut().zip(&s.theta).zip(&s.r).zip(&s.blocked)
        {
            let turn = circular_difference(theta, theta_last);
            // Eq. 5's c: −1 (a bonus) for keeping the previous direction.
            // A half turn has no direction of its own; it keeps the
            // previous one (rounding would otherwise pick its sign).
            let step = turn.abs() * per_width;
            let half_turn = turn.abs() >= PI - TIE;
            let keeps_direction = if half_turn {
                previous_turn != 0.0
            } else {
                turn * previous_turn > 0.0
            };
            *cost = blocked + if keeps_direction { r - step } else { r + step };
        }
        let next = argmin(&s.cost);
        let mut turn = circular_difference(s.theta[next], theta_last);
        if turn.abs() >= PI - TIE {
            turn = if previous_turn < 0.0 { -PI } else { PI };
        }
        alpha += turn;
        tau += turn.abs();
        if turn.abs() > TIE {
            previous_turn = turn;
        }
        s.blocked[next] = f64::INFINITY;
        last = next;
        // A path that winds exactly once (within ties) goes on, and
        // counts as surrounding P_i.
        if tau > TAU + TIE {
            break;
        }
    }
    alpha.abs() < TAU - TIE
}

/// Largest empty angular gap round P_i (radians, 60°) below which P_i is
/// surrounded without linking a path: the neighbours taken in angular
/// order then already form a path that winds once round it, each step
/// turning less than this. The linking of eq. 5 is greedy, and on
/// blue-noise samplings it can fail to close round a point deep inside
/// the surface (docs/bpd.md, "Points surrounded in every direction").
const SURROUNDED_BELOW_GAP: f64 = PI / 3.0;

/// Angles (radians) and costs closer than this are ties. Far above the
/// rounding of the local coordinates (about 10⁻¹¹ of a spacing for a cloud
/// 10⁵ spacings from the origin), where quantised clouds put neighbours at
/// exactly equal angles, costs and gaps; far below anything the test
/// weighs.
const TIE: f64 = 1e-9;

/// Start angle and width of the smallest sector holding all `theta` (in
/// [−π, π]): the complement of the largest gap between consecutive angles.
///
/// Without sorting (the sort cost more than the rest of the test): with the
/// circle cut into n buckets of width 2π/n, the n gaps sum to 2π, so the
/// largest is at least 2π/n and no gap inside a bucket can beat it; only
/// the gaps between one non-empty bucket's largest angle and the next one's
/// smallest count. Gaps within [`TIE`] of the largest tie, and the one
/// that starts first counting round from the nearest neighbour's angle
/// (`theta[0]`) wins, so that the choice follows the neighbours, not the
/// rounding or the ±π seam of the angles. The same result as
/// [`occupied_sector_sorted`] except where a gap inside a bucket ties with
/// the largest (all gaps within [`TIE`] of 2π/n).
///
/// Each pass is a plain loop over slices of exactly n buckets: the gap
/// before every bucket is written (−∞ for an empty one), so no pass
/// branches on which buckets are filled, and only the rare tie goes through
/// [`choose_gap`].
// Not inlined: inlined into the path test's AVX2 variant it took more
// instructions (12k benchmark: the path test 59.2M → 61.0M; kept apart,
// 54.7M).
#[inline(never)]
fn occupied_sector(theta: &[f64], s: &mut SectorScratch) -> (f64, f64) {
    let n = theta.len();
    if n == 0 {
        // No angles: no sector, which the caller reads as open.
        return (0.0, 0.0);
    }
    let per_bucket = n as f64 / TAU;
    // `as u32`: the same bucket as `as usize` for these small,
    // non-negative values, in fewer instructions.
    let bucket = |t: f64| ((((t + PI) * per_bucket) as u32) as usize).min(n - 1);
    s.lows.clear();
    s.lows.resize(n, f64::INFINITY);
    s.highs.clear();
    s.highs.resize(n, f64::NEG_INFINITY);
    s.gaps.clear();
    s.gaps.resize(n, f64::NEG_INFINITY);
    // Slices of length n: `bucket` is below n, so no bounds checks.
    let (lows, highs, gaps) = (&mut s.lows[..n], &mut s.highs[..n], &mut s.gaps[..n]);
    let (mut smallest, mut largest) = (f64::INFINITY, f64::NEG_INFINITY);
    for &t in theta {
        let b = bucket(t);
        // Comparisons, not `f64::min`/`max`, whose NaN handling costs
        // more (the angles are finite).
        lows[b] = if t < lows[b] { t } else { lows[b] };
        highs[b] = if t > highs[b] { t } else { highs[b] };
        smallest = if t < smallest { t } else { smallest };
        largest = if t > largest { t } else { largest };
    }
    // The gap before each bucket: from the largest angle of the buckets
    // below (an empty one's `hi` is −∞, so a running maximum) to its
    // smallest.
    let mut previous_high = f64::NEG_INFINITY;
    for b in 0..n {
        let (lo, hi) = (lows[b], highs[b]);
        gaps[b] = if lo <= hi {
            lo - previous_high
        } else {
            f64::NEG_INFINITY
        };
        previous_high = if hi > previous_high {
            hi
        } else {
            previous_high
        };
    }
    // The first filled bucket starts at the smallest angle; its gap wraps
    // round from the largest.
    gaps[bucket(smallest)] = smallest + TAU - largest;
    let widest = gaps
        .iter()
        .fold(f64::NEG_INFINITY, |m, &g| if g > m { g } else { m });
    let mut contenders = (0..n).filter(|&b| gaps[b] >= widest - TIE);
    if let (Some(b), None) = (contenders.next(), contenders.next()) {
        return (lows[b], TAU - gaps[b]);
    }
    // Ties: the filled buckets' gaps, in bucket order, for `choose_gap`.
    s.pairs.clear();
    s.pairs.extend(
        gaps.iter()
            .zip(lows.iter())
            .filter(|(&g, _)| g > f64::NEG_INFINITY)
            .map(|(&g, &lo)| (g, lo)),
    );
    choose_gap(&s.pairs, theta[0])
}

/// Reusable buffers for [`occupied_sector`], one slot per bucket.
#[derive(Default, Debug, Clone)]
struct SectorScratch {
    /// Smallest and largest angle in each bucket (±∞ when empty).
    lows: Vec<f64>,
    highs: Vec<f64>,
    /// The gap before each bucket, −∞ for empty ones.
    gaps: Vec<f64>,
    /// Ties only: (gap, angle where it ends) of the filled buckets.
    pairs: Vec<(f64, f64)>,
}

/// The sector left by the largest of `gaps` (gap, angle where it ends),
/// ties broken as [`occupied_sector`] says: (start, width).
fn choose_gap(gaps: &[(f64, f64)], theta_ref: f64) -> (f64, f64) {
    let largest = gaps.iter().fold(f64::NEG_INFINITY, |m, g| m.max(g.0));
    // Where a sector starts, counted from the reference direction; a start
    // within a tie of a full turn is the reference itself.
    let from_reference = |start: f64| {
        let a = wrap_positive(start - theta_ref);
        if a > TAU - TIE {
            0.0
        } else {
            a
        }
    };
    let (gap, start) = gaps
        .iter()
        .filter(|g| g.0 >= largest - TIE)
        .min_by(|a, b| from_reference(a.1).total_cmp(&from_reference(b.1)))
        .copied()
        // Only an all-NaN list (impossible: the angles come from finite
        // coordinates) has no largest gap.
        .unwrap_or(gaps[0]);
    (start, TAU - gap)
}

/// [`occupied_sector`] by sorting the angles; the reference for tests.
#[cfg(test)]
fn occupied_sector_sorted(theta: &[f64]) -> (f64, f64) {
    let mut sorted = theta.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    let mut gaps = vec![(sorted[0] + TAU - sorted[n - 1], sorted[0])];
    gaps.extend(sorted.windows(2).map(|w| (w[1] - w[0], w[1])));
    choose_gap(&gaps, theta[0])
}

/// `a − b` wrapped into (−π, π], for angles from `atan2` (in [−π, π]), whose
/// difference lies in [−2π, 2π]; avoids the slow floating-point remainder.
fn circular_difference(a: f64, b: f64) -> f64 {
    let d = a - b;
    if d > PI {
        d - TAU
    } else if d <= -PI {
        d + TAU
    } else {
        d
    }
}

/// An angle difference in [−2π, 2π] moved into [0, 2π).
fn wrap_positive(d: f64) -> f64 {
    if d < 0.0 {
        d + TAU
    } else if d >= TAU {
        d - TAU
    } else {
        d
    }
}

/// atan2(y, x) in [−π, π], within a few ulps of the library's, without
/// branches or calls so the loop over a neighbourhood vectorises (the
/// library call takes a third of the test's time). Cephes' atan: the ratio
/// of the smaller to the larger coordinate, t ∈ [0, 1], is moved below
/// 0.66 by atan t = π/4 + atan((t − 1)/(t + 1)), then a degree 4/5
/// rational approximation in t².
pub(crate) fn atan2(y: f64, x: f64) -> f64 {
    const P: [f64; 5] = [
        -8.750_608_600_031_904e-1,
        -1.615_753_718_733_365e1,
        -7.500_855_792_314_705e1,
        -1.228_866_684_490_136_2e2,
        -6.485_021_904_942_025e1,
    ];
    const Q: [f64; 5] = [
        2.485_846_490_142_306_3e1,
        1.650_270_098_316_988_6e2,
        4.328_810_604_912_903e2,
        4.853_903_996_359_137e2,
        1.945_506_571_482_614e2,
    ];
    const MORE_BITS: f64 = 6.123_233_995_736_766e-17; // π/2 − f64(π/2)
    let (ax, ay) = (x.abs(), y.abs());
    let steep = ay > ax;
    let (small, big) = if steep { (ax, ay) } else { (ay, ax) };
    let t = if big > 0.0 { small / big } else { 0.0 };
    let shifted = t > 0.66;
    let u = if shifted { (t - 1.0) / (t + 1.0) } else { t };
    let z = u * u;
    let p = (((P[0] * z + P[1]) * z + P[2]) * z + P[3]) * z + P[4];
    let q = ((((z + Q[0]) * z + Q[1]) * z + Q[2]) * z + Q[3]) * z + Q[4];
    let mut a = u * (z * p / q) + u;
    if shifted {
        a += FRAC_PI_4 + 0.5 * MORE_BITS;
    }
    if steep {
        a = FRAC_PI_2 - a + MORE_BITS;
    }
    if x < 0.0 {
        a = PI - a + 2.0 * MORE_BITS;
    }
    if y < 0.0 {
        -a
    } else {
        a
    }
}

/// Index of the smallest cost; on ties (costs within [`TIE`]) the first,
/// which is the nearest neighbour, then the lowest rank.
fn argmin(cost: &[f64]) -> usize {
    // Four independent minima: one running minimum is a chain of dependent
    // instructions, which the compiler may not reorder for floats (the
    // minimum itself does not depend on the order).
    let mut lanes = [f64::INFINITY; 4];
    let chunks = cost.chunks_exact(4);
    let rest = chunks.remainder();
    for chunk in chunks {
        for (m, &c) in lanes.iter_mut().zip(chunk) {
            *m = if c < *m { c } else { *m };
        }
    }
    let least = lanes
        .iter()
        .chain(rest)
        .fold(f64::INFINITY, |m, &c| if c < m { c } else { m });
    cost.iter().position(|&c| c <= least + TIE).unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ring(n: usize, radius: f64, from: f64, to: f64) -> Vec<Point2> {
        (0..n)
            .map(|i| {
                let t = from + (to - from) * i as f64 / (n - 1) as f64;
                [radius * t.cos(), radius * t.sin()]
            })
            .collect()
    }

    /// Twelve neighbours of a blue-noise sampling (no two closer than 0.8)
    /// all round P_i, the largest angular gap 44°: the greedy linking of
    /// eq. 5 does not close round P_i, the angular-gap rule does.
    #[test]
    fn point_with_no_wide_gap_is_surrounded_where_the_linking_fails() {
        let nb = [
            [0.95, 0.03],
            [-0.50, 1.30],
            [1.56, 0.63],
            [-1.62, 1.15],
            [0.30, 1.71],
            [-1.93, -0.33],
            [1.39, -1.02],
            [-0.43, -1.93],
            [0.37, 0.86],
            [0.46, -0.90],
            [-0.87, -0.58],
            [-0.92, 0.54],
        ];
        let mut s = PolarScratch::default();
        s.theta.extend(nb.iter().map(|p| atan2(p[1], p[0])));
        let (theta_min, width) = occupied_sector(&s.theta, &mut s.sector);
        let gap = TAU - width;
        assert!(gap < SURROUNDED_BELOW_GAP, "gap {gap}");
        assert!(linked_path_is_open(&nb, theta_min, width, &mut s));
        assert!(!surrounding_path_is_open(&nb, &mut s));
    }

    #[test]
    fn point_inside_a_full_ring_is_surrounded() {
        let mut nb = ring(12, 1.0, 0.0, TAU * 11.0 / 12.0);
        nb.extend(ring(17, 2.0, 0.1, 0.1 + TAU * 16.0 / 17.0));
        assert!(!surrounding_path_is_open(&nb, &mut PolarScratch::default()));
    }

    #[test]
    fn point_on_the_hull_is_open() {
        let mut nb = ring(10, 1.0, 0.0, 0.9 * PI);
        nb.extend(ring(19, 2.0, 0.05, 0.9 * PI));
        assert!(surrounding_path_is_open(&nb, &mut PolarScratch::default()));
    }

    #[test]
    fn bucketed_sector_matches_sorting_on_random_angles() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let mut sector = SectorScratch::default();
        for case in 0..2000 {
            let n = 1 + case % 40;
            // Clustered angles (a sector), spread ones, and the ends ±π.
            let spread = [0.3, 2.0, TAU][case % 3];
            let centre = rng.random_range(-PI..PI);
            let mut theta: Vec<f64> = (0..n)
                .map(|_| {
                    let t = centre + rng.random_range(-0.5..0.5) * spread;
                    circular_difference(t, 0.0)
                })
                .collect();
            if case % 7 == 0 {
                theta[0] = PI;
                theta[n - 1] = -PI;
            }
            assert_eq!(
                occupied_sector(&theta, &mut sector),
                occupied_sector_sorted(&theta),
                "{theta:?}"
            );
        }
    }

    #[test]
    fn atan2_is_within_a_few_ulps_of_the_library() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(8);
        let mut worst: f64 = 0.0;
        for i in 0..200_000 {
            let scale = 10f64.powi(rng.random_range(-8..8));
            let (y, x) = match i % 5 {
                0 => (0.0, rng.random_range(-1.0..1.0)),
                1 => (rng.random_range(-1.0..1.0), 0.0),
                2 => {
                    let v = rng.random_range(-1.0..1.0);
                    (v, v * [1.0, -1.0][i % 2])
                }
                _ => (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)),
            };
            let (y, x) = (y * scale, x * scale);
            let want = y.atan2(x);
            let got = atan2(y, x);
            assert!(got.abs() <= PI, "atan2({y}, {x}) = {got}");
            worst = worst.max((got - want).abs() / want.abs().max(1e-300).max(f64::EPSILON));
        }
        assert!(worst < 4.0 * f64::EPSILON, "worst relative error {worst:e}");
    }

    #[test]
    fn circular_difference_takes_the_short_way() {
        assert!((circular_difference(3.0, -3.0) - (6.0 - TAU)).abs() < 1e-12);
        assert!((circular_difference(-3.0, 3.0) - (TAU - 6.0)).abs() < 1e-12);
        assert_eq!(circular_difference(PI, 0.0), PI);
    }

    /// Quantised angles (multiples of π/4, as quantised clouds give) tie
    /// for the largest gap; the tie rule picks the same sector either way.
    #[test]
    fn bucketed_sector_breaks_ties_as_sorting_does() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut sector = SectorScratch::default();
        let mut tied = 0;
        for case in 0..2000 {
            let n = 2 + case % 30;
            let theta: Vec<f64> = (0..n)
                .map(|_| circular_difference(f64::from(rng.random_range(-4..4)) * FRAC_PI_4, 0.0))
                .collect();
            let (_, width) = occupied_sector_sorted(&theta);
            let gap = TAU - width;
            let mut sorted = theta.clone();
            sorted.sort_by(f64::total_cmp);
            let ties = sorted
                .windows(2)
                .filter(|w| (w[1] - w[0] - gap).abs() <= TIE)
                .count()
                + usize::from((sorted[0] + TAU - sorted[n - 1] - gap).abs() <= TIE);
            tied += usize::from(ties > 1);
            assert_eq!(
                occupied_sector(&theta, &mut sector),
                occupied_sector_sorted(&theta),
                "{theta:?}"
            );
        }
        assert!(tied > 100, "only {tied} cases with tied gaps");
    }
}
