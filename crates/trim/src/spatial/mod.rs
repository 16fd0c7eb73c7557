//! Spatial indexes: Morton (Z-order) cells, the k nearest neighbours of
//! every point (the only place that names kiddo), and the closest face of
//! a mesh.

pub(crate) mod closest_face;
pub(crate) mod morton;
pub(crate) mod neighbours;
