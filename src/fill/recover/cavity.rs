//! Recovery where flips cannot: the tetrahedra crossing the missing edge or triangle are
//! removed and their cavity filled again by cones, from one of its vertices when that sees
//! every face, else from a Steiner point strictly inside (never on the boundary).
//!
//! A cone whose tetrahedra are all positive by [`orient3d`] fills its cavity exactly once
//! (the winding number of the cavity's boundary is 1 inside and 0 outside, and each point is
//! in as many cone tetrahedra as that), so only the signs are tested.
//!
//! - A missing edge `ab`: the cone from `a` over the faces of the cavity without `a` has the
//!   edge (one of those faces has `b`); a face `a` does not see has the tetrahedron across it
//!   taken into the cavity, and so on; then the same from `b`.
//! - A missing triangle whose edges are edges, or the two triangles on a missing edge whose
//!   other edges are edges (a patch): the tetrahedra crossing it meet its surface in the patch
//!   exactly (a tetrahedron crossing it cannot cross its rim), so the patch splits their
//!   cavity in two, each filled by a cone (from one of its vertices, else from a Steiner point:
//!   the Schönhardt polyhedron needs one).

use std::collections::{HashMap, HashSet};

use super::cross::Target;
use super::recovery::{cavity_faces, Recovery};
use crate::fill::improve::NO_TET;
use crate::geometry::predicates::{orient2d, orient3d, Sign};
use crate::geometry::DVec3;
use crate::mesh::sorted_edge;

/// Tetrahedra at most taken into a missing edge's cavity to make it seen from an end.
const MAX_GROWTH: usize = 64;

/// A cavity's side filled: the cone's tetrahedra and its Steiner point, if any.
struct Cone {
    tets: Vec<[u32; 4]>,
    steiner: Option<DVec3>,
}

impl Recovery {
    /// The faces of the cavity of tetrahedra `cavity`, their normals pointing into it, and
    /// whether each has a tetrahedron across it.
    fn cavity_faces(&self, cavity: &[u32]) -> Vec<([u32; 3], Option<u32>)> {
        cavity_faces(&self.mesh, cavity.iter().copied(), |n| cavity.contains(&n))
            .into_iter()
            .map(|(face, _, across)| (face, (across != NO_TET).then_some(across)))
            .collect()
    }

    /// The cone from vertex `v` over the faces without it, if every tetrahedron is positive.
    fn cone_from_vertex(&self, faces: &[[u32; 3]], v: u32) -> Option<Vec<[u32; 4]>> {
        let p = self.mesh.points[v as usize];
        let mut tets = Vec::with_capacity(faces.len());
        for f in faces.iter().filter(|f| !f.contains(&v)) {
            let [a, b, c] = f.map(|u| self.mesh.points[u as usize]);
            if orient3d(a, b, c, p) != Sign::Positive {
                return None;
            }
            tets.push([f[0], f[1], f[2], v]);
        }
        Some(tets)
    }

    /// The cone from a new point at `p` (the next point index) over all the faces, if every
    /// tetrahedron is positive and `p` is on no boundary triangle.
    fn cone_from_point(&self, faces: &[[u32; 3]], p: DVec3, triangles: &[[u32; 3]]) -> Option<Vec<[u32; 4]>> {
        let v = self.mesh.points.len() as u32;
        let visible = faces.iter().all(|f| {
            let [a, b, c] = f.map(|u| self.mesh.points[u as usize]);
            orient3d(a, b, c, p) == Sign::Positive
        });
        let on_boundary = triangles.iter().any(|t| on_triangle(p, t.map(|u| self.mesh.points[u as usize])));
        (visible && !on_boundary).then(|| faces.iter().map(|f| [f[0], f[1], f[2], v]).collect())
    }

