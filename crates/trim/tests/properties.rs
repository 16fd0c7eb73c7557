//! Property tests (proptest) of the whole pipeline on generated patches:
//! what must hold for every input, not only for the hand-picked ones.
//!
//! - Detection does not depend on the order of the input points (labels
//!   exactly; β to the last bits, summed in neighbour order).
//! - The fast detection equals the reference one, for any k, on awkward
//!   clouds:
//!   quantised coordinates (many exact distance ties), duplicates, a stray
//!   line of points, any scale; and their labels survive a generic
//!   rotation and a move 10⁵ units away, which round every coordinate.
//! - The whole job (detect, edges, trim) moves with the part; so do the
//!   border cleanup of a triangulated scan and the Delaunay mesh of a
//!   cloud.
//! - Trimming and the Delaunay mesh do not depend on the order of the
//!   cloud's points.
//! - Trimming a mesh that overshoots the cloud gives a valid mesh, no
//!   larger than the input, the same on every run.

use proptest::prelude::*;
use testkit::{
    synthetic::jagged::jagged_mesh,
    synthetic::{jittered_grid, Circle, Region, SpacingField, Surface},
};
use trim::{
    clean_mesh, delaunay_mesh, detect_boundary, detect_boundary_reference, reconstruct_edges,
    trim_mesh, BpdOptions, CleanOptions, DelaunayOptions, EdgeOptions, Mesh, Point3, TrimOptions,
};

/// A jittered patch of about `20 × 14 / h²` points on a gently curved
/// surface, with one hole; `seed` chooses the surface, the hole and the
/// jitter.
fn patch(seed: u64, h: f64) -> Vec<Point3> {
    let surface = surface(seed);
    let region = region(seed);
    jittered_grid(&region, SpacingField::Uniform(h), 0.15, None, seed)
        .into_iter()
        .map(|(uv, _)| surface.point(uv))
        .collect()
}

/// [`patch`] with every coordinate rounded to a multiple of `quantum`
/// (none when 0), as scanners write them.
fn quantised_patch(seed: u64, h: f64, quantum: f64) -> Vec<Point3> {
    let quantise = |p: Point3| {
        if quantum > 0.0 {
            p.map(|c| (c / quantum).round() * quantum)
        } else {
            p
        }
    };
    patch(seed, h).into_iter().map(quantise).collect()
}

/// `points` moved by `shift` along every axis.
fn moved(points: &[Point3], shift: f64) -> Vec<Point3> {
    points.iter().map(|p| p.map(|c| c + shift)).collect()
}

/// `mesh` moved by `shift` along every axis.
fn moved_mesh(mesh: &Mesh, shift: f64) -> Mesh {
    Mesh {
        vertices: moved(&mesh.vertices, shift),
        faces: mesh.faces.clone(),
    }
}

/// Each of `there` is the same of `here` moved by `shift`, within 10⁻⁶
/// (coordinates round at the shift's scale: 1e5 rounds at about 1.5e-11).
fn assert_moved(here: &[Point3], there: &[Point3], shift: f64) -> Result<(), TestCaseError> {
    prop_assert_eq!(here.len(), there.len());
    for (a, b) in here.iter().zip(there) {
        for k in 0..3 {
            prop_assert!((a[k] + shift - b[k]).abs() < 1e-6, "{:?} {:?}", a, b);
        }
    }
    Ok(())
}

fn surface(seed: u64) -> Surface {
    match seed % 3 {
        0 => Surface::Plane,
        1 => Surface::Saddle { a: 0.004 },
        _ => Surface::Cylinder { radius: 30.0 },
    }
}

fn region(seed: u64) -> Region {
    let mut region = Region::rectangle([0.0, 0.0], [20.0, 14.0]);
    let (cu, cv) = (6.0 + (seed % 7) as f64, 5.0 + (seed % 5) as f64);
    region.holes.push(Circle {
        centre: [cu, cv],
        radius: 2.5,
    });
    region
}

/// `cases` cases (or `PROPTEST_CASES`) from a fixed seed, so that every
/// run, CI's included, tries the same clouds; a wider search is
/// `PROPTEST_CASES=5000`.
fn config(cases: u32) -> ProptestConfig {
    let from_env = ProptestConfig::default();
    let cases = if std::env::var_os("PROPTEST_CASES").is_some() {
        from_env.cases
    } else {
        cases
    };
    ProptestConfig {
        cases,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x6d65_7368_7472_696d),
        ..from_env
    }
}

/// The permutation of 0..n drawn from `seed` (Fisher–Yates).
fn permutation(n: usize, seed: u64) -> Vec<usize> {
    let mut rng = testkit::synthetic::SplitMix64::new(seed);
    let mut order: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        let j = (rng.next_u64() % (i as u64 + 1)) as usize;
        order.swap(i, j);
    }
    order
}

