//! [`CoreMesher`] through TetGen 1.5 (system library `libtet`, C++ shim `csrc/tetgen_shim.cpp`).
//!
//! Switches (TetGen 1.5 manual, section 4.2; `tetgenbehavior::parse_commandline`):
//! - `p`: the input is a piecewise linear complex (our boundary triangles, one facet each);
//! - `Y`: keep the boundary mesh: no Steiner point on a boundary triangle or edge, so the front
//!   triangles stay faces of the tetrahedra exactly;
//! - `M`: do not merge coplanar neighbouring facets (merging flips their triangles' diagonals);
//! - `z`: number from zero; `Q`: quiet;
//! - `q{ratio}/{angle}`: Delaunay refinement until no tetrahedron has a radius-edge ratio above
//!   `ratio` or a dihedral angle below `angle` (where the boundary allows it);
//! - `m`: the size at every boundary point (`pointmtrlist`): a tetrahedron is split while its
//!   circumradius exceeds the size at one of its nodes; added points interpolate the sizes;
//! - `O{level}/7`: mesh optimisation after refinement (flips, smoothing of added points, point
//!   insertion/deletion), `level` passes;
//! - `o/{angle}`: the optimisation works on tetrahedra with a dihedral angle above `angle`.
//!
//! Hole points (`holelist`) inside the body shells make TetGen carve the body's interior.
//! TetGen keeps global state, so calls are serialised.
//!
//! TetGen runs in a forked child process ([`run`]): it ends on a failed internal assertion
//! (`abort`), which seen from here is a crash of the whole program. In a child, it is an error
//! the fill can answer (by meshing again without its seeds).

use std::ffi::{c_char, c_int, CString};
use std::sync::Mutex;

use super::isolate::{in_child, ChildEnd};
use super::{ClosedBoundary, CoreGuide, CoreMesher, CoreTets, FillError, CIRCUMRADIUS_PER_SIZE};
use crate::geometry::predicates::{orient3d, Sign};
use crate::geometry::DVec3;

/// TetGen with its quality and optimisation settings.
#[derive(Clone, Debug, PartialEq)]
pub struct TetGen {
    /// Largest radius-edge ratio of a tetrahedron (`-q`), >= 1.
    pub radius_edge: f64,
    /// Smallest dihedral angle refinement aims at, degrees (`-q.../angle`).
    pub min_dihedral: f64,
    /// Optimisation passes (`-O`), 0..=9.
    pub optimisation: u8,
    /// The optimisation works on tetrahedra with a dihedral angle above this, degrees
    /// (`-o/angle`; TetGen's default 165). 150 halves the tetrahedra below 10 degrees that
    /// TetGen leaves on spot and the Onera M6, at no cost in time.
    pub optimisation_max_dihedral: f64,
}

impl Default for TetGen {
    fn default() -> Self {
        // Each optimisation level doubles TetGen's passes (level 9: 511); where the boundary
        // has slivers it cannot improve (-Y keeps them), every pass visits them all again:
        // level 9 took minutes on the elbow's core, level 4 seconds. Our own pass
        // (`fill::improve`) follows.
        // Refinement for radius-edge 1.4 or dihedral angles of 18 degrees put a point near the
        // front in a fifth of the first core cells (fandisk: 80% within [1/r, r] of the last
        // layer, 92% at 2.0 and no bound on the angle) and the optimisation and our own pass
        // bring the angles back: the same share below 15 degrees either way (0.3%). On the
        // ONERA M6, whose stretched front triangles carry last layers 1.5 times taller than
        // their mean edge, 2.0 still put a point half way up the first core cell of 1 front
        // triangle in 7 (81.6% within [1/r, r]; 3.0: 86.7%, and the same angles after our pass).
        TetGen { radius_edge: 3.0, min_dihedral: 0.0, optimisation: 4, optimisation_max_dihedral: 150.0 }
    }
}

impl TetGen {
    /// The switch string for a run with (`sized`) or without per-point sizes.
    pub fn switches(&self, sized: bool) -> String {
        let radius_edge = self.radius_edge.max(1.0);
        let angle = self.min_dihedral.clamp(0.0, 60.0);
        let level = self.optimisation.min(9);
        let max_angle = self.optimisation_max_dihedral.clamp(90.0, 180.0);
        format!("pYMzQq{radius_edge:.4}/{angle:.4}O{level}/7o/{max_angle:.4}{}", if sized { "m" } else { "" })
    }
}

