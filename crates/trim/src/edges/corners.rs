//! Corners of a boundary loop (section 3.1 of the paper).
//!
//! The paper labels P_i a corner when the circle through its predecessor,
//! P_i and its successor has a radius below β_i: the boundary turns there
//! on a scale smaller than the local resolution. With the *immediate*
//! neighbours, jitter of a fraction of the spacing makes zig-zags whose
//! circles are that small too, so corners appear on smooth borders.
//! meshtrim keeps the paper's idea and judges the turn at the scale the
//! idea names:
//!
//! - the neighbours of P_i are the points of the loop polyline exactly β_i
//!   of arc before and after it (not the next samples): R(β) < β_i is the paper's criterion
//!   at the paper's scale. For legs of length β and an interior angle θ,
//!   R = β / (2 cos(θ/2)), so this marks turns sharper than 120°, as the
//!   paper's rule does on clean data, and never an arc of radius ≥ β;
//! - the turn must persist at twice that scale, R(2β) < 2β_i: a zig-zag
//!   of the sampling straightens out over 2β, a corner does not (for a
//!   corner R grows in proportion to the scale, for jitter much faster);
//! - one corner per turn: candidates are taken by increasing R(β), and one
//!   within 2β of arc of an accepted corner is dropped.
//!
//! Loops too short to hold a turn at that scale (shorter than 8β) have no
//! corners.

use crate::cloud::{cross, dist2, norm2, sub, Point3};

/// Positions (into `loop_points`) of the corners of a closed loop,
/// ascending. `beta[i]` is the local resolution at `loop_points[i]`.
pub fn find_corners(loop_points: &[Point3], beta: &[f64]) -> Vec<usize> {
    let n = loop_points.len();
    if n < 5 {
        return Vec::new();
    }
    let arc = ArcLength::new(loop_points);
    let mut candidates: Vec<(f64, usize)> = (0..n)
        .filter(|&i| arc.total >= 8.0 * beta[i])
        .filter_map(|i| {
            let r1 = arc.turn_radius(loop_points, i, beta[i])?;
            let r2 = arc.turn_radius(loop_points, i, 2.0 * beta[i])?;
            (r1 < beta[i] && r2 < 2.0 * beta[i]).then_some((r1 / beta[i], i))
        })
        .collect();
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut corners: Vec<usize> = Vec::new();
    for (_, i) in candidates {
        let near = corners
            .iter()
            .any(|&c| arc.between(i, c) < 2.0 * beta[i].max(beta[c]));
        if !near {
            corners.push(i);
        }
    }
    corners.sort_unstable();
    corners
}

/// Cumulative arc length along a closed loop.
struct ArcLength {
    /// `at[i]`: length from point 0 to point i along the loop.
    at: Vec<f64>,
    total: f64,
}

impl ArcLength {
    fn new(pts: &[Point3]) -> Self {
        let n = pts.len();
        let mut at = Vec::with_capacity(n);
        let mut sum = 0.0;
        for i in 0..n {
            at.push(sum);
            sum += dist2(pts[i], pts[(i + 1) % n]).sqrt();
        }
        Self { at, total: sum }
    }

    /// Shorter arc distance between points i and j.
    fn between(&self, i: usize, j: usize) -> f64 {
        let d = (self.at[i] - self.at[j]).abs();
        d.min(self.total - d)
    }

    /// Circumradius of (a, P_i, b), where a and b lie on the loop exactly
    /// `s` of arc before and after P_i; None when the loop is too short.
    fn turn_radius(&self, pts: &[Point3], i: usize, s: f64) -> Option<f64> {
        if 2.0 * s >= self.total {
            return None;
        }
        let a = self.point_at(pts, self.at[i] - s);
        let b = self.point_at(pts, self.at[i] + s);
        Some(circumradius(a, pts[i], b))
    }

    /// The point of the loop at arc position `t` (any real: wraps).
    fn point_at(&self, pts: &[Point3], t: f64) -> Point3 {
        let t = t.rem_euclid(self.total);
        // Last vertex at or before t.
        let k = self.at.partition_point(|&x| x <= t).saturating_sub(1);
        let (p, q) = (pts[k], pts[(k + 1) % pts.len()]);
        let len = dist2(p, q).sqrt();
        let f = if len > 0.0 {
            (t - self.at[k]) / len
        } else {
            0.0
        };
        [0, 1, 2].map(|c| p[c] + f * (q[c] - p[c]))
    }
}

/// Radius of the circle through three points (+∞ if collinear).
fn circumradius(a: Point3, b: Point3, c: Point3) -> f64 {
    let (ab, bc, ca) = (dist2(a, b).sqrt(), dist2(b, c).sqrt(), dist2(c, a).sqrt());
    let twice_area = norm2(cross(sub(b, a), sub(c, a))).sqrt();
    if twice_area == 0.0 {
        return f64::INFINITY;
    }
    ab * bc * ca / (2.0 * twice_area)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rectangle w × h sampled every `step`, with deterministic jitter of
    /// amplitude `jitter` across the border; corners at the first sample
    /// of each side.
    fn jittered_rectangle(w: f64, h: f64, step: f64, jitter: f64) -> (Vec<Point3>, Vec<usize>) {
        let mut pts = Vec::new();
        let mut corners = Vec::new();
        let sides = [
            ([0.0, 0.0], [1.0, 0.0], w),
            ([w, 0.0], [0.0, 1.0], h),
            ([w, h], [-1.0, 0.0], w),
            ([0.0, h], [0.0, -1.0], h),
        ];
        let mut k = 0u64;
        for (start, dir, len) in sides {
            corners.push(pts.len());
            let count = (len / step).round() as usize;
            for s in 0..count {
                k += 1;
                let t = s as f64 * step;
                let wiggle = if s == 0 {
                    0.0
                } else {
                    jitter * (((k * 7919) % 13) as f64 / 6.0 - 1.0)
                };
                // Jitter across the side: along the inward normal (−dir.y, dir.x).
                pts.push([
                    start[0] + dir[0] * t - dir[1] * wiggle,
                    start[1] + dir[1] * t + dir[0] * wiggle,
                    0.0,
                ]);
            }
        }
        (pts, corners)
    }

    #[test]
    fn rectangle_corners_are_found_once_each() {
        let (pts, truth) = jittered_rectangle(40.0, 25.0, 1.0, 0.3);
        let found = find_corners(&pts, &vec![1.3; pts.len()]);
        assert_eq!(found.len(), 4, "{found:?}");
        for (f, t) in found.iter().zip(&truth) {
            assert!(f.abs_diff(*t) <= 2, "corner at {f}, expected near {t}");
        }
    }

    #[test]
    fn jittered_circles_have_no_corners() {
        for (radius, jitter) in [(3.0, 0.3), (10.0, 0.3), (40.0, 0.4)] {
            let n = (std::f64::consts::TAU * radius).round() as usize;
            let pts: Vec<Point3> = (0..n)
                .map(|i| {
                    let t = i as f64 / n as f64 * std::f64::consts::TAU;
                    let r = radius + jitter * (((i * 7919) % 13) as f64 / 6.0 - 1.0);
                    [r * t.cos(), r * t.sin(), 0.0]
                })
                .collect();
            let found = find_corners(&pts, &vec![1.3; n]);
            assert!(found.is_empty(), "radius {radius}: {found:?}");
        }
    }

    #[test]
    fn a_four_point_hole_has_no_corner() {
        let pts = [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
        ];
        assert!(find_corners(&pts, &[1.0; 4]).is_empty());
    }
}
