//! Best-fit plane of a neighbourhood and its 2D projection (section 2 of the
//! paper: "each investigated point and its neighbours are projected to the
//! best fit plane").
//!
//! The plane is the total-least-squares fit (PCA): through the centroid,
//! normal along the covariance eigenvector of the smallest eigenvalue. The
//! projection is expressed in an orthonormal basis (u, v) of the plane with
//! the investigated point at the origin, so distances and angles in the
//! projection are those of the surface to first order.

use nalgebra::Matrix3;

use crate::geom::{dot, sub, Point3};

/// A point in a neighbourhood's plane, relative to the investigated point.
pub type Point2 = [f64; 2];

/// An orthonormal frame: two tangent axes and the normal (all zero by
/// default: a placeholder, not a frame).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Frame {
    /// First tangent axis: the direction of largest spread from
    /// [`fit_plane`], or one fixed by the normal alone.
    pub u: Point3,
    /// Second tangent axis.
    pub v: Point3,
    /// Unit normal of the best-fit plane (smallest spread).
    pub normal: Point3,
}

/// Fits the plane of `members` (indices into `points`) by PCA.
///
/// Degenerate neighbourhoods (all members on a line) still get a frame whose
/// `u` axis follows the line; callers decide what that means.
// Baseline and AVX2 variants, chosen at run time (crate doc, "Vector kernels").
#[multiversion::multiversion(targets("x86_64+avx2"))]
pub fn fit_plane(points: &[Point3], members: &[u32]) -> Frame {
    let (_, [normal, _, u]) = symmetric_eigen3(&covariance(points, members));
    let u = canonical_sign(u);
    let normal = canonical_sign(normal);
    let v = crate::geom::cross(normal, u);
    Frame { u, v, normal }
}

/// [`fit_plane`]'s normal (the same bits) with in-plane axes that follow
/// from the normal alone, not from the spread within the plane: for
/// callers whose use of the plane does not depend on how its axes turn
/// in it, as none of BPD's tests does (distances, angles between members,
/// the sampling tensor and its map all turn with the axes). It skips the
/// eigenvector of the middle eigenvalue, and in the usual case (a flat
/// neighbourhood, whose smallest eigenvalue stands apart) the largest
/// eigenvalue's cosine.
// Baseline and AVX2 variants, chosen at run time (crate doc, "Vector kernels").
#[multiversion::multiversion(targets("x86_64+avx2"))]
pub fn fit_plane_normal(points: &[Point3], members: &[u32]) -> Frame {
    Frame::of_normal(canonical_sign(smallest_eigenvector(&covariance(
        points, members,
    ))))
}

/// The variances of `members`' positions along their principal axes,
/// ascending (the covariance's eigenvalues, divided by the count).
pub fn spread(points: &[Point3], members: &[u32]) -> [f64; 3] {
    let (values, _) = symmetric_eigen3(&covariance(points, members));
    values.map(|v| v.max(0.0) / members.len() as f64)
}

impl Frame {
    /// The frame of the unit `normal` alone: in-plane
    /// axes that follow from the normal's components alone, so a caller
    /// that keeps only the normal gets the same frame, bit for bit.
    pub fn of_normal(normal: Point3) -> Self {
        let (u, v) = orthogonal_complement(normal);
        Frame { u, v, normal }
    }
}

/// The covariance of `members`' positions (unnormalised).
#[inline(always)]
fn covariance(points: &[Point3], members: &[u32]) -> Matrix3<f64> {
    let n = members.len() as f64;
    let origin = points[members[0] as usize];
    // Centre on the first member before summing: keeps precision for clouds
    // far from the origin (a translation of 1e5 units must not change labels).
    let mut sum = [0.0; 3];
    for &m in members {
        let d = sub(points[m as usize], origin);
        for a in 0..3 {
            sum[a] += d[a];
        }
    }
    let mean = sum.map(|c| c / n);
    // The six distinct entries only (nalgebra's d dᵀ would form all nine).
    let mut c = [0.0; 6];
    for &m in members {
        let d = sub(sub(points[m as usize], origin), mean);
        c[0] += d[0] * d[0];
        c[1] += d[0] * d[1];
        c[2] += d[0] * d[2];
        c[3] += d[1] * d[1];
        c[4] += d[1] * d[2];
        c[5] += d[2] * d[2];
    }
    Matrix3::new(c[0], c[1], c[2], c[1], c[3], c[4], c[2], c[4], c[5])
}

