//! Medit / libMeshb: `.mesh` (ASCII) and `.meshb` (binary) surfaces read and written, volume
//! meshes written.
//!
//! Only `Dimension` (3, assumed when absent), `Vertices`, `Triangles` and `Quadrilaterals`
//! (split in two triangles) are read; every other section is skipped. Each element reference
//! becomes patch `ref_<n>`.
//! ASCII keywords are case-insensitive and found wherever they are, as libMeshb does.
//! Binary files start with the integer 1 (its byte order gives the file's), then the version:
//! 1 = 4-byte reals, 2 = 8-byte reals, 3 = also 8-byte keyword positions, 4 = also 8-byte
//! integers. Each keyword is `code, position of the next keyword, [line count], data`.

use std::io::Write;

use super::scan::{self, ByteReader, Tokens};
use super::ParseError;
use crate::geometry::DVec3;
use crate::mesh::{CellKind, VolumeMesh};
use crate::surface::Surface;

/// libMeshb keyword codes.
const DIMENSION: i32 = 3;
const VERTICES: i32 = 4;
const TRIANGLES: i32 = 6;
const QUADRILATERALS: i32 = 7;
const TETRAHEDRA: i32 = 8;
const PRISMS: i32 = 9;
const HEXAHEDRA: i32 = 10;
const PYRAMIDS: i32 = 49;
const END: i32 = 54;

/// The sections read, by code and (case-insensitive) ASCII name.
const SECTIONS: [(i32, &str); 5] = [
    (DIMENSION, "Dimension"),
    (VERTICES, "Vertices"),
    (TRIANGLES, "Triangles"),
    (QUADRILATERALS, "Quadrilaterals"),
    (END, "End"),
];

pub fn parse_surface(bytes: &[u8]) -> Result<Surface, ParseError> {
    match bytes.get(..4) {
        Some([1, 0, 0, 0]) => parse_binary(bytes, false),
        Some([0, 0, 0, 1]) => parse_binary(bytes, true),
        _ => parse_ascii(&scan::text(bytes)),
    }
}

/// Numbers read one at a time from either form, with errors located in the file.
trait Source {
    fn int(&mut self, what: &str) -> Result<i64, ParseError>;
    fn real(&mut self, what: &str) -> Result<f64, ParseError>;
    fn error(&self, message: String) -> ParseError;
    /// Bytes left: bounds the items still to come.
    fn remaining(&self) -> usize;

    fn dimension(&mut self) -> Result<i64, ParseError> {
        self.int("the dimension")
    }

    fn count(&mut self, what: &str) -> Result<usize, ParseError> {
        let n = self.int(&format!("the {what} count"))?;
        let n = u64::try_from(n).map_err(|_| self.error(format!("negative {what} count {n}")))?;
        scan::check_count(n, what).map_err(|m| self.error(m))
    }
}

impl Source for Tokens<'_> {
    fn int(&mut self, what: &str) -> Result<i64, ParseError> {
        Tokens::int(self, what)
    }
    fn real(&mut self, what: &str) -> Result<f64, ParseError> {
        Tokens::real(self, what)
    }
    fn error(&self, message: String) -> ParseError {
        ParseError::at_line(self.line(), message)
    }
    fn remaining(&self) -> usize {
        Tokens::remaining(self)
    }
}

/// A binary file's number sizes, from its version.
#[derive(Clone, Copy, Debug)]
struct Layout {
    int8: bool,
    real8: bool,
    position8: bool,
}

impl Layout {
    fn of_version(version: i32) -> Self {
        Layout { int8: version >= 4, real8: version >= 2, position8: version >= 3 }
    }
}

struct BinarySource<'a> {
    reader: ByteReader<'a>,
    layout: Layout,
    /// Where the last number read starts: errors about a value point at it.
    value_at: usize,
}

