//! Jagged meshes: what scanner software makes of a synthetic cloud, with
//! the cloud's known boundary as ground truth for border cleaning.
//!
//! [`jagged_mesh`] triangulates the points in their parameter domain
//! (Delaunay, spade) and keeps the triangles that lie in the region, so
//! the border runs through the outermost samples and zigzags between them,
//! as a scan's border does. [`border_error`] measures how far a mesh's
//! border lies from the true boundary, in local spacings: 0.27 to 0.39
//! (mean over the border, largest 0.73 to 1.1) for jagged meshes of the
//! blade, the notched plate and the curved disc over six seeds, the figure
//! a border-cleaning step has to bring down. Every sample lies inside the
//! region, so a border through samples lies inside the true boundary: a
//! smoothing that only averages border vertices keeps most of that offset.
//!
//! # Which triangles are kept
//!
//! A Delaunay triangle of the parameter positions is kept when
//!
//! - its centroid lies in the region (so notches and holes open up), and
//! - its circumradius is at most [`MAX_CIRCUMRADIUS`] local pitches (the
//!   spacing field at its centroid). A jittered hexagonal grid gives
//!   circumradii near 0.58 pitch; the long slivers that join samples
//!   across a concave part of the border or along the convex hull have
//!   much larger ones.
//!
//! Then bow-ties are removed: where the kept triangles around a vertex
//! form several fans (two border loops touching at that vertex), every fan
//! but the largest is removed (ties: the one holding the lowest face index
//! stays), and this is repeated until no vertex has two fans. Last, only
//! the largest edge-connected piece is kept, so that an island of a few
//! triangles cut off by the pruning does not add border loops. (On the
//! blade, notched plate and curved disc at 6 seeds neither step removed
//! a face; they are there for other shapes and pitches.) The result
//! is edge-manifold (a subset of a planar triangulation) and
//! vertex-manifold.
//!
//! Faces are counter-clockwise seen from the side the true normal points
//! to: spade's faces are counter-clockwise in the parameter domain and
//! the normal is ∂u × ∂v, so they already are; every face is still checked
//! against its vertices' true normals and flipped if needed.

use std::collections::HashMap;

use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};

use super::{jittered, notched_plate_region, Region, SpacingField, Surface, SyntheticCloud, P3};
use crate::synthetic::BoundaryIndex;
use crate::vec3::{cross, dot, sub};
use trim::Mesh;

/// Largest kept circumradius, in local pitches (see the module doc).
pub const MAX_CIRCUMRADIUS: f64 = 2.0;

/// A triangulated jittered cloud whose border zigzags through the
/// outermost samples (see the module doc). Vertices are the cloud's points
/// that some face uses, in cloud order.
pub fn jagged_mesh(cloud: &SyntheticCloud) -> Mesh {
    jagged_mesh_with_source(cloud).0
}

/// [`jagged_mesh`] and, for each of its vertices, the index of the cloud
/// point it is.
pub fn jagged_mesh_with_source(cloud: &SyntheticCloud) -> (Mesh, Vec<u32>) {
    let mut faces = region_triangles(cloud);
    orient_to_normals(&mut faces, cloud);
    remove_bow_ties(&mut faces, cloud.len());
    let faces = largest_piece(faces);
    compact(cloud, faces)
}

/// A spade vertex carrying the index of its cloud point.
#[derive(Debug, Clone, Copy)]
struct Node {
    position: Point2<f64>,
    id: u32,
}

impl HasPosition for Node {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.position
    }
}

/// A spade point; coordinates too small for spade's predicates are zero.
fn point(p: [f64; 2]) -> Point2<f64> {
    let flush = |c: f64| {
        if c.abs() < spade::MIN_ALLOWED_VALUE {
            0.0
        } else {
            c
        }
    };
    Point2::new(flush(p[0]), flush(p[1]))
}

