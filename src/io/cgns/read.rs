//! Reading back a single-zone unstructured CGNS file of linear elements (what the writer makes,
//! and what other tools write in the same shape).

use std::collections::HashMap;
use std::path::Path;

use super::ffi::{self, BocoHeader, CgSize, File, SectionHeader};
use super::write::{MIXED, QUAD_4, TRI_3};
use super::{BcType, BoundaryCondition, CgnsError, CgnsFile, Section};
use crate::geometry::DVec3;
use crate::mesh::{CellKind, VolumeMesh};

/// HDF5 datasets may be compressed: counts read from the file may ask for up to this many times
/// the file's size in memory, and no more.
const MAX_EXPANSION: u64 = 64;

/// A face element: its element number, nodes (0-based) and section index.
struct Face {
    number: CgSize,
    nodes: Vec<u32>,
    section: usize,
}

pub(super) fn read_file(path: &Path) -> Result<CgnsFile, CgnsError> {
    let file_len = std::fs::metadata(path).map_err(|e| CgnsError::new(format!("cannot read: {e}")))?.len();
    let budget = file_len.saturating_mul(MAX_EXPANSION);
    let mut file = File::open(path, ffi::MODE_READ)?;
    let (b, z) = (1, 1);
    open_single_unstructured_zone(&mut file)?;
    let [vertices, cells, _] = file.unstructured_zone_size(b, z)?;
    let vertex_count = capped(vertices, 24, budget, "vertices")?;
    let mut axes = Vec::with_capacity(3);
    for name in ["CoordinateX", "CoordinateY", "CoordinateZ"] {
        axes.push(file.read_coordinate(b, z, name, vertices)?);
    }
    let points = (0..vertex_count).map(|i| DVec3::new(axes[0][i], axes[1][i], axes[2][i])).collect();
    let mut mesh = VolumeMesh { points, ..Default::default() };
    let (sections, faces) = read_sections(&mut file, &mut mesh, budget)?;
    let boundary_conditions = read_boundary(&mut file, &mut mesh, &faces, &sections, budget)?;
    file.close()?;
    // Compared with what the sections hold by the caller; refused only when negative.
    let zone_cells =
        usize::try_from(cells).map_err(|_| CgnsError::new(format!("the zone has {cells} cells")))?;
    Ok(CgnsFile { zone_vertices: vertex_count, zone_cells, mesh, sections, boundary_conditions })
}

/// Every element section: cells into `mesh` (a volume zone per section that has cells), faces
/// returned for the boundary conditions.
fn read_sections(
    file: &mut File,
    mesh: &mut VolumeMesh,
    budget: u64,
) -> Result<(Vec<Section>, Vec<Face>), CgnsError> {
    let (b, z) = (1, 1);
    let mut sections = Vec::new();
    let mut faces = Vec::new();
    for s in 1..=file.section_count(b, z)? {
        let header = file.section_header(b, z, s)?;
        let size = file.section_data_size(b, z, s)?;
        let len = capped(size, std::mem::size_of::<CgSize>() as u64, budget, &header.name)?;
        let mixed_count = match header.element_type {
            MIXED => Some(capped(element_count(&header)?, 8, budget, &header.name)?),
            _ => None,
        };
        let data = file.read_elements((b, z, s), mixed_count, len)?;
        let elements = parse_elements(&header, &data, mesh.points.len())?;
        let zone = mesh.zone_names.len() as u32;
        let mut has_cells = false;
        for (i, (element_type, nodes)) in elements.iter().enumerate() {
            match CellKind::from_cgns_type(*element_type) {
                Some(kind) => {
                    mesh.push_cell(kind, nodes, zone);
                    has_cells = true;
                }
                None => {
                    // Within start..=end: parse_elements checked the count.
                    let number = header.start + i as CgSize;
                    faces.push(Face { number, nodes: nodes.clone(), section: sections.len() });
                }
            }
        }
        if has_cells {
            mesh.zone_names.push(header.name.clone());
        }
        sections.push(Section {
            name: header.name,
            element_type: header.element_type,
            elements: elements.len(),
        });
    }
    Ok((sections, faces))
}

/// Check that base 1 is 3D and has exactly one zone, unstructured.
fn open_single_unstructured_zone(file: &mut File) -> Result<(), CgnsError> {
    if file.base_count()? < 1 {
        return Err(CgnsError::new("the file has no base"));
    }
    let dims = file.base_dimensions(1)?;
    if dims != (3, 3) {
        return Err(CgnsError::new(format!("base 1 has cell/physical dimensions {dims:?}, not (3, 3)")));
    }
    match file.zone_count(1)? {
        1 => {}
        n => return Err(CgnsError::new(format!("base 1 has {n} zones: only single-zone files are read"))),
    }
    if file.zone_type(1, 1)? != ffi::UNSTRUCTURED {
        return Err(CgnsError::new("the zone is structured: only unstructured zones are read"));
    }
    Ok(())
}

