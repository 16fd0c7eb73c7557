//! Generates `fixtures/meshes/blade_holes.ply`: a twisted, cambered
//! blade-like surface with three round holes, sampled on a jittered grid.
//!
//! Run from the repository root:
//! `cargo run --release --example make_fixtures`. The output is the same
//! byte for byte on every run (fixed seed, own PRNG, exact binary floats).
//! fixtures/meshes/README.md describes the result.

use std::f64::consts::PI;
use std::path::Path;

use meshtrim::io::{atomic::write_atomic, ply, Point3};

/// Span (along u) and chord (along v) of the blade, in mm.
const SPAN: f64 = 120.0;
const CHORD: f64 = 40.0;
/// Grid spacing before jitter, in mm.
const SPACING: f64 = 0.8;
/// Jitter, as a fraction of the spacing, in each of u and v.
const JITTER: f64 = 0.3;
/// Twist from root to tip, in degrees.
const TWIST_DEG: f64 = 30.0;
/// Camber: height of the chord-wise arc at mid-chord, in mm.
const CAMBER: f64 = 3.0;
/// Holes as (u, v, radius) in mm, in the (u, v) parameter plane.
const HOLES: [(f64, f64, f64); 3] = [(30.0, 0.0, 3.0), (65.0, 8.0, 5.0), (95.0, -6.0, 8.0)];
const SEED: u64 = 0x6d65_7368_7472_696d; // "meshtrim"

/// SplitMix64: tiny, seedable and fully specified, so the fixture does not
/// depend on another crate's generator staying the same.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [-1, 1).
    fn symmetric(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// The surface point at parameters (u, v): a cambered strip twisted about
/// the span axis.
fn blade(u: f64, v: f64) -> Point3 {
    let t = 2.0 * v / CHORD;
    let camber = CAMBER * (1.0 - t * t);
    let angle = TWIST_DEG * PI / 180.0 * u / SPAN;
    let (s, c) = angle.sin_cos();
    [u, v * c - camber * s, v * s + camber * c]
}

fn in_hole(u: f64, v: f64) -> bool {
    HOLES
        .iter()
        .any(|&(hu, hv, r)| (u - hu).powi(2) + (v - hv).powi(2) < r * r)
}

/// Jittered grid samples of the blade, holes left out, in grid order.
fn sample() -> Vec<Point3> {
    let mut rng = SplitMix64(SEED);
    let nu = (SPAN / SPACING).round() as usize + 1;
    let nv = (CHORD / SPACING).round() as usize + 1;
    let mut points = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            // Jitter stays inside the strip so the outer border is straight.
            let u = (i as f64 * SPACING + JITTER * SPACING * rng.symmetric()).clamp(0.0, SPAN);
            let v = (j as f64 * SPACING - CHORD / 2.0 + JITTER * SPACING * rng.symmetric())
                .clamp(-CHORD / 2.0, CHORD / 2.0);
            if !in_hole(u, v) {
                points.push(blade(u, v));
            }
        }
    }
    points
}

fn main() -> anyhow::Result<()> {
    let points = sample();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/meshes/blade_holes.ply");
    let comment = "blade_holes: twisted blade 120 x 40 mm, 3 holes; examples/make_fixtures.rs";
    write_atomic(&path, |w| ply::write_points(w, &points, comment))?;
    println!("{}: {} points", path.display(), points.len());
    Ok(())
}
