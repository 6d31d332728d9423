//! Reading surfaces and volume meshes, writing volume meshes.
//!
//! Every parser works on bytes in memory (`parse(&[u8])`) so that tests and fuzzers need no files;
//! [`read_surface`] and [`read_volume_mesh`] add the file name to errors. Every writer goes through
//! [`write_atomic`], so a failed run never leaves a half-written output file.

pub mod cart3d;
pub mod cgns;
pub mod foam;
pub mod medit;
pub mod msh;
pub mod obj;
pub mod off;
mod scan;
pub mod stl;
pub mod su2;
mod temporaries;
pub mod ugrid;
pub mod uh3d;
pub mod vtu;

pub(crate) use temporaries::remove_all_and_hold as remove_temporaries_and_hold;

use std::fmt;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::config::Role;
use crate::mesh::VolumeMesh;
use crate::surface::Surface;

/// Where in a file a parse error is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Location {
    /// 1-based line number of a text file.
    Line(usize),
    /// Byte offset in a binary file.
    Byte(u64),
    /// The file as a whole (e.g. it is empty).
    File,
}

/// A malformed or truncated file: what is wrong and where.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParseError {
    pub at: Location,
    pub message: String,
}

impl ParseError {
    pub fn at_line(line: usize, message: impl Into<String>) -> Self {
        ParseError { at: Location::Line(line), message: message.into() }
    }
    pub fn at_byte(offset: u64, message: impl Into<String>) -> Self {
        ParseError { at: Location::Byte(offset), message: message.into() }
    }
    pub fn file(message: impl Into<String>) -> Self {
        ParseError { at: Location::File, message: message.into() }
    }
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.at {
            Location::Line(l) => write!(f, "line {l}: {}", self.message),
            Location::Byte(b) => write!(f, "byte {b}: {}", self.message),
            Location::File => write!(f, "{}", self.message),
        }
    }
}

impl std::error::Error for ParseError {}

/// Reading a file failed.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    #[error("{}: cannot read: {source}", path.display())]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{}: {source}", path.display())]
    Parse { path: PathBuf, source: ParseError },
    #[error("{}: unknown file type (expected {expected})", path.display())]
    UnknownFormat { path: PathBuf, expected: &'static str },
}

/// Surface formats, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceFormat {
    Stl,
    Obj,
    Off,
    Msh,
    MeditAscii,
    MeditBinary,
    Cart3d,
    Uh3d,
}

const SURFACE_EXTENSIONS: &str = ".stl, .obj, .off, .msh, .mesh, .meshb, .tri, .uh3d";

impl SurfaceFormat {
    pub fn from_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "stl" => SurfaceFormat::Stl,
            "obj" => SurfaceFormat::Obj,
            "off" => SurfaceFormat::Off,
            "msh" => SurfaceFormat::Msh,
            "mesh" => SurfaceFormat::MeditAscii,
            "meshb" => SurfaceFormat::MeditBinary,
            "tri" => SurfaceFormat::Cart3d,
            "uh3d" => SurfaceFormat::Uh3d,
            _ => return None,
        })
    }

    /// Parse a surface of this format from bytes.
    pub fn parse(self, bytes: &[u8]) -> Result<Surface, ParseError> {
        match self {
            SurfaceFormat::Stl => stl::parse(bytes),
            SurfaceFormat::Obj => obj::parse(bytes),
            SurfaceFormat::Off => off::parse(bytes),
            SurfaceFormat::Msh => msh::parse_surface(bytes),
            SurfaceFormat::MeditAscii | SurfaceFormat::MeditBinary => medit::parse_surface(bytes),
            SurfaceFormat::Cart3d => cart3d::parse(bytes),
            SurfaceFormat::Uh3d => uh3d::parse(bytes),
        }
    }
}

fn read_bytes(path: &Path) -> Result<Vec<u8>, ReadError> {
    std::fs::read(path).map_err(|source| ReadError::Io { path: path.to_owned(), source })
}

