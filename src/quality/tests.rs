//! Tests of the checker on meshes built in code: valid ones pass with the exact volume, and every
//! kind of defect is found and named.

use proptest::prelude::*;

use super::samples::{cube_grid, hybrid_column, CubeSplit};
use super::*;
use crate::geometry::DVec3;
use crate::mesh::{BoundaryFaces, CellBlock};

fn problems(r: &CheckReport, p: FaceProblem) -> usize {
    r.conformity.by_problem.get(&p).copied().unwrap_or(0)
}

/// Reverse the orientation of a cell of any kind (a mirrored node order).
fn flip(kind: CellKind, nodes: &mut [u32]) {
    let perm: &[usize] = match kind {
        CellKind::Tetrahedron => &[0, 2, 1, 3],
        CellKind::Pyramid => &[0, 3, 2, 1, 4],
        CellKind::Prism => &[3, 4, 5, 0, 1, 2],
        CellKind::Hexahedron => &[4, 5, 6, 7, 0, 1, 2, 3],
    };
    let old = nodes.to_vec();
    for (n, &p) in nodes.iter_mut().zip(perm) {
        *n = old[p];
    }
}

fn remove_cell(mesh: &mut VolumeMesh, kind: CellKind, index: usize) {
    let b = mesh.block_mut(kind);
    let n = kind.node_count();
    b.nodes.drain(index * n..(index + 1) * n);
    b.zone.remove(index);
}

#[test]
fn hybrid_column_is_valid_with_the_exact_volume() {
    let mesh = hybrid_column();
    let r = check(&mesh);
    assert!(r.is_valid(), "{r}");
    assert_eq!(r.cells, PerKind { tetrahedron: 8, pyramid: 5, prism: 2, hexahedron: 1 });
    assert!((r.volume.cells - 4.0).abs() < 1e-14 && (r.volume.enclosed - 4.0).abs() < 1e-14, "{r}");
    // hex|centre 1, centre cube 12 + 1, centre|prisms 2, prisms 1, prisms|tets 2, tets 6.
    assert_eq!(r.conformity.interior_faces, 25, "{r}");
    let side: Vec<(usize, usize)> = r.patches.iter().map(|p| (p.triangles, p.quads)).collect();
    // x/y sides: the hexahedron, centre cube and prisms give a quad each, the tetrahedra two
    // triangles; the bottom is the hexahedron's quad, the top the tetrahedra's triangles.
    assert_eq!(side, [(2, 3), (2, 3), (2, 3), (2, 3), (0, 1), (2, 0)]);
    assert_eq!(r.unused_points, 0);
    assert!(r.warnings.is_empty(), "{r}");
    let text = r.to_string();
    assert!(text.contains("VALID") && !text.contains("INVALID"), "{text}");
    let json = serde_json::to_value(&r).unwrap();
    assert_eq!(json["cells"]["pyramid"], 5);
}

#[test]
fn quality_of_the_hybrid_column() {
    let r = check(&hybrid_column());
    let hex = r.quality.get(CellKind::Hexahedron);
    assert_eq!((hex.scaled_jacobian.min, hex.scaled_jacobian.max), (1.0, 1.0));
    assert_eq!(hex.scaled_jacobian.histogram[10], 1);
    assert!((hex.dihedral_deg[0] - 90.0).abs() < 1e-12);
    let prism = r.quality.get(CellKind::Prism);
    assert!((prism.scaled_jacobian.min - 0.5f64.sqrt()).abs() < 1e-12);
    let tet = r.quality.get(CellKind::Tetrahedron);
    assert!(tet.scaled_jacobian.min > 0.0 && tet.scaled_jacobian.max <= 1.0);
    assert!(tet.dihedral_deg[0] > 0.0 && tet.dihedral_deg[1] < 180.0);
    assert_eq!(tet.scaled_jacobian.histogram.iter().sum::<usize>(), 8);
}

#[test]
fn an_inverted_tetrahedron_is_found() {
    let mut mesh = hybrid_column();
    flip(CellKind::Tetrahedron, &mut mesh.block_mut(CellKind::Tetrahedron).nodes[0..4]);
    let r = check(&mesh);
    assert!(!r.is_valid());
    assert_eq!(r.validity.invalid_cells, 1);
    assert_eq!((r.validity.inverted_corners, r.validity.nonpositive_decomposition), (1, 1));
    let e = &r.validity.examples[0];
    assert_eq!(e.cell, CellRef { kind: CellKind::Tetrahedron, index: 0 });
    assert!(e.problem.contains("negative"), "{}", e.problem);
    assert_eq!(e.points.len(), 4);
    assert!(r.to_string().contains("tetrahedron 0 nodes"), "{r}");
    // Its faces now run the same way as its neighbours' and the boundary's.
    assert!(problems(&r, FaceProblem::DoubledFace) + problems(&r, FaceProblem::InvertedBoundaryFace) > 0);
}

