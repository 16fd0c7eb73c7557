//! k-nearest-neighbour search (section 2 of the paper: "k-NN ... it finds the
//! closest k members of the cloud"), with kiddo behind it.
//!
//! Two ways to search: kiddo's *immutable* tree, for points in any order
//! ([`NeighbourIndex::new`]; it is built once from the whole slice, so it
//! has no bucket that can overflow when many points share one coordinate
//! value, as quantised scanner data does and kiddo's mutable tree fails
//! on), and the points' own Morton order ([`NeighbourIndex::in_morton_order`],
//! [`crate::spatial::morton`]), which BPD sorts its points into anyway and which
//! needs nothing built. The neighbourhood of a point includes the point
//! itself, first.
//! Ties in distance are broken by index so the result never depends on the
//! tree's internal layout.

use std::num::NonZeroUsize;
use std::ops::Range;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

use crate::geom::Point3;
use crate::spatial::morton::{positions_in_order, spatial_order, MortonCells, MortonGrid};

/// A k-NN index over a slice of distinct points.
pub struct NeighbourIndex<'a> {
    points: &'a [Point3],
    search: Search<'a>,
    ranks: Option<&'a [u32]>,
}

/// How an index finds the points near a place.
enum Search<'a> {
    /// kiddo's immutable k-d tree, for points in any order.
    Tree(ImmutableKdTree<f64, 3>),
    /// The points' own Morton order ([`crate::spatial::morton`]): nothing to build.
    Morton(MortonCells<'a>),
}

impl<'a> NeighbourIndex<'a> {
    /// Builds the index. `points` must be finite and have fewer than 2^32 entries.
    pub fn new(points: &'a [Point3]) -> Self {
        // kiddo builds in parallel only from 2¹⁸ points by default; the
        // serial build takes a tenth of BPD's time at 100k points. The
        // queries' answers do not depend on the tree's layout (ties are
        // cut by rank), so the split is free to differ.
        let tree = ImmutableKdTree::builder()
            .with_parallel_construction_threshold(PARALLEL_TREE_FROM)
            .build_from_slice(points)
            .expect("point count fits in u32, checked at the entry point");
        Self {
            points,
            search: Search::Tree(tree),
            ranks: None,
        }
    }

    /// The index of points sorted by Morton key (`cells`, see
    /// [`crate::spatial::morton`]): the same answers as [`Self::new`]'s, found
    /// through the sorted keys instead of a tree.
    pub(crate) fn in_morton_order(points: &'a [Point3], cells: MortonCells<'a>) -> Self {
        Self {
            points,
            search: Search::Morton(cells),
            ranks: None,
        }
    }

    /// Breaks distance ties by `ranks[i]` instead of the index i (e.g. the
    /// points' input order when `points` was reordered).
    pub(crate) fn with_ranks(mut self, ranks: &'a [u32]) -> Self {
        self.ranks = Some(ranks);
        self
    }

