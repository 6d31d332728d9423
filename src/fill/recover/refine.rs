//! Delaunay refinement of the region's tetrahedra to a size field and a radius-edge bound, in
//! the manner of TetGen's `-q` and `-m` with `-Y`: the boundary never gets a point.
//!
//! Every point carries a size (the target edge length). A tetrahedron is split while its
//! circumradius exceeds [`RefineOptions::circumradius_per_size`] times the smallest size at
//! its corners (too large), or [`RefineOptions::radius_edge`] times its shortest edge (poorly
//! shaped). The worst first (too large before poorly shaped, each by its ratio, from a
//! priority queue): a too large one at its circumcentre, a poorly shaped one at its off-centre
//! (Üngör: on the way from its shortest edge's midpoint to the circumcentre, no farther than
//! where the shortest edge and the point would make a triangle of the bound; fewer points than
//! circumcentres for the same bound). The point goes in by Bowyer–Watson with the boundary
//! triangles as walls, and its size is the linear interpolation of the sizes at the corners
//! of the tetrahedron holding it (graded from the cavity's vertices when
//! [`RefineOptions::gradation`] says so), so sizes carry from the boundary into the region.
//!
//! A point is rejected where it would spoil the boundary's tetrahedra rather than split the
//! boundary: outside the region (the walk to it leaves it), nearer a boundary triangle than
//! [`RefineOptions::clearance`] sizes, inside the diametral sphere of a boundary
//! triangle its cavity reaches (encroachment: the triangle's new tetrahedron would have an
//! angle of 90 degrees or more at the point), nearer a vertex than [`RefineOptions::spacing`]
//! times the local size, or with a cavity of more than [`RefineOptions::max_cavity`] tetrahedra. A too large
//! tetrahedron whose circumcentre is rejected is tried at points towards its centroid; one
//! left unsplit is taken up again in a later pass only (its neighbourhood may have changed),
//! unless every rejection was for a reason that lasts (outside, near the boundary or a vertex).
//! The refinement ends when no tetrahedron is bad, or after [`RefineOptions::passes`] passes,
//! or at [`RefineOptions::max_points`] points added.

use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::time::Instant;

use serde::Serialize;

use super::insert::{star_cavity, walk, Skipped};
use super::recovery::cavity_faces;
use crate::fill::improve::{Change, TetMesh, NO_TET, TET_EDGES};
use crate::geometry::bvh::TriangleBvh;
use crate::geometry::{tet_circumcentre, tet_signed_volume, triangle_circumcentre, DVec3};

/// How far the refinement goes and where it may put points.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RefineOptions {
    /// Largest circumradius over shortest edge of a tetrahedron. 2 is TetGen's default `-q`:
    /// Delaunay refinement is proved to end in 3D for bounds above 2 (Shewchuk), and below
    /// about 1.5 it chases slivers, which the radius-edge ratio does not see (the improvement
    /// mends those).
    pub radius_edge: f64,
    /// A tetrahedron is too large while its circumradius exceeds this many times the smallest
    /// size at its corners (TetGen's `-m` rule, with the factor of the TetGen path:
    /// [`crate::fill::CIRCUMRADIUS_PER_SIZE`]).
    pub circumradius_per_size: f64,
    /// No point nearer a boundary triangle than this many times the size interpolated there
    /// (the first core cells on the front stay the seeds'; in a gap narrower than its sizes,
    /// no point goes in).
    pub clearance: f64,
    /// No point nearer a vertex than this many times the size interpolated there (the shortest
    /// edge of the tetrahedron it splits where there are no sizes). Near a size much smaller
    /// than its surroundings' this stops the refinement short of it (edges up to about 4 times
    /// the size at such a point); allowing the smallest size at the tetrahedron's corners
    /// instead tripled the points in mech_test_gapdetection's gaps. With sizes, points stay apart, so the
    /// refinement ends even near small angles of the boundary, where radius-edge refinement
    /// alone would not.
    pub spacing: f64,
    /// Tetrahedra at most in the cavity of a point (a bound on the work of one insertion; the
    /// first points in the coarse tetrahedralisation of the boundary have cavities of
    /// thousands).
    pub max_cavity: usize,
    /// Points added at most.
    pub max_points: usize,
    /// Passes over the tetrahedra left bad at most.
    pub passes: usize,
    /// When set, an added point's size is at most the size of each vertex of its cavity plus
    /// `gradation - 1` times its distance to it (sizes graded as they are made); `None`:
    /// interpolated only. The pipeline grades the sizes by a first fill instead
    /// ([`crate::fill::grading`]): one graded fill gives a finer core than that (straight
    /// distances are shorter than paths along edges).
    pub gradation: Option<f64>,
    /// No size above this (the user's maximum size, `[sizing] max_size`) at the corners of a
    /// tetrahedron or at an added point; `None`: no bound.
    pub max_size: Option<f64>,
}

