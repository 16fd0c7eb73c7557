//! Morton (Z-order) keys, and neighbour search over points sorted by them.
//!
//! Not from the paper: how BPD's step 1 (k-NN, section 2) finds
//! neighbourhoods fast. The points are cut into a grid of 2²¹ cells per axis
//! over their bounding cube, and each point gets its cell's Morton key (the
//! cell's three coordinates, bits interleaved). Sorted by key, points in one
//! cell of any coarser level of the octree (a key prefix) are one range of
//! the sorted list. So the sorted keys are themselves a search tree: the
//! points near a centre are found by binary searches for the few cells
//! that cover the ball, with nothing built. BPD sorts by Morton key anyway
//! (queries in spatial order share the cache), and a k-d tree built on top
//! cost a serial 0.5 ms at 12k points, 70–90 ms at 1M.
//!
//! The sorted keys also cut the points into runs of whole octree cells
//! ([`octree_runs`]): the groups whose k-NN queries share one range query.

use rayon::prelude::*;

use voracious_radix_sort::RadixSort;

use crate::cloud::PASS_PIECE;
use crate::geom::{dist2, Point3};

/// Bits per axis of a cell coordinate.
const BITS: u32 = 21;
const MAX_CELL: u64 = (1 << BITS) - 1;

/// The grid of a cloud's Morton keys.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MortonGrid {
    lo: Point3,
    /// Cells per unit of length.
    scale: f64,
}

impl MortonGrid {
    /// The grid over `points`' bounding cube. Minima and maxima are exact
    /// whatever the split, so the parallel pass gives the serial result.
    pub fn of(points: &[Point3]) -> Self {
        let (lo, hi) = points
            .par_iter()
            .with_min_len(PASS_PIECE)
            .fold(
                || ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
                |(lo, hi), p| (min3(lo, *p), max3(hi, *p)),
            )
            .reduce(
                || ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
                |(lo_a, hi_a), (lo_b, hi_b)| (min3(lo_a, lo_b), max3(hi_a, hi_b)),
            );
        let extent = (0..3)
            .map(|a| hi[a] - lo[a])
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        Self {
            lo,
            scale: MAX_CELL as f64 / extent,
        }
    }

    /// The Morton key of `p`'s cell. Copies of a point share it, and so do
    /// −0.0 and +0.0.
    pub fn key(&self, p: Point3) -> u64 {
        interleave([0, 1, 2].map(|a| self.cell(p[a], a)))
    }

    /// The cell coordinate of `x` along `axis`, clamped to the grid (`as`
    /// saturates below zero). Monotone in `x`: every operation on the way
    /// rounds monotonically.
    fn cell(&self, x: f64, axis: usize) -> u64 {
        (((x - self.lo[axis]) * self.scale) as u64).min(MAX_CELL)
    }
}

/// Each point's position in `order` (the point at each position).
pub(crate) fn positions_in_order(order: &[u32]) -> Vec<u32> {
    let mut position_of = vec![0u32; order.len()];
    for (position, &i) in order.iter().enumerate() {
        position_of[i as usize] = position as u32;
    }
    position_of
}

/// Indices of `points` sorted by Morton key, and the keys in that order.
pub fn spatial_order(points: &[Point3], grid: &MortonGrid) -> (Vec<u32>, Vec<u64>) {
    // The key above the index in one integer: sorted, they are in the
    // order of (key, index), and every value is distinct, so any correct
    // sort gives these same bytes.
    let mut keyed: Vec<u128> = points
        .par_iter()
        .with_min_len(PASS_PIECE)
        .enumerate()
        .map(|(i, p)| (u128::from(grid.key(*p)) << 32) | i as u128)
        .collect();
    // A radix sort where it is the faster: 12k points 185 µs against
    // 370 µs for rayon's (in the benchmark, two threads); from about 100k
    // points rayon's parallel sort wins (sort benchmark in docs/bpd.md, "Speed").
    if keyed.len() < RADIX_SORT_BELOW {
        keyed.voracious_sort();
    } else {
        keyed.par_sort_unstable();
    }
    keyed
        .into_par_iter()
        .with_min_len(PASS_PIECE)
        .map(|k| (k as u32, (k >> 32) as u64))
        .unzip()
}

