//! Improvement of the core tetrahedra after the mesher, with small local operators in the manner
//! of MMG and of Klingner & Shewchuk ("Aggressive tetrahedral mesh improvement", 2007): face
//! flips ([`TetMesh::flip_23`]), edge removal ([`TetMesh::remove_edge`]: 3-2, 4-4 and larger
//! rings), smoothing of the points the mesher added ([`TetMesh::smooth_vertex`]) and insertion of
//! points on interior edges ([`TetMesh::split_edge`]).
//!
//! The boundary's triangles never change: an operator removes only faces with a tetrahedron on
//! both sides and edges with a closed ring of tetrahedra around them (so every boundary triangle
//! stays a face of the cavity it rebuilds), moves only points above the fixed boundary points
//! (and, to mend a sliver, front points down their columns: [`slide`]), and adds points only
//! inside. Every tetrahedron it creates is positive by the exact `orient3d`. The
//! quality is the smallest dihedral angle; an operator is applied only when it raises the
//! smallest angle of the tetrahedra it replaces.

use std::collections::{HashMap, HashSet};
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use super::size_jump::height_over;
use super::{sorted_triangle, ClosedBoundary, CoreTets, MARKER_FARFIELD, MARKER_FRONT, MARKER_WALL};
use crate::geometry::bvh::TriangleBvh;
use crate::geometry::predicates::{orient3d, Sign};
use crate::geometry::{tet_circumcentre, triangle_area_vector, triangle_min_angle, DVec3};
use crate::mesh::{sorted_edge, CellKind};

pub use slide::{FrontSlides, MAX_SINK};

/// No tetrahedron (across a boundary face).
pub(crate) const NO_TET: u32 = u32::MAX;

/// The local index of the node of `tet` that is not on its face `face`.
fn opposite_node(tet: [u32; 4], face: [u32; 3]) -> usize {
    (0..4).find(|&i| !face.contains(&tet[i])).expect("a face of the tetrahedron")
}

/// The face of `tet` opposite its node `i` (unoriented).
fn face_opposite(tet: [u32; 4], i: usize) -> [u32; 3] {
    [tet[(i + 1) % 4], tet[(i + 2) % 4], tet[(i + 3) % 4]]
}

/// Quality of a flat or inverted tetrahedron: below every real angle.
const INVALID: f64 = -1.0;

/// Smallest rise of the worst angle (degrees) worth a change: below it, hill climbing crawls.
const MIN_GAIN: f64 = 0.01;

/// A change may not leave more tetrahedra with an [`angle_quality`] below this (degrees).
const COUNTED_BELOW: f64 = 12.0;

/// A rise of the worst angle (degrees) worth two more tetrahedra below [`COUNTED_BELOW`].
const MUCH_BETTER: f64 = 2.0;

/// Passes of the worst-first rule at most (they cost more than they give after a few).
const WORST_FIRST_PASSES: usize = 3;

/// Largest ring of tetrahedra around an edge that edge removal rebuilds.
const MAX_RING: usize = 7;

/// The six edges of a tetrahedron, as local node pairs.
pub(crate) const TET_EDGES: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// Smallest dihedral angle of tetrahedron `x` in degrees; [`INVALID`] when it is not positive.
pub fn min_dihedral(x: [DVec3; 4]) -> f64 {
    dihedral_cosines(x).map_or(INVALID, |(most, _)| most.acos().to_degrees())
}

/// What the operators maximise: how far the dihedral angles of tetrahedron `x` stay from 0 and
/// from 180 degrees (a cap, flat with an angle near 180, can have no small angle); [`INVALID`]
/// when it is not positive.
pub fn angle_quality(x: [DVec3; 4]) -> f64 {
    // min(angle, 180 - largest angle) is the arc cosine of the larger of the smallest angle's
    // cosine and the negated largest angle's: one arc cosine per tetrahedron, the measure of
    // every change the improvement weighs.
    dihedral_cosines(x).map_or(INVALID, |(most, least)| most.max(-least).acos().to_degrees())
}

/// The largest and smallest cosine of the dihedral angles of a positive tetrahedron (those of
/// its smallest and largest angle); `None` when it is not positive. The faces' normals are
/// the gradients of the barycentric coordinates, all pointing inward, so the angle at the edge
/// two faces share has the negated cosine of the angle between their normals.
fn dihedral_cosines(x: [DVec3; 4]) -> Option<(f64, f64)> {
    if orient3d(x[0], x[1], x[2], x[3]) != Sign::Positive {
        return None;
    }
    let (e1, e2, e3) = (x[1] - x[0], x[2] - x[0], x[3] - x[0]);
    let (g1, g2, g3) = (e2.cross(e3), e3.cross(e1), e1.cross(e2));
    let normals = [-(g1 + g2 + g3), g1, g2, g3];
    let inverse_length = normals.map(|n| n.length_recip());
    let (mut most, mut least) = (f64::NEG_INFINITY, f64::INFINITY);
    for (i, j) in TET_EDGES {
        let cosine = (-normals[i].dot(normals[j]) * inverse_length[i] * inverse_length[j]).clamp(-1.0, 1.0);
        most = most.max(cosine);
        least = least.min(cosine);
    }
    Some((most, least))
}

/// How hard the improvement tries.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ImproveOptions {
    /// Tetrahedra whose [`angle_quality`] (degrees) is below this are worked on.
    pub target_dihedral: f64,
    /// Passes over the bad tetrahedra (0: no improvement).
    pub passes: usize,
    /// Insert points on interior edges when flips and smoothing do not help.
    pub insert_points: bool,
    /// No change may take more first core tetrahedra out of [1/size_band, size_band] of the
    /// last layer under them (their height over the front triangle; the growth ratio).
    pub size_band: f64,
}

impl Default for ImproveOptions {
    fn default() -> Self {
        ImproveOptions {
            target_dihedral: 12.0,
            passes: 20,
            insert_points: true,
            size_band: crate::config::DEFAULT_GROWTH,
        }
    }
}

/// What the improvement did.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ImproveStats {
    pub flips_23: usize,
    pub flips_32: usize,
    pub flips_44: usize,
    /// Edge removals with rings of 5 to [`MAX_RING`] tetrahedra.
    pub edge_removals: usize,
    pub smoothed_points: usize,
    /// Added points removed by merging them into a neighbour ([`TetMesh::collapse_edge`]).
    pub collapsed_edges: usize,
    pub inserted_points: usize,
    /// Flips and moves that gave a first core tetrahedron the last layer's height
    /// ([`TetMesh::match_front`]).
    pub front_matches: usize,
    /// Front points moved to mend a sliver: columns' tops down their last step, pyramids'
    /// apexes ([`TetMesh::move_front_point`]).
    pub moved_front_points: usize,
    pub passes: usize,
    pub seconds: f64,
}

/// A local change proposed by an operator: tetrahedra to remove and to add, and a point moved
/// (or added, when its index is the point count).
#[derive(Clone, Debug)]
pub struct Change {
    pub remove: Vec<u32>,
    pub add: Vec<[u32; 4]>,
    pub point: Option<(u32, DVec3)>,
    /// Worst [`angle_quality`] of the tetrahedra changed, before and after.
    pub before: f64,
    pub after: f64,
    /// How many of them are below the target, before and after.
    below_before: usize,
    below_after: usize,
}

impl Change {
    /// A change judged by its caller (no qualities): tetrahedra `remove` replaced by `add`,
    /// with the point moved or added as said.
    pub(crate) fn replacing(remove: Vec<u32>, add: Vec<[u32; 4]>, point: Option<(u32, DVec3)>) -> Change {
        Change { remove, add, point, before: 0.0, after: 0.0, below_before: 0, below_after: 0 }
    }

    fn from_qualities(
        remove: Vec<u32>,
        add: Vec<[u32; 4]>,
        point: Option<(u32, DVec3)>,
        old: &[f64],
        new: &[f64],
    ) -> Change {
        let worst = |q: &[f64]| q.iter().copied().fold(f64::INFINITY, f64::min);
        let below = |q: &[f64]| q.iter().filter(|&&x| x < COUNTED_BELOW).count();
        Change {
            remove,
            add,
            point,
            before: worst(old),
            after: worst(new),
            below_before: below(old),
            below_after: below(new),
        }
    }

    /// The worst tetrahedron gets better and no more are left below [`COUNTED_BELOW`] (else a
    /// point insertion can trade one sliver for several slightly better ones), or it gets much
    /// better for at most two more.
    fn improves(&self, rule: Rule) -> bool {
        if rule == Rule::WorstFirst {
            return self.after > self.before + MIN_GAIN;
        }
        let fewer_bad = self.below_after <= self.below_before;
        let much_better =
            self.after >= self.before + MUCH_BETTER && self.below_after <= self.below_before + 2;
        self.after > self.before + MIN_GAIN && (fewer_bad || much_better)
    }
}

