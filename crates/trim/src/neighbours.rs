//! k-nearest-neighbour search (section 2 of the paper: "k-NN ... it finds the
//! closest k members of the cloud"), with kiddo behind it.
//!
//! kiddo's *immutable* tree is used: it is built once from the whole slice,
//! so it has no bucket that can overflow when many points share one
//! coordinate value (quantised scanner data), which makes kiddo's mutable
//! tree fail. The neighbourhood of a point includes the point itself, first.
//! Ties in distance are broken by index so the result never depends on the
//! tree's internal layout.

use std::num::NonZeroUsize;

use kiddo::{ImmutableKdTree, SquaredEuclidean};

use crate::cloud::Point3;

/// A k-NN index over a slice of distinct points.
pub struct NeighbourIndex<'a> {
    points: &'a [Point3],
    tree: ImmutableKdTree<f64, 3>,
    ranks: Option<&'a [u32]>,
}

impl<'a> NeighbourIndex<'a> {
    /// Builds the index. `points` must be finite and have fewer than 2^32 entries.
    pub fn new(points: &'a [Point3]) -> Self {
        let tree = ImmutableKdTree::new_from_slice(points)
            .expect("point count fits in u32, checked at the entry point");
        Self {
            points,
            tree,
            ranks: None,
        }
    }

    /// Breaks distance ties by `ranks[i]` instead of the index i (e.g. the
    /// points' input order when `points` was reordered).
    pub fn with_ranks(mut self, ranks: &'a [u32]) -> Self {
        self.ranks = Some(ranks);
        self
    }

    /// The indexed points.
    pub fn points(&self) -> &'a [Point3] {
        self.points
    }

    fn rank(&self, i: u32) -> u32 {
        self.ranks.map_or(i, |r| r[i as usize])
    }

    /// Writes the indices of the `k` points nearest to point `i` (itself
    /// first, then by increasing distance, ties by rank) into `out`.
    ///
    /// When points tie at the k-th distance, which of them kiddo returns
    /// depends on the tree; so the query asks for one more than needed and
    /// widens until the tie is enclosed, then cuts by rank.
    pub fn nearest(&self, i: usize, k: usize, out: &mut Vec<u32>) {
        self.nearest_near_last(i, k, out, &mut QueryHint::default());
    }

    /// [`Self::nearest`], faster when consecutive calls with the same `hint`
    /// ask about nearby points: the last answer bounds the search radius.
    /// The result does not depend on the hint.
    pub fn nearest_near_last(&self, i: usize, k: usize, out: &mut Vec<u32>, hint: &mut QueryHint) {
        out.clear();
        let k = k.min(self.points.len());
        if k == 0 {
            return;
        }
        let p = self.points[i];
        // Triangle inequality: the last point's k nearest all lie within
        // r = d_k(last) + |p − last| of p, so p's k nearest do too.
        let bound = hint.last.map(|(q, d_k)| {
            let r = (d_k + crate::cloud::dist2(p, self.points[q]).sqrt()) * (1.0 + 1e-9);
            r * r
        });
        let mut ask = (k + 1).min(self.points.len());
        let mut radius = bound;
        let found = loop {
            let query = self.tree.query(&p);
            let n = NonZeroUsize::new(ask).expect("ask ≥ 1");
            let found = match radius {
                Some(r2) => query
                    .nearest_n::<SquaredEuclidean<f64>>(n)
                    .within::<SquaredEuclidean<f64>>(r2)
                    .execute(),
                None => query.nearest_n::<SquaredEuclidean<f64>>(n).execute(),
            };
            if found.len() < k {
                radius = None; // rounding defeated the bound: search freely
                continue;
            }
            let tie_reaches_end = ask < self.points.len()
                && found.len() == ask
                && found[ask - 1].distance <= found[k - 1].distance;
            if !tie_reaches_end {
                break found;
            }
            ask = (2 * ask).min(self.points.len());
        };
        let mut found: Vec<(bool, f64, u32, u32)> = found
            .iter()
            .map(|n| (n.item as usize != i, n.distance, self.rank(n.item), n.item))
            .collect();
        found.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)).then(a.2.cmp(&b.2)));
        found.truncate(k);
        hint.last = Some((i, found.iter().map(|n| n.1).fold(0.0, f64::max).sqrt()));
        out.extend(found.iter().map(|n| n.3));
    }
}

