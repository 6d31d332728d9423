//! The CGNS writer (layout in the module docs).

use std::collections::HashSet;
use std::path::Path;

use super::ffi::{self, CgSize, File};
use super::{default_role, BcType, CgnsError};
use crate::config::Role;
use crate::mesh::VolumeMesh;

pub(super) const TRI_3: i32 = 5;
pub(super) const QUAD_4: i32 = 7;
pub(super) const MIXED: i32 = 20;
const BASE: &str = "Base";
const ZONE: &str = "Zone";
/// The dimensional exponents (mass, length, time, temperature, angle) of a length.
const LENGTH: [f64; 5] = [0.0, 1.0, 0.0, 0.0, 0.0];
/// Child names of a zone that sections must not take.
const ZONE_CHILDREN: [&str; 3] = ["GridCoordinates", "ZoneBC", "ZoneType"];

/// The elements of one section: its name, `ElementType_t` and connectivity (1-based nodes,
/// each element preceded by its type in a `MIXED` section).
struct SectionData {
    name: String,
    element_type: i32,
    count: usize,
    connectivity: Vec<CgSize>,
    /// `MIXED` only: where each element starts in `connectivity`, then its length.
    offsets: Vec<CgSize>,
}

impl SectionData {
    fn new(name: String, element_type: i32) -> Self {
        let offsets = if element_type == MIXED { vec![0] } else { Vec::new() };
        SectionData { name, element_type, count: 0, connectivity: Vec::new(), offsets }
    }
}

pub(super) fn write_file(path: &Path, mesh: &VolumeMesh, roles: &[Role]) -> Result<(), CgnsError> {
    let mut names = UniqueNames::default();
    let cells = cell_sections(mesh, &mut names)?;
    let patches = patch_sections(mesh, &mut names)?;
    let mut file = File::open(path, ffi::MODE_WRITE)?;
    let b = file.write_base(BASE, 3, 3)?;
    // The coordinates are in the surface's units, which the mesher does not know.
    file.write_data_class(&format!("/{BASE}"), ffi::UNKNOWN_UNITS)?;
    let size = [to_size(mesh.points.len(), "points")?, to_size(mesh.cell_count(), "cells")?, 0];
    let z = file.write_unstructured_zone(b, ZONE, size)?;
    for (axis, name) in ["CoordinateX", "CoordinateY", "CoordinateZ"].into_iter().enumerate() {
        let values: Vec<f64> = mesh.points.iter().map(|p| p[axis]).collect();
        file.write_coordinate(b, z, name, &values)?;
        file.write_exponents(&format!("/{BASE}/{ZONE}/GridCoordinates/{name}"), LENGTH)?;
    }
    let mut next = 1;
    for section in &cells {
        next = write_section(&mut file, (b, z), section, next)?;
    }
    for (patch, parts) in &patches {
        let first = next;
        for section in parts {
            next = write_section(&mut file, (b, z), section, next)?;
        }
        let name = mesh.patch_names.get(*patch).map_or("", String::as_str);
        let role = roles.get(*patch).copied().unwrap_or_else(|| default_role(name));
        let range = [first, next - 1];
        // Named like the patch's first section: valid, unique and short.
        let bc_name = &parts[0].name;
        file.write_face_boco((b, z), bc_name, BcType::for_role(role).code(), ffi::POINT_RANGE, &range)?;
    }
    file.close()
}

/// Write `section` from element number `first`; the next free element number.
fn write_section(
    file: &mut File,
    base_zone: (i32, i32),
    section: &SectionData,
    first: CgSize,
) -> Result<CgSize, CgnsError> {
    let count = to_size(section.count, "elements")?;
    let last = first.checked_add(count - 1).ok_or_else(|| too_many("elements"))?;
    let offsets = (section.element_type == MIXED).then_some(&section.offsets[..]);
    let range = (first, last);
    file.write_section(
        base_zone,
        &section.name,
        section.element_type,
        range,
        &section.connectivity,
        offsets,
    )?;
    last.checked_add(1).ok_or_else(|| too_many("elements"))
}

/// One `MIXED` section per volume zone that has cells, in zone order.
fn cell_sections(mesh: &VolumeMesh, names: &mut UniqueNames) -> Result<Vec<SectionData>, CgnsError> {
    let zone_count = mesh.blocks.iter().flat_map(|b| &b.zone).map(|&z| z as usize + 1).max().unwrap_or(0);
    let mut sections: Vec<Option<SectionData>> = (0..zone_count).map(|_| None).collect();
    for block in &mesh.blocks {
        for (nodes, &zone) in block.iter().zip(&block.zone) {
            let section = sections[zone as usize].get_or_insert_with(|| {
                let name = mesh.zone_names.get(zone as usize).map(String::as_str);
                SectionData::new(names.take(name, "cells", zone as usize), MIXED)
            });
            push_element(section, block.kind.cgns_type(), nodes)?;
        }
    }
    Ok(sections.into_iter().flatten().collect())
}

