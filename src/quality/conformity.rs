//! Conformity: every face of every cell, and every boundary face, sorted by its vertex set.
//!
//! An interior face is used by exactly two cells in opposite orientations. A face of one cell
//! (a free face) must be a listed boundary face with the same orientation (out of the domain);
//! when the mesh lists no boundary faces at all, the free faces are taken as its boundary. The
//! volume enclosed by the free faces is summed here too, for the volume identity.

use super::measures::face_triangles;
use super::report::{BoundaryRef, CellRef, Conformity, FaceIssue, FaceProblem};
use crate::geometry::{Aabb, DVec3};
use crate::mesh::faces::{sorted, CellNumbering, FaceUse, FaceUses};
use crate::mesh::{CellKind, VolumeMesh};

/// How two uses of the same vertex set are oriented relative to each other.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Relation {
    Same,
    Opposite,
    /// Same vertices in another cyclic order (quads only, or faces with repeated vertices).
    Twisted,
}

/// The lexicographically smallest rotation of a face: equal for the same oriented cycle.
fn canonical<const N: usize>(face: [u32; N]) -> [u32; N] {
    (0..N)
        .map(|r| {
            let mut f = face;
            f.rotate_left(r);
            f
        })
        .min()
        .unwrap_or(face)
}

fn reversed<const N: usize>(face: [u32; N]) -> [u32; N] {
    let mut f = face;
    f.reverse();
    f
}

fn relation<const N: usize>(a: [u32; N], b: [u32; N]) -> Relation {
    let a = canonical(a);
    if a == canonical(b) {
        Relation::Same
    } else if a == canonical(reversed(b)) {
        Relation::Opposite
    } else {
        Relation::Twisted
    }
}

/// The mesh seen as face owners.
struct Owners<'a, const N: usize> {
    mesh: &'a VolumeMesh,
    numbering: CellNumbering,
    boundary: &'a [[u32; N]],
    /// Every use of an N-vertex face, sorted.
    uses: &'a [FaceUse<N>],
}

impl<'a, const N: usize> Owners<'a, N> {
    fn cell_count(&self) -> usize {
        self.numbering.cell_count()
    }

    fn is_cell(&self, owner: u32) -> bool {
        (owner as usize) < self.cell_count()
    }

    fn cell(&self, owner: u32) -> CellRef {
        let (kind, index) = self.numbering.locate(owner as usize);
        CellRef { kind, index }
    }

    fn boundary_index(&self, owner: u32) -> usize {
        owner as usize - self.cell_count()
    }

    /// The face's vertices in the orientation its owner gives it.
    fn oriented(&self, u: &FaceUse<N>) -> [u32; N] {
        if !self.is_cell(u.owner) {
            return self.boundary[self.boundary_index(u.owner)];
        }
        let nodes = self.numbering.nodes(self.mesh, u.owner as usize);
        let local = self.cell(u.owner).kind.faces()[u.local as usize];
        std::array::from_fn(|i| nodes[local[i]])
    }

    fn issue(&self, problem: FaceProblem, group: &[FaceUse<N>]) -> FaceIssue {
        let nodes = group.first().map(|u| self.oriented(u).to_vec()).unwrap_or_default();
        let pts: Option<Vec<DVec3>> =
            nodes.iter().map(|&n| self.mesh.points.get(n as usize).copied()).collect();
        let centre = pts.map(|p| (p.iter().sum::<DVec3>() / p.len().max(1) as f64).to_array());
        let (cells, bounds): (Vec<&FaceUse<N>>, Vec<_>) = group.iter().partition(|u| self.is_cell(u.owner));
        FaceIssue {
            problem,
            nodes,
            centre,
            cells: cells.iter().map(|u| self.cell(u.owner)).collect(),
            boundary_faces: bounds
                .iter()
                .map(|u| BoundaryRef { quad: N == 4, index: self.boundary_index(u.owner) })
                .collect(),
        }
    }
}

/// A free face of a cell not matched by a boundary face (yet).
#[derive(Clone, Copy, Debug)]
struct Unmatched<const N: usize> {
    face: FaceUse<N>,
    consumed: bool,
}

/// What the scan over the uses of one face size found.
struct Scan<const N: usize> {
    unmatched: Vec<Unmatched<N>>,
    /// Every free face (matched or not), for the quad-split test.
    free: Vec<FaceUse<N>>,
    enclosed: f64,
}

/// Classify every group of uses of the same vertex set.
fn scan<const N: usize>(owners: &Owners<N>, origin: DVec3, report: &mut Conformity) -> Scan<N> {
    let uses = owners.uses;
    let mut out = Scan { unmatched: Vec::new(), free: Vec::new(), enclosed: 0.0 };
    for group in uses.chunk_by(|a, b| a.key == b.key) {
        let split = group.partition_point(|u| owners.is_cell(u.owner));
        let (cells, bounds) = group.split_at(split);
        match cells {
            [] => report.record(owners.issue(FaceProblem::BoundaryFaceNotCovered, group)),
            [cell] => {
                out.free.push(*cell);
                out.enclosed += enclosed_part(&owners.mesh.points, &owners.oriented(cell), origin);
                match bounds {
                    [] => out.unmatched.push(Unmatched { face: *cell, consumed: false }),
                    [b, rest @ ..] => {
                        if !rest.is_empty() {
                            report.record(owners.issue(FaceProblem::DuplicateBoundaryFace, group));
                        }
                        let problem = match relation(owners.oriented(cell), owners.oriented(b)) {
                            Relation::Same => None,
                            Relation::Opposite => Some(FaceProblem::InvertedBoundaryFace),
                            Relation::Twisted => Some(FaceProblem::TwistedQuad),
                        };
                        if let Some(p) = problem {
                            report.record(owners.issue(p, group));
                        }
                    }
                }
            }
            [a, b] => {
                match relation(owners.oriented(a), owners.oriented(b)) {
                    Relation::Opposite => report.interior_faces += 1,
                    Relation::Same => report.record(owners.issue(FaceProblem::DoubledFace, group)),
                    Relation::Twisted => report.record(owners.issue(FaceProblem::TwistedQuad, group)),
                }
                if !bounds.is_empty() {
                    report.record(owners.issue(FaceProblem::BoundaryFaceNotCovered, group));
                }
            }
            _ => report.record(owners.issue(FaceProblem::NonManifoldFace, group)),
        }
    }
    out
}

