//! Insertion of the guide's points into the region's tetrahedra by Bowyer–Watson with the
//! boundary triangles as walls: the cavity grows across interior faces only (the region's
//! tetrahedra have none across a boundary triangle), then shrinks until it is star-shaped
//! from the point (every face of it seen positively) and keeps every point.

use std::collections::{BTreeSet, HashSet};

use super::recovery::inward_faces;
use crate::fill::improve::{Change, TetMesh, NO_TET};
use crate::geometry::predicates::{insphere, orient3d, Sign};
use crate::geometry::DVec3;

/// Why a point was not inserted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Skipped {
    /// Outside the region (in no tetrahedron).
    Outside,
    /// On a boundary triangle (or a wall).
    OnBoundary,
    /// No cavity around it is star-shaped from it.
    NoStar,
    /// At a vertex.
    Duplicate,
    /// Its cavity would take more tetrahedra than allowed.
    LargeCavity,
}

/// Steps at most of a walk before the search.
const MAX_WALK: usize = 100_000;

/// The live tetrahedron whose closure holds `p`: by a visibility walk from each of `hints` in
/// turn (leaving each tetrahedron through a face `p` is strictly beyond, the faces tried from
/// one chosen by the step, so that it cannot cycle for long), else, when every walk leaves the
/// region (a hole or a concave boundary is in the way), by a search of them all.
fn locate(mesh: &TetMesh, hints: &[u32], p: DVec3) -> Option<u32> {
    let beyond = |t: u32, i: usize| {
        let f = inward_faces(mesh.tet(t))[i];
        let [a, b, c] = f.map(|v| mesh.points[v as usize]);
        orient3d(a, b, c, p) == Sign::Negative
    };
    if let Some(t) = hints.iter().find_map(|&hint| walk(mesh, hint, p)) {
        return Some(t);
    }
    (0..mesh.slots() as u32).filter(|&t| mesh.is_alive(t)).find(|&t| (0..4).all(|i| !beyond(t, i)))
}

/// The visibility walk of [`locate`] from `hint`; `None` when it leaves the region.
pub(super) fn walk(mesh: &TetMesh, hint: u32, p: DVec3) -> Option<u32> {
    let beyond = |t: u32, i: usize| {
        let f = inward_faces(mesh.tet(t))[i];
        let [a, b, c] = f.map(|v| mesh.points[v as usize]);
        orient3d(a, b, c, p) == Sign::Negative
    };
    let mut t = hint;
    // No tetrahedron is `NO_TET` (a face without one across is an exit like any other).
    let mut came_from = None;
    for step in 0..MAX_WALK.min(mesh.slots()) {
        if !mesh.is_alive(t) {
            break;
        }
        let first = ((step as u64 ^ u64::from(t)).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 62) as usize;
        let adjacent = mesh.adjacent(t);
        let exit = (0..4).map(|j| (first + j) & 3).find(|&i| Some(adjacent[i]) != came_from && beyond(t, i));
        match exit {
            None => return Some(t),
            Some(i) if adjacent[i] == NO_TET => break,
            Some(i) => {
                came_from = Some(t);
                t = adjacent[i];
            }
        }
    }
    None
}

/// Insert `p` (strictly inside the region), locating it from the tetrahedra `hints`; the new
/// point's index.
pub(super) fn insert_point(mesh: &mut TetMesh, hints: &[u32], p: DVec3) -> Result<u32, Skipped> {
    let (remove, add) = star_cavity(mesh, hints, p, &|_| false, usize::MAX)?;
    let v = mesh.points.len() as u32;
    mesh.apply(&Change::replacing(remove, add, Some((v, p))));
    Ok(v)
}

