//! OpenFOAM polyMesh writer: an output path whose last component is `polyMesh` is written as the
//! directory OpenFOAM reads (`CASE/constant/polyMesh`), in ASCII FoamFile format.
//!
//! Files: `points`, `faces`, `owner`, `neighbour`, `boundary` (one patch per blmesh patch, in our
//! patch order, named after ours) and `cellZones` (our volume zones). Cells are numbered as
//! [`VolumeMesh::cells`] lists them. Faces are in OpenFOAM's order: the internal faces first, sorted
//! by owner then neighbour (upper-triangular, owner < neighbour, the normal pointing from owner to
//! neighbour), then each patch's faces together, pointing out of the domain. Free faces that no
//! patch lists (a mesh without boundary faces) go to a last patch `defaultFaces`. Points no face
//! uses are left out (checkMesh fails a mesh on them) and the others renumbered in order.

use std::io::{self, Write};
use std::path::Path;

use crate::config::Role;
use crate::geometry::DVec3;
use crate::mesh::{compact_points, Across, FaceTable, VolumeMesh};
use crate::quality::fv::face_geometry;

/// The last path component that makes an output a polyMesh directory.
pub const DIR_NAME: &str = "polyMesh";

/// Patch for free faces no blmesh patch lists (OpenFOAM's own name for such faces).
const DEFAULT_PATCH: &str = "defaultFaces";

/// Whether `path` names a polyMesh directory (its last component is `polyMesh`).
pub fn is_poly_mesh_dir(path: &Path) -> bool {
    path.file_name().is_some_and(|n| n == DIR_NAME)
}

/// The patches' face ranges in a face table: patch `p` is faces `start[p]..start[p + 1]`; the
/// free faces, if any, make a last patch ([`DEFAULT_PATCH`]), and then the flag is set.
fn patch_starts(mesh: &VolumeMesh, table: &FaceTable) -> (Vec<usize>, bool) {
    let patch_of = |f: usize| match table.across(f) {
        Across::Patch(p) => Some(p as usize),
        Across::Free | Across::Cell(_) => None,
    };
    let boundary = table.interior_count()..table.len();
    let patches = boundary.clone().filter_map(patch_of).map(|p| p + 1).max().unwrap_or(0);
    let patches = patches.max(mesh.patch_names.len());
    // One count per patch, then the free faces.
    let mut count = vec![0; patches + 1];
    for f in boundary {
        count[patch_of(f).unwrap_or(patches)] += 1;
    }
    let free = count[patches] > 0;
    if !free {
        count.pop();
    }
    let mut start = vec![table.interior_count()];
    for c in count {
        start.push(start[start.len() - 1] + c);
    }
    (start, free)
}

/// Write `mesh` as the polyMesh directory `path`, atomically; `roles[p]` is the role of patch
/// `p` ([`super::cgns::default_role`] beyond `roles`).
pub fn write(path: &Path, mesh: &VolumeMesh, roles: &[Role]) -> io::Result<()> {
    let table = FaceTable::new(mesh);
    super::write_dir_atomic(path, |dir| write_files(dir, mesh, &table, roles))
}

/// The polyMesh files of `mesh` into the existing directory `dir`.
pub fn write_files(dir: &Path, mesh: &VolumeMesh, table: &FaceTable, roles: &[Role]) -> io::Result<()> {
    let file = |name: &str, write: &dyn Fn(&mut dyn Write) -> io::Result<()>| {
        super::write_file_synced(&dir.join(name), |w| write(w))
    };
    let (points, ids) = used_points(&mesh.points, table);
    let note = note(points.len(), mesh, table);
    let owner: Vec<u32> = (0..table.len()).map(|f| table.owner(f)).collect();
    let neighbour: Vec<u32> = (0..table.interior_count()).filter_map(|f| table.neighbour(f)).collect();
    file("points", &|w| write_points(w, &points))?;
    file("faces", &|w| write_faces(w, table, &ids))?;
    file("owner", &|w| write_labels(w, "owner", &note, &owner))?;
    file("neighbour", &|w| write_labels(w, "neighbour", &note, &neighbour))?;
    file("boundary", &|w| write_boundary(w, mesh, table, roles))?;
    file("cellZones", &|w| write_cell_zones(w, mesh))
}

