//! AFLR3 UGRID volume mesh writer (`.ugrid` ASCII, `.b8.ugrid` big-endian, `.lb8.ugrid`
//! little-endian binary), with the FUN3D boundary condition file `.mapbc` beside it: the mesh
//! format of FUN3D, AFLR3 and refine.
//!
//! # Layout
//! From the UG_IO documentation of the UGRID 3D grid file type
//! (<https://www.simcenter.msstate.edu/software/documentation/ug_io/3d_grid_file_type_ugrid.html>):
//!
//! ```text
//! nnode ntri nquad ntet npyr nprism nhex
//! x y z                          nnode times (interleaved per node)
//! n1 n2 n3                       ntri boundary triangles
//! n1 n2 n3 n4                    nquad boundary quadrilaterals
//! id                             ntri + nquad surface ids (triangles first, then quads)
//! n1 .. n4                       ntet tetrahedra
//! n1 .. n5                       npyr pyramids
//! n1 .. n6                       nprism prisms
//! n1 .. n8                       nhex hexahedra
//! ```
//!
//! Node indices are 1-based. The format suffix before `.ugrid` says the encoding (UG_IO file
//! names, same documentation): none is ASCII; `.b8` is C binary (no Fortran record marks), big
//! endian, 64-bit reals and 32-bit integers; `.lb8` the same little endian. Other suffixes
//! (`.b4`, `.r8`, `.lr8`, ...: single precision or Fortran records) are not written. The
//! optional trailing records (reconnection flags, boundary conditions, initial spacing) are
//! left out, as AFLR3's output usually does.
//!
//! # Node orders
//! UGRID's cells are those of our [`crate::mesh`] (Gmsh) orders except the pyramid:
//! - Tetrahedron, prism, hexahedron: written as ours. A UGRID tetrahedron with nodes 0..3 has
//!   the positive volume `(n1 - n0) . ((n2 - n0) x (n3 - n0)) / 6` (refine's
//!   `ref_node_tet_vol`), as ours; the prism's triangle (0,1,2) has its right-hand normal
//!   towards (3,4,5), the hexahedron's quad (0,1,2,3) towards (4,5,6,7), lateral edges
//!   0-3, 1-4, 2-5 (0-4, ... for the hexahedron), as ours (refine's edge and face tables in
//!   `ref_cell.c`; meshio's UGRID reader and writer leave these three kinds unpermuted).
//! - Pyramid: the apex is UGRID's third node (index 2) and the base is the cycle 0, 1, 4, 3,
//!   whose right-hand normal points to the apex. `ugrid[i] = ours[PYRAMID[i]]` with
//!   `PYRAMID = [1, 0, 4, 2, 3]` (ours: base 0,1,2,3, apex 4): the same permutation as refine's
//!   `VTK_PYRAMID_TO_UGRID` (`ref_import.c`, VTK's pyramid is ours) and meshio's UGRID writer
//!   (`out[:, [1, 0, 4, 2, 3]]`).
//!
//! # Boundary faces
//! Written with their right-hand normals pointing *into* the domain (out of the bodies), the
//! reverse of [`crate::mesh::BoundaryFaces`]: refine, FUN3D's adaptation companion, reorients
//! every boundary face of a grid it imports that way (`ref_grid_inward_boundary_orientation`,
//! and "refine assumes normal point into the domain" in `ref_egads.c`). AFLR3 itself accepts
//! either orientation per closed surface (UG_IO "3D input/output grids").
//!
//! # `.mapbc`
//! FUN3D's boundary condition file, named like the grid without the `.b8.ugrid` (FUN3D reads
//! `project.b8.ugrid` with `project.mapbc`): the number of surface ids on the first line, then
//! `id code name` per patch, the id being the patch index + 1. Codes from the FUN3D manual's
//! boundary condition list (chapter 4), by [`Role`]:
//!
//! | role      | code | FUN3D |
//! |-----------|------|-------|
//! | wall      | 4000 | viscous, no-slip (strong) |
//! | symmetry  | 6661 / 6662 / 6663 | symmetry plane x / y / z = const, when every node of the patch is on such a plane |
//! | symmetry  | 3000 | tangency (slip), when it is on no such plane |
//! | farfield  | 5000 | farfield, Riemann invariants |
//! | inlet     | 7011 | subsonic inflow, total pressure and temperature |
//! | outlet    | 5051 | back pressure (static pressure) |
//! | none      | 3000 | tangency |
//!
//! Inlet and outlet values are set in FUN3D's `&boundary_conditions` namelist.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

