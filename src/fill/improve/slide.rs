//! Sliding front points down their columns: the one change of the core's boundary the
//! improvement makes.
//!
//! A sliver whose four nodes are all on the front (a front triangle and a front point nearly in
//! its plane, where the front is crumpled) has no interior face or edge whose flip mends it and
//! no room for a point. Lowering one of its front points along the last step of its column
//! lifts it out of that plane. The last layer gets shorter by at most [`MAX_SINK`] of its step,
//! so the layer heights still grow by no more than the growth ratio (DESIGN.md, smoothness) and
//! the stack keeps at least 95% of its thickness. Every cell outside the core at the point (the
//! layer cells and the pyramids on the front's quads) must stay valid by the checker's exact
//! test, and the tetrahedra at it positive: the point stays inside its star, so the mesh stays
//! a partition of the domain.

use std::collections::HashMap;

use super::{Change, TetMesh};
use crate::fill::{ClosedBoundary, MARKER_FRONT};
use crate::geometry::DVec3;
use crate::mesh::{CellKind, VolumeMesh};
use crate::quality::validity::cell_validity;

/// How far down its last step a front point may slide (fraction of the step; less when the
/// growth ratio r is below 1.12, see [`TetMesh::max_sink`]): at 0.2 a stack of 10 layers at
/// growth 1.2 loses at most 4% of its thickness.
pub const MAX_SINK: f64 = 0.2;

/// Places tried along the path, evenly spaced down to [`MAX_SINK`].
const SINK_STEPS: usize = 8;

/// How a boundary point may move.
#[derive(Clone, Copy, Debug)]
enum Freedom {
    Fixed,
    /// Down the last step of its column, from where it was built.
    Column {
        origin: DVec3,
        step: DVec3,
    },
    /// Anywhere its cells stay valid: the apex of a pyramid on a front quad (it is a point of
    /// the core, on the boundary only because the mesher takes triangles).
    Free,
}

/// The front points that may move, and the cells outside the core at them.
#[derive(Clone, Debug, Default)]
pub struct FrontSlides {
    /// How every boundary point may move.
    freedom: Vec<Freedom>,
    /// The cells outside the core at the points that may move; a node below the boundary
    /// point count is a boundary point, the others index `outer_points`.
    cells: Vec<(CellKind, [u32; 8])>,
    cells_at: HashMap<u32, Vec<u32>>,
    outer_points: Vec<DVec3>,
}

impl FrontSlides {
    /// The freedom of the front points of `boundary` (boundary point `i` being node `nodes[i]`
    /// of `mesh`, the mesh around the core, and `steps[i]` its column's last step) and the
    /// cells of `mesh` at them. A point on a boundary triangle that is not the front's stays.
    pub fn new(boundary: &ClosedBoundary, steps: &[DVec3], mesh: &VolumeMesh, nodes: &[u32]) -> FrontSlides {
        let n = boundary.points.len();
        let mut freedom: Vec<Freedom> = (0..n)
            .map(|i| match steps.get(i) {
                Some(&step) if step.is_finite() => Freedom::Column { origin: boundary.points[i], step },
                _ => Freedom::Free,
            })
            .collect();
        for (t, &marker) in boundary.triangles.iter().zip(&boundary.markers) {
            if marker != MARKER_FRONT {
                for &v in t {
                    freedom[v as usize] = Freedom::Fixed;
                }
            }
        }
        let mut local: HashMap<u32, u32> = nodes.iter().enumerate().map(|(i, &m)| (m, i as u32)).collect();
        let mut slides = FrontSlides { freedom, ..Default::default() };
        // (apex of a pyramid, in another cell) for every boundary point.
        let mut seen = vec![(false, false); n];
        for (kind, cell) in mesh.cells() {
            for (k, m) in cell.iter().enumerate() {
                if let Some(&i) = local.get(m).filter(|&&i| (i as usize) < n) {
                    let apex = kind == CellKind::Pyramid && k == 4;
                    let (as_apex, otherwise) = &mut seen[i as usize];
                    *as_apex |= apex;
                    *otherwise |= !apex;
                }
            }
        }
        for (f, seen) in slides.freedom.iter_mut().zip(seen) {
            if matches!(f, Freedom::Free) && seen != (true, false) {
                *f = Freedom::Fixed;
            }
        }
        for (kind, cell) in mesh.cells() {
            let moves = |m: &u32| {
                local
                    .get(m)
                    .and_then(|&i| slides.freedom.get(i as usize))
                    .is_some_and(|f| !matches!(f, Freedom::Fixed))
            };
            if !cell.iter().any(moves) {
                continue;
            }
            let mut corners = [0u32; 8];
            for (corner, &m) in corners.iter_mut().zip(cell) {
                *corner = *local.entry(m).or_insert_with(|| {
                    slides.outer_points.push(mesh.points[m as usize]);
                    (n + slides.outer_points.len() - 1) as u32
                });
            }
            let c = slides.cells.len() as u32;
            for &v in corners[..kind.node_count()].iter().filter(|&&v| (v as usize) < n) {
                if !matches!(slides.freedom[v as usize], Freedom::Fixed) {
                    slides.cells_at.entry(v).or_default().push(c);
                }
            }
            slides.cells.push((kind, corners));
        }
        slides
    }

