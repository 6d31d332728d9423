use proptest::prelude::*;

use super::*;
use crate::geometry::DVec3;
use crate::mesh::{CellKind, VolumeMesh};
use crate::quality::samples::{cube_grid, hybrid_column, CubeSplit};

const WHITE: [u8; 3] = [255, 255, 255];

fn rgb(pixmap: &Pixmap, x: u32, y: u32) -> [u8; 3] {
    let p = pixmap.pixel(x, y).expect("pixel inside the picture");
    [p.red(), p.green(), p.blue()]
}

fn count(pixmap: &Pixmap, keep: impl Fn([u8; 3]) -> bool) -> usize {
    pixmap.pixels().iter().filter(|p| keep([p.red(), p.green(), p.blue()])).count()
}

fn drawn(pixmap: &Pixmap) -> usize {
    count(pixmap, |c| c != WHITE)
}

/// The unit cube as 2 x 2 x 2 cubes cut as `split`.
fn unit_cube(split: CubeSplit) -> VolumeMesh {
    cube_grid([2, 2, 2], DVec3::splat(0.5), &|_| split, &|_| 0)
}

fn horizontal(z: f64) -> CutPlane {
    CutPlane { origin: DVec3::new(0.0, 0.0, z), normal: DVec3::Z }
}

/// The pixel of plane coordinates (u, v) in a `side` x `side` picture of `view` (u, v measured
/// from the view centre's projection).
fn pixel(view: &View, side: u32, (u, v): (f64, f64)) -> (u32, u32) {
    let scale = f64::from(side) / (2.0 * view.half_width);
    let half = 0.5 * f64::from(side);
    ((half + u * scale) as u32, (half - v * scale) as u32)
}

#[test]
fn unit_cube_cut_is_a_square_of_the_right_area() {
    let view = View::around(DVec3::splat(0.5), 1.0);
    let square = 100.0 * 100.0; // 200 pixels for 2 units
    for split in CubeSplit::ALL {
        let mesh = unit_cube(split);
        // z = 0.5 runs through nodes and faces (the symbolic shift), z = 0.3 through cells.
        for z in [0.5, 0.3, 1.0, 1e-9] {
            let picture = cut_picture(&mesh, &horizontal(z), &view, Colouring::Kind, 200, 200);
            let n = drawn(&picture) as f64;
            // The walls' 2.5-pixel strokes reach 1.25 pixels out of the square, anti-aliased.
            assert!(n > square * 0.99 && n <= 104.0 * 104.0, "{split:?} z = {z}: {n} pixels drawn");
            assert_eq!(rgb(&picture, 20, 20), WHITE);
            assert_eq!(rgb(&picture, 180, 100), WHITE);
        }
    }
    let mesh = unit_cube(CubeSplit::Hexahedron);
    let picture = cut_picture(&mesh, &horizontal(0.3), &view, Colouring::Kind, 200, 200);
    assert_eq!(rgb(&picture, 75, 75), kind_colour(CellKind::Hexahedron));
    assert_eq!(rgb(&picture, 50, 100), [0, 0, 0], "the wall is black");
    let grey = rgb(&picture, 100, 75);
    assert!(grey != kind_colour(CellKind::Hexahedron) && grey[0] < 200, "an inner face is stroked: {grey:?}");
}

#[test]
fn a_face_in_the_plane_is_not_drawn_over_by_the_cell_above() {
    // Prisms below z = 1, tetrahedra above: z = 1 is the shared face, drawn by the cell below.
    let mesh =
        cube_grid([1, 1, 2], DVec3::ONE, &|c| [CubeSplit::Prisms, CubeSplit::Tetrahedra][c[2]], &|_| 0);
    let view = View::around(DVec3::new(0.5, 0.5, 1.0), 1.0);
    let picture = cut_picture(&mesh, &horizontal(1.0), &view, Colouring::Kind, 200, 200);
    assert_eq!(rgb(&picture, 130, 80), kind_colour(CellKind::Prism));
    assert_eq!(count(&picture, |c| c == kind_colour(CellKind::Tetrahedron)), 0);
}

