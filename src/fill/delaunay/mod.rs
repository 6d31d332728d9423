//! Delaunay tetrahedralisation of a point set: the first piece of a native core mesher.
//!
//! [`Delaunay::new`] computes the Delaunay tetrahedralisation of the input points, exactly: no
//! point is added (no bounding tetrahedron), and every combinatorial decision is an exact
//! predicate ([`orient3d`], [`insphere_perturbed`]). The tetrahedra on the convex hull's faces
//! share an *infinite vertex* ([`INFINITE`]), so the hull is a triangulated sphere like any
//! other cavity boundary and a point outside it is inserted like one inside.
//!
//! Insertion is Bowyer–Watson's: find the tetrahedron containing the new point by a
//! visibility walk from the last one created (the exit face is tried in a random order, so
//! that the walk cannot cycle), grow from it the cavity of the tetrahedra whose circumsphere
//! contains the point, and replace the cavity by the tetrahedra joining the point to the
//! cavity's boundary faces. The tetrahedra are linked by their faces: `neighbours[t][i]` is
//! the tetrahedron across the face opposite vertex `i` of `t`. The cavity's slots are reused
//! by the new tetrahedra, and slots left over are reused by later insertions.
//!
//! Predicate rules:
//! - A finite tetrahedron is in the cavity when the point is inside its circumsphere by
//!   [`insphere_perturbed`]: points on the sphere (a cubic grid has many) are decided by a
//!   symbolic perturbation that depends on the points alone (lexicographic order), so the
//!   result is the Delaunay tetrahedralisation of a perturbed point set in general position,
//!   whatever the insertion order.
//! - An infinite tetrahedron (a hull face and the infinite vertex) is in the cavity when the
//!   point is strictly outside its hull face by [`orient3d`]; a point in the hull face's plane
//!   is in its cavity exactly when it is in that of the finite tetrahedron across the face (the
//!   infinite vertex comes first in the perturbation order, before every point).
//! - The cavity is star-shaped from the point: a boundary face whose new tetrahedron would not
//!   be positive by [`orient3d`] has the tetrahedron across it added to the cavity
//!   ([`Delaunay::cavity_repairs`] counts them; the perturbation leaves none to repair). A
//!   face between two strict verdicts (no tie broken) needs no test: the point is then
//!   strictly on the cavity's side of it. So every finite tetrahedron is positive:
//!   `orient3d(a, b, c, d)` is `Positive`, the convention of [`crate::fill::CoreTets`] and
//!   [`TetMesh`].
//! - A point equal to a vertex is not inserted ([`Delaunay::duplicates`],
//!   [`InsertError::Duplicate`]). The first tetrahedron is the first four points in insertion
//!   order that are not coplanar (exact tests); all points coplanar is an error.
//!
//! Bulk insertion ([`Delaunay::new`]) takes the points in a biased randomised insertion order
//! (module `sort`): random rounds of doubling size, each sorted along a Hilbert curve, so that each
//! walk is short and the cavities stay small; the randomness has a fixed seed, so the same
//! input gives the same tetrahedra, byte for byte. [`Delaunay::insert`] adds one point.
//!
//! The predicates are exact while none of their floating-point products overflows or
//! underflows: the insphere determinant is of degree 5 in the coordinates relative to the
//! tested point, so those must stay between about 1e-60 and 1e60 in magnitude.
//!
//! The rest of the native core mesher (boundary recovery, exterior removal, refinement to the
//! sizes) is [`crate::fill::recover`]; local re-meshing of a cavity is left.

mod insert;
mod sort;
#[cfg(test)]
mod tests;

use crate::fill::improve::TetMesh;
use crate::geometry::predicates::{collinear, orient3d, Sign};
use crate::geometry::DVec3;
use crate::surface::family::SplitMix64;

#[cfg(doc)]
use crate::geometry::predicates::insphere_perturbed;

/// The vertex at infinity: the fourth vertex of the tetrahedra on the convex hull's faces.
pub const INFINITE: u32 = u32::MAX;

/// The vertices of a free tetrahedron slot.
const FREE: u32 = u32::MAX - 1;

/// The local vertices of the face opposite each vertex, ordered so that the face's right-hand
/// normal points to that vertex: on a positive tetrahedron `orient3d(face, v_i)` is positive.
/// On an infinite tetrahedron, the hull face (opposite the infinite vertex) faces out of the
/// hull: the tetrahedron is positive with a point far beyond the face in the infinite
/// vertex's place.
pub(crate) const FACES: [[usize; 3]; 4] = [[1, 3, 2], [0, 2, 3], [0, 3, 1], [0, 1, 2]];