use crate::config::Role;
use crate::geometry::Aabb;
use crate::mesh::{CellKind, VolumeMesh};

/// How the numbers of a UGRID file are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    Ascii,
    /// `.b8`: C binary, big endian, f64 and i32.
    BigEndian,
    /// `.lb8`: C binary, little endian, f64 and i32.
    LittleEndian,
}

/// UG_IO format suffixes of encodings we do not write.
const UNWRITTEN: [&str; 8] = ["b4", "lb4", "r4", "lr4", "r8", "lr8", "b8l", "lb8l"];

impl Encoding {
    /// The encoding named by the suffix before `.ugrid` (`x.b8.ugrid`), if the path ends in
    /// `.ugrid` and the suffix is one we write; any other suffix (`case.v2.ugrid`) is part of
    /// the name and the file is ASCII.
    pub fn from_path(path: &Path) -> Option<Encoding> {
        let name = path.file_name()?.to_str()?.to_ascii_lowercase();
        let stem = name.strip_suffix(".ugrid")?;
        let suffix = stem.rsplit_once('.').map(|(_, s)| s);
        match suffix {
            Some("b8") => Some(Encoding::BigEndian),
            Some("lb8") => Some(Encoding::LittleEndian),
            Some(s) if UNWRITTEN.contains(&s) => None,
            _ => Some(Encoding::Ascii),
        }
    }
}

/// `ugrid[i] = ours[PYRAMID[i]]` for a pyramid (see the module doc).
pub const PYRAMID: [usize; 5] = [1, 0, 4, 2, 3];

/// The UGRID node order of a cell kind: `ugrid[i] = ours[order[i]]`.
pub fn node_order(kind: CellKind) -> &'static [usize] {
    match kind {
        CellKind::Pyramid => &PYRAMID,
        CellKind::Tetrahedron => &[0, 1, 2, 3],
        CellKind::Prism => &[0, 1, 2, 3, 4, 5],
        CellKind::Hexahedron => &[0, 1, 2, 3, 4, 5, 6, 7],
    }
}

/// The `.mapbc` beside a UGRID file: `wing.b8.ugrid` -> `wing.mapbc`.
pub fn mapbc_path(path: &Path) -> PathBuf {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("mesh.ugrid");
    let lower = name.to_ascii_lowercase();
    let mut stem = &name[..lower.strip_suffix(".ugrid").map_or(name.len(), str::len)];
    if let Some((base, suffix)) = stem.rsplit_once('.') {
        if ["b8", "lb8"].contains(&suffix.to_ascii_lowercase().as_str()) {
            stem = base;
        }
    }
    path.with_file_name(format!("{stem}.mapbc"))
}

/// Write `mesh` to `path` and its `.mapbc` beside it, each atomically; `roles[p]` is the role
/// of patch `p` ([`super::cgns::default_role`] beyond `roles`).
pub fn write_files(path: &Path, mesh: &VolumeMesh, roles: &[Role], encoding: Encoding) -> io::Result<()> {
    let count = mesh.points.len() + mesh.boundary.triangles.len() + mesh.boundary.quads.len();
    if count.max(mesh.cell_count()) > i32::MAX as usize {
        return Err(io::Error::other("too many nodes, faces or cells for UGRID's 32-bit integers"));
    }
    super::write_atomic(path, |w| write(w, mesh, encoding))?;
    super::write_atomic(&mapbc_path(path), |w| write_mapbc(w, mesh, roles))
}

/// Numbers as text (one record a line) or as binary values.
struct Out<'a> {
    w: &'a mut dyn Write,
    encoding: Encoding,
}

