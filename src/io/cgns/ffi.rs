//! The few functions of the CGNS mid-level library (`libcgns`, Debian `libcgns-dev` 3.4) that the
//! writer and reader need, with safe wrappers that turn error codes into [`CgnsError`]s carrying
//! `cg_get_error`'s message.
//!
//! The library keeps global state (open files, the last error), so every call is made while
//! holding [`LIBRARY`]: an open [`File`] owns the lock until it is closed.

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::Path;
use std::sync::{Mutex, MutexGuard};

use super::CgnsError;

/// `cgsize_t`: `int` in Debian's build (`CG_BUILD_LEGACY`), `long` in a 64-bit build; build.rs
/// reads `cgnstypes.h` and sets `cgns_size64` for the latter.
#[cfg(not(cgns_size64))]
pub type CgSize = i32;
#[cfg(cgns_size64)]
pub type CgSize = i64;

pub const MODE_READ: c_int = 0;
pub const MODE_WRITE: c_int = 1;
const FILE_HDF5: c_int = 2;
const CG_OK: c_int = 0;
/// `DataClass_t::NormalizedByUnknownDimensional`: numbers in units nobody stated.
pub const UNKNOWN_UNITS: c_int = 4;
/// `ZoneType_t::Unstructured`.
pub const UNSTRUCTURED: c_int = 3;
/// `DataType_t::RealDouble`.
pub const REAL_DOUBLE: c_int = 4;
/// `GridLocation_t::Vertex`, `FaceCenter`.
pub const VERTEX: c_int = 2;
pub const FACE_CENTER: c_int = 4;
/// `PointSetType_t` values.
pub const POINT_LIST: c_int = 2;
pub const POINT_RANGE: c_int = 4;
pub const ELEMENT_RANGE: c_int = 6;
pub const ELEMENT_LIST: c_int = 7;
/// Node names are at most 32 characters (`char name[33]` with the terminator).
pub const NAME_LEN: usize = 32;

