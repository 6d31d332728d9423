//! Sliding front points down their columns: the one change of the core's boundary the
//! improvement makes.
//!
//! A sliver whose four nodes are all on the front (a front triangle and a front point nearly in
//! its plane, where the front is crumpled) has no interior face or edge whose flip mends it and
//! no room for a point. Lowering one of its front points along the last step of its column
//! (where columns merged and no prism is under it, along the front's normal by the step of
//! the columns around it) lifts it out of that plane. The last layer gets shorter by at most
//! [`MAX_SINK`] of its step, no more than keeps it within the growth ratio of the layer under
//! it (smoothness), and the stack loses at most [`MAX_THINNING`] of its thickness.
//! A pyramid's apex on a front quad moves too, its height kept in the size band. Every cell
//! outside the core at the point (the layer cells and the pyramids on the front's quads) must
//! stay valid by the checker's exact test, and the tetrahedra at it positive: the point stays
//! inside its star, so the mesh stays a partition of the domain. (The last layer heights the
//! front match keeps, [`TetMesh::keep_front_match`], are those before any slide.)

use std::collections::HashMap;

use super::{Change, TetMesh};
use crate::fill::{ClosedBoundary, MARKER_FRONT};
use crate::geometry::{triangle_area_vector, DVec3};
use crate::layers::guard::quad_frame;
use crate::mesh::{CellKind, VolumeMesh};
use crate::quality::validity::cell_validity;

/// How far down its last step a front point may slide (fraction of the step; less when the
/// growth ratio r is below 1.12, see [`TetMesh::max_sink`], or the stack is thin).
pub const MAX_SINK: f64 = 0.2;

/// The most of its stack's thickness a slide may take (the stack is measured down the
/// prisms' vertical edges under the point; `shared/bench/measure.py` counts a column covered
/// from 95% of its thickness).
pub const MAX_THINNING: f64 = 0.04;

/// Places tried along the path, evenly spaced down to [`MAX_SINK`].
const SINK_STEPS: usize = 8;

/// How a boundary point may move.
#[derive(Clone, Copy, Debug)]
enum Freedom {
    Fixed,
    /// Down the last step of its column, from where it was built, by at most `reach` of it
    /// ([`MAX_SINK`], less on a thin stack).
    Column {
        origin: DVec3,
        step: DVec3,
        reach: f64,
    },
    /// Anywhere its cells stay valid and its height over the plane through `centre` normal
    /// to `normal` within the size band of `height`, where it was built: the apex of a
    /// pyramid on a front quad (a point of the core, on the boundary only because the mesher
    /// takes triangles; its height matches the last layer under the quad).
    Apex {
        centre: DVec3,
        normal: DVec3,
        height: f64,
    },
    /// Not known yet: a point with no column under it, an apex if only pyramids have it so.
    Unknown,
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
    /// cells of `mesh` at them. A point on a boundary triangle that is not the front's, or on
    /// the boundary of `mesh`, stays.
    pub fn new(boundary: &ClosedBoundary, steps: &[DVec3], mesh: &VolumeMesh, nodes: &[u32]) -> FrontSlides {
        let local: HashMap<u32, u32> = nodes.iter().enumerate().map(|(i, &m)| (m, i as u32)).collect();
        let mut freedom = column_freedom(boundary, steps, mesh, nodes);
        for (t, &marker) in boundary.triangles.iter().zip(&boundary.markers) {
            if marker != MARKER_FRONT {
                for &v in t {
                    freedom[v as usize] = Freedom::Fixed;
                }
            }
        }
        // A top on the mesh's boundary (a column that slid on a patch without layers, whose
        // layer faces lie in its plane) stays, even where no core boundary triangle of that
        // patch reaches it.
        for m in mesh.boundary.nodes() {
            if let Some(&i) = local.get(&m) {
                freedom[i as usize] = Freedom::Fixed;
            }
        }
        settle_apexes(&mut freedom, mesh, &local);
        borrow_neighbour_columns(&mut freedom, boundary);
        for f in &mut freedom {
            if matches!(f, Freedom::Unknown) {
                *f = Freedom::Fixed;
            }
        }
        let mut slides = FrontSlides { freedom, ..Default::default() };
        slides.gather_cells(mesh, local);
        slides
    }

