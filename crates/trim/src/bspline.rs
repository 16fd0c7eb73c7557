//! Cubic B-spline curves through the smoothed edge points, for CAD export
//! (meshtrim's extension; the paper stops at the smoothed points).
//!
//! A centripetal Catmull–Rom spline (parameters spaced by the square root
//! of the chord length, which keeps the curve tight to the polygon and
//! free of cusps and self-intersections; Yuksel, Schaefer and Keyser 2011):
//! between consecutive
//! points a cubic Hermite segment whose end tangents are the central
//! differences of the neighbouring points (one-sided at an open curve's
//! ends, across the seam of a closed one). Written as a B-spline with
//! interior knots of multiplicity 3, every data point is a control point
//! the curve passes through exactly, to the bit, so consecutive edges meet
//! exactly at their corners and a closed loop closes exactly; the tangents
//! match across each point, so the curve is C¹. A local interpolant was
//! chosen over the global C² one (Piegl and Tiller, section 9.2.1) because
//! the C² curve's tangents depend on every point and it overshoots around
//! the short, sharply turning loops of real scans (small holes of four to
//! six points); this one bends only between the points around each turn.
//!
//! Round the sharpest turns of those small loops even the Catmull–Rom
//! handles swing out of the polygon, so a point's tangent is shortened
//! where a segment would stray from its chord by more than
//! [`MAX_BULGE`] of the curve's median chord (`limited`); the curve still
//! passes through every point and stays C¹.

use crate::geom::{dot, norm2, sub, Point3};

/// A clamped B-spline curve of degree `degree`: knots as distinct values
/// with multiplicities (as STEP writes them), control points.
#[derive(Debug, Clone, PartialEq)]
pub struct BSpline {
    /// The degree (3).
    pub degree: usize,
    /// Control points: each data point, and two between consecutive ones.
    pub control_points: Vec<Point3>,
    /// Distinct knot values, ascending, from 0 to 1.
    pub knots: Vec<f64>,
    /// Multiplicity of each distinct knot (`degree + 1` at both ends).
    pub multiplicities: Vec<usize>,
}

/// The cubic B-spline through `points` (see the module doc), back to the
/// first point when `closed`. `None` for fewer than two points, or when
/// consecutive points coincide (no parameter step between them).
pub fn interpolate(points: &[Point3], closed: bool) -> Option<BSpline> {
    let mut through = points.to_vec();
    if closed {
        through.push(*points.first()?);
    }
    let n = through.len();
    if n < 2 {
        return None;
    }
    let params = centripetal_parameters(&through)?;
    let tangents = limited(
        tangents(&through, &params, closed),
        &through,
        &params,
        closed,
    );
    let mut control_points = Vec::with_capacity(3 * n - 2);
    for i in 0..n - 1 {
        let h = (params[i + 1] - params[i]) / 3.0;
        let (p, q) = (through[i], through[i + 1]);
        let (s, t) = (tangents[i], tangents[i + 1]);
        control_points.push(p);
        control_points.push([p[0] + s[0] * h, p[1] + s[1] * h, p[2] + s[2] * h]);
        control_points.push([q[0] - t[0] * h, q[1] - t[1] * h, q[2] - t[2] * h]);
    }
    control_points.push(through[n - 1]);
    let mut multiplicities = vec![3; n];
    multiplicities[0] = 4;
    multiplicities[n - 1] = 4;
    Some(BSpline {
        degree: 3,
        control_points,
        knots: params,
        multiplicities,
    })
}

/// Catmull–Rom tangents (d/du) at the points: central differences over the
/// parameters; at the ends of an open curve the one-sided
/// chord, around the seam of a closed one the central difference across it.
fn tangents(points: &[Point3], params: &[f64], closed: bool) -> Vec<Point3> {
    let n = points.len();
    let slope = |a: usize, b: usize, du: f64| -> Point3 {
        [0, 1, 2].map(|c| (points[b][c] - points[a][c]) / du)
    };
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let t = if i > 0 && i + 1 < n {
            slope(i - 1, i + 1, params[i + 1] - params[i - 1])
        } else if closed {
            // The seam: the last point repeats the first.
            let du = (1.0 - params[n - 2]) + params[1];
            slope(n - 2, 1, du)
        } else if i == 0 {
            slope(0, 1, params[1])
        } else {
            slope(n - 2, n - 1, 1.0 - params[n - 2])
        };
        out.push(t);
    }
    out
}