/// Read a triangle surface with patch names; the format is chosen by the file extension.
pub fn read_surface(path: &Path) -> Result<Surface, ReadError> {
    let format = SurfaceFormat::from_path(path)
        .ok_or_else(|| ReadError::UnknownFormat { path: path.to_owned(), expected: SURFACE_EXTENSIONS })?;
    let bytes = read_bytes(path)?;
    format.parse(&bytes).map_err(|source| ReadError::Parse { path: path.to_owned(), source })
}

/// Read a volume mesh (`.msh` Gmsh 4.1/2.2, `.vtu`, `.cgns` with the `cgns` feature).
pub fn read_volume_mesh(path: &Path) -> Result<VolumeMesh, ReadError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let parse: fn(&[u8]) -> Result<VolumeMesh, ParseError> = match ext.as_deref() {
        Some("msh") => msh::parse_volume,
        Some("vtu") => vtu::parse,
        // The CGNS library reads the file itself.
        Some("cgns") => {
            return cgns::read(path)
                .map(|file| file.mesh)
                .map_err(|e| ReadError::Parse { path: path.to_owned(), source: ParseError::file(e.message) })
        }
        _ => return Err(ReadError::UnknownFormat { path: path.to_owned(), expected: ".msh, .vtu, .cgns" }),
    };
    let bytes = read_bytes(path)?;
    parse(&bytes).map_err(|source| ReadError::Parse { path: path.to_owned(), source })
}

/// Volume mesh output formats, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// Gmsh MSH 4.1 (binary unless `ascii`).
    Msh {
        ascii: bool,
    },
    Vtu,
    /// SU2 native (ASCII), patches as markers.
    Su2,
    /// Medit `.meshb` (binary) or `.mesh` (ASCII), patch and zone index + 1 as references.
    Medit {
        binary: bool,
    },
    /// CGNS (HDF5): one unstructured zone, patches as boundary conditions (feature `cgns`).
    Cgns,
    /// OpenFOAM polyMesh directory (ASCII), chosen by the output's last component `polyMesh`.
    Foam,
    /// AFLR3/FUN3D UGRID (`.ugrid` ASCII, `.b8.ugrid`, `.lb8.ugrid`) with a FUN3D `.mapbc` beside.
    Ugrid {
        encoding: ugrid::Encoding,
    },
}

/// The volume mesh output extensions, for messages.
pub const MESH_EXTENSIONS: &str =
    ".msh, .vtu, .su2, .mesh, .meshb, .cgns, .ugrid, .b8.ugrid, .lb8.ugrid, or a directory named polyMesh";

impl MeshFormat {
    pub fn from_path(path: &Path, ascii: bool) -> Option<Self> {
        if foam::is_poly_mesh_dir(path) {
            return Some(MeshFormat::Foam);
        }
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "msh" => Some(MeshFormat::Msh { ascii }),
            "vtu" => Some(MeshFormat::Vtu),
            "su2" => Some(MeshFormat::Su2),
            "mesh" => Some(MeshFormat::Medit { binary: false }),
            "meshb" => Some(MeshFormat::Medit { binary: true }),
            "cgns" => Some(MeshFormat::Cgns),
            "ugrid" => ugrid::Encoding::from_path(path).map(|encoding| MeshFormat::Ugrid { encoding }),
            _ => None,
        }
    }

    /// Why this build cannot write the format (checked before meshing), if it cannot.
    pub fn unavailable(self) -> Option<&'static str> {
        (self == MeshFormat::Cgns && !cgns::AVAILABLE).then_some(cgns::NOT_BUILT)
    }
}

/// Write a volume mesh atomically in the given format.
pub fn write_volume_mesh(path: &Path, mesh: &VolumeMesh, format: MeshFormat) -> std::io::Result<()> {
    write_volume_mesh_with_roles(path, mesh, format, &[])
}

