//! The size jump at the top of the layers: over every front triangle, the height of
//! the core tetrahedron on it (its fourth node's distance from the triangle's plane) over the
//! height of the last layer under it. A smooth transition keeps the ratio within [1/r, r]; an
//! isotropic core on thin last layers gives ratios far above r.
//!
//! The last layer's height under a front triangle is the mean, over its nodes, of the last
//! step of the column ending there (the vertical edge of the prism of the column's last layer)
//! along the triangle's normal: over a prism, its height; over the ramp cells where neighbouring
//! stacks ended a layer apart, the height of the layers they ended with.

use std::collections::{HashMap, HashSet};

use serde::Serialize;

use super::sorted_triangle;
use crate::geometry::{triangle_area_vector, DVec3};
use crate::layers::smoothness::RatioStats;
use crate::mesh::{CellKind, VolumeMesh};

/// The size-jump ratios and their histogram.
#[derive(Clone, Debug, Default, Serialize)]
pub struct SizeJump {
    /// Within the band [1/r, r]; over the front triangles with a last step at a node.
    pub stats: RatioStats,
    /// The same over the front triangles on a prism only.
    pub on_prisms: RatioStats,
    /// Every front triangle (a face of a layer cell and a core tetrahedron); those with no
    /// node at the top of a prism (a column born or merged in the last layer at each) and the
    /// side faces are not measured.
    pub front_triangles: usize,
    /// Front triangles that are sides of the layers, not tops ([`LastLayer::is_side_face`]).
    pub side_faces: usize,
    /// Counts per bin, the bins bounded by powers of r: (label, count).
    pub histogram: Vec<(String, usize)>,
}

/// Upper bounds of the histogram bins, as powers of the growth ratio.
const BIN_POWERS: [i32; 6] = [-2, -1, 1, 2, 4, 8];

/// The last layer's height under the front triangles of a layered mesh.
#[derive(Clone, Debug, Default)]
pub struct LastLayer {
    /// The height of every prism, by its top (sorted nodes).
    prism_under: HashMap<[u32; 3], f64>,
    /// The last step of the column at every node at the top of a prism: the prism's vertical
    /// edge up to it (top minus bottom), averaged over the prisms there (a node where columns
    /// merged tops prisms on different columns).
    steps: HashMap<u32, DVec3>,
}

impl LastLayer {
    /// The prisms of `layer_zone` in `mesh`.
    pub fn of(mesh: &VolumeMesh, layer_zone: u32) -> LastLayer {
        let prisms = mesh.block(CellKind::Prism);
        let mut last = LastLayer::default();
        let mut sums: HashMap<u32, (DVec3, f64)> = HashMap::new();
        for (p, &zone) in prisms.nodes.chunks_exact(6).zip(&prisms.zone) {
            let Ok(nodes) = <[u32; 6]>::try_from(p) else { continue };
            let x = nodes.iter().map(|&n| mesh.points.get(n as usize).copied()).collect::<Option<Vec<_>>>();
            let Some(x) = x.filter(|_| zone == layer_zone) else { continue };
            for i in 0..3 {
                let sum = sums.entry(nodes[i + 3]).or_insert((DVec3::ZERO, 0.0));
                sum.0 += x[i + 3] - x[i];
                sum.1 += 1.0;
            }
            let x: [DVec3; 6] = std::array::from_fn(|i| x[i]);
            last.prism_under.insert(sorted_triangle([nodes[3], nodes[4], nodes[5]]), prism_height(x));
        }
        last.steps = sums.into_iter().map(|(n, (sum, count))| (n, sum / count)).collect();
        last
    }

    /// The last step of the column at `node` (the mean vertical edge of the prisms it tops).
    pub fn step(&self, node: u32) -> Option<DVec3> {
        self.steps.get(&node).copied()
    }

