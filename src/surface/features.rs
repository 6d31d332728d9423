//! Feature analysis: the signed dihedral turn of every edge, ridge edges,
//! ridge lines, and the kind of every vertex (smooth, ridge, corner).
//!
//! Convention: the right-hand normals of the surface point INTO the fluid. After validation that
//! holds for an external body (each shell's normals point out of it). For internal flow (the
//! surface bounds the fluid, e.g. a pipe), the caller flips the surface first
//! ([`Surface::flip_all`]) so that convex and concave are as seen from the fluid.
//! Convex: the fluid sees an outside corner (the edges of a box seen from outside; normals
//! diverge, an expansion). Concave: an inside corner (normals converge).

use super::topology::{find, opposite_vertex, union, Topology};
use super::Surface;
use crate::geometry::DVec3;

/// How many cells the ridges of [`Features::near_concave_ridges`] span at most, in all.
const MAX_RIDGE_SAMPLES: usize = 1 << 20;

/// The default feature angle: an edge whose normals turn by more than this is a ridge.
pub const DEFAULT_FEATURE_ANGLE_DEG: f64 = 30.0;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EdgeKind {
    Smooth,
    ConvexRidge,
    ConcaveRidge,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum VertexKind {
    /// No ridge edge.
    Smooth,
    /// On a convex ridge line (two convex ridge edges), or at the loose end of one (one edge).
    ConvexRidge,
    ConcaveRidge,
    /// Three or more ridge edges (or two of different kinds), all convex.
    ConvexCorner,
    /// All concave.
    ConcaveCorner,
    /// Convex and concave ridge edges meet.
    SaddleCorner,
}

/// A chain of ridge edges of one kind between corners or loose ends (or a closed loop).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct RidgeLine {
    pub kind: EdgeKind,
    pub edges: u32,
}

/// How many edges, vertices and ridge lines of every kind.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct FeatureCounts {
    pub smooth_edges: usize,
    pub convex_ridge_edges: usize,
    pub concave_ridge_edges: usize,
    pub convex_ridge_lines: usize,
    pub concave_ridge_lines: usize,
    pub smooth_vertices: usize,
    pub convex_ridge_vertices: usize,
    pub concave_ridge_vertices: usize,
    pub convex_corners: usize,
    pub concave_corners: usize,
    pub saddle_corners: usize,
}

#[derive(Clone, Debug)]
pub struct Features {
    pub feature_angle_deg: f64,
    /// Signed dihedral turn of every topology edge, in degrees: 0 = flat, positive = convex,
    /// negative = concave (0 for an edge without exactly two triangles).
    pub turn_deg: Vec<f64>,
    pub edge_kind: Vec<EdgeKind>,
    /// The kind of every vertex (vertices of no triangle are smooth).
    pub vertex_kind: Vec<VertexKind>,
    /// The ridge line of every ridge edge.
    pub edge_line: Vec<Option<u32>>,
    pub lines: Vec<RidgeLine>,
    pub counts: FeatureCounts,
}

impl Features {
    /// Classify the edges and vertices of `surface` (whose `topology` must be current): an edge
    /// is a ridge when its |turn| exceeds `feature_angle_deg`.
    pub fn compute(surface: &Surface, topology: &Topology, feature_angle_deg: f64) -> Features {
        let turn_deg: Vec<f64> =
            (0..topology.edge_count() as u32).map(|e| signed_turn_deg(surface, topology, e)).collect();
        let edge_kind: Vec<EdgeKind> = turn_deg
            .iter()
            .map(|&turn| match turn {
                t if t > feature_angle_deg => EdgeKind::ConvexRidge,
                t if t < -feature_angle_deg => EdgeKind::ConcaveRidge,
                _ => EdgeKind::Smooth,
            })
            .collect();
        let ridges_at = count_ridges_at_vertices(topology, &edge_kind);
        let vertex_kind: Vec<VertexKind> = ridges_at.iter().map(|&r| classify_vertex(r)).collect();
        let (edge_line, lines) = ridge_lines(topology, &edge_kind, &ridges_at);
        let counts = count_kinds(&edge_kind, &vertex_kind, &lines);
        Features { feature_angle_deg, turn_deg, edge_kind, vertex_kind, edge_line, lines, counts }
    }
}