// Linked by build.rs (feature `cgns`). Declarations as in cgnslib.h 3.4 (enums are `int`).
#[rustfmt::skip]
extern "C" {
    fn cg_set_file_type(file_type: c_int) -> c_int;
    fn cg_open(filename: *const c_char, mode: c_int, fn_: *mut c_int) -> c_int;
    fn cg_close(fn_: c_int) -> c_int;
    fn cg_get_error() -> *const c_char;
    fn cg_gopath(fn_: c_int, path: *const c_char) -> c_int;
    fn cg_dataclass_write(data_class: c_int) -> c_int;
    fn cg_exponents_write(data_type: c_int, exponents: *const c_void) -> c_int;
    fn cg_base_write(fn_: c_int, name: *const c_char, cell_dim: c_int, phys_dim: c_int, b: *mut c_int) -> c_int;
    fn cg_nbases(fn_: c_int, n: *mut c_int) -> c_int;
    fn cg_base_read(fn_: c_int, b: c_int, name: *mut c_char, cell_dim: *mut c_int, phys_dim: *mut c_int) -> c_int;
    fn cg_zone_write(fn_: c_int, b: c_int, name: *const c_char, size: *const CgSize, zone_type: c_int,
        z: *mut c_int) -> c_int;
    fn cg_nzones(fn_: c_int, b: c_int, n: *mut c_int) -> c_int;
    fn cg_zone_type(fn_: c_int, b: c_int, z: c_int, zone_type: *mut c_int) -> c_int;
    fn cg_zone_read(fn_: c_int, b: c_int, z: c_int, name: *mut c_char, size: *mut CgSize) -> c_int;
    fn cg_coord_write(fn_: c_int, b: c_int, z: c_int, data_type: c_int, name: *const c_char,
        data: *const c_void, c: *mut c_int) -> c_int;
    fn cg_coord_read(fn_: c_int, b: c_int, z: c_int, name: *const c_char, data_type: c_int,
        rmin: *const CgSize, rmax: *const CgSize, data: *mut c_void) -> c_int;
    fn cg_section_write(fn_: c_int, b: c_int, z: c_int, name: *const c_char, element_type: c_int,
        start: CgSize, end: CgSize, nbndry: c_int, elements: *const CgSize, s: *mut c_int) -> c_int;
    fn cg_poly_section_write(fn_: c_int, b: c_int, z: c_int, name: *const c_char, element_type: c_int,
        start: CgSize, end: CgSize, nbndry: c_int, elements: *const CgSize, offsets: *const CgSize,
        s: *mut c_int) -> c_int;
    fn cg_nsections(fn_: c_int, b: c_int, z: c_int, n: *mut c_int) -> c_int;
    fn cg_section_read(fn_: c_int, b: c_int, z: c_int, s: c_int, name: *mut c_char, element_type: *mut c_int,
        start: *mut CgSize, end: *mut CgSize, nbndry: *mut c_int, parent_flag: *mut c_int) -> c_int;
    fn cg_ElementDataSize(fn_: c_int, b: c_int, z: c_int, s: c_int, size: *mut CgSize) -> c_int;
    fn cg_elements_read(fn_: c_int, b: c_int, z: c_int, s: c_int, elements: *mut CgSize,
        parent_data: *mut CgSize) -> c_int;
    fn cg_poly_elements_read(fn_: c_int, b: c_int, z: c_int, s: c_int, elements: *mut CgSize,
        offsets: *mut CgSize, parent_data: *mut CgSize) -> c_int;
    fn cg_boco_write(fn_: c_int, b: c_int, z: c_int, name: *const c_char, bc_type: c_int,
        point_set_type: c_int, npnts: CgSize, pnts: *const CgSize, bc: *mut c_int) -> c_int;
    fn cg_boco_gridlocation_write(fn_: c_int, b: c_int, z: c_int, bc: c_int, location: c_int) -> c_int;
    fn cg_nbocos(fn_: c_int, b: c_int, z: c_int, n: *mut c_int) -> c_int;
    fn cg_boco_info(fn_: c_int, b: c_int, z: c_int, bc: c_int, name: *mut c_char, bc_type: *mut c_int,
        point_set_type: *mut c_int, npnts: *mut CgSize, normal_index: *mut c_int,
        normal_list_size: *mut CgSize, normal_data_type: *mut c_int, ndataset: *mut c_int) -> c_int;
    fn cg_boco_read(fn_: c_int, b: c_int, z: c_int, bc: c_int, pnts: *mut CgSize, normals: *mut c_void) -> c_int;
    fn cg_boco_gridlocation_read(fn_: c_int, b: c_int, z: c_int, bc: c_int, location: *mut c_int) -> c_int;
}

/// Serialises every use of the library (it is not thread-safe).
static LIBRARY: Mutex<()> = Mutex::new(());

/// `Ok` for `CG_OK`, else the library's message for the failed `what`.
fn check(code: c_int, what: &str) -> Result<(), CgnsError> {
    if code == CG_OK {
        return Ok(());
    }
    // SAFETY: cg_get_error returns a pointer to the library's static, NUL-terminated message.
    let message = unsafe {
        let p = cg_get_error();
        if p.is_null() {
            String::new()
        } else {
            CStr::from_ptr(p).to_string_lossy().into_owned()
        }
    };
    Err(CgnsError::library(what, message))
}

fn c_string(text: &str) -> Result<CString, CgnsError> {
    CString::new(text).map_err(|_| CgnsError::new(format!("name {text:?} contains a NUL character")))
}

/// A name read into a `char[33]` buffer.
fn name_from(buffer: &[c_char; NAME_LEN + 1]) -> String {
    let bytes: Vec<u8> = buffer.iter().take_while(|&&c| c != 0).map(|&c| c as u8).collect();
    String::from_utf8_lossy(&bytes).into_owned()
}

