//! Geometry shared by every stage (infrastructure; no section of the
//! paper): vector arithmetic on points, planar predicates, medians and
//! union-find.

mod predicates;
mod union_find;
mod vec3;

pub(crate) use predicates::{orient, orientation, segments_meet};
pub(crate) use union_find::UnionFind;
pub(crate) use vec3::{
    add, cross, dist2, dot, lerp, lerp2, norm2, scale, segment_dist2, segment_param, sub, unit,
};
pub use vec3::{rotation_from_quaternion, Point3};

/// The median of the finite values (the upper one of an even count), or 1
/// when there is none: a scale that is never zero or NaN.
pub(crate) fn median(values: &[f64]) -> f64 {
    let mut v: Vec<f64> = values.iter().copied().filter(|b| b.is_finite()).collect();
    if v.is_empty() {
        return 1.0;
    }
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// A length ordered by `total_cmp`, for the heaps of shortest paths.
pub(crate) struct Length(pub(crate) f64);

impl PartialEq for Length {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other).is_eq()
    }
}

impl Eq for Length {}

impl PartialOrd for Length {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Length {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}
