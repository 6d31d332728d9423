//! Tests of the MSH reader and writer.

use super::*;
use crate::io::Location;
use crate::quality::{check, samples::hybrid_column};

fn write_to_vec(mesh: &VolumeMesh, ascii: bool) -> Vec<u8> {
    let mut bytes = Vec::new();
    write(&mut bytes, mesh, ascii).unwrap();
    bytes
}

#[test]
fn round_trip_ascii_and_binary() {
    let mesh = hybrid_column();
    for ascii in [true, false] {
        let bytes = write_to_vec(&mesh, ascii);
        let back = parse_volume(&bytes).unwrap();
        assert_eq!(back.points, mesh.points);
        for kind in crate::mesh::CellKind::ALL {
            assert_eq!(back.block(kind).nodes, mesh.block(kind).nodes, "{kind:?}");
            assert_eq!(back.block(kind).zone, mesh.block(kind).zone, "{kind:?}");
        }
        assert_eq!(back.patch_names, mesh.patch_names);
        assert_eq!(back.zone_names, mesh.zone_names);
        let r = check(&back);
        assert!(r.is_valid(), "{r}");
        assert_eq!(r.patches, check(&mesh).patches);
    }
}

/// A tetrahedron with sparse, unordered node tags, a point and a line element to skip, an
/// unknown section, a parametric node block, and faces in a named, an unnamed and no group.
const GMSH41: &str = r#"$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
2 7 "wall left"
3 9 "fluid"
$EndPhysicalNames
$Comments
anything, even $Nodes
$EndComments
$Entities
1 0 3 1
1 0 0 0 0
1 0 0 0 1 1 1 1 7 0
2 0 0 0 1 1 1 1 8 0
4 0 0 0 1 1 1 0 0
3 0 0 0 1 1 1 1 9 2 1 2
$EndEntities
$Nodes
3 5 5 40
0 1 0 1
5
0 0 0
2 1 1 2
10
20
0 0 0 0.1 0.2
1 0 0 0.3 0.4
3 3 0 2
40
30
0 0 1
0 1 0
$EndNodes
$Elements
6 7 100 106
0 1 15 1
100 5
1 1 1 1
101 10 20
2 1 2 1
102 10 30 20
2 2 2 1
103 10 20 40
3 3 4 1
104 10 20 30 40
2 4 2 2
105 20 30 40
106 10 40 30
$EndElements
"#;

const GMSH22: &str = r#"$MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
1
2 7 "wall left"
$EndPhysicalNames
$Nodes
4
10 0 0 0
20 1 0 0
30 0 1 0
40 0 0 1
$EndNodes
$Elements
7
1 15 2 0 1 10
2 1 2 0 1 10 20
3 2 2 7 1 10 30 20
4 2 2 8 2 10 20 40
5 4 2 9 3 10 20 30 40
6 2 2 0 4 20 30 40
7 2 2 0 4 10 40 30
$EndElements
"#;

#[test]
fn gmsh_41_ascii_with_sparse_tags_and_groups() {
    let mesh = parse_volume(GMSH41.as_bytes()).unwrap();
    assert_eq!(mesh.points.len(), 5);
    assert_eq!(mesh.block(crate::mesh::CellKind::Tetrahedron).nodes, [1, 2, 4, 3]);
    assert_eq!(mesh.patch_names, ["wall left", "physical_8", "surface_4"]);
    assert_eq!(mesh.boundary.triangle_patch, [0, 1, 2, 2]);
    assert_eq!(mesh.zone_names, ["fluid"]);
    let r = check(&mesh);
    assert!(r.is_valid(), "{r}");
    assert_eq!(r.unused_points, 1);
}

#[test]
fn unknown_element_types_are_skipped_in_text() {
    let unknown = "0 1 15 1\n100 5\n0 1 99 2\n200 1 2 3 4 5 6 7\n201 1 2 3 4 5 6 7\n";
    let mesh = parse_volume(
        GMSH41.replace("6 7 100 106", "7 9 100 201").replace("0 1 15 1\n100 5\n", unknown).as_bytes(),
    );
    assert!(check(&mesh.unwrap()).is_valid());
    let mesh = parse_volume(
        GMSH22.replace("7\n1 15 2 0 1 10", "8\n0 99 2 0 1 1 2 3 4 5 6 7\n1 15 2 0 1 10").as_bytes(),
    );
    assert!(check(&mesh.unwrap()).is_valid());
}

#[test]
fn gmsh_22_ascii() {
    let mesh = parse_volume(GMSH22.as_bytes()).unwrap();
    assert_eq!(mesh.patch_names, ["wall left", "physical_8", "surface_4"]);
    assert_eq!(mesh.zone_names, ["physical_9"]);
    assert!(check(&mesh).is_valid());
}

