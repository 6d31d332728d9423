//! Thin gaps: where the wall faces itself across less than two stack thicknesses, the fronts
//! from the two sides meet at the medial surface between them. The march stops them a layer
//! short of it, where the climb from their wall points stalls ([`room_above`]), and the
//! crossing guard where they would cross all the same. Such a stack is as thick as the gap
//! allows, so it counts as reached: the medial surface is the bisector of the two walls.
//!
//! A column the march stopped at a gap is gap-limited. Another that stopped early is
//! gap-limited when the front above its top has no room for the layer it could not build:
//! climbing the exact wall distance from the top (away from the nearest wall points, along a
//! shock where two meet) gains less than that layer before the climb stalls at the medial
//! surface of a gap (where two walls within
//! [`TUNING.gaps.facing_angle_deg`](super::tuning::Gaps::facing_angle_deg) of facing each other
//! meet: across a slot, at a slot's bottom corners and lips, in a narrow wedge). Where the front
//! closes on an axis, as in a bore, two layers. The fronts at a concave ridge of a wider angle go
//! on along its bisector, so a stop there is never excused.

use glam::DVec3;
use rayon::prelude::*;

use super::front::Columns;
use super::tuning::TUNING;
use crate::geometry::bvh::TriangleBvh;
use crate::surface::topology::Topology;
use crate::surface::Surface;

/// For every wall vertex of `stopped` (ids into the surface's points), whether a column of it
/// that stopped early is gap-limited; `points` are the layered mesh's points. (The columns of a
/// fan end together: on the rim of a narrow hole the fan's columns into the hole end at its
/// axis, and those along the face beside it end with them.)
pub fn gap_limited(
    surface: &Surface,
    topology: &Topology,
    columns: &Columns,
    points: &[DVec3],
    stopped: &[u32],
) -> Vec<bool> {
    let mut limited = vec![false; surface.points.len()];
    if stopped.is_empty() {
        return limited;
    }
    let bvh = TriangleBvh::new((0..surface.triangles.len()).map(|t| surface.triangle_points(t)).collect());
    let mut is_stopped = vec![false; surface.points.len()];
    for &v in stopped {
        is_stopped[v as usize] = true;
    }
    let short: Vec<(usize, bool)> = (0..columns.len())
        .into_par_iter()
        .filter(|&c| is_stopped[columns.wall_vertex[c] as usize] && stopped_early(columns, c))
        .map(|c| {
            let v = columns.wall_vertex[c] as usize;
            let planned = columns.ended_at_gap(columns.carrier(c));
            let limited = planned || {
                let edges = wall_edges_at(surface, topology, v as u32);
                reaches_medial_surface(surface, &bvh, columns, points, c, &edges)
            };
            (v, limited)
        })
        .collect();
    for (v, ok) in short {
        limited[v] |= ok;
    }
    limited
}

/// The directions of the wall edges at vertex `v` (each once per triangle using it).
fn wall_edges_at(surface: &Surface, topology: &Topology, v: u32) -> Vec<DVec3> {
    let p = surface.points[v as usize];
    let corners = topology.vertex_triangles(v).iter().flat_map(|&t| surface.triangles[t as usize]);
    corners.filter(|&w| w != v).map(|w| (surface.points[w as usize] - p).normalize_or_zero()).collect()
}

/// Whether column `c` (or the column it merged into) has fewer layers than its full count.
fn stopped_early(columns: &Columns, c: usize) -> bool {
    let carrier = columns.carrier(c);
    columns.full_count(c).is_some_and(|t| columns.layers[carrier] < t && !columns.ended_isotropic(carrier))
}

/// Whether the stack of column `c` ends within one layer of the medial surface of a gap
/// (`wall_edges`: the directions of the wall edges at its wall point).
fn reaches_medial_surface(
    surface: &Surface,
    bvh: &TriangleBvh,
    columns: &Columns,
    points: &[DVec3],
    c: usize,
    wall_edges: &[DVec3],
) -> bool {
    let (base, dir) = (columns.base[c], columns.dir[c]);
    let Some(first) = columns.spec[c].map(|s| s.first_height) else { return false };
    let carrier = columns.carrier(c);
    let k = columns.layers[carrier];
    let top = points[columns.node[carrier] as usize];
    // The layers it could not build (or, past its stack, its last one).
    let height = |j: u32| match columns.layer_height(carrier, j) {
        h if h > 0.0 => h,
        _ => columns.layer_height(carrier, k.max(1)),
    };
    let (next, after) = (height(k + 1), height(k + 2));
    let room = room_above(bvh, top, columns.dir[carrier], next + after);
    tracing::debug!(c, ?top, k, room, next, "room above a stopped stack");
    if room < next {
        return true;
    }
    // A front closing on an axis (a bore narrower than twice the stack) shrinks around it as
    // it rises: the last layer short of the axis would be crushed along the front to a small
    // fraction of its width and cannot be built (the flange's 1 mm bore: six layers reach 75%
    // of its radius, a seventh would reach 97%). Where the wall across faces back and the
    // front closes, two layers short of the medial surface is as far as it goes.
    let Some((across, t)) = bvh.first_hit(base, dir, TUNING.gaps.own_wall * first, |_| false) else {
        return false;
    };
    room < next + after
        && surface.triangle_normal(t as usize).dot(dir) < -TUNING.gaps.facing_angle_deg.to_radians().cos()
        && closes_on_an_axis(surface, bvh, (base, dir, TUNING.gaps.own_wall * first), across, wall_edges)
}