#[test]
fn a_removed_interior_cell_leaves_a_hole() {
    let mut mesh = cube_grid([3, 3, 3], DVec3::ONE, &|_| CubeSplit::Tetrahedra, &|_| 0);
    // Cube (1, 1, 1) is the 14th; its first tetrahedron touches no boundary.
    remove_cell(&mut mesh, CellKind::Tetrahedron, 13 * 6);
    let r = check(&mesh);
    assert!(!r.is_valid());
    assert_eq!(problems(&r, FaceProblem::Hole), 4, "{r}");
    assert_eq!(r.conformity.errors, 4);
    assert!(r.volume_identity_holds(), "the hole's walls close the free surface");
    assert!((r.volume.cells - 27.0 + 1.0 / 6.0).abs() < 1e-12);
    assert!(r.to_string().contains("hole"), "{r}");
}

#[test]
fn a_doubled_element_is_found() {
    let mut mesh = hybrid_column();
    let hex: Vec<u32> = mesh.block(CellKind::Hexahedron).cell(0).to_vec();
    mesh.push_cell(CellKind::Hexahedron, &hex, 0);
    let r = check(&mesh);
    assert!(!r.is_valid());
    assert_eq!(r.validity.invalid_cells, 0);
    assert_eq!(problems(&r, FaceProblem::DoubledFace), 5, "{r}");
    assert_eq!(problems(&r, FaceProblem::NonManifoldFace), 1, "{r}");
    assert!(!r.volume_identity_holds());
}

/// A prism over the triangle (0,0), (1,0), (0,1), z in [0, 1], and two tetrahedra behind its
/// y = 0 quad that cut it into two triangles.
fn prism_next_to_two_tets() -> VolumeMesh {
    let mut mesh = VolumeMesh::default();
    let p =
        [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.], [1., 0., 1.], [0., 1., 1.], [0.5, -1., 0.5]];
    mesh.points = p.iter().map(|q| DVec3::from_array(*q)).collect();
    mesh.push_cell(CellKind::Prism, &[0, 1, 2, 3, 4, 5], 0);
    mesh.push_cell(CellKind::Tetrahedron, &[0, 1, 4, 6], 0);
    mesh.push_cell(CellKind::Tetrahedron, &[0, 4, 3, 6], 0);
    mesh.zone_names = vec!["fluid".into()];
    mesh
}

#[test]
fn a_non_matching_quad_split_is_named() {
    let mesh = prism_next_to_two_tets();
    let r = check(&mesh);
    assert_eq!(r.validity.invalid_cells, 0, "{r}");
    assert!(r.conformity.free_faces_taken_as_boundary);
    assert_eq!(problems(&r, FaceProblem::NonMatchingQuadSplit), 1, "{r}");
    assert_eq!(r.conformity.errors, 1, "{r}");
    let e = &r.conformity.examples[0];
    assert_eq!(e.cells.len(), 3);
    assert_eq!(e.centre, Some([0.5, 0.0, 0.5]));
    assert!(!r.is_valid());
    assert!(r.to_string().contains("non-matching quad split"), "{r}");
}

#[test]
fn prisms_ordered_the_wrong_way_are_invalid() {
    for nodes in [[0, 2, 1, 3, 5, 4], [0, 2, 1, 3, 4, 5], [3, 4, 5, 0, 1, 2]] {
        let mut mesh = prism_next_to_two_tets();
        mesh.blocks[CellKind::Prism as usize].nodes = nodes.to_vec();
        let r = check(&mesh);
        assert_eq!(r.validity.invalid_cells, 1, "{nodes:?}: {r}");
        assert!(r.validity.examples[0].problem.contains("corner tetrahedron"), "{r}");
        assert!(!r.is_valid());
    }
}

#[test]
fn boundary_face_problems_are_named() {
    let mut mesh = hybrid_column();
    mesh.boundary.triangles[0].swap(1, 2);
    let r = check(&mesh);
    assert_eq!((problems(&r, FaceProblem::InvertedBoundaryFace), r.conformity.errors), (1, 1), "{r}");

    let mut mesh = hybrid_column();
    let extra = mesh.boundary.quads[0];
    mesh.boundary.quads.push(extra);
    mesh.boundary.quad_patch.push(0);
    mesh.boundary.triangles.push([0, 1, 6]);
    mesh.boundary.triangle_patch.push(1);
    let r = check(&mesh);
    assert_eq!(problems(&r, FaceProblem::DuplicateBoundaryFace), 1, "{r}");
    assert_eq!(problems(&r, FaceProblem::BoundaryFaceNotCovered), 1, "{r}");
    assert_eq!(r.patches[0].quads, 4);
}

