//! Ordering a cluster of boundary points into a closed loop (section 3 of
//! the paper: "the clustered points can be ordered through algorithms
//! capable of solving the so called travelling salesman problem").
//!
//! The tour is built and improved as a Euclidean travelling-salesman tour:
//! - clusters of up to [`EXACT_MAX`] points are solved exactly;
//! - larger ones start from a greedy-edge tour over candidate edges (the
//!   cluster's boundary links, which usually already form the loop, and each
//!   point's nearest cluster members), whose fragments are joined nearest
//!   end first;
//! - then 2-opt and Or-opt (moving runs of 1–3 points) moves over the
//!   candidate lists are applied until none shortens the tour. A 2-opt-
//!   optimal tour in the plane does not cross itself.
//!
//! Everything is sequential and tie-broken by index: the same cluster gives
//! the same tour.

use std::num::NonZeroUsize;

use crate::geom::UnionFind;
use crate::geom::{dist2, Point3};
use crate::spatial::PointTree;

/// Clusters up to this size get the exact shortest tour.
pub(crate) const EXACT_MAX: usize = 8;

/// Nearest cluster members considered for each point's moves.
const CANDIDATES: usize = 8;

/// The closed tour through `members` (indices into `points`), starting at
/// the smallest index. `links` (pairs of member indices) are preferred
/// edges for the first tour.
pub fn closed_tour(points: &[Point3], members: &[u32], links: &[[u32; 2]]) -> Vec<u32> {
    let local: Vec<Point3> = members.iter().map(|&m| points[m as usize]).collect();
    let tour = if local.len() <= EXACT_MAX {
        exact_tour(&local)
    } else {
        let local_links = to_local(members, links);
        let candidates = candidate_lists(&local, &local_links);
        let mut tour = greedy_tour(&local, &candidates, &local_links);
        improve(&local, &candidates, &mut tour);
        tour
    };
    canonical(tour.iter().map(|&t| members[t as usize]).collect())
}

/// Length of a closed tour (indices into `points`).
pub fn tour_length(points: &[Point3], tour: &[u32]) -> f64 {
    (0..tour.len())
        .map(|i| dist(points, tour[i], tour[(i + 1) % tour.len()]))
        .sum()
}

fn dist(points: &[Point3], a: u32, b: u32) -> f64 {
    dist2(points[a as usize], points[b as usize]).sqrt()
}

/// Rotates the tour to start at its smallest index, and orients it so the
/// second entry is the smaller of that point's two tour neighbours.
pub(crate) fn canonical(mut tour: Vec<u32>) -> Vec<u32> {
    let Some(start) = (0..tour.len()).min_by_key(|&i| tour[i]) else {
        return tour;
    };
    tour.rotate_left(start);
    if tour.len() > 2 && tour[tour.len() - 1] < tour[1] {
        tour[1..].reverse();
    }
    tour
}

fn to_local(members: &[u32], links: &[[u32; 2]]) -> Vec<[u32; 2]> {
    let local = |m: u32| members.binary_search(&m).ok().map(|i| i as u32);
    links
        .iter()
        .filter_map(|&[a, b]| Some([local(a)?, local(b)?]))
        .collect()
}

/// Shortest tour by trying every order (point 0 first).
fn exact_tour(pts: &[Point3]) -> Vec<u32> {
    let n = pts.len() as u32;
    if n <= 3 {
        return (0..n).collect();
    }
    let mut rest: Vec<u32> = (1..n).collect();
    let mut best = (f64::INFINITY, Vec::new());
    loop {
        let tour: Vec<u32> = std::iter::once(0).chain(rest.iter().copied()).collect();
        let len = tour_length(pts, &tour);
        if len < best.0 {
            best = (len, tour);
        }
        if !next_permutation(&mut rest) {
            break;
        }
    }
    best.1
}

/// Advances to the next lexicographic permutation; false after the last.
fn next_permutation(v: &mut [u32]) -> bool {
    let Some(i) = (1..v.len()).rev().find(|&i| v[i - 1] < v[i]) else {
        return false;
    };
    let j = (i..v.len())
        .rev()
        .find(|&j| v[j] > v[i - 1])
        .expect("exists");
    v.swap(i - 1, j);
    v[i..].reverse();
    true
}