impl Features {
    /// Whether each vertex lies within `radius[v]` of a concave ridge edge (`None`: not asked).
    /// The ridge edges are binned on a grid of the largest radius, so each vertex looks at the
    /// edges of the cells around its own only.
    pub fn near_concave_ridges(
        &self,
        surface: &Surface,
        topology: &Topology,
        radius: &[Option<f64>],
    ) -> Vec<bool> {
        let reach = radius.iter().flatten().fold(0.0f64, |m, &r| m.max(r));
        let ridges: Vec<[DVec3; 2]> = (0..topology.edges.len())
            .filter(|&e| self.edge_kind[e] == EdgeKind::ConcaveRidge)
            .map(|e| topology.edges[e].map(|v| surface.points[v as usize]))
            .collect();
        if ridges.is_empty() || !(reach > 0.0 && reach.is_finite()) {
            return vec![false; radius.len()];
        }
        // Cells of at least the reach, and coarse enough that the ridges give at most about
        // 2 MAX_RIDGE_SAMPLES samples whatever the scale of the reach.
        let length: f64 = ridges.iter().map(|[a, b]| a.distance(*b)).sum();
        let size = reach.max(length / MAX_RIDGE_SAMPLES as f64);
        if !size.is_finite() {
            return vec![false; radius.len()];
        }
        let cell = |p: DVec3| (p / size).floor().as_i64vec3().to_array();
        let mut grid: std::collections::HashMap<[i64; 3], Vec<u32>> = std::collections::HashMap::new();
        for (i, &[a, b]) in ridges.iter().enumerate() {
            // Samples at most half a cell apart: the closest point of the segment to a vertex
            // within reach is within half a cell of one, so within two cells of the vertex's.
            let samples = ((a.distance(b) / (0.5 * size)).ceil() as usize).max(1);
            let mut cells: Vec<[i64; 3]> =
                (0..=samples).map(|k| cell(a.lerp(b, k as f64 / samples as f64))).collect();
            cells.dedup();
            for c in cells {
                let edges = grid.entry(c).or_default();
                if edges.last() != Some(&(i as u32)) {
                    edges.push(i as u32);
                }
            }
        }
        let near = |v: usize, r: f64| {
            let p = surface.points[v];
            let c = cell(p);
            (-2..=2).any(|dx| {
                (-2..=2).any(|dy| {
                    (-2..=2).any(|dz| {
                        grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]).is_some_and(|edges| {
                            edges.iter().any(|&i| {
                                let [a, b] = ridges[i as usize];
                                crate::geometry::distance::closest_point_on_segment(p, a, b).distance(p) <= r
                            })
                        })
                    })
                })
            })
        };
        radius.iter().enumerate().map(|(v, r)| r.is_some_and(|r| near(v, r))).collect()
    }
}

/// Signed turn of edge `e` in degrees ([`crate::geometry::signed_turn_deg`]): convex when the far
/// corner of the second triangle lies behind the plane of the first.
pub fn signed_turn_deg(surface: &Surface, topology: &Topology, e: u32) -> f64 {
    let [first, second] = match topology.edge_uses(e) {
        [a, b] => [a.triangle as usize, b.triangle as usize],
        _ => return 0.0,
    };
    let Some([a, b, c]) = surface_points(surface, first) else { return 0.0 };
    let Some(second_points) = surface_points(surface, second) else { return 0.0 };
    let far = opposite_vertex(surface.triangles[second], topology.edges[e as usize]);
    crate::geometry::signed_turn_deg([a, b, c], second_points, surface.points[far as usize])
}

/// The corner points of triangle `t`, or `None` if it refers to a missing vertex.
fn surface_points(surface: &Surface, t: usize) -> Option<[crate::geometry::DVec3; 3]> {
    let tri = surface.triangles.get(t)?;
    let mut points = [crate::geometry::DVec3::ZERO; 3];
    for (p, &v) in points.iter_mut().zip(tri) {
        *p = *surface.points.get(v as usize)?;
    }
    Some(points)
}

/// Number of (convex, concave) ridge edges at every vertex.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct RidgesAt {
    convex: u32,
    concave: u32,
}

