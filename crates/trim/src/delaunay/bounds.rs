//! Steps 3 and 4 of the Delaunay path: the loops made valid in the
//! projection, and the cloud points inside them.

use super::*;

/// Points closer to a loop in the projection than this share of
/// [`DelaunayOptions::exclude`]·β are left out whatever their distance in
/// 3D: on a constraint they would split it.
const IN_PROJECTION: f64 = 1.0 / 3.0;

/// Consecutive loop vertices closer than this many β in the projection
/// are merged (step 3): a much shorter segment than the spacing, opposite
/// a point a spacing away, makes a sliver.
const LOOP_GAP: f64 = 0.4;

/// The loops that bound the mesh, valid in the projection.
pub(super) struct Bounds {
    pub(super) rings: Vec<Ring>,
    pub(super) grid: SegmentGrid,
    /// Where loops crossed: each ring's surface side ([`surface_sides`]),
    /// the surface then being where the winding is at least 1. `None`
    /// where no loop crosses: parity says the same without sides.
    pub(super) sides: Option<Vec<i32>>,
    /// What the errors call the plane.
    pub(super) onto: &'static str,
}

impl Bounds {
    /// Is the point `p3`, at `p` in the projection, within `reach` of a
    /// loop in 3D, or within [`IN_PROJECTION`]·`reach` of one in the
    /// projection, where it could lie on the constraint? Measured in 3D
    /// because that is where the faces are: where the surface turns
    /// steeply away from the projection near its border, a point close to
    /// the loop in the projection lies far from it on the surface, and its
    /// faces are well shaped.
    pub(super) fn near_loop(&self, p3: Point3, p: [f64; 2], reach: f64) -> bool {
        self.grid.near(p, IN_PROJECTION * reach)
            || self.grid.near_where(p, reach, |s| {
                let (l, j) = self.grid.owner[s as usize];
                let ring = &self.rings[l as usize];
                let (a, b) = (
                    ring.p3[j as usize],
                    ring.p3[(j as usize + 1) % ring.p3.len()],
                );
                segment_dist2(p3, a, b) < reach * reach
            })
    }

    /// Is `p` (away from the loops) on the surface?
    pub(super) fn inside(&self, p: [f64; 2]) -> bool {
        match &self.sides {
            None => self.grid.parity(p),
            Some(sides) => self.grid.winding(p, sides) >= 1,
        }
    }
}

/// Step 3, **loops made valid**: each smoothed loop as a ring projected
/// onto the plane, vertices closer than 0.4 β merged, small self-crossings
/// untwisted ([`untwist`]); where that leaves loops crossing, they are
/// split at their crossings instead ([`untangle`]) and each gets its
/// surface side. Fills `loop_vertices_merged`, `loop_vertices_dropped`
/// and `loop_crossings`.
pub(super) fn valid_rings(
    edges: &Edges,
    cloud: &[Point3],
    beta: &[f64],
    beta_median: f64,
    plane: &Projection,
    options: &DelaunayOptions,
    report: &mut DelaunayReport,
) -> Result<Bounds, DelaunayError> {
    let mut rings: Vec<Ring> = edges
        .loops
        .iter()
        .map(|lp| Ring::from_loop(lp, beta))
        .collect();
    for ring in rings.iter_mut() {
        ring.p2 = ring.p3.iter().map(|&p| plane.to2(p)).collect();
        report.loop_vertices_merged += ring.merge_coincident();
        report.loop_vertices_merged += ring.even_out_in_projection(LOOP_GAP);
    }
    let min_cell = options.exclude * beta_median;
    let merged = rings.clone();
    match untwist(&mut rings, min_cell, options.max_repair) {
        Ok((grid, dropped)) => {
            report.loop_vertices_dropped += dropped;
            Ok(Bounds {
                rings,
                grid,
                sides: None,
                onto: plane.onto,
            })
        }
        Err(tangle) => untangled(&merged, cloud, beta, plane, min_cell, report)
            .ok_or_else(|| tangle_error(tangle, plane.onto)),
    }
}

/// The loops split at their crossings ([`untangle`]), each with the
/// surface side the cloud points near it vote for; `None` where loops
/// touch or run along each other, which no split resolves.
fn untangled(
    rings: &[Ring],
    cloud: &[Point3],
    beta: &[f64],
    plane: &Projection,
    min_cell: f64,
    report: &mut DelaunayReport,
) -> Option<Bounds> {
    let split = untangle(rings, &SegmentGrid::new(rings, min_cell)).ok()?;
    let grid = SegmentGrid::new(&split.rings, min_cell);
    let votes: Vec<Option<(u32, f64)>> = (0..cloud.len())
        .into_par_iter()
        .map(|i| grid.nearest(plane.to2(cloud[i]), VOTE_REACH * beta[i]))
        .collect();
    let sides = surface_sides(&split.rings, &grid, votes.into_iter().flatten());
    report.loop_crossings = split.crossings;
    Some(Bounds {
        rings: split.rings,
        grid,
        sides: Some(sides),
        onto: plane.onto,
    })
}

fn tangle_error(tangle: Tangle, onto: &'static str) -> DelaunayError {
    match tangle {
        Tangle::SelfCrossing {
            index,
            vertices,
            dropped,
        } => DelaunayError::LoopNotSimple {
            onto,
            index,
            vertices,
            dropped,
        },
        Tangle::Crossing { a, b } => DelaunayError::LoopsCross { onto, a, b },
    }
}

/// Where a cloud point lies relative to the loops (step 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum PointClass {
    /// Inside the loops by parity and away from them: inserted.
    Inside,
    /// Within [`DelaunayOptions::exclude`]·β of a loop: left out, the loop stands for the
    /// border there.
    NearLoop,
    /// Beyond the outer border or in a hole.
    Outside,
}

/// Step 4, **which points go in**: the cloud points inside the loops by
/// parity and farther than [`DelaunayOptions::exclude`]·βᵢ from every loop, as
/// triangulation nodes in cloud order. Points next to a loop would only
/// make slivers, or on it split the constraint and change the border's
/// vertex sequence. Fills `points_near_loop` and `points_outside`.
pub(super) fn points_inside(
    cloud: &[Point3],
    beta: &[f64],
    plane: &Projection,
    bounds: &Bounds,
    exclude: f64,
    report: &mut DelaunayReport,
) -> Vec<Node> {
    let class: Vec<PointClass> = (0..cloud.len())
        .into_par_iter()
        .map(|i| {
            let p = plane.to2(cloud[i]);
            if bounds.near_loop(cloud[i], p, exclude * beta[i]) {
                PointClass::NearLoop
            } else if bounds.inside(p) {
                PointClass::Inside
            } else {
                PointClass::Outside
            }
        })
        .collect();
    let count = |c: PointClass| class.iter().filter(|&&k| k == c).count();
    report.points_near_loop = count(PointClass::NearLoop);
    report.points_outside = count(PointClass::Outside);
    (0..cloud.len())
        .filter(|&i| class[i] == PointClass::Inside)
        .map(|i| Node::new(plane.to2(cloud[i]), i as u32))
        .collect()
}
