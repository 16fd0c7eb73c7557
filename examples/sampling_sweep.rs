//! Detection accuracy and noise robustness over many samplings of the
//! paper's blade (4, 8, 16 and 34 mm): for each resolution and sampling
//! seed, BPD's precision, recall and F1 against the truth (and the ideal
//! first layer's), then the paper's noise sweep (steps of 5 % up to 75 %,
//! along the true normal) scored against the truth: Ω the largest noise at
//! which recall stays that of the noise-free cloud, Ψ the largest at which
//! no point more than one spacing from the true border turns boundary.
//! Prints one markdown row per sampling and a summary per resolution; the
//! misses of the weakest sampling are listed (distance to the border in
//! spacings, neighbourhood span).
//!
//! `cargo run --release --example sampling_sweep [SEEDS] [GENERATOR]`
//! (default 10 seeds from 1; GENERATOR `lattice` (default) or `decimated`;
//! a third argument `isotropic` turns the anisotropy map off)

use testkit::evaluate::{noise_robustness, percent_sweep, precision_recall};
use testkit::synthetic::{self, SyntheticCloud};
use trim::{detect_boundary, BpdOptions};

/// One sampling's scores.
struct Row {
    seed: u64,
    f1: f64,
    omega: f64,
    psi: f64,
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let seeds: u64 = args.next().map_or(Ok(10), |s| s.parse())?;
    let generator = args.next().unwrap_or_else(|| "lattice".into());
    let blade: fn(f64, u64) -> SyntheticCloud = match generator.as_str() {
        "lattice" => synthetic::blade,
        "decimated" => synthetic::decimated_blade,
        other => anyhow::bail!("unknown generator {other}: lattice or decimated"),
    };
    let options = BpdOptions {
        anisotropy: args.next().as_deref() != Some("isotropic"),
        ..BpdOptions::default()
    };
    println!("| blade | seed | points | precision | recall | F1 | ideal recall | Ω truth % | Ψ truth % |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    let mut summary = Vec::new();
    for h in [4.0, 8.0, 16.0, 34.0] {
        let mut rows = Vec::new();
        for seed in 1..=seeds {
            let cloud = blade(h, seed);
            let det = detect_boundary(&cloud.points, &options)?;
            let a = precision_recall(&cloud.points, &det.boundary, &cloud);
            let ideal = precision_recall(
                &cloud.points,
                &testkit::evaluate::ideal_first_layer(&cloud),
                &cloud,
            );
            let noise = noise_robustness(&cloud, &percent_sweep(5.0, 75.0), &options, 7)?;
            println!(
                "| {h} mm | {seed} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {}{} | {}{} |",
                cloud.len(),
                a.precision,
                a.recall,
                a.f1,
                ideal.recall,
                noise.omega_truth.percent,
                if noise.omega_truth.capped { "+" } else { "" },
                noise.psi_truth.percent,
                if noise.psi_truth.capped { "+" } else { "" },
            );
            rows.push(Row {
                seed,
                f1: a.f1,
                omega: noise.omega_truth.percent,
                psi: noise.psi_truth.percent,
            });
        }
        summary.push((h, rows));
    }
    println!();
    println!("| blade | F1 min | F1 median | F1 ≥ 0.98 | Ω ≥ 25 % | Ψ ≥ 75 % | weakest F1 seed | weakest Ψ seed |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    for (h, rows) in &summary {
        let mut f1: Vec<f64> = rows.iter().map(|r| r.f1).collect();
        f1.sort_unstable_by(f64::total_cmp);
        let count = |ok: fn(&Row) -> bool| rows.iter().filter(|r| ok(r)).count();
        let weakest = |key: fn(&Row) -> f64| {
            rows.iter()
                .min_by(|a, b| key(a).total_cmp(&key(b)))
                .map_or(0, |r| r.seed)
        };
        let n = rows.len();
        println!(
            "| {h} mm | {:.4} | {:.4} | {}/{n} | {}/{n} | {}/{n} | {} | {} |",
            f1[0],
            f1[f1.len() / 2],
            count(|r| r.f1 >= 0.98),
            count(|r| r.omega >= 25.0),
            count(|r| r.psi >= 75.0),
            weakest(|r| r.f1),
            weakest(|r| r.psi),
        );
    }
    Ok(())
}
