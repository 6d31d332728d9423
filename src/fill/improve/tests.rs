use std::collections::HashMap;

use proptest::prelude::*;

use super::*;
use crate::geometry::tet_signed_volume;
use crate::quality::samples::{cube_grid, CubeSplit};

/// The faces of the mesh (sorted nodes) with the number of tetrahedra on each.
fn face_counts(mesh: &TetMesh) -> HashMap<[u32; 3], usize> {
    let mut count = HashMap::new();
    for tet in mesh.tets() {
        for f in CellKind::Tetrahedron.faces() {
            *count.entry(sorted_triangle([tet[f[0]], tet[f[1]], tet[f[2]]])).or_insert(0) += 1;
        }
    }
    count
}

fn boundary_faces(mesh: &TetMesh) -> Vec<[u32; 3]> {
    let mut faces: Vec<[u32; 3]> =
        face_counts(mesh).into_iter().filter(|(_, n)| *n == 1).map(|(f, _)| f).collect();
    faces.sort_unstable();
    faces
}

fn volume(mesh: &TetMesh) -> f64 {
    mesh.tets()
        .map(|t| t.map(|v| mesh.points[v as usize]))
        .map(|[a, b, c, d]| tet_signed_volume(a, b, c, d))
        .sum()
}

/// Every tetrahedron positive (exact), no face on more than two, the boundary and the volume as
/// in `reference`, the fixed points where they were.
fn assert_consistent(mesh: &TetMesh, reference: &TetMesh) {
    for tet in mesh.tets() {
        let [a, b, c, d] = tet.map(|v| mesh.points[v as usize]);
        assert_eq!(orient3d(a, b, c, d), Sign::Positive, "{tet:?}");
    }
    assert!(face_counts(mesh).values().all(|&n| n <= 2), "a face on more than two tetrahedra");
    assert_adjacent(mesh);
    assert_eq!(boundary_faces(mesh), boundary_faces(reference));
    let (v, w) = (volume(mesh), volume(reference));
    assert!((v - w).abs() <= 1e-12 * w.abs(), "volume {v} vs {w}");
    assert_eq!(mesh.points[..mesh.fixed], reference.points[..reference.fixed]);
}

/// The neighbour the mesh keeps across every face of every live tetrahedron is the other live
/// tetrahedron on that face (none on the boundary).
fn assert_adjacent(mesh: &TetMesh) {
    for t in (0..mesh.tets.len() as u32).filter(|&t| mesh.alive[t as usize]) {
        for face in mesh.outward_faces(t) {
            let others: Vec<u32> = mesh.tets_with(&face).into_iter().filter(|&s| s != t).collect();
            assert_eq!(mesh.neighbour(t, face), others.first().copied(), "tetrahedron {t}, face {face:?}");
        }
    }
}

/// Tetrahedra around the edge from `bottom` to `top` (nodes 0 and 1) with a regular ring of
/// `m` nodes (2..) around it at height `z`; a wiggle moves every other ring node up.
fn ring_mesh(m: usize, z: f64, wiggle: f64) -> TetMesh {
    let mut points = vec![DVec3::new(0.0, 0.0, -1.0), DVec3::new(0.0, 0.0, 1.0)];
    for i in 0..m {
        let angle = std::f64::consts::TAU * i as f64 / m as f64;
        let up = if i % 2 == 0 { wiggle } else { 0.0 };
        points.push(DVec3::new(angle.cos(), angle.sin(), z + up));
    }
    let ring = |i: usize| 2 + (i % m) as u32;
    let tets = (0..m).map(|i| [0, 1, ring(i), ring(i + 1)]).collect();
    TetMesh::new(points, tets, 2 + m)
}

#[test]
fn ring_order_makes_positive_tetrahedra() {
    let mesh = ring_mesh(5, 0.0, 0.0);
    let (tets, ring) = mesh.ring(0, 1).unwrap();
    assert_eq!(tets.len(), 5);
    for i in 0..5 {
        let tet = [0, 1, ring[i], ring[(i + 1) % 5]];
        assert!(mesh.quality(tet) > 0.0, "{tet:?}");
    }
    // A boundary edge has no closed ring.
    assert!(mesh.ring(0, 2).is_none());
}

