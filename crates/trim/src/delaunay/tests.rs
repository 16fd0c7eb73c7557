use super::*;
use crate::planar::pinched_faces;
use rand::{RngExt, SeedableRng};

/// The straightforward local normals: one query a point, each on its
/// own, in input order (no Morton runs).
fn local_normals_reference(cloud: &[Point3], plane_normal: Point3) -> Vec<Point3> {
    let index = NeighbourIndex::new(cloud);
    let mut nb = Vec::new();
    (0..cloud.len())
        .map(|i| {
            index.nearest(i, NORMAL_K, &mut nb);
            oriented_normal(cloud, &nb, plane_normal)
        })
        .collect()
}

/// The Morton-run search gives the reference's normals bit for bit, on
/// wavy sheets with quantised coordinates (ties at every distance) and
/// repeated points, and on clouds smaller than a neighbourhood.
#[test]
fn local_normals_match_the_reference() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    for case in 0..12 {
        let n = [5, 29, 30, 31, 400, 3000][case % 6];
        let step = if case < 6 { 0.0 } else { 0.25 };
        let mut cloud: Vec<Point3> = (0..n)
            .map(|_| {
                let (x, y): (f64, f64) = (rng.random_range(0.0..20.0), rng.random_range(0.0..20.0));
                let p = [x, y, (0.3 * x).sin() + 0.1 * y];
                if step > 0.0 {
                    p.map(|c: f64| (c / step).round() * step)
                } else {
                    p
                }
            })
            .collect();
        for i in 0..n / 10 {
            cloud.push(cloud[(7 * i) % n]);
        }
        let up = [0.0, 0.0, 1.0];
        assert_eq!(
            local_normals(&cloud, up),
            local_normals_reference(&cloud, up),
            "case {case}"
        );
    }
}

/// A circle of `m` vertices round `c` of radius `r`, counter-clockwise
/// or not, as a smoothed loop of the cloud (each vertex smoothed from
/// the nearest cloud point).
fn circle(cloud: &[Point3], c: [f64; 2], r: f64, m: usize, ccw: bool) -> crate::edges::Loop {
    let sense = if ccw { 1.0 } else { -1.0 };
    let points: Vec<Point3> = (0..m)
        .map(|j| {
            let t = sense * std::f64::consts::TAU * j as f64 / m as f64;
            [c[0] + r * t.cos(), c[1] + r * t.sin(), 0.0]
        })
        .collect();
    let nearest = |p: Point3| {
        (0..cloud.len())
            .min_by(|&a, &b| norm2(sub(cloud[a], p)).total_cmp(&norm2(sub(cloud[b], p))))
            .unwrap_or(0) as u32
    };
    crate::edges::Loop {
        boundary_points: points.iter().map(|&p| nearest(p)).collect(),
        corners: Vec::new(),
        edges: vec![crate::edges::Edge {
            closed: true,
            points,
        }],
        sides: Vec::new(),
    }
}

/// A 30 × 30 grid of spacing 0.5, jittered by up to 0.1, on the wave
/// z = `bump`·sin(0.7x).
/// A 30 × 30 jittered sheet, bumped by `bump`·sin(0.7 x), and its
/// detection.
fn detected_sheet(rng: &mut rand_chacha::ChaCha8Rng, bump: f64) -> (Vec<Point3>, Detection) {
    let mut cloud = Vec::new();
    for i in 0..30 {
        for j in 0..30 {
            let jitter = [0, 1].map(|_| rng.random_range(-0.1..0.1));
            let (x, y) = (i as f64 * 0.5 + jitter[0], j as f64 * 0.5 + jitter[1]);
            cloud.push([x, y, bump * (x * 0.7).sin()]);
        }
    }
    let detection =
        crate::bpd::detect_boundary(&cloud, &crate::bpd::BpdOptions::default()).unwrap();
    (cloud, detection)
}

/// Edges of a random number of circles over the sheet, of random
/// centres, radii, vertex counts and senses.
fn random_circles(
    rng: &mut rand_chacha::ChaCha8Rng,
    cloud: &[Point3],
    count: std::ops::Range<usize>,
    radius: std::ops::Range<f64>,
) -> Edges {
    let loops = (0..rng.random_range(count))
        .map(|_| {
            let c = [rng.random_range(2.0..13.0), rng.random_range(2.0..13.0)];
            let (r, m) = (rng.random_range(radius.clone()), rng.random_range(4..40));
            circle(cloud, c, r, m, rng.random_bool(0.5))
        })
        .collect();
    Edges {
        loops,
        ..Default::default()
    }
}

