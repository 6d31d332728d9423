//! Entropy collapse: where fronts from different walls meet (concave ridges and corners, the
//! compressed side of concave curvature), their columns merge instead of crossing, so the front
//! follows the first-arrival offset (the entropy solution of the eikonal equation) and keeps
//! marching.
//!
//! A front face whose cell would be invalid while its columns converge (its proposed top keeps
//! less area than its bottom) loses its most shrunk edge instead of stopping. The survivor is the column
//! that already lies on the bisector: the one with the larger extrusion scale (a concave ridge
//! column has `1/sin(phi/2)`, a corner column more, a face column 1), so the merged node stays on
//! the Voronoi bisector at the exact wall distance. Between two columns of the same kind the
//! merged column goes through the middle of their proposals, along their mean direction.

use glam::DVec3;

use super::front::{Columns, Front};
use super::march::SlabPlan;

/// Two columns meet when their proposed top edge keeps less than this fraction of its bottom
/// edge: merging them then moves neither far (merging columns still apart twists the lateral
/// faces of the cells around them).
pub const MEETING_RATIO: f64 = 0.25;

/// Two scales closer than this ratio are the same kind of column.
const SAME_SCALE: f64 = 1.01;

/// Signed length of the top edge (`top_a`, `top_b`) along the bottom edge (`a`, `b`), relative
/// to the bottom edge: 1 for parallel columns, less where they converge, negative once crossed.
pub fn shrink_ratio(a: DVec3, b: DVec3, top_a: DVec3, top_b: DVec3) -> f64 {
    let e = b - a;
    (top_b - top_a).dot(e) / e.length_squared()
}

/// Shrink ratio of the edge between roots `a` and `b` under the plan.
fn edge_ratio(plan: &SlabPlan, columns: &Columns, points: &[DVec3], a: u32, b: u32) -> f64 {
    let bottom = |c: u32| points[columns.node[c as usize] as usize];
    shrink_ratio(bottom(a), bottom(b), plan.proposed[a as usize], plan.proposed[b as usize])
}

fn moving_roots(plan: &SlabPlan, a: u32, b: u32) -> bool {
    a != b
        && plan.moving[a as usize]
        && plan.moving[b as usize]
        && !plan.merges.is_merged(a)
        && !plan.merges.is_merged(b)
}

/// How much of face `f`'s area its proposed top keeps, measured along the bottom's normal:
/// 1 for parallel columns, less where they converge, negative once the top has turned over.
/// `None` for a face that is degenerate at the bottom (fan faces at the wall).
fn area_ratio(plan: &SlabPlan, front: &Front, f: usize, columns: &Columns, points: &[DVec3]) -> Option<f64> {
    let cols = front.face_columns(f);
    let bottom: Vec<DVec3> = cols.iter().map(|&c| points[columns.node[c as usize] as usize]).collect();
    let top: Vec<DVec3> = cols.iter().map(|&c| plan.proposed[plan.merges.root(c) as usize]).collect();
    let (nb, nt) = (newell(&bottom), newell(&top));
    let area = nb.length();
    (area > 0.0).then(|| nt.dot(nb) / (area * area))
}

/// Twice the area vector of a polygon (Newell's formula).
fn newell(p: &[DVec3]) -> DVec3 {
    (0..p.len()).map(|i| p[i].cross(p[(i + 1) % p.len()])).sum()
}

/// Repair invalid face `f` by a collapse if it is being crushed; returns the columns whose
/// cells changed.
pub(super) fn collapse_crushed_edge(
    plan: &mut SlabPlan,
    front: &Front,
    f: usize,
    columns: &Columns,
    points: &[DVec3],
) -> Option<Vec<u32>> {
    area_ratio(plan, front, f, columns, points).filter(|&r| r < 1.0)?;
    let root = collapse_most_shrunk_edge(plan, front, f, columns, points)?;
    Some(plan.merges.group(root).collect())
}

/// Collapse the edge of face `f` whose top has shrunk most relative to its bottom, if the
/// front allows it; returns the surviving root.
fn collapse_most_shrunk_edge(
    plan: &mut SlabPlan,
    front: &Front,
    f: usize,
    columns: &Columns,
    points: &[DVec3],
) -> Option<u32> {
    let face = plan.merges.resolved_face(front, f)?;
    let n = face.nodes();
    let (_, a, b) = (0..n.len())
        .map(|i| (n[i], n[(i + 1) % n.len()]))
        .filter(|&(a, b)| moving_roots(plan, a, b) && plan.merges.can_collapse(front, a, b))
        .map(|(a, b)| (edge_ratio(plan, columns, points, a, b), a, b))
        .filter(|&(ratio, _, _)| ratio < MEETING_RATIO)
        .min_by(|x, y| x.0.total_cmp(&y.0))?;
    collapse(plan, columns, a, b);
    Some(plan.merges.root(a))
}

/// Which of roots `a` and `b` survives their merge, which goes, and whether the survivor
/// moves to the middle: the bisector column (larger scale) survives; equals meet in the middle.
fn survivor(columns: &Columns, a: u32, b: u32) -> (u32, u32, bool) {
    let (sa, sb) = (columns.scale[a as usize], columns.scale[b as usize]);
    if sa > sb * SAME_SCALE {
        (a, b, false)
    } else if sb > sa * SAME_SCALE {
        (b, a, false)
    } else {
        (a.min(b), a.max(b), true)
    }
}

/// Merge roots `a` and `b` (see [`survivor`]).
pub(super) fn collapse(plan: &mut SlabPlan, columns: &Columns, a: u32, b: u32) {
    let (sa, sb) = (columns.scale[a as usize], columns.scale[b as usize]);
    let at = |c: u32| columns.base[c as usize].as_vec3();
    tracing::debug!("collapse columns {a} at {} (scale {sa:.3}) and {b} at {} (scale {sb:.3})", at(a), at(b));
    let (keep, drop, middle) = survivor(columns, a, b);
    if middle {
        let (k, d) = (keep as usize, drop as usize);
        plan.proposed[k] = columns.slide[k].project(0.5 * (plan.proposed[k] + plan.proposed[d]));
        let dir = (columns.dir[k] + columns.dir[d]).normalize_or(columns.dir[k]);
        plan.redirected.push((keep, dir, 0.5 * (sa + sb)));
    }
    plan.merges.merge(keep, drop);
    plan.collapses += 1;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shrink_ratio_tells_parallel_converging_and_crossed() {
        let (a, b) = (DVec3::ZERO, DVec3::X);
        let up = DVec3::Y;
        assert_eq!(shrink_ratio(a, b, a + up, b + up), 1.0);
        assert_eq!(shrink_ratio(a, b, a + up + 0.25 * DVec3::X, b + up - 0.25 * DVec3::X), 0.5);
        assert!(shrink_ratio(a, b, b + up, a + up) < 0.0);
    }
}