/// The tetrahedra to replace to insert `p` (located from `hints`), and the cone from the new
/// point (the next point index) replacing them; the cavity does not cross the faces without
/// a tetrahedron across nor the `wall` faces, and `p` must be strictly off them. A cavity
/// growing past `max_tets` tetrahedra is given up (its shrinking to a star costs their
/// square).
pub(super) fn star_cavity(
    mesh: &TetMesh,
    hints: &[u32],
    p: DVec3,
    wall: &dyn Fn(&[u32; 3]) -> bool,
    max_tets: usize,
) -> Result<(Vec<u32>, Vec<[u32; 4]>), Skipped> {
    let start = locate(mesh, hints, p).ok_or(Skipped::Outside)?;
    let tet = mesh.tet(start);
    if tet.iter().any(|&v| mesh.points[v as usize] == p) {
        return Err(Skipped::Duplicate);
    }
    let x = |v: u32| mesh.points[v as usize];
    // On a boundary triangle (a face with nothing across): not strictly inside.
    for (i, f) in inward_faces(tet).iter().enumerate() {
        let closed = mesh.adjacent(start)[i] == NO_TET || wall(f);
        if closed && orient3d(x(f[0]), x(f[1]), x(f[2]), p) == Sign::Zero {
            return Err(Skipped::OnBoundary);
        }
    }
    let mut cavity: BTreeSet<u32> = BTreeSet::from([start]);
    let mut stack = vec![start];
    while let Some(t) = stack.pop() {
        let faces = inward_faces(mesh.tet(t));
        for (i, n) in mesh.adjacent(t).into_iter().enumerate() {
            if n != NO_TET && !cavity.contains(&n) && !wall(&faces[i]) {
                let [a, b, c, d] = mesh.tet(n).map(x);
                if insphere(a, b, c, d, p) == Sign::Positive {
                    cavity.insert(n);
                    stack.push(n);
                }
                if cavity.len() > max_tets {
                    return Err(Skipped::LargeCavity);
                }
            }
        }
    }
    loop {
        let faces = cavity_faces(mesh, &cavity);
        // The tetrahedra with a face not seen from `p` leave, all at once (one at a time costs
        // the square of a large cavity). The first holds `p`: a face of it that `p` is on has
        // a tetrahedron holding `p` across, in the cavity, unless it is a boundary triangle.
        let seen = |f: &[u32; 3]| orient3d(x(f[0]), x(f[1]), x(f[2]), p) == Sign::Positive;
        let unseen: BTreeSet<u32> = faces.iter().filter(|(f, _)| !seen(f)).map(|&(_, t)| t).collect();
        if !unseen.is_empty() {
            if unseen.len() == 1 && unseen.contains(&start) {
                // Only on a face of the first tetrahedron: `p` is on the boundary.
                return Err(Skipped::OnBoundary);
            }
            cavity.retain(|t| *t == start || !unseen.contains(t));
            keep_connected(mesh, &mut cavity, start);
            continue;
        }
        let v = mesh.points.len() as u32;
        let add: Vec<[u32; 4]> = faces.iter().map(|(f, _)| [f[0], f[1], f[2], v]).collect();
        let kept: HashSet<u32> = add.iter().flatten().copied().collect();
        let lost: HashSet<u32> =
            cavity.iter().flat_map(|&t| mesh.tet(t)).filter(|u| !kept.contains(u)).collect();
        if !lost.is_empty() {
            // Vertices inside the cavity: the tetrahedra at them leave.
            let before = cavity.len();
            cavity.retain(|&t| t == start || !mesh.tet(t).iter().any(|u| lost.contains(u)));
            if cavity.len() == before {
                return Err(Skipped::NoStar);
            }
            keep_connected(mesh, &mut cavity, start);
            continue;
        }
        return Ok((cavity.into_iter().collect(), add));
    }
}

/// The faces of the cavity (normals into it) with the cavity's tetrahedron on each.
fn cavity_faces(mesh: &TetMesh, cavity: &BTreeSet<u32>) -> Vec<([u32; 3], u32)> {
    super::recovery::cavity_faces(mesh, cavity.iter().copied(), |n| cavity.contains(&n))
        .into_iter()
        .map(|(face, t, _)| (face, t))
        .collect()
}

/// Keep only the tetrahedra of `cavity` connected to `start` through its faces.
fn keep_connected(mesh: &TetMesh, cavity: &mut BTreeSet<u32>, start: u32) {
    let mut reached = BTreeSet::from([start]);
    let mut stack = vec![start];
    while let Some(t) = stack.pop() {
        for n in mesh.adjacent(t) {
            if cavity.contains(&n) && reached.insert(n) {
                stack.push(n);
            }
        }
    }
    *cavity = reached;
}
