//! Accuracy of boundary detection against synthetic ground truth
//! ([`crate::synthetic`]).
//!
//! # Precision and recall
//!
//! Distances are measured in 3D, to the true boundary curves mapped onto
//! the surface ([`BoundaryIndex`]), and the tolerance is *one intended
//! local resolution* (`SyntheticCloud::spacing`, see the synthetic module
//! doc):
//!
//! - **precision**: the fraction of detected points whose distance to the
//!   true boundary is at most their own intended spacing;
//! - **recall**: the fraction of the true boundary's *length* that has a
//!   detected point within one intended spacing (at that place of the
//!   boundary). The dense boundary samples (at most h/20 apart) each carry
//!   half the length of their two adjacent segments.
//!
//! [`ideal_first_layer`] is the reference detector the scores should be
//! compared with: the points that are the nearest sample (in the parameter
//! domain) to some place of the true boundary. Its scores are below 1 only
//! where the jitter opens a gap wider than the tolerance: where the
//! outermost sample lies more than one pitch inside the boundary, or no
//! sample is within one pitch of a place of the boundary (at convex
//! corners, where the nearest sample can be √2·depth away, and at holes
//! not much larger than the pitch). No detector can beat it by much, so a
//! detector's scores should be read against it.
//!
//! # Noise robustness: Ω and Ψ (section 4 of the paper)
//!
//! The paper adds out-of-plane noise of p % of the local resolution,
//! increasing p from 0 in steps of 1 %, and defines
//!
//! - **Ω**: "the maximum percentage value after which at least one of the
//!   boundary points is not detected (false negative)";
//! - **Ψ**: "the maximum percentage value after which at least one of the
//!   internal points is labelled as boundary point".
//!
//! The paper's clouds are real scans with no ground truth, so its boundary
//! and internal points are those of the *noise-free detection*; this module
//! follows it: a point is *lost* at p when the detection at 0 % labels it
//! boundary and the detection at p labels it interior, and *false* at p when
//! the detection at 0 % labels it interior and the one at p boundary. Ω (Ψ)
//! is the largest p of the sweep such that no point is lost (false) at any
//! p' ≤ p of the sweep. The noise is [`SyntheticCloud::with_noise`]: along
//! the true normal, uniform(−p, p) times the intended spacing, with the same
//! unit draws at every p (one noise pattern, scaled), so that the sweep is
//! a sweep of amplitude only.
//!
//! On a synthetic cloud the truth is known, and the paper's terms *false
//! negative* and *internal point* can be taken literally as well; both
//! readings are reported ([`NoiseRobustness`]):
//!
//! - **Ω against the truth**: the largest p such that the recall does not
//!   fall below the noise-free detection's — no stretch of the true
//!   boundary loses its last detected point within one spacing;
//! - **Ψ against the truth**: the largest p such that no point farther than
//!   one intended spacing from the true boundary (the precision rule's
//!   interior) is newly labelled boundary.
//!
//! The paper's rule counts a first-row point the noise-free detection
//! happened to miss, once noise makes it boundary, as a false one, and
//! counts the loss of a redundant second-row point as a lost boundary
//! point; on jittered clouds, where some point's empty circle is always
//! within a fraction of a percent of β, those marginal points decide it.

use kiddo::{ImmutableKdTree, SquaredEuclidean};

use crate::synthetic::{BoundaryIndex, SyntheticCloud, P3};
use trim::{detect_boundary, BpdOptions, CloudError};

/// Scores of a detection against ground truth (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Accuracy {
    /// Fraction of detected points within one intended spacing of the true
    /// boundary (1 when nothing is detected).
    pub precision: f64,
    /// Fraction of the true boundary's length with a detected point within
    /// one intended spacing.
    pub recall: f64,
    /// Harmonic mean of precision and recall.
    pub f1: f64,
    /// Number of detected points.
    pub detected: usize,
    /// Number of detected points within tolerance of the true boundary.
    pub true_positives: usize,
    /// Length of the true boundary (3D).
    pub true_boundary_len: f64,
    /// Length of the true boundary covered by a detected point.
    pub covered_len: f64,
}

/// Precision and recall of `detected` (one flag per point of `points`)
/// against the true boundary of `truth`. `points` are usually
/// `truth.points`, possibly moved (noise, rigid motion undone); the
/// tolerance of point i is `truth.spacing[i]`.
///
/// # Panics
/// If `points`, `detected` and `truth.points` differ in length.
pub fn precision_recall(points: &[P3], detected: &[bool], truth: &SyntheticCloud) -> Accuracy {
    precision_recall_with(&BoundaryIndex::new(truth), points, detected, truth)
}

