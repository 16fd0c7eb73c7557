//! Metrics of reconstructed edges (polylines of [`Point3`]).
//!
//! - [`points_to_polyline`]: the paper's Table 2 metric, the mean, maximum
//!   and standard deviation of the distances from the boundary points to
//!   the smoothed edges;
//! - [`polyline_to_truth_in_spacings`]: how far an edge strays from the
//!   true boundary of a synthetic cloud, in local spacings;
//! - [`true_corners`] and [`match_corners`]: corners of the true boundary
//!   and how many of them a corner finder recovers;
//! - [`tour_jumps`]: steps of a loop that jump across the surface (longer
//!   than 3β and not a BPD link).
//!
//! Distances to a polyline are exact (to its segments, not its vertices):
//! the polyline is sampled at most `δ` apart (δ its mean segment length,
//! so at most about twice as many samples as segments), the samples go in
//! a k-d tree, and for a query point p with nearest sample at distance d_s
//! every sample within d_s + δ/2 is visited and the two segments at it are
//! measured. The nearest point of the polyline lies within δ/2 of a sample
//! of its own segment (or of the vertex that ends it), so its segment is
//! among those measured.
//!
//! [`DistanceStats::std`] is the population standard deviation (divided by
//! the count, as the paper's STD of all distances).

use kiddo::{ImmutableKdTree, SquaredEuclidean};

use crate::synthetic::BoundaryIndex;
use crate::synthetic::SyntheticCloud;
use crate::vec3::{dist2, dot, norm2, sub};
use trim::internals::step_is_supported;
use trim::Point3;

/// Turning angle above which a vertex of a true boundary is a corner
/// ([`true_corners`]), in degrees.
pub const TRUE_CORNER_ANGLE_DEG: f64 = 30.0;

/// Upper bound on the samples [`polyline_to_truth_in_spacings`] takes; a
/// smaller `step` is raised to keep within it.
pub const MAX_SAMPLES: usize = 5_000_000;

/// Mean, maximum and population standard deviation of a set of distances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistanceStats {
    /// Mean distance.
    pub mean: f64,
    /// Largest distance.
    pub max: f64,
    /// Population standard deviation (√ of the mean squared deviation).
    pub std: f64,
    /// Number of distances.
    pub count: usize,
}

impl DistanceStats {
    /// Statistics of `d`; all zero for an empty slice. An infinite distance
    /// makes mean and max infinite and std NaN.
    pub fn from_distances(d: &[f64]) -> Self {
        if d.is_empty() {
            return Self {
                mean: 0.0,
                max: 0.0,
                std: 0.0,
                count: 0,
            };
        }
        let n = d.len() as f64;
        let mean = d.iter().sum::<f64>() / n;
        let var = d.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n;
        Self {
            mean,
            max: d.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            std: var.sqrt(),
            count: d.len(),
        }
    }
}

/// Distances from each of `points` to the polyline (`closed`: the last
/// vertex joins the first). With no polyline vertex every distance is
/// infinite (mean = max = ∞); a single vertex is a point.
pub fn points_to_polyline(points: &[Point3], polyline: &[Point3], closed: bool) -> DistanceStats {
    let index = PolylineIndex::new(polyline, closed);
    let d: Vec<f64> = points.iter().map(|&p| index.distance(p)).collect();
    DistanceStats::from_distances(&d)
}