    /// The indexed points.
    pub fn points(&self) -> &'a [Point3] {
        self.points
    }

    fn rank(&self, i: u32) -> u32 {
        self.ranks.map_or(i, |r| r[i as usize])
    }

    /// Writes the indices of the `k` points nearest to point `i` (itself
    /// first, then by increasing distance, ties by rank) into `out`.
    ///
    /// When points tie at the k-th distance, which of them kiddo returns
    /// depends on the tree; so the query asks for one more than needed and
    /// widens until the tie is enclosed, then cuts by rank.
    pub fn nearest(&self, i: usize, k: usize, out: &mut Vec<u32>) {
        self.nearest_holding(i, k, None, out);
    }

    /// A radius round point `i` of an index in Morton order that holds at
    /// least k points: that of the k nearest of the 2k points beside `i`
    /// in the order, which are near it in space (the smallest cell with k
    /// points, [`MortonCells::radius_holding`], often holds hundreds). 0
    /// when k copies of the point sit there.
    fn radius_from_order(&self, i: usize, k: usize) -> f64 {
        let n = self.points.len();
        let from = i.saturating_sub(k).min(n.saturating_sub(2 * k));
        let p = self.points[i];
        let mut d2: Vec<f64> = (from..(from + 2 * k).min(n))
            .map(|j| crate::geom::dist2(p, self.points[j]))
            .collect();
        let (_, kth, _) = d2.select_nth_unstable_by(k - 1, f64::total_cmp);
        // A hair wider, so that rounding in r² cannot leave the k-th out.
        kth.sqrt() * (1.0 + 1e-9)
    }

    /// [`Self::nearest`], given when known a radius round point `i` that
    /// holds at least k points: with Morton cells the search starts there
    /// (else at a radius found from the cells); the tree does not need it.
    fn nearest_holding(&self, i: usize, k: usize, holding: Option<f64>, out: &mut Vec<u32>) {
        out.clear();
        let k = k.min(self.points.len());
        if k == 0 {
            return;
        }
        match &self.search {
            Search::Tree(tree) => self.nearest_in_tree(tree, i, k, out),
            Search::Morton(cells) => {
                // A radius of 0 would never grow (k = 1 at a run's centre).
                let radius = holding.unwrap_or_else(|| self.radius_from_order(i, k));
                let radius = if radius > 0.0 {
                    radius
                } else {
                    cells.radius_holding(i, k)
                };
                self.nearest_in_cells(cells, i, k, radius, out);
            }
        }
    }

    /// [`Self::nearest`] through kiddo's tree, for 1 ≤ k ≤ n.
    fn nearest_in_tree(
        &self,
        tree: &ImmutableKdTree<f64, 3>,
        i: usize,
        k: usize,
        out: &mut Vec<u32>,
    ) {
        let p = self.points[i];
        let mut ask = (k + 1).min(self.points.len());
        let found = loop {
            let query = tree.query(&p);
            let n = NonZeroUsize::new(ask).expect("ask ≥ 1");
            let found = query.nearest_n::<SquaredEuclidean<f64>>(n).execute();
            let tie_reaches_end = ask < self.points.len()
                && found.len() == ask
                && tie_key(found[ask - 1].distance) <= tie_key(found[k - 1].distance);
            if !tie_reaches_end {
                break found;
            }
            ask = (2 * ask).min(self.points.len());
        };
        let mut found: Vec<(bool, u64, u32, u32)> = found
            .iter()
            .map(|n| {
                (
                    n.item as usize != i,
                    tie_key(n.distance),
                    self.rank(n.item),
                    n.item,
                )
            })
            .collect();
        found.sort_unstable();
        found.truncate(k);
        out.extend(found.iter().map(|n| n.3));
    }

    /// [`Self::nearest`] through Morton cells, for 1 ≤ k ≤ n, starting from
    /// a `radius` > 0 that holds at least k points: the points within it,
    /// sorted as the tree's answer is. The radius doubles until the k-th is
    /// strictly inside its tie bin, so that no point outside can tie with it.
    fn nearest_in_cells(
        &self,
        cells: &MortonCells,
        i: usize,
        k: usize,
        mut radius: f64,
        out: &mut Vec<u32>,
    ) {
        let p = self.points[i];
        // Allocated per call: these queries are the rare fallbacks.
        let mut found: Vec<(bool, u64, u32, u32)> = Vec::new();
        loop {
            found.clear();
            cells.within(self.points, p, radius, |j| {
                let d2 = crate::geom::dist2(p, self.points[j as usize]);
                found.push((j as usize != i, tie_key(d2), self.rank(j), j));
            });
            let everything = found.len() == self.points.len();
            if found.len() >= k {
                found.select_nth_unstable(k - 1);
                if everything || found[k - 1].1 < tie_key(radius * radius) {
                    break;
                }
            }
            radius *= 2.0;
        }
        found[..k].sort_unstable();
        out.extend(found[..k].iter().map(|n| n.3));
    }
}