/// [`precision_recall`] with a prebuilt [`BoundaryIndex`] of `truth`.
pub fn precision_recall_with(
    index: &BoundaryIndex,
    points: &[P3],
    detected: &[bool],
    truth: &SyntheticCloud,
) -> Accuracy {
    assert_eq!(points.len(), detected.len(), "one flag per point");
    assert_eq!(points.len(), truth.len(), "points of the synthetic cloud");
    let chosen: Vec<usize> = (0..points.len()).filter(|&i| detected[i]).collect();
    let true_positives = chosen
        .iter()
        .filter(|&&i| index.distance(points[i]) <= truth.spacing[i])
        .count();
    let precision = if chosen.is_empty() {
        1.0
    } else {
        true_positives as f64 / chosen.len() as f64
    };
    let true_boundary_len = index.length();
    let mut covered_len = 0.0;
    if !chosen.is_empty() {
        let pts: Vec<P3> = chosen.iter().map(|&i| points[i]).collect();
        let tree: ImmutableKdTree<f64, 3> =
            ImmutableKdTree::new_from_slice(&pts).expect("detected points fit in u32");
        for (j, s) in index.samples.iter().enumerate() {
            let d2 = tree
                .query(s)
                .nearest_one::<SquaredEuclidean<f64>>()
                .execute()
                .distance;
            if d2.sqrt() <= index.spacing[j] {
                covered_len += index.weight[j];
            }
        }
    }
    let recall = covered_len / true_boundary_len;
    let f1 = if precision + recall > 0.0 {
        2.0 * precision * recall / (precision + recall)
    } else {
        0.0
    };
    Accuracy {
        precision,
        recall,
        f1,
        detected: chosen.len(),
        true_positives,
        true_boundary_len,
        covered_len,
    }
}

/// The ideal "first layer" of boundary points: point i is in it when it is
/// the nearest sample, in the parameter domain, to some sample of the
/// dense true boundary.
pub fn ideal_first_layer(truth: &SyntheticCloud) -> Vec<bool> {
    let mut flags = vec![false; truth.len()];
    if truth.is_empty() {
        return flags;
    }
    let tree: ImmutableKdTree<f64, 2> =
        ImmutableKdTree::new_from_slice(&truth.uv).expect("points fit in u32");
    for curve in &truth.boundary {
        for s in curve {
            let nearest = tree
                .query(s)
                .nearest_one::<SquaredEuclidean<f64>>()
                .execute();
            flags[nearest.item as usize] = true;
        }
    }
    flags
}

/// One step of a noise sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseStep {
    /// Noise amplitude, % of the intended local resolution.
    pub percent: f64,
    /// Points labelled boundary at 0 % and interior here.
    pub lost: usize,
    /// Points labelled interior at 0 % and boundary here.
    pub false_boundary: usize,
    /// Of `false_boundary`, those more than one intended spacing from the
    /// true boundary: interior points by the ground truth.
    pub false_interior: usize,
    /// Points labelled boundary here.
    pub boundary: usize,
    /// Recall against the ground truth here (see [`precision_recall`]).
    pub recall: f64,
}

/// A noise level found by a sweep: the largest swept p at which, and at
/// every swept p' below which, a criterion held.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseLevel {
    /// The level, in % of the local resolution.
    pub percent: f64,
    /// True if the criterion held over the whole sweep: `percent` is then
    /// only a lower bound (the sweep's largest p).
    pub capped: bool,
}

impl NoiseLevel {
    fn start() -> Self {
        Self {
            percent: 0.0,
            capped: true,
        }
    }

    /// Records the step at `percent`; `held` says whether the criterion held.
    fn record(&mut self, percent: f64, held: bool) {
        if self.capped {
            if held {
                self.percent = percent;
            } else {
                self.capped = false;
            }
        }
    }
}

impl std::fmt::Display for NoiseLevel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.capped {
            write!(f, "≥ {}", self.percent)
        } else {
            write!(f, "{}", self.percent)
        }
    }
}

/// Result of [`noise_robustness`] (see the module doc for Ω and Ψ).
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseRobustness {
    /// Ω, the paper's rule: no boundary point of the noise-free detection
    /// is lost.
    pub omega: NoiseLevel,
    /// Ψ, the paper's rule: no interior point of the noise-free detection
    /// is labelled boundary.
    pub psi: NoiseLevel,
    /// Ω against the ground truth: the recall does not fall below the
    /// noise-free detection's (no stretch of the true boundary loses its
    /// last detected point within one spacing).
    pub omega_truth: NoiseLevel,
    /// Ψ against the ground truth: no point more than one intended spacing
    /// from the true boundary is newly labelled boundary.
    pub psi_truth: NoiseLevel,
    /// Boundary points of the noise-free detection.
    pub reference_boundary: usize,
    /// Recall of the noise-free detection.
    pub reference_recall: f64,
    /// The steps run, in order (the sweep stops once every level is
    /// found).
    pub steps: Vec<NoiseStep>,
}

