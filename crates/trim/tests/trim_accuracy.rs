//! Trimming on synthetic clouds with ground truth: a mesh that overshoots
//! the part, caps its hole and has an unsupported far sheet is cut back to
//! the smoothed boundary. Run with `--nocapture` for the numbers.

use testkit::{
    synthetic::BoundaryIndex,
    synthetic::{self, SyntheticCloud},
};
use trim::{
    detect_boundary, reconstruct_edges, trim_mesh, BpdOptions, EdgeOptions, Mesh, Point3,
    TrimOptions,
};

/// A square grid of pitch `h` over [x0, x1] × [y0, y1] at height z,
/// facing +z (or −z when `down`).
fn grid(x0: f64, x1: f64, y0: f64, y1: f64, h: f64, z: f64, down: bool) -> Mesh {
    let (nx, ny) = (((x1 - x0) / h) as u32, ((y1 - y0) / h) as u32);
    let vertices: Vec<Point3> = (0..=ny)
        .flat_map(|j| (0..=nx).map(move |i| [x0 + i as f64 * h, y0 + j as f64 * h, z]))
        .collect();
    let at = |i: u32, j: u32| j * (nx + 1) + i;
    let mut faces = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            if down {
                faces.extend([[a, c, b], [a, d, c]]);
            } else {
                faces.extend([[a, b, c], [a, c, d]]);
            }
        }
    }
    Mesh { vertices, faces }
}

fn append(mut a: Mesh, b: &Mesh) -> Mesh {
    let offset = a.vertices.len() as u32;
    a.vertices.extend_from_slice(&b.vertices);
    a.faces
        .extend(b.faces.iter().map(|f| f.map(|v| v + offset)));
    a
}

fn true_area_of_notched_plate(h: f64) -> f64 {
    (60.0 * 40.0 - 15.0 * 15.0) * h * h - std::f64::consts::PI * 25.0 * h * h
}

fn trimmed(cloud: &SyntheticCloud, mesh: &Mesh) -> (Mesh, trim::TrimReport) {
    let detection = detect_boundary(&cloud.points, &BpdOptions::default()).unwrap();
    let edges = reconstruct_edges(&cloud.points, &detection, &EdgeOptions::default());
    trim_mesh(
        mesh,
        &cloud.points,
        &detection,
        &edges,
        &TrimOptions::default(),
    )
    .unwrap()
}

/// The notched plate (spacing 1) and a mesh that overshoots it by 5
/// spacings, caps its hole and has an unsupported far sheet 3 below.
fn notched_plate_and_overshooting_envelope() -> (SyntheticCloud, Mesh) {
    let cloud = synthetic::notched_plate(1.0, 2);
    let front = grid(-5.0, 65.0, -5.0, 45.0, 0.7, 0.0, false);
    let back = grid(-5.0, 65.0, -5.0, 45.0, 0.7, -3.0, true);
    (cloud, append(front, &back))
}

#[test]
fn an_overshooting_capped_mesh_is_cut_to_the_notched_plate() {
    let (cloud, mesh) = notched_plate_and_overshooting_envelope();
    let (out, report) = trimmed(&cloud, &mesh);
    let truth = BoundaryIndex::new(&cloud);
    let h = 1.0;
    let loops = out.boundary_loops();
    let border: Vec<f64> = loops
        .iter()
        .flatten()
        .map(|&v| truth.distance(out.vertices[v as usize]) / h)
        .collect();
    let mean = border.iter().sum::<f64>() / border.len() as f64;
    let max = border.iter().copied().fold(0.0, f64::max);
    let area_error = (out.area() / true_area_of_notched_plate(h) - 1.0).abs();
    eprintln!(
        "loops {} border→truth mean {mean:.3} max {max:.3} spacings, area error {:.2} %, {report:?}",
        loops.len(),
        100.0 * area_error
    );
    assert_eq!(loops.len(), 2, "outer border and the hole");
    assert!(
        mean <= 0.3 && max <= 2.0,
        "border mean {mean:.3}, max {max:.3}"
    );
    assert!(
        area_error <= 0.03,
        "area off by {:.2} %",
        100.0 * area_error
    );
    assert!(out.is_edge_manifold());
    assert!(
        out.vertices.iter().all(|v| v[2] == 0.0),
        "the far sheet must go"
    );
    for f in 0..out.faces.len() {
        assert!(out.face_area(f) > 1e-6 * h * h, "face {f} is degenerate");
        let [a, b, c] = out.faces[f].map(|i| out.vertices[i as usize]);
        let normal_z = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        assert!(normal_z > 0.0, "face {f} flipped");
    }
    // The far sheet and the cap over the hole go as pieces of their own;
    // nothing on this open plate lies behind a wall and is covered.
    assert!(report.pieces_dropped >= 2, "{report:?}");
    assert_eq!(report.pieces_restored, 0, "{report:?}");
}

