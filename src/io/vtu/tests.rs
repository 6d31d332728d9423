//! Tests of the VTU reader and writer.

use super::*;
use crate::quality::{check, samples::hybrid_column};

fn write_to_vec(mesh: &VolumeMesh) -> Vec<u8> {
    let mut bytes = Vec::new();
    write(&mut bytes, mesh).unwrap();
    bytes
}

#[test]
fn round_trip() {
    let mesh = hybrid_column();
    let back = parse(&write_to_vec(&mesh)).unwrap();
    assert_eq!(back.points, mesh.points);
    for kind in CellKind::ALL {
        assert_eq!(back.block(kind).nodes, mesh.block(kind).nodes, "{kind:?}");
        assert_eq!(back.block(kind).zone, mesh.block(kind).zone, "{kind:?}");
    }
    assert_eq!(back.boundary.triangles, mesh.boundary.triangles);
    assert_eq!(back.boundary.quad_patch, mesh.boundary.quad_patch);
    assert_eq!(back.zone_names, mesh.zone_names);
    assert_eq!(back.patch_names, ["patch_0", "patch_1", "patch_2", "patch_3", "patch_4", "patch_5"]);
    assert!(check(&back).is_valid());
}

/// A unit tetrahedron and one triangle as meshio 5.3.5 writes them by default (zlib, UInt32
/// headers, header and data in separate base64 pieces), with `gmsh:physical` 5 and 7.
const MESHIO_ZLIB: &str = r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian" compressor="vtkZLibDataCompressor">
<!--This file was created by meshio v5.3.5-->
<UnstructuredGrid>
<Piece NumberOfPoints="4" NumberOfCells="2">
<Points>
<DataArray type="Float64" Name="Points" NumberOfComponents="3" format="binary">
AQAAAACAAABgAAAAEgAAAA==eJxjYMAHPtjjlSZCHgB4XQOO
</DataArray>
</Points>
<Cells>
<DataArray type="Int64" Name="connectivity" format="binary">
AQAAAACAAAA4AAAAFwAAAA==eJxjYIAARijNBKWZGVABE5o6AAFAAAo=
</DataArray>
<DataArray type="Int64" Name="offsets" format="binary">
AQAAAACAAAAQAAAADgAAAA==eJxjYYAAdigNAACIAAw=
</DataArray>
<DataArray type="Int64" Name="types" format="binary">
AQAAAACAAAAQAAAADgAAAA==eJzjYoAAVigNAADYABA=
</DataArray>
</Cells>
<CellData>
<DataArray type="Int64" Name="gmsh:physical" format="binary">
AQAAAACAAAAQAAAADgAAAA==eJxjZYAAdigNAACYAA0=
</DataArray>
<DataArray type="Int64" Name="gmsh:geometrical" format="binary">
AQAAAACAAAAQAAAADgAAAA==eJxjZIAAJigNAAAwAAQ=
</DataArray>
</CellData>
</Piece>
</UnstructuredGrid>
</VTKFile>
"#;

/// The same without compression (header and data in one base64 piece).
const MESHIO_BINARY: &str = r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
<UnstructuredGrid>
<Piece NumberOfPoints="4" NumberOfCells="2">
<Points>
<DataArray type="Float64" Name="Points" NumberOfComponents="3" format="binary">
YAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAPA/AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA8D8AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAADwPw==
</DataArray>
</Points>
<Cells>
<DataArray type="Int64" Name="connectivity" format="binary">
OAAAAAAAAAAAAAAAAQAAAAAAAAACAAAAAAAAAAMAAAAAAAAAAAAAAAAAAAACAAAAAAAAAAEAAAAAAAAA
</DataArray>
<DataArray type="Int64" Name="offsets" format="binary">
EAAAAAQAAAAAAAAABwAAAAAAAAA=
</DataArray>
<DataArray type="Int64" Name="types" format="binary">
EAAAAAoAAAAAAAAABQAAAAAAAAA=
</DataArray>
</Cells>
<CellData>
<DataArray type="Int64" Name="gmsh:physical" format="binary">
EAAAAAUAAAAAAAAABwAAAAAAAAA=
</DataArray>
</CellData>
</Piece>
</UnstructuredGrid>
</VTKFile>
"#;

/// The same in ASCII with Float32 and Int32 arrays, a `cell_tags` array and a line cell to skip.
const ASCII: &str = r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
<UnstructuredGrid>
<Piece NumberOfPoints="4" NumberOfCells="3">
<Points>
<DataArray type="Float32" Name="Points" NumberOfComponents="3" format="ascii">
0 0 0 1 0 0
0 1 0 0 0 1
</DataArray>
</Points>
<Cells>
<DataArray type="Int32" Name="connectivity" format="ascii">
0 1 2 3
0 2 1
0 3
</DataArray>
<DataArray type="Int32" Name="offsets" format="ascii">4 7 9</DataArray>
<DataArray type="UInt8" Name="types" format="ascii">10 5 3</DataArray>
</Cells>
<CellData>
<DataArray type="Int32" Name="cell_tags" format="ascii">5 7 0</DataArray>
</CellData>
</Piece>
</UnstructuredGrid>
</VTKFile>
"#;

