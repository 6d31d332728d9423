//! Cart3D `.tri` surfaces, ASCII or Fortran-unformatted binary.
//!
//! Layout: `nVerts nTris [nScalars]`, the vertices, the triangles (1-based), then optionally one
//! component id per triangle (patch `component_<id>`; without them the patch is `wall`) and
//! scalars (ignored). The binary form holds the same data as Fortran records (a length marker
//! before and after each), little- or big-endian, with 4- or 8-byte reals and integers.

use super::scan::{self, ByteReader, Tokens};
use super::ParseError;
use crate::geometry::DVec3;
use crate::surface::Surface;

pub fn parse(bytes: &[u8]) -> Result<Surface, ParseError> {
    match binary_byte_order(bytes) {
        Some(big_endian) => parse_binary(bytes, big_endian),
        None => parse_ascii(&scan::text(bytes)),
    }
}

/// A binary file starts with the length of its header record, 8 or 12 bytes (two or three
/// 4-byte counts); returns whether it is big-endian. Text never starts with such bytes.
fn binary_byte_order(bytes: &[u8]) -> Option<bool> {
    let first: [u8; 4] = bytes.get(..4)?.try_into().ok()?;
    let is_header_length = |n: u32| n == 8 || n == 12;
    if is_header_length(u32::from_le_bytes(first)) {
        Some(false)
    } else if is_header_length(u32::from_be_bytes(first)) {
        Some(true)
    } else {
        None
    }
}

fn triangles_to_surface(
    points: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    components: Option<Vec<i64>>,
) -> Result<Surface, ParseError> {
    let mut surface = Surface { points, ..Surface::default() };
    match components {
        Some(ids) => surface.set_patches_from_labels(&ids, |id| format!("component_{id}")),
        None => {
            surface.triangle_patch = vec![0; triangles.len()];
            surface.patch_names = vec!["wall".to_owned()];
        }
    }
    surface.triangles = triangles;
    scan::finish(surface)
}

fn parse_ascii(text: &str) -> Result<Surface, ParseError> {
    let mut tokens = Tokens::new(text, None);
    let vertex_count = tokens.count("vertex")?;
    let header_line = tokens.line();
    let triangle_count = read_header_rest(tokens.rest_of_line(), header_line)?;
    let mut points = Vec::with_capacity(scan::capacity(vertex_count, tokens.remaining(), 6));
    for _ in 0..vertex_count {
        points.push(DVec3::from_array(tokens.point("a vertex coordinate")?));
    }
    let mut triangles = Vec::with_capacity(scan::capacity(triangle_count, tokens.remaining(), 6));
    for _ in 0..triangle_count {
        triangles.push(read_ascii_triangle(&mut tokens, vertex_count)?);
    }
    let components = if tokens.peek().is_some() {
        let ids = (0..triangle_count).map(|_| tokens.int::<i64>("a component id"));
        Some(ids.collect::<Result<Vec<i64>, ParseError>>()?)
    } else {
        None
    };
    triangles_to_surface(points, triangles, components)
}

/// The header line after the vertex count: `nTris [nScalars]`.
fn read_header_rest(rest: &str, line: usize) -> Result<usize, ParseError> {
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let [triangles, scalars @ ..] = fields.as_slice() else {
        return Err(ParseError::at_line(line, "expected 'nVerts nTris [nScalars]' on the first line"));
    };
    if scalars.len() > 1 {
        return Err(ParseError::at_line(line, format!("too many counts on the first line: '{rest}'")));
    }
    let count: u64 = scan::parse_int(triangles, line, "the triangle count")?;
    scan::check_count(count, "triangle").map_err(|m| ParseError::at_line(line, m))
}

fn read_ascii_triangle(tokens: &mut Tokens, vertex_count: usize) -> Result<[u32; 3], ParseError> {
    let mut t = [0; 3];
    for corner in &mut t {
        let value: i64 = tokens.int("a triangle vertex index")?;
        *corner = scan::vertex_index(value, 1, vertex_count).ok_or_else(|| {
            ParseError::at_line(tokens.line(), scan::bad_vertex(value, vertex_count, "from 1"))
        })?;
    }
    Ok(t)
}

fn parse_binary(bytes: &[u8], big_endian: bool) -> Result<Surface, ParseError> {
    let mut r = ByteReader::new(bytes, big_endian);
    let (vertex_count, triangle_count) = read_binary_header(&mut r)?;
    let points = read_binary_points(&mut r, vertex_count)?;
    let triangles = read_binary_triangles(&mut r, triangle_count, vertex_count)?;
    let components = if r.at_end() {
        None
    } else {
        Some(read_binary_integers(&mut r, triangle_count, "component record")?)
    };
    triangles_to_surface(points, triangles, components)
}

