//! Counts the jumps of the edge tours on the real range scans: tour steps
//! longer than 3 β that no BPD link supports (see
//! `testkit::edge_metrics::tour_jumps`).
//!
//! `cargo run --release --example tour_jumps`

use std::path::Path;

use testkit::edge_metrics::tour_jumps;
use trim::{detect_boundary, reconstruct_edges, BpdOptions, EdgeOptions};

const SCANS: &[&str] = &["stanford_bunny/bun000.ply", "meshlab_scans/face000.ply"];

fn main() -> anyhow::Result<()> {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    let data = if data.is_dir() {
        data
    } else {
        Path::new("/work/shared/data").to_path_buf()
    };
    println!("| scan | loops | dropped groups | loops with jumps | jumps | longest jump (β) |");
    println!("|---|---:|---:|---:|---:|---:|");
    for &file in SCANS {
        let cloud = meshtrim::io::read_cloud(&data.join(file))?;
        let found = detect_boundary(&cloud.points, &BpdOptions::default())?;
        let edges = reconstruct_edges(&cloud.points, &found, &EdgeOptions { offset: false });
        let per_loop: Vec<_> = edges
            .loops
            .iter()
            .map(|l| tour_jumps(&cloud.points, &found.beta, &found.links, &l.boundary_points))
            .collect();
        let jumps: usize = per_loop.iter().map(|j| j.count).sum();
        let with: usize = per_loop.iter().filter(|j| j.count > 0).count();
        let longest = per_loop
            .iter()
            .map(|j| j.longest_in_beta)
            .fold(0.0, f64::max);
        println!(
            "| {file} | {} | {} | {with} | {jumps} | {longest:.1} |",
            edges.loops.len(),
            edges.dropped_clusters
        );
        if std::env::var_os("JUMPS_DETAIL").is_some() {
            for (l, j) in edges.loops.iter().zip(&per_loop) {
                println!(
                    "  loop of {} points: {} jumps, longest {:.1} β",
                    l.boundary_points.len(),
                    j.count,
                    j.longest_in_beta
                );
            }
        }
    }
    Ok(())
}
