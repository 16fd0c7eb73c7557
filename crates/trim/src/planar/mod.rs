//! The planar toolkit shared by the Delaunay path and cleanup
//! (infrastructure; no section of the paper): a constrained
//! Delaunay triangulation (spade, exact predicates) whose vertices carry
//! ids, smoothed loops as closed polylines in a projection, their repair
//! where they cross themselves, and a segment grid for parity, proximity
//! and crossing queries.

mod diagonals;
mod ring;
mod segment_grid;
mod tangle;

use spade::handles::{FixedFaceHandle, FixedVertexHandle, InnerTag};

use crate::hash::HashMap;
use spade::{
    ConstrainedDelaunayTriangulation, HasPosition, Intersection, LineIntersectionIterator, Point2,
    Triangulation,
};

pub(crate) use diagonals::{canonical_diagonals, cocircular};
pub(crate) use ring::{untwist, Ring, Tangle};
pub(crate) use segment_grid::SegmentGrid;
#[cfg(test)]
pub(crate) use tangle::pinched_faces;
pub(crate) use tangle::{pinches_opened, surface_sides, untangle, VOTE_REACH};

/// The constrained Delaunay triangulation of a projection.
pub(crate) type Cdt = ConstrainedDelaunayTriangulation<Node>;

/// A triangulation vertex: a cloud point (id < n) or a loop vertex
/// (id − n into the loop vertices).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Node {
    pub(crate) position: Point2<f64>,
    pub(crate) id: u32,
}

impl Node {
    pub(crate) fn new(p: [f64; 2], id: u32) -> Self {
        Node {
            position: point(p),
            id,
        }
    }
}

/// Id of a vertex inserted by refinement until it gets its own.
pub(crate) const STEINER: u32 = u32::MAX;

impl From<Point2<f64>> for Node {
    fn from(position: Point2<f64>) -> Self {
        Node {
            position,
            id: STEINER,
        }
    }
}

impl HasPosition for Node {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.position
    }
}

/// A spade point; coordinates too small for spade's predicates are zero.
pub(crate) fn point(p: [f64; 2]) -> Point2<f64> {
    let flush = |c: f64| {
        if c.abs() < spade::MIN_ALLOWED_VALUE {
            0.0
        } else {
            c
        }
    };
    Point2::new(flush(p[0]), flush(p[1]))
}

/// What stands in the way of a constraint from `a` to `b`: a constraint
/// edge it crosses or overlaps, or a vertex it passes through (its id).
pub(crate) fn obstacle(cdt: &Cdt, a: FixedVertexHandle, b: FixedVertexHandle) -> Option<u32> {
    if a == b {
        return Some(cdt.vertex(a).data().id);
    }
    for intersection in LineIntersectionIterator::new_from_handles(cdt, a, b) {
        match intersection {
            Intersection::EdgeIntersection(e) if e.is_constraint_edge() => {
                return Some(e.from().data().id)
            }
            Intersection::EdgeOverlap(e) if e.is_constraint_edge() => {
                return Some(e.from().data().id)
            }
            Intersection::VertexIntersection(v) if v.fix() != a && v.fix() != b => {
                return Some(v.data().id)
            }
            _ => {}
        }
    }
    None
}

/// The inner faces with odd parity: a flood fill from the outside that
/// flips parity across each constraint edge.
pub(crate) fn inside_faces(cdt: &Cdt) -> Vec<FixedFaceHandle<InnerTag>> {
    let mut parity: Vec<Option<bool>> = vec![None; cdt.num_all_faces()];
    let mut stack = Vec::new();
    for e in cdt.convex_hull() {
        for side in [e, e.rev()] {
            if let Some(inner) = side.face().as_inner() {
                if parity[inner.fix().index()].is_none() {
                    let odd = side.is_constraint_edge();
                    parity[inner.fix().index()] = Some(odd);
                    stack.push((inner.fix(), odd));
                }
            }
        }
    }
    while let Some((f, odd)) = stack.pop() {
        for e in cdt.face(f).adjacent_edges() {
            if let Some(next) = e.rev().face().as_inner() {
                if parity[next.fix().index()].is_none() {
                    let p = odd ^ e.is_constraint_edge();
                    parity[next.fix().index()] = Some(p);
                    stack.push((next.fix(), p));
                }
            }
        }
    }
    cdt.fixed_inner_faces()
        .filter(|f| parity[f.index()] == Some(true))
        .collect()
}

/// Turns of constraint edges: for the edge between two vertices (smaller
/// handle first), what the winding gains crossing it from the right of
/// smaller → larger to its left.
pub(crate) type Turns = HashMap<(FixedVertexHandle, FixedVertexHandle), i32>;

/// The inner faces whose winding is at least 1: a flood fill from the
/// outside (winding 0) that adds each constraint edge's turn as it crosses.
pub(crate) fn winding_faces(cdt: &Cdt, turns: &Turns) -> Vec<FixedFaceHandle<InnerTag>> {
    // What the winding gains crossing edge from → to from its right to
    // its left.
    let gain = |from: FixedVertexHandle, to: FixedVertexHandle| {
        if from < to {
            turns.get(&(from, to)).copied().unwrap_or(0)
        } else {
            -turns.get(&(to, from)).copied().unwrap_or(0)
        }
    };
    let mut winding: Vec<Option<i32>> = vec![None; cdt.num_all_faces()];
    let mut stack = Vec::new();
    for e in cdt.convex_hull() {
        for side in [e, e.rev()] {
            // The face on the side's left, entered from the outside on its
            // right.
            if let Some(inner) = side.face().as_inner() {
                if winding[inner.fix().index()].is_none() {
                    let w = gain(side.from().fix(), side.to().fix());
                    winding[inner.fix().index()] = Some(w);
                    stack.push((inner.fix(), w));
                }
            }
        }
    }
    while let Some((f, w)) = stack.pop() {
        for e in cdt.face(f).adjacent_edges() {
            // f is on e's left; the next face on its right.
            if let Some(next) = e.rev().face().as_inner() {
                if winding[next.fix().index()].is_none() {
                    let v = w - gain(e.from().fix(), e.to().fix());
                    winding[next.fix().index()] = Some(v);
                    stack.push((next.fix(), v));
                }
            }
        }
    }
    cdt.fixed_inner_faces()
        .filter(|f| winding[f.index()].is_some_and(|w| w >= 1))
        .collect()
}