/// Distances from the polyline, sampled at most `step` apart (its vertices
/// included), to the true boundary of `truth` (3D, [`BoundaryIndex`]), each
/// divided by the intended spacing (`truth.spacing`) of the cloud point
/// nearest the sample: distances in local spacings. A non-positive or
/// non-finite `step` samples the vertices only; `step` is raised if needed
/// to keep within [`MAX_SAMPLES`]. An empty polyline gives zero statistics;
/// a truth without points or boundary, infinite distances.
pub fn polyline_to_truth_in_spacings(
    polyline: &[Point3],
    closed: bool,
    step: f64,
    truth: &SyntheticCloud,
) -> DistanceStats {
    let samples = densify(polyline, closed, step);
    if samples.is_empty() {
        return DistanceStats::from_distances(&[]);
    }
    let boundary_len: usize = truth.boundary.iter().map(Vec::len).sum();
    if truth.is_empty() || boundary_len == 0 {
        return DistanceStats::from_distances(&vec![f64::INFINITY; samples.len()]);
    }
    let index = BoundaryIndex::new(truth);
    let Ok(cloud) = ImmutableKdTree::<f64, 3>::new_from_slice(&truth.points) else {
        return DistanceStats::from_distances(&vec![f64::INFINITY; samples.len()]);
    };
    let d: Vec<f64> = samples
        .iter()
        .map(|s| {
            let nearest = cloud
                .query(s)
                .nearest_one::<SquaredEuclidean<f64>>()
                .execute();
            index.distance(*s) / truth.spacing[nearest.item as usize]
        })
        .collect();
    DistanceStats::from_distances(&d)
}

/// Matches found corners to true corners: a true corner is found if some
/// found corner lies within `tol` of it (3D). Returns (true corners found,
/// true corners missed, found corners with no true corner within `tol`).
/// The matching is not one-to-one: two found corners near one true corner
/// both count as matched (neither is false).
pub fn match_corners(found: &[Point3], truth: &[Point3], tol: f64) -> (usize, usize, usize) {
    let tol2 = tol * tol;
    let near = |a: Point3, set: &[Point3]| set.iter().any(|&b| dist2(a, b) <= tol2);
    let found_true = truth.iter().filter(|&&t| near(t, found)).count();
    let false_found = found.iter().filter(|&&f| !near(f, truth)).count();
    (found_true, truth.len() - found_true, false_found)
}

/// Corners of the true boundary of `truth`: vertices of the closed
/// polylines of [`SyntheticCloud::boundary_3d`] where the direction turns by
/// more than [`TRUE_CORNER_ANGLE_DEG`] (30°) between the incoming and the
/// outgoing segment. The true boundaries are the region's polygon, whose
/// vertices are samples, subdivided at most h/20 apart, and hole circles
/// sampled as finely: smooth parts turn by far less than 30° per sample (a
/// circle needs fewer than 12 samples to reach it), so only the polygon's
/// real corners qualify.
pub fn true_corners(truth: &SyntheticCloud) -> Vec<Point3> {
    truth
        .boundary_3d()
        .iter()
        .flat_map(|curve| {
            let pts: Vec<Point3> = curve.iter().map(|&(p, _)| p).collect();
            turning_vertices(&pts, true, TRUE_CORNER_ANGLE_DEG)
                .into_iter()
                .map(move |i| pts[i])
        })
        .collect()
}

/// Positions of the vertices of a polyline where the direction turns by
/// more than `min_angle_deg` degrees (the ends of an open polyline never
/// do). Zero-length segments are skipped: the turn is measured between the
/// nearest distinct neighbours.
pub fn turning_vertices(polyline: &[Point3], closed: bool, min_angle_deg: f64) -> Vec<usize> {
    let n = polyline.len();
    if n < 3 {
        return Vec::new();
    }
    let cos_max = min_angle_deg.to_radians().cos();
    let neighbour = |i: usize, forward: bool| -> Option<Point3> {
        let p = polyline[i];
        for k in 1..n {
            let j = if forward {
                if !closed && i + k >= n {
                    return None;
                }
                (i + k) % n
            } else {
                if !closed && k > i {
                    return None;
                }
                (i + n - k) % n
            };
            if dist2(polyline[j], p) > 0.0 {
                return Some(polyline[j]);
            }
        }
        None
    };
    (0..n)
        .filter(|&i| {
            let (Some(a), Some(b)) = (neighbour(i, false), neighbour(i, true)) else {
                return false;
            };
            let u = sub(polyline[i], a);
            let v = sub(b, polyline[i]);
            let c = dot(u, v) / (norm2(u) * norm2(v)).sqrt();
            c < cos_max
        })
        .collect()
}

