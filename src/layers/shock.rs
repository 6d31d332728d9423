//! The entropy plan: where each column's characteristic meets a shock, computed from the exact
//! wall distance before the column gets there.
//!
//! The layer front is the first-arrival offset {x : d(x) = t} of the walls with layers. A column
//! from wall vertex `v` follows its characteristic `x(t) = base + dir * scale * t`, on which its
//! own walls (the triangles around `v`) are `t` away. Its shock is the first `t` at which a wall
//! that is not its own comes nearer than that: past it, the column would be behind the offset,
//! inside another wall's layers. Concave ridges and corners (the bisector), smooth valleys (the
//! focal surface), ledges and thin gaps (the medial surface) are all found this one way.

use rayon::prelude::*;

use super::entropy::VertexWalls;
use super::front::Columns;

/// A wall that is not the column's own must be nearer than the column's own by this fraction of
/// the layer height at that distance to count as a shock. It absorbs round-off and the faceting
/// of walls that continue the column's own plane (a coplanar triangle is exactly as near, never
/// nearer), and it places the shock within this fraction of a layer past the exact one.
pub const TOLERANCE: f64 = 0.1;

/// Bisection steps between the last layer short of the shock and the first past it: the shock
/// is then known to 1/64 of a layer.
const BISECTIONS: u32 = 6;

/// For every column, the distance from the wall (in the column's own units, as
/// [`Columns::distance`]) at which its characteristic meets a shock; infinite where it meets none
/// within its stack, and for columns born above the wall (splits), which have no plan.
#[derive(Clone, Debug, Default)]
pub struct Shocks {
    pub at: Vec<f64>,
}

impl Shocks {
    /// Plan the columns added since the last call.
    pub fn extend(&mut self, columns: &Columns, walls: &VertexWalls) {
        let first = self.at.len();
        let planned: Vec<f64> = (first..columns.len())
            .into_par_iter()
            .map(|c| if columns.born_at[c] == 0 { shock_of(columns, walls, c) } else { f64::INFINITY })
            .collect();
        self.at.extend(planned);
    }

    /// Whether column `c` meets its shock at its layer `k`, so that it merges there.
    /// The column ends at the layer whose top is nearest its shock: past it, or short of it by
    /// less than half the next layer.
    pub fn passed(&self, columns: &Columns, c: usize, k: u32) -> bool {
        let Some(d) = columns.distance(c, k) else { return false };
        let next = columns.distance(c, k + 1).unwrap_or(d);
        0.5 * (d + next) > self.at[c]
    }
}

/// The shock of wall column `c` (see [`Shocks`]).
fn shock_of(columns: &Columns, walls: &VertexWalls, c: usize) -> f64 {
    let Some(spec) = columns.spec[c] else { return f64::INFINITY };
    let v = columns.wall_vertex[c];
    let at = |t: f64| columns.slide[c].project(columns.base[c] + columns.dir[c] * (columns.scale[c] * t));
    let past = |t: f64, height: f64| walls.foreign_nearer(at(t), v, t - TOLERANCE * height);
    let mut before = 0.0;
    for k in 1..=spec.max_count() {
        let d = spec.distance(k);
        let height = d - before;
        if past(d, height) {
            let (mut short, mut beyond) = (before, d);
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (short + beyond);
                if past(mid, height) {
                    beyond = mid;
                } else {
                    short = mid;
                }
            }
            return beyond;
        }
        before = d;
    }
    f64::INFINITY
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::LayerSpec;
    use crate::layers::front::ColumnStart;
    use crate::surface::shapes;
    use crate::surface::topology::Topology;
    use crate::surface::Surface;
    use glam::DVec3;

    /// The shocks of columns up from `bases` along `dirs` (scales 1) over `surface`, with 20
    /// layers of 0.05.
    fn shocks(surface: &Surface, starts: &[(u32, DVec3, f64)]) -> Vec<f64> {
        let topology = Topology::new(surface);
        let walls = VertexWalls::new(surface, &topology, |_| true);
        let mut columns = Columns::default();
        for &(v, dir, scale) in starts {
            columns.push(ColumnStart {
                base: surface.points[v as usize],
                dir,
                scale,
                node: v,
                layers: 0,
                wall_vertex: v,
                slide: Default::default(),
                spec: Some(LayerSpec::fixed(0.05, 1.0, 20)),
                last_step: 0.0,
            });
        }
        let mut plan = Shocks::default();
        plan.extend(&columns, &walls);
        plan.at
    }

    fn vertex_at(surface: &Surface, p: DVec3) -> u32 {
        surface.points.iter().position(|q| q.distance(p) < 1e-9).expect("a vertex there") as u32
    }

    #[test]
    fn a_face_column_beside_a_groove_meets_the_bisector_and_the_ridge_column_goes_on() {
        // A 90-degree groove along y at x = 4, z = 1, walls at 45 deg; grid of 4 per unit.
        let surface = shapes::grooved_block(90.0, 4);
        let ridge = vertex_at(&surface, DVec3::new(4.0, 1.0, 1.0));
        // A wall vertex 0.25 along z up the left wall (x = 3.75), 0.25 * sqrt 2 from the ridge.
        let face = vertex_at(&surface, DVec3::new(3.75, 1.0, 1.25));
        let n = DVec3::new(1.0, 0.0, 1.0).normalize();
        let at = shocks(&surface, &[(face, n, 1.0), (ridge, DVec3::Z, 2f64.sqrt())]);
        // Its characteristic meets the bisector plane x = 4 at t = 0.25 sqrt 2.
        let exact = 0.25 * 2f64.sqrt();
        assert!(
            at[0] >= exact && at[0] <= exact + TOLERANCE * 0.05 * 1.01,
            "face column's shock at {}",
            at[0]
        );
        // The ridge column rises on the bisector until the lips (z = 2, t = 1/sqrt 2) are nearer.
        assert!(at[1] > 0.7, "ridge column's shock at {}", at[1]);
    }

    #[test]
    fn columns_on_a_flat_or_convex_wall_meet_no_shock() {
        let cube = shapes::cuboid(DVec3::splat(2.0), 4);
        let v = vertex_at(&cube, DVec3::new(1.0, 1.0, 2.0));
        let corner = vertex_at(&cube, DVec3::new(2.0, 2.0, 2.0));
        let at = shocks(&cube, &[(v, DVec3::Z, 1.0), (corner, DVec3::ONE.normalize(), 3f64.sqrt())]);
        assert_eq!(at, vec![f64::INFINITY; 2]);
    }

    #[test]
    fn the_walls_of_a_thin_slot_meet_at_its_medial_plane() {
        // A 2 x 1 x 1 block in voxels of 0.25 without the middle column of voxels: a slot 0.25
        // wide (x in [1, 1.25]) open at the top; its walls face each other 0.125 from the middle.
        let s = shapes::voxels([8, 4, 4], 0.25, 1, |i, _, k| !(i == 4 && k >= 1));
        let wall = vertex_at(&s, DVec3::new(1.0, 0.5, 0.75));
        let at = shocks(&s, &[(wall, DVec3::X, 1.0)]);
        assert!(at[0] >= 0.125 && at[0] <= 0.125 + TOLERANCE * 0.05 * 1.01, "slot wall's shock at {}", at[0]);
    }
}
