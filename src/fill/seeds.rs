//! The first core points above the front (no size jump at the layer top): a point over
//! every front vertex at the height of the last layer under it, leaning from the front's normal
//! towards the column's last step where the vertex tops a column's prisms.
//! Left to itself, the mesher's Delaunay refinement puts the fourth node of the tetrahedron on a
//! front triangle wherever its radius-edge rule lands it (about 0.7 of the last layer height on
//! fandisk and the Onera M6); with a point above every vertex, that node is one of them and the
//! first core cell is as tall as the layer below it.
//!
//! A seed is kept only where it is plainly inside the region: its clearance to every boundary
//! triangle is a good part of its height, nothing crosses the way up to it, and no other seed
//! is close (two fronts facing each other across a gap, or a concave fold of the front, would
//! put seeds on top of each other).

use super::{ClosedBoundary, FrontLayer, MARKER_FRONT};
use crate::geometry::bvh::{box_distance_squared, TriangleBvh};
use crate::geometry::intersect::segment_triangle;
use crate::geometry::{triangle_area_vector, Aabb, DVec3};

/// A seed's height over its vertex in the local front size (mean boundary edge length there):
/// at least this, so that a thin last layer does not make flat tetrahedra (the jump is then the
/// layers', which end too thin for isotropic cells). An apex 0.3 edges over an equilateral base
/// still makes dihedral angles of 46 to 103 degrees; at 0.5 instead, spot's stacks that step
/// down to a stopped neighbour kept 78% of their first core cells in [1/r, r], at 0.3 91%...
const LOWEST_PER_SIZE: f64 = 0.3;
/// ...and at most this: a tetrahedron much taller than its base is wide is a needle (a last
/// layer up to twice as tall as the front is wide still gets its match).
const HIGHEST_PER_SIZE: f64 = 2.0;
/// Every front triangle at the vertex must face the seed's direction at least this much
/// (cosine): at a sharper crease of the front the seed would lean over a neighbour.
const MIN_NORMAL_COSINE: f64 = 0.5;
/// How far a seed leans from the front's normal towards its column's last step (0: along the
/// normal, 1: one more step of the column). Measured over every front triangle at 0.25 / 0.5 /
/// 0.75 / 1 (defaults): fandisk 89.2 / 92.4 / 95.2 / 94.7%, box 92.6 / 94.0 / 94.9 / 94.9%,
/// sphere 97.3 / 98.5 / 99.2 / 97.0%, ONERA 98.3 / 98.9 / 99.0 / 98.9%; at 1 the example's
/// 15-layer sphere fell to 85.1% (94.1% at 0.75): seeds leaning as far as the columns split
/// on its growing front crowd each other into flat tetrahedra.
const SEED_LEAN: f64 = 0.75;
/// Smallest distance from a seed to the boundary, in seed heights (a flat front gives 1).
const CLEARANCE: f64 = 0.7;
/// Smallest distance between two seeds, in the smaller of their heights: enough to keep
/// seeds of two fronts facing each other, or of a front folding, off each other (at 0.5, 10% of
/// the ONERA M6's candidates were thinned out where its stretched triangles are narrow).
const SPACING: f64 = 0.35;

/// Seeds and what became of the candidates.
#[derive(Clone, Debug, Default)]
pub struct Seeds {
    pub points: Vec<DVec3>,
    /// The front vertex under every seed (a boundary point index).
    pub vertex: Vec<u32>,
    /// Every seed's height over the front.
    pub height: Vec<f64>,
    /// Front vertices with a last layer under them and a normal their triangles face (the
    /// candidates).
    pub candidates: usize,
}

/// The seeds over the front of `boundary`, whose last layer is `front`; `size[v]` is the
/// tangential size at boundary point `v`.
pub fn seed_points(boundary: &ClosedBoundary, front: &FrontLayer, size: &[f64]) -> Seeds {
    let candidates = candidates(boundary, front, size);
    let bvh =
        TriangleBvh::new(boundary.triangles.iter().map(|t| t.map(|v| boundary.points[v as usize])).collect());
    let clear: Vec<Candidate> = candidates
        .iter()
        .copied()
        .filter(|c| {
            let from = boundary.points[c.vertex as usize];
            let clear = is_clear(&bvh, from, c.point, c.height);
            if !clear {
                // How near the boundary is, in seed heights (below CLEARANCE: not clear).
                let near = bvh.nearest(c.point).map(|n| n.distance / c.height);
                tracing::trace!(vertex = c.vertex, at = ?c.point, height = c.height, ?near, "seed not clear");
            }
            clear
        })
        .collect();
    let points = spaced(&clear);
    tracing::debug!(
        candidates = candidates.len(),
        clear = clear.len(),
        spaced = points.len(),
        "seeds over the front"
    );
    Seeds {
        points: points.iter().map(|&i| clear[i].point).collect(),
        vertex: points.iter().map(|&i| clear[i].vertex).collect(),
        height: points.iter().map(|&i| clear[i].height).collect(),
        candidates: candidates.len(),
    }
}