impl NeighbourIndex<'_> {
    /// The k nearest of every point of `run` (positions in the indexed
    /// slice, best a compact group in space, e.g. an octree cell), written
    /// `k` per point into `out` in the order of [`Self::nearest`], with the
    /// same result.
    ///
    /// One range query serves the whole run: the points within a radius G of
    /// the run's central point c are gathered once. For a point p of the
    /// run they include every point within G − |p − c| of p; when at least
    /// k do, p's k nearest (ties included) are among them, exactly. G is
    /// chosen so that this almost always holds: c's k-th distance d_k with
    /// a margin, plus the run's radius. d_k is first estimated by the
    /// previous run's (consecutive runs are neighbours in space, and a tree
    /// query for c cost more than the guess at a million points) and
    /// checked: c's k nearest must lie within G; if not, c gets its own
    /// k-NN query. A point for which the gathered set cannot prove its
    /// answer gets its own k-NN query too.
    pub(crate) fn nearest_of_run(
        &self,
        run: Range<usize>,
        k: usize,
        out: &mut [u32],
        s: &mut RunScratch,
    ) {
        let k = k.min(self.points.len());
        debug_assert_eq!(out.len(), run.len() * k);
        if k == 0 || run.is_empty() {
            return;
        }
        let centre = self.central_point(run.clone());
        let pc = self.points[centre];
        let h = run
            .clone()
            .map(|p| dist(pc, self.points[p]))
            .fold(0.0, f64::max);
        // Rounding slack: relative to the distances, and absolute for the
        // coordinates' own precision far from the origin.
        let slack = |r: f64| 1e-9 * r + 1e-13 * magnitude(pc);
        // The previous run's k-th distance estimates c's: gather with it
        // and check that c's own k nearest are inside; if not, ask the tree.
        let guessed = s.last_d_k.and_then(|estimate| {
            let gather = RUN_MARGIN * estimate + h;
            self.gather(pc, gather + slack(gather), s);
            let reach = gather - slack(gather);
            let mut own = std::mem::take(&mut s.centre);
            own.resize(k, 0);
            let found = select_within(pc, 0.0, reach * reach, k, s, &mut own);
            s.centre = own;
            found.then(|| (dist(pc, self.points[s.centre[k - 1] as usize]), gather))
        });
        // With a good guess, c's k nearest are already in `s.centre`.
        let centre_known = guessed.is_some();
        let (d_k, gather) = guessed.unwrap_or_else(|| {
            self.nearest(centre, k, &mut s.single);
            let d_k = dist(pc, self.points[s.single[k - 1] as usize]);
            let gather = RUN_MARGIN * d_k + h;
            self.gather(pc, gather + slack(gather), s);
            (d_k, gather)
        });
        s.last_d_k = Some(d_k);
        let slack = slack(gather);
        // The previous point's k-th distance: neighbours' k-th distances
        // differ little, so a little more than it usually encloses k
        // candidates, far fewer than the proven reach (see `select_nearest`).
        let mut previous_d_k = d_k;
        for (p, out) in run.zip(out.chunks_exact_mut(k)) {
            if p == centre && centre_known {
                out.copy_from_slice(&s.centre);
                continue;
            }
            let pp = self.points[p];
            let from_centre = dist(pc, pp);
            // Every gathered point within `reach` of p is a candidate; and
            // p's k nearest lie within d_k(c) + |p − c| (that ball holds
            // c's k nearest), so the nearer of the two radii loses nothing.
            let reach = (gather - from_centre - slack).min(d_k + from_centre + slack);
            let guess = GUESS_MARGIN * previous_d_k;
            if !self.select_nearest(pp, from_centre, reach * reach, guess * guess, k, s, out) {
                // c's k nearest lie within d_k(c) + |p − c| of p.
                let holding = d_k + from_centre;
                self.nearest_holding(p, k, Some(holding + 2.0 * slack), &mut s.single);
                out.copy_from_slice(&s.single);
            }
            previous_d_k = dist(pp, self.points[out[k - 1] as usize]);
        }
    }

    /// Gathers the points within `radius` of `centre` as candidates.
    fn gather(&self, centre: Point3, radius: f64, s: &mut RunScratch) {
        s.candidates.clear();
        match &self.search {
            Search::Tree(tree) => tree
                .query(&centre)
                .within::<SquaredEuclidean<f64>>(radius * radius)
                .unsorted()
                .without_distances()
                .visit(|found| s.candidates.push(found.item)),
            Search::Morton(cells) => {
                cells.within(self.points, centre, radius, |j| s.candidates.push(j))
            }
        }
        s.rank_and_index.clear();
        s.rank_and_index.extend(
            s.candidates
                .iter()
                .map(|&j| (u64::from(self.rank(j)) << 32) | u64::from(j)),
        );
        // In rank order, a candidate's position breaks distance ties as its
        // rank does (see `select_within`).
        s.rank_and_index.sort_unstable();
        // Then in shells of equal area by distance from the centre, so
        // that a query scans only the shells that can reach it (see
        // `select_within`); each candidate keeps its position in rank
        // order for the ties. A counting sort: cheaper than sorting by
        // distance, and the last shell scanned is only 1/SHELLS of them.
        s.shell_scale = SHELLS as f64 / (radius * radius);
        let shell_of =
            |q: Point3| ((crate::geom::dist2(centre, q) * s.shell_scale) as usize).min(SHELLS - 1);
        let mut starts = [0u32; SHELLS + 1];
        s.shells.clear();
        s.shells.extend(s.rank_and_index.iter().map(|&ri| {
            let shell = shell_of(self.points[(ri as u32) as usize]);
            starts[shell + 1] += 1;
            shell as u8
        }));
        for shell in 0..SHELLS {
            starts[shell + 1] += starts[shell];
        }
        s.shell_end.copy_from_slice(&starts[1..]);
        s.positions.clear();
        s.positions.resize(s.shells.len(), 0);
        s.coords.clear();
        s.coords.resize(s.shells.len(), [0.0; 3]);
        for (position, (&shell, &ri)) in s.shells.iter().zip(&s.rank_and_index).enumerate() {
            let slot = &mut starts[shell as usize];
            s.positions[*slot as usize] = position as u32;
            s.coords[*slot as usize] = self.points[(ri as u32) as usize];
            *slot += 1;
        }
        s.keyed.resize(s.coords.len(), 0);
        s.centre_slack = 1e-12 * magnitude(centre);
    }

    /// The run's point closest to the run's mean.
    fn central_point(&self, run: Range<usize>) -> usize {
        let n = run.len() as f64;
        let mut mean = [0.0; 3];
        for p in run.clone() {
            for (m, c) in mean.iter_mut().zip(self.points[p]) {
                *m += c / n;
            }
        }
        let key = |p: &usize| crate::geom::dist2(mean, self.points[*p]);
        run.min_by(|a, b| key(a).total_cmp(&key(b)))
            .expect("run is not empty")
    }

    /// Writes into `out` the k nearest of `p` among the gathered candidates
    /// within `reach2` (squared) of it; false if fewer than k are.
    ///
    /// Tries the candidates within the smaller `guess2` first: when they
    /// prove the answer (k of them, the k-th strictly inside the guess's tie
    /// bin), it is the same, and selecting among fewer is cheaper.
    #[allow(clippy::too_many_arguments)]
    fn select_nearest(
        &self,
        p: Point3,
        from_centre: f64,
        reach2: f64,
        guess2: f64,
        k: usize,
        s: &mut RunScratch,
        out: &mut [u32],
    ) -> bool {
        (guess2 < reach2 && select_within(p, from_centre, guess2, k, s, out))
            || select_within(p, from_centre, reach2, k, s, out)
    }
}

