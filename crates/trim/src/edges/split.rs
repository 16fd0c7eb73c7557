//! Tours cut at their jumps and joined again by supported steps.
//!
//! On real range scans a cluster can hold two borders joined at two places
//! (an outer border and a depth-discontinuity border touching it twice);
//! the one closed tour through all its points must then jump across the
//! surface somewhere. A step of a tour is *supported* when its two points
//! are at most 3β apart (β the larger local resolution of the two) or BPD
//! linked them; a *jump* is an unsupported step. A tour without jumps is
//! kept as it is.
//! Otherwise it is cut at every jump into pieces that follow the borders,
//! and the pieces' ends are joined again, nearest pair first, by supported
//! steps only (an end joins at most one other end, possibly the other end
//! of its own chain, which closes it). Closed chains of at least
//! [`MIN_LOOP_POINTS`] points are loops; an open chain is closed along the
//! links (from either end, the shortest link path back to the chain that
//! makes the longest cycle; the rest of the chain likewise), and what
//! cannot close is dropped and counted. Last, longest first, a loop within
//! 3β of longer loops all along (a parallel copy of their border inside a
//! thick band of boundary points) is dropped and counted too. No
//! threshold beyond the local resolution is involved: 3β is the step
//! length a border sampled at resolution β never needs.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use crate::hash::{HashMap, HashSet};

use crate::geom::UnionFind;
use crate::geom::{dist2, Length, Point3};

use super::cluster::MIN_LOOP_POINTS;
use super::order::canonical;

/// Factor of β above which a step no link supports is a jump.
const JUMP_BETAS: f64 = 3.0;

/// Is the step between `a` and `b` supported: at most 3β long (the larger
/// β of the two), or a link? `links` are sorted pairs, smaller index first.
pub fn supported(points: &[Point3], beta: &[f64], links: &[[u32; 2]], a: u32, b: u32) -> bool {
    within_jump(points, beta, a, b) || links.binary_search(&[a.min(b), a.max(b)]).is_ok()
}

/// Cuts a closed `tour` at its jumps and joins the pieces again by
/// supported steps; returns the closed loops (canonical: smallest index
/// first) and the number of pieces or chains dropped. A tour without jumps
/// comes back unchanged.
pub fn split_at_jumps(
    points: &[Point3],
    beta: &[f64],
    links: &[[u32; 2]],
    tour: Vec<u32>,
) -> (Vec<Vec<u32>>, usize) {
    let ok = |a: u32, b: u32| supported(points, beta, links, a, b);
    let Some(pieces) = cut_at_jumps(&tour, ok) else {
        return (vec![tour], 0);
    };
    let partner = join_ends(points, &pieces, ok);
    let (mut loops, open) = follow_chains(&pieces, &partner);
    let unclosed = close_open_chains(points, links, open, &mut loops);
    let (kept, shadowed) = drop_shadowed_loops(points, beta, loops);
    (kept, unclosed + shadowed)
}

/// The pieces of `tour`: maximal runs of supported steps, each starting
/// after a jump. None if the tour has no jump.
fn cut_at_jumps(tour: &[u32], ok: impl Fn(u32, u32) -> bool) -> Option<Vec<Vec<u32>>> {
    let n = tour.len();
    let first_jump = (0..n).find(|&k| !ok(tour[k], tour[(k + 1) % n]))?;
    let mut pieces: Vec<Vec<u32>> = Vec::new();
    let mut current = Vec::new();
    for j in 1..=n {
        let k = (first_jump + j) % n;
        current.push(tour[k]);
        if !ok(tour[k], tour[(k + 1) % n]) {
            pieces.push(std::mem::take(&mut current));
        }
    }
    Some(pieces)
}

/// The point at piece end `e`: ends are numbered 2·piece + side (0: first
/// point, 1: last point).
fn end_point(pieces: &[Vec<u32>], e: usize) -> u32 {
    let p = &pieces[e / 2];
    if e & 1 == 0 {
        p[0]
    } else {
        p[p.len() - 1]
    }
}

/// Joins the pieces' ends by supported steps, nearest pair first; an end
/// joins at most one other end, and a chain of pieces closes at most
/// once. Returns each end's partner (usize::MAX for a free end).
fn join_ends(points: &[Point3], pieces: &[Vec<u32>], ok: impl Fn(u32, u32) -> bool) -> Vec<usize> {
    let mut partner = vec![usize::MAX; 2 * pieces.len()];
    let mut closed = vec![false; pieces.len()];
    // Chains as union–find over pieces.
    let mut chains = UnionFind::new(pieces.len());
    for (e, f) in supported_end_pairs(points, pieces, ok) {
        if partner[e] != usize::MAX || partner[f] != usize::MAX {
            continue;
        }
        let (re, rf) = (
            chains.find((e / 2) as u32) as usize,
            chains.find((f / 2) as u32) as usize,
        );
        if re == rf {
            if closed[re] {
                continue;
            }
            closed[re] = true;
        } else {
            if closed[re] || closed[rf] {
                continue;
            }
            chains.union(re as u32, rf as u32);
        }
        partner[e] = f;
        partner[f] = e;
    }
    partner
}

