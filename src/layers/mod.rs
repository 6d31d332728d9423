//! Layer marching: columns, the front, and the slab of cells between two fronts.

pub mod slab;
