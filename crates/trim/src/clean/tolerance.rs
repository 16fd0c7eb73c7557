//! The `max_deviation` option: each smoothed loop kept within a distance
//! of the border it replaces (meshtrim's own, not the paper's: its
//! low-pass filter has no bound on how far the smoothed edge may move).
//!
//! The FFT low-pass (section 3.3) follows β, not the part's tolerance: a
//! notch a few spacings wide is bridged and a narrow corner cut off,
//! however deep (on the MeshLab face scan, 13.1 mm and 12.6 mm). Each
//! smoothed vertex is the filtered position of one border vertex (its
//! `reference`), so a vertex farther than the bound from its own border
//! vertex is moved towards it until it lies at the bound. Both ways are
//! then bounded: every smoothed vertex lies within the bound of the old
//! border, and every old border vertex within the bound of the smoothed
//! loop. The loop stays as smooth as β makes it where the scan's border
//! is within tolerance of it, and follows the border, at the bound,
//! where it is not (into a notch, round a corner). The vertices the
//! cleanup removes lie between the two curves or within half a β of the
//! new one, and the new ones on the smoothed loop, so the report's two
//! deviations follow the bound. The strip smooths a silhouette's depth
//! again after this (up to 20 spacings on the bunny's scans), so it holds
//! its points to the bound once more; and the points it adds inside
//! itself when it refines thin faces, which across a range grid's skirts
//! lie off the scan, are moved towards the scan's faces it replaces
//! ([`pull_within`]), so that every new vertex lies within the bound.

use crate::attributes::closest_on_face;
use crate::geom::{add, dist2, scale, sub, Point3};
use crate::mesh::Mesh;

/// Moves every point of a smoothed loop that lies farther than `max` from
/// the mesh vertex it was smoothed from (`references`, in step) to
/// distance `max` from it, along the line between them. Returns how many
/// points moved.
pub(super) fn keep_within(
    points: &mut [Point3],
    references: &[u32],
    vertices: &[Point3],
    max: f64,
) -> usize {
    let mut moved = 0;
    for (p, &reference) in points.iter_mut().zip(references) {
        let Some(&from) = vertices.get(reference as usize) else {
            continue;
        };
        let distance = dist2(*p, from).sqrt();
        if distance > max {
            *p = add(from, scale(sub(*p, from), max / distance));
            moved += 1;
        }
    }
    moved
}

/// Moves every point farther than `max` from `faces` of `mesh` (the
/// scan's faces a patch replaces) towards its closest point on them, to
/// distance `max`. Returns how many moved.
pub(super) fn pull_within(points: &mut [Point3], mesh: &Mesh, faces: &[u32], max: f64) -> usize {
    let mut moved = 0;
    for p in points.iter_mut() {
        let Some((d2, on)) = faces
            .iter()
            .map(|&f| closest_point_on_face(mesh, f, *p))
            .min_by(|a, b| a.0.total_cmp(&b.0))
        else {
            continue;
        };
        let distance = d2.sqrt();
        if distance > max {
            *p = add(on, scale(sub(*p, on), max / distance));
            moved += 1;
        }
    }
    moved
}

fn closest_point_on_face(mesh: &Mesh, face: u32, p: Point3) -> (f64, Point3) {
    let (d2, w) = closest_on_face(mesh, face, p);
    let [a, b, c] = mesh.faces[face as usize].map(|v| mesh.vertices[v as usize]);
    let on = std::array::from_fn(|k| w[0] * a[k] + w[1] * b[k] + w[2] * c[k]);
    (d2, on)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_off_the_faces_comes_back_towards_its_closest_point() {
        let mesh = crate::mesh::tests::grid(4);
        // Above face interiors, beside the grid's edge, and near enough.
        let mut points = vec![[1.5, 1.5, 3.0], [-2.0, 2.0, 0.0], [2.2, 3.1, 0.5]];
        let all: Vec<u32> = (0..mesh.faces.len() as u32).collect();
        assert_eq!(pull_within(&mut points, &mesh, &all, 1.0), 2);
        let expected = [[1.5, 1.5, 1.0], [-1.0, 2.0, 0.0], [2.2, 3.1, 0.5]];
        for (p, e) in points.iter().zip(expected) {
            assert!(dist2(*p, e) < 1e-24, "{p:?} {e:?}");
        }
        // Only the faces given count: the grid's first row of squares.
        let mut point = vec![[2.5, 3.5, 0.0]];
        assert_eq!(
            pull_within(&mut point, &mesh, &[0, 1, 2, 3, 4, 5, 6, 7], 0.5),
            1
        );
        assert!(dist2(point[0], [2.5, 1.5, 0.0]) < 1e-24, "{point:?}");
    }

    #[test]
    fn a_vertex_beyond_the_bound_comes_back_to_it_along_its_line() {
        let vertices = vec![[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 10.0, 0.0]];
        let mut points = vec![[0.0, 3.0, 4.0], [10.0, 0.2, 0.0], [12.0, 10.0, 0.0]];
        assert_eq!(keep_within(&mut points, &[0, 1, 2], &vertices, 1.0), 2);
        let expected = [[0.0, 0.6, 0.8], [10.0, 0.2, 0.0], [11.0, 10.0, 0.0]];
        for (p, e) in points.iter().zip(expected) {
            assert!(dist2(*p, e) < 1e-24, "{p:?} {e:?}");
        }
    }
}