impl Default for RefineOptions {
    fn default() -> Self {
        RefineOptions {
            radius_edge: 2.0,
            circumradius_per_size: crate::fill::CIRCUMRADIUS_PER_SIZE,
            clearance: 0.5,
            spacing: 0.5,
            max_cavity: 100_000,
            max_points: (crate::fill::grading::MAX_CORE_TETRAHEDRA / 5.0) as usize,
            passes: 3,
            gradation: None,
            max_size: None,
        }
    }
}

/// What the refinement did.
#[derive(Clone, Debug, Default, Serialize, PartialEq, Eq)]
pub struct RefineStats {
    /// Points added for too large tetrahedra and for poorly shaped ones.
    pub for_size: usize,
    pub for_quality: usize,
    /// Candidate points rejected, by reason.
    pub outside: usize,
    pub near_boundary: usize,
    pub encroaching: usize,
    pub near_vertex: usize,
    pub no_cavity: usize,
    /// Tetrahedra left too large, and left poorly shaped only, after the last pass.
    pub left_too_large: usize,
    pub left_poorly_shaped: usize,
    pub passes: usize,
    /// Whether [`RefineOptions::max_points`] stopped it.
    pub point_limit: bool,
}

/// Why a candidate point was not inserted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Rejected {
    Outside,
    NearBoundary,
    Encroaching,
    NearVertex,
    NoCavity,
}

/// A tetrahedron to split: how bad it is and where to split it.
#[derive(Clone, Copy, Debug)]
struct Bad {
    tet: u32,
    /// Too large (else poorly shaped only), and the ratio to its bound (above 1).
    too_large: bool,
    ratio: f64,
    centre: DVec3,
    /// The ends of its shortest edge.
    shortest: [DVec3; 2],
}

impl Bad {
    /// The queue's order: too large first, then by ratio, then by slot (the same mesh for any
    /// run).
    fn key(&self) -> (bool, f64, std::cmp::Reverse<u32>) {
        (self.too_large, self.ratio, std::cmp::Reverse(self.tet))
    }
}

impl PartialEq for Bad {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Bad {}

impl PartialOrd for Bad {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Bad {
    fn cmp(&self, other: &Self) -> Ordering {
        let (a, b) = (self.key(), other.key());
        a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)).then(a.2.cmp(&b.2))
    }
}

/// The refinement under way: the mesh, the size at every point (NaN: none, as for points no
/// tetrahedron uses), the boundary triangles for the clearance, and the tetrahedron slots
/// given up (every point for them rejected for a reason a later pass cannot change).
pub(super) struct Refinement<'a> {
    mesh: &'a mut TetMesh,
    size: &'a mut Vec<f64>,
    boundary: &'a TriangleBvh,
    options: &'a RefineOptions,
    given_up: Vec<bool>,
}

impl Rejected {
    /// Whether the same point is rejected again while the tetrahedron lives: the boundary does
    /// not change, and refinement only adds vertices.
    fn lasting(self) -> bool {
        matches!(self, Rejected::Outside | Rejected::NearBoundary | Rejected::NearVertex)
    }
}

impl<'a> Refinement<'a> {
    /// `size` has an entry for every point of `mesh`; `boundary` holds the corners of the
    /// region's boundary triangles.
    pub fn new(
        mesh: &'a mut TetMesh,
        size: &'a mut Vec<f64>,
        boundary: &'a TriangleBvh,
        options: &'a RefineOptions,
    ) -> Self {
        Refinement { mesh, size, boundary, options, given_up: Vec::new() }
    }

    /// Refine until no tetrahedron is bad or a limit is reached (see the module
    /// documentation).
    pub fn run(&mut self) -> RefineStats {
        let start = Instant::now();
        let mut stats = RefineStats::default();
        let limit = self.mesh.points.len().saturating_add(self.options.max_points);
        for _ in 0..self.options.passes {
            stats.passes += 1;
            let mut queue: BinaryHeap<Bad> = self.bad_tets(0..self.mesh.slots() as u32).collect();
            let before = stats.for_size + stats.for_quality;
            while let Some(bad) = queue.pop() {
                if !self.mesh.is_alive(bad.tet) {
                    continue;
                }
                if self.mesh.points.len() >= limit {
                    stats.point_limit = true;
                    tracing::warn!(
                        max_points = self.options.max_points,
                        "refinement stopped at its point limit"
                    );
                    break;
                }
                let first_new = self.mesh.slots() as u32;
                if self.split(&bad, &mut stats) {
                    queue.extend(self.bad_tets(first_new..self.mesh.slots() as u32));
                    if (stats.for_size + stats.for_quality) % 100_000 == 0 {
                        tracing::debug!(?stats, queued = queue.len(), ?bad, "refinement under way");
                    }
                }
            }
            if stats.point_limit || stats.for_size + stats.for_quality == before {
                break;
            }
        }
        self.given_up.clear();
        for bad in self.bad_tets(0..self.mesh.slots() as u32) {
            *(if bad.too_large { &mut stats.left_too_large } else { &mut stats.left_poorly_shaped }) += 1;
        }
        tracing::debug!(?stats, seconds = start.elapsed().as_secs_f64(), "native core: refined");
        stats
    }

