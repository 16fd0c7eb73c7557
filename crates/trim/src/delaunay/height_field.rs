//! Steps 2 and 7 of the Delaunay path: the checks that the cloud, then
//! the triangulation, is a height field over the projection.

use super::*;

/// Neighbourhood size of the local normals of the height-field check.
pub(super) const NORMAL_K: usize = 30;

/// Most points per k-NN run of the local normals (as BPD's runs).
const NORMAL_RUN: usize = 32;

/// A local normal with |nᵢ·n| below this stands on edge over the plane.
const STEEP_COS: f64 = 0.1;

/// A triangle whose normal makes a mean |n_t·nᵥ| below this with its
/// vertices' local normals does not follow the surface.
const MISFIT_COS: f64 = 0.5;

/// Step 2, **local normals**: each point's normal fitted to its
/// 30 nearest neighbours, oriented to the side `plane_normal`
/// points to.
///
/// The search runs over the points in Morton order, as BPD's does (about
/// twice as fast as a k-d tree at 1M points), with ties cut by input
/// index: the same neighbours in the same order as [`NeighbourIndex::new`]
/// gives, so the same normals.
pub(super) fn local_normals(cloud: &[Point3], plane_normal: Point3) -> Vec<Point3> {
    let grid = MortonGrid::of(cloud);
    let (order, keys) = spatial_order(cloud, &grid);
    let sorted: Vec<Point3> = order.par_iter().map(|&i| cloud[i as usize]).collect();
    let index =
        NeighbourIndex::in_morton_order(&sorted, MortonCells::new(grid, &keys)).with_ranks(&order);
    // Each run's normals written in place, in Morton order.
    let mut by_position = vec![[0.0; 3]; cloud.len()];
    let runs = octree_runs(&keys, NORMAL_RUN);
    let pieces = split_by_runs(&runs, &mut by_position, 1);
    let k = NORMAL_K.min(cloud.len());
    runs.into_par_iter().zip(pieces).for_each_init(
        || (RunScratch::default(), Vec::new()),
        |(scratch, members), (run, out)| {
            members.resize(run.len() * k, 0);
            index.nearest_of_run(run, k, members, scratch);
            for (nb, normal) in members.chunks_exact_mut(k).zip(out) {
                nb.iter_mut().for_each(|q| *q = order[*q as usize]);
                *normal = oriented_normal(cloud, nb, plane_normal);
            }
        },
    );
    // The sorted copy's block is free again for the normals.
    drop(index);
    drop(sorted);
    let mut normals = vec![[0.0; 3]; cloud.len()];
    for (&i, m) in order.iter().zip(by_position) {
        normals[i as usize] = m;
    }
    normals
}

/// The normal of the plane fitted to `members`, on `plane_normal`'s side.
pub(super) fn oriented_normal(cloud: &[Point3], members: &[u32], plane_normal: Point3) -> Point3 {
    let m = fit_plane(cloud, members).normal;
    if dot(m, plane_normal) < 0.0 {
        m.map(|c| -c)
    } else {
        m
    }
}

/// Step 2, **height-field check on the points**: where the surface stands
/// on edge or folds over its plane, local normals turn perpendicular to
/// the plane normal; more than [`DelaunayOptions::max_steep_share`] of them below
/// 0.1 is [`DelaunayError::NotAHeightField`]. Fills
/// `steep_normals_percent`.
pub(super) fn check_steep_normals(
    cloud: &[Point3],
    normals: &[Point3],
    plane: &Projection,
    options: &DelaunayOptions,
    report: &mut DelaunayReport,
) -> Result<(), DelaunayError> {
    let n = normals.len();
    let steep = normals
        .iter()
        .zip(cloud)
        .filter(|&(m, &p)| dot(*m, plane.sight(p)).abs() < STEEP_COS)
        .count();
    report.steep_normals_percent = 100.0 * steep as f64 / n as f64;
    if steep as f64 > options.max_steep_share * n as f64 {
        return Err(DelaunayError::NotAHeightField {
            onto: plane.onto,
            percent: report.steep_normals_percent,
            what: "local normals",
            limit: 100.0 * options.max_steep_share,
        });
    }
    Ok(())
}

/// Step 7, **height-field check on the triangles**: a lifted
/// counter-clockwise triangle can never be flipped relative to the plane
/// normal, so folds show instead as triangles joining the overlapping
/// sheets, steep to the surface. Misfits ([`is_misfit`]) holding more than
/// [`DelaunayOptions::max_misfit_share`] of the mesh's area is
/// [`DelaunayError::NotAHeightField`]. The share is of the area, not of
/// the triangles: a fold's triangles span the gap between its sheets,
/// while a sliver between two loops that nearly touch has a normal that
/// says nothing of the surface and covers almost none of it (on a blade
/// of 101 points, 2 such slivers were 1.1 % of the triangles and 0.09 %
/// of the area). Fills `degenerate_faces` (below 10⁻¹²·β², counted, not
/// removed) and `misfit_area_percent`.
pub(super) fn check_triangles(
    mesh: &Mesh,
    reference: &[u32],
    normals: &[Point3],
    beta_median: f64,
    onto: &'static str,
    options: &DelaunayOptions,
    report: &mut DelaunayReport,
) -> Result<(), DelaunayError> {
    let (mut misfit_area, mut area) = (0.0, 0.0);
    for face in &mesh.faces {
        let [a, b, c] = face.map(|v| mesh.vertices[v as usize]);
        let nt = cross(sub(b, a), sub(c, a));
        let len = norm2(nt).sqrt();
        if 0.5 * len <= DEGENERATE * beta_median * beta_median {
            report.degenerate_faces += 1;
        }
        // The local normals of the points the face's vertices stand for.
        let vertex_normals = face.map(|v| normals[reference[v as usize] as usize]);
        area += 0.5 * len;
        if is_misfit(nt, len, vertex_normals) {
            misfit_area += 0.5 * len;
        }
    }
    report.misfit_area_percent = 100.0 * misfit_area / area;
    if misfit_area > options.max_misfit_share * area {
        return Err(DelaunayError::NotAHeightField {
            onto,
            percent: report.misfit_area_percent,
            what: "triangles' area",
            limit: 100.0 * options.max_misfit_share,
        });
    }
    Ok(())
}

/// Does a triangle with normal `nt` (unnormalised, of length `len`) not
/// follow the surface: a mean |n_t·nᵥ| over its vertices' local normals
/// below 0.5? A zero-area triangle counts as one.
fn is_misfit(nt: Point3, len: f64, vertex_normals: [Point3; 3]) -> bool {
    if len == 0.0 {
        return true;
    }
    let fit: f64 = vertex_normals
        .iter()
        .map(|&m| dot(nt, m).abs() / len)
        .sum::<f64>()
        / 3.0;
    fit < MISFIT_COS
}
