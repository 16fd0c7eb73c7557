//! Ω/Ψ by the paper's rule against the sampling's regularity: blades at 4,
//! 8 and 16 mm sampled on a lattice with jitter 0 (a perfect lattice in the
//! parameter domain), 0.05 and 0.15 (the default) of the pitch, five noise
//! patterns each. Prints a markdown table.
//!
//! `cargo run --release -p meshtrim-testkit --example noise_jitter`

use testkit::{
    evaluate::{noise_robustness, percent_sweep},
    synthetic,
};
use trim::BpdOptions;

fn main() {
    let sweep = percent_sweep(1.0, 200.0);
    let noise_seeds = [7, 1, 2, 3, 4];
    println!("| cloud | anisotropy | Ω % (5 noise patterns) | Ψ % | Ω vs truth % | Ψ vs truth % |");
    println!("|---|---|---|---|---|---|");
    for (i, h) in [4.0, 8.0, 16.0].into_iter().enumerate() {
        for jitter in [0.0, 0.05, 0.15] {
            let cloud = synthetic::blade_with_jitter(h, jitter, 10 + i as u64);
            for anisotropy in [true, false] {
                let options = BpdOptions {
                    anisotropy,
                    ..BpdOptions::default()
                };
                let runs: Vec<_> = noise_seeds
                    .iter()
                    .map(|&s| noise_robustness(&cloud, &sweep, &options, s).expect("valid cloud"))
                    .collect();
                let column = |f: &dyn Fn(&testkit::evaluate::NoiseRobustness) -> String| {
                    runs.iter().map(f).collect::<Vec<_>>().join(" / ")
                };
                println!(
                    "| {} | {} | {} | {} | {} | {} |",
                    cloud.name,
                    if anisotropy { "on" } else { "off" },
                    column(&|r| r.omega.to_string()),
                    column(&|r| r.psi.to_string()),
                    column(&|r| r.omega_truth.to_string()),
                    column(&|r| r.psi_truth.to_string()),
                );
            }
        }
    }
}