/// [`NeighbourIndex::select_nearest`] with one radius (it reads only the
/// gathered candidates in `s`); `from_centre` is |p − c|.
// Baseline and AVX2 variants, chosen at run time (crate doc, "Vector kernels").
#[multiversion::multiversion(targets("x86_64+avx2"))]
fn select_within(
    p: Point3,
    from_centre: f64,
    reach2: f64,
    k: usize,
    s: &mut RunScratch,
    out: &mut [u32],
) -> bool {
    if s.coords.len() > POSITION_MASK as usize {
        return false; // positions would not fit their bits
    }
    // A candidate q within reach of p has |q − c| ≤ |p − c| + reach: only
    // the candidates up to that distance from the centre are scanned
    // (about half of them). The bound is widened for rounding, by far
    // more than the distances' own error; a candidate let in by the
    // margin is still measured against `reach2` below.
    let bound = (from_centre + reach2.sqrt()) * (1.0 + 1e-9) + s.centre_slack;
    // The same monotone formula as the gathering's shells.
    let last_shell = ((bound * bound * s.shell_scale) as usize).min(SHELLS - 1);
    let end = s.shell_end[last_shell] as usize;
    // Every candidate is written and only those within reach advance
    // the end: no branch to mispredict on a coin-flip test. `keyed`
    // has one slot per candidate since the gathering, so it is not
    // cleared per query.
    let mut len = 0;
    for (&q, &position) in s.coords[..end].iter().zip(&s.positions) {
        let d = crate::geom::dist2(p, q);
        s.keyed[len] = (tie_key(d) << POSITION_BITS) | u64::from(position);
        len += usize::from(d <= reach2);
    }
    let within = &mut s.keyed[..len];
    if within.len() < k {
        return false;
    }
    // Up to 2k candidates (the usual case after the first guess) one
    // sort is cheaper than a selection and a sort of the k: −1.6 % of the
    // 12k benchmark's instructions.
    if within.len() > 2 * k {
        within.select_nth_unstable(k - 1);
        within[..k].sort_unstable();
    } else {
        within.sort_unstable();
    }
    let nearest = &within[..k];
    // A point beyond the reach may tie with the k-th (its distance in
    // the same tie bin) and win on rank: only a k-th strictly below the
    // reach's bin proves the answer.
    if nearest[k - 1] >> POSITION_BITS >= tie_key(reach2) {
        return false;
    }
    for (o, n) in out.iter_mut().zip(nearest.iter()) {
        *o = s.rank_and_index[(n & POSITION_MASK) as usize] as u32;
    }
    true
}