/// OpenFOAM's summary line in `owner` and `neighbour` (some readers size their arrays from it).
fn note(points: usize, mesh: &VolumeMesh, table: &FaceTable) -> String {
    format!(
        "nPoints:{points} nCells:{} nFaces:{} nInternalFaces:{}",
        mesh.cell_count(),
        table.len(),
        table.interior_count()
    )
}

const BANNER: &str = "\
/*--------------------------------*- C++ -*----------------------------------*\\
| polyMesh written by blmesh                                                  |
\\*---------------------------------------------------------------------------*/
";

/// The `FoamFile` dictionary every OpenFOAM file starts with.
fn header(w: &mut dyn Write, class: &str, object: &str, note: Option<&str>) -> io::Result<()> {
    write!(w, "{BANNER}FoamFile\n{{\n    version     2.0;\n    format      ascii;\n")?;
    writeln!(w, "    class       {class};")?;
    if let Some(note) = note {
        writeln!(w, "    note        \"{note}\";")?;
    }
    writeln!(w, "    location    \"constant/polyMesh\";\n    object      {object};\n}}\n")
}

fn write_points(w: &mut dyn Write, points: &[DVec3]) -> io::Result<()> {
    header(w, "vectorField", "points", None)?;
    writeln!(w, "{}\n(", points.len())?;
    for p in points {
        // `{:e}` prints the shortest digits that read back to the same f64.
        writeln!(w, "({:e} {:e} {:e})", p.x, p.y, p.z)?;
    }
    writeln!(w, ")")
}

/// The points some face uses, and the new number of every old point (`u32::MAX` if left out).
fn used_points(points: &[DVec3], table: &FaceTable) -> (Vec<DVec3>, Vec<u32>) {
    let mut used = vec![false; points.len()];
    for f in 0..table.len() {
        for &n in table.nodes(f) {
            used[n as usize] = true;
        }
    }
    compact_points(points, &used)
}

fn write_faces(w: &mut dyn Write, table: &FaceTable, ids: &[u32]) -> io::Result<()> {
    header(w, "faceList", "faces", None)?;
    writeln!(w, "{}\n(", table.len())?;
    for f in 0..table.len() {
        let nodes = table.nodes(f);
        write!(w, "{}(", nodes.len())?;
        for (i, &n) in nodes.iter().enumerate() {
            write!(w, "{}{}", if i == 0 { "" } else { " " }, ids[n as usize])?;
        }
        writeln!(w, ")")?;
    }
    writeln!(w, ")")
}

fn write_labels(w: &mut dyn Write, object: &str, note: &str, labels: &[u32]) -> io::Result<()> {
    header(w, "labelList", object, Some(note))?;
    writeln!(w, "{}\n(", labels.len())?;
    for l in labels {
        writeln!(w, "{l}")?;
    }
    writeln!(w, ")")
}

fn write_boundary(w: &mut dyn Write, mesh: &VolumeMesh, table: &FaceTable, roles: &[Role]) -> io::Result<()> {
    header(w, "polyBoundaryMesh", "boundary", None)?;
    let (starts, free) = patch_starts(mesh, table);
    let patches = starts.len() - 1;
    writeln!(w, "{patches}\n(")?;
    for (p, range) in starts.windows(2).enumerate() {
        let (start, end) = (range[0], range[1]);
        let faces = (start..end).map(|f| table.nodes(f));
        let is_free = free && p + 1 == patches;
        let role = if is_free { Role::None } else { role_of(p, mesh, roles) };
        let kind = patch_type(role, &mesh.points, faces);
        let name = if is_free { DEFAULT_PATCH.to_owned() } else { patch_name(mesh, p) };
        writeln!(w, "    {name}\n    {{")?;
        writeln!(w, "        type            {kind};")?;
        if kind == "wall" {
            writeln!(w, "        inGroups        List<word> 1(wall);")?;
        }
        writeln!(w, "        nFaces          {};\n        startFace       {start};\n    }}", end - start)?;
    }
    writeln!(w, ")")
}

