//! Bending a column to mend an invalid cell, the repair before stopping columns.
//!
//! Where the front is crumpled (spot's valleys, the arrow's fin roots just ahead of their
//! trailing edges and at their leading edges), the directions of neighbouring columns can differ
//! by more than their cells stand: a column's cell turns inside out although no edge is crushed
//! and no bisector is passed. Stopping its columns leaves a cliff in the front, and the core
//! fills a cliff with slivers. Turning the column part of the way to the mean direction of its
//! neighbours (a step of Laplacian smoothing of the direction field, as advancing-layer methods
//! smooth their normals) often mends the cell; the column keeps its step length and marches on
//! in its new direction. (It does not mend the ONERA M6 wing-tip cap, faceted 5 times finer
//! than its first layer: the cells that fail there are fan cells.)

use super::entropy::neighbour_roots;
use super::front::{Columns, Front};
use super::march::SlabPlan;
use crate::geometry::DVec3;

/// How far a column turns to its neighbours' mean direction, tried in order (the least bend
/// that mends first).
const BENDS: [f64; 3] = [0.25, 0.5, 1.0];

/// Bend one moving root of invalid face `f` (see the module doc) so that `f`'s cell is valid
/// and fewer cells around the root are invalid; returns the root. Fan columns are left alone:
/// their directions are set by their fan, and bending one would flatten the fan's strip cells.
pub(super) fn bend_to_mend(
    plan: &mut SlabPlan,
    front: &Front,
    f: usize,
    columns: &Columns,
    points: &[DVec3],
    face_valid: &impl Fn(&SlabPlan) -> bool,
    invalid_cells: &impl Fn(&SlabPlan, &[u32]) -> usize,
) -> Option<u32> {
    for r in plan.merges.face_roots(front, f) {
        if !plan.moving[r as usize] || in_a_fan(front, columns, r) {
            continue;
        }
        let Some(mean) = neighbour_direction(plan, front, columns, r) else { continue };
        let group: Vec<u32> = plan.merges.group(r).collect();
        let before = invalid_cells(plan, &group);
        let (saved, redirected) = (plan.proposed[r as usize], plan.redirected.len());
        let c = r as usize;
        let node = points[columns.node[c] as usize];
        let step = saved.distance(node);
        for w in BENDS {
            let dir = columns.dir[c].lerp(mean, w).normalize_or_zero();
            if dir == DVec3::ZERO {
                continue;
            }
            plan.proposed[c] = columns.slide[c].project(node + dir * step);
            if face_valid(plan) && invalid_cells(plan, &group) < before {
                plan.redirected.push((r, dir, columns.scale[c]));
                plan.bends += 1;
                tracing::debug!(f, r, w, at = ?columns.base[c], "invalid cell mended by bending a column");
                return Some(r);
            }
        }
        plan.proposed[c] = saved;
        plan.redirected.truncate(redirected);
    }
    None
}

/// Whether column `c` is joined to another by a fan edge.
fn in_a_fan(front: &Front, columns: &Columns, c: u32) -> bool {
    let mut mates = Vec::new();
    front.fan_mates(columns, c as usize, &mut mates);
    !mates.is_empty()
}

/// The mean direction of the roots next to root `r`'s group across front edges, `None` when
/// there is none.
fn neighbour_direction(plan: &SlabPlan, front: &Front, columns: &Columns, r: u32) -> Option<DVec3> {
    let sum: DVec3 = neighbour_roots(plan, front, r).iter().map(|&m| columns.dir[m as usize]).sum();
    let mean = sum.normalize_or_zero();
    (mean != DVec3::ZERO).then_some(mean)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Column 0 at the centre of a hexagon of columns 1-6 on the plane z = 0, in triangles
    /// (0, i, i + 1); the ring rises 0.5 up +z, column 0 leans along +x past the ring's column 1.
    fn leaning_centre() -> (Columns, Front, Vec<DVec3>, SlabPlan) {
        let ring = (0..6).map(|i| {
            let a = i as f64 * std::f64::consts::FRAC_PI_3;
            DVec3::new(a.cos(), a.sin(), 0.0)
        });
        let bottoms: Vec<DVec3> = std::iter::once(DVec3::ZERO).chain(ring).collect();
        let mut columns = Columns::rising(&bottoms, None);
        columns.dir[0] = DVec3::new(0.9, 0.0, 0.44).normalize();
        let mut front = Front::default();
        for i in 1..=6u32 {
            front.push(&[0, i, i % 6 + 1], 0, None);
        }
        front.index_columns(bottoms.len());
        let mut proposed: Vec<DVec3> = bottoms.iter().map(|&b| b + 0.5 * DVec3::Z).collect();
        proposed[0] = 1.2 * columns.dir[0];
        (columns, front, bottoms, SlabPlan::moving_to(proposed))
    }

    /// Stand-in for the cell test: a face's cell is valid while its top triangle faces up.
    fn top_faces_up(plan: &SlabPlan, front: &Front, f: usize) -> bool {
        let [a, b, c] = [0, 1, 2].map(|i| plan.proposed[front.face_columns(f)[i] as usize]);
        (b - a).cross(c - a).z > 0.0
    }

    #[test]
    fn a_column_leaning_over_its_neighbours_is_bent_back_until_its_cells_stand() {
        let (columns, front, bottoms, mut plan) = leaning_centre();
        let invalid = |plan: &SlabPlan, group: &[u32]| {
            let faces = front.faces_around_columns(group);
            faces.into_iter().filter(|&f| !top_faces_up(plan, &front, f)).count()
        };
        assert_eq!(invalid(&plan, &[0]), 2, "the lean turns two tops over");
        let face_valid = |plan: &SlabPlan| top_faces_up(plan, &front, 0);
        let bent = bend_to_mend(&mut plan, &front, 0, &columns, &bottoms, &face_valid, &invalid);
        assert_eq!(bent, Some(0), "the leaning column bends, not a ring column");
        assert_eq!(invalid(&plan, &[0]), 0);
        let &[(c, dir, scale)] = &plan.redirected[..] else { panic!("one column redirected") };
        assert_eq!((c, scale), (0, 1.0));
        assert!(dir.z > columns.dir[0].z && dir.x > 0.0, "turned part of the way to +z: {dir}");
        assert!((plan.proposed[0].length() - 1.2).abs() < 1e-12, "the step keeps its length");
    }

    #[test]
    fn a_fan_column_is_not_bent() {
        let (mut columns, front, bottoms, mut plan) = leaning_centre();
        // Column 1 becomes a fan mate of column 0 (the same wall point).
        columns.base[1] = columns.base[0];
        let invalid = |plan: &SlabPlan, group: &[u32]| {
            let faces = front.faces_around_columns(group);
            faces.into_iter().filter(|&f| !top_faces_up(plan, &front, f)).count()
        };
        let face_valid = |plan: &SlabPlan| top_faces_up(plan, &front, 0);
        let before = plan.proposed.clone();
        let bent = bend_to_mend(&mut plan, &front, 0, &columns, &bottoms, &face_valid, &invalid);
        assert_ne!(bent, Some(0));
        assert_eq!(plan.proposed[0], before[0]);
    }
}