#[test]
fn without_boundary_faces_the_free_faces_are_the_boundary() {
    let mut mesh = hybrid_column();
    mesh.boundary = BoundaryFaces::default();
    let r = check(&mesh);
    assert!(r.is_valid(), "{r}");
    assert!(r.conformity.free_faces_taken_as_boundary);
    assert_eq!((r.conformity.free_triangles, r.conformity.free_quads), (10, 13));
    assert!(r.warnings[0].contains("taken as its boundary"), "{r}");
}

#[test]
fn bad_indices_are_reported_without_panicking() {
    let mut mesh = hybrid_column();
    mesh.points.push(DVec3::splat(9.0));
    mesh.block_mut(CellKind::Tetrahedron).nodes[0] = 1000;
    mesh.boundary.triangle_patch[0] = 77;
    mesh.boundary.quads[0][0] = 5000;
    mesh.block_mut(CellKind::Prism).zone[0] = 9;
    mesh.block_mut(CellKind::Pyramid).nodes.pop();
    let r = check(&mesh);
    assert!(!r.is_valid());
    assert_eq!(r.validity.nodes_out_of_range, 1);
    assert_eq!(r.structure_errors.len(), 4, "{:?}", r.structure_errors);
    assert_eq!(r.unused_points, 1);
    let _ = r.to_string();
}

#[test]
fn an_empty_mesh_is_not_valid() {
    let r = check(&VolumeMesh::default());
    assert!(!r.is_valid());
    assert_eq!(r.volume.relative_difference, 0.0);
}

/// A small xorshift generator: proptest picks the seed, so failures shrink and replay.
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % n.max(1) as u64) as usize
    }

    fn permutation(&mut self, n: usize) -> Vec<usize> {
        let mut p: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            p.swap(i, self.below(i + 1));
        }
        p
    }
}

/// The same mesh with points, cells and boundary faces renumbered at random, tetrahedra rotated.
fn shuffle(mesh: &VolumeMesh, rng: &mut Rng) -> VolumeMesh {
    let order = rng.permutation(mesh.points.len());
    let mut new_index = vec![0u32; order.len()];
    for (new, &old) in order.iter().enumerate() {
        new_index[old] = new as u32;
    }
    let renumber = |n: u32| new_index[n as usize];
    let mut out = VolumeMesh {
        points: order.iter().map(|&o| mesh.points[o]).collect(),
        zone_names: mesh.zone_names.clone(),
        patch_names: mesh.patch_names.clone(),
        ..Default::default()
    };
    for block in &mesh.blocks {
        let mut shuffled = CellBlock::new(block.kind);
        for i in rng.permutation(block.len()) {
            let mut cell: Vec<u32> = block.cell(i).iter().map(|&n| renumber(n)).collect();
            if block.kind == CellKind::Tetrahedron {
                let r = rng.below(3);
                cell[..3].rotate_left(r);
            }
            shuffled.push(&cell, block.zone[i]);
        }
        out.blocks[block.kind as usize] = shuffled;
    }
    let b = &mesh.boundary;
    for i in rng.permutation(b.triangles.len()) {
        out.boundary.triangles.push(b.triangles[i].map(renumber));
        out.boundary.triangle_patch.push(b.triangle_patch[i]);
    }
    for i in rng.permutation(b.quads.len()) {
        let mut q = b.quads[i].map(renumber);
        q.rotate_left(rng.below(4));
        out.boundary.quads.push(q);
        out.boundary.quad_patch.push(b.quad_patch[i]);
    }
    out
}

fn random_grid(dims: [usize; 3], spacing: [f64; 3], splits: &[usize]) -> VolumeMesh {
    let split = |c: [usize; 3]| CubeSplit::ALL[splits[(c[0] + 3 * (c[1] + 3 * c[2])) % splits.len()] % 4];
    cube_grid(dims, DVec3::from_array(spacing), &split, &|c| (c[2] % 2) as u32)
}