/// The Delaunay triangles of the parameter positions that lie in the
/// region and are not slivers, counter-clockwise in the parameter domain.
fn region_triangles(cloud: &SyntheticCloud) -> Vec<[u32; 3]> {
    let nodes = cloud
        .uv
        .iter()
        .enumerate()
        .map(|(i, &p)| Node {
            position: point(p),
            id: i as u32,
        })
        .collect();
    let Ok(dt) = DelaunayTriangulation::<Node>::bulk_load(nodes) else {
        return Vec::new(); // non-finite parameters: the generators make none
    };
    dt.inner_faces()
        .filter(|f| {
            let c = f.center();
            let (_, r2) = f.circumcircle();
            let pitch = cloud.field.at(c.x);
            r2 <= (MAX_CIRCUMRADIUS * pitch).powi(2) && cloud.region.contains([c.x, c.y])
        })
        .map(|f| f.vertices().map(|v| v.data().id))
        .collect()
}

/// Flips the faces whose geometric normal points away from their
/// vertices' true normals.
fn orient_to_normals(faces: &mut [[u32; 3]], cloud: &SyntheticCloud) {
    for f in faces.iter_mut() {
        let [a, b, c] = f.map(|v| cloud.points[v as usize]);
        let n = cross(sub(b, a), sub(c, a));
        let truth = f.iter().fold([0.0; 3], |s, &v| {
            let m = cloud.normals[v as usize];
            [s[0] + m[0], s[1] + m[1], s[2] + m[2]]
        });
        if dot(n, truth) < 0.0 {
            f.swap(1, 2);
        }
    }
}

/// Removes every fan but the largest at each vertex with several, until
/// none has (see the module doc).
fn remove_bow_ties(faces: &mut Vec<[u32; 3]>, vertices: usize) {
    let mut around: Vec<Vec<u32>> = vec![Vec::new(); vertices];
    for (i, f) in faces.iter().enumerate() {
        for &v in f {
            around[v as usize].push(i as u32);
        }
    }
    let mut alive = vec![true; faces.len()];
    let mut work: Vec<u32> = (0..vertices as u32).rev().collect();
    while let Some(v) = work.pop() {
        let live: Vec<u32> = around[v as usize]
            .iter()
            .copied()
            .filter(|&f| alive[f as usize])
            .collect();
        let fans = fans_around(v, &live, faces);
        if fans.len() < 2 {
            continue;
        }
        let keep = largest_fan(&fans);
        for (k, fan) in fans.iter().enumerate() {
            if k == keep {
                continue;
            }
            for &f in fan {
                alive[f as usize] = false;
                work.extend(faces[f as usize].iter().filter(|&&w| w != v));
            }
        }
    }
    let mut i = 0;
    faces.retain(|_| {
        i += 1;
        alive[i - 1]
    });
}

/// The faces around vertex `v` grouped into fans: two faces are in the
/// same fan when they share an edge at `v`. Each fan in face order.
fn fans_around(v: u32, live: &[u32], faces: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let mut group: Vec<usize> = (0..live.len()).collect();
    fn root(group: &mut [usize], mut i: usize) -> usize {
        while group[i] != i {
            group[i] = group[group[i]];
            i = group[i];
        }
        i
    }
    // A handful of faces per vertex: linear scans beat hashing.
    let mut by_edge: Vec<(u32, usize)> = Vec::with_capacity(2 * live.len());
    for (k, &f) in live.iter().enumerate() {
        for &w in faces[f as usize].iter().filter(|&&w| w != v) {
            if let Some(&(_, other)) = by_edge.iter().find(|e| e.0 == w) {
                let (a, b) = (root(&mut group, k), root(&mut group, other));
                group[a.max(b)] = a.min(b);
            } else {
                by_edge.push((w, k));
            }
        }
    }
    let mut roots: Vec<usize> = Vec::new();
    let mut fans: Vec<Vec<u32>> = Vec::new();
    for (k, &f) in live.iter().enumerate() {
        let r = root(&mut group, k);
        let s = roots.iter().position(|&x| x == r).unwrap_or_else(|| {
            roots.push(r);
            fans.push(Vec::new());
            fans.len() - 1
        });
        fans[s].push(f);
    }
    fans
}

