//! Times BPD and edge reconstruction on one seeded synthetic cloud and
//! prints one JSON line.
//!
//! `cargo run --release --example bench_bpd -- N [sheet|linescan|viewed|ragged] [OUT.ply]`
//!
//! The cloud is a jittered, twisted sheet of about N points with three holes;
//! `linescan` samples it in lines four times farther apart than the points
//! along each line; `viewed` is the sheet detected with its line of sight
//! given (along z, over which the sheet is a height field), so that its
//! edges are traced in the image plane; `ragged` is the sheet whose points
//! within 4 spacings of its outer edge are kept at random (three in five),
//! so that BPD's links leave that border open and the edges are traced in
//! the sheet's own best-fit plane. With OUT.ply the cloud is also written (binary PLY) so
//! that `bench/bpd.sh` can time Open3D on the very same points.
//!
//! Detection runs `BENCH_REPEAT` times (default: 3 up to 1.5M points, 1
//! above) and the fastest run is reported (`detect_ms`), which damps noise
//! from other work on the machine; `first_ms` is the process's first, cold
//! run, and the peak memory is the first run's.

use std::io::Write;
use std::time::Instant;

use trim::{detect_boundary, BpdOptions, Point3, View};

fn main() -> anyhow::Result<()> {
    // As the `meshtrim` binary does, so that the benchmark times the library
    // as the binary runs it.
    meshtrim::alloc::keep_freed_memory();
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(100_000);
    let kind = args.get(2).map(String::as_str).unwrap_or("sheet");
    let cloud = match kind {
        "linescan" => twisted_sheet(n, 4.0, 7, false),
        "ragged" => twisted_sheet(n, 1.0, 7, true),
        _ => twisted_sheet(n, 1.0, 7, false),
    };
    let options = BpdOptions {
        view: (kind == "viewed").then_some(View::Along([0.0, 0.0, 1.0])),
        ..BpdOptions::default()
    };
    if let Some(path) = args.get(3).filter(|p| !p.is_empty()) {
        write_ply(path, &cloud)?;
    }
    let default_repeat = if cloud.len() <= 1_500_000 { 3 } else { 1 };
    let repeat = std::env::var("BENCH_REPEAT")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(default_repeat);
    let mut ms = f64::INFINITY;
    let mut first_ms = None;
    let mut found = None;
    let mut peak_mb = None;
    for _ in 0..repeat.max(1) {
        drop(found.take()); // not two results in the peak memory
        let start = Instant::now();
        found = Some(detect_boundary(&cloud, &options)?);
        let run_ms = start.elapsed().as_secs_f64() * 1e3;
        // The process's first run, cold: code, caches and thread pool.
        first_ms.get_or_insert(run_ms);
        ms = ms.min(run_ms);
        // The first run's peak: later runs add the allocator's leftovers.
        peak_mb.get_or_insert_with(peak_rss_mb);
    }
    let found = found.ok_or_else(|| anyhow::anyhow!("no detection ran"))?;
    let start = Instant::now();
    let edges = trim::reconstruct_edges(&cloud, &found, &trim::EdgeOptions::default());
    let edges_ms = start.elapsed().as_secs_f64() * 1e3;
    let by_path = found
        .decision
        .iter()
        .filter(|&&d| d == trim::Decision::OpenPath)
        .count();
    println!(
        "{{\"kind\":\"{kind}\",\"points\":{},\"boundary\":{},\"by_path_test\":{by_path},\"detect_ms\":{ms:.1},\"first_ms\":{:.1},\"loops\":{},\"largest_loop\":{},\"loops_from\":\"{}\",\"edges_ms\":{edges_ms:.1},\"peak_rss_mb\":{:.1}}}",
        cloud.len(),
        found.boundary_count(),
        first_ms.unwrap_or(f64::NAN),
        edges.loops.len(),
        edges.loops.iter().map(|l| l.boundary_points.len()).max().unwrap_or(0),
        edges.loops_from.name(),
        peak_mb.unwrap_or(f64::NAN)
    );
    Ok(())
}

/// A twisted, cambered sheet (about 600 × 200 units) with three round holes,
/// jittered-grid sampled with about `n` points; rows are `ratio` times
/// farther apart than points within a row. When `ragged`, the points within
/// 4 spacings of the outer edge are kept at random, three in five.
fn twisted_sheet(n: usize, ratio: f64, seed: u64, ragged: bool) -> Vec<Point3> {
    let (w, h) = (600.0, 200.0);
    let s = (w * h / (n as f64 * ratio)).sqrt();
    let mut rng = SplitMix(seed);
    let holes = [
        (150.0, 100.0, 30.0),
        (350.0, 60.0, 15.0),
        (480.0, 140.0, 6.0),
    ];
    let mut out = Vec::with_capacity(n);
    let (nu, nv) = ((w / s) as usize, (h / (s * ratio)) as usize);
    for j in 0..nv {
        for i in 0..nu {
            let u = (i as f64 + 0.5 + 0.6 * (rng.unit() - 0.5)) * s;
            let v = (j as f64 + 0.5 + 0.6 * (rng.unit() - 0.5) / ratio) * s * ratio;
            if holes.iter().any(|&(x, y, r)| (u - x).hypot(v - y) < r) {
                continue;
            }
            let edge = u.min(v).min(w - u).min(h - v);
            if ragged && edge < 4.0 * s && rng.unit() < 0.4 {
                continue;
            }
            let twist = 0.5 * u / w;
            let (c, sn) = (twist.cos(), twist.sin());
            let y = v - h / 2.0;
            let camber = 40.0 * (1.0 - (2.0 * y / h).powi(2));
            out.push([u, y * c - camber * sn, y * sn + camber * c]);
        }
    }
    out
}

struct SplitMix(u64);

impl SplitMix {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn write_ply(path: &str, cloud: &[Point3]) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    write!(
        f,
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\nend_header\n",
        cloud.len()
    )?;
    for p in cloud {
        for c in p {
            f.write_all(&c.to_le_bytes())?;
        }
    }
    f.flush()
}

/// Peak resident memory of this process (Linux), in MB.
fn peak_rss_mb() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}
