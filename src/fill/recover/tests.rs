use std::collections::HashMap;

use proptest::prelude::*;

use super::cavity::on_triangle;
use super::*;
use crate::fill::{merge, sorted_triangle, MARKER_WALL};
use crate::geometry::tet_signed_volume;
use crate::surface::{shapes, Surface};

/// The region inside the closed outward surfaces `outer` (reversed: its normals into the
/// region) and outside the `holes`.
pub(super) fn region(outer: &Surface, holes: &[Surface]) -> ClosedBoundary {
    let mut boundary = ClosedBoundary::default();
    for (k, s) in std::iter::once(outer).chain(holes).enumerate() {
        let offset = boundary.points.len() as u32;
        boundary.points.extend(&s.points);
        boundary.triangles.extend(s.triangles.iter().map(|t| {
            let t = t.map(|v| v + offset);
            if k == 0 {
                [t[0], t[2], t[1]]
            } else {
                t
            }
        }));
    }
    boundary.markers = vec![MARKER_WALL; boundary.triangles.len()];
    boundary
}

fn moved(mut s: Surface, by: DVec3) -> Surface {
    s.points.iter_mut().for_each(|p| *p += by);
    s
}

/// The fill's invariants: boundary points first and unchanged, every tetrahedron positive,
/// every boundary triangle a face of exactly one tetrahedron on its inner side
/// ([`merge::check_boundary_kept`]), every other face shared by two, no added point on the
/// boundary, and the volume enclosed.
pub(super) fn check(boundary: &ClosedBoundary, core: &CoreTets) {
    merge::check_boundary_kept(boundary, core).unwrap();
    let mut uses: HashMap<[u32; 3], usize> = HashMap::new();
    for &tet in &core.tets {
        for f in recovery::inward_faces(tet) {
            *uses.entry(sorted_triangle(f)).or_default() += 1;
        }
    }
    let on_boundary: std::collections::HashSet<[u32; 3]> =
        boundary.triangles.iter().map(|&t| sorted_triangle(t)).collect();
    for (face, &count) in &uses {
        let expected = if on_boundary.contains(face) { 1 } else { 2 };
        assert_eq!(count, expected, "face {face:?}");
    }
    let n = boundary.points.len();
    for (i, &p) in core.points.iter().enumerate().skip(n) {
        let on = boundary.triangles.iter().find(|t| on_triangle(p, t.map(|v| boundary.points[v as usize])));
        assert!(on.is_none(), "point {i} at {p:?} is on boundary triangle {on:?}");
    }
    let x = |v: u32| core.points[v as usize];
    let volume: f64 = core.tets.iter().map(|t| tet_signed_volume(x(t[0]), x(t[1]), x(t[2]), x(t[3]))).sum();
    let enclosed: f64 = boundary.triangles.iter().map(|t| -x(t[0]).dot(x(t[1]).cross(x(t[2]))) / 6.0).sum();
    assert!((volume - enclosed).abs() <= 1e-9 * enclosed.abs(), "volume {volume}, enclosed {enclosed}");
}

/// Fill `boundary` natively with `interior` points, check it and return the recovery's
/// figures.
fn fill_and_check(boundary: &ClosedBoundary, interior: Vec<DVec3>) -> RecoveryStats {
    let (_, stats) = recover_region(boundary).unwrap();
    eprintln!("{} triangles: {stats:?}", boundary.triangles.len());
    let guide = CoreGuide { interior, ..Default::default() };
    let core = NativeCore::default().fill(boundary, &guide).unwrap();
    check(boundary, &core);
    stats
}

#[test]
fn cube() {
    let stats = fill_and_check(&region(&shapes::cuboid(DVec3::ONE, 1), &[]), Vec::new());
    assert_eq!(stats.steiner_points_inside, 0, "{stats:?}");
}

#[test]
fn cube_with_interior_points() {
    let interior = vec![
        DVec3::splat(0.5),
        DVec3::new(0.25, 0.5, 0.75),
        DVec3::new(2.0, 0.5, 0.5),
        DVec3::new(0.5, 0.5, 0.0),
    ];
    let boundary = region(&shapes::cuboid(DVec3::ONE, 2), &[]);
    let core = NativeCore::default().fill(&boundary, &CoreGuide { interior, ..Default::default() }).unwrap();
    check(&boundary, &core);
    // The two inside went in; the one outside and the one on the boundary did not.
    assert_eq!(core.points.len(), boundary.points.len() + 2);
}

#[test]
fn cube_with_a_cubic_hole() {
    let hole = moved(shapes::cuboid(DVec3::ONE, 2), DVec3::ONE);
    fill_and_check(&region(&shapes::cuboid(DVec3::splat(3.0), 3), &[hole]), vec![DVec3::splat(0.5)]);
}

#[test]
fn thin_slab() {
    fill_and_check(&region(&shapes::cuboid(DVec3::new(10.0, 10.0, 0.05), 8), &[]), Vec::new());
}

#[test]
fn l_block_and_tunnel() {
    let l_block = shapes::voxels([2, 2, 1], 1.0, 2, |i, j, _| i == 0 || j == 0);
    fill_and_check(&region(&l_block, &[]), Vec::new());
    let tunnel = shapes::voxels([3, 3, 1], 1.0, 1, |i, j, _| i != 1 || j != 1);
    fill_and_check(&region(&tunnel, &[]), Vec::new());
}