/// A tetrahedral mesh with the tetrahedra at every point, for local changes.
#[derive(Clone, Debug)]
pub struct TetMesh {
    pub points: Vec<DVec3>,
    tets: Vec<[u32; 4]>,
    alive: Vec<bool>,
    /// The live tetrahedra at every point.
    ball: Vec<Vec<u32>>,
    /// The tetrahedron across the face opposite each node of every tetrahedron ([`NO_TET`] on
    /// the boundary): the cavities of insertions walk faces far more often than changes are
    /// applied.
    adjacent: Vec<[u32; 4]>,
    /// Points below this index are on the boundary: they never move.
    fixed: usize,
    /// The last layer's height under every front triangle with a prism under it, and the band
    /// the first core tetrahedron's height over it is kept in ([`TetMesh::keep_front_match`]).
    front_height: HashMap<[u32; 3], f64>,
    /// The points of the triangles of `front_height`: a face with another point is not one.
    on_front: Vec<bool>,
    band: f64,
    /// The front points that may slide down their columns, with the cells outside the core at
    /// them ([`TetMesh::allow_front_slides`]); none: the boundary never moves.
    slides: Option<FrontSlides>,
    /// Changes applied so far, and at every point the count when the last change at it (its
    /// tetrahedra or its place) was applied.
    applied: usize,
    touched: Vec<usize>,
}

impl TetMesh {
    /// `tets` must be positive and index `points`; the first `fixed` points never move.
    pub fn new(points: Vec<DVec3>, tets: Vec<[u32; 4]>, fixed: usize) -> TetMesh {
        let mut ball = vec![Vec::new(); points.len()];
        for (t, tet) in tets.iter().enumerate() {
            for &v in tet {
                ball[v as usize].push(t as u32);
            }
        }
        let alive = vec![true; tets.len()];
        let points_len = points.len();
        let mut mesh = TetMesh {
            points,
            tets,
            alive,
            ball,
            adjacent: Vec::new(),
            fixed,
            front_height: HashMap::new(),
            on_front: Vec::new(),
            band: f64::INFINITY,
            slides: None,
            applied: 0,
            touched: vec![0; points_len],
        };
        mesh.adjacent = vec![[NO_TET; 4]; mesh.tets.len()];
        for t in 0..mesh.tets.len() as u32 {
            mesh.link_faces(t);
        }
        mesh
    }

    /// Set the neighbours across the faces of live tetrahedron `t`, on both sides.
    fn link_faces(&mut self, t: u32) {
        let tet = self.tets[t as usize];
        for i in 0..4 {
            let face = face_opposite(tet, i);
            let other = self.tets_with(&face).into_iter().find(|&s| s != t);
            self.adjacent[t as usize][i] = other.unwrap_or(NO_TET);
            if let Some(s) = other {
                let opposite = opposite_node(self.tets[s as usize], face);
                self.adjacent[s as usize][opposite] = t;
            }
        }
    }

    /// Refuse every change that leaves more tetrahedra on the front triangles of
    /// `front_height` (sorted nodes, last layer height) with a height over their triangle out
    /// of [1/band, band] of it, unless it mends a sliver (below [`SLIVER_THRESHOLD`]): the
    /// seeds gave the first core cells the last layer's height, and a flip or an insertion
    /// near the front would take it away.
    pub fn keep_front_match(&mut self, front_height: HashMap<[u32; 3], f64>, band: f64) {
        self.on_front = vec![false; self.points.len()];
        for v in front_height.keys().flatten() {
            self.on_front[*v as usize] = true;
        }
        self.front_height = front_height;
        self.band = band;
    }

    /// How many front triangles of `tet` (with point `moved` at its new place) have it out of
    /// the band of their last layer.
    fn front_mismatches(&self, tet: [u32; 4], moved: Option<(u32, DVec3)>) -> usize {
        let x = |v: u32| match moved {
            Some((m, p)) if m == v => p,
            _ => self.points[v as usize],
        };
        (0..4)
            .filter(|&apex| {
                let face = face_opposite(tet, apex);
                if !face.iter().all(|&v| self.on_front.get(v as usize).copied().unwrap_or(false)) {
                    return false;
                }
                let key = sorted_triangle(face);
                self.front_height.get(&key).is_some_and(|&h| {
                    let ratio = height_over(key.map(x), x(tet[apex])).abs() / h;
                    !(1.0 / self.band..=self.band).contains(&ratio)
                })
            })
            .count()
    }

    /// Give the front triangles whose first core tetrahedron is out of the band of their last
    /// layer (the mesher joined them to a point of the front nearby, or to one of its own low
    /// points) a better apex: a 2-3 flip through a face at the apex, or the removal of an edge
    /// from the apex to the triangle, makes a node beyond the apex the triangle's; or an apex
    /// the mesher added moves into the band along the triangle's normal; failing those, a point
    /// is inserted in the band over the triangle ([`TetMesh::matched_apex_candidates`]). A
    /// change is taken when it leaves fewer tetrahedra out of the band and none below
    /// [`SLIVER_THRESHOLD`] (unless it removes one as bad). Returns the changes made.
    pub fn match_front(&mut self, insertion: MatchInsertion) -> usize {
        let mut triangles: Vec<[u32; 3]> = self.front_height.keys().copied().collect();
        triangles.sort_unstable();
        // The triangles no change helped, with the count of changes applied then: tried again
        // only once a change touches their tetrahedron.
        let mut unmatched: HashMap<[u32; 3], usize> = HashMap::new();
        let mut made = 0;
        for _ in 0..MATCH_ROUNDS {
            let before = made;
            for &key in &triangles {
                let &[t] = &self.tets_with(&key)[..] else { continue };
                let tet = self.tets[t as usize];
                let stale = unmatched.get(&key).is_some_and(|&at| self.untouched_since(tet, at));
                if stale || self.front_mismatches(tet, None) == 0 {
                    continue;
                }
                let Some(apex) = tet.into_iter().find(|v| !key.contains(v)) else { continue };
                match self.better_apex(t, key, apex, insertion) {
                    Some(change) => {
                        self.apply(&change);
                        made += 1;
                    }
                    None => {
                        unmatched.insert(key, self.applied);
                    }
                }
            }
            if made == before {
                break;
            }
        }
        made
    }

    /// The change giving front triangle `key` (its tetrahedron `t`, apex `apex`) an apex in the
    /// band, if one is found: the best of the flips, the apex's move and (for
    /// [`MatchInsertion::OverCentreForFixedApex`]) the point over the centre; for
    /// [`MatchInsertion::InBand`], failing those, the first point insertion that does.
    fn better_apex(&self, t: u32, key: [u32; 3], apex: u32, insertion: MatchInsertion) -> Option<Change> {
        let accepted = |change: Change| {
            let gain = self.mismatch_gain(&change);
            (gain > 0 && change.after >= SLIVER_THRESHOLD.min(change.before)).then_some((gain, change))
        };
        let flips = (0..3).filter_map(|i| self.flip_23([key[i], key[(i + 1) % 3], apex]));
        let removals = (0..3).filter_map(|i| self.remove_edge(apex, key[i]));
        let over_centre = (insertion == MatchInsertion::OverCentreForFixedApex
            && (apex as usize) < self.fixed)
            .then(|| self.insert_point(t, self.matched_apex(t, key)?, Placement::AsGiven))
            .flatten();
        let best = flips
            .chain(removals)
            .chain(self.raise_apex(key, apex))
            .chain(over_centre)
            .filter_map(accepted)
            .max_by(|x, y| x.0.cmp(&y.0).then(x.1.after.total_cmp(&y.1.after)));
        if best.is_some() || insertion == MatchInsertion::OverCentreForFixedApex {
            return best.map(|(_, change)| change);
        }
        // Insertions cost more: the first that helps, nearest the ideal apex first.
        self.matched_apex_candidates(t, key)
            .into_par_iter()
            .filter_map(|p| self.insert_point(t, p, Placement::AsGiven))
            .find_map_first(accepted)
            .map(|(_, change)| change)
    }