/// The fan that stays: the most faces, then the lowest face index.
fn largest_fan(fans: &[Vec<u32>]) -> usize {
    let key = |fan: &Vec<u32>| (fan.len(), std::cmp::Reverse(fan.iter().min().copied()));
    (0..fans.len()).max_by_key(|&k| key(&fans[k])).unwrap_or(0)
}

/// The faces of the largest edge-connected piece (ties: the piece holding
/// the lowest face index), in their order.
fn largest_piece(faces: Vec<[u32; 3]>) -> Vec<[u32; 3]> {
    let mut by_edge: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for (i, f) in faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            by_edge
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(i as u32);
        }
    }
    let mut piece = vec![u32::MAX; faces.len()];
    let mut sizes = Vec::new();
    for start in 0..faces.len() {
        if piece[start] != u32::MAX {
            continue;
        }
        let id = sizes.len() as u32;
        let mut stack = vec![start as u32];
        piece[start] = id;
        let mut size = 0usize;
        while let Some(f) = stack.pop() {
            size += 1;
            let t = faces[f as usize];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                for &g in &by_edge[&(a.min(b), a.max(b))] {
                    if piece[g as usize] == u32::MAX {
                        piece[g as usize] = id;
                        stack.push(g);
                    }
                }
            }
        }
        sizes.push(size);
    }
    let best = (0..sizes.len())
        .max_by_key(|&k| (sizes[k], std::cmp::Reverse(k)))
        .unwrap_or(0) as u32;
    faces
        .into_iter()
        .zip(piece)
        .filter(|&(_, p)| p == best)
        .map(|(f, _)| f)
        .collect()
}

/// The mesh over the used points only, and each vertex's cloud index.
fn compact(cloud: &SyntheticCloud, faces: Vec<[u32; 3]>) -> (Mesh, Vec<u32>) {
    let mut mesh = Mesh {
        vertices: cloud.points.clone(),
        faces,
    };
    let mut used = vec![false; cloud.len()];
    for f in &mesh.faces {
        for &v in f {
            used[v as usize] = true;
        }
    }
    let source = (0..cloud.len() as u32)
        .filter(|&i| used[i as usize])
        .collect();
    mesh.remove_unused_vertices();
    (mesh, source)
}

/// How far a mesh's border lies from the true boundary of `truth`, in
/// local spacings: (mean, largest).
///
/// The border is sampled at the vertices of its loops
/// ([`Mesh::boundary_loops`]) and at the midpoint of every border edge, so
/// that a long edge cutting a corner or spanning a notch counts too. Each
/// sample's 3D distance to the true boundary ([`BoundaryIndex`]) is divided
/// by the intended spacing at the nearest true-boundary sample: the
/// truth's own resolution at the place the border should be, which does
/// not depend on the mesh's vertices being cloud points (a cleaned border
/// has new vertices).
///
/// Only the mesh-to-truth direction is measured: a border that follows
/// part of the true boundary and misses the rest scores well. A mesh with
/// no border gives (NaN, NaN), which fails every bound.
pub fn border_error(mesh: &Mesh, truth: &SyntheticCloud) -> (f64, f64) {
    border_error_with(&BoundaryIndex::new(truth), mesh)
}

/// [`border_error`] with a prebuilt [`BoundaryIndex`] of the truth.
pub fn border_error_with(index: &BoundaryIndex, mesh: &Mesh) -> (f64, f64) {
    let (mut sum, mut max, mut n) = (0.0, f64::NAN, 0usize);
    for p in border_samples(mesh) {
        let (d, h) = index.distance_and_spacing(p);
        let e = d / h;
        sum += e;
        max = if n == 0 { e } else { max.max(e) };
        n += 1;
    }
    if n == 0 {
        return (f64::NAN, f64::NAN);
    }
    (sum / n as f64, max)
}

