//! Row sweeps over a small projected neighbourhood, laid out so the compiler
//! vectorises them: the fast versions of the O(k²) nearest-member searches
//! behind β ([`crate::resolution`]) and the sampling tensor
//! ([`crate::anisotropy`]). Each has a plain reference in its own module and
//! a test that the two agree exactly.

use crate::frame::Point2;

/// Reusable buffers: coordinates as two arrays and one row of squared
/// distances.
#[derive(Default)]
pub struct RowScratch {
    xs: Vec<f64>,
    ys: Vec<f64>,
    row: Vec<f64>,
    matrix: Vec<f64>,
}

impl RowScratch {
    /// Loads `pts` into the coordinate arrays.
    pub fn load(&mut self, pts: &[Point2]) {
        self.xs.clear();
        self.ys.clear();
        self.xs.extend(pts.iter().map(|p| p[0]));
        self.ys.extend(pts.iter().map(|p| p[1]));
        self.row.resize(pts.len(), 0.0);
    }

    /// Number of loaded points.
    pub fn len(&self) -> usize {
        self.xs.len()
    }

    /// True when no point is loaded.
    pub fn is_empty(&self) -> bool {
        self.xs.is_empty()
    }

    /// Vector from point `j` to point `m`.
    pub fn vector(&self, j: usize, m: usize) -> Point2 {
        [self.xs[m] - self.xs[j], self.ys[m] - self.ys[j]]
    }

    /// Fills the row with squared distances from point `j`; the entry of `j`
    /// itself is +∞.
    pub fn fill_row(&mut self, j: usize) {
        let (px, py) = (self.xs[j], self.ys[j]);
        for ((d, &x), &y) in self.row.iter_mut().zip(&self.xs).zip(&self.ys) {
            let (ex, ey) = (x - px, y - py);
            *d = ex * ex + ey * ey;
        }
        self.row[j] = f64::INFINITY;
    }

    /// Fills the n×n matrix of squared distances between the loaded points,
    /// each pair computed once; the diagonal and coincident pairs (which
    /// carry no direction) are +∞.
    pub fn fill_direction_matrix(&mut self) {
        let n = self.len();
        self.matrix.clear();
        self.matrix.resize(n * n, f64::INFINITY);
        for j in 0..n {
            let (px, py) = (self.xs[j], self.ys[j]);
            for m in j + 1..n {
                let (ex, ey) = (self.xs[m] - px, self.ys[m] - py);
                let d = ex * ex + ey * ey;
                let d = if d == 0.0 { f64::INFINITY } else { d };
                self.matrix[j * n + m] = d;
                self.matrix[m * n + j] = d;
            }
        }
    }

    /// First index of the smallest finite entry of matrix row `j`.
    pub fn nearest_direction(&self, j: usize) -> Option<usize> {
        let n = self.len();
        first_min(&self.matrix[j * n..(j + 1) * n], |_, d| d)
    }

    /// Like [`Self::nearest_direction`], keeping only members m whose vector
    /// e from point `j` lies at least the given angle from the line of `e1`:
    /// (e·e1)² ≤ cos2 |e1|² |e|².
    pub fn nearest_direction_away(&self, j: usize, e1: Point2, cos2: f64) -> Option<usize> {
        let n = self.len();
        let (px, py) = (self.xs[j], self.ys[j]);
        let limit = cos2 * (e1[0] * e1[0] + e1[1] * e1[1]);
        first_min(&self.matrix[j * n..(j + 1) * n], |m, d| {
            let dot = (self.xs[m] - px) * e1[0] + (self.ys[m] - py) * e1[1];
            if dot * dot > limit * d {
                f64::INFINITY
            } else {
                d
            }
        })
    }

    /// Smallest entry of the row and its first index, unless all are +∞.
    pub fn row_min(&self) -> Option<(f64, usize)> {
        // New minima are rare after the first few entries, so this branch
        // predicts well.
        let mut best = (f64::INFINITY, usize::MAX);
        for (m, &d) in self.row.iter().enumerate() {
            if d < best.0 {
                best = (d, m);
            }
        }
        (best.1 != usize::MAX).then_some(best)
    }
}

/// First index whose `cost(index, value)` is smallest, unless all are +∞.
fn first_min(values: &[f64], cost: impl Fn(usize, f64) -> f64) -> Option<usize> {
    // New minima are rare after the first few entries: the branch predicts
    // well.
    let mut best = (f64::INFINITY, usize::MAX);
    for (m, &d) in values.iter().enumerate() {
        if d < best.0 {
            let c = cost(m, d);
            if c < best.0 {
                best = (c, m);
            }
        }
    }
    (best.1 != usize::MAX).then_some(best.1)
}