fn count_ridges_at_vertices(topology: &Topology, edge_kind: &[EdgeKind]) -> Vec<RidgesAt> {
    let mut ridges = vec![RidgesAt::default(); topology.vertex_count()];
    for (edge, kind) in topology.edges.iter().zip(edge_kind) {
        for &v in edge {
            let at = &mut ridges[v as usize];
            match kind {
                EdgeKind::ConvexRidge => at.convex += 1,
                EdgeKind::ConcaveRidge => at.concave += 1,
                EdgeKind::Smooth => {}
            }
        }
    }
    ridges
}

/// No ridge edge: smooth; one ridge edge, or two of one kind: ridge; otherwise a corner,
/// convex or concave when all its ridge edges are, saddle when they are mixed.
fn classify_vertex(r: RidgesAt) -> VertexKind {
    match (r.convex, r.concave) {
        (0, 0) => VertexKind::Smooth,
        (1 | 2, 0) => VertexKind::ConvexRidge,
        (0, 1 | 2) => VertexKind::ConcaveRidge,
        (_, 0) => VertexKind::ConvexCorner,
        (0, _) => VertexKind::ConcaveCorner,
        _ => VertexKind::SaddleCorner,
    }
}

/// A vertex that a ridge line passes through (rather than ends at).
fn continues_line(r: RidgesAt) -> bool {
    (r.convex, r.concave) == (2, 0) || (r.convex, r.concave) == (0, 2)
}

/// Group ridge edges into lines: connected through vertices that continue a line; line ids
/// in the order of their smallest edge.
fn ridge_lines(
    topology: &Topology,
    edge_kind: &[EdgeKind],
    ridges_at: &[RidgesAt],
) -> (Vec<Option<u32>>, Vec<RidgeLine>) {
    let mut parent: Vec<u32> = (0..edge_kind.len() as u32).collect();
    let mut first_ridge_edge = vec![u32::MAX; ridges_at.len()];
    for (e, edge) in topology.edges.iter().enumerate() {
        if edge_kind[e] == EdgeKind::Smooth {
            continue;
        }
        for &v in edge {
            if !continues_line(ridges_at[v as usize]) {
                continue;
            }
            match first_ridge_edge[v as usize] {
                u32::MAX => first_ridge_edge[v as usize] = e as u32,
                other => {
                    union(&mut parent, other, e as u32);
                }
            }
        }
    }
    let mut line_of_root = vec![u32::MAX; edge_kind.len()];
    let mut lines: Vec<RidgeLine> = Vec::new();
    let mut edge_line = vec![None; edge_kind.len()];
    for (e, &kind) in edge_kind.iter().enumerate() {
        if kind == EdgeKind::Smooth {
            continue;
        }
        let root = find(&mut parent, e as u32) as usize;
        if line_of_root[root] == u32::MAX {
            line_of_root[root] = lines.len() as u32;
            lines.push(RidgeLine { kind, edges: 0 });
        }
        lines[line_of_root[root] as usize].edges += 1;
        edge_line[e] = Some(line_of_root[root]);
    }
    (edge_line, lines)
}

