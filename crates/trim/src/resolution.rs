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

/// Nearest-neighbour distance of every member, within the neighbourhood.
///
/// `out[j]` is the distance from `pts[j]` to the closest other member. The
/// points are copied into coordinate columns, padded to whole tiles of
/// `LANES`, and the pairs are measured tile by tile over the upper
/// triangle of tiles only: each distance updates both its row's minimum and
/// its column's, in independent lanes that the compiler turns into vector
/// instructions. Half the pairs of a full row-by-row pass and no branch;
/// minima do not depend on the order and a − b = −(b − a) exactly, so the
/// results equal [`nearest_distances_reference`]'s.
// Baseline and AVX2 variants, chosen at run time (crate doc, "Vector kernels").
#[multiversion::multiversion(targets("x86_64+avx2"))]
pub fn nearest_distances(pts: &[Point2], out: &mut Vec<f64>, columns: &mut Columns) {
    let n = pts.len();
    let padded = n.div_ceil(LANES) * LANES;
    // Padding is infinitely far: it never wins a real member's minimum
    // (padding against padding gives NaN, which loses every comparison).
    columns.x.clear();
    columns.y.clear();
    columns.x.extend(pts.iter().map(|p| p[0]));
    columns.y.extend(pts.iter().map(|p| p[1]));
    columns.x.resize(padded, f64::INFINITY);
    columns.y.resize(padded, f64::INFINITY);
    columns.column_best.clear();
    columns.column_best.resize(padded, f64::INFINITY);
    out.clear();
    let (x_tiles, _) = columns.x.as_chunks::<LANES>();
    let (y_tiles, _) = columns.y.as_chunks::<LANES>();
    let (best_tiles, _) = columns.column_best.as_chunks_mut::<LANES>();
    for (t, (rx, ry)) in x_tiles.iter().zip(y_tiles).enumerate() {
        let mut row_best = [[f64::INFINITY; LANES]; LANES];
        diagonal_tile(rx, ry, &mut row_best);
        let columns_after = x_tiles[t + 1..].iter().zip(&y_tiles[t + 1..]);
        for ((cx, cy), column_best) in columns_after.zip(&mut best_tiles[t + 1..]) {
            off_diagonal_tile((rx, ry), (cx, cy), &mut row_best, column_best);
        }
        let real_rows = n.saturating_sub(t * LANES);
        for (lanes, &column) in row_best.iter().zip(&best_tiles[t]).take(real_rows) {
            let best = lanes.iter().fold(column, |m, &d| if d < m { d } else { m });
            out.push(best.sqrt());
        }
    }
}

type Tile = [f64; LANES];

/// Pairs within one tile of rows, each member against the others (its own
/// lane is skipped).
fn diagonal_tile(xs: &Tile, ys: &Tile, row_best: &mut [Tile; LANES]) {
    for (r, best) in row_best.iter_mut().enumerate() {
        let (px, py) = (xs[r], ys[r]);
        for (lane, b) in best.iter_mut().enumerate() {
            if lane != r {
                let (dx, dy) = (xs[lane] - px, ys[lane] - py);
                let d = dx * dx + dy * dy;
                *b = if d < *b { d } else { *b };
            }
        }
    }
}

/// Pairs between a tile of rows and a tile of columns: row minima in
/// `row_best` (per lane), column minima in `column_best`.
fn off_diagonal_tile(
    (xs, ys): (&Tile, &Tile),
    (cx, cy): (&Tile, &Tile),
    row_best: &mut [Tile; LANES],
    column_best: &mut Tile,
) {
    for (best, (&px, &py)) in row_best.iter_mut().zip(xs.iter().zip(ys)) {
        for lane in 0..LANES {
            let (dx, dy) = (cx[lane] - px, cy[lane] - py);
            let d = dx * dx + dy * dy;
            // `if` rather than `f64::min`, whose NaN handling blocks the
            // plain min instruction.
            best[lane] = if d < best[lane] { d } else { best[lane] };
            column_best[lane] = if d < column_best[lane] {
                d
            } else {
                column_best[lane]
            };
        }
    }
}

/// Lanes of [`nearest_distances`]' inner loop: one AVX2 register of f64.
/// 4 against 2: −2.5 % of the 12k benchmark's instructions; 8 spills
/// registers (+9 %).
const LANES: usize = 4;

/// Reusable coordinate columns for [`nearest_distances`].
#[derive(Debug, Default, Clone)]
pub struct Columns {
    x: Vec<f64>,
    y: Vec<f64>,
    /// Squared minimum of each column over the tiles above the diagonal.
    column_best: Vec<f64>,
}

