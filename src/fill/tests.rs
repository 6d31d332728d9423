use super::*;
use crate::geometry::predicates::{orient3d, Sign};
use crate::layers::{LAYER_ZONE_NAME, TOP_PATCH};
use crate::quality;
use crate::surface::shapes;

/// The "layered mesh" of a wall without layers: its points, no cells, no top faces.
fn bare_wall(wall: &Surface) -> VolumeMesh {
    let mut patch_names = wall.patch_names.clone();
    patch_names.push(TOP_PATCH.to_owned());
    VolumeMesh {
        points: wall.points.clone(),
        zone_names: vec![LAYER_ZONE_NAME.to_owned()],
        patch_names,
        ..Default::default()
    }
}

/// A surface as a boundary, every triangle marked as wall.
fn boundary_of(s: &Surface) -> ClosedBoundary {
    ClosedBoundary {
        points: s.points.clone(),
        triangles: s.triangles.clone(),
        markers: vec![MARKER_WALL; s.triangles.len()],
    }
}

#[test]
fn hole_points_lie_inside_bodies_only() {
    let cube = shapes::cuboid(DVec3::splat(1.0), 2);
    let boundary = boundary_of(&cube);
    let mut with_farfield = boundary.clone();
    let far = farfield::farfield(&FarfieldSpec::default(), cube.bounding_box()).unwrap();
    let offset = with_farfield.points.len() as u32;
    with_farfield.points.extend(far.points);
    with_farfield.triangles.extend(far.triangles.iter().map(|t| t.map(|v| v + offset)));
    with_farfield.markers.resize(with_farfield.triangles.len(), MARKER_FARFIELD);
    let holes = with_farfield.hole_points().unwrap();
    assert_eq!(holes.len(), 1);
    assert!(holes[0].cmpgt(DVec3::ZERO).all() && holes[0].cmplt(DVec3::ONE).all(), "{:?}", holes[0]);
    // The body shell facing inward bounds the region from outside: no hole.
    let mut inward = boundary.clone();
    inward.triangles.iter_mut().for_each(|t| t.swap(1, 2));
    assert!(inward.hole_points().unwrap().is_empty());
    // Alone, the body shell leaves the region unbounded.
    assert!(matches!(boundary.hole_points(), Err(FillError::Input(_))));
}

#[test]
fn sizing_is_the_mean_edge_length() {
    let cube = shapes::cuboid(DVec3::splat(2.0), 1);
    let boundary = boundary_of(&cube);
    let sizing = CoreGuide::mean_edge_length(&boundary);
    // Every edge is 2 or 2 sqrt(2) long; each corner's mean lies between.
    assert!(sizing.size.iter().all(|&s| s > 2.0 && s < 2.0 * 2f64.sqrt()), "{:?}", sizing.size);
}

#[test]
fn pyramid_apex_is_above_the_quad_and_lower_when_needed() {
    let square = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
    let apex = crate::layers::guard::pyramid_apex(square).unwrap();
    assert!((apex - DVec3::new(0.5, 0.5, 0.5)).length() < 1e-12, "{apex:?}");
    // A flat (zero-area) quad has no valid pyramid.
    let flat = [DVec3::ZERO, DVec3::X, DVec3::X, DVec3::ZERO];
    assert!(crate::layers::guard::pyramid_apex(flat).is_none());
}

#[test]
fn a_wall_that_is_not_the_meshes_is_rejected() {
    let cube = shapes::cuboid(DVec3::splat(1.0), 2);
    let mut other = cube.clone();
    other.points[0].x += 0.1;
    let r = fill_core(&bare_wall(&other), &cube, &CoreOptions::default());
    assert!(matches!(r, Err(FillError::WallMismatch(_))), "{r:?}");
}