/// Eigenvalues (ascending) and unit eigenvectors of a symmetric 3×3 matrix,
/// in closed form: D. Eberly's non-iterative solver ("A Robust Eigensolver
/// for 3 × 3 Symmetric Matrices", Geometric Tools, 2014). The eigenvalues
/// come from the trigonometric solution of the characteristic cubic after
/// scaling and shifting; the eigenvector of the best-separated eigenvalue
/// from the largest cross product of two rows of A − λI, the middle one in
/// that vector's orthogonal complement, the third by a cross product, so
/// the three are orthonormal even when two eigenvalues coincide.
///
/// BPD fits a plane per point, and nalgebra's general iterative solver
/// would take a tenth of its time; [`symmetric_eigen3`] agrees with it
/// (see the tests) in about a third of the time.
pub fn symmetric_eigen3(a: &Matrix3<f64>) -> ([f64; 3], [Point3; 3]) {
    let (rows, shape) = match spectrum(a) {
        Spectrum::Zero => return ([0.0; 3], AXES),
        Spectrum::Diagonal(d, scale) => return diagonal_eigen(d, scale),
        Spectrum::General(rows, shape) => (rows, shape),
    };
    let values = shape.values();
    (
        values.map(|l| l * shape.max_abs),
        eigenvectors(rows, &shape, values),
    )
}

/// The unit eigenvectors of the scaled `rows` with eigenvalues `values`:
/// the best-separated eigenvalue's from cross products, the middle one in
/// its orthogonal complement, the third by a cross product.
fn eigenvectors(rows: [Point3; 3], shape: &Cubic, values: [f64; 3]) -> [Point3; 3] {
    if shape.half_det >= 0.0 {
        let v2 = eigenvector_of_simple(rows, values[2]);
        let v1 = eigenvector_in_complement(rows, v2, values[1]);
        [unit_cross(v1, v2), v1, v2]
    } else {
        let v0 = eigenvector_of_simple(rows, values[0]);
        let v1 = eigenvector_in_complement(rows, v0, values[1]);
        [v0, v1, unit_cross(v0, v1)]
    }
}

/// The unit eigenvector of the smallest eigenvalue: [`symmetric_eigen3`]'s
/// first vector, the same bits, without the others when the smallest
/// eigenvalue is the best separated.
pub fn smallest_eigenvector(a: &Matrix3<f64>) -> Point3 {
    match spectrum(a) {
        Spectrum::Zero => AXES[0],
        Spectrum::Diagonal(d, scale) => diagonal_eigen(d, scale).1[0],
        Spectrum::General(rows, shape) if shape.half_det < 0.0 => {
            eigenvector_of_simple(rows, shape.smallest())
        }
        Spectrum::General(rows, shape) => eigenvectors(rows, &shape, shape.values())[0],
    }
}

