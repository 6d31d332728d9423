//! Pictures of a real boundary-layer mesh: a box's layers cut half-way up its vertical edge
//! x = y = 0, where a fan of prisms lying on their side, then hexahedra, turns the layers by 90
//! degrees. `cargo test --release --test pictures -- --ignored` renders the pictures of `docs/`.

use std::time::Instant;

use blmesh::config::{Config, LayerCount, LayerSettings};
use blmesh::geometry::DVec3;
use blmesh::mesh::{CellKind, VolumeMesh};
use blmesh::picture::{
    cut_picture, histogram_picture, kind_colour, scaled_jacobians, write_png, Colouring, CutPlane, Pixmap,
    View,
};
use blmesh::pipeline::{run, MeshOptions};
use blmesh::progress::Progress;
use blmesh::quality::samples::{cube_grid, CubeSplit};
use blmesh::surface::shapes;

/// 10 layers from h0 = 0.01 at r = 1.2 (0.26 thick) around the box [0, 2] x [0, 1] x [0, 1.5].
fn box_layers() -> VolumeMesh {
    let config = Config {
        layers: LayerSettings {
            first_height: Some(0.01),
            growth: Some(1.2),
            count: Some(LayerCount::Fixed(10)),
            thickness: None,
            transition: Some(false),
            first_aspect: None,
        },
        ..Default::default()
    };
    let surface = shapes::cuboid(DVec3::new(2.0, 1.0, 1.5), 4);
    run(surface, &config, &MeshOptions { core: false }, Progress::hidden()).expect("the box meshes").mesh
}

/// Half-way up the vertical edge, between two rows of wall nodes (z = 0.75 holds a row).
const CORNER_PLANE: CutPlane = CutPlane { origin: DVec3::new(0.0, 0.0, 0.7), normal: DVec3::Z };
/// The layers around the corner (x, y) = (0, 0): (u, v) = (x, y) on this plane.
const CORNER_VIEW: View = View { centre: DVec3::new(-0.08, -0.08, 0.7), half_width: 0.25 };
const SIDE: u32 = 800;

/// The colour at (x, y) of a picture of `view` on the plane z = const.
fn colour_at(picture: &Pixmap, view: &View, x: f64, y: f64) -> [u8; 3] {
    let scale = f64::from(SIDE) / (2.0 * view.half_width);
    let px = 0.5 * f64::from(SIDE) + (x - view.centre.x) * scale;
    let py = 0.5 * f64::from(SIDE) - (y - view.centre.y) * scale;
    let p = picture.pixel(px as u32, py as u32).expect("inside the picture");
    [p.red(), p.green(), p.blue()]
}

#[test]
fn the_corner_cut_shows_prisms_along_the_walls_and_the_fan() {
    let mesh = box_layers();
    let picture = cut_picture(&mesh, &CORNER_PLANE, &CORNER_VIEW, Colouring::Kind, SIDE, SIDE);
    let at = |x, y| colour_at(&picture, &CORNER_VIEW, x, y);
    assert_eq!(at(0.1, 0.1), [255, 255, 255], "inside the box: no cell");
    assert_eq!(at(0.1, -0.3), [255, 255, 255], "beyond the layers");
    // Layer k spans distances 0.01 (1.2^k - 1) / 0.2 from the wall: the middle of layer 7.
    let d = 0.025 * (1.2f64.powi(7) + 1.2f64.powi(8) - 2.0);
    assert_eq!(at(0.15, -d), kind_colour(CellKind::Prism), "layers on the face y = 0");
    assert_eq!(at(-d, 0.15), kind_colour(CellKind::Prism), "layers on the face x = 0");
    assert_eq!(at(-0.7 * d, -0.7 * d), kind_colour(CellKind::Hexahedron), "the fan above its first layer");
    assert_eq!(at(0.15, 0.0), [0, 0, 0], "the wall");
}

#[test]
#[ignore = "writes docs/*.png; run with --release"]
fn render_docs_pictures() {
    let mesh = box_layers();
    let docs = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/");
    let zoom = View::around(DVec3::new(-0.01, -0.01, 0.7), 0.025);
    for (view, colouring, name) in [
        (CORNER_VIEW, Colouring::Kind, "box_corner_fan.png"),
        (CORNER_VIEW, Colouring::Quality, "box_corner_quality.png"),
        (zoom, Colouring::Kind, "box_corner_fan_zoom.png"),
    ] {
        let picture = cut_picture(&mesh, &CORNER_PLANE, &view, colouring, SIDE, SIDE);
        write_png(&picture, format!("{docs}{name}").as_ref()).expect("docs/ is writable");
    }
    let quality = scaled_jacobians(&mesh);
    let histogram = histogram_picture(&quality, 40, (0.0, 1.0), 600, 300);
    write_png(&histogram, format!("{docs}box_quality_histogram.png").as_ref()).expect("docs/ is writable");
}

#[test]
#[ignore = "timing; run with --release"]
fn a_million_cells_draw_in_seconds() {
    let mesh = cube_grid([100, 100, 100], DVec3::splat(0.01), &|_| CubeSplit::Hexahedron, &|_| 0);
    for (colouring, plane) in [
        (Colouring::Kind, CutPlane { origin: DVec3::splat(0.5), normal: DVec3::Z }),
        (Colouring::Quality, CutPlane { origin: DVec3::splat(0.5), normal: DVec3::new(1.0, 2.0, 3.0) }),
    ] {
        let start = Instant::now();
        let view = View::fit(&mesh, &plane);
        let picture = cut_picture(&mesh, &plane, &view, colouring, 1600, 1600);
        let seconds = start.elapsed().as_secs_f64();
        println!("{} cells, {colouring:?}: {seconds:.2} s", mesh.cell_count());
        assert!(picture.pixels().iter().any(|p| p.red() != 255));
        assert!(seconds < 5.0);
    }
}