/// A point near a loop in the projection but far from it in 3D, where
/// the surface turns steeply away near its border, goes in; one near
/// it in 3D, or on it in the projection, stays out.
#[test]
fn points_are_left_out_near_a_loop_by_their_distance_in_3d() {
    // A square loop of side 4 in the plane z = 0, β 1.
    let ring = crate::planar::flat_ring(vec![[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]);
    let bounds = Bounds {
        grid: SegmentGrid::new(std::slice::from_ref(&ring), 0.1),
        rings: vec![ring],
        sides: None,
        onto: BEST_FIT_PLANE,
    };
    let reach = 0.3;
    // 0.2 inside the bottom edge in the projection.
    let p = [2.0, 0.2];
    assert!(bounds.near_loop([2.0, 0.2, 0.0], p, reach));
    assert!(!bounds.near_loop([2.0, 0.2, 0.5], p, reach));
    // 0.05 inside: on the constraint for spade's purposes, whatever
    // its depth.
    assert!(bounds.near_loop([2.0, 0.05, 5.0], [2.0, 0.05], reach));
    assert!(!bounds.near_loop([2.0, 1.0, 0.0], [2.0, 1.0], reach));
}

/// A disc of radius 9 with three holes where no point was sampled:
/// one across the border, two overlapping each other. The smoothed
/// loops cross four times; the mesh is the disc less the holes, one
/// manifold piece with two borders, whichever way each loop runs.
#[test]
fn loops_that_cross_bound_the_surface_by_winding() {
    let holes = [([18.0, 10.0], 2.0), ([8.0, 10.0], 1.6), ([10.0, 10.0], 1.6)];
    let in_hole = |p: [f64; 2], slack: f64| {
        holes
            .iter()
            .any(|(c, r)| (p[0] - c[0]).hypot(p[1] - c[1]) < r - slack)
    };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let mut cloud = Vec::new();
    for i in 0..=48 {
        for j in 0..=48 {
            let p = [
                i as f64 * 0.42 + rng.random_range(-0.05..0.05),
                j as f64 * 0.42 + rng.random_range(-0.05..0.05),
            ];
            if (p[0] - 10.0).hypot(p[1] - 10.0) < 8.9 && !in_hole(p, -0.1) {
                cloud.push([p[0], p[1], 0.0]);
            }
        }
    }
    let detection =
        crate::bpd::detect_boundary(&cloud, &crate::bpd::BpdOptions::default()).unwrap();
    for senses in [[false, true, false, true], [true, false, true, false]] {
        let mut loops = vec![circle(&cloud, [10.0, 10.0], 9.0, 120, senses[0])];
        for ((c, r), ccw) in holes.iter().zip(&senses[1..]) {
            loops.push(circle(&cloud, *c, *r, 40, *ccw));
        }
        let edges = Edges {
            loops,
            ..Default::default()
        };
        let (mesh, report) =
            delaunay_mesh_with_report(&cloud, &detection, &edges, &DelaunayOptions::default())
                .unwrap();
        assert_eq!(report.loop_crossings, 4, "{senses:?}");
        mesh.check_manifold().unwrap();
        for f in 0..mesh.faces.len() {
            let [a, b, c] = mesh.faces[f].map(|v| mesh.vertices[v as usize]);
            let centre = [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0];
            assert!(!in_hole(centre, 0.0), "{senses:?}: face {f} in a hole");
            assert!((centre[0] - 10.0).hypot(centre[1] - 10.0) < 9.0);
        }
        assert_eq!(mesh.boundary_loops().len(), 2, "{senses:?}");
        // The disc less the holes, by the midpoint rule.
        let step = 0.02;
        let cells = (0..1000 * 1000)
            .filter(|k| {
                let p = [(k % 1000) as f64 + 0.5, (k / 1000) as f64 + 0.5].map(|c| c * step);
                (p[0] - 10.0).hypot(p[1] - 10.0) < 9.0 && !in_hole(p, 0.0)
            })
            .count();
        let expected = cells as f64 * step * step;
        assert!(
            (mesh.area() - expected).abs() < 0.01 * expected,
            "{} {expected}",
            mesh.area()
        );
    }
}

/// The flood fill's faces (parity where no loop crosses, winding where
/// loops cross) are those a ray cast over the loops keeps at the
/// face's centroid, the straightforward reference: on random circles
/// that cross one another and themselves, each run either way, over a
/// jittered grid.
#[test]
fn the_filled_faces_match_a_ray_cast_at_every_centroid() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let (cloud, detection) = detected_sheet(&mut rng, 0.0);
    let beta_median = median(&detection.beta);
    let plane = Projection::new(&cloud, None).unwrap();
    let (mut crossed, mut compared) = (0, 0);
    for case in 0..60 {
        let edges = random_circles(&mut rng, &cloud, 1..6, 1.0..6.0);
        let options = DelaunayOptions::default();
        let mut report = DelaunayReport::default();
        let Ok(bounds) = valid_rings(
            &edges,
            &cloud,
            &detection.beta,
            beta_median,
            &plane,
            &options,
            &mut report,
        ) else {
            continue;
        };
        let nodes = points_inside(
            &cloud,
            &detection.beta,
            &plane,
            &bounds,
            options.exclude,
            &mut report,
        );
        let Ok(t) = LoopCdt::build(nodes, &bounds, cloud.len(), &mut report) else {
            continue;
        };
        crossed += usize::from(bounds.sides.is_some());
        let kept: HashSet<_> = t.surface_faces().into_iter().collect();
        for f in t.cdt.fixed_inner_faces() {
            let p = t.cdt.face(f).vertices().map(|v| v.position());
            let centre = [
                (p[0].x + p[1].x + p[2].x) / 3.0,
                (p[0].y + p[1].y + p[2].y) / 3.0,
            ];
            if bounds.grid.near(centre, 1e-9 * beta_median) {
                continue;
            }
            compared += 1;
            assert_eq!(kept.contains(&f), bounds.inside(centre), "case {case}");
        }
    }
    assert!(crossed >= 20 && compared > 10_000, "{crossed} {compared}");
}

