//! Vector arithmetic on points stored as `[f64; 3]`.

/// A point in 3D, in the cloud's own units (or a vector).
pub type Point3 = [f64; 3];

pub(crate) fn sub(a: Point3, b: Point3) -> Point3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn dot(a: Point3, b: Point3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn cross(a: Point3, b: Point3) -> Point3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn norm2(a: Point3) -> f64 {
    dot(a, a)
}

pub(crate) fn dist2(a: Point3, b: Point3) -> f64 {
    norm2(sub(a, b))
}

pub(crate) fn add(a: Point3, b: Point3) -> Point3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// a + t (b − a).
pub(crate) fn lerp(a: Point3, b: Point3, t: f64) -> Point3 {
    [0, 1, 2].map(|c| a[c] + t * (b[c] - a[c]))
}

/// a + t (b − a), in the plane.
pub(crate) fn lerp2(a: [f64; 2], b: [f64; 2], t: f64) -> [f64; 2] {
    [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
}

pub(crate) fn scale(a: Point3, s: f64) -> Point3 {
    a.map(|c| c * s)
}

/// `a` scaled to unit length (zero stays zero).
pub(crate) fn unit(a: Point3) -> Point3 {
    let l = norm2(a).sqrt();
    if l > 0.0 {
        scale(a, 1.0 / l)
    } else {
        a
    }
}

/// Where the point of the segment from `a` to `b` nearest `p` lies, as a
/// fraction of the way from `a` (0 for a segment of zero length).
pub(crate) fn segment_param(p: Point3, a: Point3, b: Point3) -> f64 {
    let ab = sub(b, a);
    let l2 = norm2(ab);
    if l2 > 0.0 {
        (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Squared distance from `p` to the segment from `a` to `b`.
pub(crate) fn segment_dist2(p: Point3, a: Point3, b: Point3) -> f64 {
    let t = segment_param(p, a, b);
    dist2(p, add(a, scale(sub(b, a), t)))
}

/// The rotation matrix (rows) of the unit quaternion `[w, x, y, z]` (the
/// caller normalises it; a scanner's pose stores one).
pub fn rotation_from_quaternion([w, x, y, z]: [f64; 4]) -> [[f64; 3]; 3] {
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}