    /// The last layer's height under front triangle `nodes` (at `x`), and whether a prism is
    /// under it: the prism's height, else the mean of the last steps at its nodes along its
    /// normal; `None` when no node has one (columns born or merged in the last layer), on a
    /// [`LastLayer::is_side_face`], or when the height is not positive.
    pub fn height(&self, nodes: [u32; 3], x: [DVec3; 3]) -> Option<(f64, bool)> {
        if let Some(&h) = self.prism_under.get(&sorted_triangle(nodes)) {
            return (h > 0.0).then_some((h, true));
        }
        let (h, cosine) = self.ramp(nodes, x)?;
        (h > 0.0 && cosine >= SIDE_COSINE).then_some((h, false))
    }

    /// Whether front triangle `nodes` (at `x`, with no prism under it) is a side of the layers
    /// rather than a top: the columns at its nodes run along it (their last steps are on the
    /// mean within [`SIDE_COSINE`] of its plane), as on the cliff where a stack ends beside a
    /// taller one. A layer height across it means nothing.
    pub fn is_side_face(&self, nodes: [u32; 3], x: [DVec3; 3]) -> bool {
        self.ramp(nodes, x).is_some_and(|(_, cosine)| cosine < SIDE_COSINE)
    }

    /// Over the last steps at the nodes of front triangle `nodes` (at `x`): the mean of their
    /// lengths along its normal and of their cosines with it; `None` when no node has one.
    fn ramp(&self, nodes: [u32; 3], x: [DVec3; 3]) -> Option<(f64, f64)> {
        let normal = triangle_area_vector(x[0], x[1], x[2]).normalize_or_zero();
        let steps: Vec<DVec3> = nodes.into_iter().filter_map(|n| self.steps.get(&n).copied()).collect();
        let mean = |f: &dyn Fn(DVec3) -> f64| steps.iter().map(|&s| f(s)).sum::<f64>() / steps.len() as f64;
        (!steps.is_empty())
            .then(|| (mean(&|s| s.dot(normal).abs()), mean(&|s| s.normalize_or_zero().dot(normal).abs())))
    }
}

/// A front triangle whose columns' last steps are on the mean within this cosine of its plane
/// (about 17 degrees) is a side of the layers ([`LastLayer::is_side_face`]).
const SIDE_COSINE: f64 = 0.3;

/// The ratios over the front triangles, in `mesh` (the merged mesh: layer cells in zone
/// `layer_zone`, core tetrahedra in `core_zone`), with the band [1/growth, growth].
pub fn measure(mesh: &VolumeMesh, layer_zone: u32, core_zone: u32, growth: f64) -> SizeJump {
    let tets = mesh.block(CellKind::Tetrahedron);
    let core_tets =
        || tets.nodes.chunks_exact(4).zip(&tets.zone).filter(move |(_, &z)| z == core_zone).map(|(c, _)| c);
    let mut in_core = vec![false; mesh.points.len()];
    for t in core_tets() {
        for &n in t {
            in_core[n as usize] = true;
        }
    }
    let last_layer = LastLayer::of(mesh, layer_zone);
    let layer_faces = layer_triangles(mesh, layer_zone, &in_core);
    let (mut ratios, mut on_prisms) = (Vec::new(), Vec::new());
    let (mut front_triangles, mut side_faces) = (0, 0);
    let x = |n: u32| mesh.points[n as usize];
    for t in core_tets() {
        for face in CellKind::Tetrahedron.faces() {
            let nodes = [t[face[0]], t[face[1]], t[face[2]]];
            if !layer_faces.contains(&sorted_triangle(nodes)) {
                continue;
            }
            front_triangles += 1;
            let corners = nodes.map(x);
            let Some((h, on_prism)) = last_layer.height(nodes, corners) else {
                side_faces += usize::from(last_layer.is_side_face(nodes, corners));
                continue;
            };
            let apex = t.iter().copied().find(|n| !nodes.contains(n)).map_or(corners[0], x);
            let ratio = height_over(corners, apex).abs() / h;
            ratios.push(ratio);
            if on_prism {
                on_prisms.push(ratio);
            }
        }
    }
    SizeJump {
        histogram: histogram(&ratios, growth),
        stats: RatioStats::of(ratios, 1.0 / growth, growth),
        on_prisms: RatioStats::of(on_prisms, 1.0 / growth, growth),
        front_triangles,
        side_faces,
    }
}