/// Shells of the gathered candidates (see [`NeighbourIndex::gather`]).
const SHELLS: usize = 32;

/// Point count from which (and subtree size down to which) the tree is
/// built in parallel.
const PARALLEL_TREE_FROM: usize = 16384;

/// How far beyond the central point's k-th distance a run gathers (see
/// [`NeighbourIndex::nearest_of_run`]); the k-th distance varies a little
/// across a run. Whole benchmark program, one thread, callgrind: 12k sheet
/// 351.5M / 351.0M / 352.9M / 354.7M instructions at 1.05 / 1.1 / 1.25 /
/// 1.35; 100k sheet 2,694M at 1.1 against 2,719M at 1.25.
const RUN_MARGIN: f64 = 1.1;

/// How far beyond the previous point's k-th distance a point's selection
/// first looks (see [`NeighbourIndex::select_nearest`]).
const GUESS_MARGIN: f64 = 1.1;

/// Reusable buffers for [`NeighbourIndex::nearest_of_run`].
#[derive(Debug, Default, Clone)]
pub struct RunScratch {
    /// The last run's central k-th distance, the next run's first guess.
    last_d_k: Option<f64>,
    /// The run's central point's k nearest, when the guess found them.
    centre: Vec<u32>,
    single: Vec<u32>,
    candidates: Vec<u32>,
    /// The candidates' points, shell by shell.
    coords: Vec<Point3>,
    /// Each candidate's rank (high half) and index (low half), sorted:
    /// candidates in rank order.
    rank_and_index: Vec<u64>,
    /// Candidates as one integer each that orders like (distance², rank):
    /// the distance's [`tie_key`] above the candidate's position in
    /// `rank_and_index` ([`POSITION_BITS`]). The bits of a non-negative f64
    /// order like the number, and comparisons of one machine word are
    /// what the selection and the sort do fastest.
    keyed: Vec<u64>,
    /// Each candidate's shell (by rank position): the shells cut the
    /// gathering ball into [`SHELLS`] of equal area around its centre.
    shells: Vec<u8>,
    /// Shells per unit of squared distance from the centre.
    shell_scale: f64,
    /// One past the last candidate of each shell, in `coords`.
    shell_end: [u32; SHELLS],
    /// The candidates' positions in `rank_and_index`, shell by shell.
    positions: Vec<u32>,
    /// Absolute rounding allowance of distances near the centre.
    centre_slack: f64,
}

/// Bits of a candidate's position in its [`RunScratch::keyed`] key. A
/// [`tie_key`] of a finite squared distance is below 2³⁷ (the f64's 63
/// value bits less [`TIE_BITS`]), which leaves 27; a run with more
/// candidates (2²⁷, only in clouds of over a hundred million points all
/// within one gathering radius) falls back to tree queries.
const POSITION_BITS: u32 = 64 - (63 - TIE_BITS);
const POSITION_MASK: u64 = (1 << POSITION_BITS) - 1;

/// The order key of a squared distance: its bits rounded to drop the
/// lowest [`TIE_BITS`], so that distances within 2⁻²⁶ ≈ 1.5·10⁻⁸ of each
/// other (relative) tie and are ordered by rank. Monotone in the distance.
///
/// Quantised coordinates (scanner data) make many neighbours exactly
/// equidistant in exact arithmetic; in floating point those distances come
/// out equal or a unit in the last place apart depending on where the
/// cloud sits, so ordering by the raw bits let a translation change which
/// of them is the k-th neighbour, and with it β and the labels. The bits
/// are rounded, not truncated: quantised coordinates give "round" squared
/// distances (2.125 = 10.001₂) whose low bits are all zero, which
/// truncation would put exactly on a bin edge, where rounding noise splits
/// the tie again; rounding puts them in the middle of a bin.
pub(crate) fn tie_key(d2: f64) -> u64 {
    (d2.to_bits() + (1 << (TIE_BITS - 1))) >> TIE_BITS
}

