//! The native core mesher (`[core] mesher = "native"`) through the whole pipeline,
//! with or without TetGen in the build: the mesh passes the checker, its cells fill the
//! farfield box minus the body, and no point is added on the front.

use blmesh::config::{Config, CoreMesherChoice, LayerCount};
use blmesh::fill::DEFAULT_FARFIELD_FACTOR;
use blmesh::geometry::DVec3;
use blmesh::pipeline::{run, MeshOptions};
use blmesh::progress::Progress;
use blmesh::quality;
use blmesh::surface::{shapes, Surface};

/// Mesh `surface` with 3 layers (h0 = 1e-3 of its diagonal) and the native core, and check it.
fn mesh_natively(name: &str, surface: Surface) {
    let diagonal = surface.bounding_box().diagonal();
    let mut config = Config::default();
    config.layers.first_height = Some(1e-3 * diagonal);
    config.layers.count = Some(LayerCount::Fixed(3));
    config.peel_rounds = Some(0);
    config.core.mesher = Some(CoreMesherChoice::Native);
    let out = run(surface.clone(), &config, &MeshOptions { core: true }, Progress::hidden())
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    let check = quality::check(&out.mesh);
    assert!(check.is_valid(), "{name}: {check}");
    let expected = (DEFAULT_FARFIELD_FACTOR * diagonal).powi(3) - surface.enclosed_volume();
    let volume = check.volume.cells;
    assert!((volume - expected).abs() <= 1e-9 * expected, "{name}: volume {volume} vs {expected}");
    let core = out.report.core.expect("a core");
    assert_eq!(core.boundary_steiner_points, 0, "{name}");
    eprintln!("{name}: {} core tetrahedra, mesher {:.3} s", core.tetrahedra, core.mesher_seconds);
}

#[test]
fn box_meshes_natively() {
    mesh_natively("box", shapes::cuboid(DVec3::new(2.0, 1.0, 1.5), 2));
}

#[test]
fn sphere_meshes_natively() {
    mesh_natively("sphere", shapes::icosphere(1.0, 2));
}
