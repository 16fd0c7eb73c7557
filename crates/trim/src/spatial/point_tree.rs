//! Nearest-point queries over a fixed set of points: kiddo's immutable k-d
//! tree behind a small interface, so that no other module depends on it.

use std::num::NonZeroUsize;

use kiddo::{ImmutableKdTree, SquaredEuclidean};

use crate::geom::Point3;

/// A k-d tree over points, queried for the nearest ones.
pub(crate) struct PointTree(ImmutableKdTree<f64, 3>);

impl PointTree {
    /// The tree of `points`; `None` only for more points than its item
    /// index holds.
    pub(crate) fn new(points: &[Point3]) -> Option<Self> {
        ImmutableKdTree::new_from_slice(points).ok().map(Self)
    }

    /// The index of the point nearest `p`, and its squared distance.
    pub(crate) fn nearest(&self, p: &Point3) -> (usize, f64) {
        let found = self
            .0
            .query(p)
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        (found.item as usize, found.distance)
    }

    /// The `n` points nearest `p` as (squared distance, index), nearest
    /// first, ties by index.
    pub(crate) fn nearest_n(&self, p: &Point3, n: NonZeroUsize) -> Vec<(f64, u32)> {
        let mut found: Vec<(f64, u32)> = self
            .0
            .query(p)
            .nearest_n::<SquaredEuclidean<f64>>(n)
            .execute()
            .into_iter()
            .map(|f| (f.distance, f.item))
            .collect();
        found.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        found
    }
}