/// The element section header as `cg_section_read` gives it.
pub struct SectionHeader {
    pub name: String,
    pub element_type: c_int,
    pub start: CgSize,
    pub end: CgSize,
}

/// A boundary condition header as `cg_boco_info` gives it.
pub struct BocoHeader {
    pub name: String,
    pub bc_type: c_int,
    pub point_set_type: c_int,
    pub point_count: CgSize,
}

/// An open CGNS file; holds the library lock until closed (or dropped).
pub struct File {
    id: c_int,
    open: bool,
    _lock: MutexGuard<'static, ()>,
}

impl File {
    /// Open `path` (`MODE_WRITE` creates an HDF5 file, replacing what is there).
    pub fn open(path: &Path, mode: c_int) -> Result<File, CgnsError> {
        let lock = LIBRARY.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        let name = path.to_str().ok_or_else(|| CgnsError::new("the path is not valid UTF-8"))?;
        let name = c_string(name)?;
        let mut id = 0;
        // SAFETY: plain values and a valid NUL-terminated string; the lock is held.
        unsafe {
            if mode == MODE_WRITE {
                check(cg_set_file_type(FILE_HDF5), "cannot select HDF5 files")?;
            }
            check(cg_open(name.as_ptr(), mode, &mut id), "cannot open")?;
        }
        Ok(File { id, open: true, _lock: lock })
    }

    /// Close the file, reporting a failure to flush it.
    pub fn close(mut self) -> Result<(), CgnsError> {
        self.open = false;
        // SAFETY: `id` is an open file of ours.
        check(unsafe { cg_close(self.id) }, "cannot close")
    }

    pub fn write_base(&mut self, name: &str, cell_dim: c_int, phys_dim: c_int) -> Result<c_int, CgnsError> {
        let name = c_string(name)?;
        let mut b = 0;
        // SAFETY: valid string and out-pointer.
        check(
            unsafe { cg_base_write(self.id, name.as_ptr(), cell_dim, phys_dim, &mut b) },
            "cannot write the base",
        )?;
        Ok(b)
    }

    /// Set the `DataClass` of the node at `path` (e.g. `/Base`), inherited by what is below it.
    pub fn write_data_class(&mut self, path: &str, data_class: c_int) -> Result<(), CgnsError> {
        let c_path = c_string(path)?;
        let what = format!("cannot write the data class of {path}");
        // SAFETY: a valid string; cg_dataclass_write applies to the node cg_gopath went to.
        unsafe {
            check(cg_gopath(self.id, c_path.as_ptr()), &what)?;
            check(cg_dataclass_write(data_class), &what)
        }
    }

    /// Set the `DimensionalExponents` (mass, length, time, temperature, angle) of the data
    /// array at `path`.
    pub fn write_exponents(&mut self, path: &str, exponents: [f64; 5]) -> Result<(), CgnsError> {
        let c_path = c_string(path)?;
        let what = format!("cannot write the dimensions of {path}");
        // SAFETY: a valid string and the 5 exponents cg_exponents_write reads.
        unsafe {
            check(cg_gopath(self.id, c_path.as_ptr()), &what)?;
            check(cg_exponents_write(REAL_DOUBLE, exponents.as_ptr().cast()), &what)
        }
    }

    pub fn base_count(&mut self) -> Result<c_int, CgnsError> {
        let mut n = 0;
        // SAFETY: valid out-pointer.
        check(unsafe { cg_nbases(self.id, &mut n) }, "cannot count the bases")?;
        Ok(n)
    }

    /// (cell dimension, physical dimension) of base `b`.
    pub fn base_dimensions(&mut self, b: c_int) -> Result<(c_int, c_int), CgnsError> {
        let mut name = [0 as c_char; NAME_LEN + 1];
        let (mut cell, mut phys) = (0, 0);
        // SAFETY: a 33-byte name buffer and valid out-pointers.
        check(
            unsafe { cg_base_read(self.id, b, name.as_mut_ptr(), &mut cell, &mut phys) },
            "cannot read the base",
        )?;
        Ok((cell, phys))
    }

