//! What storing a mesh's coordinates as `f32` does to it, checked before
//! STL or glTF is written.
//!
//! `f32` keeps 24 bits: at a coordinate of 4·10⁶ (a UTM northing, in
//! metres) it steps by 0.25 or 0.5. A mesh that far from the origin with
//! edges a few units long loses its shape when rounded: distinct vertices
//! fall on one point (an STL reader merges them, STL having no shared
//! vertices), faces lose their area or turn over.
//!
//! - glTF stores its positions about the centre of the mesh's bounding
//!   box, the centre as the node's translation, when plain rounding would
//!   move a coordinate by more than [`PLAIN_ROUNDING`] of the mesh's
//!   diagonal ([`storage_origin`]): `f32` then steps over the mesh's own
//!   extent, not over its distance from the origin. The centre is itself
//!   an `f32` value, so that readers holding the translation as `f32`
//!   (the spec's type) and as `f64` read the same one.
//! - STL has no such place. A mesh that rounding would change, merging
//!   vertices, flattening faces to zero area (below
//!   [`trim::MIN_RELATIVE_AREA`] of the squared diagonal, as the repair
//!   measures it) or turning them over, is refused ([`check_rounding`])
//!   with the numbers and the formats that keep it. glTF is checked the
//!   same way about its origin.

use anyhow::{bail, Result};

use super::hash::HashMap;
use super::{doubled_area, Point3};

/// Plain `f32` rounding beyond this share of the mesh's diagonal has glTF
/// store the positions about the mesh's centre.
pub const PLAIN_ROUNDING: f64 = 1e-6;

/// The origin glTF stores `vertices` about (see the module doc): `None`
/// when plain rounding keeps them within [`PLAIN_ROUNDING`] of the
/// diagonal, or when there are none.
pub fn storage_origin(vertices: &[Point3]) -> Option<Point3> {
    let (lo, hi) = bounds(vertices.iter().copied())?;
    let plain = vertices
        .iter()
        .flatten()
        .fold(0.0, |m: f64, &c| m.max((c - f64::from(c as f32)).abs()));
    (plain > PLAIN_ROUNDING * distance(lo, hi))
        .then(|| std::array::from_fn(|k| f64::from((0.5 * (lo[k] + hi[k])) as f32)))
}

/// A vertex as the file stores it: its offset from `origin` in `f32`.
pub fn stored(p: &Point3, origin: Option<Point3>) -> [f32; 3] {
    let o = origin.unwrap_or([0.0; 3]);
    std::array::from_fn(|k| (p[k] - o[k]) as f32)
}

/// What rounding to `f32` about an origin does to a mesh.
#[derive(Debug, Default, PartialEq)]
struct Damage {
    /// Vertices at distinct points that round to one point: the first
    /// pair found, in vertex order, and how many points in all fall on a
    /// rounded point another already took.
    merged: Option<(u32, u32)>,
    merges: usize,
    /// Faces with area that round to zero area (the first, and how many).
    flattened: Option<usize>,
    flattenings: usize,
    /// Faces with area whose rounded normal turns against their own.
    turned: Option<usize>,
    turnings: usize,
}

impl Damage {
    fn is_none(&self) -> bool {
        self.merges + self.flattenings + self.turnings == 0
    }
}

