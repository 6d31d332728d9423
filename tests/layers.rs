//! Boundary layers on smooth and convex walls: every mesh goes through the checker;
//! the box and the sphere must reach every layer everywhere, and their outermost layer must lie
//! on the exact offset surface (faces, cylinders at the ridges, spheres at the corners).

mod common;

use blmesh::config::{Config, LayerCount, LayerSettings};
use blmesh::geometry::distance::closest_point_on_triangle;
use blmesh::geometry::DVec3;
use blmesh::layers::TOP_PATCH;
use blmesh::mesh::VolumeMesh;
use blmesh::pipeline::{run, MeshOptions, MeshOutput};
use blmesh::progress::Progress;
use blmesh::surface::{shapes, Surface};

#[path = "common/shared.rs"]
mod shared;
use shared::shared_geometry;

const LAYERS: u32 = 20;
const GROWTH: f64 = 1.2;

/// 20 layers, h0 = 1e-4 of the bounding-box diagonal, r = 1.2 (the layer benchmark's set-up).
fn mesh_layers(surface: &Surface) -> (MeshOutput, f64) {
    let h0 = 1e-4 * surface.bounding_box().diagonal();
    let config = Config {
        layers: LayerSettings {
            first_height: Some(h0),
            growth: Some(GROWTH),
            count: Some(LayerCount::Fixed(LAYERS)),
            thickness: None,
            transition: Some(false),
            first_aspect: None,
        },
        ..Default::default()
    };
    let out = run(surface.clone(), &config, &MeshOptions { core: false }, Progress::hidden())
        .expect("meshing a valid surface succeeds");
    let thickness = h0 * (GROWTH.powi(LAYERS as i32) - 1.0) / (GROWTH - 1.0);
    (out, thickness)
}

