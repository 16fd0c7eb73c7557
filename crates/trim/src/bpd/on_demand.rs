//! The local resolution β (section 2 of the paper, step 3 of BPD) found
//! only for the points asked for.
//!
//! Cleaning a scanned mesh reads β at its borders and in the bands beside
//! them, a few percent of the vertices of a large scan; finding it for every
//! vertex took as long as the cleanup itself. [`LocalResolution`] finds
//! β(P_i) as [`local_resolution`] does, bit for bit: P_i's k nearest
//! neighbours, their plane and, with anisotropy on, the sampling moment
//! of each member (from the member's own neighbourhood), which are kept
//! for the next point asked for, whose neighbourhood shares most members.
//!
//! The cleanup also needs the median β as a scale: exact for a cloud of
//! at most [`LocalResolution::ALL_AT_ONCE`] points, whose β are all found
//! at once (in BPD's fast pass), and over [`MEDIAN_RUNS`] runs of
//! [`MEDIAN_RUN`] consecutive points in spatial order, spread evenly over
//! the cloud, for a larger one.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use super::*;
use crate::geom::median;
use crate::hash::HashMap;

/// Runs of consecutive points (in spatial order) the median of a larger
/// cloud is taken over …
const MEDIAN_RUNS: usize = 16;
/// … and the points in each.
const MEDIAN_RUN: usize = 1024;
/// Locks the kept neighbourhoods are spread over, so that threads asking
/// for β at once seldom wait for each other.
const SHARDS: usize = 64;
/// The bits of a β not found yet (no β is NaN).
const NOT_FOUND: u64 = u64::MAX;

/// A position's k nearest neighbours (itself first) and its sampling moment
/// and plane.
#[derive(Clone)]
struct Known {
    members: Box<[u32]>,
    sampling: Sampling,
}

/// β of a cloud's points, found when first asked for and kept.
///
/// Each value equals [`local_resolution`]'s for the same point, bit for
/// bit, whatever the order or the threads the points are asked for in.
/// A cloud of at most [`LocalResolution::ALL_AT_ONCE`] points has every β
/// found when it is made (as fast as [`local_resolution`]), a larger one
/// only each point's own when it is asked for: cleaning a jagged scan of
/// 2.5 million vertices reads β of 2 % of them.
pub struct LocalResolution {
    spatial: SpatialOrder,
    /// Each input point's position in the spatial order.
    position_of_input: Vec<u32>,
    k: usize,
    view: Option<View>,
    anisotropy: bool,
    /// β per position, as bits; [`NOT_FOUND`] until found.
    beta: Vec<AtomicU64>,
    /// The neighbourhoods and sampling moments found so far (with
    /// anisotropy on), by position.
    known: Vec<Mutex<HashMap<u32, Known>>>,
    median: f64,
}

impl LocalResolution {
    /// Clouds of up to this many points have every β found at once.
    pub const ALL_AT_ONCE: usize = 1 << 17;

    /// Checks the cloud as [`local_resolution`] does (the same errors) and
    /// puts it in spatial order; finds every β of a cloud of at most
    /// [`Self::ALL_AT_ONCE`] points.
    pub fn new(points: &[Point3], options: &BpdOptions) -> Result<Self, CloudError> {
        Self::all_at_once_up_to(points, options, Self::ALL_AT_ONCE)
    }

    /// [`Self::new`], every β found at once for clouds of up to `limit`
    /// points (0: none, for tests of the finding on demand).
    pub(crate) fn all_at_once_up_to(
        points: &[Point3],
        options: &BpdOptions,
        limit: usize,
    ) -> Result<Self, CloudError> {
        let Prepared { site_of, spatial } = prepare(points, options)?;
        let position_of_site = positions_in_order(&spatial.order);
        let position_of_input = site_of
            .par_iter()
            .with_min_len(PASS_PIECE)
            .map(|&s| position_of_site[s as usize])
            .collect();
        let n = spatial.points.len();
        let mut resolution = Self {
            spatial,
            position_of_input,
            k: options.k,
            view: options.view,
            anisotropy: options.anisotropy,
            beta: (0..n).map(|_| AtomicU64::new(NOT_FOUND)).collect(),
            known: (0..SHARDS).map(|_| Mutex::default()).collect(),
            median: f64::NAN,
        };
        resolution.median = if n <= limit {
            resolution.find_all(options)
        } else {
            resolution.median_of_runs()
        };
        Ok(resolution)
    }

