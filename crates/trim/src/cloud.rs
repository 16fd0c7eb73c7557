//! A validated point cloud: finite coordinates, exact duplicates merged.
//!
//! Scanners and merged scan passes often repeat a point exactly. A repeated
//! point adds no information about the surface but would put a zero into the
//! nearest-neighbour distances of the local resolution (section 2 of the
//! paper) and hide a real neighbour from the k-NN query. So exact duplicates
//! are merged into one *site* before detection, and every copy gets the
//! label and resolution of its site. Points that differ in any bit are kept
//! as they are.

use rayon::prelude::*;

use crate::error::CloudError;
use crate::geom::{cross, dist2, norm2, sub};

pub use crate::geom::Point3;

/// The distinct points of a cloud and the map from input points to them.
#[derive(Debug, Clone)]
pub struct Sites {
    /// Distinct points, in order of first appearance in the input.
    pub points: Vec<Point3>,
    /// For every input point, the index of its site in `points`.
    pub site_of: Vec<u32>,
}

impl Sites {
    #[cfg(test)]
    /// Number of input points that were copies of an earlier point.
    pub fn duplicates(&self) -> usize {
        self.site_of.len() - self.points.len()
    }
}

/// The largest |coordinate| meshtrim accepts. The geometry squares
/// distances (f64 overflows near 1e154), multiplies two squares (cross
/// products' norms, circle tests: overflow near 1e77), and spade refuses
/// plane coordinates beyond 2^201 ≈ 3.2e60; 1e50 stays ten orders of
/// magnitude below the first of these, with the cloud anywhere in that box.
pub(crate) const MAX_COORDINATE: f64 = 1e50;

/// The smallest largest |coordinate| meshtrim accepts (except 0: points all
/// at the origin are one point). Spade flushes plane coordinates below
/// 2^-142 ≈ 1.8e-43 to zero, and products of two squared distances
/// underflow near 1e-77; from 1e-30 up the flush moves a point by less than
/// 1e-12 of the cloud's size, below the rounding of the plane fit.
pub(crate) const MIN_LARGEST_COORDINATE: f64 = 1e-30;

/// Fewest points per piece of a parallel pass over a cloud: a pass over
/// fewer runs on the calling thread alone. Such passes (bounds, checks,
/// keys, copies) take microseconds per thousand points, about what waking
/// another thread costs: at the 12k benchmark, splitting them made BPD's
/// preparation take 0.9–1.0 ms instead of 0.55.
pub(crate) const PASS_PIECE: usize = 16384;

/// The largest |coordinate| of finite `points`, when it lies outside the
/// supported range ([`MIN_LARGEST_COORDINATE`] to [`MAX_COORDINATE`]).
pub fn out_of_range(points: &[Point3]) -> Option<f64> {
    let largest = points
        .par_iter()
        .with_min_len(PASS_PIECE)
        .map(largest_coordinate)
        .reduce(|| 0.0, f64::max);
    beyond_range(largest)
}

/// `largest` (a largest |coordinate|) when it lies outside the supported
/// range.
fn beyond_range(largest: f64) -> Option<f64> {
    let tiny = largest > 0.0 && largest < MIN_LARGEST_COORDINATE;
    (tiny || largest > MAX_COORDINATE).then_some(largest)
}

fn largest_coordinate(p: &Point3) -> f64 {
    p.iter().fold(0.0, |m: f64, c| m.max(c.abs()))
}

/// Refuses finite `points` outside the supported range, where squared
/// distances and spade's predicates would overflow or underflow and give
/// wrong verdicts or panics instead of errors.
pub fn check_range(points: &[Point3]) -> Result<(), CloudError> {
    beyond_range_error(out_of_range(points))
}

fn beyond_range_error(largest: Option<f64>) -> Result<(), CloudError> {
    match largest {
        Some(largest) => Err(CloudError::OutOfRange {
            largest,
            min: MIN_LARGEST_COORDINATE,
            max: MAX_COORDINATE,
        }),
        None => Ok(()),
    }
}