/// `query(scratch, i)` for every point `i` of `points`, evaluated in Morton
/// order on every thread (each with its own `scratch`, made by `init`) and
/// returned in the points' own order. For queries that start from the
/// last one's answer (the face hierarchy's label search): in a cloud
/// shuffled by its writer the last answer is anywhere. The answers do not
/// depend on the order they are computed in. (kiddo's nearest-point
/// queries gain nothing from it: on 2.5M points they took 0.26 s in the
/// cloud's shuffled order and 0.54 s in Morton order, the ordering
/// included.)
pub fn query_in_spatial_order<T, S, Q>(
    points: &[Point3],
    init: impl Fn() -> S + Sync + Send,
    query: Q,
) -> Vec<T>
where
    T: Send + Copy + Default,
    Q: Fn(&mut S, usize) -> T + Sync + Send,
{
    let (order, _) = spatial_order(points, &MortonGrid::of(points));
    let answers: Vec<T> = order
        .par_iter()
        .with_min_len(PASS_PIECE)
        .map_init(&init, |scratch, &i| query(scratch, i as usize))
        .collect();
    let mut in_point_order = vec![T::default(); points.len()];
    for (&i, answer) in order.iter().zip(answers) {
        in_point_order[i as usize] = answer;
    }
    in_point_order
}

/// Point count below which [`spatial_order`] sorts with a (serial) radix
/// sort rather than rayon's parallel sort.
const RADIX_SORT_BELOW: usize = 65536;

/// Splits sorted Morton `keys` into runs of at most `max` consecutive
/// points that each lie in one octree cell: a cell with more points is
/// split into its eight children, and neighbouring children are merged
/// back while they fit. Unlike fixed-length stretches of the curve, which
/// jump between distant cells, every run is compact in space.
pub fn octree_runs(keys: &[u64], max: usize) -> Vec<std::ops::Range<usize>> {
    let mut runs = Vec::with_capacity(2 * keys.len() / max.max(1) + 1);
    split_cell(keys, 0..keys.len(), 63, max, &mut runs);
    runs
}

/// `out` cut into one piece per run, `per_point` items for each of the
/// run's points, in run order (the runs cover the order in sequence, as
/// [`octree_runs`] makes them): so that each run's results are written in
/// place by parallel jobs. With `per_point` 0 every piece is empty.
pub fn split_by_runs<'a, T>(
    runs: &[std::ops::Range<usize>],
    mut out: &'a mut [T],
    per_point: usize,
) -> Vec<&'a mut [T]> {
    runs.iter()
        .map(|run| {
            let (piece, rest) = std::mem::take(&mut out).split_at_mut(run.len() * per_point);
            out = rest;
            piece
        })
        .collect()
}

fn split_cell(
    keys: &[u64],
    cell: std::ops::Range<usize>,
    shift: u32,
    max: usize,
    runs: &mut Vec<std::ops::Range<usize>>,
) {
    // A cell (or merged siblings) that fits is a run.
    if cell.len() <= max || shift == 0 {
        runs.push(cell);
        return;
    }
    let child_shift = shift - 3;
    let child_of = |i: usize| (keys[i] >> child_shift) & 7;
    let mut pending: Option<std::ops::Range<usize>> = None;
    let mut start = cell.start;
    while start < cell.end {
        let child = child_of(start);
        let end =
            start + keys[start..cell.end].partition_point(|&key| (key >> child_shift) & 7 == child);
        match pending.take() {
            Some(p) if p.len() + (end - start) <= max => pending = Some(p.start..end),
            Some(p) => {
                split_cell(keys, p, child_shift, max, runs);
                pending = Some(start..end);
            }
            None => pending = Some(start..end),
        }
        start = end;
    }
    if let Some(p) = pending {
        split_cell(keys, p, child_shift, max, runs);
    }
}

/// Points sorted by Morton key, searched through their keys.
#[derive(Debug, Clone, Copy)]
pub struct MortonCells<'a> {
    grid: MortonGrid,
    keys: &'a [u64],
}

impl<'a> MortonCells<'a> {
    /// `keys` must be sorted, each the key (on `grid`) of the point at its
    /// position.
    pub fn new(grid: MortonGrid, keys: &'a [u64]) -> Self {
        debug_assert!(keys.is_sorted());
        Self { grid, keys }
    }

