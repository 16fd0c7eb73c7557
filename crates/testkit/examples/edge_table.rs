//! The paper's Table 2 comparison on synthetic clouds with ground truth:
//! FFT edges (meshtrim, with and without the physical-edge offset) against
//! the paper's two baselines, a third-order polynomial per edge and a cubic
//! smoothing spline, all fitted to the same ordered boundary points.
//!
//! `cargo run --release -p meshtrim-testkit --example edge_table`
//!
//! Columns: the paper's metric (distance from the boundary points to their
//! edge: mean, max, STD, in local spacings) and the distance from the edge
//! to the true boundary (mean, max, in local spacings), which the paper's
//! metric cannot see.

use std::time::Instant;

use testkit::{
    baseline::{polynomial_edge, smoothing_spline_edge},
    edge_metrics::{points_to_polyline, polyline_to_truth_in_spacings, DistanceStats},
    synthetic::{self, SyntheticCloud},
};
use trim::{detect_boundary, reconstruct_edges, BpdOptions, EdgeOptions, Edges, Point3};

/// One smoothed edge with the raw boundary points it was fitted to.
struct Piece {
    raw: Vec<Point3>,
    closed: bool,
}

fn main() {
    let clouds = [
        synthetic::blade(4.0, 10),
        synthetic::blade(8.0, 11),
        synthetic::blade(16.0, 12),
        synthetic::notched_plate(1.0, 2),
        synthetic::curved_disc_with_hole(1.5, 3),
    ];
    println!("| cloud | method | pts→edge mean | max | STD | edge→truth mean | max |");
    println!("|---|---|---:|---:|---:|---:|---:|");
    for cloud in &clouds {
        let detection = detect_boundary(&cloud.points, &BpdOptions::default()).unwrap();
        let start = Instant::now();
        let paper = reconstruct_edges(&cloud.points, &detection, &EdgeOptions { offset: false });
        let edges_ms = start.elapsed().as_secs_f64() * 1e3;
        let offset = reconstruct_edges(&cloud.points, &detection, &EdgeOptions { offset: true });
        let pieces = pieces(cloud, &paper);
        let h = cloud.spacing.iter().sum::<f64>() / cloud.len() as f64;
        let raw: Vec<Vec<Point3>> = pieces.iter().map(|p| p.raw.clone()).collect();
        let fft: Vec<Vec<Point3>> = paper
            .loops
            .iter()
            .flat_map(|l| l.edges.iter().map(|e| e.points.clone()))
            .collect();
        let fft_offset: Vec<Vec<Point3>> = offset
            .loops
            .iter()
            .flat_map(|l| l.edges.iter().map(|e| e.points.clone()))
            .collect();
        let poly: Vec<Vec<Point3>> = pieces
            .iter()
            .map(|p| closing(polynomial_edge(&closed_input(p), 3), p.closed))
            .collect();
        let spline: Vec<Vec<Point3>> = pieces
            .iter()
            .map(|p| smoothing_spline_edge(&p.raw, p.closed))
            .collect();
        for (method, fitted) in [
            ("raw ordered points", &raw),
            ("3rd-order polynomial", &poly),
            ("cubic smoothing spline", &spline),
            ("FFT (paper)", &fft),
            ("FFT + offset (meshtrim)", &fft_offset),
        ] {
            let (to_edge, to_truth) = score(cloud, &pieces, fitted, h);
            println!(
                "| {} | {method} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} |",
                cloud.name, to_edge.mean, to_edge.max, to_edge.std, to_truth.0, to_truth.1
            );
        }
        eprintln!("{}: edges in {edges_ms:.1} ms", cloud.name);
    }
}

/// The raw boundary points of every edge, in the pipeline's order.
fn pieces(cloud: &SyntheticCloud, edges: &Edges) -> Vec<Piece> {
    let mut out = Vec::new();
    for lp in &edges.loops {
        let pts: Vec<Point3> = lp
            .boundary_points
            .iter()
            .map(|&i| cloud.points[i as usize])
            .collect();
        if lp.corners.is_empty() {
            out.push(Piece {
                raw: pts,
                closed: true,
            });
            continue;
        }
        let n = pts.len();
        for k in 0..lp.corners.len() {
            let (from, to) = (lp.corners[k], lp.corners[(k + 1) % lp.corners.len()]);
            let len = match (to + n - from) % n {
                0 => n,
                l => l,
            };
            out.push(Piece {
                raw: (0..=len).map(|j| pts[(from + j) % n]).collect(),
                closed: false,
            });
        }
    }
    out
}

/// A closed loop as an open run from its first point back to it, so that
/// the end-pinned polynomial can fit it.
fn closed_input(p: &Piece) -> Vec<Point3> {
    let mut v = p.raw.clone();
    if p.closed {
        v.push(p.raw[0]);
    }
    v
}

fn closing(mut fitted: Vec<Point3>, closed: bool) -> Vec<Point3> {
    if closed {
        fitted.pop();
    }
    fitted
}

/// (points → edge in spacings, (edge → truth mean, max) in spacings).
fn score(
    cloud: &SyntheticCloud,
    pieces: &[Piece],
    fitted: &[Vec<Point3>],
    h: f64,
) -> (DistanceStats, (f64, f64)) {
    let mut to_edge = Vec::new();
    let (mut sum, mut count, mut max) = (0.0, 0usize, 0.0f64);
    for (piece, edge) in pieces.iter().zip(fitted) {
        let d = points_to_polyline(&piece.raw, edge, piece.closed);
        to_edge.push((d.mean, d.max, d.std, d.count));
        let t = polyline_to_truth_in_spacings(edge, piece.closed, h / 4.0, cloud);
        sum += t.mean * t.count as f64;
        count += t.count;
        max = max.max(t.max);
    }
    // Pool the per-edge statistics into one over all points.
    let n: usize = to_edge.iter().map(|e| e.3).sum();
    let mean = to_edge.iter().map(|e| e.0 * e.3 as f64).sum::<f64>() / n as f64;
    let second = to_edge
        .iter()
        .map(|e| (e.2 * e.2 + e.0 * e.0) * e.3 as f64)
        .sum::<f64>()
        / n as f64;
    let stats = DistanceStats {
        mean: mean / h,
        max: to_edge.iter().map(|e| e.1).fold(0.0, f64::max) / h,
        std: (second - mean * mean).max(0.0).sqrt() / h,
        count: n,
    };
    (stats, (sum / count as f64, max))
}
