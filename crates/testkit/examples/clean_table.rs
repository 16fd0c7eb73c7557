//! The border-cleanup table of docs/clean.md: jagged Delaunay meshes of
//! jittered synthetic clouds, their border's distance to the true border
//! (mean / largest, in local spacings) before and after `clean_mesh`, with
//! and without the outward offset, over several seeds.
//!
//! `cargo run --release -p meshtrim-testkit --example clean_table`

use testkit::{
    synthetic::jagged::{border_error, jagged_mesh},
    synthetic::{self, SyntheticCloud},
};
use trim::{clean_mesh, detect_boundary, BpdOptions, CleanOptions};

fn main() {
    type Make = fn(u64) -> SyntheticCloud;
    let shapes: [(&str, Make); 4] = [
        ("blade 4 mm", |s| synthetic::blade(4.0, s)),
        ("blade 8 mm", |s| synthetic::blade(8.0, s)),
        ("notched plate", |s| synthetic::notched_plate(1.0, s)),
        ("curved disc with hole", |s| {
            synthetic::curved_disc_with_hole(1.0, s)
        }),
    ];
    println!("| surface | seeds | jagged input | cleaned, paper's edges | cleaned, offset (default) | smallest new angle |");
    println!("|---|---|---|---|---|---|");
    for (name, make) in shapes {
        let seeds = 1..=5u64;
        let mut rows = [(0.0, 0.0f64); 3];
        let mut min_angle = f64::INFINITY;
        for seed in seeds.clone() {
            let truth = make(seed);
            let input = jagged_mesh(&truth);
            let beta = detect_boundary(&input.vertices, &BpdOptions::default())
                .expect("synthetic clouds are valid")
                .beta;
            let mut add = |k: usize, (mean, max): (f64, f64)| {
                rows[k].0 += mean / seeds.clone().count() as f64;
                rows[k].1 = rows[k].1.max(max);
            };
            add(0, border_error(&input, &truth));
            for (k, offset) in [(1, false), (2, true)] {
                let (out, report) = clean_mesh(
                    &input,
                    &beta,
                    &CleanOptions {
                        offset,
                        ..CleanOptions::default()
                    },
                )
                .expect("jagged meshes are valid");
                add(k, border_error(&out, &truth));
                if offset {
                    min_angle = min_angle.min(report.min_angle_new);
                }
            }
        }
        let cell = |(mean, max): (f64, f64)| format!("{mean:.3} / {max:.2}");
        println!(
            "| {name} | {} | {} | {} | {} | {min_angle:.1}° |",
            seeds.count(),
            cell(rows[0]),
            cell(rows[1]),
            cell(rows[2])
        );
    }
}
