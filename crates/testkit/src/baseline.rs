//! The two classic edge smoothers the paper compares its FFT filter with
//! (section 3.2 and Table 2): a least-squares polynomial and a cubic
//! smoothing spline. They are baselines for comparison only; the pipeline
//! smooths edges with the spatial low-pass filter (section 3.3).
//!
//! Both treat an edge as three functions x(t), y(t), z(t) of one parameter,
//! the *cumulative chord length* of the input polyline (the paper plots
//! the Cartesian components against the curvilinear distance), and return
//! one fitted point per input point, at that point's parameter.
//!
//! # Polynomial ([`polynomial_edge`])
//!
//! The paper's "3rd order polynomial fitting": each component is a
//! least-squares polynomial of the given degree in the normalised chord
//! length t ∈ [0, 1], *constrained to pass through both end points*, so
//! that consecutive edges of a loop still share their corners (as the FFT
//! edges do). The fit is the straight line through the ends plus a least-
//! squares combination of t(1−t)·T_k(2t−1), k = 0 … degree−2 (T_k the
//! Chebyshev polynomials, for conditioning): exactly the polynomials of the
//! degree that vanish at t = 0 and t = 1. The coefficients come from a thin
//! SVD of the n × (degree−1) design matrix (O(n·degree²)). The only
//! parameter is the degree; the paper uses 3. Degrees 0 and 1 give the
//! chord between the ends; a degree above n − 1 is lowered to n − 1 (which
//! interpolates). A closed loop has no ends: pass it with its first point
//! repeated at the end, and it is pinned there.
//!
//! A curve that is a cubic of its own parameter is reproduced exactly by
//! [`polynomial_fit_at`] given that parameter. With the chord-length
//! parameter it is reproduced only up to the difference between that
//! parameter and its own: a polynomial curve has constant speed only if it
//! is a line, so no cubic but a line is a cubic of its arc length.
//!
//! # Smoothing spline ([`smoothing_spline_edge`])
//!
//! The penalised least-squares cubic spline with knots at every point
//! (Reinsch 1967; Green and Silverman 1994, ch. 2): for each component it
//! minimises Σ_i w_i (y_i − s(t_i))² + λ ∫ s''(t)² dt. It is computed in
//! the Reinsch form: with Q the second-difference matrix and R the
//! tridiagonal Gram matrix of the spline's knot second derivatives γ,
//! (R + λ Qᵀ W⁻¹ Q) γ = Qᵀ y and s = y − λ W⁻¹ Q γ. The system is
//! pentadiagonal for an open edge and cyclic pentadiagonal for a closed
//! loop (a *periodic* spline, whose last point joins the first); both are
//! factorised by an envelope (skyline) Cholesky in O(n): the cyclic corner
//! only fills the last two rows.
//!
//! - **Ends**: an open edge keeps its end points exactly (infinite weight:
//!   W⁻¹ = 0 at the two ends, 1 elsewhere); a closed loop moves every point.
//! - **λ**: one λ for the three components (the result does not depend on
//!   the orientation of the axes), chosen by Reinsch's classic smoothing
//!   target: the residual sum of squares Σ_i |p_i − s(t_i)|² equals m·σ̂²,
//!   m the number of free points (n − 2 open, n closed) and σ̂² the noise
//!   variance (summed over the components) estimated from the data. σ̂² is
//!   the mean of |r_i|² / (1 + Σ_k ℓ_k²), where r_i is the difference
//!   between p_i and the cubic Lagrange interpolation ℓ of its two
//!   neighbours on each side (exact for a cubic, so curvature barely biases
//!   it; the linear interpolation of one neighbour each side on 4-point
//!   inputs). RSS increases with λ, so λ is found by bisection on log λ
//!   between 10⁻⁶·h̄³ and min(n⁴, 10¹²)·h̄³ (t normalised to [0, 1], h̄ the
//!   mean parameter step); if even the largest λ leaves RSS below the
//!   target, the largest is used. Setting RSS = m·σ² (instead of its
//!   expectation, σ²·(m − trace of the hat matrix)) errs towards
//!   smoothing a little more than generalised cross-validation would.
//!   [`smoothing_spline_fit`] reports λ and σ̂.
//!
//! Consecutive points closer than 10⁻³ of the mean step are kept apart in
//! the parameter by that much, so duplicates do not make the system
//! singular.
//!
//! Neither function panics: fewer than [`MIN_POINTS`] points, non-finite
//! coordinates, a zero-length edge or a failed factorisation return the
//! input unchanged.

use nalgebra::DMatrix;

use crate::vec3::dist2;
use trim::Point3;

/// Inputs with fewer points are returned unchanged.
pub const MIN_POINTS: usize = 4;