/// The triangular faces (sorted nodes) of the layer cells in `layer_zone` whose nodes are all
/// `in_core`: every front triangle is one of them.
fn layer_triangles(mesh: &VolumeMesh, layer_zone: u32, in_core: &[bool]) -> HashSet<[u32; 3]> {
    let mut faces = HashSet::new();
    for kind in [CellKind::Prism, CellKind::Pyramid, CellKind::Tetrahedron] {
        let block = mesh.block(kind);
        for (cell, &zone) in block.nodes.chunks_exact(kind.node_count()).zip(&block.zone) {
            if zone != layer_zone {
                continue;
            }
            for face in kind.faces().iter().filter(|f| f.len() == 3) {
                let mut t = [cell[face[0]], cell[face[1]], cell[face[2]]];
                if t.iter().all(|&n| in_core.get(n as usize) == Some(&true)) {
                    t.sort_unstable();
                    faces.insert(t);
                }
            }
        }
    }
    faces
}

/// The signed distance of `apex` from the plane of `triangle` (positive on the side its
/// right-hand normal points to): a tetrahedron's height over that face.
pub fn height_over([a, b, c]: [DVec3; 3], apex: DVec3) -> f64 {
    (apex - a).dot(triangle_area_vector(a, b, c).normalize_or_zero())
}

/// The height of a prism (Gmsh order, bottom `0 1 2`, top `3 4 5`) under its top: the mean
/// distance of its bottom nodes from the top's plane. A prism that widens over a convex wall
/// has a top larger than its bottom; its volume over its top's area would be less than that.
pub fn prism_height(x: [DVec3; 6]) -> f64 {
    let normal = triangle_area_vector(x[3], x[4], x[5]).normalize_or_zero();
    x[..3].iter().map(|&b| (x[3] - b).dot(normal)).sum::<f64>() / 3.0
}

