//! Entropy collapse: where fronts from different walls meet (concave ridges and corners, the
//! compressed side of concave curvature), their columns merge instead of crossing, so the front
//! follows the first-arrival offset (the entropy solution of the eikonal equation) and keeps
//! marching.
//!
//! A face column beside a concave ridge merges into the ridge's bisector column as soon as its
//! proposed top passes the bisector ([`merge_bisector_crossings`]), before the cells are tested.
//! Then, a front face whose cell would still be invalid while its columns converge (its proposed
//! top keeps less area than its bottom) loses its most shrunk edge instead of stopping. The
//! survivor is the column that already lies on the bisector: the one with the larger extrusion
//! scale (a concave ridge column has `1/sin(phi/2)`, a corner column more, a face column 1), so the
//! merged node stays on the Voronoi bisector at the exact wall distance. Between two columns of the
//! same kind the merged column goes through the middle of their proposals, along their mean
//! direction.
//!
//! Where the wall's edges run obliquely to a ridge, a face can turn over with no edge shrinking
//! much: a corner closes in on its opposite edge (the bisector column passing the face columns
//! in front of it). Such a face loses that corner instead, merged into the nearer end of the
//! edge.
//!
//! Fronts also meet with no ridge between them (a step lower than the layers are thick, a fin's
//! edge at a body, a concave valley): a column whose top falls behind its layer's distance from
//! the wall (a BVH over the walls with layers) merges into a neighbour on time
//! ([`merge_overtaken`]). Before a cell's columns stop, a merge along one of its edges
//! that leaves every cell around valid mends it ([`merge_to_mend`]). Last, two faces whose tops
//! cross over a front edge they share (two fronts closing a V over the crease where they met,
//! as a groove's lip fans do over its filled mouth) merge their columns into the crease instead
//! of stopping ([`merge_into_crease`]); where crossing faces share no edge but one is a fan
//! strip, fronts met head on over a convex ridge, and the fan columns the other front reached
//! first merge into their fan mates ([`retreat_fans`]).

use glam::DVec3;
use rayon::prelude::*;

use super::front::{Columns, Front};
use super::slab::Polygon;
use super::slab_plan::SlabPlan;
use super::tuning::TUNING;
use crate::geometry::distance::closest_point_on_triangle;
use crate::geometry::triangle_max_angle;
use crate::sizing::wall::WallDistance;
use crate::surface::topology::Topology;
use crate::surface::Surface;

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
    area_ratio_with(plan, front, f, columns, points, |c| plan.merges.root(c))
}

/// [`area_ratio`] with the tops of the columns' roots as `root` says.
fn area_ratio_with(
    plan: &SlabPlan,
    front: &Front,
    f: usize,
    columns: &Columns,
    points: &[DVec3],
    root: impl Fn(u32) -> u32,
) -> Option<f64> {
    let cols = front.face_columns(f);
    let bottom: Vec<DVec3> = cols.iter().map(|&c| points[columns.node[c as usize] as usize]).collect();
    let top: Vec<DVec3> = cols.iter().map(|&c| plan.proposed[root(c) as usize]).collect();
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
    let crushed = area_ratio(plan, front, f, columns, points).is_some_and(|r| r < 1.0);
    let root = crushed
        .then(|| collapse_most_shrunk_edge(plan, front, f, columns, points))
        .flatten()
        .or_else(|| collapse_crossing_corner(plan, front, f, columns, points))?;
    Some(plan.merges.group(root).collect())
}

/// What the entropy collapse knows of the wall: the normals of the wall triangles at every wall
/// vertex (through the surface's topology), and the distance to the walls that get layers.
pub struct VertexWalls<'a> {
    topology: &'a Topology,
    /// Every wall triangle's unit normal.
    normals: Vec<DVec3>,
    /// The triangles of the patches with layers (the others are no front to be overtaken by).
    layered: WallDistance,
    /// Every wall triangle's index in `layered` (`u32::MAX` for those without layers).
    layered_index: Vec<u32>,
    /// Normals of the offset cylinders of ridges at their roots, by wall vertex
    /// ([`WallNormals::cylinder_normals`](crate::normals::WallNormals::cylinder_normals)).
    cylinders: Vec<(u32, DVec3)>,
}

impl<'a> VertexWalls<'a> {
    /// `layered(p)`: whether patch `p` gets layers.
    pub fn new(surface: &Surface, topology: &'a Topology, layered: impl Fn(u32) -> bool) -> Self {
        let mut walls = surface.clone();
        let keep: Vec<usize> =
            (0..surface.triangles.len()).filter(|&t| layered(surface.triangle_patch[t])).collect();
        walls.triangles = keep.iter().map(|&t| surface.triangles[t]).collect();
        walls.triangle_patch = keep.iter().map(|&t| surface.triangle_patch[t]).collect();
        let mut layered_index = vec![u32::MAX; surface.triangles.len()];
        for (i, &t) in keep.iter().enumerate() {
            layered_index[t] = i as u32;
        }
        VertexWalls {
            topology,
            normals: (0..surface.triangles.len()).map(|t| surface.triangle_normal(t)).collect(),
            layered: WallDistance::new(&walls),
            layered_index,
            cylinders: Vec::new(),
        }
    }

    /// With the offset cylinders of ridges at their roots as walls of their own (sorted by
    /// vertex): a ridge's fan column there bisects its cylinder and the floor.
    pub fn with_cylinders(mut self, cylinders: &[(u32, DVec3)]) -> Self {
        self.cylinders = cylinders.to_vec();
        self
    }

    /// The normals at wall vertex `v` (none for a vertex off the surface): its triangles', and
    /// those of a ridge's offset cylinder where the ridge has its root at `v`.
    pub fn at(&self, v: u32) -> impl Iterator<Item = DVec3> + '_ {
        let start = self.cylinders.partition_point(|&(x, _)| x < v);
        let cylinders = self.cylinders[start..].iter().take_while(move |&&(x, _)| x == v).map(|&(_, n)| n);
        self.triangles_at(v).iter().map(|&t| self.normals[t as usize]).chain(cylinders)
    }

    /// The wall triangles at wall vertex `v` (none for a vertex off the surface).
    fn triangles_at(&self, v: u32) -> &[u32] {
        if (v as usize) < self.topology.vertex_count() {
            self.topology.vertex_triangles(v)
        } else {
            &[]
        }
    }

    /// How much farther from the walls with layers the front can climb from `top`, up to
    /// `reach` ([`super::gap::room_above`]).
    pub fn room_above(&self, top: DVec3, heading: DVec3, reach: f64) -> f64 {
        super::gap::room_above(self.layered.bvh(), top, heading, reach)
    }

    /// Distance from `p` to the nearest wall with layers (infinite when there is none).
    pub fn distance(&self, p: DVec3) -> f64 {
        self.layered.closest(p).map_or(f64::INFINITY, |w| w.distance)
    }

    /// [`distance`](Self::distance) when it is below `reach`, else `None` (a search that
    /// skips everything farther).
    pub fn distance_within(&self, p: DVec3, reach: f64) -> Option<f64> {
        self.layered.bvh().nearest_within(p, reach).map(|near| near.distance)
    }

    /// An upper bound of [`distance`](Self::distance) at `p` for a point of wall vertex `v`'s
    /// column: the distance to the triangles with layers at `v` (infinite when there are none).
    pub fn distance_bound(&self, v: u32, p: DVec3) -> f64 {
        self.triangles_at(v)
            .iter()
            .map(|&t| self.layered_index[t as usize])
            .filter(|&i| i != u32::MAX)
            .map(|i| {
                let [a, b, c] = self.layered.bvh().corners(i);
                closest_point_on_triangle(p, a, b, c).distance(p)
            })
            .fold(f64::INFINITY, f64::min)
    }
}

