//! Ω/Ψ noise sweep (section 4 of the paper, Table 1) on the synthetic
//! blade clouds at 4, 8, 16 and 34 mm and the ×10 variable-density cloud,
//! with the anisotropy map on and off. Prints a markdown table.
//!
//! `cargo run --release -p meshtrim-testkit --example noise_sweep`

use testkit::{
    evaluate::{noise_robustness, percent_sweep, precision_recall},
    synthetic,
};
use trim::{detect_boundary, BpdOptions};

fn main() {
    let clouds = synthetic::noise_sweep_clouds();
    // The paper's 1 % steps, up to 200 %.
    let sweep = percent_sweep(1.0, 200.0);
    println!(
        "| cloud | anisotropy | points | boundary (0 %) | Ω % | Ψ % | Ω % vs truth | Ψ % vs truth | precision | recall |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for cloud in &clouds {
        for anisotropy in [true, false] {
            let options = BpdOptions {
                anisotropy,
                ..BpdOptions::default()
            };
            let det = detect_boundary(&cloud.points, &options).expect("valid cloud");
            let acc = precision_recall(&cloud.points, &det.boundary, cloud);
            let r = noise_robustness(cloud, &sweep, &options, 7).expect("valid cloud");
            println!(
                "| {} | {} | {} | {} | {} | {} | {} | {} | {:.4} | {:.4} |",
                cloud.name,
                if anisotropy { "on" } else { "off" },
                cloud.len(),
                r.reference_boundary,
                r.omega,
                r.psi,
                r.omega_truth,
                r.psi_truth,
                acc.precision,
                acc.recall,
            );
        }
    }
}