proptest! {
    #![proptest_config(config(200))]

    #[test]
    fn detection_does_not_depend_on_the_input_order(seed in 0u64..1_000_000, shuffle in any::<u64>(), anisotropy in any::<bool>()) {
        let cloud = patch(seed, 1.0);
        let order = permutation(cloud.len(), shuffle);
        let shuffled: Vec<Point3> = order.iter().map(|&i| cloud[i]).collect();
        let options = BpdOptions { anisotropy, ..BpdOptions::default() };
        let a = detect_boundary(&cloud, &options).unwrap();
        let b = detect_boundary(&shuffled, &options).unwrap();
        for (new, &old) in order.iter().enumerate() {
            prop_assert_eq!(b.boundary[new], a.boundary[old], "point {} (was {})", new, old);
            // β sums its distances in neighbour order, which the input
            // order decides among near-ties (docs/bpd.md, "Ties"): equal
            // to the last bits.
            let (x, y) = (b.beta[new], a.beta[old]);
            prop_assert!((x - y).abs() <= 1e-12 * y, "β of point {}: {} against {}", new, x, y);
        }
        // The links, mapped back to the original indices.
        let mut mapped: Vec<[u32; 2]> = b
            .links
            .iter()
            .map(|&[p, q]| {
                let (p, q) = (order[p as usize] as u32, order[q as usize] as u32);
                [p.min(q), p.max(q)]
            })
            .collect();
        mapped.sort_unstable();
        prop_assert_eq!(mapped, a.links.clone());
    }

    #[test]
    fn fast_detection_equals_the_reference_for_any_k(
        seed in 0u64..1_000_000,
        k in prop_oneof![Just(4usize), Just(7), Just(16), Just(45), Just(64)],
        h in prop_oneof![Just(0.5), Just(1.2)],
        quantum in prop_oneof![Just(0.0), Just(0.05)],
        duplicates in 0usize..40,
        anisotropy in any::<bool>(),
    ) {
        let mut cloud = quantised_patch(seed, h, quantum);
        let n = cloud.len();
        for i in 0..duplicates {
            cloud.push(cloud[(i * 7919) % n]);
        }
        let options = BpdOptions { k, anisotropy, view: None };
        let fast = detect_boundary(&cloud, &options).unwrap();
        let plain = detect_boundary_reference(&cloud, &options).unwrap();
        prop_assert_eq!(&fast.boundary, &plain.boundary);
        prop_assert_eq!(&fast.beta, &plain.beta);
        prop_assert_eq!(&fast.links, &plain.links);
    }

    #[test]
    fn fast_detection_equals_the_reference_on_awkward_clouds(
        seed in 0u64..1_000_000,
        quantum in prop_oneof![Just(0.0), Just(0.05), Just(0.25)],
        duplicates in 0usize..40,
        stray_line in any::<bool>(),
        log_scale in -3i32..4,
        far in any::<bool>(),
        anisotropy in any::<bool>(),
    ) {
        let mut cloud = patch(seed, 1.2);
        if quantum > 0.0 {
            for p in &mut cloud {
                *p = p.map(|c| (c / quantum).round() * quantum);
            }
        }
        let n = cloud.len();
        for i in 0..duplicates {
            cloud.push(cloud[(i * 7919) % n]);
        }
        if stray_line {
            // A scan line sticking out of the patch's edge.
            cloud.extend((1..12).map(|i| [20.0 + 0.8 * i as f64, 7.0, 0.0]));
        }
        let scale = 10f64.powi(log_scale);
        for p in &mut cloud {
            *p = p.map(|c| c * scale);
        }
        let options = BpdOptions { anisotropy, ..BpdOptions::default() };
        let fast = detect_boundary(&cloud, &options).unwrap();
        let plain = detect_boundary_reference(&cloud, &options).unwrap();
        prop_assert_eq!(fast.boundary.len(), cloud.len());
        prop_assert!(fast.beta.iter().all(|b| b.is_finite() && *b > 0.0));
        prop_assert_eq!(&fast.boundary, &plain.boundary);
        prop_assert_eq!(&fast.beta, &plain.beta);
        prop_assert_eq!(&fast.links, &plain.links);
        {
            // A generic rotation rounds every coordinate: exact ties become
            // near ones, which must still tie.
            let (a, b) = (0.6_f64, 0.9_f64);
            let (ca, sa, cb, sb) = (a.cos(), a.sin(), b.cos(), b.sin());
            let rotated: Vec<Point3> = cloud
                .iter()
                .map(|p| {
                    let (x, y) = (ca * p[0] - sa * p[1], sa * p[0] + ca * p[1]);
                    [x, cb * y - sb * p[2], sb * y + cb * p[2]]
                })
                .collect();
            let turned = detect_boundary(&rotated, &options).unwrap();
            prop_assert_eq!(&turned.boundary, &fast.boundary);
        }
        if far {
            // Far from the origin the coordinates themselves round (at
            // 1e5 a double's step is 1.5e-11), which on quantised clouds
            // turns exact distance ties into near ones: the labels must not
            // move with them (docs/bpd.md, "Ties and duplicates").
            let moved: Vec<Point3> = cloud.iter().map(|p| p.map(|c| c + 1e5 * scale)).collect();
            let there = detect_boundary(&moved, &options).unwrap();
            prop_assert_eq!(&there.boundary, &fast.boundary);
        }
    }
}

