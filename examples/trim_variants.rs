//! Trims a mesh with its cloud two ways, for the pictures and numbers of
//! docs/trimming.md: as `meshtrim MESH CLOUD OUT` does, and without the
//! cut along the cloud's reach. Writes `PREFIX_default.ply` and
//! `PREFIX_no_reach.ply` and prints each one's kept area, farthest vertex
//! from the cloud in local spacings (mean distance to the 6 nearest
//! points) and the pieces beyond a wall that the cloud's support kept.
//!
//! `cargo run --release --example trim_variants -- MESH CLOUD PREFIX`

use std::path::Path;

use trim::{
    detect_boundary, reconstruct_edges, trim_mesh, BpdOptions, EdgeOptions, NeighbourIndex, Point3,
    TrimOptions,
};

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [mesh, cloud, prefix] = args.as_slice() else {
        anyhow::bail!("usage: MESH CLOUD PREFIX");
    };
    let mesh = meshtrim::io::read_mesh_with_faces(Path::new(mesh), "mesh")?;
    let cloud = meshtrim::io::read_cloud(Path::new(cloud))?.points;
    let detection = detect_boundary(&cloud, &BpdOptions::default())?;
    let edges = reconstruct_edges(&cloud, &detection, &EdgeOptions::default());
    let spacing = local_spacing(&cloud);
    let variants = [
        ("default", TrimOptions::default()),
        (
            "no_reach",
            TrimOptions {
                reach: f64::INFINITY,
                ..TrimOptions::default()
            },
        ),
    ];
    println!("{} loops", edges.loops.len());
    for (name, options) in variants {
        let (kept, report) = trim_mesh(&mesh, &cloud, &detection, &edges, &options)?;
        let farthest = farthest_in_spacings(&kept.vertices, &cloud, &spacing);
        meshtrim::io::write_mesh(
            Path::new(&format!("{prefix}_{name}.ply")),
            &kept.vertices,
            &kept.faces,
        )?;
        println!(
            "{name}: area kept {:.6}, farthest vertex {farthest:.1} spacings, pieces restored {}",
            report.area_out, report.pieces_restored
        );
    }
    Ok(())
}

/// Each cloud point's mean distance to its 6 nearest points.
fn local_spacing(cloud: &[Point3]) -> Vec<f64> {
    let index = NeighbourIndex::new(cloud);
    let mut near = Vec::new();
    (0..cloud.len())
        .map(|i| {
            index.nearest(i, 7, &mut near);
            near[1..]
                .iter()
                .map(|&j| distance(cloud[i], cloud[j as usize]))
                .sum::<f64>()
                / 6.0
        })
        .collect()
}

/// The largest distance from a vertex to its nearest cloud point, in that
/// point's local spacings.
fn farthest_in_spacings(vertices: &[Point3], cloud: &[Point3], spacing: &[f64]) -> f64 {
    vertices
        .iter()
        .map(|&v| {
            let (i, d) = cloud
                .iter()
                .enumerate()
                .map(|(i, &p)| (i, distance(v, p)))
                .fold((0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
            d / spacing[i]
        })
        .fold(0.0, f64::max)
}

fn distance(a: Point3, b: Point3) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}
