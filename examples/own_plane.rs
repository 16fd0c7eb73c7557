//! The two measures that decide whether a cloud without a view has its
//! loops traced in its own best-fit plane (docs/edges.md, "Clustering"):
//! the share of the linked points that the links' tours leave on no loop
//! (traced above 5 %), and the share of the points in two layers of the
//! own plane's image (traced up to 0.5 %). Prints a markdown table for the
//! real scans in `../shared/data` and synthetic sheets.
//!
//! `cargo run --release --example own_plane`

use std::path::Path;

use testkit::synthetic;
use trim::internals::{own_plane_layered_share, share_left_by_tours};
use trim::{detect_boundary, reconstruct_edges, BpdOptions, EdgeOptions, Point3};

const SCANS: &[&str] = &[
    "blade_scan_kinect/BladeScan1.csv",
    "blade_scan_kinect/BladeScan2.csv",
    "pcl_test/milk.pcd",
    "meshlab_scans/face000.ply",
    "meshlab_scans/lato000.ply",
    "meshlab_scans/Laurana50k.ply",
    "stanford_bunny/bun000.ply",
    "stanford_bunny/bun045.ply",
    "stanford_bunny/bun090.ply",
    "stanford_bunny/chin.ply",
    "stanford_bunny/bun_zipper.ply",
    "pcl_test/rops_cloud.pcd",
    "pcl_test/rs1.pcd",
    "pcl_test/table_scene_mug_stereo_textured.pcd",
];

fn main() -> anyhow::Result<()> {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    println!("| cloud | points | left by the tours | in two layers | loops from |");
    println!("|---|---:|---:|---:|---|");
    for rel in SCANS {
        let cloud = meshtrim::io::read_cloud(&data.join(rel))?;
        row(rel, &cloud.points)?;
    }
    let synthetic = [
        synthetic::blade(4.0, 1),
        synthetic::blade(16.0, 1),
        synthetic::plane_with_holes(1.0, 1),
        synthetic::saddle_with_hole(1.0, 1),
        synthetic::curved_disc_with_hole(1.0, 1),
        synthetic::cylinder_with_hole(1.0, 1),
        synthetic::notched_plate(1.0, 1),
        synthetic::variable_density(3.4, 1),
        synthetic::line_scan(4.0, 20f64.to_radians(), 1.0, 1),
    ];
    for cloud in synthetic {
        row(&cloud.name, &cloud.points)?;
    }
    Ok(())
}

fn row(name: &str, points: &[Point3]) -> anyhow::Result<()> {
    let detection = detect_boundary(points, &BpdOptions::default())?;
    let left = share_left_by_tours(points, &detection);
    let layered = own_plane_layered_share(points, &detection)
        .map_or("no region of half the points".to_string(), |s| {
            format!("{:.2} %", 100.0 * s)
        });
    let edges = reconstruct_edges(points, &detection, &EdgeOptions::default());
    let from = edges.loops_from.name();
    println!(
        "| {name} | {} | {:.1} % | {layered} | {from} |",
        points.len(),
        100.0 * left
    );
    Ok(())
}
