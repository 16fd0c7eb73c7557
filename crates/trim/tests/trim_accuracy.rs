//! Trimming on synthetic clouds with ground truth: a mesh that overshoots
//! the part, caps its hole and has an unsupported far sheet is cut back to
//! the smoothed boundary. Run with `--nocapture` for the numbers.

use trim::edges::{reconstruct_edges, EdgeOptions};
use trim::evaluate::BoundaryIndex;
use trim::mesh::Mesh;
use trim::synthetic::{self, SyntheticCloud};
use trim::trimming::trim_mesh;
use trim::{detect_boundary, BpdOptions, Point3};

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

fn trimmed(cloud: &SyntheticCloud, mesh: &Mesh) -> (Mesh, trim::trimming::TrimReport) {
    let detection = detect_boundary(&cloud.points, &BpdOptions::default()).unwrap();
    let edges = reconstruct_edges(&cloud.points, &detection, &EdgeOptions::default());
    trim_mesh(mesh, &cloud.points, &detection, &edges).unwrap()
}

#[test]
fn an_overshooting_capped_mesh_is_cut_to_the_notched_plate() {
    let cloud = synthetic::notched_plate(1.0, 2);
    let front = grid(-5.0, 65.0, -5.0, 45.0, 0.7, 0.0, false);
    let back = grid(-5.0, 65.0, -5.0, 45.0, 0.7, -3.0, true);
    let mesh = append(front, &back);
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