impl CoreMesher for TetGen {
    fn fill(&self, boundary: &ClosedBoundary, guide: &CoreGuide) -> Result<CoreTets, FillError> {
        let sized = !guide.size.is_empty();
        let points = boundary.points.len() + guide.interior.len();
        if sized && guide.size.len() != points {
            return Err(FillError::Input(format!("{} sizes for {points} points", guide.size.len())));
        }
        let radii: Vec<f64> = guide.size.iter().map(|s| s * CIRCUMRADIUS_PER_SIZE).collect();
        let input = Input::new(boundary, &guide.interior, sized.then_some(&radii[..]))?;
        let output = run(&input, &self.switches(sized))?;
        output.into_core(boundary.points.len())
    }
}

/// The boundary as TetGen's C arrays, checked.
struct Input {
    points: Vec<f64>,
    sizes: Option<Vec<f64>>,
    triangles: Vec<c_int>,
    markers: Vec<c_int>,
    holes: Vec<f64>,
}

impl Input {
    /// The boundary and the interior points after it (TetGen inserts the points no facet uses
    /// as they are, and lists its input points first in its output).
    fn new(boundary: &ClosedBoundary, interior: &[DVec3], sizes: Option<&[f64]>) -> Result<Input, FillError> {
        let fits = |count: usize, what: &str| {
            c_int::try_from(count)
                .map_err(|_| FillError::Input(format!("{count} {what} are too many for TetGen")))
        };
        fits(boundary.points.len() + interior.len(), "points")?;
        if let Some(p) = interior.iter().position(|p| !p.is_finite()) {
            return Err(FillError::Input(format!("interior point {p} is not finite: {:?}", interior[p])));
        }
        fits(boundary.triangles.len(), "triangles")?;
        if let Some(p) = sizes.and_then(|s| s.iter().position(|x| !(x.is_finite() && *x >= 0.0))) {
            return Err(FillError::Input(format!("the size at point {p} is not a length")));
        }
        // TetGen may crash (not fail) on a boundary that intersects itself.
        boundary.check_no_self_intersection()?;
        let holes = boundary.hole_points()?;
        Ok(Input {
            points: boundary.points.iter().chain(interior).flat_map(|p| p.to_array()).collect(),
            sizes: sizes.map(<[f64]>::to_vec),
            // Node indices are < the point count, which fits c_int.
            triangles: boundary.triangles.iter().flatten().map(|&v| v as c_int).collect(),
            markers: boundary.markers.iter().map(|&m| c_int::try_from(m).unwrap_or(c_int::MAX)).collect(),
            holes: holes.iter().flat_map(|p| p.to_array()).collect(),
        })
    }
}

/// TetGen's output, copied out of the shim.
struct Output {
    points: Vec<DVec3>,
    tets: Vec<[c_int; 4]>,
    boundary_triangles: Vec<[c_int; 3]>,
}

impl Output {
    /// Checked indices, positive orientation, and the count of added boundary points.
    fn into_core(self, boundary_points: usize) -> Result<CoreTets, FillError> {
        let n = self.points.len();
        let index = |v: c_int| usize::try_from(v).ok().filter(|&v| v < n).map(|v| v as u32);
        let mut tets = Vec::with_capacity(self.tets.len());
        for (i, tet) in self.tets.iter().enumerate() {
            let bad = || FillError::BadOutput(format!("TetGen tetrahedron {i} {tet:?} is out of range"));
            let mut t = [0u32; 4];
            for (ti, &v) in t.iter_mut().zip(tet) {
                *ti = index(v).ok_or_else(bad)?;
            }
            let [a, b, c, d] = t.map(|v| self.points[v as usize]);
            match orient3d(a, b, c, d) {
                Sign::Positive => tets.push(t),
                Sign::Negative => tets.push([t[1], t[0], t[2], t[3]]),
                Sign::Zero => {
                    return Err(FillError::BadOutput(format!("TetGen tetrahedron {i} {t:?} is flat")))
                }
            }
        }
        let mut added_on_boundary: Vec<usize> = self
            .boundary_triangles
            .iter()
            .flatten()
            .filter_map(|&v| usize::try_from(v).ok())
            .filter(|&v| v >= boundary_points)
            .collect();
        added_on_boundary.sort_unstable();
        added_on_boundary.dedup();
        Ok(CoreTets { points: self.points, tets, boundary_steiner_points: added_on_boundary.len() })
    }
}

/// TetGen keeps global state (its predicates' constants, among others): one run at a time.
static TETGEN: Mutex<()> = Mutex::new(());

mod ffi {
    use std::ffi::{c_char, c_int};

    /// The shim's opaque result (a `tetgenio`).
    #[repr(C)]
    pub struct BlmeshTetgenResult {
        _private: [u8; 0],
    }