    /// β of input point `i` (`i` below the number of points given).
    pub fn beta(&self, i: usize) -> f64 {
        self.at_position(self.position_of_input[i] as usize)
    }

    /// The median β over the distinct positions; for a cloud of more than
    /// [`Self::ALL_AT_ONCE`] points, over 16 runs of 1,024 consecutive
    /// points in spatial order, spread evenly over the cloud.
    pub fn median(&self) -> f64 {
        self.median
    }

    /// Every β by BPD's fast pass; the median over the distinct positions
    /// (a point stored twice, as a seam's copies are, counts once).
    fn find_all(&self, options: &BpdOptions) -> f64 {
        let how = TestImpl::Fast;
        let hoods = neighbourhoods(self.spatial.clone(), options, how, &|_| {});
        let betas = per_position(&hoods, how, &|_| {}, |s, p| {
            projected_beta(&hoods, p, hoods.sampling.as_deref(), s)
        });
        for (slot, b) in self.beta.iter().zip(&betas) {
            slot.store(b.to_bits(), Ordering::Relaxed);
        }
        median(&betas)
    }

    /// The median β over [`MEDIAN_RUNS`] runs of consecutive positions.
    /// (Every position when there are no more.)
    fn median_of_runs(&self) -> f64 {
        let n = self.beta.len();
        let positions: Vec<usize> = if n <= MEDIAN_RUNS * MEDIAN_RUN {
            (0..n).collect()
        } else {
            let step = n / MEDIAN_RUNS;
            (0..MEDIAN_RUNS)
                .flat_map(|r| r * step..r * step + MEDIAN_RUN)
                .collect()
        };
        // Consecutive positions share neighbours: pieces keep them together.
        let sample: Vec<f64> = positions
            .par_iter()
            .with_min_len(MEDIAN_RUN / 4)
            .map(|&p| self.at_position(p))
            .collect();
        median(&sample)
    }

    fn at_position(&self, p: usize) -> f64 {
        let bits = self.beta[p].load(Ordering::Relaxed);
        if bits != NOT_FOUND {
            return f64::from_bits(bits);
        }
        let beta = self.find(p);
        // Two threads may find the same β at once: the same bits.
        self.beta[p].store(beta.to_bits(), Ordering::Relaxed);
        beta
    }

    /// β at position `p`, as [`projected_beta`] finds it.
    fn find(&self, p: usize) -> f64 {
        let index = self.spatial.index();
        let mut s = Scratch::default();
        let points = &self.spatial.points;
        let view = self.view.as_ref();
        if !self.anisotropy {
            let mut members = Vec::with_capacity(self.k);
            index.nearest(p, self.k, &mut members);
            let frame = fit_plane_normal(points, &members);
            let none: Option<std::iter::Empty<&SamplingMoment>> = None;
            return beta_in_plane(points, &members, &frame, view, none, &mut s);
        }
        let own = self.known(&index, p as u32, |known| known.clone(), &mut s);
        let samplings: Vec<Sampling> = own
            .members
            .iter()
            .map(|&m| self.known(&index, m, |known| known.sampling, &mut s))
            .collect();
        let moments = samplings.iter().map(|v| &v.moment);
        let frame = own.sampling.frame();
        beta_in_plane(points, &own.members, &frame, view, Some(moments), &mut s)
    }

    /// `read` of the neighbourhood and sampling moment at position `p`,
    /// found (one k-NN query) the first time.
    fn known<R>(
        &self,
        index: &NeighbourIndex,
        p: u32,
        read: impl Fn(&Known) -> R,
        s: &mut Scratch,
    ) -> R {
        let shard = &self.known[p as usize % SHARDS];
        if let Some(known) = lock(shard).get(&p) {
            return read(known);
        }
        let mut members = Vec::with_capacity(self.k);
        index.nearest(p as usize, self.k, &mut members);
        let sampling = sampling_at(
            &self.spatial.points,
            &members,
            self.view.as_ref(),
            &mut s.projected,
        );
        let known = Known {
            members: members.into(),
            sampling,
        };
        let answer = read(&known);
        lock(shard).insert(p, known);
        answer
    }

    /// Forgets every β and neighbourhood found.
    #[cfg(test)]
    pub(crate) fn forget(&mut self) {
        self.beta
            .iter()
            .for_each(|b| b.store(NOT_FOUND, Ordering::Relaxed));
        self.known.iter_mut().for_each(|shard| lock(shard).clear());
    }
}