    /// An unstructured zone with `size` = [vertices, cells, boundary vertices].
    pub fn write_unstructured_zone(
        &mut self,
        b: c_int,
        name: &str,
        size: [CgSize; 3],
    ) -> Result<c_int, CgnsError> {
        let name = c_string(name)?;
        let mut z = 0;
        // SAFETY: `size` has the 3 values an unstructured zone needs.
        check(
            unsafe { cg_zone_write(self.id, b, name.as_ptr(), size.as_ptr(), UNSTRUCTURED, &mut z) },
            "cannot write the zone",
        )?;
        Ok(z)
    }

    pub fn zone_count(&mut self, b: c_int) -> Result<c_int, CgnsError> {
        let mut n = 0;
        // SAFETY: valid out-pointer.
        check(unsafe { cg_nzones(self.id, b, &mut n) }, "cannot count the zones")?;
        Ok(n)
    }

    pub fn zone_type(&mut self, b: c_int, z: c_int) -> Result<c_int, CgnsError> {
        let mut t = 0;
        // SAFETY: valid out-pointer.
        check(unsafe { cg_zone_type(self.id, b, z, &mut t) }, "cannot read the zone type")?;
        Ok(t)
    }

    /// [vertices, cells, boundary vertices] of an unstructured zone (check its type first: a
    /// structured zone has 9 values).
    pub fn unstructured_zone_size(&mut self, b: c_int, z: c_int) -> Result<[CgSize; 3], CgnsError> {
        let mut name = [0 as c_char; NAME_LEN + 1];
        // Room for the 9 values of a 3D structured zone, whatever the type.
        let mut size = [0 as CgSize; 9];
        // SAFETY: a 33-byte name buffer and room for any zone's sizes.
        check(
            unsafe { cg_zone_read(self.id, b, z, name.as_mut_ptr(), size.as_mut_ptr()) },
            "cannot read the zone",
        )?;
        Ok([size[0], size[1], size[2]])
    }

    pub fn write_coordinate(
        &mut self,
        b: c_int,
        z: c_int,
        name: &str,
        values: &[f64],
    ) -> Result<(), CgnsError> {
        let c_name = c_string(name)?;
        let mut c = 0;
        // SAFETY: the zone was written with `values.len()` vertices.
        check(
            unsafe {
                cg_coord_write(self.id, b, z, REAL_DOUBLE, c_name.as_ptr(), values.as_ptr().cast(), &mut c)
            },
            &format!("cannot write {name}"),
        )
    }

    /// All values of coordinate `name` of a zone of `count` vertices.
    pub fn read_coordinate(
        &mut self,
        b: c_int,
        z: c_int,
        name: &str,
        count: CgSize,
    ) -> Result<Vec<f64>, CgnsError> {
        let c_name = c_string(name)?;
        let len = usize::try_from(count).map_err(|_| CgnsError::new(format!("{count} vertices")))?;
        let mut values = vec![0.0f64; len];
        let (rmin, rmax): (CgSize, CgSize) = (1, count);
        // SAFETY: the range 1..=count fills exactly `len` values.
        check(
            unsafe {
                cg_coord_read(
                    self.id,
                    b,
                    z,
                    c_name.as_ptr(),
                    REAL_DOUBLE,
                    &rmin,
                    &rmax,
                    values.as_mut_ptr().cast(),
                )
            },
            &format!("cannot read {name}"),
        )?;
        Ok(values)
    }

