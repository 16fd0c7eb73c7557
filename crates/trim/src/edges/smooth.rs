//! Spatial-FFT low-pass smoothing of boundary edges — the paper's section
//! 3.3 ("FFT-based reconstruction"), with the cut-off of eq. 7,
//! f_max = 1 / (2π β), following the local resolution β along the edge.
//!
//! Each Cartesian component of an edge is treated as a function of the arc
//! length d along the input polyline (the paper's "curvilinear distance"),
//! made periodic, low-pass filtered by zeroing every spatial-frequency
//! component above f_max, and evaluated back at the input points' own arc
//! positions: one smoothed point per input point. The FFT is `rustfft`
//! (a proven, widely used pure-Rust FFT that handles any length; the
//! design card names it). The choices, step by step:
//!
//! 1. **Periodic signal.** A closed loop ([`smooth_closed_edge`]) is
//!    already periodic: its arc length includes the closing segment from
//!    the last point back to the first and the period is the loop length
//!    (the paper's figure 5b: no flipping). An open edge
//!    ([`smooth_open_edge`], corner to corner, length D) has the straight
//!    line from its first to its last point subtracted, so that every
//!    component is 0 at both ends. This plays the role of the paper's
//!    translation and rotation by α; it is a shear of the (d, x) plot
//!    rather than a rotation, so the abscissa d is left unchanged (a
//!    rotation would mix distances with coordinates and move the samples
//!    along d). The period, of length 2D, is the detrended pattern f
//!    followed by its inverted, flipped copy: g(D + t) = −f(D − t) (an
//!    odd extension, continuous with a continuous slope at both joins, as
//!    in figure 5a).
//! 2. **Uniform resampling.** The FFT needs equally spaced samples: the
//!    period is resampled, by linear interpolation between the input
//!    points, at a spacing d_s no larger than the smallest non-zero input
//!    step ("equal or smaller than the minimum original sampling
//!    distance"): N = ⌈length / smallest step⌉ samples per length D (open:
//!    2N per period, so that both ends fall on samples) or per loop
//!    (closed). To bound memory and time, d_s is never smaller than
//!    length / 2¹⁶ (at most 2¹⁶ samples per D, 2¹⁷ per open period);
//!    below that, a tiny step is simply resolved less finely. Zero-length
//!    steps (repeated consecutive points) are skipped.
//! 3. **Low-pass filter (eq. 7).** One forward FFT per component (x and y
//!    share one complex transform as x + i·y, z is the other: the filter
//!    is real and symmetric in frequency, so it acts on the real and
//!    imaginary parts separately). Bin k of a period of length P has the
//!    spatial frequency k/P for k ≤ N/2 and (N − k)/P for the negative
//!    half, so harmonic m = min(k, N − k) is kept if and only if
//!    m / P ≤ 1 / (2π β), i.e. m ≤ ⌊P / (2π β)⌋, and zeroed otherwise; an
//!    inverse FFT and division by N follow. The FFT is planned once per
//!    length and its buffers and scratch are reused across cut-offs.
//! 4. **β along the edge.** The cut-off follows the local β, not one value
//!    per edge: the signal is filtered at a small bank of cut-offs, for β
//!    levels spaced geometrically from the edge's smallest to its largest
//!    β with ratio steps ≤ 1.1 (at most 16 levels, so the ratio step grows
//!    beyond 1.1 only when max β / min β > 1.1¹⁵ ≈ 4.2; one level when β
//!    is constant; levels with the same harmonic cut-off are filtered once).
//!    Each output point takes its local β — the linear interpolation of
//!    the input β along the arc, evaluated at the point's own arc
//!    position, i.e. its own `beta[i]` — and blends the two filtered
//!    signals whose β levels bracket it, linearly in ln β. Where β is
//!    constant over a stretch, the output there is exactly the single-
//!    cut-off filter of that β.
//! 5. **Back to points.** Each filtered period is evaluated at the input
//!    points' arc positions by linear interpolation of the uniform
//!    samples; an open edge gets its straight line added back, and its two
//!    end points are returned exactly (bit-identical) as given, so that
//!    consecutive edges of a loop still share their corners.
//! 6. **No repetition of the period.** The paper repeats the period until
//!    the FFT input has ≥ 1000 samples, for frequency resolution. For a
//!    periodic signal this changes nothing: the DFT of M copies of a
//!    period of N samples is non-zero only at bins M·k, where it equals M
//!    times bin k of one period; the bins in between are zero. Bin M·k of
//!    the repeated signal (period M·P) has the frequency M·k / (M·P) =
//!    k / P, so exactly the same harmonics are kept, and the inverse gives
//!    M copies of the one-period result. The repetition is therefore
//!    skipped; a unit test filters a jittered signal both ways and finds
//!    the same result to 10⁻⁹ relative.
//!
//! Neither function panics. Edges with fewer than 3 points, a zero or
//! non-finite total length, non-finite coordinates, a `beta` of another
//! length than `points`, or any β that is not finite and positive, are
//! returned unchanged. The result is covariant under rigid motions and
//! uniform scaling (with β scaled too).

