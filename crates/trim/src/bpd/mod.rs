//! BPD — boundary point detection (section 2 of the paper).
//!
//! For every point P_i of an unorganised surface cloud, with no user
//! threshold:
//! 1. its k nearest neighbours, P_i included ([`crate::spatial::neighbours`]);
//! 2. their best-fit plane and 2D projection ([`crate::frame`]), mapped by the
//!    sampling tensor when `anisotropy` is on ([`crate::anisotropy`]);
//! 3. the local resolution β_i = μ_i + 2σ_i ([`crate::resolution`]);
//! 4. the empty-circle test ([`circle`]); if it does not find P_i on the
//!    boundary,
//! 5. the surrounding-path test ([`polar`]).
//!
//! [`detect_boundary`] is the fast, parallel version; [`detect_boundary_reference`]
//! runs the same decisions with the plain O(k³) circle test, one point at a
//! time, and exists to check the fast one.

pub mod circle;
mod on_demand;
pub mod polar;

pub use on_demand::LocalResolution;

use std::ops::Range;

use rayon::prelude::*;

use crate::anisotropy::{
    apply, own_sampling_vectors, sampling_moment, sampling_tensor_of_moments, whitening_map,
    SamplingMoment,
};
use crate::cloud::{check_finite, check_not_degenerate, merge_duplicates, Sites, PASS_PIECE};
use crate::error::CloudError;
use crate::frame::{fit_plane_normal, project_sheared, ray_shear, spread, Frame, Point2};
use crate::geom::{add, dist2, sub, unit, Point3};
use crate::resolution::{beta_of, nearest_distances, Columns};
use crate::spatial::morton::{
    octree_runs, positions_in_order, spatial_order, split_by_runs, MortonCells, MortonGrid,
};
use crate::spatial::neighbours::{NeighbourIndex, RunScratch};

/// Options of boundary point detection.
#[derive(Debug, Clone, PartialEq)]
pub struct BpdOptions {
    /// Neighbourhood size, the point itself included (the paper's k = 30,
    /// so 29 neighbours). Must be at least [`BpdOptions::MIN_K`].
    pub k: usize,
    /// Map each projected neighbourhood by its sampling tensor before the
    /// tests (meshtrim's extension for line scans; docs/bpd.md).
    /// Off gives the paper's isotropic behaviour.
    pub anisotropy: bool,
    /// Where a range scanner saw the cloud from, when known: each
    /// neighbourhood is then projected onto its plane along the scanner's
    /// line of sight instead of along the plane's normal (meshtrim's
    /// extension for range scans; see [`View`]). `None` is the paper's
    /// projection.
    pub view: Option<View>,
}

impl BpdOptions {
    /// Smallest accepted k: the point and three neighbours.
    pub const MIN_K: usize = 4;
}

impl Default for BpdOptions {
    fn default() -> Self {
        Self {
            k: 30,
            anisotropy: true,
            view: None,
        }
    }
}

/// Where a range scanner (a depth camera, a laser line or structured-light
/// scanner) saw the cloud from.
///
/// A range scanner errs along its line of sight: depth noise, and the
/// terraces of a quantised depth, move points along the ray, not along
/// the surface's normal. Where the surface is inclined to the ray, the
/// paper's projection along the normal turns part of each such move into a
/// shift within the plane, and the terraces of a quantised depth open gaps
/// of a spacing or more between their rows: interior points turn boundary
/// all over the scan. Projected along the ray, a point moved along its ray lands where
/// it would have without the move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum View {
    /// Every line of sight has this direction (either sense): a distant or
    /// orthographic scanner, or a cloud in a frame whose axis the scanner
    /// looked along.
    Along(Point3),
    /// The scanner stood here (a depth camera's centre): the line of sight
    /// to a point runs from here to it.
    From(Point3),
}

/// Smallest cosine between a point's line of sight from the scanner's
/// position and the camera's axis: a camera's field of view is well inside
/// ±84°; farther off the axis the image plane no longer holds the cloud.
pub(crate) const MIN_AXIS_COSINE: f64 = 0.1;

impl View {
    /// The line of sight to `p` (not normalised; zero for `p` at the
    /// scanner, which then gets the paper's projection).
    fn ray_to(&self, p: Point3) -> Point3 {
        match *self {
            View::Along(direction) => direction,
            View::From(origin) => sub(p, origin),
        }
    }

    /// The axis of a camera at `eye` that sees `points`: the mean of the
    /// unit lines of sight to them.
    pub(crate) fn camera_axis(eye: Point3, points: &[Point3]) -> Point3 {
        unit(
            points
                .iter()
                .fold([0.0; 3], |sum, &p| add(sum, unit(sub(p, eye)))),
        )
    }

    /// The depth of `ray` (from the camera) along the camera's `axis`, or
    /// `None` when it runs more than [`MIN_AXIS_COSINE`] off the axis, or
    /// is NaN (a point at the camera): no camera image holds it.
    pub(crate) fn camera_depth(ray: Point3, axis: Point3) -> Option<f64> {
        let depth = ray[0] * axis[0] + ray[1] * axis[1] + ray[2] * axis[2];
        let length = (ray[0] * ray[0] + ray[1] * ray[1] + ray[2] * ray[2]).sqrt();
        (depth > MIN_AXIS_COSINE * length).then_some(depth)
    }

    /// Rejects a zero or non-finite direction and a non-finite position.
    fn check(&self) -> Result<(), CloudError> {
        let (what, [x, y, z]) = match *self {
            View::Along(d) => ("direction", d),
            View::From(o) => ("position", o),
        };
        let bad = |why| Err(CloudError::BadView { what, x, y, z, why });
        if ![x, y, z].iter().all(|c| c.is_finite()) {
            return bad("a component is not finite");
        }
        if matches!(self, View::Along(_)) && [x, y, z] == [0.0; 3] {
            return bad("a direction cannot be zero");
        }
        Ok(())
    }
}