fn count_kinds(edge_kind: &[EdgeKind], vertex_kind: &[VertexKind], lines: &[RidgeLine]) -> FeatureCounts {
    let mut c = FeatureCounts::default();
    for kind in edge_kind {
        match kind {
            EdgeKind::Smooth => c.smooth_edges += 1,
            EdgeKind::ConvexRidge => c.convex_ridge_edges += 1,
            EdgeKind::ConcaveRidge => c.concave_ridge_edges += 1,
        }
    }
    for line in lines {
        match line.kind {
            EdgeKind::ConvexRidge => c.convex_ridge_lines += 1,
            _ => c.concave_ridge_lines += 1,
        }
    }
    for kind in vertex_kind {
        match kind {
            VertexKind::Smooth => c.smooth_vertices += 1,
            VertexKind::ConvexRidge => c.convex_ridge_vertices += 1,
            VertexKind::ConcaveRidge => c.concave_ridge_vertices += 1,
            VertexKind::ConvexCorner => c.convex_corners += 1,
            VertexKind::ConcaveCorner => c.concave_corners += 1,
            VertexKind::SaddleCorner => c.saddle_corners += 1,
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::DVec3;
    use crate::surface::topology::tests::{cube_without_octant, voxel_surface};

    fn features(surface: &Surface) -> Features {
        Features::compute(surface, &Topology::new(surface), DEFAULT_FEATURE_ANGLE_DEG)
    }

    #[test]
    fn cube_has_convex_edges_and_corners() {
        let f = features(&voxel_surface(&[[0, 0, 0]]));
        let c = &f.counts;
        assert_eq!((c.convex_ridge_edges, c.concave_ridge_edges, c.smooth_edges), (12, 0, 6));
        assert_eq!(c.convex_corners, 8);
        assert_eq!(c.convex_ridge_lines, 12);
        for (turn, kind) in f.turn_deg.iter().zip(&f.edge_kind) {
            let expected = if *kind == EdgeKind::ConvexRidge { 90.0 } else { 0.0 };
            assert!((turn - expected).abs() < 1e-9, "{turn}");
        }
    }

    #[test]
    fn inverted_cube_is_concave_everywhere() {
        // The inside of a box seen from the fluid in it (internal flow, after flipping).
        let mut s = voxel_surface(&[[0, 0, 0]]);
        s.flip_all();
        let c = features(&s).counts;
        assert_eq!((c.concave_ridge_edges, c.concave_corners, c.concave_ridge_lines), (12, 8, 12));
    }

    #[test]
    fn cube_without_an_octant() {
        let s = cube_without_octant();
        let f = features(&s);
        let c = &f.counts;
        assert_eq!((c.convex_ridge_edges, c.concave_ridge_edges), (27, 3));
        assert_eq!((c.convex_corners, c.concave_corners, c.saddle_corners), (10, 1, 3));
        assert_eq!((c.convex_ridge_vertices, c.concave_ridge_vertices, c.smooth_vertices), (9, 0, 3));
        assert_eq!((c.convex_ridge_lines, c.concave_ridge_lines), (18, 3));
        let corner = s.points.iter().position(|&p| p == DVec3::ONE).unwrap();
        assert_eq!(f.vertex_kind[corner], VertexKind::ConcaveCorner);
        let saddle = s.points.iter().position(|&p| p == DVec3::new(2.0, 1.0, 1.0)).unwrap();
        assert_eq!(f.vertex_kind[saddle], VertexKind::SaddleCorner);
        let concave: Vec<f64> =
            f.turn_deg.iter().copied().filter(|t| *t < -DEFAULT_FEATURE_ANGLE_DEG).collect();
        assert!(concave.iter().all(|t| (t + 90.0).abs() < 1e-9), "{concave:?}");
    }

    #[test]
    fn threshold_on_a_shallow_roof() {
        // A box whose top is a roof with a 40 degree turn at its ridge: a ridge at 30, not at 45.
        let h = 20f64.to_radians().tan();
        let mut s = voxel_surface(&[[0, 0, 0], [1, 0, 0]]);
        for p in &mut s.points {
            if p.z == 1.0 && p.x == 1.0 {
                p.z += h;
            }
        }
        let topology = Topology::new(&s);
        let ridge = (0..topology.edge_count())
            .find(|&e| topology.edges[e].iter().all(|&v| s.points[v as usize].z > 1.0))
            .unwrap();
        let f = Features::compute(&s, &topology, 30.0);
        assert!((f.turn_deg[ridge] - 40.0).abs() < 1e-9, "{}", f.turn_deg[ridge]);
        assert_eq!(f.edge_kind[ridge], EdgeKind::ConvexRidge);
        assert_eq!(Features::compute(&s, &topology, 45.0).edge_kind[ridge], EdgeKind::Smooth);
    }

    #[test]
    fn vertex_rule() {
        let at = |convex, concave| classify_vertex(RidgesAt { convex, concave });
        assert_eq!(at(0, 0), VertexKind::Smooth);
        assert_eq!(at(1, 0), VertexKind::ConvexRidge);
        assert_eq!(at(0, 2), VertexKind::ConcaveRidge);
        assert_eq!(at(1, 1), VertexKind::SaddleCorner);
        assert_eq!(at(3, 0), VertexKind::ConvexCorner);
        assert_eq!(at(0, 4), VertexKind::ConcaveCorner);
        assert_eq!(at(2, 1), VertexKind::SaddleCorner);
    }

    #[test]
    fn open_surface_does_not_panic() {
        let mut s = voxel_surface(&[[0, 0, 0]]);
        s.triangles.truncate(5);
        s.triangles.push([0, 1, 42]);
        let f = features(&s);
        assert_eq!(f.turn_deg.len(), Topology::new(&s).edge_count());
    }
}
