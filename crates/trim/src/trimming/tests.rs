//! Tests of trimming: the fast field, cut and pieces against plain
//! references on random inputs.

use super::*;
use crate::error::Placement;
use rand::{RngExt, SeedableRng};

/// Walls along a regular `n`-gon of radius `r` in the plane z = 0,
/// each segment's outward direction its own in-plane normal, the local
/// spacing growing round the loop.
fn polygon_walls(n: usize, r: f64) -> Walls {
    let points: Vec<Point3> = (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            [r * a.cos(), r * a.sin(), 0.0]
        })
        .collect();
    let out = (0..n)
        .map(|k| {
            let d = sub(points[(k + 1) % n], points[k]);
            let len = norm2(d).sqrt();
            [d[1] / len, -d[0] / len, 0.0]
        })
        .collect();
    Walls {
        tree: PointTree::new(&points),
        points,
        out,
        next: (0..n).map(|k| ((k + 1) % n) as u32).collect(),
        prev: (0..n).map(|k| ((k + n - 1) % n) as u32).collect(),
        beta: (0..n).map(|k| 1.0 + 0.1 * k as f64).collect(),
        loop_of: vec![0; n],
        loops: 1,
    }
}

#[test]
fn the_field_and_the_spacing_are_continuous_near_the_wall() {
    // Sharp turns (a hexagon) make the vertex regions wide. On a fine
    // grid over one corner and its two segments, within 0.2 of the
    // wall, neighbouring samples may differ in f by at most their
    // distance (f is 1-Lipschitz where the nearest point moves
    // continuously), and in spacing by far less than the 0.1 step
    // between the corners' spacings. (Inside a convex corner the
    // nearest point jumps from one segment to the other, but so close
    // to the corner that the spacing barely differs.)
    let walls = polygon_walls(6, 10.0);
    let step = 4e-3;
    let at = |i: i32, j: i32| [4.0 + i as f64 * step, -1.5 + j as f64 * step, 0.3];
    let (mut largest_jump, mut band_samples) = (0.0_f64, 0);
    for i in 0..1875 {
        for j in 0..2750 {
            let (f0, s0) = walls.signed_distance(at(i, j));
            if f0.abs() >= 0.2 {
                continue;
            }
            band_samples += 1;
            for (f, s) in [
                walls.signed_distance(at(i + 1, j)),
                walls.signed_distance(at(i, j + 1)),
            ] {
                largest_jump = largest_jump.max((f - f0).abs());
                assert!(
                    (s - s0).abs() < 0.02,
                    "spacing jumps from {s0} to {s} at {:?}",
                    at(i, j)
                );
            }
        }
    }
    assert!(band_samples > 100_000, "{band_samples}");
    assert!(
        largest_jump <= step * (1.0 + 1e-9),
        "f jumps by {largest_jump}"
    );
}