/// Merge every face column whose proposed top passes the bisector of a concave ridge column next to
/// it into that column, before any cell is tested. This is the entropy collapse where it is due,
/// whatever the shape of the cells: a face column of wall 1 beside a concave ridge has crossed the
/// bisector once its top is nearer the other wall's offset than its own, i.e. past the plane
/// through the ridge column's top normal to `n - (n . d) d` (`n` its direction, `d` the ridge
/// column's). The cells' tests see such a crossing late or not at all where the wall's edges run
/// obliquely to the ridge, and merge the wrong edge then (two face columns with each other, off the
/// bisector).
pub(super) fn merge_bisector_crossings(
    plan: &mut SlabPlan,
    front: &Front,
    columns: &Columns,
    points: &[DVec3],
    walls: &VertexWalls,
    invalid_cells: impl Fn(&SlabPlan, &[u32]) -> usize,
) {
    // A column passes only the bisectors of neighbours with a larger scale by the ridge scale
    // ([`passed_bisectors`]): none beyond the largest scale of all.
    let largest_scale = columns.scale.iter().copied().fold(0.0, f64::max);
    loop {
        let mut merged = false;
        for c in 0..columns.len() as u32 {
            let below_a_ridge = columns.scale[c as usize] * TUNING.entropy.ridge_scale <= largest_scale;
            if !plan.moving[c as usize] || plan.merges.is_merged(c) || !below_a_ridge {
                continue;
            }
            // The nearest bisector it has passed (one ridge column beside another may see the
            // same crossing: the nearer keeps the front's cells in shape).
            let top = |x: u32| plan.proposed[x as usize];
            // Equally near (a face column half way between two ridge columns), the one that
            // leaves no face flat ([`flattened_if_merged`]).
            let key = |x: u32| {
                (flattened_if_merged(plan, front, columns, points, x, c), top(x).distance_squared(top(c)))
            };
            let Some(r) =
                passed_bisectors(plan, front, columns, points, walls, c, TUNING.entropy.anticipation)
                    .into_iter()
                    .map(|x| (key(x), x))
                    .min_by(|(kx, _), (ky, _)| kx.0.cmp(&ky.0).then(kx.1.total_cmp(&ky.1)))
                    .map(|(_, x)| x)
            else {
                continue;
            };
            if !can_merge(plan, front, columns, r, c) {
                continue;
            }
            // Not into more invalid cells than it leaves (the crossing may have turned some over
            // already: the cells' repairs mend those).
            let group: Vec<u32> = plan.merges.group(r).chain(plan.merges.group(c)).collect();
            let before = invalid_cells(plan, &group);
            merged |= try_collapse(plan, columns, r, c, &|plan, group| invalid_cells(plan, group) <= before);
        }
        if !merged {
            break;
        }
    }
}

/// How late root `c`'s proposed top (its `k`-th layer) is on the first-arrival offset: its lag
/// behind the layer's distance from the wall, in layer heights, plus
/// [`TUNING.entropy.anticipation`](super::tuning::Entropy::anticipation) times what it fell behind
/// since its bottom; 0 for a column not falling behind
/// ([`TUNING.entropy.falling_behind`](super::tuning::Entropy::falling_behind)) or past its stack.
fn lateness(
    plan: &SlabPlan,
    columns: &Columns,
    points: &[DVec3],
    walls: &VertexWalls,
    c: u32,
    k: u32,
) -> f64 {
    let (Some(d), Some(d_below)) = (columns.distance(c as usize, k), columns.distance(c as usize, k - 1))
    else {
        return 0.0;
    };
    let h = d - d_below;
    if h <= 0.0 {
        return 0.0;
    }
    let (top_point, bottom_point) = (plan.proposed[c as usize], points[columns.node[c as usize] as usize]);
    // Falling behind means a top less than (1 - falling_behind) h farther from the walls than
    // the bottom: with the bottom's distance bounded by its own wall's triangles, most columns
    // are ruled out by a search that skips everything farther (the margin covers rounding).
    let reach = walls.distance_bound(columns.wall_vertex[c as usize], bottom_point)
        + (1.0 - TUNING.entropy.falling_behind) * h;
    let Some(top_distance) = walls.distance_within(top_point, reach + 1e-9 * (reach.abs() + h)) else {
        return 0.0;
    };
    let top = (d - top_distance) / h;
    let bottom = (d_below - walls.distance(bottom_point)) / h;
    if top - bottom > TUNING.entropy.falling_behind {
        top + TUNING.entropy.anticipation * (top - bottom)
    } else {
        0.0
    }
}

/// Merge every column that another wall's front has overtaken
/// ([`TUNING.entropy.overtaken`](super::tuning::Entropy::overtaken)) into a neighbour root that is
/// on time (the least late that the cells allow), which keeps its top: the first-arrival rule
/// itself, wherever fronts meet, with or without a feature ridge between them (a step narrower than
/// the layers are thick, a fin's edge at a body, a concave valley). The latest go first. A column
/// whose neighbours are all late (fronts meeting head on across a gap) is left to the crossing
/// guard, which ends the stacks at the medial surface.
pub(super) fn merge_overtaken(
    plan: &mut SlabPlan,
    front: &Front,
    columns: &Columns,
    points: &[DVec3],
    walls: &VertexWalls,
    k: u32,
    invalid_cells: impl Fn(&SlabPlan, &[u32]) -> usize,
) {
    let is_root = |plan: &SlabPlan, c: u32| plan.moving[c as usize] && !plan.merges.is_merged(c);
    // The merges here keep the survivors' tops, so every column's lateness holds all along.
    let late: Vec<f64> = (0..columns.len() as u32)
        .into_par_iter()
        .map(|c| if plan.moving[c as usize] { lateness(plan, columns, points, walls, c, k) } else { 0.0 })
        .collect();
    loop {
        let mut overtaken: Vec<(f64, u32)> = (0..columns.len() as u32)
            .filter(|&c| is_root(plan, c) && late[c as usize] > TUNING.entropy.overtaken)
            .map(|c| (late[c as usize], c))
            .collect();
        overtaken.sort_by(|x, y| y.0.total_cmp(&x.0));
        let mut merged = false;
        for (_, c) in overtaken {
            if !is_root(plan, c) {
                continue;
            }
            // Equally late, the nearest top: merging moves the front least.
            let apart = |r: u32| plan.proposed[r as usize].distance_squared(plan.proposed[c as usize]);
            let mut on_time: Vec<(f64, f64, u32)> = neighbour_roots(plan, front, c)
                .into_iter()
                .filter(|&r| is_root(plan, r) && can_merge(plan, front, columns, r, c))
                .map(|r| (late[r as usize], apart(r), r))
                .filter(|&(l, _, _)| l <= TUNING.entropy.overtaken)
                .collect();
            on_time.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.total_cmp(&y.1)));
            merged |= on_time.into_iter().any(|(_, _, r)| {
                let group: Vec<u32> = plan.merges.group(r).chain(plan.merges.group(c)).collect();
                let before = invalid_cells(plan, &group);
                try_merge_as(plan, columns, (r, c, false), &|plan, group| {
                    invalid_cells(plan, group) <= before
                })
            });
        }
        if !merged {
            break;
        }
    }
}

