//! The fields trimming cuts along (steps 1, 2 and 4 of the module doc):
//! the signed distance to the smoothed loops' walls, and how far a vertex
//! lies beyond the cloud's reach.

use super::*;

/// The smoothed loops as walls: polyline vertices with outward directions
/// and local spacing, indexed for nearest queries.
pub(super) struct Walls {
    pub(super) points: Vec<Point3>,
    /// Outward unit direction of the segment from point i to its successor.
    pub(super) out: Vec<Point3>,
    /// Successor and predecessor of each point in its closed loop.
    pub(super) next: Vec<u32>,
    pub(super) prev: Vec<u32>,
    pub(super) beta: Vec<f64>,
    /// The loop each point belongs to.
    pub(super) loop_of: Vec<u32>,
    pub(super) loops: usize,
    pub(super) tree: Option<PointTree>,
}

impl Walls {
    pub(super) fn new(cloud: &[Point3], detection: &Detection, edges: &Edges) -> Self {
        // The offset already measured each boundary point's side; without
        // it (offset off) they are measured here.
        let index = edges
            .loops
            .iter()
            .any(|lp| lp.sides.len() != lp.boundary_points.len())
            .then(|| NeighbourIndex::new(cloud));
        let mut w = Walls {
            points: Vec::new(),
            out: Vec::new(),
            next: Vec::new(),
            prev: Vec::new(),
            beta: Vec::new(),
            loop_of: Vec::new(),
            loops: edges.loops.len(),
            tree: None,
        };
        for (l, lp) in edges.loops.iter().enumerate() {
            let measured;
            let sides = match &index {
                Some(index) if lp.sides.len() != lp.boundary_points.len() => {
                    measured = edge_sides(index, &lp.boundary_points);
                    &measured
                }
                _ => &lp.sides,
            };
            let mut positions = Vec::new();
            for (p, position) in lp.closed_polyline() {
                positions.push(position);
                w.points.push(p);
            }
            let start = w.points.len() - positions.len();
            let m = positions.len();
            for (j, &position) in positions.iter().enumerate() {
                w.next.push((start + (j + 1) % m) as u32);
                w.prev.push((start + (j + m - 1) % m) as u32);
                w.beta
                    .push(detection.beta[lp.boundary_points[position] as usize]);
                w.loop_of.push(l as u32);
            }
            for j in 0..m {
                let i = start + j;
                let (a, b) = (w.points[i], w.points[w.next[i] as usize]);
                w.out
                    .push(outward(sub(b, a), a, &sides[positions[j]]).unwrap_or([0.0; 3]));
            }
        }
        if !w.points.is_empty() {
            w.tree = PointTree::new(&w.points);
        }
        w
    }

    pub(super) fn nearest_point(&self, v: Point3) -> Option<usize> {
        let tree = self.tree.as_ref()?;
        Some(tree.nearest(&v).0)
    }

    /// f(v): signed distance from v to the nearest wall (negative inside),
    /// and the local spacing there. With no loop at all, everything is
    /// inside.
    ///
    /// f = (v − q)·o(q) for the nearest point q of the polyline. The
    /// outward direction o and the spacing are interpolated along each
    /// segment between their values at its ends, so both are continuous
    /// along the loop and so is f: a vertex on the border between a
    /// segment's and a polyline vertex's region gets the same value from
    /// either, and rounding (moving the part far from the origin, say)
    /// cannot move the cut by more than it moves the points.
    pub(super) fn signed_distance(&self, v: Point3) -> (f64, f64) {
        let Some(i) = self.nearest_point(v) else {
            return (-1.0, 0.0);
        };
        // The nearest point on the two segments at the nearest vertex.
        let mut best = (
            dist2(v, self.points[i]),
            self.points[i],
            self.vertex_out(i),
            self.beta[i],
        );
        for (a, b) in [(self.prev[i] as usize, i), (i, self.next[i] as usize)] {
            if a == b {
                continue;
            }
            let (pa, pb) = (self.points[a], self.points[b]);
            let ab = sub(pb, pa);
            let len2 = norm2(ab);
            if len2 == 0.0 {
                continue;
            }
            let t = (dot(sub(v, pa), ab) / len2).clamp(0.0, 1.0);
            let q = lerp(pa, pb, t);
            let d = dist2(v, q);
            if d < best.0 && t > 0.0 && t < 1.0 {
                let out = unit_or(lerp(self.vertex_out(a), self.vertex_out(b), t), self.out[a]);
                let beta = self.beta[a] + t * (self.beta[b] - self.beta[a]);
                best = (d, q, out, beta);
            }
        }
        (dot(sub(v, best.1), best.2), best.3)
    }

