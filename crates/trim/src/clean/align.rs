//! Where the wall's vertices lie along the smoothed loop (step 4 of the
//! strip): each wall vertex gets a segment of the loop, in order, so that
//! the squared distances from the vertices to their segments sum to the
//! least (a monotone alignment by dynamic programming, as dynamic time
//! warping aligns two series).
//!
//! Following the nearest segment from vertex to vertex gets lost where the
//! wall cuts across a stretch of the loop: where the cut of a cropped scan
//! runs straight across a bay of the smoothed loop, the next wall vertex's
//! nearest segment lies 70 segments on, and a search a few dozen segments
//! ahead finds only the bay's near side, then follows it back. The
//! alignment weighs the whole wall at once, so it skips the bay, and a
//! neck of the surface (two stretches of the loop close in space, far
//! apart along it) draws no vertex across, since the vertices after it
//! would lie far from their segments.

use crate::geom::{segment_dist2, segment_param, Point3};
use crate::spatial::PointTree;
use std::num::NonZeroUsize;

/// Above this many wall vertex × segment pairs, each wall vertex is
/// aligned only with the segments round its nearest guide vertices
/// ([`CANDIDATES`]): the full table grows as the square of the loop's
/// length (a 2,160-vertex wall on a 2,330-segment loop: 37 ms).
const FULL_TABLE_LIMIT: usize = 16_000_000;
/// Guide vertices round which a wall vertex's segments are taken when the
/// table is not full.
const CANDIDATES: usize = 64;

/// The wall's positions along the guide: arc length from the place of the
/// first wall vertex (`start`: its segment and the position along it, 0
/// to 1), non-decreasing and at most the loop's length. `guide` is the
/// closed loop's vertices, `arc` the arc length at each vertex (one more
/// entry than vertices: the last is the loop's length).
pub(super) fn place_along(
    guide: &[Point3],
    arc: &[f64],
    wall: &[Point3],
    start: (usize, f64),
) -> Vec<f64> {
    let m = guide.len();
    if m == 0 || wall.is_empty() {
        return vec![0.0; wall.len()];
    }
    let segments = if wall.len() * (m + 1) <= FULL_TABLE_LIMIT {
        cheapest_segments(guide, wall, start.0)
    } else {
        cheapest_near_segments(guide, wall, start.0)
    };
    let length = arc[m];
    let origin = arc[start.0] + start.1 * (arc[start.0 + 1] - arc[start.0]);
    let mut placed = Vec::with_capacity(wall.len());
    let mut last = 0.0;
    for (i, &s) in segments.iter().enumerate() {
        let j = (start.0 + s) % m;
        let (a, b) = (guide[j], guide[(j + 1) % m]);
        let t = if i == 0 {
            start.1
        } else {
            segment_param(wall[i], a, b)
        };
        // Arc length from the guide's vertex 0, unwrapped past the start.
        let at = arc[j] + t * (arc[j + 1] - arc[j]) + if start.0 + s >= m { length } else { 0.0 };
        // max and min rather than clamp: a position that is not a number
        // stays where the last one was.
        last = (at - origin).max(last).min(length);
        placed.push(last);
    }
    placed
}

/// The squared distance from `p` to segment `s` of the guide, counted
/// from segment `first`.
fn segment_cost(guide: &[Point3], first: usize, p: Point3, s: usize) -> f64 {
    let m = guide.len();
    let j = (first + s) % m;
    segment_dist2(p, guide[j], guide[(j + 1) % m])
}

/// For each wall vertex, its segment counted from the start segment
/// (0 to m: m is the start segment again, after a whole turn), non-
/// decreasing, the first at 0, with the least sum of squared distances.
fn cheapest_segments(guide: &[Point3], wall: &[Point3], first: usize) -> Vec<usize> {
    let m = guide.len();
    let columns = m + 1;
    let cost = |i: usize, s: usize| segment_cost(guide, first, wall[i], s);
    // total[s]: the least cost of the vertices so far with the last on
    // segment s. minima[i]: the segments at which the running minimum of
    // vertex i − 1's totals falls, ascending: vertex i − 1's segment, for
    // vertex i on segment s, is the last of them up to s. The running
    // minimum falls seldom, so they are few.
    let mut total = vec![f64::INFINITY; columns];
    total[0] = 0.0;
    let mut minima: Vec<Vec<usize>> = vec![Vec::new(); wall.len()];
    let mut next = vec![0.0; columns];
    for (i, falls) in minima.iter_mut().enumerate().skip(1) {
        let mut best = f64::INFINITY;
        for s in 0..columns {
            if total[s] < best {
                best = total[s];
                falls.push(s);
            }
            next[s] = best + cost(i, s);
        }
        std::mem::swap(&mut total, &mut next);
    }
    let mut s = (0..columns)
        .min_by(|&a, &b| total[a].total_cmp(&total[b]).then(a.cmp(&b)))
        .unwrap_or(0);
    let mut segments = vec![0; wall.len()];
    for i in (1..wall.len()).rev() {
        segments[i] = s;
        let k = minima[i].partition_point(|&from| from <= s);
        s = k.checked_sub(1).map_or(0, |k| minima[i][k]);
    }
    segments
}

