//! Writes jagged triangle meshes, as scanner software makes them, for
//! batch benchmarks of border cleaning.
//!
//! `cargo run --release --example make_jagged -- OUT_DIR COUNT [TARGET_TRIANGLES]`
//! writes `OUT_DIR/jagged_NNNN_SHAPE.stl` (binary STL) for NNNN = 0 …
//! COUNT−1. The shape cycles through the blade, the notched plate and the
//! curved disc with a hole by index, the seed is the index, and the pitch
//! is chosen so that each mesh has about TARGET_TRIANGLES faces (default
//! 50,000); see `testkit::synthetic::jagged`. The same arguments give the
//! same files.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use meshtrim::io::write_mesh;
use testkit::synthetic::jagged::{jagged_mesh, sized_cloud, Shape};

const DEFAULT_TRIANGLES: usize = 50_000;

fn main() -> Result<()> {
    let (dir, count, triangles) = arguments()?;
    std::fs::create_dir_all(&dir).with_context(|| dir.display().to_string())?;
    let mut total = 0;
    for index in 0..count {
        total += write_one(&dir, index, triangles)?;
    }
    println!("{count} meshes, {total} triangles in {}", dir.display());
    Ok(())
}

fn arguments() -> Result<(PathBuf, usize, usize)> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: make_jagged OUT_DIR COUNT [TARGET_TRIANGLES]";
    if !(2..=3).contains(&args.len()) {
        bail!("{usage}");
    }
    let number = |s: &str| {
        s.parse::<usize>()
            .with_context(|| format!("'{s}' is not a count; {usage}"))
    };
    let triangles = args.get(2).map_or(Ok(DEFAULT_TRIANGLES), |s| number(s))?;
    if triangles == 0 {
        bail!("TARGET_TRIANGLES must be positive");
    }
    Ok((PathBuf::from(&args[0]), number(&args[1])?, triangles))
}

/// Writes mesh `index`; returns its triangle count.
fn write_one(dir: &Path, index: usize, triangles: usize) -> Result<usize> {
    let shape = Shape::ALL[index % Shape::ALL.len()];
    let cloud = sized_cloud(shape, triangles, index as u64);
    let mesh = jagged_mesh(&cloud);
    let path = dir.join(format!("jagged_{index:04}_{}.stl", shape.name()));
    write_mesh(&path, &mesh.vertices, &mesh.faces)?;
    Ok(mesh.faces.len())
}