    /// Calls `visit(position)` for every point of `points` (the sorted
    /// points) within `radius` of `centre`: `dist2 ≤ radius²`, exactly.
    ///
    /// The ball lies in the box of cells from `centre − radius` to
    /// `centre + radius` on each axis (rounding is monotone, so a point
    /// inside never falls outside). At the level where a cell is wider than
    /// half that box, the box meets at most three cells per axis: at most 27
    /// key ranges, each found by binary search. Against the level where a
    /// cell is wider than the whole box (at most 8 ranges, but up to 4× the
    /// box's extent per axis, so many more points measured), the 12k
    /// benchmark took 1.1 % fewer instructions (343.0M → 339.2M), the 100k
    /// one 1.1 %; one level finer still (up to 125 ranges) took 2.5 % more.
    /// Splitting big cells adaptively to skip their parts outside the box
    /// measured fewer points but cost more (+1.2M instructions at 12k).
    pub fn within(
        &self,
        points: &[Point3],
        centre: Point3,
        radius: f64,
        mut visit: impl FnMut(u32),
    ) {
        let low = [0, 1, 2].map(|a| self.grid.cell(centre[a] - radius, a));
        let high = [0, 1, 2].map(|a| self.grid.cell(centre[a] + radius, a));
        let span = (0..3)
            .map(|a| high[a].saturating_sub(low[a]))
            .max()
            .unwrap_or(0);
        // Cells of side 2^shift > span / 2.
        let shift = (u64::BITS - span.leading_zeros())
            .saturating_sub(1)
            .min(BITS);
        let (low, high) = (low.map(|c| c >> shift), high.map(|c| c >> shift));
        let r2 = radius * radius;
        // Morton keys grow with each coordinate, so every cell of the box
        // lies between its lowest and highest corners' keys: the cells are
        // searched for in that stretch of the keys alone.
        let level = 3 * shift;
        let from = self.keys.partition_point(|&k| k >> level < interleave(low));
        let to = from + self.keys[from..].partition_point(|&k| k >> level <= interleave(high));
        let stretch = &self.keys[from..to];
        for z in low[2]..=high[2] {
            for y in low[1]..=high[1] {
                for x in low[0]..=high[0] {
                    let cell = cell_range_in(stretch, interleave([x, y, z]), shift);
                    let first = from + cell.start;
                    for (position, &p) in (first..).zip(&points[first..from + cell.end]) {
                        if dist2(p, centre) <= r2 {
                            visit(position as u32);
                        }
                    }
                }
            }
        }
    }

    /// Positions of the points in the cell with Morton key `cell` at the
    /// level of cells of side 2^shift.
    fn cell_range(&self, cell: u64, shift: u32) -> std::ops::Range<usize> {
        cell_range_in(self.keys, cell, shift)
    }

    /// A radius around the point at `position` that holds at least `k`
    /// points (or all of them): the diagonal of the smallest cell around it
    /// with `k` points, widened for rounding.
    pub fn radius_holding(&self, position: usize, k: usize) -> f64 {
        let key = self.keys[position];
        let shift = (0..=BITS)
            .find(|&s| self.cell_range(key >> (3 * s), s).len() >= k)
            .unwrap_or(BITS);
        let side = (1u64 << shift) as f64 / self.grid.scale;
        // A cell's points differ by less than its side on each axis, up to
        // the rounding of (x − lo)·scale.
        side * 3f64.sqrt() * (1.0 + 1e-6) + 1e-12 * (side + magnitude(self.grid.lo))
    }
}

/// Positions in `keys` (sorted) of the points in the cell with Morton key
/// `cell` at the level of cells of side 2^shift.
fn cell_range_in(keys: &[u64], cell: u64, shift: u32) -> std::ops::Range<usize> {
    let level = 3 * shift;
    // At the top level (shift = BITS) the only cell is the whole grid;
    // keys have 3·BITS = 63 bits, so the shifts stay below 64.
    let start = keys.partition_point(|&k| k >> level < cell);
    let len = keys[start..].partition_point(|&k| k >> level == cell);
    start..start + len
}

fn magnitude(p: Point3) -> f64 {
    p.iter().fold(0.0, |m, c| m.max(c.abs()))
}

/// The Morton key of cell coordinates (each below 2²¹).
fn interleave(cell: [u64; 3]) -> u64 {
    spread_bits(cell[0]) | spread_bits(cell[1]) << 1 | spread_bits(cell[2]) << 2
}