/// Exact distance from `p` to the wall (brute force over the triangles).
fn wall_distance(surface: &Surface, p: DVec3) -> f64 {
    (0..surface.triangles.len())
        .map(|t| {
            let [a, b, c] = surface.triangle_points(t);
            (closest_point_on_triangle(p, a, b, c) - p).length()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Nodes of the top faces of the layers.
fn top_nodes(mesh: &VolumeMesh) -> Vec<u32> {
    let top = mesh.patch_names.iter().position(|n| n == TOP_PATCH).expect("a bl_top patch") as u32;
    let b = &mesh.boundary;
    let mut nodes: Vec<u32> = b
        .triangles
        .iter()
        .zip(&b.triangle_patch)
        .filter(|(_, &p)| p == top)
        .flat_map(|(t, _)| t.iter().copied())
        .chain(
            b.quads.iter().zip(&b.quad_patch).filter(|(_, &p)| p == top).flat_map(|(q, _)| q.iter().copied()),
        )
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

fn assert_full_and_on_offset(surface: &Surface, out: &MeshOutput, thickness: f64) {
    let r = &out.report;
    common::assert_valid_for_a_solver("assert_full_and_on_offset", &r.check);
    assert_eq!(r.layers.stopped_vertices, 0, "columns stopped early: {:?}", r.layers.stopped_examples);
    assert_eq!((r.layers.layers_min, r.layers.layers_max), (LAYERS, LAYERS));
    assert_eq!(r.layers.full_coverage, 1.0);
    let nodes = top_nodes(&out.mesh);
    assert!(!nodes.is_empty());
    let worst = nodes
        .iter()
        .map(|&n| (wall_distance(surface, out.mesh.points[n as usize]) - thickness).abs() / thickness)
        .fold(0.0, f64::max);
    assert!(worst < 0.01, "outermost layer off the exact offset by {:.3}% of the thickness", 100.0 * worst);
}

#[test]
fn box_gets_all_layers_with_fans_on_the_exact_offset() {
    let (a, b, c) = (2.0, 1.0, 1.5);
    let surface = shapes::cuboid(DVec3::new(a, b, c), 4);
    let (out, t) = mesh_layers(&surface);
    assert_full_and_on_offset(&surface, &out, t);
    let n = &out.report.normals;
    assert_eq!(n.fan_edges, 12 * 4, "every box edge is a fan edge");
    assert_eq!(n.corner_patches, 8);
    // Volume identity: the layers fill the Minkowski offset shell (faces + quarter cylinders +
    // sphere octants). Fans are chords of the cylinders and spheres: with steps of at most
    // 20 degrees they miss at most 1 - sin(20)/20deg = 2% of those curved parts' volume.
    let exact_faces = 2.0 * (a * b + b * c + c * a) * t;
    let exact_curved =
        std::f64::consts::PI * (a + b + c) * t * t + 4.0 / 3.0 * std::f64::consts::PI * t.powi(3);
    let v = out.report.check.volume.cells;
    let missing = exact_faces + exact_curved - v;
    assert!(missing >= -1e-12 * v, "more than the exact offset volume: {v}");
    assert!(missing <= 0.02 * exact_curved, "missing {missing} of {exact_curved} in the fans");
}

#[test]
fn sphere_gets_all_layers_on_the_exact_offset() {
    let surface = shapes::icosphere(1.0, 3);
    let (out, t) = mesh_layers(&surface);
    assert_full_and_on_offset(&surface, &out, t);
    assert_eq!(out.report.normals.fan_edges, 0, "a smooth sphere needs no fans");
    assert_eq!(out.report.cells.prisms, surface.triangles.len() * LAYERS as usize);
    // Volume identity: prisms over the polyhedral wall with every column at distance t from its
    // incident faces. On a sphere of radius R the shell volume is area * t * (1 + t/R + t^2/3R^2);
    // the polyhedral wall (edge turns ~9 degrees) may differ from that by at most 1%.
    let area: f64 =
        (0..surface.triangles.len()).map(|i| surface.triangle_area_vector(i).length() / 2.0).sum();
    let v = out.report.check.volume.cells;
    let sphere_shell = area * t * (1.0 + t + t * t / 3.0);
    assert!((v / sphere_shell - 1.0).abs() < 0.01, "shell volume {v} vs {sphere_shell}");
}

/// Real organic surfaces (mild concavity): the layers are valid and conforming everywhere;
/// columns may stop early near concave folds where the entropy collapse does not reach, so
/// the coverage is reported, and most of the wall must get the full stack.
#[test]
fn spot_and_bunny_layers_are_valid() {
    for (name, min_coverage) in [("spot.obj", 0.8), ("bunny_closed_herholz.off", 0.8)] {
        let surface = blmesh::io::read_surface(&shared_geometry(name)).unwrap();
        let (out, _) = mesh_layers(&surface);
        let r = &out.report;
        common::assert_valid_for_a_solver(name, &r.check);
        assert_eq!(r.layers.layers_max, LAYERS);
        assert!(r.layers.full_coverage >= min_coverage, "{name}: coverage {}", r.layers.full_coverage);
        // Their many short convex ridges end on smooth wall: the fans there keep their layers
        // (26% of the convex ridge vertices got full stacks when a ridge end's fan triangles
        // had no standard shape in the first layer and stopped, with the fans along the ridge).
        let convex = r.layers.convex_coverage;
        assert!(convex >= 0.7, "{name}: full stacks at {convex} of the convex ridge vertices");
        eprintln!(
            "{name}: {} prisms, {} pyramids, {} tets, {} hexes; full stack at {:.2}% of wall vertices ({:.2}% convex)",
            r.cells.prisms,
            r.cells.pyramids,
            r.cells.tetrahedra,
            r.cells.hexahedra,
            100.0 * r.layers.full_coverage,
            100.0 * convex
        );
    }
}

/// `count = "auto"`: every column of the box and the sphere ends its stack where its
/// next layer would be as high as the front is wide (or the wall, where a convex front widens
/// faster than the layers grow), the mesh passes the checker, every wall vertex completes its
/// stack, and the stacks end smoothly: neighbouring thicknesses within two growth ratios.
#[test]
fn auto_count_stops_at_isotropy_smoothly() {
    for surface in [shapes::cuboid(DVec3::new(2.0, 1.5, 1.0), 6), shapes::icosphere(1.0, 3)] {
        let config = Config {
            layers: LayerSettings {
                first_height: Some(1e-3 * surface.bounding_box().diagonal()),
                growth: Some(GROWTH),
                count: Some(LayerCount::Auto),
                thickness: None,
                transition: None,
                first_aspect: None,
            },
            ..Default::default()
        };
        let out = run(surface.clone(), &config, &MeshOptions { core: false }, Progress::hidden())
            .expect("meshing a valid surface succeeds");
        common::assert_valid_for_a_solver("auto_count_stops_at_isotropy_smoothly", &out.report.check);
        let layers = &out.report.layers;
        assert_eq!(layers.full_coverage, 1.0, "every stack ends at isotropy, none early");
        let s = &layers.smoothness;
        assert!(s.isotropy_ratio.count > 0);
        // The last layer is lower than the size that ended the stack, and not by more than r.
        assert!(s.isotropy_ratio.max < 1.0 && s.isotropy_ratio.median > 0.3, "{:?}", s.isotropy_ratio);
        assert!(s.neighbour_thickness_ratio.max <= GROWTH * GROWTH, "{:?}", s.neighbour_thickness_ratio);
        assert_eq!(s.layer_height_ratio.within_band, 1.0, "{:?}", s.layer_height_ratio);
    }
}

/// Transition layers (the default): after a fixed count of thin layers, the stacks of
/// the box and the sphere go on growing until their cells are isotropic, as with
/// `count = "auto"`; every stack counts as full once it has the count, and the last layers end
/// within the growth ratio of the front's size. Without them, the stacks end at the count.
#[test]
fn transition_layers_carry_a_fixed_count_to_isotropy() {
    for surface in [shapes::cuboid(DVec3::new(2.0, 1.5, 1.0), 6), shapes::icosphere(1.0, 3)] {
        let settings = |transition| LayerSettings {
            first_height: Some(1e-3 * surface.bounding_box().diagonal()),
            growth: Some(GROWTH),
            count: Some(LayerCount::Fixed(5)),
            thickness: None,
            transition,
            first_aspect: None,
        };
        let mesh = |transition| {
            let config = Config { layers: settings(transition), ..Default::default() };
            run(surface.clone(), &config, &MeshOptions { core: false }, Progress::hidden())
                .expect("meshing a valid surface succeeds")
        };
        let (with, without) = (mesh(None), mesh(Some(false)));
        for out in [&with, &without] {
            common::assert_valid_for_a_solver(
                "transition_layers_carry_a_fixed_count_to_isotropy",
                &out.report.check,
            );
            assert_eq!(out.report.layers.full_coverage, 1.0);
            assert!(out.report.layers.layers_min >= 5);
        }
        assert_eq!(without.report.layers.layers_max, 5);
        let layers = &with.report.layers;
        assert!(layers.layers_median > 10, "{} layers", layers.layers_median);
        let iso = &layers.smoothness.isotropy_ratio;
        assert!(iso.count > 0 && iso.max < 1.0 && iso.median > 1.0 / GROWTH, "{iso:?}");
        assert_eq!(layers.smoothness.layer_height_ratio.within_band, 1.0);
    }
}

/// Patch-wise layer settings: the arrow's fins get a first height 4 times smaller than
/// the body, its cap 2 times. The first heights are graded across the patch borders, so
/// neighbouring stacks differ by at most one growth ratio (measured over all wall edges, apart
/// from the few columns that stop early).
#[test]
fn patch_settings_meet_without_steps() {
    let surface = blmesh::io::read_surface(&shared_geometry("arrow_cape.stl")).expect("the arrow reads");
    let config = Config::from_toml_str(
        "[layers]\nfirst_height = 0.01\ncount = 10\ntransition = false\n\
         [[patch]]\nmatch = \"fin.*\"\nfirst_height = 0.0025\n\
         [[patch]]\nmatch = \"cap\"\nfirst_height = 0.005\n",
    )
    .expect("a valid config");
    let out =
        run(surface, &config, &MeshOptions { core: false }, Progress::hidden()).expect("meshing succeeds");
    common::assert_valid_for_a_solver("patch_settings_meet_without_steps", &out.report.check);
    let ratio = &out.report.layers.smoothness.neighbour_thickness_ratio;
    // Thickness is measured as the distance from the wall vertex to its top node, which curved
    // fronts bend by a little: 1% slack. Without the grading p95 is 2.0 (the cap against the body).
    assert!(ratio.p95 <= GROWTH * 1.01, "{ratio:?}");
    // At the patch borders themselves (edges with an end on one), where the settings meet: within
    // one growth ratio at 90% and more (the rest where columns stop at the fin-body junction).
    let border = &out.report.layers.smoothness.patch_border_thickness_ratio;
    assert!(border.count > 1000 && border.within_band >= 0.9, "{border:?}");
    assert!(out.report.layers.full_coverage >= 0.95, "{}", out.report.layers.full_coverage);
}

/// `first_aspect` (default 2) lowers the first height only where stacks stop short under a
/// first layer too tall for the wall's facets: a box faceted at 0.17-0.33 under a first height
/// of 0.15 stands everywhere, so it keeps the height asked.
#[test]
fn a_first_layer_taller_than_half_the_walls_edges_stays_where_its_stacks_stand() {
    let surface = shapes::cuboid(DVec3::new(2.0, 1.5, 1.0), 6);
    let config = Config::from_toml_str("[layers]\nfirst_height = 0.15\ncount = 3\ntransition = false\n")
        .expect("a valid config");
    let out =
        run(surface, &config, &MeshOptions { core: false }, Progress::hidden()).expect("the box meshes");
    common::assert_valid_for_a_solver(
        "a_first_layer_taller_than_half_the_walls_edges_stays_where_its_stacks_stand",
        &out.report.check,
    );
    assert_eq!(out.report.layers.full_coverage, 1.0);
    assert_eq!(out.report.layers.lowered_first_height_vertices, 0);
    assert_eq!(out.report.layers.lowest_first_height_ratio, 1.0);
}
