//! Clustering of boundary points into separate boundaries (section 3 of the
//! paper: "the detected points need to be clustered, so that points
//! belonging to the same boundary are grouped together").
//!
//! The paper leaves the rule open. A distance threshold ("link points closer
//! than 2β") merges a hole with a nearby outer border on sparse clouds.
//! meshtrim links two boundary points when BPD found an empty circle of
//! radius ≥ β through both ([`crate::Detection::links`]: the edges of the
//! α-shape with α = β). Between a hole and the outer border there are
//! interior points, so no such circle joins them, however close they are;
//! around a hole of radius ≈ β found by four points, the four are joined by
//! the circle that made them boundary points.
//!
//! Thinning: spurs (chains hanging off a boundary), stray boundary points
//! and isolated points cannot be part of a closed boundary, and a tour
//! through them would zig-zag. Links on no cycle of the link graph
//! (bridges: a chain of stray points joining two boundaries) are removed,
//! then each cluster keeps the *2-core* of its link graph: points of
//! degree < 2 are removed until none is left. Clusters with
//! an empty 2-core (a chain, a lone point) are dropped and counted, and so
//! are 2-cores of three points: a loop needs four (see [`MIN_LOOP_POINTS`]).

use crate::geom::UnionFind;

/// Boundaries found among the boundary points.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Clusters {
    /// Each cluster's point indices, ascending; clusters ordered by their
    /// smallest index.
    pub clusters: Vec<Vec<u32>>,
    /// Links of each cluster, as pairs of point indices (both in the
    /// cluster), sorted.
    pub links: Vec<Vec<[u32; 2]>>,
    /// Groups of linked boundary points that hold no closed boundary.
    pub dropped_clusters: usize,
    /// Boundary points removed as spurs, strays or isolated points.
    pub thinned_points: usize,
}

/// Groups the boundary points by the links between them and thins each
/// group to the 2-core of its link graph.
///
/// `boundary[i]` labels point i; `links` are pairs of point indices. Links
/// that touch a non-boundary point are ignored.
pub fn cluster_boundary(boundary: &[bool], links: &[[u32; 2]]) -> Clusters {
    let valid: Vec<[u32; 2]> = links
        .iter()
        .copied()
        .filter(|&[a, b]| a != b && boundary[a as usize] && boundary[b as usize])
        .collect();
    let (groups, _) = components(boundary.len(), boundary, &valid);
    // Links on no cycle (bridges) join separate boundaries through a chain
    // of stray points; without them the 2-core splits into the loops.
    let mut valid = valid;
    let bridges = bridges(boundary.len(), &valid);
    valid.retain(|l| {
        bridges
            .binary_search(&[l[0].min(l[1]), l[0].max(l[1])])
            .is_err()
    });
    let core = two_core(boundary, &valid);
    let dropped_clusters = groups
        .iter()
        .filter(|g| !g.iter().any(|&i| core[i as usize]))
        .count();
    let kept: Vec<[u32; 2]> = valid
        .into_iter()
        .filter(|&[a, b]| core[a as usize] && core[b as usize])
        .collect();
    let (mut clusters, mut links) = components(boundary.len(), &core, &kept);
    let triangles = keep_loops(&mut clusters, &mut links);
    let core_count: usize = clusters.iter().map(Vec::len).sum();
    let boundary_count = boundary.iter().filter(|&&b| b).count();
    Clusters {
        dropped_clusters: dropped_clusters + triangles,
        thinned_points: boundary_count - core_count,
        clusters,
        links,
    }
}

/// The smallest loop kept: the paper's smallest hole, of radius just
/// above β, is found by four points.
pub(crate) const MIN_LOOP_POINTS: usize = 4;

/// Drops clusters of fewer than [`MIN_LOOP_POINTS`] points (three points
/// around an empty circle of radius β: a gap of the sampling itself at the
/// resolution limit, which jittered clouds of a million points show a few
/// times); returns how many were dropped.
fn keep_loops(clusters: &mut Vec<Vec<u32>>, links: &mut Vec<Vec<[u32; 2]>>) -> usize {
    let keep: Vec<bool> = clusters
        .iter()
        .map(|c| c.len() >= MIN_LOOP_POINTS)
        .collect();
    let mut flags = keep.iter();
    links.retain(|_| *flags.next().expect("one flag per cluster"));
    clusters.retain(|c| c.len() >= MIN_LOOP_POINTS);
    keep.iter().filter(|&&k| !k).count()
}

/// The bridges of the link graph (links on no cycle), as sorted pairs
/// (smaller index first). Iterative Tarjan: discovery order and low-links.
fn bridges(n: usize, links: &[[u32; 2]]) -> Vec<[u32; 2]> {
    let mut adjacency: Vec<Vec<(u32, usize)>> = vec![Vec::new(); n];
    for (e, &[a, b]) in links.iter().enumerate() {
        adjacency[a as usize].push((b, e));
        adjacency[b as usize].push((a, e));
    }
    let mut order = vec![u32::MAX; n];
    let mut low = vec![0u32; n];
    let mut counter = 0u32;
    let mut found = Vec::new();
    for root in 0..n {
        if order[root] != u32::MAX || adjacency[root].is_empty() {
            continue;
        }
        // Stack of (vertex, link it was entered by, next neighbour slot).
        let mut stack: Vec<(usize, usize, usize)> = vec![(root, usize::MAX, 0)];
        order[root] = counter;
        low[root] = counter;
        counter += 1;
        while let Some(&mut (v, via, ref mut slot)) = stack.last_mut() {
            if let Some(&(w, e)) = adjacency[v].get(*slot) {
                *slot += 1;
                let w = w as usize;
                if e == via {
                    continue;
                }
                if order[w] == u32::MAX {
                    order[w] = counter;
                    low[w] = counter;
                    counter += 1;
                    stack.push((w, e, 0));
                } else {
                    low[v] = low[v].min(order[w]);
                }
            } else {
                stack.pop();
                if let Some(&(parent, _, _)) = stack.last() {
                    low[parent] = low[parent].min(low[v]);
                    if low[v] > order[parent] {
                        let (a, b) = (parent as u32, v as u32);
                        found.push([a.min(b), a.max(b)]);
                    }
                }
            }
        }
    }
    found.sort_unstable();
    found
}