impl Source for BinarySource<'_> {
    fn int(&mut self, what: &str) -> Result<i64, ParseError> {
        self.value_at = self.reader.pos();
        if self.layout.int8 {
            self.reader.i64(what)
        } else {
            self.reader.i32(what).map(i64::from)
        }
    }
    fn real(&mut self, what: &str) -> Result<f64, ParseError> {
        self.value_at = self.reader.pos();
        if self.layout.real8 {
            self.reader.f64(what)
        } else {
            self.reader.f32(what).map(f64::from)
        }
    }
    fn error(&self, message: String) -> ParseError {
        ParseError::at_byte(self.value_at as u64, message)
    }
    fn remaining(&self) -> usize {
        self.reader.remaining()
    }
    /// The dimension is a 4-byte integer in every version.
    fn dimension(&mut self) -> Result<i64, ParseError> {
        self.value_at = self.reader.pos();
        self.reader.i32("the dimension").map(i64::from)
    }
}

/// Where the data of each section read starts (a source positioned after its keyword).
struct Sections<S> {
    dimension: Option<S>,
    vertices: Option<S>,
    triangles: Option<S>,
    quadrilaterals: Option<S>,
}

impl<S> Sections<S> {
    fn new() -> Self {
        Sections { dimension: None, vertices: None, triangles: None, quadrilaterals: None }
    }

    /// Record section `code` starting at `source` (codes not read are ignored).
    fn record(&mut self, code: i32, source: S, name: &str) -> Result<(), String> {
        let slot = match code {
            DIMENSION => &mut self.dimension,
            VERTICES => &mut self.vertices,
            TRIANGLES => &mut self.triangles,
            QUADRILATERALS => &mut self.quadrilaterals,
            _ => return Ok(()),
        };
        match slot.replace(source) {
            Some(_) => Err(format!("a second {name} section")),
            None => Ok(()),
        }
    }
}

fn parse_ascii(text: &str) -> Result<Surface, ParseError> {
    let mut tokens = Tokens::new(text, Some('#'));
    let mut sections = Sections::new();
    while let Some((line, token)) = tokens.next_token() {
        let Some(&(code, name)) = SECTIONS.iter().find(|(_, name)| token.eq_ignore_ascii_case(name)) else {
            continue;
        };
        if code == END {
            break;
        }
        sections.record(code, tokens.clone(), name).map_err(|m| ParseError::at_line(line, m))?;
    }
    read_sections(sections)
}

fn parse_binary(bytes: &[u8], big_endian: bool) -> Result<Surface, ParseError> {
    let mut reader = ByteReader::new(bytes, big_endian);
    reader.i32("the byte order code")?;
    let version = reader.i32("the version")?;
    if !(1..=4).contains(&version) {
        return Err(ParseError::at_byte(4, format!("unknown libMeshb version {version} (1 to 4 known)")));
    }
    let layout = Layout::of_version(version);
    let mut sections = Sections::new();
    loop {
        let start = reader.pos() as u64;
        let code = reader.i32("a keyword code")?;
        if code == END {
            break;
        }
        let position_at = reader.pos() as u64;
        let next = if layout.position8 {
            reader.i64("a next-keyword position")?
        } else {
            reader.i32("a next-keyword position").map(i64::from)?
        };
        let name = SECTIONS.iter().find(|s| s.0 == code).map_or("", |s| s.1);
        let source = BinarySource { reader: reader.clone(), layout, value_at: reader.pos() };
        sections.record(code, source, name).map_err(|m| ParseError::at_byte(start, m))?;
        if next == 0 {
            break;
        }
        // Positions must move forward, or a corrupt file could loop forever.
        if next <= start as i64 {
            let message = format!("next keyword position {next} does not move forward");
            return Err(ParseError::at_byte(position_at, message));
        }
        reader
            .seek(next as u64, "the next-keyword position")
            .map_err(|e| ParseError::at_byte(position_at, e.message))?;
    }
    read_sections(sections)
}

