use std::collections::HashSet;

use proptest::prelude::*;

use super::*;
use crate::geometry::predicates::insphere;
use crate::geometry::tet_signed_volume;

/// Point clouds that the tests draw from.
#[derive(Clone, Copy, Debug)]
enum Cloud {
    /// Uniform in the unit cube.
    Uniform,
    /// A few tight clusters far apart (sizes over six orders of magnitude).
    Clustered,
    /// On the unit sphere, up to rounding: nearly cospherical.
    Sphere,
    /// Nodes of a 5 x 5 x 5 grid: exactly cospherical and coplanar by the dozen.
    Grid,
    /// Uniform, then a third of them again.
    Duplicated,
    /// Uniform in a slab 1e-9 thick: nearly coplanar.
    Slab,
    /// Integer points on the sphere of radius 9 (x^2 + y^2 + z^2 = 81), exactly cospherical.
    IntegerSphere,
}

/// `n` points of `cloud` drawn with `seed` (the grid and the integer sphere pick among theirs).
fn cloud(kind: Cloud, n: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = SplitMix64::new(seed);
    let uniform = |rng: &mut SplitMix64| DVec3::new(rng.unit(), rng.unit(), rng.unit());
    match kind {
        Cloud::Uniform => (0..n).map(|_| uniform(&mut rng)).collect(),
        Cloud::Clustered => {
            let centres: Vec<DVec3> = (0..4).map(|_| uniform(&mut rng) * 100.0).collect();
            (0..n)
                .map(|i| {
                    let spread = 10f64.powi(-(i as i32 % 7));
                    centres[i % 4] + (uniform(&mut rng) - DVec3::splat(0.5)) * spread
                })
                .collect()
        }
        Cloud::Sphere => (0..n)
            .map(|_| loop {
                let p = uniform(&mut rng) * 2.0 - DVec3::ONE;
                if p.length() > 0.1 {
                    break p.normalize();
                }
            })
            .collect(),
        Cloud::Grid => pick(grid(5), n, &mut rng),
        Cloud::Duplicated => {
            let mut points: Vec<DVec3> = (0..n - n / 3).map(|_| uniform(&mut rng)).collect();
            for i in 0..n / 3 {
                let again = points[(rng.next_u64() % (n - n / 3) as u64) as usize];
                points.insert(i * 3 % points.len(), again);
            }
            points
        }
        Cloud::Slab => (0..n).map(|_| uniform(&mut rng) * DVec3::new(1.0, 1.0, 1e-9)).collect(),
        Cloud::IntegerSphere => {
            let r = -9..=9;
            let on_sphere = r.clone().flat_map(|x: i32| {
                let r = r.clone();
                r.clone().flat_map(move |y| r.clone().map(move |z| [x, y, z]))
            });
            let all = on_sphere
                .filter(|[x, y, z]| x * x + y * y + z * z == 81)
                .map(|[x, y, z]| DVec3::new(x as f64, y as f64, z as f64));
            pick(all.collect(), n, &mut rng)
        }
    }
}

/// The nodes of an `n` x `n` x `n` grid of unit spacing.
fn grid(n: usize) -> Vec<DVec3> {
    let mut points = Vec::new();
    for i in 0..n * n * n {
        points.push(DVec3::new((i % n) as f64, (i / n % n) as f64, (i / n / n) as f64));
    }
    points
}

/// `n` of `points` (all when there are fewer), shuffled.
fn pick(mut points: Vec<DVec3>, n: usize, rng: &mut SplitMix64) -> Vec<DVec3> {
    for i in (1..points.len()).rev() {
        points.swap(i, rng.below(i + 1));
    }
    points.truncate(n);
    points
}

/// What every tetrahedralisation must be; the empty sphere by brute force with `brute_force`.
fn check(d: &Delaunay, brute_force: bool) -> Result<(), String> {
    let points = d.points();
    let tets: Vec<[u32; 4]> = d.tets().collect();
    for t in &tets {
        let [a, b, c, e] = t.map(|v| points[v as usize]);
        if orient3d(a, b, c, e) != Sign::Positive {
            return Err(format!("tetrahedron {t:?} is not positive"));
        }
    }
    check_links(d)?;
    check_locally_delaunay(d)?;
    check_volume(d, &tets)?;
    check_vertices(d, &tets)?;
    if brute_force {
        check_empty_spheres(points, &tets)?;
        check_convex_hull(d)?;
    }
    Ok(())
}

