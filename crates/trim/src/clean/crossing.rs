//! Where a strip crosses the kept surface or itself (meshtrim's own, not
//! the paper's). On a range grid's silhouette the wall can lie several
//! spacings behind the smoothed loop, across the grid's skirts, and a
//! strip face from the loop to the wall can pierce the kept surface
//! between them, or the strip fold over itself where the wall zig-zags.
//! The strip takes those kept faces, and the wall's vertices at its
//! folds, into its cut and is made again
//! ([`super::strip::replace_by_strip`]).

use super::*;

/// A triangle's corners.
type Corners = [Point3; 3];

/// The kept faces of `mesh` (those not in `removed`, ascending) that a
/// triangle of `strip` passes through, where the two share no edge
/// (`strip`'s ids below the mesh's vertex count are mesh vertices),
/// ascending. The strip's triangles are filed in a grid of cells `cell`
/// wide (a few spacings), and each kept face compared with those in the
/// cells its bounding box meets.
pub(super) fn kept_faces_crossed(
    mesh: &Mesh,
    removed: &[u32],
    strip: &[[u32; 3]],
    position: &dyn Fn(u32) -> Point3,
    cell: f64,
) -> Vec<u32> {
    let corners: Vec<Corners> = strip.iter().map(|f| f.map(position)).collect();
    let Some(grid) = Grid::new(&corners, cell) else {
        return Vec::new();
    };
    let mut crossed = Vec::new();
    let mut candidates = Vec::new();
    for (f, face) in mesh.faces.iter().enumerate() {
        let f = f as u32;
        let kept = face.map(|v| mesh.vertices[v as usize]);
        // Most of the mesh lies away from the strip: its box decides.
        if grid.beyond(&kept) || removed.binary_search(&f).is_ok() {
            continue;
        }
        grid.candidates(&kept, strip.len(), &mut candidates);
        let crosses = candidates.iter().any(|&s| {
            !share_an_edge(&strip[s as usize], face) && triangles_cross(&kept, &corners[s as usize])
        });
        if crosses {
            crossed.push(f);
        }
    }
    crossed
}

/// The pairs of `faces` (indices, the smaller first, ascending) that
/// share no edge and cross (see [`triangles_cross`]): a strip folding
/// over itself. The faces are filed in a grid of cells `cell` wide, and
/// each compared with those in the cells its bounding box meets.
pub(super) fn crossing_pairs_filed(
    faces: &[[u32; 3]],
    position: &dyn Fn(u32) -> Point3,
    cell: f64,
) -> Vec<(u32, u32)> {
    let corners: Vec<Corners> = faces.iter().map(|f| f.map(position)).collect();
    let Some(grid) = Grid::new(&corners, cell) else {
        return Vec::new();
    };
    let mut pairs = Vec::new();
    let mut candidates = Vec::new();
    for (i, face) in faces.iter().enumerate() {
        grid.candidates(&corners[i], faces.len(), &mut candidates);
        for &j in candidates.iter().filter(|&&j| j as usize > i) {
            let other = &faces[j as usize];
            if !share_an_edge(face, other) && triangles_cross(&corners[i], &corners[j as usize]) {
                pairs.push((i as u32, j));
            }
        }
    }
    pairs
}

/// [`crossing_pairs_filed`] without a grid, for a few hundred faces (one
/// refined run of a strip): a sweep along x compares the faces whose
/// bounding boxes meet.
pub(super) fn crossing_pairs(
    faces: &[[u32; 3]],
    position: &dyn Fn(u32) -> Point3,
) -> Vec<(u32, u32)> {
    let corners: Vec<Corners> = faces.iter().map(|f| f.map(position)).collect();
    let boxes: Vec<[Point3; 2]> = corners.iter().map(bounding_box).collect();
    let mut order: Vec<usize> = (0..faces.len()).collect();
    order.sort_by(|&a, &b| boxes[a][0][0].total_cmp(&boxes[b][0][0]).then(a.cmp(&b)));
    let mut pairs = Vec::new();
    for (k, &i) in order.iter().enumerate() {
        for &j in &order[k + 1..] {
            if boxes[j][0][0] > boxes[i][1][0] {
                break;
            }
            if boxes_meet(&boxes[i], &boxes[j])
                && !share_an_edge(&faces[i], &faces[j])
                && triangles_cross(&corners[i], &corners[j])
            {
                pairs.push((i.min(j) as u32, i.max(j) as u32));
            }
        }
    }
    pairs.sort_unstable();
    pairs
}