/// Where a border did not close into a loop, no wall cuts the envelope off
/// and the piece beyond it is the part's own: the reach of the cloud (2 β)
/// ends it instead. The notched plate's mesh overshoots by 5 spacings; with
/// the outer loop left out of the edges, the overshoot is cut back to the
/// cloud's reach while the hole is still cut along its smoothed loop.
#[test]
fn envelope_that_no_wall_cuts_off_ends_at_the_clouds_reach() {
    let (cloud, mesh) = notched_plate_and_overshooting_envelope();
    let detection = detect_boundary(&cloud.points, &BpdOptions::default()).unwrap();
    let mut edges = reconstruct_edges(&cloud.points, &detection, &EdgeOptions::default());
    assert_eq!(edges.loops.len(), 2, "outer border and the hole");
    let outer = (0..2)
        .max_by_key(|&l| edges.loops[l].boundary_points.len())
        .unwrap();
    edges.loops.remove(outer);
    let (out, report) = trim_mesh(
        &mesh,
        &cloud.points,
        &detection,
        &edges,
        &TrimOptions::default(),
    )
    .unwrap();
    // Every kept vertex within reach of the cloud. The cut runs straight
    // across each face between the field's zeros at its edges, so it may
    // pass up to half a face diagonal (0.5 here) farther out.
    let farthest = out
        .vertices
        .iter()
        .map(|v| {
            let (i, d2) = cloud
                .points
                .iter()
                .enumerate()
                .map(|(i, p)| (i, (0..3).map(|c| (v[c] - p[c]).powi(2)).sum::<f64>()))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            d2.sqrt() - TrimOptions::default().reach * detection.beta[i]
        })
        .fold(f64::NEG_INFINITY, f64::max);
    eprintln!("farthest vertex {farthest:.3} beyond reach, {report:?}");
    assert!(farthest <= 0.5, "{farthest:.3} beyond the reach");
    assert!(report.faces_out_of_reach > 0, "{report:?}");
    // The overshoot went, and only it: the area is the plate's and a
    // fringe within reach of its outer border (perimeter 200 spacings).
    let plate = true_area_of_notched_plate(1.0);
    let beta_max = detection.beta.iter().copied().fold(0.0, f64::max);
    let fringe = 200.0 * TrimOptions::default().reach * beta_max;
    assert!(
        out.area() > plate && out.area() < plate + fringe,
        "area {} against the plate's {plate} and the fringe {fringe}",
        out.area()
    );
    assert!(
        out.vertices.iter().all(|v| v[2] == 0.0),
        "the far sheet must go"
    );
    assert!(out.is_edge_manifold());
    // The hole is still cut along its smoothed loop: the shorter border.
    let borders = out.boundary_loops();
    assert_eq!(borders.len(), 2);
    let hole = borders.iter().min_by_key(|b| b.len()).unwrap();
    let truth = BoundaryIndex::new(&cloud);
    let to_truth: Vec<f64> = hole
        .iter()
        .map(|&v| truth.distance(out.vertices[v as usize]))
        .collect();
    let mean = to_truth.iter().sum::<f64>() / to_truth.len() as f64;
    let max = to_truth.iter().copied().fold(0.0, f64::max);
    assert!(
        mean <= 0.3 && max <= 2.0,
        "hole border mean {mean:.3}, max {max:.3}"
    );
}

/// The reach cut opens a gap of the cloud only where the spot out of reach
/// is at least a disc of radius β: a sheet sampled with two round gaps and
/// no loops at all (as if no border had closed), meshed finely straight
/// across both. The gap of 6 β leaves a spot of about 4 β radius out of
/// reach: a hole. The gap of 2.5 β leaves one of about 0.5 β, which the
/// cloud cannot resolve: no hole.
#[test]
fn only_gaps_the_cloud_resolves_open_holes_beyond_its_reach() {
    let mut rng = 0x2545_f491_4f6c_dd1du64;
    let mut jitter = move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let lattice: Vec<Point3> = (0..60)
        .flat_map(|j| (0..60).map(move |i| (i, j)))
        .map(|(i, j)| [i as f64 + 0.3 * jitter(), j as f64 + 0.3 * jitter(), 0.0])
        .collect();
    let beta = {
        let d = detect_boundary(&lattice, &BpdOptions::default()).unwrap();
        let mut b = d.beta.clone();
        b.sort_by(f64::total_cmp);
        b[b.len() / 2]
    };
    let (small, big) = (([15.0, 30.0], 2.5 * beta), ([44.0, 30.0], 6.0 * beta));
    let outside = |p: &Point3, (c, r): ([f64; 2], f64)| (p[0] - c[0]).hypot(p[1] - c[1]) > r;
    let points: Vec<Point3> = lattice
        .into_iter()
        .filter(|p| outside(p, small) && outside(p, big))
        .collect();
    let detection = detect_boundary(&points, &BpdOptions::default()).unwrap();
    let mut edges = reconstruct_edges(&points, &detection, &EdgeOptions::default());
    edges.loops.clear();
    let mesh = grid(0.0, 59.0, 0.0, 59.0, 0.4, 0.0, false);
    let (out, report) =
        trim_mesh(&mesh, &points, &detection, &edges, &TrimOptions::default()).unwrap();
    // Loops inside the sheet's own border.
    let inner = |l: &&Vec<u32>| {
        l.iter().all(|&v| {
            let p = out.vertices[v as usize];
            p[0] > 3.0 && p[0] < 56.0 && p[1] > 3.0 && p[1] < 56.0
        })
    };
    let holes: Vec<[f64; 2]> = out
        .boundary_loops()
        .iter()
        .filter(inner)
        .map(|l| {
            let n = l.len() as f64;
            let sum = l.iter().fold([0.0, 0.0], |s, &v| {
                let p = out.vertices[v as usize];
                [s[0] + p[0], s[1] + p[1]]
            });
            [sum[0] / n, sum[1] / n]
        })
        .collect();
    eprintln!("β {beta:.3}, holes at {holes:?}, {report:?}");
    assert_eq!(holes.len(), 1, "one hole: {holes:?}");
    assert!(
        (holes[0][0] - 44.0).hypot(holes[0][1] - 30.0) < 1.0,
        "{holes:?}"
    );
    assert!(report.faces_out_of_reach > 0, "{report:?}");
    assert!(out.is_edge_manifold());
}