/// Refuses a mesh that storing as `f32` about `origin` would change (see
/// the module doc); `merges_vertices` for formats without shared
/// vertices, whose readers merge vertices at one point (STL).
pub fn check_rounding(
    format: &str,
    vertices: &[Point3],
    faces: &[[u32; 3]],
    origin: Option<Point3>,
    merges_vertices: bool,
) -> Result<()> {
    let damage = damage(vertices, faces, origin, merges_vertices);
    if damage.is_none() {
        return Ok(());
    }
    let mut what = Vec::new();
    if let Some((a, b)) = damage.merged {
        let [p, q] = [a, b].map(|v| super::show(&vertices[v as usize]));
        what.push(format!(
            "merges vertex {b} {q} into vertex {a} {p} ({} points in all fall on another's)",
            damage.merges
        ));
    }
    if let Some(f) = damage.flattened {
        what.push(format!(
            "flattens {} to zero area (the first: triangle {f})",
            faces_counted(damage.flattenings)
        ));
    }
    if let Some(f) = damage.turned {
        what.push(format!(
            "turns {} over (the first: triangle {f})",
            faces_counted(damage.turnings)
        ));
    }
    let (far, step) = reach_and_step(vertices, origin);
    let about = if origin.is_some() {
        " (here about the mesh's centre)"
    } else {
        ""
    };
    let from = if origin.is_some() {
        "its centre"
    } else {
        "the origin"
    };
    // Storing about the centre helps only a mesh far from the origin.
    let far_from_the_origin = origin.is_none() && storage_origin(vertices).is_some();
    let instead = if far_from_the_origin {
        "write .ply or .obj (f64 coordinates) or .glb (f32 about the mesh's centre), \
         or move the mesh near the origin"
    } else {
        "write .ply or .obj (f64 coordinates)"
    };
    bail!(
        "{format} stores coordinates as f32{about}, which at up to {far:e} from {from} \
         step by up to {step:e}: rounding {}; {instead}",
        what.join(", ")
    )
}

fn faces_counted(n: usize) -> String {
    format!("{n} {}", if n == 1 { "face" } else { "faces" })
}

fn damage(
    vertices: &[Point3],
    faces: &[[u32; 3]],
    origin: Option<Point3>,
    merges_vertices: bool,
) -> Damage {
    let used = used_vertices(vertices.len(), faces);
    let Some((lo, hi)) = bounds(used.iter().map(|&v| vertices[v as usize])) else {
        return Damage::default();
    };
    let o = origin.unwrap_or([0.0; 3]);
    let local = |v: u32| -> Point3 { std::array::from_fn(|k| vertices[v as usize][k] - o[k]) };
    let rounded = |v: u32| stored(&vertices[v as usize], origin).map(f64::from);
    // Only a vertex that rounding moves can change anything.
    let moved: Vec<bool> = (0..vertices.len() as u32)
        .map(|v| rounded(v) != local(v))
        .collect();
    let mut damage = Damage::default();
    if merges_vertices {
        find_merges(&used, &moved, origin, vertices, &mut damage);
    }
    let min_area2 = (trim::MIN_RELATIVE_AREA * distance2(lo, hi)).powi(2);
    for (t, f) in faces.iter().enumerate() {
        if !f.iter().any(|&v| moved[v as usize]) {
            continue;
        }
        let exact = doubled_area(f.map(local));
        if norm2(exact) < 4.0 * min_area2 {
            continue;
        }
        let after = doubled_area(f.map(rounded));
        if norm2(after) < 4.0 * min_area2 {
            damage.flattened.get_or_insert(t);
            damage.flattenings += 1;
        } else if dot(after, exact) <= 0.0 {
            damage.turned.get_or_insert(t);
            damage.turnings += 1;
        }
    }
    damage
}

/// Vertices at distinct points that round to one point. A pair needs a
/// moved vertex (two unmoved ones at one rounded point are at one point),
/// so only the points that moved vertices round to are followed.
fn find_merges(
    used: &[u32],
    moved: &[bool],
    origin: Option<Point3>,
    vertices: &[Point3],
    damage: &mut Damage,
) {
    let key = |v: u32| stored(&vertices[v as usize], origin).map(f32::to_bits);
    // Each followed rounded point: the distinct points on it, with the
    // first vertex at each.
    let mut on: HashMap<[u32; 3], Vec<(Point3, u32)>> = HashMap::default();
    for &v in used.iter().filter(|&&v| moved[v as usize]) {
        on.entry(key(v)).or_default();
    }
    for &v in used {
        let Some(points) = on.get_mut(&key(v)) else {
            continue;
        };
        let p = vertices[v as usize];
        if points.iter().any(|&(q, _)| q == p) {
            continue;
        }
        if let Some(&(_, first)) = points.first() {
            damage.merged.get_or_insert((first, v));
            damage.merges += 1;
        }
        points.push((p, v));
    }
}