/// Least-squares polynomial of `degree` per Cartesian component against
/// the normalised chord length, through both end points (see the module
/// doc). One fitted point per input point.
pub fn polynomial_edge(points: &[Point3], degree: usize) -> Vec<Point3> {
    if points.len() < MIN_POINTS || !all_finite(points) {
        return points.to_vec();
    }
    match chord_parameter(points, false) {
        Some((t, _)) => polynomial_fit_at(points, &t, degree),
        None => points.to_vec(),
    }
}

/// [`polynomial_edge`] with a given parameter `t` of each point (any
/// strictly monotone values; they are rescaled so that the ends are 0 and
/// 1). A curve whose components are polynomials of degree ≤ `degree` in
/// `t` is reproduced exactly (up to rounding). Returns the input when `t`
/// does not match it, is not finite, or has equal ends.
pub fn polynomial_fit_at(points: &[Point3], t: &[f64], degree: usize) -> Vec<Point3> {
    let n = points.len();
    if n < MIN_POINTS || t.len() != n || !all_finite(points) || t.iter().any(|v| !v.is_finite()) {
        return points.to_vec();
    }
    let (t0, t1) = (t[0], t[n - 1]);
    if t1 == t0 {
        return points.to_vec();
    }
    let s: Vec<f64> = t.iter().map(|&v| (v - t0) / (t1 - t0)).collect();
    let (a, b) = (points[0], points[n - 1]);
    let line = |s: f64| -> Point3 { std::array::from_fn(|c| a[c] + s * (b[c] - a[c])) };
    let degree = degree.min(n - 1);
    if degree <= 1 {
        return s.iter().map(|&s| line(s)).collect();
    }
    let m = degree - 1;
    let design = DMatrix::from_fn(n, m, |i, k| {
        let si = s[i];
        si * (1.0 - si) * chebyshev(k, 2.0 * si - 1.0)
    });
    let rhs = DMatrix::from_fn(n, 3, |i, c| points[i][c] - line(s[i])[c]);
    let Some(svd) = design.clone().try_svd(true, true, f64::EPSILON, 0) else {
        return points.to_vec();
    };
    let tol = svd.singular_values.max() * 1e-12 * n as f64;
    let Ok(coef) = svd.solve(&rhs, tol) else {
        return points.to_vec();
    };
    let fit = &design * coef;
    let out: Vec<Point3> = (0..n)
        .map(|i| {
            let l = line(s[i]);
            std::array::from_fn(|c| l[c] + fit[(i, c)])
        })
        .collect();
    if all_finite(&out) {
        out
    } else {
        points.to_vec()
    }
}

/// A smoothing-spline fit and the parameters it chose.
#[derive(Debug, Clone, PartialEq)]
pub struct SplineFit {
    /// One fitted point per input point.
    pub points: Vec<Point3>,
    /// The smoothing parameter λ, for the chord length normalised to
    /// [0, 1] (0 when the input was returned unchanged).
    pub lambda: f64,
    /// The estimated noise σ̂ (3D: the root of the variance summed over the
    /// components).
    pub sigma: f64,
    /// Residual sum of squares Σ |p_i − s(t_i)|².
    pub rss: f64,
}

/// Cubic smoothing spline per component against chord length, λ from the
/// smoothing target RSS = m·σ̂² (see the module doc). Open edges keep their
/// ends exactly; `closed` gives a periodic spline through the closing
/// segment from the last point to the first. One fitted point per input
/// point.
pub fn smoothing_spline_edge(points: &[Point3], closed: bool) -> Vec<Point3> {
    smoothing_spline_fit(points, closed).points
}

/// [`smoothing_spline_edge`] with the chosen λ, σ̂ and residual.
pub fn smoothing_spline_fit(points: &[Point3], closed: bool) -> SplineFit {
    if points.len() < MIN_POINTS || !all_finite(points) {
        return SplineFit::unchanged(points, 0.0);
    }
    let Some(system) = SplineSystem::new(points, closed) else {
        return SplineFit::unchanged(points, 0.0);
    };
    let sigma2 = system.noise_variance();
    let target = smoothing_target(points.len(), closed, sigma2);
    if !target.is_finite() || target <= 0.0 {
        return SplineFit::unchanged(points, sigma2.max(0.0).sqrt());
    }
    match system.fit_to_target(target) {
        Some((lambda, fit, rss)) if all_finite(&fit) => SplineFit {
            points: fit,
            lambda,
            sigma: sigma2.sqrt(),
            rss,
        },
        _ => SplineFit::unchanged(points, sigma2.sqrt()),
    }
}