fn read_sections<S: Source>(sections: Sections<S>) -> Result<Surface, ParseError> {
    if let Some(mut source) = sections.dimension {
        let dimension = source.dimension()?;
        if dimension != 3 {
            return Err(source.error(format!("dimension {dimension}: only 3D surfaces are read")));
        }
    }
    let mut vertices = sections.vertices.ok_or_else(|| ParseError::file("no Vertices section"))?;
    let mut surface = Surface { points: read_vertices(&mut vertices)?, ..Surface::default() };
    let mut refs = Vec::new();
    if let Some(mut source) = sections.triangles {
        read_elements::<3>(&mut source, &mut surface, &mut refs)?;
    }
    if let Some(mut source) = sections.quadrilaterals {
        read_elements::<4>(&mut source, &mut surface, &mut refs)?;
    }
    surface.set_patches_from_labels(&refs, |r| format!("ref_{r}"));
    scan::finish(surface)
}

fn read_vertices<S: Source>(source: &mut S) -> Result<Vec<DVec3>, ParseError> {
    let count = source.count("vertex")?;
    let mut points = Vec::with_capacity(scan::capacity(count, source.remaining(), 8));
    for _ in 0..count {
        let p = [source.real("a vertex")?, source.real("a vertex")?, source.real("a vertex")?];
        source.int("a vertex reference")?;
        points.push(DVec3::from_array(p));
    }
    Ok(points)
}

/// Triangles (`N` = 3) or quadrilaterals (`N` = 4, split along their 1-3 diagonal), each with
/// its reference.
fn read_elements<const N: usize>(
    source: &mut impl Source,
    surface: &mut Surface,
    refs: &mut Vec<i64>,
) -> Result<(), ParseError> {
    let (what, corner_what, reference_what) = if N == 3 {
        ("triangle", "a triangle vertex", "a triangle reference")
    } else {
        ("quadrilateral", "a quadrilateral vertex", "a quadrilateral reference")
    };
    let count = source.count(what)?;
    let vertex_count = surface.points.len();
    surface.triangles.reserve(scan::capacity(count, source.remaining(), 8));
    for _ in 0..count {
        let mut corners = [0u32; N];
        for corner in &mut corners {
            let value = source.int(corner_what)?;
            *corner = scan::vertex_index(value, 1, vertex_count).ok_or_else(|| {
                source.error(format!("{what}: {}", scan::bad_vertex(value, vertex_count, "from 1")))
            })?;
        }
        let reference = source.int(reference_what)?;
        for triangle in scan::fan(&corners) {
            surface.triangles.push(triangle);
            refs.push(reference);
        }
    }
    Ok(())
}

/// Write `s` as Medit ASCII (`.mesh`) or binary (`.meshb`); references are patch index + 1.
/// Binary files are version 2 (8-byte reals) when they can be, else 3 or 4 for large meshes.
pub fn write_surface(w: &mut dyn Write, s: &Surface, binary: bool) -> std::io::Result<()> {
    let sections = [Section::triangles(&s.triangles, &s.triangle_patch)];
    write_sections(w, &s.points, &sections, binary)
}

/// Write `mesh` as a Medit volume mesh: boundary triangles and quadrilaterals with the patch
/// index + 1 as reference, cells with the zone index + 1. Node orders are the crate's (Gmsh)
/// ones, which are also meshio's reading of Medit files (see [`crate::mesh`]).
pub fn write_volume(w: &mut dyn Write, mesh: &VolumeMesh, binary: bool) -> std::io::Result<()> {
    let b = &mesh.boundary;
    let mut sections = vec![
        Section::triangles(&b.triangles, &b.triangle_patch),
        Section {
            code: QUADRILATERALS,
            name: "Quadrilaterals",
            nodes_per: 4,
            nodes: b.quads.as_flattened(),
            ids: &b.quad_patch,
        },
    ];
    for block in &mesh.blocks {
        let (code, name) = cell_section(block.kind);
        let nodes_per = block.kind.node_count();
        sections.push(Section { code, name, nodes_per, nodes: &block.nodes, ids: &block.zone });
    }
    sections.retain(|s| !s.ids.is_empty());
    write_sections(w, &mesh.points, &sections, binary)
}

