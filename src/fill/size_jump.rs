//! The size jump at the top of the layers (issue 5): over every front triangle, the height of
//! the core tetrahedron on it (its fourth node's distance from the triangle's plane) over the
//! height of the last layer's prism under it. A smooth transition keeps the ratio within
//! [1/r, r]; an isotropic core on thin last layers gives ratios far above r.

use std::collections::{HashMap, HashSet};

use serde::Serialize;

use crate::geometry::{triangle_area_vector, DVec3};
use crate::layers::smoothness::RatioStats;
use crate::mesh::{CellKind, VolumeMesh};

/// The size-jump ratios and their histogram.
#[derive(Clone, Debug, Default, Serialize)]
pub struct SizeJump {
    /// Within the band [1/r, r]; over the front triangles on a prism.
    pub stats: RatioStats,
    /// Every front triangle (a face of a layer cell and a core tetrahedron): those on a
    /// pyramid or a tetrahedron (where columns stopped, merged or split at the last layer) are
    /// not measured, their cells having no one height.
    pub front_triangles: usize,
    /// Counts per bin, the bins bounded by powers of r: (label, count).
    pub histogram: Vec<(String, usize)>,
}

/// Upper bounds of the histogram bins, as powers of the growth ratio.
const BIN_POWERS: [i32; 6] = [-2, -1, 1, 2, 4, 8];

/// The ratios over the front triangles, in `mesh` (the merged mesh: layer cells in zone
/// `layer_zone`, core tetrahedra in `core_zone`), with the band [1/growth, growth].
pub fn measure(mesh: &VolumeMesh, layer_zone: u32, core_zone: u32, growth: f64) -> SizeJump {
    let key = |mut t: [u32; 3]| {
        t.sort_unstable();
        t
    };
    let tets = mesh.block(CellKind::Tetrahedron);
    let core_tets =
        || tets.nodes.chunks_exact(4).zip(&tets.zone).filter(move |(_, &z)| z == core_zone).map(|(c, _)| c);
    // Only the prisms whose top touches the core can be under a front triangle.
    let mut in_core = vec![false; mesh.points.len()];
    for t in core_tets() {
        for &n in t {
            in_core[n as usize] = true;
        }
    }
    let prisms = mesh.block(CellKind::Prism);
    let mut last_height: HashMap<[u32; 3], f64> = HashMap::new();
    for (p, &zone) in prisms.nodes.chunks_exact(6).zip(&prisms.zone) {
        let top = [p[3], p[4], p[5]];
        if zone == layer_zone && top.iter().all(|&n| in_core[n as usize]) {
            let (Ok(nodes), None) =
                (<[u32; 6]>::try_from(p), p.iter().find(|&&n| n as usize >= in_core.len()))
            else {
                continue;
            };
            let height = prism_height(nodes.map(|n| mesh.points[n as usize]));
            if height > 0.0 {
                last_height.insert(key(top), height);
            }
        }
    }
    let layer_faces = layer_triangles(mesh, layer_zone, &in_core);
    let mut ratios = Vec::new();
    let mut front_triangles = 0;
    for t in core_tets() {
        for face in CellKind::Tetrahedron.faces() {
            let [a, b, c] = [t[face[0]], t[face[1]], t[face[2]]];
            front_triangles += usize::from(layer_faces.contains(&key([a, b, c])));
            if let Some(&h) = last_height.get(&key([a, b, c])) {
                let x = |n: u32| mesh.points[n as usize];
                let apex = t.iter().copied().find(|n| ![a, b, c].contains(n)).map_or(x(a), x);
                ratios.push(height_over([x(a), x(b), x(c)], apex).abs() / h);
            }
        }
    }
    SizeJump {
        histogram: histogram(&ratios, growth),
        stats: RatioStats::of(ratios, 1.0 / growth, growth),
        front_triangles,
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

    /// A prism of height 0.5 under a tetrahedron of height 1.5 on its top: ratio 3, outside
    /// the band for r = 1.2 and in the bin (r^4, r^8].
    #[test]
    fn ratio_of_a_tet_on_a_prism() {
        let mut mesh = VolumeMesh {
            points: vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.0, 0.0, 0.5),
                DVec3::new(1.0, 0.0, 0.5),
                DVec3::new(0.0, 1.0, 0.5),
                DVec3::new(0.3, 0.3, 2.0),
            ],
            zone_names: vec!["layers".into(), "core".into()],
            ..Default::default()
        };
        mesh.push_cell(CellKind::Prism, &[0, 1, 2, 3, 4, 5], 0);
        mesh.push_cell(CellKind::Tetrahedron, &[3, 4, 5, 6], 1);
        let jump = measure(&mesh, 0, 1, 1.2);
        assert_eq!(jump.stats.count, 1);
        assert!((jump.stats.median - 3.0).abs() < 1e-12, "{:?}", jump.stats);
        assert_eq!(jump.stats.within_band, 0.0);
        assert_eq!(jump.histogram[5].1, 1, "{:?}", jump.histogram);
        assert_eq!(jump.front_triangles, 1);
    }

    /// A core tetrahedron on a layer tetrahedron (a stopped or split column's cell) is a front
    /// triangle the ratio leaves out.
    #[test]
    fn a_front_triangle_on_a_layer_tet_is_counted_not_measured() {
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