/// [`write_volume_mesh`] with the role of each patch (CGNS boundary condition types, polyMesh
/// patch types, UGRID's `.mapbc` codes; patches beyond `roles` get [`cgns::default_role`]).
pub fn write_volume_mesh_with_roles(
    path: &Path,
    mesh: &VolumeMesh,
    format: MeshFormat,
    roles: &[Role],
) -> std::io::Result<()> {
    match format {
        MeshFormat::Msh { ascii } => write_atomic(path, |w| msh::write(w, mesh, ascii)),
        MeshFormat::Vtu => write_atomic(path, |w| vtu::write(w, mesh)),
        MeshFormat::Su2 => write_atomic(path, |w| su2::write(w, mesh)),
        MeshFormat::Medit { binary } => write_atomic(path, |w| medit::write_volume(w, mesh, binary)),
        MeshFormat::Cgns => cgns::write(path, mesh, roles),
        MeshFormat::Foam => foam::write(path, mesh, roles),
        MeshFormat::Ugrid { encoding } => ugrid::write_files(path, mesh, roles, encoding),
    }
}

/// Write a file through a temporary in the same directory, renamed over `path` only when
/// `write` succeeded: readers never see a half-written file, and a failure leaves no file.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    replace_through_temporary(path, |tmp| {
        let mut buffered = std::io::BufWriter::new(tmp.as_file_mut());
        write(&mut buffered)?;
        buffered.flush()
    })
}

/// [`write_atomic`] for a writer that opens the file itself (a C library): it gets the path of
/// the temporary, which it may replace.
pub fn write_atomic_via_path(
    path: &Path,
    write: impl FnOnce(&Path) -> std::io::Result<()>,
) -> std::io::Result<()> {
    replace_through_temporary(path, |tmp| {
        write(tmp.path())?;
        // Reopen: the writer may have replaced the file the temporary's handle points to.
        *tmp.as_file_mut() = std::fs::OpenOptions::new().read(true).write(true).open(tmp.path())?;
        Ok(())
    })
}

/// Write a directory of files atomically: `fill` builds it as a temporary sibling, which is then
/// renamed over `path` (an older directory there is moved aside first and removed after), so
/// readers never see a half-written directory. Missing parent directories are created.
pub fn write_dir_atomic(path: &Path, fill: impl FnOnce(&Path) -> std::io::Result<()>) -> std::io::Result<()> {
    let parent = parent_dir(path);
    std::fs::create_dir_all(parent)?;
    let (registration, tmp) =
        temporaries::create(|| temporary_builder(0o777).tempdir_in(parent), |d| d.path())?;
    fill(tmp.path())?;
    registration.finish(|| {
        let aside = temporary_builder(0o700).tempdir_in(parent)?;
        let old = aside.path().join("old");
        let had_old = match std::fs::rename(path, &old) {
            Ok(()) => true,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => false,
            Err(e) => return Err(e),
        };
        if let Err(e) = std::fs::rename(tmp.path(), path) {
            if had_old {
                std::fs::rename(&old, path)?;
            }
            return Err(e);
        }
        let _ = tmp.keep();
        Ok(())
    })
}

/// Write one file of a directory being built by [`write_dir_atomic`], synced to disk.
pub fn write_file_synced(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let mut file = std::fs::File::create(path)?;
    let mut buffered = std::io::BufWriter::new(&mut file);
    write(&mut buffered)?;
    buffered.flush()?;
    drop(buffered);
    file.sync_all()
}

fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Temporaries are named `.blmesh-*`; `mode` (less the umask) is what the output should get,
/// not the private mode temporaries get by default.
fn temporary_builder(mode: u32) -> tempfile::Builder<'static, 'static> {
    let mut builder = tempfile::Builder::new();
    builder.prefix(".blmesh-");
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(mode));
    #[cfg(not(unix))]
    let _ = mode;
    builder
}