fn assert_unit_tet(mesh: &VolumeMesh) {
    assert_eq!(mesh.points.len(), 4);
    assert_eq!(mesh.block(CellKind::Tetrahedron).nodes, [0, 1, 2, 3]);
    assert_eq!(mesh.boundary.triangles, [[0, 2, 1]]);
    assert_eq!(mesh.patch_names, ["patch_7"]);
    assert_eq!(mesh.zone_names, ["zone_5"]);
    let r = check(mesh);
    assert!((r.volume.cells - 1.0 / 6.0).abs() < 1e-15, "{r}");
    assert_eq!(r.validity.invalid_cells, 0);
}

#[test]
fn meshio_files() {
    for text in [MESHIO_ZLIB, MESHIO_BINARY, ASCII] {
        assert_unit_tet(&parse(text.as_bytes()).unwrap());
    }
}

/// The unit tetrahedron with every array appended: raw bytes or base64 pieces.
fn appended(raw: bool) -> Vec<u8> {
    let b64 = |d: &[u8]| base64::Engine::encode(&base64::engine::general_purpose::STANDARD, d);
    let arrays: [(&str, &str, Vec<u8>); 4] = [
        (
            "Float64\" NumberOfComponents=\"3",
            "Points",
            [0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1.]
                .iter()
                .flat_map(|v: &f64| v.to_le_bytes())
                .collect(),
        ),
        ("Int64", "connectivity", [0i64, 1, 2, 3].iter().flat_map(|v| v.to_le_bytes()).collect()),
        ("Int64", "offsets", 4i64.to_le_bytes().to_vec()),
        ("UInt8", "types", vec![10]),
    ];
    let mut xml =
        String::from("<VTKFile type=\"UnstructuredGrid\" header_type=\"UInt64\"><UnstructuredGrid>\n");
    xml += "<Piece NumberOfPoints=\"4\" NumberOfCells=\"1\">\n";
    let mut data: Vec<u8> = Vec::new();
    for (i, (ty, name, bytes)) in arrays.iter().enumerate() {
        let section = if i == 0 { "Points" } else { "Cells" };
        let offset = data.len();
        let attributes = format!("type=\"{ty}\" Name=\"{name}\" format=\"appended\" offset=\"{offset}\"");
        xml += &format!("<{section}><DataArray {attributes}/></{section}>\n");
        let header = (bytes.len() as u64).to_le_bytes();
        if raw {
            data.extend_from_slice(&header);
            data.extend_from_slice(bytes);
        } else {
            data.extend(b64(&header).bytes());
            data.extend(b64(bytes).bytes());
        }
    }
    let encoding = if raw { "raw" } else { "base64" };
    let mut out =
        format!("{xml}</Piece></UnstructuredGrid>\n<AppendedData encoding=\"{encoding}\">\n_").into_bytes();
    out.extend_from_slice(&data);
    out.extend_from_slice(b"\n</AppendedData></VTKFile>\n");
    out
}

#[test]
fn appended_raw_and_base64() {
    for raw in [true, false] {
        let mesh = parse(&appended(raw)).unwrap();
        assert_eq!(mesh.block(CellKind::Tetrahedron).nodes, [0, 1, 2, 3]);
        assert_eq!(mesh.zone_names, ["volume"]);
        assert!(mesh.patch_names.is_empty());
        assert!(check(&mesh).is_valid());
    }
}

#[test]
fn errors_name_the_problem_and_the_line() {
    let e = parse(ASCII.replace("0 2 1\n", "0 2 9\n").as_bytes()).unwrap_err();
    assert_eq!(e.at, crate::io::Location::Line(12), "{e}");
    assert!(e.message.contains("cell 1: node 9 out of range"), "{e}");
    let e = parse(ASCII.replace("10 5 3", "10 5 42").as_bytes()).unwrap_err();
    assert!(e.message.contains("unsupported VTK cell type 42"), "{e}");
    let e = parse(ASCII.replace("4 7 9", "4 7").as_bytes()).unwrap_err();
    assert!(e.message.contains("'offsets': 2 values for 3 cells"), "{e}");
    let e = parse(
        MESHIO_ZLIB
            .replace("eJxjYIAARijNBKWZGVABE5o6AAFAAAo=", "AAxjYIAARijNBKWZGVABE5o6AAFAAAo=")
            .as_bytes(),
    );
    assert!(e.unwrap_err().message.contains("zlib"));
    let e = parse(MESHIO_BINARY.replace("EAAAAAQAAAAAAAAABwAAAAAAAAA=", "EAAAAAQAAAAAAAAA").as_bytes())
        .unwrap_err();
    assert!(e.message.contains("truncated"), "{e}");
    assert!(parse(b"<VTKFile type=\"PolyData\">").unwrap_err().message.contains("PolyData"));
    assert!(parse(b"not xml at all").unwrap_err().message.contains("VTKFile"));
}

proptest::proptest! {
    #[test]
    fn arbitrary_damage_never_panics(
        cut in 0usize..8000,
        flips in proptest::collection::vec((0usize..8000, 0u8..=255), 0..4),
    ) {
        let ours = write_to_vec(&hybrid_column());
        for mut bytes in [ours, MESHIO_ZLIB.as_bytes().to_vec(), appended(true), appended(false)] {
            for &(at, b) in &flips {
                let n = bytes.len();
                bytes[at % n] = b;
            }
            bytes.truncate(cut.min(bytes.len()));
            let _ = parse(&bytes);
        }
    }
}
