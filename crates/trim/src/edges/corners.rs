//! Corners of a boundary loop (section 3.1 of the paper).
//!
//! The paper labels P_i a corner when the circle through its predecessor,
//! P_i and its successor has a radius below β_i: the boundary turns there
//! on a scale smaller than the local resolution. With the *immediate*
//! neighbours, jitter of a fraction of the spacing makes zig-zags whose
//! circles are that small too, so corners appear on smooth borders.
//! meshtrim keeps the paper's idea — a corner is where the loop turns on a
//! scale smaller than β — and measures the turn robustly:
//!
//! - the circle goes through P_i and the points of the loop polyline exactly
//!   s of arc before and after it (not the next samples). For legs of
//!   length s and an interior angle θ, R(s) = s / (2 cos(θ/2)), so R(s) < s
//!   means a turn sharper than 120°, the paper's R < β rule on clean data;
//! - the turn is required at s = 2β and s = 4β: jitter of the sampling makes
//!   zig-zags sharp at the scale of one spacing, which straighten out over
//!   two; on measured jittered boundaries R(β) of a straight side fell to
//!   0.7β while true 90° corners scored 0.63–0.99β, so the paper's scale
//!   cannot separate them, while at 2β and 4β the sides score above 1 and
//!   the corners 0.63–0.99;
//! - the turn must be *concentrated*: for a corner R grows in proportion to
//!   the scale (R(4β) = 2·R(2β), R(6β) = 1.5·R(4β)), for a circular arc it
//!   stays the radius. Requiring R(4β) ≥ 1.5·R(2β) and R(6β) ≥ 1.25·R(4β)
//!   (and R(6β) < 6β) keeps arcs corner-free — holes of any radius, curved
//!   borders — which is the paper's intent for arcs of radius ≥ β; the
//!   third scale catches a kink of the sampling on a small hole, which
//!   passes the first two (measured on the blade's 4-spacing holes);
//! - one corner per turn: candidates by increasing R(2β)/2β + R(4β)/4β; a
//!   candidate within 4β of arc of an accepted corner is dropped. (So two
//!   corners less than 4β apart, such as both corners of a slot narrower
//!   than 4β, count as one.)
//!
//! Loops shorter than 12β have no corners (the test needs 6β on each side):
//! a hole of radius ≈ β found by four points is one closed edge, as in the
//! paper's Figure 4.

use crate::geom::{cross, dist2, norm2, sub, Point3};

/// Positions (into `loop_points`) of the corners of a closed loop,
/// ascending. `beta[i]` is the local resolution at `loop_points[i]`.
pub fn find_corners(loop_points: &[Point3], beta: &[f64]) -> Vec<usize> {
    let n = loop_points.len();
    if n < 5 {
        return Vec::new();
    }
    let arc = ArcLength::new(loop_points);
    let mut candidates: Vec<(f64, usize)> = (0..n)
        .filter_map(|i| {
            let b = beta[i];
            let near = arc.turn_radius(loop_points, i, NEAR * b)?;
            let far = arc.turn_radius(loop_points, i, FAR * b)?;
            let wide = arc.turn_radius(loop_points, i, WIDE * b)?;
            let sharp = near < NEAR * b && far < FAR * b && wide < WIDE * b;
            // R ∝ scale for a corner: ratios 2 and 1.5; 1 for an arc.
            let concentrated = far >= 1.5 * near && wide >= 1.25 * far;
            (sharp && concentrated).then_some((near / (NEAR * b) + far / (FAR * b), i))
        })
        .collect();
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut corners: Vec<usize> = Vec::new();
    for (_, i) in candidates {
        let near = corners
            .iter()
            .any(|&c| arc.between(i, c) < FAR * beta[i].max(beta[c]));
        if !near {
            corners.push(i);
        }
    }
    corners.sort_unstable();
    corners
}

/// The three scales of the turn test, in units of β.
const NEAR: f64 = 3.0;
const FAR: f64 = 6.0;
const WIDE: f64 = 9.0;

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