/// Start of a Fortran record: its length, checked against what is left.
fn record_start(r: &mut ByteReader, what: &str) -> Result<usize, ParseError> {
    let start = r.pos();
    let length = r.u32(&format!("the length of the {what}"))? as usize;
    if length > r.remaining() {
        return Err(ParseError::at_byte(
            start as u64,
            format!("the {what} says {length} bytes but only {} are left", r.remaining()),
        ));
    }
    Ok(length)
}

/// End of a Fortran record: the trailing length marker must repeat the leading one.
fn record_end(r: &mut ByteReader, length: usize, what: &str) -> Result<(), ParseError> {
    let at = r.pos();
    let trailing = r.u32(&format!("the end marker of the {what}"))?;
    if trailing as usize != length {
        return Err(ParseError::at_byte(
            at as u64,
            format!("the {what} ends with length marker {trailing}, its start said {length}"),
        ));
    }
    Ok(())
}

/// The size in bytes (4 or 8) of the `count` values a record of `length` bytes holds.
fn value_size(r: &ByteReader, length: usize, count: usize, what: &str) -> Result<usize, ParseError> {
    match [4, 8].into_iter().find(|&size| count.checked_mul(size) == Some(length)) {
        Some(size) if count > 0 => Ok(size),
        _ => Err(ParseError::at_byte(
            r.pos() as u64 - 4,
            format!("the {what} has {length} bytes, not 4 or 8 bytes for each of its {count} values"),
        )),
    }
}

fn read_binary_header(r: &mut ByteReader) -> Result<(usize, usize), ParseError> {
    let length = record_start(r, "header record")?;
    let mut counts = [0usize; 3];
    for (k, count) in counts.iter_mut().take(length / 4).enumerate() {
        let what = ["vertex", "triangle", "scalar"][k];
        let at = r.pos() as u64;
        let value = r.i32(&format!("the {what} count"))?;
        let value = u64::try_from(value)
            .map_err(|_| ParseError::at_byte(at, format!("negative {what} count {value}")))?;
        *count = scan::check_count(value, what).map_err(|m| ParseError::at_byte(at, m))?;
    }
    record_end(r, length, "header record")?;
    Ok((counts[0], counts[1]))
}

fn read_binary_points(r: &mut ByteReader, count: usize) -> Result<Vec<DVec3>, ParseError> {
    let length = record_start(r, "vertex record")?;
    let size = value_size(r, length, 3 * count, "vertex record")?;
    let mut points = Vec::with_capacity(count);
    for _ in 0..count {
        let mut p = [0.0; 3];
        for c in &mut p {
            *c = if size == 4 { f64::from(r.f32("a vertex")?) } else { r.f64("a vertex")? };
        }
        points.push(DVec3::from_array(p));
    }
    record_end(r, length, "vertex record")?;
    Ok(points)
}

fn read_binary_triangles(
    r: &mut ByteReader,
    count: usize,
    vertex_count: usize,
) -> Result<Vec<[u32; 3]>, ParseError> {
    let at = r.pos();
    let values = read_binary_integers(r, 3 * count, "triangle record")?;
    values
        .chunks_exact(3)
        .enumerate()
        .map(|(t, corners)| {
            let mut triangle = [0; 3];
            for (slot, &value) in triangle.iter_mut().zip(corners) {
                *slot = scan::vertex_index(value, 1, vertex_count).ok_or_else(|| {
                    let message = scan::bad_vertex(value, vertex_count, "from 1");
                    ParseError::at_byte(at as u64, format!("triangle {}: {message}", t + 1))
                })?;
            }
            Ok(triangle)
        })
        .collect()
}