/// The pairs of piece ends (e < f) joined by a supported step, nearest
/// first (ties by e, then f).
fn supported_end_pairs(
    points: &[Point3],
    pieces: &[Vec<u32>],
    ok: impl Fn(u32, u32) -> bool,
) -> Vec<(usize, usize)> {
    let ends = 2 * pieces.len();
    let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
    for e in 0..ends {
        for f in e + 1..ends {
            // A one-point piece does not close on itself.
            if f == e + 1 && e & 1 == 0 && pieces[e / 2].len() == 1 {
                continue;
            }
            let (a, b) = (end_point(pieces, e), end_point(pieces, f));
            if ok(a, b) {
                pairs.push((dist2(points[a as usize], points[b as usize]), e, f));
            }
        }
    }
    pairs.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
    pairs.into_iter().map(|(_, e, f)| (e, f)).collect()
}

/// The chains of joined pieces: the closed ones of at least
/// [`MIN_LOOP_POINTS`] points as loops (canonical), the others as open
/// chains, those with a free end first, walked from it.
fn follow_chains(pieces: &[Vec<u32>], partner: &[usize]) -> (Vec<Vec<u32>>, Vec<Vec<u32>>) {
    let mut visited = vec![false; pieces.len()];
    let mut loops = Vec::new();
    let mut open = Vec::new();
    for e in 0..partner.len() {
        if partner[e] == usize::MAX && !visited[e / 2] {
            open.push(walk_chain(pieces, partner, e, &mut visited).0);
        }
    }
    for p in 0..pieces.len() {
        if !visited[p] {
            let (chain, closed) = walk_chain(pieces, partner, 2 * p, &mut visited);
            if closed && chain.len() >= MIN_LOOP_POINTS {
                loops.push(canonical(chain));
            } else {
                open.push(chain);
            }
        }
    }
    (loops, open)
}

/// The points of the chain that starts at piece end `start`, marking its
/// pieces `visited`, and whether it closes.
fn walk_chain(
    pieces: &[Vec<u32>],
    partner: &[usize],
    start: usize,
    visited: &mut [bool],
) -> (Vec<u32>, bool) {
    let mut chain = Vec::new();
    let mut e = start;
    loop {
        let piece = e / 2;
        visited[piece] = true;
        if e & 1 == 0 {
            chain.extend_from_slice(&pieces[piece]);
        } else {
            chain.extend(pieces[piece].iter().rev());
        }
        let next = partner[e ^ 1];
        if next == usize::MAX {
            return (chain, false);
        }
        if next == start || visited[next / 2] {
            return (chain, true);
        }
        e = next;
    }
}

/// Closes the `open` chains, longest first, along the links through
/// points no loop holds yet ([`peel_cycle`]), adding the cycles to
/// `loops`; returns the number of chains dropped because they could not
/// close.
fn close_open_chains(
    points: &[Point3],
    links: &[[u32; 2]],
    mut open: Vec<Vec<u32>>,
    loops: &mut Vec<Vec<u32>>,
) -> usize {
    let mut dropped = 0;
    let mut used: HashSet<u32> = loops.iter().flatten().copied().collect();
    let adjacency = link_adjacency(links);
    // Longest first (popped from the end).
    open.sort_by(|x, y| x.len().cmp(&y.len()).then(y.cmp(x)));
    while let Some(chain) = open.pop() {
        let runs = unclaimed_runs(&chain, &used);
        if runs.len() != 1 {
            dropped += usize::from(runs.is_empty());
            open.extend(runs);
            continue;
        }
        let chain = runs.into_iter().next().expect("one run");
        match peel_cycle(points, &adjacency, &used, &chain) {
            Some((ring, rest)) => {
                used.extend(ring.iter().copied());
                loops.push(canonical(ring));
                if rest.len() >= 2 {
                    open.push(rest);
                }
            }
            None => dropped += 1,
        }
    }
    dropped
}

