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

use super::ParseError;
use crate::geometry::DVec3;
use crate::mesh::{CellKind, VolumeMesh};
use read::{Array, Section, VtuFile};

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
    fn new(mut v: Vec<i64>, prefix: &str, default: &str, has_array: bool) -> Groups {
        v.sort_unstable();
        v.dedup();
        let names = if has_array {
            v.iter().map(|x| format!("{prefix}_{x}")).collect()
        } else {
            vec![default.into()]
        };
        Groups { values: v, names }
    }

    fn index(&self, value: i64) -> u32 {
        self.values.binary_search(&value).unwrap_or(0) as u32
    }
}

fn required<'f, 'a>(
    file: &'f VtuFile<'a>,
    section: Section,
    name: Option<&str>,
    what: &str,
) -> Result<&'f Array<'a>, ParseError> {
    file.find(section, name)
        .ok_or_else(|| ParseError::file(format!("no {what} DataArray in the file's {section:?} section")))
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

/// The cells of the file: VTK types, and the node lists as connectivity + end offsets.
struct Cells<'f, 'a> {
    connectivity: Vec<i64>,
    offsets: Vec<i64>,
    types: Vec<i64>,
    /// The connectivity array, where cell errors are reported.
    array: &'f Array<'a>,
}

impl<'f, 'a> Cells<'f, 'a> {
    fn read(file: &'f VtuFile<'a>) -> Result<Self, ParseError> {
        let array = required(file, Section::Cells, Some("connectivity"), "connectivity")?;
        Ok(Cells {
            connectivity: file.ints(array)?,
            offsets: per_cell(file, required(file, Section::Cells, Some("offsets"), "offsets")?)?,
            types: per_cell(file, required(file, Section::Cells, Some("types"), "types")?)?,
            array,
        })
    }

    /// What cell `i` becomes and its nodes in our order (`None`: a cell to skip).
    fn cell(
        &self,
        file: &VtuFile,
        i: usize,
        points: usize,
    ) -> Result<Option<(VtkCell, Vec<u32>)>, ParseError> {
        let error = |m: String| file.error(self.array, format!("cell {i}: {m}"));
        let start = if i == 0 { Some(0) } else { usize::try_from(self.offsets[i - 1]).ok() };
        let end = usize::try_from(self.offsets[i]).ok();
        let nodes = match (start, end) {
            (Some(s), Some(e)) if s <= e && e <= self.connectivity.len() => &self.connectivity[s..e],
            _ => return Err(error(format!("offset {} out of range", self.offsets[i]))),
        };
        let t = self.types[i];
        let shape = vtk_cell(t).ok_or_else(|| error(format!("unsupported VTK cell type {t}")))?;
        let (count, perm) = match shape {
            VtkCell::Skip => return Ok(None),
            VtkCell::Face(n, perm) => (n, perm),
            VtkCell::Volume(kind, perm) => (kind.node_count(), perm),
        };
        if nodes.len() != count {
            return Err(error(format!("{} nodes for VTK type {t} ({count} expected)", nodes.len())));
        }
        let ours = perm.iter().map(|&p| {
            let n = nodes[p];
            u32::try_from(n)
                .ok()
                .filter(|&n| (n as usize) < points)
                .ok_or_else(|| error(format!("node {n} out of range ({points} points)")))
        });
        Ok(Some((shape, ours.collect::<Result<_, _>>()?)))
    }
}

/// The patch of every face and the zone of every volume cell, from the CellData arrays.
struct Tags {
    patch: Option<Vec<i64>>,
    zone: Option<Vec<i64>>,
    patches: Groups,
    zones: Groups,
}

impl Tags {
    fn read(file: &VtuFile, types: &[i64]) -> Result<Tags, ParseError> {
        let patch = tag_array(file, &PATCH_ARRAYS)?;
        let zone = match tag_array(file, &["zone"])? {
            Some(z) => Some(z),
            None => patch.clone(),
        };
        let values_of = |values: &Option<Vec<i64>>, face: bool| {
            let kept = |i: &usize| match vtk_cell(types[*i]) {
                Some(VtkCell::Face(..)) => face,
                Some(VtkCell::Volume(..)) => !face,
                _ => false,
            };
            (0..types.len()).filter(kept).map(|i| values.as_ref().map_or(0, |v| v[i])).collect()
        };
        let patches = Groups::new(values_of(&patch, true), "patch", "boundary", patch.is_some());
        let zones = Groups::new(values_of(&zone, false), "zone", "volume", zone.is_some());
        Ok(Tags { patch, zone, patches, zones })
    }

    fn patch(&self, i: usize) -> u32 {
        self.patches.index(self.patch.as_ref().map_or(0, |v| v[i]))
    }

    fn zone(&self, i: usize) -> u32 {
        self.zones.index(self.zone.as_ref().map_or(0, |v| v[i]))
    }
}

/// Read a `.vtu` volume mesh; 2D cells become boundary faces.
pub fn parse(bytes: &[u8]) -> Result<VolumeMesh, ParseError> {
    let file = read::scan(bytes)?;
    let mut mesh = VolumeMesh { points: read_points(&file)?, ..Default::default() };
    if file.cells == 0 {
        return Err(ParseError::file("the file has no cells"));
    }
    let cells = Cells::read(&file)?;
    let tags = Tags::read(&file, &cells.types)?;
    for i in 0..file.cells {
        let Some((shape, nodes)) = cells.cell(&file, i, mesh.points.len())? else { continue };
        let faces = &mut mesh.boundary;
        match (shape, nodes.as_slice()) {
            (VtkCell::Volume(kind, _), _) => mesh.push_cell(kind, &nodes, tags.zone(i)),
            (_, &[a, b, c]) => {
                faces.triangles.push([a, b, c]);
                faces.triangle_patch.push(tags.patch(i));
            }
            (_, &[a, b, c, d]) => {
                faces.quads.push([a, b, c, d]);
                faces.quad_patch.push(tags.patch(i));
            }
            _ => {}
        }
    }
    if mesh.cell_count() == 0 {
        return Err(ParseError::file(
            "no volume cells (tetrahedra, pyramids, wedges, hexahedra) in the file",
        ));
    }
    let has_faces = !mesh.boundary.triangles.is_empty() || !mesh.boundary.quads.is_empty();
    mesh.patch_names = if has_faces { tags.patches.names } else { Vec::new() };
    mesh.zone_names = tags.zones.names;
    Ok(mesh)
}

#[cfg(test)]
mod tests;