#[test]
fn surfaces_keep_only_used_points() {
    let s = parse_surface(GMSH41.as_bytes()).unwrap();
    assert_eq!((s.points.len(), s.triangles.len()), (4, 4));
    assert!(s.enclosed_volume() > 0.0);
    let s = parse_surface(&write_to_vec(&hybrid_column(), true)).unwrap();
    assert_eq!((s.points.len(), s.triangles.len()), (20, 10 + 2 * 13));
    assert_eq!(s.patch_names, ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"]);
    assert!((s.enclosed_volume() - 4.0).abs() < 1e-12);
}

/// A value of a hand-made binary file.
enum V {
    I(i32),
    S(u64),
    D(f64),
    T(&'static str),
}

fn binary(big_endian: bool, parts: &[V]) -> Vec<u8> {
    let mut out = Vec::new();
    for p in parts {
        match *p {
            V::I(v) => out.extend(if big_endian { v.to_be_bytes() } else { v.to_le_bytes() }),
            V::S(v) => out.extend(if big_endian { v.to_be_bytes() } else { v.to_le_bytes() }),
            V::D(v) => out.extend(if big_endian { v.to_be_bytes() } else { v.to_le_bytes() }),
            V::T(t) => out.extend_from_slice(t.as_bytes()),
        }
    }
    out
}

fn unit_tet_41(big_endian: bool) -> Vec<u8> {
    use V::*;
    let mut parts = vec![T("$MeshFormat\n4.1 1 8\n"), I(1), T("\n$EndMeshFormat\n$Nodes\n")];
    parts.extend([S(1), S(4), S(10), S(40), I(3), I(3), I(0), S(4), S(10), S(20), S(30), S(40)]);
    for x in [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0] {
        parts.push(D(x));
    }
    parts.extend([T("\n$EndNodes\n$Elements\n"), S(1), S(1), S(1), S(1), I(3), I(3), I(4), S(1)]);
    parts.extend([S(1), S(10), S(20), S(30), S(40), T("\n$EndElements\n")]);
    binary(big_endian, &parts)
}

fn unit_tet_22(big_endian: bool) -> Vec<u8> {
    use V::*;
    let mut parts = vec![T("$MeshFormat\n2.2 1 8\n"), I(1), T("\n$EndMeshFormat\n$Nodes\n4\n")];
    for (tag, x) in
        [(10, [0.0, 0.0, 0.0]), (20, [1.0, 0.0, 0.0]), (30, [0.0, 1.0, 0.0]), (40, [0.0, 0.0, 1.0])]
    {
        parts.extend([I(tag), D(x[0]), D(x[1]), D(x[2])]);
    }
    parts.extend([T("\n$EndNodes\n$Elements\n1\n"), I(4), I(1), I(2), I(5), I(0), I(3)]);
    parts.extend([I(10), I(20), I(30), I(40), T("\n$EndElements\n")]);
    binary(big_endian, &parts)
}

#[test]
fn binary_files_of_either_byte_order() {
    for big_endian in [false, true] {
        for bytes in [unit_tet_41(big_endian), unit_tet_22(big_endian)] {
            let mesh = parse_volume(&bytes).unwrap();
            let r = check(&mesh);
            assert!(r.is_valid() && r.conformity.free_faces_taken_as_boundary, "{r}");
            assert!((r.volume.cells - 1.0 / 6.0).abs() < 1e-15);
        }
    }
}

fn error(text: &str) -> ParseError {
    parse_volume(text.as_bytes()).unwrap_err()
}

#[test]
fn errors_name_the_problem_and_the_line() {
    let e = error(&GMSH41.replace("104 10 20 30 40", "104 10 20 30 99"));
    assert_eq!(e.at, Location::Line(47), "{e}");
    assert!(e.message.contains("node 99"), "{e}");
    let e = error(&GMSH41.replace("3 3 4 1\n104 10 20 30 40", "3 3 11 1\n104 10 20 30 40 1 2 3 4 5 6"));
    assert!(e.message.contains("higher-order tetrahedron"), "{e}");
    let e = error(&GMSH41[..GMSH41.find("105 20").unwrap()]);
    assert!(e.at == Location::Line(49) && e.message.contains("end of the file"), "{e}");
    let e = error(&GMSH41.replace("4.1 0 8", "4 0 8"));
    assert!(e.message.contains("MSH 4.0"), "{e}");
    assert!(error("hello").message.contains("expected a section"));
    assert!(error("").message.contains("no $MeshFormat"));
    let e = error(&GMSH22.replace("30 0 1 0", "20 0 1 0"));
    assert!(e.message.contains("node tag 20 appears twice"), "{e}");
    let e = error(&GMSH22.replace("$EndNodes", "$EndNode"));
    assert!(e.message.contains("expected $EndNodes"), "{e}");
    let surface_only = GMSH22.replace("5 4 2 9 3 10 20 30 40", "5 15 2 0 1 10");
    assert!(error(&surface_only).message.contains("no volume elements"));
}

#[test]
fn truncated_binary_files_fail_at_a_byte_offset() {
    let bytes = write_to_vec(&hybrid_column(), false);
    let header = b"$MeshFormat\n4.1 1 8\n".len();
    for cut in (header..bytes.len() - 1).step_by(7) {
        // A cut between two sections leaves a whole file without cells (a file-level error).
        match parse_volume(&bytes[..cut]) {
            Err(ParseError { at: Location::Byte(b), .. }) => assert!(b as usize <= cut),
            Err(ParseError { at: Location::File, message }) => {
                assert!(message.contains("no volume elements"))
            }
            other => panic!("cut at {cut}: {other:?}"),
        }
    }
}

proptest::proptest! {
    #[test]
    fn arbitrary_damage_never_panics(
        cut in 0usize..4000,
        flips in proptest::collection::vec((0usize..4000, 0u8..=255), 0..4),
    ) {
        let files = [GMSH41.as_bytes().to_vec(), write_to_vec(&hybrid_column(), false), unit_tet_22(true)];
        for mut bytes in files {
            for &(at, b) in &flips {
                let n = bytes.len();
                bytes[at % n] = b;
            }
            bytes.truncate(cut.min(bytes.len()));
            let _ = parse_volume(&bytes);
            let _ = parse_surface(&bytes);
        }
    }
}