    /// Keep the cells of `mesh` at the points that move, their nodes numbered by `local`
    /// (mesh node to boundary point), extended to the other nodes.
    fn gather_cells(&mut self, mesh: &VolumeMesh, mut local: HashMap<u32, u32>) {
        let n = self.freedom.len();
        for (kind, cell) in mesh.cells() {
            if !cell.iter().any(|m| local.get(m).is_some_and(|&i| self.moves(i))) {
                continue;
            }
            let mut corners = [0u32; 8];
            for (corner, &m) in corners.iter_mut().zip(cell) {
                *corner = *local.entry(m).or_insert_with(|| {
                    self.outer_points.push(mesh.points[m as usize]);
                    (n + self.outer_points.len() - 1) as u32
                });
            }
            let c = self.cells.len() as u32;
            for &v in &corners[..kind.node_count()] {
                if self.moves(v) {
                    self.cells_at.entry(v).or_default().push(c);
                }
            }
            self.cells.push((kind, corners));
        }
    }

    /// Whether boundary point `v` may move (false for the other points).
    fn moves(&self, v: u32) -> bool {
        self.freedom.get(v as usize).is_some_and(|f| !matches!(f, Freedom::Fixed | Freedom::Unknown))
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

/// A column's top for every boundary point with a last step (its reach down it bounded by
/// [`MAX_SINK`] and [`MAX_THINNING`] of the stack of prisms under it), [`Freedom::Unknown`]
/// for the others.
fn column_freedom(
    boundary: &ClosedBoundary,
    steps: &[DVec3],
    mesh: &VolumeMesh,
    nodes: &[u32],
) -> Vec<Freedom> {
    let stack = StackHeights::of(mesh);
    (0..boundary.points.len())
        .map(|i| match steps.get(i) {
            Some(&step) if step.is_finite() && step != DVec3::ZERO => {
                let thinning = MAX_THINNING * stack.under(nodes[i]) / step.length();
                Freedom::Column { origin: boundary.points[i], step, reach: MAX_SINK.min(thinning) }
            }
            _ => Freedom::Unknown,
        })
        .collect()
}

/// The points of no column that are the apex of a pyramid and of no other cell of `mesh` move
/// as one ([`apex_freedom`]).
fn settle_apexes(freedom: &mut [Freedom], mesh: &VolumeMesh, local: &HashMap<u32, u32>) {
    // (the apex's freedom in the last pyramid it tops, whether it is in another cell)
    let mut seen = vec![(None, false); freedom.len()];
    for (kind, cell) in mesh.cells() {
        for (k, m) in cell.iter().enumerate() {
            let Some((as_apex, otherwise)) = local.get(m).and_then(|&i| seen.get_mut(i as usize)) else {
                continue;
            };
            if kind == CellKind::Pyramid && k == 4 {
                *as_apex = Some(apex_freedom(std::array::from_fn(|j| mesh.points[cell[j] as usize])));
            } else {
                *otherwise = true;
            }
        }
    }
    for (f, seen) in freedom.iter_mut().zip(seen) {
        if let (Freedom::Unknown, (Some(apex), false)) = (&f, seen) {
            *f = apex;
        }
    }
}

/// A front point of no column and no pyramid's apex (where columns merged in the last layers,
/// over tetrahedra and pyramids) sinks along the front's normal there, as far as the columns
/// around it on the front may: their mean step, their least reach.
fn borrow_neighbour_columns(freedom: &mut [Freedom], boundary: &ClosedBoundary) {
    let n = freedom.len();
    let mut normal = vec![DVec3::ZERO; n];
    // (sum of the neighbours' step lengths, their least reach, how many)
    let mut around = vec![(0.0, f64::INFINITY, 0usize); n];
    for (t, _) in boundary.triangles.iter().zip(&boundary.markers).filter(|(_, &m)| m == MARKER_FRONT) {
        let [a, b, c] = t.map(|v| boundary.points[v as usize]);
        let area = triangle_area_vector(a, b, c);
        for &v in t {
            normal[v as usize] += area;
            for &u in t {
                if let Freedom::Column { step, reach, .. } = freedom[u as usize] {
                    let (sum, least, count) = &mut around[v as usize];
                    (*sum, *least, *count) = (*sum + step.length(), least.min(reach), *count + 1);
                }
            }
        }
    }
    for (v, f) in freedom.iter_mut().enumerate() {
        let (sum, least, count) = around[v];
        let direction = normal[v].normalize_or_zero();
        if matches!(f, Freedom::Unknown) && count > 0 && direction != DVec3::ZERO {
            let step = direction * (sum / count as f64);
            *f = Freedom::Column { origin: boundary.points[v], step, reach: least };
        }
    }
}

/// The freedom of the apex of the pyramid `x` (its base, then its apex).
fn apex_freedom(x: [DVec3; 5]) -> Freedom {
    let (centre, normal) = quad_frame([x[0], x[1], x[2], x[3]]);
    Freedom::Apex { centre, normal, height: (x[4] - centre).dot(normal) }
}

/// The height of the stack of prisms under every node: the lengths of their vertical edges,
/// followed down to the wall (or to a cell that is not a prism).
struct StackHeights<'a> {
    below: HashMap<u32, u32>,
    points: &'a [DVec3],
}

impl StackHeights<'_> {
    fn of(mesh: &VolumeMesh) -> StackHeights<'_> {
        let prisms = mesh.block(CellKind::Prism);
        let below = prisms.iter().flat_map(|p| (0..3).map(move |i| (p[i + 3], p[i]))).collect();
        StackHeights { below, points: &mesh.points }
    }

    fn under(&self, top: u32) -> f64 {
        let (mut height, mut at) = (0.0, top);
        // No stack has more layers than the mesh has points (a guard against a cycle).
        for _ in 0..self.points.len() {
            let Some(&next) = self.below.get(&at) else { break };
            height += self.points[at as usize].distance(self.points[next as usize]);
            at = next;
        }
        height
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
    /// the core at it stays valid: a column's top down its last step (as far as its reach and
    /// the growth ratio allow, [`TetMesh::max_sink`]), a pyramid's apex to its best place
    /// (hill climbing) with its height over the quad brought into the size band, then back
    /// towards where it was until its pyramid is valid. `None` when it may not move or no other
    /// place keeps them valid.
    pub fn move_front_point(&self, v: u32) -> Option<Change> {
        let slides = self.slides.as_ref()?;
        let ball = self.ball_of(v);
        let here = self.points[v as usize];
        let valid = |p: &DVec3| *p != here && slides.cells_stay_valid(v, *p, &self.points);
        let best = match *slides.freedom.get(v as usize)? {
            Freedom::Fixed | Freedom::Unknown => return None,
            Freedom::Column { origin, step, reach } => {
                (0..=SINK_STEPS)
                    .map(|k| origin - step * (self.max_sink().min(reach) * k as f64 / SINK_STEPS as f64))
                    .filter(valid)
                    .map(|p| (self.ball_quality(&ball, v, p), p))
                    .max_by(|x, y| x.0.total_cmp(&y.0))?
                    .1
            }
            Freedom::Apex { centre, normal, height } => {
                // The best place, brought into the band of heights over the quad.
                let (p, _) = self.best_position(&ball, v, here);
                let h = (p - centre).dot(normal);
                let p = p + normal * (h.clamp(height / self.band, height * self.band) - h);
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

    /// A front triangle (0, 1, 2) at z = 0 on a stack of prisms down to the heights `levels`
    /// (the last step is 1 high whatever they are), and a front point (3) of no column 0.05
    /// over the triangle's centre: the core tetrahedron on them is a flat sliver.
    fn flat_cap(levels: &[f64]) -> (TetMesh, ClosedBoundary, VolumeMesh, Vec<u32>) {
        let s = 3f64.sqrt();
        let top = [DVec3::ZERO, DVec3::X, DVec3::new(0.5, s / 2.0, 0.0)];
        let apex = DVec3::new(0.5, s / 6.0, 0.05);
        let at = |z: f64| top.map(|p| p + z * DVec3::Z);
        let points = top.into_iter().chain([apex]).chain(levels.iter().flat_map(|&z| at(z))).collect();
        let mut mesh = VolumeMesh { points, ..Default::default() };
        let level = |l: usize| [0u32, 1, 2].map(|i| if l == 0 { i } else { 4 + 3 * (l as u32 - 1) + i });
        for l in 0..levels.len() {
            let (upper, lower) = (level(l), level(l + 1));
            mesh.push_cell(CellKind::Prism, &[lower, upper].concat(), 0);
        }
        let boundary = ClosedBoundary {
            points: top.into_iter().chain([apex]).collect(),
            triangles: vec![[0, 1, 2]],
            markers: vec![MARKER_FRONT],
        };
        let core = TetMesh::new(boundary.points.clone(), vec![[0, 1, 2, 3]], 4);
        (core, boundary, mesh, vec![0, 1, 2, 3])
    }

    /// Ten layers one high.
    const TEN: [f64; 10] = [-1.0, -2.0, -3.0, -4.0, -5.0, -6.0, -7.0, -8.0, -9.0, -10.0];

    fn steps() -> Vec<DVec3> {
        vec![DVec3::Z, DVec3::Z, DVec3::Z, DVec3::NAN]
    }

    fn prism_valid(slides: &FrontSlides, core: &TetMesh) -> bool {
        let (kind, nodes) =
            slides.cells_at[&0].iter().map(|&c| slides.cells[c as usize]).next().expect("a prism");
        let mut points: Vec<DVec3> = core.points.clone();
        points.extend(&slides.outer_points);
        cell_validity(kind, &gather(&points, &nodes[..6]).expect("in range")).is_valid()
    }

    #[test]
    fn a_front_sliver_is_mended_by_sinking_a_top_down_its_column() {
        let (mut core, boundary, mesh, nodes) = flat_cap(&TEN);
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
        let (mut core, mut boundary, mesh, nodes) = flat_cap(&TEN);
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
        // The last prism is a tenth as high as its step says: a sink of 0.2 of the step puts
        // the top under its bottom.
        let levels: Vec<f64> = [-0.1].into_iter().chain(TEN[..9].iter().copied()).collect();
        let (mut core, boundary, mesh, nodes) = flat_cap(&levels);
        core.keep_front_match(HashMap::new(), 1.2);
        let slides = FrontSlides::new(&boundary, &steps(), &mesh, &nodes);
        assert!(slides.cells_stay_valid(0, DVec3::new(0.0, 0.0, -0.05), &core.points));
        assert!(!slides.cells_stay_valid(0, DVec3::new(0.0, 0.0, -0.15), &core.points));
        core.allow_front_slides(slides);
        let p = core.move_front_point(0).and_then(|c| c.point).expect("a move").1;
        assert!(p.z > -0.1, "{p}");
    }

    /// On a stack of one layer, a top may take 4% of its thickness, not 20% of its step.
    #[test]
    fn a_thin_stack_loses_little_of_its_thickness() {
        let (mut core, boundary, mesh, nodes) = flat_cap(&[-1.0]);
        core.keep_front_match(HashMap::new(), 1.2);
        core.allow_front_slides(FrontSlides::new(&boundary, &steps(), &mesh, &nodes));
        let p = core.move_front_point(0).and_then(|c| c.point).expect("a move").1;
        assert!(p.z >= -MAX_THINNING - 1e-12 && p.z < 0.0, "{p}");
    }

    /// A top whose column slid on a patch without layers is on the mesh's boundary (a layer
    /// face in the patch's plane): it stays, though only front triangles of the core have it.
    #[test]
    fn a_top_on_the_mesh_boundary_stays() {
        let (_, boundary, mut mesh, nodes) = flat_cap(&TEN);
        mesh.boundary.quads.push([4, 5, 1, 0]);
        mesh.boundary.quad_patch.push(0);
        let slides = FrontSlides::new(&boundary, &steps(), &mesh, &nodes);
        assert!(slides.freedom[..2].iter().all(|f| matches!(f, Freedom::Fixed)));
        assert!(matches!(slides.freedom[2], Freedom::Column { .. }));
    }

    /// A front point with no prism under it (columns merged in the last layer) borrows the
    /// columns around it on the front: it sinks along the front's normal by their step, no
    /// further than they may. A front point on no front triangle stays.
    #[test]
    fn a_top_of_no_prism_sinks_as_far_as_the_columns_around_it() {
        let (mut core, boundary, mesh, nodes) = flat_cap(&TEN);
        let steps = [DVec3::Z, DVec3::Z, DVec3::NAN, DVec3::NAN];
        let slides = FrontSlides::new(&boundary, &steps, &mesh, &nodes);
        let Freedom::Column { step, reach, .. } = slides.freedom[2] else {
            panic!("{:?}", slides.freedom[2])
        };
        assert!((step - DVec3::Z).length() < 1e-12 && reach == MAX_SINK, "{step} {reach}");
        assert!(matches!(slides.freedom[3], Freedom::Fixed));
        core.keep_front_match(HashMap::new(), 1.2);
        core.allow_front_slides(slides);
        let p = core.move_front_point(2).and_then(|c| c.point).expect("a move").1;
        assert!(p.z >= -MAX_SINK - 1e-12 && p.z < 0.0, "{p}");
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
        assert!(matches!(slides.freedom[4], Freedom::Apex { height: 0.5, .. }));
        assert!(slides.freedom[..4].iter().all(|f| matches!(f, Freedom::Fixed)));
        let at = |z: f64| slides.cells_stay_valid(4, DVec3::new(0.3, 0.6, z), &boundary.points);
        assert!(at(0.2) && at(2.0));
        assert!(!at(0.0) && !at(-0.1), "through its quad");
    }
}
