//! Exterior removal: the tetrahedra on the region's side of the boundary triangles, and those
//! reached from them across faces that are not boundary triangles, are the region's; the
//! others (behind a triangle, in the holes, beyond the outer shell) go.

use std::collections::HashMap;

use super::recovery::inward_faces;
use crate::fill::improve::{TetMesh, NO_TET};
use crate::fill::sorted_triangle;
use crate::fill::FillError;
use crate::geometry::predicates::{orient3d, Sign};

/// Whether each tetrahedron slot of `mesh` is in the region bounded by `triangles` (normals
/// into the region), which are all faces; an error when a tetrahedron is reached from both
/// sides (the boundary is not closed).
pub(super) fn region_tets(mesh: &TetMesh, triangles: &[[u32; 3]]) -> Result<Vec<bool>, FillError> {
    let index: HashMap<[u32; 3], usize> =
        triangles.iter().enumerate().map(|(i, &t)| (sorted_triangle(t), i)).collect();
    let mut inside: Vec<Option<bool>> = vec![None; mesh.slots()];
    let mut stack: Vec<(u32, bool)> = Vec::new();
    for t in (0..mesh.slots() as u32).filter(|&t| mesh.is_alive(t)) {
        let tet = mesh.tet(t);
        for (i, face) in inward_faces(tet).iter().enumerate() {
            let Some(&k) = index.get(&sorted_triangle(*face)) else { continue };
            let [a, b, c] = triangles[k].map(|v| mesh.points[v as usize]);
            let on_region_side = orient3d(a, b, c, mesh.points[tet[i] as usize]) == Sign::Positive;
            stack.push((t, on_region_side));
        }
        if mesh.adjacent(t).contains(&NO_TET) {
            stack.push((t, false));
        }
    }
    while let Some((t, side)) = stack.pop() {
        match inside[t as usize] {
            Some(s) if s == side => continue,
            Some(_) => {
                let centre =
                    mesh.tet(t).map(|v| mesh.points[v as usize]).iter().sum::<crate::geometry::DVec3>() / 4.0;
                return Err(FillError::Recovery(format!(
                    "the tetrahedron at {:?} is both inside and outside the region: the boundary is not closed",
                    centre.to_array()
                )));
            }
            None => inside[t as usize] = Some(side),
        }
        let tet = mesh.tet(t);
        for (i, face) in inward_faces(tet).iter().enumerate() {
            let n = mesh.adjacent(t)[i];
            if n != NO_TET && !index.contains_key(&sorted_triangle(*face)) {
                stack.push((n, side));
            }
        }
    }
    Ok(inside.into_iter().map(|s| s == Some(true)).collect())
}