const AXES: [Point3; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// A symmetric matrix's spectrum as [`symmetric_eigen3`] solves it.
enum Spectrum {
    /// All zero (or not finite): any axes.
    Zero,
    /// Diagonal entries, scaled to [−1, 1], and the scale.
    Diagonal([f64; 3], f64),
    /// The scaled rows, and the cubic's solution.
    General([Point3; 3], Cubic),
}

/// The trigonometric solution of the characteristic cubic of the scaled
/// matrix: eigenvalue q + p·2cos(angle + 2πj/3).
#[derive(Clone, Copy)]
struct Cubic {
    q: f64,
    p: f64,
    angle: f64,
    half_det: f64,
    max_abs: f64,
}

impl Cubic {
    const TWO_THIRDS_PI: f64 = 2.0 * std::f64::consts::FRAC_PI_3;

    /// The smallest root of the shifted, scaled cubic.
    fn beta0(&self) -> f64 {
        2.0 * (self.angle + Self::TWO_THIRDS_PI).cos()
    }

    /// The smallest eigenvalue of the scaled matrix.
    fn smallest(&self) -> f64 {
        self.q + self.p * self.beta0()
    }

    /// The eigenvalues of the scaled matrix, ascending.
    fn values(&self) -> [f64; 3] {
        let beta2 = 2.0 * self.angle.cos();
        let beta0 = self.beta0();
        let beta1 = -(beta0 + beta2);
        [
            self.q + self.p * beta0,
            self.q + self.p * beta1,
            self.q + self.p * beta2,
        ]
    }
}

/// Scales `a` to entries in [−1, 1] and solves its characteristic cubic.
fn spectrum(a: &Matrix3<f64>) -> Spectrum {
    let max_abs = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if max_abs == 0.0 || !max_abs.is_finite() {
        return Spectrum::Zero;
    }
    // Scaled to entries in [−1, 1] against overflow and underflow.
    let s = 1.0 / max_abs;
    let (a00, a01, a02) = (a[(0, 0)] * s, a[(0, 1)] * s, a[(0, 2)] * s);
    let (a11, a12, a22) = (a[(1, 1)] * s, a[(1, 2)] * s, a[(2, 2)] * s);
    let off_diagonal = a01 * a01 + a02 * a02 + a12 * a12;
    if off_diagonal == 0.0 {
        return Spectrum::Diagonal([a00, a11, a22], max_abs);
    }
    let q = (a00 + a11 + a22) / 3.0;
    let (b00, b11, b22) = (a00 - q, a11 - q, a22 - q);
    let p = ((b00 * b00 + b11 * b11 + b22 * b22 + 2.0 * off_diagonal) / 6.0).sqrt();
    let c00 = b11 * b22 - a12 * a12;
    let c01 = a01 * b22 - a12 * a02;
    let c02 = a01 * a12 - b11 * a02;
    let det = (b00 * c00 - a01 * c01 + a02 * c02) / (p * p * p);
    let half_det = (0.5 * det).clamp(-1.0, 1.0);
    let angle = half_det.acos() / 3.0;
    let rows = [[a00, a01, a02], [a01, a11, a12], [a02, a12, a22]];
    Spectrum::General(
        rows,
        Cubic {
            q,
            p,
            angle,
            half_det,
            max_abs,
        },
    )
}

/// a × b for orthonormal a and b, renormalised so that rounding does not
/// leave it a few ulps off unit length (an axis comes out exact).
fn unit_cross(a: Point3, b: Point3) -> Point3 {
    let c = crate::geom::cross(a, b);
    let length = dot(c, c).sqrt();
    c.map(|x| x / length)
}

fn diagonal_eigen(d: [f64; 3], scale: f64) -> ([f64; 3], [Point3; 3]) {
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| d[i].total_cmp(&d[j]));
    let axis = |i: usize| {
        let mut e = [0.0; 3];
        e[i] = 1.0;
        e
    };
    (order.map(|i| d[i] * scale), order.map(axis))
}

/// Unit eigenvector of an eigenvalue well separated from the other two:
/// the rows of A − λI span a plane whose normal it is; the largest of the
/// rows' three cross products is the best-conditioned normal.
fn eigenvector_of_simple(rows: [Point3; 3], value: f64) -> Point3 {
    let mut r = rows;
    for (i, row) in r.iter_mut().enumerate() {
        row[i] -= value;
    }
    let candidates = [
        crate::geom::cross(r[0], r[1]),
        crate::geom::cross(r[0], r[2]),
        crate::geom::cross(r[1], r[2]),
    ];
    let (best, length2) = candidates
        .iter()
        .map(|c| (c, dot(*c, *c)))
        .fold((&candidates[0], -1.0), |b, c| if c.1 > b.1 { c } else { b });
    if length2 <= 0.0 {
        // A − λI = 0: every vector is an eigenvector.
        return [1.0, 0.0, 0.0];
    }
    // Division, not a reciprocal's product: an axis comes out exactly unit.
    let length = length2.sqrt();
    best.map(|c| c / length)
}

/// Unit eigenvector of `value` orthogonal to the unit eigenvector `w`:
/// the 2×2 problem of A − λI restricted to w's orthogonal complement.
fn eigenvector_in_complement(rows: [Point3; 3], w: Point3, value: f64) -> Point3 {
    let (u, v) = orthogonal_complement(w);
    let times = |x: Point3| [dot(rows[0], x), dot(rows[1], x), dot(rows[2], x)];
    let (au, av) = (times(u), times(v));
    let m00 = dot(u, au) - value;
    let m01 = dot(u, av);
    let m11 = dot(v, av) - value;
    let combine = |(a, b): (f64, f64)| [0, 1, 2].map(|i| a * u[i] - b * v[i]);
    // The null vector of the 2×2 matrix is orthogonal to its larger row.
    if m00.abs().max(m01.abs()) >= m11.abs() {
        if m00 == 0.0 && m01 == 0.0 {
            return u;
        }
        let (c, s) = unit_pair(m00, m01);
        combine((s, c))
    } else {
        let (c, s) = unit_pair(m11, m01);
        combine((c, s))
    }
}