/// How much farther from the wall (up to `reach`) the front can get above `top`: climb the
/// wall distance from `top` in steps of `reach / climb_steps`, along `heading` (the column's
/// direction: a top still on the wall has no other) or away from the nearest wall point, or,
/// where that step crosses a shock (another wall point becomes the nearest), along the shock,
/// away from both; stop where no step gains `sin(facing_angle_deg / 2)` of its length (both of
/// [`TUNING.gaps`](super::tuning::Gaps)). That is the rise along the bisector of two walls at the
/// facing angle: between walls that face each other more, the climb stalls at their medial
/// surface.
pub fn room_above(bvh: &TriangleBvh, top: DVec3, mut heading: DVec3, reach: f64) -> f64 {
    let step = reach / TUNING.gaps.climb_steps;
    let least_rise = (0.5 * TUNING.gaps.facing_angle_deg).to_radians().sin() * step;
    let Some(start) = bvh.nearest(top) else { return f64::INFINITY };
    let away_from = |x: DVec3, n: &crate::geometry::bvh::Nearest| (x - n.point).normalize_or_zero();
    let (mut x, mut d) = (top, start.distance);
    // Each step gains `least_rise` at least: the climb ends.
    while d - start.distance < reach {
        let Some(near) = bvh.nearest(x) else { break };
        let gradient = away_from(x, &near);
        let mut tried = Vec::with_capacity(3);
        let mut moved = false;
        for direction in [heading, gradient] {
            if direction == DVec3::ZERO || tried.contains(&direction) {
                continue;
            }
            tried.push(direction);
            let y = x + step * direction;
            let Some(at_y) = bvh.nearest(y) else { continue };
            if at_y.distance >= d + least_rise {
                (x, d, heading, moved) = (y, at_y.distance, direction, true);
                break;
            }
            // Across a shock: along it, away from the walls on both sides.
            let along = (direction + away_from(y, &at_y)).normalize_or_zero();
            if along == DVec3::ZERO || tried.contains(&along) {
                continue;
            }
            tried.push(along);
            let z = x + step * along;
            if let Some(at_z) = bvh.nearest(z).filter(|n| n.distance >= d + least_rise) {
                (x, d, heading, moved) = (z, at_z.distance, along, true);
                break;
            }
        }
        if !moved {
            break;
        }
    }
    d - start.distance
}

