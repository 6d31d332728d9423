//! STL: ASCII (one patch per `solid NAME ... endsolid` block) and binary (one patch).
//!
//! Facet normals are ignored (exporters often get them wrong); the vertex order gives the
//! orientation. STL repeats every shared vertex, so coincident vertices are welded (bit-exact)
//! across the whole file, solids included.

use super::scan::{self, ByteReader, Tokens};
use super::ParseError;
use crate::geometry::DVec3;
use crate::surface::{PatchTable, Surface};

const BINARY_HEADER: usize = 80;
const BINARY_RECORD: usize = 50;

/// Parse an ASCII or binary STL. A file that starts with `solid` is ASCII unless it fails to
/// parse as ASCII and its size is exactly that of a binary STL (some binary exporters put
/// `solid` in the header).
pub fn parse(bytes: &[u8]) -> Result<Surface, ParseError> {
    let text_start = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes).trim_ascii_start();
    if !text_start.get(..5).is_some_and(|start| start.eq_ignore_ascii_case(b"solid")) {
        return parse_binary(bytes);
    }
    match parse_ascii(&scan::text(bytes)) {
        Ok(surface) => Ok(surface),
        Err(ascii_error) if binary_size_matches(bytes) => parse_binary(bytes).map_err(|_| ascii_error),
        Err(ascii_error) => Err(ascii_error),
    }
}

fn binary_size_matches(bytes: &[u8]) -> bool {
    binary_triangle_count(bytes).is_some_and(|n| expected_binary_size(n) == bytes.len() as u64)
}

fn binary_triangle_count(bytes: &[u8]) -> Option<u32> {
    let count = bytes.get(BINARY_HEADER..BINARY_HEADER + 4)?;
    Some(u32::from_le_bytes([count[0], count[1], count[2], count[3]]))
}

fn expected_binary_size(count: u32) -> u64 {
    (BINARY_HEADER + 4) as u64 + BINARY_RECORD as u64 * u64::from(count)
}

/// The raw triangles of a file before welding: three vertices each, and a patch each.
#[derive(Default)]
struct Soup {
    corners: Vec<DVec3>,
    triangle_patch: Vec<u32>,
}

impl Soup {
    fn into_surface(self, patch_names: Vec<String>) -> Result<Surface, ParseError> {
        if self.corners.len() > scan::MAX_COUNT {
            return Err(ParseError::file("too many vertices for 32-bit indices"));
        }
        let triangles =
            (0..self.triangle_patch.len() as u32).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
        let mut surface =
            Surface { points: self.corners, triangles, triangle_patch: self.triangle_patch, patch_names };
        surface.weld_exact();
        scan::finish(surface)
    }
}

fn parse_ascii(text: &str) -> Result<Surface, ParseError> {
    let mut tokens = Tokens::new(text, None);
    let mut soup = Soup::default();
    let mut patches = PatchTable::default();
    let mut solid_number = 0;
    while let Some((line, word)) = tokens.next_token() {
        if !word.eq_ignore_ascii_case("solid") {
            return Err(ParseError::at_line(line, format!("expected 'solid', found '{word}'")));
        }
        solid_number += 1;
        let name = match tokens.rest_of_line() {
            "" => format!("solid_{solid_number}"),
            name => name.to_owned(),
        };
        let patch = patches.index(&name);
        read_facets(&mut tokens, &mut soup, patch)?;
    }
    soup.into_surface(patches.into_names())
}

/// Read the facets of one solid, through its `endsolid` line.
fn read_facets(tokens: &mut Tokens, soup: &mut Soup, patch: u32) -> Result<(), ParseError> {
    loop {
        let (line, word) = tokens.require("'facet' or 'endsolid'")?;
        if word.eq_ignore_ascii_case("endsolid") {
            tokens.rest_of_line();
            return Ok(());
        } else if word.eq_ignore_ascii_case("facet") {
            read_facet(tokens, soup)?;
            soup.triangle_patch.push(patch);
        } else {
            return Err(ParseError::at_line(line, format!("expected 'facet' or 'endsolid', found '{word}'")));
        }
    }
}

/// The rest of a facet after its `facet` keyword.
fn read_facet(tokens: &mut Tokens, soup: &mut Soup) -> Result<(), ParseError> {
    tokens.keyword("normal")?;
    tokens.point("the facet normal")?;
    tokens.keyword("outer")?;
    tokens.keyword("loop")?;
    for _ in 0..3 {
        tokens.keyword("vertex")?;
        soup.corners.push(DVec3::from_array(tokens.point("a vertex coordinate")?));
    }
    tokens.keyword("endloop")?;
    tokens.keyword("endfacet")?;
    Ok(())
}

