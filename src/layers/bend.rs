//! Bending or tipping a column to mend an invalid cell, the repairs before stopping columns.
//!
//! Where the front is crumpled (spot's valleys, the arrow's fin roots just ahead of their
//! trailing edges and at their leading edges), the directions of neighbouring columns can differ
//! by more than their cells stand: a column's cell turns inside out although no edge is crushed
//! and no bisector is passed. Stopping its columns leaves a cliff in the front, and the core
//! fills a cliff with slivers. Turning the column part of the way to the mean direction of its
//! neighbours (a step of Laplacian smoothing of the direction field, as advancing-layer methods
//! smooth their normals) often mends the cell; the column keeps its step length and marches on
//! in its new direction. (It does not mend the ONERA M6 wing-tip cap, faceted 5 times finer
//! than its first layer: the cells that fail there are fan cells.) Where the bend does not
//! mend, a small sideways tip of one column's top, tried round its direction, often does
//! ([`nudge_to_mend`]).

use super::entropy::neighbour_roots;
use super::front::{Columns, Front};
use super::slab_plan::SlabPlan;
use super::tuning::TUNING;
use crate::geometry::DVec3;

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
        let c = r as usize;
        let node = points[columns.node[c] as usize];
        let step = plan.proposed[c].distance(node);
        for w in TUNING.repairs.bends {
            let dir = columns.dir[c].lerp(mean, w).normalize_or_zero();
            if dir == DVec3::ZERO {
                continue;
            }
            let top = columns.slide[c].project(node + dir * step);
            if let Some((top, dir)) = best_top(plan, r, [(top, dir)], face_valid, invalid_cells) {
                move_top(plan, r, top, (dir, columns.scale[c]));
                plan.bends += 1;
                tracing::debug!(f, r, w, at = ?columns.base[c], "invalid cell mended by bending a column");
                return Some(r);
            }
        }
    }
    None
}

/// Of the `candidates` for root `r`'s top (each with the direction it would march on in), the
/// one that leaves the cell tested by `face_valid` valid and the fewest cells around `r`'s
/// group invalid, fewer than now (the first of equals); `plan` is left as it was.
fn best_top(
    plan: &mut SlabPlan,
    r: u32,
    candidates: impl IntoIterator<Item = (DVec3, DVec3)>,
    face_valid: &impl Fn(&SlabPlan) -> bool,
    invalid_cells: &impl Fn(&SlabPlan, &[u32]) -> usize,
) -> Option<(DVec3, DVec3)> {
    let c = r as usize;
    let group: Vec<u32> = plan.merges.group(r).collect();
    let before = invalid_cells(plan, &group);
    let saved = plan.proposed[c];
    let mut best: Option<(usize, (DVec3, DVec3))> = None;
    for (top, dir) in candidates {
        plan.proposed[c] = top;
        if !face_valid(plan) {
            continue;
        }
        let left = invalid_cells(plan, &group);
        if left < before && best.is_none_or(|(b, _)| left < b) {
            best = Some((left, (top, dir)));
        }
    }
    plan.proposed[c] = saved;
    best.map(|(_, chosen)| chosen)
}

/// Move root `r`'s top to `top`, the column marching on along `(direction, scale)`.
fn move_top(plan: &mut SlabPlan, r: u32, top: DVec3, (dir, scale): (DVec3, f64)) {
    plan.proposed[r as usize] = top;
    plan.redirected.push((r, dir, scale));
}

/// Tip one moving root of invalid face `f` sideways (its step keeps its length; eight ways round
/// its direction, the least tip first) so that `f`'s cell is valid and fewer cells around the
/// root are invalid; returns the root. The last repair before stopping columns, for cells that
/// no merge and no bend to the neighbours' mean mends: where fronts from several walls meet in
/// a corner the mean direction of a column's neighbours (fans, bisectors) says little, but a
/// small turn of the merged column's top often unfolds the cell (the arrow's fin trailing
/// edges, where fin, trailing edge and body fronts meet). Fan columns are tipped too (the
/// cells around them are tested alike), though not everywhere ([`may_tip`]).
pub(super) fn nudge_to_mend(
    plan: &mut SlabPlan,
    front: &Front,
    f: usize,
    columns: &Columns,
    points: &[DVec3],
    face_valid: &impl Fn(&SlabPlan) -> bool,
    invalid_cells: &impl Fn(&SlabPlan, &[u32]) -> usize,
) -> Option<u32> {
    for r in plan.merges.face_roots(front, f) {
        let c = r as usize;
        if !plan.moving[c] || !may_tip(front, columns, c) {
            continue;
        }
        let node = points[columns.node[c] as usize];
        let step = plan.proposed[c] - node;
        let along = step.normalize_or_zero();
        if along == DVec3::ZERO {
            continue;
        }
        // The direction it marches on in: a column tipped before in this slab goes on from there.
        let (dir, scale) = plan
            .redirected
            .iter()
            .rev()
            .find(|e| e.0 == r)
            .map_or((columns.dir[c], columns.scale[c]), |e| (e.1, e.2));
        let (e1, e2) = along.any_orthonormal_pair();
        for t in TUNING.repairs.nudges {
            let tips = (0..8).map(|i| {
                let a = i as f64 * std::f64::consts::FRAC_PI_4;
                let tipped = (along + t * (a.cos() * e1 + a.sin() * e2)).normalize();
                let turn = glam::DQuat::from_rotation_arc(along, tipped);
                (columns.slide[c].project(node + tipped * step.length()), (turn * dir).normalize())
            });
            if let Some((top, dir)) = best_top(plan, r, tips, face_valid, invalid_cells) {
                move_top(plan, r, top, (dir, scale));
                plan.tips += 1;
                tracing::debug!(f, r, t, at = ?columns.base[c], "invalid cell mended by tipping a column");
                return Some(r);
            }
        }
    }
    None
}