impl SplineFit {
    /// The input as it stands (λ = 0, no residual), with the noise
    /// estimate `sigma` when there is one.
    fn unchanged(points: &[Point3], sigma: f64) -> SplineFit {
        SplineFit {
            points: points.to_vec(),
            lambda: 0.0,
            sigma,
            rss: 0.0,
        }
    }
}

/// Reinsch's smoothing target m·σ̂² for the residual sum of squares, m the
/// number of free points: n − 2 open (the ends are kept), n closed.
fn smoothing_target(n: usize, closed: bool, sigma2: f64) -> f64 {
    let free = if closed { n } else { n - 2 };
    free as f64 * sigma2
}

/// A fit at one λ: (λ, the fitted points, their residual sum of squares).
type LambdaFit = (f64, Vec<Point3>, f64);

/// Cumulative chord length of `points` (starting at 0) and the total
/// length, including the closing segment when `closed`. None when the
/// total is zero or not finite.
fn chord_parameter(points: &[Point3], closed: bool) -> Option<(Vec<f64>, f64)> {
    let mut t = Vec::with_capacity(points.len());
    let mut acc = 0.0;
    t.push(0.0);
    for w in points.windows(2) {
        acc += dist2(w[0], w[1]).sqrt();
        t.push(acc);
    }
    if closed {
        if let (Some(&first), Some(&last)) = (points.first(), points.last()) {
            acc += dist2(last, first).sqrt();
        }
    }
    (acc > 0.0 && acc.is_finite()).then_some((t, acc))
}

fn all_finite(points: &[Point3]) -> bool {
    points.iter().flatten().all(|v| v.is_finite())
}

/// Chebyshev polynomial T_k(x).
fn chebyshev(k: usize, x: f64) -> f64 {
    let (mut a, mut b) = (1.0, x);
    if k == 0 {
        return a;
    }
    for _ in 1..k {
        (a, b) = (b, 2.0 * x * b - a);
    }
    b
}

/// Lower triangle of a symmetric matrix in envelope (skyline) storage:
/// row i holds columns first[i] ..= i.
#[derive(Debug, Clone)]
struct Skyline {
    first: Vec<usize>,
    start: Vec<usize>,
    data: Vec<f64>,
}

impl Skyline {
    fn with_first(first: Vec<usize>) -> Self {
        let mut start = Vec::with_capacity(first.len());
        let mut len = 0;
        for (i, &f) in first.iter().enumerate() {
            start.push(len);
            len += i + 1 - f;
        }
        Self {
            first,
            start,
            data: vec![0.0; len],
        }
    }

    fn row(&self, i: usize) -> &[f64] {
        let len = i + 1 - self.first[i];
        &self.data[self.start[i]..self.start[i] + len]
    }

    /// Adds `v` at (i, j), i ≥ j, inside the envelope.
    fn add(&mut self, i: usize, j: usize, v: f64) {
        let k = self.start[i] + j - self.first[i];
        self.data[k] += v;
    }

    /// In-place Cholesky factorisation (A = L Lᵀ, L in the envelope).
    /// False if the matrix is not numerically positive definite.
    fn factorise(&mut self) -> bool {
        let n = self.first.len();
        for i in 0..n {
            let fi = self.first[i];
            for j in fi..=i {
                let fj = self.first[j];
                let lo = fi.max(fj);
                let mut s = self.data[self.start[i] + j - fi];
                for k in lo..j {
                    s -= self.data[self.start[i] + k - fi] * self.data[self.start[j] + k - fj];
                }
                if j < i {
                    let d = self.data[self.start[j] + j - fj];
                    self.data[self.start[i] + j - fi] = s / d;
                } else {
                    if !s.is_finite() || s <= 0.0 {
                        return false;
                    }
                    self.data[self.start[i] + i - fi] = s.sqrt();
                }
            }
        }
        true
    }

    /// Solves L Lᵀ x = b in place (after [`Self::factorise`]).
    fn solve(&self, b: &mut [[f64; 3]]) {
        let n = self.first.len();
        for i in 0..n {
            let row = self.row(i);
            let fi = self.first[i];
            let mut s = b[i];
            for (k, &l) in (fi..i).zip(row) {
                for c in 0..3 {
                    s[c] -= l * b[k][c];
                }
            }
            let d = row[i - fi];
            b[i] = s.map(|v| v / d);
        }
        for i in (0..n).rev() {
            let row = self.row(i);
            let fi = self.first[i];
            let d = row[i - fi];
            b[i] = b[i].map(|v| v / d);
            let xi = b[i];
            for (k, &l) in (fi..i).zip(row) {
                for c in 0..3 {
                    b[k][c] -= l * xi[c];
                }
            }
        }
    }
}

