//! How much Ω and Ψ depend on the draw: the noise sweep (1 % steps to
//! 200 %, default options) on blades at 4, 8 and 16 mm, two sampling seeds
//! each, five noise patterns each. Prints one markdown row per cloud, each
//! cell Ω / Ψ / Ω vs truth / Ψ vs truth in % (see `testkit::evaluate`).
//!
//! `cargo run --release -p meshtrim-testkit --example noise_seed_spread`

use testkit::{
    evaluate::{noise_robustness, percent_sweep},
    synthetic,
};
use trim::BpdOptions;
fn main() {
    let sweep = percent_sweep(1.0, 200.0);
    for (i, h) in [4.0, 8.0, 16.0].into_iter().enumerate() {
        for cloud_seed in [10 + i as u64, 100 + i as u64] {
            let cloud = synthetic::blade(h, cloud_seed);
            let mut row = Vec::new();
            for noise_seed in [7u64, 1, 2, 3, 4] {
                let r = noise_robustness(&cloud, &sweep, &BpdOptions::default(), noise_seed)
                    .expect("valid cloud");
                row.push(format!(
                    "{}/{}/{}/{}",
                    r.omega, r.psi, r.omega_truth, r.psi_truth
                ));
            }
            println!(
                "| {} (cloud seed {cloud_seed}) | {} |",
                cloud.name,
                row.join(" | ")
            );
        }
    }
}
