//! CGNS (`.cgns`, HDF5) output and read-back through the CGNS library (cargo feature `cgns`,
//! Debian `libcgns-dev`).
//!
//! A file has one base (`Base`, 3D) and one unstructured zone (`Zone`): the coordinates, one
//! `MIXED` element section per volume zone of the mesh (named after it: `layers`, `core`, ...),
//! then the faces of each boundary patch: a `TRI_3` section named after it and a `QUAD_4` one
//! (`<patch>_quads` when it has both), with a boundary condition of the patch's name on their
//! element range (`PointRange` at `FaceCenter`) whose type comes from the patch role
//! ([`BcType::for_role`]). Cells keep our node orders, which are
//! the CGNS ones ([`crate::mesh`]). Node names are at most 32 characters: longer patch names are
//! cut, and names that would repeat get a `_2`, `_3`... suffix.

#[cfg(feature = "cgns")]
mod ffi;
#[cfg(feature = "cgns")]
mod read;
#[cfg(feature = "cgns")]
mod write;

use std::path::Path;

use crate::config::Role;
use crate::fill::FARFIELD_PATCH;
use crate::layers::TOP_PATCH;
use crate::mesh::VolumeMesh;

/// What a build without the `cgns` feature says when asked for a `.cgns` file.
pub const NOT_BUILT: &str =
    "CGNS support is not built in: rebuild blmesh with `--features cgns` (needs Debian's libcgns-dev)";

/// A failed CGNS call (with the library's message) or a file we cannot represent.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct CgnsError {
    pub message: String,
}

impl CgnsError {
    pub fn new(message: impl Into<String>) -> Self {
        CgnsError { message: message.into() }
    }

    /// `what` failed with the library's `message`.
    pub fn library(what: &str, message: String) -> Self {
        CgnsError { message: format!("{what}: {}", message.trim()) }
    }
}

impl From<CgnsError> for std::io::Error {
    fn from(e: CgnsError) -> Self {
        std::io::Error::other(e)
    }
}

/// The CGNS `BCType_t` values blmesh writes (and [`BcType::Other`] for any other read back).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BcType {
    Farfield,
    General,
    Inflow,
    Outflow,
    SymmetryPlane,
    Wall,
    WallViscous,
    Other(i32),
}

impl BcType {
    const KNOWN: [BcType; 7] = [
        BcType::Farfield,
        BcType::General,
        BcType::Inflow,
        BcType::Outflow,
        BcType::SymmetryPlane,
        BcType::Wall,
        BcType::WallViscous,
    ];

    /// The condition for a patch of this role: walls get layers, so they are viscous walls;
    /// a patch without a role of its own (`none`) is `BCGeneral`.
    pub fn for_role(role: Role) -> BcType {
        match role {
            Role::Wall => BcType::WallViscous,
            Role::Symmetry => BcType::SymmetryPlane,
            Role::Farfield => BcType::Farfield,
            Role::Inlet => BcType::Inflow,
            Role::Outlet => BcType::Outflow,
            Role::None => BcType::General,
        }
    }

    pub fn code(self) -> i32 {
        match self {
            BcType::Farfield => 7,
            BcType::General => 8,
            BcType::Inflow => 9,
            BcType::Outflow => 13,
            BcType::SymmetryPlane => 16,
            BcType::Wall => 20,
            BcType::WallViscous => 22,
            BcType::Other(code) => code,
        }
    }

    pub fn from_code(code: i32) -> BcType {
        BcType::KNOWN.into_iter().find(|t| t.code() == code).unwrap_or(BcType::Other(code))
    }
}

/// The role of a patch when the config does not say: the farfield we build is a farfield, the
/// top of the layers (a mesh without core) is an open interface (`none`), anything else a wall.
pub fn default_role(patch_name: &str) -> Role {
    match patch_name {
        FARFIELD_PATCH => Role::Farfield,
        TOP_PATCH => Role::None,
        _ => Role::Wall,
    }
}

/// One element section as read back.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Section {
    pub name: String,
    /// CGNS `ElementType_t` value (`MIXED` = 20).
    pub element_type: i32,
    pub elements: usize,
}

/// One boundary condition as read back: its faces are the boundary faces of the mesh's patch of
/// the same index.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BoundaryCondition {
    pub name: String,
    pub bc_type: BcType,
    pub faces: usize,
}

/// A CGNS file read back: the mesh (volume zones from the cell sections, patches from the
/// boundary conditions, then one patch per face section for faces under no condition) and what
/// the file lists.
#[derive(Clone, Debug)]
pub struct CgnsFile {
    /// The zone's declared size: vertices and cells.
    pub zone_vertices: usize,
    pub zone_cells: usize,
    pub mesh: VolumeMesh,
    pub sections: Vec<Section>,
    pub boundary_conditions: Vec<BoundaryCondition>,
}