/// The vertices the faces use, in order.
fn used_vertices(count: usize, faces: &[[u32; 3]]) -> Vec<u32> {
    let mut used = vec![false; count];
    for &v in faces.iter().flatten() {
        used[v as usize] = true;
    }
    (0..count as u32).filter(|&v| used[v as usize]).collect()
}

/// The largest |coordinate| stored (about `origin`) and `f32`'s step there.
fn reach_and_step(vertices: &[Point3], origin: Option<Point3>) -> (f64, f64) {
    let far = vertices
        .iter()
        .flat_map(|p| stored(p, origin))
        .fold(0.0f32, |m, c| m.max(c.abs()));
    let step = far.next_up() - far;
    (f64::from(far), f64::from(step))
}

fn bounds(points: impl Iterator<Item = Point3>) -> Option<(Point3, Point3)> {
    points.fold(None, |acc, p| {
        let (mut lo, mut hi) = acc.unwrap_or((p, p));
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
        Some((lo, hi))
    })
}

fn sub(a: Point3, b: Point3) -> Point3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: Point3, b: Point3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm2(a: Point3) -> f64 {
    dot(a, a)
}

fn distance2(a: Point3, b: Point3) -> f64 {
    norm2(sub(a, b))
}

fn distance(a: Point3, b: Point3) -> f64 {
    distance2(a, b).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grid of `n` × `n` vertices `spacing` apart, its corner at `at`,
    /// two triangles a cell.
    fn grid(n: u32, spacing: f64, at: Point3) -> (Vec<Point3>, Vec<[u32; 3]>) {
        let vertices = (0..n * n)
            .map(|i| {
                let (x, y) = (f64::from(i % n), f64::from(i / n));
                [
                    at[0] + x * spacing,
                    at[1] + y * spacing,
                    at[2] + 0.1 * x * y,
                ]
            })
            .collect();
        let mut faces = Vec::new();
        for y in 0..n - 1 {
            for x in 0..n - 1 {
                let v = y * n + x;
                faces.extend([[v, v + 1, v + n + 1], [v, v + n + 1, v + n]]);
            }
        }
        (vertices, faces)
    }

    const UTM: Point3 = [512_345.0, 4_123_456.0, 250.0];

    #[test]
    fn a_mesh_far_from_the_origin_is_stored_about_its_centre() {
        let (near, _) = grid(5, 0.3, [1.0, 2.0, 3.0]);
        assert_eq!(storage_origin(&near), None);
        let (far, _) = grid(5, 0.3, UTM);
        let origin = storage_origin(&far).unwrap();
        // The centre, as an f32 value.
        let centre = [UTM[0] + 0.6, UTM[1] + 0.6, UTM[2] + 0.8];
        for k in 0..3 {
            assert_eq!(origin[k], f64::from(origin[k] as f32));
            assert!((origin[k] - centre[k]).abs() <= 0.25, "{origin:?}");
        }
        // About it, each vertex keeps f32's precision over the mesh's size.
        for p in &far {
            let back = stored(p, Some(origin));
            for k in 0..3 {
                assert!((f64::from(back[k]) + origin[k] - p[k]).abs() < 1e-6);
            }
        }
        assert_eq!(storage_origin(&[]), None);
    }

    #[test]
    fn rounding_that_changes_the_mesh_is_refused_with_the_numbers() {
        let (near, faces) = grid(6, 0.1, [10.0, 20.0, 30.0]);
        assert!(check_rounding("STL", &near, &faces, None, true).is_ok());
        // 0.1 apart where f32 steps by 0.25 or 0.5.
        let (far, faces) = grid(6, 0.1, UTM);
        let message = check_rounding("STL", &far, &faces, None, true)
            .unwrap_err()
            .to_string();
        assert!(
            message.starts_with("STL stores coordinates as f32, which at up to 4.123"),
            "{message}"
        );
        assert!(message.contains("step by up to 2.5e-1"), "{message}");
        assert!(message.contains("rounding merges vertex 6 "), "{message}");
        assert!(message.contains("flattens"), "{message}");
        assert!(
            message.ends_with("or move the mesh near the origin"),
            "{message}"
        );
        // glTF about the centre keeps it.
        let origin = storage_origin(&far);
        assert!(check_rounding("glTF", &far, &faces, origin, false).is_ok());
        // A sliver near the origin 10⁻⁹ high (area 5·10⁻¹⁰ of the
        // squared diagonal) rounds flat: no other place to store it helps.
        let sliver = [[1.0, 1.0, 1.0], [2.0, 1.0, 1.0], [1.5, 1.0 + 1e-9, 1.0]];
        let message = check_rounding("glTF", &sliver, &[[0, 1, 2]], None, false)
            .unwrap_err()
            .to_string();
        assert!(
            message.ends_with(
                "rounding flattens 1 face to zero area (the first: triangle 0); \
                 write .ply or .obj (f64 coordinates)"
            ),
            "{message}"
        );
    }

    #[test]
    fn faces_turned_over_or_flattened_are_counted() {
        // At 5·10⁶ f32 steps by 0.5; x stays exact.
        let y = 5_000_000.0;
        let at = |x: f64, dy: f64| [x, y + dy, 0.0];
        // The apex 0.1 above the edge rounds onto it.
        let flat = damage_of(&[at(0.0, 0.0), at(10.0, 0.0), at(5.0, 0.1)]);
        assert_eq!(
            (flat.flattened, flat.flattenings, flat.turnings),
            (Some(0), 1, 0)
        );
        // An edge from y + 0.24 (rounded down to y) to y + 0.76 (up to
        // y + 1): at x = 4 it runs at y + 0.448, and an apex 0.018 below
        // it rounds up to y + 0.5, above the rounded edge's y + 0.4.
        let over = damage_of(&[at(0.0, 0.24), at(10.0, 0.76), at(4.0, 0.43)]);
        assert_eq!(
            (over.turned, over.turnings, over.flattenings),
            (Some(0), 1, 0)
        );
        // A face only moved is not damaged.
        assert!(damage_of(&[at(0.0, 0.0), at(10.0, 0.0), at(5.0, 3.1)]).is_none());
    }

    fn damage_of(corners: &[Point3; 3]) -> Damage {
        damage(corners, &[[0, 1, 2]], None, false)
    }

    /// The merges found through the hash are those of comparing every
    /// pair of vertices, on random clusters of nearby points at random
    /// distances from the origin (some of them repeated points, which are
    /// not merges).
    #[test]
    fn merges_are_those_of_comparing_every_pair() {
        let mut rng = testkit::synthetic::SplitMix64::new(5);
        for case in 0..200 {
            let offset = [1.0, 1e5, 3e6, 2e7][case % 4];
            let n = 2 + (rng.next_u64() % 30) as usize;
            let mut vertices: Vec<Point3> = Vec::new();
            for _ in 0..n {
                if !vertices.is_empty() && rng.unit() < 0.2 {
                    let i = (rng.next_u64() % vertices.len() as u64) as usize;
                    vertices.push(vertices[i]);
                } else {
                    vertices.push([0; 3].map(|_| offset + rng.range(0.0, 4.0)));
                }
            }
            let faces: Vec<[u32; 3]> = (0..n as u32 - 1).map(|v| [v, v + 1, v]).collect();
            let found = damage(&vertices, &faces, None, true);
            let (pair, merges) = merges_by_pairs(&vertices);
            assert_eq!((found.merged, found.merges), (pair, merges), "case {case}");
        }
    }

    /// Every pair compared: for each vertex, whether an earlier one at
    /// another point rounds to the same point while no earlier one is at
    /// its own point.
    fn merges_by_pairs(vertices: &[Point3]) -> (Option<(u32, u32)>, usize) {
        let rounded = |p: &Point3| p.map(|c| c as f32);
        let (mut first, mut merges) = (None, 0);
        for (j, q) in vertices.iter().enumerate() {
            let earlier = &vertices[..j];
            if earlier.contains(q) {
                continue;
            }
            if let Some(i) = earlier.iter().position(|p| rounded(p) == rounded(q)) {
                first.get_or_insert((i as u32, j as u32));
                merges += 1;
            }
        }
        (first, merges)
    }
}