/// Spreads the low 21 bits of `x` so they occupy every third bit.
fn spread_bits(x: u64) -> u64 {
    let mut x = x & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

fn min3(a: Point3, b: Point3) -> Point3 {
    [0, 1, 2].map(|i| a[i].min(b[i]))
}

fn max3(a: Point3, b: Point3) -> Point3 {
    [0, 1, 2].map(|i| a[i].max(b[i]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    fn sorted(points: &[Point3]) -> (Vec<Point3>, Vec<u64>, MortonGrid) {
        let grid = MortonGrid::of(points);
        let (order, keys) = spatial_order(points, &grid);
        (
            order.iter().map(|&i| points[i as usize]).collect(),
            keys,
            grid,
        )
    }

    /// Balls of every size, from inside one cell to the whole cloud and
    /// beyond it, on a sheet whose density varies a hundredfold.
    #[test]
    fn within_finds_exactly_the_points_in_the_ball() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        let raw: Vec<Point3> = (0..3000)
            .map(|i| {
                let s = if i % 2 == 0 { 1.0 } else { 0.01 };
                [
                    rng.random::<f64>() * s,
                    rng.random::<f64>() * s,
                    rng.random::<f64>() * 0.01,
                ]
            })
            .collect();
        let (points, keys, grid) = sorted(&raw);
        let cells = MortonCells::new(grid, &keys);
        for case in 0..300 {
            let centre = points[rng.random_range(0..points.len())];
            let radius = 10f64.powf(rng.random_range(-4.0..0.5));
            let centre = if case % 5 == 0 {
                [centre[0] + 2.0, centre[1] - 1.0, centre[2]] // outside the grid
            } else {
                centre
            };
            let mut got = Vec::new();
            cells.within(&points, centre, radius, |p| got.push(p));
            got.sort_unstable();
            let want: Vec<u32> = (0..points.len() as u32)
                .filter(|&p| dist2(points[p as usize], centre) <= radius * radius)
                .collect();
            assert_eq!(got, want, "centre {centre:?}, radius {radius}");
        }
    }

    /// Runs cover the Morton order in sequence, hold at most `max` points,
    /// and each is made of whole octree cells that are siblings: at some
    /// level, the run's cells share one parent and no cell of that level is
    /// cut by the run's ends (fixed-length stretches of the curve fail this).
    #[test]
    fn octree_runs_are_whole_sibling_cells() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(6);
        let points: Vec<Point3> = (0..2500)
            .map(|_| [rng.random(), rng.random(), rng.random::<f64>() * 0.05])
            .collect();
        let (_, keys) = spatial_order(&points, &MortonGrid::of(&points));
        let whole_siblings = |run: &std::ops::Range<usize>, level: u32| {
            let cell = |i: usize| keys[i] >> level;
            let parent = |i: usize| keys[i] >> (level + 3);
            parent(run.start) == parent(run.end - 1)
                && (run.start == 0 || cell(run.start - 1) != cell(run.start))
                && (run.end == keys.len() || cell(run.end) != cell(run.end - 1))
        };
        for max in [1, 5, 16, 40] {
            let runs = octree_runs(&keys, max);
            let mut next = 0;
            for run in &runs {
                assert_eq!(run.start, next);
                assert!(!run.is_empty() && run.len() <= max, "{run:?}");
                assert!(
                    (0..61).step_by(3).any(|level| whole_siblings(run, level)),
                    "max {max}: {run:?} cuts a cell"
                );
                next = run.end;
            }
            assert_eq!(next, keys.len());
        }
        let mut fixed = (0..keys.len() / 16).map(|i| i * 16..i * 16 + 16);
        assert!(fixed.any(|run| !(0..61).step_by(3).any(|level| whole_siblings(&run, level))));
    }

    /// Both sorts (the radix sort below [`RADIX_SORT_BELOW`] points,
    /// rayon's above) give the plain sort's order of (key, index), with
    /// repeated keys (copies of points, which come in at random places).
    #[test]
    fn spatial_order_is_the_order_of_key_then_index() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for n in [1, 40, 5000, RADIX_SORT_BELOW + 3000] {
            let mut points: Vec<Point3> = (0..n)
                .map(|_| [rng.random(), rng.random::<f64>() * 1e-3, rng.random()])
                .collect();
            for _ in 0..n / 10 {
                let copy = points[rng.random_range(0..n)];
                let at = rng.random_range(0..n);
                points[at] = copy;
            }
            let grid = MortonGrid::of(&points);
            let mut want: Vec<(u64, u32)> =
                (0..n).map(|i| (grid.key(points[i]), i as u32)).collect();
            want.sort_unstable();
            let (order, keys) = spatial_order(&points, &grid);
            let got: Vec<(u64, u32)> = keys.into_iter().zip(order).collect();
            assert_eq!(got, want, "{n} points");
        }
    }

    /// Each point gets its own query's answer, in its own place, whatever
    /// the order of evaluation (a scratch that grows with every query
    /// changes nothing).
    #[test]
    fn queries_in_spatial_order_answer_in_point_order() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(8);
        for n in [0, 1, 7, 20_000] {
            let points: Vec<Point3> = (0..n).map(|_| [rng.random(), rng.random(), 0.0]).collect();
            let answers = query_in_spatial_order(&points, Vec::new, |seen: &mut Vec<usize>, i| {
                seen.push(i);
                (i, points[i][0].to_bits())
            });
            let expected: Vec<(usize, u64)> = points
                .iter()
                .enumerate()
                .map(|(i, p)| (i, p[0].to_bits()))
                .collect();
            assert_eq!(answers, expected, "{n} points");
        }
    }

    #[test]
    fn radius_holding_holds_k_points() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let raw: Vec<Point3> = (0..2000)
            .map(|_| [rng.random::<f64>() * 1e-3 + 1e5, rng.random(), 0.5])
            .collect();
        let (points, keys, grid) = sorted(&raw);
        let cells = MortonCells::new(grid, &keys);
        for position in (0..points.len()).step_by(37) {
            for k in [1, 30, 500, 2000] {
                let r = cells.radius_holding(position, k);
                let mut count = 0;
                cells.within(&points, points[position], r, |_| count += 1);
                assert!(count >= k, "position {position}, k {k}: {count}");
            }
        }
    }
}