/// A grid mesh over the patch's rectangle grown by `margin` on every side
/// (a reconstruction that overshoots the cloud and caps its hole), on the
/// same surface, with its vertices jittered.
fn overshooting_mesh(seed: u64, margin: f64, step: f64) -> Mesh {
    let surface = surface(seed);
    let mut rng = testkit::synthetic::SplitMix64::new(seed ^ 0xabcd);
    let (nu, nv) = (
        ((20.0 + 2.0 * margin) / step) as u32,
        ((14.0 + 2.0 * margin) / step) as u32,
    );
    let mut vertices = Vec::new();
    for j in 0..=nv {
        for i in 0..=nu {
            let u = -margin + i as f64 * step + rng.range(-0.2, 0.2) * step;
            let v = -margin + j as f64 * step + rng.range(-0.2, 0.2) * step;
            vertices.push(surface.point([u, v]));
        }
    }
    let at = |i: u32, j: u32| j * (nu + 1) + i;
    let mut faces = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            faces.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            faces.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    Mesh { vertices, faces }
}

proptest! {
    #![proptest_config(config(24))]

    #[test]
    fn trimming_gives_a_valid_smaller_mesh_the_same_every_time(
        seed in 0u64..1_000_000,
        margin in 0.5f64..4.0,
        step in 0.4f64..1.5,
    ) {
        let cloud = patch(seed, 0.8);
        let detection = detect_boundary(&cloud, &BpdOptions::default()).unwrap();
        let edges = reconstruct_edges(&cloud, &detection, &EdgeOptions::default());
        let mesh = overshooting_mesh(seed, margin, step);
        let (out, report) = trim_mesh(&mesh, &cloud, &detection, &edges, &TrimOptions::default()).unwrap();
        prop_assert!(out.validate().is_ok());
        prop_assert!(out.vertices.iter().flatten().all(|c| c.is_finite()));
        prop_assert_eq!(report.faces_in, mesh.faces.len());
        prop_assert_eq!(report.faces_out, out.faces.len());
        prop_assert!(report.area_out > 0.0);
        prop_assert!(report.area_out <= report.area_in * (1.0 + 1e-12));
        // The hole and the overshoot are gone: the part is smaller than
        // the mesh by at least most of the margin band.
        let band = 2.0 * margin * (20.0 + 14.0);
        prop_assert!(report.area_out < report.area_in - 0.5 * band);
        let (again, _) = trim_mesh(&mesh, &cloud, &detection, &edges, &TrimOptions::default()).unwrap();
        prop_assert_eq!(&again.faces, &out.faces);
        prop_assert_eq!(&again.vertices, &out.vertices);
    }

    #[test]
    fn the_whole_job_moves_with_the_part(
        seed in 0u64..1_000_000,
        quantum in prop_oneof![Just(0.0), Just(0.05)],
        shift in prop_oneof![Just(1e3), Just(1e5)],
    ) {
        let cloud = quantised_patch(seed, 0.8, quantum);
        let mesh = overshooting_mesh(seed, 2.0, 0.7);
        let job = |cloud: &[Point3], mesh: &Mesh| {
            let detection = detect_boundary(cloud, &BpdOptions::default()).unwrap();
            let edges = reconstruct_edges(cloud, &detection, &EdgeOptions::default());
            let (out, _) = trim_mesh(mesh, cloud, &detection, &edges, &TrimOptions::default()).unwrap();
            (detection.boundary, edges.loops.len(), out)
        };
        let (labels, loops, out) = job(&cloud, &mesh);
        let (labels2, loops2, out2) = job(&moved(&cloud, shift), &moved_mesh(&mesh, shift));
        prop_assert_eq!(labels, labels2);
        prop_assert_eq!(loops, loops2);
        prop_assert_eq!(&out.faces, &out2.faces);
        assert_moved(&out.vertices, &out2.vertices, shift)?;
    }

    #[test]
    fn border_cleanup_moves_with_the_part(
        seed in 0u64..1_000_000,
        spacing in prop_oneof![Just(1.5), Just(2.0)],
        disc in any::<bool>(),
        shift in prop_oneof![Just(1e3), Just(1e5)],
    ) {
        let truth = if disc {
            testkit::synthetic::curved_disc_with_hole(spacing + 1.0, seed)
        } else {
            testkit::synthetic::notched_plate(spacing, seed)
        };
        let mesh = jagged_mesh(&truth);
        let job = |mesh: &Mesh| {
            let detection = detect_boundary(&mesh.vertices, &BpdOptions::default()).unwrap();
            clean_mesh(mesh, &detection.beta, &CleanOptions::default()).unwrap()
        };
        let (out, report) = job(&mesh);
        let (out2, report2) = job(&moved_mesh(&mesh, shift));
        // Not vacuous: the border was replaced.
        prop_assert!(report.loops_smoothed > 0 && report.faces_added > 0);
        prop_assert_eq!(&out.faces, &out2.faces);
        prop_assert_eq!(report.loops_smoothed, report2.loops_smoothed);
        prop_assert_eq!(report.faces_added, report2.faces_added);
        prop_assert_eq!(&report.loops_left, &report2.loops_left);
        assert_moved(&out.vertices, &out2.vertices, shift)?;
    }

    #[test]
    fn the_delaunay_mesh_moves_with_the_part(
        seed in 0u64..1_000_000,
        quantum in prop_oneof![Just(0.0), Just(0.05)],
        shift in prop_oneof![Just(1e3), Just(1e5)],
    ) {
        let cloud = quantised_patch(seed, 0.8, quantum);
        let job = |cloud: &[Point3]| {
            let detection = detect_boundary(cloud, &BpdOptions::default()).unwrap();
            let edges = reconstruct_edges(cloud, &detection, &EdgeOptions::default());
            delaunay_mesh(cloud, &detection, &edges, &DelaunayOptions::default()).unwrap()
        };
        let (out, out2) = (job(&cloud), job(&moved(&cloud, shift)));
        prop_assert!(!out.faces.is_empty());
        assert_moved(&out.vertices, &out2.vertices, shift)?;
        // Quantised clouds included: their lattice's co-circular quads take
        // the canonical diagonal (`delaunay::diagonals`).
        prop_assert_eq!(&out.faces, &out2.faces);
    }

    #[test]
    fn trimming_does_not_depend_on_the_cloud_order(
        seed in 0u64..1_000_000,
        shuffle in any::<u64>(),
    ) {
        // Unquantised: on a quantised cloud exact distance ties go by input
        // order already in BPD (docs/bpd.md, "Ties and duplicates").
        let cloud = patch(seed, 0.8);
        let order = permutation(cloud.len(), shuffle);
        let shuffled: Vec<Point3> = order.iter().map(|&i| cloud[i]).collect();
        let mesh = overshooting_mesh(seed, 2.0, 0.7);
        let job = |cloud: &[Point3]| {
            let detection = detect_boundary(cloud, &BpdOptions::default()).unwrap();
            let edges = reconstruct_edges(cloud, &detection, &EdgeOptions::default());
            trim_mesh(&mesh, cloud, &detection, &edges, &TrimOptions::default()).unwrap().0
        };
        let (out, out2) = (job(&cloud), job(&shuffled));
        prop_assert_eq!(&out.faces, &out2.faces);
        assert_moved(&out.vertices, &out2.vertices, 0.0)?;
    }

    #[test]
    fn the_delaunay_mesh_does_not_depend_on_the_cloud_order(
        seed in 0u64..1_000_000,
        shuffle in any::<u64>(),
    ) {
        let cloud = patch(seed, 0.8);
        let order = permutation(cloud.len(), shuffle);
        let shuffled: Vec<Point3> = order.iter().map(|&i| cloud[i]).collect();
        let job = |cloud: &[Point3]| {
            let detection = detect_boundary(cloud, &BpdOptions::default()).unwrap();
            let edges = reconstruct_edges(cloud, &detection, &EdgeOptions::default());
            delaunay_mesh(cloud, &detection, &edges, &DelaunayOptions::default()).unwrap()
        };
        let (out, out2) = (job(&cloud), job(&shuffled));
        // The same triangles over the same positions, whatever the numbering.
        let triangles = |m: &Mesh| {
            let mut t: Vec<[[u64; 3]; 3]> = m
                .faces
                .iter()
                .map(|f| {
                    let mut corners = f.map(|v| m.vertices[v as usize].map(f64::to_bits));
                    let first = (0..3).min_by_key(|&k| corners[k]).unwrap_or(0);
                    corners.rotate_left(first);
                    corners
                })
                .collect();
            t.sort_unstable();
            t
        };
        prop_assert_eq!(triangles(&out), triangles(&out2));
    }
}