#[test]
fn a_plane_missing_the_mesh_gives_a_blank_picture() {
    let mesh = unit_cube(CubeSplit::Centre);
    let view = View::around(DVec3::splat(0.5), 1.0);
    let blank = |plane: &CutPlane, view: &View| {
        let picture = cut_picture(&mesh, plane, view, Colouring::Quality, 64, 48);
        assert_eq!((picture.width(), picture.height()), (64, 48));
        assert_eq!(drawn(&picture), 0, "{plane:?} {view:?}");
    };
    blank(&horizontal(1.5), &view);
    blank(&horizontal(-1e-9), &view);
    blank(&CutPlane { origin: DVec3::ZERO, normal: DVec3::ZERO }, &view);
    blank(&horizontal(0.5), &View::around(DVec3::splat(5.0), 1.0));
    blank(&horizontal(0.5), &View::around(DVec3::splat(0.5), 0.0));
    blank(&horizontal(0.5), &View::around(DVec3::splat(f64::NAN), 1.0));
}

#[test]
fn every_kind_of_the_hybrid_column_shows_in_its_colour() {
    let mesh = hybrid_column();
    let plane = CutPlane { origin: DVec3::new(0.5, 0.0, 0.0), normal: DVec3::X };
    let view = View::fit(&mesh, &plane);
    assert!((view.centre - DVec3::new(0.5, 0.5, 2.0)).length() < 1e-12, "{view:?}");
    assert!((view.half_width - 2.1).abs() < 1e-12);
    let picture = cut_picture(&mesh, &plane, &view, Colouring::Kind, 400, 400);
    // The plane x = 0.5 has u = y and v = z.
    let at = |y: f64, z: f64| {
        let (px, py) = pixel(&view, 400, (y - 0.5, z - 2.0));
        rgb(&picture, px, py)
    };
    assert_eq!(at(0.25, 0.5), kind_colour(CellKind::Hexahedron));
    assert_eq!(at(0.5, 1.1), kind_colour(CellKind::Pyramid));
    assert_eq!(at(0.25, 2.5), kind_colour(CellKind::Prism));
    assert_eq!(at(0.6, 3.3), kind_colour(CellKind::Tetrahedron));
}

#[test]
fn a_prism_layer_under_tetrahedra_shows_both_colours_in_proportion() {
    let split = |c: [usize; 3]| if c[2] == 0 { CubeSplit::Prisms } else { CubeSplit::Tetrahedra };
    let mesh = cube_grid([3, 3, 3], DVec3::splat(1.0 / 3.0), &split, &|_| 0);
    let plane = CutPlane { origin: DVec3::splat(0.4), normal: DVec3::Y };
    let picture = cut_picture(&mesh, &plane, &View::fit(&mesh, &plane), Colouring::Kind, 300, 300);
    let prisms = count(&picture, |c| c == kind_colour(CellKind::Prism)) as f64;
    let tets = count(&picture, |c| c == kind_colour(CellKind::Tetrahedron)) as f64;
    assert!(prisms > 5000.0, "{prisms} prism pixels");
    assert!((tets / prisms - 2.0).abs() < 0.25, "tets {tets} / prisms {prisms}: the layer is a third");
}