#[test]
fn flip_32_removes_the_edge_of_a_flat_ring() {
    // Three tetrahedra around a long edge: the two across the ring are better.
    let mesh = ring_mesh(3, 0.0, 0.0);
    let change = mesh.remove_edge(0, 1).unwrap();
    assert_eq!((change.remove.len(), change.add.len()), (3, 2));
    assert!(change.improves(Rule::FewerBad), "{change:?}");
    let mut after = mesh.clone();
    after.apply(&change);
    assert_consistent(&after, &mesh);
    assert!(after.tets().all(|t| !(t.contains(&0) && t.contains(&1))));
}

#[test]
fn flip_23_is_the_inverse_of_flip_32() {
    let mut mesh = ring_mesh(3, 0.0, 0.0);
    let reference = mesh.clone();
    mesh.apply(&mesh.remove_edge(0, 1).unwrap());
    let change = mesh.flip_23([2, 3, 4]).unwrap();
    assert_eq!((change.remove.len(), change.add.len()), (2, 3));
    mesh.apply(&change);
    assert_consistent(&mesh, &reference);
    assert_eq!(mesh.tets_with(&[0, 1]).len(), 3);
    // A face on the boundary cannot flip.
    assert!(mesh.flip_23([0, 2, 3]).is_none());
}

#[test]
fn flip_44_and_larger_edge_removals_keep_the_cavity() {
    for m in 4..=MAX_RING {
        let mesh = ring_mesh(m, 0.0, 0.1);
        let change = mesh.remove_edge(0, 1).unwrap();
        assert_eq!((change.remove.len(), change.add.len()), (m, 2 * (m - 2)), "ring of {m}");
        let mut after = mesh.clone();
        after.apply(&change);
        assert_consistent(&after, &mesh);
    }
    // Rings above the limit are left alone.
    assert!(ring_mesh(MAX_RING + 1, 0.0, 0.0).remove_edge(0, 1).is_none());
}

#[test]
fn edge_removal_refuses_a_ring_that_cannot_be_rebuilt() {
    // The ring polygon lies far above both ends of the edge: joining it to the bottom node
    // makes tetrahedra of the wrong orientation.
    let mesh = ring_mesh(3, 2.0, 0.0);
    assert!(mesh.tets().all(|t| mesh.quality(t) > 0.0));
    assert!(mesh.remove_edge(0, 1).is_none());
}

#[test]
fn split_edge_adds_an_interior_point_and_keeps_the_cavity() {
    let mesh = ring_mesh(4, 0.0, 0.0);
    let change = mesh.split_edge(0, 1).unwrap();
    assert_eq!((change.remove.len(), change.add.len()), (4, 8));
    assert_eq!(change.point.map(|p| p.0), Some(6));
    let mut after = mesh.clone();
    after.apply(&change);
    assert_eq!(after.points.len(), 7);
    assert_consistent(&after, &mesh);
}

#[test]
fn smoothing_moves_only_added_points_and_raises_the_worst_angle() {
    // A point added at the centre of an octahedron, pulled near a corner.
    let mut mesh = ring_mesh(4, 0.0, 0.0);
    mesh.apply(&mesh.split_edge(0, 1).unwrap());
    mesh.points[6] = DVec3::new(0.9, 0.0, 0.05);
    let reference = mesh.clone();
    let change = mesh.smooth_vertex(6).unwrap();
    assert!(change.after > change.before + 10.0, "{change:?}");
    mesh.apply(&change);
    assert_consistent(&mesh, &reference);
    assert!(mesh.smooth_vertex(0).is_none(), "node 0 is fixed");
}

#[test]
fn histogram_counts_every_tetrahedron() {
    let mesh = ring_mesh(6, 0.0, 0.0);
    let (points, tets) = mesh.into_parts();
    let h = DihedralHistogram::of(&points, &tets);
    assert_eq!(h.counts.iter().sum::<usize>(), 6);
    assert!(h.to_string().starts_with("0-5: "));
}

