//! Best-fit plane of a neighbourhood and its 2D projection (section 2 of the
//! paper: "each investigated point and its neighbours are projected to the
//! best fit plane").
//!
//! The plane is the total-least-squares fit (PCA): through the centroid,
//! normal along the covariance eigenvector of the smallest eigenvalue. The
//! projection is expressed in an orthonormal basis (u, v) of the plane with
//! the investigated point at the origin, so distances and angles in the
//! projection are those of the surface to first order.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

use crate::cloud::{dot, sub, Point3};

/// A point in a neighbourhood's plane, relative to the investigated point.
pub type Point2 = [f64; 2];

/// An orthonormal frame: two tangent axes and the normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// First tangent axis (largest spread).
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
pub fn fit_plane(points: &[Point3], members: &[u32]) -> Frame {
    let n = members.len() as f64;
    let origin = points[members[0] as usize];
    // Centre on the first member before summing: keeps precision for clouds
    // far from the origin (a translation of 1e5 units must not change labels).
    let mut mean = [0.0; 3];
    for &m in members {
        let d = sub(points[m as usize], origin);
        for a in 0..3 {
            mean[a] += d[a] / n;
        }
    }
    let mut cov = Matrix3::<f64>::zeros();
    for &m in members {
        let d = sub(sub(points[m as usize], origin), mean);
        let d = Vector3::from(d);
        cov += d * d.transpose();
    }
    let eig = SymmetricEigen::new(cov);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let axis = |i: usize| {
        let c = eig.eigenvectors.column(order[i]);
        [c[0], c[1], c[2]]
    };
    let u = canonical_sign(axis(0));
    let normal = canonical_sign(axis(2));
    let v = crate::cloud::cross(normal, u);
    Frame { u, v, normal }
}

/// Flips a unit vector so its largest component is positive, so the frame
/// does not depend on the eigen solver's arbitrary sign.
fn canonical_sign(a: Point3) -> Point3 {
    let big = (0..3)
        .max_by(|&i, &j| a[i].abs().total_cmp(&a[j].abs()))
        .unwrap_or(0);
    if a[big] < 0.0 {
        [-a[0], -a[1], -a[2]]
    } else {
        a
    }
}

/// Projects `members` onto the frame's plane, relative to `points[members[0]]`.
pub fn project(points: &[Point3], members: &[u32], frame: &Frame, out: &mut Vec<Point2>) {
    out.clear();
    let origin = points[members[0] as usize];
    out.extend(members.iter().map(|&m| {
        let d = sub(points[m as usize], origin);
        [dot(d, frame.u), dot(d, frame.v)]
    }));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_of_a_tilted_grid_has_its_normal() {
        let n = [1.0, 2.0, 2.0].map(|c: f64| c / 3.0);
        let a = [2.0 / 3.0, 1.0 / 3.0, -2.0 / 3.0];
        let b = crate::cloud::cross(n, a);
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
        let d3 = crate::cloud::dist2(pts[3], pts[17]).sqrt();
        let d2 = ((q[3][0] - q[17][0]).powi(2) + (q[3][1] - q[17][1]).powi(2)).sqrt();
        assert!((d3 - d2).abs() < 1e-12);
    }
}