impl Out<'_> {
    fn ints(&mut self, values: impl IntoIterator<Item = usize>) -> io::Result<()> {
        let mut first = true;
        for v in values {
            let v = v as i32;
            match self.encoding {
                Encoding::Ascii => write!(self.w, "{}{v}", if first { "" } else { " " })?,
                Encoding::BigEndian => self.w.write_all(&v.to_be_bytes())?,
                Encoding::LittleEndian => self.w.write_all(&v.to_le_bytes())?,
            }
            first = false;
        }
        self.end_record()
    }

    fn reals(&mut self, values: [f64; 3]) -> io::Result<()> {
        match self.encoding {
            // `{:e}` prints the shortest digits that read back to the same f64.
            Encoding::Ascii => write!(self.w, "{:e} {:e} {:e}", values[0], values[1], values[2])?,
            Encoding::BigEndian => values.iter().try_for_each(|v| self.w.write_all(&v.to_be_bytes()))?,
            Encoding::LittleEndian => values.iter().try_for_each(|v| self.w.write_all(&v.to_le_bytes()))?,
        }
        self.end_record()
    }

    fn end_record(&mut self) -> io::Result<()> {
        if self.encoding == Encoding::Ascii {
            self.w.write_all(b"\n")?;
        }
        Ok(())
    }
}

/// Write `mesh` as a UGRID file (the layout of the module doc).
pub fn write(w: &mut dyn Write, mesh: &VolumeMesh, encoding: Encoding) -> io::Result<()> {
    let b = &mesh.boundary;
    let mut out = Out { w, encoding };
    let mut header = vec![mesh.points.len(), b.triangles.len(), b.quads.len()];
    header.extend(CellKind::ALL.iter().map(|&k| mesh.block(k).len()));
    out.ints(header)?;
    for p in &mesh.points {
        out.reals(p.to_array())?;
    }
    // Reversed: ours point out of the domain, UGRID's (for FUN3D and refine) into it.
    for t in &b.triangles {
        out.ints([t[0], t[2], t[1]].map(|n| n as usize + 1))?;
    }
    for q in &b.quads {
        out.ints([q[0], q[3], q[2], q[1]].map(|n| n as usize + 1))?;
    }
    for &patch in b.triangle_patch.iter().chain(&b.quad_patch) {
        out.ints([patch as usize + 1])?;
    }
    for kind in CellKind::ALL {
        let order = node_order(kind);
        for cell in mesh.block(kind).iter() {
            out.ints(order.iter().map(|&local| cell[local] as usize + 1))?;
        }
    }
    Ok(())
}

/// Write the FUN3D `.mapbc` of `mesh`: every patch, with the code of its role.
pub fn write_mapbc(w: &mut dyn Write, mesh: &VolumeMesh, roles: &[Role]) -> io::Result<()> {
    let b = &mesh.boundary;
    let used = b.triangle_patch.iter().chain(&b.quad_patch).map(|&p| p as usize + 1).max().unwrap_or(0);
    let patches = used.max(mesh.patch_names.len());
    writeln!(w, "{patches}")?;
    for p in 0..patches {
        let code = bc_code(super::foam::role_of(p, mesh, roles), symmetry_axis(mesh, p as u32));
        writeln!(w, "{} {code} {}", p + 1, mapbc_name(mesh, p))?;
    }
    Ok(())
}

/// The FUN3D boundary condition code of a role; `axis` is the coordinate that is constant on
/// the patch, if one is.
pub fn bc_code(role: Role, axis: Option<usize>) -> u32 {
    match role {
        Role::Wall => 4000,
        Role::Symmetry => axis.map_or(3000, |a| 6661 + a as u32),
        Role::Farfield => 5000,
        Role::Inlet => 7011,
        Role::Outlet => 5051,
        Role::None => 3000,
    }
}

/// The axis `a` such that every node of patch `patch` has the same coordinate `a` (within 1e-9
/// of the mesh's size), if there is one.
fn symmetry_axis(mesh: &VolumeMesh, patch: u32) -> Option<usize> {
    let b = &mesh.boundary;
    let triangles = b.triangles.iter().zip(&b.triangle_patch).filter(|(_, &q)| q == patch);
    let quads = b.quads.iter().zip(&b.quad_patch).filter(|(_, &q)| q == patch);
    let nodes: Vec<u32> = triangles.flat_map(|(t, _)| *t).chain(quads.flat_map(|(q, _)| *q)).collect();
    let first = mesh.points[*nodes.first()? as usize];
    let tolerance = 1e-9 * Aabb::from_points(&mesh.points).diagonal();
    (0..3).find(|&a| nodes.iter().all(|&n| (mesh.points[n as usize][a] - first[a]).abs() <= tolerance))
}