#[test]
fn a_cap_has_no_good_tetrahedron_but_a_needle_and_an_equilateral_triangle_have() {
    let equilateral = best_apex_quality(DVec3::ZERO, DVec3::X, DVec3::new(0.5, 0.75f64.sqrt(), 0.0));
    assert!(equilateral > 65.0, "{equilateral}");
    let cap = best_apex_quality(DVec3::ZERO, DVec3::X, DVec3::new(0.5, 0.01, 0.0));
    assert!(cap < 10.0, "{cap}");
    // A needle has a good tetrahedron: the apex near its short edge (a needle too).
    let needle = best_apex_quality(DVec3::ZERO, DVec3::X, DVec3::new(0.0, 0.02, 0.0));
    assert!(needle > 10.0, "{needle}");
}

/// A grid of `n`^3 cubes cut into Kuhn tetrahedra, interior points moved by `jitter` (in grid
/// cells) and numbered after the boundary points, which are fixed.
fn jittered_grid(n: usize, jitter: &[f64]) -> Option<TetMesh> {
    let grid = cube_grid([n; 3], DVec3::ONE, &|_| CubeSplit::Tetrahedra, &|_| 0);
    let inside = |p: DVec3| p.cmpgt(DVec3::ZERO).all() && p.cmplt(DVec3::splat(n as f64)).all();
    let mut order: Vec<usize> = (0..grid.points.len()).collect();
    order.sort_by_key(|&i| inside(grid.points[i]));
    let mut new_index = vec![0u32; order.len()];
    for (k, &i) in order.iter().enumerate() {
        new_index[i] = k as u32;
    }
    let fixed = order.iter().filter(|&&i| !inside(grid.points[i])).count();
    let mut points: Vec<DVec3> = order.iter().map(|&i| grid.points[i]).collect();
    for (k, p) in points.iter_mut().enumerate().skip(fixed) {
        let j = 3 * (k - fixed);
        *p += DVec3::new(
            jitter[j % jitter.len()],
            jitter[(j + 1) % jitter.len()],
            jitter[(j + 2) % jitter.len()],
        );
    }
    let block = grid.block(CellKind::Tetrahedron);
    let tets: Vec<[u32; 4]> = block.iter().map(|t| [0, 1, 2, 3].map(|i| new_index[t[i] as usize])).collect();
    let mesh = TetMesh::new(points, tets, fixed);
    let valid = mesh.tets().all(|t| mesh.quality(t) > 0.0);
    valid.then_some(mesh)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// The tetrahedron's own dihedral measures equal the checker's, computed from each face's
    /// normal by its definition.
    #[test]
    fn tetrahedron_angles_equal_the_checkers(raw in proptest::array::uniform12(-1.0f64..1.0)) {
        let x: [DVec3; 4] = std::array::from_fn(|i| DVec3::new(raw[3 * i], raw[3 * i + 1], raw[3 * i + 2]));
        let mut corners = [DVec3::ZERO; 8];
        corners[..4].copy_from_slice(&x);
        let pairs = crate::quality::measures::edge_face_pairs(CellKind::Tetrahedron);
        let (lo, hi) = crate::quality::measures::dihedral_range(CellKind::Tetrahedron, &corners, &pairs);
        let volume = tet_signed_volume(x[0], x[1], x[2], x[3]);
        if volume > 1e-6 {
            prop_assert!((min_dihedral(x) - lo).abs() < 1e-6, "{} {}", min_dihedral(x), lo);
            prop_assert!((angle_quality(x) - lo.min(180.0 - hi)).abs() < 1e-6);
        } else if volume < 0.0 {
            prop_assert_eq!(min_dihedral(x), INVALID);
        }
    }

    /// Any sequence of operators (point insertion at each of its places, the centroid among
    /// them, too) on a jittered grid keeps the mesh valid, conforming, with the
    /// same boundary and volume.
    #[test]
    fn operators_keep_the_mesh_valid(
        jitter in proptest::collection::vec(-0.35f64..0.35, 30),
        ops in proptest::collection::vec((0usize..5, 0usize..10_000, 0usize..6), 1..40),
    ) {
        let Some(mut mesh) = jittered_grid(3, &jitter) else { return Ok(()) };
        let reference = mesh.clone();
        for (op, pick, local) in ops {
            let live: Vec<u32> = (0..mesh.tets.len() as u32).filter(|&t| mesh.alive[t as usize]).collect();
            let t = live[pick % live.len()];
            let tet = mesh.tets[t as usize];
            let (i, j) = TET_EDGES[local];
            let f = CellKind::Tetrahedron.faces()[local % 4];
            let change = match op {
                0 => mesh.flip_23([tet[f[0]], tet[f[1]], tet[f[2]]]),
                1 => mesh.remove_edge(tet[i], tet[j]),
                2 => mesh.split_edge(tet[i], tet[j]),
                3 => {
                    let places = mesh.insertion_points(t);
                    let (p, placement) = places[local % places.len()];
                    mesh.insert_point(t, p, placement)
                }
                _ => mesh.smooth_vertex(tet[local % 4]),
            };
            if let Some(change) = change {
                prop_assert!(change.after > INVALID);
                mesh.apply(&change);
            }
        }
        assert_consistent(&mesh, &reference);
    }

    /// The improvement never lowers the worst angle and keeps the mesh consistent.
    #[test]
    fn improvement_never_lowers_the_worst_angle(jitter in proptest::collection::vec(-0.4f64..0.4, 30)) {
        let Some(mut mesh) = jittered_grid(3, &jitter) else { return Ok(()) };
        let reference = mesh.clone();
        let before = mesh.worst(mesh.tets());
        mesh.improve(&ImproveOptions { target_dihedral: 30.0, ..Default::default() });
        assert_consistent(&mesh, &reference);
        prop_assert!(mesh.worst(mesh.tets()) >= before);
    }
}

