//! Reading the sections of an MSH 4.1 or 2.2 file (ASCII or binary) into a [`RawMesh`].

use std::collections::HashMap;

use super::cursor::Cursor;
use crate::geometry::DVec3;
use crate::io::ParseError;
use crate::mesh::CellKind;

/// The shape of a first-order element blmesh keeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    Triangle,
    Quad,
    Cell(CellKind),
}

impl Shape {
    pub fn node_count(self) -> usize {
        match self {
            Shape::Triangle => 3,
            Shape::Quad => 4,
            Shape::Cell(k) => k.node_count(),
        }
    }

    pub fn dim(self) -> i32 {
        if matches!(self, Shape::Cell(_)) {
            3
        } else {
            2
        }
    }
}

/// What blmesh does with a Gmsh element type.
enum ElementType {
    Keep(Shape),
    /// Points and lines (of any order): skipped.
    Skip(usize),
    /// Higher-order surface or volume elements: an error.
    HigherOrder(&'static str),
}

/// Gmsh element types by number (`None`: unknown).
fn element_type(t: i32) -> Option<ElementType> {
    use ElementType::*;
    Some(match t {
        2 => Keep(Shape::Triangle),
        3 => Keep(Shape::Quad),
        4..=7 => Keep(Shape::Cell(CellKind::from_gmsh_type(t)?)),
        1 => Skip(2),
        8 => Skip(3),
        15 => Skip(1),
        26 => Skip(4),
        27 => Skip(5),
        28 => Skip(6),
        9 | 20 | 21 | 22 | 23 | 24 | 25 => HigherOrder("triangle"),
        10 | 16 => HigherOrder("quadrangle"),
        11 | 29 | 30 | 31 => HigherOrder("tetrahedron"),
        12 | 17 | 92 | 93 => HigherOrder("hexahedron"),
        13 | 18 => HigherOrder("prism"),
        14 | 19 => HigherOrder("pyramid"),
        _ => return None,
    })
}

/// A run of elements of one shape from one entity.
#[derive(Clone, Debug)]
pub struct RawBlock {
    pub shape: Shape,
    /// Elementary entity tag.
    pub entity: i32,
    /// Physical tag given on the element (MSH 2.2); MSH 4.1 gives them per entity.
    pub physical: Option<i32>,
    /// Dense node indices, `shape.node_count()` per element.
    pub nodes: Vec<u32>,
}

/// The content of an MSH file that blmesh uses.
#[derive(Debug, Default)]
pub struct RawMesh {
    pub points: Vec<DVec3>,
    /// Physical group names by (dimension, tag).
    pub names: HashMap<(i32, i32), String>,
    /// Physical tags of each entity by (dimension, tag) (MSH 4.1 `$Entities`).
    pub entity_physicals: HashMap<(i32, i32), Vec<i32>>,
    pub blocks: Vec<RawBlock>,
    /// Node tag -> dense index (tags may be sparse and in any order).
    node_index: HashMap<u64, u32>,
}

/// The MSH version of a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Version {
    V2,
    V4,
}

/// Parse an MSH 4.1 or 2.2 file (ASCII or binary).
pub fn read(bytes: &[u8]) -> Result<RawMesh, ParseError> {
    let mut c = Cursor::new(bytes);
    let mut mesh = RawMesh::default();
    let mut version = None;
    let mut binary = false;
    while !c.at_end() {
        let section = c.token("a section such as $Nodes")?;
        let Some(name) = section.strip_prefix('$') else {
            return Err(c.error(format!("expected a section such as $Nodes, found '{}'", clip(section))));
        };
        if name == "MeshFormat" {
            let (v, b) = read_format(&mut c)?;
            (version, binary) = (Some(v), b);
            c.expect("$EndMeshFormat")?;
            continue;
        }
        let Some(v) = version else {
            return Err(c.error(format!("${} before $MeshFormat: not an MSH file", clip(name))));
        };
        match (name, v) {
            ("PhysicalNames", _) => read_physical_names(&mut c, &mut mesh)?,
            ("Entities", Version::V4) => with_binary(&mut c, binary, |c| read_entities(c, &mut mesh))?,
            ("Nodes", Version::V4) => with_binary(&mut c, binary, |c| read_nodes4(c, &mut mesh))?,
            ("Elements", Version::V4) => with_binary(&mut c, binary, |c| read_elements4(c, &mut mesh))?,
            ("Nodes", Version::V2) => read_nodes2(&mut c, binary, &mut mesh)?,
            ("Elements", Version::V2) => read_elements2(&mut c, binary, &mut mesh)?,
            _ => {
                c.skip_past(&format!("$End{name}"))?;
                continue;
            }
        }
        c.expect(&format!("$End{name}"))?;
    }
    if version.is_none() {
        return Err(ParseError::file("no $MeshFormat section in the file: not an MSH file"));
    }
    Ok(mesh)
}