    /// Elements `start..=end` of type `element_type`. A `MIXED` section (each element preceded
    /// by its type) also needs `offsets`: where each element starts in `elements`, and its end.
    pub fn write_section(
        &mut self,
        (b, z): (c_int, c_int),
        name: &str,
        element_type: c_int,
        (start, end): (CgSize, CgSize),
        elements: &[CgSize],
        offsets: Option<&[CgSize]>,
    ) -> Result<(), CgnsError> {
        let c_name = c_string(name)?;
        let mut s = 0;
        let (n, e) = (c_name.as_ptr(), elements.as_ptr());
        // SAFETY: `elements` (and `offsets`, `end - start + 2` values) describe the
        // `end - start + 1` elements.
        let code = unsafe {
            match offsets {
                Some(o) => cg_poly_section_write(
                    self.id,
                    b,
                    z,
                    n,
                    element_type,
                    start,
                    end,
                    0,
                    e,
                    o.as_ptr(),
                    &mut s,
                ),
                None => cg_section_write(self.id, b, z, n, element_type, start, end, 0, e, &mut s),
            }
        };
        check(code, &format!("cannot write section {name}"))
    }

    pub fn section_count(&mut self, b: c_int, z: c_int) -> Result<c_int, CgnsError> {
        let mut n = 0;
        // SAFETY: valid out-pointer.
        check(unsafe { cg_nsections(self.id, b, z, &mut n) }, "cannot count the sections")?;
        Ok(n)
    }

    pub fn section_header(&mut self, b: c_int, z: c_int, s: c_int) -> Result<SectionHeader, CgnsError> {
        let mut name = [0 as c_char; NAME_LEN + 1];
        let (mut element_type, mut start, mut end, mut nbndry, mut parent) = (0, 0, 0, 0, 0);
        // SAFETY: a 33-byte name buffer and valid out-pointers.
        check(
            unsafe {
                cg_section_read(
                    self.id,
                    b,
                    z,
                    s,
                    name.as_mut_ptr(),
                    &mut element_type,
                    &mut start,
                    &mut end,
                    &mut nbndry,
                    &mut parent,
                )
            },
            &format!("cannot read section {s}"),
        )?;
        Ok(SectionHeader { name: name_from(&name), element_type, start, end })
    }

    /// Number of values in the connectivity of section `s`.
    pub fn section_data_size(&mut self, b: c_int, z: c_int, s: c_int) -> Result<CgSize, CgnsError> {
        let mut size = 0;
        // SAFETY: valid out-pointer.
        check(
            unsafe { cg_ElementDataSize(self.id, b, z, s, &mut size) },
            &format!("cannot size section {s}"),
        )?;
        Ok(size)
    }

    /// The connectivity of section `s`, of `len` values ([`File::section_data_size`]); a
    /// `MIXED` section of `count` elements is read with its offsets, which are dropped (the
    /// type before each element gives its size).
    pub fn read_elements(
        &mut self,
        (b, z, s): (c_int, c_int, c_int),
        mixed_count: Option<usize>,
        len: usize,
    ) -> Result<Vec<CgSize>, CgnsError> {
        let mut elements = vec![0 as CgSize; len];
        let e = elements.as_mut_ptr();
        let null = std::ptr::null_mut();
        // SAFETY: the buffer has the section's data size, the offsets one more value than the
        // section has elements; no parent data is requested.
        let code = unsafe {
            match mixed_count {
                Some(count) => {
                    let mut offsets = vec![0 as CgSize; count + 1];
                    cg_poly_elements_read(self.id, b, z, s, e, offsets.as_mut_ptr(), null)
                }
                None => cg_elements_read(self.id, b, z, s, e, null),
            }
        };
        check(code, &format!("cannot read section {s}"))?;
        Ok(elements)
    }

    /// A boundary condition on the face elements `points` (a `POINT_RANGE` [first, last] or a
    /// `POINT_LIST`), located at face centres.
    pub fn write_face_boco(
        &mut self,
        (b, z): (c_int, c_int),
        name: &str,
        bc_type: c_int,
        point_set_type: c_int,
        points: &[CgSize],
    ) -> Result<(), CgnsError> {
        let c_name = c_string(name)?;
        let count =
            CgSize::try_from(points.len()).map_err(|_| CgnsError::new(format!("{} faces", points.len())))?;
        let mut bc = 0;
        let what = format!("cannot write boundary condition {name}");
        // SAFETY: `points` holds `count` element numbers.
        unsafe {
            check(
                cg_boco_write(
                    self.id,
                    b,
                    z,
                    c_name.as_ptr(),
                    bc_type,
                    point_set_type,
                    count,
                    points.as_ptr(),
                    &mut bc,
                ),
                &what,
            )?;
            check(cg_boco_gridlocation_write(self.id, b, z, bc, FACE_CENTER), &what)
        }
    }