/// Marks the points of the 2-core: repeatedly removes points with fewer
/// than two links.
fn two_core(boundary: &[bool], links: &[[u32; 2]]) -> Vec<bool> {
    let n = boundary.len();
    let mut degree = vec![0u32; n];
    let mut adjacency: Vec<Vec<u32>> = vec![Vec::new(); n];
    for &[a, b] in links {
        degree[a as usize] += 1;
        degree[b as usize] += 1;
        adjacency[a as usize].push(b);
        adjacency[b as usize].push(a);
    }
    let mut alive = boundary.to_vec();
    let mut stack: Vec<u32> = (0..n as u32)
        .filter(|&i| alive[i as usize] && degree[i as usize] < 2)
        .collect();
    while let Some(i) = stack.pop() {
        if !alive[i as usize] {
            continue;
        }
        alive[i as usize] = false;
        for &j in &adjacency[i as usize] {
            if alive[j as usize] {
                degree[j as usize] -= 1;
                if degree[j as usize] < 2 {
                    stack.push(j);
                }
            }
        }
    }
    alive
}

/// Connected components of the `alive` points under `links`.
fn components(n: usize, alive: &[bool], links: &[[u32; 2]]) -> (Vec<Vec<u32>>, Vec<Vec<[u32; 2]>>) {
    let mut sets = UnionFind::new(n);
    for &[a, b] in links {
        sets.union(a, b);
    }
    let mut slot_of_root = vec![u32::MAX; n];
    let mut clusters: Vec<Vec<u32>> = Vec::new();
    for i in 0..n as u32 {
        if !alive[i as usize] {
            continue;
        }
        let root = sets.find(i) as usize;
        if slot_of_root[root] == u32::MAX {
            slot_of_root[root] = clusters.len() as u32;
            clusters.push(Vec::new());
        }
        clusters[slot_of_root[root] as usize].push(i);
    }
    let mut cluster_links = vec![Vec::new(); clusters.len()];
    for &[a, b] in links {
        let root = sets.find(a) as usize;
        cluster_links[slot_of_root[root] as usize].push([a.min(b), a.max(b)]);
    }
    for l in cluster_links.iter_mut() {
        l.sort_unstable();
        l.dedup();
    }
    (clusters, cluster_links)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ring of `n` points starting at `first`, each linked to the next.
    fn ring(first: u32, n: u32) -> Vec<[u32; 2]> {
        (0..n).map(|i| [first + i, first + (i + 1) % n]).collect()
    }

    #[test]
    fn separate_rings_are_separate_clusters() {
        let mut links = ring(0, 6);
        links.extend(ring(6, 4)); // a four-point hole
        let c = cluster_boundary(&[true; 10], &links);
        assert_eq!(
            c.clusters,
            vec![(0..6).collect::<Vec<u32>>(), (6..10).collect()]
        );
        assert_eq!(c.dropped_clusters, 0);
        assert_eq!(c.thinned_points, 0);
    }

    #[test]
    fn spurs_and_lone_points_are_thinned() {
        let mut links = ring(0, 5);
        links.extend([[2, 5], [5, 6]]); // a spur 2–5–6
        links.extend([[7, 8], [8, 9]]); // a chain: no loop
        let mut boundary = vec![true; 11]; // 10 is alone
        boundary[10] = true;
        let c = cluster_boundary(&boundary, &links);
        assert_eq!(c.clusters, vec![(0..5).collect::<Vec<u32>>()]);
        assert_eq!(c.links[0], {
            let mut r: Vec<[u32; 2]> = ring(0, 5)
                .iter()
                .map(|&[a, b]| [a.min(b), a.max(b)])
                .collect();
            r.sort_unstable();
            r
        });
        assert_eq!(c.thinned_points, 6);
        assert_eq!(c.dropped_clusters, 2); // the chain and the lone point
    }

    #[test]
    fn two_loops_joined_by_a_chain_are_separated() {
        let mut links = ring(0, 5);
        links.extend(ring(5, 6));
        links.extend([[2, 11], [11, 12], [12, 7]]); // a chain between them
        let c = cluster_boundary(&[true; 13], &links);
        assert_eq!(
            c.clusters,
            vec![(0..5).collect::<Vec<u32>>(), (5..11).collect()]
        );
        assert_eq!(c.thinned_points, 2);
    }

    #[test]
    fn triangles_are_not_loops() {
        let mut links = ring(0, 3);
        links.extend(ring(3, 4));
        let c = cluster_boundary(&[true; 7], &links);
        assert_eq!(c.clusters, vec![vec![3, 4, 5, 6]]);
        assert_eq!(c.dropped_clusters, 1);
        assert_eq!(c.thinned_points, 3);
    }

    #[test]
    fn links_to_interior_points_are_ignored() {
        let mut links = ring(0, 4);
        links.push([1, 4]);
        links.push([4, 2]);
        let mut boundary = vec![true; 5];
        boundary[4] = false;
        let c = cluster_boundary(&boundary, &links);
        assert_eq!(c.clusters, vec![vec![0, 1, 2, 3]]);
        assert_eq!(c.links[0].len(), 4);
    }
}