/// Every face is shared, both ways, by two live tetrahedra that have exactly its three
/// vertices in common and read it in opposite orders.
fn check_links(d: &Delaunay) -> Result<(), String> {
    for t in 0..d.cell_slots() as u32 {
        let Some(cell) = d.cell(t) else { continue };
        for (i, n) in d.neighbours(t).into_iter().enumerate() {
            let other = d.cell(n).ok_or(format!("cell {t} has the free slot {n} across face {i}"))?;
            let j = d.neighbours(n).iter().position(|&m| m == t);
            let j = j.ok_or(format!("cell {n} does not link back to {t}"))?;
            let shared = cell.iter().filter(|v| other.contains(v)).count();
            let face = FACES[i].map(|l| cell[l]);
            let back = FACES[j].map(|l| other[l]);
            let reversed = (0..3).any(|r| (0..3).all(|k| face[k] == back[(r + 3 - k) % 3]));
            if shared != 3 || other[j] == cell[i] || !reversed {
                return Err(format!("cells {t} {cell:?} and {n} {other:?} do not share face {face:?}"));
            }
        }
    }
    Ok(())
}

/// Across every face between finite tetrahedra, the far vertex is not strictly inside the
/// near one's circumsphere (locally Delaunay everywhere is Delaunay).
fn check_locally_delaunay(d: &Delaunay) -> Result<(), String> {
    for t in 0..d.cell_slots() as u32 {
        let Some(cell) = d.cell(t).filter(|c| !c.contains(&INFINITE)) else { continue };
        for n in d.neighbours(t) {
            let other = d.cell(n).unwrap_or([INFINITE; 4]);
            let Some(&far) = other.iter().find(|v| !cell.contains(v)) else { continue };
            if far == INFINITE {
                continue;
            }
            let [a, b, c, e] = cell.map(|v| d.points()[v as usize]);
            if insphere(a, b, c, e, d.points()[far as usize]) == Sign::Positive {
                return Err(format!("vertex {far} is inside the circumsphere of {cell:?}"));
            }
        }
    }
    Ok(())
}

/// The finite tetrahedra fill the convex hull: their volumes add up to the hull's, computed
/// from the hull's triangles by the divergence theorem.
fn check_volume(d: &Delaunay, tets: &[[u32; 4]]) -> Result<(), String> {
    let p = |v: u32| d.points()[v as usize];
    let volume: f64 = tets.iter().map(|t| tet_signed_volume(p(t[0]), p(t[1]), p(t[2]), p(t[3]))).sum();
    // Relative to a point of the hull, for accuracy far from the origin.
    let o = p(tets[0][0]);
    let hull: f64 =
        d.hull_triangles().map(|[a, b, c]| (p(a) - o).dot((p(b) - o).cross(p(c) - o)) / 6.0).sum();
    let scale: f64 = tets
        .iter()
        .map(|t| tet_signed_volume(p(t[0]), p(t[1]), p(t[2]), p(t[3])).abs())
        .sum::<f64>()
        .max(f64::MIN_POSITIVE);
    if (volume - hull).abs() > 1e-9 * scale {
        return Err(format!("the tetrahedra's volume {volume} is not the hull's {hull}"));
    }
    Ok(())
}

/// Every point is a vertex, or a duplicate of one.
fn check_vertices(d: &Delaunay, tets: &[[u32; 4]]) -> Result<(), String> {
    let used: HashSet<u32> = tets.iter().flatten().copied().collect();
    let duplicate: HashSet<u32> = d.duplicates().iter().map(|x| x.point).collect();
    for dup in d.duplicates() {
        if !used.contains(&dup.of) || d.points()[dup.of as usize] != d.points()[dup.point as usize] {
            return Err(format!("{dup:?} is not at a vertex"));
        }
    }
    match (0..d.points().len() as u32).find(|v| used.contains(v) == duplicate.contains(v)) {
        Some(v) => Err(format!("point {v} is a vertex and a duplicate, or neither")),
        None => Ok(()),
    }
}