/// The Reinsch system of one edge, independent of λ.
struct SplineSystem {
    closed: bool,
    y: Vec<Point3>,
    /// Parameter (normalised chord length, with duplicates kept apart).
    tau: Vec<f64>,
    /// Steps: h[i] = τ[i+1] − τ[i]; closed: h[n−1] closes the loop.
    h: Vec<f64>,
    /// Inverse weights: 0 at the pinned ends, 1 elsewhere.
    dinv: Vec<f64>,
    /// Nonzeros of each row of Q: (column, value).
    q_rows: SparseRows,
    /// Qᵀ y, one row per column of Q.
    qty: Vec<[f64; 3]>,
    /// R and Qᵀ W⁻¹ Q in the same envelope.
    r: Skyline,
    qdq: Skyline,
}

impl SplineSystem {
    /// The system of `points` (at least [`MIN_POINTS`], finite); None when
    /// the edge has no finite, nonzero length.
    fn new(points: &[Point3], closed: bool) -> Option<Self> {
        let n = points.len();
        let (t, total) = chord_parameter(points, closed)?;
        let h = parameter_steps(&t, total, closed);
        let tau = knots(&h, n);
        let dinv = inverse_weights(n, closed);
        let cols = q_columns(n, closed);
        let (q_rows, r_entries) = second_differences(&h, n, closed);
        let qdq_entries = weighted_gram(&q_rows, &dinv);
        let (r, qdq) = shared_envelope(cols, &r_entries, &qdq_entries);
        let qty = q_transpose_times(&q_rows, points, cols);
        Some(Self {
            closed,
            y: points.to_vec(),
            tau,
            h,
            dinv,
            q_rows,
            qty,
            r,
            qdq,
        })
    }

    /// The fit whose residual sum of squares meets `target` (see the
    /// module doc): λ = μ·h̄³ with μ between 10⁻⁶ and min(n⁴, 10¹²), the
    /// largest if even it stays below the target, otherwise found by
    /// bisection on log μ. None when no fit at or near the target was
    /// found.
    fn fit_to_target(&self, target: f64) -> Option<LambdaFit> {
        let hbar = 1.0 / self.h.len() as f64;
        let scale = hbar.powi(3);
        let mu_max = (self.y.len() as f64).powi(4).min(1e12);
        let lo = (1e-6f64).ln();
        let hi = mu_max.ln();
        self.fit_at_largest(scale, hi, target)
            .or_else(|| self.bisect(scale, lo, hi, target))
    }

    /// The largest λ first (`scale`·e^`hi`): if it stays below the
    /// target, it is the answer.
    fn fit_at_largest(&self, scale: f64, hi: f64, target: f64) -> Option<LambdaFit> {
        let (fit, rss) = self.solve(scale * hi.exp())?;
        (rss <= target).then(|| (scale * hi.exp(), fit, rss))
    }

    /// Bisection on log μ between `lo` and `hi` (λ = `scale`·e^log μ):
    /// RSS increases with λ. Stops when RSS is within 10⁻⁴ of the target
    /// (relative) or the interval is narrower than 10⁻⁶; λ that fail to
    /// give a fit count as too large.
    fn bisect(&self, scale: f64, mut lo: f64, mut hi: f64, target: f64) -> Option<LambdaFit> {
        let mut best = None;
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            let lambda = scale * mid.exp();
            match self.solve(lambda) {
                Some((fit, rss)) => {
                    let close = (rss / target - 1.0).abs() < 1e-4;
                    if rss <= target {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                    // Keep the last fit at or below the target (or on it).
                    if rss <= target || close {
                        best = Some((lambda, fit, rss));
                    }
                    if close {
                        break;
                    }
                }
                None => hi = mid,
            }
            if hi - lo < 1e-6 {
                break;
            }
        }
        best
    }

    /// The fit at `lambda` and its residual sum of squares.
    fn solve(&self, lambda: f64) -> Option<(Vec<Point3>, f64)> {
        let mut m = self.r.clone();
        for (v, q) in m.data.iter_mut().zip(&self.qdq.data) {
            *v += lambda * q;
        }
        if !m.factorise() {
            return None;
        }
        let mut gamma = self.qty.clone();
        m.solve(&mut gamma);
        let mut rss = 0.0;
        let fit: Vec<Point3> = self
            .y
            .iter()
            .zip(&self.q_rows)
            .zip(&self.dinv)
            .map(|((p, row), &d)| {
                let mut qg = [0.0; 3];
                for &(c, v) in row {
                    for k in 0..3 {
                        qg[k] += v * gamma[c][k];
                    }
                }
                let r = qg.map(|v| lambda * d * v);
                rss += r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
                std::array::from_fn(|k| p[k] - r[k])
            })
            .collect();
        rss.is_finite().then_some((fit, rss))
    }