fn replace_through_temporary(
    path: &Path,
    fill: impl FnOnce(&mut tempfile::NamedTempFile) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let (registration, mut tmp) =
        temporaries::create(|| temporary_builder(0o666).tempfile_in(parent_dir(path)), |f| f.path())?;
    fill(&mut tmp)?;
    tmp.as_file().sync_all()?;
    registration.finish(|| tmp.persist(path).map_err(|e| e.error))?;
    Ok(())
}

/// Fail now, before minutes of work, when `path` could not be written later: its directory
/// must exist and take a new file. With `created_dirs`, missing directories above `path` are
/// made when writing, so the nearest one that exists must take them.
pub fn check_writable(path: &Path, created_dirs: bool) -> std::io::Result<()> {
    let mut dir = parent_dir(path);
    if created_dirs {
        while !dir.exists() {
            dir = parent_dir(dir);
        }
    }
    let problem = |why: &str| std::io::Error::other(format!("directory {} {why}", dir.display()));
    match std::fs::metadata(dir) {
        Ok(meta) if meta.is_dir() => {}
        Ok(_) => return Err(problem("is not a directory")),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err(problem("does not exist")),
        Err(e) => return Err(problem(&format!("cannot be read: {e}"))),
    }
    // Permission bits do not tell (root, read-only mounts, ACLs): try.
    let probe = temporaries::create(|| temporary_builder(0o600).tempfile_in(dir), |f| f.path());
    probe.map(drop).map_err(|e| problem(&format!("is not writable: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An atomically written output gets the same mode as a file created the ordinary way.
    #[cfg(unix)]
    #[test]
    fn atomic_output_has_the_usual_mode() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let (ours, plain) = (dir.path().join("ours.txt"), dir.path().join("plain.txt"));
        write_atomic(&ours, |w| w.write_all(b"x")).unwrap();
        std::fs::write(&plain, b"x").unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&ours), mode(&plain));
    }

    #[test]
    fn atomic_write_leaves_nothing_on_failure() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        let r = write_atomic(&path, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("boom"))
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        write_atomic(&path, |w| w.write_all(b"whole")).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"whole");
    }

    /// A failed directory write leaves the old directory as it was and no temporary beside it.
    #[test]
    fn atomic_directory_write_keeps_the_old_one_on_failure() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out");
        write_dir_atomic(&path, |d| std::fs::write(d.join("a"), "old")).unwrap();
        let r = write_dir_atomic(&path, |d| {
            std::fs::write(d.join("a"), "new")?;
            Err(std::io::Error::other("boom"))
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(path.join("a")).unwrap(), "old");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn cgns_output_is_available_exactly_with_the_feature() {
        let format = MeshFormat::from_path(Path::new("out.CGNS"), false);
        assert_eq!(format, Some(MeshFormat::Cgns));
        assert_eq!(MeshFormat::Cgns.unavailable().is_some(), !cfg!(feature = "cgns"));
        if let Some(why) = MeshFormat::Cgns.unavailable() {
            assert!(why.contains("--features cgns"), "{why}");
        }
        assert_eq!(MeshFormat::Su2.unavailable(), None);
    }

    #[test]
    fn ugrid_encoding_comes_from_the_suffix_before_the_extension() {
        let format = |name: &str| MeshFormat::from_path(Path::new(name), false);
        let ugrid = |encoding| Some(MeshFormat::Ugrid { encoding });
        assert_eq!(format("wing.b8.ugrid"), ugrid(ugrid::Encoding::BigEndian));
        assert_eq!(format("wing.lb8.ugrid"), ugrid(ugrid::Encoding::LittleEndian));
        assert_eq!(format("wing.ugrid"), ugrid(ugrid::Encoding::Ascii));
        assert_eq!(format("wing.r8.ugrid"), None);
    }

    #[test]
    fn unknown_extension_is_a_clear_error() {
        let e = read_surface(Path::new("body.xyz")).unwrap_err();
        assert!(e.to_string().contains("unknown file type"), "{e}");
    }
}