/// Run a section parser with binary numbers if the file is binary.
fn with_binary(
    c: &mut Cursor,
    binary: bool,
    f: impl FnOnce(&mut Cursor) -> Result<(), ParseError>,
) -> Result<(), ParseError> {
    c.set_binary(binary);
    let r = f(c);
    c.set_binary(false);
    r
}

fn clip(s: &str) -> String {
    s.chars().take(40).collect()
}

/// `$MeshFormat`: version, file type, data size and (binary) the endianness marker.
fn read_format(c: &mut Cursor) -> Result<(Version, bool), ParseError> {
    let v: String = c.token("the MSH version")?.to_string();
    let version = match v.as_str() {
        "4.1" => Version::V4,
        "2.2" | "2.1" | "2" | "2.0" => Version::V2,
        "4" | "4.0" => return Err(c.error("MSH 4.0 is not supported: save the mesh as MSH 4.1 or 2.2")),
        _ => return Err(c.error(format!("unsupported MSH version '{}' (expected 4.1 or 2.2)", clip(&v)))),
    };
    let file_type: i32 = c.parse("the file type (0 ASCII, 1 binary)")?;
    let data_size: usize = c.parse("the data size")?;
    if !matches!(data_size, 4 | 8) {
        return Err(c.error(format!("unsupported data size {data_size} (expected 8)")));
    }
    c.size_t = data_size;
    let binary = match file_type {
        0 => false,
        1 => true,
        _ => return Err(c.error(format!("file type {file_type} is neither 0 (ASCII) nor 1 (binary)"))),
    };
    if binary {
        c.set_binary(true);
        let marker = c.take(4, "the endianness marker (int 1)")?;
        let marker = [marker[0], marker[1], marker[2], marker[3]];
        c.swap = match (u32::from_le_bytes(marker), u32::from_be_bytes(marker)) {
            (1, _) => false,
            (_, 1) => true,
            _ => return Err(c.error(format!("bad endianness marker {marker:?} (expected the int 1)"))),
        };
        c.set_binary(false);
    }
    Ok((version, binary))
}

/// `$PhysicalNames`: always text.
fn read_physical_names(c: &mut Cursor, mesh: &mut RawMesh) -> Result<(), ParseError> {
    let count: u64 = c.parse("the number of physical names")?;
    for _ in 0..count {
        let dim: i32 = c.parse("the dimension of a physical name")?;
        let tag: i32 = c.parse("the tag of a physical name")?;
        let name = c.rest_of_line().trim();
        let name = name.strip_prefix('"').and_then(|n| n.strip_suffix('"')).unwrap_or(name);
        mesh.names.insert((dim, tag), name.to_string());
    }
    Ok(())
}

/// `$Entities` (4.1): the physical tags of every entity.
fn read_entities(c: &mut Cursor, mesh: &mut RawMesh) -> Result<(), ParseError> {
    let mut counts = [0u64; 4];
    for (dim, n) in counts.iter_mut().enumerate() {
        *n = c.size(&format!("the number of entities of dimension {dim}"))?;
    }
    for (dim, &n) in counts.iter().enumerate() {
        for _ in 0..n {
            let tag = c.int("an entity tag")?;
            for _ in 0..if dim == 0 { 3 } else { 6 } {
                c.double("an entity bounding box")?;
            }
            let n_phys = c.size("the number of physical tags")?;
            let mut physicals = Vec::with_capacity(c.capacity(n_phys, 2));
            for _ in 0..n_phys {
                physicals.push(c.int("a physical tag")?);
            }
            mesh.entity_physicals.insert((dim as i32, tag), physicals);
            if dim > 0 {
                let n_bound = c.size("the number of bounding entities")?;
                for _ in 0..n_bound {
                    c.int("a bounding entity tag")?;
                }
            }
        }
    }
    Ok(())
}

