//! Extrusion directions at wall vertices: one "most normal" direction where it serves,
//! fans of normals at convex ridges and corners.

pub mod most_normal;

pub use most_normal::{most_normal, MostNormal};