/// Whether the wall across a gap (`across` along `dir` from `base`, hits nearer than `skip`
/// being the column's own wall) curves around the ray in one direction, as in a bore: rays
/// tilted both ways in that direction hit it sooner than the straight one (a chord of the
/// bore), where across a flat gap they would hit it later. The directions tried: two square to
/// each other, and those of the wall edges at the column's wall point (`wall_edges`: at a bore's
/// mouth, only the rim's direction keeps both rays in the bore; the others take one out).
fn closes_on_an_axis(
    surface: &Surface,
    bvh: &TriangleBvh,
    (base, dir, skip): (DVec3, DVec3, f64),
    across: f64,
    wall_edges: &[DVec3],
) -> bool {
    let (sin, cos) = TUNING.gaps.probe_tilt_deg.to_radians().sin_cos();
    let u = dir.any_orthonormal_vector();
    let hit = |side: DVec3| bvh.first_hit(base, cos * dir + sin * side, skip, |_| false);
    let sooner = |side: DVec3| {
        hit(side).is_some_and(|(t, tri)| t < across && surface.triangle_normal(tri as usize).dot(dir) < 0.0)
    };
    let along_edges = wall_edges.iter().map(|&e| (e - e.dot(dir) * dir).normalize_or_zero());
    let sides: Vec<DVec3> =
        [u, dir.cross(u)].into_iter().chain(along_edges).filter(|s| *s != DVec3::ZERO).collect();
    sides.into_iter().any(|side| {
        let lean = TUNING.gaps.probe_lean * dir.cross(side);
        [lean, -lean].into_iter().any(|l| sooner(side + l) && sooner(-side + l))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::LayerSpec;
    use crate::layers::front::ColumnStart;
    use crate::normals::constraint::Slide;

    /// A wall vertex at the origin facing +z, and a wall triangle over it at `height` facing
    /// down (or tilted by `tilt` radians about x).
    fn gap_case(height: f64, tilt: f64, top: f64) -> bool {
        let n = DVec3::new(0.0, tilt.sin(), -tilt.cos());
        let (u, w) = (DVec3::X, n.cross(DVec3::X));
        let centre = DVec3::new(0.0, 0.0, height);
        // Counter-clockwise about n.
        let lid = [centre - u - w, centre + u - w, centre + w];
        let floor = [DVec3::new(-1.0, -1.0, 0.0), DVec3::new(1.0, -1.0, 0.0), DVec3::new(0.0, 1.0, 0.0)];
        let surface = Surface {
            points: [floor, lid].concat(),
            triangles: vec![[0, 1, 2], [3, 4, 5]],
            triangle_patch: vec![0, 0],
            patch_names: vec!["wall".into()],
        };
        assert!(surface.triangle_normal(1).dot(n) > 0.999);
        let spec = LayerSpec::fixed(0.01, 1.2, 10);
        let mut columns = Columns::default();
        columns.push(ColumnStart {
            base: DVec3::ZERO,
            dir: DVec3::Z,
            scale: 1.0,
            node: 6,
            layers: 3,
            wall_vertex: 0,
            slide: Slide::Free,
            spec: Some(spec),
            last_step: 0.0,
        });
        let mut points = surface.points.clone();
        points.push(DVec3::new(0.0, 0.0, top));
        gap_limited(&surface, &Topology::new(&surface), &columns, &points, &[0])[0]
    }

    /// The inside of a tube of radius 1 along z (`n` sides, rings at z = -1, 0, 1), its
    /// triangles facing the axis.
    fn bore(n: usize) -> Surface {
        let mut points = Vec::new();
        for z in [-1.0, 0.0, 1.0] {
            for i in 0..n {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                points.push(DVec3::new(a.cos(), a.sin(), z));
            }
        }
        let at = |ring: usize, i: usize| (ring * n + i % n) as u32;
        let mut triangles = Vec::new();
        for ring in 0..2 {
            for i in 0..n {
                triangles.push([at(ring, i), at(ring + 1, i), at(ring, i + 1)]);
                triangles.push([at(ring, i + 1), at(ring + 1, i), at(ring + 1, i + 1)]);
            }
        }
        let count = triangles.len();
        Surface { points, triangles, triangle_patch: vec![0; count], patch_names: vec!["bore".into()] }
    }

    #[test]
    fn a_bore_closes_on_its_axis_and_a_flat_gap_does_not() {
        let tube = bore(24);
        let bvh = TriangleBvh::new((0..tube.triangles.len()).map(|t| tube.triangle_points(t)).collect());
        let (base, dir) = (DVec3::X, -DVec3::X);
        assert!(tube.triangle_normal(0).dot(DVec3::new(-1.0, -0.1, 0.0)) > 0.9, "facing the axis");
        let (across, _) = bvh.first_hit(base, dir, 1e-6, |_| false).unwrap();
        assert!((across - 2.0).abs() < 1e-9);
        assert!(closes_on_an_axis(&tube, &bvh, (base, dir, 1e-6), across, &[]));
        // Two parallel walls 2 apart: tilted rays hit the far one later.
        let flat = Surface {
            points: vec![
                DVec3::new(0.0, -5.0, -5.0),
                DVec3::new(0.0, 5.0, -5.0),
                DVec3::new(0.0, 0.0, 5.0),
                DVec3::new(-2.0, -5.0, -5.0),
                DVec3::new(-2.0, 0.0, 5.0),
                DVec3::new(-2.0, 5.0, -5.0),
            ],
            triangles: vec![[0, 2, 1], [3, 5, 4]],
            triangle_patch: vec![0, 0],
            patch_names: vec!["wall".into()],
        };
        let bvh = TriangleBvh::new((0..2).map(|t| flat.triangle_points(t)).collect());
        assert!(flat.triangle_normal(1).dot(dir) < -0.99, "the far wall faces back");
        assert!(!closes_on_an_axis(&flat, &bvh, (DVec3::ZERO, dir, 1e-6), 2.0, &[]));
        // Nor along the wall's own edges.
        let edges = [DVec3::Y, DVec3::new(0.0, 1.0, 1.0).normalize()];
        assert!(!closes_on_an_axis(&flat, &bvh, (DVec3::ZERO, dir, 1e-6), 2.0, &edges));
    }

    #[test]
    fn a_bore_closes_on_its_axis_at_its_mouth_along_its_rim() {
        let tube = bore(24);
        let bvh = TriangleBvh::new((0..tube.triangles.len()).map(|t| tube.triangle_points(t)).collect());
        // On the rim of the mouth at z = 1, across the mouth.
        let (v, dir) = (2 * 24, -DVec3::X);
        let base = tube.points[v];
        assert_eq!(base, DVec3::new(1.0, 0.0, 1.0));
        let (across, _) = bvh.first_hit(base, dir, 1e-6, |_| false).unwrap();
        let edges = wall_edges_at(&tube, &Topology::new(&tube), v as u32);
        assert!(edges.iter().any(|e| e.z.abs() < 1e-12), "an edge along the rim");
        assert!(closes_on_an_axis(&tube, &bvh, (base, dir, 1e-6), across, &edges));
    }

    /// A plane wall through `at` spanned by `u` and `v`, 40 across.
    fn plane(at: DVec3, u: DVec3, v: DVec3) -> [[DVec3; 3]; 2] {
        let (u, v) = (20.0 * u, 20.0 * v);
        [[at - u - v, at + u - v, at + u + v], [at - u - v, at + u + v, at - u + v]]
    }

    fn walls(planes: &[[[DVec3; 3]; 2]]) -> TriangleBvh {
        TriangleBvh::new(planes.iter().flatten().copied().collect())
    }

    #[test]
    fn the_climb_stalls_at_the_medial_surface_of_a_gap() {
        let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
        let tol = 0.02;
        // Two parallel walls 1 apart: 0.05 above a top at 0.45.
        let gap = walls(&[plane(DVec3::ZERO, x, y), plane(z, x, y)]);
        assert!((room_above(&gap, 0.45 * z, z, 0.2) - 0.05).abs() < tol);
        // A top still on the wall climbs along its column.
        assert!(room_above(&gap, DVec3::ZERO, z, 0.2) >= 0.2);
        // A slot 1 wide: from its bottom corner's bisector up to where the three walls are
        // equally near (0.5 from each).
        let slot = walls(&[plane(DVec3::ZERO, x, y), plane(DVec3::ZERO, y, z), plane(x, y, z)]);
        let room = room_above(&slot, DVec3::new(0.3, 0.0, 0.3), z, 0.5);
        assert!((room - 0.2).abs() < tol, "{room}");
        // Across the mouth of a slot between two lips: the fronts from the lips meet over it,
        // and a top low in the mouth has little room.
        let lips = walls(&[plane(-20.0 * x, x, y), plane(20.0 * x + x, x, y)]);
        assert!(room_above(&lips, DVec3::new(0.45, 0.0, 0.01), z, 0.2) < 0.1);
    }

    #[test]
    fn the_climb_goes_on_along_a_concave_ridge_and_a_wedge_wider_than_facing_walls() {
        let (x, y) = (DVec3::X, DVec3::Y);
        for (opening, stalls) in [(90.0f64, false), (40.0, false), (20.0, true)] {
            // A wedge along y, its faces at +-opening/2 from the bisector (x).
            let half = (0.5 * opening).to_radians();
            let (a, b) = (DVec3::new(half.cos(), 0.0, half.sin()), DVec3::new(half.cos(), 0.0, -half.sin()));
            let wedge = walls(&[plane(20.0 * a, a, y), plane(20.0 * b, b, y)]);
            let top = 0.3 * x + 0.02 * DVec3::Z;
            let room = room_above(&wedge, top, DVec3::Z, 0.2);
            assert_eq!(room < 0.1, stalls, "opening {opening}: room {room}");
        }
    }

    #[test]
    fn a_stack_stopped_half_way_across_a_gap_is_limited_by_it() {
        // Three layers from 0.01 by 1.2 reach 0.0364; the fourth would add 0.0173.
        assert!(gap_case(0.1, 0.0, 0.0364), "0.054 reaches the middle of a 0.1 gap");
        assert!(!gap_case(0.2, 0.0, 0.0364), "a 0.2 gap: stopped well short of its middle");
        assert!(!gap_case(0.1, 1.0, 0.0364), "a wall at 57 degrees does not face it");
        assert!(gap_case(0.1, 0.4, 0.0364), "a wall at 23 degrees does");
    }
}