#[test]
fn icosphere_in_a_box() {
    let sphere = moved(shapes::icosphere(1.0, 3), DVec3::splat(2.0));
    fill_and_check(&region(&shapes::cuboid(DVec3::splat(4.0), 4), std::slice::from_ref(&sphere)), Vec::new());
    // And its inside.
    fill_and_check(&region(&sphere, &[]), Vec::new());
}

/// The twisted prism of Schönhardt: no tetrahedralisation without a Steiner point.
fn schonhardt() -> Surface {
    let corner = |k: usize, z: f64, twist: f64| {
        let angle = (k as f64 * 120.0 + twist).to_radians();
        DVec3::new(angle.cos(), angle.sin(), z)
    };
    let mut points: Vec<DVec3> = (0..3).map(|k| corner(k, 0.0, 0.0)).collect();
    points.extend((0..3).map(|k| corner(k, 1.0, 30.0)));
    let mut triangles = vec![[0, 2, 1], [3, 4, 5]];
    for k in 0..3u32 {
        let (b0, b1, t0, t1) = (k, (k + 1) % 3, 3 + k, 3 + (k + 1) % 3);
        // The diagonal b0-t1 bends in (reflex): the other one is on the convex hull.
        triangles.push([b0, b1, t1]);
        triangles.push([b0, t1, t0]);
    }
    Surface {
        points,
        triangles: triangles.clone(),
        triangle_patch: vec![0; triangles.len()],
        patch_names: vec![String::new()],
    }
}

#[test]
fn schonhardt_needs_an_interior_steiner_point() {
    let s = schonhardt();
    let volume: f64 = s
        .triangles
        .iter()
        .map(|t| s.points[t[0] as usize].dot(s.points[t[1] as usize].cross(s.points[t[2] as usize])))
        .sum();
    assert!(volume > 0.0, "outward");
    let stats = fill_and_check(&region(&s, &[]), Vec::new());
    assert!(stats.steiner_points_inside >= 1, "{stats:?}");
}

/// A random convex polyhedron: the hull of random points.
fn hull(points: &[DVec3]) -> Option<Surface> {
    let delaunay = Delaunay::new(points).ok()?;
    let triangles: Vec<[u32; 3]> = delaunay.hull_triangles().collect();
    Some(Surface {
        points: points.to_vec(),
        triangle_patch: vec![0; triangles.len()],
        triangles,
        patch_names: vec![String::new()],
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn random_convex_hulls(coordinates in prop::collection::vec(-10i32..10, 3 * 8..3 * 40)) {
        let points: Vec<DVec3> = coordinates.chunks_exact(3).map(|c| DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64)).collect();
        let Some(mut s) = hull(&points) else { return Ok(()) };
        s.remove_unused_points();
        prop_assume!(s.triangles.len() >= 4);
        let boundary = region(&s, &[]);
        // The hull of points on a grid can have flat triangles (collinear points on a face).
        prop_assume!(boundary.check_structure().is_ok());
        fill_and_check(&boundary, Vec::new());
    }

    #[test]
    fn boxes_in_a_box(corners in prop::collection::vec((0u8..4, 0u8..4, 0u8..4, 1u8..3), 1..4), n in 1usize..4, shift in -0.3f64..0.3) {
        // Boxes on a grid of 4 x 4 x 4 cells in a box of 6, apart by at least a cell.
        let mut taken = [[[false; 6]; 6]; 6];
        let mut holes = Vec::new();
        for (i, j, k, side) in corners {
            let (i, j, k, side) = (i as usize + 1, j as usize + 1, k as usize + 1, (side as usize).min(5 - i as usize - 1).max(1));
            let cells = |a: usize| a.saturating_sub(1)..(a + side + 1).min(6);
            if cells(i).any(|x| cells(j).any(|y| cells(k).any(|z| taken[x][y][z]))) || i + side > 5 || j + side > 5 || k + side > 5 {
                continue;
            }
            for plane in &mut taken[i..i + side] {
                for row in &mut plane[j..j + side] {
                    row[k..k + side].fill(true);
                }
            }
            let hole = moved(shapes::cuboid(DVec3::splat(side as f64), n), DVec3::new(i as f64, j as f64 + shift * 0.1, k as f64));
            holes.push(hole);
        }
        fill_and_check(&region(&shapes::cuboid(DVec3::splat(6.0), 2 * n), &holes), Vec::new());
    }
}

/// A boundary the pipeline failed to recover, written by `BLMESH_DUMP_RECOVERY=FILE` (see
/// [`recover_region`]): `BLMESH_RECOVERY_CASE=FILE cargo test dumped_boundary -- --ignored`.
#[test]
#[ignore]
fn dumped_boundary() {
    let path = std::env::var("BLMESH_RECOVERY_CASE").expect("BLMESH_RECOVERY_CASE names the dumped boundary");
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let points: Vec<DVec3> = serde_json::from_value(json["points"].clone()).unwrap();
    let triangles: Vec<[u32; 3]> = serde_json::from_value(json["triangles"].clone()).unwrap();
    let boundary = ClosedBoundary { markers: vec![MARKER_WALL; triangles.len()], points, triangles };
    let start = std::time::Instant::now();
    let stats = recover_region(&boundary).map(|(_, stats)| stats);
    eprintln!("{stats:?} in {:.2} s", start.elapsed().as_secs_f64());
    eprintln!("{:?}", fill_and_check(&boundary, Vec::new()));
}
