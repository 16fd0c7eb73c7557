//! Times `meshtrim::io::read_cloud` on one file and prints one JSON line.
//!
//! `cargo run --release --example bench_read -- FILE [REPEAT]`
//!
//! The file is read REPEAT times (default 5) in one process and the
//! fastest read is reported, as `bench/open3d_read.py` does for Open3D,
//! so both sides read from the page cache. `bench/io.sh` runs both.

use std::path::Path;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    meshtrim::alloc::keep_freed_memory();
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .ok_or_else(|| anyhow::anyhow!("usage: bench_read FILE [REPEAT]"))?;
    let repeat: usize = args.get(2).and_then(|r| r.parse().ok()).unwrap_or(5);
    let mut best = f64::INFINITY;
    let mut points = 0;
    for _ in 0..repeat.max(1) {
        let start = Instant::now();
        let cloud = meshtrim::io::read_cloud(Path::new(path))?;
        best = best.min(start.elapsed().as_secs_f64() * 1e3);
        points = cloud.points.len();
    }
    println!("{{\"points\":{points},\"read_ms\":{best:.1}}}");
    Ok(())
}