    extern "C" {
        #[allow(clippy::too_many_arguments)]
        pub fn blmesh_tetgen_run(
            n_points: c_int,
            points: *const f64,
            sizes: *const f64,
            n_triangles: c_int,
            triangles: *const c_int,
            markers: *const c_int,
            n_holes: c_int,
            holes: *const f64,
            switches: *const c_char,
            result: *mut *mut BlmeshTetgenResult,
            message: *mut c_char,
            message_capacity: usize,
        ) -> c_int;
        pub fn blmesh_tetgen_points(
            n_points: c_int,
            points: *const f64,
            switches: *const c_char,
            result: *mut *mut BlmeshTetgenResult,
            message: *mut c_char,
            message_capacity: usize,
        ) -> c_int;
        pub fn blmesh_tetgen_counts(
            result: *const BlmeshTetgenResult,
            n_points: *mut c_int,
            n_tets: *mut c_int,
            n_boundary_triangles: *mut c_int,
        );
        pub fn blmesh_tetgen_copy(
            result: *const BlmeshTetgenResult,
            points: *mut f64,
            tets: *mut c_int,
            boundary_triangles: *mut c_int,
        );
        pub fn blmesh_tetgen_free(result: *mut BlmeshTetgenResult);
    }
}

/// Frees the shim's result however the copy ends.
struct ResultGuard(*mut ffi::BlmeshTetgenResult);

impl Drop for ResultGuard {
    fn drop(&mut self) {
        // SAFETY: the pointer came from a successful `blmesh_tetgen_run`, is non-null, and is
        // freed exactly once, here.
        unsafe { ffi::blmesh_tetgen_free(self.0) }
    }
}

/// Run TetGen on `input` in a forked child process ([`in_child`]): an abort or a crash of
/// TetGen becomes [`FillError::TetGenCrashed`]. Where no child can be started, here.
fn run(input: &Input, switches: &str) -> Result<Output, FillError> {
    let _one_at_a_time = TETGEN.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    match in_child(|| encode(&run_here(input, switches))) {
        Ok(bytes) => decode(&bytes).unwrap_or_else(|| {
            Err(FillError::BadOutput(format!(
                "TetGen's process answered {} bytes that do not decode",
                bytes.len()
            )))
        }),
        Err(ChildEnd::Signal(signal)) => Err(FillError::TetGenCrashed { signal }),
        Err(ChildEnd::Exit(status)) => {
            Err(FillError::BadOutput(format!("TetGen's process exited with status {status} and no answer")))
        }
        Err(ChildEnd::NotStarted) => run_here(input, switches),
    }
}

/// TetGen's result as bytes for the pipe: a tag (0 output, 1 error), then the counts and
/// arrays (little-endian), or the error's code and message.
fn encode(result: &Result<Output, FillError>) -> Vec<u8> {
    let mut bytes = Vec::new();
    match result {
        Ok(out) => {
            bytes.push(0);
            for n in [out.points.len(), out.tets.len(), out.boundary_triangles.len()] {
                bytes.extend((n as u64).to_le_bytes());
            }
            bytes.extend(out.points.iter().flat_map(|p| p.to_array()).flat_map(f64::to_le_bytes));
            bytes.extend(out.tets.iter().flatten().flat_map(|v| v.to_le_bytes()));
            bytes.extend(out.boundary_triangles.iter().flatten().flat_map(|v| v.to_le_bytes()));
        }
        Err(error) => {
            let (code, message) = match error {
                FillError::TetGen { code, message } => (*code, message.clone()),
                other => (-1, other.to_string()),
            };
            bytes.push(1);
            bytes.extend(code.to_le_bytes());
            bytes.extend(message.as_bytes());
        }
    }
    bytes
}

/// The result [`encode`] wrote; `None` when the bytes are not a whole one.
fn decode(bytes: &[u8]) -> Option<Result<Output, FillError>> {
    let (&tag, rest) = bytes.split_first()?;
    if tag == 1 {
        let code = i32::from_le_bytes(rest.get(..4)?.try_into().ok()?);
        let message = String::from_utf8_lossy(rest.get(4..)?).into_owned();
        return Some(Err(FillError::TetGen { code, message }));
    }
    let mut bytes = Bytes(rest);
    let (n_points, n_tets, n_triangles) = (bytes.count()?, bytes.count()?, bytes.count()?);
    let coordinates: Vec<f64> = bytes
        .take(n_points.checked_mul(24)?)?
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap_or_default()))
        .collect();
    let points = coordinates.chunks_exact(3).map(|p| DVec3::new(p[0], p[1], p[2])).collect();
    let tets =
        bytes.ints(n_tets.checked_mul(4)?)?.chunks_exact(4).map(|t| [t[0], t[1], t[2], t[3]]).collect();
    let boundary_triangles =
        bytes.ints(n_triangles.checked_mul(3)?)?.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    bytes.0.is_empty().then_some(Ok(Output { points, tets, boundary_triangles }))
}

