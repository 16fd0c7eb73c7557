//! Edge reconstruction (section 3 of the paper): from labelled boundary
//! points to ordered, closed boundary loops.
//!
//! 1. [`cluster`] groups the boundary points into separate boundaries by the
//!    links BPD found between them and thins spurs away;
//! 2. [`order`] turns each group into a closed tour.

pub mod cluster;
pub mod order;
