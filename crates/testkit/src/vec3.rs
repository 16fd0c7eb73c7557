//! Vector arithmetic on `[f64; 3]` points.

use trim::Point3;

pub fn sub(a: Point3, b: Point3) -> Point3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn dot(a: Point3, b: Point3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: Point3, b: Point3) -> Point3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub fn norm2(a: Point3) -> f64 {
    dot(a, a)
}

pub fn dist2(a: Point3, b: Point3) -> f64 {
    norm2(sub(a, b))
}
