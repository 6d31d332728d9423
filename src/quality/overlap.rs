//! Overlapping cells: a mesh whose cells are each valid and conforming can still fold over
//! itself (two layer fronts crossing at a concave ridge). Its boundary then intersects itself,
//! which the exact triangle tests of the surface validation detect.

use serde::Serialize;

use crate::mesh::VolumeMesh;
use crate::surface::validate::intersecting_pairs;
use crate::surface::Surface;

/// Pairs of boundary faces that intersect other than along shared edges and vertices.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Overlap {
    pub intersecting_pairs: usize,
    /// Centres of the first few intersecting pairs of faces.
    pub examples: Vec<[[f64; 3]; 2]>,
}

/// The boundary faces (quads split along a diagonal) as one surface, and the intersecting pairs.
pub fn boundary_overlap(mesh: &VolumeMesh) -> Overlap {
    let b = &mesh.boundary;
    let mut triangles = b.triangles.clone();
    for q in &b.quads {
        triangles.push([q[0], q[1], q[2]]);
        triangles.push([q[0], q[2], q[3]]);
    }
    if triangles.iter().flatten().any(|&v| v as usize >= mesh.points.len()) {
        return Overlap::default(); // reported as a structure error by the checker
    }
    let count = triangles.len();
    let surface = Surface {
        points: mesh.points.clone(),
        triangles,
        triangle_patch: vec![0; count],
        patch_names: vec!["boundary".into()],
    };
    let pairs = intersecting_pairs(&surface);
    let centre = |t: u32| {
        let p = surface.triangle_points(t as usize);
        ((p[0] + p[1] + p[2]) / 3.0).to_array()
    };
    Overlap {
        intersecting_pairs: pairs.len(),
        examples: pairs.iter().take(super::EXAMPLES).map(|&(a, c)| [centre(a), centre(c)]).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::samples::hybrid_column;

    #[test]
    fn a_valid_mesh_has_no_overlap_and_a_folded_one_has() {
        let mesh = hybrid_column();
        assert_eq!(boundary_overlap(&mesh).intersecting_pairs, 0);
        // Two copies of the same mesh on top of each other: their boundaries cross everywhere.
        let mut twice = mesh.clone();
        let n = mesh.points.len() as u32;
        twice.points.extend(mesh.points.iter().map(|p| *p + glam::DVec3::splat(0.25)));
        for (t, &patch) in mesh.boundary.triangles.iter().zip(&mesh.boundary.triangle_patch) {
            twice.boundary.triangles.push(t.map(|v| v + n));
            twice.boundary.triangle_patch.push(patch);
        }
        for (q, &patch) in mesh.boundary.quads.iter().zip(&mesh.boundary.quad_patch) {
            twice.boundary.quads.push(q.map(|v| v + n));
            twice.boundary.quad_patch.push(patch);
        }
        assert!(boundary_overlap(&twice).intersecting_pairs > 0);
    }
}