/// libMeshb code and ASCII keyword of a cell kind.
fn cell_section(kind: CellKind) -> (i32, &'static str) {
    match kind {
        CellKind::Tetrahedron => (TETRAHEDRA, "Tetrahedra"),
        CellKind::Pyramid => (PYRAMIDS, "Pyramids"),
        CellKind::Prism => (PRISMS, "Prisms"),
        CellKind::Hexahedron => (HEXAHEDRA, "Hexahedra"),
    }
}

/// One element section to write: `nodes_per` 0-based nodes and one id per element; the
/// reference written is id + 1 (Medit reserves 0 for "no reference").
struct Section<'a> {
    code: i32,
    name: &'static str,
    nodes_per: usize,
    nodes: &'a [u32],
    ids: &'a [u32],
}

impl<'a> Section<'a> {
    fn triangles(triangles: &'a [[u32; 3]], ids: &'a [u32]) -> Self {
        Section { code: TRIANGLES, name: "Triangles", nodes_per: 3, nodes: triangles.as_flattened(), ids }
    }

    fn elements(&self) -> impl Iterator<Item = (&'a [u32], u32)> {
        self.nodes.chunks_exact(self.nodes_per).zip(self.ids.iter().copied())
    }
}

fn write_sections(
    w: &mut dyn Write,
    points: &[DVec3],
    sections: &[Section],
    binary: bool,
) -> std::io::Result<()> {
    if binary {
        write_binary_version(w, points, sections, binary_version(points, sections), false)
    } else {
        write_ascii(w, points, sections)
    }
}

fn write_ascii(w: &mut dyn Write, points: &[DVec3], sections: &[Section]) -> std::io::Result<()> {
    writeln!(w, "MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n{}", points.len())?;
    for p in points {
        // `{:e}` prints the shortest digits that read back to the same f64.
        writeln!(w, "{:e} {:e} {:e} 0", p.x, p.y, p.z)?;
    }
    for section in sections {
        writeln!(w, "\n{}\n{}", section.name, section.ids.len())?;
        for (nodes, id) in section.elements() {
            for n in nodes {
                write!(w, "{} ", u64::from(*n) + 1)?;
            }
            writeln!(w, "{}", u64::from(id) + 1)?;
        }
    }
    writeln!(w, "\nEnd")
}

/// Write the sections in binary libMeshb `version`, in either byte order (readers must take both).
fn write_binary_version(
    w: &mut dyn Write,
    points: &[DVec3],
    sections: &[Section],
    version: i32,
    big_endian: bool,
) -> std::io::Result<()> {
    let layout = Layout::of_version(version);
    let int = if layout.int8 { 8 } else { 4 };
    let real = if layout.real8 { 8 } else { 4 };
    let keyword = 4 + if layout.position8 { 8 } else { 4 };
    let vertices_at = 8 + keyword + 4;
    let mut next = vertices_at + keyword + int + points.len() as u64 * (3 * real + int);
    let mut out = BinaryWriter { w, layout, big_endian };
    out.number(1, 4)?;
    out.number(version as u64, 4)?;
    out.keyword(DIMENSION, vertices_at)?;
    out.number(3, 4)?;
    out.keyword(VERTICES, next)?;
    out.int(points.len() as u64)?;
    for p in points {
        for c in p.to_array() {
            out.real(c)?;
        }
        out.int(0)?;
    }
    for section in sections {
        next += keyword + int + section.ids.len() as u64 * (section.nodes_per as u64 + 1) * int;
        out.keyword(section.code, next)?;
        out.int(section.ids.len() as u64)?;
        for (nodes, id) in section.elements() {
            for n in nodes {
                out.int(u64::from(*n) + 1)?;
            }
            out.int(u64::from(id) + 1)?;
        }
    }
    out.keyword(END, 0)
}