/// Each point's neighbours along the links.
fn link_adjacency(links: &[[u32; 2]]) -> HashMap<u32, Vec<u32>> {
    let mut adjacency: HashMap<u32, Vec<u32>> = HashMap::default();
    for &[a, b] in links {
        adjacency.entry(a).or_default().push(b);
        adjacency.entry(b).or_default().push(a);
    }
    adjacency
}

/// The runs of at least 2 points of `chain` that no loop took meanwhile
/// (not `used`).
fn unclaimed_runs(chain: &[u32], used: &HashSet<u32>) -> Vec<Vec<u32>> {
    chain
        .split(|p| used.contains(p))
        .filter(|run| run.len() >= 2)
        .map(<[u32]>::to_vec)
        .collect()
}

/// Drops, longest first, each loop that runs within 3β of longer loops all
/// along: a parallel copy of their border (a cycle inside a thick band of
/// boundary points), not a border of its own. Returns the loops kept, in
/// sorted order, and the number dropped.
fn drop_shadowed_loops(
    points: &[Point3],
    beta: &[f64],
    mut loops: Vec<Vec<u32>>,
) -> (Vec<Vec<u32>>, usize) {
    loops.sort_by(|x, y| y.len().cmp(&x.len()).then(x.cmp(y)));
    let mut kept: Vec<Vec<u32>> = Vec::new();
    let mut dropped = 0;
    for ring in loops {
        let shadowed = ring.iter().all(|&p| {
            kept.iter()
                .flatten()
                .any(|&q| within_jump(points, beta, p, q))
        });
        if shadowed {
            dropped += 1;
        } else {
            kept.push(ring);
        }
    }
    kept.sort_unstable();
    (kept, dropped)
}

/// Are `a` and `b` at most 3β apart (the larger β of the two)?
fn within_jump(points: &[Point3], beta: &[f64], a: u32, b: u32) -> bool {
    let scale = JUMP_BETAS * beta[a as usize].max(beta[b as usize]);
    dist2(points[a as usize], points[b as usize]) <= scale * scale
}

/// The longest cycle of at least [`MIN_LOOP_POINTS`] points made of a run
/// of the open `chain` from one of its ends and a path along the links
/// from that end back to the chain (through points neither on the chain
/// nor `used`); returns it and the rest of the chain beyond the run.
fn peel_cycle(
    points: &[Point3],
    adjacency: &HashMap<u32, Vec<u32>>,
    used: &HashSet<u32>,
    chain: &[u32],
) -> Option<(Vec<u32>, Vec<u32>)> {
    let position: HashMap<u32, usize> = chain.iter().enumerate().map(|(i, &p)| (p, i)).collect();
    let n = chain.len();
    let mut best: Option<(Vec<u32>, Vec<u32>)> = None;
    for from_start in [false, true] {
        let end = if from_start { chain[0] } else { chain[n - 1] };
        for (target, path) in link_paths(
            points,
            adjacency,
            end,
            |p| used.contains(&p) || position.contains_key(&p),
            |p| position.contains_key(&p),
        ) {
            let j = position[&target];
            let (mut ring, rest) = if from_start {
                (chain[..=j].to_vec(), chain[j + 1..].to_vec())
            } else {
                (chain[j..].to_vec(), chain[..j].to_vec())
            };
            // The path runs from `end` to `target`: after the run's last
            // point when the run starts at `end`, reversed otherwise.
            if from_start {
                ring.extend(path.iter().rev());
            } else {
                ring.extend(path.iter());
            }
            let longer = match &best {
                Some(b) => ring.len() > b.0.len(),
                None => true,
            };
            if ring.len() >= MIN_LOOP_POINTS && longer {
                best = Some((ring, rest));
            }
        }
    }
    best
}