/// A count read from the file as `usize`, refused when negative or when `count * bytes_each`
/// exceeds the memory `budget`.
fn capped(count: CgSize, bytes_each: u64, budget: u64, what: &str) -> Result<usize, CgnsError> {
    let fits = u64::try_from(count).ok().filter(|&n| n.saturating_mul(bytes_each) <= budget);
    fits.and_then(|n| usize::try_from(n).ok())
        .ok_or_else(|| CgnsError::new(format!("{what}: count {count} is negative or too large for the file")))
}

/// The number of elements of a section, from its range.
fn element_count(header: &SectionHeader) -> Result<CgSize, CgnsError> {
    let count = header.end.checked_sub(header.start).and_then(|d| d.checked_add(1)).filter(|&n| n > 0);
    count.ok_or_else(|| {
        CgnsError::new(format!("section {}: range {}..{}", header.name, header.start, header.end))
    })
}

/// The elements of a section as (`ElementType_t`, 0-based nodes), checked against the section's
/// element range and the zone's vertex count.
fn parse_elements(
    header: &SectionHeader,
    data: &[CgSize],
    vertex_count: usize,
) -> Result<Vec<(i32, Vec<u32>)>, CgnsError> {
    let name = &header.name;
    let error = |message: String| CgnsError::new(format!("section {name}: {message}"));
    let expected = element_count(header)?;
    let mut elements = Vec::new();
    let mut rest = data;
    while !rest.is_empty() {
        let number = i64::from(header.start).saturating_add(elements.len() as i64);
        let (element_type, body) = match (header.element_type, rest) {
            (MIXED, [t, body @ ..]) => (element_type_of(*t), body),
            (t, body) => (t, body),
        };
        let npe = nodes_per_element(element_type).ok_or_else(|| {
            error(format!(
                "element {number} has type {element_type}: only TRI_3, QUAD_4, TETRA_4, PYRA_5, PENTA_6 and HEXA_8 are read"
            ))
        })?;
        let nodes =
            body.get(..npe).ok_or_else(|| error(format!("the connectivity ends inside element {number}")))?;
        let nodes = nodes
            .iter()
            .map(|&v| match usize::try_from(v) {
                Ok(one_based) if (1..=vertex_count).contains(&one_based) => Ok(one_based as u32 - 1),
                _ => {
                    Err(error(format!("element {number} refers to vertex {v} (the zone has {vertex_count})")))
                }
            })
            .collect::<Result<Vec<u32>, _>>()?;
        elements.push((element_type, nodes));
        rest = &body[npe..];
    }
    if CgSize::try_from(elements.len()).ok() != Some(expected) {
        return Err(error(format!(
            "{} elements for the range {}..{}",
            elements.len(),
            header.start,
            header.end
        )));
    }
    Ok(elements)
}

/// An `ElementType_t` stored in a connectivity array (-1, unknown, when out of range).
#[allow(clippy::useless_conversion)] // `CgSize` is `i64` in a 64-bit CGNS build.
fn element_type_of(value: CgSize) -> i32 {
    i32::try_from(value).unwrap_or(-1)
}

fn nodes_per_element(element_type: i32) -> Option<usize> {
    match element_type {
        TRI_3 => Some(3),
        QUAD_4 => Some(4),
        t => CellKind::from_cgns_type(t).map(CellKind::node_count),
    }
}

/// Patches from the boundary conditions, then one per face section for the faces under none.
fn read_boundary(
    file: &mut File,
    mesh: &mut VolumeMesh,
    faces: &[Face],
    sections: &[Section],
    budget: u64,
) -> Result<Vec<BoundaryCondition>, CgnsError> {
    let face_of_number: HashMap<CgSize, usize> =
        faces.iter().enumerate().map(|(i, f)| (f.number, i)).collect();
    let mut patch_of_face: Vec<Option<u32>> = vec![None; faces.len()];
    let mut conditions = Vec::new();
    for bc in 1..=file.boco_count(1, 1)? {
        let header = file.boco_header(1, 1, bc)?;
        let len = capped(header.point_count, std::mem::size_of::<CgSize>() as u64, budget, &header.name)?;
        let (points, location) = file.read_boco(1, 1, bc, len)?;
        let numbers = face_numbers(&header, &points, location, faces.len())?;
        let patch = mesh.patch_names.len() as u32;
        for number in &numbers {
            let face = face_of_number.get(number).ok_or_else(|| {
                CgnsError::new(format!("boundary condition {}: element {number} is not a face", header.name))
            })?;
            patch_of_face[*face] = Some(patch);
        }
        mesh.patch_names.push(header.name.clone());
        let bc_type = BcType::from_code(header.bc_type);
        conditions.push(BoundaryCondition { name: header.name, bc_type, faces: numbers.len() });
    }
    let mut section_patch: HashMap<usize, u32> = HashMap::new();
    for (face, patch) in faces.iter().zip(patch_of_face) {
        let patch = patch.unwrap_or_else(|| {
            *section_patch.entry(face.section).or_insert_with(|| {
                mesh.patch_names.push(sections[face.section].name.clone());
                mesh.patch_names.len() as u32 - 1
            })
        });
        push_face(mesh, &face.nodes, patch);
    }
    Ok(conditions)
}

