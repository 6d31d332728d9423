//! Set-ups shared by several integration tests.

use blmesh::config::{Config, LayerCount, LayerSettings};
use blmesh::geometry::DVec3;
use blmesh::quality::CheckReport;
use blmesh::surface::{shapes, Surface};

/// A 2 x 1 x 1.5 box (3 divisions per edge) and 5 layers of h0 = 0.01, r = 1.2: its layers have
/// every cell kind (prisms, fans of hexahedra, pyramids and tetrahedra at the corners).
pub fn layered_box() -> (Surface, Config) {
    let surface = shapes::cuboid(DVec3::new(2.0, 1.0, 1.5), 3);
    let layers = LayerSettings {
        first_height: Some(0.01),
        growth: Some(1.2),
        count: Some(LayerCount::Fixed(5)),
        thickness: None,
        transition: Some(false),
        first_aspect: None,
    };
    (surface, Config { layers, ..Default::default() })
}

/// The invariants every produced mesh meets: valid for the checker, and nothing a finite-volume
/// solver would reject (no wrong face pyramid, no face at 90 degrees non-orthogonality or more).
#[allow(dead_code)] // not every test crate checks meshes
pub fn assert_valid_for_a_solver(name: &str, check: &CheckReport) {
    assert!(check.is_valid(), "{name}: {check}");
    if let Some(why) = check.fv.rejection() {
        panic!("{name}: {why}\n{}", check.fv);
    }
}