/// Which test labelled a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Decision {
    /// An empty circle of radius ≥ β, or an empty half-plane, through P_i.
    EmptyCircle,
    /// No surrounding path through the neighbours.
    OpenPath,
    /// Both tests found P_i surrounded.
    Interior,
}

/// Result of boundary point detection, one entry per input point.
#[derive(Debug, Clone, PartialEq)]
pub struct Detection {
    /// True for boundary points, in input order.
    pub boundary: Vec<bool>,
    /// Local resolution β_i, in input order (in the cloud's units).
    pub beta: Vec<f64>,
    /// Which test decided each point, in input order.
    pub decision: Vec<Decision>,
    /// Number of input points that were exact copies of an earlier point
    /// (they share the label of that point).
    pub duplicates: usize,
    /// Pairs of boundary points (input indices, smaller first, sorted)
    /// joined by an empty circle of radius ≥ β: neighbours along the
    /// boundary, the edges of the α-shape with α = β. A duplicate point is represented by
    /// its first copy. Edge reconstruction clusters and orders with them.
    pub links: Vec<[u32; 2]>,
    /// The scanner's view the neighbourhoods were projected along, when
    /// given.
    pub view: Option<View>,
    /// Each point's neighbourhood radius (the distance to the farthest of
    /// its k nearest points), in input order. Edge reconstruction tells
    /// from it the neighbours in an image plane that lie across a jump in
    /// depth.
    pub reach: Vec<f64>,
}

impl Detection {
    /// Number of boundary points.
    pub fn boundary_count(&self) -> usize {
        self.boundary.iter().filter(|&&b| b).count()
    }
}

/// Fast, parallel BPD. The labels do not depend on the number of threads.
pub fn detect_boundary(points: &[Point3], options: &BpdOptions) -> Result<Detection, CloudError> {
    detect_boundary_with_progress(points, options, &|_| {})
}

