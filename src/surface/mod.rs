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

use std::collections::HashMap;

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

    /// Drop the points no triangle uses and renumber the rest (order kept), so that every
    /// point is a triangle vertex. Triangle indices must be in range.
    pub fn remove_unused_points(&mut self) {
        let mut used = vec![false; self.points.len()];
        for &v in self.triangles.iter().flatten() {
            used[v as usize] = true;
        }
        let mut new_index = vec![u32::MAX; self.points.len()];
        let mut points = Vec::with_capacity(self.points.len());
        for (i, &p) in self.points.iter().enumerate() {
            if used[i] {
                new_index[i] = points.len() as u32;
                points.push(p);
            }
        }
        self.points = points;
        self.renumber_triangles(&new_index);
    }

    /// Merge points with bit-identical coordinates (-0.0 counts as 0.0), keeping the first
    /// occurrence's position in the order. Used where a format repeats shared vertices (STL).
    pub fn weld_exact(&mut self) {
        let mut index_of: HashMap<[u64; 3], u32> = HashMap::with_capacity(self.points.len());
        let mut points = Vec::with_capacity(self.points.len());
        let new_index: Vec<u32> = self
            .points
            .iter()
            .map(|&p| {
                // Adding +0.0 maps -0.0 to +0.0 and leaves every other value (and NaN bits) alone.
                let key = (p + DVec3::ZERO).to_array().map(f64::to_bits);
                *index_of.entry(key).or_insert_with(|| {
                    points.push(p + DVec3::ZERO);
                    (points.len() - 1) as u32
                })
            })
            .collect();
        self.points = points;
        self.renumber_triangles(&new_index);
    }

    fn renumber_triangles(&mut self, new_index: &[u32]) {
        for t in &mut self.triangles {
            *t = t.map(|v| new_index[v as usize]);
        }
    }

    /// Set the patches from one integer label per triangle (Cart3D component, Medit reference,
    /// UH3D component): one patch per distinct label, in increasing label order, named by
    /// `name`; labels given the same name share a patch.
    pub fn set_patches_from_labels(&mut self, labels: &[i64], name: impl Fn(i64) -> String) {
        let mut distinct = labels.to_vec();
        distinct.sort_unstable();
        distinct.dedup();
        let mut table = PatchTable::default();
        let patch_of: HashMap<i64, u32> =
            distinct.into_iter().map(|label| (label, table.index(&name(label)))).collect();
        self.triangle_patch = labels.iter().map(|label| patch_of[label]).collect();
        self.patch_names = table.into_names();
    }
}

/// Patch names met while reading a file (STL solids, OBJ groups), each given an index once,
/// in order of first use; a name met again gets its earlier index.
#[derive(Clone, Debug, Default)]
pub struct PatchTable {
    index_of: HashMap<String, u32>,
    names: Vec<String>,
}

impl PatchTable {
    /// The index of patch `name`, a new one if the name is new.
    pub fn index(&mut self, name: &str) -> u32 {
        if let Some(&i) = self.index_of.get(name) {
            return i;
        }
        let i = self.names.len() as u32;
        self.index_of.insert(name.to_owned(), i);
        self.names.push(name.to_owned());
        i
    }

    pub fn into_names(self) -> Vec<String> {
        self.names
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn soup() -> Surface {
        Surface {
            points: vec![
                DVec3::X,
                DVec3::new(9.0, 9.0, 9.0),
                DVec3::ZERO,
                DVec3::X,
                DVec3::new(-0.0, 0.0, 0.0),
            ],
            triangles: vec![[0, 2, 3], [3, 4, 0]],
            triangle_patch: vec![0, 0],
            patch_names: vec!["wall".into()],
        }
    }

    #[test]
    fn unused_points_are_dropped_in_order() {
        let mut s = soup();
        s.remove_unused_points();
        assert_eq!(s.points, vec![DVec3::X, DVec3::ZERO, DVec3::X, DVec3::ZERO]);
        assert_eq!(s.triangles, vec![[0, 1, 2], [2, 3, 0]]);
    }

    #[test]
    fn exact_weld_merges_equal_bits_and_signed_zeros() {
        let mut s = soup();
        s.weld_exact();
        s.remove_unused_points();
        assert_eq!(s.points, vec![DVec3::X, DVec3::ZERO]);
        assert!(!s.points[1].x.is_sign_negative());
        assert_eq!(s.triangles, vec![[0, 1, 0], [0, 1, 0]]);
        let mut nearly = soup();
        nearly.points[3].x = 1.0 + f64::EPSILON;
        nearly.weld_exact();
        assert_eq!(nearly.points.len(), 4, "only bit-identical points merge");
    }

    #[test]
    fn labels_become_patches_in_increasing_order_and_names_merge() {
        let mut s = soup();
        s.set_patches_from_labels(&[7, -2], |l| format!("ref_{l}"));
        assert_eq!(s.patch_names, vec!["ref_-2", "ref_7"]);
        assert_eq!(s.triangle_patch, vec![1, 0]);
        s.set_patches_from_labels(&[7, -2], |_| "same".into());
        assert_eq!((s.patch_names.len(), s.triangle_patch.clone()), (1, vec![0, 0]));
        let mut table = PatchTable::default();
        assert_eq!([table.index("b"), table.index("a"), table.index("b")], [0, 1, 0]);
        assert_eq!(table.into_names(), vec!["b", "a"]);
    }
}

pub mod family;
pub mod shapes;