use std::sync::Arc;

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};

use crate::geom::{dist2, Point3};

/// Edges with fewer points are returned unchanged.
const MIN_POINTS: usize = 3;
/// At most this many uniform samples per edge length D (open) or loop.
const MAX_SAMPLES: f64 = 65536.0;
/// Largest ratio between consecutive β levels of the filter bank …
const LEVEL_RATIO: f64 = 1.1;
/// … unless that would need more levels than this.
const MAX_LEVELS: usize = 16;

/// Smooths an open edge (corner to corner). `points` in order, `beta[i]` the local resolution at `points[i]` (> 0).
/// Returns one smoothed point per input point, at the same arc-length parameter; the first and last points are returned exactly (bit-identical) as given.
pub fn smooth_open_edge(points: &[Point3], beta: &[f64]) -> Vec<Point3> {
    let n = points.len();
    if !valid_input(points, beta) {
        return points.to_vec();
    }
    let s = arc_lengths(points, false);
    let total = s[n - 1];
    let Some(half) = sample_count(&s, total) else {
        return points.to_vec();
    };
    let (a, b) = (points[0], points[n - 1]);
    let trend = |si: f64| -> Point3 {
        let t = si / total;
        std::array::from_fn(|c| a[c] + t * (b[c] - a[c]))
    };
    let detrended: Vec<Point3> = points
        .iter()
        .zip(&s)
        .map(|(p, &si)| {
            let l = trend(si);
            std::array::from_fn(|c| p[c] - l[c])
        })
        .collect();
    let ds = total / half as f64;
    // f at j·ds, j = 0 … half, then the odd extension g(D + t) = −f(D − t).
    let f = resample(&s, &detrended, ds, half + 1);
    let period: [Vec<f64>; 3] = std::array::from_fn(|c| {
        let mut g = Vec::with_capacity(2 * half);
        g.extend_from_slice(&f[c]);
        g[0] = 0.0;
        g[half] = 0.0;
        g.extend((1..half).map(|j| -f[c][half - j]));
        g
    });
    let mut out = filter_and_evaluate(&period, 2.0 * total, ds, &s, beta, 0);
    for (o, &si) in out.iter_mut().zip(&s) {
        let l = trend(si);
        *o = std::array::from_fn(|c| o[c] + l[c]);
    }
    out[0] = points[0];
    out[n - 1] = points[n - 1];
    if all_finite(&out) {
        out
    } else {
        points.to_vec()
    }
}

/// Smooths a closed loop without corners (the last point joins the first). One smoothed point per input point.
pub fn smooth_closed_edge(points: &[Point3], beta: &[f64]) -> Vec<Point3> {
    let n = points.len();
    if !valid_input(points, beta) {
        return points.to_vec();
    }
    let s = arc_lengths(points, true);
    let total = s[n];
    let Some(count) = sample_count(&s, total) else {
        return points.to_vec();
    };
    let ds = total / count as f64;
    let mut closed = points.to_vec();
    closed.push(points[0]);
    let samples = resample(&s, &closed, ds, count);
    // A closed loop keeps at least its first harmonic (its best-fit
    // ellipse): a hole whose perimeter is below 2πβ would otherwise
    // collapse to its centroid.
    let out = filter_and_evaluate(&samples, total, ds, &s[..n], beta, 1);
    if all_finite(&out) {
        out
    } else {
        points.to_vec()
    }
}

fn all_finite(points: &[Point3]) -> bool {
    points.iter().flatten().all(|v| v.is_finite())
}

fn valid_input(points: &[Point3], beta: &[f64]) -> bool {
    points.len() >= MIN_POINTS
        && beta.len() == points.len()
        && all_finite(points)
        && beta.iter().all(|&b| b.is_finite() && b > 0.0)
}

