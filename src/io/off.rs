//! OFF (Object File Format) and its COFF/NOFF/STOFF variants: one vertex per line (extra
//! values such as colours and normals are ignored), one polygon per line (fan-triangulated,
//! a trailing face colour ignored), 0-based indices, `#` comments. One patch, `wall`.

use super::scan;
use super::ParseError;
use crate::geometry::DVec3;
use crate::surface::Surface;

pub fn parse(bytes: &[u8]) -> Result<Surface, ParseError> {
    let text = scan::text(bytes);
    let mut lines = scan::content_lines(&text, Some('#'));
    let (vertex_count, face_count, mut last_line) = read_header(&mut lines)?;
    let mut surface = Surface::default();
    surface.points.reserve(scan::capacity(vertex_count, text.len(), 6));
    for k in 0..vertex_count {
        let (line, content) =
            lines.next().ok_or_else(|| truncated(last_line, "vertices", k, vertex_count))?;
        surface.points.push(DVec3::from_array(scan::line_point(content, line, "a vertex")?));
        last_line = line;
    }
    for k in 0..face_count {
        let (line, content) = lines.next().ok_or_else(|| truncated(last_line, "faces", k, face_count))?;
        let corners = read_face(content, line, vertex_count)?;
        for i in 1..corners.len() - 1 {
            surface.triangles.push([corners[0], corners[i], corners[i + 1]]);
        }
        last_line = line;
    }
    if let Some((line, _)) = lines.next() {
        return Err(ParseError::at_line(
            line,
            format!("unexpected data after the {face_count} faces the header announced"),
        ));
    }
    surface.triangle_patch = vec![0; surface.triangles.len()];
    surface.patch_names = vec!["wall".to_owned()];
    scan::finish(surface)
}

fn truncated(last_line: usize, what: &str, found: usize, expected: usize) -> ParseError {
    ParseError::at_line(
        last_line,
        format!("file ends after {found} of the {expected} {what} the header announced"),
    )
}

/// The `[ST][C][N]OFF` keyword and the counts `vertices faces [edges]` (on the same line or
/// the next); returns the counts and the line they were on.
fn read_header<'a>(
    lines: &mut impl Iterator<Item = (usize, &'a str)>,
) -> Result<(usize, usize, usize), ParseError> {
    let (line, first) = lines.next().ok_or_else(|| ParseError::file("empty file: no OFF header"))?;
    let (keyword, rest) = first.split_once(char::is_whitespace).unwrap_or((first, ""));
    check_keyword(keyword, line)?;
    if !rest.trim().is_empty() {
        return read_counts(rest, line).map(|(v, f)| (v, f, line));
    }
    let (line, counts) = lines
        .next()
        .ok_or_else(|| ParseError::at_line(line, "file ends before the vertex and face counts"))?;
    read_counts(counts, line).map(|(v, f)| (v, f, line))
}

fn check_keyword(keyword: &str, line: usize) -> Result<(), ParseError> {
    let variant = keyword.strip_prefix("ST").unwrap_or(keyword);
    let variant = variant.strip_prefix('C').unwrap_or(variant);
    let variant = variant.strip_prefix('N').unwrap_or(variant);
    if variant == "OFF" {
        return Ok(());
    }
    let message = if keyword.ends_with("OFF") {
        format!("OFF variant '{keyword}' is not supported (only [ST][C][N]OFF in 3D)")
    } else {
        format!("not an OFF file: expected 'OFF' at the start, found '{keyword}'")
    };
    Err(ParseError::at_line(line, message))
}

fn read_counts(text: &str, line: usize) -> Result<(usize, usize), ParseError> {
    let fields: Vec<&str> = text.split_whitespace().collect();
    if fields.first() == Some(&"BINARY") {
        return Err(ParseError::at_line(line, "binary OFF is not supported"));
    }
    if !(2..=3).contains(&fields.len()) {
        return Err(ParseError::at_line(
            line,
            format!("expected 'vertices faces [edges]' counts, found '{text}'"),
        ));
    }
    let count = |i: usize, what: &str| -> Result<usize, ParseError> {
        let n: u64 = scan::parse_int(fields[i], line, &format!("the {what} count"))?;
        scan::check_count(n, what).map_err(|m| ParseError::at_line(line, m))
    };
    Ok((count(0, "vertex")?, count(1, "face")?))
}