    /// The bad live tetrahedra among the slots `slots`, but those given up.
    fn bad_tets(&self, slots: std::ops::Range<u32>) -> impl Iterator<Item = Bad> + '_ {
        let given_up = |t: u32| self.given_up.get(t as usize).copied().unwrap_or(false);
        slots.filter(move |&t| self.mesh.is_alive(t) && !given_up(t)).filter_map(|t| self.assess(t))
    }

    /// Whether live tetrahedron `t` is too large or poorly shaped, and how much.
    fn assess(&self, t: u32) -> Option<Bad> {
        let tet = self.mesh.tet(t);
        let x = tet.map(|v| self.mesh.points[v as usize]);
        let centre = tet_circumcentre(x)?;
        let radius = centre.distance(x[0]);
        let (i, j) = TET_EDGES
            .into_iter()
            .min_by(|&(a, b), &(c, d)| x[a].distance_squared(x[b]).total_cmp(&x[c].distance_squared(x[d])))?;
        // NaN sizes (none known) drop out of the minimum.
        let largest = self.options.max_size.unwrap_or(f64::INFINITY);
        let smallest = tet.iter().map(|&v| self.size[v as usize]).fold(largest, f64::min);
        let size_ratio = radius / (self.options.circumradius_per_size * smallest);
        let shape_ratio = radius / (self.options.radius_edge * x[i].distance(x[j]));
        let too_large = size_ratio > 1.0;
        let ratio = if too_large { size_ratio } else { shape_ratio };
        (ratio > 1.0).then_some(Bad { tet: t, too_large, ratio, centre, shortest: [x[i], x[j]] })
    }

    /// Insert a point for `bad` at the first of its candidates that is not rejected; whether
    /// one went in. A tetrahedron whose every candidate is rejected for a lasting reason is
    /// given up.
    fn split(&mut self, bad: &Bad, stats: &mut RefineStats) -> bool {
        let mut lasting = true;
        for p in self.candidates(bad) {
            match self.insert(bad, p) {
                Ok(()) => {
                    *(if bad.too_large { &mut stats.for_size } else { &mut stats.for_quality }) += 1;
                    return true;
                }
                Err(why) => {
                    lasting &= why.lasting();
                    *match why {
                        Rejected::Outside => &mut stats.outside,
                        Rejected::NearBoundary => &mut stats.near_boundary,
                        Rejected::Encroaching => &mut stats.encroaching,
                        Rejected::NearVertex => &mut stats.near_vertex,
                        Rejected::NoCavity => &mut stats.no_cavity,
                    } += 1
                }
            }
        }
        if lasting {
            let t = bad.tet as usize;
            self.given_up.resize(self.given_up.len().max(t + 1), false);
            self.given_up[t] = true;
        }
        false
    }

    /// Where to split `bad`: a too large tetrahedron at its circumcentre, else half way to its
    /// centroid, else at the centroid; a poorly shaped one at its off-centre.
    fn candidates(&self, bad: &Bad) -> Vec<DVec3> {
        if !bad.too_large {
            return vec![off_centre(bad.centre, bad.shortest, self.options.radius_edge)];
        }
        let centroid =
            self.mesh.tet(bad.tet).iter().map(|&v| self.mesh.points[v as usize]).sum::<DVec3>() / 4.0;
        vec![bad.centre, (bad.centre + centroid) / 2.0, centroid]
    }

    /// Insert `p` to split `bad`, unless it is rejected (see the module documentation).
    fn insert(&mut self, bad: &Bad, p: DVec3) -> Result<(), Rejected> {
        let mesh = &*self.mesh;
        let start = walk(mesh, bad.tet, p).ok_or(Rejected::Outside)?;
        let largest = self.options.max_size.unwrap_or(f64::INFINITY);
        let shortest = bad.shortest[0].distance(bad.shortest[1]);
        let interpolated = interpolate(mesh, self.size, start, p).min(largest);
        let or_shortest = |size: f64| if size.is_finite() { size } else { shortest };
        let local = or_shortest(interpolated);
        let distance = |v: &u32| mesh.points[*v as usize].distance(p);
        let near_vertex = |vertices: &[u32]| {
            vertices.iter().map(distance).fold(f64::INFINITY, f64::min) < self.options.spacing * local
        };
        if near_vertex(&mesh.tet(start)) {
            return Err(Rejected::NearVertex);
        }
        if self.boundary.nearest_within(p, self.options.clearance * local).is_some() {
            return Err(Rejected::NearBoundary);
        }
        let (remove, add) =
            star_cavity(mesh, &[start], p, &|_| false, self.options.max_cavity).map_err(|why| match why {
                Skipped::Outside | Skipped::OnBoundary => Rejected::Outside,
                Skipped::NoStar | Skipped::Duplicate | Skipped::LargeCavity => Rejected::NoCavity,
            })?;
        let inside = |n: u32| remove.binary_search(&n).is_ok();
        let encroached =
            cavity_faces(mesh, remove.iter().copied(), inside).into_iter().any(|(face, _, across)| {
                across == NO_TET && in_diametral_sphere(face.map(|v| mesh.points[v as usize]), p)
            });
        if encroached {
            return Err(Rejected::Encroaching);
        }
        let mut vertices: Vec<u32> = add.iter().flat_map(|t| [t[0], t[1], t[2]]).collect();
        vertices.sort_unstable();
        vertices.dedup();
        if near_vertex(&vertices) {
            return Err(Rejected::NearVertex);
        }
        let size = self.options.gradation.map_or(interpolated, |g| {
            vertices
                .iter()
                .map(|v| self.size[*v as usize] + (g - 1.0) * distance(v))
                .fold(interpolated, f64::min)
        });
        let v = mesh.points.len() as u32;
        self.mesh.apply(&Change::replacing(remove, add, Some((v, p))));
        self.size.push(if size.is_finite() { size } else { f64::NAN });
        Ok(())
    }
}