#[derive(Clone, Copy, Debug)]
struct Candidate {
    /// The front vertex under it.
    vertex: u32,
    /// Where it stands: on the vertex's normal, `height` over the triangles around on the mean
    /// (further from the vertex where the front bends).
    point: DVec3,
    /// Its height over the front: the layer's, within the bounds of the front's size.
    height: f64,
}

/// One candidate over every vertex whose triangles are all on the front, with a last layer's
/// height under at least one, and whose normal the triangles around it all face. Its height is
/// the mean of those heights, weighed by area.
fn candidates(boundary: &ClosedBoundary, front: &FrontLayer, size: &[f64]) -> Vec<Candidate> {
    let n = boundary.points.len();
    let (mut normal, mut height, mut area) = (vec![DVec3::ZERO; n], vec![0.0; n], vec![0.0; n]);
    let mut normal_area = vec![0.0; n];
    let mut on_front = vec![true; n];
    for (t, tri) in boundary.triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|v| boundary.points[v as usize]);
        let w = triangle_area_vector(a, b, c);
        let h = front.heights.get(t).copied().unwrap_or(f64::NAN);
        for &v in tri {
            let v = v as usize;
            on_front[v] &= boundary.markers[t] == MARKER_FRONT;
            normal[v] += w;
            normal_area[v] += w.length();
            if h.is_finite() && h > 0.0 {
                height[v] += w.length() * h;
                area[v] += w.length();
            }
        }
    }
    // The smallest and the area-weighted mean cosine between the triangles' normals and the
    // vertex's.
    let (mut min_cosine, mut cosine) = (vec![1.0f64; n], vec![0.0; n]);
    for tri in &boundary.triangles {
        let [a, b, c] = tri.map(|v| boundary.points[v as usize]);
        let w = triangle_area_vector(a, b, c);
        for &v in tri {
            let v = v as usize;
            let cos = w.normalize_or_zero().dot(normal[v].normalize_or_zero());
            min_cosine[v] = min_cosine[v].min(cos);
            cosine[v] += w.length() * cos / normal_area[v];
        }
    }
    (0..n)
        .filter(|&v| on_front[v] && min_cosine[v] >= MIN_NORMAL_COSINE && area[v] > 0.0 && size[v] > 0.0)
        .map(|v| {
            let layer = height[v] / area[v];
            let h = layer.clamp(LOWEST_PER_SIZE * size[v], HIGHEST_PER_SIZE * size[v]);
            // Where the front bends, the triangles around see a seed on the vertex's normal
            // lower by their cosine: raise it so that they see it at `h` on the mean (at a
            // convex crease, the mitred offset).
            let normal = normal[v].normalize();
            let along =
                front.steps.get(v).map(|s| s.normalize()).filter(|s| s.dot(normal) >= MIN_NORMAL_COSINE);
            let way = along.map_or(normal, |s| (normal + SEED_LEAN * (s - normal)).normalize());
            let point = boundary.points[v] + way * (h / cosine[v] / way.dot(normal));
            Candidate { vertex: v as u32, point, height: h }
        })
        .filter(|c| c.point.is_finite())
        .collect()
}

/// Whether `to` keeps its clearance from the boundary and the way up from `from` crosses no
/// boundary triangle (the segment starts a little above `from`, off its own triangles).
fn is_clear(bvh: &TriangleBvh, from: DVec3, to: DVec3, height: f64) -> bool {
    if bvh.nearest(to).is_none_or(|near| near.distance < CLEARANCE * height) {
        return false;
    }
    let start = from + (to - from) * 0.01;
    let span = Aabb::from_points(&[start, to]);
    let mut crossed = false;
    // Boxes off the segment's box cost 2, triangles 1 (or -inf once one is crossed, which ends
    // the search): after the first leaf, only boxes overlapping the segment's are opened.
    bvh.branch_and_bound(
        |bounds| if bounds.overlaps(&span) { 0.0 } else { 2.0 },
        |_, corners| {
            crossed |= segment_triangle(start, to, *corners);
            if crossed {
                f64::NEG_INFINITY
            } else {
                1.0
            }
        },
    );
    !crossed
}