/// The bytes of [`decode`] not read yet.
struct Bytes<'a>(&'a [u8]);

impl<'a> Bytes<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let (head, tail) = self.0.split_at_checked(n)?;
        self.0 = tail;
        Some(head)
    }

    fn count(&mut self) -> Option<usize> {
        usize::try_from(u64::from_le_bytes(self.take(8)?.try_into().ok()?)).ok()
    }

    fn ints(&mut self, n: usize) -> Option<Vec<c_int>> {
        let bytes = self.take(n.checked_mul(4)?)?;
        Some(bytes.chunks_exact(4).map(|c| c_int::from_le_bytes(c.try_into().unwrap_or_default())).collect())
    }
}

/// Run TetGen in this process (the lock held by the caller).
fn run_here(input: &Input, switches: &str) -> Result<Output, FillError> {
    let switches = CString::new(switches).map_err(|_| FillError::Input("switches contain a NUL".into()))?;
    let mut result: *mut ffi::BlmeshTetgenResult = std::ptr::null_mut();
    let mut message = [0 as c_char; 256];
    // SAFETY: every array holds the counts passed with it (checked to fit c_int in Input::new;
    // triangle indices are < n_points); `sizes` is null or n_points long; `holes` holds 3 values
    // per hole; the strings are NUL-terminated and `message` has the capacity passed. The shim
    // catches every C++ exception, so nothing unwinds into Rust.
    let code = unsafe {
        ffi::blmesh_tetgen_run(
            (input.points.len() / 3) as c_int,
            input.points.as_ptr(),
            input.sizes.as_ref().map_or(std::ptr::null(), |s| s.as_ptr()),
            (input.triangles.len() / 3) as c_int,
            input.triangles.as_ptr(),
            input.markers.as_ptr(),
            (input.holes.len() / 3) as c_int,
            input.holes.as_ptr(),
            switches.as_ptr(),
            &mut result,
            message.as_mut_ptr(),
            message.len(),
        )
    };
    if code != 0 || result.is_null() {
        return Err(tetgen_error(code, &message));
    }
    copy_out(ResultGuard(result))
}

/// TetGen's Delaunay tetrahedralisation of a bare point set, for comparing Delaunay kernels:
/// the tetrahedra, indices into `points`, as TetGen orders their vertices (positive by our
/// `orient3d`, not checked here). Switches `zQF`: no facets (no `p`), no faces written. It runs
/// in this process, not in a child: the answer (millions of tetrahedra) would cost more to send
/// through the pipe than to compute, which would blur the comparison; so a crash of TetGen ends
/// the program.
pub fn delaunay_of_points(points: &[DVec3]) -> Result<Vec<[u32; 4]>, FillError> {
    let n = c_int::try_from(points.len())
        .map_err(|_| FillError::Input(format!("{} points are too many for TetGen", points.len())))?;
    if let Some(p) = points.iter().position(|p| !p.is_finite()) {
        return Err(FillError::Input(format!("point {p} is not finite: {:?}", points[p])));
    }
    let coordinates: Vec<f64> = points.iter().flat_map(|p| p.to_array()).collect();
    let _one_at_a_time = TETGEN.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let mut result: *mut ffi::BlmeshTetgenResult = std::ptr::null_mut();
    let mut message = [0 as c_char; 256];
    // SAFETY: `coordinates` holds 3 values per point; the switches are NUL-terminated and
    // `message` has the capacity passed. The shim catches every C++ exception.
    let code = unsafe {
        ffi::blmesh_tetgen_points(
            n,
            coordinates.as_ptr(),
            c"zQF".as_ptr(),
            &mut result,
            message.as_mut_ptr(),
            message.len(),
        )
    };
    if code != 0 || result.is_null() {
        return Err(tetgen_error(code, &message));
    }
    let output = copy_out(ResultGuard(result))?;
    let index = |v: c_int| u32::try_from(v).ok().filter(|&v| (v as usize) < points.len());
    output
        .tets
        .iter()
        .map(|t| {
            let checked = [index(t[0]), index(t[1]), index(t[2]), index(t[3])];
            match checked {
                [Some(a), Some(b), Some(c), Some(d)] => Ok([a, b, c, d]),
                _ => Err(FillError::BadOutput(format!("TetGen tetrahedron {t:?} is out of range"))),
            }
        })
        .collect()
}