/// Üngör's off-centre of a tetrahedron with circumcentre `centre` and shortest edge
/// `shortest`: on the way from the edge's midpoint to the circumcentre (perpendicular to the
/// edge), no farther than where the edge and the point make an isosceles triangle of
/// circumradius `bound` times the edge.
pub(super) fn off_centre(centre: DVec3, [a, b]: [DVec3; 2], bound: f64) -> DVec3 {
    let middle = (a + b) / 2.0;
    let length = a.distance(b);
    // Height h of the triangle: (h^2 + l^2 / 4) / (2 h) = bound l, the larger root.
    let reach = length * (bound + (bound * bound - 0.25).max(0.0).sqrt());
    let away = centre - middle;
    let distance = away.length();
    if distance <= reach {
        centre
    } else {
        middle + away * (reach / distance)
    }
}

/// Whether `p` is strictly inside the sphere whose equator is the circumcircle of triangle
/// `face`.
pub(super) fn in_diametral_sphere([a, b, c]: [DVec3; 3], p: DVec3) -> bool {
    triangle_circumcentre(a, b, c)
        .is_some_and(|centre| centre.distance_squared(p) < centre.distance_squared(a))
}

/// The size at `p` in live tetrahedron `t` (which holds it), interpolated linearly from its
/// corners' sizes that are known; NaN when none is.
pub(super) fn interpolate(mesh: &TetMesh, size: &[f64], t: u32, p: DVec3) -> f64 {
    let tet = mesh.tet(t);
    let x = tet.map(|v| mesh.points[v as usize]);
    let (mut weighted, mut total) = (0.0, 0.0);
    for i in 0..4 {
        let s = size[tet[i] as usize];
        if !s.is_finite() {
            continue;
        }
        let mut y = x;
        y[i] = p;
        let w = tet_signed_volume(y[0], y[1], y[2], y[3]).max(0.0);
        weighted += w * s;
        total += w;
    }
    if total > 0.0 {
        weighted / total
    } else {
        // On a face whose corners have no size, or in a flat tetrahedron.
        tet.iter().map(|&v| size[v as usize]).fold(f64::NAN, f64::min)
    }
}

/// Sizes for the points that have none but are vertices of tetrahedra (recovery's Steiner
/// points): the mean of their neighbours' sizes, spreading out from those that have one.
pub(super) fn complete_sizes(mesh: &TetMesh, size: &mut [f64]) {
    loop {
        let mut changed = false;
        for v in 0..size.len() {
            if size[v].is_finite() {
                continue;
            }
            let mut neighbours: Vec<u32> = mesh.ball(v as u32).iter().flat_map(|&t| mesh.tet(t)).collect();
            neighbours.sort_unstable();
            neighbours.dedup();
            let known: Vec<f64> =
                neighbours.iter().map(|&w| size[w as usize]).filter(|s| s.is_finite()).collect();
            if !known.is_empty() {
                size[v] = known.iter().sum::<f64>() / known.len() as f64;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
}

#[cfg(test)]
mod tests;
