//! The tetrahedra under recovery, the boundary they must come to keep, and what a change to
//! them does to a missing edge or triangle.

use std::collections::{HashMap, HashSet, VecDeque};

use super::cross::Target;
use crate::fill::delaunay::FACES;
use crate::fill::improve::{Change, TetMesh, NO_TET, TET_EDGES};
use crate::fill::sorted_triangle;
use crate::mesh::sorted_edge;

/// The tetrahedralisation being changed, with the boundary's edges and triangles (sorted
/// nodes): those that are present never go (the operators check it).
pub(super) struct Recovery {
    pub mesh: TetMesh,
    pub edges: HashSet<[u32; 2]>,
    pub triangles: HashSet<[u32; 3]>,
}

/// The sorted edges of a tetrahedron.
pub(super) fn tet_edges(tet: [u32; 4]) -> [[u32; 2]; 6] {
    TET_EDGES.map(|(i, j)| sorted_edge(tet[i], tet[j]))
}

/// The faces of a tetrahedron, their right-hand normals pointing into it, by opposite node.
pub(super) fn inward_faces(tet: [u32; 4]) -> [[u32; 3]; 4] {
    FACES.map(|f| f.map(|i| tet[i]))
}

/// The faces of the cavity made of the tetrahedra `cavity` (`inside` tells its members), their
/// normals pointing into it: each with the cavity's tetrahedron on it and the one across
/// ([`NO_TET`] on the boundary), in the order of `cavity` and of each tetrahedron's nodes.
pub(super) fn cavity_faces(
    mesh: &TetMesh,
    cavity: impl IntoIterator<Item = u32>,
    inside: impl Fn(u32) -> bool,
) -> Vec<([u32; 3], u32, u32)> {
    let mut faces = Vec::new();
    for t in cavity {
        let inward = inward_faces(mesh.tet(t));
        for (i, n) in mesh.adjacent(t).into_iter().enumerate() {
            if !inside(n) {
                faces.push((inward[i], t, n));
            }
        }
    }
    faces
}

/// The sorted faces of a tetrahedron.
fn tet_faces(tet: [u32; 4]) -> [[u32; 3]; 4] {
    inward_faces(tet).map(sorted_triangle)
}

/// The edges and faces of some tetrahedra, each once, sorted.
#[derive(Default)]
struct Elements {
    edges: Vec<[u32; 2]>,
    faces: Vec<[u32; 3]>,
}

impl Elements {
    fn of(tets: impl IntoIterator<Item = [u32; 4]>) -> Elements {
        let mut elements = Elements::default();
        for tet in tets {
            elements.edges.extend(tet_edges(tet));
            elements.faces.extend(tet_faces(tet));
        }
        elements.edges.sort_unstable();
        elements.edges.dedup();
        elements.faces.sort_unstable();
        elements.faces.dedup();
        elements
    }

    fn has_edge(&self, e: &[u32; 2]) -> bool {
        self.edges.binary_search(e).is_ok()
    }

    fn has_face(&self, f: &[u32; 3]) -> bool {
        self.faces.binary_search(f).is_ok()
    }
}

impl Recovery {
    pub(super) fn new(mesh: TetMesh, triangles: &[[u32; 3]]) -> Recovery {
        let edges =
            triangles.iter().flat_map(|t| (0..3).map(|i| sorted_edge(t[i], t[(i + 1) % 3]))).collect();
        Recovery { mesh, edges, triangles: triangles.iter().map(|&t| sorted_triangle(t)).collect() }
    }

    /// Whether the target is an edge or a face of the tetrahedra.
    pub(super) fn present(&self, target: Target) -> bool {
        !self.mesh.tets_with(target.vertices()).is_empty()
    }