/// Cumulative arc length at each point (and, closed, at the first point
/// again after the closing segment: n + 1 values).
pub(crate) fn arc_lengths(points: &[Point3], closed: bool) -> Vec<f64> {
    let mut s = Vec::with_capacity(points.len() + 1);
    let mut acc = 0.0;
    s.push(0.0);
    for w in points.windows(2) {
        acc += dist2(w[0], w[1]).sqrt();
        s.push(acc);
    }
    if closed {
        acc += dist2(points[points.len() - 1], points[0]).sqrt();
        s.push(acc);
    }
    s
}

/// Number of uniform samples over `total` (step 2): ⌈total / smallest
/// non-zero step⌉, at most [`MAX_SAMPLES`]. `None` for a zero or
/// non-finite length.
fn sample_count(s: &[f64], total: f64) -> Option<usize> {
    if !(total.is_finite() && total > 0.0) {
        return None;
    }
    let min_step = s
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|&h| h > 0.0)
        .fold(f64::INFINITY, f64::min);
    let count = (total / min_step).ceil();
    // NaN (impossible here) and tiny steps both end up within [1, MAX].
    Some(if count.is_nan() {
        1.0
    } else {
        count.clamp(1.0, MAX_SAMPLES)
    } as usize)
}

/// Linear interpolation of `values` (at non-decreasing arc positions `s`)
/// at j·`ds`, j = 0 … `count` − 1; positions past the end take the last
/// value. Zero-length segments are skipped.
fn resample(s: &[f64], values: &[Point3], ds: f64, count: usize) -> [Vec<f64>; 3] {
    let mut out: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(count));
    let last = s.len() - 1;
    let mut i = 0;
    for j in 0..count {
        let t = j as f64 * ds;
        while i < last && s[i + 1] <= t {
            i += 1;
        }
        let v = if i >= last {
            values[last]
        } else {
            let w = (t - s[i]) / (s[i + 1] - s[i]);
            let (a, b) = (values[i], values[i + 1]);
            std::array::from_fn(|c| a[c] + w * (b[c] - a[c]))
        };
        for c in 0..3 {
            out[c].push(v[c]);
        }
    }
    out
}

/// The β levels of the filter bank (step 4): geometric from `lo` to `hi`.
fn beta_levels(lo: f64, hi: f64) -> Vec<f64> {
    let ratio = hi / lo;
    if ratio <= 1.0 {
        return vec![lo];
    }
    let steps = (ratio.ln() / LEVEL_RATIO.ln()).ceil().max(1.0) as usize;
    let steps = steps.min(MAX_LEVELS - 1);
    let q = ratio.powf(1.0 / steps as f64);
    let mut levels: Vec<f64> = (0..steps).map(|j| lo * q.powi(j as i32)).collect();
    levels.push(hi);
    levels
}

/// Levels and weight bracketing `b`: (j, w) for (1 − w)·level j + w·level
/// j + 1, linear in ln β.
fn bracket(levels: &[f64], b: f64) -> (usize, f64) {
    if levels.len() == 1 {
        return (0, 0.0);
    }
    let j = levels
        .partition_point(|&l| l <= b)
        .clamp(1, levels.len() - 1)
        - 1;
    let w = (b / levels[j]).ln() / (levels[j + 1] / levels[j]).ln();
    (j, w.clamp(0.0, 1.0))
}

/// Highest harmonic kept by eq. 7 for a period of length `period`, capped
/// at N / 2 (everything kept).
fn harmonic_cutoff(period: f64, beta: f64, n: usize) -> usize {
    let k = period / (2.0 * std::f64::consts::PI * beta);
    if k.is_finite() && k < (n / 2) as f64 {
        k.floor() as usize
    } else {
        n / 2
    }
}

/// Reused FFT plans and buffers for one sample count.
struct LowPass {
    n: usize,
    inverse: Arc<dyn Fft<f64>>,
    scratch: Vec<Complex<f64>>,
    /// Spectra of x + i·y and of z.
    spectra: [Vec<Complex<f64>>; 2],
    work: Vec<Complex<f64>>,
}