/// Runs BPD with `options` on `truth` moved by noise of each of `percents`
/// (% of the intended local resolution, increasing, ≥ 0) and finds Ω and Ψ
/// against the noise-free detection and against the ground truth. `seed`
/// chooses the noise pattern.
pub fn noise_robustness(
    truth: &SyntheticCloud,
    percents: &[f64],
    options: &BpdOptions,
    seed: u64,
) -> Result<NoiseRobustness, CloudError> {
    noise_robustness_with(truth, percents, options, |p| truth.with_noise(p, seed))
}

/// [`noise_robustness`] with the noisy points of each level p (a fraction
/// of the local resolution) from `noisy`: noise along a line of sight, in
/// the tangent plane, or any other kind.
pub fn noise_robustness_with(
    truth: &SyntheticCloud,
    percents: &[f64],
    options: &BpdOptions,
    noisy: impl Fn(f64) -> Vec<P3>,
) -> Result<NoiseRobustness, CloudError> {
    let index = BoundaryIndex::new(truth);
    let deep: Vec<bool> = truth
        .points
        .iter()
        .zip(&truth.spacing)
        .map(|(&p, &h)| index.distance(p) > h)
        .collect();
    let reference = detect_boundary(&truth.points, options)?.boundary;
    let reference_recall = precision_recall_with(&index, &truth.points, &reference, truth).recall;
    let mut result = NoiseRobustness {
        omega: NoiseLevel::start(),
        psi: NoiseLevel::start(),
        omega_truth: NoiseLevel::start(),
        psi_truth: NoiseLevel::start(),
        reference_boundary: reference.iter().filter(|&&b| b).count(),
        reference_recall,
        steps: Vec::new(),
    };
    for &percent in percents {
        let labels = if percent == 0.0 {
            reference.clone()
        } else {
            detect_boundary(&noisy(percent / 100.0), options)?.boundary
        };
        let mut step = NoiseStep {
            percent,
            lost: 0,
            false_boundary: 0,
            false_interior: 0,
            boundary: 0,
            recall: precision_recall_with(&index, &truth.points, &labels, truth).recall,
        };
        for ((&r, &b), &deep) in reference.iter().zip(&labels).zip(&deep) {
            step.lost += usize::from(r && !b);
            step.false_boundary += usize::from(!r && b);
            step.false_interior += usize::from(!r && b && deep);
            step.boundary += usize::from(b);
        }
        result.steps.push(step);
        result.omega.record(percent, step.lost == 0);
        result.psi.record(percent, step.false_boundary == 0);
        result
            .omega_truth
            .record(percent, step.recall >= reference_recall);
        result.psi_truth.record(percent, step.false_interior == 0);
        let levels = [
            result.omega,
            result.psi,
            result.omega_truth,
            result.psi_truth,
        ];
        if levels.iter().all(|l| !l.capped) {
            break;
        }
    }
    Ok(result)
}

/// The sweep 0, `step`, 2·`step`, … up to `max` (percent).
pub fn percent_sweep(step: f64, max: f64) -> Vec<f64> {
    let n = (max / step).floor() as usize;
    (0..=n).map(|i| i as f64 * step).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::{notched_plate, plane_with_holes};

    #[test]
    fn boundary_distance_matches_the_exact_uv_distance_on_the_plane() {
        let c = notched_plate(1.0, 2);
        let index = BoundaryIndex::new(&c);
        for (p, uv) in c.points.iter().zip(&c.uv).step_by(7) {
            let exact = c.distance_to_boundary_uv(*uv);
            assert!((index.distance(*p) - exact).abs() < 1e-3, "{uv:?}");
        }
    }

    #[test]
    fn perfect_and_empty_detections() {
        let c = plane_with_holes(1.0, 4);
        let ideal = ideal_first_layer(&c);
        let a = precision_recall(&c.points, &ideal, &c);
        assert!(a.precision > 0.99 && a.recall > 0.99, "{a:?}");
        let none = precision_recall(&c.points, &vec![false; c.len()], &c);
        assert_eq!((none.precision, none.recall, none.f1), (1.0, 0.0, 0.0));
        let all = precision_recall(&c.points, &vec![true; c.len()], &c);
        // Not 1: the jitter leaves a few places of the boundary with no
        // sample at all within one pitch.
        assert!(all.recall > 0.99 && all.recall >= a.recall, "{all:?}");
        assert!(all.precision < 0.3);
    }

    #[test]
    fn sweep_is_inclusive() {
        assert_eq!(percent_sweep(5.0, 20.0), vec![0.0, 5.0, 10.0, 15.0, 20.0]);
    }
}
