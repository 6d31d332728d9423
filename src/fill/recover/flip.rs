//! Recovery by flips: a missing boundary edge or triangle is crossed by fewer and fewer edges
//! and faces, each step the flip (2-3 on a face, or the removal of an edge: 3-2, 4-4 and
//! larger rings) that takes away the most crossings, or where none does, two flips in a row
//! that do (the first may add one), until none is left or nothing helps.

use super::cross::Target;
use super::recovery::{inward_faces, tet_edges, Recovery};
use crate::fill::improve::{best_polygon_triangulation, ring_tets, Change};
use crate::fill::sorted_triangle;
use crate::geometry::predicates::{orient3d, Sign};

/// Largest ring of tetrahedra around an edge that a flip removes.
const MAX_RING: usize = 10;

/// Flips at most per target (each removes a crossing: a bound on the work only).
const MAX_FLIPS: usize = 10_000;

/// A flip and how many crossings of the target it takes away.
struct Flip {
    remove: Vec<u32>,
    add: Vec<[u32; 4]>,
    gain: i64,
}

impl Recovery {
    /// Flip until the target is an edge or a face (`true`) or no flip, nor two in a row, takes
    /// a crossing away; counts the flips made in `flips`.
    pub(super) fn flip_to(&mut self, target: Target, flips: &mut usize) -> bool {
        for _ in 0..MAX_FLIPS {
            let crossing = self.crossing_tets(target);
            if crossing.is_empty() {
                return self.present(target);
            }
            let candidates = self.flips(target, &crossing);
            let count = candidates.len();
            match candidates.into_iter().max_by_key(|f| f.gain) {
                Some(best) if best.gain > 0 => {
                    *flips += 1;
                    self.replace(best.remove, best.add, None);
                }
                _ if self.two_flips(target, count, flips) => {}
                _ => return false,
            }
        }
        false
    }

    /// Where no flip takes a crossing away: a flip that takes none followed by one that takes
    /// some, if there is such a pair; whether it made one. (Each first flip tried is undone,
    /// which renumbers tetrahedra: the candidates are listed again after it.)
    fn two_flips(&mut self, target: Target, count: usize, flips: &mut usize) -> bool {
        for k in 0..count {
            let crossing = self.crossing_tets(target);
            let Some(first) = self.flips(target, &crossing).into_iter().filter(|f| f.gain >= 0).nth(k) else {
                return false;
            };
            let undo: Vec<[u32; 4]> = first.remove.iter().map(|&t| self.mesh.tet(t)).collect();
            let slots = self.mesh.slots() as u32;
            self.replace(first.remove, first.add, None);
            let created: Vec<u32> = (slots..self.mesh.slots() as u32).collect();
            let crossing = self.crossing_tets(target);
            let second = self
                .flips(target, &crossing)
                .into_iter()
                .filter(|f| first.gain + f.gain > 0)
                .max_by_key(|f| f.gain);
            if let Some(second) = second {
                *flips += 2;
                self.replace(second.remove, second.add, None);
                return true;
            }
            self.replace(created, undo, None);
        }
        false
    }

    /// The flips at the tetrahedra `crossing` that keep the boundary, with how many crossings
    /// each takes away.
    fn flips(&self, target: Target, crossing: &[u32]) -> Vec<Flip> {
        let mut faces: Vec<[u32; 3]> =
            crossing.iter().flat_map(|&t| inward_faces(self.mesh.tet(t))).map(sorted_triangle).collect();
        faces.sort_unstable();
        faces.dedup();
        let mut edges: Vec<[u32; 2]> = crossing.iter().flat_map(|&t| tet_edges(self.mesh.tet(t))).collect();
        edges.sort_unstable();
        edges.dedup();
        let face_flips = faces
            .into_iter()
            .filter(|f| !self.triangles.contains(f))
            .filter_map(|f| self.mesh.flip_23(f))
            .map(|change: Change| (change.remove, change.add));
        let edge_flips = edges
            .into_iter()
            .filter(|e| !self.edges.contains(e))
            .filter_map(|[a, b]| self.edge_flip(target, a, b));
        face_flips
            .chain(edge_flips)
            .map(|(remove, add)| {
                let gain = -self.crossing_change(target, &remove, &add);
                Flip { remove, add, gain }
            })
            .collect()
    }

    /// The removal of edge `ab` whose new edges and faces cross the target least, with every
    /// new tetrahedron positive.
    fn edge_flip(&self, target: Target, a: u32, b: u32) -> Option<(Vec<u32>, Vec<[u32; 4]>)> {
        let (tets, ring) = self.mesh.ring(a, b)?;
        if ring.len() > MAX_RING {
            return None;
        }
        let points = &self.mesh.points;
        let positive = |t: [u32; 4]| {
            let [p, q, r, s] = t.map(|v| points[v as usize]);
            orient3d(p, q, r, s) == Sign::Positive
        };
        let last = ring.len() - 1;
        // Each new edge is the base (i, j) of one triangle: counted there.
        let weight = |i: usize, k: usize, j: usize| {
            let pair = ring_tets(a, b, &ring, (i, k, j));
            if !pair.iter().all(|&t| positive(t)) {
                return f64::NEG_INFINITY;
            }
            let (ri, rk, rj) = (ring[i], ring[k], ring[j]);
            let mut crossings = usize::from(target.crossed_by_face(points, [ri, rk, rj]));
            if (i, j) != (0, last) {
                crossings += usize::from(target.crossed_by_edge(points, [ri, rj]))
                    + usize::from(target.crossed_by_face(points, [ri, rj, a]))
                    + usize::from(target.crossed_by_face(points, [ri, rj, b]));
            }
            -(crossings as f64)
        };
        let triangles = best_polygon_triangulation(ring.len(), weight, |x, y| x + y, 0.0, f64::NEG_INFINITY)?;
        let add = triangles.into_iter().flat_map(|t| ring_tets(a, b, &ring, t)).collect();
        Some((tets, add))
    }
}
