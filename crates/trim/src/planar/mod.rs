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
#[cfg(test)]
pub(crate) use ring::flat_ring;
pub(crate) use ring::{kept_apart, untwist, Ring, Tangle};
pub(crate) use segment_grid::{Contact, SegmentGrid};
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
    let parity = flood(cdt, false, |odd, edge| odd ^ edge.constraint);
    cdt.fixed_inner_faces()
        .filter(|f| parity[f.index()] == Some(true))
        .collect()
}

/// An edge crossed by [`flood`], from its right to its left.
struct Crossing {
    from: FixedVertexHandle,
    to: FixedVertexHandle,
    constraint: bool,
}

/// A value for every face reached from the outside (which holds
/// `outside`), flooding across edges: a face's value is `enter` of its
/// neighbour's and the edge crossed into it. Indexed by face.
fn flood<T: Copy>(cdt: &Cdt, outside: T, enter: impl Fn(T, Crossing) -> T) -> Vec<Option<T>> {
    let crossing = |e: spade::handles::DirectedEdgeHandle<Node, (), _, ()>| Crossing {
        from: e.from().fix(),
        to: e.to().fix(),
        constraint: e.is_constraint_edge(),
    };
    let mut value: Vec<Option<T>> = vec![None; cdt.num_all_faces()];
    let mut stack = Vec::new();
    for e in cdt.convex_hull() {
        for side in [e, e.rev()] {
            // The face on the side's left, entered from the outside.
            if let Some(inner) = side.face().as_inner() {
                if value[inner.fix().index()].is_none() {
                    let v = enter(outside, crossing(side));
                    value[inner.fix().index()] = Some(v);
                    stack.push((inner.fix(), v));
                }
            }
        }
    }
    while let Some((f, v)) = stack.pop() {
        for e in cdt.face(f).adjacent_edges() {
            // f is on e's left: the next face, on its right, is entered
            // across e's reverse from that one's right to its left.
            if let Some(next) = e.rev().face().as_inner() {
                if value[next.fix().index()].is_none() {
                    let w = enter(v, crossing(e.rev()));
                    value[next.fix().index()] = Some(w);
                    stack.push((next.fix(), w));
                }
            }
        }
    }
    value
}

/// Turns of constraint edges: for the edge between two vertices (smaller
/// handle first), what the winding gains crossing it from the right of
/// smaller → larger to its left.
pub(crate) type Turns = HashMap<(FixedVertexHandle, FixedVertexHandle), i32>;

/// The inner faces whose winding is at least 1: a flood fill from the
/// outside (winding 0) that adds each constraint edge's turn as it crosses.
pub(crate) fn winding_faces(cdt: &Cdt, turns: &Turns) -> Vec<FixedFaceHandle<InnerTag>> {
    let winding = flood(cdt, 0, |w, edge| {
        // What the winding gains crossing edge from → to from its right
        // to its left.
        w + if edge.from < edge.to {
            turns.get(&(edge.from, edge.to)).copied().unwrap_or(0)
        } else {
            -turns.get(&(edge.to, edge.from)).copied().unwrap_or(0)
        }
    });
    cdt.fixed_inner_faces()
        .filter(|f| winding[f.index()].is_some_and(|w| w >= 1))
        .collect()
}
