//! blmesh: boundary-layer volume meshes for CFD.
//!
//! The crate follows the pipeline of `docs/design.md`, one module per stage, data flowing one way:
//!
//! ```text
//! io (read surface) -> surface::validate -> surface::features -> normals -> sizing
//!    -> layers -> fill -> quality (check) -> io (write mesh + report)
//! ```
//!
//! Shared vocabulary lives in [`geometry`] (points, exact predicates), [`surface`] (the input
//! triangle surface with named patches) and [`mesh`] (the hybrid volume mesh and its node orders).

pub mod api;
pub mod cli;
pub mod config;
pub mod fill;
#[cfg(unix)]
pub mod fuzz;
pub mod geometry;
pub mod interrupt;
pub mod io;
pub mod layers;
pub mod limits;
pub mod mesh;
pub mod normals;
pub mod picture;
pub mod pipeline;
pub mod progress;
pub mod quality;
pub mod sizing;
pub mod surface;
pub mod yplus;

/// The shared test data, found the one way the integration tests find it.
#[cfg(test)]
#[path = "../tests/common/shared.rs"]
mod test_shared;
