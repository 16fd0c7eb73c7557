//! Orientation and segment-intersection predicates in the plane.
//!
//! Decisions (does a loop cross itself, do two segments meet) take the
//! exact sign of the orientation determinant, from Shewchuk's adaptive
//! predicate (the `robust` crate, the one spade uses): collinear is
//! collinear and crossing is crossing, whatever the rounding of the plain
//! determinant. [`orient`] keeps the plain value where it is an area.

/// Twice the signed area of the triangle abc: positive when a, b, c run
/// counter-clockwise.
pub(crate) fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// The exact sign of [`orient`]: 1 counter-clockwise, −1 clockwise, 0
/// collinear.
pub(crate) fn orientation(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    let coord = |p: [f64; 2]| robust::Coord { x: p[0], y: p[1] };
    let det = robust::orient2d(coord(a), coord(b), coord(c));
    if det > 0.0 {
        1.0
    } else if det < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// True if closed segments ab and cd share a point (exact).
pub(crate) fn segments_meet(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let (d1, d2) = (orientation(c, d, a), orientation(c, d, b));
    let (d3, d4) = (orientation(a, b, c), orientation(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let within = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        r[0] >= p[0].min(q[0])
            && r[0] <= p[0].max(q[0])
            && r[1] >= p[1].min(q[1])
            && r[1] <= p[1].max(q[1])
    };
    (d1 == 0.0 && within(c, d, a))
        || (d2 == 0.0 && within(c, d, b))
        || (d3 == 0.0 && within(a, b, c))
        || (d4 == 0.0 && within(a, b, d))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// The exact sign agrees with the plain determinant wherever that is
    /// far from zero, and decides the near-collinear cases the plain one
    /// gets wrong: a point a hair off a long line.
    #[test]
    fn orientation_is_exact() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for _ in 0..10_000 {
            let p = [0; 3].map(|_| [rng.random_range(-1e3..1e3), rng.random_range(-1e3..1e3)]);
            let plain = orient(p[0], p[1], p[2]);
            if plain.abs() > 1e-6 {
                assert_eq!(orientation(p[0], p[1], p[2]), plain.signum());
            }
        }
        // On the line y = x, 0.5 + 1e-16 rounds to 0.5 in the plain
        // determinant's products but not in the exact one.
        let (a, b) = ([0.1, 0.1], [1e8 + 0.1, 1e8 + 0.1]);
        assert_eq!(orientation(a, b, [0.7, 0.7]), 0.0);
        assert_eq!(orientation(a, b, [0.7, 0.7000000000000001]), 1.0);
        assert_eq!(orientation(a, b, [0.7, 0.6999999999999998]), -1.0);
    }

    #[test]
    fn segments_meet_at_crossings_ends_and_overlaps() {
        assert!(segments_meet(
            [0.0, 0.0],
            [2.0, 2.0],
            [0.0, 2.0],
            [2.0, 0.0]
        ));
        assert!(segments_meet(
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 0.0],
            [1.0, 5.0]
        ));
        assert!(segments_meet(
            [0.0, 0.0],
            [3.0, 0.0],
            [1.0, 0.0],
            [2.0, 0.0]
        ));
        assert!(!segments_meet(
            [0.0, 0.0],
            [1.0, 0.0],
            [2.0, 0.0],
            [3.0, 0.0]
        ));
        assert!(!segments_meet(
            [0.0, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
            [0.4, 0.6 + 1e-9]
        ));
    }
}