/// Collapse the shortest top edge of every face left flat or turned over
/// ([`TUNING.entropy.flat_top`](super::tuning::Entropy::flat_top)) along a line
/// ([`TUNING.entropy.line_like`](super::tuning::Entropy::line_like)), with three corners or more
/// still apart, if the cells around allow it. The merges make such faces: where the face columns
/// beside a ridge merge into its ridge columns, one that goes back along the ridge next to one that
/// goes forward leaves the face between them flat along the bisector, over three ridge columns
/// ([`flattened_if_merged`] avoids it only where a choice is left); the other wall's front meets
/// the ridge's middle column, the flat face does not, and the two cross. Merging the middle ridge
/// column with one beside it (equal columns meet in the middle, on the bisector of a straight
/// ridge) gives both sides the same edge there. So do a wall edge far shorter than the layer (its
/// face turns over in one layer) and a valley narrower than the layers (its faces squeezed flat).
/// A triangle whose top is a cap
/// ([`TUNING.unfolding.cap_angle`](super::tuning::Unfolding::cap_angle)) on a crease counts as flat
/// whatever its area: where two walls' columns converge on their bisector (a post's or a wing's
/// foot), a column about to reach it has its top nearly on the line of two that did (they carry
/// merged columns); left so on the final front, every core tetrahedron on that cap is a sliver. Its
/// shortest edge, the middle corner to the nearer end, is merged first: the column meets the
/// bisector a step early. Such a cap's cell is valid, so its merge must leave every cell around
/// valid; a cap with a fan's column is the front wrapping round a convex edge, not a crease.
/// Returns the number of collapses.
pub(super) fn merge_flat_tops(
    plan: &mut SlabPlan,
    front: &Front,
    columns: &Columns,
    points: &[DVec3],
    k: u32,
    invalid_cells: impl Fn(&SlabPlan, &[u32]) -> usize,
) -> usize {
    let carries = super::swap::carrying_merged(columns);
    // The faces of `plan` left flat along a line, with their columns' roots.
    let flat_along_a_line = |plan: &SlabPlan, f: usize| {
        let face = plan.merges.resolved_face(front, f)?;
        let n = face.nodes();
        // A column that does not move has no proposed top. Above the full stacks (layer `k`
        // past a full count) a flat face is most often a front closing on itself at a medial
        // surface (a wall strip narrower than twice the layers), which the crossing guard
        // ends: collapsing those pinched an internal box's front into a pocket.
        let moving = front.face_columns(f).iter().all(|&c| plan.moving[c as usize]);
        let in_stack = n.iter().all(|&c| columns.full_count(c as usize).is_some_and(|t| k <= t));
        if n.len() < 3 || !moving || !in_stack {
            return None;
        }
        let top = |c: u32| plan.proposed[c as usize];
        let in_fan = |c: u32| {
            let mut mates = Vec::new();
            front.fan_mates(columns, c as usize, &mut mates);
            !mates.is_empty()
        };
        let on_crease = |c: u32| carries[c as usize] || plan.merges.group(c).nth(1).is_some();
        let cap = n.len() == 3
            && triangle_max_angle(top(n[0]), top(n[1]), top(n[2])) > TUNING.unfolding.cap_angle
            && !n.iter().any(|&c| in_fan(c))
            && long_edge_ends(n, &top).iter().all(|&c| on_crease(c));
        let flat = area_ratio(plan, front, f, columns, points).is_some_and(|a| a < TUNING.entropy.flat_top);
        if !cap && !flat {
            return None;
        }
        // Flat along a line, not crushed to a point (the cells' repairs see to those).
        let bottom = |c: u32| points[columns.node[c as usize] as usize];
        let longest = |at: &dyn Fn(u32) -> DVec3| {
            (0..n.len()).map(|i| at(n[i]).distance(at(n[(i + 1) % n.len()]))).fold(0.0, f64::max)
        };
        (longest(&top) >= TUNING.entropy.line_like * longest(&bottom)).then_some((face, !flat))
    };
    // Seen for every face in parallel under the plan as it comes; once a merge changed it, face
    // by face (a merge tried and undone leaves the plan as it was).
    let flat_at_first: Vec<bool> =
        (0..front.len()).into_par_iter().map(|f| flat_along_a_line(plan, f).is_some()).collect();
    let mut merged = 0;
    for (f, flat_at_first) in flat_at_first.into_iter().enumerate() {
        if merged == 0 && !flat_at_first {
            continue;
        }
        let Some((face, cap_only)) = flat_along_a_line(plan, f) else { continue };
        let n = face.nodes();
        let top = |c: u32| plan.proposed[c as usize];
        let mut edges: Vec<(f64, u32, u32)> = (0..n.len())
            .map(|i| (n[i], n[(i + 1) % n.len()]))
            .filter(|&(a, b)| can_merge(plan, front, columns, a, b))
            .map(|(a, b)| (top(a).distance_squared(top(b)), a, b))
            .collect();
        edges.sort_by(|x, y| x.0.total_cmp(&y.0));
        for (_, a, b) in edges {
            let group: Vec<u32> = plan.merges.group(a).chain(plan.merges.group(b)).collect();
            // A cap is valid as it is: its merge, for the core's sake, must leave every cell
            // around valid.
            let allowed = if cap_only { 0 } else { invalid_cells(plan, &group) };
            if try_collapse(plan, columns, a, b, &|plan, group| invalid_cells(plan, group) <= allowed) {
                tracing::debug!(f, a, b, at = ?columns.base[a as usize], "flat top mended by a merge");
                merged += 1;
                break;
            }
        }
    }
    merged
}

/// The ends of the longest edge of the triangle `n` with corners at `top`.
fn long_edge_ends(n: &[u32], top: &impl Fn(u32) -> DVec3) -> [u32; 2] {
    let i = (0..3)
        .max_by(|&i, &j| {
            let length = |i: usize| top(n[i]).distance_squared(top(n[(i + 1) % 3]));
            length(i).total_cmp(&length(j))
        })
        .unwrap_or(0);
    [n[i], n[(i + 1) % 3]]
}

/// The roots of the columns next to root `c`'s group on the front, other than `c`.
pub(super) fn neighbour_roots(plan: &SlabPlan, front: &Front, c: u32) -> Vec<u32> {
    let mut next = Vec::new();
    for g in plan.merges.group(c) {
        front.neighbours(g as usize, &mut next);
    }
    let mut roots: Vec<u32> = next.iter().map(|&x| plan.merges.root(x as u32)).filter(|&r| r != c).collect();
    roots.sort_unstable();
    roots.dedup();
    roots
}

/// How many faces around root `c`'s group would be left flat
/// ([`TUNING.entropy.flat_top`](super::tuning::Entropy::flat_top)) with three distinct corners if
/// `c` merged into root `r`: two face columns beside a ridge merged into two ridge columns with a
/// third between them fold the front along the ridge, every cell valid.
fn flattened_if_merged(
    plan: &SlabPlan,
    front: &Front,
    columns: &Columns,
    points: &[DVec3],
    r: u32,
    c: u32,
) -> usize {
    let group: Vec<u32> = plan.merges.group(c).collect();
    let root = |x: u32| if plan.merges.root(x) == c { r } else { plan.merges.root(x) };
    front
        .faces_around_columns(&group)
        .into_iter()
        .filter(|&f| {
            let mut roots: Vec<u32> = front.face_columns(f).iter().map(|&x| root(x)).collect();
            roots.sort_unstable();
            roots.dedup();
            roots.len() >= 3
                && area_ratio_with(plan, front, f, columns, points, root)
                    .is_some_and(|a| a < TUNING.entropy.flat_top)
        })
        .count()
}

/// The concave ridge columns (roots) beside root `c`'s group whose bisectors `c` has passed, or
/// will within `anticipation` of its last approach ([`crosses_bisector`]).
fn passed_bisectors(
    plan: &SlabPlan,
    front: &Front,
    columns: &Columns,
    points: &[DVec3],
    walls: &VertexWalls,
    c: u32,
    anticipation: f64,
) -> Vec<u32> {
    let mut passed = neighbour_roots(plan, front, c);
    passed.retain(|&r| {
        columns.scale[c as usize] * TUNING.entropy.ridge_scale <= columns.scale[r as usize]
            && crosses_bisector(plan, columns, points, walls, r, c, anticipation)
    });
    passed
}

/// Whether column `c`'s proposed top has passed the bisector through concave ridge column `r`
/// that its bottom is short of (see [`merge_bisector_crossings`]).
fn crosses_bisector(
    plan: &SlabPlan,
    columns: &Columns,
    points: &[DVec3],
    walls: &VertexWalls,
    r: u32,
    c: u32,
    anticipation: f64,
) -> bool {
    let (d, n) = (columns.dir[r as usize], columns.dir[c as usize]);
    let across = n - n.dot(d) * d;
    // `r` must be the bisector of `c`'s wall and another at its vertex: `c`'s direction
    // mirrored about `d` is that other wall's normal (not so for a fan's column at a saddle,
    // nor at a corner of three walls, which the cells' tests handle).
    let is_wall = |m: DVec3| {
        walls.at(columns.wall_vertex[r as usize]).any(|w| w.dot(m) >= TUNING.entropy.same_wall_cosine)
    };
    if across.length() < TUNING.entropy.min_bisector_sine || !is_wall(n) || !is_wall(2.0 * n.dot(d) * d - n) {
        return false;
    }
    let bottom = |x: u32| points[columns.node[x as usize] as usize];
    let top = |x: u32| plan.proposed[x as usize];
    let apart = bottom(c) - bottom(r);
    let (before, after) = (apart.dot(across), (top(c) - top(r)).dot(across));
    // An edge along the ridge (where it fades out, say) starts on the bisector: no crossing.
    if -before < TUNING.entropy.across_ridge * across.length() * apart.length() {
        return false;
    }
    // Passed, or short of it by less than `anticipation` times what it closed in this layer: as
    // many more layers would take it past.
    before < 0.0 && after + anticipation * (after - before) >= 0.0
}