/// Whether column `c` may be tipped: within its full stack (a stop in the transition layers
/// above costs no coverage, and there the tips roughen the front the core fills: bunny, 20
/// layers, 19 -> 55 tetrahedra below 10 deg), and a fan's column not in its first layer (a
/// fan's cells start as wedges on the wall edge; tipped there, the bunny's fans at a corner
/// went on a few layers and stopped one by one: 96).
fn may_tip(front: &Front, columns: &Columns, c: usize) -> bool {
    let within_stack = columns.full_count(c).is_some_and(|n| columns.layers[c] < n);
    within_stack && (columns.layers[c] > 0 || !in_a_fan(front, columns, c as u32))
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
    use crate::config::LayerSpec;

    /// Column 0 at the centre of a hexagon of columns 1-6 on the plane z = 0, in triangles
    /// (0, i, i + 1); the ring rises 0.5 up +z, column 0 leans along +x past the ring's column 1.
    fn leaning_centre() -> (Columns, Front, Vec<DVec3>, SlabPlan) {
        let ring = (0..6).map(|i| {
            let a = i as f64 * std::f64::consts::FRAC_PI_3;
            DVec3::new(a.cos(), a.sin(), 0.0)
        });
        let bottoms: Vec<DVec3> = std::iter::once(DVec3::ZERO).chain(ring).collect();
        let mut columns = Columns::rising(&bottoms, Some(LayerSpec::fixed(0.1, 1.2, 10)));
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

    #[test]
    fn a_fan_column_bend_leaves_alone_is_tipped_back_until_its_cells_stand() {
        let (mut columns, front, bottoms, mut plan) = leaning_centre();
        columns.base[1] = columns.base[0];
        columns.layers[0] = 3;
        let invalid = |plan: &SlabPlan, group: &[u32]| {
            let faces = front.faces_around_columns(group);
            faces.into_iter().filter(|&f| !top_faces_up(plan, &front, f)).count()
        };
        let face_valid = |plan: &SlabPlan| top_faces_up(plan, &front, 0);
        assert_eq!(bend_to_mend(&mut plan, &front, 0, &columns, &bottoms, &face_valid, &invalid), None);
        // Each tip leaves fewer cells inverted; the march tips again while one is left.
        let mut tips = 0;
        while invalid(&plan, &[0]) > 0 {
            let before = invalid(&plan, &[0]);
            assert_eq!(
                nudge_to_mend(&mut plan, &front, 0, &columns, &bottoms, &face_valid, &invalid),
                Some(0)
            );
            assert!(invalid(&plan, &[0]) < before);
            tips += 1;
        }
        assert!(tips <= 2, "{tips} tips");
        assert!((plan.proposed[0].length() - 1.2).abs() < 1e-12, "the step keeps its length");
        let &(c, dir, _) = plan.redirected.last().unwrap();
        assert_eq!(c, 0);
        let step_dir = plan.proposed[0].normalize();
        assert!(dir.angle_between(step_dir) < 1e-9, "it marches on along its tipped step");
        let tip = dir.angle_between(columns.dir[0]).to_degrees();
        assert!(tip > 0.0 && tip <= tips as f64 * 0.5f64.atan().to_degrees() + 1e-9, "tipped {tip} deg");
        assert!(plan.proposed[0].z > 1.2 * columns.dir[0].z, "tipped up, back over its ring");
    }

    #[test]
    fn a_cell_no_tip_mends_leaves_the_plan_as_it_was() {
        let (columns, front, bottoms, mut plan) = leaning_centre();
        // Far out past the ring and nearly flat: half a step sideways cannot bring it back.
        plan.proposed[0] = 3.0 * DVec3::new(1.0, 0.0, 0.05).normalize();
        let before = plan.proposed.clone();
        let invalid = |plan: &SlabPlan, group: &[u32]| {
            let faces = front.faces_around_columns(group);
            faces.into_iter().filter(|&f| !top_faces_up(plan, &front, f)).count()
        };
        let face_valid = |plan: &SlabPlan| top_faces_up(plan, &front, 0);
        assert_eq!(nudge_to_mend(&mut plan, &front, 0, &columns, &bottoms, &face_valid, &invalid), None);
        assert_eq!(plan.proposed, before);
        assert!(plan.redirected.is_empty());
    }

    #[test]
    fn no_column_is_tipped_above_its_full_stack_nor_a_fan_in_its_first_layer() {
        let (mut columns, front, bottoms, mut plan) = leaning_centre();
        let invalid = |plan: &SlabPlan, group: &[u32]| {
            let faces = front.faces_around_columns(group);
            faces.into_iter().filter(|&f| !top_faces_up(plan, &front, f)).count()
        };
        let face_valid = |plan: &SlabPlan| top_faces_up(plan, &front, 0);
        // Every column in its 11th layer of 10: transition layers.
        columns.layers.iter_mut().for_each(|l| *l = 10);
        assert_eq!(nudge_to_mend(&mut plan, &front, 0, &columns, &bottoms, &face_valid, &invalid), None);
        // In its first layer, as a fan's column.
        columns.layers.iter_mut().for_each(|l| *l = 0);
        columns.base[1] = columns.base[0];
        assert_eq!(nudge_to_mend(&mut plan, &front, 0, &columns, &bottoms, &face_valid, &invalid), None);
        // In its first layer, alone: tipped.
        columns.base[1] = bottoms[1];
        assert_eq!(nudge_to_mend(&mut plan, &front, 0, &columns, &bottoms, &face_valid, &invalid), Some(0));
    }
}
