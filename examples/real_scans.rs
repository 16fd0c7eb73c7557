//! Runs BPD on the real scans in `../shared/data`, prints a markdown table
//! and draws each detection to `docs/img/<name>.png`.
//!
//! `cargo run --release --example real_scans`

use std::path::Path;
use std::time::Instant;

use trim::{
    detect_boundary, reconstruct_edges, BpdOptions, EdgeOptions, Edges, Point3, View as Scanner,
};

/// How to look at a scan: along its best-fit normal, or along an axis.
#[derive(Clone, Copy)]
enum View {
    /// Orthographic, looking along the cloud's smallest principal axis.
    Plane,
    /// Orthographic, looking along +axis (0 = x, 1 = y, 2 = z) from the
    /// negative side when `from_below`.
    Axis(usize, bool),
}

/// Each scan: its picture's name, its file, how to look at it, and the
/// scanner's line of sight when the detection is to use it (BPD's
/// `view`; `None` is the paper's projection along each normal).
const SCANS: &[(&str, &str, View, Option<Scanner>)] = &[
    (
        "bunny_zipper",
        "stanford_bunny/bun_zipper.ply",
        View::Axis(1, true),
        None,
    ),
    (
        "bunny_bun000",
        "stanford_bunny/bun000.ply",
        View::Axis(2, false),
        None,
    ),
    (
        "bunny_bun000_view",
        "stanford_bunny/bun000.ply",
        View::Axis(2, false),
        // A range scan in the scanner's frame, seen along its z.
        Some(Scanner::Along([0.0, 0.0, 1.0])),
    ),
    (
        "blade_scan1",
        "blade_scan_kinect/BladeScan1.csv",
        View::Plane,
        None,
    ),
    (
        "blade_scan1_view",
        "blade_scan_kinect/BladeScan1.csv",
        View::Plane,
        // The robot frame's z, which the panel faces.
        Some(Scanner::Along([0.0, 0.0, 1.0])),
    ),
    (
        "blade_scan2",
        "blade_scan_kinect/BladeScan2.csv",
        View::Plane,
        None,
    ),
    (
        "blade_scan2_view",
        "blade_scan_kinect/BladeScan2.csv",
        View::Plane,
        Some(Scanner::Along([0.0, 0.0, 1.0])),
    ),
    ("milk", "pcl_test/milk.pcd", View::Plane, None),
    (
        "milk_view",
        "pcl_test/milk.pcd",
        View::Plane,
        // A cloud in the depth camera's own frame.
        Some(Scanner::From([0.0, 0.0, 0.0])),
    ),
    (
        "face000",
        "meshlab_scans/face000.ply",
        View::Axis(2, false),
        None,
    ),
];

fn main() -> anyhow::Result<()> {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    let out = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/img");
    std::fs::create_dir_all(&out)?;
    println!("| scan | points | boundary points | loops | corners | dropped groups | β mean | detect ms | edges ms | picture |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---|");
    for &(name, file, view, scanner) in SCANS {
        let cloud = meshtrim::io::read_cloud(&data.join(file))?;
        let options = BpdOptions {
            view: scanner,
            ..BpdOptions::default()
        };
        let start = Instant::now();
        let found = detect_boundary(&cloud.points, &options)?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        let start = Instant::now();
        let edges = reconstruct_edges(&cloud.points, &found, &EdgeOptions::default());
        let edges_ms = start.elapsed().as_secs_f64() * 1e3;
        let corners: usize = edges.loops.iter().map(|l| l.corners.len()).sum();
        let beta = found.beta.iter().sum::<f64>() / found.beta.len() as f64;
        let png = out.join(format!("{name}.png"));
        draw(&cloud.points, &found.boundary, &edges, view, &png)?;
        println!(
            "| {file}{} | {} | {} | {} | {corners} | {} | {beta:.4} | {ms:.0} | {edges_ms:.0} | ![{name}](img/{name}.png) |",
            scanner.map_or(String::new(), |s| format!(" ({s:?})")),
            cloud.points.len(),
            found.boundary_count(),
            edges.loops.len(),
            edges.dropped_clusters,
        );
    }
    Ok(())
}