/// Register a node: its tag must be new.
fn add_node(c: &Cursor, mesh: &mut RawMesh, tag: u64, p: DVec3) -> Result<(), ParseError> {
    let index = u32::try_from(mesh.points.len()).map_err(|_| c.error("more than 2^32 nodes"))?;
    if mesh.node_index.insert(tag, index).is_some() {
        return Err(c.error(format!("node tag {tag} appears twice")));
    }
    mesh.points.push(p);
    Ok(())
}

fn read_point(c: &mut Cursor) -> Result<DVec3, ParseError> {
    Ok(DVec3::new(c.double("a node's x")?, c.double("a node's y")?, c.double("a node's z")?))
}

/// `$Nodes` (4.1): blocks of tags followed by their coordinates.
fn read_nodes4(c: &mut Cursor, mesh: &mut RawMesh) -> Result<(), ParseError> {
    let blocks = c.size("the number of node blocks")?;
    let total = c.size("the number of nodes")?;
    c.size("the smallest node tag")?;
    c.size("the largest node tag")?;
    mesh.points.reserve(c.capacity(total, 8));
    for _ in 0..blocks {
        let dim = c.int("a node block's entity dimension")?;
        c.int("a node block's entity tag")?;
        let parametric = c.int("a node block's parametric flag")?;
        let n = c.size("the number of nodes in a block")?;
        let mut tags = Vec::with_capacity(c.capacity(n, 2));
        for _ in 0..n {
            tags.push(c.size("a node tag")?);
        }
        let params = if parametric != 0 { dim.clamp(0, 3) } else { 0 };
        for tag in tags {
            let p = read_point(c)?;
            for _ in 0..params {
                c.double("a node's parametric coordinate")?;
            }
            add_node(c, mesh, tag, p)?;
        }
    }
    Ok(())
}

/// `$Nodes` (2.2): a text count, then `tag x y z` records.
fn read_nodes2(c: &mut Cursor, binary: bool, mesh: &mut RawMesh) -> Result<(), ParseError> {
    let n: u64 = c.parse("the number of nodes")?;
    c.set_binary(binary);
    mesh.points.reserve(c.capacity(n, 8));
    for _ in 0..n {
        let tag = c.count("a node tag", false)?;
        let p = read_point(c)?;
        add_node(c, mesh, tag, p)?;
    }
    c.set_binary(false);
    Ok(())
}

/// Dense index of a node tag named by an element.
fn node(c: &Cursor, index: &HashMap<u64, u32>, tag: u64, element: u64) -> Result<u32, ParseError> {
    let missing = || c.error(format!("element {element} refers to node {tag}, which is not in $Nodes"));
    index.get(&tag).copied().ok_or_else(missing)
}

/// The block to append elements of (shape, entity, physical) to: the last one if it matches.
fn block_for(blocks: &mut Vec<RawBlock>, shape: Shape, entity: i32, physical: Option<i32>) -> &mut RawBlock {
    let matches = |b: &RawBlock| b.shape == shape && b.entity == entity && b.physical == physical;
    if !blocks.last().is_some_and(matches) {
        blocks.push(RawBlock { shape, entity, physical, nodes: Vec::new() });
    }
    let last = blocks.len() - 1;
    &mut blocks[last]
}

fn higher_order_error(c: &Cursor, t: i32, shape: &str) -> ParseError {
    c.error(format!("element type {t} is a higher-order {shape}: blmesh reads first-order meshes only"))
}

/// `$Elements` (4.1): blocks of elements of one type from one entity.
fn read_elements4(c: &mut Cursor, mesh: &mut RawMesh) -> Result<(), ParseError> {
    let blocks = c.size("the number of element blocks")?;
    c.size("the number of elements")?;
    c.size("the smallest element tag")?;
    c.size("the largest element tag")?;
    for _ in 0..blocks {
        c.int("an element block's entity dimension")?;
        let entity = c.int("an element block's entity tag")?;
        let t = c.int("an element type")?;
        let n = c.size("the number of elements in a block")?;
        let shape = match element_type(t) {
            Some(ElementType::Keep(shape)) => shape,
            Some(ElementType::Skip(nodes)) => {
                skip_elements4(c, n, nodes)?;
                continue;
            }
            Some(ElementType::HigherOrder(s)) => return Err(higher_order_error(c, t, s)),
            None if !c.binary => {
                c.rest_of_line(); // the block header's line break, then one line per element
                for _ in 0..n {
                    c.rest_of_line();
                }
                continue;
            }
            None => {
                return Err(c.error(format!("unknown element type {t}: its size is unknown in a binary file")))
            }
        };
        let nodes_per = shape.node_count();
        let block = block_for(&mut mesh.blocks, shape, entity, None);
        block.nodes.reserve(c.capacity(n, 2) * nodes_per);
        for _ in 0..n {
            let tag = c.size("an element tag")?;
            for _ in 0..nodes_per {
                let t = c.size("an element's node tag")?;
                block.nodes.push(node(c, &mesh.node_index, t, tag)?);
            }
        }
    }
    Ok(())
}

