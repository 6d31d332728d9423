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
//! - A missing triangle whose edges are edges: the tetrahedra crossing it meet its plane in
//!   the triangle exactly (a tetrahedron crossing it cannot cross its edges), so the triangle
//!   splits their cavity in two, each filled by a cone (from one of its vertices, else from a
//!   Steiner point: the Schönhardt polyhedron needs one).

use super::cross::Target;
use super::recovery::{inward_faces, Recovery};
use crate::fill::improve::NO_TET;
use crate::geometry::predicates::{orient2d, orient3d, Sign};
use crate::geometry::DVec3;

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
        let mut faces = Vec::new();
        for &t in cavity {
            let faces_of_t = inward_faces(self.mesh.tet(t));
            for (i, &n) in self.mesh.adjacent(t).iter().enumerate() {
                if !cavity.contains(&n) {
                    faces.push((faces_of_t[i], (n != NO_TET).then_some(n)));
                }
            }
        }
        faces
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
        let mut candidates = vec![centroid];
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

    /// Recover the missing triangle `abc` (whose edges are edges) by filling its cavity again;
    /// returns the Steiner points added, `None` when no cone fills a side.
    pub(super) fn refill_triangle(&mut self, abc: [u32; 3], triangles: &[[u32; 3]]) -> Option<usize> {
        let cavity = self.crossing_tets(Target::Triangle(abc));
        if cavity.is_empty() {
            return Some(0);
        }
        let t = abc.map(|v| self.mesh.points[v as usize]);
        let side = |f: &[u32; 3]| {
            let signs = f.map(|v| orient3d(t[0], t[1], t[2], self.mesh.points[v as usize]));
            signs.into_iter().find(|&s| s != Sign::Zero).unwrap_or(Sign::Zero)
        };
        let faces: Vec<[u32; 3]> = self.cavity_faces(&cavity).into_iter().map(|(f, _)| f).collect();
        let normal = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
        let mut cones = Vec::new();
        for (sign, up, cap) in
            [(Sign::Positive, normal, abc), (Sign::Negative, -normal, [abc[0], abc[2], abc[1]])]
        {
            let mut side_faces: Vec<[u32; 3]> = faces.iter().filter(|f| side(f) == sign).copied().collect();
            side_faces.push(cap);
            cones.push(self.cone(&side_faces, Some((t, up)), triangles)?);
        }
        let add: Vec<[u32; 4]> = cones.iter().flat_map(|c| c.tets.iter().copied()).collect();
        // Steiner points are numbered in turn: the second cone's is one further.
        if cones[0].steiner.is_some() && cones[1].steiner.is_some() {
            let v = self.mesh.points.len() as u32;
            let renumber = |t: [u32; 4]| t.map(|u| if u == v { v + 1 } else { u });
            let (first, second) = (&cones[0], &cones[1]);
            let second_tets: Vec<[u32; 4]> = second.tets.iter().map(|&t| renumber(t)).collect();
            let all: Vec<[u32; 4]> = first.tets.iter().copied().chain(second_tets.iter().copied()).collect();
            if !self.keeps_boundary(&cavity, &all) {
                return None;
            }
            self.replace(cavity, first.tets.clone(), first.steiner);
            self.replace(Vec::new(), second_tets, second.steiner);
            return Some(2);
        }
        if !self.keeps_boundary(&cavity, &add) {
            return None;
        }
        let steiner = cones.iter().find_map(|c| c.steiner);
        self.replace(cavity, add, steiner);
        Some(usize::from(steiner.is_some()))
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
    pub(super) fn steiner_near_edge(&mut self, [a, b]: [u32; 2], triangles: &[[u32; 3]]) -> bool {
        let x = |v: u32| self.mesh.points[v as usize];
        let normal = |t: &[u32; 3]| (x(t[1]) - x(t[0])).cross(x(t[2]) - x(t[0])).normalize_or_zero();
        let at_edge = triangles.iter().filter(|t| t.contains(&a) && t.contains(&b));
        let direction = at_edge.map(normal).sum::<DVec3>().normalize_or_zero();
        let (middle, length) = (0.5 * (x(a) + x(b)), x(a).distance(x(b)));
        let hint = self.mesh.ball(a).first().copied().unwrap_or(0);
        let wall = |f: &[u32; 3]| self.triangles.contains(&crate::fill::sorted_triangle(*f));
        for s in [0.2, 0.05, 0.01] {
            let p = middle + s * length * direction;
            if triangles.iter().any(|t| on_triangle(p, t.map(x))) {
                continue;
            }
            let Ok((remove, add)) = super::insert::star_cavity(&self.mesh, hint, p, &wall) else { continue };
            if self.keeps_boundary(&remove, &add) {
                self.replace(remove, add, Some(p));
                return true;
            }
        }
        false
    }
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