    /// Outward direction at polyline vertex i: the mean of its segments'.
    pub(super) fn vertex_out(&self, i: usize) -> Point3 {
        let (a, b) = (self.out[self.prev[i] as usize], self.out[i]);
        unit_or(lerp(a, b, 0.5), b)
    }

    /// Mean and largest distance from the border vertices of `mesh` to the
    /// nearest loop, per loop.
    pub(super) fn border_fit(&self, mesh: &Mesh) -> Vec<LoopFit> {
        let mut fits = vec![LoopFit::default(); self.loops];
        for border in mesh.boundary_loops() {
            for v in border {
                let p = mesh.vertices[v as usize];
                let Some(i) = self.nearest_point(p) else {
                    continue;
                };
                let d = self.distance_to_polyline(p, i);
                let fit = &mut fits[self.loop_of[i] as usize];
                fit.mean += d;
                fit.max = fit.max.max(d);
                fit.count += 1;
            }
        }
        for fit in fits.iter_mut() {
            if fit.count > 0 {
                fit.mean /= fit.count as f64;
            }
        }
        fits
    }

    pub(super) fn distance_to_polyline(&self, v: Point3, i: usize) -> f64 {
        let mut best = dist2(v, self.points[i]);
        for (a, b) in [(self.prev[i] as usize, i), (i, self.next[i] as usize)] {
            let (pa, pb) = (self.points[a], self.points[b]);
            let ab = sub(pb, pa);
            let len2 = norm2(ab);
            if len2 > 0.0 {
                let t = (dot(sub(v, pa), ab) / len2).clamp(0.0, 1.0);
                best = best.min(dist2(v, lerp(pa, pb, t)));
            }
        }
        best.sqrt()
    }
}

/// The cloud's reach: how far from the cloud the kept surface may lie.
pub(super) struct Reach<'a> {
    pub(super) beta: &'a [f64],
    /// β's that end the kept surface.
    pub(super) reach: f64,
    pub(super) tree: Option<PointTree>,
}

impl<'a> Reach<'a> {
    pub(super) fn new(cloud: &[Point3], beta: &'a [f64], reach: f64) -> Self {
        Reach {
            beta,
            reach,
            tree: PointTree::new(cloud),
        }
    }

    /// g(v) = d − reach·β, with d the distance from v to the nearest cloud
    /// point and β that point's local resolution; and β, which snaps g.
    /// g > 0 where v is out of the cloud's reach.
    pub(super) fn excess(&self, v: Point3) -> (f64, f64) {
        // The tree refuses only more points than its item index holds:
        // then, as without walls, nothing is cut.
        let Some(tree) = &self.tree else {
            return (-1.0, 0.0);
        };
        let (nearest, distance2) = tree.nearest(&v);
        let beta = self.beta[nearest];
        (distance2.sqrt() - self.reach * beta, beta)
    }
}

/// The field of a cut from each vertex's (value, local spacing), and how
/// many values were snapped to 0: a vertex closer to the cut than `snap`
/// local spacings is moved onto it (f := 0), so that the cut passes
/// through it instead of leaving a sliver beside it.
pub(super) fn snapped_field(values: &[(f64, f64)], snap: f64) -> (Vec<f64>, usize) {
    let mut snapped = 0;
    let field = values
        .iter()
        .map(|&(f, spacing)| {
            if f != 0.0 && f.abs() < snap * spacing {
                snapped += 1;
                0.0
            } else {
                f
            }
        })
        .collect();
    (field, snapped)
}

/// `v` scaled to unit length, or `fallback` when `v` is zero (opposite
/// directions averaged).
pub(super) fn unit_or(v: Point3, fallback: Point3) -> Point3 {
    let len = norm2(v).sqrt();
    if len > 0.0 {
        v.map(|c| c / len)
    } else {
        fallback
    }
}
