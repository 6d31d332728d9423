//! The input wall: a closed triangle surface with named patches.
//!
//! Invariants after [`validate`] succeeds: every edge has exactly two triangles, every vertex's
//! triangle fan is a single disc, neighbouring triangles are oriented alike, each shell has
//! positive enclosed volume (normals point into the fluid for an external body), no triangle is
//! degenerate and no two triangles intersect except at shared edges/vertices.

pub mod features;
pub mod info;
pub mod topology;
pub mod validate;

use crate::geometry::{triangle_area_vector, Aabb, DVec3};

/// A triangle surface: points, triangles (counter-clockwise seen from the fluid, so the
/// right-hand normal points into the fluid for an external body) and the patch of each triangle.
#[derive(Clone, Debug, Default)]
pub struct Surface {
    pub points: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    /// Index into `patch_names` for every triangle.
    pub triangle_patch: Vec<u32>,
    pub patch_names: Vec<String>,
}

impl Surface {
    pub fn bounding_box(&self) -> Aabb {
        Aabb::from_points(&self.points)
    }

    pub fn triangle_points(&self, t: usize) -> [DVec3; 3] {
        let [a, b, c] = self.triangles[t];
        [self.points[a as usize], self.points[b as usize], self.points[c as usize]]
    }

    /// Twice the area vector of triangle `t` (right-hand normal, length = 2 * area).
    pub fn triangle_area_vector(&self, t: usize) -> DVec3 {
        let [a, b, c] = self.triangle_points(t);
        triangle_area_vector(a, b, c)
    }

    /// Unit right-hand normal of triangle `t` (zero for a degenerate triangle).
    pub fn triangle_normal(&self, t: usize) -> DVec3 {
        self.triangle_area_vector(t).normalize_or_zero()
    }

    /// Volume enclosed by the surface (divergence theorem); positive when normals point outward.
    pub fn enclosed_volume(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.triangle_points(t);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// Number of triangles in every patch, in `patch_names` order.
    pub fn patch_triangle_counts(&self) -> Vec<usize> {
        let mut counts = vec![0; self.patch_names.len()];
        for &p in &self.triangle_patch {
            counts[p as usize] += 1;
        }
        counts
    }

    /// Reverse the orientation of every triangle.
    pub fn flip_all(&mut self) {
        for t in &mut self.triangles {
            t.swap(1, 2);
        }
    }
}