/// [`detect_boundary`], calling `progress(done)` with the number of distinct
/// points processed so far (all passes counted together, scaled to the
/// number of distinct points) after every block of each pass: blocks of
/// 16,384 points up to 4.2M points, then 256 blocks per pass up to 16.7M,
/// then blocks of 65,536.
pub fn detect_boundary_with_progress(
    points: &[Point3],
    options: &BpdOptions,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<Detection, CloudError> {
    run(points, options, progress, TestImpl::Fast)
}

/// Plain, sequential BPD with the O(k³) reference circle test; the same
/// labels as [`detect_boundary`], for tests.
pub fn detect_boundary_reference(
    points: &[Point3],
    options: &BpdOptions,
) -> Result<Detection, CloudError> {
    run(points, options, &|_| {}, TestImpl::Reference)
}

/// The neighbourhoods of all points, `k` indices each. The points are
/// copied in spatial order (see [`spatial_order`]), so that neighbours are
/// close in memory too: position p is site `order[p]`, and the lists hold
/// positions.
struct Neighbourhoods {
    points: Vec<Point3>,
    order: Vec<u32>,
    k: usize,
    lists: Vec<u32>,
    /// Each position's sampling moment and plane, with anisotropy on.
    sampling: Option<Vec<Sampling>>,
    /// The scanner's view, when given: projections follow its rays.
    view: Option<View>,
}

impl Neighbourhoods {
    fn at(&self, position: usize) -> &[u32] {
        &self.lists[position * self.k..(position + 1) * self.k]
    }
}

fn run(
    points: &[Point3],
    options: &BpdOptions,
    progress: &(dyn Fn(usize) + Sync),
    how: TestImpl,
) -> Result<Detection, CloudError> {
    let Prepared { site_of, spatial } = prepare(points, options)?;
    let n = spatial.points.len();
    // Neighbourhoods (with each point's sampling moment when the map is on)
    // and the tests.
    let passes = 2;
    let report = |pass: usize| move |done: usize| progress((pass * n + done) / passes);
    let hoods = neighbourhoods(spatial, options, how, &report(0));
    check_two_dimensional(&hoods)?;
    let tests = &report(passes - 1);
    // The default neighbourhood's links fit in one word's bits.
    let detection = if hoods.k <= SLOT_BITS_CAPACITY {
        analyse_all::<SlotBits>(&hoods, &site_of, how, tests)
    } else {
        analyse_all::<Vec<u32>>(&hoods, &site_of, how, tests)
    };
    let reach = neighbourhood_reach(&hoods, &site_of);
    Ok(Detection {
        view: options.view,
        reach,
        ..detection
    })
}

/// The distance from each input point to the farthest member of its
/// neighbourhood.
fn neighbourhood_reach(hoods: &Neighbourhoods, site_of: &[u32]) -> Vec<f64> {
    let radius: Vec<f64> = (0..hoods.points.len())
        .into_par_iter()
        .with_min_len(PASS_PIECE)
        .map(|p| {
            let at = hoods.points[p];
            hoods
                .at(p)
                .iter()
                .map(|&m| dist2(at, hoods.points[m as usize]))
                .fold(0.0, f64::max)
                .sqrt()
        })
        .collect();
    let position_of = positions_in_order(&hoods.order);
    site_of
        .par_iter()
        .with_min_len(PASS_PIECE)
        .map(|&site| radius[position_of[site as usize] as usize])
        .collect()
}

/// Neighbourhoods sampled to judge whether the cloud has a second
/// dimension (evenly spread over the spatial order).
const THICKNESS_SAMPLES: usize = 1024;

/// Median thickness (see [`neighbourhood_thickness`]) below which a
/// cloud is a line or a curve, not a surface. Measured with the default
/// k = 30: the real scans 0.73–0.93, a line scan with lines 8 point
/// spacings apart 0.74, strips of 4, 3 and 2 rows 0.50, 0.28 and 0.12; a
/// line profile with noise across it of 0.2, 0.5 and 1 spacing 0.025,
/// 0.060 and 0.118 (as thick as two rows: the two cannot be told apart).
const MIN_THICKNESS: f64 = 0.1;

/// Rejects a cloud whose neighbourhoods have no second dimension: a laser
/// line profile, points along a curve, or a line that rounding (a float32
/// file) made not exactly straight. The global test
/// ([`check_not_degenerate`]) catches exact lines only; this one judges
/// each neighbourhood against its own length, so rounding and noise well
/// below the spacing do not make a line a surface.
fn check_two_dimensional(hoods: &Neighbourhoods) -> Result<(), CloudError> {
    let thickness = median_thickness(hoods);
    if thickness < MIN_THICKNESS {
        return Err(CloudError::NoSurface {
            distinct: hoods.points.len(),
            thickness,
        });
    }
    Ok(())
}

/// The median [`neighbourhood_thickness`] of up to [`THICKNESS_SAMPLES`]
/// neighbourhoods.
fn median_thickness(hoods: &Neighbourhoods) -> f64 {
    let n = hoods.points.len();
    let step = n.div_ceil(THICKNESS_SAMPLES).max(1);
    let mut values: Vec<f64> = (0..n)
        .step_by(step)
        .map(|p| neighbourhood_thickness(&hoods.points, hoods.at(p)))
        .collect();
    values.sort_unstable_by(f64::total_cmp);
    values[values.len() / 2]
}

/// How wide a neighbourhood is for its length: the spread along its second
/// principal axis over that along the first (standard deviations). About
/// 0.6-1 on a surface's neighbourhood, the noise over a third of the
/// neighbourhood's length on a line.
fn neighbourhood_thickness(points: &[Point3], members: &[u32]) -> f64 {
    let [_, second, first] = spread(points, members);
    if first > 0.0 {
        (second / first).sqrt()
    } else {
        0.0
    }
}

/// The tests at every position, and their results in input order.
fn analyse_all<L: LinkSlots>(
    hoods: &Neighbourhoods,
    site_of: &[u32],
    how: TestImpl,
    progress: &(dyn Fn(usize) + Sync),
) -> Detection {
    let vectors = hoods.sampling.as_deref();
    let verdicts = per_position(hoods, how, progress, |s, p| {
        analyse_point::<L>(hoods, p, vectors, s, how)
    });
    let links = links_in_input_order(site_of, hoods, &verdicts);
    let mut detection = spread_to_input(site_of, &hoods.order, &verdicts, |v| (v.decision, v.beta));
    detection.links = links;
    detection
}

/// The local resolution β_i = μ_i + 2σ_i of every point (section 2,
/// steps 1–2) without the boundary tests: the same values as
/// [`detect_boundary`]'s `beta`, in about half the time. For a mesh's own
/// vertices, whose border the mesh already knows (`crate::clean`).
pub fn local_resolution(points: &[Point3], options: &BpdOptions) -> Result<Vec<f64>, CloudError> {
    let Prepared { site_of, spatial } = prepare(points, options)?;
    let how = TestImpl::Fast;
    let hoods = neighbourhoods(spatial, options, how, &|_| {});
    let betas = per_position(&hoods, how, &|_| {}, |s, p| {
        (
            Decision::Interior,
            projected_beta(&hoods, p, hoods.sampling.as_deref(), s),
        )
    });
    Ok(spread_to_input(&site_of, &hoods.order, &betas, |&v| v).beta)
}

/// A checked cloud's distinct points (sites) in spatial order.
struct Prepared {
    /// For every input point, the index of its site.
    site_of: Vec<u32>,
    spatial: SpatialOrder,
}

/// Sites copied in spatial order ([`spatial_order`]): position p holds
/// site `order[p]`, whose Morton key is `keys[p]`.
#[derive(Clone)]
struct SpatialOrder {
    points: Vec<Point3>,
    order: Vec<u32>,
    keys: Vec<u64>,
    grid: MortonGrid,
}

impl SpatialOrder {
    /// The k-NN index over the points in this order (nothing to build),
    /// ties cut by site index, which unlike the spatial order does not
    /// change when the cloud is moved.
    fn index(&self) -> NeighbourIndex<'_> {
        let cells = MortonCells::new(self.grid, &self.keys);
        NeighbourIndex::in_morton_order(&self.points, cells).with_ranks(&self.order)
    }

    /// True when two sites share a Morton key, as copies of a point do.
    fn keys_repeat(&self) -> bool {
        self.keys
            .par_windows(2)
            .with_min_len(PASS_PIECE)
            .any(|w| w[0] == w[1])
    }

    /// The sites' Morton order, and their copy in that order.
    fn of(sites: &[Point3]) -> Self {
        let grid = MortonGrid::of(sites);
        let (order, keys) = spatial_order(sites, &grid);
        let points = order
            .par_iter()
            .with_min_len(PASS_PIECE)
            .map(|&i| sites[i as usize])
            .collect();
        Self {
            points,
            order,
            keys,
            grid,
        }
    }
}

/// Checks the options and the cloud, merges exact duplicates and puts the
/// sites in spatial order.
///
/// Most clouds have no duplicates, and copies of a point share its Morton
/// key: when no two points share a key, the points are the sites and the
/// order of the points is the sites' order, so the sort that merging needs
/// is skipped (at 1M points, a sort of as many (point, index) pairs).
fn prepare(points: &[Point3], options: &BpdOptions) -> Result<Prepared, CloudError> {
    if options.k < BpdOptions::MIN_K {
        return Err(CloudError::KTooSmall {
            k: options.k,
            min: BpdOptions::MIN_K,
        });
    }
    if let Some(view) = &options.view {
        view.check()?;
    }
    if points.is_empty() {
        return Err(CloudError::NoPoints);
    }
    check_finite(points)?;
    let in_order = SpatialOrder::of(points);
    if !in_order.keys_repeat() {
        check_sites(points, points.len(), options)?;
        return Ok(Prepared {
            site_of: (0..points.len() as u32)
                .into_par_iter()
                .with_min_len(PASS_PIECE)
                .collect(),
            spatial: in_order,
        });
    }
    drop(in_order);
    let (sites, spatial) = merged_in_spatial_order(points)?;
    check_sites(&sites.points, points.len(), options)?;
    Ok(Prepared {
        site_of: sites.site_of,
        spatial,
    })
}