    /// Points in the band over front triangle `key` (its tetrahedron `t`) for a new apex: the
    /// last layer's height over its centre ([`TetMesh::matched_apex`]) first, then heights
    /// within the band ([`MATCHED_APEX_BAND_POWERS`]) over the centre and over points from a
    /// quarter to nine tenths of the way to each corner: the centre's cavity often holds a
    /// front point nearby, or is not star-shaped. On spot (H = 1e-3 D, 10 layers) the centre
    /// alone left 9.1% of the front triangles out of the band, these 5.1% (growth 1.2).
    fn matched_apex_candidates(&self, t: u32, key: [u32; 3]) -> Vec<DVec3> {
        let Some(over_centre) = self.matched_apex(t, key) else { return Vec::new() };
        let corners = key.map(|v| self.points[v as usize]);
        let centre = corners.iter().sum::<DVec3>() / 3.0;
        let up = over_centre - centre;
        let bases: Vec<DVec3> = std::iter::once(centre)
            .chain(
                MATCHED_APEX_BASES
                    .into_iter()
                    .flat_map(|w| corners.map(|corner| centre + w * (corner - centre))),
            )
            .collect();
        // A last layer's height comes with its band (`keep_front_match`).
        let band = self.band;
        MATCHED_APEX_BAND_POWERS
            .iter()
            .flat_map(|&k| bases.iter().map(move |&base| base + band.powf(k) * up))
            .collect()
    }

    /// The point at the last layer's height over the centre of front triangle `face`, on the
    /// side of its tetrahedron `t`; `None` when it has no last layer.
    fn matched_apex(&self, t: u32, face: [u32; 3]) -> Option<DVec3> {
        let h = *self.front_height.get(&sorted_triangle(face))?;
        let [a, b, c] = face.map(|v| self.points[v as usize]);
        let apex = self.tets[t as usize].into_iter().find(|v| !face.contains(v))?;
        let side = match orient3d(a, b, c, self.points[apex as usize]) {
            Sign::Positive => 1.0,
            Sign::Negative => -1.0,
            Sign::Zero => return None,
        };
        Some((a + b + c) / 3.0 + side * h * triangle_area_vector(a, b, c).normalize_or_zero())
    }

    /// Move the added point `apex` of front triangle `key`'s tetrahedron along the triangle's
    /// normal into the band of the last layer's height over it.
    fn raise_apex(&self, key: [u32; 3], apex: u32) -> Option<Change> {
        let h = *self.front_height.get(&key)?;
        if (apex as usize) < self.fixed {
            return None;
        }
        let [a, b, c] = key.map(|v| self.points[v as usize]);
        let normal = triangle_area_vector(a, b, c).normalize_or_zero();
        let p = self.points[apex as usize];
        let height = height_over([a, b, c], p);
        // Just into the band: the least move (a stretched triangle's tetrahedron as tall as
        // its layer can be a needle).
        let wanted = height.abs().clamp(h / self.band * 1.01, h * self.band / 1.01);
        let target = p + normal * (wanted.copysign(height) - height);
        Some(self.point_move(&self.ball_of(apex), apex, target))
    }

    /// How many fewer tetrahedra `change` leaves out of the band of their last layer.
    fn mismatch_gain(&self, change: &Change) -> i64 {
        let count = |tets: &mut dyn Iterator<Item = [u32; 4]>, moved| {
            tets.map(|t| self.front_mismatches(t, moved)).sum::<usize>() as i64
        };
        if change.remove.is_empty() && change.add.is_empty() {
            // A point moved: its ball, before and after.
            let Some((v, _)) = change.point else { return 0 };
            let ball = &self.ball[v as usize];
            count(&mut ball.iter().map(|&t| self.tets[t as usize]), None)
                - count(&mut ball.iter().map(|&t| self.tets[t as usize]), change.point)
        } else {
            count(&mut change.remove.iter().map(|&t| self.tets[t as usize]), None)
                - count(&mut change.add.iter().copied(), change.point)
        }
    }

