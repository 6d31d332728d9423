//! The standard set of pictures of a mesh (what `blmesh mesh --pictures DIR` writes).

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::cut::gather;
use super::{cut_picture, histogram_picture, write_png, Colouring, CutPlane, View};
use crate::geometry::{Aabb, DVec3};
use crate::mesh::{CellKind, VolumeMesh};
use crate::quality::fv::non_orthogonality_by_kind;
use crate::quality::measures::scaled_jacobian;

/// Side of the square cut pictures, in pixels.
const SIDE: u32 = 1200;

/// Scaled Jacobian of every cell, in [`VolumeMesh::cells`] order (NaN for a cell with a bad node
/// index or a non-finite coordinate).
pub fn scaled_jacobians(mesh: &VolumeMesh) -> Vec<f64> {
    let per_block = |b: &crate::mesh::CellBlock| -> Vec<f64> {
        let n = b.kind.node_count();
        b.nodes
            .par_chunks_exact(n)
            .map(|nodes| gather(nodes, &mesh.points).map_or(f64::NAN, |x| scaled_jacobian(b.kind, &x)))
            .collect()
    };
    mesh.blocks.iter().flat_map(per_block).collect()
}

/// A named place to cut the mesh at (a concave ridge, a convex corner), with the half width of
/// the view around it.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PictureSpot {
    pub name: String,
    pub origin: DVec3,
    pub normal: DVec3,
    pub half_width: f64,
}

/// Write the standard pictures of `mesh` into `dir` (created if missing) and return their paths:
/// - `cut_x.png`, `cut_y.png`, `cut_z.png`: cuts through the centre of the mesh's bounding box
///   normal to each axis, the whole cut in view, cells coloured by kind; `cut_*_quality.png`
///   the same coloured by scaled Jacobian;
/// - `worst_cell.png`, `worst_cell_quality.png`: a cut z = const through the centroid of the
///   cell of lowest scaled Jacobian, zoomed on its neighbourhood (4 times its size);
/// - `quality_histogram.png`: the scaled Jacobians of all cells in 50 bins over [0, 1]
///   (invalid cells, <= 0, in the first bin);
/// - `non_orthogonality_KIND.png` for every kind of cell with interior faces: the
///   non-orthogonality of the faces touching such cells, 45 bins over [0, 90] degrees;
/// - `NAME.png`, `NAME_quality.png` for every spot: the cut through it, zoomed to its width.
pub fn write_overview(mesh: &VolumeMesh, dir: &Path, spots: &[PictureSpot]) -> std::io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let mut written = Vec::new();
    let mut write = |name: &str, picture: &tiny_skia::Pixmap| {
        let path = dir.join(name);
        write_png(picture, &path)?;
        written.push(path);
        std::io::Result::Ok(())
    };
    let centre = Aabb::from_points(mesh.points.iter().filter(|p| p.is_finite())).center();
    for (axis, normal) in [("x", DVec3::X), ("y", DVec3::Y), ("z", DVec3::Z)] {
        let plane = CutPlane { origin: centre, normal };
        let view = View::fit(mesh, &plane);
        write(&format!("cut_{axis}.png"), &cut_picture(mesh, &plane, &view, Colouring::Kind, SIDE, SIDE))?;
        let quality = cut_picture(mesh, &plane, &view, Colouring::Quality, SIDE, SIDE);
        write(&format!("cut_{axis}_quality.png"), &quality)?;
    }
    for spot in spots {
        let plane = CutPlane { origin: spot.origin, normal: spot.normal };
        let view = View::around(spot.origin, spot.half_width);
        write(&format!("{}.png", spot.name), &cut_picture(mesh, &plane, &view, Colouring::Kind, SIDE, SIDE))?;
        let quality = cut_picture(mesh, &plane, &view, Colouring::Quality, SIDE, SIDE);
        write(&format!("{}_quality.png", spot.name), &quality)?;
    }
    let quality = scaled_jacobians(mesh);
    if let Some((plane, view)) = worst_cell_view(mesh, &quality) {
        write("worst_cell.png", &cut_picture(mesh, &plane, &view, Colouring::Kind, SIDE, SIDE))?;
        write("worst_cell_quality.png", &cut_picture(mesh, &plane, &view, Colouring::Quality, SIDE, SIDE))?;
    }
    write("quality_histogram.png", &histogram_picture(&quality, 50, (0.0, 1.0), 1000, 400))?;
    for (kind, angles) in CellKind::ALL.iter().zip(non_orthogonality_by_kind(mesh)) {
        if !angles.is_empty() {
            let picture = histogram_picture(&angles, 45, (0.0, 90.0), 1000, 400);
            write(&format!("non_orthogonality_{}.png", kind.name()), &picture)?;
        }
    }
    Ok(written)
}

/// The plane z = const through the centroid of the cell of lowest scaled Jacobian, and a view of
/// 4 times the cell's size around it.
fn worst_cell_view(mesh: &VolumeMesh, quality: &[f64]) -> Option<(CutPlane, View)> {
    let worst = (0..quality.len())
        .filter(|&i| !quality[i].is_nan())
        .min_by(|&a, &b| quality[a].total_cmp(&quality[b]))?;
    let (kind, nodes) = mesh.cells().nth(worst)?;
    let x = gather(nodes, &mesh.points)?;
    let x = &x[..kind.node_count()];
    let centroid = x.iter().sum::<DVec3>() / x.len() as f64;
    let size = Aabb::from_points(x).diagonal();
    let plane = CutPlane { origin: centroid, normal: DVec3::Z };
    Some((plane, View::around(centroid, 2.0 * size)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::samples::hybrid_column;

    #[test]
    fn overview_writes_every_picture() {
        let dir = tempfile::tempdir().unwrap();
        let mut mesh = hybrid_column();
        mesh.points[5].x += 0.3; // the worst cell is then next to node 5
        let centre = Aabb::from_points(&mesh.points).center();
        let spot = PictureSpot { name: "spot".into(), origin: centre, normal: DVec3::X, half_width: 1.0 };
        let written = write_overview(&mesh, &dir.path().join("pictures"), &[spot]).unwrap();
        let names: Vec<_> =
            written.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
        assert_eq!(names.len(), 15, "{names:?}");
        assert!(names.contains(&"non_orthogonality_pyramid.png".to_string()));
        assert!(
            names.contains(&"worst_cell.png".to_string()) && names.contains(&"spot_quality.png".to_string())
        );
        for path in &written {
            let picture = tiny_skia::Pixmap::load_png(path).unwrap();
            assert!(picture.pixels().iter().any(|p| p.red() != 255), "{} is blank", path.display());
        }
    }

    #[test]
    fn scaled_jacobians_follow_the_cells() {
        let mut mesh = hybrid_column();
        let q = scaled_jacobians(&mesh);
        assert_eq!(q.len(), mesh.cell_count());
        assert_eq!(q.iter().copied().fold(0.0, f64::max), 1.0);
        mesh.points[0] = DVec3::splat(f64::NAN); // a corner of the hexahedron, the last cell
        let q = scaled_jacobians(&mesh);
        assert!(q[q.len() - 1].is_nan() && q[..q.len() - 1].iter().all(|q| *q > 0.0));
    }
}