/// Repair invalid face `f` by merging one of its face columns into the bisector column beside it
/// that it will pass within
/// [`TUNING.entropy.repair_anticipation`](super::tuning::Entropy::repair_anticipation) of its last
/// approaches (with its fan mates, if it is a fan's), if that leaves fewer invalid cells around;
/// returns the surviving root. On a thin wall triangle along a ridge, one corner merging on time
/// can turn the cell over while the next corner is a layer short of the bisector: merging that one
/// early keeps the cell, where a general earlier merge would take the front off the offset
/// elsewhere (at 1.5 approaches everywhere, the flange fell to 86.9%).
pub(super) fn merge_before_crossing(
    plan: &mut SlabPlan,
    front: &Front,
    f: usize,
    columns: &Columns,
    points: &[DVec3],
    walls: &VertexWalls,
    invalid_cells: &impl Fn(&SlabPlan, &[u32]) -> usize,
) -> Option<u32> {
    // The face may be down to an edge already (one corner merged).
    let mut candidates: Vec<(u32, u32)> = plan
        .merges
        .face_roots(front, f)
        .iter()
        .flat_map(|&c| {
            let passed =
                passed_bisectors(plan, front, columns, points, walls, c, TUNING.entropy.repair_anticipation);
            passed.into_iter().map(move |r| (r, c))
        })
        .filter(|&(r, c)| can_merge(plan, front, columns, r, c))
        .collect();
    candidates.sort_unstable();
    candidates.dedup();
    for (r, c) in candidates {
        let group: Vec<u32> = plan.merges.group(r).chain(plan.merges.group(c)).collect();
        let before = invalid_cells(plan, &group);
        let fewer_invalid = |plan: &SlabPlan, group: &[u32]| invalid_cells(plan, group) < before;
        if try_collapse(plan, columns, r, c, &fewer_invalid) {
            return Some(plan.merges.root(r));
        }
        // A fan column at a saddle: its fan mates beside the bisector column go with it, or the
        // fan's cells between them turn over.
        if let Some(root) = try_collapse_with_fan_mates(plan, front, columns, r, c, &fewer_invalid) {
            return Some(root);
        }
    }
    None
}

/// Collapse the corner of invalid triangle `f` that closes in fastest on its opposite edge into
/// the nearer end of that edge, if the front allows it; returns the surviving root. This is a
/// bisector column overtaking the face columns in front of it along a ridge whose wall edges
/// run obliquely to it: no edge of the face shrinks much while the face turns over, and the
/// face's bottom may already be nearly flat (its area says nothing then). Merging the corner
/// that closes in, rather than waiting for it to cross, keeps the bisector column moving.
fn collapse_crossing_corner(
    plan: &mut SlabPlan,
    front: &Front,
    f: usize,
    columns: &Columns,
    points: &[DVec3],
) -> Option<u32> {
    let (v, ends) = crossing_corner(plan, front, f, columns, points)?;
    let w = ends.into_iter().find(|&w| can_merge(plan, front, columns, v, w))?;
    collapse(plan, columns, v, w);
    Some(plan.merges.root(v))
}

/// Whether roots `v` and `w` may merge: both moving, the front stays a manifold, and they are
/// not two columns of one fan or columns that slide differently.
fn can_merge(plan: &SlabPlan, front: &Front, columns: &Columns, v: u32, w: u32) -> bool {
    !columns.is_fan_edge(v as usize, w as usize) && can_merge_fan_mate(plan, front, columns, v, w)
}

/// Merge root `c` into root `r`, and with it the fan mates of `c` that can follow; undo it all
/// unless `accept` holds for the merged group. Returns the surviving root.
fn try_collapse_with_fan_mates(
    plan: &mut SlabPlan,
    front: &Front,
    columns: &Columns,
    r: u32,
    c: u32,
    accept: &impl Fn(&SlabPlan, &[u32]) -> bool,
) -> Option<u32> {
    let mut mates = Vec::new();
    front.fan_mates(columns, c as usize, &mut mates);
    if mates.is_empty() {
        return None;
    }
    let saved = plan.clone();
    collapse(plan, columns, r, c);
    for &m in &mates {
        let (root, m) = (plan.merges.root(r), m as u32);
        if can_merge_fan_mate(plan, front, columns, root, m) {
            collapse(plan, columns, root, m);
        }
    }
    let root = plan.merges.root(r);
    let group: Vec<u32> = plan.merges.group(root).collect();
    if accept(plan, &group) {
        return Some(root);
    }
    *plan = saved;
    None
}

/// Whether roots `v` and `m` may merge though a fan edge may join them (a fan mate following its
/// column into a bisector): both moving, sliding alike, and the front stays a manifold.
fn can_merge_fan_mate(plan: &SlabPlan, front: &Front, columns: &Columns, v: u32, m: u32) -> bool {
    moving_roots(plan, v, m)
        && columns.slide[v as usize] == columns.slide[m as usize]
        && plan.merges.can_collapse(front, v, m)
}

/// The corner of triangle `f` (after the merges so far) whose height over its opposite edge
/// falls most this layer, if below
/// [`TUNING.entropy.closing_in`](super::tuning::Entropy::closing_in) of what it was: the corner and
/// the ends of its edge, nearer end (at the proposed tops) first. Heights are seen along the face's
/// mean column direction. Only a face spanning a ridge, and not a sliver on the wall, has one.
fn crossing_corner(
    plan: &SlabPlan,
    front: &Front,
    f: usize,
    columns: &Columns,
    points: &[DVec3],
) -> Option<(u32, [u32; 2])> {
    let face = plan.merges.resolved_face(front, f)?;
    let &[a, b, c] = face.nodes() else { return None };
    // Only along a ridge: a bisector column (a larger extrusion scale) among face columns.
    let scales = [a, b, c].map(|r| columns.scale[r as usize]);
    if scales.iter().fold(0.0f64, |m, &s| m.max(s))
        < TUNING.entropy.ridge_scale * scales.iter().fold(f64::INFINITY, |m, &s| m.min(s))
    {
        return None;
    }
    let bottom = |r: u32| points[columns.node[r as usize] as usize];
    let top = |r: u32| plan.proposed[r as usize];
    let axis =
        (columns.dir[a as usize] + columns.dir[b as usize] + columns.dir[c as usize]).normalize_or_zero();
    let wall = |r: u32| columns.base[r as usize];
    let height_ratio = |v: u32, [w0, w1]: [u32; 2]| {
        let at_bottom = corner_height(axis, bottom(v), bottom(w0), bottom(w1));
        let at_top = corner_height(axis, top(v), top(w0), top(w1));
        // A sliver on the wall (a long edge with its corner close by) turns over by the least
        // difference between its columns: that is no meeting of fronts.
        let sliver = corner_height(axis, wall(v), wall(w0), wall(w1))
            < TUNING.entropy.sliver * wall(w0).distance(wall(w1));
        if at_bottom > 0.0 && !sliver {
            at_top / at_bottom
        } else {
            f64::INFINITY
        }
    };
    let (_, v, mut ends) = [(a, [b, c]), (b, [c, a]), (c, [a, b])]
        .into_iter()
        .map(|(v, e)| (height_ratio(v, e), v, e))
        .filter(|&(ratio, _, _)| ratio < TUNING.entropy.closing_in)
        .min_by(|x, y| x.0.total_cmp(&y.0))?;
    let nearer = |w: u32| top(v).distance_squared(top(w));
    ends.sort_by(|x, y| nearer(*x).total_cmp(&nearer(*y)));
    Some((v, ends))
}

/// Signed distance of corner `v` from the line through `a` and `b`, seen along `axis`
/// (positive on the side where `a`, `b`, `v` turn counter-clockwise about it).
fn corner_height(axis: DVec3, v: DVec3, a: DVec3, b: DVec3) -> f64 {
    let edge = b - a;
    let across = edge.cross(axis).length();
    if across == 0.0 {
        return 0.0;
    }
    axis.dot(edge.cross(v - a)) / across
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
        .filter(|&(ratio, _, _)| ratio < TUNING.entropy.meeting_ratio)
        .min_by(|x, y| x.0.total_cmp(&y.0))?;
    collapse(plan, columns, a, b);
    Some(plan.merges.root(a))
}

