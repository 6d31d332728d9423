//! Extrusion directions at wall vertices: one "most normal" direction where it serves,
//! fans of normals at convex ridges and corners.

pub mod constraint;
pub mod fans;
pub mod most_normal;

pub use fans::{wall_normals, wall_normals_of_layered, ColumnSeed, FanFace, NormalStats, WallNormals};
pub use most_normal::{most_normal, MostNormal};