/// The first core tetrahedron on a front triangle keeps the last layer's height: lowering its
/// apex to the regular tetrahedron's height is a gain in angles, refused once it takes the cell
/// out of [1/r, r] of the layer under it, allowed within.
#[test]
fn no_change_takes_a_first_core_cell_off_the_last_layer_height() {
    let s = 3f64.sqrt();
    let apex = |z: f64| DVec3::new(0.5, s / 6.0, z);
    let points = vec![DVec3::ZERO, DVec3::X, DVec3::new(0.5, s / 2.0, 0.0), apex(1.0)];
    assert!(tet_signed_volume(points[0], points[1], points[2], points[3]) > 0.0);
    let mut mesh = TetMesh::new(points, vec![[0, 1, 2, 3]], 3);
    let lower = |mesh: &TetMesh, z: f64| mesh.change(vec![0], vec![[0, 1, 2, 3]], Some((3, apex(z))));
    assert!(lower(&mesh, 0.82).is_some_and(|c| c.after > c.before + 1.0), "a plain gain without the layer");
    mesh.keep_front_match(HashMap::from([([0, 1, 2], 1.0)]), 1.2);
    assert!(lower(&mesh, 0.82).is_none(), "0.82 is below 1/1.2 of the layer");
    assert!(lower(&mesh, 0.9).is_some(), "0.9 is within the band");
}

/// A front triangle (0, 1, 2) at z = 0 under a last layer 1 high, joined by the mesher to a
/// point 0.7 as high (3); the tetrahedron beyond the face (0, 1, 3) has a point at the layer's
/// height (4): the 2-3 flip through that face makes 4 the triangle's apex.
#[test]
fn a_flip_gives_a_low_first_core_cell_the_last_layers_height() {
    let points = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.5, 1.0, 0.0),
        DVec3::new(0.5, 0.7, 0.7),
        DVec3::new(0.5, -0.5, 1.0),
    ];
    let positive = |t: [u32; 4]| {
        let x = t.map(|v| points[v as usize]);
        if tet_signed_volume(x[0], x[1], x[2], x[3]) > 0.0 {
            t
        } else {
            [t[1], t[0], t[2], t[3]]
        }
    };
    let mut mesh = TetMesh::new(points.clone(), vec![positive([0, 1, 2, 3]), positive([0, 1, 3, 4])], 5);
    let reference = mesh.clone();
    mesh.keep_front_match(HashMap::from([([0, 1, 2], 1.0)]), 1.2);
    let on_front = |mesh: &TetMesh| mesh.tets().find(|t| [0, 1, 2].iter().all(|v| t.contains(v)));
    assert!(on_front(&mesh).unwrap().contains(&3));
    assert_eq!(mesh.match_front(MatchInsertion::InBand), 1);
    assert!(on_front(&mesh).unwrap().contains(&4), "the point at the layer's height is its apex");
    assert_consistent(&mesh, &reference);
    assert!(mesh.tets().all(|t| angle_quality(t.map(|v| mesh.points[v as usize])) >= SLIVER_THRESHOLD));
    assert_eq!(mesh.match_front(MatchInsertion::InBand), 0, "nothing left to match");
}