fn bounding_box(corners: &Corners) -> [Point3; 2] {
    let pick =
        |k: usize, f: fn(f64, f64) -> f64| corners.iter().map(|p| p[k]).fold(corners[0][k], f);
    [
        std::array::from_fn(|k| pick(k, f64::min)),
        std::array::from_fn(|k| pick(k, f64::max)),
    ]
}

/// Whether two bounding boxes meet (a NaN corner meets nothing).
fn boxes_meet(a: &[Point3; 2], b: &[Point3; 2]) -> bool {
    (0..3).all(|k| a[0][k] <= b[1][k] && b[0][k] <= a[1][k])
}

/// Cells a triangle's bounding box may meet and still be filed in them;
/// a larger one is a candidate everywhere (on a scan's strip, faces span
/// tens of cells at most).
const MAX_CELLS: i64 = 4096;

/// A uniform grid of cells holding the triangles whose bounding boxes
/// meet them, and the triangles too large for it.
struct Grid {
    cell: f64,
    cells: HashMap<[i64; 3], Vec<u32>>,
    everywhere: Vec<u32>,
    /// The bounding box of every triangle filed, corner by corner.
    lo: Point3,
    hi: Point3,
}

impl Grid {
    fn new(triangles: &[Corners], cell: f64) -> Option<Grid> {
        if triangles.is_empty() || !(cell > 0.0 && cell.is_finite()) {
            return None;
        }
        let mut grid = Grid {
            cell,
            cells: HashMap::default(),
            everywhere: Vec::new(),
            lo: [f64::INFINITY; 3],
            hi: [f64::NEG_INFINITY; 3],
        };
        for (t, corners) in triangles.iter().enumerate() {
            for p in corners {
                for (k, &x) in p.iter().enumerate() {
                    // A NaN corner opens the box along its axis, so that
                    // nothing is passed over that was compared before.
                    let (lo, hi) = if x.is_nan() {
                        (f64::NEG_INFINITY, f64::INFINITY)
                    } else {
                        (x, x)
                    };
                    grid.lo[k] = grid.lo[k].min(lo);
                    grid.hi[k] = grid.hi[k].max(hi);
                }
            }
            match grid.cells_met(corners) {
                Some(cells) => {
                    for key in cells {
                        grid.cells.entry(key).or_default().push(t as u32);
                    }
                }
                None => grid.everywhere.push(t as u32),
            }
        }
        Some(grid)
    }

    /// The cells `corners`' bounding box meets, or `None` past
    /// [`MAX_CELLS`] (or for a box beyond the grid's coordinates).
    fn cells_met(&self, corners: &Corners) -> Option<impl Iterator<Item = [i64; 3]>> {
        let at = |k: usize, pick: fn(f64, f64) -> f64| {
            let c = corners.iter().map(|p| p[k]).fold(corners[0][k], pick);
            (c / self.cell).floor()
        };
        let lo: [f64; 3] = std::array::from_fn(|k| at(k, f64::min));
        let hi: [f64; 3] = std::array::from_fn(|k| at(k, f64::max));
        let count = (0..3).fold(1.0, |n, k| n * (hi[k] - lo[k] + 1.0));
        // A NaN count (a non-finite corner) is past the limit too.
        if count.is_nan() || count > MAX_CELLS as f64 {
            return None;
        }
        let [lo, hi] = [lo, hi].map(|c| c.map(|x| x as i64));
        Some((lo[0]..=hi[0]).flat_map(move |x| {
            (lo[1]..=hi[1]).flat_map(move |y| (lo[2]..=hi[2]).map(move |z| [x, y, z]))
        }))
    }