fn parse_binary(bytes: &[u8]) -> Result<Surface, ParseError> {
    let count = binary_triangle_count(bytes).ok_or_else(|| {
        ParseError::at_byte(
            bytes.len() as u64,
            format!(
                "not an STL file: too short for a binary STL header ({} bytes, at least {} needed) \
                 and not ASCII (no 'solid' at the start)",
                bytes.len(),
                BINARY_HEADER + 4
            ),
        )
    })?;
    check_binary_size(bytes.len(), count)?;
    let mut reader = ByteReader::new(bytes, false);
    reader.take(BINARY_HEADER + 4, "the header")?;
    let mut soup = Soup::default();
    soup.corners.reserve(3 * count as usize);
    for _ in 0..count {
        reader.take(12, "a facet normal")?;
        for _ in 0..3 {
            let p = [reader.f32("a vertex")?, reader.f32("a vertex")?, reader.f32("a vertex")?];
            soup.corners.push(DVec3::from_array(p.map(f64::from)));
        }
        reader.take(2, "a facet attribute")?;
        soup.triangle_patch.push(0);
    }
    soup.into_surface(vec![binary_patch_name(&bytes[..BINARY_HEADER])])
}

fn check_binary_size(len: usize, count: u32) -> Result<(), ParseError> {
    let expected = expected_binary_size(count);
    let actual = len as u64;
    if actual < expected {
        let complete = (actual - (BINARY_HEADER + 4) as u64) / BINARY_RECORD as u64;
        let offset = (BINARY_HEADER + 4) as u64 + complete * BINARY_RECORD as u64;
        return Err(ParseError::at_byte(
            offset,
            format!(
                "binary STL truncated: the header says {count} triangles ({expected} bytes) \
                 but the file has {actual} bytes; triangle {} is cut off",
                complete + 1
            ),
        ));
    }
    if actual > expected {
        return Err(ParseError::at_byte(
            expected,
            format!(
                "binary STL has {} bytes after its {count} triangles: the header says {expected} \
                 bytes, the file has {actual}",
                actual - expected
            ),
        ));
    }
    Ok(())
}

