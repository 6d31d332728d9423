//! UH3D, the comma-separated surface format of NASA's CAPE tools:
//!
//! ```text
//! any title line
//! nNodes, nNodes, nTris, nTris, nComps, nComps
//! id, x, y, z                     (nNodes lines, ids 1..nNodes in order)
//! id, a, b, c, component          (nTris lines, 1-based node ids)
//! id, 'name'                      (component names, up to nComps lines)
//! 99,99,99,99,99                  (optional end marker)
//! ```
//!
//! Each component is a patch named from the list (`component_<id>` if it has no name).

use std::collections::HashMap;

use super::scan;
use super::ParseError;
use crate::geometry::DVec3;
use crate::surface::Surface;

pub fn parse(bytes: &[u8]) -> Result<Surface, ParseError> {
    let text = scan::text(bytes);
    // Line 1 is a title, whatever it holds.
    let mut lines = scan::content_lines(&text, None).filter(|&(line, _)| line > 1).peekable();
    let (line, counts) = lines.next().ok_or_else(|| ParseError::file("no counts line after the title"))?;
    let counts = Counts::parse(counts, line)?;
    let mut last_line = line;
    let mut next_line = |what: &str, k: usize, total: usize| {
        let next = lines.next().ok_or_else(|| {
            ParseError::at_line(last_line, format!("file ends after {k} of the {total} {what}"))
        })?;
        last_line = next.0;
        Ok::<_, ParseError>(next)
    };
    let mut surface = Surface::default();
    surface.points.reserve(scan::capacity(counts.nodes, text.len(), 8));
    for k in 0..counts.nodes {
        let (line, content) = next_line("nodes", k, counts.nodes)?;
        surface.points.push(read_node(content, line, k)?);
    }
    let mut components = Vec::with_capacity(scan::capacity(counts.triangles, text.len(), 10));
    for k in 0..counts.triangles {
        let (line, content) = next_line("triangles", k, counts.triangles)?;
        let (triangle, component) = read_triangle(content, line, counts.nodes)?;
        surface.triangles.push(triangle);
        components.push(component);
    }
    let names = read_component_names(&mut lines, counts.components)?;
    surface.set_patches_from_labels(&components, |id| match names.get(&id) {
        Some(name) => name.clone(),
        None => format!("component_{id}"),
    });
    scan::finish(surface)
}

struct Counts {
    nodes: usize,
    triangles: usize,
    /// The number of component name lines, when the counts line says it.
    components: Option<usize>,
}

impl Counts {
    fn parse(content: &str, line: usize) -> Result<Self, ParseError> {
        let fields = fields(content);
        if fields.len() < 3 {
            return Err(ParseError::at_line(
                line,
                format!("expected 'nNodes, nNodes, nTris, nTris, nComps, nComps', found '{content}'"),
            ));
        }
        let count = |i: usize, what: &str| -> Result<usize, ParseError> {
            let n: u64 = scan::parse_int(fields[i], line, &format!("the {what} count"))?;
            scan::check_count(n, what).map_err(|m| ParseError::at_line(line, m))
        };
        let components = if fields.len() >= 5 { Some(count(4, "component")?) } else { None };
        Ok(Counts { nodes: count(0, "node")?, triangles: count(2, "triangle")?, components })
    }
}

fn fields(content: &str) -> Vec<&str> {
    content.split(',').map(str::trim).collect()
}

/// `fields` of a line, which must number `n`.
fn fields_of<'a>(content: &'a str, line: usize, n: usize, layout: &str) -> Result<Vec<&'a str>, ParseError> {
    let f = fields(content);
    if f.len() == n {
        Ok(f)
    } else {
        Err(ParseError::at_line(line, format!("expected '{layout}', found '{content}'")))
    }
}

/// Node `k` (0-based): `id, x, y, z` with id = k + 1.
fn read_node(content: &str, line: usize, k: usize) -> Result<DVec3, ParseError> {
    let f = fields_of(content, line, 4, "id, x, y, z")?;
    let id: u64 = scan::parse_int(f[0], line, "a node id")?;
    if id != k as u64 + 1 {
        return Err(ParseError::at_line(
            line,
            format!("node id {id} where {} was expected (ids must be 1, 2, ... in order)", k + 1),
        ));
    }
    let mut p = [0.0; 3];
    for (c, token) in p.iter_mut().zip(&f[1..]) {
        *c = scan::parse_f64(token, line, "a node coordinate")?;
    }
    Ok(DVec3::from_array(p))
}