/// `n i_1 ... i_n [colour]`: a polygon of n >= 3 vertices, 0-based.
fn read_face(content: &str, line: usize, vertex_count: usize) -> Result<Vec<u32>, ParseError> {
    let mut fields = content.split_whitespace();
    let size: usize = scan::parse_int(fields.next().unwrap_or(""), line, "the face size")?;
    if size < 3 {
        return Err(ParseError::at_line(line, format!("a face needs at least 3 vertices, not {size}")));
    }
    let corners = fields
        .by_ref()
        .take(size)
        .map(|field| {
            let value: i64 = scan::parse_int(field, line, "a face vertex index")?;
            scan::vertex_index(value, 0, vertex_count)
                .ok_or_else(|| ParseError::at_line(line, scan::bad_vertex(value, vertex_count, "from 0")))
        })
        .collect::<Result<Vec<u32>, ParseError>>()?;
    if corners.len() < size {
        return Err(ParseError::at_line(
            line,
            format!("face of {size} vertices lists only {}", corners.len()),
        ));
    }
    Ok(corners)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::scan::testing::assert_error;
    use crate::io::Location;
    use proptest::prelude::*;

    const SQUARE_PYRAMID: &str = "OFF
# a pyramid on a square base
5 5 8
0 0 0
1 0 0
1 1 0
0 1 0
0.5 0.5 1  # apex
4 0 3 2 1
3 0 1 4
3 1 2 4 255 0 0
3 2 3 4
3 3 0 4
";

    #[test]
    fn reads_polygons_as_fans_into_one_patch() {
        let s = parse(SQUARE_PYRAMID.as_bytes()).unwrap();
        assert_eq!(s.triangles.len(), 6);
        assert_eq!(s.triangles[..2], [[0, 3, 2], [0, 2, 1]]);
        assert_eq!(s.patch_names, vec!["wall"]);
        assert_eq!(s.triangle_patch, vec![0; 6]);
        assert!((s.enclosed_volume() - 1.0 / 3.0).abs() < 1e-15);
    }

    #[test]
    fn header_variants_and_counts_on_the_keyword_line() {
        let one_line = SQUARE_PYRAMID.replacen("OFF\n# a pyramid on a square base\n5 5 8", "OFF 5 5 8", 1);
        assert_eq!(parse(one_line.as_bytes()).unwrap().triangles.len(), 6);
        let coff = SQUARE_PYRAMID.replacen("OFF", "COFF", 1).replace("0 0 0\n", "0 0 0 1 1 1 1\n");
        assert_eq!(parse(coff.as_bytes()).unwrap().points.len(), 5);
        assert!(parse(SQUARE_PYRAMID.replacen("OFF", "NOFF", 1).as_bytes()).is_ok());
    }

    #[test]
    fn malformed_files_name_the_line() {
        let cut = &SQUARE_PYRAMID[..SQUARE_PYRAMID.find("3 1 2 4").unwrap()];
        assert_error(parse, cut, Location::Line(10), "file ends after 2 of the 5 faces");
        assert_error(
            parse,
            &SQUARE_PYRAMID[..SQUARE_PYRAMID.find("0 1 0").unwrap()],
            Location::Line(6),
            "after 3 of the 5 vertices",
        );
        assert_error(
            parse,
            &SQUARE_PYRAMID.replace("3 2 3 4", "3 2 3 5"),
            Location::Line(12),
            "vertex index 5 out of range: the file has 5 vertices",
        );
        assert_error(parse, &SQUARE_PYRAMID.replace("3 2 3 4", "3 2 3"), Location::Line(12), "lists only 2");
        assert_error(parse, &SQUARE_PYRAMID.replace("3 2 3 4", "2 2 3"), Location::Line(12), "at least 3");
        assert_error(
            parse,
            &SQUARE_PYRAMID.replace("1 1 0", "1 1"),
            Location::Line(6),
            "needs 3 coordinates, found 2",
        );
        assert_error(parse, &format!("{SQUARE_PYRAMID}3 0 1 2\n"), Location::Line(14), "after the 5 faces");
        assert_error(parse, "4OFF\n1 1 0\n", Location::Line(1), "not supported");
        assert_error(parse, "PLY\n", Location::Line(1), "not an OFF file");
        assert_error(parse, "OFF\n3 x 0\n", Location::Line(2), "bad integer 'x'");
        assert_error(parse, "OFF 99999999999 1 0\n", Location::Line(1), "exceeds");
    }

    proptest! {
        #[test]
        fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
            let _ = parse(&bytes);
            let mut with_header = b"OFF\n".to_vec();
            with_header.extend(&bytes);
            let _ = parse(&with_header);
        }

        #[test]
        fn truncated_files_never_panic(cut in 0usize..SQUARE_PYRAMID.len()) {
            let _ = parse(&SQUARE_PYRAMID.as_bytes()[..cut]);
        }
    }
}