/// Exact duplicates merged, then the sites put in spatial order.
fn merged_in_spatial_order(points: &[Point3]) -> Result<(Sites, SpatialOrder), CloudError> {
    let sites = merge_duplicates(points)?;
    let spatial = SpatialOrder::of(&sites.points);
    Ok((sites, spatial))
}

/// Rejects `distinct` points (in input order) that are degenerate or fewer
/// than a neighbourhood.
fn check_sites(distinct: &[Point3], total: usize, options: &BpdOptions) -> Result<(), CloudError> {
    check_not_degenerate(distinct)?;
    if distinct.len() < options.k {
        return Err(CloudError::TooFewPoints {
            distinct: distinct.len(),
            total,
            k: options.k,
        });
    }
    Ok(())
}

/// Finds every neighbourhood once (step 1), queried in spatial order so
/// consecutive queries touch the same part of the tree; with anisotropy on,
/// also each point's plane and sampling moment ([`sampling_at`]), which the
/// fast version computes right after the point's k-NN, while its
/// neighbours are still in the cache.
fn neighbourhoods(
    spatial: SpatialOrder,
    options: &BpdOptions,
    how: TestImpl,
    progress: &(dyn Fn(usize) + Sync),
) -> Neighbourhoods {
    let k = options.k;
    let view = options.view.as_ref();
    let index = spatial.index();
    let (points, keys) = (&spatial.points, &spatial.keys);
    let mut lists = vec![0u32; points.len() * k];
    let mut sampling = options.anisotropy.then(|| {
        let unset = Sampling::default();
        let mut all = Vec::with_capacity(points.len());
        all.par_extend(rayon::iter::repeat_n(unset, points.len()));
        all
    });
    match how {
        TestImpl::Fast => {
            let runs = octree_runs(keys, RUN);
            let sampled = usize::from(sampling.is_some());
            let sampling_pieces =
                split_by_runs(&runs, sampling.as_deref_mut().unwrap_or_default(), sampled);
            let list_pieces = split_by_runs(&runs, &mut lists, k);
            let mut jobs: Vec<_> = runs
                .into_iter()
                .zip(list_pieces)
                .zip(sampling_pieces)
                .map(|((run, out), out_sampling)| (run, out, out_sampling))
                .collect();
            for block in blocks_of_runs(&mut jobs, block_len(points.len()), |job| &job.0) {
                block.par_iter_mut().for_each_init(
                    || (RunScratch::default(), Vec::new()),
                    |(scratch, projected), (run, out, out_sampling)| {
                        index.nearest_of_run(run.clone(), k, out, scratch);
                        for (members, o) in out.chunks_exact(k).zip(out_sampling.iter_mut()) {
                            *o = sampling_at(points, members, view, projected);
                        }
                    },
                );
                progress(block.last().map_or(0, |(run, _, _)| run.end));
            }
        }
        TestImpl::Reference => {
            // The reference asks every query afresh, one by one, and finds
            // the sampling moments in a pass of their own.
            let mut members = Vec::new();
            for (p, out) in lists.chunks_mut(k).enumerate() {
                index.nearest(p, k, &mut members);
                out.copy_from_slice(&members);
                if p % 4096 == 0 {
                    progress(p);
                }
            }
            let mut projected = Vec::new();
            for (members, o) in lists.chunks_exact(k).zip(sampling.iter_mut().flatten()) {
                *o = sampling_at(points, members, view, &mut projected);
            }
        }
    }
    drop(index);
    let SpatialOrder { points, order, .. } = spatial;
    Neighbourhoods {
        points,
        order,
        k,
        lists,
        sampling,
        view: options.view,
    }
}

/// A point's sampling moment and the plane of its neighbourhood, kept from
/// the k-NN pass for the tests. Only the plane's normal is stored: its
/// axes follow from it, as [`fit_plane_normal`] computes them (72 bytes
/// per point, not 120).
#[derive(Debug, Clone, Copy, Default)]
struct Sampling {
    moment: SamplingMoment,
    /// The plane's normal ([`Frame::of_normal`] gives its axes).
    normal: Point3,
}

impl Sampling {
    fn frame(&self) -> Frame {
        Frame::of_normal(self.normal)
    }
}

/// The plane of a neighbourhood (`members`, the point first) and the
/// point's own sampling moment in it ([`crate::anisotropy`]).
fn sampling_at(
    points: &[Point3],
    members: &[u32],
    view: Option<&View>,
    projected: &mut Vec<Point2>,
) -> Sampling {
    let frame = fit_plane_normal(points, members);
    let shear = shear_towards(view, &frame, points[members[0] as usize]);
    project_sheared(points, members, &frame, shear, projected);
    Sampling {
        moment: sampling_moment(&own_sampling_vectors(projected, &frame)),
        normal: frame.normal,
    }
}

/// The shear that projects the neighbourhood of the point at `at` onto
/// `frame`'s plane along the scanner's line of sight; none without a view.
fn shear_towards(view: Option<&View>, frame: &Frame, at: Point3) -> [f64; 2] {
    view.map_or([0.0, 0.0], |v| ray_shear(frame, v.ray_to(at)))
}

