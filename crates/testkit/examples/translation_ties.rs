//! Do the labels move with the cloud? Quantised clouds (coordinates on a
//! grid, as scanners write them) have many exactly equidistant neighbours;
//! far from the origin the coordinates round and those ties turn into
//! near-ties. For each quantum (as a share of the 1.2 pitch) and shift,
//! 100 seeded jittered patches with a hole (flat and saddle in turn) are
//! detected at the origin and shifted along (1, 1, 1), and the labels
//! compared. `ANISO_OFF=1` runs without the anisotropy map.
//!
//! `cargo run --release -p meshtrim-testkit --example translation_ties`

use testkit::synthetic::{jittered_grid, Circle, Region, SpacingField, Surface};
use trim::{detect_boundary, BpdOptions, Point3};

fn main() {
    let options = BpdOptions {
        anisotropy: std::env::var_os("ANISO_OFF").is_none(),
        ..BpdOptions::default()
    };
    println!("| quantum / pitch | shift 1e2 | 1e3 | 1e4 | 1e5 | 1e6 |");
    println!("|---|---|---|---|---|---|");
    for quantum in [0.01, 0.03, 0.05, 0.1, 0.25] {
        let mut row = format!("| {:.3} |", quantum / 1.2);
        for shift in [1e2, 1e3, 1e4, 1e5, 1e6] {
            let (mut differ, mut total) = (0, 0);
            for seed in 0..100u64 {
                let cloud = quantised_patch(seed, quantum);
                let here = detect_boundary(&cloud, &options).expect("valid cloud");
                let moved: Vec<Point3> = cloud.iter().map(|p| p.map(|c| c + shift)).collect();
                let there = detect_boundary(&moved, &options).expect("valid cloud");
                differ += here
                    .boundary
                    .iter()
                    .zip(&there.boundary)
                    .filter(|(a, b)| a != b)
                    .count();
                total += cloud.len();
            }
            row += &format!(" {differ} / {total} |");
        }
        println!("{row}");
    }
}

fn quantised_patch(seed: u64, quantum: f64) -> Vec<Point3> {
    let mut region = Region::rectangle([0.0, 0.0], [20.0, 14.0]);
    region.holes.push(Circle {
        centre: [8.0, 7.0],
        radius: 2.5,
    });
    let surface = if seed.is_multiple_of(2) {
        Surface::Plane
    } else {
        Surface::Saddle { a: 0.004 }
    };
    jittered_grid(&region, SpacingField::Uniform(1.2), 0.15, None, seed)
        .into_iter()
        .map(|(uv, _)| surface.point(uv).map(|c| (c / quantum).round() * quantum))
        .collect()
}