/// Copy TetGen's output out of the shim's result, and free it.
fn copy_out(guard: ResultGuard) -> Result<Output, FillError> {
    let (mut n_points, mut n_tets, mut n_triangles) = (0 as c_int, 0 as c_int, 0 as c_int);
    // SAFETY: `guard.0` is a live result; the three out-pointers are valid for writes.
    unsafe { ffi::blmesh_tetgen_counts(guard.0, &mut n_points, &mut n_tets, &mut n_triangles) };
    let count = |c: c_int| usize::try_from(c).map_err(|_| FillError::BadOutput(format!("TetGen count {c}")));
    let (n_points, n_tets, n_triangles) = (count(n_points)?, count(n_tets)?, count(n_triangles)?);
    let mut points = vec![0.0f64; 3 * n_points];
    let mut tets = vec![0 as c_int; 4 * n_tets];
    let mut triangles = vec![0 as c_int; 3 * n_triangles];
    // SAFETY: the buffers are sized from the counts the shim just reported for this result.
    unsafe {
        ffi::blmesh_tetgen_copy(guard.0, points.as_mut_ptr(), tets.as_mut_ptr(), triangles.as_mut_ptr())
    };
    drop(guard);
    Ok(Output {
        points: points.chunks_exact(3).map(|p| DVec3::new(p[0], p[1], p[2])).collect(),
        tets: tets.chunks_exact(4).map(|t| [t[0], t[1], t[2], t[3]]).collect(),
        boundary_triangles: triangles.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
    })
}

/// TetGen's error codes (`terminatetetgen`) and the shim's own, explained.
fn tetgen_error(code: c_int, message: &[c_char]) -> FillError {
    let bytes: Vec<u8> = message.iter().take_while(|&&c| c != 0).map(|&c| c as u8).collect();
    let detail = String::from_utf8_lossy(&bytes);
    let meaning = match code {
        1 => "out of memory",
        2 => "internal error",
        3 => "the boundary intersects itself (the front crosses itself or the farfield)",
        4 => "a very small input feature (points or edges too close for the tolerance)",
        5 => "two boundary triangles are very close to each other",
        10 => "input error",
        100 => "bad arguments to the shim",
        101 | 102 => "C++ exception",
        _ => "unknown error",
    };
    FillError::TetGen { code, message: format!("{meaning}; {detail}") }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_answer_crosses_the_pipe_whole() {
        let output = Output {
            points: vec![DVec3::new(1.0, -2.5, 3.25), DVec3::new(f64::MIN_POSITIVE, 0.0, 1e300)],
            tets: vec![[0, 1, 2, 3], [4, 5, 6, 7]],
            boundary_triangles: vec![[0, 1, 2]],
        };
        let Some(Ok(back)) = decode(&encode(&Ok(output))) else { panic!("no output") };
        assert_eq!(back.points, vec![DVec3::new(1.0, -2.5, 3.25), DVec3::new(f64::MIN_POSITIVE, 0.0, 1e300)]);
        assert_eq!(
            (back.tets.len(), back.tets[1], back.boundary_triangles),
            (2, [4, 5, 6, 7], vec![[0, 1, 2]])
        );
        let error = FillError::TetGen { code: 3, message: "self-intersection".into() };
        let Some(Err(FillError::TetGen { code, message })) = decode(&encode(&Err(error))) else { panic!() };
        assert_eq!((code, message.as_str()), (3, "self-intersection"));
        let whole =
            encode(&Ok(Output { points: vec![DVec3::ONE], tets: vec![], boundary_triangles: vec![] }));
        assert!(decode(&whole[..whole.len() - 1]).is_none(), "a truncated answer is not one");
    }

    #[test]
    fn switches_keep_the_boundary_and_bound_the_quality() {
        let s = TetGen::default().switches(true);
        assert!(s.starts_with("pYMzQq3.0000/0.0000O4/7"), "{s}");
        assert!(s.ends_with('m'));
        assert!(!TetGen::default().switches(false).contains('m'));
    }

    #[test]
    fn error_codes_are_explained() {
        let msg: Vec<c_char> = b"TetGen stopped\0".iter().map(|&b| b as c_char).collect();
        let e = tetgen_error(3, &msg).to_string();
        assert!(e.contains("intersects itself") && e.contains("TetGen stopped"), "{e}");
    }
}
