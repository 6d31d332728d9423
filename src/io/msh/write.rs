//! MSH 4.1 writer (ASCII or binary): one surface entity and 2D physical group per patch, one
//! volume entity and 3D physical group per zone, all nodes in the first volume entity.

use std::io::{self, Write};

use crate::geometry::Aabb;
use crate::mesh::{CellKind, VolumeMesh};

/// Numbers written as text tokens or as little-endian binary values.
struct Out<'a> {
    w: &'a mut dyn Write,
    ascii: bool,
    first_on_line: bool,
}

impl Out<'_> {
    fn token(&mut self, value: impl std::fmt::Display) -> io::Result<()> {
        if !self.first_on_line {
            self.w.write_all(b" ")?;
        }
        self.first_on_line = false;
        write!(self.w, "{value}")
    }

    fn int(&mut self, v: i32) -> io::Result<()> {
        if self.ascii {
            self.token(v)
        } else {
            self.w.write_all(&v.to_le_bytes())
        }
    }

    fn size(&mut self, v: u64) -> io::Result<()> {
        if self.ascii {
            self.token(v)
        } else {
            self.w.write_all(&v.to_le_bytes())
        }
    }

    fn double(&mut self, v: f64) -> io::Result<()> {
        if self.ascii {
            self.token(v)
        } else {
            self.w.write_all(&v.to_le_bytes())
        }
    }

    /// End a line of numbers (nothing in binary).
    fn end_line(&mut self) -> io::Result<()> {
        self.first_on_line = true;
        if self.ascii {
            self.w.write_all(b"\n")?;
        }
        Ok(())
    }

    /// Open a section whose numbers are binary in a binary file.
    fn begin(&mut self, section: &str) -> io::Result<()> {
        writeln!(self.w, "${section}")
    }

    fn end(&mut self, section: &str) -> io::Result<()> {
        if !self.ascii {
            self.w.write_all(b"\n")?;
        }
        writeln!(self.w, "$End{section}")
    }
}

/// Names of `count` groups: the mesh's names, completed by `prefix_<index>`.
fn group_names(names: &[String], count: usize, prefix: &str) -> Vec<String> {
    (0..count)
        .map(|i| names.get(i).cloned().unwrap_or_else(|| format!("{prefix}_{i}")))
        .map(|n| n.replace('"', "'").replace(['\n', '\r'], " "))
        .collect()
}

fn max_index(indices: impl Iterator<Item = u32>) -> usize {
    indices.map(|i| i as usize + 1).max().unwrap_or(0)
}

/// Write `mesh` as MSH 4.1 (binary unless `ascii`).
pub fn write(w: &mut dyn Write, mesh: &VolumeMesh, ascii: bool) -> io::Result<()> {
    let b = &mesh.boundary;
    let patch_count =
        max_index(b.triangle_patch.iter().chain(&b.quad_patch).copied()).max(mesh.patch_names.len());
    let zone_count =
        max_index(mesh.blocks.iter().flat_map(|b| b.zone.iter().copied())).max(mesh.zone_names.len()).max(1);
    let patches = group_names(&mesh.patch_names, patch_count, "patch");
    let zones = group_names(&mesh.zone_names, zone_count, "zone");
    let mut out = Out { w, ascii, first_on_line: true };
    writeln!(out.w, "$MeshFormat\n4.1 {} 8", if ascii { 0 } else { 1 })?;
    if !ascii {
        out.w.write_all(&1i32.to_le_bytes())?;
        out.w.write_all(b"\n")?;
    }
    writeln!(out.w, "$EndMeshFormat\n$PhysicalNames\n{}", patches.len() + zones.len())?;
    for (i, name) in patches.iter().enumerate() {
        writeln!(out.w, "2 {} \"{name}\"", i + 1)?;
    }
    for (i, name) in zones.iter().enumerate() {
        writeln!(out.w, "3 {} \"{name}\"", i + 1)?;
    }
    writeln!(out.w, "$EndPhysicalNames")?;
    write_entities(&mut out, mesh, patches.len(), zones.len())?;
    write_nodes(&mut out, mesh)?;
    write_elements(&mut out, mesh, patches.len(), zones.len())
}

