//! Gmsh MSH: reader for versions 4.1 and 2.2 (ASCII and binary), writer for 4.1.
//!
//! Patches are the surface elements' physical groups: the group's name, `physical_<tag>` for an
//! unnamed group, `surface_<entity>` for elements in no group. Zones are named the same way from
//! the volume elements (`volume_<entity>`). Named groups come first, in tag order.

mod cursor;
mod read;
mod write;

use std::collections::{HashMap, HashSet};

pub use write::write;

use super::ParseError;
use crate::mesh::VolumeMesh;
use crate::surface::Surface;
use read::{RawBlock, RawMesh, Shape};

/// Names of the groups (patches or zones) of one dimension, and the group of every block.
struct Groups {
    names: Vec<String>,
    of_block: Vec<u32>,
}

impl Groups {
    fn new(raw: &RawMesh, dim: i32, prefix: &str) -> Groups {
        let labels: Vec<Option<(String, (u8, i32))>> =
            raw.blocks.iter().map(|b| (b.shape.dim() == dim).then(|| label(raw, dim, b, prefix))).collect();
        let mut distinct: Vec<&(String, (u8, i32))> = labels.iter().flatten().collect();
        distinct.sort_by(|a, b| (a.1, &a.0).cmp(&(b.1, &b.0)));
        let mut seen = HashSet::new();
        distinct.retain(|l| seen.insert(l.0.as_str()));
        let names: Vec<String> = distinct.iter().map(|l| l.0.clone()).collect();
        let index: HashMap<&str, u32> =
            names.iter().enumerate().map(|(i, n)| (n.as_str(), i as u32)).collect();
        let of_block =
            labels.iter().map(|l| l.as_ref().and_then(|l| index.get(l.0.as_str()).copied()).unwrap_or(0));
        Groups { of_block: of_block.collect(), names }
    }
}

/// The group name of a block and its sort key: named physical groups by tag, then unnamed
/// physical groups by tag, then entities without a group by entity tag.
fn label(raw: &RawMesh, dim: i32, block: &RawBlock, prefix: &str) -> (String, (u8, i32)) {
    let physicals = match block.physical {
        Some(p) => vec![p],
        None => raw.entity_physicals.get(&(dim, block.entity)).cloned().unwrap_or_default(),
    };
    if let Some((p, name)) = physicals.iter().find_map(|&p| Some((p, raw.names.get(&(dim, p))?))) {
        return (name.clone(), (0, p));
    }
    match physicals.first() {
        Some(&p) => (format!("physical_{p}"), (1, p)),
        None => (format!("{prefix}_{}", block.entity), (2, block.entity)),
    }
}

/// Read a volume mesh: cells with zones, triangles and quads as boundary faces with patches.
pub fn parse_volume(bytes: &[u8]) -> Result<VolumeMesh, ParseError> {
    let raw = read::read(bytes)?;
    let patches = Groups::new(&raw, 2, "surface");
    let zones = Groups::new(&raw, 3, "volume");
    let mut mesh = VolumeMesh::default();
    for (i, block) in raw.blocks.iter().enumerate() {
        let (patch, zone) = (patches.of_block[i], zones.of_block[i]);
        let b = &mut mesh.boundary;
        match block.shape {
            Shape::Triangle => {
                for t in block.nodes.chunks_exact(3) {
                    b.triangles.push([t[0], t[1], t[2]]);
                    b.triangle_patch.push(patch);
                }
            }
            Shape::Quad => {
                for q in block.nodes.chunks_exact(4) {
                    b.quads.push([q[0], q[1], q[2], q[3]]);
                    b.quad_patch.push(patch);
                }
            }
            Shape::Cell(kind) => {
                for cell in block.nodes.chunks_exact(kind.node_count()) {
                    mesh.push_cell(kind, cell, zone);
                }
            }
        }
    }
    if mesh.cell_count() == 0 {
        return Err(ParseError::file(
            "no volume elements (tetrahedra, pyramids, prisms, hexahedra) in the file",
        ));
    }
    mesh.points = raw.points;
    mesh.patch_names = patches.names;
    mesh.zone_names = zones.names;
    Ok(mesh)
}

/// Read a triangle surface: triangles and quads (cut in two), points renumbered to those used.
pub fn parse_surface(bytes: &[u8]) -> Result<Surface, ParseError> {
    let raw = read::read(bytes)?;
    let patches = Groups::new(&raw, 2, "surface");
    let mut surface = Surface::default();
    let mut new_index = vec![u32::MAX; raw.points.len()];
    let mut renumber = |n: u32, points: &mut Vec<_>| {
        let slot = &mut new_index[n as usize];
        if *slot == u32::MAX {
            *slot = points.len() as u32;
            points.push(raw.points[n as usize]);
        }
        *slot
    };
    for (i, block) in raw.blocks.iter().enumerate() {
        let faces: Vec<[u32; 3]> = match block.shape {
            Shape::Triangle => block.nodes.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
            Shape::Quad => {
                block.nodes.chunks_exact(4).flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect()
            }
            Shape::Cell(_) => continue,
        };
        for f in faces {
            let t = f.map(|n| renumber(n, &mut surface.points));
            surface.triangles.push(t);
            surface.triangle_patch.push(patches.of_block[i]);
        }
    }
    if surface.triangles.is_empty() {
        return Err(ParseError::file("no triangles or quadrangles in the file"));
    }
    surface.patch_names = patches.names;
    Ok(surface)
}

#[cfg(test)]
mod tests;