/// `jobs` (one per run, in order) cut into blocks of about `block` points:
/// runs hold fewer than [`RUN`] points on average, so blocks counted in
/// runs would leave a small last block, where a thread waits.
fn blocks_of_runs<J>(
    mut jobs: &mut [J],
    block: usize,
    run_of: impl Fn(&J) -> &Range<usize>,
) -> Vec<&mut [J]> {
    let mut blocks = Vec::new();
    while !jobs.is_empty() {
        let start = run_of(&jobs[0]).start;
        let len = jobs
            .partition_point(|job| run_of(job).end <= start + block)
            .max(1);
        let (head, tail) = std::mem::take(&mut jobs).split_at_mut(len);
        blocks.push(head);
        jobs = tail;
    }
    blocks
}

/// Most points per k-NN run (see [`NeighbourIndex::nearest_of_run`] and
/// [`octree_runs`]): enough to share one range query among them, few
/// enough that the run stays small next to a neighbourhood. 32 against 16:
/// the same time at 12k points, 2 % less at 1M (fewer tree queries where
/// the tree no longer fits in the cache). 48 against 32: the k-NN pass at
/// 12k points 6.2 ms against 6.6 (two threads; 11.9 against 12.3 on one)
/// for the same instruction count within 0.1 %, and the same time at 100k
/// and 1M; 40 and 56 measured like 48.
const RUN: usize = 48;

/// Runs `f` at every position of the spatial order, in blocks (parallel for
/// the fast implementation), and returns the results in that order.
fn per_position<T: Send>(
    hoods: &Neighbourhoods,
    how: TestImpl,
    progress: &(dyn Fn(usize) + Sync),
    f: impl Fn(&mut Scratch, usize) -> T + Sync,
) -> Vec<T> {
    let n = hoods.order.len();
    let block = block_len(n);
    let mut out = Vec::with_capacity(n);
    let mut scratch = Scratch::default();
    for start in (0..n).step_by(block) {
        let range = start..(start + block).min(n);
        match how {
            TestImpl::Fast => out.par_extend(
                range
                    .into_par_iter()
                    // Pieces of about a hundred microseconds, so that
                    // neither thread waits long at a block's end.
                    .with_min_len(32)
                    .map_init(Scratch::default, |s, p| f(s, p)),
            ),
            TestImpl::Reference => out.extend(range.map(|p| f(&mut scratch, p))),
        }
        progress(out.len());
    }
    out
}

/// Points per block of a pass: the progress is reported, and the threads
/// wait for each other, between blocks. At least 16,384, so that a cloud
/// of the paper's size runs in one block: each wait costs the time one
/// thread takes to finish its last piece (at the 12k benchmark, 4,096-point
/// blocks were 3–8 % slower).
fn block_len(n: usize) -> usize {
    (n / 256).clamp(16384, 65536)
}

/// The links found at each position, as pairs of input indices.
fn links_in_input_order<L: LinkSlots>(
    site_of: &[u32],
    hoods: &Neighbourhoods,
    verdicts: &[Verdict<L>],
) -> Vec<[u32; 2]> {
    let order = &hoods.order;
    let mut first_input = vec![u32::MAX; order.len()];
    for (input, &site) in site_of.iter().enumerate().rev() {
        first_input[site as usize] = input as u32;
    }
    let input_of = |position: u32| first_input[order[position as usize] as usize];
    // Each pair as one integer, smaller index above: sorted, the order of
    // the pairs, in less than half the time that sorting the pairs takes.
    let mut links: Vec<u64> = Vec::new();
    for (p, v) in verdicts.iter().enumerate() {
        let (a, members) = (input_of(p as u32), hoods.at(p));
        v.links.for_each(|slot| {
            let b = input_of(members[slot as usize]);
            links.push((u64::from(a.min(b)) << 32) | u64::from(a.max(b)));
        });
    }
    if links.len() < PASS_PIECE {
        links.sort_unstable();
    } else {
        links.par_sort_unstable();
    }
    links.dedup();
    links
        .iter()
        .map(|&l| [(l >> 32) as u32, l as u32])
        .collect()
}