/// No point is strictly inside any tetrahedron's circumsphere (exact insphere).
fn check_empty_spheres(points: &[DVec3], tets: &[[u32; 4]]) -> Result<(), String> {
    for t in tets {
        let [a, b, c, e] = t.map(|v| points[v as usize]);
        if let Some(v) = points.iter().position(|&x| insphere(a, b, c, e, x) == Sign::Positive) {
            return Err(format!("point {v} is inside the circumsphere of {t:?}"));
        }
    }
    Ok(())
}

/// No point is strictly outside a hull triangle.
fn check_convex_hull(d: &Delaunay) -> Result<(), String> {
    let p = |v: u32| d.points()[v as usize];
    for [a, b, c] in d.hull_triangles() {
        if let Some(v) = d.points().iter().position(|&x| orient3d(p(a), p(b), p(c), x) == Sign::Positive) {
            return Err(format!("point {v} is outside the hull triangle {:?}", [a, b, c]));
        }
    }
    Ok(())
}

/// The tetrahedra by their corners' coordinates, each sorted and all sorted: the same for
/// the same triangulation whatever the numbering of vertices and slots.
fn tets_by_corners(d: &Delaunay) -> Vec<[[u64; 3]; 4]> {
    let corner = |v: u32| d.points()[v as usize].to_array().map(f64::to_bits);
    let mut tets: Vec<[[u64; 3]; 4]> = d
        .tets()
        .map(|t| {
            let mut corners = t.map(corner);
            corners.sort_unstable();
            corners
        })
        .collect();
    tets.sort_unstable();
    tets
}

/// The tetrahedralisation of `points`; none when they are all in one plane (a few grid or
/// sphere nodes can be), which is then checked.
fn tetrahedralise(points: &[DVec3]) -> Result<Option<Delaunay>, TestCaseError> {
    match Delaunay::new(points) {
        Ok(d) => Ok(Some(d)),
        Err(DelaunayError::Flat(_)) => {
            let n = points.len();
            let spans = |i: usize, j: usize, k: usize| {
                (k + 1..n).any(|l| orient3d(points[i], points[j], points[k], points[l]) != Sign::Zero)
            };
            let tetrahedron = (0..n).any(|i| (i + 1..n).any(|j| (j + 1..n).any(|k| spans(i, j, k))));
            prop_assert!(!tetrahedron, "four of the points refused as flat span a tetrahedron");
            Ok(None)
        }
        Err(e) => Err(TestCaseError::fail(e.to_string())),
    }
}