/// For each point, its linked points and nearest cluster members, without
/// repeats, nearest first.
fn candidate_lists(pts: &[Point3], links: &[[u32; 2]]) -> Vec<Vec<u32>> {
    let tree = PointTree::new(pts).expect("a cluster fits in the tree's index");
    let want = NonZeroUsize::new((CANDIDATES + 1).min(pts.len())).expect("non-empty");
    let mut lists: Vec<Vec<u32>> = pts
        .iter()
        .enumerate()
        .map(|(i, p)| {
            tree.nearest_n(p, want)
                .into_iter()
                .map(|(_, j)| j)
                .filter(|&j| j as usize != i)
                .collect()
        })
        .collect();
    for &[a, b] in links {
        lists[a as usize].push(b);
        lists[b as usize].push(a);
    }
    for (i, list) in lists.iter_mut().enumerate() {
        let p = pts[i];
        list.sort_unstable_by(|&a, &b| {
            dist2(p, pts[a as usize])
                .total_cmp(&dist2(p, pts[b as usize]))
                .then(a.cmp(&b))
        });
        list.dedup();
    }
    lists
}

/// Greedy-edge tour: shortest candidate edges first (links before others
/// of the same length), no vertex of degree 3, no early cycle; the
/// remaining path fragments are then joined nearest ends first.
fn greedy_tour(pts: &[Point3], candidates: &[Vec<u32>], links: &[[u32; 2]]) -> Vec<u32> {
    let n = pts.len();
    let mut edges: Vec<(f64, u32, u32)> = candidates
        .iter()
        .enumerate()
        .flat_map(|(a, list)| list.iter().map(move |&b| (a as u32, b)))
        .chain(links.iter().map(|&[a, b]| (a, b)))
        .filter(|&(a, b)| a != b)
        .map(|(a, b)| (dist(pts, a, b), a.min(b), a.max(b)))
        .collect();
    edges.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
    edges.dedup_by(|x, y| x.1 == y.1 && x.2 == y.2);
    let mut adjacency = vec![[u32::MAX; 2]; n];
    let mut degree = vec![0u8; n];
    let mut sets = UnionFind::new(n);
    let mut added = 0;
    let add = |a: u32, b: u32, adjacency: &mut [[u32; 2]], degree: &mut [u8]| {
        adjacency[a as usize][degree[a as usize] as usize] = b;
        adjacency[b as usize][degree[b as usize] as usize] = a;
        degree[a as usize] += 1;
        degree[b as usize] += 1;
    };
    for &(_, a, b) in &edges {
        if degree[a as usize] < 2
            && degree[b as usize] < 2
            && sets.find(a) != sets.find(b)
            && added + 1 < n
        {
            sets.union(a, b);
            add(a, b, &mut adjacency, &mut degree);
            added += 1;
        }
    }
    // Join the fragments: repeatedly link the closest pair of free ends
    // that lie on different fragments, then close the last one.
    while added + 1 < n {
        let ends: Vec<u32> = (0..n as u32).filter(|&i| degree[i as usize] < 2).collect();
        let mut best = (f64::INFINITY, 0, 0);
        for (x, &a) in ends.iter().enumerate() {
            for &b in &ends[x + 1..] {
                let d = dist(pts, a, b);
                if d < best.0 && sets.find(a) != sets.find(b) {
                    best = (d, a, b);
                }
            }
        }
        let (_, a, b) = best;
        sets.union(a, b);
        add(a, b, &mut adjacency, &mut degree);
        added += 1;
    }
    let ends: Vec<u32> = (0..n as u32).filter(|&i| degree[i as usize] < 2).collect();
    walk_path(&adjacency, ends[0])
}

/// Follows a Hamiltonian path from one of its ends.
fn walk_path(adjacency: &[[u32; 2]], start: u32) -> Vec<u32> {
    let mut tour = vec![start];
    let mut previous = u32::MAX;
    let mut at = start;
    while tour.len() < adjacency.len() {
        let next = adjacency[at as usize]
            .into_iter()
            .find(|&x| x != u32::MAX && x != previous)
            .expect("a Hamiltonian path");
        previous = at;
        at = next;
        tour.push(at);
    }
    tour
}

