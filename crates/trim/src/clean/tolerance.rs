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
//! its points to the bound once more.

use crate::geom::{add, dist2, scale, sub, Point3};

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

#[cfg(test)]
mod tests {
    use super::*;

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