/// A cube with no layers in a box farfield: the core alone, valid, its volume the box's minus
/// the cube's, and every wall triangle a face of exactly one tetrahedron.
#[cfg(feature = "tetgen")]
#[test]
fn cube_in_a_box_without_layers() {
    let wall = shapes::cuboid(DVec3::splat(1.0), 4);
    let options = CoreOptions {
        farfield: Some(FarfieldSpec { factor: 4.0, ..Default::default() }),
        ..Default::default()
    };
    let (mesh, stats) = fill_core(&bare_wall(&wall), &wall, &options).unwrap();
    let check = quality::check(&mesh);
    assert!(check.is_valid(), "{check}");
    let side = 4.0 * 3f64.sqrt();
    let expected = side.powi(3) - 1.0;
    assert!((check.volume.cells - expected).abs() < 1e-9 * expected, "{} vs {expected}", check.volume.cells);
    assert_eq!(stats.boundary_steiner_points, 0);
    assert_eq!(stats.pyramids, 0);
    assert!(stats.tetrahedra > 0 && stats.min_dihedral > 0.0);
    assert_eq!(mesh.patch_names, ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax", FARFIELD_PATCH]);
    assert_eq!(mesh.zone_names, [LAYER_ZONE_NAME, CORE_ZONE_NAME]);
    // Wall faces point into the body; the tetrahedron on each lies on the fluid side.
    for (t, [a, b, c]) in wall.triangles.iter().enumerate() {
        let on = mesh
            .block(crate::mesh::CellKind::Tetrahedron)
            .iter()
            .filter(|tet| [a, b, c].iter().all(|v| tet.contains(v)));
        let tets: Vec<&[u32]> = on.collect();
        assert_eq!(tets.len(), 1, "wall triangle {t}");
        let d = tets[0].iter().find(|v| ![a, b, c].contains(v)).unwrap();
        let p = |v: u32| mesh.points[v as usize];
        assert_eq!(orient3d(p(*a), p(*b), p(*c), p(*d)), Sign::Positive);
    }
    eprintln!("cube without layers: {stats:?}");
}

mod properties {
    use proptest::prelude::*;

    use super::*;
    use crate::mesh::CellKind;
    use crate::quality::validity::cell_validity;

    proptest! {
        /// Whatever the quad, a pyramid is only ever proposed valid.
        #[test]
        fn proposed_pyramids_are_valid(coords in proptest::collection::vec(-1.0f64..1.0, 12)) {
            let x: Vec<DVec3> = coords.chunks(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect();
            if let Some(apex) = crate::layers::guard::pyramid_apex([x[0], x[1], x[2], x[3]]) {
                let mut p = [DVec3::ZERO; 8];
                p[..4].copy_from_slice(&x);
                p[4] = apex;
                prop_assert!(cell_validity(CellKind::Pyramid, &p).is_valid());
            }
        }
    }

    #[cfg(feature = "tetgen")]
    proptest! {
        #![proptest_config(ProptestConfig { cases: 8, ..ProptestConfig::default() })]
        /// Boxes of any proportions, resolution and farfield: a valid mesh of the right volume.
        #[test]
        fn any_box_in_any_farfield_fills_validly(
            size in (0.05f64..20.0, 0.05f64..20.0, 0.05f64..20.0),
            n in 1usize..4,
            factor in 2.0f64..40.0,
            sphere in any::<bool>(),
        ) {
            let wall = shapes::cuboid(DVec3::new(size.0, size.1, size.2), n);
            let shape = if sphere { crate::config::FarfieldShape::Sphere } else { crate::config::FarfieldShape::Box };
            let spec = FarfieldSpec { shape, factor, cell_size: None };
            let options = CoreOptions { farfield: Some(spec), ..Default::default() };
            let (mesh, stats) = fill_core(&bare_wall(&wall), &wall, &options).unwrap();
            let check = quality::check(&mesh);
            prop_assert!(check.is_valid(), "{}", check);
            let far = farfield::farfield(&spec, wall.bounding_box()).unwrap();
            let expected = -far.enclosed_volume() - wall.enclosed_volume();
            prop_assert!((check.volume.cells - expected).abs() <= 1e-9 * expected);
            prop_assert_eq!(stats.boundary_steiner_points, 0);
        }
    }
}

#[test]
fn broken_boundaries_are_errors_not_crashes() {
    let cube = shapes::cuboid(DVec3::splat(1.0), 1);
    let good = boundary_of(&cube);
    good.check_structure().unwrap();
    let mut out_of_range = good.clone();
    out_of_range.triangles[3][1] = 99;
    let mut nan = good.clone();
    nan.points[2].y = f64::NAN;
    let mut flat = good.clone();
    flat.triangles[0] = [0, 1, 1];
    let mut unmarked = good.clone();
    unmarked.markers.pop();
    for broken in [out_of_range, nan, flat, unmarked] {
        assert!(matches!(broken.check_structure(), Err(FillError::Input(_))));
        assert!(broken.hole_points().is_err() && broken.check_no_self_intersection().is_err());
    }
    // A cube crossing another one is reported before any mesher sees it.
    let mut crossing = good.clone();
    let offset = crossing.points.len() as u32;
    crossing.points.extend(cube.points.iter().map(|p| *p + DVec3::splat(0.5)));
    crossing.triangles.extend(cube.triangles.iter().map(|t| t.map(|v| v + offset)));
    crossing.markers.resize(24, MARKER_FRONT);
    let e = crossing.check_no_self_intersection().unwrap_err();
    assert!(matches!(e, FillError::SelfIntersecting { .. }), "{e}");
}

/// A mesher that loses the boundary while a guide point stands near triangle 0 (as TetGen can
/// where seeds stand close to a front that nearly touches itself), else fills the single
/// tetrahedron the boundary is.
struct LosesTriangleNearSeeds {
    tet: [u32; 4],
    always: bool,
}

impl CoreMesher for LosesTriangleNearSeeds {
    fn fill(&self, boundary: &ClosedBoundary, guide: &CoreGuide) -> Result<CoreTets, FillError> {
        let [a, b, c] = boundary.triangles[0].map(|v| boundary.points[v as usize]);
        let centre = (a + b + c) / 3.0;
        let near = guide.interior.iter().any(|p| p.distance(centre) < 1.0);
        let points = [boundary.points.clone(), guide.interior.clone()].concat();
        let tets = if near || self.always { Vec::new() } else { vec![self.tet] };
        Ok(CoreTets { points, tets, boundary_steiner_points: 0 })
    }
}

/// The boundary of one tetrahedron, its triangles facing in, and the tetrahedron.
fn one_tetrahedron(size: f64) -> (ClosedBoundary, [u32; 4]) {
    let mut points = vec![DVec3::ZERO, DVec3::X * size, DVec3::Y * size, DVec3::Z * size];
    if orient3d(points[0], points[1], points[2], points[3]) != Sign::Positive {
        points.swap(1, 2);
    }
    let faces = [[0u32, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]];
    let inward = |[a, b, c]: [u32; 3]| {
        let d = (0..4).find(|v| ![a, b, c].contains(v)).unwrap();
        let p = |v: u32| points[v as usize];
        if orient3d(p(a), p(b), p(c), p(d)) == Sign::Positive {
            [a, b, c]
        } else {
            [a, c, b]
        }
    };
    let triangles: Vec<[u32; 3]> = faces.into_iter().map(inward).collect();
    let markers = vec![MARKER_WALL; triangles.len()];
    (ClosedBoundary { points, triangles, markers }, [0, 1, 2, 3])
}

#[test]
fn a_lost_boundary_triangle_is_retried_without_the_seeds_near_it() {
    let (boundary, tet) = one_tetrahedron(30.0);
    let [a, b, c] = boundary.triangles[0].map(|v| boundary.points[v as usize]);
    let seed = (a + b + c) / 3.0 + 0.01 * (DVec3::ONE);
    let mut guide = CoreGuide::mean_edge_length(&boundary);
    guide.interior = vec![seed];
    guide.size.push(1.0);
    let mesher = LosesTriangleNearSeeds { tet, always: false };
    let (tets, seeds_used) =
        fill_keeping_boundary(&mesher, &boundary, &mut guide.clone()).expect("the retry keeps it");
    assert_eq!((tets.tets.len(), seeds_used, tets.points.len()), (1, 0, 4));
    // A mesher that loses it whatever the seeds: an error, after the retries.
    let stubborn = LosesTriangleNearSeeds { tet, always: true };
    assert!(matches!(
        fill_keeping_boundary(&stubborn, &boundary, &mut guide),
        Err(FillError::BoundaryNotKept { triangle: 0, .. })
    ));
}

#[test]
fn seeds_still_in_place_come_first_after_the_boundary() {
    let (boundary, _) = one_tetrahedron(1.0);
    let seeds = [DVec3::splat(0.1), DVec3::splat(0.2), DVec3::splat(0.15)];
    let guide = CoreGuide { interior: seeds.to_vec(), ..Default::default() };
    // The mesher moved the first seed, added a point of its own first, and kept the others.
    let moved = DVec3::splat(0.11);
    let own = DVec3::new(0.2, 0.1, 0.1);
    let mut core = CoreTets {
        points: [boundary.points.clone(), vec![own, moved, seeds[2], seeds[1]]].concat(),
        tets: vec![[0, 1, 2, 4], [0, 1, 5, 6], [1, 2, 7, 4]],
        boundary_steiner_points: 0,
    };
    let before: Vec<[DVec3; 4]> = core.tets.iter().map(|t| t.map(|v| core.points[v as usize])).collect();
    assert_eq!(merge::seeds_in_place_first(&boundary, &guide, &mut core), 2);
    assert_eq!(&core.points[4..6], &[seeds[1], seeds[2]], "in the guide's order");
    assert_eq!(&core.points[..4], &boundary.points[..]);
    let after: Vec<[DVec3; 4]> = core.tets.iter().map(|t| t.map(|v| core.points[v as usize])).collect();
    assert_eq!(before, after, "the tetrahedra keep their corners");
    // The guide's last point only carries a size (a graded fill's): in place, it is no seed.
    let sizing = CoreGuide { sizing_points: 1, ..guide };
    assert_eq!(merge::seeds_in_place_first(&boundary, &sizing, &mut core), 1);
    assert_eq!(core.points[4], seeds[1]);
}

/// A mesher that crashes (as TetGen aborts on some seed sets) whenever it is given seeds, else
/// is TetGen; it counts its runs.
#[cfg(feature = "tetgen")]
struct CrashesOnSeeds {
    runs: std::cell::Cell<usize>,
}

#[cfg(feature = "tetgen")]
impl CoreMesher for CrashesOnSeeds {
    fn fill(&self, boundary: &ClosedBoundary, guide: &CoreGuide) -> Result<CoreTets, FillError> {
        self.runs.set(self.runs.get() + 1);
        if !guide.interior.is_empty() {
            return Err(FillError::TetGenCrashed { signal: 6 });
        }
        tetgen::TetGen::default().fill(boundary, guide)
    }
}

/// A cube (its faces the front, a last layer 0.1 under each) in a box farfield.
#[cfg(feature = "tetgen")]
#[test]
fn a_mesher_crashing_on_the_seeds_is_run_again_with_fewer_then_none() {
    let cube = shapes::cuboid(DVec3::splat(1.0), 4);
    let mut boundary = boundary_of(&cube);
    boundary.markers = vec![MARKER_FRONT; cube.triangles.len()];
    let far = farfield::farfield(&FarfieldSpec::default(), cube.bounding_box()).unwrap();
    let offset = boundary.points.len() as u32;
    boundary.points.extend(far.points);
    boundary.triangles.extend(far.triangles.iter().map(|t| t.map(|v| v + offset)));
    boundary.markers.resize(boundary.triangles.len(), MARKER_FARFIELD);
    let mut heights = vec![0.1; cube.triangles.len()];
    heights.resize(boundary.triangles.len(), f64::NAN);
    let front = FrontLayer { heights, steps: vec![DVec3::NAN; boundary.points.len()] };
    assert!(!CoreGuide::with_seeds(&boundary, &front).1.points.is_empty(), "there are seeds to crash on");
    let mesher = CrashesOnSeeds { runs: std::cell::Cell::new(0) };
    let SeededFill { tets, seeds_used: used, seeds, crashes, .. } =
        fill_with_seeds(&mesher, &boundary, &front, || front.clone()).expect("no seeds at last");
    assert_eq!((used, seeds.points.len(), mesher.runs.get(), crashes), (0, 0, 3, 2));
    assert!(seeds.candidates > 0, "the candidates are still reported");
    merge::check_boundary_kept(&boundary, &tets).expect("a whole fill");
}

/// The safety net under the front slides: a wall point moved by the improvement is an error
/// naming the node, not a mesh off its input surface.
#[test]
fn a_moved_mesh_boundary_point_is_an_error() {
    let cube = shapes::cuboid(DVec3::splat(1.0), 2);
    let core = front::core_boundary(&bare_wall(&cube), &cube).expect("a core boundary");
    let (boundary, nodes) = core.closed_boundary();
    let mut tets = CoreTets { points: boundary.points.clone(), ..Default::default() };
    merge::check_mesh_boundary_kept(&core, &nodes, &tets).expect("nothing moved");
    tets.points[3].z += 1e-3;
    let err = merge::check_mesh_boundary_kept(&core, &nodes, &tets).expect_err("a wall point moved");
    assert!(err.to_string().contains(&format!("node {}", nodes[3])), "{err}");
}

/// Points on a line, each edge to the next three (tetrahedra over four consecutive points):
/// the sizes grow from the fine end by the gradation along the path, up to the coarse end's size
/// or `max_size`.
#[test]
fn graded_sizes_grow_by_the_gradation_from_the_boundary() {
    let points: Vec<DVec3> = (0..41).map(|i| DVec3::new(i as f64 * 0.5, 0.0, 0.0)).collect();
    // Boundary points first: the fine end (size 0.1) and the coarse end (size 2).
    let order: Vec<usize> = [0, 40].into_iter().chain(1..40).collect();
    let core = CoreTets {
        points: order.iter().map(|&i| points[i]).collect(),
        tets: (0..38)
            .map(|i| [i, i + 1, i + 2, i + 3].map(|k| order.iter().position(|&o| o == k).unwrap() as u32))
            .collect(),
        boundary_steiner_points: 0,
    };
    let sizing = |gradation, max_size| grading::CoreSizing { gradation, max_size, regions: Vec::new() };
    let size = grading::graded_sizes(&core, &[0.1, 2.0], &sizing(1.2, None));
    for (p, s) in core.points.iter().zip(&size) {
        let expected = (0.1 + 0.2 * p.x).min(2.0 + 0.2 * (20.0 - p.x)).min(2.0);
        assert!((s - expected).abs() < 1e-12, "at x = {}: {s} vs {expected}", p.x);
    }
    let capped = grading::graded_sizes(&core, &[0.1, 2.0], &sizing(1.2, Some(1.0)));
    assert!(capped.iter().skip(2).all(|&s| s <= 1.0 + 1e-12), "{capped:?}");
    assert_eq!(capped[1], 2.0, "a boundary size stays as given");
    // A steeper gradation reaches the cap sooner.
    let steep = grading::graded_sizes(&core, &[0.1, 2.0], &sizing(1.5, None));
    assert!(steep.iter().zip(&size).all(|(a, b)| a >= b), "sizes only grow with the gradation");
}

/// A mesher that loses a boundary triangle on the second fill whatever it is given leaves the
/// first; one that loses it on a point near the boundary takes the retry without it.
#[test]
fn a_graded_fill_that_loses_the_boundary_keeps_the_first() {
    let (boundary, tet) = one_tetrahedron(30.0);
    let first = CoreTets { points: boundary.points.clone(), tets: vec![tet], boundary_steiner_points: 0 };
    let guide = CoreGuide::mean_edge_length(&boundary);
    let stubborn = LosesTriangleNearSeeds { tet, always: true };
    let sizing = grading::CoreSizing::default();
    let (tets, used, graded) =
        grading::fill_graded(&stubborn, &boundary, first.clone(), 0, guide.clone(), &sizing).unwrap();
    assert!(!graded.graded && used == 0 && tets.tets == first.tets);
    let fine = LosesTriangleNearSeeds { tet, always: false };
    let (tets, _, graded) =
        grading::fill_graded(&fine, &boundary, first.clone(), 0, guide.clone(), &sizing).unwrap();
    assert!(graded.graded);
    merge::check_boundary_kept(&boundary, &tets).expect("kept");
    // A point of the first fill close to triangle 0 makes the second lose it: the retry leaves
    // the points near the boundary out.
    let [a, b, c] = boundary.triangles[0].map(|v| boundary.points[v as usize]);
    let near = (a + b + c) / 3.0 + 0.5 * triangle_area_vector(a, b, c).normalize();
    let with_near = CoreTets { points: [first.points.clone(), vec![near]].concat(), ..first.clone() };
    let (tets, _, graded) =
        grading::fill_graded(&fine, &boundary, with_near, 0, guide.clone(), &sizing).unwrap();
    assert!(graded.graded, "the retry without the point takes");
    merge::check_boundary_kept(&boundary, &tets).expect("kept");
    // Sizes a thousand times finer than the tetrahedron (10^9 tetrahedra) are an error.
    let tiny = CoreGuide { size: vec![0.03; 4], ..guide };
    let e = grading::fill_graded(&fine, &boundary, first, 0, tiny, &sizing).unwrap_err();
    assert!(matches!(e, FillError::Options(_)) && e.to_string().contains("max_size"), "{e}");
}

/// The sizes of a regular tetrahedron's corners are alike; a second, twice as large on a face of
/// it, makes the edges between the two apart.
#[test]
fn size_ratios_across_edges_are_one_on_equal_cells_and_more_where_sizes_change() {
    let (boundary, tet) = one_tetrahedron(1.0);
    let regular = [
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(1.0, -1.0, -1.0),
        DVec3::new(-1.0, 1.0, -1.0),
        DVec3::new(-1.0, -1.0, 1.0),
    ];
    let one = grading::size_ratio_across_edges(&regular, &[[0, 1, 2, 3]], 1.2);
    assert_eq!((one.count, one.max, one.within_band), (6, 1.0, 1.0));
    let mut points = boundary.points.clone();
    points.push(DVec3::splat(-2.0));
    let two = grading::size_ratio_across_edges(&points, &[tet, [1, 2, 3, 4]], 1.2);
    assert_eq!(two.count, 9);
    assert!(two.max > 1.2 && two.within_band < 1.0, "{two:?}");
}