/// Mend invalid face `f` by a merge along one of its edges that leaves every cell around the
/// merged column valid; returns the surviving root. The last repair before stopping columns:
/// at a saddle corner (a fin's trailing edge at the body, a step's end at a side wall) a
/// corner's fan and the bisector column beside it converge with no edge crushed, no bisector
/// passed and neither column late, and their cell turns inside out. Only where one column
/// absorbs the other (the larger scale survives, see [`survivor`]: two of a kind would meet in
/// the middle, off the offset; two ridge columns along a fin junction folded the arrow's
/// front), and only between wall points that the two columns' travel spans (fronts collapsing
/// in a closed box bring columns from far apart next to each other: merging those folded the
/// front onto itself).
pub(super) fn merge_to_mend(
    plan: &mut SlabPlan,
    front: &Front,
    f: usize,
    columns: &Columns,
    invalid_cells: &impl Fn(&SlabPlan, &[u32]) -> usize,
) -> Option<u32> {
    let face = plan.merges.resolved_face(front, f)?;
    let n = face.nodes();
    let base = |c: u32| columns.base[c as usize];
    let travel = |c: u32| plan.proposed[c as usize].distance(base(c));
    let near = |a: u32, b: u32| base(a).distance(base(b)) <= travel(a) + travel(b);
    let edges: Vec<(u32, u32)> =
        (0..n.len()).map(|i| (n[i], n[(i + 1) % n.len()])).filter(|&(a, b)| near(a, b)).collect();
    for (a, b) in edges {
        if !can_merge(plan, front, columns, a, b) || survivor(columns, a, b).2 {
            continue;
        }
        if try_collapse(plan, columns, a, b, &|plan, group| invalid_cells(plan, group) == 0) {
            tracing::debug!(f, a, b, at = ?columns.base[a as usize], "invalid cell mended by a merge");
            return Some(plan.merges.root(a));
        }
    }
    None
}

/// Where two faces whose tops cross share a front edge after the merges, fronts from two walls
/// met along that edge and close a V over it (the crease of a groove whose mouth the layers
/// fill: each lip's fan strip rises from the crease, and the exact fronts meet there at a cusp,
/// nearly closed right after they meet). The V's columns on both sides of each end of that edge
/// meet there: they merge into the edge's column, whose top goes to the middle of theirs (on the
/// medial surface, where the fronts cross next), when that uncrosses the faces (`crosses`) and
/// leaves every cell around valid. `pairs` are all the pairs crossing over a shared edge that
/// close at once (the V along a whole groove): each end of the crease that several pairs share
/// takes the columns of all of them, and the crease rises alike along its whole length, where
/// raising it pair by pair stepped it up beside the pair next to it, whose cell turned over.
/// Returns the columns whose tops moved, or `None` (the plan as it was) where the faces share no
/// edge or the merge does not help.
pub(super) fn merge_into_crease(
    plan: &mut SlabPlan,
    front: &Front,
    columns: &Columns,
    pairs: &[(usize, usize)],
    crosses: &impl Fn(&SlabPlan) -> bool,
    invalid_cells: &impl Fn(&SlabPlan, &[u32]) -> usize,
) -> Option<Vec<u32>> {
    // Each V column merges into one end (the first pair's that names it).
    let mut meeting_at: Vec<(u32, Vec<u32>)> = Vec::new();
    for &pair in pairs {
        for (r, meeting) in crease_meetings(plan, front, pair, pairs.len() == 1)? {
            let fresh: Vec<u32> =
                meeting.into_iter().filter(|c| !meeting_at.iter().any(|m| m.1.contains(c))).collect();
            match meeting_at.iter_mut().find(|m| m.0 == r) {
                Some((_, all)) => all.extend(fresh),
                None if !fresh.is_empty() => meeting_at.push((r, fresh)),
                None => {}
            }
        }
    }
    if meeting_at.is_empty() {
        return None;
    }
    // Each end of the crease, its top and the middle of its meeting columns' tops.
    let top = |c: u32| plan.proposed[c as usize];
    let meetings: Vec<(u32, DVec3, DVec3)> = meeting_at
        .iter()
        .map(|(r, meeting)| {
            (*r, top(*r), meeting.iter().map(|&c| top(c)).sum::<DVec3>() / meeting.len() as f64)
        })
        .collect();
    let saved = plan.clone();
    for (r, meeting) in &meeting_at {
        for &c in meeting {
            let c = plan.merges.root(c);
            if c == *r {
                continue;
            }
            if !can_merge(plan, front, columns, *r, c) {
                *plan = saved;
                return None;
            }
            merge_as(plan, columns, (*r, c, false));
        }
    }
    // Every column whose top moved: the crease's ends carry the tops of the columns merged into
    // them, now and before.
    let group: Vec<u32> = meetings.iter().flat_map(|m| plan.merges.group(m.0)).collect();
    // The highest meeting point, from the middle of the V down to the crease's top, that keeps
    // every cell valid: the crease's column carries cells below it that a jump up turns over,
    // the V's columns fan cells that a drop onto the crease does.
    for part in TUNING.entropy.meeting_heights {
        for &(r, crease_top, middle) in &meetings {
            plan.proposed[r as usize] = columns.slide[r as usize].project(crease_top.lerp(middle, part));
        }
        let (crossing, invalid) = (crosses(plan), invalid_cells(plan, &group));
        tracing::trace!(?pairs, part, crossing, invalid, "a V's merge into its crease tried");
        if !crossing && invalid == 0 {
            redirect_creases(plan, columns, &meeting_at);
            tracing::debug!(
                ?pairs,
                ?group,
                part,
                "crossing faces over a shared edge: merged into the crease"
            );
            return Some(group);
        }
    }
    *plan = saved;
    None
}

/// Once a V has closed on its crease, each end goes on along the mean direction `m` of the V's
/// columns it took, as the meeting line of their offsets does: at `1 / (d . m)` for columns
/// along `d` (a concave ridge's bisector rule; their mean scale over the mean of `d . m`). The
/// crease column's own scale (a narrow groove's bottom bisector: 1 / sin of half its angle)
/// ran it ever farther ahead of the front above the closed V.
fn redirect_creases(plan: &mut SlabPlan, columns: &Columns, meetings: &[(u32, Vec<u32>)]) {
    for (r, meeting) in meetings {
        let v: Vec<usize> = meeting.iter().map(|&c| c as usize).collect();
        let Some(dir) = v.iter().map(|&c| columns.dir[c]).sum::<DVec3>().try_normalize() else { continue };
        let mean = |x: &dyn Fn(usize) -> f64| v.iter().map(|&c| x(c)).sum::<f64>() / v.len() as f64;
        let cos = mean(&|c| columns.dir[c].dot(dir));
        let scale = if cos > 0.0 { (mean(&|c| columns.scale[c]) / cos).max(1.0) } else { continue };
        plan.redirected.push((*r, dir, scale));
    }
}