/// A front triangle's tetrahedron whose apex is a point the mesher added, 0.4 of the last
/// layer high: the apex moves up along the triangle's normal into the band, no further.
#[test]
fn an_added_apex_too_low_for_the_last_layer_moves_into_its_band() {
    let points = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(0.3, 0.3, 0.4),
    ];
    let mut mesh = TetMesh::new(points, vec![[0, 1, 2, 3]], 3);
    mesh.keep_front_match(HashMap::from([([0, 1, 2], 1.0)]), 1.2);
    assert_eq!(mesh.match_front(MatchInsertion::InBand), 1);
    let apex = mesh.points[3];
    assert!((apex.z - 1.01 / 1.2).abs() < 1e-12, "just into the band: {apex}");
    assert_eq!((apex.x, apex.y), (0.3, 0.3), "along the normal");
}

/// Of two changes that both mend a sliver on a front triangle, the one that leaves its first
/// core cell in the band of the last layer wins over a better-shaped one that does not: the
/// apex at 1.0 (the layer's height) over 0.8 (the regular tetrahedron's, below 1/1.2).
#[test]
fn mending_a_sliver_keeps_the_first_core_cell_on_the_last_layer_height() {
    let s = 3f64.sqrt();
    let apex = |z: f64| DVec3::new(0.5, s / 6.0, z);
    let points = vec![DVec3::ZERO, DVec3::X, DVec3::new(0.5, s / 2.0, 0.0), apex(0.05)];
    let mut mesh = TetMesh::new(points, vec![[0, 1, 2, 3]], 3);
    mesh.keep_front_match(HashMap::from([([0, 1, 2], 1.0)]), 1.2);
    let raise = |z: f64| mesh.change(vec![0], vec![[0, 1, 2, 3]], Some((3, apex(z)))).expect("positive");
    let (regular, matched) = (raise(0.8), raise(1.0));
    assert!(regular.after > matched.after && matched.after >= SLIVER_THRESHOLD);
    let best = mesh.best_improving(vec![regular, matched], Rule::FewerBad).expect("both improve");
    assert_eq!(best.point.map(|p| p.1.z), Some(1.0));
}

/// A front triangle (0, 1, 2) under a last layer 1 high, at the foot of a prism of fixed points
/// 2 high cut into three tetrahedra: the triangle's apex (3) is twice the layer's height, and no
/// flip or move can help (every point is fixed). A point inserted in the band becomes its apex,
/// within [1/r, r] of the layer's height, and leaves no sliver.
#[test]
fn a_point_inserted_in_the_band_gives_a_front_triangle_its_last_layers_height() {
    let s = 3f64.sqrt();
    let base = [DVec3::ZERO, DVec3::X, DVec3::new(0.5, s / 2.0, 0.0)];
    let mut points = base.to_vec();
    points.extend(base.map(|p| p + 2.0 * DVec3::Z));
    let mut mesh = TetMesh::new(points, vec![[0, 1, 2, 3], [1, 2, 3, 4], [2, 3, 4, 5]], 6);
    let reference = mesh.clone();
    mesh.keep_front_match(HashMap::from([([0, 1, 2], 1.0)]), 1.2);
    assert_eq!(mesh.match_front(MatchInsertion::InBand), 1);
    let on_front =
        mesh.tets().find(|t| [0, 1, 2].iter().all(|v| t.contains(v))).expect("a tetrahedron on it");
    assert!(on_front.contains(&6), "the inserted point is its apex: {on_front:?}");
    let height = mesh.points[6].z;
    assert!((1.0 / 1.2..=1.2).contains(&height), "height {height}");
    assert_consistent(&mesh, &reference);
    assert!(mesh.tets().all(|t| angle_quality(t.map(|v| mesh.points[v as usize])) >= SLIVER_THRESHOLD));
    assert_eq!(mesh.match_front(MatchInsertion::InBand), 0, "nothing left to match");
}