    /// Whether `corners`' bounding box lies clear of every triangle filed,
    /// so that it can meet none. False where a coordinate is NaN.
    fn beyond(&self, corners: &Corners) -> bool {
        (0..3).any(|k| {
            corners.iter().all(|p| p[k] < self.lo[k]) || corners.iter().all(|p| p[k] > self.hi[k])
        })
    }

    /// The triangles that may meet `corners`' bounding box (every one for
    /// a box past [`MAX_CELLS`]), ascending, once each.
    fn candidates(&self, corners: &Corners, count: usize, out: &mut Vec<u32>) {
        out.clear();
        match self.cells_met(corners) {
            Some(cells) => {
                for key in cells {
                    if let Some(ts) = self.cells.get(&key) {
                        out.extend_from_slice(ts);
                    }
                }
                out.extend_from_slice(&self.everywhere);
            }
            None => out.extend(0..count as u32),
        }
        out.sort_unstable();
        out.dedup();
    }
}

/// Whether two faces share two or more vertices: triangles along a
/// common edge meet there and cross nowhere else unless they lie in one
/// plane, which [`triangles_cross`] does not compare. Faces sharing one
/// vertex are compared: an edge away from it can pass through the other.
fn share_an_edge(a: &[u32; 3], b: &[u32; 3]) -> bool {
    a.iter().filter(|v| b.contains(v)).count() >= 2
}

/// Whether an edge of either triangle passes through the other's interior
/// (not through its edges or corners, so triangles that only touch do not
/// cross; coplanar ones are not compared).
pub(super) fn triangles_cross(a: &Corners, b: &Corners) -> bool {
    let edge_through = |t: &Corners, s: &Corners| {
        (0..3).any(|k| segment_through_triangle(s[k], s[(k + 1) % 3], t))
    };
    edge_through(a, b) || edge_through(b, a)
}