/// The crossing pairs of `pairs` that close a V over a shared edge ([`merge_into_crease`]),
/// grouped along their creases: two pairs are in one group when an end of one's crease is an
/// end of the other's or next to one on the front. Each group is one V closing along its crease
/// (the crease edges between its pairs may not cross yet, their neighbours on both sides do).
pub(super) fn crease_groups(
    plan: &SlabPlan,
    front: &Front,
    pairs: &[(usize, usize)],
) -> Vec<Vec<(usize, usize)>> {
    /// A creased pair, its crease's ends, and those ends with the roots next to them (sorted).
    struct Creased {
        pair: (usize, usize),
        ends: Vec<u32>,
        near: Vec<u32>,
    }
    let mut creased: Vec<Creased> = Vec::new();
    let mut beside = Vec::new();
    for &pair in pairs {
        let Some(meetings) = crease_meetings(plan, front, pair, false).filter(|m| !m.is_empty()) else {
            continue;
        };
        let ends: Vec<u32> = meetings.iter().map(|m| m.0).collect();
        let mut near: Vec<u32> = ends.clone();
        for &r in &ends {
            for c in plan.merges.group(r) {
                beside.clear();
                front.neighbours(c as usize, &mut beside);
                near.extend(beside.iter().map(|&n| plan.merges.root(n as u32)));
            }
        }
        near.sort_unstable();
        near.dedup();
        creased.push(Creased { pair, ends, near });
    }
    // Connected components of "an end of one is near the other's" (union-find).
    let mut parent: Vec<usize> = (0..creased.len()).collect();
    let find = |parent: &mut Vec<usize>, mut i: usize| {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    };
    for (i, a) in creased.iter().enumerate() {
        for (j, b) in creased.iter().enumerate().skip(i + 1) {
            if a.ends.iter().any(|r| b.near.binary_search(r).is_ok()) {
                let (x, y) = (find(&mut parent, i), find(&mut parent, j));
                parent[x.max(y)] = x.min(y);
            }
        }
    }
    let mut groups: Vec<Vec<(usize, usize)>> = Vec::new();
    let mut slot_of: Vec<Option<usize>> = vec![None; creased.len()];
    for (i, c) in creased.iter().enumerate() {
        let root = find(&mut parent, i);
        let slot = *slot_of[root].get_or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[slot].push(c.pair);
    }
    groups
}

/// The ends of the edge that crossing faces `(f, g)` share (after the merges), each with the
/// columns of the V beside it on both faces; `None` where they share no edge (unless
/// `or_corner`: then their one shared corner, [`vertex_meeting`]), an empty list where no end
/// has V columns on both sides.
fn crease_meetings(
    plan: &SlabPlan,
    front: &Front,
    (f, g): (usize, usize),
    or_corner: bool,
) -> Option<Vec<(u32, Vec<u32>)>> {
    let (pf, pg) = (plan.merges.resolved_face(front, f)?, plan.merges.resolved_face(front, g)?);
    let Some(crease) = shared_edge(pf.nodes(), pg.nodes()) else {
        return vertex_meeting(plan, &pf, &pg).filter(|_| or_corner).map(|m| vec![m]);
    };
    // Each corner of a face off the crease, with the end of the crease beside it (the nearer
    // one for a triangle's apex).
    let off_crease = |p: &Polygon| -> Vec<(u32, u32)> {
        let n = p.nodes();
        let top = |c: u32| plan.proposed[c as usize];
        (0..n.len())
            .filter(|&i| !crease.contains(&n[i]))
            .filter_map(|i| {
                let beside = [n[(i + 1) % n.len()], n[(i + n.len() - 1) % n.len()]];
                let near = |r: &u32| top(*r).distance_squared(top(n[i]));
                let r = beside
                    .into_iter()
                    .filter(|r| crease.contains(r))
                    .min_by(|a, b| near(a).total_cmp(&near(b)))?;
                Some((n[i], r))
            })
            .collect()
    };
    let (sides_f, sides_g) = (off_crease(&pf), off_crease(&pg));
    let at =
        |side: &[(u32, u32)], r: u32| side.iter().filter(|m| m.1 == r).map(|m| m.0).collect::<Vec<u32>>();
    Some(
        crease
            .into_iter()
            .filter_map(|r| {
                let (a, b) = (at(&sides_f, r), at(&sides_g, r));
                (!a.is_empty() && !b.is_empty()).then(|| (r, a.into_iter().chain(b).collect()))
            })
            .collect(),
    )
}

/// Where two crossing faces share one corner and no edge (two triangles beside a ridge column,
/// one on each wall, whose far corners passed its bisector with no collapse), the V closes at
/// that corner: from each face, the corner beside it nearest the other face meets there.
fn vertex_meeting(plan: &SlabPlan, pf: &Polygon, pg: &Polygon) -> Option<(u32, Vec<u32>)> {
    let shared: Vec<u32> = pf.nodes().iter().copied().filter(|c| pg.nodes().contains(c)).collect();
    let &[r] = shared.as_slice() else { return None };
    let top = |c: u32| plan.proposed[c as usize];
    let centre = |p: &Polygon| top_centre(plan, p);
    let nearest_beside = |p: &Polygon, other: DVec3| {
        let n = p.nodes();
        let i = n.iter().position(|&c| c == r)?;
        [n[(i + 1) % n.len()], n[(i + n.len() - 1) % n.len()]]
            .into_iter()
            .min_by(|&a, &b| top(a).distance_squared(other).total_cmp(&top(b).distance_squared(other)))
    };
    Some((r, vec![nearest_beside(pf, centre(pg))?, nearest_beside(pg, centre(pf))?]))
}

/// The mean of the proposed tops of polygon `p`'s columns.
fn top_centre(plan: &SlabPlan, p: &Polygon) -> DVec3 {
    p.nodes().iter().map(|&c| plan.proposed[c as usize]).sum::<DVec3>() / p.nodes().len() as f64
}

/// Where two faces whose tops cross are fan strips of a convex ridge or corner (or one of them
/// is), fronts met head on over them: the lips' fans over a groove's filled mouth, a trailing
/// edge's fan leaning over the wall below it. A fan column's characteristic ends where another
/// front reached its top first, so on each fan edge of the two faces the column nearer the
/// other face merges into its fan mate, which keeps its top: the fan shrinks to the columns the
/// other front has not reached, and its wall point's stack goes on in them. The guard tests the
/// faces around again; the next strip retreats in turn if it crosses too. Returns the columns
/// whose cells changed, or `None` (the plan as it was) where neither face has a fan edge whose
/// columns can merge, or the merges leave more invalid cells around than there were.
pub(super) fn retreat_fans(
    plan: &mut SlabPlan,
    front: &Front,
    columns: &Columns,
    (f, g): (usize, usize),
    invalid_cells: &impl Fn(&SlabPlan, &[u32]) -> usize,
) -> Option<Vec<u32>> {
    let (pf, pg) = (plan.merges.resolved_face(front, f)?, plan.merges.resolved_face(front, g)?);
    let top = |c: u32| plan.proposed[c as usize];
    let centre = |p: &Polygon| top_centre(plan, p);
    let mut retreats: Vec<(u32, u32)> = Vec::new();
    for (p, other) in [(&pf, centre(&pg)), (&pg, centre(&pf))] {
        let n = p.nodes();
        for i in 0..n.len() {
            let (a, b) = (n[i], n[(i + 1) % n.len()]);
            if columns.is_fan_edge(a as usize, b as usize) {
                let near = |c: u32| top(c).distance_squared(other);
                retreats.push(if near(a) < near(b) { (b, a) } else { (a, b) });
            }
        }
    }
    let roots: Vec<u32> = retreats.iter().flat_map(|&(keep, drop)| [keep, drop]).collect();
    let around = |plan: &SlabPlan| -> Vec<u32> {
        let mut group: Vec<u32> =
            roots.iter().flat_map(|&c| plan.merges.group(plan.merges.root(c))).collect();
        group.sort_unstable();
        group.dedup();
        group
    };
    let before = invalid_cells(plan, &around(plan));
    let saved = plan.clone();
    let mut merged = false;
    for (keep, drop) in retreats {
        let (keep, drop) = (plan.merges.root(keep), plan.merges.root(drop));
        if can_merge_fan_mate(plan, front, columns, keep, drop) {
            merge_as(plan, columns, (keep, drop, false));
            merged = true;
        }
    }
    let group = around(plan);
    let after = invalid_cells(plan, &group);
    tracing::trace!(f, g, merged, before, after, "fans' retreat tried");
    if !merged || after > before {
        *plan = saved;
        return None;
    }
    tracing::debug!(f, g, at = ?columns.base[pf.nodes()[0] as usize], "fronts met head on: fans retreated");
    Some(group)
}

/// The edge two polygons share (consecutive in both), if any.
fn shared_edge(a: &[u32], b: &[u32]) -> Option<[u32; 2]> {
    (0..a.len()).map(|i| [a[i], a[(i + 1) % a.len()]]).find(|&[x, y]| {
        (0..b.len()).any(|j| {
            let (u, v) = (b[j], b[(j + 1) % b.len()]);
            (u, v) == (x, y) || (u, v) == (y, x)
        })
    })
}