/// The smallest libMeshb version with 8-byte reals that holds the points and sections.
fn binary_version(points: &[DVec3], sections: &[Section]) -> i32 {
    let fits_i32 = |n: usize| n < i32::MAX as usize;
    let counts_fit =
        sections.iter().all(|s| fits_i32(s.ids.len()) && s.ids.iter().all(|&i| i < i32::MAX as u32));
    if !fits_i32(points.len()) || !counts_fit {
        return 4;
    }
    // Upper bound of a version-2 file's size: its positions must fit in 4 bytes.
    let elements: u64 = sections.iter().map(|s| 4 * (s.nodes_per as u64 + 1) * s.ids.len() as u64).sum();
    let size = 64 + 16 * sections.len() as u64 + 28 * points.len() as u64 + elements;
    if size < i32::MAX as u64 {
        2
    } else {
        3
    }
}

/// libMeshb numbers in the file's widths and byte order.
struct BinaryWriter<'a> {
    w: &'a mut dyn Write,
    layout: Layout,
    big_endian: bool,
}

impl BinaryWriter<'_> {
    /// The low `bytes` (4 or 8) bytes of `v`; callers keep `v` in range (see `binary_version`).
    fn number(&mut self, v: u64, bytes: usize) -> std::io::Result<()> {
        let mut field = [0u8; 8];
        field[..bytes].copy_from_slice(&v.to_le_bytes()[..bytes]);
        if self.big_endian {
            field[..bytes].reverse();
        }
        self.w.write_all(&field[..bytes])
    }

    fn int(&mut self, v: u64) -> std::io::Result<()> {
        self.number(v, if self.layout.int8 { 8 } else { 4 })
    }

    fn real(&mut self, v: f64) -> std::io::Result<()> {
        if self.layout.real8 {
            self.number(v.to_bits(), 8)
        } else {
            self.number(u64::from((v as f32).to_bits()), 4)
        }
    }

    fn keyword(&mut self, code: i32, next: u64) -> std::io::Result<()> {
        self.number(code as u64, 4)?;
        self.number(next, if self.layout.position8 { 8 } else { 4 })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::scan::testing::assert_error;
    use crate::io::Location;
    use proptest::prelude::*;

    /// A unit square pyramid: a quadrilateral base (ref 2) and four triangles (ref 1), with
    /// sections this reader skips.
    const PYRAMID: &str = "MeshVersionFormatted 2
# comment: Triangles 99
dimension
3
Vertices 5
0 0 0 0
1 0 0 0
1 1 0 0
0 1 0 0
0.5 0.5 1 7
Corners 1 5
Edges 1
1 2 0
TRIANGLES
4
1 2 5 1
2 3 5 1
3 4 5 1
4 1 5 1
Quadrilaterals 1
1 4 3 2 2
NormalAtVertices 0
End
";

    #[test]
    fn ascii_reads_triangles_and_split_quadrilaterals() {
        let s = parse_surface(PYRAMID.as_bytes()).unwrap();
        assert_eq!(s.points.len(), 5);
        assert_eq!(s.triangles.len(), 6);
        assert_eq!(s.triangles[4..], [[0, 3, 2], [0, 2, 1]]);
        assert_eq!(s.patch_names, vec!["ref_1", "ref_2"]);
        assert_eq!(s.triangle_patch, vec![0, 0, 0, 0, 1, 1]);
        assert!((s.enclosed_volume() - 1.0 / 3.0).abs() < 1e-15);
    }

    #[test]
    fn malformed_ascii_names_the_line() {
        assert_error(
            parse_surface,
            PYRAMID.replace("3 4 5 1", "3 4 6 1"),
            Location::Line(18),
            "triangle: vertex index 6 out of range",
        );
        assert_error(
            parse_surface,
            PYRAMID.replace("0.5 0.5 1 7", "0.5 0.5 x 7"),
            Location::Line(10),
            "bad number 'x'",
        );
        assert_error(
            parse_surface,
            &PYRAMID[..PYRAMID.find("0 1 0 0").unwrap()],
            Location::Line(8),
            "end of file: expected a vertex",
        );
        assert_error(
            parse_surface,
            PYRAMID.replace("dimension\n3", "Dimension 2"),
            Location::Line(3),
            "dimension 2",
        );
        assert_error(parse_surface, PYRAMID.replace("Vertices", "Vertexes"), Location::File, "no Vertices");
        assert_error(
            parse_surface,
            PYRAMID.replace("Corners 1 5", "Triangles 0"),
            Location::Line(14),
            "a second Triangles section",
        );
        assert_error(
            parse_surface,
            PYRAMID.replace("Vertices 5", "Vertices -5"),
            Location::Line(5),
            "negative vertex count",
        );
    }

    fn written(s: &Surface, version: i32, big_endian: bool) -> Vec<u8> {
        let mut bytes = Vec::new();
        let sections = [Section::triangles(&s.triangles, &s.triangle_patch)];
        write_binary_version(&mut bytes, &s.points, &sections, version, big_endian).unwrap();
        bytes
    }

    fn assert_same(a: &Surface, b: &Surface) {
        let bits = |s: &Surface| s.points.iter().map(|p| p.to_array().map(f64::to_bits)).collect::<Vec<_>>();
        assert_eq!(bits(a), bits(b));
        assert_eq!(a.triangles, b.triangles);
        assert_eq!(a.triangle_patch, b.triangle_patch);
    }

    #[test]
    fn every_binary_version_and_byte_order_reads_back() {
        let mut s = parse_surface(PYRAMID.as_bytes()).unwrap();
        s.points[4] = DVec3::new(0.1, -0.0, 1.0 / 3.0);
        for version in 1..=4 {
            for big_endian in [false, true] {
                let back = parse_surface(&written(&s, version, big_endian)).unwrap();
                if version == 1 {
                    assert_eq!(back.points[4].y.to_bits(), (-0.0f64).to_bits());
                    assert_eq!(back.points[4].z, f64::from((1.0f64 / 3.0) as f32));
                } else {
                    assert_same(&s, &back);
                }
                assert_eq!(back.patch_names, vec!["ref_1", "ref_2"]);
            }
        }
        let mut ascii = Vec::new();
        write_surface(&mut ascii, &s, false).unwrap();
        assert_same(&s, &parse_surface(&ascii).unwrap());
        let mut binary = Vec::new();
        write_surface(&mut binary, &s, true).unwrap();
        assert_eq!(binary, written(&s, 2, false));
    }

    #[test]
    fn volume_mesh_boundary_reads_back_and_cells_are_counted() {
        let mesh = crate::quality::samples::hybrid_column();
        let b = &mesh.boundary;
        for binary in [false, true] {
            let mut bytes = Vec::new();
            write_volume(&mut bytes, &mesh, binary).unwrap();
            let back = parse_surface(&bytes).unwrap();
            assert_eq!(back.triangles.len(), b.triangles.len() + 2 * b.quads.len());
            // The boundary faces (outward) enclose the column of four unit cubes.
            assert!((back.enclosed_volume() - 4.0).abs() < 1e-12, "{}", back.enclosed_volume());
            if !binary {
                let text = String::from_utf8(bytes).unwrap();
                for kind in CellKind::ALL {
                    let name = cell_section(kind).1;
                    let at = text.find(&format!("\n{name}\n")).unwrap();
                    let count = text[at + name.len() + 2..].lines().next().unwrap();
                    assert_eq!(count, mesh.block(kind).len().to_string(), "{name}");
                }
            }
        }
    }

    /// A little-endian version-2 file made of `(code, payload)` keywords, positions filled in.
    fn meshb(keywords: &[(i32, Vec<u8>)]) -> Vec<u8> {
        let mut out = [1i32.to_le_bytes(), 2i32.to_le_bytes()].concat();
        for (k, (code, payload)) in keywords.iter().enumerate() {
            let next = out.len() + 8 + payload.len();
            let next = if k + 1 == keywords.len() { 0 } else { next as i32 };
            out.extend(code.to_le_bytes());
            out.extend(next.to_le_bytes());
            out.extend(payload);
        }
        out
    }

    fn ints(values: &[i32]) -> Vec<u8> {
        values.iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    fn unit_triangle() -> Vec<(i32, Vec<u8>)> {
        let mut vertices = ints(&[3]);
        for p in [[0.0f64, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            vertices.extend(p.iter().flat_map(|c| c.to_le_bytes()));
            vertices.extend(ints(&[0]));
        }
        vec![
            (DIMENSION, ints(&[3])),
            (5, ints(&[1, 1, 2, 0])),
            (VERTICES, vertices),
            (TRIANGLES, ints(&[1, 1, 2, 3, 4])),
            (END, vec![]),
        ]
    }

    #[test]
    fn binary_skips_unknown_keywords_and_reports_bad_ones() {
        let s = parse_surface(&meshb(&unit_triangle())).unwrap();
        assert_eq!(s.triangles, vec![[0, 1, 2]]);
        assert_eq!(s.patch_names, vec!["ref_4"]);

        let mut bad_index = unit_triangle();
        bad_index[3].1 = ints(&[1, 1, 2, 9, 4]);
        let bytes = meshb(&bad_index);
        assert_error(
            parse_surface,
            &bytes,
            Location::Byte(bytes.len() as u64 - 12 - 4),
            "vertex index 9 out of range",
        );

        let mut backwards = meshb(&unit_triangle());
        backwards[12..16].copy_from_slice(&4i32.to_le_bytes());
        assert_error(parse_surface, &backwards, Location::Byte(12), "does not move forward");

        let mut beyond = meshb(&unit_triangle());
        beyond[12..16].copy_from_slice(&1000i32.to_le_bytes());
        assert_error(parse_surface, &beyond, Location::Byte(12), "points to byte 1000, beyond the end");

        let good = meshb(&unit_triangle());
        let (end_at, cut) = (good.len() - 8, good.len() - 14);
        let message = format!("points to byte {end_at}, beyond the end of the file ({cut} bytes)");
        assert_error(parse_surface, &good[..cut], Location::Byte(end_at as u64 - 28 + 4), &message);
        let no_end = meshb(&unit_triangle()[..4]);
        assert_error(
            parse_surface,
            &no_end[..no_end.len() - 2],
            Location::Byte(no_end.len() as u64 - 4),
            "file ends inside a triangle reference",
        );
        let mut version = good.clone();
        version[4] = 9;
        assert_error(parse_surface, &version, Location::Byte(4), "unknown libMeshb version 9");
    }

    proptest! {
        #[test]
        fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
            let _ = parse_surface(&bytes);
            for header in [[1u8, 0, 0, 0, 2, 0, 0, 0], [0, 0, 0, 1, 0, 0, 0, 4]] {
                let mut binary = header.to_vec();
                binary.extend(&bytes);
                let _ = parse_surface(&binary);
            }
        }

        #[test]
        fn corrupted_binary_never_panics(
            edits in proptest::collection::vec((0usize..400, any::<u8>()), 1..4),
            version in 1i32..=4,
        ) {
            let s = parse_surface(PYRAMID.as_bytes()).unwrap();
            let mut binary = written(&s, version, false);
            for (at, byte) in edits {
                let n = binary.len();
                binary[at % n] = byte;
            }
            let _ = parse_surface(&binary);
        }

        #[test]
        fn truncated_files_never_panic(cut in 0usize..PYRAMID.len(), version in 1i32..=4) {
            let _ = parse_surface(&PYRAMID.as_bytes()[..cut]);
            let s = parse_surface(PYRAMID.as_bytes()).unwrap();
            let binary = written(&s, version, version % 2 == 0);
            let _ = parse_surface(&binary[..cut.min(binary.len())]);
        }
    }
}