    /// Noise variance (summed over components) from the residuals of
    /// Lagrange interpolation by the neighbours (see the module doc).
    fn noise_variance(&self) -> f64 {
        let n = self.y.len();
        let offsets: &[isize] = if n >= 5 { &[-2, -1, 1, 2] } else { &[-1, 1] };
        let reach = offsets.len() / 2;
        let (lo, hi) = if self.closed {
            (0, n)
        } else {
            (reach, n - reach)
        };
        let mut sum = 0.0;
        let mut count = 0usize;
        for i in lo..hi {
            let mut nodes = [(0.0f64, [0.0f64; 3]); 4];
            for (slot, &o) in nodes.iter_mut().zip(offsets) {
                let k = i as isize + o;
                let (idx, shift) = if k < 0 {
                    ((k + n as isize) as usize, -1.0)
                } else if k >= n as isize {
                    ((k - n as isize) as usize, 1.0)
                } else {
                    (k as usize, 0.0)
                };
                *slot = (self.tau[idx] + shift, self.y[idx]);
            }
            let nodes = &nodes[..offsets.len()];
            let x = self.tau[i];
            let mut interp = [0.0; 3];
            let mut norm = 1.0;
            for (a, &(xa, ya)) in nodes.iter().enumerate() {
                let mut l = 1.0;
                for (b, &(xb, _)) in nodes.iter().enumerate() {
                    if a != b {
                        l *= (x - xb) / (xa - xb);
                    }
                }
                norm += l * l;
                for c in 0..3 {
                    interp[c] += l * ya[c];
                }
            }
            let r2 = dist2(self.y[i], interp) / norm;
            if r2.is_finite() {
                sum += r2;
                count += 1;
            }
        }
        if count == 0 {
            0.0
        } else {
            sum / count as f64
        }
    }
}

/// Lower-triangle entries (row, column, value), row ≥ column, of a
/// symmetric matrix, to be summed into a [`Skyline`].
type Entries = Vec<(usize, usize, f64)>;

/// Nonzeros of each row of Q: (column, value).
type SparseRows = Vec<Vec<(usize, f64)>>;

/// Number of columns of Q: one per knot with a second derivative
/// (interior knots when open, every knot when closed).
fn q_columns(n: usize, closed: bool) -> usize {
    if closed {
        n
    } else {
        n - 2
    }
}

/// The parameter steps from the cumulative chord length `t` (of `total`
/// length), each at least 10⁻³ of the mean step, so that duplicate points
/// do not make the system singular, then normalised to sum 1; closed, the
/// last step closes the loop.
fn parameter_steps(t: &[f64], total: f64, closed: bool) -> Vec<f64> {
    let n = t.len();
    let segments = if closed { n } else { n - 1 };
    let floor = 1e-3 / segments as f64;
    let mut h: Vec<f64> = (0..segments)
        .map(|i| {
            let next = if i + 1 < n { t[i + 1] } else { total };
            ((next - t[i]) / total).max(floor)
        })
        .collect();
    let sum: f64 = h.iter().sum();
    for v in &mut h {
        *v /= sum;
    }
    h
}

/// The `n` knots τ: the cumulative steps `h`, from 0.
fn knots(h: &[f64], n: usize) -> Vec<f64> {
    let mut tau = Vec::with_capacity(n);
    let mut acc = 0.0;
    for i in 0..n {
        tau.push(acc);
        if i < h.len() {
            acc += h[i];
        }
    }
    tau
}

/// The inverse weights W⁻¹: 0 at the ends of an open edge, which are
/// pinned (infinite weight), 1 elsewhere.
fn inverse_weights(n: usize, closed: bool) -> Vec<f64> {
    let mut dinv = vec![1.0; n];
    if !closed {
        dinv[0] = 0.0;
        dinv[n - 1] = 0.0;
    }
    dinv
}

/// The rows of the second-difference matrix Q (n rows, one column per
/// knot with a second derivative) and the entries of the Gram matrix R of
/// those second derivatives: tridiagonal, cyclic when `closed`.
fn second_differences(h: &[f64], n: usize, closed: bool) -> (SparseRows, Entries) {
    let segments = h.len();
    let cols = q_columns(n, closed);
    let knot = |c: usize| if closed { c } else { c + 1 };
    let mut q_rows: SparseRows = vec![Vec::with_capacity(3); n];
    let mut r_entries: Entries = Vec::with_capacity(2 * cols);
    for c in 0..cols {
        let j = knot(c);
        let (jm, jp) = ((j + n - 1) % n, (j + 1) % n);
        let (hm, hj) = (h[(j + segments - 1) % segments], h[j % segments]);
        q_rows[jm].push((c, 1.0 / hm));
        q_rows[j].push((c, -1.0 / hm - 1.0 / hj));
        q_rows[jp].push((c, 1.0 / hj));
        r_entries.push((c, c, (hm + hj) / 3.0));
        let next = if closed {
            Some((c + 1) % cols)
        } else {
            (c + 1 < cols).then_some(c + 1)
        };
        if let Some(c2) = next {
            r_entries.push((c.max(c2), c.min(c2), hj / 6.0));
        }
    }
    (q_rows, r_entries)
}

