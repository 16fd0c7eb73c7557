//! The true boundary of a synthetic cloud on its surface, indexed for
//! distance queries.

use kiddo::{ImmutableKdTree, SquaredEuclidean};

use super::{SyntheticCloud, P3};

/// The true boundary of a synthetic cloud on the surface, for distance
/// queries.
pub struct BoundaryIndex {
    pub(crate) samples: Vec<P3>,
    pub(crate) spacing: Vec<f64>,
    /// Half the length of the two segments at each sample.
    pub(crate) weight: Vec<f64>,
    prev: Vec<u32>,
    next: Vec<u32>,
    tree: ImmutableKdTree<f64, 3>,
}

impl BoundaryIndex {
    /// Maps the cloud's boundary curves to 3D and indexes their samples.
    pub fn new(truth: &SyntheticCloud) -> Self {
        let mut samples = Vec::new();
        let mut spacing = Vec::new();
        let mut prev = Vec::new();
        let mut next = Vec::new();
        for curve in truth.boundary_3d() {
            let start = samples.len() as u32;
            let n = curve.len() as u32;
            for (i, (p, h)) in curve.into_iter().enumerate() {
                let i = i as u32;
                samples.push(p);
                spacing.push(h);
                prev.push(start + (i + n - 1) % n);
                next.push(start + (i + 1) % n);
            }
        }
        let weight = (0..samples.len())
            .map(|i| {
                0.5 * (dist(samples[i], samples[prev[i] as usize])
                    + dist(samples[i], samples[next[i] as usize]))
            })
            .collect();
        let tree = ImmutableKdTree::new_from_slice(&samples).expect("boundary samples fit in u32");
        Self {
            samples,
            spacing,
            weight,
            prev,
            next,
            tree,
        }
    }

    /// Distance from `p` to the true boundary polylines (to the two
    /// segments at the nearest sample).
    pub fn distance(&self, p: P3) -> f64 {
        self.distance_and_spacing(p).0
    }

    /// [`Self::distance`] and the intended spacing at the nearest boundary
    /// sample, to express the distance in local spacings.
    pub fn distance_and_spacing(&self, p: P3) -> (f64, f64) {
        let nearest = self
            .tree
            .query(&p)
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        let i = nearest.item as usize;
        let a = self.samples[i];
        let d_prev = dist_to_segment(p, a, self.samples[self.prev[i] as usize]);
        let d_next = dist_to_segment(p, a, self.samples[self.next[i] as usize]);
        (d_prev.min(d_next), self.spacing[i])
    }

    /// Total length of the true boundary, in 3D.
    pub fn length(&self) -> f64 {
        self.weight.iter().sum()
    }
}

fn dist(a: P3, b: P3) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

fn dist_to_segment(p: P3, a: P3, b: P3) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let ap = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
    let t = if len2 > 0.0 {
        ((ap[0] * ab[0] + ap[1] * ab[1] + ap[2] * ab[2]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    dist(p, [a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]])
}