/// The border's loop vertices, then the midpoints of its edges.
fn border_samples(mesh: &Mesh) -> Vec<P3> {
    let at = |v: u32| mesh.vertices[v as usize];
    let mut out = Vec::new();
    for lp in mesh.boundary_loops() {
        out.extend(lp.iter().map(|&v| at(v)));
        let n = lp.len();
        if n < 2 {
            continue;
        }
        for k in 0..n {
            let (a, b) = (at(lp[k]), at(lp[(k + 1) % n]));
            out.push([
                0.5 * (a[0] + b[0]),
                0.5 * (a[1] + b[1]),
                0.5 * (a[2] + b[2]),
            ]);
        }
    }
    out
}

/// The shapes [`sized_cloud`] makes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// The blade of [`super::blade`]: outer border and three holes.
    Blade,
    /// A 60 × 40 plate with a 15 × 15 notch and a hole of radius 5, the
    /// geometry of [`super::notched_plate`] at a fixed size.
    NotchedPlate,
    /// The curved disc with a hole of [`super::curved_disc_with_hole`].
    CurvedDisc,
}

impl Shape {
    /// The three shapes, in the order the batch generator cycles through.
    pub const ALL: [Shape; 3] = [Shape::Blade, Shape::NotchedPlate, Shape::CurvedDisc];

    /// A short name for file names.
    pub fn name(self) -> &'static str {
        match self {
            Shape::Blade => "blade",
            Shape::NotchedPlate => "notched_plate",
            Shape::CurvedDisc => "curved_disc",
        }
    }

    fn surface(self) -> Surface {
        match self {
            Shape::Blade => super::BLADE,
            Shape::NotchedPlate => Surface::Plane,
            Shape::CurvedDisc => Surface::Saddle { a: 0.004 },
        }
    }

    fn region(self, spacing: f64) -> Region {
        match self {
            Shape::Blade => super::blade_region(spacing),
            Shape::NotchedPlate => notched_plate_region(1.0),
            Shape::CurvedDisc => super::curved_disc_region(),
        }
    }
}