/// The role of patch `patch`: `roles[patch]`, else [`super::cgns::default_role`] of its name.
pub(super) fn role_of(patch: usize, mesh: &VolumeMesh, roles: &[Role]) -> Role {
    match (roles.get(patch), mesh.patch_names.get(patch)) {
        (Some(&role), _) => role,
        (None, Some(name)) => super::cgns::default_role(name),
        (None, None) => Role::Wall,
    }
}

/// OpenFOAM's patch type for a role. A symmetry patch is a `symmetryPlane` only when planar
/// (OpenFOAM refuses a `symmetryPlane` whose face normals differ), else a `symmetry`.
fn patch_type<'a>(role: Role, points: &[DVec3], faces: impl Iterator<Item = &'a [u32]>) -> &'static str {
    match role {
        Role::Wall => "wall",
        Role::Symmetry if is_planar(points, faces) => "symmetryPlane",
        Role::Symmetry => "symmetry",
        Role::Farfield | Role::Inlet | Role::Outlet | Role::None => "patch",
    }
}

/// Whether every face's unit normal is within 1e-3 of the mean (OpenFOAM allows 1e-2).
fn is_planar<'a>(points: &[DVec3], faces: impl Iterator<Item = &'a [u32]>) -> bool {
    let normals: Vec<DVec3> = faces
        .map(|f| {
            let corners: Vec<DVec3> = f.iter().map(|&n| points[n as usize]).collect();
            face_geometry(&corners).area
        })
        .collect();
    let mean = normals.iter().sum::<DVec3>().normalize_or_zero();
    normals.iter().all(|n| (n.normalize_or_zero() - mean).length() < 1e-3)
}

/// A patch or zone name as an OpenFOAM word: no whitespace, quotes or punctuation it parses.
fn foam_word(name: &str, fallback: String) -> String {
    let name = name.trim();
    if name.is_empty() {
        return fallback;
    }
    let word: String = name
        .chars()
        .map(|c| if c.is_whitespace() || "\"'/;{}()[]$#".contains(c) { '_' } else { c })
        .collect();
    if word.starts_with(|c: char| c.is_ascii_digit()) {
        format!("_{word}")
    } else {
        word
    }
}

fn patch_name(mesh: &VolumeMesh, patch: usize) -> String {
    foam_word(mesh.patch_names.get(patch).map_or("", String::as_str), format!("patch_{patch}"))
}

fn write_cell_zones(w: &mut dyn Write, mesh: &VolumeMesh) -> io::Result<()> {
    header(w, "regIOobject", "cellZones", None)?;
    let zones = zone_cells(mesh);
    writeln!(w, "{}\n(", zones.len())?;
    for (z, cells) in zones.iter().enumerate() {
        let name = foam_word(mesh.zone_names.get(z).map_or("", String::as_str), format!("zone_{z}"));
        writeln!(w, "{name}\n{{\n    type cellZone;\n    cellLabels List<label> {}\n(", cells.len())?;
        for c in cells {
            writeln!(w, "{c}")?;
        }
        writeln!(w, ")\n;\n}}")?;
    }
    writeln!(w, ")")
}

