//! Convex ridges ending on concave ones: a wing's trailing edge at its root on a plate.
//!
//! Around such a root the ring of triangles is the ridge's two sides and, between the two
//! concave edges where the sides meet the floor, the floor. No single direction sees them all:
//! the most normal one runs nearly along the floor, and its column stops in the first layer.
//! The exact offset there is the ridge's cylinder cut by the floor's offset plane; they meet
//! along the bisectors of the cylinder's normals and the floor's. So the ridge's fan goes on to
//! the root, each column turned towards the floor as far as the layer distance from both, and the
//! floor triangles at the root take the fan column heading most nearly their way. Between two
//! triangles with different columns, over their common edge, a chain of fan triangles from the
//! columns in between to the edge's far vertex closes the front, as at the end of any ridge.

use glam::DVec3;

use super::{edge_sides, push_sector_column, slerp, vertex_ring, FanFace, WallNormals, MAX_RIDGE_FAN_SCALE};
use crate::normals::most_normal::most_normal;
use crate::surface::features::{EdgeKind, Features};
use crate::surface::topology::Topology;
use crate::surface::Surface;

/// A vertex where one convex ridge ends between two concave ones.
#[derive(Clone, Debug)]
pub(super) struct RidgeRoot {
    pub vertex: u32,
    pub ridge: u32,
    /// The ring's triangles (with their corner at the vertex) in order from the ridge round to
    /// it: the ridge's first side, the floor, its other side.
    side_a: Vec<(u32, usize)>,
    floor: Vec<(u32, usize)>,
    side_b: Vec<(u32, usize)>,
    /// The edges from the last triangle of `side_a` through the floor's to the first of
    /// `side_b` (the two concave edges and the floor's edges between them), with their far
    /// vertices.
    seams: Vec<(u32, u32)>,
    /// The most normal direction of the floor's triangles.
    floor_normal: DVec3,
}

/// The ridge roots of the wall, sorted by vertex: vertices whose only cut edge (`is_cut`) is a
/// convex ridge and whose ring has exactly two concave edges, where a single column would be
/// longer than [`MAX_RIDGE_FAN_SCALE`] layer distances, with every seam's far vertex free
/// of cut edges (its single column closes the fan chains) and not shared with another root.
pub(super) fn find(
    surface: &Surface,
    topology: &Topology,
    features: &Features,
    is_cut: &impl Fn(u32) -> bool,
) -> Vec<RidgeRoot> {
    let concave = |e: u32| features.edge_kind[e as usize] == EdgeKind::ConcaveRidge;
    let mut far_taken = std::collections::HashSet::new();
    let mut roots = Vec::new();
    for v in 0..surface.points.len() as u32 {
        let Some(root) = root_at(surface, topology, v, &concave, is_cut) else { continue };
        let whole = |x: u32| !vertex_ring(surface, topology, x).edge_after.iter().any(|&e| is_cut(e));
        if root.seams.iter().all(|&(_, far)| whole(far) && !far_taken.contains(&far)) {
            far_taken.extend(root.seams.iter().map(|&(_, far)| far));
            roots.push(root);
        }
    }
    roots
}