/// Indices of the candidates kept: lowest first, each one at least [`SPACING`] times the smaller
/// height away from every one kept before it.
fn spaced(candidates: &[Candidate]) -> Vec<usize> {
    let bvh = TriangleBvh::new(candidates.iter().map(|c| [c.point; 3]).collect());
    let mut order: Vec<usize> = (0..candidates.len()).collect();
    order.sort_by(|&i, &j| candidates[i].height.total_cmp(&candidates[j].height).then(i.cmp(&j)));
    let mut kept = vec![false; candidates.len()];
    let mut out = Vec::new();
    for i in order {
        let c = candidates[i];
        // Distance over the smaller height; a box is no closer than its distance over c's.
        let mut nearest = f64::INFINITY;
        bvh.branch_and_bound(
            |bounds| box_distance_squared(c.point, bounds).sqrt() / c.height,
            |j, _| {
                let o = candidates[j as usize];
                if kept[j as usize] {
                    nearest = nearest.min(o.point.distance(c.point) / o.height.min(c.height));
                }
                nearest
            },
        );
        if nearest >= SPACING {
            kept[i] = true;
            out.push(i);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat square front of 2 x 2 cells (unit edges, facing +z) closed by a box far above:
    /// the inner vertex gets its seed at the layer height, straight above; the rim vertices
    /// touch the box's walls (marked wall), so they get none.
    fn plate(layer: f64) -> (ClosedBoundary, FrontLayer) {
        let mut points = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                points.push(DVec3::new(i as f64, j as f64, 0.0));
            }
        }
        let id = |i: u32, j: u32| j * 3 + i;
        let mut triangles = Vec::new();
        for j in 0..2 {
            for i in 0..2 {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let n = triangles.len();
        let mut markers = vec![MARKER_FRONT; n];
        // A far lid over the rim vertices, marked as wall (its shape does not matter here).
        let lid = points.len() as u32;
        points.push(DVec3::new(1.0, 1.0, 50.0));
        for (a, b) in [(id(0, 0), id(2, 0)), (id(2, 0), id(2, 2)), (id(2, 2), id(0, 2)), (id(0, 2), id(0, 0))]
        {
            triangles.push([b, a, lid]);
            markers.push(super::super::MARKER_WALL);
        }
        let mut heights = vec![layer; n];
        heights.resize(triangles.len(), f64::NAN);
        let steps = vec![DVec3::NAN; points.len()];
        (ClosedBoundary { points, triangles, markers }, FrontLayer { heights, steps })
    }

    #[test]
    fn a_seed_stands_over_the_inner_vertex_at_the_layer_height() {
        let (boundary, heights) = plate(0.9);
        let size = crate::sizing::wall::mean_edge_length_per_vertex(&boundary.points, &boundary.triangles);
        let seeds = seed_points(&boundary, &heights, &size);
        assert_eq!(seeds.vertex, vec![4], "{seeds:?}");
        let p = seeds.points[0];
        assert!((p - DVec3::new(1.0, 1.0, 0.9)).length() < 1e-12, "{p:?}");
    }

    /// The column under the inner vertex leans (its last step 0.9 up and 0.3 along x): the seed
    /// leans with it, not as far, still at the layer's height over the front.
    #[test]
    fn a_seed_leans_towards_the_last_step_of_its_column() {
        let (boundary, mut front) = plate(0.9);
        front.steps[4] = DVec3::new(0.3, 0.0, 0.9);
        let size = crate::sizing::wall::mean_edge_length_per_vertex(&boundary.points, &boundary.triangles);
        let p = seed_points(&boundary, &front, &size).points[0];
        assert!((p.z - 0.9).abs() < 1e-12 && p.y == 1.0, "{p:?}");
        assert!(p.x > 1.15 && p.x < 1.3, "leans most of the way: {p:?}");
    }

    #[test]
    fn a_thin_layer_gets_its_seed_at_the_lowest_height_of_the_size() {
        let (boundary, heights) = plate(0.01);
        let size = vec![1.0; boundary.points.len()];
        let seeds = seed_points(&boundary, &heights, &size);
        assert!((seeds.points[0].z - LOWEST_PER_SIZE).abs() < 1e-12, "{seeds:?}");
    }

    #[test]
    fn no_seed_without_clearance() {
        // A lid triangle just above the inner vertex: the seed would be too close to it.
        let (mut boundary, mut heights) = plate(0.9);
        let base = boundary.points.len() as u32;
        boundary.points.extend([
            DVec3::new(0.5, 0.5, 1.2),
            DVec3::new(1.5, 0.5, 1.2),
            DVec3::new(1.0, 1.5, 1.2),
        ]);
        boundary.triangles.push([base, base + 2, base + 1]);
        boundary.markers.push(super::super::MARKER_WALL);
        heights.heights.push(f64::NAN);
        heights.steps.extend([DVec3::NAN; 3]);
        let size = vec![1.0; boundary.points.len()];
        assert!(seed_points(&boundary, &heights, &size).points.is_empty());
    }

    #[test]
    fn seeds_too_close_to_each_other_are_thinned_lowest_first() {
        let c = |x: f64, h: f64, v: u32| Candidate { vertex: v, point: DVec3::new(x, 0.0, 0.0), height: h };
        // 0 and 1 are 0.3 apart (under SPACING of the smaller height 1): the lower, 1, wins; 2
        // is far.
        let kept = spaced(&[c(0.0, 1.2, 0), c(0.3, 1.0, 1), c(3.0, 1.0, 2)]);
        assert_eq!(kept, vec![1, 2]);
    }
}