/// Möller and Trumbore's segment–triangle test, strictly inside both.
fn segment_through_triangle(p: Point3, q: Point3, [a, b, c]: &Corners) -> bool {
    const INSIDE: f64 = 1e-9;
    let (e1, e2, d) = (sub(*b, *a), sub(*c, *a), sub(q, p));
    let h = cross(d, e2);
    let det = dot(e1, h);
    if det.abs() <= 1e-12 * norm2(e1).sqrt() * norm2(e2).sqrt() * norm2(d).sqrt() {
        return false;
    }
    let s = sub(p, *a);
    let u = dot(s, h) / det;
    let qv = cross(s, e1);
    let v = dot(d, qv) / det;
    let t = dot(e2, qv) / det;
    u > INSIDE && v > INSIDE && u + v < 1.0 - INSIDE && t > INSIDE && t < 1.0 - INSIDE
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// Every kept face compared with every strip triangle.
    fn kept_faces_crossed_reference(
        mesh: &Mesh,
        removed: &[u32],
        strip: &[[u32; 3]],
        position: &dyn Fn(u32) -> Point3,
    ) -> Vec<u32> {
        (0..mesh.faces.len() as u32)
            .filter(|f| !removed.contains(f))
            .filter(|&f| {
                let face = mesh.faces[f as usize];
                let kept = face.map(|v| mesh.vertices[v as usize]);
                strip
                    .iter()
                    .any(|s| !share_an_edge(s, &face) && triangles_cross(&kept, &s.map(position)))
            })
            .collect()
    }

    /// The grid finds what comparing every pair finds: a bumpy grid mesh
    /// with some faces removed, pierced by random triangles of new points
    /// and mesh vertices, long ones among them, at cells from a hundredth
    /// of the mesh's spacing (every box too large to file) to beyond its
    /// size.
    #[test]
    fn the_grid_finds_every_crossing_pair() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(17);
        let mut mesh = crate::mesh::tests::grid(12);
        for p in &mut mesh.vertices {
            p[2] = 0.3 * (p[0] * 0.7).sin() * (p[1] * 0.5).cos();
        }
        let n = mesh.vertices.len() as u32;
        let mut total = 0;
        for case in 0..60 {
            let removed: Vec<u32> = (0..mesh.faces.len() as u32)
                .filter(|_| rng.random::<f64>() < 0.2)
                .collect();
            let new_points: Vec<Point3> = (0..30)
                .map(|_| {
                    [
                        rng.random_range(0.0..11.0),
                        rng.random_range(0.0..11.0),
                        rng.random_range(-1.0..1.0),
                    ]
                })
                .collect();
            let id = |rng: &mut rand::rngs::StdRng| {
                if rng.random::<f64>() < 0.3 {
                    rng.random_range(0..n)
                } else {
                    n + rng.random_range(0..new_points.len() as u32)
                }
            };
            let strip: Vec<[u32; 3]> = (0..20)
                .map(|_| [id(&mut rng), id(&mut rng), id(&mut rng)])
                .collect();
            let position = |v: u32| match v.checked_sub(n) {
                None => mesh.vertices[v as usize],
                Some(k) => new_points[k as usize],
            };
            // At 0.01 every box is past MAX_CELLS, at 0.1 the strip's.
            let cell = [0.01, 0.1, 0.7, 2.0, 50.0][case % 5];
            let fast = kept_faces_crossed(&mesh, &removed, &strip, &position, cell);
            let plain = kept_faces_crossed_reference(&mesh, &removed, &strip, &position);
            assert_eq!(fast, plain, "case {case}");
            total += fast.len();
        }
        assert!(total > 100, "{total}");
    }

    /// The sweep and the grid find what comparing every pair finds:
    /// random triangles on a few shared points (many share a vertex or an
    /// edge) or on many, in cells from a thousandth of their extent (every
    /// box too large to file) to beyond it.
    #[test]
    fn the_sweep_and_the_grid_find_every_crossing_pair_of_one_set() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(23);
        let mut total = 0;
        for case in 0..40 {
            let count = [12, 40, 240][case % 3];
            let points: Vec<Point3> = (0..count)
                .map(|_| std::array::from_fn(|_| rng.random_range(0.0..10.0)))
                .collect();
            let faces: Vec<[u32; 3]> = (0..80)
                .map(|_| std::array::from_fn(|_| rng.random_range(0..points.len() as u32)))
                .filter(|f: &[u32; 3]| f[0] != f[1] && f[1] != f[2] && f[0] != f[2])
                .collect();
            let position = |v: u32| points[v as usize];
            let mut plain = Vec::new();
            for i in 0..faces.len() {
                for j in i + 1..faces.len() {
                    if !share_an_edge(&faces[i], &faces[j])
                        && triangles_cross(&faces[i].map(position), &faces[j].map(position))
                    {
                        plain.push((i as u32, j as u32));
                    }
                }
            }
            assert_eq!(crossing_pairs(&faces, &position), plain, "case {case}");
            let cell = [0.01, 0.5, 2.0, 50.0][case % 4];
            let filed = crossing_pairs_filed(&faces, &position, cell);
            assert_eq!(filed, plain, "case {case}, cell {cell}");
            total += plain.len();
        }
        assert!(total > 100, "{total}");
    }

    #[test]
    fn triangles_cross_only_through_their_interiors() {
        let flat = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
        let through = [[1.0, 1.0, -1.0], [1.0, 1.0, 1.0], [3.0, 3.0, 1.0]];
        assert!(triangles_cross(&flat, &through));
        assert!(triangles_cross(&through, &flat));
        let above = through.map(|p| [p[0], p[1], p[2] + 2.0]);
        assert!(!triangles_cross(&flat, &above));
        // Sharing an edge, folded: touching is not crossing.
        let hinge = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [2.0, 0.0, 3.0]];
        assert!(!triangles_cross(&flat, &hinge));
        // One edge of each through the other (a chain link).
        let link = [[1.0, -1.0, -1.0], [1.0, 2.0, -1.0], [1.0, 0.5, 2.0]];
        assert!(triangles_cross(&flat, &link));
    }
}