/// Area of a region in the parameter domain.
fn region_area(region: &Region) -> f64 {
    let n = region.outer.len();
    let twice: f64 = (0..n)
        .map(|i| {
            let (a, b) = (region.outer[i], region.outer[(i + 1) % n]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum();
    let holes: f64 = region
        .holes
        .iter()
        .map(|h| std::f64::consts::PI * h.radius * h.radius)
        .sum();
    0.5 * twice.abs() - holes
}

/// A jittered cloud of `shape` whose [`jagged_mesh`] has about `triangles`
/// faces: a jittered hexagonal grid of pitch h holds one point per
/// (√3/2)·h² of parameter area and a triangulation about two triangles per
/// point, so h = √(2·area / (√3/2 · triangles)).
pub fn sized_cloud(shape: Shape, triangles: usize, seed: u64) -> SyntheticCloud {
    let pitch = |region: &Region| {
        let per_point = 2.0 * region_area(region) / triangles.max(1) as f64;
        (per_point / (0.5 * 3f64.sqrt())).sqrt()
    };
    // The blade's smallest hole grows with the pitch: settle it once.
    let h = pitch(&shape.region(pitch(&shape.region(1.0))));
    let region = shape.region(h);
    jittered(
        format!("jagged {} h={h:.4}", shape.name()),
        shape.surface(),
        region,
        SpacingField::Uniform(h),
        seed,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::{blade, curved_disc_with_hole, notched_plate};

    /// True if every vertex's faces form one fan.
    fn vertex_manifold(mesh: &Mesh) -> bool {
        let mut around: Vec<Vec<u32>> = vec![Vec::new(); mesh.vertices.len()];
        for (i, f) in mesh.faces.iter().enumerate() {
            for &v in f {
                around[v as usize].push(i as u32);
            }
        }
        (0..mesh.vertices.len() as u32)
            .all(|v| fans_around(v, &around[v as usize], &mesh.faces).len() <= 1)
    }

    /// Every face's normal agrees with the true normals at its corners.
    fn positively_oriented(mesh: &Mesh, source: &[u32], truth: &SyntheticCloud) -> bool {
        mesh.faces.iter().all(|f| {
            let [a, b, c] = f.map(|v| mesh.vertices[v as usize]);
            let n = cross(sub(b, a), sub(c, a));
            f.iter()
                .all(|&v| dot(n, truth.normals[source[v as usize] as usize]) > 0.0)
        })
    }

    /// Mean distance of the border vertices to the true boundary, in
    /// spacings of their own cloud points.
    fn mean_vertex_error(mesh: &Mesh, source: &[u32], truth: &SyntheticCloud) -> f64 {
        let index = BoundaryIndex::new(truth);
        let border: Vec<u32> = mesh.boundary_loops().concat();
        let sum: f64 = border
            .iter()
            .map(|&v| {
                index.distance(mesh.vertices[v as usize])
                    / truth.spacing[source[v as usize] as usize]
            })
            .sum();
        sum / border.len() as f64
    }

    fn check(truth: &SyntheticCloud, loops: usize) -> (f64, f64, f64) {
        let (mesh, source) = jagged_mesh_with_source(truth);
        assert!(mesh.validate().is_ok(), "{}", truth.name);
        assert!(mesh.is_edge_manifold(), "{}", truth.name);
        assert!(vertex_manifold(&mesh), "{}", truth.name);
        assert_eq!(mesh.boundary_loops().len(), loops, "{}", truth.name);
        assert!(positively_oriented(&mesh, &source, truth), "{}", truth.name);
        for (v, &s) in source.iter().enumerate() {
            assert_eq!(mesh.vertices[v], truth.points[s as usize]);
        }
        let (mean, max) = border_error(&mesh, truth);
        (mean_vertex_error(&mesh, &source, truth), mean, max)
    }

    #[test]
    fn blade_has_an_outer_border_and_three_holes() {
        let (vertices, mean, max) = check(&blade(4.0, 3), 4);
        assert!((0.2..0.5).contains(&vertices), "{vertices}");
        assert!((0.2..0.5).contains(&mean) && max < 1.5, "{mean} {max}");
    }

    #[test]
    fn notched_plate_has_an_outer_loop_and_a_hole() {
        // The plate has a hole of radius 5h besides its notched outer border.
        let (vertices, mean, max) = check(&notched_plate(1.0, 5), 2);
        assert!((0.2..0.5).contains(&vertices), "{vertices}");
        assert!((0.2..0.5).contains(&mean) && max < 1.5, "{mean} {max}");
    }

    #[test]
    fn curved_disc_has_two_loops() {
        let (vertices, mean, max) = check(&curved_disc_with_hole(2.0, 9), 2);
        assert!((0.2..0.5).contains(&vertices), "{vertices}");
        assert!((0.2..0.5).contains(&mean) && max < 1.5, "{mean} {max}");
    }

    #[test]
    fn sized_clouds_hit_the_triangle_count() {
        for (k, shape) in Shape::ALL.into_iter().enumerate() {
            let mesh = jagged_mesh(&sized_cloud(shape, 20_000, k as u64));
            let n = mesh.faces.len() as f64;
            assert!((n / 20_000.0 - 1.0).abs() < 0.1, "{shape:?}: {n}");
        }
    }

    #[test]
    fn the_true_boundary_scores_zero_and_no_border_is_nan() {
        let truth = notched_plate(1.0, 2);
        let mut flat = Mesh::default();
        let (mean, _) = border_error(&flat, &truth);
        assert!(mean.is_nan());
        // A fan over the true outer polygon: its border is the boundary.
        flat.vertices = truth
            .region
            .outer
            .iter()
            .map(|p| [p[0], p[1], 0.0])
            .collect();
        flat.vertices.push([10.0, 10.0, 0.0]);
        let n = truth.region.outer.len() as u32;
        flat.faces = (0..n).map(|i| [n, i, (i + 1) % n]).collect();
        let (mean, max) = border_error(&flat, &truth);
        assert!(mean < 1e-9 && max < 1e-9, "{mean} {max}");
    }

    #[test]
    fn a_bow_tie_loses_its_smaller_fan() {
        // Two fans at vertex 0: three triangles on one side, one on the other.
        let mut faces = vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 5, 6]];
        remove_bow_ties(&mut faces, 7);
        assert_eq!(faces, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
    }
}