/// Which of roots `a` and `b` survives their merge, which goes, and whether the survivor
/// moves to the middle: the bisector column (larger scale) survives; equals meet in the middle.
fn survivor(columns: &Columns, a: u32, b: u32) -> (u32, u32, bool) {
    let (sa, sb) = (columns.scale[a as usize], columns.scale[b as usize]);
    if sa > sb * TUNING.entropy.same_scale {
        (a, b, false)
    } else if sb > sa * TUNING.entropy.same_scale {
        (b, a, false)
    } else {
        (a.min(b), a.max(b), true)
    }
}

/// Merge roots `a` and `b` (see [`survivor`]).
pub(super) fn collapse(plan: &mut SlabPlan, columns: &Columns, a: u32, b: u32) {
    merge_as(plan, columns, survivor(columns, a, b));
}

/// Merge root `drop` into root `keep`, `keep`'s top moving to the middle of theirs if `middle`.
fn merge_as(plan: &mut SlabPlan, columns: &Columns, (keep, drop, middle): (u32, u32, bool)) {
    let (sk, sd) = (columns.scale[keep as usize], columns.scale[drop as usize]);
    let at = |c: u32| columns.base[c as usize].as_vec3();
    tracing::debug!(
        "collapse columns {keep} at {} (scale {sk:.3}) and {drop} at {} (scale {sd:.3})",
        at(keep),
        at(drop)
    );
    if middle {
        let (k, d) = (keep as usize, drop as usize);
        plan.proposed[k] = columns.slide[k].project(0.5 * (plan.proposed[k] + plan.proposed[d]));
        let dir = (columns.dir[k] + columns.dir[d]).normalize_or(columns.dir[k]);
        plan.redirected.push((keep, dir, 0.5 * (sk + sd)));
    }
    plan.merges.merge(keep, drop);
    plan.collapses += 1;
}

/// Merge roots `a` and `b` (see [`survivor`]); undo the merge (and keep the plan as it was) if a
/// cell around them turns invalid.
pub(super) fn try_collapse(
    plan: &mut SlabPlan,
    columns: &Columns,
    a: u32,
    b: u32,
    cells_valid: &impl Fn(&SlabPlan, &[u32]) -> bool,
) -> bool {
    try_merge_as(plan, columns, survivor(columns, a, b), cells_valid)
}