/// Farthest a segment may stray from its chord, as a share of the curve's
/// median chord (its points' typical spacing).
pub const MAX_BULGE: f64 = 0.15;

/// The tangents shortened where a segment would bulge more than
/// [`MAX_BULGE`] of the median chord from its own chord: round a sharp
/// turn of a small loop the Catmull–Rom handles swing out of the polygon.
/// A segment strays from its chord by at most 3/4 of its handles' larger
/// offset across the chord (3(1−t)t ≤ 3/4 in the Bézier form), so the
/// handles are scaled until that bound holds. Each point's tangent is
/// scaled as a whole (both of its handles, keeping its direction), so the
/// curve stays C¹ and still passes through every point exactly; where no
/// segment bulges the curve is the plain centripetal Catmull–Rom one.
fn limited(
    mut tangents: Vec<Point3>,
    points: &[Point3],
    params: &[f64],
    closed: bool,
) -> Vec<Point3> {
    let n = points.len();
    let chords: Vec<Point3> = points.windows(2).map(|w| sub(w[1], w[0])).collect();
    let bound = {
        let mut lengths: Vec<f64> = chords.iter().map(|&c| norm2(c).sqrt()).collect();
        lengths.sort_unstable_by(f64::total_cmp);
        MAX_BULGE * lengths[lengths.len() / 2]
    };
    let mut scale = vec![1.0f64; n];
    for (i, &chord) in chords.iter().enumerate() {
        let step = (params[i + 1] - params[i]) / 3.0;
        for end in [i, i + 1] {
            let bulge = 0.75 * across(tangents[end].map(|c| c * step), chord);
            if bulge > bound {
                scale[end] = scale[end].min(bound / bulge);
            }
        }
    }
    if closed {
        // The seam's two ends are one point: one tangent.
        let both = scale[0].min(scale[n - 1]);
        scale[0] = both;
        scale[n - 1] = both;
    }
    for (t, s) in tangents.iter_mut().zip(scale) {
        *t = t.map(|c| c * s);
    }
    tangents
}

/// Length of the part of `v` square to `chord` (all of `v` for a zero chord).
fn across(v: Point3, chord: Point3) -> f64 {
    let c2 = norm2(chord);
    if c2 == 0.0 {
        return norm2(v).sqrt();
    }
    let along = dot(v, chord) / c2;
    norm2(sub(v, chord.map(|c| c * along))).sqrt()
}

impl BSpline {
    /// The same curve with its interior knots of multiplicity 2, C¹ in its
    /// parameter as well as in shape (readers that split curves at knots
    /// of lower continuity, such as OpenCASCADE's IGES reader, keep it
    /// whole). Knot removal drops each interior data point from the
    /// control points: it is exactly the mean of the control points beside
    /// it weighted by the parameter steps, so the curve still passes
    /// through it, to rounding rather than to the bit. Ends are unchanged.
    pub fn with_double_knots(&self) -> BSpline {
        let last = self.control_points.len() - 1;
        let control_points = self
            .control_points
            .iter()
            .enumerate()
            .filter(|&(i, _)| i == 0 || i == last || i % 3 != 0)
            .map(|(_, &p)| p)
            .collect();
        let inner = self.multiplicities.len() - 1;
        let multiplicities = (0..=inner)
            .map(|i| {
                if i == 0 || i == inner {
                    self.degree + 1
                } else {
                    2
                }
            })
            .collect();
        BSpline {
            degree: self.degree,
            control_points,
            knots: self.knots.clone(),
            multiplicities,
        }
    }

    /// The full knot vector, each knot repeated by its multiplicity.
    pub fn knot_vector(&self) -> Vec<f64> {
        self.knots
            .iter()
            .zip(&self.multiplicities)
            .flat_map(|(&k, &m)| std::iter::repeat_n(k, m))
            .collect()
    }

    /// The point at parameter `u` in [0, 1] (de Boor's algorithm).
    pub fn point_at(&self, u: f64) -> Point3 {
        let knots = self.knot_vector();
        let p = self.degree;
        let span = find_span(&knots, p, self.control_points.len() - 1, u);
        let mut d: Vec<Point3> = (0..=p).map(|j| self.control_points[span - p + j]).collect();
        for r in 1..=p {
            for j in (r..=p).rev() {
                let i = span - p + j;
                let denominator = knots[i + p + 1 - r] - knots[i];
                let alpha = if denominator > 0.0 {
                    (u - knots[i]) / denominator
                } else {
                    0.0
                };
                let (before, at) = (d[j - 1], d[j]);
                d[j] = [0, 1, 2].map(|c| (1.0 - alpha) * before[c] + alpha * at[c]);
            }
        }
        d[p]
    }
}