/// (kind, index) of the cell with the given global number.
fn nth_cell(mesh: &VolumeMesh, mut n: usize) -> (CellKind, usize) {
    for kind in CellKind::ALL {
        let len = mesh.block(kind).len();
        if n < len {
            return (kind, n);
        }
        n -= len;
    }
    unreachable!("cell number past the end")
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_cube_grids_pass_and_each_defect_fails(
        dims in proptest::array::uniform3(1usize..=3),
        spacing in proptest::array::uniform3(0.01f64..100.0),
        splits in proptest::collection::vec(0usize..4, 27),
        seed in 1u64..u64::MAX,
        pick in 0usize..10_000,
    ) {
        let mut rng = Rng(seed);
        let mesh = shuffle(&random_grid(dims, spacing, &splits), &mut rng);
        let r = check(&mesh);
        prop_assert!(r.is_valid(), "{}", r);
        let box_volume = dims.iter().zip(spacing).map(|(&n, h)| n as f64 * h).product::<f64>();
        prop_assert!((r.volume.cells - box_volume).abs() <= 1e-12 * box_volume, "{}", r);

        let (kind, index) = nth_cell(&mesh, pick % mesh.cell_count());
        let mut removed = mesh.clone();
        remove_cell(&mut removed, kind, index);
        prop_assert!(!check(&removed).is_valid());

        let mut flipped = mesh.clone();
        let n = kind.node_count();
        flip(kind, &mut flipped.block_mut(kind).nodes[index * n..(index + 1) * n]);
        let r = check(&flipped);
        prop_assert!(!r.is_valid());
        prop_assert_eq!(r.validity.invalid_cells, 1);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// The face-pyramid cells of the finite-volume measures fill the box exactly, and a valid
    /// grid has no wrong face pyramid and no open cell.
    #[test]
    fn finite_volume_cells_add_up_to_the_mesh_volume(
        dims in proptest::array::uniform3(1usize..=3),
        spacing in proptest::array::uniform3(0.01f64..100.0),
        splits in proptest::collection::vec(0usize..4, 27),
        seed in 1u64..u64::MAX,
    ) {
        let mesh = shuffle(&random_grid(dims, spacing, &splits), &mut Rng(seed));
        let cells = super::fv::cell_geometries(&mesh);
        let sum: f64 = cells.iter().map(|c| c.volume).sum();
        let box_volume = dims.iter().zip(spacing).map(|(&n, h)| n as f64 * h).product::<f64>();
        prop_assert!((sum - box_volume).abs() <= 1e-12 * box_volume, "{sum} against {box_volume}");
        let fv = check(&mesh).fv;
        prop_assert_eq!(fv.wrong_face_pyramids, 0);
        prop_assert!(fv.non_orthogonality_max < 90.0 && fv.cell_openness_max < 1e-12, "{}", fv);
        prop_assert_eq!(fv.faces, crate::mesh::FaceTable::new(&mesh).len());
    }
}

#[test]
fn the_report_serialises_the_finite_volume_measures() {
    let json = serde_json::to_value(check(&hybrid_column())).unwrap();
    let fv = &json["fv"];
    for key in [
        "faces",
        "non_orthogonality_max",
        "non_orthogonality_mean",
        "faces_above_70",
        "faces_above_80",
        "faces_above_85",
        "skewness_max",
        "faces_skewness_above_4",
        "wrong_face_pyramids",
        "worst_non_orthogonality",
    ] {
        assert!(fv.get(key).is_some(), "no fv.{key} in {fv}");
    }
    assert!(fv["worst_skewness"][0]["centre"].is_array() && fv["worst_skewness"][0]["owner"].is_string());
}

/// `cargo test --release -- --ignored one_million_cells --nocapture` prints the time to check
/// about a million cells of every kind.
#[test]
#[ignore]
fn one_million_cells() {
    let splits = |c: [usize; 3]| CubeSplit::ALL[(c[0] / 8 + c[1] / 8 + c[2] / 8) % 4];
    let mesh = cube_grid([60, 60, 60], DVec3::ONE, &splits, &|_| 0);
    let t = std::time::Instant::now();
    let r = check(&mesh);
    println!("{} cells checked in {:.2} s\n{r}", mesh.cell_count(), t.elapsed().as_secs_f64());
    let t = std::time::Instant::now();
    let table = crate::mesh::FaceTable::new(&mesh);
    let table_seconds = t.elapsed().as_secs_f64();
    let fv = super::fv::measure(&mesh, &table);
    println!(
        "face table {table_seconds:.2} s, fv measures {:.2} s",
        t.elapsed().as_secs_f64() - table_seconds
    );
    assert_eq!((fv.faces, fv.non_orthogonality_max), (r.fv.faces, r.fv.non_orthogonality_max));
    assert!(r.is_valid());
}