impl LowPass {
    fn new(samples: &[Vec<f64>; 3]) -> Self {
        let n = samples[0].len();
        let mut planner = FftPlanner::<f64>::new();
        let forward = planner.plan_fft_forward(n);
        let inverse = planner.plan_fft_inverse(n);
        let scratch_len = forward
            .get_inplace_scratch_len()
            .max(inverse.get_inplace_scratch_len());
        let mut scratch = vec![Complex::new(0.0, 0.0); scratch_len];
        let mut xy: Vec<Complex<f64>> = samples[0]
            .iter()
            .zip(&samples[1])
            .map(|(&x, &y)| Complex::new(x, y))
            .collect();
        let mut z: Vec<Complex<f64>> = samples[2].iter().map(|&z| Complex::new(z, 0.0)).collect();
        forward.process_with_scratch(&mut xy, &mut scratch);
        forward.process_with_scratch(&mut z, &mut scratch);
        Self {
            n,
            inverse,
            scratch,
            spectra: [xy, z],
            work: Vec::with_capacity(n),
        }
    }

    /// The three components with every harmonic above `keep` zeroed.
    fn filtered(&mut self, keep: usize) -> [Vec<f64>; 3] {
        let n = self.n;
        let scale = 1.0 / n as f64;
        let mut out: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(n));
        for (which, spectrum) in self.spectra.iter().enumerate() {
            self.work.clear();
            self.work.extend(spectrum.iter().enumerate().map(|(k, &v)| {
                if k.min(n - k) <= keep {
                    v
                } else {
                    Complex::new(0.0, 0.0)
                }
            }));
            self.inverse
                .process_with_scratch(&mut self.work, &mut self.scratch);
            if which == 0 {
                out[0].extend(self.work.iter().map(|v| v.re * scale));
                out[1].extend(self.work.iter().map(|v| v.im * scale));
            } else {
                out[2].extend(self.work.iter().map(|v| v.re * scale));
            }
        }
        out
    }
}