/// The ridge root at `v`, if its ring is one.
fn root_at(
    surface: &Surface,
    topology: &Topology,
    v: u32,
    concave: &impl Fn(u32) -> bool,
    is_cut: &impl Fn(u32) -> bool,
) -> Option<RidgeRoot> {
    if topology.vertex_triangles(v).is_empty() {
        return None;
    }
    let ring = vertex_ring(surface, topology, v);
    let n = ring.triangles.len();
    let mut cuts = (0..n).filter(|&i| is_cut(ring.edge_after[i]));
    let (Some(i_ridge), None) = (cuts.next(), cuts.next()) else { return None };
    let ridge = ring.edge_after[i_ridge];
    if (0..n).filter(|&i| concave(ring.edge_after[i])).count() != 2 {
        return None;
    }
    // Where the vertex's one column stays as short as a ridge vertex's fan columns may be (the
    // edge of a box standing on a plate), it serves.
    let all: Vec<DVec3> = ring.triangles.iter().map(|&(t, _)| surface.triangle_normal(t as usize)).collect();
    if most_normal(&all).is_some_and(|m| m.extrusion_scale() <= MAX_RIDGE_FAN_SCALE) {
        return None;
    }
    // Walk the ring from the ridge: side a up to the first concave edge, the floor up to the
    // second, then side b.
    let (mut side_a, mut floor, mut side_b) = (Vec::new(), Vec::new(), Vec::new());
    let mut seams = Vec::new();
    let mut group = 0;
    for s in 1..=n {
        let i = (i_ridge + s) % n;
        [&mut side_a, &mut floor, &mut side_b][group].push(ring.triangles[i]);
        let e = ring.edge_after[i];
        if group == 1 || (group == 0 && concave(e)) {
            let [p, q] = topology.edges[e as usize];
            seams.push((e, if p == v { q } else { p }));
        }
        if concave(e) {
            group += 1;
        }
    }
    if floor.is_empty() || side_b.is_empty() {
        return None;
    }
    let normals: Vec<DVec3> = floor.iter().map(|&(t, _)| surface.triangle_normal(t as usize)).collect();
    let floor_normal = most_normal(&normals)?.direction;
    Some(RidgeRoot { vertex: v, ridge, side_a, floor, side_b, seams, floor_normal })
}

impl RidgeRoot {
    /// The columns of the ridge's two sides, each seeing its side and the floor, recorded as the
    /// sector columns on either side of the ridge in `ends` (t1's side first, as
    /// [`super::sector_columns`] records them).
    pub fn side_columns(
        &self,
        surface: &Surface,
        topology: &Topology,
        out: &mut WallNormals,
        ends: &mut Vec<(u32, u32, u32)>,
    ) {
        let side_column = |side: &[(u32, usize)], out: &mut WallNormals| {
            let col = push_sector_column(surface, self.vertex, side, out);
            let mut normals: Vec<DVec3> =
                side.iter().map(|&(t, _)| surface.triangle_normal(t as usize)).collect();
            normals.push(self.floor_normal);
            if let Some(m) = most_normal(&normals) {
                out.columns[col as usize].direction = m.direction;
                out.columns[col as usize].scale = m.extrusion_scale();
            }
            col
        };
        let a = side_column(&self.side_a, out);
        let b = side_column(&self.side_b, out);
        // Side a follows the ridge in the ring, so it is t1's side where the ridge runs from
        // this vertex.
        let from_here = topology.edges[self.ridge as usize][0] == self.vertex;
        ends.push(if from_here { (self.ridge, a, b) } else { (self.ridge, b, a) });
    }

    /// The fan across the ridge at the root from sector column `a` (t1's side) to `b`, `m`
    /// segments: the ridge's fan directions turned towards the floor to the bisector.
    pub fn fan(
        &self,
        surface: &Surface,
        topology: &Topology,
        (a, b): (u32, u32),
        m: usize,
        out: &mut WallNormals,
    ) -> Vec<u32> {
        let (p1, q1, _) = edge_sides(surface, topology, self.ridge, self.vertex);
        let mut cols = vec![a];
        for j in 1..m {
            let across = slerp(p1, q1, j as f64 / m as f64);
            let (direction, scale) = most_normal(&[across, self.floor_normal])
                .map_or((across, 1.0), |x| (x.direction, x.extrusion_scale()));
            cols.push(out.columns.len() as u32);
            out.cylinder_normals.push((self.vertex, across));
            out.columns.push(super::ColumnSeed { vertex: self.vertex, direction, scale });
            out.stats.fan_columns += 1;
        }
        cols.push(b);
        cols
    }