    /// Whether every cell outside the core at point `v` is valid with `v` at `p` (the other
    /// boundary points at their places in `points`).
    fn cells_stay_valid(&self, v: u32, p: DVec3, points: &[DVec3]) -> bool {
        let n = self.freedom.len();
        let at = |u: u32| match u as usize {
            _ if u == v => p,
            i if i < n => points[i],
            i => self.outer_points[i - n],
        };
        self.cells_at.get(&v).is_none_or(|cells| {
            cells.iter().all(|&c| {
                let (kind, nodes) = &self.cells[c as usize];
                let mut x = [DVec3::ZERO; 8];
                for (xi, &u) in x.iter_mut().zip(&nodes[..kind.node_count()]) {
                    *xi = at(u);
                }
                cell_validity(*kind, &x).is_valid()
            })
        })
    }
}

impl TetMesh {
    /// Let the front points move ([`TetMesh::move_front_point`]).
    pub fn allow_front_slides(&mut self, slides: FrontSlides) {
        self.slides = Some(slides);
    }

    /// How far down its last step a column's top may go: [`MAX_SINK`], and no further than
    /// keeps the last layer within the growth ratio (the size band) of the one under it.
    fn max_sink(&self) -> f64 {
        MAX_SINK.min(1.0 - 1.0 / (self.band * self.band)).max(0.0)
    }