/// `verdicts` by spatial position, in input order: `site_of` is each input
/// point's site, `order` each position's site, and `decided` reads a
/// verdict's decision and β.
fn spread_to_input<T: Sync>(
    site_of: &[u32],
    order: &[u32],
    verdicts: &[T],
    decided: impl Fn(&T) -> (Decision, f64) + Sync,
) -> Detection {
    // Site → position, so that each input point reads its verdict in one
    // gather (one pass: at 12k points the verdicts no longer sit in the
    // cache, and each pass over them cost some 30 µs).
    let position_of = positions_in_order(order);
    let (decision, beta): (Vec<Decision>, Vec<f64>) = site_of
        .par_iter()
        .with_min_len(PASS_PIECE)
        .map(|&i| decided(&verdicts[position_of[i as usize] as usize]))
        .unzip();
    Detection {
        boundary: decision
            .par_iter()
            .with_min_len(PASS_PIECE)
            .map(|&d| d != Decision::Interior)
            .collect(),
        beta,
        decision,
        duplicates: site_of.len() - verdicts.len(),
        links: Vec::new(),
        view: None,
        reach: Vec::new(),
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum TestImpl {
    Fast,
    Reference,
}

/// What the analysis finds at one point.
struct Verdict<L> {
    decision: Decision,
    beta: f64,
    /// The neighbours along the boundary, by their slot in the point's
    /// neighbourhood (none unless the circle test decided).
    links: L,
}

/// A set of neighbourhood slots: a point's boundary links.
trait LinkSlots: Send + Sync {
    /// The slots `slots`, each below the neighbourhood size.
    fn of(slots: impl Iterator<Item = u32>) -> Self;
    /// No slot.
    fn none() -> Self;
    /// Calls `f` with every slot, in increasing order.
    fn for_each(&self, f: impl FnMut(u32));
}

/// Slots as the bits of one word, for neighbourhoods of up to 64 points
/// (the default is 30): the verdicts stay small and no point's links
/// allocate.
type SlotBits = u64;

/// How many slots a [`SlotBits`] holds.
const SLOT_BITS_CAPACITY: usize = SlotBits::BITS as usize;

impl LinkSlots for SlotBits {
    fn of(slots: impl Iterator<Item = u32>) -> Self {
        slots.fold(0, |bits, slot| bits | 1 << slot)
    }

    fn none() -> Self {
        0
    }

    fn for_each(&self, mut f: impl FnMut(u32)) {
        let mut bits = *self;
        while bits != 0 {
            f(bits.trailing_zeros());
            bits &= bits - 1;
        }
    }
}

/// Slots listed, for larger neighbourhoods (`--k` above 64): a boundary
/// point's list is allocated.
impl LinkSlots for Vec<u32> {
    fn of(slots: impl Iterator<Item = u32>) -> Self {
        let mut list: Vec<u32> = slots.collect();
        list.sort_unstable();
        list
    }

    fn none() -> Self {
        Vec::new()
    }

    fn for_each(&self, f: impl FnMut(u32)) {
        self.iter().copied().for_each(f);
    }
}

/// Per-thread buffers: nothing is allocated per interior point once they
/// have grown.
#[derive(Default)]
struct Scratch {
    projected: Vec<Point2>,
    distances: Vec<f64>,
    columns: Columns,
    neighbours: Vec<Point2>,
    /// Member slot of each entry of `neighbours`.
    slots: Vec<u32>,
    along: Vec<u32>,
    cell: circle::CellScratch,
    polar: polar::PolarScratch,
}

/// Steps 1–2 at one position: the neighbourhood projected onto its plane
/// (and mapped by its sampling tensor) into `s.projected`, and its local
/// resolution β = μ + 2σ.
fn projected_beta(
    hoods: &Neighbourhoods,
    p: usize,
    vectors: Option<&[Sampling]>,
    s: &mut Scratch,
) -> f64 {
    let members = hoods.at(p);
    // The first pass already fitted this neighbourhood's plane.
    let frame = vectors.map_or_else(
        || fit_plane_normal(&hoods.points, members),
        |v| v[p].frame(),
    );
    let moments = vectors.map(|v| members.iter().map(|&m| &v[m as usize].moment));
    beta_in_plane(
        &hoods.points,
        members,
        &frame,
        hoods.view.as_ref(),
        moments,
        s,
    )
}

/// β of the neighbourhood `members` (the point first) in `frame`'s plane,
/// mapped by the members' sampling moments when given; the projection is
/// left in `s.projected`.
fn beta_in_plane<'m>(
    points: &[Point3],
    members: &[u32],
    frame: &Frame,
    view: Option<&View>,
    moments: Option<impl Iterator<Item = &'m SamplingMoment>>,
    s: &mut Scratch,
) -> f64 {
    let shear = shear_towards(view, frame, points[members[0] as usize]);
    project_sheared(points, members, frame, shear, &mut s.projected);
    if let Some(moments) = moments {
        let map = whitening_map(sampling_tensor_of_moments(frame, moments));
        for q in s.projected.iter_mut() {
            *q = apply(&map, *q);
        }
    }
    nearest_distances(&s.projected, &mut s.distances, &mut s.columns);
    beta_of(&s.distances)
}

fn analyse_point<L: LinkSlots>(
    hoods: &Neighbourhoods,
    p: usize,
    vectors: Option<&[Sampling]>,
    s: &mut Scratch,
    how: TestImpl,
) -> Verdict<L> {
    let beta = projected_beta(hoods, p, vectors, s);
    // Neighbours that project onto P_i itself carry no direction.
    s.neighbours.clear();
    s.slots.clear();
    for (slot, q) in s.projected.iter().enumerate().skip(1) {
        if q[0] != 0.0 || q[1] != 0.0 {
            s.neighbours.push(*q);
            s.slots.push(slot as u32);
        }
    }
    // The links always come from the fast cell, so both implementations
    // report the same ones; the reference decides with its own test.
    let cell_says = circle::largest_empty_circle_exceeds(&s.neighbours, beta, &mut s.cell);
    let by_circle = match how {
        TestImpl::Fast => cell_says,
        TestImpl::Reference => {
            s.projected.truncate(1);
            s.projected.extend_from_slice(&s.neighbours);
            circle::empty_circle_reference(&s.projected, beta)
        }
    };
    let links = if by_circle && cell_says {
        circle::boundary_links(&s.neighbours, beta, &mut s.cell, &mut s.along);
        L::of(s.along.iter().map(|&j| s.slots[j as usize]))
    } else {
        L::none()
    };
    let decision = if by_circle {
        Decision::EmptyCircle
    } else if polar::surrounding_path_is_open(&s.neighbours, &mut s.polar) {
        Decision::OpenPath
    } else {
        Decision::Interior
    };
    Verdict {
        decision,
        beta,
        links,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The β-only pass gives exactly BPD's β, with and without the
    /// sampling-tensor map, with duplicates, on random sheets.
    #[test]
    fn local_resolution_is_bpds_beta() {
        for (seed, stretch) in [(1, 1.0), (2, 3.0), (3, 0.5)] {
            let mut points = random_sheet(seed, 24, 0.05, stretch);
            points.extend_from_within(..10);
            for anisotropy in [true, false] {
                let options = BpdOptions {
                    k: 30,
                    anisotropy,
                    view: None,
                };
                let full = detect_boundary(&points, &options).unwrap().beta;
                let alone = local_resolution(&points, &options).unwrap();
                assert_eq!(full, alone, "seed {seed}, anisotropy {anisotropy}");
            }
        }
    }

    /// A wavy jittered sheet with a hole and a notch, plus uniform noise.
    fn random_sheet(seed: u64, n_side: usize, noise: f64, stretch: f64) -> Vec<Point3> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut pts = Vec::new();
        for i in 0..n_side {
            for j in 0..n_side {
                let x = i as f64 + rng.random_range(-0.35..0.35);
                let y = (j as f64 + rng.random_range(-0.35..0.35)) * stretch;
                let hole = (x - 0.3 * n_side as f64).hypot(y - 0.5 * n_side as f64 * stretch) < 3.0;
                let notch = x > 0.7 * n_side as f64 && y < 0.3 * n_side as f64 * stretch;
                if hole || notch {
                    continue;
                }
                let z = 0.05 * (x * x + y * y).sqrt()
                    + 2.0 * (0.1 * x).sin()
                    + rng.random_range(-noise..=noise);
                pts.push([x, y, z]);
            }
        }
        pts
    }

    #[test]
    fn fast_detection_matches_reference_on_random_clouds() {
        for seed in 0..6 {
            let noise = [0.0, 0.1, 0.4][seed as usize % 3];
            let stretch = [1.0, 3.0][seed as usize % 2];
            let pts = random_sheet(seed, 40, noise, stretch);
            let views = [
                None,
                Some(View::Along([0.3, -0.5, 1.0])),
                Some(View::From([-20.0, 10.0, 30.0])),
            ];
            for (anisotropy, view) in [false, true]
                .into_iter()
                .flat_map(|a| views.map(|v| (a, v)))
            {
                let opts = BpdOptions {
                    k: 30,
                    anisotropy,
                    view,
                };
                let fast = detect_boundary(&pts, &opts).unwrap();
                let slow = detect_boundary_reference(&pts, &opts).unwrap();
                assert_eq!(fast.beta, slow.beta, "seed {seed} {view:?}");
                let differ: Vec<usize> = (0..pts.len())
                    .filter(|&i| fast.boundary[i] != slow.boundary[i])
                    .collect();
                assert!(
                    differ.is_empty(),
                    "seed {seed} anisotropy {anisotropy} {view:?}: labels differ at {differ:?}"
                );
            }
        }
    }

    #[test]
    fn links_as_bits_and_as_lists_are_the_same_links() {
        for (seed, k) in [(1, 8), (2, 30), (3, 64)] {
            let pts = random_sheet(seed, 40, 0.1, 1.0);
            let options = BpdOptions {
                k,
                ..BpdOptions::default()
            };
            let Prepared { site_of, spatial } = prepare(&pts, &options).unwrap();
            let hoods = neighbourhoods(spatial, &options, TestImpl::Fast, &|_| {});
            let analyse = |bits: bool| {
                let how = TestImpl::Fast;
                if bits {
                    analyse_all::<SlotBits>(&hoods, &site_of, how, &|_| {})
                } else {
                    analyse_all::<Vec<u32>>(&hoods, &site_of, how, &|_| {})
                }
            };
            let (bits, lists) = (analyse(true), analyse(false));
            assert!(bits.links.len() > 100, "k {k}: {} links", bits.links.len());
            assert_eq!(bits, lists, "k {k}");
        }
    }

    #[test]
    fn blocks_of_runs_hold_whole_runs_of_about_a_block_of_points() {
        let lengths = [32, 5, 17, 32, 1, 30, 32, 8, 20, 32, 32, 3];
        let mut runs = Vec::new();
        let mut start = 0;
        for len in lengths {
            runs.push(start..start + len);
            start += len;
        }
        let mut jobs = runs.clone();
        let blocks = blocks_of_runs(&mut jobs, 64, |run| run);
        let points = |block: &[Range<usize>]| block.last().unwrap().end - block[0].start;
        assert_eq!(blocks.concat(), runs, "every run once, in order");
        assert!(blocks.iter().all(|b| points(b) <= 64));
        // Each block ends only where the next run would overflow it.
        for pair in blocks.windows(2) {
            assert!(pair[1][0].end - pair[0][0].start > 64);
        }
        // A run longer than a block is a block of its own.
        let mut long = vec![0..100, 100..110];
        assert_eq!(blocks_of_runs(&mut long, 64, |run| run).len(), 2);
    }

    #[test]
    fn labels_do_not_depend_on_thread_count() {
        let pts = random_sheet(11, 60, 0.2, 1.0);
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| detect_boundary(&pts, &BpdOptions::default()).unwrap())
        };
        assert_eq!(run(1), run(2));
        assert_eq!(run(1), run(3));
    }

    #[test]
    fn copies_of_a_point_always_share_its_morton_key() {
        let mut cloud = random_sheet(5, 20, 0.1, 1.0);
        assert!(!SpatialOrder::of(&cloud).keys_repeat());
        // An exact copy far from the first, and a zero of the other sign.
        cloud.push(cloud[3]);
        assert!(SpatialOrder::of(&cloud).keys_repeat());
        cloud.pop();
        cloud[7][2] = 0.0;
        cloud.push([cloud[7][0], cloud[7][1], -0.0]);
        assert!(SpatialOrder::of(&cloud).keys_repeat());
    }

    #[test]
    fn without_copies_merging_finds_the_same_sites_as_skipping_it() {
        // A twin a hair's breadth away shares a Morton key with its point,
        // which sends the cloud through the merge; it is no copy, so the
        // result must be the cloud itself, as on the direct path.
        let mut cloud = random_sheet(6, 25, 0.1, 1.0);
        let twin = cloud[11].map(|c| c + 1e-9);
        cloud.insert(40, twin);
        let direct = SpatialOrder::of(&cloud);
        assert!(direct.keys_repeat());
        let (sites, merged) = merged_in_spatial_order(&cloud).unwrap();
        let identity: Vec<u32> = (0..cloud.len() as u32).collect();
        assert_eq!(sites.site_of, identity);
        assert_eq!(merged.order, direct.order);
        assert_eq!(merged.keys, direct.keys);
        assert_eq!(merged.points, direct.points);
    }

    #[test]
    fn duplicates_share_their_site_label_and_do_not_change_it() {
        let pts = random_sheet(3, 30, 0.0, 1.0);
        let mut doubled = pts.clone();
        doubled.extend_from_slice(&pts);
        let once = detect_boundary(&pts, &BpdOptions::default()).unwrap();
        let twice = detect_boundary(&doubled, &BpdOptions::default()).unwrap();
        assert_eq!(twice.duplicates, pts.len());
        assert_eq!(&twice.boundary[..pts.len()], &once.boundary[..]);
        assert_eq!(&twice.boundary[pts.len()..], &once.boundary[..]);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let opts = BpdOptions::default();
        let few: Vec<Point3> = (0..10).map(|i| [i as f64, (i * i) as f64, 0.0]).collect();
        assert!(matches!(
            detect_boundary(&few, &opts),
            Err(CloudError::TooFewPoints { .. })
        ));
        let same = vec![[1.0, 2.0, 3.0]; 100];
        assert!(matches!(
            detect_boundary(&same, &opts),
            Err(CloudError::Degenerate { .. })
        ));
        let k3 = BpdOptions { k: 3, ..opts };
        assert!(matches!(
            detect_boundary(&few, &k3),
            Err(CloudError::KTooSmall { .. })
        ));
        assert!(matches!(
            detect_boundary(&[], &BpdOptions::default()),
            Err(CloudError::NoPoints)
        ));
        assert_eq!(
            local_resolution(&[], &BpdOptions::default()),
            Err(CloudError::NoPoints)
        );
    }

    /// Points along a line or a curve have no surface, whether rounding
    /// (float32) made the line not exactly straight or the points curve
    /// with noise across them; three rows of points are a surface.
    #[test]
    fn points_along_a_line_or_curve_have_no_surface() {
        let opts = BpdOptions::default();
        let single = |x: f64| x as f32 as f64;
        let line: Vec<Point3> = (0..500)
            .map(|i| {
                let t = i as f64 / 499.0;
                [12.3 + 310.7 * t, -4.56 + 123.45 * t, 7.89 - 98.76 * t].map(single)
            })
            .collect();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let curve: Vec<Point3> = (0..400)
            .map(|i| {
                let x = 0.5 * i as f64;
                let z = 8.0 * (-((x - 100.0) / 25.0).powi(2)).exp();
                [
                    x,
                    rng.random_range(-0.15..0.15),
                    z + rng.random_range(-0.15..0.15),
                ]
            })
            .collect();
        for cloud in [&line, &curve] {
            assert!(matches!(
                detect_boundary(cloud, &opts),
                Err(CloudError::NoSurface { thickness, .. }) if thickness < MIN_THICKNESS
            ));
        }
        let rows: Vec<Point3> = (0..600)
            .map(|i| [(i / 3) as f64, (i % 3) as f64, 0.0])
            .collect();
        assert!(detect_boundary(&rows, &opts).is_ok());
    }

    /// A view turns and moves with the cloud: the same labels and links
    /// after a rotation and a translation of both; a view along the normal
    /// of an exactly flat cloud is the paper's projection.
    #[test]
    fn the_view_moves_with_the_cloud() {
        let pts = random_sheet(7, 30, 0.3, 1.0);
        let (s, c) = 0.8f64.sin_cos();
        let turn = |p: Point3| [c * p[0] - s * p[2] + 5e3, p[1] - 2e3, s * p[0] + c * p[2]];
        let turn_direction = |d: Point3| [c * d[0] - s * d[2], d[1], s * d[0] + c * d[2]];
        let moved: Vec<Point3> = pts.iter().map(|&p| turn(p)).collect();
        for (view, moved_view) in [
            (
                View::Along([0.4, 0.1, 1.0]),
                View::Along(turn_direction([0.4, 0.1, 1.0])),
            ),
            (
                View::From([10.0, -5.0, 40.0]),
                View::From(turn([10.0, -5.0, 40.0])),
            ),
        ] {
            let at = |view| BpdOptions {
                view: Some(view),
                ..BpdOptions::default()
            };
            let before = detect_boundary(&pts, &at(view)).unwrap();
            let after = detect_boundary(&moved, &at(moved_view)).unwrap();
            assert_eq!(before.boundary, after.boundary, "{view:?}");
            assert_eq!(before.links, after.links, "{view:?}");
        }
        let flat: Vec<Point3> = pts.iter().map(|p| [p[0], p[1], 0.0]).collect();
        let paper = detect_boundary(&flat, &BpdOptions::default()).unwrap();
        let along_z = BpdOptions {
            view: Some(View::Along([0.0, 0.0, -2.0])),
            ..BpdOptions::default()
        };
        let viewed = detect_boundary(&flat, &along_z).unwrap();
        assert_eq!(viewed.view, along_z.view);
        assert_eq!(viewed.reach.len(), flat.len());
        let without_view = Detection {
            view: None,
            ..viewed
        };
        assert_eq!(paper, without_view);
    }

    #[test]
    fn unusable_views_are_refused() {
        let pts = random_sheet(8, 10, 0.0, 1.0);
        for view in [
            View::Along([0.0, 0.0, 0.0]),
            View::Along([f64::NAN, 0.0, 1.0]),
            View::From([0.0, f64::INFINITY, 0.0]),
        ] {
            let options = BpdOptions {
                view: Some(view),
                ..BpdOptions::default()
            };
            let error = detect_boundary(&pts, &options).unwrap_err();
            assert!(
                matches!(error, CloudError::BadView { .. }),
                "{view:?}: {error}"
            );
        }
    }
}