    /// A cone filling the region bounded by `faces`: from one of their vertices, else from a
    /// Steiner point (tried: the vertices' centroid, points over `over`'s centroid along its
    /// normal `up`, the centroids of the tetrahedra `cavity` clipped to the side).
    fn cone(
        &self,
        faces: &[[u32; 3]],
        over: Option<([DVec3; 3], DVec3)>,
        triangles: &[[u32; 3]],
    ) -> Option<Cone> {
        let mut vertices: Vec<u32> = faces.iter().flatten().copied().collect();
        vertices.sort_unstable();
        vertices.dedup();
        if let Some(tets) = vertices.iter().find_map(|&v| self.cone_from_vertex(faces, v)) {
            return Some(Cone { tets, steiner: None });
        }
        let x = |v: u32| self.mesh.points[v as usize];
        let centroid = vertices.iter().map(|&v| x(v)).sum::<DVec3>() / vertices.len() as f64;
        let mut candidates: Vec<DVec3> =
            kernel_point(&faces.iter().map(|f| f.map(x)).collect::<Vec<_>>(), centroid)
                .into_iter()
                .chain([centroid])
                .collect();
        if let Some((t, up)) = over {
            let middle = (t[0] + t[1] + t[2]) / 3.0;
            let height = vertices.iter().map(|&v| (x(v) - middle).dot(up)).fold(0.0, f64::max);
            candidates.extend([0.5, 0.25, 0.1, 0.03, 0.01].map(|s| middle + s * height * up));
        }
        candidates.extend(faces.iter().map(|f| {
            let c = (x(f[0]) + x(f[1]) + x(f[2])) / 3.0;
            0.5 * (c + centroid)
        }));
        candidates.into_iter().find_map(|p| {
            self.cone_from_point(faces, p, triangles).map(|tets| Cone { tets, steiner: Some(p) })
        })
    }

    /// Recover the boundary triangles `patch` (a disc: one triangle, or two on a missing edge),
    /// whose rim edges are edges, by filling their cavity again: the tetrahedra crossing them
    /// (or the edges between them) meet the patch's surface in the patch exactly, so their
    /// cavity's faces split at the rim into two discs, each closed by the patch into a side
    /// filled by a cone. Returns the Steiner points added, `None` when no cone fills a side.
    pub(super) fn refill_patch(&mut self, patch: &[[u32; 3]], triangles: &[[u32; 3]]) -> Option<usize> {
        let edge_uses = directed_edges(patch);
        let rim: Vec<[u32; 2]> = edge_uses
            .iter()
            .filter(|(e, _)| !edge_uses.contains_key(&[e[1], e[0]]))
            .map(|(e, _)| *e)
            .collect();
        if rim.iter().any(|&[u, v]| !self.present(Target::Edge([u, v]))) {
            return None;
        }
        let inner = edge_uses.keys().filter(|e| e[0] < e[1] && edge_uses.contains_key(&[e[1], e[0]]));
        let targets = patch.iter().map(|&t| Target::Triangle(t)).chain(inner.map(|&e| Target::Edge(e)));
        let mut cavity: Vec<u32> = targets.flat_map(|t| self.crossing_tets(t)).collect();
        cavity.sort_unstable();
        cavity.dedup();
        if cavity.is_empty() {
            return Some(0);
        }
        let faces: Vec<[u32; 3]> = self.cavity_faces(&cavity).into_iter().map(|(f, _)| f).collect();
        let sides = split_at_rim(&faces, &rim)?;
        let x = |v: u32| self.mesh.points[v as usize];
        let mut cones = Vec::new();
        for side in sides {
            // The patch closes the side with its edges the other way round from the side's.
            let along = side.iter().any(|f| (0..3).any(|i| edge_uses.contains_key(&[f[i], f[(i + 1) % 3]])));
            let cap: Vec<[u32; 3]> =
                patch.iter().map(|&[a, b, c]| if along { [a, c, b] } else { [a, b, c] }).collect();
            let t = cap[0].map(x);
            let up = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
            let closed: Vec<[u32; 3]> = side.into_iter().chain(cap).collect();
            cones.push(self.cone(&closed, Some((t, up)), triangles)?);
        }
        let [first, second] = &cones[..] else { return None };
        // Steiner points are numbered in turn: the second cone's is one further when both have one.
        let v = self.mesh.points.len() as u32;
        let shift = u32::from(first.steiner.is_some() && second.steiner.is_some());
        let second_tets: Vec<[u32; 4]> =
            second.tets.iter().map(|t| t.map(|u| if u == v { v + shift } else { u })).collect();
        let all: Vec<[u32; 4]> = first.tets.iter().copied().chain(second_tets.iter().copied()).collect();
        if !self.keeps_boundary(&cavity, &all) {
            return None;
        }
        match (first.steiner, second.steiner) {
            (Some(p), Some(q)) => {
                self.replace(cavity, first.tets.clone(), Some(p));
                self.replace(Vec::new(), second_tets, Some(q));
                Some(2)
            }
            (p, q) => {
                self.replace(cavity, all, p.or(q));
                Some(usize::from(p.or(q).is_some()))
            }
        }
    }