/// [`merge_as`], undone unless `cells_valid` holds for the merged group.
fn try_merge_as(
    plan: &mut SlabPlan,
    columns: &Columns,
    how: (u32, u32, bool),
    cells_valid: &impl Fn(&SlabPlan, &[u32]) -> bool,
) -> bool {
    let (a, b, _) = how;
    let saved = (plan.proposed[a as usize], plan.proposed[b as usize], plan.redirected.len());
    let merges_before = plan.merges.clone_groups(a, b);
    merge_as(plan, columns, how);
    let group: Vec<u32> = plan.merges.group(a).collect();
    if cells_valid(plan, &group) {
        return true;
    }
    plan.merges.restore_groups(merges_before);
    plan.proposed[a as usize] = saved.0;
    plan.proposed[b as usize] = saved.1;
    plan.redirected.truncate(saved.2);
    plan.collapses -= 1;
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layers::front::{ColumnStart, ColumnState};

    /// The ridge vertex 0 at the origin with one triangle `size` long on each wall: wall 1
    /// (y = 0, x > 0, normal +y) and wall 2 (x = 0, y > 0, normal +x).
    fn two_walls(size: f64) -> Surface {
        Surface {
            points: vec![DVec3::ZERO, size * DVec3::Z, size * DVec3::X, size * DVec3::Y],
            triangles: vec![[0, 1, 2], [0, 3, 1]],
            triangle_patch: vec![0, 0],
            patch_names: vec!["wall".into()],
        }
    }

    /// A 90-degree concave ridge along z at the origin between wall 1 (y = 0, x > 0, normal +y)
    /// and wall 2 (x = 0, y > 0, normal +x): column 0 on the ridge, column 1 at `at` on the
    /// wall with direction `dir`, both `d` out (the ridge column by its scale, on the bisector).
    fn ridge_case(at: DVec3, dir: DVec3, d: f64) -> bool {
        ridge_case_ahead(at, dir, d, TUNING.entropy.anticipation)
    }

    fn ridge_case_ahead(at: DVec3, dir: DVec3, d: f64, anticipation: f64) -> bool {
        let mut columns = Columns::default();
        let bisector = DVec3::new(1.0, 1.0, 0.0).normalize();
        for (c, (base, dir, scale)) in
            [(DVec3::ZERO, bisector, 2f64.sqrt()), (at, dir, 1.0)].into_iter().enumerate()
        {
            columns.push(ColumnStart {
                base,
                dir,
                scale,
                node: c as u32,
                layers: 0,
                wall_vertex: 0,
                slide: Default::default(),
                spec: None,
                last_step: 0.0,
            });
        }
        let plan = SlabPlan::moving_to(vec![bisector * 2f64.sqrt() * d, at + dir * d]);
        let surface = two_walls(1.0);
        assert_eq!((surface.triangle_normal(0), surface.triangle_normal(1)), (DVec3::Y, DVec3::X));
        let topology = Topology::new(&surface);
        let walls = VertexWalls::new(&surface, &topology, |_| true);
        crosses_bisector(&plan, &columns, &[DVec3::ZERO, at], &walls, 0, 1, anticipation)
    }

    #[test]
    fn a_face_column_passes_the_bisector_when_the_other_wall_is_nearer() {
        let at = DVec3::new(0.1, 0.0, 0.0);
        assert!(!ridge_case(at, DVec3::Y, 0.04), "0.4 of the way: one more step leaves it short");
        assert!(ridge_case(at, DVec3::Y, 0.1), "on the bisector");
        // Short of it by less than what it closed in on it this layer.
        assert!(ridge_case(at, DVec3::Y, 0.09));
        // A column not of these walls (a saddle fan's), and one along the ridge, never cross.
        assert!(!ridge_case(at, DVec3::Z, 0.2));
        assert!(!ridge_case(DVec3::new(0.0, 0.0, 0.1), DVec3::Y, 0.2));
        // To mend a cell, a column two approaches short of the bisector merges, not three.
        assert!(ridge_case_ahead(at, DVec3::Y, 0.04, TUNING.entropy.repair_anticipation));
        assert!(!ridge_case_ahead(at, DVec3::Y, 0.02, TUNING.entropy.repair_anticipation));
    }

    /// Lateness (in layer heights) of a column from `bottom` to `top` at its layer `k` of
    /// uniform 0.1-high layers, over [`two_walls`] extended far out.
    fn lateness_case(bottom: DVec3, top: DVec3, k: u32) -> f64 {
        let spec = crate::config::LayerSpec::fixed(0.1, 1.0, 20);
        let mut columns = Columns::default();
        columns.push(ColumnStart {
            base: bottom,
            dir: (top - bottom).normalize(),
            scale: 1.0,
            node: 0,
            layers: k - 1,
            wall_vertex: 0,
            slide: Default::default(),
            spec: Some(spec),
            last_step: 0.1,
        });
        let plan = SlabPlan::moving_to(vec![top]);
        let surface = two_walls(10.0);
        let topology = Topology::new(&surface);
        let walls = VertexWalls::new(&surface, &topology, |_| true);
        lateness(&plan, &columns, &[bottom], &walls, 0, k)
    }

    #[test]
    fn a_column_passing_the_other_walls_offset_is_late_and_a_chord_is_not() {
        // On wall 1 (y = 0) 0.25 from wall 2 (x = 0), moving up +y: layer 2 (0.1 to 0.2) is on
        // time, layer 3 (0.2 to 0.3) ends 0.05 nearer wall 2 than its distance, and fell behind
        // by as much: half a layer late, plus half anticipated.
        let at = |d: f64| DVec3::new(0.25, d, 1.0);
        assert_eq!(lateness_case(at(0.1), at(0.2), 2), 0.0);
        assert!((lateness_case(at(0.2), at(0.3), 3) - 1.0).abs() < 1e-9);
        // Late by as much at its bottom as at its top (a split column's chord): not overtaken.
        let chord = |d: f64| DVec3::new(2.0, d - 0.05, 1.0);
        assert_eq!(lateness_case(chord(0.2), chord(0.3), 3), 0.0);
    }

    /// Ridge columns 0, 1, 2 along x at y = 0 and face columns 3 (x = 0.5) and 4 (x = 1.5) at
    /// y = 1, in triangles (0, 1, 3), (3, 1, 4), (1, 2, 4); every top 0.1 up the ridge's
    /// bisector, so the ridge columns' tops lie on a line. Column 3 has merged into 0.
    #[test]
    fn a_merge_that_would_fold_the_front_along_a_ridge_is_seen() {
        let bottoms =
            [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (0.5, 1.0), (1.5, 1.0)].map(|(x, y)| DVec3::new(x, y, 0.0));
        let columns = Columns::rising(&bottoms, None);
        let mut front = Front::default();
        for t in [[0, 1, 3], [3, 1, 4], [1, 2, 4]] {
            front.push(&t, 0, None);
        }
        front.index_columns(5);
        let up = DVec3::new(0.0, 0.1, 0.1);
        let mut plan = SlabPlan::moving_to(bottoms.iter().map(|&b| DVec3::new(b.x, 0.0, 0.0) + up).collect());
        plan.merges.merge(0, 3);
        // Into 2: triangle (3, 1, 4) becomes (0, 1, 2), three tops on a line.
        assert_eq!(flattened_if_merged(&plan, &front, &columns, &bottoms, 2, 4), 1);
        // Into 1: it keeps two corners and vanishes, and so does (1, 2, 4): nothing left flat.
        assert_eq!(flattened_if_merged(&plan, &front, &columns, &bottoms, 1, 4), 0);
    }

    /// A ridge along x (columns 0-4 at y = 0) between two walls of face columns (5-8 at y = 1,
    /// 9-12 at y = -1): their bottoms and the front over them.
    fn ridge_between_walls() -> (Vec<DVec3>, Front) {
        let ridge = (0..5).map(|i| DVec3::new(i as f64, 0.0, 0.0));
        let side = |y: f64| (0..4).map(move |i| DVec3::new(i as f64 + 0.5, y, 0.0));
        let bottoms: Vec<DVec3> = ridge.chain(side(1.0)).chain(side(-1.0)).collect();
        let mut front = Front::default();
        for i in 0..4u32 {
            let (r, a, b) = (i, 5 + i, 9 + i);
            front.push(&[r, r + 1, a], 0, None);
            front.push(&[r + 1, b, r], 0, None);
            if i < 3 {
                front.push(&[r + 1, a + 1, a], 0, None);
                front.push(&[r + 1, b, b + 1], 0, None);
            }
        }
        // Indexed for two more columns, off the front (merged ones in a test).
        front.index_columns(bottoms.len() + 2);
        (bottoms, front)
    }

    /// The ridge and walls of [`ridge_between_walls`], every column rising by 0.1; face columns
    /// 6 and 7 beside ridge column 2 merge into ridge columns 1 and 3, leaving the face (2, 7, 6)
    /// flat on the ridge.
    #[test]
    fn a_face_flattened_along_a_ridge_by_merges_both_ways_is_collapsed() {
        let (bottoms, front) = ridge_between_walls();
        let columns = Columns::rising(&bottoms, Some(crate::config::LayerSpec::fixed(0.01, 1.2, 10)));
        let mut plan = SlabPlan::moving_to(bottoms.iter().map(|&b| b + 0.1 * DVec3::Z).collect());
        plan.merges.merge(1, 6);
        plan.merges.merge(3, 7);
        let flat = |plan: &SlabPlan| {
            (0..front.len()).filter(|&f| plan.merges.face_roots(&front, f).len() >= 3).any(|f| {
                area_ratio(plan, &front, f, &columns, &bottoms).is_some_and(|a| a < TUNING.entropy.flat_top)
            })
        };
        assert!(flat(&plan), "the face between the two merges lies flat on the ridge");
        assert_eq!(merge_flat_tops(&mut plan, &front, &columns, &bottoms, 1, |_, _| 0), 1);
        assert!(!flat(&plan));
        let root = |c: u32| plan.merges.root(c);
        assert!(root(2) == root(1) || root(2) == root(3), "the middle ridge column merged");
        assert_eq!(plan.proposed[root(2) as usize].y, 0.0, "on the ridge's bisector");
    }

    /// The ridge and walls of [`ridge_between_walls`], every column rising by 0.1 but face
    /// column 6, whose top comes to lie `gap` from the ridge between ridge columns 1 and 2: when
    /// those carry merged columns (a crease), the face (1, 2, 6) is a cap at 6 whatever its area
    /// (at a gap of 0.06, 166 degrees, the top keeps 6% of the bottom's) and is merged into the
    /// crease; a face merely thin, or a cap off a crease, is left alone.
    #[test]
    fn a_face_whose_top_is_a_cap_on_a_crease_is_collapsed_and_a_thin_one_is_not() {
        let spec = crate::config::LayerSpec::fixed(0.01, 1.2, 10);
        let (bottoms, front) = ridge_between_walls();
        let plain = Columns::rising(&bottoms, Some(spec));
        // Two columns off the front, merged into ridge columns 1 and 2 in an earlier layer.
        let mut crease = Columns::rising(&[bottoms.clone(), vec![DVec3::Z; 2]].concat(), Some(spec));
        crease.state[13] = ColumnState::MergedInto(1);
        crease.state[14] = ColumnState::MergedInto(2);
        let merged = |columns: &Columns, gap: f64| {
            let mut tops: Vec<DVec3> = (0..columns.len()).map(|c| columns.base[c] + 0.1 * DVec3::Z).collect();
            tops[6] = DVec3::new(1.5, gap, 0.1);
            let mut plan = SlabPlan::moving_to(tops);
            let n = merge_flat_tops(&mut plan, &front, columns, &columns.base, 1, |_, _| 0);
            let root = plan.merges.root(6);
            assert!(n == 0 || root == 1 || root == 2, "the cap's middle corner joins the crease");
            n
        };
        assert_eq!(merged(&crease, 0.06), 1, "a cap on the crease: 166 degrees at column 6's top");
        assert_eq!(merged(&crease, 0.3), 0, "118 degrees: left alone");
        assert_eq!(merged(&plain, 0.06), 0, "a cap between columns that carry none: no crease");
    }

    /// A corner overtaking its opposite edge while no edge of the triangle shrinks much.
    #[test]
    fn corner_height_sees_a_corner_crossing_its_edge() {
        let (v, a, b) = (DVec3::new(0.0, -0.3, 0.0), DVec3::new(1.0, 0.0, 0.0), DVec3::new(-1.0, 0.0, 0.0));
        let up = DVec3::Z;
        assert!((corner_height(up, v, a, b) - 0.3).abs() < 1e-12);
        // Seen along a tilted axis, heights scale but keep their sign.
        assert!(corner_height((up + 0.3 * DVec3::Y).normalize(), v, a, b) > 0.0);
        let crossed = v + up + 0.4 * DVec3::Y;
        assert!(corner_height(up, crossed, a + up, b + up) < 0.0);
        // Its edges from v keep most of their length along the bottom edges.
        assert!(shrink_ratio(v, a, crossed, a + up) > 0.6);
    }

    #[test]
    fn shrink_ratio_tells_parallel_converging_and_crossed() {
        let (a, b) = (DVec3::ZERO, DVec3::X);
        let up = DVec3::Y;
        assert_eq!(shrink_ratio(a, b, a + up, b + up), 1.0);
        assert_eq!(shrink_ratio(a, b, a + up + 0.25 * DVec3::X, b + up - 0.25 * DVec3::X), 0.5);
        assert!(shrink_ratio(a, b, b + up, a + up) < 0.0);
    }

    #[test]
    fn shared_edge_is_an_edge_of_both_polygons_either_way_round() {
        // A quad and a triangle on the edge 2-3, the triangle running it the other way.
        assert_eq!(shared_edge(&[1, 2, 3, 4], &[3, 2, 7]), Some([2, 3]));
        assert_eq!(shared_edge(&[1, 2, 3, 4], &[4, 1, 9]), Some([4, 1]));
        // Two corners in common that are not an edge of one of them (a quad's diagonal).
        assert_eq!(shared_edge(&[1, 2, 3, 4], &[1, 3, 8]), None);
        assert_eq!(shared_edge(&[1, 2, 3], &[4, 5, 6]), None);
    }
}
