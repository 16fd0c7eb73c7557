//! Local resolution β_i = μ_i + 2σ_i (section 2 of the paper).
//!
//! "For every point of its neighbourhood (P_i,j), the minimum distance (d_j,k)
//! between that point and all other neighbours is computed"; μ_i and σ_i are
//! the mean and the (population) standard deviation of these minimum
//! distances over all k members of the neighbourhood, the investigated point
//! included. meshtrim measures them in the neighbourhood's plane after the
//! anisotropy map (see `docs/bpd.md`): out-of-plane noise then does not
//! inflate β, and on line scans β is the spacing the tests see.

use crate::frame::Point2;

/// Nearest-neighbour distance of every member, within the neighbourhood.
///
/// `out[j]` is the distance from `pts[j]` to the closest other member. Each
/// pair is measured once; the inner loop's minimum updates are branch-free
/// and vectorise.
pub fn nearest_distances(pts: &[Point2], out: &mut Vec<f64>) {
    out.clear();
    out.resize(pts.len(), f64::INFINITY);
    for j in 0..pts.len() {
        let p = pts[j];
        let (head, tail) = out.split_at_mut(j + 1);
        let mut best = head[j];
        for (d_m, &q) in tail.iter_mut().zip(&pts[j + 1..]) {
            let d = dist2(p, q);
            // `if` rather than `f64::min`, whose NaN handling blocks the
            // plain min instruction (no NaN can occur here).
            best = if d < best { d } else { best };
            *d_m = if d < *d_m { d } else { *d_m };
        }
        head[j] = best;
    }
    for d in out.iter_mut() {
        *d = d.sqrt();
    }
}

/// β = μ + 2σ of the given distances (0 for an empty slice).
pub fn beta_of(distances: &[f64]) -> f64 {
    if distances.is_empty() {
        return 0.0;
    }
    let n = distances.len() as f64;
    let mean = distances.iter().sum::<f64>() / n;
    let var = distances
        .iter()
        .map(|d| (d - mean) * (d - mean))
        .sum::<f64>()
        / n;
    mean + 2.0 * var.sqrt()
}

pub(crate) fn dist2(a: Point2, b: Point2) -> f64 {
    let (dx, dy) = (a[0] - b[0], a[1] - b[1]);
    dx * dx + dy * dy
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn beta_of_a_regular_grid_is_its_spacing() {
        let pts: Vec<Point2> = (0..30)
            .map(|i| [(i % 6) as f64 * 2.0, (i / 6) as f64 * 2.0])
            .collect();
        let mut d = Vec::new();
        nearest_distances(&pts, &mut d);
        assert!(d.iter().all(|&x| (x - 2.0).abs() < 1e-12));
        assert!((beta_of(&d) - 2.0).abs() < 1e-12);
    }

    #[test]
    fn beta_adds_two_standard_deviations() {
        assert!((beta_of(&[1.0, 3.0]) - (2.0 + 2.0)).abs() < 1e-12);
    }
}
