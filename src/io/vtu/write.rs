//! `.vtu` writer: inline base64 binary arrays with UInt64 headers, little-endian.

use std::io::{self, Write};

use base64::engine::general_purpose::STANDARD;
use base64::write::EncoderWriter;

use crate::mesh::VolumeMesh;

/// VTK types of the 2D boundary cells.
const VTK_TRIANGLE: u8 = 5;
const VTK_QUAD: u8 = 9;

/// Write one binary DataArray: base64 of (byte count as UInt64, then the values).
fn binary_array(
    w: &mut dyn Write,
    ty: &str,
    name: &str,
    components: usize,
    bytes: usize,
    values: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    writeln!(
        w,
        r#"<DataArray type="{ty}" Name="{name}" NumberOfComponents="{components}" format="binary">"#
    )?;
    {
        let mut encoder = EncoderWriter::new(&mut *w, &STANDARD);
        encoder.write_all(&(bytes as u64).to_le_bytes())?;
        values(&mut encoder)?;
        encoder.finish()?;
    }
    writeln!(w, "\n</DataArray>")
}

/// Write `mesh` as VTK XML: volume cells, then boundary triangles and quads as 2D cells.
pub fn write(w: &mut dyn Write, mesh: &VolumeMesh) -> io::Result<()> {
    let b = &mesh.boundary;
    let faces = b.triangles.len() + b.quads.len();
    let cells = mesh.cell_count() + faces;
    let nodes: usize =
        mesh.blocks.iter().map(|b| b.nodes.len()).sum::<usize>() + 3 * b.triangles.len() + 4 * b.quads.len();
    writeln!(w, r#"<?xml version="1.0"?>"#)?;
    writeln!(
        w,
        r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">"#
    )?;
    writeln!(
        w,
        "<UnstructuredGrid>\n<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{cells}\">",
        mesh.points.len()
    )?;
    writeln!(w, "<Points>")?;
    binary_array(w, "Float64", "Points", 3, 24 * mesh.points.len(), |e| {
        mesh.points.iter().flat_map(|p| p.to_array()).try_for_each(|v| e.write_all(&v.to_le_bytes()))
    })?;
    writeln!(w, "</Points>\n<Cells>")?;
    binary_array(w, "Int64", "connectivity", 1, 8 * nodes, |e| {
        for block in &mesh.blocks {
            let perm = block.kind.vtk_permutation();
            for cell in block.iter() {
                perm.iter().try_for_each(|&p| e.write_all(&i64::from(cell[p]).to_le_bytes()))?;
            }
        }
        b.nodes().try_for_each(|n| e.write_all(&i64::from(n).to_le_bytes()))
    })?;
    binary_array(w, "Int64", "offsets", 1, 8 * cells, |e| {
        let sizes = mesh.blocks.iter().flat_map(|b| std::iter::repeat_n(b.kind.node_count(), b.len()));
        let sizes = sizes
            .chain(std::iter::repeat_n(3, b.triangles.len()))
            .chain(std::iter::repeat_n(4, b.quads.len()));
        let mut end = 0i64;
        sizes.into_iter().try_for_each(|n| {
            end += n as i64;
            e.write_all(&end.to_le_bytes())
        })
    })?;
    binary_array(w, "UInt8", "types", 1, cells, |e| {
        let types = mesh.blocks.iter().flat_map(|b| std::iter::repeat_n(b.kind.vtk_type(), b.len()));
        let types = types.chain(std::iter::repeat_n(VTK_TRIANGLE, b.triangles.len()));
        let types: Vec<u8> = types.chain(std::iter::repeat_n(VTK_QUAD, b.quads.len())).collect();
        e.write_all(&types)
    })?;
    writeln!(w, "</Cells>\n<CellData>")?;
    let minus_ones = |n: usize| std::iter::repeat_n(-1i32, n);
    binary_array(w, "Int32", "patch", 1, 4 * cells, |e| {
        let patches = b.triangle_patch.iter().chain(&b.quad_patch).map(|&p| p as i32);
        minus_ones(mesh.cell_count()).chain(patches).try_for_each(|p| e.write_all(&p.to_le_bytes()))
    })?;
    binary_array(w, "Int32", "zone", 1, 4 * cells, |e| {
        let zones = mesh.blocks.iter().flat_map(|b| b.zone.iter().map(|&z| z as i32));
        zones.chain(minus_ones(faces)).try_for_each(|z| e.write_all(&z.to_le_bytes()))
    })?;
    writeln!(w, "</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>")
}