/// The previous query of a sequence of [`NeighbourIndex::nearest_near_last`]
/// calls: its point and the distance to its k-th nearest.
#[derive(Debug, Default, Clone)]
pub struct QueryHint {
    last: Option<(usize, f64)>,
}

/// Reference k-NN by sorting all distances; for tests.
pub fn nearest_brute_force(points: &[Point3], i: usize, k: usize) -> Vec<u32> {
    let p = points[i];
    let mut all: Vec<(bool, f64, u32)> = points
        .iter()
        .enumerate()
        .map(|(j, q)| (j != i, crate::cloud::dist2(p, *q), j as u32))
        .collect();
    all.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)).then(a.2.cmp(&b.2)));
    all.into_iter().take(k).map(|t| t.2).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    #[test]
    fn matches_brute_force_on_random_points() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let pts: Vec<Point3> = (0..500)
            .map(|_| [rng.random(), rng.random(), rng.random::<f64>() * 0.1])
            .collect();
        let index = NeighbourIndex::new(&pts);
        let mut out = Vec::new();
        for i in (0..pts.len()).step_by(7) {
            index.nearest(i, 30, &mut out);
            assert_eq!(out, nearest_brute_force(&pts, i, 30), "point {i}");
        }
    }

    #[test]
    fn ties_at_the_kth_distance_are_cut_by_rank() {
        // A square grid: the 4 points at distance 1 tie, as do the 4 at √2.
        let pts: Vec<Point3> = (0..49)
            .map(|i| [(i % 7) as f64, (i / 7) as f64, 0.0])
            .collect();
        let reversed: Vec<u32> = (0..49u32).rev().collect();
        let index = NeighbourIndex::new(&pts).with_ranks(&reversed);
        let mut out = Vec::new();
        index.nearest(24, 3, &mut out);
        // Centre 24; its distance-1 neighbours are 17, 23, 25, 31: the two
        // of highest index rank first.
        assert_eq!(out, vec![24, 31, 25]);
        let plain = NeighbourIndex::new(&pts);
        plain.nearest(24, 3, &mut out);
        assert_eq!(out, vec![24, 17, 23]);
    }

    #[test]
    fn hinted_queries_match_plain_ones() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let pts: Vec<Point3> = (0..3000)
            .map(|_| [rng.random(), rng.random(), rng.random::<f64>() * 0.01])
            .collect();
        let index = NeighbourIndex::new(&pts);
        let (mut plain, mut hinted) = (Vec::new(), Vec::new());
        let mut hint = QueryHint::default();
        // Far jumps and near steps alike.
        for i in (0..pts.len())
            .step_by(3)
            .chain((0..pts.len()).rev().step_by(101))
        {
            index.nearest(i, 30, &mut plain);
            index.nearest_near_last(i, 30, &mut hinted, &mut hint);
            assert_eq!(plain, hinted, "point {i}");
        }
    }

    /// Quantised scanner data puts thousands of points on one coordinate
    /// value; kiddo's mutable tree panics on that, the immutable one must not.
    #[test]
    fn survives_many_points_sharing_one_coordinate() {
        let pts: Vec<Point3> = (0..20_000)
            .map(|i| [(i % 200) as f64, (i / 200) as f64, 5.0])
            .collect();
        let index = NeighbourIndex::new(&pts);
        let mut out = Vec::new();
        index.nearest(10_050, 9, &mut out);
        assert_eq!(out[0], 10_050);
        let mut got: Vec<u32> = out.clone();
        got.sort_unstable();
        let mut want = nearest_brute_force(&pts, 10_050, 9);
        want.sort_unstable();
        assert_eq!(got, want);
    }
}
