//! Ω/Ψ on blades *decimated* to their resolution, as the paper's clouds
//! were ([`testkit::synthetic::decimated_blade`]: Poisson-disk elimination of
//! a dense jittered blade), at 4, 8, 16 and 34 mm, two sampling seeds, the
//! anisotropy map on and off, five noise patterns each; then the same for
//! the variable-density blade decimated alike
//! ([`testkit::synthetic::decimated_variable_density`], 3.4 → 34 mm, the
//! paper's cloud e), sampling seeds 5–10. Prints a markdown table: β's mean
//! and spread (the paper's Table 1 rows), then Ω and Ψ by the paper's rule
//! and against the truth, one value per noise pattern.
//!
//! `cargo run --release -p meshtrim-testkit --example noise_decimated`

use testkit::{
    evaluate::{noise_robustness, percent_sweep, NoiseRobustness},
    synthetic,
};
use trim::BpdOptions;

fn main() {
    let sweep = percent_sweep(1.0, 200.0);
    let noise_seeds = [7, 1, 2, 3, 4];
    println!("| cloud | sampling seed | anisotropy | points | β mean | β σ | boundary (0 %) | Ω % (5 noise patterns) | Ψ % | Ω vs truth % | Ψ vs truth % |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let mut clouds = Vec::new();
    for (i, h) in [4.0, 8.0, 16.0, 34.0].into_iter().enumerate() {
        for seed in [10 + i as u64, 100 + i as u64] {
            clouds.push((seed, synthetic::decimated_blade(h, seed)));
        }
    }
    for seed in 5..=10 {
        clouds.push((seed, synthetic::decimated_variable_density(3.4, seed)));
    }
    for (seed, cloud) in clouds {
        for anisotropy in [true, false] {
            let options = BpdOptions {
                anisotropy,
                ..BpdOptions::default()
            };
            let detection = trim::detect_boundary(&cloud.points, &options).expect("valid cloud");
            let (mean, sd) = mean_and_sd(&detection.beta);
            let runs: Vec<NoiseRobustness> = noise_seeds
                .iter()
                .map(|&s| noise_robustness(&cloud, &sweep, &options, s).expect("valid cloud"))
                .collect();
            let column = |f: &dyn Fn(&NoiseRobustness) -> String| {
                runs.iter().map(f).collect::<Vec<_>>().join(" / ")
            };
            println!(
                "| {} | {seed} | {} | {} | {mean:.2} | {sd:.2} | {} | {} | {} | {} | {} |",
                cloud.name,
                if anisotropy { "on" } else { "off" },
                cloud.len(),
                detection.boundary_count(),
                column(&|r| r.omega.to_string()),
                column(&|r| r.psi.to_string()),
                column(&|r| r.omega_truth.to_string()),
                column(&|r| r.psi_truth.to_string()),
            );
        }
    }
}

/// Mean and (population) standard deviation.
fn mean_and_sd(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    (mean, var.sqrt())
}