/// An insertion never does worse than the Delaunay cavity's cone, and on jittered grids (not
/// Delaunay: Kuhn cubes moved) the cavity grown across its flat faces sometimes does better
/// (6 of the 3,888 insertions here): at a point four fifths of the way from a tetrahedron's
/// centroid to one of its corners, the cone over the Delaunay cavity has a sliver that the
/// grown one avoids.
#[test]
fn a_cavity_grown_across_its_flat_faces_beats_the_delaunay_one() {
    let (mut better, mut tried) = (0, 0);
    for seed in 0..6 {
        let jitter: Vec<f64> =
            (0..30).map(|i| 0.35 * (((i * 7 + seed * 13) % 17) as f64 / 8.0 - 1.0)).collect();
        let Some(mesh) = jittered_grid(3, &jitter) else { continue };
        for t in (0..mesh.tets.len() as u32).filter(|&t| mesh.alive[t as usize]) {
            let centroid = mesh.centroid(t);
            for corner in mesh.corners(mesh.tets[t as usize]) {
                let p = centroid.lerp(corner, 0.8);
                let Some(cavity) = mesh.delaunay_cavity(t, p) else { continue };
                let delaunay = mesh.fill_cavity(cavity, p, Placement::AsGiven).map_or(INVALID, |c| c.after);
                let chosen = mesh.insert_point(t, p, Placement::AsGiven);
                let after = chosen.as_ref().map_or(INVALID, |c| c.after);
                assert!(after >= delaunay, "{after} < {delaunay}");
                tried += 1;
                if delaunay < SLIVER_THRESHOLD && after >= SLIVER_THRESHOLD {
                    better += 1;
                    let mut changed = mesh.clone();
                    changed.apply(&chosen.expect("a change"));
                    assert_consistent(&changed, &mesh);
                }
            }
        }
    }
    assert!(better > 0, "no grown cavity did better in {tried} insertions");
}

/// An octahedron (its six corners fixed) split around an added point near corner +x: the point
/// merged into that corner leaves the four tetrahedra from it over the far faces, better than
/// the slivers at the point; the point is gone from the parts, and a fixed point never merges.
#[test]
fn an_added_point_near_a_corner_merges_into_it() {
    let corners = [DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z, -DVec3::Z];
    let mut points = corners.to_vec();
    points.push(DVec3::new(0.9, 0.0, 0.02));
    let faces = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
    let tets = faces.iter().map(|&[a, b, c]| [a, c, b, 6]).collect();
    let mut mesh = TetMesh::new(points, tets, 6);
    let reference = mesh.clone();
    assert!(mesh.tets().all(|t| mesh.quality(t) > 0.0), "positive to start with");
    assert!(mesh.collapse_edge(0, 6).is_none(), "corner 0 is fixed");
    let change = mesh.collapse_edge(6, 0).expect("the octahedron is convex");
    assert_eq!((change.remove.len(), change.add.len()), (8, 4));
    assert!(change.after > change.before + 10.0, "{} -> {}", change.before, change.after);
    mesh.apply(&change);
    assert_consistent(&mesh, &reference);
    let (points, tets) = mesh.into_parts();
    let mut core = CoreTets { points, tets, boundary_steiner_points: 0 };
    crate::fill::merge::drop_unused_points(&mut core, 6);
    assert_eq!((core.points.len(), core.tets.len()), (6, 4));
    assert!(core.tets.iter().all(|t| t.contains(&0)));
}

/// The needle (a corner of about 1 degree) and the cap (a corner of about 179 degrees) give
/// their edges; the fair triangle beside them does not.
#[test]
fn needles_and_caps_of_the_boundary_give_their_edges_and_a_fair_triangle_does_not() {
    let points = vec![
        DVec3::ZERO,
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(1.0, 0.02, 0.0),
        DVec3::new(0.5, 0.8, 0.0),
        DVec3::new(0.5, -0.005, 0.0),
    ];
    let boundary = ClosedBoundary {
        points,
        triangles: vec![[0, 1, 2], [0, 2, 3], [1, 0, 4]],
        markers: vec![MARKER_FRONT; 3],
    };
    let edges = poor_triangle_edges(&boundary, SLIVER_THRESHOLD);
    let mut expected = vec![[0, 1], [1, 2], [0, 2], [0, 4], [1, 4]];
    expected.sort_unstable();
    let mut found: Vec<[u32; 2]> = edges.into_iter().collect();
    found.sort_unstable();
    assert_eq!(found, expected);
}