/// The face sections of every patch that has faces, with its patch index: its triangles
/// (`TRI_3`, named after the patch), then its quads (`QUAD_4`, named `<patch>_quads` when the
/// patch also has triangles), so that one element range covers the patch. Fixed-type sections
/// rather than MIXED: cgnscheck 3.4 looks up faces in MIXED face sections with the node count of
/// the element before, and some readers take boundary sections of one type only.
fn patch_sections(
    mesh: &VolumeMesh,
    names: &mut UniqueNames,
) -> Result<Vec<(usize, Vec<SectionData>)>, CgnsError> {
    let b = &mesh.boundary;
    let patch_count =
        b.triangle_patch.iter().chain(&b.quad_patch).map(|&p| p as usize + 1).max().unwrap_or(0);
    let mut faces: Vec<[Vec<&[u32]>; 2]> = vec![[Vec::new(), Vec::new()]; patch_count];
    for (t, &patch) in b.triangles.iter().zip(&b.triangle_patch) {
        faces[patch as usize][0].push(&t[..]);
    }
    for (q, &patch) in b.quads.iter().zip(&b.quad_patch) {
        faces[patch as usize][1].push(&q[..]);
    }
    let mut sections = Vec::new();
    for (patch, [triangles, quads]) in faces.into_iter().enumerate() {
        let name = mesh.patch_names.get(patch).map(String::as_str);
        let mut parts = Vec::new();
        for (element_type, faces) in [(TRI_3, triangles), (QUAD_4, quads)] {
            if faces.is_empty() {
                continue;
            }
            let section_name = match (element_type, parts.is_empty()) {
                (QUAD_4, false) => {
                    names.take(name.map(|n| format!("{n}_quads")).as_deref(), "patch_quads", patch)
                }
                _ => names.take(name, "patch", patch),
            };
            let mut section = SectionData::new(section_name, element_type);
            for nodes in faces {
                push_element(&mut section, element_type, nodes)?;
            }
            parts.push(section);
        }
        if !parts.is_empty() {
            sections.push((patch, parts));
        }
    }
    Ok(sections)
}

/// Append an element (its type first in a `MIXED` section) with 1-based node numbers.
fn push_element(section: &mut SectionData, element_type: i32, nodes: &[u32]) -> Result<(), CgnsError> {
    if section.element_type == MIXED {
        section.connectivity.push(element_type as CgSize);
    }
    for &n in nodes {
        let one_based = CgSize::try_from(u64::from(n) + 1).map_err(|_| too_many("points"))?;
        section.connectivity.push(one_based);
    }
    if section.element_type == MIXED {
        section.offsets.push(to_size(section.connectivity.len(), "connectivity values")?);
    }
    section.count += 1;
    Ok(())
}

fn to_size(n: usize, what: &str) -> Result<CgSize, CgnsError> {
    CgSize::try_from(n).map_err(|_| too_many(what))
}

fn too_many(what: &str) -> CgnsError {
    CgnsError::new(format!(
        "too many {what} for this CGNS library (its cgsize_t has {} bits)",
        8 * std::mem::size_of::<CgSize>()
    ))
}

/// Node names of the zone's sections: at most 32 bytes, no `/`, none repeated.
#[derive(Default)]
struct UniqueNames {
    taken: HashSet<String>,
}

impl UniqueNames {
    /// `name` made valid and unique (`{fallback}_{index}` when it is empty or missing).
    fn take(&mut self, name: Option<&str>, fallback: &str, index: usize) -> String {
        let cleaned: String =
            name.unwrap_or("").trim().chars().map(|c| if c == '/' { '_' } else { c }).collect();
        let base = if cleaned.is_empty() { format!("{fallback}_{index}") } else { cleaned };
        let mut candidate = truncated(&base, ffi::NAME_LEN).to_owned();
        let mut k = 1;
        while self.taken.contains(&candidate) || ZONE_CHILDREN.contains(&candidate.as_str()) {
            k += 1;
            let suffix = format!("_{k}");
            candidate = format!("{}{suffix}", truncated(&base, ffi::NAME_LEN - suffix.len()));
        }
        self.taken.insert(candidate.clone());
        candidate
    }
}

/// The longest prefix of `s` of at most `max` bytes that ends on a character boundary.
fn truncated(s: &str, max: usize) -> &str {
    let end = (0..=max.min(s.len())).rev().find(|&i| s.is_char_boundary(i)).unwrap_or(0);
    &s[..end]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn section_names_are_short_valid_and_unique() {
        let mut names = UniqueNames::default();
        assert_eq!(names.take(Some("wing"), "patch", 0), "wing");
        assert_eq!(names.take(Some("wing"), "patch", 1), "wing_2");
        assert_eq!(names.take(Some("a/b"), "patch", 2), "a_b");
        assert_eq!(names.take(Some(" "), "patch", 3), "patch_3");
        assert_eq!(names.take(None, "cells", 4), "cells_4");
        assert_eq!(names.take(Some("ZoneBC"), "patch", 5), "ZoneBC_2");
        let long = "é".repeat(40);
        let first = names.take(Some(&long), "patch", 6);
        assert_eq!(first, "é".repeat(16));
        let second = names.take(Some(&long), "patch", 7);
        assert!(second.len() <= ffi::NAME_LEN && second.ends_with("_2"), "{second}");
    }

    #[test]
    fn mixed_sections_prefix_every_element_with_its_type() {
        let mut mixed = SectionData::new("m".into(), MIXED);
        push_element(&mut mixed, TRI_3, &[0, 1, 2]).unwrap();
        push_element(&mut mixed, QUAD_4, &[3, 4, 5, 6]).unwrap();
        assert_eq!(mixed.connectivity, [TRI_3, 1, 2, 3, QUAD_4, 4, 5, 6, 7].map(|v| v as CgSize));
        assert_eq!(mixed.offsets, [0, 4, 9]);
        let mut tris = SectionData::new("t".into(), TRI_3);
        push_element(&mut tris, TRI_3, &[0, 1, 2]).unwrap();
        assert_eq!((tris.count, tris.connectivity), (1, vec![1, 2, 3]));
    }
}