fn write_entities(out: &mut Out, mesh: &VolumeMesh, patches: usize, zones: usize) -> io::Result<()> {
    let bbox = if mesh.points.is_empty() {
        Aabb { min: Default::default(), max: Default::default() }
    } else {
        Aabb::from_points(&mesh.points)
    };
    out.begin("Entities")?;
    for n in [0, 0, patches, zones] {
        out.size(n as u64)?;
    }
    out.end_line()?;
    for n in (0..patches).chain(0..zones) {
        out.int(n as i32 + 1)?;
        for v in bbox.min.to_array().into_iter().chain(bbox.max.to_array()) {
            out.double(v)?;
        }
        out.size(1)?;
        out.int(n as i32 + 1)?;
        out.size(0)?;
        out.end_line()?;
    }
    out.end("Entities")
}

fn write_nodes(out: &mut Out, mesh: &VolumeMesh) -> io::Result<()> {
    let n = mesh.points.len() as u64;
    out.begin("Nodes")?;
    for v in [u64::from(n > 0), n, n.min(1), n] {
        out.size(v)?;
    }
    out.end_line()?;
    if n > 0 {
        for v in [3, 1, 0] {
            out.int(v)?;
        }
        out.size(n)?;
        out.end_line()?;
        for tag in 1..=n {
            out.size(tag)?;
            out.end_line()?;
        }
        for p in &mesh.points {
            for v in p.to_array() {
                out.double(v)?;
            }
            out.end_line()?;
        }
    }
    out.end("Nodes")
}

/// One element block: dimension, entity tag, Gmsh type, and the elements' nodes (flattened).
struct Block<'a> {
    dim: i32,
    entity: usize,
    gmsh_type: i32,
    nodes_per: usize,
    elements: Vec<&'a [u32]>,
}

/// Elements sorted into `groups` buckets by their group index.
fn bucket<'a>(elements: impl Iterator<Item = (&'a [u32], u32)>, groups: usize) -> Vec<Vec<&'a [u32]>> {
    let mut buckets = vec![Vec::new(); groups];
    for (e, g) in elements {
        if let Some(b) = buckets.get_mut(g as usize) {
            b.push(e);
        }
    }
    buckets
}

fn element_blocks(mesh: &VolumeMesh, patches: usize, zones: usize) -> Vec<Block<'_>> {
    let b = &mesh.boundary;
    let tris = bucket(b.triangles.iter().map(|t| &t[..]).zip(b.triangle_patch.iter().copied()), patches);
    let quads = bucket(b.quads.iter().map(|q| &q[..]).zip(b.quad_patch.iter().copied()), patches);
    let mut blocks = Vec::new();
    for (p, (tris, quads)) in tris.into_iter().zip(quads).enumerate() {
        blocks.push(Block { dim: 2, entity: p + 1, gmsh_type: 2, nodes_per: 3, elements: tris });
        blocks.push(Block { dim: 2, entity: p + 1, gmsh_type: 3, nodes_per: 4, elements: quads });
    }
    for kind in CellKind::ALL {
        let block = mesh.block(kind);
        let (gmsh_type, nodes_per) = (kind.gmsh_type(), kind.node_count());
        for (z, cells) in bucket(block.iter().zip(block.zone.iter().copied()), zones).into_iter().enumerate()
        {
            blocks.push(Block { dim: 3, entity: z + 1, gmsh_type, nodes_per, elements: cells });
        }
    }
    blocks.retain(|b| !b.elements.is_empty());
    blocks
}

fn write_elements(out: &mut Out, mesh: &VolumeMesh, patches: usize, zones: usize) -> io::Result<()> {
    let blocks = element_blocks(mesh, patches, zones);
    let total: u64 = blocks.iter().map(|b| b.elements.len() as u64).sum();
    out.begin("Elements")?;
    for v in [blocks.len() as u64, total, total.min(1), total] {
        out.size(v)?;
    }
    out.end_line()?;
    let mut tag = 0u64;
    for block in &blocks {
        for v in [block.dim, block.entity as i32, block.gmsh_type] {
            out.int(v)?;
        }
        out.size(block.elements.len() as u64)?;
        out.end_line()?;
        for element in &block.elements {
            tag += 1;
            out.size(tag)?;
            for &node in element.iter().take(block.nodes_per) {
                out.size(u64::from(node) + 1)?;
            }
            out.end_line()?;
        }
    }
    out.end("Elements")
}