fn push_face(mesh: &mut VolumeMesh, nodes: &[u32], patch: u32) {
    let b = &mut mesh.boundary;
    match *nodes {
        [p, q, r] => {
            b.triangles.push([p, q, r]);
            b.triangle_patch.push(patch);
        }
        [p, q, r, s] => {
            b.quads.push([p, q, r, s]);
            b.quad_patch.push(patch);
        }
        _ => {}
    }
}

/// The face element numbers of a boundary condition (a range or a list at face centres).
fn face_numbers(
    header: &BocoHeader,
    points: &[CgSize],
    location: i32,
    face_count: usize,
) -> Result<Vec<CgSize>, CgnsError> {
    let error = |message: String| CgnsError::new(format!("boundary condition {}: {message}", header.name));
    let is_range = match header.point_set_type {
        ffi::POINT_RANGE | ffi::ELEMENT_RANGE => true,
        ffi::POINT_LIST | ffi::ELEMENT_LIST => false,
        t => return Err(error(format!("point set type {t} is not read (only ranges and lists)"))),
    };
    let by_element = matches!(header.point_set_type, ffi::ELEMENT_RANGE | ffi::ELEMENT_LIST);
    if !by_element && location != ffi::FACE_CENTER {
        let at =
            if location == ffi::VERTEX { "vertices".to_string() } else { format!("location {location}") };
        return Err(error(format!("given at {at}: only conditions on face elements are read")));
    }
    if !is_range {
        return Ok(points.to_vec());
    }
    match *points {
        [first, last]
            if last.checked_sub(first).is_some_and(|d| d >= 0 && (d as u64) < face_count as u64) =>
        {
            Ok((first..=last).collect())
        }
        _ => Err(error(format!("range {points:?} is not within the file's {face_count} faces"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(element_type: i32, start: CgSize, end: CgSize) -> SectionHeader {
        SectionHeader { name: "s".into(), element_type, start, end }
    }

    #[test]
    fn mixed_and_fixed_sections_parse_to_zero_based_nodes() {
        let mixed = [10, 1, 2, 3, 4, 5, 4, 3, 2];
        let elements = parse_elements(&header(MIXED, 7, 8), &mixed, 4).unwrap();
        assert_eq!(elements, [(10, vec![0, 1, 2, 3]), (5, vec![3, 2, 1])]);
        let quads = parse_elements(&header(QUAD_4, 1, 1), &[1, 2, 3, 4], 4).unwrap();
        assert_eq!(quads, [(QUAD_4, vec![0, 1, 2, 3])]);
    }

    #[test]
    fn bad_connectivity_is_named() {
        let message = |h: SectionHeader, data: &[CgSize]| parse_elements(&h, data, 4).unwrap_err().message;
        assert!(message(header(TRI_3, 1, 1), &[1, 2, 5]).contains("element 1 refers to vertex 5"));
        assert!(message(header(TRI_3, 1, 1), &[1, 0, 2]).contains("vertex 0"));
        assert!(message(header(MIXED, 3, 3), &[10, 1, 2]).contains("ends inside element 3"));
        assert!(message(header(MIXED, 1, 1), &[99, 1]).contains("type 99"));
        assert!(message(header(MIXED, 1, 1), &[CgSize::MAX, 1]).contains("type"));
        assert!(message(header(TRI_3, 1, 2), &[1, 2, 3]).contains("1 elements for the range 1..2"));
    }

    #[test]
    fn counts_beyond_the_file_are_refused() {
        assert_eq!(capped(10, 8, 80, "x"), Ok(10));
        assert!(capped(11, 8, 80, "x").is_err());
        assert!(capped(-1, 8, 80, "x").is_err());
    }

    #[test]
    fn boundary_ranges_stay_within_the_faces() {
        let bc =
            |point_set_type| BocoHeader { name: "wall".into(), bc_type: 22, point_set_type, point_count: 2 };
        assert_eq!(face_numbers(&bc(ffi::POINT_RANGE), &[5, 7], ffi::FACE_CENTER, 3), Ok(vec![5, 6, 7]));
        assert!(face_numbers(&bc(ffi::POINT_RANGE), &[5, 8], ffi::FACE_CENTER, 3).is_err());
        assert!(face_numbers(&bc(ffi::POINT_RANGE), &[1, CgSize::MAX], ffi::FACE_CENTER, 3).is_err());
        assert!(face_numbers(&bc(ffi::POINT_RANGE), &[7, 5], ffi::FACE_CENTER, 3).is_err());
        let at_vertices = face_numbers(&bc(ffi::POINT_LIST), &[1, 2], ffi::VERTEX, 3).unwrap_err();
        assert!(at_vertices.message.contains("given at vertices"), "{at_vertices}");
        assert_eq!(face_numbers(&bc(ffi::ELEMENT_LIST), &[4, 2], ffi::VERTEX, 3), Ok(vec![4, 2]));
    }
}