    /// The live tetrahedra.
    pub fn tets(&self) -> impl Iterator<Item = [u32; 4]> + '_ {
        self.tets.iter().zip(&self.alive).filter(|(_, &a)| a).map(|(t, _)| *t)
    }

    /// The points (also those an edge collapse left unused: [`super::merge::drop_unused_points`])
    /// and the live tetrahedra.
    pub fn into_parts(self) -> (Vec<DVec3>, Vec<[u32; 4]>) {
        let tets = self.tets().collect();
        (self.points, tets)
    }

    fn corners(&self, tet: [u32; 4]) -> [DVec3; 4] {
        tet.map(|v| self.points[v as usize])
    }

    fn quality(&self, tet: [u32; 4]) -> f64 {
        angle_quality(self.corners(tet))
    }

    fn worst(&self, tets: impl IntoIterator<Item = [u32; 4]>) -> f64 {
        tets.into_iter().map(|t| self.quality(t)).fold(f64::INFINITY, f64::min)
    }

    /// Commit a change proposed by one of the operators.
    pub fn apply(&mut self, change: &Change) {
        self.applied += 1;
        // A point moved (not added: a change may fill an empty cavity around a new point).
        let moved_ball = change
            .point
            .filter(|&(v, _)| change.remove.is_empty() && (v as usize) < self.points.len())
            .map(|(v, _)| v);
        let touched = change
            .remove
            .iter()
            .chain(moved_ball.iter().flat_map(|&v| &self.ball[v as usize]))
            .flat_map(|&t| self.tets[t as usize])
            .chain(change.add.iter().flatten().copied())
            .chain(change.point.map(|(v, _)| v))
            .collect::<Vec<u32>>();
        // Room for a point the change adds.
        self.touched.resize(self.points.len() + 1, 0);
        for v in touched {
            self.touched[v as usize] = self.applied;
        }
        if let Some((v, p)) = change.point {
            if v as usize == self.points.len() {
                self.points.push(p);
                self.ball.push(Vec::new());
            } else {
                self.points[v as usize] = p;
            }
        }
        for &t in &change.remove {
            self.alive[t as usize] = false;
            for v in self.tets[t as usize] {
                self.ball[v as usize].retain(|&s| s != t);
            }
        }
        let first_new = self.tets.len() as u32;
        for &tet in &change.add {
            let t = self.tets.len() as u32;
            self.tets.push(tet);
            self.alive.push(true);
            self.adjacent.push([NO_TET; 4]);
            for v in tet {
                self.ball[v as usize].push(t);
            }
        }
        // Every face of the cavity is a face of a new tetrahedron: linking those links all.
        for t in first_new..self.tets.len() as u32 {
            self.link_faces(t);
        }
    }

    /// Tetrahedron slots, live or removed: the bound of a tetrahedron index.
    pub(crate) fn slots(&self) -> usize {
        self.tets.len()
    }

    /// The nodes of tetrahedron slot `t` (removed or not).
    pub(crate) fn tet(&self, t: u32) -> [u32; 4] {
        self.tets[t as usize]
    }

    pub(crate) fn is_alive(&self, t: u32) -> bool {
        self.alive[t as usize]
    }

    /// The tetrahedra across the faces opposite each node of live tetrahedron `t` ([`NO_TET`]
    /// on the boundary).
    pub(crate) fn adjacent(&self, t: u32) -> [u32; 4] {
        self.adjacent[t as usize]
    }

    /// The live tetrahedra at point `v`.
    pub(crate) fn ball(&self, v: u32) -> &[u32] {
        &self.ball[v as usize]
    }

    /// The live tetrahedra having all of `nodes`.
    pub(crate) fn tets_with(&self, nodes: &[u32]) -> Vec<u32> {
        let Some(&first) = nodes.first() else { return Vec::new() };
        self.ball[first as usize]
            .iter()
            .copied()
            .filter(|&t| nodes.iter().all(|v| self.tets[t as usize].contains(v)))
            .collect()
    }

    /// The tetrahedra around edge `ab` and their other nodes in order, when they close a ring
    /// (the edge is interior): consecutive ring nodes `x, y` make the positive tetrahedron
    /// `(a, b, x, y)`.
    pub fn ring(&self, a: u32, b: u32) -> Option<(Vec<u32>, Vec<u32>)> {
        let tets = self.tets_with(&[a, b]);
        let pairs: Vec<(u32, u32)> = tets.iter().map(|&t| ring_pair(self.tets[t as usize], a, b)).collect();
        let start = pairs.first()?.0;
        let mut ring = vec![start];
        let mut at = start;
        for _ in 0..pairs.len() {
            at = pairs.iter().find(|p| p.0 == at)?.1;
            if at == start {
                break;
            }
            ring.push(at);
        }
        (at == start && ring.len() == pairs.len()).then_some((tets, ring))
    }

    /// The change replacing tetrahedra `remove` by `add` (with the point moved or added as
    /// said); `None` when a new tetrahedron is not positive.
    fn change(&self, remove: Vec<u32>, add: Vec<[u32; 4]>, point: Option<(u32, DVec3)>) -> Option<Change> {
        let old: Vec<f64> = remove.iter().map(|&t| self.quality(self.tets[t as usize])).collect();
        let new: Vec<f64> = match point {
            Some((v, p)) => add.iter().map(|&t| self.quality_at(t, v, p)).collect(),
            None => add.iter().map(|&t| self.quality(t)).collect(),
        };
        let change = Change::from_qualities(remove, add, point, &old, &new);
        // A sliver may be mended at the cost of a first core cell's match, nothing less.
        if change.before >= SLIVER_THRESHOLD
            && !self.front_height.is_empty()
            && self.mismatch_gain(&change) < 0
        {
            return None;
        }
        (change.after > INVALID).then_some(change)
    }

    /// Flip 2-3: replace the two tetrahedra on the interior face `abc` by three around the
    /// edge joining their apexes. `None` when the face is on the boundary or a new tetrahedron
    /// would not be positive.
    pub fn flip_23(&self, face: [u32; 3]) -> Option<Change> {
        let tets = self.tets_with(&face);
        let &[s, t] = &tets[..] else { return None };
        let apex = |t: u32| self.tets[t as usize].into_iter().find(|v| !face.contains(v));
        let (d, e) = (apex(s)?, apex(t)?);
        let [a, b, c] = face.map(|v| self.points[v as usize]);
        let (top, bottom) = match orient3d(a, b, c, self.points[d as usize]) {
            Sign::Positive => (d, e),
            Sign::Negative => (e, d),
            Sign::Zero => return None,
        };
        let add: Vec<[u32; 4]> = (0..3).map(|i| [bottom, top, face[i], face[(i + 1) % 3]]).collect();
        self.change(tets, add, None)
    }

    /// Edge removal: replace the ring of tetrahedra around the interior edge `ab` (3 to
    /// [`MAX_RING`] of them) by the best triangulation of the ring polygon joined to `a` and to
    /// `b` (Shewchuk's dynamic programme); 3 tetrahedra give the 3-2 flip, 4 the 4-4 flip.
    pub fn remove_edge(&self, a: u32, b: u32) -> Option<Change> {
        let (tets, ring) = self.ring(a, b)?;
        let m = ring.len();
        if !(3..=MAX_RING).contains(&m) {
            return None;
        }
        let add = self.best_ring_triangulation(a, b, &ring)?;
        self.change(tets, add, None)
    }

    /// The triangulation of the ring polygon that maximises the worst of the tetrahedra
    /// `(ri, rk, rj, b)` and `(rk, ri, rj, a)` over its triangles `i < k < j`; `None` when every
    /// triangulation has a tetrahedron that is not positive.
    fn best_ring_triangulation(&self, a: u32, b: u32, ring: &[u32]) -> Option<Vec<[u32; 4]>> {
        let pair = |i: usize, k: usize, j: usize| ring_tets(a, b, ring, (i, k, j));
        let triangles = best_polygon_triangulation(
            ring.len(),
            |i, k, j| self.worst(pair(i, k, j)),
            f64::min,
            f64::INFINITY,
            INVALID,
        )?;
        Some(triangles.into_iter().flat_map(|(i, k, j)| pair(i, k, j)).collect())
    }

    /// Edge collapse: remove the added point `a` by merging it into `b`, a node of its star:
    /// the tetrahedra at `a` without `b` take `b` in its place, those with both go. `None`
    /// when `a` is fixed or a new tetrahedron is not positive (then the cone from `b` does not
    /// fill the star of `a`).
    pub fn collapse_edge(&self, a: u32, b: u32) -> Option<Change> {
        if (a as usize) < self.fixed {
            return None;
        }
        let remove = self.ball[a as usize].clone();
        let add: Vec<[u32; 4]> = remove
            .iter()
            .map(|&t| self.tets[t as usize])
            .filter(|t| !t.contains(&b))
            .map(|t| t.map(|v| if v == a { b } else { v }))
            .collect();
        if add.len() == remove.len() {
            return None;
        }
        let volume = |t: [u32; 4]| {
            let [p, q, r, s] = self.corners(t);
            crate::geometry::tet_signed_volume(p, q, r, s)
        };
        let old: f64 = remove.iter().map(|&t| volume(self.tets[t as usize])).sum();
        let new: f64 = add.iter().map(|&t| volume(t)).sum();
        if (new - old).abs() > 1e-9 * old {
            return None;
        }
        self.change(remove, add, None)
    }

    /// Move the added point `v` where the worst tetrahedron at it is best.
    pub fn smooth_vertex(&self, v: u32) -> Option<Change> {
        if (v as usize) < self.fixed {
            return None;
        }
        let ball = self.ball_of(v);
        let (p, _) = self.best_position(&ball, v, self.points[v as usize]);
        Some(self.point_move(&ball, v, p))
    }

    /// The tetrahedra at point `v`.
    fn ball_of(&self, v: u32) -> Vec<[u32; 4]> {
        self.ball[v as usize].iter().map(|&t| self.tets[t as usize]).collect()
    }

    /// The change moving point `v`, whose tetrahedra are `ball`, to `p`.
    fn point_move(&self, ball: &[[u32; 4]], v: u32, p: DVec3) -> Change {
        let old: Vec<f64> = ball.iter().map(|&t| self.quality(t)).collect();
        let new: Vec<f64> = ball.iter().map(|&t| self.quality_at(t, v, p)).collect();
        Change::from_qualities(Vec::new(), Vec::new(), Some((v, p)), &old, &new)
    }

    /// Insert a point on the interior edge `ab`, placed where the worst of its tetrahedra is
    /// best.
    pub fn split_edge(&self, a: u32, b: u32) -> Option<Change> {
        let (tets, ring) = self.ring(a, b)?;
        let p = self.points.len() as u32;
        let add: Vec<[u32; 4]> = (0..ring.len())
            .flat_map(|i| {
                let (x, y) = (ring[i], ring[(i + 1) % ring.len()]);
                [[a, p, x, y], [p, b, x, y]]
            })
            .collect();
        let middle = 0.5 * (self.points[a as usize] + self.points[b as usize]);
        let (position, _) = self.best_position(&add, p, middle);
        self.change(tets, add, Some((p, position)))
    }

    /// Insert a point at `p` (with [`Placement::Best`], then moved where its tetrahedra are
    /// best): the tetrahedra whose circumsphere holds `p`, grown from the one holding it (found
    /// by walking from `start`) across interior faces, are replaced by the cone from the new
    /// point over their boundary (Bowyer-Watson). `None` when `p` is outside the region or the
    /// cone is not positive. When that cone would have a tetrahedron below
    /// [`SLIVER_THRESHOLD`], the cavity grown across the faces that make them
    /// ([`TetMesh::grow_cavity_for_quality`]) is tried first, and the Delaunay one only when
    /// the grown one does no better: the better of the two is taken.
    pub fn insert_point(&self, start: u32, p: DVec3, placement: Placement) -> Option<Change> {
        let cavity = self.delaunay_cavity(start, p)?;
        let mut grown = cavity.clone();
        if !self.grow_cavity_for_quality(&mut grown, p) {
            return self.fill_cavity(cavity, p, placement);
        }
        let grown = self.fill_cavity(grown, p, placement);
        if grown.as_ref().is_some_and(|c| c.after >= SLIVER_THRESHOLD) {
            return grown;
        }
        match (self.fill_cavity(cavity, p, placement), grown) {
            (Some(d), Some(g)) => Some(if g.after > d.after { g } else { d }),
            (d, g) => d.or(g),
        }
    }

    /// The tetrahedra whose circumsphere holds `p` (at most [`MAX_CAVITY`]), grown from the
    /// one holding it (found by walking from `start`) across interior faces, and `start`;
    /// `None` when `p` is outside the region.
    fn delaunay_cavity(&self, start: u32, p: DVec3) -> Option<Vec<u32>> {
        let first = self.locate(start, p)?;
        // The tetrahedron to improve goes too, whether or not its circumsphere holds `p`.
        let mut cavity = vec![first];
        if start != first {
            cavity.push(start);
        }
        let mut i = 0;
        while let Some(&t) = cavity.get(i) {
            i += 1;
            for face in self.outward_faces(t) {
                match self.neighbour(t, face) {
                    Some(n)
                        if !cavity.contains(&n)
                            && cavity.len() < MAX_CAVITY
                            && self.in_circumsphere(n, p) =>
                    {
                        cavity.push(n)
                    }
                    _ => {}
                }
            }
        }
        Some(cavity)
    }

    /// Grow `cavity` across its interior faces whose cone from `p` would be below
    /// [`SLIVER_THRESHOLD`] or not positive, until none is (or it holds [`MAX_CAVITY`]
    /// tetrahedra): a point near a flat face of the Delaunay cavity, or seeing one from
    /// behind, makes a sliver there or no cone at all, where the tetrahedron beyond the face
    /// taken in gives the point a better view. Returns whether it grew.
    fn grow_cavity_for_quality(&self, cavity: &mut Vec<u32>, p: DVec3) -> bool {
        let v = self.points.len() as u32;
        let size = cavity.len();
        // A face's cone depends on the face and `p` only: each tetrahedron's faces are looked
        // at once, when it joins.
        let mut i = 0;
        while let Some(&t) = cavity.get(i) {
            i += 1;
            for face in self.outward_faces(t) {
                if cavity.len() >= MAX_CAVITY {
                    break;
                }
                let Some(n) = self.neighbour(t, face) else { continue };
                if !cavity.contains(&n)
                    && self.quality_at([face[0], face[2], face[1], v], v, p) < SLIVER_THRESHOLD
                {
                    cavity.push(n);
                }
            }
        }
        cavity.len() > size
    }

    /// The cone from a new point at `p` (or, with [`Placement::Best`], where its tetrahedra
    /// are best) over the boundary of `cavity`, replacing it; `None` when the cone does not
    /// fill the cavity exactly (it is not star-shaped from the point, or holds a point).
    fn fill_cavity(&self, cavity: Vec<u32>, p: DVec3, placement: Placement) -> Option<Change> {
        let v = self.points.len() as u32;
        let mut add = Vec::new();
        for &t in &cavity {
            for face in self.outward_faces(t) {
                if !self.neighbour(t, face).is_some_and(|n| cavity.contains(&n)) {
                    add.push([face[0], face[2], face[1], v]);
                }
            }
        }
        let position = match placement {
            Placement::Best => self.best_position(&add, v, p).0,
            Placement::AsGiven => p,
        };
        let new_volume: f64 = add.iter().map(|t| self.volume_at(*t, v, position)).sum();
        let old_volume: f64 =
            cavity.iter().map(|&t| self.volume_at(self.tets[t as usize], v, position)).sum();
        // A cavity that is not a ball (pinched) would not be filled exactly by the cone, and
        // one with a point inside would lose it.
        let kept = |u: &u32| add.iter().any(|t| t.contains(u));
        let lost = cavity.iter().flat_map(|&t| self.tets[t as usize]).any(|u| !kept(&u));
        if (new_volume - old_volume).abs() > 1e-9 * old_volume || lost {
            return None;
        }
        self.change(cavity, add, Some((v, position)))
    }

    fn volume_at(&self, tet: [u32; 4], v: u32, p: DVec3) -> f64 {
        let [a, b, c, d] = tet.map(|u| if u == v { p } else { self.points[u as usize] });
        crate::geometry::tet_signed_volume(a, b, c, d)
    }

    /// The faces of tetrahedron `t`, their right-hand normals pointing out of it.
    fn outward_faces(&self, t: u32) -> [[u32; 3]; 4] {
        let tet = self.tets[t as usize];
        let faces = CellKind::Tetrahedron.faces();
        std::array::from_fn(|k| [tet[faces[k][0]], tet[faces[k][1]], tet[faces[k][2]]])
    }

    /// The other tetrahedron on a face of `t` (none on the boundary).
    fn neighbour(&self, t: u32, face: [u32; 3]) -> Option<u32> {
        let other = self.adjacent[t as usize][opposite_node(self.tets[t as usize], face)];
        (other != NO_TET).then_some(other)
    }

    /// The tetrahedron holding `p`, walking from `start` across the faces `p` lies beyond;
    /// `None` when the walk leaves the region or goes on too long.
    fn locate(&self, start: u32, p: DVec3) -> Option<u32> {
        let mut t = start;
        'walk: for _ in 0..1000 {
            for face in self.outward_faces(t) {
                let [a, b, c] = face.map(|v| self.points[v as usize]);
                if orient3d(a, b, c, p) == Sign::Positive {
                    t = self.neighbour(t, face)?;
                    continue 'walk;
                }
            }
            return Some(t);
        }
        None
    }

    /// Whether `p` is inside the circumsphere of tetrahedron `t` (floating point: it only
    /// chooses the cavity, whose cone is then checked exactly).
    fn in_circumsphere(&self, t: u32, p: DVec3) -> bool {
        let x = self.corners(self.tets[t as usize]);
        tet_circumcentre(x)
            .is_some_and(|centre| (p - centre).length_squared() < (x[0] - centre).length_squared())
    }

    /// Where to insert a point for tetrahedron `t`: over each of its boundary faces the best
    /// apex and, on a front triangle with a last layer under it, the point at that layer's
    /// height over its centre; its circumcentre; and its centroid (the circumcentre of a flat
    /// sliver is far away, often outside the region, while the centroid's cavity is small and
    /// the point, once moved to its best place, splits the sliver). With each, whether the
    /// point is to stay where it is (a matched apex moved to the best place would sink towards
    /// the front).
    fn insertion_points(&self, t: u32) -> Vec<(DVec3, Placement)> {
        let mut points = Vec::new();
        for face in self.outward_faces(t) {
            if self.neighbour(t, face).is_some() {
                continue;
            }
            let [a, b, c] = face.map(|v| self.points[v as usize]);
            points.push((best_apex(a, c, b).0, Placement::Best));
            points.extend(self.matched_apex(t, face).map(|p| (p, Placement::AsGiven)));
        }
        points.extend(tet_circumcentre(self.corners(self.tets[t as usize])).map(|p| (p, Placement::Best)));
        points.push((self.centroid(t), Placement::Best));
        points
    }

    /// The centroid of tetrahedron `t`.
    fn centroid(&self, t: u32) -> DVec3 {
        self.corners(self.tets[t as usize]).iter().sum::<DVec3>() / 4.0
    }

    /// Worst quality of `ball` (tetrahedra at `v`) with `v` at `p`.
    fn ball_quality(&self, ball: &[[u32; 4]], v: u32, p: DVec3) -> f64 {
        ball.iter().map(|t| self.quality_at(*t, v, p)).fold(f64::INFINITY, f64::min)
    }

    fn quality_at(&self, tet: [u32; 4], v: u32, p: DVec3) -> f64 {
        angle_quality(tet.map(|u| if u == v { p } else { self.points[u as usize] }))
    }

    /// Hill climbing on the worst tetrahedron of `ball` from `start`: first the centroid of
    /// the ball's other nodes, then steps along the gradient of the worst angle(s).
    fn best_position(&self, ball: &[[u32; 4]], v: u32, start: DVec3) -> (DVec3, f64) {
        let mut others: Vec<u32> = ball.iter().flatten().copied().filter(|&u| u != v).collect();
        others.sort_unstable();
        others.dedup();
        if others.is_empty() {
            return (start, self.ball_quality(ball, v, start));
        }
        let centroid = others.iter().map(|&u| self.points[u as usize]).sum::<DVec3>() / others.len() as f64;
        let scale = others.iter().map(|&u| (self.points[u as usize] - centroid).length()).sum::<f64>()
            / others.len() as f64;
        let (mut p, mut q) = (start, self.ball_quality(ball, v, start));
        let qc = self.ball_quality(ball, v, centroid);
        if qc > q {
            (p, q) = (centroid, qc);
        }
        for _ in 0..12 {
            let Some(direction) = self.ascent_direction(ball, v, p, q, scale) else { break };
            let mut step = 0.25 * scale;
            let mut moved = false;
            for _ in 0..8 {
                let candidate = p + step * direction;
                let qn = self.ball_quality(ball, v, candidate);
                if qn > q {
                    (p, q, moved) = (candidate, qn, true);
                    break;
                }
                step *= 0.5;
            }
            if !moved {
                break;
            }
        }
        (p, q)
    }

    /// The normalised sum of the normalised gradients of the tetrahedra within a degree of
    /// the worst (numerical, central differences).
    fn ascent_direction(&self, ball: &[[u32; 4]], v: u32, p: DVec3, worst: f64, scale: f64) -> Option<DVec3> {
        let h = 1e-5 * scale;
        let mut direction = DVec3::ZERO;
        for &tet in ball {
            if self.quality_at(tet, v, p) > worst + 1.0 {
                continue;
            }
            let derivative = |e: DVec3| {
                (self.quality_at(tet, v, p + h * e) - self.quality_at(tet, v, p - h * e)) / (2.0 * h)
            };
            let gradient = DVec3::new(derivative(DVec3::X), derivative(DVec3::Y), derivative(DVec3::Z));
            direction += gradient.normalize_or_zero();
        }
        let direction = direction.normalize_or_zero();
        (direction != DVec3::ZERO && direction.is_finite()).then_some(direction)
    }

    /// Of the changes that improve by `rule`, the best: one that mends the sliver (leaves no
    /// angle below [`SLIVER_THRESHOLD`]) first, then one that leaves the most first core cells
    /// in the band of their last layer, then the one that raises the worst angle most.
    fn best_improving(&self, changes: Vec<Change>, rule: Rule) -> Option<Change> {
        let key = |c: &Change| {
            let matches = if self.front_height.is_empty() { 0 } else { self.mismatch_gain(c) };
            (c.after >= SLIVER_THRESHOLD, matches)
        };
        changes
            .into_iter()
            .filter(|c| c.improves(rule))
            .map(|c| (key(&c), c))
            .max_by(|(kx, x), (ky, y)| kx.cmp(ky).then(x.after.total_cmp(&y.after)))
            .map(|(_, c)| c)
    }

    /// The change the operators propose for tetrahedron `t`: the best flip, else the best
    /// smoothing of one of its points, else the best point insertion, if one helps.
    fn improve_tet(
        &self,
        t: u32,
        options: &ImproveOptions,
        rule: Rule,
        stats: &mut ImproveStats,
    ) -> Option<Change> {
        let tet = self.tets[t as usize];
        let mut flips: Vec<Change> =
            TET_EDGES.iter().filter_map(|&(i, j)| self.remove_edge(tet[i], tet[j])).collect();
        flips.extend(
            CellKind::Tetrahedron
                .faces()
                .iter()
                .filter_map(|f| self.flip_23([tet[f[0]], tet[f[1]], tet[f[2]]])),
        );
        if let Some(change) = self.best_improving(flips, rule) {
            match (change.remove.len(), change.add.len()) {
                (2, 3) => stats.flips_23 += 1,
                (3, 2) => stats.flips_32 += 1,
                (4, 4) => stats.flips_44 += 1,
                _ => stats.edge_removals += 1,
            }
            return Some(change);
        }
        let smoothing = tet.iter().filter_map(|&v| self.smooth_vertex(v)).collect();
        if let Some(change) = self.best_improving(smoothing, rule) {
            stats.smoothed_points += 1;
            return Some(change);
        }
        let collapses = TET_EDGES
            .iter()
            .flat_map(|&(i, j)| [(tet[i], tet[j]), (tet[j], tet[i])])
            .filter_map(|(a, b)| self.collapse_edge(a, b))
            .collect();
        if let Some(change) = self.best_improving(collapses, rule) {
            stats.collapsed_edges += 1;
            return Some(change);
        }
        // The front moves only to mend a sliver.
        if self.quality(tet) < SLIVER_THRESHOLD {
            let moves = tet.iter().filter_map(|&v| self.move_front_point(v)).collect();
            if let Some(change) = self.best_improving(moves, rule) {
                stats.moved_front_points += 1;
                return Some(change);
            }
        }
        // Insertion under the worst-first rule trades one sliver for many slightly better ones.
        if !options.insert_points || rule == Rule::WorstFirst {
            return None;
        }
        let mut insertions: Vec<Change> =
            TET_EDGES.iter().filter_map(|&(i, j)| self.split_edge(tet[i], tet[j])).collect();
        let points = self.insertion_points(t);
        insertions.extend(points.iter().filter_map(|&(p, placement)| self.insert_point(t, p, placement)));
        // Nearer the tetrahedron, the cavity is smaller and more often star-shaped.
        let centre = self.centroid(t);
        insertions.extend(
            points
                .iter()
                .filter(|&&(p, _)| p != centre)
                .filter_map(|&(p, _)| self.insert_point(t, 0.5 * (p + centre), Placement::Best)),
        );
        let change = self.best_improving(insertions, rule)?;
        stats.inserted_points += 1;
        Some(change)
    }

    /// Passes over the tetrahedra below the target angle, worst first.
    /// Passes over the tetrahedra below the target quality, worst first: first changes that
    /// leave fewer bad tetrahedra, then, for those still below [`SLIVER_THRESHOLD`], any change
    /// that raises the worst angle.
    pub fn improve(&mut self, options: &ImproveOptions) -> ImproveStats {
        let start = Instant::now();
        let mut stats = ImproveStats::default();
        if options.passes > 0 {
            stats.front_matches += self.match_front(MatchInsertion::OverCentreForFixedApex);
        }
        self.passes(options.passes, options, Rule::FewerBad, options.target_dihedral, &mut stats);
        let worst_first = options.passes.min(WORST_FIRST_PASSES);
        self.passes(
            worst_first,
            options,
            Rule::WorstFirst,
            options.target_dihedral.min(SLIVER_THRESHOLD),
            &mut stats,
        );
        // The points the passes added to mend slivers low over the front go up into the band
        // where they can.
        if options.passes > 0 {
            stats.front_matches += self.match_front(MatchInsertion::InBand);
        }
        stats.seconds = start.elapsed().as_secs_f64();
        stats
    }

    fn passes(
        &mut self,
        passes: usize,
        options: &ImproveOptions,
        rule: Rule,
        target: f64,
        stats: &mut ImproveStats,
    ) {
        // A tetrahedron no operator helped is tried again only once a change touches one of
        // its nodes: `failed[t]` is the count of changes applied when it failed.
        let mut failed: Vec<Option<usize>> = vec![None; self.tets.len()];
        for _ in 0..passes {
            let stale = |t: usize| failed[t].is_some_and(|at| self.untouched_since(self.tets[t], at));
            let mut bad: Vec<(f64, u32)> = (0..self.tets.len())
                .filter(|&t| self.alive[t] && !stale(t))
                .map(|t| (self.quality(self.tets[t]), t as u32))
                .filter(|&(q, _)| q < target)
                .collect();
            if bad.is_empty() {
                break;
            }
            stats.passes += 1;
            bad.sort_by(|x, y| x.0.total_cmp(&y.0));
            for (_, t) in bad {
                if !self.alive[t as usize] {
                    continue;
                }
                match self.improve_tet(t, options, rule, stats) {
                    Some(change) => {
                        self.apply(&change);
                        failed.resize(self.tets.len(), None);
                    }
                    None => failed[t as usize] = Some(self.applied),
                }
            }
        }
    }

    /// Whether no change applied after the `at`-th touched a node of `tet` (its tetrahedra or
    /// its place): an operator that found nothing for it then finds nothing now.
    fn untouched_since(&self, tet: [u32; 4], at: usize) -> bool {
        tet.iter().all(|&v| self.touched[v as usize] <= at)
    }
}

