//! Border cleanup against ground truth: jagged Delaunay meshes of jittered
//! synthetic clouds with known borders, cleaned by [`trim::clean_mesh`];
//! the cleaned border must lie within 0.25 local spacings of the true
//! border on average.

use testkit::{
    synthetic::jagged::{border_error, jagged_mesh},
    synthetic::{self, SyntheticCloud},
};
use trim::{clean_mesh, detect_boundary, BpdOptions, CleanOptions, CleanReport, Mesh};

struct Case {
    truth: SyntheticCloud,
    input: Mesh,
    output: Mesh,
    report: CleanReport,
}

fn clean(truth: SyntheticCloud, offset: bool) -> Case {
    let input = jagged_mesh(&truth);
    let detection = detect_boundary(&input.vertices, &BpdOptions::default()).unwrap();
    let (output, report) = clean_mesh(
        &input,
        &detection.beta,
        &CleanOptions {
            offset,
            ..CleanOptions::default()
        },
    )
    .unwrap();
    Case {
        truth,
        input,
        output,
        report,
    }
}

fn cases() -> Vec<SyntheticCloud> {
    vec![
        synthetic::blade(4.0, 1),
        synthetic::blade(8.0, 2),
        synthetic::notched_plate(1.0, 3),
        synthetic::curved_disc_with_hole(1.0, 4),
    ]
}

/// Measured (offset on): mean 0.11–0.15 spacings after, 0.27–0.37 before;
/// largest 0.43–0.60 after. The paper's edges (offset off) keep the jagged
/// border's inward offset: 0.26–0.37.
#[test]
fn cleaned_borders_lie_on_the_true_border() {
    for truth in cases() {
        let c = clean(truth, true);
        let before = border_error(&c.input, &c.truth);
        let after = border_error(&c.output, &c.truth);
        let name = &c.truth.name;
        assert!(
            after.0 <= 0.25,
            "{name}: mean {:.3} (before {:.3})",
            after.0,
            before.0
        );
        assert!(after.1 <= 1.0, "{name}: largest {:.3}", after.1);
        assert!(after.0 < 0.6 * before.0, "{name}: {before:?} -> {after:?}");
        assert_eq!(c.report.loops_smoothed, c.truth.boundary.len(), "{name}");
        assert!(
            c.report.loops_left.is_empty(),
            "{name}: {:?}",
            c.report.loops_left
        );
        assert_eq!(
            c.output.boundary_loops().len(),
            c.truth.boundary.len(),
            "{name}"
        );
    }
}

/// The paper's edges run through the border vertices: without the offset
/// the border stays where the jagged one was on average (smoother, not
/// closer), which is why the offset is on by default.
#[test]
fn without_the_offset_the_border_keeps_the_inward_bias() {
    let c = clean(synthetic::blade(4.0, 1), false);
    let before = border_error(&c.input, &c.truth);
    let after = border_error(&c.output, &c.truth);
    assert!(after.0 > 0.8 * before.0, "{before:?} -> {after:?}");
    assert!(after.1 < before.1, "{before:?} -> {after:?}");
}

/// The output is a valid mesh: edge-manifold, consistently oriented with
/// the input (every face faces the true normal), no degenerate or sliver
/// faces among the new ones, no duplicate vertices; vertices that are not
/// on the new border are input vertices, bit for bit.
#[test]
fn cleaned_meshes_are_valid_and_keep_the_interior() {
    for truth in cases() {
        let c = clean(truth, true);
        let name = &c.truth.name;
        let out = &c.output;
        assert!(out.is_edge_manifold(), "{name}");
        assert_consistently_oriented(out, name);
        assert!(
            c.report.min_angle_new > 10.0,
            "{name}: {}",
            c.report.min_angle_new
        );
        let mut seen = std::collections::HashSet::new();
        for v in &out.vertices {
            assert!(
                seen.insert(v.map(f64::to_bits)),
                "{name}: duplicate vertex {v:?}"
            );
        }
        let input: std::collections::HashSet<[u64; 3]> = c
            .input
            .vertices
            .iter()
            .map(|v| v.map(f64::to_bits))
            .collect();
        let border: std::collections::HashSet<u32> =
            out.boundary_loops().into_iter().flatten().collect();
        for (i, v) in out.vertices.iter().enumerate() {
            assert!(
                input.contains(&v.map(f64::to_bits)) || border.contains(&(i as u32)),
                "{name}: vertex {i} is new but not on the border"
            );
        }
        let cloud_index: std::collections::HashMap<[u64; 3], usize> = c
            .truth
            .points
            .iter()
            .enumerate()
            .map(|(i, p)| (p.map(f64::to_bits), i))
            .collect();
        for f in &out.faces {
            let [a, b, cc] = f.map(|v| out.vertices[v as usize]);
            let n = cross(sub(b, a), sub(cc, a));
            let centre = [0, 1, 2].map(|k| (a[k] + b[k] + cc[k]) / 3.0);
            let i = [a, b, cc]
                .iter()
                .find_map(|p| cloud_index.get(&p.map(f64::to_bits)).copied())
                .unwrap_or_else(|| nearest_point(&c.truth.points, centre));
            assert!(
                dot(n, c.truth.normals[i]) > 0.0,
                "{name}: a face turned over"
            );
        }
    }
}