/// Low bits of a squared distance ignored by [`tie_key`]. Wide enough for
/// the rounding of coordinates 10⁵ spacings from the origin (~10⁻¹⁰
/// relative), narrow enough that distances that really differ almost never
/// tie (which would make them depend on the input order): see
/// `docs/bpd.md`, "Ties and duplicates".
const TIE_BITS: u32 = 26;

fn dist(a: Point3, b: Point3) -> f64 {
    crate::geom::dist2(a, b).sqrt()
}

fn magnitude(p: Point3) -> f64 {
    p.iter().fold(0.0, |m, c| m.max(c.abs()))
}

/// The k nearest points of a cloud's point, by index: the point itself
/// first, then by increasing distance, ties by index ([`NeighbourIndex`]'s
/// answers, whichever index gives them).
pub trait KNearest: Sync {
    /// The cloud.
    fn points(&self) -> &[Point3];
    /// Writes the indices of the `k` points nearest to point `i` into `out`.
    fn nearest(&self, i: usize, k: usize, out: &mut Vec<u32>);
}

impl KNearest for NeighbourIndex<'_> {
    fn points(&self) -> &[Point3] {
        NeighbourIndex::points(self)
    }
    fn nearest(&self, i: usize, k: usize, out: &mut Vec<u32>) {
        NeighbourIndex::nearest(self, i, k, out);
    }
}

/// A k-NN index over points in any order, searched through a copy of them
/// in Morton order: [`NeighbourIndex::new`]'s answers with nothing to
/// build but the sort, for a few queries over a large cloud (a mesh's
/// border vertices among all its vertices: building the k-d tree over 2.5
/// million vertices cost more than all the queries). Each query starts
/// from the radius of the point's neighbours in the order.
pub struct MortonIndex<'a> {
    points: &'a [Point3],
    in_order: Vec<Point3>,
    /// The point at each position of the order, and its Morton key.
    order: Vec<u32>,
    keys: Vec<u64>,
    /// Each point's position in the order.
    position_of: Vec<u32>,
    grid: MortonGrid,
}

impl<'a> MortonIndex<'a> {
    /// Sorts the points. `points` must be finite and have fewer than 2^32
    /// entries.
    pub fn new(points: &'a [Point3]) -> Self {
        let grid = MortonGrid::of(points);
        let (order, keys) = spatial_order(points, &grid);
        let in_order = order.par_iter().map(|&i| points[i as usize]).collect();
        let position_of = positions_in_order(&order);
        Self {
            points,
            in_order,
            order,
            keys,
            position_of,
            grid,
        }
    }
}

impl KNearest for MortonIndex<'_> {
    fn points(&self) -> &[Point3] {
        self.points
    }
    fn nearest(&self, i: usize, k: usize, out: &mut Vec<u32>) {
        let cells = MortonCells::new(self.grid, &self.keys);
        let index = NeighbourIndex::in_morton_order(&self.in_order, cells).with_ranks(&self.order);
        index.nearest(self.position_of[i] as usize, k, out);
        for found in out.iter_mut() {
            *found = self.order[*found as usize];
        }
    }
}

