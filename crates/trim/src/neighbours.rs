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
}

impl<'a> NeighbourIndex<'a> {
    /// Builds the index. `points` must be finite and have fewer than 2^32 entries.
    pub fn new(points: &'a [Point3]) -> Self {
        let tree = ImmutableKdTree::new_from_slice(points)
            .expect("point count fits in u32, checked at the entry point");
        Self { points, tree }
    }

    /// The indexed points.
    pub fn points(&self) -> &'a [Point3] {
        self.points
    }

    /// Writes the indices of the `k` points nearest to point `i` (itself
    /// first, then by increasing distance, ties by index) into `out`.
    pub fn nearest(&self, i: usize, k: usize, out: &mut Vec<u32>) {
        out.clear();
        let Some(k) = NonZeroUsize::new(k.min(self.points.len())) else {
            return;
        };
        let mut found = self
            .tree
            .query(&self.points[i])
            .nearest_n::<SquaredEuclidean<f64>>(k)
            .execute();
        found.sort_unstable_by(|a, b| {
            let self_first = (b.item as usize == i).cmp(&(a.item as usize == i));
            self_first
                .then(a.distance.total_cmp(&b.distance))
                .then(a.item.cmp(&b.item))
        });
        out.extend(found.iter().map(|n| n.item));
    }
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