/// The cells of every zone (at least the named zones), in cell order.
fn zone_cells(mesh: &VolumeMesh) -> Vec<Vec<u32>> {
    let zone_ids = mesh.blocks.iter().flat_map(|b| b.zone.iter().copied());
    let count = zone_ids.clone().map(|z| z as usize + 1).max().unwrap_or(0).max(mesh.zone_names.len());
    let mut zones = vec![Vec::new(); count];
    for (cell, z) in zone_ids.enumerate() {
        zones[z as usize].push(cell as u32);
    }
    zones
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::CellKind;
    use crate::quality::samples::hybrid_column;

    /// Two tetrahedra on the face (0, 1, 2): A above it (cell 0), B below (cell 1); A's outer
    /// faces on patch 1, B's on patch 0, so patch order and owner order differ.
    fn two_tetrahedra() -> VolumeMesh {
        let mut m = VolumeMesh::default();
        m.points = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.], [0., 0., -1.]]
            .map(DVec3::from_array)
            .to_vec();
        m.push_cell(CellKind::Tetrahedron, &[0, 1, 2, 3], 0);
        m.push_cell(CellKind::Tetrahedron, &[0, 2, 1, 4], 0);
        m.boundary.triangles = vec![[0, 1, 3], [1, 2, 3], [0, 3, 2], [0, 2, 4], [2, 1, 4], [0, 4, 1]];
        m.boundary.triangle_patch = vec![1, 1, 1, 0, 0, 0];
        m.patch_names = vec!["lower".into(), "upper".into()];
        m.zone_names = vec!["fluid".into()];
        m
    }

    /// Write `mesh` as `polyMesh` in a fresh directory; the directory guard and the path.
    fn written(mesh: &VolumeMesh, roles: &[Role]) -> (tempfile::TempDir, std::path::PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("constant").join(DIR_NAME);
        write(&path, mesh, roles).unwrap();
        (dir, path)
    }

    /// The entries of a FoamFile list (one per line between its `(` and `)`).
    fn items(path: &Path, name: &str) -> Vec<String> {
        let text = std::fs::read_to_string(path.join(name)).unwrap();
        let body = &text[text.find("}\n").unwrap()..];
        let mut lines = body.lines().skip_while(|l| l.trim() != "(").skip(1);
        lines.by_ref().take_while(|l| *l != ")").map(str::to_owned).collect()
    }

    fn labels(path: &Path, name: &str) -> Vec<u32> {
        items(path, name).iter().map(|l| l.parse().unwrap()).collect()
    }

    #[test]
    fn two_tetrahedra_give_openfoams_face_order() {
        let (_dir, path) = written(&two_tetrahedra(), &[Role::Farfield, Role::Wall]);
        let faces = ["3(0 2 1)", "3(0 2 4)", "3(2 1 4)", "3(0 4 1)", "3(0 1 3)", "3(1 2 3)", "3(0 3 2)"];
        assert_eq!(items(&path, "faces"), faces);
        assert_eq!(labels(&path, "owner"), [0, 1, 1, 1, 0, 0, 0]);
        assert_eq!(labels(&path, "neighbour"), [1]);
        let boundary = std::fs::read_to_string(path.join("boundary")).unwrap();
        let squeezed: String = boundary.split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(squeezed.contains("lower { type patch; nFaces 3; startFace 1; }"), "{boundary}");
        assert!(squeezed.contains("upper { type wall; inGroups List<word> 1(wall); nFaces 3; startFace 4; }"));
        let owner = std::fs::read_to_string(path.join("owner")).unwrap();
        assert!(owner.contains("note        \"nPoints:5 nCells:2 nFaces:7 nInternalFaces:1\";"), "{owner}");
        let zones = std::fs::read_to_string(path.join("cellZones")).unwrap();
        assert!(
            zones.contains("fluid\n{\n    type cellZone;\n    cellLabels List<label> 2\n(\n0\n1\n)"),
            "{zones}"
        );
    }

    /// Counts read back from the files of a mesh with every cell kind.
    #[test]
    fn hybrid_column_counts_round_trip() {
        let mesh = hybrid_column();
        let (_dir, path) = written(&mesh, &[]);
        let (owner, neighbour) = (labels(&path, "owner"), labels(&path, "neighbour"));
        let cells = owner.iter().chain(&neighbour).max().map_or(0, |&c| c as usize + 1);
        assert_eq!(cells, mesh.cell_count());
        assert_eq!(items(&path, "points").len(), mesh.points.len());
        let boundary = mesh.boundary.triangles.len() + mesh.boundary.quads.len();
        assert_eq!(owner.len(), neighbour.len() + boundary);
        let cell_faces: usize = mesh.cells().map(|(kind, _)| kind.faces().len()).sum();
        assert_eq!(cell_faces, 2 * neighbour.len() + boundary);
        assert!(neighbour.iter().zip(&owner).all(|(n, o)| o < n), "owner < neighbour");
        let pairs: Vec<(u32, u32)> = owner.iter().copied().zip(neighbour.iter().copied()).collect();
        assert!(pairs.windows(2).all(|w| w[0] < w[1]), "upper-triangular order");
    }

    #[test]
    fn unused_points_are_left_out_and_the_rest_renumbered() {
        let mut mesh = two_tetrahedra();
        mesh.points.insert(0, DVec3::splat(9.0));
        mesh.blocks[0].nodes.iter_mut().for_each(|n| *n += 1);
        mesh.boundary.triangles.iter_mut().flatten().for_each(|n| *n += 1);
        let (_dir, path) = written(&mesh, &[]);
        assert_eq!(items(&path, "points").len(), 5);
        assert_eq!(items(&path, "faces")[0], "3(0 2 1)");
    }

    /// A planar symmetry patch is a `symmetryPlane`, a curved one a `symmetry`; free faces no
    /// patch lists go to `defaultFaces`.
    #[test]
    fn patch_types_and_default_faces() {
        let mesh = two_tetrahedra();
        let (_dir, path) = written(&mesh, &[Role::Symmetry, Role::Symmetry]);
        let boundary = std::fs::read_to_string(path.join("boundary")).unwrap();
        assert!(boundary.contains("lower\n    {\n        type            symmetry;"), "{boundary}");
        let mut bare = mesh.clone();
        bare.boundary = Default::default();
        let (_dir, path) = written(&bare, &[]);
        let boundary = std::fs::read_to_string(path.join("boundary")).unwrap();
        let squeezed: String = boundary.split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(squeezed.contains("defaultFaces { type patch; nFaces 6; startFace 1; }"), "{boundary}");
        let mut plane = two_tetrahedra();
        plane.boundary.triangle_patch = vec![1, 1, 1, 1, 1, 0];
        let (_dir, path) = written(&plane, &[Role::Symmetry, Role::Wall]);
        let boundary = std::fs::read_to_string(path.join("boundary")).unwrap();
        assert!(boundary.contains("lower\n    {\n        type            symmetryPlane;"), "{boundary}");
    }

    #[test]
    fn an_existing_poly_mesh_is_replaced_whole() {
        let (dir, path) = written(&two_tetrahedra(), &[]);
        std::fs::write(path.join("stale"), "x").unwrap();
        write(&path, &hybrid_column(), &[]).unwrap();
        assert!(!path.join("stale").exists());
        let names: Vec<_> =
            std::fs::read_dir(path.parent().unwrap()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names, [DIR_NAME], "no temporaries left beside it");
        drop(dir);
    }

    #[test]
    fn names_become_openfoam_words() {
        assert_eq!(foam_word("wing tip;(1)", "x".into()), "wing_tip__1_");
        assert_eq!(foam_word("9lives", "x".into()), "_9lives");
        assert_eq!(foam_word("  ", "patch_3".into()), "patch_3");
        assert!(is_poly_mesh_dir(Path::new("case/constant/polyMesh")));
        assert!(!is_poly_mesh_dir(Path::new("polyMesh.vtu")));
    }
}