    /// Recover the missing edge `ab` by a cone from one of its ends over a cavity around it
    /// (no Steiner point); whether it did.
    pub(super) fn refill_edge(&mut self, [a, b]: [u32; 2]) -> bool {
        let start = self.crossing_tets(Target::Edge([a, b]));
        for (apex, other) in [(a, b), (b, a)] {
            let mut cavity = start.clone();
            for _ in 0..MAX_GROWTH {
                let faces = self.cavity_faces(&cavity);
                let p = self.mesh.points[apex as usize];
                let hidden = faces.iter().find(|(f, _)| {
                    let [x, y, z] = f.map(|u| self.mesh.points[u as usize]);
                    !f.contains(&apex) && orient3d(x, y, z, p) != Sign::Positive
                });
                match hidden {
                    None => {
                        let faces: Vec<[u32; 3]> = faces.into_iter().map(|(f, _)| f).collect();
                        let Some(add) = self.cone_from_vertex(&faces, apex) else { break };
                        if add.iter().any(|t| t.contains(&other)) && self.keeps_boundary(&cavity, &add) {
                            self.replace(cavity, add, None);
                            return true;
                        }
                        break;
                    }
                    Some(&(f, Some(n))) if !self.triangles.contains(&crate::fill::sorted_triangle(f)) => {
                        cavity.push(n)
                    }
                    Some(_) => break,
                }
            }
        }
        false
    }
}

impl Recovery {
    /// Insert a Steiner point near the missing edge `ab`, off it into the region (along the
    /// sum of its boundary triangles' normals), by Bowyer–Watson with the present boundary
    /// triangles as walls, if one keeps the boundary; whether it did.
    pub(super) fn steiner_near_edge(
        &mut self,
        [a, b]: [u32; 2],
        triangles: &[[u32; 3]],
        attempt: usize,
    ) -> bool {
        let x = |v: u32| self.mesh.points[v as usize];
        let normal = |t: &[u32; 3]| (x(t[1]) - x(t[0])).cross(x(t[2]) - x(t[0])).normalize_or_zero();
        let at_edge = triangles.iter().filter(|t| t.contains(&a) && t.contains(&b));
        let direction = at_edge.map(normal).sum::<DVec3>().normalize_or_zero();
        let length = x(a).distance(x(b));
        let hint = self.mesh.ball(a).first().copied().unwrap_or(0);
        let wall = |f: &[u32; 3]| self.triangles.contains(&crate::fill::sorted_triangle(*f));
        // Along the edge: its middle first, then a point further on at each attempt.
        let along = STEINER_ALONG[attempt % STEINER_ALONG.len()];
        for s in [0.2, 0.05, 0.01] {
            let p = x(a).lerp(x(b), along) + s * length * direction;
            if triangles.iter().any(|t| on_triangle(p, t.map(x))) {
                continue;
            }
            let Ok((remove, add)) = super::insert::star_cavity(&self.mesh, &[hint], p, &wall, usize::MAX)
            else {
                continue;
            };
            if self.keeps_boundary(&remove, &add) {
                self.replace(remove, add, Some(p));
                return true;
            }
        }
        false
    }
}

/// Where along a missing edge the Steiner points near it go, in turn.
const STEINER_ALONG: [f64; 7] = [0.5, 0.25, 0.75, 0.125, 0.875, 0.375, 0.625];

/// Steps of the search for [`kernel_point`].
const KERNEL_STEPS: usize = 400;