/// The entries of Qᵀ W⁻¹ Q, row by row of Q (the pinned rows, of weight
/// 0, add nothing).
fn weighted_gram(q_rows: &SparseRows, dinv: &[f64]) -> Entries {
    let mut qdq_entries: Entries = Vec::with_capacity(9 * q_rows.len());
    for (row, &d) in q_rows.iter().zip(dinv) {
        if d == 0.0 {
            continue;
        }
        for &(a, va) in row {
            for &(b, vb) in row {
                if a >= b {
                    qdq_entries.push((a, b, d * va * vb));
                }
            }
        }
    }
    qdq_entries
}

/// R and Qᵀ W⁻¹ Q, `cols` × `cols`, in the same envelope (the one both
/// need), so that R + λ Qᵀ W⁻¹ Q is a sum of their data.
fn shared_envelope(cols: usize, r_entries: &Entries, qdq_entries: &Entries) -> (Skyline, Skyline) {
    let mut first: Vec<usize> = (0..cols).collect();
    for &(i, j, _) in r_entries.iter().chain(qdq_entries) {
        first[i] = first[i].min(j);
    }
    let mut r = Skyline::with_first(first.clone());
    let mut qdq = Skyline::with_first(first);
    for &(i, j, v) in r_entries {
        r.add(i, j, v);
    }
    for &(i, j, v) in qdq_entries {
        qdq.add(i, j, v);
    }
    (r, qdq)
}