/// The two tetrahedra that triangle `(i, k, j)` of the ring polygon around edge `ab` (see
/// [`TetMesh::ring`]) makes with `a` and `b`, positive when the edge removal is valid there.
pub(crate) fn ring_tets(a: u32, b: u32, ring: &[u32], (i, k, j): (usize, usize, usize)) -> [[u32; 4]; 2] {
    let (ri, rk, rj) = (ring[i], ring[k], ring[j]);
    [[ri, rk, rj, b], [rk, ri, rj, a]]
}

/// The triangulation of a convex `m`-gon (vertices `0..m`, as triangles `(i, k, j)` with
/// `i < k < j`) that maximises the `join` of the `weight`s of its triangles, by dynamic
/// programming (Shewchuk's for edge removal): `empty` is the value of no triangle, and `None`
/// is returned when the best is not above `invalid`.
pub(crate) fn best_polygon_triangulation(
    m: usize,
    weight: impl Fn(usize, usize, usize) -> f64,
    join: impl Fn(f64, f64) -> f64,
    empty: f64,
    invalid: f64,
) -> Option<Vec<(usize, usize, usize)>> {
    if m < 3 {
        return None;
    }
    // best[i][j]: the best triangulation of polygon i..=j; split[i][j]: its apex.
    let mut best = vec![vec![empty; m]; m];
    let mut split = vec![vec![0usize; m]; m];
    for len in 2..m {
        for i in 0..m - len {
            let j = i + len;
            best[i][j] = invalid;
            for k in i + 1..j {
                let q = join(join(best[i][k], best[k][j]), weight(i, k, j));
                if q > best[i][j] {
                    best[i][j] = q;
                    split[i][j] = k;
                }
            }
        }
    }
    if best[0][m - 1] <= invalid {
        return None;
    }
    let mut triangles = Vec::with_capacity(m - 2);
    let mut stack = vec![(0, m - 1)];
    while let Some((i, j)) = stack.pop() {
        if j < i + 2 {
            continue;
        }
        let k = split[i][j];
        triangles.push((i, k, j));
        stack.push((i, k));
        stack.push((k, j));
    }
    Some(triangles)
}

