//! How often edge reconstruction finds exactly the true number of borders
//! on seeded synthetic clouds (every border one loop, no extra loop).
//!
//! `cargo run --release -p meshtrim-testkit --example loop_counts [SEEDS]`
//!
//! One row per kind of cloud: how many of SEEDS sampling seeds (default 20;
//! seeds 1000, 1001, …) gave the true loop count, and the counts that came
//! out otherwise, each with its seeds.

use std::collections::BTreeMap;

use testkit::synthetic::{self, SyntheticCloud};
use trim::{detect_boundary, reconstruct_edges, BpdOptions, EdgeOptions};

type Maker = Box<dyn Fn(u64) -> SyntheticCloud>;

fn main() {
    let seeds: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    let kinds: Vec<(&str, Maker)> = vec![
        (
            "plane, holes 2β/4β/8β",
            Box::new(|s| synthetic::plane_with_holes(1.0, s)),
        ),
        (
            "notched plate",
            Box::new(|s| synthetic::notched_plate(1.0, s)),
        ),
        (
            "saddle with hole",
            Box::new(|s| synthetic::saddle_with_hole(1.0, s)),
        ),
        (
            "curved disc with hole",
            Box::new(|s| synthetic::curved_disc_with_hole(1.5, s)),
        ),
        (
            "cylinder with hole",
            Box::new(|s| synthetic::cylinder_with_hole(1.0, s)),
        ),
        ("blade 1 mm", Box::new(|s| synthetic::blade(1.0, s))),
        (
            "blade 1 mm, jitter ±0.3",
            Box::new(|s| synthetic::blade_with_jitter(1.0, 0.3, s)),
        ),
        ("blade 4 mm", Box::new(|s| synthetic::blade(4.0, s))),
        ("blade 16 mm", Box::new(|s| synthetic::blade(16.0, s))),
        (
            "variable density 3.4–34 mm",
            Box::new(|s| synthetic::variable_density(3.4, s)),
        ),
        (
            "line scan 1:2, 20°",
            Box::new(|s| synthetic::line_scan(2.0, 0.35, 1.0, s)),
        ),
        (
            "line scan 1:3, 20°",
            Box::new(|s| synthetic::line_scan(3.0, 0.35, 1.0, s)),
        ),
        (
            "line scan 1:4, 20°",
            Box::new(|s| synthetic::line_scan(4.0, 0.35, 1.0, s)),
        ),
        (
            "line scan 1:6, 20°",
            Box::new(|s| synthetic::line_scan(6.0, 0.35, 1.0, s)),
        ),
    ];
    println!("| cloud | true loops | seeds with the true count | other counts (seeds) |");
    println!("|---|---:|---:|---|");
    for (name, make) in kinds {
        let mut right = 0;
        let mut wrong: BTreeMap<usize, Vec<u64>> = BTreeMap::new();
        let mut truth = 0;
        for seed in 0..seeds {
            let seed = 1000 + seed;
            let cloud = make(seed);
            truth = cloud.boundary.len();
            let found = match detect_boundary(&cloud.points, &BpdOptions::default()) {
                Ok(found) => found,
                Err(e) => {
                    eprintln!("{name}, seed {seed}: {e}");
                    continue;
                }
            };
            let edges = reconstruct_edges(&cloud.points, &found, &EdgeOptions::default());
            if edges.loops.len() == truth {
                right += 1;
            } else {
                wrong.entry(edges.loops.len()).or_default().push(seed);
            }
        }
        let other: Vec<String> = wrong
            .iter()
            .map(|(n, seeds)| format!("{n} (seeds {seeds:?})"))
            .collect();
        println!(
            "| {name} | {truth} | {right} / {seeds} | {} |",
            other.join(", ")
        );
    }
}
