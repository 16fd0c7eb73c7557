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
use crate::rows::RowScratch;

/// Nearest-neighbour distance of every member, within the neighbourhood.
///
/// `out[j]` is the distance from `pts[j]` to the closest other member.
/// Plain reference of [`nearest_distances_fast`].
pub fn nearest_distances(pts: &[Point2], out: &mut Vec<f64>) {
    out.clear();
    out.resize(pts.len(), f64::INFINITY);
    for j in 0..pts.len() {
        for m in j + 1..pts.len() {
            let d = dist2(pts[j], pts[m]);
            if d < out[j] {
                out[j] = d;
            }
            if d < out[m] {
                out[m] = d;
            }
        }
    }
    for d in out.iter_mut() {
        *d = d.sqrt();
    }
}

/// [`nearest_distances`] of the points loaded in `rows`, by vectorised row
/// sweeps; the same result.
pub fn nearest_distances_fast(rows: &mut RowScratch, out: &mut Vec<f64>) {
    out.clear();
    for j in 0..rows.len() {
        rows.fill_row(j);
        out.push(rows.row_min().map_or(f64::INFINITY, |(d2, _)| d2.sqrt()));
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
    fn fast_distances_equal_reference() {
        let pts: Vec<Point2> = (0..37)
            .map(|i| [((i * 17) % 23) as f64 * 0.37, ((i * 5) % 11) as f64 * 1.3])
            .collect();
        let (mut slow, mut fast) = (Vec::new(), Vec::new());
        nearest_distances(&pts, &mut slow);
        let mut rows = RowScratch::default();
        rows.load(&pts);
        nearest_distances_fast(&mut rows, &mut fast);
        assert_eq!(slow, fast);
    }

    #[test]
    fn beta_adds_two_standard_deviations() {
        assert!((beta_of(&[1.0, 3.0]) - (2.0 + 2.0)).abs() < 1e-12);
    }
}