/// Steps 3–5 (without the trend): filters one period of uniform `samples`
/// (spacing `ds`, length `period`) at the bank of β levels and evaluates
/// the blend at arc positions `s` with local resolutions `beta`, keeping
/// at least `min_harmonics` harmonics.
fn filter_and_evaluate(
    samples: &[Vec<f64>; 3],
    period: f64,
    ds: f64,
    s: &[f64],
    beta: &[f64],
    min_harmonics: usize,
) -> Vec<Point3> {
    let n = samples[0].len();
    let lo = beta.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = beta.iter().copied().fold(0.0, f64::max);
    let levels = beta_levels(lo, hi);
    let mut lowpass = LowPass::new(samples);
    // Filtered signals per level; equal cut-offs share one.
    let mut bank: Vec<Arc<[Vec<f64>; 3]>> = Vec::with_capacity(levels.len());
    let mut last_keep = None;
    for &b in &levels {
        let keep = harmonic_cutoff(period, b, n).max(min_harmonics.min(n / 2));
        if last_keep != Some(keep) {
            bank.push(Arc::new(lowpass.filtered(keep)));
            last_keep = Some(keep);
        } else {
            let prev = Arc::clone(&bank[bank.len() - 1]);
            bank.push(prev);
        }
    }
    let at = |signal: &[Vec<f64>; 3], si: f64| -> Point3 {
        let pos = (si / ds).max(0.0);
        let j = (pos.floor() as usize).min(n - 1);
        let w = pos - j as f64;
        let k = (j + 1) % n;
        std::array::from_fn(|c| signal[c][j] + w * (signal[c][k] - signal[c][j]))
    };
    s.iter()
        .zip(beta)
        .map(|(&si, &b)| {
            let (j, w) = bracket(&levels, b);
            let p = at(&bank[j], si);
            if w == 0.0 {
                return p;
            }
            let q = at(&bank[j + 1], si);
            std::array::from_fn(|c| p[c] + w * (q[c] - p[c]))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;
    use testkit::SplitMix64;

    /// One component filtered at one β (step 3 alone).
    fn lowpass_one(signal: &[f64], period: f64, beta: f64) -> Vec<f64> {
        let zeros = vec![0.0; signal.len()];
        let samples = [signal.to_vec(), zeros.clone(), zeros];
        let keep = harmonic_cutoff(period, beta, signal.len());
        let [x, _, _] = LowPass::new(&samples).filtered(keep);
        x
    }

    /// The paper's variant: the period repeated to ≥ 1000 samples, filtered
    /// at the repeated period's frequency resolution, first period kept.
    fn lowpass_repeated(signal: &[f64], period: f64, beta: f64) -> Vec<f64> {
        let n = signal.len();
        let copies = 1000usize.div_ceil(n).max(2);
        let long: Vec<f64> = signal.iter().copied().cycle().take(n * copies).collect();
        let mut out = lowpass_one(&long, period * copies as f64, beta);
        out.truncate(n);
        out
    }

    #[test]
    fn repeating_the_period_changes_nothing() {
        let mut rng = SplitMix64::new(7);
        let n = 97;
        let ds = 0.37;
        let signal: Vec<f64> = (0..n)
            .map(|j| (2.0 * PI * j as f64 / n as f64).sin() * 5.0 + rng.range(-1.0, 1.0))
            .collect();
        for beta in [0.2, 0.5, 1.0, 3.0] {
            let one = lowpass_one(&signal, n as f64 * ds, beta);
            let rep = lowpass_repeated(&signal, n as f64 * ds, beta);
            let scale = one.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (a, b) in one.iter().zip(&rep) {
                assert!((a - b).abs() <= 1e-9 * scale, "{a} vs {b} at β = {beta}");
            }
        }
    }

    fn circle(rng: &mut SplitMix64, r: f64, spacing: f64, jitter: f64) -> Vec<Point3> {
        let n = (2.0 * PI * r / spacing).round() as usize;
        (0..n)
            .map(|i| {
                let a = 2.0 * PI * i as f64 / n as f64;
                let rr = r + rng.range(-jitter, jitter);
                [rr * a.cos(), rr * a.sin(), 0.0]
            })
            .collect()
    }

    fn radius(p: &Point3) -> f64 {
        (p[0] * p[0] + p[1] * p[1]).sqrt()
    }

    /// (a) R = 20β, ±0.3β radial jitter. Eq. 7 keeps the harmonics up to
    /// L / (2πβ); points every β carry about L / (2β), so only ~1/π of
    /// white noise's power is kept (rms error / √π ≈ 1.8): the 3×
    /// reduction needs denser points (every β/4 here). The fundamental
    /// 1/(2πR) is far below the cut-off, so the radius is kept.
    #[test]
    fn jittered_circle_is_smoothed_without_shrinking() {
        let beta = 1.0;
        let r = 20.0 * beta;
        for (spacing, factor) in [(beta, 1.8), (0.25 * beta, 3.0)] {
            for seed in 1..4 {
                let mut rng = SplitMix64::new(seed);
                let pts = circle(&mut rng, r, spacing, 0.3 * beta);
                let betas = vec![beta; pts.len()];
                let out = smooth_closed_edge(&pts, &betas);
                assert_eq!(out.len(), pts.len());
                let mean_err = |p: &[Point3]| {
                    p.iter().map(|q| (radius(q) - r).abs()).sum::<f64>() / p.len() as f64
                };
                let mean_r = out.iter().map(radius).sum::<f64>() / out.len() as f64;
                let (before, after) = (mean_err(&pts), mean_err(&out));
                assert!(
                    after * factor <= before,
                    "spacing {spacing}: {before} -> {after}"
                );
                assert!((mean_r - r).abs() <= 0.05 * beta, "mean radius {mean_r}");
            }
        }
    }

    /// Mean distance to the line through the origin along unit `d`.
    fn line_dev(points: &[Point3], d: Point3) -> f64 {
        points
            .iter()
            .map(|p| {
                let a = p[0] * d[0] + p[1] * d[1] + p[2] * d[2];
                (p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - a * a)
                    .max(0.0)
                    .sqrt()
            })
            .sum::<f64>()
            / points.len() as f64
    }

    /// (b) See (a) for why the points are every β/4.
    #[test]
    fn jittered_line_keeps_its_ends_and_is_smoothed() {
        let beta = 1.0;
        let d = [2.0 / 3.0, 1.0 / 3.0, 2.0 / 3.0];
        let u = [-1.0 / 5f64.sqrt(), 2.0 / 5f64.sqrt(), 0.0];
        let v = [-4.0 / 45f64.sqrt(), -2.0 / 45f64.sqrt(), 5.0 / 45f64.sqrt()];
        for seed in 1..4 {
            let mut rng = SplitMix64::new(seed);
            let pts: Vec<Point3> = (0..=400)
                .map(|i| {
                    let t = 0.25 * i as f64;
                    let (a, b) = (rng.range(-0.3, 0.3), rng.range(-0.3, 0.3));
                    std::array::from_fn(|c| t * d[c] + a * u[c] + b * v[c])
                })
                .collect();
            let out = smooth_open_edge(&pts, &vec![beta; pts.len()]);
            assert_eq!(out.len(), pts.len());
            assert_eq!(out[0].map(f64::to_bits), pts[0].map(f64::to_bits));
            assert_eq!(out[400].map(f64::to_bits), pts[400].map(f64::to_bits));
            let (before, after) = (line_dev(&pts, d), line_dev(&out, d));
            assert!(after * 3.0 <= before, "{before} -> {after}");
        }
    }

    /// Amplitude of y against sin/cos(2π x / λ), least squares, over
    /// points with x in [lo, hi].
    fn amplitude(points: &[Point3], wavelength: f64, lo: f64, hi: f64) -> f64 {
        let (mut ss, mut cc, mut sc, mut ys, mut yc) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for p in points.iter().filter(|p| p[0] >= lo && p[0] <= hi) {
            let a = 2.0 * PI * p[0] / wavelength;
            let (s, c) = a.sin_cos();
            ss += s * s;
            cc += c * c;
            sc += s * c;
            ys += p[1] * s;
            yc += p[1] * c;
        }
        let det = ss * cc - sc * sc;
        let a = (ys * cc - yc * sc) / det;
        let b = (yc * ss - ys * sc) / det;
        (a * a + b * b).sqrt()
    }

    fn wiggle(length: f64, step: f64, wavelength: f64, amp: f64) -> Vec<Point3> {
        let n = (length / step).round() as usize;
        (0..=n)
            .map(|i| {
                let x = length * i as f64 / n as f64;
                [x, amp * (2.0 * PI * x / wavelength).sin(), 0.0]
            })
            .collect()
    }

    /// (c) A wiggle of wavelength 2β is above f_max = 1/(2πβ), one of 40β
    /// below it.
    #[test]
    fn short_wiggles_go_long_wiggles_stay() {
        let beta = 1.0;
        let short = wiggle(80.0, 0.25, 2.0 * beta, 0.1);
        let out = smooth_open_edge(&short, &vec![beta; short.len()]);
        let (a0, a1) = (
            amplitude(&short, 2.0, 0.0, 80.0),
            amplitude(&out, 2.0, 0.0, 80.0),
        );
        assert!(a1 * 10.0 <= a0, "short wiggle {a0} -> {a1}");
        let long = wiggle(160.0, 0.25, 40.0 * beta, 1.0);
        let out = smooth_open_edge(&long, &vec![beta; long.len()]);
        let (a0, a1) = (
            amplitude(&long, 40.0, 0.0, 160.0),
            amplitude(&out, 40.0, 0.0, 160.0),
        );
        assert!((a1 / a0 - 1.0).abs() <= 0.05, "long wiggle {a0} -> {a1}");
    }

    /// (d) One edge, β = 4 on the left, 0.4 on the right (linear between):
    /// a wiggle of wavelength 8 (frequency 1/8, between 1/(8π) and
    /// 1/(0.8π)) goes on the left and stays on the right.
    #[test]
    fn cut_off_follows_beta_along_the_edge() {
        let pts = wiggle(160.0, 0.25, 8.0, 0.2);
        let betas: Vec<f64> = pts
            .iter()
            .map(|p| {
                let t = ((p[0] - 70.0) / 20.0).clamp(0.0, 1.0);
                4.0 + t * (0.4 - 4.0)
            })
            .collect();
        let out = smooth_open_edge(&pts, &betas);
        let left = (
            amplitude(&pts, 8.0, 10.0, 60.0),
            amplitude(&out, 8.0, 10.0, 60.0),
        );
        let right = (
            amplitude(&pts, 8.0, 100.0, 150.0),
            amplitude(&out, 8.0, 100.0, 150.0),
        );
        assert!(left.1 * 10.0 <= left.0, "left {left:?}");
        assert!((right.1 / right.0 - 1.0).abs() <= 0.05, "right {right:?}");
    }

    fn max_abs_diff(a: &[Point3], b: &[Point3]) -> f64 {
        a.iter()
            .zip(b)
            .flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs()))
            .fold(0.0, f64::max)
    }

    /// (e) Rigid motion and uniform scale, with β scaled too.
    #[test]
    fn covariant_under_similarity() {
        let mut rng = SplitMix64::new(5);
        let pts: Vec<Point3> = (0..300)
            .map(|i| {
                let a = 4.0 * i as f64 / 300.0;
                let r = 30.0 + rng.range(-0.4, 0.4);
                [r * a.cos(), r * a.sin(), rng.range(-0.3, 0.3)]
            })
            .collect();
        let betas: Vec<f64> = (0..300).map(|i| 0.5 + 1.5 * i as f64 / 299.0).collect();
        // Rotation from a unit quaternion, scale and translation.
        let rot = crate::geom::rotation_from_quaternion([0.5, 0.5, -0.5, 0.5]);
        let scale = 3.7;
        let shift = [100.0, -50.0, 20.0];
        let tf = |p: &Point3| -> Point3 {
            std::array::from_fn(|r| {
                scale * (rot[r][0] * p[0] + rot[r][1] * p[1] + rot[r][2] * p[2]) + shift[r]
            })
        };
        let moved: Vec<Point3> = pts.iter().map(tf).collect();
        let scaled_betas: Vec<f64> = betas.iter().map(|b| b * scale).collect();
        let extent = scale * 60.0;
        for closed in [false, true] {
            let smooth = if closed {
                smooth_closed_edge
            } else {
                smooth_open_edge
            };
            let a: Vec<Point3> = smooth(&pts, &betas).iter().map(tf).collect();
            let b = smooth(&moved, &scaled_betas);
            let diff = max_abs_diff(&a, &b);
            assert!(diff <= 1e-9 * extent, "closed {closed}: {diff}");
            // And the smoothing did something.
            assert!(max_abs_diff(&b, &moved) > 1e-3 * extent);
        }
    }

    /// (f) Degenerate inputs.
    #[test]
    fn degenerate_inputs_do_not_panic() {
        for smooth in [smooth_open_edge, smooth_closed_edge] {
            assert!(smooth(&[], &[]).is_empty());
            let one = [[1.0, 2.0, 3.0]];
            assert_eq!(smooth(&one, &[1.0]), one.to_vec());
            let two = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]];
            assert_eq!(smooth(&two, &[1.0, 1.0]), two.to_vec());
            let same = [[1.0, 2.0, 3.0]; 5];
            assert_eq!(smooth(&same, &[1.0; 5]), same.to_vec());
            // Bad β or mismatched lengths: unchanged.
            let three = [[0.0, 0.0, 0.0], [1.0, 0.5, 0.0], [2.0, 0.0, 0.0]];
            assert_eq!(smooth(&three, &[1.0, 0.0, 1.0]), three.to_vec());
            assert_eq!(smooth(&three, &[1.0, f64::NAN, 1.0]), three.to_vec());
            assert_eq!(smooth(&three, &[1.0, 1.0]), three.to_vec());
            let bad = [[0.0, 0.0, 0.0], [f64::INFINITY, 0.5, 0.0], [2.0, 0.0, 0.0]];
            assert_eq!(smooth(&bad, &[1.0; 3]).len(), 3);
            // Three points, and repeated consecutive points.
            assert_eq!(smooth(&three, &[1.0; 3]).len(), 3);
            let mut rng = SplitMix64::new(9);
            let mut dup = Vec::new();
            for i in 0..60 {
                let p = [i as f64 * 0.5, rng.range(-0.2, 0.2), 0.0];
                for _ in 0..1 + i % 3 {
                    dup.push(p);
                }
            }
            dup.push(dup[dup.len() - 1]);
            let out = smooth(&dup, &vec![1.0; dup.len()]);
            assert_eq!(out.len(), dup.len());
            assert!(out.iter().flatten().all(|v| v.is_finite()));
            for i in 1..dup.len() - 2 {
                if dup[i] == dup[i + 1] {
                    assert_eq!(out[i], out[i + 1]);
                }
            }
            // A tiny step hits the sample cap rather than memory.
            let tiny = [
                [0.0, 0.0, 0.0],
                [1e-30, 0.0, 0.0],
                [5.0, 1.0, 0.0],
                [10.0, 0.0, 0.0],
            ];
            let out = smooth(&tiny, &[1.0; 4]);
            assert_eq!(out.len(), 4);
            assert!(out.iter().flatten().all(|v| v.is_finite()));
        }
        let open = smooth_open_edge(&[[0.0; 3], [1.0, 1.0, 0.0], [0.0; 3]], &[1.0; 3]);
        assert_eq!(open[0], [0.0; 3]);
    }
}