/// Applies improving 2-opt and Or-opt moves until there are none.
fn improve(pts: &[Point3], candidates: &[Vec<u32>], tour: &mut Vec<u32>) {
    // Each accepted move shortens the tour by a relative margin, so this
    // terminates; the cap only guards against pathological inputs.
    for _ in 0..1000 {
        let changed_2 = two_opt_pass(pts, candidates, tour);
        let changed_or = or_opt_pass(pts, candidates, tour);
        if !changed_2 && !changed_or {
            break;
        }
    }
}

/// True when replacing length `old` by `new` is a real improvement, not
/// rounding.
fn shorter(new: f64, old: f64) -> bool {
    new < old * (1.0 - 1e-12)
}

fn positions(tour: &[u32]) -> Vec<usize> {
    let mut pos = vec![0; tour.len()];
    for (i, &t) in tour.iter().enumerate() {
        pos[t as usize] = i;
    }
    pos
}

/// One sweep of 2-opt: for the tour edge (a, next(a)) and each candidate c
/// of a, try replacing (a, a') and (c, c') by (a, c) and (a', c').
fn two_opt_pass(pts: &[Point3], candidates: &[Vec<u32>], tour: &mut [u32]) -> bool {
    let n = tour.len();
    let mut pos = positions(tour);
    let mut changed = false;
    for i in 0..n {
        let a = tour[i];
        let a_next = tour[(i + 1) % n];
        let d_a = dist(pts, a, a_next);
        for &c in &candidates[a as usize] {
            let d_ac = dist(pts, a, c);
            if d_ac >= d_a {
                break; // candidates are sorted: no later one can gain
            }
            let j = pos[c as usize];
            let c_next = tour[(j + 1) % n];
            if c == a_next || c_next == a {
                continue;
            }
            let old = d_a + dist(pts, c, c_next);
            let new = d_ac + dist(pts, a_next, c_next);
            if shorter(new, old) {
                reverse_between(tour, &mut pos, (i + 1) % n, j);
                changed = true;
                break;
            }
        }
    }
    changed
}

/// Reverses the circular tour segment from position `from` to `to`
/// (inclusive), keeping `pos` in step.
fn reverse_between(tour: &mut [u32], pos: &mut [usize], from: usize, to: usize) {
    let n = tour.len();
    let len = (to + n - from) % n + 1;
    for step in 0..len / 2 {
        let (x, y) = ((from + step) % n, (to + n - step) % n);
        tour.swap(x, y);
        pos[tour[x] as usize] = x;
        pos[tour[y] as usize] = y;
    }
}

/// One sweep of Or-opt: moves a run of 1–3 consecutive points between a
/// candidate c and its successor, in either orientation, when shorter.
fn or_opt_pass(pts: &[Point3], candidates: &[Vec<u32>], tour: &mut Vec<u32>) -> bool {
    let mut changed = false;
    let mut pos = positions(tour);
    for run in 1..=3usize {
        let mut i = 0;
        while i < tour.len() {
            if tour.len() < run + 3 {
                return changed;
            }
            if let Some(new_tour) = try_move_run(pts, candidates, tour, &pos, i, run) {
                *tour = new_tour;
                pos = positions(tour);
                changed = true;
            }
            i += 1;
        }
    }
    changed
}