/// The polyline sampled at most `step` apart (vertices included; the
/// closing segment too when `closed`).
fn densify(polyline: &[Point3], closed: bool, step: f64) -> Vec<Point3> {
    let n = polyline.len();
    if n < 2 {
        return polyline.to_vec();
    }
    let segments = if closed { n } else { n - 1 };
    let seg = |k: usize| (polyline[k], polyline[(k + 1) % n]);
    let total: f64 = (0..segments)
        .map(|k| {
            let (a, b) = seg(k);
            dist2(a, b).sqrt()
        })
        .sum();
    let step = if step > 0.0 && step.is_finite() && total.is_finite() {
        step.max(total / MAX_SAMPLES.saturating_sub(n + 1).max(1) as f64)
    } else {
        f64::INFINITY
    };
    let mut out = Vec::new();
    for k in 0..segments {
        let (a, b) = seg(k);
        let m = (dist2(a, b).sqrt() / step).ceil().max(1.0) as usize;
        for j in 0..m {
            let t = j as f64 / m as f64;
            out.push(std::array::from_fn(|c| a[c] + t * (b[c] - a[c])));
        }
    }
    if !closed {
        out.push(polyline[n - 1]);
    }
    out
}

/// Exact point-to-polyline distances (see the module doc).
struct PolylineIndex<'a> {
    vertices: &'a [Point3],
    closed: bool,
    /// Segment k joins vertex k to vertex k + 1 (mod n when closed).
    segments: usize,
    /// The segment each sample lies on (the last vertex of an open
    /// polyline: the last segment).
    segment_of: Vec<usize>,
    half_step: f64,
    tree: Option<ImmutableKdTree<f64, 3>>,
}

impl<'a> PolylineIndex<'a> {
    fn new(vertices: &'a [Point3], closed: bool) -> Self {
        let n = vertices.len();
        let segments = match n {
            0 | 1 => 0,
            2 => 1,
            _ if closed => n,
            _ => n - 1,
        };
        let len = |k: usize| dist2(vertices[k], vertices[(k + 1) % n]).sqrt();
        let mean = if segments > 0 {
            (0..segments).map(len).sum::<f64>() / segments as f64
        } else {
            0.0
        };
        let mut samples = Vec::new();
        let mut segment_of = Vec::new();
        let mut step: f64 = 0.0;
        for k in 0..segments {
            let (a, b) = (vertices[k], vertices[(k + 1) % n]);
            let l = len(k);
            let m = if mean > 0.0 && mean.is_finite() {
                ((l / mean).ceil() as usize).max(1)
            } else {
                1
            };
            step = step.max(l / m as f64);
            for j in 0..m {
                let t = j as f64 / m as f64;
                samples.push(std::array::from_fn(|c| a[c] + t * (b[c] - a[c])));
                segment_of.push(k);
            }
        }
        if n >= 2 && segments == n - 1 {
            samples.push(vertices[n - 1]);
            segment_of.push(segments.saturating_sub(1));
        }
        let tree = if samples.iter().flatten().all(|v| v.is_finite()) {
            ImmutableKdTree::new_from_slice(&samples).ok()
        } else {
            None
        };
        Self {
            vertices,
            closed,
            segments,
            segment_of,
            half_step: 0.5 * step,
            tree,
        }
    }

    fn segment_distance2(&self, p: Point3, k: usize) -> f64 {
        let n = self.vertices.len();
        dist2_to_segment(p, self.vertices[k], self.vertices[(k + 1) % n])
    }

