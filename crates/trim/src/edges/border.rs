//! A mesh's own border as edges, for writing it as curves the way
//! reconstructed edges are written.
//!
//! Each border loop of the mesh ([`Mesh::boundary_loops`]) is split at its
//! corners, found by the paper's corner test (section 3.1, [`corners`]) at
//! the border vertices' β, into edges through the border vertices
//! themselves: nothing is detected, smoothed or moved. Meant for a mesh
//! whose border is already smooth: a cleaned scan, whose new border is the
//! smoothed loop (a loop the cleanup left is written as it is, jagged).

use super::{between_corners, corners, Edge, Edges, Loop, LoopSource};
use crate::geom::Point3;
use crate::mesh::Mesh;
use crate::resolution::PointResolution;

/// The border of `mesh` as [`Edges`]: one [`Loop`] per border loop, in the
/// mesh's order, its `boundary_points` the border vertices (indices into
/// `mesh.vertices`, as the faces run), its corners by the paper's corner
/// test at `beta` (one value per vertex of the mesh; only the border's
/// are read), its edges through the vertices from corner to corner (one
/// closed edge without corners). A mesh without a border has no loops.
///
/// The faces must index the vertices (as [`Mesh::validate`] checks), and
/// `beta` must hold a value for every border vertex.
pub fn mesh_border_edges(mesh: &Mesh, beta: &(impl PointResolution + ?Sized)) -> Edges {
    let loops = mesh
        .boundary_loops()
        .into_iter()
        .map(|border| border_loop(&mesh.vertices, beta, border))
        .collect();
    Edges {
        loops,
        dropped_clusters: 0,
        thinned_points: 0,
        loops_from: LoopSource::MeshBorder,
    }
}

/// One border loop of vertex indices as a [`Loop`].
fn border_loop(
    vertices: &[Point3],
    beta: &(impl PointResolution + ?Sized),
    border: Vec<u32>,
) -> Loop {
    let points: Vec<Point3> = border.iter().map(|&v| vertices[v as usize]).collect();
    let loop_beta: Vec<f64> = border.iter().map(|&v| beta.beta(v as usize)).collect();
    let corners = corners::find_corners(&points, &loop_beta);
    let edges = if corners.is_empty() {
        vec![Edge {
            closed: true,
            points,
        }]
    } else {
        between_corners(points.len(), &corners)
            .map(|run| Edge {
                closed: false,
                points: run.iter().map(|&j| points[j]).collect(),
            })
            .collect()
    };
    Loop {
        boundary_points: border,
        corners,
        edges,
        sides: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square of `n` × `n` unit cells, triangulated, with the cell at
    /// (`hole`, `hole`) left out when given.
    fn square(n: u32, hole: Option<u32>) -> Mesh {
        let id = |i: u32, j: u32| i * (n + 1) + j;
        let vertices = (0..=n)
            .flat_map(|i| (0..=n).map(move |j| [f64::from(i), f64::from(j), 0.0]))
            .collect();
        let mut faces = Vec::new();
        for i in 0..n {
            for j in 0..n {
                if hole == Some(i) && hole == Some(j) {
                    continue;
                }
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                faces.extend([[a, b, c], [a, c, d]]);
            }
        }
        Mesh { vertices, faces }
    }

    #[test]
    fn a_square_has_four_corners_and_its_hole_none() {
        let mesh = square(20, Some(10));
        let beta = vec![1.0; mesh.vertices.len()];
        let edges = mesh_border_edges(&mesh, &beta);
        assert_eq!(edges.loops_from, LoopSource::MeshBorder);
        let borders = mesh.boundary_loops();
        assert_eq!(edges.loops.len(), 2);
        for (lp, border) in edges.loops.iter().zip(&borders) {
            assert_eq!(&lp.boundary_points, border);
            // The edges run through the border vertices themselves, each
            // corner shared by the two edges it joins.
            let mut through: Vec<Point3> = Vec::new();
            for edge in &lp.edges {
                let own = if edge.closed {
                    &edge.points[..]
                } else {
                    &edge.points[..edge.points.len() - 1]
                };
                through.extend_from_slice(own);
            }
            let expected: Vec<Point3> = border.iter().map(|&v| mesh.vertices[v as usize]).collect();
            let start = lp.corners.first().copied().unwrap_or(0);
            let rotated: Vec<Point3> = (0..expected.len())
                .map(|j| expected[(start + j) % expected.len()])
                .collect();
            assert_eq!(through, rotated);
        }
        let outer = edges
            .loops
            .iter()
            .find(|l| l.boundary_points.len() == 80)
            .unwrap();
        let corner_points: Vec<Point3> = outer
            .corners
            .iter()
            .map(|&c| mesh.vertices[outer.boundary_points[c] as usize])
            .collect();
        assert_eq!(outer.corners.len(), 4, "{corner_points:?}");
        for p in corner_points {
            assert!(
                [0.0, 20.0].contains(&p[0]) && [0.0, 20.0].contains(&p[1]),
                "{p:?}"
            );
        }
        let hole = edges
            .loops
            .iter()
            .find(|l| l.boundary_points.len() == 4)
            .unwrap();
        assert!(hole.corners.is_empty() && hole.edges.len() == 1 && hole.edges[0].closed);
    }

    #[test]
    fn a_closed_mesh_has_no_loops() {
        let tetrahedron = Mesh {
            vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            faces: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        };
        assert!(mesh_border_edges(&tetrahedron, &vec![1.0; 4])
            .loops
            .is_empty());
    }
}
