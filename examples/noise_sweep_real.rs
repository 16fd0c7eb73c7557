//! The paper's noise test (section 4, Table 1) on real scans, done as the
//! paper did it: every point moved along the normal of its k-neighbourhood's
//! best-fit plane by uniform(−p, p) × its local resolution β_i, p from 0 in
//! steps of 1 %; Ω is the largest p at which no boundary point of the
//! noise-free detection is lost, Ψ the largest p at which no interior one
//! turns boundary (against the noise-free detection: real scans have no
//! ground truth). Default options (`ANISO_OFF=1`: without the anisotropy
//! map; `VIEW_ALONG=X,Y,Z`: projected along that line of sight, as
//! `--view-along`). Prints a markdown table.
//!
//! `cargo run --release --example noise_sweep_real [FILES...]` (default: the
//! two Kinect blade scans and two Stanford range scans of `../shared/data`)

use std::path::PathBuf;

use testkit::synthetic::SplitMix64;
use trim::{detect_boundary, fit_plane, BpdOptions, NeighbourIndex, Point3, View};

const DEFAULT_SCANS: &[&str] = &[
    "blade_scan_kinect/BladeScan1.csv",
    "blade_scan_kinect/BladeScan2.csv",
    "stanford_bunny/bun000.ply",
    "meshlab_scans/lato000.ply",
];

fn main() -> anyhow::Result<()> {
    let args: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    let files = if args.is_empty() {
        let data = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data"));
        DEFAULT_SCANS.iter().map(|f| data.join(f)).collect()
    } else {
        args
    };
    println!("| scan | points | boundary (0 %) | Ω % | Ψ % | lost / false at 25 % | at 75 % |");
    println!("|---|---:|---:|---:|---:|---|---|");
    for file in &files {
        let cloud = meshtrim::io::read_cloud(file)?.points;
        let options = BpdOptions {
            anisotropy: std::env::var_os("ANISO_OFF").is_none(),
            view: view_along()?,
            ..BpdOptions::default()
        };
        let clean = detect_boundary(&cloud, &options)?;
        let normals = normals(&cloud, options.k);
        let draws: Vec<f64> = {
            let mut rng = SplitMix64::new(7);
            cloud.iter().map(|_| rng.range(-1.0, 1.0)).collect()
        };
        let (mut omega, mut psi) = (None, None);
        let (mut at25, mut at75) = ((0, 0), (0, 0));
        for step in 1..=200 {
            let p = step as f64 / 100.0;
            let noisy: Vec<Point3> = (0..cloud.len())
                .map(|i| {
                    let d = draws[i] * p * clean.beta[i];
                    [0, 1, 2].map(|a| cloud[i][a] + d * normals[i][a])
                })
                .collect();
            let labels = detect_boundary(&noisy, &options)?.boundary;
            let lost = (0..cloud.len())
                .filter(|&i| clean.boundary[i] && !labels[i])
                .count();
            let false_ = (0..cloud.len())
                .filter(|&i| !clean.boundary[i] && labels[i])
                .count();
            if lost > 0 && omega.is_none() {
                omega = Some(step - 1);
            }
            if false_ > 0 && psi.is_none() {
                psi = Some(step - 1);
            }
            match step {
                25 => at25 = (lost, false_),
                75 => at75 = (lost, false_),
                _ => {}
            }
            if omega.is_some() && psi.is_some() && step >= 75 {
                break;
            }
        }
        let level = |v: Option<usize>| v.map_or("≥ 200".to_string(), |v| v.to_string());
        println!(
            "| {} | {} | {} | {} | {} | {} / {} | {} / {} |",
            file.file_name().unwrap_or_default().to_string_lossy(),
            cloud.len(),
            clean.boundary_count(),
            level(omega),
            level(psi),
            at25.0,
            at25.1,
            at75.0,
            at75.1
        );
    }
    Ok(())
}

/// The line of sight given in `VIEW_ALONG` ("X,Y,Z"), if any.
fn view_along() -> anyhow::Result<Option<View>> {
    let Ok(text) = std::env::var("VIEW_ALONG") else {
        return Ok(None);
    };
    let parts = text
        .split(',')
        .map(|c| c.trim().parse::<f64>())
        .collect::<Result<Vec<f64>, _>>()?;
    match parts[..] {
        [x, y, z] => Ok(Some(View::Along([x, y, z]))),
        _ => anyhow::bail!("VIEW_ALONG={text:?}: expected X,Y,Z"),
    }
}

/// The unit normal of every point's k-neighbourhood plane.
fn normals(cloud: &[Point3], k: usize) -> Vec<Point3> {
    let index = NeighbourIndex::new(cloud);
    let mut members = Vec::new();
    (0..cloud.len())
        .map(|i| {
            index.nearest(i, k, &mut members);
            fit_plane(cloud, &members).normal
        })
        .collect()
}