    pub fn boco_count(&mut self, b: c_int, z: c_int) -> Result<c_int, CgnsError> {
        let mut n = 0;
        // SAFETY: valid out-pointer.
        check(unsafe { cg_nbocos(self.id, b, z, &mut n) }, "cannot count the boundary conditions")?;
        Ok(n)
    }

    pub fn boco_header(&mut self, b: c_int, z: c_int, bc: c_int) -> Result<BocoHeader, CgnsError> {
        let mut name = [0 as c_char; NAME_LEN + 1];
        let (mut bc_type, mut point_set_type, mut point_count) = (0, 0, 0);
        let (mut normal_index, mut normal_size, mut normal_type, mut datasets) = ([0 as c_int; 3], 0, 0, 0);
        // SAFETY: a 33-byte name buffer, room for 3 normal indices, valid out-pointers.
        check(
            unsafe {
                cg_boco_info(
                    self.id,
                    b,
                    z,
                    bc,
                    name.as_mut_ptr(),
                    &mut bc_type,
                    &mut point_set_type,
                    &mut point_count,
                    normal_index.as_mut_ptr(),
                    &mut normal_size,
                    &mut normal_type,
                    &mut datasets,
                )
            },
            &format!("cannot read boundary condition {bc}"),
        )?;
        Ok(BocoHeader { name: name_from(&name), bc_type, point_set_type, point_count })
    }

    /// The `len` points of boundary condition `bc` ([`BocoHeader::point_count`]) and their location.
    pub fn read_boco(
        &mut self,
        b: c_int,
        z: c_int,
        bc: c_int,
        len: usize,
    ) -> Result<(Vec<CgSize>, c_int), CgnsError> {
        let mut points = vec![0 as CgSize; len];
        let mut location = 0;
        let what = format!("cannot read boundary condition {bc}");
        // SAFETY: the buffer has the condition's point count; no normals are requested.
        unsafe {
            check(cg_boco_read(self.id, b, z, bc, points.as_mut_ptr(), std::ptr::null_mut()), &what)?;
            check(cg_boco_gridlocation_read(self.id, b, z, bc, &mut location), &what)?;
        }
        Ok((points, location))
    }
}

impl Drop for File {
    fn drop(&mut self) {
        if self.open {
            // SAFETY: `id` is an open file of ours; the lock is still held (fields drop after this).
            unsafe { cg_close(self.id) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fill::isolate::in_child;

    /// HDF5 locks the file it writes (flock). A child forked meanwhile by another thread, as the
    /// TetGen fill does, inherited that lock and kept the finished file unreadable until it ended.
    #[test]
    fn a_file_written_while_a_child_runs_can_be_read_at_once() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("locked.cgns");
        let mut file = File::open(&path, MODE_WRITE).unwrap();
        file.write_base("Base", 3, 3).unwrap();
        let (forking, forked) = std::sync::mpsc::channel();
        let child = std::thread::spawn(move || {
            forking.send(()).unwrap();
            in_child(|| {
                std::thread::sleep(std::time::Duration::from_secs(2));
                Vec::new()
            })
        });
        forked.recv().unwrap();
        std::thread::sleep(std::time::Duration::from_millis(200));
        file.close().unwrap();
        let mut back = File::open(&path, MODE_READ).expect("the child held the file's lock");
        assert_eq!(back.base_count().unwrap(), 1);
        drop(back);
        assert_eq!(child.join().unwrap(), Ok(Vec::new()));
    }
}