/// Where an inserted point goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Placement {
    /// Where the worst of its tetrahedra is best ([`TetMesh::best_position`]).
    Best,
    /// Where it was given.
    AsGiven,
}

/// When a change is an improvement.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Rule {
    /// The worst angle rises and no more tetrahedra are left below [`COUNTED_BELOW`] (or only
    /// two more, for a much better worst angle).
    FewerBad,
    /// The worst angle rises.
    WorstFirst,
}

/// The other two nodes `(x, y)` of `tet` (positive, with nodes `a` and `b`) ordered so that
/// `(a, b, x, y)` is an even permutation of it, hence positive too.
fn ring_pair(tet: [u32; 4], a: u32, b: u32) -> (u32, u32) {
    let position = |v: u32| tet.iter().position(|&u| u == v).unwrap_or(0);
    let rest: Vec<usize> = (0..4).filter(|&i| tet[i] != a && tet[i] != b).collect();
    let (x, y) = (rest.first().copied().unwrap_or(0), rest.get(1).copied().unwrap_or(0));
    let order = [position(a), position(b), x, y];
    let inversions =
        (0..4).flat_map(|i| (i + 1..4).map(move |j| (i, j))).filter(|&(i, j)| order[i] > order[j]).count();
    if inversions % 2 == 0 {
        (tet[x], tet[y])
    } else {
        (tet[y], tet[x])
    }
}

