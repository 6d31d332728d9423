use proptest::prelude::*;

use super::*;
use crate::fill::recover::tests::{check, region};
use crate::fill::recover::NativeCore;
use crate::fill::{ClosedBoundary, CoreGuide, CoreTets};
use crate::mesh::sorted_edge;
use crate::surface::shapes;

/// Fill `boundary` natively, refined to `size` (a function of place) at its points, and
/// check the fill's invariants (boundary kept, no added point on it, every tetrahedron
/// positive, the volume enclosed).
fn refined(boundary: &ClosedBoundary, size: impl Fn(DVec3) -> f64) -> (CoreTets, RefineStats) {
    let guide = CoreGuide { size: boundary.points.iter().map(|&p| size(p)).collect(), ..Default::default() };
    let (core, stats) = NativeCore::default().fill_refined(boundary, &guide).unwrap();
    eprintln!("{} points, {} tetrahedra: {stats:?}", core.points.len(), core.tets.len());
    check(boundary, &core);
    (core, stats)
}

/// The edges of `core` with both ends added (off the boundary's `n` points), each once.
fn interior_edges(core: &CoreTets, n: usize) -> Vec<[u32; 2]> {
    let mut edges: Vec<[u32; 2]> = core
        .tets
        .iter()
        .flat_map(|t| TET_EDGES.map(|(i, j)| sorted_edge(t[i], t[j])))
        .filter(|e| e.iter().all(|&v| v as usize >= n))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges
}

/// The value below which a share `q` of `values` lie.
fn quantile(mut values: Vec<f64>, q: f64) -> f64 {
    values.sort_by(f64::total_cmp);
    values[((values.len() - 1) as f64 * q) as usize]
}

#[test]
fn a_cube_refined_to_a_size_small_near_one_corner_is_graded() {
    // Boundary edges and sizes of 1, and one sizing point of size 0.1 near a corner.
    let boundary = region(&shapes::cuboid(DVec3::splat(8.0), 8), &[]);
    let small = DVec3::splat(2.0);
    let mut size = vec![1.0; boundary.points.len()];
    size.push(0.1);
    let guide = CoreGuide { interior: vec![small], size, sizing_points: 1 };
    let (core, stats) = NativeCore::default().fill_refined(&boundary, &guide).unwrap();
    eprintln!("{} points, {} tetrahedra: {stats:?}", core.points.len(), core.tets.len());
    check(&boundary, &core);
    assert!(!stats.point_limit && stats.for_size > 0, "{stats:?}");
    let edges = interior_edges(&core, boundary.points.len());
    let x = |v: u32| core.points[v as usize];
    let lengths_near = |centre: DVec3, reach: f64| -> Vec<f64> {
        let near = |&&[a, b]: &&[u32; 2]| ((x(a) + x(b)) / 2.0).distance(centre) < reach;
        edges.iter().filter(near).map(|&[a, b]| x(a).distance(x(b))).collect()
    };
    // Circumradii at most 1.2 times the smallest size at the corners would make edges of at
    // most 2.4 sizes; points no nearer than half the size interpolated there stop short.
    let v = core.points.iter().position(|&p| p == small).unwrap() as u32;
    let at_small =
        edges.iter().filter(|e| e.contains(&v)).map(|&[a, b]| x(a).distance(x(b))).fold(0.0, f64::max);
    let mid = quantile(lengths_near(small, 1.0), 0.5);
    let far = quantile(lengths_near(DVec3::splat(5.0), 1.0), 0.5);
    eprintln!("longest edge at the small size {at_small:.3}, median within 1 {mid:.3}, far {far:.3}");
    assert!(at_small <= 5.0 * 0.1, "{at_small}");
    assert!(
        mid < 0.5 * far && (0.3..=2.4).contains(&far),
        "median edges near the small size {mid}, far {far}"
    );
}

#[test]
fn graded_sizes_refine_farther_from_a_small_size() {
    // As above; graded by 1.2, the sizes away from the small one grow by 0.2 per unit length
    // at most, where interpolated they reach the boundary's 1 over 2 units.
    let boundary = region(&shapes::cuboid(DVec3::splat(8.0), 8), &[]);
    let mut size = vec![1.0; boundary.points.len()];
    size.push(0.1);
    let guide = CoreGuide { interior: vec![DVec3::splat(2.0)], size, sizing_points: 1 };
    let points = |gradation| {
        let native = NativeCore { refine: RefineOptions { gradation, ..Default::default() } };
        let (core, stats) = native.fill_refined(&boundary, &guide).unwrap();
        check(&boundary, &core);
        assert!(!stats.point_limit, "{stats:?}");
        core.points.len()
    };
    let (interpolated, graded) = (points(None), points(Some(1.2)));
    assert!(2 * graded > 3 * interpolated, "{graded} points graded, {interpolated} interpolated");
}

#[test]
fn refinement_of_a_thin_slab_ends() {
    // Sizes far above the slab's thickness: every candidate point is near the boundary.
    let boundary = region(&shapes::cuboid(DVec3::new(10.0, 10.0, 0.05), 8), &[]);
    let (core, stats) = refined(&boundary, |_| 0.3);
    assert!(!stats.point_limit, "{stats:?}");
    assert!(core.points.len() < boundary.points.len() + 1000, "{} points", core.points.len());
}

#[test]
fn without_sizes_only_the_shape_is_refined() {
    let mut sphere = shapes::icosphere(1.0, 2);
    sphere.points.iter_mut().for_each(|p| *p += DVec3::splat(2.0));
    let boundary = region(&shapes::cuboid(DVec3::splat(4.0), 2), &[sphere]);
    let guide = CoreGuide::default();
    let (core, stats) = NativeCore::default().fill_refined(&boundary, &guide).unwrap();
    check(&boundary, &core);
    assert_eq!(stats.for_size, 0, "{stats:?}");
}

#[test]
fn an_off_centre_stops_at_the_bound() {
    let (a, b) = (DVec3::ZERO, DVec3::X);
    let far = DVec3::new(0.5, 10.0, 0.0);
    let p = off_centre(far, [a, b], 2.0);
    // The triangle (a, b, p) has circumradius 2 |ab|.
    let height = p.y;
    let radius = (height * height + 0.25) / (2.0 * height);
    assert!((radius - 2.0).abs() < 1e-12, "{p:?}: circumradius {radius}");
    let near = DVec3::new(0.5, 1.0, 0.0);
    assert_eq!(off_centre(near, [a, b], 2.0), near);
}

#[test]
fn a_point_over_a_triangle_encroaches_it_up_to_its_circumradius() {
    let face = [DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0), DVec3::new(0.0, 2.0, 0.0)];
    // Circumcentre (1, 1, 0), circumradius sqrt(2).
    assert!(in_diametral_sphere(face, DVec3::new(1.0, 1.0, 1.4)));
    assert!(!in_diametral_sphere(face, DVec3::new(1.0, 1.0, 1.5)));
    assert!(!in_diametral_sphere(face, DVec3::new(-0.1, -0.1, 0.0)));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(8))]

    #[test]
    fn random_sizes_keep_the_boundary(sizes in prop::collection::vec(0.15f64..1.0, 26), n in 2usize..4) {
        let boundary = region(&shapes::cuboid(DVec3::splat(2.0), n), &[]);
        let (_, stats) = refined(&boundary, |p| {
            let k = ((p.x * 7.0 + p.y * 3.0 + p.z * 5.0).abs() * 10.0) as usize;
            sizes[k % sizes.len()]
        });
        prop_assert!(!stats.point_limit);
    }
}