/// The β of some of a cloud's points, renumbered: point `i` is point
/// `of[i]` of `all` (the vertices a mesh keeps once its seams are
/// stitched, among all it stored).
pub(crate) struct Picked<'a> {
    pub(crate) all: &'a dyn PointResolution,
    pub(crate) of: &'a [u32],
}

impl PointResolution for Picked<'_> {
    fn len(&self) -> usize {
        self.of.len()
    }
    fn beta(&self, i: usize) -> f64 {
        self.all.beta(self.of[i] as usize)
    }
    /// The whole cloud's: the scale of its spacing.
    fn median(&self) -> f64 {
        self.all.median()
    }
}

#[cfg(test)]
/// [`nearest_distances`] measuring each pair once, the plain way; the
/// reference for tests.
pub fn nearest_distances_reference(pts: &[Point2], out: &mut Vec<f64>) {
    out.clear();
    out.resize(pts.len(), f64::INFINITY);
    for j in 0..pts.len() {
        let p = pts[j];
        let (head, tail) = out.split_at_mut(j + 1);
        let mut best = head[j];
        for (d_m, &q) in tail.iter_mut().zip(&pts[j + 1..]) {
            let d = dist2(p, q);
            best = best.min(d);
            *d_m = d_m.min(d);
        }
        head[j] = best;
    }
    for d in out.iter_mut() {
        *d = d.sqrt();
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

/// β of each point of a cloud, however it was found: a slice with every
/// point's ([`crate::local_resolution`]), or a [`crate::LocalResolution`]
/// that finds each where it is first asked for.
pub trait PointResolution: Sync {
    /// How many points it has β for.
    fn len(&self) -> usize;
    /// Whether it has β for no point.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// β of point `i` (`i < len()`).
    fn beta(&self, i: usize) -> f64;
    /// The median β, the scale of the cloud's spacing.
    fn median(&self) -> f64;
}

impl PointResolution for [f64] {
    fn len(&self) -> usize {
        <[f64]>::len(self)
    }
    fn beta(&self, i: usize) -> f64 {
        self[i]
    }
    fn median(&self) -> f64 {
        crate::geom::median(self)
    }
}

impl PointResolution for Vec<f64> {
    fn len(&self) -> usize {
        self.as_slice().len()
    }
    fn beta(&self, i: usize) -> f64 {
        self.as_slice().beta(i)
    }
    fn median(&self) -> f64 {
        self.as_slice().median()
    }
}

impl<const N: usize> PointResolution for [f64; N] {
    fn len(&self) -> usize {
        N
    }
    fn beta(&self, i: usize) -> f64 {
        self.as_slice().beta(i)
    }
    fn median(&self) -> f64 {
        self.as_slice().median()
    }
}

/// A reference to any [`PointResolution`] (a slice included) as a sized
/// one, which a `&dyn PointResolution` can point to.
pub(crate) struct ByRef<'a, R: PointResolution + ?Sized>(pub(crate) &'a R);

impl<R: PointResolution + ?Sized> PointResolution for ByRef<'_, R> {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn beta(&self, i: usize) -> f64 {
        self.0.beta(i)
    }
    fn median(&self) -> f64 {
        self.0.median()
    }
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
        nearest_distances(&pts, &mut d, &mut Columns::default());
        assert!(d.iter().all(|&x| (x - 2.0).abs() < 1e-12));
        assert!((beta_of(&d) - 2.0).abs() < 1e-12);
    }

    #[test]
    fn columns_match_the_reference_on_random_neighbourhoods() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2);
        let (mut fast, mut plain, mut columns) = (Vec::new(), Vec::new(), Columns::default());
        for n in (2..64).chain([30; 200]) {
            let mut pts: Vec<Point2> = (0..n)
                .map(|_| [rng.random_range(-3.0..3.0), rng.random_range(-1.0..1.0)])
                .collect();
            // Members that project onto one another measure 0.
            if n % 3 == 0 {
                pts[n - 1] = pts[0];
            }
            nearest_distances(&pts, &mut fast, &mut columns);
            nearest_distances_reference(&pts, &mut plain);
            assert_eq!(fast, plain, "{pts:?}");
        }
    }

    #[test]
    fn beta_adds_two_standard_deviations() {
        assert!((beta_of(&[1.0, 3.0]) - (2.0 + 2.0)).abs() < 1e-12);
    }
}