impl crate::resolution::PointResolution for LocalResolution {
    fn len(&self) -> usize {
        self.position_of_input.len()
    }
    fn beta(&self, i: usize) -> f64 {
        LocalResolution::beta(self, i)
    }
    fn median(&self) -> f64 {
        self.median
    }
}

impl std::fmt::Debug for LocalResolution {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LocalResolution")
            .field("points", &self.position_of_input.len())
            .field("distinct", &self.beta.len())
            .field("median", &self.median)
            .finish_non_exhaustive()
    }
}

/// A shard's map, even if a thread panicked while holding it (the map is
/// only ever added to whole entries).
fn lock(shard: &Mutex<HashMap<u32, Known>>) -> std::sync::MutexGuard<'_, HashMap<u32, Known>> {
    shard
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point3;

    /// A wavy, jittered sheet with a hole, some points repeated.
    fn sheet(seed: u64, n: usize) -> Vec<Point3> {
        let mut state = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let side = (n as f64).sqrt() as usize;
        let mut points = Vec::new();
        for i in 0..side {
            for j in 0..side {
                let (x, y) = (i as f64 + 0.3 * next(), (j as f64) * 0.7 + 0.3 * next());
                if (x - 10.0).powi(2) + (y - 7.0).powi(2) < 9.0 {
                    continue;
                }
                points.push([x, y, 0.5 * (x * 0.2).sin() + 0.05 * next()]);
            }
        }
        let copies: Vec<Point3> = points.iter().step_by(37).copied().collect();
        points.extend(copies);
        points
    }

    /// Found all at once, or one point at a time in any order and on any
    /// thread, β equals BPD's pass bit for bit.
    #[test]
    fn equals_the_full_pass_bit_for_bit() {
        for (seed, anisotropy, view) in [
            (1, true, None),
            (2, false, None),
            (3, true, Some(View::Along([0.2, 0.1, 1.0]))),
        ] {
            let points = sheet(seed, 900);
            let options = BpdOptions {
                anisotropy,
                view,
                ..BpdOptions::default()
            };
            let all = local_resolution(&points, &options).unwrap();
            let at_once = LocalResolution::new(&points, &options).unwrap();
            let mut lazily = LocalResolution::all_at_once_up_to(&points, &options, 0).unwrap();
            let small_median = lazily.median();
            // The median found them all: forgotten, to be found again one at
            // a time.
            lazily.forget();
            let backwards: Vec<f64> = (0..points.len()).rev().map(|i| lazily.beta(i)).collect();
            let in_parallel: Vec<f64> = (0..points.len())
                .into_par_iter()
                .map(|i| lazily.beta(i))
                .collect();
            for (i, &b) in all.iter().enumerate() {
                assert_eq!(at_once.beta(i).to_bits(), b.to_bits(), "point {i}");
                assert_eq!(
                    backwards[points.len() - 1 - i].to_bits(),
                    b.to_bits(),
                    "point {i}"
                );
                assert_eq!(in_parallel[i].to_bits(), b.to_bits(), "point {i}");
            }
            // The median over the distinct points (the sheet has copies),
            // found at once or, the runs covering a small cloud, by them.
            let distinct: Vec<f64> = at_once
                .beta
                .iter()
                .map(|b| f64::from_bits(b.load(Ordering::Relaxed)))
                .collect();
            assert!(distinct.len() < all.len());
            assert_eq!(at_once.median(), median(&distinct));
            assert_eq!(small_median, median(&distinct));
        }
    }

    /// Over a cloud larger than the runs, the median of 16 runs of 1,024
    /// consecutive points is close to the median of all (the wavy sheet's
    /// β varies with its jitter and its hole).
    #[test]
    fn the_median_of_runs_is_close_to_the_median() {
        let points = sheet(4, 40_000);
        let options = BpdOptions::default();
        let all = median(&local_resolution(&points, &options).unwrap());
        let runs = LocalResolution::all_at_once_up_to(&points, &options, 0)
            .unwrap()
            .median();
        assert!(
            (runs - all).abs() < 0.01 * all,
            "median of runs {runs}, of all {all}"
        );
    }

    #[test]
    fn bad_clouds_get_the_full_pass_errors() {
        let line: Vec<Point3> = (0..100).map(|i| [i as f64, 0.0, 0.0]).collect();
        let options = BpdOptions::default();
        assert_eq!(
            LocalResolution::new(&line, &options).err(),
            local_resolution(&line, &options).err()
        );
        assert_eq!(
            LocalResolution::new(&[], &options).err(),
            Some(CloudError::NoPoints)
        );
    }
}
