//! SU2 native mesh writer (`.su2`, ASCII), <https://su2code.github.io/docs_v7/Mesh-File/>.
//!
//! `NDIME= 3`; `NELEM` cells as `VTK-type nodes... index` (0-based nodes, VTK node orders: the
//! prism is permuted by [`crate::mesh::CellKind::vtk_permutation`]); `NPOIN` points as `x y z index`; `NMARK`
//! markers, one per patch that has faces, named by `MARKER_TAG` (the patch name) with its
//! triangles (VTK type 5) and quadrilaterals (9) under `MARKER_ELEMS`. Patches without faces are
//! left out: a marker with no element is refused by some readers (meshio).

use std::io::{self, Write};

use crate::mesh::VolumeMesh;

const VTK_TRIANGLE: u8 = 5;
const VTK_QUAD: u8 = 9;

/// Write `mesh` as an SU2 mesh.
pub fn write(w: &mut dyn Write, mesh: &VolumeMesh) -> io::Result<()> {
    writeln!(w, "% SU2 mesh written by blmesh\n%\nNDIME= 3\nNELEM= {}", mesh.cell_count())?;
    for (index, (kind, nodes)) in mesh.cells().enumerate() {
        write!(w, "{}", kind.vtk_type())?;
        for &local in kind.vtk_permutation() {
            write!(w, " {}", nodes[local])?;
        }
        writeln!(w, " {index}")?;
    }
    writeln!(w, "NPOIN= {}", mesh.points.len())?;
    for (i, p) in mesh.points.iter().enumerate() {
        // `{:e}` prints the shortest digits that read back to the same f64.
        writeln!(w, "{:e} {:e} {:e} {i}", p.x, p.y, p.z)?;
    }
    write_markers(w, mesh)
}

fn write_markers(w: &mut dyn Write, mesh: &VolumeMesh) -> io::Result<()> {
    let b = &mesh.boundary;
    let patch_count =
        b.triangle_patch.iter().chain(&b.quad_patch).map(|&p| p as usize + 1).max().unwrap_or(0);
    let mut faces: Vec<Vec<(u8, &[u32])>> = vec![Vec::new(); patch_count];
    let triangles = b.triangles.iter().map(|t| (VTK_TRIANGLE, &t[..])).zip(&b.triangle_patch);
    let quads = b.quads.iter().map(|q| (VTK_QUAD, &q[..])).zip(&b.quad_patch);
    for (face, &patch) in triangles.chain(quads) {
        faces[patch as usize].push(face);
    }
    writeln!(w, "NMARK= {}", faces.iter().filter(|f| !f.is_empty()).count())?;
    for (patch, faces) in faces.iter().enumerate().filter(|(_, f)| !f.is_empty()) {
        writeln!(w, "MARKER_TAG= {}", marker_tag(mesh, patch))?;
        writeln!(w, "MARKER_ELEMS= {}", faces.len())?;
        for (vtk_type, nodes) in faces {
            write!(w, "{vtk_type}")?;
            for n in *nodes {
                write!(w, " {n}")?;
            }
            writeln!(w)?;
        }
    }
    Ok(())
}

/// The patch name as one token without `=` (the file's key separator), or `patch_<index>`.
fn marker_tag(mesh: &VolumeMesh, patch: usize) -> String {
    match mesh.patch_names.get(patch).map(|n| n.trim()).filter(|n| !n.is_empty()) {
        Some(name) => name.chars().map(|c| if c.is_whitespace() || c == '=' { '_' } else { c }).collect(),
        None => format!("patch_{patch}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::CellKind;
    use crate::quality::samples::hybrid_column;

    fn written(mesh: &VolumeMesh) -> String {
        let mut bytes = Vec::new();
        write(&mut bytes, mesh).unwrap();
        String::from_utf8(bytes).unwrap()
    }

    /// The value of `KEY= value` lines, in order.
    fn values<'a>(text: &'a str, key: &str) -> Vec<&'a str> {
        text.lines().filter_map(|l| l.strip_prefix(key)?.strip_prefix('=')).map(str::trim).collect()
    }

    #[test]
    fn sections_count_every_cell_point_and_face() {
        let mesh = hybrid_column();
        let text = written(&mesh);
        assert_eq!(values(&text, "NDIME"), ["3"]);
        assert_eq!(values(&text, "NELEM"), [mesh.cell_count().to_string()]);
        assert_eq!(values(&text, "NPOIN"), [mesh.points.len().to_string()]);
        let tags = values(&text, "MARKER_TAG");
        let used: std::collections::BTreeSet<u32> =
            mesh.boundary.triangle_patch.iter().chain(&mesh.boundary.quad_patch).copied().collect();
        assert_eq!(values(&text, "NMARK"), [used.len().to_string()]);
        assert_eq!(tags.len(), used.len());
        let elems: usize = values(&text, "MARKER_ELEMS").iter().map(|n| n.parse::<usize>().unwrap()).sum();
        assert_eq!(elems, mesh.boundary.triangles.len() + mesh.boundary.quads.len());
    }

    #[test]
    fn prisms_are_written_in_vtk_order() {
        let mesh = hybrid_column();
        let prism = mesh.block(CellKind::Prism).cell(0);
        let text = written(&mesh);
        let line = text.lines().find(|l| l.starts_with("13 ")).unwrap();
        let nodes: Vec<u32> = line.split(' ').skip(1).take(6).map(|n| n.parse().unwrap()).collect();
        assert_eq!(nodes, [prism[0], prism[2], prism[1], prism[3], prism[5], prism[4]]);
    }

    #[test]
    fn marker_tags_are_single_tokens() {
        let mut mesh = hybrid_column();
        mesh.patch_names = vec!["inlet = 1".into(), " ".into()];
        assert_eq!(marker_tag(&mesh, 0), "inlet___1");
        assert_eq!(marker_tag(&mesh, 1), "patch_1");
        assert_eq!(marker_tag(&mesh, 5), "patch_5");
    }
}