/// Whatever random circles bound it (crossing one another and
/// themselves, touching, nested), the Delaunay path gives a clear
/// error or a mesh that is manifold at every edge and vertex, whose
/// every vertex is a cloud point or on a loop.
#[test]
fn random_loops_give_an_error_or_a_manifold_mesh() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
    let (cloud, detection) = detected_sheet(&mut rng, 0.05);
    let (mut meshed, mut crossed) = (0, 0);
    for case in 0..80 {
        let edges = random_circles(&mut rng, &cloud, 1..7, 0.3..7.0);
        let options = DelaunayOptions::default();
        let Ok((mesh, report)) = delaunay_mesh_with_report(&cloud, &detection, &edges, &options)
        else {
            continue;
        };
        meshed += 1;
        crossed += usize::from(report.loop_crossings > 0);
        mesh.check_manifold().unwrap();
        let pinched = pinched_faces(&mesh.faces, mesh.vertices.len(), 0);
        assert!(pinched.is_empty(), "case {case}: a pinched vertex");
    }
    assert!(meshed >= 40 && crossed >= 20, "{meshed} {crossed}");
}

/// A flat 10 × 10 grid (162 triangles, area 81) with `extra` triangles standing on
/// edge above it, each `size` long: the triangle check counts their area.
fn grid_with_steep_triangles(extra: usize, size: f64) -> (Mesh, Vec<u32>, Vec<Point3>) {
    let n = 10;
    let mut vertices: Vec<Point3> = (0..n * n)
        .map(|i| [(i % n) as f64, (i / n) as f64, 0.0])
        .collect();
    let mut faces = Vec::new();
    for y in 0..n - 1 {
        for x in 0..n - 1 {
            let v = |dx: usize, dy: usize| ((y + dy) * n + x + dx) as u32;
            faces.extend([[v(0, 0), v(1, 0), v(1, 1)], [v(0, 0), v(1, 1), v(0, 1)]]);
        }
    }
    for k in 0..extra {
        let base = vertices.len() as u32;
        let x = k as f64;
        vertices.extend([[x, 0.5, 0.0], [x + size, 0.5, 0.0], [x, 0.5, size]]);
        faces.push([base, base + 1, base + 2]);
    }
    let reference: Vec<u32> = (0..vertices.len() as u32).collect();
    let normals = vec![[0.0, 0.0, 1.0]; vertices.len()];
    (Mesh { vertices, faces }, reference, normals)
}

#[test]
fn the_triangle_check_weighs_misfits_by_their_area() {
    let check = |extra: usize, size: f64| {
        let (mesh, reference, normals) = grid_with_steep_triangles(extra, size);
        let mut report = DelaunayReport::default();
        let result = check_triangles(
            &mesh,
            &reference,
            &normals,
            1.0,
            "the best-fit plane",
            &DelaunayOptions::default(),
            &mut report,
        );
        (result.is_ok(), report.misfit_area_percent)
    };
    // Three slivers on edge: 1.8 % of the triangles, 0.02 % of the area.
    let (accepted, percent) = check(3, 0.1);
    assert!(accepted && percent < 0.1, "{percent}");
    // Three triangles on edge, each larger than a grid cell: 4 % of the area.
    let (accepted, percent) = check(3, 1.5);
    assert!(!accepted && percent > 3.0, "{percent}");
}