/// (x, y) scaled to unit length with the sign of its larger component,
/// dividing by that component first so that nothing overflows.
fn unit_pair(x: f64, y: f64) -> (f64, f64) {
    if x.abs() >= y.abs() {
        let t = y / x;
        let c = 1.0 / (1.0 + t * t).sqrt();
        (c, t * c)
    } else {
        let t = x / y;
        let s = 1.0 / (1.0 + t * t).sqrt();
        (t * s, s)
    }
}

/// An orthonormal basis (u, v) of the plane orthogonal to the unit `w`.
fn orthogonal_complement(w: Point3) -> (Point3, Point3) {
    let u = if w[0].abs() > w[1].abs() {
        let length = (w[0] * w[0] + w[2] * w[2]).sqrt();
        [-w[2] / length, 0.0, w[0] / length]
    } else {
        let length = (w[1] * w[1] + w[2] * w[2]).sqrt();
        [0.0, w[2] / length, -w[1] / length]
    };
    (u, crate::geom::cross(w, u))
}

/// Flips a unit vector so its largest component is positive, so the frame
/// does not depend on the eigen solver's arbitrary sign.
fn canonical_sign(a: Point3) -> Point3 {
    let big = (0..3)
        .max_by(|&i, &j| a[i].abs().total_cmp(&a[j].abs()))
        .unwrap_or(0);
    let signed = if a[big] < 0.0 { a.map(|c| -c) } else { a };
    // + 0.0 turns −0.0 into 0.0, so equal frames compare equal.
    signed.map(|c| c + 0.0)
}

/// Projects `members` onto the frame's plane, relative to `points[members[0]]`.
// Baseline and AVX2 variants, chosen at run time (crate doc, "Vector kernels").
#[multiversion::multiversion(targets("x86_64+avx2"))]
pub fn project(points: &[Point3], members: &[u32], frame: &Frame, out: &mut Vec<Point2>) {
    out.clear();
    let origin = points[members[0] as usize];
    out.extend(members.iter().map(|&m| {
        let d = sub(points[m as usize], origin);
        [dot(d, frame.u), dot(d, frame.v)]
    }));
}

/// Steepest incidence of a scanner's ray on a neighbourhood's plane that
/// [`ray_shear`] follows, 70° from the normal: beyond it the ray is
/// treated as if at 70°. Near grazing incidence, a projection along the
/// ray multiplies every height above the fitted plane (curvature, noise
/// across the ray) by tan θ (2.7 at 70°, 11 at 85°) into the plane, and
/// at 90° it has no answer; scanners measure little there anyway.
pub(crate) const MAX_INCIDENCE_DEGREES: f64 = 70.0;

/// The shear that projects a neighbourhood onto its plane along `ray`
/// (a scanner's line of sight, either sense) instead of along the normal.
///
/// Along the ray, an offset d lands on the plane at d − (d·n / r·n) r,
/// whose plane coordinates are (d·u − s_u h, d·v − s_v h) with h = d·n and
/// s = (r·u, r·v) / (r·n): the in-plane shift per unit of height. It is
/// (0, 0) when the ray is the normal; its length tan θ (θ the incidence)
/// is capped at tan [`MAX_INCIDENCE_DEGREES`], keeping its direction.
pub fn ray_shear(frame: &Frame, ray: Point3) -> [f64; 2] {
    let ray = moderate(ray);
    let (along_u, along_v, along_n) =
        (dot(ray, frame.u), dot(ray, frame.v), dot(ray, frame.normal));
    let tangential = along_u.hypot(along_v);
    if tangential == 0.0 {
        return [0.0, 0.0];
    }
    let cap = MAX_INCIDENCE_DEGREES.to_radians().tan();
    let tan_incidence = tangential / along_n.abs();
    // Also the answer for a ray in the plane (r·n = 0: tan θ = ∞).
    let length = if tan_incidence < cap {
        tan_incidence
    } else {
        cap
    };
    let sense = if along_n < 0.0 { -1.0 } else { 1.0 };
    [
        sense * length * along_u / tangential,
        sense * length * along_v / tangential,
    ]
}