fn histogram(ratios: &[f64], growth: f64) -> Vec<(String, usize)> {
    let mut counts = vec![0usize; BIN_POWERS.len() + 1];
    for &q in ratios {
        let bin = BIN_POWERS.iter().position(|&k| q <= growth.powi(k)).unwrap_or(BIN_POWERS.len());
        counts[bin] += 1;
    }
    let mut labels: Vec<String> = BIN_POWERS.iter().map(|k| format!("<= r^{k}")).collect();
    labels.push(format!("> r^{}", BIN_POWERS[BIN_POWERS.len() - 1]));
    labels.into_iter().zip(counts).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A prism widening upward (top twice the bottom's size) 0.5 high: its height is 0.5, its
    /// volume over its top's area less.
    #[test]
    fn a_widening_prism_is_as_high_as_its_planes_are_apart() {
        let bottom = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let top = bottom.map(|p| 2.0 * p + DVec3::new(-0.2, -0.2, 0.5));
        let x = [bottom[0], bottom[1], bottom[2], top[0], top[1], top[2]];
        assert!((prism_height(x) - 0.5).abs() < 1e-12);
    }

    /// A layer prism (zone 0) of height 0.5 over the triangle (0, x, y), nodes 0-5, and the
    /// points `more` from node 6 on; zone 1 is the core.
    fn on_a_prism(more: &[DVec3]) -> VolumeMesh {
        let bottom = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let mut points: Vec<DVec3> =
            bottom.iter().chain(&bottom.map(|p| p + 0.5 * DVec3::Z)).copied().collect();
        points.extend(more);
        let mut mesh =
            VolumeMesh { points, zone_names: vec!["layers".into(), "core".into()], ..Default::default() };
        mesh.push_cell(CellKind::Prism, &[0, 1, 2, 3, 4, 5], 0);
        mesh
    }

    /// A prism of height 0.5 under a tetrahedron of height 1.5 on its top: ratio 3, outside
    /// the band for r = 1.2 and in the bin (r^4, r^8].
    #[test]
    fn ratio_of_a_tet_on_a_prism() {
        let mut mesh = on_a_prism(&[DVec3::new(0.3, 0.3, 2.0)]);
        mesh.push_cell(CellKind::Tetrahedron, &[3, 4, 5, 6], 1);
        let jump = measure(&mesh, 0, 1, 1.2);
        assert_eq!(jump.stats.count, 1);
        assert!((jump.stats.median - 3.0).abs() < 1e-12, "{:?}", jump.stats);
        assert_eq!(jump.stats.within_band, 0.0);
        assert_eq!(jump.histogram[5].1, 1, "{:?}", jump.histogram);
        assert_eq!(jump.front_triangles, 1);
    }

    /// A ramp: a layer tetrahedron over a prism's top, its new node 0.6 over a corner (a column
    /// going on where its neighbours ended). The front triangle over the ramp has the prism's
    /// last steps (0.5 up) at two nodes: its height is theirs along its tilted normal.
    #[test]
    fn a_ramp_face_has_the_last_steps_of_its_nodes_along_its_normal() {
        let ramp_top = [DVec3::new(0.0, 0.0, 1.1), DVec3::new(1.0, 0.0, 0.5), DVec3::new(0.0, 1.0, 0.5)];
        let normal = triangle_area_vector(ramp_top[0], ramp_top[1], ramp_top[2]).normalize();
        let h = 0.5 * normal.z;
        let apex = (ramp_top[0] + ramp_top[1] + ramp_top[2]) / 3.0 + 1.1 * h * normal;
        let mut mesh = on_a_prism(&[ramp_top[0], apex]);
        mesh.push_cell(CellKind::Tetrahedron, &[3, 4, 5, 6], 0);
        mesh.push_cell(CellKind::Tetrahedron, &[6, 4, 5, 7], 1);
        let jump = measure(&mesh, 0, 1, 1.2);
        assert_eq!((jump.front_triangles, jump.stats.count, jump.on_prisms.count), (1, 1, 0));
        assert!((jump.stats.median - 1.1).abs() < 1e-9, "{:?}", jump.stats);
    }

    /// The cliff where a column goes on beside its stopped neighbours: the layer tetrahedron's
    /// face up the column (nodes 3, 4 and 6 over 3, in the plane y = 0) has the columns' steps
    /// in its plane. It is a side of the layers: counted, not measured.
    #[test]
    fn a_side_of_the_layers_is_not_measured() {
        let mut mesh = on_a_prism(&[DVec3::new(0.0, 0.0, 1.1), DVec3::new(0.5, -1.0, 0.7)]);
        mesh.push_cell(CellKind::Tetrahedron, &[3, 4, 5, 6], 0);
        mesh.push_cell(CellKind::Tetrahedron, &[3, 6, 4, 7], 1);
        let jump = measure(&mesh, 0, 1, 1.2);
        assert_eq!((jump.front_triangles, jump.side_faces, jump.stats.count), (1, 1, 0));
    }

    /// A core tetrahedron on a layer tetrahedron whose nodes are at no prism's top (columns
    /// born in the last layer) is a front triangle the ratio leaves out.
    #[test]
    fn a_front_triangle_with_no_last_step_is_counted_not_measured() {
        let mut mesh = VolumeMesh {
            points: vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.3, 0.3, -0.5),
                DVec3::new(0.3, 0.3, 1.0),
            ],
            zone_names: vec!["layers".into(), "core".into()],
            ..Default::default()
        };
        mesh.push_cell(CellKind::Tetrahedron, &[0, 2, 1, 3], 0);
        mesh.push_cell(CellKind::Tetrahedron, &[0, 1, 2, 4], 1);
        let jump = measure(&mesh, 0, 1, 1.2);
        assert_eq!((jump.front_triangles, jump.stats.count), (1, 0));
    }
}