/// Width of the bins of a [`DihedralHistogram`], degrees.
pub const HISTOGRAM_BIN: f64 = 5.0;

/// Histogram of the smallest dihedral angle of tetrahedra: `counts[i]` tetrahedra have it in
/// `[i, i + 1) * bin_degrees` (the largest possible, 70.5 degrees, is in the last bin).
#[derive(Clone, Debug, Default, Serialize)]
pub struct DihedralHistogram {
    pub bin_degrees: f64,
    pub counts: Vec<usize>,
}

impl DihedralHistogram {
    pub fn of(points: &[DVec3], tets: &[[u32; 4]]) -> DihedralHistogram {
        let mut counts = vec![0; 15];
        for tet in tets {
            let q = min_dihedral(tet.map(|v| points[v as usize]));
            let bin = ((q.max(0.0) / HISTOGRAM_BIN) as usize).min(counts.len() - 1);
            counts[bin] += 1;
        }
        DihedralHistogram { bin_degrees: HISTOGRAM_BIN, counts }
    }
}

impl std::fmt::Display for DihedralHistogram {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let bins = self.counts.iter().enumerate().map(|(i, n)| {
            let lo = i as f64 * self.bin_degrees;
            format!("{lo:.0}-{:.0}: {n}", lo + self.bin_degrees)
        });
        write!(f, "{}", bins.collect::<Vec<_>>().join(", "))
    }
}

/// Why a tetrahedron below the threshold angle is there.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum SliverCause {
    /// At one of its boundary edges the region's angle (between the two boundary triangles
    /// there) is below the threshold, so every tetrahedron at that edge has a smaller angle.
    BoundaryAngle,
    /// A boundary triangle of it is so badly shaped that no tetrahedron on it reaches the
    /// threshold.
    BoundaryTriangle,
    /// A boundary triangle at one of its edges has a corner angle below the threshold: a
    /// needle or a cap of the front (or a pyramid's face over a narrow quad). A tetrahedron on
    /// it alone may keep the threshold, but the tetrahedra around its short edge or its long
    /// one, which join it to the triangles beside it, inherit its angle.
    PoorBoundaryTriangle,
    /// The region is thin there: across the boundary triangle nearest to it, the region is
    /// `w` wide, and every tetrahedron on that triangle (inradius `r`) has a dihedral angle at
    /// most about `atan(w / r)`, which is below the threshold.
    ThinGap,
    /// Nothing in the boundary forces it.
    NotForced,
}

/// A tetrahedron below the threshold angle, where it is and what it touches.
#[derive(Clone, Debug, Serialize)]
pub struct Sliver {
    pub centre: [f64; 3],
    pub min_dihedral: f64,
    pub cause: SliverCause,
    /// The smallest angle of the region at its boundary edges (sum of the dihedral angles of
    /// the tetrahedra there; `null`: no boundary edge).
    pub boundary_edge_angle: f64,
    /// Its faces on the boundary, and its nodes on a front, wall or farfield triangle (a node
    /// where a front and a wall meet counts in both) or inside.
    pub boundary_faces: usize,
    /// Width of the region across the nearest boundary triangle, and that triangle's inradius
    /// (`atan(width / inradius)` bounds the angles of tetrahedra on it).
    pub gap_width: f64,
    pub nearest_inradius: f64,
    pub front_nodes: usize,
    pub wall_nodes: usize,
    pub farfield_nodes: usize,
    pub interior_nodes: usize,
}

/// The tetrahedra left below the threshold angle, by cause.
#[derive(Clone, Debug, Default, Serialize)]
pub struct SliverCensus {
    pub threshold: f64,
    pub count: usize,
    pub boundary_angle: usize,
    pub boundary_triangle: usize,
    pub poor_boundary_triangle: usize,
    pub thin_gap: usize,
    pub not_forced: usize,
    /// Of all of them, those with their four nodes on the boundary (no point to move: only a
    /// point inserted near them can remove them).
    pub all_nodes_on_boundary: usize,
    /// The worst few.
    pub examples: Vec<Sliver>,
}

/// Dihedral angle at edge `(i, j)` of tetrahedron `x`, degrees.
fn dihedral_at(x: [DVec3; 4], i: usize, j: usize) -> f64 {
    let rest: Vec<usize> = (0..4).filter(|&k| k != i && k != j).collect();
    let e = (x[j] - x[i]).normalize_or_zero();
    let off = |k: usize| {
        let d = x[k] - x[i];
        (d - e * d.dot(e)).normalize_or_zero()
    };
    off(rest[0]).dot(off(rest[1])).clamp(-1.0, 1.0).acos().to_degrees()
}

/// The best [`angle_quality`] of a tetrahedron on triangle `(a, b, c)` (apex on the side its
/// right-hand normal points to): no tetrahedron on it has all its dihedral angles further from
/// 0 and 180 degrees.
pub fn best_apex_quality(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    best_apex(a, b, c).1
}

/// The apex of [`best_apex_quality`] and its quality.
fn best_apex(a: DVec3, b: DVec3, c: DVec3) -> (DVec3, f64) {
    let normal = (b - a).cross(c - a).normalize_or_zero();
    let edge = ((b - a).length() + (c - b).length() + (a - c).length()) / 3.0;
    let apex = (a + b + c) / 3.0 + normal * edge * (2.0f64 / 3.0).sqrt();
    let single = TetMesh::new(vec![a, b, c, apex], vec![[0, 1, 2, 3]], 3);
    single.best_position(&[[0, 1, 2, 3]], 3, apex)
}

/// The edges of the boundary triangles with a corner angle below `threshold` degrees.
fn poor_triangle_edges(boundary: &ClosedBoundary, threshold: f64) -> HashSet<[u32; 2]> {
    boundary
        .triangles
        .iter()
        .filter(|t| {
            let [a, b, c] = t.map(|v| boundary.points[v as usize]);
            triangle_min_angle(a, b, c) < threshold
        })
        .flat_map(|&[a, b, c]| [sorted_edge(a, b), sorted_edge(b, c), sorted_edge(c, a)])
        .collect()
}

/// Which boundary triangles (marker bits) every boundary point is on.
fn node_markers(boundary: &ClosedBoundary) -> Vec<u8> {
    let mut bits = vec![0u8; boundary.points.len()];
    for (t, &m) in boundary.triangles.iter().zip(&boundary.markers) {
        for &v in t {
            bits[v as usize] |= 1 << m.min(7);
        }
    }
    bits
}

