//! Spatial indexes: Morton (Z-order) cells, the k nearest neighbours of
//! every point (section 2 of the paper: "the k nearest neighbours";
//! kiddo's k-d tree, named nowhere else), and the closest face of a mesh
//! (trimming's support test).

pub(crate) mod closest_face;
pub(crate) mod morton;
pub(crate) mod neighbours;
mod point_tree;

pub(crate) use point_tree::PointTree;