/// Same input, same bytes out (the bands are processed in parallel).
#[test]
fn cleaning_is_deterministic() {
    let a = clean(synthetic::blade(8.0, 5), true);
    let b = clean(synthetic::blade(8.0, 5), true);
    assert_eq!(a.output, b.output);
}

fn nearest_point(points: &[[f64; 3]], p: [f64; 3]) -> usize {
    (0..points.len())
        .min_by(|&i, &j| {
            let d = |q: [f64; 3]| (0..3).map(|k| (q[k] - p[k]).powi(2)).sum::<f64>();
            d(points[i]).total_cmp(&d(points[j]))
        })
        .unwrap()
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Rigid motion and change of units do not change the result: the cleaned
/// border error (in local spacings) and the face counts are the same for
/// the blade moved far from the origin, turned, and scaled to metres.
#[test]
fn cleaning_does_not_depend_on_pose_or_units() {
    let truth = synthetic::blade(8.0, 6);
    let input = jagged_mesh(&truth);
    let base = clean_mesh_of(&input);
    let (c, s) = (0.6f64, 0.8f64);
    let moved = |p: [f64; 3]| {
        let q = [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]];
        [
            (q[0] + 5e4) * 1e-3,
            (q[1] - 2e4) * 1e-3,
            (q[2] + 7e3) * 1e-3,
        ]
    };
    let input_moved = Mesh {
        vertices: input.vertices.iter().map(|&p| moved(p)).collect(),
        faces: input.faces.clone(),
    };
    let other = clean_mesh_of(&input_moved);
    assert_eq!(base.1.loops_smoothed, other.1.loops_smoothed);
    assert_eq!(base.0.faces.len(), other.0.faces.len());
    // Same border, moved: every border vertex of one is within 1e-6 of
    // the spacing of a border vertex of the other.
    let border = |m: &Mesh| -> Vec<[f64; 3]> {
        m.boundary_loops()
            .into_iter()
            .flatten()
            .map(|v| m.vertices[v as usize])
            .collect()
    };
    let (a, b) = (border(&base.0), border(&other.0));
    assert_eq!(a.len(), b.len());
    for p in a.iter().map(|&p| moved(p)) {
        let nearest = b
            .iter()
            .map(|q| ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt())
            .fold(f64::INFINITY, f64::min);
        assert!(nearest < 1e-6 * 8.0e-3, "{nearest}");
    }
}

/// Random jagged meshes (shapes, pitches, seeds, jitter of the surface
/// along its normal): cleaning never fails, the output is edge-manifold
/// and consistently oriented, every loop is smoothed, and the border is
/// closer to the truth than the input's.
#[test]
fn random_jagged_meshes_are_cleaned() {
    let mut rng = synthetic::SplitMix64::new(42);
    for case in 0..12u64 {
        let pitch = rng.range(0.6, 1.6);
        let truth = match case % 3 {
            0 => synthetic::blade(4.0 * pitch, case),
            1 => synthetic::notched_plate(pitch, case),
            _ => synthetic::curved_disc_with_hole(pitch, case),
        };
        let noise = rng.range(0.0, 0.1);
        let mut input = jagged_mesh(&truth);
        let noisy = truth.with_noise(noise, case);
        let index: std::collections::HashMap<[u64; 3], usize> = truth
            .points
            .iter()
            .enumerate()
            .map(|(i, p)| (p.map(f64::to_bits), i))
            .collect();
        for v in input.vertices.iter_mut() {
            *v = noisy[index[&v.map(f64::to_bits)]];
        }
        let name = format!("{} case {case} noise {noise:.3}", truth.name);
        let (out, report) = clean_mesh_of(&input);
        assert!(out.is_edge_manifold(), "{name}");
        assert_consistently_oriented(&out, &name);
        assert_eq!(
            report.loops_smoothed,
            truth.boundary.len(),
            "{name}: {:?}",
            report.loops_left
        );
        let before = border_error(&input, &truth);
        let after = border_error(&out, &truth);
        assert!(after.0 < before.0, "{name}: {before:?} -> {after:?}");
        assert!(after.0 <= 0.25, "{name}: {after:?}");
    }
}

fn clean_mesh_of(input: &Mesh) -> (Mesh, CleanReport) {
    let beta = trim::local_resolution(&input.vertices, &BpdOptions::default()).unwrap();
    clean_mesh(input, &beta, &CleanOptions::default()).unwrap()
}

/// Every directed edge is used once: neighbouring faces run their shared
/// edge in opposite directions.
fn assert_consistently_oriented(mesh: &Mesh, name: &str) {
    let mut directed = std::collections::HashSet::new();
    for f in &mesh.faces {
        for k in 0..3 {
            assert!(
                directed.insert((f[k], f[(k + 1) % 3])),
                "{name}: an edge run twice the same way"
            );
        }
    }
}