/// Seed of the insertion order's and the walk's random choices.
const SEED: u64 = 0x5EED_DE1A_07A7_0001;

/// A Delaunay tetrahedralisation with its infinite tetrahedra; see the module documentation.
#[derive(Clone, Debug)]
pub struct Delaunay {
    /// Every point given, inserted or not: vertex `v` is `points[v]`.
    points: Vec<DVec3>,
    /// Every tetrahedron slot.
    cells: Vec<Cell>,
    /// Free slots of `cells`.
    free: Vec<u32>,
    /// A live finite tetrahedron near the last point inserted, where the next walk starts.
    hint: u32,
    rng: SplitMix64,
    duplicates: Vec<Duplicate>,
    repairs: usize,
    scratch: insert::Scratch,
}

/// A tetrahedron slot: the vertices (positive when finite, one of them [`INFINITE`] on the
/// hull, all [`FREE`] in a free slot) and the tetrahedra across the faces opposite them.
#[derive(Clone, Copy, Debug)]
struct Cell {
    vertices: [u32; 4],
    neighbours: [u32; 4],
}

impl Cell {
    const FREE: Cell = Cell { vertices: [FREE; 4], neighbours: [FREE; 4] };
}

/// A point not inserted because it coincides with a vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Duplicate {
    /// The point's index in the input.
    pub point: u32,
    /// The vertex at the same place.
    pub of: u32,
}

#[derive(Debug, PartialEq, Eq, thiserror::Error)]
pub enum DelaunayError {
    #[error("point {0} is not finite")]
    NotFinite(usize),
    #[error("the {0} points lie in one plane: they span no tetrahedron")]
    Flat(usize),
    #[error("{0} points are too many (vertex indices are u32)")]
    TooMany(usize),
}

#[derive(Debug, PartialEq, Eq, thiserror::Error)]
pub enum InsertError {
    #[error("the point is not finite")]
    NotFinite,
    #[error("the point coincides with vertex {0}")]
    Duplicate(u32),
    #[error("no vertex index is left (vertex indices are u32)")]
    TooMany,
}

impl Delaunay {
    /// The Delaunay tetrahedralisation of `points`, inserted in the order of module `sort`. Vertex
    /// `v` is `points[v]`; points equal to an earlier inserted one are left out
    /// ([`Delaunay::duplicates`]).
    pub fn new(points: &[DVec3]) -> Result<Delaunay, DelaunayError> {
        if points.len() >= FREE as usize {
            return Err(DelaunayError::TooMany(points.len()));
        }
        if let Some(i) = points.iter().position(|p| !p.is_finite()) {
            return Err(DelaunayError::NotFinite(i));
        }
        // Inserted as vertices numbered in insertion order, so that the points of neighbouring
        // tetrahedra are near in memory too; renumbered as the input at the end.
        let order = sort::insertion_order(points);
        let in_order: Vec<DVec3> = order.iter().map(|&v| points[v as usize]).collect();
        let first = first_tetrahedron(&in_order).ok_or(DelaunayError::Flat(points.len()))?;
        let mut delaunay = Delaunay::around(in_order, first);
        for v in (0..points.len() as u32).filter(|v| !first.contains(v)) {
            let p = delaunay.points[v as usize];
            let start = delaunay.locate(p);
            match delaunay.vertex_at(start, p) {
                Some(of) => delaunay.duplicates.push(Duplicate { point: v, of }),
                None => delaunay.insert_vertex(v, start),
            }
        }
        delaunay.renumber(&order, points);
        Ok(delaunay)
    }

    /// Vertex `v` becomes `input[v]`, and the points `points` (in input order).
    fn renumber(&mut self, input: &[u32], points: &[DVec3]) {
        let number = |v: u32| if v < FREE { input[v as usize] } else { v };
        for cell in &mut self.cells {
            cell.vertices = cell.vertices.map(number);
        }
        for duplicate in &mut self.duplicates {
            *duplicate = Duplicate { point: number(duplicate.point), of: number(duplicate.of) };
        }
        self.points = points.to_vec();
    }

    /// Insert `p` and return its vertex index (the next point index).
    pub fn insert(&mut self, p: DVec3) -> Result<u32, InsertError> {
        if !p.is_finite() {
            return Err(InsertError::NotFinite);
        }
        if self.points.len() >= FREE as usize {
            return Err(InsertError::TooMany);
        }
        let start = self.locate(p);
        if let Some(of) = self.vertex_at(start, p) {
            return Err(InsertError::Duplicate(of));
        }
        let v = self.points.len() as u32;
        self.points.push(p);
        self.insert_vertex(v, start);
        Ok(v)
    }