/// Contribution of an outward face to the enclosed volume (divergence theorem about `origin`).
fn enclosed_part(points: &[DVec3], face: &[u32], origin: DVec3) -> f64 {
    let pts: Option<Vec<DVec3>> = face.iter().map(|&n| points.get(n as usize).map(|p| *p - origin)).collect();
    let mut v = 0.0;
    if let Some(pts) = pts {
        face_triangles(&pts, |[a, b, c]| v += a.dot(b.cross(c)) / 6.0);
    }
    v
}

/// Free quads whose two halves (along either diagonal) are unmatched free triangles: both
/// the quad and the triangles are then reported as a non-matching quad split, not as holes.
fn find_quad_splits(
    quads: &Owners<4>,
    quad_scan: &mut Scan<4>,
    tris: &Owners<3>,
    tri_scan: &mut Scan<3>,
    report: &mut Conformity,
) {
    let unmatched = &mut tri_scan.unmatched;
    for quad in &quad_scan.free {
        let [a, b, c, d] = quads.oriented(quad);
        for halves in [[[a, b, c], [a, c, d]], [[b, c, d], [b, d, a]]] {
            let found: Vec<usize> = halves
                .iter()
                .filter_map(|h| unmatched.binary_search_by(|u| u.face.key.cmp(&sorted(*h))).ok())
                .filter(|&i| !unmatched[i].consumed)
                .collect();
            if found.len() == 2 {
                let mut issue = quads.issue(FaceProblem::NonMatchingQuadSplit, std::slice::from_ref(quad));
                for &i in &found {
                    unmatched[i].consumed = true;
                    issue.cells.push(tris.cell(unmatched[i].face.owner));
                }
                report.record(issue);
                let unmatched_quads = &mut quad_scan.unmatched;
                if let Ok(i) = unmatched_quads.binary_search_by(|u| u.face.key.cmp(&quad.key)) {
                    unmatched_quads[i].consumed = true;
                }
                break;
            }
        }
    }
}

/// Face owners are `u32`: cells and boundary faces of one size must number less than 2^32.
pub fn owner_ids_fit(mesh: &VolumeMesh) -> bool {
    let cells: usize = CellKind::ALL.iter().map(|&k| mesh.block(k).nodes.len() / k.node_count()).sum();
    let faces = mesh.boundary.triangles.len().max(mesh.boundary.quads.len());
    cells.checked_add(faces).is_some_and(|total| total < u32::MAX as usize)
}

/// Conformity of the mesh's faces and the volume enclosed by its free faces.
pub(crate) fn check_faces(mesh: &VolumeMesh, uses: &FaceUses) -> (Conformity, f64) {
    let mut report = Conformity::default();
    let b = &mesh.boundary;
    let numbering = uses.numbering;
    let tris = Owners { mesh, numbering, boundary: &b.triangles, uses: &uses.triangles };
    let quads = Owners { mesh, numbering, boundary: &b.quads, uses: &uses.quads };
    let origin = Aabb::from_points(&mesh.points).center();
    let mut tri_scan = scan(&tris, origin, &mut report);
    let mut quad_scan = scan(&quads, origin, &mut report);
    report.free_triangles = tri_scan.free.len();
    report.free_quads = quad_scan.free.len();
    find_quad_splits(&quads, &mut quad_scan, &tris, &mut tri_scan, &mut report);
    let has_boundary = !b.triangles.is_empty() || !b.quads.is_empty();
    report.free_faces_taken_as_boundary = !has_boundary;
    if has_boundary {
        report_holes(&tris, &tri_scan.unmatched, &mut report);
        report_holes(&quads, &quad_scan.unmatched, &mut report);
    }
    (report, tri_scan.enclosed + quad_scan.enclosed)
}

fn report_holes<const N: usize>(owners: &Owners<N>, unmatched: &[Unmatched<N>], report: &mut Conformity) {
    for u in unmatched.iter().filter(|u| !u.consumed) {
        report.record(owners.issue(FaceProblem::Hole, std::slice::from_ref(&u.face)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relations_of_triangles_and_quads() {
        assert_eq!(relation([1, 2, 3], [2, 3, 1]), Relation::Same);
        assert_eq!(relation([1, 2, 3], [3, 2, 1]), Relation::Opposite);
        assert_eq!(relation([1, 2, 3, 4], [4, 3, 2, 1]), Relation::Opposite);
        assert_eq!(relation([1, 2, 3, 4], [3, 4, 1, 2]), Relation::Same);
        assert_eq!(relation([1, 2, 3, 4], [1, 3, 2, 4]), Relation::Twisted);
        // Repeated vertices (collapsed faces) still compare by cycle.
        assert_eq!(relation([1, 2, 1, 3], [1, 3, 1, 2]), Relation::Same);
    }
}