#[test]
fn quality_colouring_follows_the_scaled_jacobian() {
    let view = View::around(DVec3::splat(0.5), 1.0);
    let cubes = unit_cube(CubeSplit::Hexahedron);
    let picture = cut_picture(&cubes, &horizontal(0.3), &view, Colouring::Quality, 200, 200);
    assert_eq!(rgb(&picture, 75, 75), quality_colour(1.0));
    let mut sheared = cubes.clone();
    for p in &mut sheared.points {
        p.x += 0.9 * p.z; // every corner angle drops: scaled Jacobian 1/sqrt(1 + 0.81)
    }
    let view = View::around(DVec3::new(0.5 + 0.9 * 0.3, 0.5, 0.3), 1.0);
    let picture = cut_picture(&sheared, &horizontal(0.3), &view, Colouring::Quality, 200, 200);
    assert_eq!(rgb(&picture, 75, 75), quality_colour(1.0 / 1.81f64.sqrt()));
    assert_ne!(quality_colour(1.0 / 1.81f64.sqrt()), quality_colour(1.0));
}

#[test]
fn fit_frames_the_cut() {
    let mesh = unit_cube(CubeSplit::Tetrahedra);
    let view = View::fit(&mesh, &horizontal(0.5));
    assert!((view.centre - DVec3::splat(0.5)).length() < 1e-12, "{view:?}");
    assert!((view.half_width - 0.525).abs() < 1e-12);
    // Missing plane: the whole mesh's projection.
    let view = View::fit(&mesh, &horizontal(3.0));
    assert!((view.centre - DVec3::new(0.5, 0.5, 3.0)).length() < 1e-12, "{view:?}");
    assert_eq!(View::fit(&VolumeMesh::default(), &horizontal(0.0)).half_width, 1.0);
}

#[test]
fn bad_meshes_do_not_panic() {
    let mut mesh = unit_cube(CubeSplit::Centre);
    mesh.points[3] = DVec3::new(f64::NAN, 0.0, 0.5);
    mesh.push_cell(CellKind::Tetrahedron, &[0, 1, 2, 999_999], 0);
    mesh.boundary.triangles.push([0, 1, u32::MAX]);
    mesh.boundary.triangle_patch.push(77);
    let view = View::fit(&mesh, &horizontal(0.5));
    let picture = cut_picture(&mesh, &horizontal(0.5), &view, Colouring::Quality, 0, 100_000);
    assert_eq!((picture.width(), picture.height()), (1, 8192));
    assert!(drawn(&cut_picture(&mesh, &horizontal(0.5), &view, Colouring::Kind, 100, 100)) > 1000);
}

#[test]
fn write_png_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cut.png");
    let mesh = hybrid_column();
    let plane = CutPlane { origin: DVec3::splat(0.5), normal: DVec3::new(1.0, 1.0, 0.0) };
    let picture = cut_picture(&mesh, &plane, &View::fit(&mesh, &plane), Colouring::Kind, 120, 90);
    write_png(&picture, &path).unwrap();
    let back = Pixmap::load_png(&path).unwrap();
    assert_eq!(back.data(), picture.data());
    assert!(write_png(&picture, &dir.path().join("missing/cut.png")).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// A tilted plane through the middle of the unit cube (a, b small: it leaves through the four
    /// vertical sides) cuts a parallelogram of area |n| / n_z whatever the cells.
    #[test]
    fn tilted_cuts_have_the_exact_area(a in -0.4f64..0.4, b in -0.4f64..0.4, split in 0usize..4) {
        let mesh = unit_cube(CubeSplit::ALL[split]);
        let normal = DVec3::new(a, b, 1.0);
        let plane = CutPlane { origin: DVec3::splat(0.5), normal };
        let picture = cut_picture(&mesh, &plane, &View::around(DVec3::splat(0.5), 1.2), Colouring::Kind, 400, 400);
        let scale = 400.0 / 2.4;
        let area = scale * scale * normal.length() / normal.z;
        // Anti-aliased wall strokes reach up to 2 pixels out along the perimeter.
        let perimeter = 2.0 * scale * ((1.0 + a * a).sqrt() + (1.0 + b * b).sqrt());
        let n = drawn(&picture) as f64;
        prop_assert!(n > 0.99 * area && n < area + 2.0 * perimeter + 16.0, "{n} pixels, area {area}");
    }
}