fn try_move_run(
    pts: &[Point3],
    candidates: &[Vec<u32>],
    tour: &[u32],
    pos: &[usize],
    i: usize,
    run: usize,
) -> Option<Vec<u32>> {
    let n = tour.len();
    let at = |k: usize| tour[k % n];
    let (prev, first, last, next) = (at(i + n - 1), at(i), at(i + run - 1), at(i + run));
    let removed_gain = dist(pts, prev, first) + dist(pts, last, next) - dist(pts, prev, next);
    if removed_gain <= 0.0 {
        return None;
    }
    let in_run = |x: u32| (pos[x as usize] + n - i) % n < run;
    for &c in candidates[first as usize]
        .iter()
        .chain(&candidates[last as usize])
    {
        let c_next = at(pos[c as usize] + 1);
        if in_run(c) || in_run(c_next) {
            continue;
        }
        let base = dist(pts, c, c_next);
        let forward = dist(pts, c, first) + dist(pts, last, c_next) - base;
        let backward = dist(pts, c, last) + dist(pts, first, c_next) - base;
        let (cost, reversed) = if backward < forward {
            (backward, true)
        } else {
            (forward, false)
        };
        if shorter(cost, removed_gain) {
            let mut segment: Vec<u32> = (0..run).map(|k| at(i + k)).collect();
            if reversed {
                segment.reverse();
            }
            let mut rest: Vec<u32> = (run..n).map(|k| at(i + k)).collect();
            let insert_after = (pos[c as usize] + n - i - run) % n;
            rest.splice(insert_after + 1..insert_after + 1, segment);
            return Some(rest);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(n: usize, r: f64) -> Vec<Point3> {
        (0..n)
            .map(|i| {
                let t = i as f64 / n as f64 * std::f64::consts::TAU;
                [r * t.cos(), r * t.sin(), 0.0]
            })
            .collect()
    }

    /// Deterministic shuffle of 0..n.
    fn shuffled(n: u32, seed: u64) -> Vec<u32> {
        let mut v: Vec<u32> = (0..n).collect();
        let mut s = seed;
        for i in (1..v.len()).rev() {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            v.swap(i, (s >> 33) as usize % (i + 1));
        }
        v
    }

    #[test]
    fn a_shuffled_circle_comes_back_in_order() {
        let pts = circle(200, 10.0);
        let order = shuffled(200, 3);
        let shuffled_pts: Vec<Point3> = order.iter().map(|&i| pts[i as usize]).collect();
        let members: Vec<u32> = (0..200).collect();
        let tour = closed_tour(&shuffled_pts, &members, &[]);
        let ideal = tour_length(&pts, &(0..200).collect::<Vec<u32>>());
        let got = tour_length(&shuffled_pts, &tour);
        assert!((got - ideal).abs() < 1e-9 * ideal, "{got} vs {ideal}");
    }

    #[test]
    fn large_loops_are_ordered_quickly_and_well() {
        // 6000 points on a jittered ellipse, shuffled.
        let mut s = 5u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let pts: Vec<Point3> = circle(6000, 1000.0)
            .into_iter()
            .map(|p| [2.0 * p[0] + 0.3 * rnd(), p[1] + 0.3 * rnd(), 0.0])
            .collect();
        let order = shuffled(6000, 9);
        let shuffled_pts: Vec<Point3> = order.iter().map(|&i| pts[i as usize]).collect();
        let members: Vec<u32> = (0..6000).collect();
        let tour = closed_tour(&shuffled_pts, &members, &[]);
        let by_angle = tour_length(&pts, &(0..6000).collect::<Vec<u32>>());
        let got = tour_length(&shuffled_pts, &tour);
        assert!(got <= by_angle * 1.01, "{got} vs {by_angle}");
    }

    #[test]
    fn small_clusters_are_exact() {
        let pts: Vec<Point3> = vec![
            [0.0, 0.0, 0.0],
            [2.0, 2.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.0, 2.0, 0.0],
            [1.0, -0.2, 0.0],
        ];
        let tour = closed_tour(&pts, &[0, 1, 2, 3, 4], &[]);
        assert_eq!(tour, vec![0, 3, 1, 2, 4]);
    }

    #[test]
    fn tours_do_not_cross_on_jittered_loops() {
        // A jittered, stretched loop with 500 points.
        let mut s = 11u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let pts: Vec<Point3> = circle(500, 50.0)
            .into_iter()
            .map(|p| [3.0 * p[0] + 0.4 * rnd(), p[1] + 0.4 * rnd(), 0.0])
            .collect();
        let order = shuffled(500, 5);
        let pts: Vec<Point3> = order.iter().map(|&i| pts[i as usize]).collect();
        let members: Vec<u32> = (0..500).collect();
        let tour = closed_tour(&pts, &members, &[]);
        assert_eq!(tour.len(), 500);
        let seg = |k: usize| (pts[tour[k] as usize], pts[tour[(k + 1) % 500] as usize]);
        for a in 0..500 {
            for b in a + 2..500 {
                if (b + 1) % 500 == a {
                    continue;
                }
                assert!(
                    !segments_cross(seg(a), seg(b)),
                    "segments {a} and {b} cross"
                );
            }
        }
    }

    fn segments_cross((p, q): (Point3, Point3), (r, s): (Point3, Point3)) -> bool {
        let orient = |a: Point3, b: Point3, c: Point3| {
            (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        };
        let (d1, d2) = (orient(p, q, r), orient(p, q, s));
        let (d3, d4) = (orient(r, s, p), orient(r, s, q));
        d1 * d2 < 0.0 && d3 * d4 < 0.0
    }
}
