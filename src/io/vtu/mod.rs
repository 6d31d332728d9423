//! VTK XML unstructured grid (`.vtu`): writer, and reader for ours and other tools' files
//! (meshio's default zlib-compressed binary, plain binary, ASCII, appended data).
//!
//! Volume cells carry CellData `zone` (zone index; -1 on faces), boundary faces are 2D cells
//! carrying `patch` (patch index; -1 on volume cells). On reading, patches come from the first
//! integer CellData array among [`PATCH_ARRAYS`] (named `patch_<value>`), else one patch
//! `boundary`; zones from `zone` or that same array (named `zone_<value>`), else one zone
//! `volume`.

mod data;
mod read;
mod write;

pub use write::write;

use read::{Array, Section, VtuFile};
use super::ParseError;
use crate::geometry::DVec3;
use crate::mesh::{CellKind, VolumeMesh};

/// CellData arrays that can hold the boundary patch of a face, by priority.
pub const PATCH_ARRAYS: [&str; 5] = ["patch", "gmsh:physical", "cell_tags", "CellEntityIds", "medit:ref"];

/// What a VTK cell type becomes.
enum VtkCell {
    Volume(CellKind, &'static [usize]),
    Face(usize, &'static [usize]),
    Skip,
}

/// Node order from VTK's: `ours[i] = vtk[perm[i]]`.
fn vtk_cell(t: i64) -> Option<VtkCell> {
    Some(match t {
        1..=4 => VtkCell::Skip,
        5 => VtkCell::Face(3, &[0, 1, 2]),
        8 => VtkCell::Face(4, &[0, 1, 3, 2]),
        9 => VtkCell::Face(4, &[0, 1, 2, 3]),
        11 => VtkCell::Volume(CellKind::Hexahedron, &[0, 1, 3, 2, 4, 5, 7, 6]),
        _ => {
            let kind = CellKind::from_vtk_type(u8::try_from(t).ok()?)?;
            VtkCell::Volume(kind, kind.vtk_permutation())
        }
    })
}

/// Group names for the distinct values of a tag array, and each value's index.
struct Groups {
    values: Vec<i64>,
    names: Vec<String>,
}

impl Groups {
    fn new(values: impl Iterator<Item = i64>, prefix: &str, default: &str, has_array: bool) -> Groups {
        let mut v: Vec<i64> = values.collect();
        v.sort_unstable();
        v.dedup();
        let names = if has_array { v.iter().map(|x| format!("{prefix}_{x}")).collect() } else { vec![default.into()] };
        Groups { values: v, names }
    }

    fn index(&self, value: i64) -> u32 {
        self.values.binary_search(&value).unwrap_or(0) as u32
    }
}

fn required<'f, 'a>(file: &'f VtuFile<'a>, section: Section, name: Option<&str>, what: &str) -> Result<&'f Array<'a>, ParseError> {
    file.find(section, name).ok_or_else(|| ParseError::file(format!("no {what} DataArray")))
}

fn read_points(file: &VtuFile) -> Result<Vec<DVec3>, ParseError> {
    if file.points == 0 {
        return Ok(Vec::new());
    }
    let array = required(file, Section::Points, None, "Points")?;
    if array.components != 3 {
        return Err(file.error(array, format!("{} components, expected 3", array.components)));
    }
    let values = file.floats(array)?;
    if values.len() != 3 * file.points {
        return Err(file.error(array, format!("{} values for {} points", values.len(), file.points)));
    }
    Ok(values.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect())
}

/// An integer array with one value per cell.
fn per_cell(file: &VtuFile, array: &Array) -> Result<Vec<i64>, ParseError> {
    let values = file.ints(array)?;
    if values.len() != file.cells {
        return Err(file.error(array, format!("{} values for {} cells", values.len(), file.cells)));
    }
    Ok(values)
}

/// The first integer CellData array among `names`.
fn tag_array(file: &VtuFile, names: &[&str]) -> Result<Option<Vec<i64>>, ParseError> {
    let found = names.iter().find_map(|n| file.find(Section::CellData, Some(n)).filter(|a| !a.ty.is_float()));
    found.map(|a| per_cell(file, a)).transpose()
}

/// Read a `.vtu` volume mesh; 2D cells become boundary faces.
pub fn parse(bytes: &[u8]) -> Result<VolumeMesh, ParseError> {
    let file = read::scan(bytes)?;
    let mut mesh = VolumeMesh { points: read_points(&file)?, ..Default::default() };
    if file.cells == 0 {
        return Err(ParseError::file("the file has no cells"));
    }
    let connectivity_array = required(&file, Section::Cells, Some("connectivity"), "connectivity")?;
    let connectivity = file.ints(connectivity_array)?;
    let offsets = per_cell(&file, required(&file, Section::Cells, Some("offsets"), "offsets")?)?;
    let types = per_cell(&file, required(&file, Section::Cells, Some("types"), "types")?)?;
    let patch = tag_array(&file, &PATCH_ARRAYS)?;
    let zone = match tag_array(&file, &["zone"])? {
        Some(z) => Some(z),
        None => patch.clone(),
    };
    let tag = |values: &Option<Vec<i64>>, i: usize| values.as_ref().map_or(0, |v| v[i]);
    let face_kind = |t: i64| matches!(vtk_cell(t), Some(VtkCell::Face(..)));
    let volume_kind = |t: i64| matches!(vtk_cell(t), Some(VtkCell::Volume(..)));
    let patches = Groups::new((0..file.cells).filter(|&i| face_kind(types[i])).map(|i| tag(&patch, i)), "patch", "boundary", patch.is_some());
    let zones = Groups::new((0..file.cells).filter(|&i| volume_kind(types[i])).map(|i| tag(&zone, i)), "zone", "volume", zone.is_some());
    let cell_error = |i: usize, m: String| file.error(connectivity_array, format!("cell {i}: {m}"));
    let mut start = 0usize;
    for i in 0..file.cells {
        let end = usize::try_from(offsets[i]).ok().filter(|&e| e >= start && e <= connectivity.len());
        let Some(end) = end else {
            return Err(cell_error(i, format!("offset {} out of range", offsets[i])));
        };
        let nodes = &connectivity[start..end];
        start = end;
        let mut ours = [0u32; 8];
        let shape = vtk_cell(types[i]).ok_or_else(|| cell_error(i, format!("unsupported VTK cell type {}", types[i])))?;
        let (count, perm) = match shape {
            VtkCell::Skip => continue,
            VtkCell::Face(n, perm) => (n, perm),
            VtkCell::Volume(kind, perm) => (kind.node_count(), perm),
        };
        if nodes.len() != count {
            return Err(cell_error(i, format!("{} nodes for VTK type {} ({count} expected)", nodes.len(), types[i])));
        }
        for (o, &p) in ours.iter_mut().zip(perm) {
            let n = nodes[p];
            *o = u32::try_from(n).ok().filter(|&n| (n as usize) < mesh.points.len())
                .ok_or_else(|| cell_error(i, format!("node {n} out of range ({} points)", mesh.points.len())))?;
        }
        match shape {
            VtkCell::Volume(kind, _) => mesh.push_cell(kind, &ours[..count], zones.index(tag(&zone, i))),
            _ if count == 3 => {
                mesh.boundary.triangles.push([ours[0], ours[1], ours[2]]);
                mesh.boundary.triangle_patch.push(patches.index(tag(&patch, i)));
            }
            _ => {
                mesh.boundary.quads.push([ours[0], ours[1], ours[2], ours[3]]);
                mesh.boundary.quad_patch.push(patches.index(tag(&patch, i)));
            }
        }
    }
    if mesh.cell_count() == 0 {
        return Err(ParseError::file("no volume cells (tetrahedra, pyramids, wedges, hexahedra) in the file"));
    }
    mesh.patch_names = if mesh.boundary.triangles.is_empty() && mesh.boundary.quads.is_empty() { Vec::new() } else { patches.names };
    mesh.zone_names = zones.names;
    Ok(mesh)
}

#[cfg(test)]
mod tests;