    /// How many elements (edges, faces) of `tets` cross the target.
    fn crossings<'a>(&self, target: Target, elements: impl Iterator<Item = Element<'a>>) -> i64 {
        let points = &self.mesh.points;
        elements
            .filter(|e| match e {
                Element::Edge(edge) => target.crossed_by_edge(points, **edge),
                Element::Face(face) => target.crossed_by_face(points, **face),
            })
            .count() as i64
    }

    /// How many more elements cross the target after tetrahedra `remove` are replaced by `add`.
    pub(super) fn crossing_change(&self, target: Target, remove: &[u32], add: &[[u32; 4]]) -> i64 {
        let old = Elements::of(remove.iter().map(|&t| self.mesh.tet(t)));
        let new = Elements::of(add.iter().copied());
        self.crossings(target, only(&new, &old)) - self.crossings(target, only(&old, &new))
    }

    /// Whether replacing tetrahedra `remove` by `add` keeps every boundary edge and triangle
    /// and every point they have (a point inside the cavity would be lost).
    pub(super) fn keeps_boundary(&self, remove: &[u32], add: &[[u32; 4]]) -> bool {
        let old = Elements::of(remove.iter().map(|&t| self.mesh.tet(t)));
        let new = Elements::of(add.iter().copied());
        let points: HashSet<u32> = add.iter().flatten().copied().collect();
        old.edges.iter().all(|e| !self.edges.contains(e) || new.has_edge(e))
            && old.faces.iter().all(|f| !self.triangles.contains(f) || new.has_face(f))
            && remove.iter().flat_map(|&t| self.mesh.tet(t)).all(|v| points.contains(&v))
    }

    /// The tetrahedra with an element crossing the target: grown from those at its vertices
    /// across the faces that cross it or have an edge that does.
    pub(super) fn crossing_tets(&self, target: Target) -> Vec<u32> {
        let points = &self.mesh.points;
        let mut seen: HashMap<u32, bool> = HashMap::new();
        let mut queue: VecDeque<u32> = VecDeque::new();
        let mut crossing = Vec::new();
        queue.extend(target.vertices().iter().flat_map(|&v| self.mesh.ball(v).iter().copied()));
        while let Some(t) = queue.pop_front() {
            if seen.contains_key(&t) {
                continue;
            }
            let tet = self.mesh.tet(t);
            let crossed_edges: Vec<[u32; 2]> =
                tet_edges(tet).into_iter().filter(|&e| target.crossed_by_edge(points, e)).collect();
            let faces = inward_faces(tet);
            let mut crosses = !crossed_edges.is_empty();
            for (i, face) in faces.iter().enumerate() {
                let through = target.crossed_by_face(points, *face)
                    || crossed_edges.iter().any(|e| face.contains(&e[0]) && face.contains(&e[1]));
                crosses |= through;
                let n = self.mesh.adjacent(t)[i];
                if through && n != NO_TET && !seen.contains_key(&n) {
                    queue.push_back(n);
                }
            }
            seen.insert(t, crosses);
            if crosses {
                crossing.push(t);
            }
        }
        crossing
    }

    /// Replace tetrahedra `remove` by `add` (with a new point, if any).
    pub(super) fn replace(
        &mut self,
        remove: Vec<u32>,
        add: Vec<[u32; 4]>,
        point: Option<crate::geometry::DVec3>,
    ) {
        let point = point.map(|p| (self.mesh.points.len() as u32, p));
        self.mesh.apply(&Change::replacing(remove, add, point));
    }
}

/// The elements of `x` not in `y`.
fn only<'a>(x: &'a Elements, y: &'a Elements) -> impl Iterator<Item = Element<'a>> {
    let edges = x.edges.iter().filter(|e| !y.has_edge(e)).map(Element::Edge);
    let faces = x.faces.iter().filter(|f| !y.has_face(f)).map(Element::Face);
    edges.chain(faces)
}

/// An edge or a face, sorted.
enum Element<'a> {
    Edge(&'a [u32; 2]),
    Face(&'a [u32; 3]),
}