/// Centripetal parameters: the running sum of √(chord length), from 0 to 1.
fn centripetal_parameters(points: &[Point3]) -> Option<Vec<f64>> {
    let chords: Vec<f64> = points
        .windows(2)
        .map(|w| {
            let d = [w[1][0] - w[0][0], w[1][1] - w[0][1], w[1][2] - w[0][2]];
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt().sqrt()
        })
        .collect();
    let total: f64 = chords.iter().sum();
    if !(total > 0.0 && total.is_finite()) || chords.iter().any(|&c| c <= 0.0) {
        return None;
    }
    let mut params = Vec::with_capacity(points.len());
    let mut run = 0.0;
    params.push(0.0);
    for &c in &chords[..chords.len() - 1] {
        run += c;
        params.push(run / total);
    }
    params.push(1.0);
    Some(params)
}

/// The knot span of `u`: the `i` with `knots[i] <= u < knots[i + 1]`, the
/// last non-empty span for `u = 1` (algorithm A2.1).
fn find_span(knots: &[f64], degree: usize, last: usize, u: f64) -> usize {
    if u >= knots[last + 1] {
        return last;
    }
    let (mut low, mut high) = (degree, last + 1);
    while high - low > 1 {
        let mid = (low + high) / 2;
        if u < knots[mid] {
            high = mid;
        } else {
            low = mid;
        }
    }
    low
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dist(a: Point3, b: Point3) -> f64 {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    }

    fn wavy(n: usize, seed: u64) -> Vec<Point3> {
        let mut state = seed;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut t = 0.0;
        (0..n)
            .map(|_| {
                t += 0.5 + next();
                [t, (t * 0.3).sin() * 4.0, 0.2 * t + next() * 0.1]
            })
            .collect()
    }

    /// Reference: the Hermite segment between points i and i + 1 at
    /// fraction s, evaluated from its cubic Hermite basis.
    fn hermite(p: Point3, q: Point3, s_tan: Point3, t_tan: Point3, h: f64, s: f64) -> Point3 {
        let (h00, h10) = (
            2.0 * s.powi(3) - 3.0 * s * s + 1.0,
            s.powi(3) - 2.0 * s * s + s,
        );
        let (h01, h11) = (-2.0 * s.powi(3) + 3.0 * s * s, s.powi(3) - s * s);
        [0, 1, 2].map(|c| h00 * p[c] + h10 * h * s_tan[c] + h01 * q[c] + h11 * h * t_tan[c])
    }

    #[test]
    fn the_curve_passes_through_every_point_bit_for_bit() {
        for n in [2, 3, 4, 5, 17, 400] {
            for closed in [false, true] {
                let points = wavy(n, n as u64);
                let curve = interpolate(&points, closed).unwrap();
                let params = centripetal_parameters(&curve_points(&points, closed)).unwrap();
                for (p, u) in points.iter().zip(&params) {
                    assert_eq!(curve.point_at(*u), *p, "n {n}");
                }
                let total: usize = curve.multiplicities.iter().sum();
                assert_eq!(total, curve.control_points.len() + curve.degree + 1);
                if closed {
                    assert_eq!(curve.point_at(1.0), points[0]);
                }
            }
        }
    }

    fn curve_points(points: &[Point3], closed: bool) -> Vec<Point3> {
        let mut through = points.to_vec();
        if closed {
            through.push(points[0]);
        }
        through
    }

    #[test]
    fn de_boor_matches_the_hermite_segments() {
        for seed in 1..10 {
            let points = wavy(6 + seed as usize, seed);
            let curve = interpolate(&points, false).unwrap();
            let params = centripetal_parameters(&points).unwrap();
            let tangents = limited(tangents(&points, &params, false), &points, &params, false);
            for i in 0..points.len() - 1 {
                let h = params[i + 1] - params[i];
                for s in [0.1, 0.5, 0.9] {
                    let expected =
                        hermite(points[i], points[i + 1], tangents[i], tangents[i + 1], h, s);
                    let got = curve.point_at(params[i] + s * h);
                    assert!(dist(got, expected) < 1e-9, "seed {seed}");
                }
            }
        }
    }

    #[test]
    fn double_knots_give_the_same_curve() {
        for seed in 1..10 {
            for closed in [false, true] {
                let points = wavy(2 + 3 * seed as usize, seed);
                let curve = interpolate(&points, closed).unwrap();
                let c1 = curve.with_double_knots();
                let total: usize = c1.multiplicities.iter().sum();
                assert_eq!(total, c1.control_points.len() + c1.degree + 1);
                let scale = points.iter().flatten().fold(0f64, |m, c| m.max(c.abs()));
                for k in 0..=1000 {
                    let u = f64::from(k) / 1000.0;
                    let d = dist(curve.point_at(u), c1.point_at(u));
                    assert!(d < 1e-12 * scale, "seed {seed} closed {closed} u {u}: {d}");
                }
                assert_eq!(c1.point_at(0.0), points[0]);
                assert_eq!(c1.control_points.last(), curve.control_points.last());
            }
        }
    }

    /// Distance from `p` to the segment `a`–`b`.
    fn to_segment(p: Point3, a: Point3, b: Point3) -> f64 {
        let ab = sub(b, a);
        let t = (dot(sub(p, a), ab) / norm2(ab)).clamp(0.0, 1.0);
        dist(p, [0, 1, 2].map(|c| a[c] + t * ab[c]))
    }

    /// Small loops with sharp turns (five to eight points at radii 0.3 to
    /// 1.7 round a circle): every segment stays within MAX_BULGE of the median chord
    /// of its own chord, where the plain Catmull–Rom curve strays farther.
    #[test]
    fn sharp_turns_do_not_bulge() {
        let mut plain_worst = 0.0f64;
        for seed in 0..200u64 {
            let n = 5 + (seed % 4) as usize;
            let points: Vec<Point3> = (0..n)
                .map(|i| {
                    let jag = ((seed * 7 + i as u64 * 13) % 11) as f64 / 10.0;
                    let a = std::f64::consts::TAU * (i as f64 + 0.4 * jag) / n as f64;
                    let r = 0.3 + 1.4 * jag;
                    [r * a.cos(), r * a.sin(), 0.0]
                })
                .collect();
            let through = curve_points(&points, true);
            let params = centripetal_parameters(&through).unwrap();
            let mut chords: Vec<f64> = through.windows(2).map(|w| dist(w[0], w[1])).collect();
            chords.sort_unstable_by(f64::total_cmp);
            let bound = MAX_BULGE * chords[chords.len() / 2];
            let curve = interpolate(&points, true).unwrap();
            let plain = tangents(&through, &params, true);
            for i in 0..n {
                let h = params[i + 1] - params[i];
                for k in 1..50 {
                    let s = f64::from(k) / 50.0;
                    let on = curve.point_at(params[i] + s * h);
                    let off = to_segment(on, through[i], through[i + 1]);
                    assert!(
                        off <= bound * (1.0 + 1e-9),
                        "seed {seed} segment {i}: {off} > {bound}"
                    );
                    let free = hermite(through[i], through[i + 1], plain[i], plain[i + 1], h, s);
                    plain_worst =
                        plain_worst.max(to_segment(free, through[i], through[i + 1]) / bound);
                }
            }
        }
        assert!(
            plain_worst > 1.0,
            "the plain curve bulges only {plain_worst} of the bound"
        );
    }

    /// Where nothing bulges (a finely sampled circle), the limit leaves the
    /// plain Catmull–Rom tangents alone.
    #[test]
    fn smooth_curves_keep_their_tangents() {
        let points: Vec<Point3> = (0..64)
            .map(|i| {
                let a = std::f64::consts::TAU * f64::from(i) / 64.0;
                [a.cos(), a.sin(), 0.1 * a.sin()]
            })
            .collect();
        let through = curve_points(&points, true);
        let params = centripetal_parameters(&through).unwrap();
        let plain = tangents(&through, &params, true);
        assert_eq!(limited(plain.clone(), &through, &params, true), plain);
    }

    #[test]
    fn a_straight_line_stays_straight() {
        let points: Vec<Point3> = (0..10).map(|i| [f64::from(i * i), 0.0, 0.0]).collect();
        let curve = interpolate(&points, false).unwrap();
        for c in &curve.control_points {
            assert_eq!(&c[1..], &[0.0, 0.0]);
        }
    }

    #[test]
    fn repeated_or_too_few_points_have_no_curve() {
        assert!(interpolate(&[[0.0; 3]], false).is_none());
        assert!(interpolate(&[[0.0; 3], [0.0; 3], [1.0, 0.0, 0.0]], false).is_none());
    }
}