/// `v` scaled by powers of two until its largest |component| lies in
/// [2⁻⁶⁴, 2⁶⁴). Only the ray's direction matters, and the user gives its
/// length (`--view-along 1e308,1e308,1e308`, or a `--view-from` far away):
/// at 1e308 the shear's `length * along_u` overflowed to infinity, and
/// subnormal components lose their bits in the products. A power of two
/// scales exactly, so a ray already in range is left as it is and any
/// other gets the shear of the same direction at unit size, bit for bit.
fn moderate(mut v: Point3) -> Point3 {
    const BIG: f64 = 18_446_744_073_709_551_616.0; // 2^64
                                                   // Found once per ray (which runs for every point) and scaled with the
                                                   // vector, exactly, since BIG is a power of two.
    let mut largest = v.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    while largest >= BIG && largest.is_finite() {
        v = v.map(|c| c / BIG);
        largest /= BIG;
    }
    while largest > 0.0 && largest < 1.0 / BIG {
        v = v.map(|c| c * BIG);
        largest *= BIG;
    }
    v
}

/// [`project`] along a scanner's ray: `shear` from [`ray_shear`]. With a
/// zero shear it is [`project`], bit for bit.
pub fn project_sheared(
    points: &[Point3],
    members: &[u32],
    frame: &Frame,
    shear: [f64; 2],
    out: &mut Vec<Point2>,
) {
    if shear == [0.0, 0.0] {
        return project(points, members, frame, out);
    }
    out.clear();
    let origin = points[members[0] as usize];
    out.extend(members.iter().map(|&m| {
        let d = sub(points[m as usize], origin);
        let height = dot(d, frame.normal);
        [
            dot(d, frame.u) - shear[0] * height,
            dot(d, frame.v) - shear[1] * height,
        ]
    }));
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{SymmetricEigen, Vector3};
    use rand::{RngExt, SeedableRng};

    /// Random symmetric matrices Q diag(λ) Qᵀ with awkward spectra: equal,
    /// nearly equal, zero and widely spread eigenvalues, scales 1e-8..1e8.
    fn awkward_matrix(rng: &mut rand_chacha::ChaCha8Rng) -> Matrix3<f64> {
        let q = nalgebra::Rotation3::from_axis_angle(
            &Vector3::new(rng.random(), rng.random(), rng.random::<f64>() - 0.5)
                .try_normalize(1e-9)
                .map_or(Vector3::z_axis(), nalgebra::Unit::new_unchecked),
            rng.random_range(0.0..6.3),
        );
        let scale = 10f64.powf(rng.random_range(-8.0..8.0));
        let base: f64 = rng.random_range(0.1..1.0);
        let mut l = [base, rng.random_range(0.0..1.0), rng.random_range(0.0..1.0)];
        match rng.random_range(0..6) {
            0 => l[1] = l[0],                 // double eigenvalue
            1 => l = [l[0]; 3],               // a multiple of I
            2 => l[2] = 0.0,                  // a plane
            3 => (l[1], l[2]) = (0.0, 0.0),   // a line
            4 => l[1] = l[0] * (1.0 + 1e-10), // nearly double
            _ => l[2] = l[0] * 1e-12,         // nearly a plane
        }
        let d = Matrix3::from_diagonal(&Vector3::from(l.map(|x| x * scale)));
        let m = q.matrix() * d * q.matrix().transpose();
        (m + m.transpose()) * 0.5
    }

    /// The closed form agrees with nalgebra's iterative solver: the same
    /// eigenvalues, orthonormal vectors with small residuals, and the same
    /// vector (up to sign) wherever its eigenvalue is well separated.
    #[test]
    fn closed_form_eigen_matches_nalgebra() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for case in 0..20_000 {
            let a = awkward_matrix(&mut rng);
            let (values, vectors) = symmetric_eigen3(&a);
            let reference = SymmetricEigen::new(a);
            let mut want: Vec<(f64, Point3)> = (0..3)
                .map(|i| {
                    let c = reference.eigenvectors.column(i);
                    (reference.eigenvalues[i], [c[0], c[1], c[2]])
                })
                .collect();
            want.sort_by(|x, y| x.0.total_cmp(&y.0));
            let size = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for i in 0..3 {
                // The trigonometric solution loses half the digits of
                // eigenvalues that nearly coincide (their vectors are
                // then nearly arbitrary in a common plane anyway); a
                // separated eigenvalue and its vector are exact to rounding.
                let gap = (0..3)
                    .filter(|&j| j != i)
                    .map(|j| (want[j].0 - want[i].0).abs())
                    .fold(f64::INFINITY, f64::min);
                let separated = gap > 1e-3 * size;
                let tolerance = if separated { 1e-12 } else { 1e-7 } * size;
                assert!(
                    (values[i] - want[i].0).abs() <= tolerance,
                    "case {case}: {values:?} vs {want:?}"
                );
                let e = vectors[i];
                for (j, &other) in vectors.iter().enumerate() {
                    let expected = if i == j { 1.0 } else { 0.0 };
                    assert!((dot(e, other) - expected).abs() < 1e-12, "case {case}");
                }
                let ae = a * Vector3::from(e);
                let residual = (ae - Vector3::from(e) * values[i]).norm();
                assert!(residual <= tolerance, "case {case}: residual {residual:e}");
                if separated {
                    let agree = dot(e, want[i].1).abs();
                    assert!(
                        (agree - 1.0).abs() < 1e-9,
                        "case {case}: {e:?} vs {:?}",
                        want[i].1
                    );
                }
            }
        }
    }

    /// Edge cases: zero, diagonal, non-finite input gives no NaN vectors.
    /// The smallest eigenvector alone is the full solver's first vector,
    /// bit for bit, on the awkward matrices, zero and diagonal ones.
    #[test]
    fn smallest_eigenvector_is_the_solvers_first() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let mut cases: Vec<Matrix3<f64>> = (0..20_000).map(|_| awkward_matrix(&mut rng)).collect();
        cases.push(Matrix3::zeros());
        cases.push(Matrix3::from_diagonal(&Vector3::new(3.0, 1.0, 2.0)));
        for (case, a) in cases.iter().enumerate() {
            let want = symmetric_eigen3(a).1[0];
            assert_eq!(
                smallest_eigenvector(a).map(f64::to_bits),
                want.map(f64::to_bits),
                "case {case}"
            );
        }
    }

    /// The shear depends on the ray's direction only, not its length, bit
    /// for bit: `--view-along 1e308,1e308,1e308` must not overflow the
    /// shear to infinity (an infinite shear finds 1012 boundary points on
    /// the blade fixture instead of 311 along 1,1,1), nor a ray of
    /// subnormal components lose its bits.
    #[test]
    fn the_shear_ignores_the_length_of_the_ray() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for case in 0..200 {
            let points: Vec<Point3> = (0..12)
                .map(|_| std::array::from_fn(|a| rng.random_range(-1.0..1.0) * [1.0, 1.0, 0.1][a]))
                .collect();
            let frame = fit_plane_normal(&points, &(0..12).collect::<Vec<u32>>());
            let ray: Point3 = std::array::from_fn(|_| f64::from(rng.random_range(-8i8..=8)));
            if ray == [0.0; 3] {
                continue;
            }
            let want = ray_shear(&frame, ray).map(f64::to_bits);
            for scale in [
                2f64.powi(1020),
                2f64.powi(-1066),
                2f64.powi(-1000) * 2f64.powi(-70),
            ] {
                let got = ray_shear(&frame, ray.map(|c| c * scale));
                assert_eq!(
                    got.map(f64::to_bits),
                    want,
                    "case {case}: {ray:?} × {scale:e}"
                );
            }
        }
    }

    /// Projected along a ray, a point moved along that ray lands where it
    /// was (up to the incidence cap); a zero shear is the plain projection,
    /// bit for bit; beyond the cap the shear keeps its direction and has
    /// length tan 70°.
    #[test]
    fn points_moved_along_the_ray_project_where_they_were() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let cap = MAX_INCIDENCE_DEGREES.to_radians().tan();
        for case in 0..2_000 {
            let points: Vec<Point3> = (0..12)
                .map(|_| {
                    let z = 0.05 * rng.random_range(-1.0..1.0);
                    [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), z]
                })
                .collect();
            let members: Vec<u32> = (0..12).collect();
            let frame = fit_plane_normal(&points, &members);
            let incidence = rng.random_range(0.0..1.5f64);
            let turn = rng.random_range(0.0..std::f64::consts::TAU);
            let sense = if case % 2 == 0 { 1.0 } else { -1.0 };
            let (sin, cos) = incidence.sin_cos();
            let ray: Point3 = std::array::from_fn(|a| {
                sense
                    * (cos * frame.normal[a]
                        + sin * (turn.cos() * frame.u[a] + turn.sin() * frame.v[a]))
            });
            let shear = ray_shear(&frame, ray);
            let length = shear[0].hypot(shear[1]);
            if incidence.tan() > cap {
                assert!((length - cap).abs() < 1e-9, "case {case}: {length}");
                continue;
            }
            assert!((length - incidence.tan()).abs() < 1e-9, "case {case}");
            let mut still = Vec::new();
            project_sheared(&points, &members, &frame, shear, &mut still);
            let moved: Vec<Point3> = points
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    let t = if i == 0 {
                        0.0
                    } else {
                        rng.random_range(-0.5..0.5)
                    };
                    std::array::from_fn(|a| p[a] + t * ray[a])
                })
                .collect();
            let mut seen = Vec::new();
            project_sheared(&moved, &members, &frame, shear, &mut seen);
            for (a, b) in still.iter().zip(&seen) {
                assert!(
                    (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12,
                    "case {case}"
                );
            }
            let mut plain = Vec::new();
            project(&moved, &members, &frame, &mut plain);
            let mut unsheared = Vec::new();
            project_sheared(&moved, &members, &frame, [0.0, 0.0], &mut unsheared);
            assert_eq!(plain, unsheared, "case {case}");
        }
    }

    /// BPD's frame has fit_plane's normal, bit for bit, and orthonormal
    /// in-plane axes with v = n × u.
    #[test]
    fn normal_frame_shares_the_normal() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(10);
        for case in 0..2_000 {
            let points: Vec<Point3> = (0..30)
                .map(|_| {
                    let (x, y) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                    let z = [0.0, 0.01, 0.3][case % 3] * rng.random_range(-1.0..1.0);
                    [x + 0.2 * y, y - 0.5 * z, z + 0.4 * x]
                })
                .collect();
            let members: Vec<u32> = (0..30).collect();
            let full = fit_plane(&points, &members);
            let frame = fit_plane_normal(&points, &members);
            assert_eq!(frame.normal, full.normal, "case {case}");
            let n = frame.normal;
            for (a, b, want) in [
                (frame.u, frame.u, 1.0),
                (frame.v, frame.v, 1.0),
                (frame.u, frame.v, 0.0),
                (frame.u, n, 0.0),
                (frame.v, n, 0.0),
            ] {
                assert!((dot(a, b) - want).abs() < 1e-12, "case {case}");
            }
            let n_cross_u = crate::geom::cross(n, frame.u);
            assert!(
                (0..3).all(|i| (n_cross_u[i] - frame.v[i]).abs() < 1e-12),
                "case {case}"
            );
        }
    }

    #[test]
    fn closed_form_eigen_edge_cases() {
        let (values, vectors) = symmetric_eigen3(&Matrix3::zeros());
        assert_eq!(values, [0.0; 3]);
        assert_eq!(vectors[2], [0.0, 0.0, 1.0]);
        let d = Matrix3::from_diagonal(&Vector3::new(3.0, 1.0, 2.0));
        let (values, vectors) = symmetric_eigen3(&d);
        assert_eq!(values, [1.0, 2.0, 3.0]);
        assert_eq!(vectors, [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]);
    }

    #[test]
    fn plane_of_a_tilted_grid_has_its_normal() {
        let n = [1.0, 2.0, 2.0].map(|c: f64| c / 3.0);
        let a = [2.0 / 3.0, 1.0 / 3.0, -2.0 / 3.0];
        let b = crate::geom::cross(n, a);
        let pts: Vec<Point3> = (0..25)
            .map(|i| {
                let (s, t) = ((i % 5) as f64, (i / 5) as f64 * 0.7);
                [0, 1, 2].map(|k| 100.0 + s * a[k] + t * b[k])
            })
            .collect();
        let members: Vec<u32> = (0..25).collect();
        let f = fit_plane(&pts, &members);
        assert!((dot(f.normal, n).abs() - 1.0).abs() < 1e-12);
        let mut q = Vec::new();
        project(&pts, &members, &f, &mut q);
        // Projection preserves in-plane distances.
        let d3 = crate::geom::dist2(pts[3], pts[17]).sqrt();
        let d2 = ((q[3][0] - q[17][0]).powi(2) + (q[3][1] - q[17][1]).powi(2)).sqrt();
        assert!((d3 - d2).abs() < 1e-12);
    }
}