/// Checks that the cloud fits u32 indices and every coordinate is finite
/// and within the supported range ([`check_range`]).
pub fn check_finite(points: &[Point3]) -> Result<(), CloudError> {
    // Sites, neighbour lists and k-d tree items are u32 indices.
    let max = u32::MAX as usize;
    if points.len() > max {
        return Err(CloudError::TooManyPoints {
            count: points.len(),
            max,
        });
    }
    // One pass for both checks: the first non-finite point (the smallest
    // index, whatever the threads) and the largest |coordinate|.
    let (first_bad, largest) = points
        .par_iter()
        .with_min_len(PASS_PIECE)
        .enumerate()
        .map(|(i, p)| {
            let finite = p.iter().all(|c| c.is_finite());
            (if finite { usize::MAX } else { i }, largest_coordinate(p))
        })
        .reduce(|| (usize::MAX, 0.0), |a, b| (a.0.min(b.0), a.1.max(b.1)));
    if let Some(p) = points.get(first_bad) {
        return Err(CloudError::NonFinite {
            index: first_bad,
            x: p[0],
            y: p[1],
            z: p[2],
        });
    }
    beyond_range_error(beyond_range(largest))
}

/// Checks that every coordinate is finite and merges exact duplicates.
pub fn merge_duplicates(points: &[Point3]) -> Result<Sites, CloudError> {
    check_finite(points)?;
    // Sort indices by coordinate bits (+0.0 and -0.0 are the same point).
    let key = |p: &Point3| p.map(|c| (c + 0.0).to_bits());
    // Sorted in parallel: (key, index) is a total order, so the result
    // does not depend on the threads.
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    order.par_sort_unstable_by_key(|&i| (key(&points[i as usize]), i));
    // Each run of equal keys starts with its lowest index, the site's
    // first occurrence in the input.
    let mut first_of_run = vec![0u32; points.len()];
    for run in order.chunk_by(|&a, &b| key(&points[a as usize]) == key(&points[b as usize])) {
        for &i in run {
            first_of_run[i as usize] = run[0];
        }
    }
    let mut site_of = vec![u32::MAX; points.len()];
    let mut sites = Vec::new();
    for i in 0..points.len() {
        let first = first_of_run[i] as usize;
        if first == i {
            site_of[i] = sites.len() as u32;
            sites.push(points[i]);
        } else {
            site_of[i] = site_of[first];
        }
    }
    Ok(Sites {
        points: sites,
        site_of,
    })
}