#[cfg(test)]
/// Reference k-NN by sorting all distances; for tests.
pub fn nearest_brute_force(points: &[Point3], i: usize, k: usize) -> Vec<u32> {
    let p = points[i];
    let mut all: Vec<(bool, u64, u32)> = points
        .iter()
        .enumerate()
        .map(|(j, q)| (j != i, tie_key(crate::geom::dist2(p, *q)), j as u32))
        .collect();
    all.sort_unstable();
    all.into_iter().take(k).map(|t| t.2).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    #[test]
    fn matches_brute_force_on_random_points() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let pts: Vec<Point3> = (0..500)
            .map(|_| [rng.random(), rng.random(), rng.random::<f64>() * 0.1])
            .collect();
        let index = NeighbourIndex::new(&pts);
        let mut out = Vec::new();
        for i in (0..pts.len()).step_by(7) {
            index.nearest(i, 30, &mut out);
            assert_eq!(out, nearest_brute_force(&pts, i, 30), "point {i}");
        }
    }

    #[test]
    fn ties_at_the_kth_distance_are_cut_by_rank() {
        // A square grid: the 4 points at distance 1 tie, as do the 4 at √2.
        let pts: Vec<Point3> = (0..49)
            .map(|i| [(i % 7) as f64, (i / 7) as f64, 0.0])
            .collect();
        let reversed: Vec<u32> = (0..49u32).rev().collect();
        let index = NeighbourIndex::new(&pts).with_ranks(&reversed);
        let mut out = Vec::new();
        index.nearest(24, 3, &mut out);
        // Centre 24; its distance-1 neighbours are 17, 23, 25, 31: the two
        // of highest index rank first.
        assert_eq!(out, vec![24, 31, 25]);
        let plain = NeighbourIndex::new(&pts);
        plain.nearest(24, 3, &mut out);
        assert_eq!(out, vec![24, 17, 23]);
    }

    /// A random sheet of `n` points and an exact 20 × 20 grid full of ties.
    fn sheet_and_grid(seed: u64, n: usize) -> Vec<Point3> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut pts: Vec<Point3> = (0..n)
            .map(|_| [rng.random(), rng.random(), rng.random::<f64>() * 0.02])
            .collect();
        pts.extend((0..400).map(|i| [2.0 + (i % 20) as f64 * 0.05, (i / 20) as f64 * 0.05, 0.0]));
        pts
    }

    /// Runs of `run_len` consecutive points give `reference`'s 30 nearest.
    fn assert_runs_match(
        index: &NeighbourIndex,
        run_len: usize,
        mut reference: impl FnMut(usize) -> Vec<u32>,
    ) {
        let n = index.points().len();
        let mut scratch = RunScratch::default();
        let mut runs = vec![0u32; 30 * run_len];
        for start in (0..n).step_by(run_len) {
            let run = start..(start + run_len).min(n);
            let out = &mut runs[..run.len() * 30];
            index.nearest_of_run(run.clone(), 30, out, &mut scratch);
            for (p, got) in run.zip(out.chunks(30)) {
                assert_eq!(got, &reference(p)[..], "point {p}");
            }
        }
    }

    #[test]
    fn run_queries_match_single_queries() {
        // The sheet and grid, and a few far outliers; ties cut by rank.
        let mut pts = sheet_and_grid(5, 1500);
        pts.extend((0..5).map(|i| [10.0 + i as f64, -3.0, 7.0]));
        let ranks: Vec<u32> = (0..pts.len() as u32).rev().collect();
        let index = NeighbourIndex::new(&pts).with_ranks(&ranks);
        let mut single = Vec::new();
        assert_runs_match(&index, 16, |p| {
            index.nearest(p, 30, &mut single);
            single.clone()
        });
    }

    /// Far from the origin and at a small scale the coordinates' rounding
    /// is largest next to the spacing: the shells the runs scan must still
    /// hold every point within reach (ties on the quantised grid included).
    #[test]
    fn run_queries_match_brute_force_far_from_the_origin() {
        let pts = far_from_the_origin(sheet_and_grid(9, 1200));
        let index = NeighbourIndex::new(&pts);
        assert_runs_match(&index, 32, |p| nearest_brute_force(&pts, p, 30));
    }

    /// The index over points in Morton order ([`crate::spatial::morton`]) gives the
    /// brute force's answers on the original points, ties cut by input
    /// index: by runs (gathers, and the fallbacks given a radius) and by
    /// single queries (which start from their neighbours in the order).
    fn assert_morton_matches_brute_force(raw: &[Point3]) {
        use crate::spatial::morton::{spatial_order, MortonCells, MortonGrid};
        let grid = MortonGrid::of(raw);
        let (order, keys) = spatial_order(raw, &grid);
        let points: Vec<Point3> = order.iter().map(|&i| raw[i as usize]).collect();
        let position_of = crate::spatial::morton::positions_in_order(&order);
        let index = NeighbourIndex::in_morton_order(&points, MortonCells::new(grid, &keys))
            .with_ranks(&order);
        let reference = |p: usize| -> Vec<u32> {
            nearest_brute_force(raw, order[p] as usize, 30)
                .into_iter()
                .map(|i| position_of[i as usize])
                .collect()
        };
        for run_len in [1, 16, 32] {
            assert_runs_match(&index, run_len, reference);
        }
        let mut single = Vec::new();
        for p in (0..points.len()).step_by(13) {
            index.nearest(p, 30, &mut single);
            assert_eq!(single, reference(p), "single query at {p}");
        }
    }

    /// [`MortonIndex`] answers as the k-d tree does, in the points' own
    /// indices, on a sheet, a grid full of ties and points repeated.
    #[test]
    fn morton_index_by_input_index_matches_the_tree() {
        let mut pts = sheet_and_grid(15, 1500);
        let copies: Vec<Point3> = pts.iter().step_by(7).copied().collect();
        pts.extend(copies);
        let (tree, morton) = (NeighbourIndex::new(&pts), MortonIndex::new(&pts));
        let (mut want, mut got) = (Vec::new(), Vec::new());
        for i in (0..pts.len()).step_by(5) {
            for k in [1, 12, 30] {
                tree.nearest(i, k, &mut want);
                KNearest::nearest(&morton, i, k, &mut got);
                assert_eq!(got, want, "point {i}, k {k}");
            }
        }
    }

    #[test]
    fn morton_index_matches_brute_force() {
        // The sheet, the grid full of ties, and far outliers.
        let mut pts = sheet_and_grid(11, 1500);
        pts.extend((0..5).map(|i| [10.0 + i as f64, -3.0, 7.0]));
        assert_morton_matches_brute_force(&pts);
    }

    #[test]
    fn morton_index_matches_brute_force_far_from_the_origin() {
        assert_morton_matches_brute_force(&far_from_the_origin(sheet_and_grid(12, 1200)));
    }

    /// With k = 1 a point's k-th distance is 0, a radius that doubling
    /// cannot grow; the query must still end, with the point itself.
    #[test]
    fn morton_index_answers_k_1() {
        use crate::spatial::morton::{spatial_order, MortonCells, MortonGrid};
        let pts = sheet_and_grid(14, 300);
        let grid = MortonGrid::of(&pts);
        let (order, keys) = spatial_order(&pts, &grid);
        let sorted: Vec<Point3> = order.iter().map(|&i| pts[i as usize]).collect();
        let index = NeighbourIndex::in_morton_order(&sorted, MortonCells::new(grid, &keys));
        let mut out = vec![0u32; 8];
        index.nearest_of_run(0..8, 1, &mut out, &mut RunScratch::default());
        assert_eq!(out, (0..8).collect::<Vec<u32>>());
        let mut single = Vec::new();
        index.nearest(5, 1, &mut single);
        assert_eq!(single, vec![5]);
        // The fallback given the run's radius d_k + |p − c| = 0 + 0.
        index.nearest_holding(5, 1, Some(0.0), &mut single);
        assert_eq!(single, vec![5]);
    }

    /// `pts` scaled by 10⁻³ and moved 10⁵ from the origin.
    fn far_from_the_origin(pts: Vec<Point3>) -> Vec<Point3> {
        pts.into_iter()
            .map(|p| [p[0] * 1e-3 + 1e5, p[1] * 1e-3 - 1e5, p[2] * 1e-3 + 1e5])
            .collect()
    }

    /// Density varying a thousandfold, and a cloud of 31 points (one more
    /// than k, so every query needs nearly all of them).
    #[test]
    fn morton_index_matches_brute_force_on_uneven_and_tiny_clouds() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(13);
        let uneven: Vec<Point3> = (0..2000)
            .map(|i| {
                let s = [1.0, 0.03, 0.001][i % 3];
                [rng.random::<f64>() * s, rng.random::<f64>() * s, 0.0]
            })
            .collect();
        assert_morton_matches_brute_force(&uneven);
        assert_morton_matches_brute_force(&uneven[..31]);
    }

    /// Quantised scanner data puts thousands of points on one coordinate
    /// value; kiddo's mutable tree panics on that, the immutable one must not.
    #[test]
    fn survives_many_points_sharing_one_coordinate() {
        let pts: Vec<Point3> = (0..20_000)
            .map(|i| [(i % 200) as f64, (i / 200) as f64, 5.0])
            .collect();
        let index = NeighbourIndex::new(&pts);
        let mut out = Vec::new();
        index.nearest(10_050, 9, &mut out);
        assert_eq!(out[0], 10_050);
        let mut got: Vec<u32> = out.clone();
        got.sort_unstable();
        let mut want = nearest_brute_force(&pts, 10_050, 9);
        want.sort_unstable();
        assert_eq!(got, want);
    }
}