    /// The tetrahedralisation of the tetrahedron `first` (positive) and its four hull faces.
    fn around(points: Vec<DVec3>, first: [u32; 4]) -> Delaunay {
        let mut vertices = vec![first];
        for face in FACES {
            let [a, b, c] = face.map(|i| first[i]);
            // Reversed: facing out of the hull.
            vertices.push([a, c, b, INFINITE]);
        }
        let neighbours = link_faces(&vertices);
        let cells =
            vertices.into_iter().zip(neighbours).map(|(vertices, neighbours)| Cell { vertices, neighbours });
        Delaunay {
            points,
            cells: cells.collect(),
            free: Vec::new(),
            hint: 0,
            rng: SplitMix64::new(SEED),
            duplicates: Vec::new(),
            repairs: 0,
            scratch: insert::Scratch::default(),
        }
    }

    /// Every point given, inserted or not (vertex `v` is `points()[v]`).
    pub fn points(&self) -> &[DVec3] {
        &self.points
    }

    /// The finite tetrahedra, positive by [`orient3d`].
    pub fn tets(&self) -> impl Iterator<Item = [u32; 4]> + '_ {
        self.cells.iter().map(|c| c.vertices).filter(|c| c[0] != FREE && !c.contains(&INFINITE))
    }

    /// The convex hull's triangles, their right-hand normals pointing out of the hull.
    pub fn hull_triangles(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        self.cells.iter().filter_map(|cell| {
            let c = cell.vertices;
            let k = c.iter().position(|&v| v == INFINITE)?;
            Some(FACES[k].map(|i| c[i]))
        })
    }

    /// The points not inserted because they coincide with a vertex.
    pub fn duplicates(&self) -> &[Duplicate] {
        &self.duplicates
    }

    /// Tetrahedra added to a cavity to make it star-shaped from its point (see the module
    /// documentation).
    pub fn cavity_repairs(&self) -> usize {
        self.repairs
    }

    /// Tetrahedron slots, live (finite or infinite) and free: the bound of a tetrahedron index.
    pub fn cell_slots(&self) -> usize {
        self.cells.len()
    }

    /// The vertices of tetrahedron `t` (one may be [`INFINITE`]); `None` for a free slot.
    pub fn cell(&self, t: u32) -> Option<[u32; 4]> {
        let cell = self.cells[t as usize].vertices;
        (cell[0] != FREE).then_some(cell)
    }

    /// The tetrahedra across the faces opposite each vertex of tetrahedron `t` (meaningless
    /// for a free slot).
    pub fn neighbours(&self, t: u32) -> [u32; 4] {
        self.cells[t as usize].neighbours
    }

    /// The finite tetrahedra as a [`TetMesh`] for the improvement operators, whose points
    /// below `fixed` never move. Duplicates stay as points no tetrahedron uses.
    pub fn to_tet_mesh(&self, fixed: usize) -> TetMesh {
        TetMesh::new(self.points.clone(), self.tets().collect(), fixed)
    }
}

/// The first four of `points` that span a tetrahedron, ordered positive; `None` when all lie
/// in one plane.
fn first_tetrahedron(points: &[DVec3]) -> Option<[u32; 4]> {
    let pa = *points.first()?;
    let b = points.iter().position(|&p| p != pa)?;
    let pb = points[b];
    let c = points.iter().position(|&p| !collinear(pa, pb, p))?;
    let pc = points[c];
    let d = points.iter().position(|&p| orient3d(pa, pb, pc, p) != Sign::Zero)?;
    let [b, c, d] = [b, c, d].map(|i| i as u32);
    match orient3d(pa, pb, pc, points[d as usize]) {
        Sign::Positive => Some([0, b, c, d]),
        _ => Some([b, 0, c, d]),
    }
}

/// The neighbours of a few tetrahedra that close up (every face shared by two), by search.
fn link_faces(cells: &[[u32; 4]]) -> Vec<[u32; 4]> {
    let face = |c: [u32; 4], i: usize| {
        let mut f = FACES[i].map(|j| c[j]);
        f.sort_unstable();
        f
    };
    let across = |t: usize, i: usize| {
        let shared = |s: &usize| *s != t && (0..4).any(|j| face(cells[*s], j) == face(cells[t], i));
        (0..cells.len()).find(shared).map_or(FREE, |s| s as u32)
    };
    (0..cells.len()).map(|t| [0, 1, 2, 3].map(|i| across(t, i))).collect()
}