/// The header text as patch name if it is printable (minus a leading `solid`), else `wall`.
fn binary_patch_name(header: &[u8]) -> String {
    // Headers are often padded with NUL bytes or spaces.
    let is_padding = |b: &u8| *b == 0 || b.is_ascii_whitespace();
    let start = header.iter().position(|b| !is_padding(b)).unwrap_or(header.len());
    let end = header.iter().rposition(|b| !is_padding(b)).map_or(start, |i| i + 1);
    let text = &header[start..end];
    let text = text.strip_prefix(b"solid").map(<[u8]>::trim_ascii).unwrap_or(text);
    let printable = !text.is_empty() && text.iter().all(|&b| b.is_ascii_graphic() || b == b' ');
    match std::str::from_utf8(text) {
        Ok(name) if printable => name.to_owned(),
        _ => "wall".to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::scan::testing::assert_error;
    use crate::io::Location;
    use proptest::prelude::*;

    const TWO_SOLIDS: &str = "solid top
  facet normal 0 0 0
    outer loop
      vertex 0 0 0
      vertex 1 0 0
      vertex 0 1 0
    endloop
  endfacet
endsolid top
solid
  facet normal 9 9 9
    outer loop
      vertex 1 0 0
      vertex -0.0 0 0
      vertex 0 0 1
    endloop
  endfacet
endsolid
";

    fn binary(header: &[u8], triangles: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut b = header.to_vec();
        b.resize(BINARY_HEADER, 0);
        b.extend((triangles.len() as u32).to_le_bytes());
        for t in triangles {
            b.extend([0u8; 12]);
            for c in t.iter().flatten() {
                b.extend(c.to_le_bytes());
            }
            b.extend([0u8; 2]);
        }
        b
    }

    const TETRA: [[[f32; 3]; 3]; 4] = [
        [[0., 0., 0.], [0., 1., 0.], [1., 0., 0.]],
        [[0., 0., 0.], [1., 0., 0.], [0., 0., 1.]],
        [[0., 0., 0.], [0., 0., 1.], [0., 1., 0.]],
        [[1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
    ];

    #[test]
    fn ascii_solids_become_patches_and_vertices_are_welded_across_them() {
        let s = parse(TWO_SOLIDS.as_bytes()).unwrap();
        assert_eq!(s.patch_names, vec!["top", "solid_2"]);
        assert_eq!(s.triangle_patch, vec![0, 1]);
        // (1,0,0) and the origin (-0.0 == 0.0) are shared: 4 distinct points.
        assert_eq!(s.points.len(), 4);
        assert_eq!(s.triangles, vec![[0, 1, 2], [1, 0, 3]]);
        assert!(s.points.iter().all(|p| !p.x.is_sign_negative()));
    }

    #[test]
    fn a_name_used_twice_is_one_patch() {
        let text = format!("{TWO_SOLIDS}{TWO_SOLIDS}");
        let s = parse(text.as_bytes()).unwrap();
        assert_eq!(s.patch_names, vec!["top", "solid_2", "solid_4"]);
        assert_eq!(s.triangle_patch, vec![0, 1, 0, 2]);
        let text = TWO_SOLIDS.replace("solid\n", "solid top\n");
        let s = parse(text.as_bytes()).unwrap();
        assert_eq!(s.patch_names, vec!["top"]);
        assert_eq!(s.triangle_patch, vec![0, 0]);
    }

    #[test]
    fn malformed_ascii_names_the_line_and_the_problem() {
        let missing_vertex = TWO_SOLIDS.replacen("      vertex 0 1 0\n", "", 1);
        assert_error(parse, &missing_vertex, Location::Line(6), "expected 'vertex', found 'endloop'");
        assert_error(
            parse,
            &TWO_SOLIDS.replacen("vertex 1 0 0", "vertex 1 0x 0", 1),
            Location::Line(5),
            "bad number '0x'",
        );
        assert_error(
            parse,
            &TWO_SOLIDS.replacen("    endloop\n", "", 1),
            Location::Line(7),
            "expected 'endloop', found 'endfacet'",
        );
        assert_error(
            parse,
            &TWO_SOLIDS.replacen("  endfacet\n", "", 1),
            Location::Line(8),
            "expected 'endfacet', found 'endsolid'",
        );
        assert_error(
            parse,
            TWO_SOLIDS.trim_end().strip_suffix("endsolid").unwrap(),
            Location::Line(17),
            "end of file: expected 'facet' or 'endsolid'",
        );
        assert_error(
            parse,
            &TWO_SOLIDS[..TWO_SOLIDS.find("vertex 0 1 0").unwrap()],
            Location::Line(5),
            "end of file: expected 'vertex'",
        );
        assert_error(
            parse,
            &format!("{TWO_SOLIDS}junk"),
            Location::Line(19),
            "expected 'solid', found 'junk'",
        );
    }

    #[test]
    fn nan_and_inf_coordinates_are_read() {
        let s = parse(TWO_SOLIDS.replace("vertex 0 0 1", "vertex nan inf 1").as_bytes()).unwrap();
        assert!(s.points.iter().any(|p| p.x.is_nan() && p.y == f64::INFINITY));
    }

    #[test]
    fn binary_reads_one_patch_named_from_the_header() {
        let s = parse(&binary(b"  solid tetra  \0\0", &TETRA)).unwrap();
        assert_eq!(s.patch_names, vec!["tetra"]);
        assert_eq!((s.points.len(), s.triangles.len()), (4, 4));
        assert!((s.enclosed_volume() - 1.0 / 6.0).abs() < 1e-15);
        assert_eq!(parse(&binary(b"\x01\x02binary junk", &TETRA)).unwrap().patch_names, ["wall"]);
        assert_eq!(parse(&binary(b"", &TETRA)).unwrap().patch_names, ["wall"]);
    }

    #[test]
    fn binary_starting_with_solid_is_detected_by_its_size() {
        let s = parse(&binary(b"solid but binary\nfacet", &TETRA)).unwrap();
        assert_eq!(s.triangles.len(), 4);
        assert_eq!(s.patch_names, ["wall"]);
    }

    #[test]
    fn binary_size_mismatch_says_where_and_how_much() {
        let full = binary(b"x", &TETRA);
        assert_error(
            parse,
            &full[..full.len() - 7],
            Location::Byte(84 + 3 * 50),
            "4 triangles (284 bytes) but the file has 277 bytes",
        );
        let mut long = full.clone();
        long.push(0);
        assert_error(parse, &long, Location::Byte(284), "1 bytes after its 4 triangles");
        assert_error(parse, &full[..50], Location::Byte(50), "too short for a binary STL header");
        assert_error(parse, binary(b"x", &[]), Location::File, "no triangles");
    }

    proptest! {
        #[test]
        fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
            let _ = parse(&bytes);
            let mut with_solid = b"solid ".to_vec();
            with_solid.extend(&bytes);
            let _ = parse(&with_solid);
        }

        #[test]
        fn truncated_files_never_panic(cut in 0usize..TWO_SOLIDS.len(), bin_cut in 0usize..284) {
            let _ = parse(&TWO_SOLIDS.as_bytes()[..cut]);
            let _ = parse(&binary(b"solid x", &TETRA)[..bin_cut]);
        }
    }
}