/// Draws interior points grey (shaded by depth) and boundary points red,
/// far points first, then the smoothed edges as dark blue lines, to a PNG.
fn draw(
    points: &[Point3],
    boundary: &[bool],
    edges: &Edges,
    view: View,
    path: &Path,
) -> anyhow::Result<()> {
    let (axes, depth_axis) = view_axes(points, view);
    let project = |p: &Point3| {
        let d = |a: &Point3| a[0] * p[0] + a[1] * p[1] + a[2] * p[2];
        (d(&axes[0]), d(&axes[1]), d(&depth_axis))
    };
    let projected: Vec<(f64, f64, f64)> = points.iter().map(project).collect();
    let bounds = |f: fn(&(f64, f64, f64)) -> f64| {
        projected
            .iter()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            })
    };
    let ((x0, x1), (y0, y1), (z0, z1)) = (bounds(|p| p.0), bounds(|p| p.1), bounds(|p| p.2));
    let (width, height) = (1000usize, 800usize);
    let scale = ((width - 40) as f64 / (x1 - x0)).min((height - 40) as f64 / (y1 - y0));
    let mut order: Vec<usize> = (0..points.len()).collect();
    // Far first, boundary after interior at equal depth; depth grows toward
    // the viewer.
    order.sort_by(|&a, &b| {
        projected[a]
            .2
            .total_cmp(&projected[b].2)
            .then(boundary[a].cmp(&boundary[b]))
    });
    let mut rgb = vec![255u8; width * height * 3];
    for &i in &order {
        let (x, y, z) = projected[i];
        let px = 20.0 + (x - x0) * scale;
        let py = height as f64 - 20.0 - (y - y0) * scale;
        let shade = (200.0 - 120.0 * (z - z0) / (z1 - z0).max(f64::MIN_POSITIVE)) as u8;
        let (colour, radius) = if boundary[i] {
            ([220u8, 20, 20], 2i64)
        } else {
            ([shade, shade, shade], 1i64)
        };
        for dy in -radius + 1..radius {
            for dx in -radius + 1..radius {
                let (cx, cy) = (px as i64 + dx, py as i64 + dy);
                if (0..width as i64).contains(&cx) && (0..height as i64).contains(&cy) {
                    let at = (cy as usize * width + cx as usize) * 3;
                    rgb[at..at + 3].copy_from_slice(&colour);
                }
            }
        }
    }
    let to_pixel = |p: &Point3| {
        let (x, y, _) = project(p);
        (
            20.0 + (x - x0) * scale,
            height as f64 - 20.0 - (y - y0) * scale,
        )
    };
    for edge in edges.loops.iter().flat_map(|l| &l.edges) {
        let n = edge.points.len();
        let segments = if edge.closed { n } else { n.saturating_sub(1) };
        for i in 0..segments {
            let (a, b) = (
                to_pixel(&edge.points[i]),
                to_pixel(&edge.points[(i + 1) % n]),
            );
            let steps = ((b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil() as usize).max(1);
            for s in 0..=steps {
                let t = s as f64 / steps as f64;
                let (x, y) = (
                    (a.0 + t * (b.0 - a.0)) as i64,
                    (a.1 + t * (b.1 - a.1)) as i64,
                );
                if (0..width as i64).contains(&x) && (0..height as i64).contains(&y) {
                    let at = (y as usize * width + x as usize) * 3;
                    rgb[at..at + 3].copy_from_slice(&[20, 40, 140]);
                }
            }
        }
    }
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, width as u32, height as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.write_header()?.write_image_data(&rgb)?;
    Ok(())
}

/// Two screen axes and the depth axis (toward the viewer) for `view`.
fn view_axes(points: &[Point3], view: View) -> ([Point3; 2], Point3) {
    match view {
        View::Axis(a, from_below) => {
            let (s, t) = ((a + 1) % 3, (a + 2) % 3);
            let unit = |i: usize| {
                let mut v = [0.0; 3];
                v[i] = 1.0;
                v
            };
            let mut depth = unit(a);
            if from_below {
                depth[a] = -1.0;
                ([unit(t), unit(s)], depth)
            } else {
                ([unit(s), unit(t)], depth)
            }
        }
        View::Plane => {
            let members: Vec<u32> = (0..points.len() as u32).collect();
            let f = trim::fit_plane(points, &members);
            ([f.u, f.v], f.normal)
        }
    }
}