fn skip_elements4(c: &mut Cursor, n: u64, nodes: usize) -> Result<(), ParseError> {
    for _ in 0..n {
        for _ in 0..=nodes {
            c.size("an element's tag or node")?;
        }
    }
    Ok(())
}

/// `$Elements` (2.2): a text count, then elements with their tags (text: one per line; binary:
/// in runs of one type that share the number of tags).
fn read_elements2(c: &mut Cursor, binary: bool, mesh: &mut RawMesh) -> Result<(), ParseError> {
    let n: u64 = c.parse("the number of elements")?;
    if !binary {
        for _ in 0..n {
            read_element2_text(c, mesh)?;
        }
        return Ok(());
    }
    c.set_binary(true);
    let mut read = 0u64;
    while read < n {
        let t = c.int("an element type")?;
        let follow = c.count("the number of elements that follow", false)?;
        let n_tags = c.count("the number of tags", false)?;
        let nodes_per = match element_type(t) {
            Some(ElementType::Keep(shape)) => shape.node_count(),
            Some(ElementType::Skip(nodes)) => nodes,
            Some(ElementType::HigherOrder(s)) => return Err(higher_order_error(c, t, s)),
            None => {
                return Err(c.error(format!("unknown element type {t}: its size is unknown in a binary file")))
            }
        };
        if follow == 0 || follow > n - read {
            return Err(c.error(format!("element header announces {follow} elements, {} remain", n - read)));
        }
        for _ in 0..follow {
            let tag = c.count("an element tag", false)?;
            let mut tags = [0i32; 2];
            for k in 0..n_tags {
                let v = c.int("an element's tag")?;
                if let Some(slot) = tags.get_mut(k as usize) {
                    *slot = v;
                }
            }
            let mut nodes = [0u64; 8];
            for slot in nodes.iter_mut().take(nodes_per) {
                *slot = c.count("an element's node", false)?;
            }
            if let Some(ElementType::Keep(shape)) = element_type(t) {
                push_element2(c, mesh, shape, tag, tags, n_tags, &nodes[..nodes_per])?;
            }
        }
        read += follow;
    }
    c.set_binary(false);
    Ok(())
}

fn read_element2_text(c: &mut Cursor, mesh: &mut RawMesh) -> Result<(), ParseError> {
    let tag: u64 = c.parse("an element tag")?;
    let t: i32 = c.parse("an element type")?;
    let n_tags: u64 = c.parse("the number of tags")?;
    let mut tags = [0i32; 2];
    for k in 0..n_tags {
        let v: i32 = c.parse("an element's tag")?;
        if let Some(slot) = tags.get_mut(k as usize) {
            *slot = v;
        }
    }
    let shape = match element_type(t) {
        Some(ElementType::Keep(shape)) => shape,
        Some(ElementType::HigherOrder(s)) => return Err(higher_order_error(c, t, s)),
        Some(ElementType::Skip(_)) | None => {
            c.rest_of_line();
            return Ok(());
        }
    };
    let mut nodes = [0u64; 8];
    for slot in nodes.iter_mut().take(shape.node_count()) {
        *slot = c.parse("an element's node")?;
    }
    push_element2(c, mesh, shape, tag, tags, n_tags, &nodes[..shape.node_count()])
}

/// Add an MSH 2.2 element: tag 1 is its physical group (0: none), tag 2 its entity.
fn push_element2(
    c: &Cursor,
    mesh: &mut RawMesh,
    shape: Shape,
    tag: u64,
    tags: [i32; 2],
    n_tags: u64,
    nodes: &[u64],
) -> Result<(), ParseError> {
    let physical = (n_tags >= 1 && tags[0] != 0).then_some(tags[0]);
    let entity = if n_tags >= 2 { tags[1] } else { 0 };
    let mut indices = [0u32; 8];
    for (i, &t) in indices.iter_mut().zip(nodes) {
        *i = node(c, &mesh.node_index, t, tag)?;
    }
    block_for(&mut mesh.blocks, shape, entity, physical).nodes.extend_from_slice(&indices[..nodes.len()]);
    Ok(())
}