/// A patch name as one token (FUN3D reads the name as the line's last word).
fn mapbc_name(mesh: &VolumeMesh, patch: usize) -> String {
    match mesh.patch_names.get(patch).map(|n| n.trim()).filter(|n| !n.is_empty()) {
        Some(name) => name.chars().map(|c| if c.is_whitespace() { '_' } else { c }).collect(),
        None => format!("patch_{patch}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::samples::hybrid_column;

    fn written(mesh: &VolumeMesh, encoding: Encoding) -> Vec<u8> {
        let mut bytes = Vec::new();
        write(&mut bytes, mesh, encoding).unwrap();
        bytes
    }

    #[test]
    fn encoding_is_the_suffix_before_ugrid() {
        let e = |name: &str| Encoding::from_path(Path::new(name));
        assert_eq!(e("out/wing.b8.ugrid"), Some(Encoding::BigEndian));
        assert_eq!(e("wing.LB8.UGRID"), Some(Encoding::LittleEndian));
        assert_eq!(e("wing.ugrid"), Some(Encoding::Ascii));
        assert_eq!(e("wing.v2.ugrid"), Some(Encoding::Ascii));
        assert_eq!(e("wing.r8.ugrid"), None);
        assert_eq!(e("wing.b4.ugrid"), None);
        assert_eq!(e("wing.msh"), None);
    }

    #[test]
    fn mapbc_is_named_like_the_project() {
        assert_eq!(mapbc_path(Path::new("a/wing.b8.ugrid")), Path::new("a/wing.mapbc"));
        assert_eq!(mapbc_path(Path::new("wing.lb8.ugrid")), Path::new("wing.mapbc"));
        assert_eq!(mapbc_path(Path::new("wing.v2.ugrid")), Path::new("wing.v2.mapbc"));
        assert_eq!(mapbc_path(Path::new("wing.ugrid")), Path::new("wing.mapbc"));
    }

    #[test]
    fn pyramid_order_is_a_permutation_with_the_apex_third() {
        let mut sorted = PYRAMID;
        sorted.sort_unstable();
        assert_eq!(sorted, [0, 1, 2, 3, 4]);
        assert_eq!(PYRAMID[2], 4, "our apex is UGRID's third node");
    }

    #[test]
    fn ascii_and_binary_hold_the_same_numbers() {
        let mesh = hybrid_column();
        let text = String::from_utf8(written(&mesh, Encoding::Ascii)).unwrap();
        let header: Vec<usize> =
            text.lines().next().unwrap().split(' ').map(|n| n.parse().unwrap()).collect();
        let b = &mesh.boundary;
        let mut expected = vec![mesh.points.len(), b.triangles.len(), b.quads.len()];
        expected.extend(CellKind::ALL.iter().map(|&k| mesh.block(k).len()));
        assert_eq!(header, expected);
        let ints: usize = 4 * b.triangles.len()
            + 5 * b.quads.len()
            + CellKind::ALL.iter().map(|&k| k.node_count() * mesh.block(k).len()).sum::<usize>();
        let big = written(&mesh, Encoding::BigEndian);
        let little = written(&mesh, Encoding::LittleEndian);
        assert_eq!(big.len(), 4 * 7 + 24 * mesh.points.len() + 4 * ints);
        assert_eq!(little.len(), big.len());
        assert_eq!(&big[..4], &(mesh.points.len() as i32).to_be_bytes());
        assert_eq!(&little[..4], &(mesh.points.len() as i32).to_le_bytes());
        assert_eq!(
            text.lines().count(),
            1 + mesh.points.len() + 2 * (b.triangles.len() + b.quads.len()) + mesh.cell_count()
        );
    }

    #[test]
    fn mapbc_codes_follow_the_roles() {
        let mesh = hybrid_column();
        let mut bytes = Vec::new();
        let roles = vec![Role::Wall; mesh.patch_names.len()];
        write_mapbc(&mut bytes, &mesh, &roles).unwrap();
        let text = String::from_utf8(bytes).unwrap();
        let mut lines = text.lines();
        let count: usize = lines.next().unwrap().parse().unwrap();
        assert_eq!(count, lines.clone().count());
        for (i, line) in lines.enumerate() {
            let words: Vec<&str> = line.split_whitespace().collect();
            assert_eq!(words.len(), 3, "{line}");
            assert_eq!(words[0], (i + 1).to_string());
            assert_eq!(words[1], "4000");
        }
        assert_eq!(bc_code(Role::Symmetry, Some(1)), 6662);
        assert_eq!(bc_code(Role::Symmetry, None), 3000);
        assert_eq!(bc_code(Role::Farfield, None), 5000);
    }
}