impl SliverCensus {
    /// Classify the tetrahedra of `core` (filling `boundary`) below `threshold` degrees.
    pub fn of(boundary: &ClosedBoundary, core: &CoreTets, threshold: f64) -> SliverCensus {
        let corners = |tet: [u32; 4]| tet.map(|v| core.points[v as usize]);
        let mut found: Vec<([u32; 4], f64)> = core
            .tets
            .iter()
            .map(|&tet| (tet, min_dihedral(corners(tet))))
            .filter(|&(_, q)| q < threshold)
            .collect();
        found.sort_by(|s, t| s.1.total_cmp(&t.1));
        let faces: HashSet<[u32; 3]> = boundary.triangles.iter().map(|&t| sorted_triangle(t)).collect();
        let edge_angle = boundary_edge_angles(boundary, core, found.iter().map(|s| s.0));
        let bits = node_markers(boundary);
        let bvh = TriangleBvh::new(
            boundary.triangles.iter().map(|t| t.map(|v| boundary.points[v as usize])).collect(),
        );
        let poor_edges = poor_triangle_edges(boundary, threshold);
        let mut census = SliverCensus { threshold, count: found.len(), ..Default::default() };
        for (tet, q) in found {
            let x = corners(tet);
            let on_boundary: Vec<[usize; 3]> = CellKind::Tetrahedron
                .faces()
                .iter()
                .map(|f| [f[0], f[1], f[2]])
                .filter(|f| faces.contains(&sorted_triangle(f.map(|i| tet[i]))))
                .collect();
            let boundary_edge_angle = TET_EDGES
                .iter()
                .filter_map(|&(i, j)| edge_angle.get(&sorted_edge(tet[i], tet[j])))
                .fold(f64::INFINITY, |a, &b| a.min(b));
            let interior_nodes = tet.iter().filter(|&&v| v as usize >= boundary.points.len()).count();
            census.all_nodes_on_boundary += usize::from(interior_nodes == 0);
            let centre = x.iter().sum::<DVec3>() / 4.0;
            let (gap_width, nearest_inradius) = gap_across_nearest(&bvh, centre);
            let cause = if boundary_edge_angle < threshold {
                census.boundary_angle += 1;
                SliverCause::BoundaryAngle
            } else if on_boundary.iter().any(|f| best_apex_quality(x[f[0]], x[f[2]], x[f[1]]) < threshold) {
                // The faces of CellKind::Tetrahedron point out of the cell: reversed, into it.
                census.boundary_triangle += 1;
                SliverCause::BoundaryTriangle
            } else if TET_EDGES.iter().any(|&(i, j)| poor_edges.contains(&sorted_edge(tet[i], tet[j]))) {
                census.poor_boundary_triangle += 1;
                SliverCause::PoorBoundaryTriangle
            } else if gap_width.atan2(nearest_inradius).to_degrees() < threshold {
                census.thin_gap += 1;
                SliverCause::ThinGap
            } else {
                census.not_forced += 1;
                SliverCause::NotForced
            };
            if census.examples.len() < 10 {
                let has = |v: u32, m: u32| bits.get(v as usize).is_some_and(|b| b & (1 << m) != 0);
                let count = |m: u32| tet.iter().filter(|&&v| has(v, m)).count();
                census.examples.push(Sliver {
                    centre: centre.to_array(),
                    min_dihedral: q,
                    cause,
                    boundary_faces: on_boundary.len(),
                    boundary_edge_angle,
                    gap_width,
                    nearest_inradius,
                    front_nodes: count(MARKER_FRONT),
                    wall_nodes: count(MARKER_WALL),
                    farfield_nodes: count(MARKER_FARFIELD),
                    interior_nodes,
                });
            }
        }
        census
    }
}

/// The angle of the region (sum of the dihedral angles of the tetrahedra of `core` there,
/// degrees) at every boundary edge of the tetrahedra `of`.
fn boundary_edge_angles(
    boundary: &ClosedBoundary,
    core: &CoreTets,
    of: impl Iterator<Item = [u32; 4]>,
) -> HashMap<[u32; 2], f64> {
    let edges: HashSet<[u32; 2]> = boundary
        .triangles
        .iter()
        .flat_map(|t| [sorted_edge(t[0], t[1]), sorted_edge(t[1], t[2]), sorted_edge(t[2], t[0])])
        .collect();
    let mut angle: HashMap<[u32; 2], f64> = of
        .flat_map(|tet| TET_EDGES.map(|(i, j)| sorted_edge(tet[i], tet[j])))
        .filter(|e| edges.contains(e))
        .map(|e| (e, 0.0))
        .collect();
    if angle.is_empty() {
        return angle;
    }
    for &tet in &core.tets {
        for (i, j) in TET_EDGES {
            if let Some(sum) = angle.get_mut(&sorted_edge(tet[i], tet[j])) {
                *sum += dihedral_at(tet.map(|v| core.points[v as usize]), i, j);
            }
        }
    }
    angle
}

/// The width of the region across the boundary triangle nearest to `p` (from the nearest
/// point along the triangle's normal, into the region, to the next boundary triangle; infinite
/// when none is hit) and that triangle's inradius.
fn gap_across_nearest(bvh: &TriangleBvh, p: DVec3) -> (f64, f64) {
    let Some(near) = bvh.nearest(p) else { return (f64::INFINITY, 0.0) };
    let [a, b, c] = bvh.corners(near.triangle);
    let area = triangle_area_vector(a, b, c);
    let inradius = area.length() / ((b - a).length() + (c - b).length() + (a - c).length());
    let direction = area.normalize_or_zero();
    // Hits closer than this are the nearest triangle's neighbours at the starting point.
    let skip = 1e-9 * inradius;
    let best =
        bvh.first_hit(near.point, direction, skip, |t| t == near.triangle).map_or(f64::INFINITY, |hit| hit.0);
    (best, inradius)
}

/// What the improvement found and did, for the report.
#[derive(Clone, Debug, Default, Serialize)]
pub struct CoreQuality {
    /// Smallest dihedral angle of the mesher's tetrahedra and their histogram, before.
    pub mesher_min_dihedral: f64,
    pub mesher_histogram: DihedralHistogram,
    /// After the improvement.
    pub min_dihedral: f64,
    pub histogram: DihedralHistogram,
    pub improvement: ImproveStats,
    /// The tetrahedra left below [`SLIVER_THRESHOLD`] degrees.
    pub slivers: SliverCensus,
}

/// The core's quality bar: no tetrahedron with a dihedral angle below this, degrees.
pub const SLIVER_THRESHOLD: f64 = 10.0;

/// The points [`TetMesh::match_front`] may insert over a front triangle whose first core
/// tetrahedron no flip or move brings into the band of its last layer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MatchInsertion {
    /// Only at the layer's height over its centre, and only where its apex is a fixed point
    /// (a front node or a seed). Before the sliver passes: the points [`MatchInsertion::InBand`]
    /// adds there leave the passes more first core cells to keep in the band, and spot more
    /// slivers (32/25/42 -> 37/30/60 tetrahedra below 10 deg over growth 1.1999/1.2/1.2001).
    OverCentreForFixedApex,
    /// Anywhere in the band over it ([`TetMesh::matched_apex_candidates`]), whatever its apex.
    /// After the sliver passes, where it cannot leave a tetrahedron below [`SLIVER_THRESHOLD`].
    InBand,
}

/// The most tetrahedra an insertion's cavity takes ([`TetMesh::insert_point`]).
const MAX_CAVITY: usize = 64;

/// Rounds of [`TetMesh::match_front`] (a flip can open the way for another).
const MATCH_ROUNDS: usize = 6;

/// Heights of the points [`TetMesh::match_front`] inserts over a front triangle: the last
/// layer's height times the band to these powers, the layer's own height first (r = 1.2: 1,
/// 0.955, 1.047, 0.913, 1.095, 0.872, 1.147, 0.849, 1.178).
const MATCHED_APEX_BAND_POWERS: [f64; 9] = [0.0, -0.25, 0.25, -0.5, 0.5, -0.75, 0.75, -0.9, 0.9];

/// Where over a front triangle [`TetMesh::match_front`] inserts points besides its centre: this
/// far from the centre towards each corner.
const MATCHED_APEX_BASES: [f64; 4] = [0.25, 0.5, 0.75, 0.9];

/// Improve the mesher's tetrahedra (`core`, filling `boundary`, whose points come first; they
/// and the next up to `fixed` stay, but for the front points `slides` lets slide, which move in
/// `boundary` too) and measure them before and after. `prism_height` is the last layer's height
/// under every boundary triangle (NaN where none): the first core tetrahedra on them keep their
/// match ([`TetMesh::keep_front_match`]).
pub fn improve_core(
    boundary: &mut ClosedBoundary,
    core: CoreTets,
    fixed: usize,
    prism_height: &[f64],
    slides: Option<FrontSlides>,
    options: &ImproveOptions,
) -> (CoreTets, CoreQuality) {
    let worst = |points: &[DVec3], tets: &[[u32; 4]]| {
        tets.iter().map(|t| min_dihedral(t.map(|v| points[v as usize]))).fold(f64::INFINITY, f64::min)
    };
    let mesher_min_dihedral = worst(&core.points, &core.tets);
    let mesher_histogram = DihedralHistogram::of(&core.points, &core.tets);
    let fixed = fixed.max(boundary.points.len());
    let mut mesh = TetMesh::new(core.points, core.tets, fixed);
    let front_height = boundary
        .triangles
        .iter()
        .zip(prism_height)
        .filter(|(_, h)| h.is_finite() && **h > 0.0)
        .map(|(&t, &h)| (sorted_triangle(t), h))
        .collect();
    mesh.keep_front_match(front_height, options.size_band);
    if let Some(slides) = slides {
        mesh.allow_front_slides(slides);
    }
    let improvement = mesh.improve(options);
    let (points, tets) = mesh.into_parts();
    let n = boundary.points.len();
    boundary.points.copy_from_slice(&points[..n]);
    let mut core = CoreTets { points, tets, boundary_steiner_points: core.boundary_steiner_points };
    // The points edge collapses removed.
    super::merge::drop_unused_points(&mut core, fixed);
    let quality = CoreQuality {
        mesher_min_dihedral,
        mesher_histogram,
        min_dihedral: worst(&core.points, &core.tets),
        histogram: DihedralHistogram::of(&core.points, &core.tets),
        improvement,
        slivers: SliverCensus::of(boundary, &core, SLIVER_THRESHOLD),
    };
    (core, quality)
}

mod slide;
#[cfg(test)]
mod tests;