/// A point deep inside the kernel of the region bounded by `faces` (normals inward): the
/// largest smallest distance to the faces' planes, by subgradient ascent from `start`
/// (floating point: only a candidate, tested exactly by the caller); `None` when no point is
/// inside them all.
fn kernel_point(faces: &[[DVec3; 3]], start: DVec3) -> Option<DVec3> {
    let planes: Vec<(DVec3, DVec3)> = faces
        .iter()
        .filter_map(|[a, b, c]| {
            let n = (*b - *a).cross(*c - *a).normalize_or_zero();
            (n != DVec3::ZERO).then_some((*a, n))
        })
        .collect();
    let scale = faces.iter().flatten().map(|p| p.distance(start)).fold(0.0, f64::max);
    let depth =
        |p: DVec3| planes.iter().map(|&(a, n)| ((p - a).dot(n), n)).min_by(|x, y| x.0.total_cmp(&y.0));
    let (mut best, mut best_depth) = (start, depth(start)?.0);
    let mut p = start;
    for k in 0..KERNEL_STEPS {
        let (d, n) = depth(p)?;
        if d > best_depth {
            (best, best_depth) = (p, d);
        }
        p += n * (scale * 0.1 / (1.0 + k as f64).sqrt());
    }
    (best_depth > 0.0).then_some(best)
}

/// The directed edges of some triangles, with the triangle using each.
fn directed_edges(triangles: &[[u32; 3]]) -> HashMap<[u32; 2], usize> {
    let mut edges = HashMap::new();
    for (k, t) in triangles.iter().enumerate() {
        for i in 0..3 {
            edges.insert([t[i], t[(i + 1) % 3]], k);
        }
    }
    edges
}

/// The cavity's faces in the two parts the rim edges split them into (through the other
/// edges, each shared by two faces); `None` unless there are two.
fn split_at_rim(faces: &[[u32; 3]], rim: &[[u32; 2]]) -> Option<[Vec<[u32; 3]>; 2]> {
    let rim: HashSet<[u32; 2]> = rim.iter().map(|&[u, v]| sorted_edge(u, v)).collect();
    let mut at_edge: HashMap<[u32; 2], Vec<usize>> = HashMap::new();
    for (k, f) in faces.iter().enumerate() {
        for i in 0..3 {
            at_edge.entry(sorted_edge(f[i], f[(i + 1) % 3])).or_default().push(k);
        }
    }
    let mut part = vec![usize::MAX; faces.len()];
    let mut parts = 0;
    for seed in 0..faces.len() {
        if part[seed] != usize::MAX {
            continue;
        }
        let mut stack = vec![seed];
        part[seed] = parts;
        while let Some(k) = stack.pop() {
            let f = faces[k];
            for i in 0..3 {
                let e = sorted_edge(f[i], f[(i + 1) % 3]);
                if rim.contains(&e) {
                    continue;
                }
                for &n in &at_edge[&e] {
                    if part[n] == usize::MAX {
                        part[n] = parts;
                        stack.push(n);
                    }
                }
            }
        }
        parts += 1;
    }
    if parts != 2 {
        return None;
    }
    let side = |s: usize| faces.iter().zip(&part).filter(|(_, &p)| p == s).map(|(f, _)| *f).collect();
    Some([side(0), side(1)])
}

/// Whether `p` is on the closed triangle `t` (exact).
pub(super) fn on_triangle(p: DVec3, t: [DVec3; 3]) -> bool {
    let lo = t[0].min(t[1]).min(t[2]);
    let hi = t[0].max(t[1]).max(t[2]);
    if p.cmplt(lo).any() || p.cmpgt(hi).any() || orient3d(t[0], t[1], t[2], p) != Sign::Zero {
        return false;
    }
    let project = super::cross::projection((t[1] - t[0]).cross(t[2] - t[0]));
    let [a, b, c, q] = [t[0], t[1], t[2], p].map(project);
    let s = [orient2d(a, b, q), orient2d(b, c, q), orient2d(c, a, q)];
    !(s.contains(&Sign::Positive) && s.contains(&Sign::Negative))
}
