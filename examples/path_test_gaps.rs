//! The largest empty angular gap round the points that BPD's empty-circle
//! test leaves to the surrounding-path test, on the blades of the sampling
//! sweep (4, 8, 16, 34 mm; ten samplings each, decimated and jittered
//! lattice; noise-free and with 25, 50, 75 % noise along the normal): the
//! point's neighbourhood (k = 30) projected on its plane, the widest angle
//! between consecutive neighbours as seen from the point. Points more than
//! one spacing from the true border are interior, border points those of
//! the ideal first layer. The path test's rule that a point with no gap of
//! 60° or more is surrounded (docs/bpd.md) is measured here: how wide the
//! interior points' gaps get, and how many border points it concerns.
//!
//! `cargo run --release --example path_test_gaps`

use testkit::evaluate::ideal_first_layer;
use testkit::synthetic::{self, BoundaryIndex, SyntheticCloud};
use trim::{detect_boundary, fit_plane, BpdOptions, Decision, NeighbourIndex};

/// The widest angle (degrees) between consecutive neighbours round
/// `members[0]`, in the plane of `members`.
fn largest_gap_degrees(points: &[[f64; 3]], members: &[u32]) -> f64 {
    let frame = fit_plane(points, members);
    let mut projected = Vec::new();
    trim::internals::project(points, members, &frame, &mut projected);
    let mut angles: Vec<f64> = projected[1..]
        .iter()
        .filter(|p| p[0] != 0.0 || p[1] != 0.0)
        .map(|p| p[1].atan2(p[0]))
        .collect();
    angles.sort_by(f64::total_cmp);
    let wrap = angles[0] + std::f64::consts::TAU - angles[angles.len() - 1];
    let inner = angles.windows(2).map(|w| w[1] - w[0]);
    inner.fold(wrap, f64::max).to_degrees()
}

/// Largest gap over interior points, and border points' gaps; the gaps
/// of the points the path test labels boundary, within a spacing of the
/// border and deeper.
#[derive(Default)]
struct Gaps {
    interior_max: f64,
    interior: usize,
    border: Vec<f64>,
    open_near: Vec<f64>,
    open_deep: Vec<f64>,
}

fn measure(cloud: &SyntheticCloud, noise: f64, gaps: &mut Gaps) {
    let points = if noise == 0.0 {
        cloud.points.clone()
    } else {
        cloud.with_noise(noise, 7)
    };
    let index = BoundaryIndex::new(cloud);
    let first_layer = ideal_first_layer(cloud);
    let decision = detect_boundary(&points, &BpdOptions::default())
        .expect("a synthetic blade is a valid cloud")
        .decision;
    let neighbours = NeighbourIndex::new(&points);
    let mut members = Vec::new();
    for i in 0..points.len() {
        if decision[i] == Decision::EmptyCircle {
            continue;
        }
        neighbours.nearest(i, 30, &mut members);
        let gap = largest_gap_degrees(&points, &members);
        let deep = index.distance(cloud.points[i]) > cloud.spacing[i];
        if decision[i] == Decision::OpenPath {
            if deep {
                &mut gaps.open_deep
            } else {
                &mut gaps.open_near
            }
            .push(gap);
        }
        if first_layer[i] {
            gaps.border.push(gap);
        } else if deep {
            gaps.interior_max = gaps.interior_max.max(gap);
            gaps.interior += 1;
        }
    }
}

/// A sampling of the blade at a resolution (mm) and seed.
type Blade = fn(f64, u64) -> SyntheticCloud;

/// "n (min–max°)", or "0".
fn range(gaps: &[f64]) -> String {
    if gaps.is_empty() {
        return "0".into();
    }
    let lo = gaps.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = gaps.iter().copied().fold(0.0, f64::max);
    format!("{} ({lo:.0}–{hi:.0}°)", gaps.len())
}

fn main() {
    println!("| sampling | interior points left to the path test | their largest gap | border points left to it | their smallest gap | border points left to it with a gap below 60° | labelled by the path test: within a spacing (gaps) | deeper (gaps) |");
    println!("|---|---:|---:|---:|---:|---:|---|---|");
    let generators: [(&str, Blade); 2] = [
        ("decimated", synthetic::decimated_blade),
        ("jittered lattice", synthetic::blade),
    ];
    for (name, blade) in generators {
        let mut gaps = Gaps::default();
        for h in [4.0, 8.0, 16.0, 34.0] {
            for seed in 1..=10 {
                let cloud = blade(h, seed);
                for noise in [0.0, 0.25, 0.5, 0.75] {
                    measure(&cloud, noise, &mut gaps);
                }
            }
        }
        let smallest = gaps.border.iter().copied().fold(f64::INFINITY, f64::min);
        let below = gaps.border.iter().filter(|&&g| g < 60.0).count();
        println!(
            "| {name} | {} | {:.1}° | {} | {:.1}° | {below} | {} | {} |",
            gaps.interior,
            gaps.interior_max,
            gaps.border.len(),
            smallest,
            range(&gaps.open_near),
            range(&gaps.open_deep),
        );
    }
}