/// A grid of quads split into triangles with random faces left out (so
/// it falls into pieces), and a few faces repeated on one edge.
fn random_grid_mesh(seed: u64, side: u32) -> Mesh {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let at = |i: u32, j: u32| i * (side + 1) + j;
    let vertices = (0..=side)
        .flat_map(|i| (0..=side).map(move |j| [i as f64, j as f64, 0.0]))
        .collect();
    let mut faces = Vec::new();
    for i in 0..side {
        for j in 0..side {
            if rng.random_range(0.0..1.0) < 0.45 {
                faces.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            }
            if rng.random_range(0.0..1.0) < 0.45 {
                faces.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }
    let extra: Vec<[u32; 3]> = faces.iter().step_by(17).copied().collect();
    faces.extend(extra);
    Mesh { vertices, faces }
}

/// The reach's field by the k-d tree equals the plain one: the nearest
/// point by scanning them all, its β, g = d − 2β.
#[test]
fn the_reach_matches_a_scan_of_every_point() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(21);
    for _ in 0..20 {
        let cloud: Vec<Point3> = (0..500)
            .map(|_| [0, 1, 2].map(|_| rng.random_range(-10.0..10.0)))
            .collect();
        let beta: Vec<f64> = (0..cloud.len())
            .map(|_| rng.random_range(0.1..2.0))
            .collect();
        let reach = Reach::new(&cloud, &beta, 2.0);
        for _ in 0..200 {
            let v = [0, 1, 2].map(|_| rng.random_range(-15.0..15.0));
            let (d2, nearest) = cloud
                .iter()
                .enumerate()
                .map(|(i, &p)| (dist2(v, p), i))
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .unwrap();
            let want = (d2.sqrt() - 2.0 * beta[nearest], beta[nearest]);
            assert_eq!(reach.excess(v), want, "at {v:?}");
        }
    }
}

#[test]
fn sorted_edges_give_the_pieces_of_the_hash_map() {
    for seed in 0..20 {
        let mesh = random_grid_mesh(seed, 30);
        // Faces on either side of the walls never join; one side
        // only is the plain case.
        let sides: Vec<bool> = (0..mesh.faces.len())
            .map(|f| seed % 2 == 1 && f % 3 == 0)
            .collect();
        let pieces = face_pieces(&mesh.faces, &sides);
        assert_eq!(
            pieces,
            face_pieces_reference(&mesh.faces, &sides),
            "seed {seed}"
        );
        // Not one piece: the test sees the joining at work.
        assert!(pieces.iter().max() > Some(&3), "seed {seed}");
    }
}

#[test]
fn counting_sort_of_edges_matches_sorting() {
    for seed in 0..20 {
        let mut mesh = random_grid_mesh(seed, 25);
        assert_eq!(
            mesh.sorted_edges(),
            mesh.sorted_edges_reference(),
            "seed {seed}"
        );
        // An index past the vertices: no panic, the same edges.
        mesh.faces.push([0, 1, mesh.vertices.len() as u32 + 5]);
        assert_eq!(
            mesh.sorted_edges(),
            mesh.sorted_edges_reference(),
            "seed {seed}"
        );
    }
}

#[test]
fn sorted_edges_give_the_border_of_the_hash_map() {
    for seed in 0..20 {
        let mesh = random_grid_mesh(seed, 30);
        let loops = mesh.boundary_loops();
        assert!(loops.len() > 3, "seed {seed}");
        assert_eq!(loops, mesh.boundary_loops_reference(), "seed {seed}");
    }
}

/// A cap of a sphere of radius 10 centred well away from the origin, so
/// that scaling a cloud about the origin by a wrong ratio moves it off:
/// `side` × `side` quads of about 0.4, split into triangles.
fn sphere_cap(side: u32) -> Mesh {
    let centre = [60.0, 25.0, 10.0];
    let at = |i: u32, j: u32| i * (side + 1) + j;
    let vertices = (0..=side)
        .flat_map(|i| {
            (0..=side).map(move |j| {
                let (u, v) = (i as f64 / side as f64 - 0.5, j as f64 / side as f64 - 0.5);
                let (theta, phi) = (1.6 * u, 1.6 * v);
                let direction = [theta.sin() * phi.cos(), phi.sin(), theta.cos() * phi.cos()];
                [0, 1, 2].map(|a| centre[a] + 10.0 * direction[a])
            })
        })
        .collect();
    let faces = (0..side)
        .flat_map(|i| {
            (0..side).flat_map(move |j| {
                [
                    [at(i, j), at(i + 1, j), at(i + 1, j + 1)],
                    [at(i, j), at(i + 1, j + 1), at(i, j + 1)],
                ]
            })
        })
        .collect();
    Mesh { vertices, faces }
}

/// A trim that finds nothing supported says where the cloud lies: in
/// other units (scaled by their ratio, it lies on the mesh), scaled by no
/// ratio of units, elsewhere, or in place.
#[test]
fn an_unsupported_cloud_is_placed_against_the_mesh() {
    let mesh = sphere_cap(40);
    let spacing = 0.4;
    let place = |factor: f64, shift: Point3| {
        let cloud: Vec<Point3> = mesh
            .vertices
            .iter()
            .map(|p| [0, 1, 2].map(|a| p[a] * factor + shift[a]))
            .collect();
        placement(&mesh, &cloud, &vec![spacing * factor; cloud.len()], 2.0)
    };
    let metres = place(0.001, [0.0; 3]);
    assert_eq!(
        metres,
        Placement::Units {
            factor: 1000.0,
            units: ("metres", "millimetres")
        }
    );
    let message = TrimError::Unsupported(metres).to_string();
    assert!(
        message.ends_with(
            "the cloud looks to be in metres and the mesh in millimetres (scaled by 1000, the \
             cloud lies on the mesh): scale the cloud by 1000"
        ),
        "{message}"
    );
    let inches = place(25.4, [0.0; 3]);
    assert_eq!(
        inches,
        Placement::Units {
            factor: 1.0 / 25.4,
            units: ("millimetres", "inches")
        }
    );
    let message = TrimError::Unsupported(inches).to_string();
    assert!(message.ends_with("scale the cloud by 1/25.4"), "{message}");
    // A ratio no two units have.
    match place(1.0 / 7.0, [0.0; 3]) {
        Placement::Scaled { ratio } => assert!((ratio * 7.0 - 1.0).abs() < 1e-9, "{ratio}"),
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        place(1.0, [500.0, 0.0, 0.0]),
        Placement::Apart { distance, .. } if (distance - 500.0).abs() < 1e-9
    ));
    assert_eq!(place(1.0, [0.0, 0.0, 1.0]), Placement::Overlapping);
}