    fn distance(&self, p: Point3) -> f64 {
        let n = self.vertices.len();
        if n == 0 {
            return f64::INFINITY;
        }
        if n == 1 {
            return dist2(p, self.vertices[0]).sqrt();
        }
        let Some(tree) = &self.tree else {
            // Non-finite vertices: measure every segment.
            return (0..self.segments)
                .map(|k| self.segment_distance2(p, k))
                .fold(f64::INFINITY, f64::min)
                .sqrt();
        };
        let nearest = tree
            .query(&p)
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        let mut best = self.segment_distance2(p, self.segment_of[nearest.item as usize]);
        let r = (nearest.distance.sqrt() + self.half_step) * (1.0 + 1e-12) + 1e-300;
        for found in tree
            .query(&p)
            .within::<SquaredEuclidean<f64>>(r * r)
            .execute()
        {
            let k = self.segment_of[found.item as usize];
            best = best.min(self.segment_distance2(p, k));
            let prev = if k > 0 {
                Some(k - 1)
            } else if self.closed && self.segments == n {
                Some(n - 1)
            } else {
                None
            };
            if let Some(j) = prev {
                best = best.min(self.segment_distance2(p, j));
            }
        }
        best.sqrt()
    }
}

fn dist2_to_segment(p: Point3, a: Point3, b: Point3) -> f64 {
    let ab = sub(b, a);
    let ap = sub(p, a);
    let len2 = norm2(ab);
    let t = if len2 > 0.0 {
        (dot(ap, ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    dist2(p, std::array::from_fn(|c| a[c] + t * ab[c]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::{blade, notched_plate, SplitMix64};
    use std::f64::consts::PI;

    const SQUARE: [Point3; 4] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];

    fn circle(n: usize, r: f64) -> Vec<Point3> {
        (0..n)
            .map(|i| {
                let a = 2.0 * PI * i as f64 / n as f64;
                [r * a.cos(), r * a.sin(), 0.0]
            })
            .collect()
    }

    fn brute(p: Point3, poly: &[Point3], closed: bool) -> f64 {
        let n = poly.len();
        let segs = if closed { n } else { n - 1 };
        (0..segs)
            .map(|k| dist2_to_segment(p, poly[k], poly[(k + 1) % n]))
            .fold(f64::INFINITY, f64::min)
            .sqrt()
    }

    #[test]
    fn stats_of_hand_made_distances() {
        let s = DistanceStats::from_distances(&[1.0, 2.0, 3.0, 6.0]);
        assert_eq!((s.mean, s.max, s.count), (3.0, 6.0, 4));
        assert!((s.std - 3.5f64.sqrt()).abs() < 1e-12);
        let e = DistanceStats::from_distances(&[]);
        assert_eq!((e.mean, e.max, e.std, e.count), (0.0, 0.0, 0.0, 0));
    }

    #[test]
    fn points_to_a_square() {
        let pts = [
            [0.5, -0.2, 0.0], // below the bottom side
            [0.5, 0.5, 0.0],  // centre
            [2.0, 0.5, 0.0],  // right of the right side
            [0.5, 0.5, 0.3],  // above the centre
            [-0.3, 0.5, 0.0], // left of the closing side
            [-3.0, -4.0, 0.0],
        ];
        let closed = points_to_polyline(&pts, &SQUARE, true);
        let want = [0.2, 0.5, 1.0, (0.25f64 + 0.09).sqrt(), 0.3, 5.0];
        assert_eq!(closed.count, 6);
        assert!((closed.mean - want.iter().sum::<f64>() / 6.0).abs() < 1e-12);
        assert!((closed.max - 5.0).abs() < 1e-12);
        // Open: the left side (closing segment) is missing.
        let open = points_to_polyline(&[[-0.3, 0.5, 0.0]], &SQUARE, false);
        assert!((open.mean - (0.09f64 + 0.25).sqrt()).abs() < 1e-12);
        // Points on the square: zero.
        let on = points_to_polyline(&[[0.3, 0.0, 0.0], [0.0, 0.7, 0.0]], &SQUARE, true);
        assert!(on.max < 1e-15);
    }

    #[test]
    fn points_to_a_circle() {
        let poly = circle(1000, 1.0);
        let pts: Vec<Point3> = circle(777, 1.1)
            .into_iter()
            .chain(circle(333, 0.95))
            .collect();
        let s = points_to_polyline(&pts, &poly, true);
        // 777 at 0.1, 333 at 0.05, up to the chord sag (5e-6).
        let mean = (777.0 * 0.1 + 333.0 * 0.05) / 1110.0;
        assert!((s.mean - mean).abs() < 1e-5, "{s:?}");
        assert!((s.max - 0.1).abs() < 1e-5);
        let var = (777.0 * (0.1f64 - mean).powi(2) + 333.0 * (0.05f64 - mean).powi(2)) / 1110.0;
        assert!((s.std - var.sqrt()).abs() < 1e-5);
    }

    #[test]
    fn exact_against_brute_force_with_uneven_segments() {
        let mut rng = SplitMix64::new(1);
        // A zig-zag with a few very long segments among short ones.
        let mut poly = Vec::new();
        let mut x = 0.0;
        for i in 0..200 {
            x += if i % 37 == 0 {
                20.0
            } else {
                rng.range(0.01, 0.5)
            };
            poly.push([x, rng.range(-1.0, 1.0), rng.range(-0.2, 0.2)]);
        }
        poly.push(poly[5]); // a repeated vertex
        for closed in [false, true] {
            let index = PolylineIndex::new(&poly, closed);
            for _ in 0..2000 {
                let p = [
                    rng.range(-5.0, x + 5.0),
                    rng.range(-6.0, 6.0),
                    rng.range(-3.0, 3.0),
                ];
                let (a, b) = (index.distance(p), brute(p, &poly, closed));
                assert!((a - b).abs() < 1e-12, "{p:?}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn degenerate_polylines() {
        let p = [[1.0, 2.0, 2.0]];
        assert_eq!(points_to_polyline(&p, &[], true).mean, f64::INFINITY);
        assert_eq!(points_to_polyline(&p, &[[0.0; 3]], true).mean, 3.0);
        assert_eq!(
            points_to_polyline(&p, &[[0.0; 3], [0.0; 3]], false).mean,
            3.0
        );
        let two = points_to_polyline(&p, &[[0.0, 2.0, 2.0], [5.0, 2.0, 2.0]], true);
        assert_eq!(two.mean, 0.0);
        assert_eq!(points_to_polyline(&[], &SQUARE, true).count, 0);
    }

    #[test]
    fn square_corners_match() {
        let found = [[0.05, 0.0, 0.0], [1.0, 1.02, 0.0], [0.5, 0.5, 0.0]];
        assert_eq!(match_corners(&found, &SQUARE, 0.1), (2, 2, 1));
        assert_eq!(match_corners(&[], &SQUARE, 0.1), (0, 4, 0));
        assert_eq!(match_corners(&SQUARE, &[], 0.1), (0, 0, 4));
        assert_eq!(match_corners(&SQUARE, &SQUARE, 0.0), (4, 0, 0));
    }

    #[test]
    fn turning_vertices_of_a_square_and_a_circle() {
        assert_eq!(turning_vertices(&SQUARE, true, 30.0), vec![0, 1, 2, 3]);
        assert_eq!(turning_vertices(&SQUARE, false, 30.0), vec![1, 2]);
        assert!(turning_vertices(&circle(13, 1.0), true, 30.0).is_empty());
        assert_eq!(turning_vertices(&circle(11, 1.0), true, 30.0).len(), 11);
    }

    #[test]
    fn notched_plate_corners_are_the_polygon_vertices() {
        let c = notched_plate(1.0, 2);
        let corners = true_corners(&c);
        let want: Vec<Point3> = c
            .region
            .outer
            .iter()
            .map(|uv| [uv[0], uv[1], 0.0])
            .collect();
        assert_eq!(corners.len(), 8, "{corners:?}");
        assert_eq!(match_corners(&corners, &want, 1e-9), (8, 0, 0));
        // None on the hole (centre (47, 15), radius 5).
        assert!(corners
            .iter()
            .all(|p| ((p[0] - 47.0).powi(2) + (p[1] - 15.0).powi(2)).sqrt() > 6.0));
    }

    #[test]
    fn blade_corners_are_the_four_chord_ends() {
        let c = blade(8.0, 41);
        let corners = true_corners(&c);
        let ends: Vec<Point3> = [[0.0, -120.0], [600.0, -110.0], [600.0, 100.0], [0.0, 120.0]]
            .iter()
            .map(|&uv| c.surface.point(uv))
            .collect();
        assert_eq!(corners.len(), 4, "{corners:?}");
        assert_eq!(match_corners(&corners, &ends, 1e-9), (4, 0, 0));
    }

    #[test]
    fn truth_distance_in_spacings() {
        for h in [1.0, 2.0] {
            let c = notched_plate(h, 2);
            // The true outer polygon: zero.
            let outer: Vec<Point3> = c
                .region
                .outer
                .iter()
                .map(|uv| [uv[0], uv[1], 0.0])
                .collect();
            let s = polyline_to_truth_in_spacings(&outer, true, 0.25 * h, &c);
            assert!(s.max < 1e-9, "{s:?}");
            assert!(s.count >= (200.0 / 0.25) as usize);
            // A circle 0.5 h outside the hole (centre (47h, 15h), r 5h).
            let ring: Vec<Point3> = circle(400, 5.5 * h)
                .into_iter()
                .map(|p| [p[0] + 47.0 * h, p[1] + 15.0 * h, 0.0])
                .collect();
            let s = polyline_to_truth_in_spacings(&ring, true, 0.1 * h, &c);
            assert!((s.mean - 0.5).abs() < 1e-3 && s.std < 1e-3, "{s:?}");
            // Lifted out of the plane by h as well: √(0.5² + 1²) spacings.
            let lifted: Vec<Point3> = ring.iter().map(|p| [p[0], p[1], h]).collect();
            let s = polyline_to_truth_in_spacings(&lifted, false, h, &c);
            assert!((s.mean - 1.25f64.sqrt()).abs() < 1e-3, "{s:?}");
        }
        let c = notched_plate(1.0, 2);
        assert_eq!(polyline_to_truth_in_spacings(&[], true, 1.0, &c).count, 0);
        let one = polyline_to_truth_in_spacings(&[[30.0, -2.0, 0.0]], true, 0.0, &c);
        assert_eq!(one.count, 1);
        assert!((one.mean - 2.0).abs() < 1e-9);
    }
}

/// Jumps of one closed tour of boundary points.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Jumps {
    /// Tour steps (including the closing one) longer than 3 β and not
    /// joined by a BPD link.
    pub count: usize,
    /// The longest such step, in β (the larger β of its two ends); 0
    /// without jumps.
    pub longest_in_beta: f64,
}

/// Steps of a closed `tour` (indices into `points`) that jump across the
/// surface, by the rule edge reconstruction cuts tours with: consecutive
/// points farther apart than 3 β (the larger local resolution of the two)
/// and not joined by one of `links` (BPD's
/// [`trim::Detection::links`], sorted pairs, smaller index first).
pub fn tour_jumps(points: &[Point3], beta: &[f64], links: &[[u32; 2]], tour: &[u32]) -> Jumps {
    let n = tour.len();
    let mut jumps = Jumps::default();
    if n < 2 {
        return jumps;
    }
    for k in 0..n {
        let (a, b) = (tour[k], tour[(k + 1) % n]);
        if !step_is_supported(points, beta, links, a, b) {
            let d = dist2(points[a as usize], points[b as usize]).sqrt();
            let scale = beta[a as usize].max(beta[b as usize]);
            jumps.count += 1;
            jumps.longest_in_beta = jumps.longest_in_beta.max(d / scale);
        }
    }
    jumps
}