fn cloud_strategy() -> impl Strategy<Value = Cloud> {
    prop_oneof![
        Just(Cloud::Uniform),
        Just(Cloud::Clustered),
        Just(Cloud::Sphere),
        Just(Cloud::Grid),
        Just(Cloud::Duplicated),
        Just(Cloud::Slab),
        Just(Cloud::IntegerSphere),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    /// Small clouds of every kind: positive, linked, Delaunay by brute force, filling the
    /// hull, every point a vertex or a duplicate, nothing to repair.
    #[test]
    fn small_clouds_are_delaunay(kind in cloud_strategy(), n in 5usize..=60, seed in any::<u64>()) {
        let points = cloud(kind, n, seed);
        let Some(d) = tetrahedralise(&points)? else { return Ok(()) };
        prop_assert_eq!(check(&d, true), Ok(()));
        prop_assert_eq!(d.cavity_repairs(), 0);
    }

    /// Inserted one by one in the input's order, the points give the same tetrahedra as bulk
    /// insertion in its own order: the perturbation makes the tetrahedralisation unique.
    #[test]
    fn one_by_one_gives_the_bulk_result(kind in cloud_strategy(), n in 8usize..=60, seed in any::<u64>()) {
        let points = cloud(kind, n, seed);
        let Some(bulk) = tetrahedralise(&points)? else { return Ok(()) };
        let start = first_tetrahedron(&points).expect("not flat");
        let mut one = Delaunay::new(&start.map(|v| points[v as usize])).expect("a tetrahedron");
        for v in (0..n as u32).filter(|v| !start.contains(v)) {
            match one.insert(points[v as usize]) {
                Ok(_) => {}
                Err(InsertError::Duplicate(of)) => prop_assert_eq!(one.points()[of as usize], points[v as usize]),
                Err(e) => return Err(TestCaseError::fail(e.to_string())),
            }
        }
        prop_assert_eq!(check(&one, false), Ok(()));
        prop_assert_eq!(tets_by_corners(&one), tets_by_corners(&bulk));
    }
}

#[test]
fn faces_point_to_their_vertex() {
    let corners = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    for (i, face) in FACES.iter().enumerate() {
        let [a, b, c] = face.map(|l| corners[l]);
        assert_eq!(orient3d(a, b, c, corners[i]), Sign::Positive, "face {i}");
        assert!(!face.contains(&i));
    }
}

#[test]
fn larger_clouds_are_locally_delaunay() {
    for (kind, n) in [
        (Cloud::Uniform, 5000),
        (Cloud::Clustered, 3000),
        (Cloud::Sphere, 3000),
        (Cloud::Duplicated, 3000),
        (Cloud::Slab, 2000),
    ] {
        let d = Delaunay::new(&cloud(kind, n, 7)).expect("a tetrahedralisation");
        assert_eq!(check(&d, false), Ok(()), "{kind:?}");
        assert_eq!(d.cavity_repairs(), 0, "{kind:?}");
    }
}

/// A 12 x 12 x 12 grid: every cube's eight corners on one sphere, and many points on every
/// hull face; the hull is the cube (volume 11^3).
#[test]
fn cubic_grid_is_delaunay() {
    let d = Delaunay::new(&grid(12)).expect("a tetrahedralisation");
    assert_eq!(check(&d, false), Ok(()));
    let volume: f64 = d
        .tets()
        .map(|t| t.map(|v| d.points()[v as usize]))
        .map(|[a, b, c, e]| tet_signed_volume(a, b, c, e))
        .sum();
    assert!((volume - 1331.0).abs() < 1e-9, "{volume}");
    assert_eq!(d.cavity_repairs(), 0);
}

#[test]
fn the_same_points_give_the_same_tetrahedra() {
    for kind in [Cloud::Uniform, Cloud::Grid, Cloud::Duplicated] {
        let points = cloud(kind, 2000, 3);
        let first: Vec<[u32; 4]> = Delaunay::new(&points).unwrap().tets().collect();
        let second: Vec<[u32; 4]> = Delaunay::new(&points).unwrap().tets().collect();
        assert_eq!(first, second, "{kind:?}");
    }
}

/// A start that is flat for a while: many points on a line, then on a plane, before the only
/// point off it.
#[test]
fn degenerate_starts_find_a_tetrahedron() {
    let mut points: Vec<DVec3> = (0..100).map(|i| DVec3::new(i as f64, 0.0, 0.0)).collect();
    points.extend((0..100).map(|i| DVec3::new((i % 10) as f64, (i / 10) as f64, 0.0)));
    points.push(DVec3::new(0.5, 0.5, 1.0));
    let first = first_tetrahedron(&points).expect("one point off the plane");
    assert_eq!(first, [0, 1, 110, 200], "the first two, the first off their line, the first off the plane");
    let d = Delaunay::new(&points).expect("one point off the plane");
    assert_eq!(check(&d, true), Ok(()));
    // The points of the plane that coincide with the line's are duplicates.
    assert_eq!(d.duplicates().len(), 10);
}

#[test]
fn flat_or_bad_inputs_are_refused() {
    let plane: Vec<DVec3> = (0..50).map(|i| DVec3::new((i % 7) as f64, (i / 7) as f64, 0.0)).collect();
    assert_eq!(Delaunay::new(&plane).unwrap_err(), DelaunayError::Flat(50));
    assert_eq!(Delaunay::new(&plane[..3]).unwrap_err(), DelaunayError::Flat(3));
    assert_eq!(Delaunay::new(&[]).unwrap_err(), DelaunayError::Flat(0));
    let line: Vec<DVec3> = (0..9).map(|i| DVec3::splat(i as f64)).collect();
    assert_eq!(Delaunay::new(&line).unwrap_err(), DelaunayError::Flat(9));
    let mut bad = plane.clone();
    bad[7].y = f64::NAN;
    assert_eq!(Delaunay::new(&bad).unwrap_err(), DelaunayError::NotFinite(7));
}

#[test]
fn insert_numbers_points_and_refuses_duplicates() {
    let corners = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    let mut d = Delaunay::new(&corners).unwrap();
    assert_eq!(d.tets().count(), 1);
    assert_eq!(d.insert(DVec3::splat(0.2)), Ok(4));
    assert_eq!(d.tets().count(), 4);
    assert_eq!(d.insert(DVec3::X), Err(InsertError::Duplicate(1)));
    assert_eq!(d.insert(DVec3::splat(f64::INFINITY)), Err(InsertError::NotFinite));
    // Outside the hull, then in the plane of a hull face, then on a hull edge.
    assert_eq!(d.insert(DVec3::splat(2.0)), Ok(5));
    assert_eq!(d.insert(DVec3::new(2.0, -1.0, 0.0)), Ok(6));
    assert_eq!(d.insert(DVec3::new(0.0, 0.5, 0.0)), Ok(7));
    assert_eq!(check(&d, true), Ok(()));
}

/// The improvement operators run on the tetrahedra (every point fixed: flips and edge
/// removals only): they stay positive and fill the hull.
#[test]
fn tet_mesh_gets_every_tetrahedron() {
    let d = Delaunay::new(&cloud(Cloud::Uniform, 300, 11)).unwrap();
    let mut mesh = d.to_tet_mesh(300);
    let mut from_mesh: Vec<[u32; 4]> = mesh.tets().collect();
    let mut ours: Vec<[u32; 4]> = d.tets().collect();
    from_mesh.sort_unstable();
    ours.sort_unstable();
    assert_eq!(from_mesh, ours);
    let volume = |tets: &[[u32; 4]]| -> f64 {
        let corners = |t: &[u32; 4]| t.map(|v| d.points()[v as usize]);
        tets.iter().map(corners).map(|[a, b, c, e]| tet_signed_volume(a, b, c, e)).sum()
    };
    let options = crate::fill::improve::ImproveOptions { insert_points: false, ..Default::default() };
    let stats = mesh.improve(&options);
    let (points, tets) = mesh.into_parts();
    assert_eq!(points, d.points());
    let positive = |t: &[u32; 4]| {
        let [a, b, c, e] = t.map(|v| points[v as usize]);
        orient3d(a, b, c, e) == Sign::Positive
    };
    assert!(tets.iter().all(positive), "{stats:?}");
    assert!(stats.flips_23 + stats.flips_32 + stats.flips_44 + stats.edge_removals > 0, "{stats:?}");
    let (before, after) = (volume(&ours), volume(&tets));
    assert!((after - before).abs() < 1e-12 * before, "{before} -> {after}");
}

/// On points in general position the Delaunay tetrahedralisation is unique: TetGen's is ours.
#[cfg(feature = "tetgen")]
#[test]
fn tetgen_finds_the_same_tetrahedra() {
    let points = cloud(Cloud::Uniform, 2000, 5);
    let ours = Delaunay::new(&points).unwrap();
    let theirs = crate::fill::tetgen::delaunay_of_points(&points).expect("TetGen runs");
    let corner = |v: u32| points[v as usize].to_array().map(f64::to_bits);
    let mut by_corners: Vec<[[u64; 3]; 4]> = theirs
        .iter()
        .map(|t| {
            let [a, b, c, e] = t.map(|v| points[v as usize]);
            assert_eq!(orient3d(a, b, c, e), Sign::Positive, "TetGen's orientation is ours");
            let mut corners = t.map(corner);
            corners.sort_unstable();
            corners
        })
        .collect();
    by_corners.sort_unstable();
    assert_eq!(tets_by_corners(&ours), by_corners);
}