    /// Move front point `v` where the worst tetrahedron at it is best and every cell outside
    /// the core at it stays valid: a column's top down its last step (to [`MAX_SINK`] of it),
    /// a pyramid's apex anywhere (hill climbing, then back towards where it was until its
    /// pyramid is valid). `None` when it may not move or no other place keeps them valid.
    pub fn move_front_point(&self, v: u32) -> Option<Change> {
        let slides = self.slides.as_ref()?;
        let ball = self.ball_of(v);
        let here = self.points[v as usize];
        let valid = |p: &DVec3| *p != here && slides.cells_stay_valid(v, *p, &self.points);
        let best = match *slides.freedom.get(v as usize)? {
            Freedom::Fixed => return None,
            Freedom::Column { origin, step } => {
                (0..=SINK_STEPS)
                    .map(|k| origin - step * (self.max_sink() * k as f64 / SINK_STEPS as f64))
                    .filter(valid)
                    .map(|p| (self.ball_quality(&ball, v, p), p))
                    .max_by(|x, y| x.0.total_cmp(&y.0))?
                    .1
            }
            Freedom::Free => {
                let (p, _) = self.best_position(&ball, v, here);
                (0..4).map(|k| here.lerp(p, 0.5f64.powi(k))).find(valid)?
            }
        };
        Some(self.point_move(&ball, v, best))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fill::improve::{ImproveOptions, SLIVER_THRESHOLD};
    use crate::fill::MARKER_FARFIELD;
    use crate::quality::validity::gather;

    /// A front triangle (0, 1, 2) at z = 0 on a prism one high, and a front point (3) of no
    /// column 0.05 over the triangle's centre: the core tetrahedron on them is a flat sliver.
    fn flat_cap() -> (TetMesh, ClosedBoundary, VolumeMesh, Vec<u32>) {
        let s = 3f64.sqrt();
        let top = [DVec3::ZERO, DVec3::X, DVec3::new(0.5, s / 2.0, 0.0)];
        let apex = DVec3::new(0.5, s / 6.0, 0.05);
        let points = top.iter().map(|p| *p - DVec3::Z).chain(top).chain([apex]).collect();
        let mut mesh = VolumeMesh { points, ..Default::default() };
        mesh.push_cell(CellKind::Prism, &[0, 1, 2, 3, 4, 5], 0);
        let boundary = ClosedBoundary {
            points: top.into_iter().chain([apex]).collect(),
            triangles: vec![[0, 1, 2]],
            markers: vec![MARKER_FRONT],
        };
        let core = TetMesh::new(boundary.points.clone(), vec![[0, 1, 2, 3]], 4);
        (core, boundary, mesh, vec![3, 4, 5, 6])
    }

    fn steps() -> Vec<DVec3> {
        vec![DVec3::Z, DVec3::Z, DVec3::Z, DVec3::NAN]
    }

    fn prism_valid(slides: &FrontSlides, core: &TetMesh) -> bool {
        let (kind, nodes) = slides.cells[0];
        let mut points: Vec<DVec3> = core.points.clone();
        points.extend(&slides.outer_points);
        cell_validity(kind, &gather(&points, &nodes[..6]).expect("in range")).is_valid()
    }

    #[test]
    fn a_front_sliver_is_mended_by_sinking_a_top_down_its_column() {
        let (mut core, boundary, mesh, nodes) = flat_cap();
        core.keep_front_match(HashMap::new(), 1.2);
        let slides = FrontSlides::new(&boundary, &steps(), &mesh, &nodes);
        core.allow_front_slides(slides);
        let before = core.quality([0, 1, 2, 3]);
        assert!(before < SLIVER_THRESHOLD);
        assert!(core.move_front_point(3).is_none(), "a point of no column nor pyramid stays");
        let change = core.move_front_point(0).expect("the top slides");
        let (v, p) = change.point.expect("a move");
        assert_eq!(v, 0);
        assert!(change.after > change.before);
        assert_eq!((p.x, p.y), (0.0, 0.0), "along its step");
        assert!((-MAX_SINK - 1e-12..0.0).contains(&p.z), "down at most MAX_SINK of its step: {p}");
        let mut moved = core.clone();
        moved.apply(&change);
        assert!(prism_valid(moved.slides.as_ref().unwrap(), &moved));
        let after = core.improve(&ImproveOptions::default());
        assert!(after.moved_front_points >= 1, "{after:?}");
        let worst = core.worst(core.tets());
        assert!(worst > 2.0 * before, "worst angle {before} -> {worst}");
        for (i, q) in core.points[..3].iter().enumerate() {
            assert!(q.z >= -MAX_SINK - 1e-12 && q.z <= 0.0, "point {i} at {q}");
        }
        assert_eq!(core.points[3], boundary.points[3]);
    }

    #[test]
    fn a_top_stays_where_its_layer_would_outgrow_the_one_under_it_or_on_another_boundary() {
        let (mut core, mut boundary, mesh, nodes) = flat_cap();
        // Growth 1.05: the last layer may lose 1 - 1/1.05^2 (9.3%) of its step, no more.
        core.keep_front_match(HashMap::new(), 1.05);
        core.allow_front_slides(FrontSlides::new(&boundary, &steps(), &mesh, &nodes));
        let p = core.move_front_point(0).and_then(|c| c.point).expect("a move").1;
        assert!(p.z >= -(1.0 - 1.0 / 1.05f64.powi(2)) - 1e-12, "{p}");
        // A point on a triangle of the farfield (or a wall without layers) never moves.
        boundary.triangles.push([0, 3, 1]);
        boundary.markers.push(MARKER_FARFIELD);
        core.allow_front_slides(FrontSlides::new(&boundary, &steps(), &mesh, &nodes));
        assert!(core.move_front_point(0).is_none());
        assert!(core.move_front_point(2).is_some());
    }

    #[test]
    fn a_top_never_slides_where_its_prism_turns_over() {
        let (mut core, boundary, mut mesh, nodes) = flat_cap();
        // The prism is one tenth as high as the step says: sinking by 0.2 puts the top
        // under its bottom.
        for p in &mut mesh.points[..3] {
            p.z = -0.1;
        }
        core.keep_front_match(HashMap::new(), 1.2);
        let slides = FrontSlides::new(&boundary, &steps(), &mesh, &nodes);
        assert!(slides.cells_stay_valid(0, DVec3::new(0.0, 0.0, -0.05), &core.points));
        assert!(!slides.cells_stay_valid(0, DVec3::new(0.0, 0.0, -0.15), &core.points));
        core.allow_front_slides(slides);
        let p = core.move_front_point(0).and_then(|c| c.point).expect("a move").1;
        assert!(p.z > -0.1, "{p}");
    }

    /// The apex of a pyramid on a front quad (a point of the core the mesher sees as
    /// boundary) moves freely but never through the quad; the quad's corners, with no step,
    /// stay.
    #[test]
    fn a_pyramid_apex_moves_only_where_its_pyramid_stands() {
        let quad = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        let apex = DVec3::new(0.5, 0.5, 0.5);
        let points = quad.into_iter().chain([apex]).collect();
        let mut mesh = VolumeMesh { points, ..Default::default() };
        mesh.push_cell(CellKind::Pyramid, &[0, 1, 2, 3, 4], 1);
        let boundary = ClosedBoundary {
            points: mesh.points.clone(),
            triangles: vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]],
            markers: vec![MARKER_FRONT; 4],
        };
        let slides = FrontSlides::new(&boundary, &[DVec3::NAN; 5], &mesh, &[0, 1, 2, 3, 4]);
        assert!(matches!(slides.freedom[4], Freedom::Free));
        assert!(slides.freedom[..4].iter().all(|f| matches!(f, Freedom::Fixed)));
        let at = |z: f64| slides.cells_stay_valid(4, DVec3::new(0.3, 0.6, z), &boundary.points);
        assert!(at(0.2) && at(2.0));
        assert!(!at(0.0) && !at(-0.1), "through its quad");
    }
}
