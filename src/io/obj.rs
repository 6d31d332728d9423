//! Wavefront OBJ: vertices (`v`), polygon faces (`f`, fan-triangulated) and groups/objects
//! (`g`, `o`) as patches. Faces before any group belong to patch `wall`; a group with no faces
//! makes no patch; a group name used again continues its patch.

use super::scan;
use super::ParseError;
use crate::geometry::DVec3;
use crate::surface::{PatchTable, Surface};

/// Statements that carry nothing a closed triangle surface needs.
const IGNORED: &[&str] =
    &["vn", "vt", "vp", "s", "usemtl", "mtllib", "l", "p", "mg", "lod", "shadow_obj", "trace_obj"];

/// Free-form geometry statements: a surface described this way cannot be read as triangles.
const FREE_FORM: &[&str] =
    &["cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm", "trim", "hole", "scrv", "sp", "end"];

pub fn parse(bytes: &[u8]) -> Result<Surface, ParseError> {
    let text = scan::text(bytes);
    let mut surface = Surface::default();
    let mut patches = PatchTable::default();
    let mut group = "wall".to_owned();
    for (line, content) in scan::content_lines(&text, Some('#')) {
        let (keyword, rest) = content.split_once(char::is_whitespace).unwrap_or((content, ""));
        match keyword {
            "v" => surface.points.push(read_vertex(rest, line)?),
            "f" => {
                let corners = read_face(rest, line, surface.points.len())?;
                let patch = patches.index(&group);
                for i in 1..corners.len() - 1 {
                    surface.triangles.push([corners[0], corners[i], corners[i + 1]]);
                    surface.triangle_patch.push(patch);
                }
            }
            "g" | "o" => group = group_name(rest),
            k if IGNORED.contains(&k) => {}
            k if FREE_FORM.contains(&k) => {
                return Err(ParseError::at_line(
                    line,
                    format!("free-form geometry ('{k}') is not supported: export triangles"),
                ));
            }
            k => return Err(ParseError::at_line(line, format!("unknown OBJ statement '{k}'"))),
        }
        if surface.points.len() > scan::MAX_COUNT {
            return Err(ParseError::at_line(line, "too many vertices for 32-bit indices"));
        }
    }
    surface.patch_names = patches.into_names();
    scan::finish(surface)
}

/// `v x y z [w]`: the weight (and any vertex colour after it) is ignored.
fn read_vertex(rest: &str, line: usize) -> Result<DVec3, ParseError> {
    scan::line_point(rest, line, "a vertex").map(DVec3::from_array)
}

/// `f v1 v2 v3 ...` with `v`, `v/t`, `v/t/n` or `v//n` corners; negative indices count back
/// from the last vertex read so far.
fn read_face(rest: &str, line: usize, vertex_count: usize) -> Result<Vec<u32>, ParseError> {
    let corners = rest
        .split_whitespace()
        .map(|corner| {
            let index = corner.split('/').next().unwrap_or(corner);
            let value: i64 = scan::parse_int(index, line, "a face vertex index")?;
            face_vertex(value, vertex_count)
                .ok_or_else(|| ParseError::at_line(line, face_index_error(value, vertex_count)))
        })
        .collect::<Result<Vec<u32>, ParseError>>()?;
    if corners.len() < 3 {
        return Err(ParseError::at_line(
            line,
            format!("a face needs at least 3 vertices, this one has {}", corners.len()),
        ));
    }
    Ok(corners)
}

/// 0-based index of OBJ vertex reference `value` (1-based, or negative = relative).
fn face_vertex(value: i64, vertex_count: usize) -> Option<u32> {
    if value < 0 {
        scan::vertex_index(value.checked_add(vertex_count as i64)?, 0, vertex_count)
    } else {
        scan::vertex_index(value, 1, vertex_count)
    }
}

fn face_index_error(value: i64, vertex_count: usize) -> String {
    format!(
        "{} (OBJ counts from 1, or back from -1 = the last vertex read)",
        scan::bad_vertex(value, vertex_count, "so far")
    )
}

/// The group named on a `g`/`o` line; an unnamed group is `wall`, like faces before any group.
fn group_name(rest: &str) -> String {
    match rest.trim() {
        "" => "wall".to_owned(),
        name => name.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::scan::testing::assert_error;
    use crate::io::Location;
    use proptest::prelude::*;

    const CUBE_ISH: &str = "# a comment
mtllib x.mtl
v 0 0 0
v 1 0 0 1.0
v 1 1 0
v 0 1 0
v 0 0 1
v 9 9 9
vt 0 0
vn 0 0 1
f 1 2 5
g bottom
usemtl steel
s off
f 1/1 4/1/1 3//1 2
o empty
g side
f -6 -2 -3
g bottom
f 1 3 4
l 1 2
";

    #[test]
    fn groups_become_patches_and_polygons_are_fans() {
        let s = parse(CUBE_ISH.as_bytes()).unwrap();
        assert_eq!(s.patch_names, vec!["wall", "bottom", "side"]);
        assert_eq!(s.triangles, vec![[0, 1, 4], [0, 3, 2], [0, 2, 1], [0, 4, 3], [0, 2, 3]]);
        assert_eq!(s.triangle_patch, vec![0, 1, 1, 2, 1]);
        // The unused vertex (9, 9, 9) is dropped.
        assert_eq!(s.points.len(), 5);
    }

    #[test]
    fn unused_vertices_are_dropped_and_indices_renumbered() {
        let s = parse(b"v 5 5 5\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 2 3 4\n").unwrap();
        assert_eq!(s.points, vec![DVec3::ZERO, DVec3::X, DVec3::Y]);
        assert_eq!(s.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn bad_lines_are_named() {
        assert_error(
            parse,
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
            Location::Line(4),
            "vertex index 4 out of range: the file has 3 vertices",
        );
        assert_error(
            parse,
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",
            Location::Line(4),
            "vertex index -4 out of range",
        );
        assert_error(parse, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", Location::Line(4), "vertex index 0");
        assert_error(parse, "v 0 0\n", Location::Line(1), "a vertex needs 3 coordinates, found 2");
        assert_error(parse, "v 0 0 zero\n", Location::Line(1), "bad number 'zero'");
        assert_error(parse, "v 0 0 0\nv 1 0 0\n\nf 1 2\n", Location::Line(4), "at least 3 vertices");
        assert_error(parse, "v 0 0 0\nf 1 x 1\n", Location::Line(2), "bad integer 'x'");
        assert_error(parse, "v 0 0 0\ncurv 0 1 1 2\n", Location::Line(2), "free-form");
        assert_error(parse, "v 0 0 0\nbogus 1\n", Location::Line(2), "unknown OBJ statement 'bogus'");
        assert_error(parse, "v 0 0 0\n", Location::File, "no triangles");
    }

    proptest! {
        #[test]
        fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
            let _ = parse(&bytes);
        }

        #[test]
        fn truncated_files_never_panic(cut in 0usize..CUBE_ISH.len()) {
            let _ = parse(&CUBE_ISH.as_bytes()[..cut]);
        }

        #[test]
        fn face_like_lines_never_panic(line in "[vfgo] [-0-9/ ]{0,30}\n") {
            let _ = parse(format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{line}").as_bytes());
        }
    }
}