/// [`cheapest_segments`] with each wall vertex's segments limited to those
/// round its [`CANDIDATES`] nearest guide vertices, and the previous wall
/// vertex's cheapest segment (so that an order-keeping choice always
/// exists).
fn cheapest_near_segments(guide: &[Point3], wall: &[Point3], first: usize) -> Vec<usize> {
    let m = guide.len();
    let Some(tree) = PointTree::new(guide) else {
        return vec![0; wall.len()];
    };
    let k = NonZeroUsize::new(CANDIDATES.min(m)).unwrap_or(NonZeroUsize::MIN);
    let cost = |i: usize, s: usize| segment_cost(guide, first, wall[i], s);
    // Segment j counted from the start segment, 0 to m − 1 (and m: the
    // start segment after a whole turn).
    let counted = |j: usize| (j + m - first) % m;
    // Per wall vertex: its candidate segments, ascending, with the least
    // cost of the vertices so far ending there and the predecessor's index.
    let mut rows: Vec<Vec<(usize, f64, usize)>> = Vec::with_capacity(wall.len());
    rows.push(vec![(0, 0.0, 0)]);
    for i in 1..wall.len() {
        let previous = &rows[i - 1];
        // The previous vertex's cheapest segment: staying there is always
        // in order.
        let cheapest = previous
            .iter()
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
            .map_or(0, |c| c.0);
        let mut candidates: Vec<usize> = vec![cheapest];
        for (_, v) in tree.nearest_n(&wall[i], k) {
            let v = v as usize;
            for j in [(v + m - 1) % m, v] {
                let s = counted(j);
                candidates.push(s);
                if s == 0 {
                    candidates.push(m);
                }
            }
        }
        candidates.sort_unstable();
        candidates.dedup();
        let mut row = Vec::with_capacity(candidates.len());
        let (mut best, mut best_at, mut p) = (f64::INFINITY, 0, 0);
        for s in candidates {
            while p < previous.len() && previous[p].0 <= s {
                if previous[p].1 < best {
                    best = previous[p].1;
                    best_at = p;
                }
                p += 1;
            }
            if best.is_finite() {
                row.push((s, best + cost(i, s), best_at));
            }
        }
        rows.push(row);
    }
    let last = rows.last().map_or(&[][..], |r| &r[..]);
    let mut at = (0..last.len())
        .min_by(|&a, &b| last[a].1.total_cmp(&last[b].1).then(a.cmp(&b)))
        .unwrap_or(0);
    let mut segments = vec![0; wall.len()];
    for i in (1..wall.len()).rev() {
        // Every row holds a finite total when the coordinates are finite.
        let Some(&(s, _, before)) = rows[i].get(at) else {
            break;
        };
        segments[i] = s;
        at = before;
    }
    segments
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edges::smooth::arc_lengths;
    use rand::{RngExt, SeedableRng};

    fn circle(m: usize, radius: f64) -> Vec<Point3> {
        (0..m)
            .map(|j| {
                let a = std::f64::consts::TAU * j as f64 / m as f64;
                [radius * a.cos(), radius * a.sin(), 0.0]
            })
            .collect()
    }

    /// `n` points in a flat box, 2 × 2 × 0.4.
    fn random_points(rng: &mut rand_chacha::ChaCha8Rng, n: usize) -> Vec<Point3> {
        (0..n)
            .map(|_| {
                [
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-0.2..0.2),
                ]
            })
            .collect()
    }

    /// The least cost over every non-decreasing choice of segments, by
    /// enumeration.
    fn least_cost(guide: &[Point3], wall: &[Point3], first: usize) -> f64 {
        let m = guide.len();
        let cost = |i: usize, s: usize| segment_cost(guide, first, wall[i], s);
        fn walk(
            i: usize,
            from: usize,
            n: usize,
            m: usize,
            cost: &dyn Fn(usize, usize) -> f64,
        ) -> f64 {
            if i == n {
                return 0.0;
            }
            (from..=m)
                .map(|s| cost(i, s) + walk(i + 1, s, n, m, cost))
                .fold(f64::INFINITY, f64::min)
        }
        walk(1, 0, wall.len(), m, &cost)
    }

    #[test]
    fn the_alignment_is_the_cheapest_monotone_one() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for _ in 0..200 {
            let m = rng.random_range(3..7);
            let p = rng.random_range(1..6);
            let guide = random_points(&mut rng, m);
            let wall = random_points(&mut rng, p);
            let first = rng.random_range(0..m);
            let segments = cheapest_segments(&guide, &wall, first);
            assert!(segments.windows(2).all(|w| w[0] <= w[1]) && segments[0] == 0);
            let cost: f64 = (1..p)
                .map(|i| segment_cost(&guide, first, wall[i], segments[i]))
                .sum();
            let best = least_cost(&guide, &wall, first);
            assert!(
                (cost - best).abs() <= 1e-12 * (1.0 + best),
                "{cost} vs {best}"
            );
        }
    }

    /// A circle of `m` segments with a bay pulled in between two random
    /// places, and a wall of `p` vertices just outside the circle, both
    /// with noise.
    fn bay_and_wall(
        rng: &mut rand_chacha::ChaCha8Rng,
        m: usize,
        p: usize,
    ) -> (Vec<Point3>, Vec<Point3>) {
        let from = rng.random_range(0..m / 2);
        let to = from + rng.random_range(m / 8..m / 2);
        let depth = rng.random_range(0.2..0.7);
        let mut guide = circle(m, 10.0);
        for (j, q) in guide.iter_mut().enumerate() {
            let mut r = 1.0 + rng.random_range(-0.01..0.01);
            if (from..to).contains(&j) {
                r -= depth * ((j - from) as f64 / (to - from) as f64 * std::f64::consts::PI).sin();
            }
            *q = [q[0] * r, q[1] * r, rng.random_range(-0.02..0.02)];
        }
        let wall = circle(p, 10.2)
            .into_iter()
            .map(|q| {
                [
                    q[0] + rng.random_range(-0.1..0.1),
                    q[1] + rng.random_range(-0.1..0.1),
                    0.0,
                ]
            })
            .collect();
        (guide, wall)
    }

    #[test]
    fn the_near_segments_agree_with_the_full_table() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for _ in 0..40 {
            let m = rng.random_range(40..400);
            let p = rng.random_range(40..400);
            let (guide, wall) = bay_and_wall(&mut rng, m, p);
            // As the zip starts: on the first wall vertex's nearest segment.
            let first = (0..m)
                .min_by(|&a, &b| {
                    let d = |j: usize| segment_cost(&guide, 0, wall[0], j);
                    d(a).total_cmp(&d(b))
                })
                .unwrap_or(0);
            assert_eq!(
                cheapest_near_segments(&guide, &wall, first),
                cheapest_segments(&guide, &wall, first),
                "m {m} p {p}"
            );
        }
    }

    #[test]
    fn a_wall_vertex_not_a_number_is_placed_without_a_panic() {
        let guide = circle(50, 10.0);
        let arc = arc_lengths(&guide, true);
        let mut wall = circle(60, 10.2);
        wall[7] = [f64::NAN, 0.0, 0.0];
        for first in [0, 13] {
            let full = cheapest_segments(&guide, &wall, first);
            let near = cheapest_near_segments(&guide, &wall, first);
            assert_eq!((full.len(), near.len()), (60, 60));
        }
        let placed = place_along(&guide, &arc, &wall, (0, 0.0));
        assert!(placed.windows(2).all(|w| w[0] <= w[1]), "{placed:?}");
    }

    #[test]
    fn a_wall_cutting_across_a_bay_skips_it() {
        // A circle of 200 segments with a deep bay cut into one side
        // (segments 40 to 120 pulled in), and a wall just outside the
        // circle that runs straight across the bay's mouth.
        let m = 200;
        let mut guide = circle(m, 10.0);
        for (j, p) in guide.iter_mut().enumerate().take(120).skip(40) {
            let depth = 1.0 - 0.6 * ((j - 40) as f64 / 80.0 * std::f64::consts::PI).sin();
            *p = [p[0] * depth, p[1] * depth, 0.0];
        }
        let outside = circle(400, 10.3);
        let wall: Vec<Point3> = outside.iter().step_by(2).copied().collect();
        let arc = arc_lengths(&guide, true);
        let placed = place_along(&guide, &arc, &wall, (0, 0.0));
        assert!(placed.windows(2).all(|w| w[0] <= w[1]));
        // The wall goes round once.
        assert!(
            placed[wall.len() - 1] > 0.95 * arc[m],
            "{:?}",
            placed.last()
        );
        // Past the bay, the wall vertices are placed past it on the loop.
        let past_bay = arc[125];
        assert!(placed[130] > past_bay, "{} vs {past_bay}", placed[130]);
    }
}