/// `id, a, b, c, component` with 1-based node ids.
fn read_triangle(content: &str, line: usize, node_count: usize) -> Result<([u32; 3], i64), ParseError> {
    let f = fields_of(content, line, 5, "id, node, node, node, component")?;
    let mut triangle = [0; 3];
    for (corner, token) in triangle.iter_mut().zip(&f[1..4]) {
        let value: i64 = scan::parse_int(token, line, "a triangle node id")?;
        *corner = scan::vertex_index(value, 1, node_count)
            .ok_or_else(|| ParseError::at_line(line, scan::bad_vertex(value, node_count, "from 1")))?;
    }
    Ok((triangle, scan::parse_int(f[4], line, "a component id")?))
}

/// The `id, 'name'` lines (at most `expected` of them when the counts line gave it), then an
/// optional `99,99,99,99,99` end marker and nothing else.
fn read_component_names<'a>(
    lines: &mut std::iter::Peekable<impl Iterator<Item = (usize, &'a str)>>,
    expected: Option<usize>,
) -> Result<HashMap<i64, String>, ParseError> {
    let mut names = HashMap::new();
    while expected.is_none_or(|n| names.len() < n) {
        let Some(&(line, content)) = lines.peek() else { break };
        let [id, name] = fields(content)[..] else { break };
        let id: i64 = scan::parse_int(id, line, "a component id")?;
        names.insert(id, name.trim_matches(['\'', '"']).trim().to_owned());
        lines.next();
    }
    lines.next_if(|&(_, content)| fields(content).iter().all(|&f| f == "99"));
    if let Some((line, content)) = lines.next() {
        return Err(ParseError::at_line(line, format!("unexpected line after the triangles: '{content}'")));
    }
    Ok(names)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::scan::testing::assert_error;
    use crate::io::Location;
    use proptest::prelude::*;

    const TETRA: &str = " written by hand
4, 4, 4, 4, 2, 2
1, 0., 0., 0.
2, 1.0E+00, 0., 0.
3, 0., 1., 0.
4, 0., 0., 1.
1, 1, 3, 2, 2
2, 1, 2, 4, 2
3, 1, 4, 3, 5
4, 2, 3, 4, 2
1, 'hull'
2, 'lid'
99,99,99,99,99
";

    #[test]
    fn reads_nodes_triangles_and_named_components() {
        let s = parse(TETRA.as_bytes()).unwrap();
        assert_eq!(s.points.len(), 4);
        assert_eq!(s.triangles[0], [0, 2, 1]);
        assert_eq!(s.patch_names, vec!["lid", "component_5"]);
        assert_eq!(s.triangle_patch, vec![0, 0, 1, 0]);
        assert!((s.enclosed_volume() - 1.0 / 6.0).abs() < 1e-15);
    }

    #[test]
    fn malformed_lines_are_named() {
        assert_error(
            parse,
            &TETRA.replace("4, 2, 3, 4, 2", "4, 2, 3, 9, 2"),
            Location::Line(10),
            "vertex index 9 out of range",
        );
        assert_error(
            parse,
            &TETRA.replace("3, 0., 1., 0.", "7, 0., 1., 0."),
            Location::Line(5),
            "node id 7 where 3 was expected",
        );
        assert_error(
            parse,
            &TETRA.replace("3, 0., 1., 0.", "3, 0., 1."),
            Location::Line(5),
            "expected 'id, x, y, z'",
        );
        assert_error(parse, &TETRA.replace("1., 0.\n", "1., zero\n"), Location::Line(5), "bad number 'zero'");
        assert_error(
            parse,
            &TETRA[..TETRA.find("3, 1, 4").unwrap()],
            Location::Line(8),
            "after 2 of the 4 triangles",
        );
        assert_error(
            parse,
            &format!("{TETRA}more\n"),
            Location::Line(14),
            "unexpected line after the triangles",
        );
        assert_error(parse, "title\n4; 4\n", Location::Line(2), "expected 'nNodes");
        assert_error(parse, "title only", Location::File, "no counts line");
    }

    proptest! {
        #[test]
        fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
            let _ = parse(&bytes);
            let mut with_counts = b"t\n2, 2, 1, 1, 1, 1\n".to_vec();
            with_counts.extend(&bytes);
            let _ = parse(&with_counts);
        }

        #[test]
        fn truncated_files_never_panic(cut in 0usize..TETRA.len()) {
            let _ = parse(&TETRA.as_bytes()[..cut]);
        }
    }
}