/// Write `mesh` to `path` (atomically); `roles[p]` is the role of patch `p`, [`default_role`]
/// for patches beyond `roles`.
pub fn write(path: &Path, mesh: &VolumeMesh, roles: &[Role]) -> std::io::Result<()> {
    #[cfg(feature = "cgns")]
    {
        super::write_atomic_via_path(path, |tmp| Ok(write::write_file(tmp, mesh, roles)?))
    }
    #[cfg(not(feature = "cgns"))]
    {
        let _ = (path, mesh, roles);
        Err(std::io::Error::other(NOT_BUILT))
    }
}

/// Read a single-zone unstructured CGNS file of linear cells and faces.
pub fn read(path: &Path) -> Result<CgnsFile, CgnsError> {
    #[cfg(feature = "cgns")]
    {
        read::read_file(path)
    }
    #[cfg(not(feature = "cgns"))]
    {
        let _ = path;
        Err(CgnsError::new(NOT_BUILT))
    }
}

/// Whether this build can write and read CGNS.
pub const AVAILABLE: bool = cfg!(feature = "cgns");

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bc_codes_are_the_cgnslib_values_and_round_trip() {
        assert_eq!(BcType::for_role(Role::Wall).code(), 22, "BCWallViscous");
        assert_eq!(BcType::for_role(Role::Farfield).code(), 7, "BCFarfield");
        assert_eq!(BcType::for_role(Role::Symmetry).code(), 16, "BCSymmetryPlane");
        assert_eq!(BcType::for_role(Role::Inlet).code(), 9, "BCInflow");
        assert_eq!(BcType::for_role(Role::Outlet).code(), 13, "BCOutflow");
        for t in BcType::KNOWN {
            assert_eq!(BcType::from_code(t.code()), t);
        }
        assert_eq!(BcType::from_code(24), BcType::Other(24));
    }

    #[test]
    fn default_roles_follow_the_patches_blmesh_makes() {
        assert_eq!(default_role(FARFIELD_PATCH), Role::Farfield);
        assert_eq!(default_role(TOP_PATCH), Role::None);
        assert_eq!(default_role("wing"), Role::Wall);
    }

    #[cfg(not(feature = "cgns"))]
    #[test]
    fn without_the_feature_cgns_is_a_clear_error() {
        let e = write(Path::new("out.cgns"), &VolumeMesh::default(), &[]).unwrap_err();
        assert!(e.to_string().contains("--features cgns"), "{e}");
        assert!(!Path::new("out.cgns").exists());
    }

    #[cfg(feature = "cgns")]
    mod with_library {
        use super::*;
        use crate::mesh::CellKind;
        use crate::quality::{check, samples::hybrid_column};

        #[test]
        fn hybrid_column_round_trips_with_its_patches_and_roles() {
            let mesh = hybrid_column();
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("column.cgns");
            let roles = [Role::Symmetry];
            write(&path, &mesh, &roles).unwrap();
            let back = read(&path).unwrap();
            assert!(check(&back.mesh).is_valid(), "{}", check(&back.mesh));
            assert_eq!(back.mesh.points, mesh.points);
            for kind in CellKind::ALL {
                assert_eq!(back.mesh.block(kind).nodes, mesh.block(kind).nodes, "{}", kind.name());
            }
            assert_eq!(back.mesh.boundary.triangles.len(), mesh.boundary.triangles.len());
            assert_eq!(back.mesh.boundary.quads.len(), mesh.boundary.quads.len());
            let used = |m: &VolumeMesh| {
                let b = &m.boundary;
                let mut p: Vec<u32> = b.triangle_patch.iter().chain(&b.quad_patch).copied().collect();
                p.sort_unstable();
                p.dedup();
                p.len()
            };
            assert_eq!(back.boundary_conditions.len(), used(&mesh));
            let first = &back.boundary_conditions[0];
            assert_eq!(
                (first.name.as_str(), first.bc_type),
                (mesh.patch_names[0].as_str(), BcType::SymmetryPlane)
            );
            for bc in &back.boundary_conditions[1..] {
                assert_eq!(bc.bc_type, BcType::WallViscous, "{}", bc.name);
            }
            // Only the file is left in the directory: the temporary was renamed.
            assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        }

        #[test]
        fn damaged_and_foreign_files_are_errors() {
            let dir = tempfile::tempdir().unwrap();
            let text = dir.path().join("text.cgns");
            std::fs::write(&text, "not a CGNS file").unwrap();
            assert!(read(&text).unwrap_err().message.contains("cannot open"));
            let whole = dir.path().join("whole.cgns");
            write(&whole, &hybrid_column(), &[]).unwrap();
            let bytes = std::fs::read(&whole).unwrap();
            for keep in [bytes.len() / 2, bytes.len() - 100, 2048] {
                let cut = dir.path().join(format!("cut{keep}.cgns"));
                std::fs::write(&cut, &bytes[..keep]).unwrap();
                assert!(read(&cut).is_err(), "a file cut at {keep} of {} bytes reads", bytes.len());
            }
            assert!(read(&dir.path().join("missing.cgns")).is_err());
        }

        #[test]
        fn a_failed_write_leaves_no_file() {
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("no/such/dir/out.cgns");
            assert!(write(&path, &hybrid_column(), &[]).is_err());
            assert!(!path.exists());
        }
    }
}