/// A record of `count` integers of 4 or 8 bytes.
fn read_binary_integers(r: &mut ByteReader, count: usize, what: &str) -> Result<Vec<i64>, ParseError> {
    let length = record_start(r, what)?;
    let size = value_size(r, length, count, what)?;
    let mut values = Vec::with_capacity(count);
    for _ in 0..count {
        values.push(if size == 4 { i64::from(r.i32(what)?) } else { r.i64(what)? });
    }
    record_end(r, length, what)?;
    Ok(values)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::scan::testing::assert_error;
    use crate::io::Location;
    use proptest::prelude::*;

    const TETRA: &str = "4 4
0 0 0  1 0 0
0 1 0
0 0 1
1 3 2
1 2 4
1 4 3
2 3 4
1 1 7 7
";

    #[test]
    fn ascii_with_and_without_components() {
        let s = parse(TETRA.as_bytes()).unwrap();
        assert_eq!(s.patch_names, vec!["component_1", "component_7"]);
        assert_eq!(s.triangle_patch, vec![0, 0, 1, 1]);
        assert_eq!(s.triangles[0], [0, 2, 1]);
        assert!((s.enclosed_volume() - 1.0 / 6.0).abs() < 1e-15);
        let plain = parse(TETRA.replace("1 1 7 7\n", "").as_bytes()).unwrap();
        assert_eq!(plain.patch_names, vec!["wall"]);
        assert_eq!(plain.triangle_patch, vec![0; 4]);
        let with_scalars = TETRA.replacen("4 4", "4 4 1", 1) + "0.1 0.2 0.3 0.4\n";
        assert_eq!(parse(with_scalars.as_bytes()).unwrap().patch_names.len(), 2);
    }

    #[test]
    fn malformed_ascii_names_the_line() {
        assert_error(
            parse,
            TETRA.replace("2 3 4\n", "2 3 5\n").as_bytes(),
            Location::Line(8),
            "vertex index 5 out of range",
        );
        assert_error(
            parse,
            TETRA.replace("1 1 7 7\n", "1 1 7\n").as_bytes(),
            Location::Line(9),
            "end of file: expected a component id",
        );
        assert_error(
            parse,
            &TETRA.as_bytes()[..TETRA.find("1 2 4").unwrap()],
            Location::Line(5),
            "expected a triangle vertex index",
        );
        assert_error(
            parse,
            TETRA.replace("0 0 1\n", "0 0 one\n").as_bytes(),
            Location::Line(4),
            "bad number 'one'",
        );
        assert_error(parse, b"4\n0 0 0\n", Location::Line(1), "nVerts nTris");
    }

    /// Write `s` as a Fortran-unformatted binary .tri (4- or 8-byte reals, 4-byte integers).
    fn binary_tri(s: &Surface, big_endian: bool, real8: bool, components: bool) -> Vec<u8> {
        let mut out = Vec::new();
        let mut record = |body: Vec<u8>| {
            let marker = body.len() as u32;
            let marker = if big_endian { marker.to_be_bytes() } else { marker.to_le_bytes() };
            out.extend(marker);
            out.extend(body);
            out.extend(marker);
        };
        let int = |v: i32| if big_endian { v.to_be_bytes() } else { v.to_le_bytes() };
        record([s.points.len() as i32, s.triangles.len() as i32].map(int).concat());
        let mut coords = Vec::new();
        for c in s.points.iter().flat_map(|p| p.to_array()) {
            match (real8, big_endian) {
                (true, true) => coords.extend(c.to_be_bytes()),
                (true, false) => coords.extend(c.to_le_bytes()),
                (false, true) => coords.extend((c as f32).to_be_bytes()),
                (false, false) => coords.extend((c as f32).to_le_bytes()),
            }
        }
        record(coords);
        record(s.triangles.iter().flatten().flat_map(|&v| int(v as i32 + 1)).collect());
        if components {
            record(s.triangle_patch.iter().flat_map(|&p| int(p as i32 + 3)).collect());
        }
        out
    }

    #[test]
    fn binary_in_every_byte_order_and_precision() {
        let ascii = parse(TETRA.as_bytes()).unwrap();
        for (big_endian, real8, components) in
            [(false, false, true), (true, false, true), (false, true, false), (true, true, true)]
        {
            let s = parse(&binary_tri(&ascii, big_endian, real8, components)).unwrap();
            assert_eq!(s.points, ascii.points);
            assert_eq!(s.triangles, ascii.triangles);
            if components {
                assert_eq!(s.patch_names, vec!["component_3", "component_4"]);
                assert_eq!(s.triangle_patch, ascii.triangle_patch);
            } else {
                assert_eq!(s.patch_names, vec!["wall"]);
            }
        }
    }

    #[test]
    fn malformed_binary_names_the_byte() {
        let ascii = parse(TETRA.as_bytes()).unwrap();
        let good = binary_tri(&ascii, false, false, true);
        // header 16 bytes, then the vertex record (4 + 48 + 4).
        assert_error(
            parse,
            &good[..40],
            Location::Byte(16),
            "vertex record says 48 bytes but only 20 are left",
        );
        let mut bad_marker = good.clone();
        bad_marker[68] = 47;
        assert_error(parse, &bad_marker, Location::Byte(68), "ends with length marker 47, its start said 48");
        let mut bad_index = good.clone();
        bad_index[76..80].copy_from_slice(&9i32.to_le_bytes());
        assert_error(parse, &bad_index, Location::Byte(72), "triangle 1: vertex index 9 out of range");
    }

    proptest! {
        #[test]
        fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
            let _ = parse(&bytes);
            let mut binary = 8u32.to_le_bytes().to_vec();
            binary.extend(&bytes);
            let _ = parse(&binary);
        }

        #[test]
        fn truncated_files_never_panic(cut in 0usize..TETRA.len(), bin_cut in 0usize..200) {
            let _ = parse(&TETRA.as_bytes()[..cut]);
            let ascii = parse(TETRA.as_bytes()).unwrap();
            let binary = binary_tri(&ascii, true, true, true);
            let _ = parse(&binary[..bin_cut.min(binary.len())]);
        }
    }
}
