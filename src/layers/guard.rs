//! The new front must not cross itself: each cell of a slab can be valid while two parts of the
//! front pass through each other (fronts meeting at a concave ridge, across a thin gap, or a fan
//! sweeping over its neighbours). The proposed front is tested with the same exact triangle
//! tests as the input surface; faces sharing a vertex are left to the cells' validity test,
//! which sees any fold between neighbours.

use glam::DVec3;

use super::front::{Columns, Front};
use super::march::SlabPlan;
use super::slab::Polygon;
use crate::mesh::{CellKind, VolumeMesh};
use crate::quality::measures::quad_centre;
use crate::quality::validity::cell_validity;
use crate::surface::validate::intersecting_pairs_with;
use crate::surface::Surface;

/// The faces of the proposed front that cross another face of it, its quads taken with the
/// pyramid the core fill will cap them with; and the quads that no pyramid can cap.
/// Only `suspects` are tested against the rest: the faces whose top moved since the last test.
pub(super) fn crossing_faces(
    plan: &SlabPlan,
    mesh: &VolumeMesh,
    columns: &Columns,
    front: &Front,
    suspects: &[usize],
) -> Vec<usize> {
    let committed = mesh.points.len() as u32;
    let mut points = mesh.points.clone();
    points.extend_from_slice(&plan.proposed);
    // Top polygon of every front face, triangulated; `owner[t]` is its face.
    let mut triangles = Vec::with_capacity(front.len() * 2);
    let mut owner = Vec::with_capacity(front.len() * 2);
    let mut uncappable = Vec::new();
    let mut suspect = vec![false; front.len()];
    for &f in suspects {
        suspect[f] = true;
    }
    for f in 0..front.len() {
        let top: Vec<u32> = front
            .face_columns(f)
            .iter()
            .map(|&c| {
                let r = plan.merges.root(c);
                if plan.moving[r as usize] {
                    committed + r
                } else {
                    columns.node[c as usize]
                }
            })
            .collect();
        let Some(polygon) = Polygon::dedup(&top) else { continue };
        let n = polygon.nodes();
        if n.len() == 3 {
            triangles.push([n[0], n[1], n[2]]);
            owner.push(f);
            continue;
        }
        // A quad is seen as the core fill will see it: capped by a pyramid.
        let Some(apex) = pyramid_apex([0, 1, 2, 3].map(|i| points[n[i] as usize])) else {
            if suspect[f] {
                uncappable.push(f);
            }
            continue;
        };
        let a = points.len() as u32;
        points.push(apex);
        for k in 0..4 {
            triangles.push([n[k], n[(k + 1) % 4], a]);
            owner.push(f);
        }
    }
    let count = triangles.len();
    let surface =
        Surface { points, triangles, triangle_patch: vec![0; count], patch_names: vec!["front".into()] };
    let moved: Vec<u32> = (0..count as u32).filter(|&t| suspect[owner[t as usize]]).collect();
    let mut faces: Vec<usize> = intersecting_pairs_with(&surface, &moved, true)
        .into_iter()
        .flat_map(|(a, b)| [owner[a as usize], owner[b as usize]])
        .collect();
    faces.extend(uncappable);
    faces.sort_unstable();
    faces.dedup();
    faces
}

/// Apex heights tried for a pyramid on a front quad: half its shortest edge, then halved.
const APEX_TRIES: i32 = 6;

/// The apex of a valid pyramid on the quad `x` (its right-hand normal pointing to the apex):
/// above the quad's centre at half its shortest edge (fan-strip quads are long and narrow: a
/// taller apex would poke through the front nearby), or lower where that is invalid.
pub fn pyramid_apex(x: [DVec3; 4]) -> Option<DVec3> {
    let centre = quad_centre(x[0], x[1], x[2], x[3]);
    let normal = (x[2] - x[0]).cross(x[3] - x[1]).normalize_or_zero();
    let min_edge = (0..4).map(|i| x[i].distance(x[(i + 1) % 4])).fold(f64::INFINITY, f64::min);
    (0..APEX_TRIES).map(|k| centre + normal * (0.5 * min_edge * 0.5f64.powi(k))).find(|&apex| {
        let mut p = [DVec3::ZERO; 8];
        p[..4].copy_from_slice(&x);
        p[4] = apex;
        cell_validity(CellKind::Pyramid, &p).is_valid()
    })
}