/// Rejects clouds whose distinct points all coincide or are collinear.
///
/// Collinearity is judged relative to the cloud's extent, so the verdict does
/// not depend on units or position within the supported range; beyond it
/// the squares below overflow or underflow (300 random points at 1e160
/// would be "one line", at 1e-300 "one point"), so such clouds are refused
/// as out of range ([`check_range`]), the same error detection gives.
pub fn check_not_degenerate(points: &[Point3]) -> Result<(), CloudError> {
    check_range(points)?;
    let distinct = points.len();
    let Some(&a) = points.first() else {
        return Err(CloudError::Degenerate {
            distinct,
            what: "one point",
        });
    };
    // In parallel, with the index as the last key so that the farthest
    // point is the serial `max_by`'s (the last of equals) whatever the
    // split.
    let far = |from: Point3| {
        points
            .par_iter()
            .with_min_len(PASS_PIECE)
            .enumerate()
            .max_by(|(i, p), (j, q)| dist2(**p, from).total_cmp(&dist2(**q, from)).then(i.cmp(j)))
            .map_or(from, |(_, p)| *p)
    };
    let b = far(a);
    let extent2 = dist2(a, b);
    if extent2 == 0.0 {
        return Err(CloudError::Degenerate {
            distinct,
            what: "one point",
        });
    }
    let ab = sub(b, a);
    let off_line2 = points
        .par_iter()
        .with_min_len(PASS_PIECE)
        .map(|p| norm2(cross(ab, sub(*p, a))) / extent2)
        .reduce(|| 0.0, f64::max);
    // Farthest distance from the line a-b, relative to the extent.
    if off_line2 <= extent2 * 1e-20 {
        return Err(CloudError::Degenerate {
            distinct,
            what: "one line",
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn duplicates_map_to_their_first_copy() {
        let pts = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [-0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
        ];
        let s = merge_duplicates(&pts).unwrap();
        assert_eq!(s.points, vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]);
        assert_eq!(s.site_of, vec![0, 1, 0, 0, 1]);
        assert_eq!(s.duplicates(), 3);
    }

    /// The sort-based merge against the plain definition: a point's site is
    /// the first earlier point equal to it (−0.0 equal to 0.0).
    #[test]
    fn merge_matches_first_occurrence_on_random_quantised_clouds() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for _ in 0..20 {
            let n = rng.random_range(1..400);
            let pts: Vec<Point3> = (0..n)
                .map(|_| {
                    // A negative step makes −0.0 from 0.
                    let step = if rng.random() { 0.5 } else { -0.5 };
                    [0; 3].map(|_| f64::from(rng.random_range(-2i8..=2)) * step)
                })
                .collect();
            let got = merge_duplicates(&pts).unwrap();
            let mut sites: Vec<Point3> = Vec::new();
            let want: Vec<u32> = pts
                .iter()
                .map(|p| match sites.iter().position(|s| s == p) {
                    Some(site) => site as u32,
                    None => {
                        sites.push(*p);
                        sites.len() as u32 - 1
                    }
                })
                .collect();
            assert_eq!(got.site_of, want);
            assert_eq!(got.points.len(), sites.len());
            for (a, b) in got.points.iter().zip(&sites) {
                assert_eq!(a, b);
            }
        }
    }

    #[test]
    fn non_finite_is_reported_with_its_index() {
        let pts = [[0.0, 0.0, 0.0], [1.0, f64::NAN, 0.0]];
        assert!(matches!(
            merge_duplicates(&pts),
            Err(CloudError::NonFinite { index: 1, .. })
        ));
    }

    #[test]
    fn collinear_and_coincident_clouds_are_degenerate() {
        let line: Vec<Point3> = (0..50)
            .map(|i| [i as f64, 2.0 * i as f64, -(i as f64)])
            .collect();
        assert!(matches!(
            check_not_degenerate(&line),
            Err(CloudError::Degenerate {
                what: "one line",
                ..
            })
        ));
        assert!(matches!(
            check_not_degenerate(&[[3.0; 3]]),
            Err(CloudError::Degenerate {
                what: "one point",
                ..
            })
        ));
        let plane: Vec<Point3> = (0..50)
            .map(|i| [(i % 7) as f64, (i / 7) as f64, 0.0])
            .collect();
        assert!(check_not_degenerate(&plane).is_ok());
    }

    /// 300 random points of a slightly thick square, at `scale`.
    fn random_slab(scale: f64) -> Vec<Point3> {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        (0..300)
            .map(|_| [1.0, 1.0, 0.01].map(|f: f64| f * rng.random::<f64>() * scale))
            .collect()
    }

    /// Beyond the supported range (squares overflow from 1e154, underflow
    /// below 1e-154, spade fails from 3.2e60) a cloud is refused by naming
    /// the range, before anything squares its coordinates.
    #[test]
    fn out_of_range_clouds_are_refused() {
        for scale in [1e160, 1e-300, 1e51, 1e-31] {
            let refused = merge_duplicates(&random_slab(scale)).unwrap_err();
            assert!(
                matches!(refused, CloudError::OutOfRange { .. }),
                "{refused}"
            );
        }
        for scale in [1.5e-30, 1e49] {
            assert!(merge_duplicates(&random_slab(scale)).is_ok(), "{scale}");
        }
        let message = check_range(&[[0.0, -2e160, 1.0]]).unwrap_err().to_string();
        assert!(
            message.contains("largest |coordinate| is 2.00e160"),
            "{message}"
        );
        assert!(message.contains("between 1e-30 and 1e50"), "{message}");
        // A cloud at the origin is one point, not out of range.
        assert!(check_range(&[[0.0; 3], [-0.0; 3]]).is_ok());
    }

    /// Within the supported range the verdict does not depend on units;
    /// beyond it the cloud is out of range, not a line or a point.
    #[test]
    fn the_verdict_does_not_depend_on_units() {
        for scale in [1.5e-30, 1e-20, 1.0, 1e20, 1e49] {
            assert!(check_not_degenerate(&random_slab(scale)).is_ok(), "{scale}");
            let line: Vec<Point3> = (1..=50)
                .map(|i| [i as f64 / 50.0 * scale, 0.5 * scale, -scale])
                .collect();
            let verdict = check_not_degenerate(&line);
            assert!(
                matches!(
                    verdict,
                    Err(CloudError::Degenerate {
                        what: "one line",
                        ..
                    })
                ),
                "{scale}: {verdict:?}"
            );
        }
        for scale in [1e160, 1e-300] {
            let refused = check_not_degenerate(&random_slab(scale)).unwrap_err();
            assert!(
                matches!(refused, CloudError::OutOfRange { .. }),
                "{refused}"
            );
        }
    }
}