/// Qᵀ y for the three components, one row per column of Q (`cols`).
fn q_transpose_times(q_rows: &SparseRows, points: &[Point3], cols: usize) -> Vec<[f64; 3]> {
    let mut qty = vec![[0.0; 3]; cols];
    for (row, p) in q_rows.iter().zip(points) {
        for &(c, v) in row {
            for k in 0..3 {
                qty[c][k] += v * p[k];
            }
        }
    }
    qty
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::SplitMix64;
    use std::f64::consts::PI;

    fn max_dev(a: &[Point3], b: &[Point3]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(p, q)| dist2(*p, *q).sqrt())
            .fold(0.0, f64::max)
    }

    /// RMS distance of points to the line through the origin along (2, 1, 0).
    fn line_dev(points: &[Point3]) -> f64 {
        let d = [2.0 / 5f64.sqrt(), 1.0 / 5f64.sqrt(), 0.0];
        let s: f64 = points
            .iter()
            .map(|p| {
                let a = p[0] * d[0] + p[1] * d[1];
                p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - a * a
            })
            .sum();
        (s / points.len() as f64).sqrt()
    }

    fn cubic(t: f64) -> Point3 {
        [
            1.0 + 2.0 * t - 3.0 * t * t + 4.0 * t * t * t,
            -2.0 + t + 5.0 * t * t * t,
            0.5 * t * t - t * t * t,
        ]
    }

    /// Points on a straight line, jittered but for the ends.
    fn jittered_line(n: usize, noise: f64, seed: u64) -> Vec<Point3> {
        let mut rng = SplitMix64::new(seed);
        let clean: Vec<Point3> = (0..n).map(|i| [i as f64, 0.5 * i as f64, 0.0]).collect();
        let mut noisy = clean.clone();
        for p in noisy.iter_mut().skip(1).take(n - 2) {
            p[0] += rng.range(-noise, noise);
            p[1] += rng.range(-noise, noise);
            p[2] += rng.range(-noise, noise);
        }
        noisy
    }

    /// Deviation of points from the circle x² + y² = r², z = 0.
    fn circle_dev(points: &[Point3], r: f64) -> (f64, f64) {
        let d: Vec<f64> = points
            .iter()
            .map(|p| ((p[0] * p[0] + p[1] * p[1]).sqrt() - r).hypot(p[2]))
            .collect();
        let rms = (d.iter().map(|v| v * v).sum::<f64>() / d.len() as f64).sqrt();
        (rms, d.iter().fold(0.0, |a: f64, &b| a.max(b)))
    }

    fn noisy_arc(n: usize, r: f64, span: f64, noise: f64, seed: u64) -> Vec<Point3> {
        let mut rng = SplitMix64::new(seed);
        (0..n)
            .map(|i| {
                let a = span * i as f64 / (n - 1) as f64;
                let rr = r + rng.range(-noise, noise);
                [rr * a.cos(), rr * a.sin(), rng.range(-noise, noise)]
            })
            .collect()
    }

    #[test]
    fn cubic_in_its_parameter_is_reproduced_exactly() {
        let t: Vec<f64> = (0..40).map(|i| (i as f64 / 39.0).powf(1.3)).collect();
        let pts: Vec<Point3> = t.iter().map(|&t| cubic(t)).collect();
        let fit = polynomial_fit_at(&pts, &t, 3);
        assert!(max_dev(&fit, &pts) < 1e-12, "{}", max_dev(&fit, &pts));
        // Degree 2 cannot.
        assert!(max_dev(&polynomial_fit_at(&pts, &t, 2), &pts) > 1e-3);
        // Higher degrees reproduce it too.
        assert!(max_dev(&polynomial_fit_at(&pts, &t, 7), &pts) < 1e-10);
    }

    #[test]
    fn polynomial_edge_reproduces_lines_and_is_close_on_a_cubic() {
        let line: Vec<Point3> = (0..30)
            .map(|i| {
                let s = (i as f64 / 29.0).powi(2);
                [3.0 * s, -s, 2.0 * s]
            })
            .collect();
        assert!(max_dev(&polynomial_edge(&line, 3), &line) < 1e-12);
        // A gently curved cubic: chord length is nearly its own parameter.
        let pts: Vec<Point3> = (0..200)
            .map(|i| {
                let t = i as f64 / 199.0;
                [10.0 * t, 0.3 * t * t * t - 0.2 * t, 0.0]
            })
            .collect();
        assert!(max_dev(&polynomial_edge(&pts, 3), &pts) < 1e-3);
    }

    #[test]
    fn polynomial_smooths_a_jittered_line_and_pins_the_ends() {
        let noisy = jittered_line(200, 0.3, 7);
        let fit = polynomial_edge(&noisy, 3);
        assert_eq!(fit.len(), noisy.len());
        // Across the line (along it, noise only moves points' parameters).
        assert!(
            line_dev(&fit) < 0.3 * line_dev(&noisy),
            "{}",
            line_dev(&fit)
        );
        assert_eq!(fit[0], noisy[0]);
        assert_eq!(fit[199], noisy[199]);
    }

    #[test]
    fn spline_smooths_a_jittered_line_and_pins_the_ends() {
        let noisy = jittered_line(300, 0.3, 11);
        let f = smoothing_spline_fit(&noisy, false);
        assert_eq!(f.points.len(), noisy.len());
        assert!(f.lambda > 0.0);
        // σ̂ estimates the noise across the curve (uniform ±0.3 per axis,
        // variance 0.03; along the line the chord parameter absorbs it).
        let sigma = (2.0 * 0.03f64).sqrt();
        assert!(
            (f.sigma / sigma - 1.0).abs() < 0.15,
            "{} vs {sigma}",
            f.sigma
        );
        assert!(
            line_dev(&f.points) < 0.4 * line_dev(&noisy),
            "{} {}",
            line_dev(&f.points),
            line_dev(&noisy)
        );
        assert_eq!(f.points[0], noisy[0]);
        assert_eq!(f.points[299], noisy[299]);
    }

    #[test]
    fn spline_smooths_an_arc_and_a_closed_circle() {
        let r = 50.0;
        let noisy = noisy_arc(400, r, 2.0, 0.5, 3);
        let fit = smoothing_spline_edge(&noisy, false);
        let (before, _) = circle_dev(&noisy[1..399], r);
        let (after, _) = circle_dev(&fit[1..399], r);
        assert!(after < 0.5 * before, "{after} vs {before}");
        assert_eq!((fit[0], fit[399]), (noisy[0], noisy[399]));

        // Closed: the whole circle, every point free.
        let mut rng = SplitMix64::new(5);
        let n = 500;
        let circle: Vec<Point3> = (0..n)
            .map(|i| {
                let a = 2.0 * PI * i as f64 / n as f64;
                let rr = r + rng.range(-0.5, 0.5);
                [rr * a.cos(), rr * a.sin(), 0.0]
            })
            .collect();
        let fit = smoothing_spline_edge(&circle, true);
        let (before, _) = circle_dev(&circle, r);
        let (after, _) = circle_dev(&fit, r);
        assert!(after < 0.5 * before, "{after} vs {before}");
        // Periodic: no seam at the first point.
        let (first, _) = circle_dev(&fit[..3], r);
        assert!(first < 2.0 * after + 0.05, "{first}");
    }

    #[test]
    fn clean_data_is_left_nearly_alone() {
        let arc: Vec<Point3> = (0..100)
            .map(|i| {
                let a = i as f64 / 99.0;
                [20.0 * a.cos(), 20.0 * a.sin(), 0.0]
            })
            .collect();
        let fit = smoothing_spline_edge(&arc, false);
        assert!(max_dev(&fit, &arc) < 1e-6, "{}", max_dev(&fit, &arc));
    }

    #[test]
    fn large_inputs_are_fast_enough() {
        let noisy = noisy_arc(10_000, 500.0, 3.0, 0.5, 9);
        let start = std::time::Instant::now();
        let fit = smoothing_spline_edge(&noisy, false);
        let closed = smoothing_spline_edge(&noisy, true);
        assert_eq!((fit.len(), closed.len()), (10_000, 10_000));
        assert!(start.elapsed().as_secs_f64() < 10.0);
        let (before, _) = circle_dev(&noisy[1..9999], 500.0);
        let (after, _) = circle_dev(&fit[1..9999], 500.0);
        assert!(after < 0.5 * before, "{after} vs {before}");
    }

    #[test]
    fn degenerate_inputs_do_not_panic() {
        let cases: Vec<Vec<Point3>> = vec![
            vec![],
            vec![[0.0; 3]],
            vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
            vec![[1.0; 3]; 10],
            vec![
                [0.0; 3],
                [0.0; 3],
                [1.0, 1.0, 0.0],
                [1.0, 1.0, 0.0],
                [2.0, 0.0, 0.0],
            ],
            vec![[0.0; 3], [f64::NAN, 0.0, 0.0], [1.0; 3], [2.0; 3], [3.0; 3]],
            vec![[0.0; 3], [f64::INFINITY, 0.0, 0.0], [1.0; 3], [2.0; 3]],
            vec![[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            vec![
                [0.0; 3],
                [1e300, 0.0, 0.0],
                [-1e300, 1.0, 0.0],
                [0.0, 1e-300, 0.0],
            ],
        ];
        for pts in &cases {
            for degree in [0, 1, 2, 3, 10, 100] {
                let fit = polynomial_edge(pts, degree);
                assert_eq!(fit.len(), pts.len());
            }
            for closed in [false, true] {
                let fit = smoothing_spline_edge(pts, closed);
                assert_eq!(fit.len(), pts.len());
                if pts.len() >= MIN_POINTS && all_finite(pts) && !closed {
                    assert_eq!(fit[0], pts[0]);
                    assert_eq!(fit[pts.len() - 1], pts[pts.len() - 1]);
                }
            }
        }
        // Short inputs come back unchanged.
        let three = &cases[2];
        assert_eq!(&polynomial_edge(three, 3), three);
        assert_eq!(&smoothing_spline_edge(three, true), three);
        // Repeated points: finite output.
        let dup = &cases[4];
        assert!(all_finite(&smoothing_spline_edge(dup, false)));
        assert!(all_finite(&smoothing_spline_edge(dup, true)));
        assert!(all_finite(&polynomial_edge(dup, 3)));
    }

    #[test]
    fn skyline_cholesky_solves_a_cyclic_system() {
        // A cyclic pentadiagonal SPD matrix against a dense solve.
        let n = 9;
        let mut dense = DMatrix::<f64>::zeros(n, n);
        for i in 0..n {
            dense[(i, i)] = 6.0 + i as f64 * 0.1;
            for (o, v) in [(1, -1.5), (2, 0.7)] {
                let j = (i + o) % n;
                dense[(i, j)] += v;
                dense[(j, i)] += v;
            }
        }
        let mut first: Vec<usize> = (0..n).collect();
        for i in 0..n {
            for j in 0..=i {
                if dense[(i, j)] != 0.0 {
                    first[i] = first[i].min(j);
                }
            }
        }
        let mut sky = Skyline::with_first(first.clone());
        for i in 0..n {
            for j in first[i]..=i {
                sky.add(i, j, dense[(i, j)]);
            }
        }
        assert!(sky.factorise());
        let b: Vec<[f64; 3]> = (0..n).map(|i| [i as f64, 1.0, -(i as f64).sin()]).collect();
        let mut x = b.clone();
        sky.solve(&mut x);
        for c in 0..3 {
            let rhs = nalgebra::DVector::from_fn(n, |i, _| b[i][c]);
            let want = dense.clone().lu().solve(&rhs).unwrap();
            for i in 0..n {
                assert!((x[i][c] - want[i]).abs() < 1e-12);
            }
        }
    }
}