    /// Give every floor triangle at the root the column of `fan` (the ridge's fan here) heading
    /// most nearly along its middle, no earlier in the fan than its predecessor's in the ring,
    /// and close the front over every seam whose two triangles took different columns.
    pub fn close_onto_floor(&self, surface: &Surface, fan: &[u32], out: &mut WallNormals) {
        let (t, corner) = self.side_a[0];
        let side_a_column = out.triangle_columns[t as usize][corner];
        let fan: Vec<u32> = if fan.first() == Some(&side_a_column) {
            fan.to_vec()
        } else {
            fan.iter().rev().copied().collect()
        };
        let at = surface.points[self.vertex as usize];
        // Headings along the floor.
        let up = self.floor_normal;
        let flat = |d: DVec3| (d - d.dot(up) * up).normalize_or_zero();
        let headings: Vec<DVec3> = fan.iter().map(|&c| flat(out.columns[c as usize].direction)).collect();
        let mut picks = vec![0];
        for &(t, corner) in &self.floor {
            let tri = surface.triangles[t as usize];
            let middle = (surface.points[tri[(corner + 1) % 3] as usize] - at).normalize_or_zero()
                + (surface.points[tri[(corner + 2) % 3] as usize] - at).normalize_or_zero();
            let middle = flat(middle);
            let best =
                (0..fan.len()).max_by(|&i, &j| headings[i].dot(middle).total_cmp(&headings[j].dot(middle)));
            let pick = best.unwrap_or(0).max(*picks.last().expect("starts with side a"));
            out.triangle_columns[t as usize][corner] = fan[pick];
            picks.push(pick);
        }
        picks.push(fan.len() - 1);
        let patch = surface.triangle_patch[self.floor[0].0 as usize];
        // The triangle before each seam in the ring holds the far vertex's single column.
        let before = std::iter::once(self.side_a[self.side_a.len() - 1]).chain(self.floor.iter().copied());
        for (k, (&(_, far), (t, _))) in self.seams.iter().zip(before).enumerate() {
            let tri = surface.triangles[t as usize];
            let corner = tri.iter().position(|&x| x == far).expect("the seam's far vertex is on it");
            let far_col = out.triangle_columns[t as usize][corner];
            for i in picks[k]..picks[k + 1] {
                out.fan_faces.push(FanFace::new(&[fan[i], far_col, fan[i + 1]], patch));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::closed_front_tests::unmatched_edges;
    use super::super::wall_normals;
    use crate::surface::family::{family_body_at, Family};
    use crate::surface::features::Features;
    use crate::surface::topology::Topology;

    /// On wings standing on a plate or a cylinder, every trailing edge's root is found, the
    /// initial front stays closed, and every column at a root sees each wall triangle it stands
    /// on from the front (without the fan, the root's one column ran nearly along the floor).
    #[test]
    fn trailing_edge_roots_get_fans_that_see_the_floor() {
        for (family, seed) in [(Family::WingPlate, 0), (Family::WingPlate, 4), (Family::FinCylinder, 3)] {
            let s = family_body_at(family, seed, 1.0);
            let topo = Topology::new(&s);
            let features = Features::compute(&s, &topo, 30.0);
            let normals = wall_normals(&s, &topo, &features, 20.0);
            assert!(normals.stats.ridge_roots >= 1, "{family:?} {seed}: no ridge root found");
            assert_eq!(unmatched_edges(&normals), vec![], "{family:?} {seed}: the front is open");
            let roots: Vec<u32> = normals.cylinder_normals.iter().map(|&(v, _)| v).collect();
            for (t, cols) in normals.triangle_columns.iter().enumerate() {
                for &c in cols {
                    let seed_col = normals.columns[c as usize];
                    if roots.contains(&seed_col.vertex) {
                        let cos = seed_col.direction.dot(s.triangle_normal(t));
                        assert!(cos > 0.1, "{family:?} {seed}: root column {c} grazes triangle {t}: {cos}");
                    }
                }
            }
        }
    }
}