/// Shortest paths along the links from `from` (Dijkstra, Euclidean
/// lengths, ties by index) through points that are not `blocked`, to every
/// `target` point reached (targets end a path; `from` is not one). Returns
/// each target with the points strictly between.
fn link_paths(
    points: &[Point3],
    adjacency: &HashMap<u32, Vec<u32>>,
    from: u32,
    blocked: impl Fn(u32) -> bool,
    target: impl Fn(u32) -> bool,
) -> Vec<(u32, Vec<u32>)> {
    let mut best: HashMap<u32, (f64, u32)> = [(from, (0.0, from))].into_iter().collect();
    let mut heap = BinaryHeap::from([Reverse((Length(0.0), from))]);
    let mut reached = Vec::new();
    while let Some(Reverse((Length(d), v))) = heap.pop() {
        if d > best[&v].0 {
            continue;
        }
        if v != from && target(v) {
            let mut path = Vec::new();
            let mut at = best[&v].1;
            while at != from {
                path.push(at);
                at = best[&at].1;
            }
            path.reverse();
            reached.push((v, path));
            continue;
        }
        for &w in adjacency.get(&v).map_or(&[][..], Vec::as_slice) {
            if w == from || (blocked(w) && !target(w)) {
                continue;
            }
            let nd = d + dist2(points[v as usize], points[w as usize]).sqrt();
            if !best.get(&w).is_some_and(|&(old, _)| nd >= old) {
                best.insert(w, (nd, v));
                heap.push(Reverse((Length(nd), w)));
            }
        }
    }
    reached.sort_unstable();
    reached
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edges::{cluster::cluster_boundary, order::closed_tour};

    /// Two concentric rings (radius 10 and 5, spacing ≈ 1) joined at two
    /// places by radial bridges of linked points: one cluster, which no
    /// single tour can follow without jumping across the surface.
    fn rings_joined_twice() -> (Vec<Point3>, Vec<[u32; 2]>, usize, usize) {
        let mut points = Vec::new();
        let mut links = Vec::new();
        let ring = |points: &mut Vec<Point3>, links: &mut Vec<[u32; 2]>, r: f64, n: usize| {
            let first = points.len() as u32;
            for i in 0..n {
                let t = i as f64 / n as f64 * std::f64::consts::TAU;
                points.push([r * t.cos(), r * t.sin(), 0.0]);
                let (a, b) = (first + i as u32, first + ((i + 1) % n) as u32);
                links.push([a.min(b), a.max(b)]);
            }
            first
        };
        let (outer_n, inner_n) = (60, 30);
        let outer = ring(&mut points, &mut links, 10.0, outer_n);
        let inner = ring(&mut points, &mut links, 5.0, inner_n);
        // Bridges at angle 0 and π: points at radius 6..9.
        for (o, i, sign) in [(outer, inner, 1.0), (outer + 30, inner + 15, -1.0)] {
            let mut previous = i;
            for r in 6..=9 {
                let p = points.len() as u32;
                points.push([sign * r as f64, 0.0, 0.0]);
                links.push([previous.min(p), previous.max(p)]);
                previous = p;
            }
            links.push([o.min(previous), o.max(previous)]);
        }
        links.sort_unstable();
        (points, links, outer_n, inner_n)
    }

    /// Steps of a closed tour that no link supports and that are longer
    /// than the jump length.
    fn jumps(points: &[Point3], beta: &[f64], links: &[[u32; 2]], tour: &[u32]) -> usize {
        let next = tour.iter().cycle().skip(1);
        tour.iter()
            .zip(next)
            .filter(|&(&a, &b)| !supported(points, beta, links, a, b))
            .count()
    }

    #[test]
    fn two_borders_joined_twice_give_two_loops_without_jumps() {
        let (points, links, outer_n, inner_n) = rings_joined_twice();
        let beta = vec![1.1; points.len()];
        let clusters = cluster_boundary(&vec![true; points.len()], &links);
        assert_eq!(clusters.clusters.len(), 1);
        let tour = closed_tour(&points, &clusters.clusters[0], &clusters.links[0]);
        assert!(jumps(&points, &beta, &links, &tour) > 0);
        let (loops, _dropped) = split_at_jumps(&points, &beta, &clusters.links[0], tour);
        assert_eq!(loops.len(), 2, "{loops:?}");
        for l in &loops {
            assert_eq!(jumps(&points, &beta, &links, l), 0, "{l:?}");
        }
        // One loop round each ring.
        let on = |l: &Vec<u32>, from: usize, n: usize| {
            (from..from + n)
                .filter(|&i| l.contains(&(i as u32)))
                .count()
        };
        let mut rings: Vec<(usize, usize)> = loops
            .iter()
            .map(|l| (on(l, 0, outer_n), on(l, outer_n, inner_n)))
            .collect();
        rings.sort_unstable();
        assert!(rings[0].0 <= 1 && rings[0].1 == inner_n, "{rings:?}");
        assert!(rings[1].0 == outer_n && rings[1].1 <= 1, "{rings:?}");
    }

    #[test]
    fn a_tour_without_jumps_is_kept() {
        let points: Vec<Point3> = (0..12)
            .map(|i| {
                let t = i as f64 / 12.0 * std::f64::consts::TAU;
                [3.0 * t.cos(), 3.0 * t.sin(), 0.0]
            })
            .collect();
        let tour: Vec<u32> = (0..12).collect();
        let (loops, dropped) = split_at_jumps(&points, &[1.0; 12], &[], tour.clone());
        assert_eq!((loops, dropped), (vec![tour], 0));
    }
}
