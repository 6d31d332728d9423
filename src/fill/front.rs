//! The core's boundary taken from the layered mesh: the top faces of the layers, the wall
//! triangles where no layer was built, pyramids on the front's quads, and the farfield.

use std::collections::{HashMap, HashSet};

use super::size_jump::LastLayer;
use super::{farfield, ClosedBoundary, FarfieldSpec, FillError, CORE_ZONE_NAME, FARFIELD_PATCH};
use super::{sorted_triangle, MARKER_FARFIELD, MARKER_FRONT, MARKER_WALL};
use crate::geometry::DVec3;
use crate::layers::march::LAYER_ZONE;
use crate::layers::sliding::SymmetryPlane;
use crate::layers::TOP_PATCH;
use crate::mesh::{BoundaryFaces, CellKind, VolumeMesh};
use crate::quality::measures::quad_centre;
use crate::surface::Surface;

/// The mesh being built around the core: the layered mesh without its top faces plus the
/// pyramids and the farfield, and the core's boundary triangles (mesh node ids, facing into
/// the core).
pub(super) struct CoreBuild {
    pub mesh: VolumeMesh,
    pub faces: Vec<[u32; 3]>,
    pub markers: Vec<u32>,
    pub core_zone: u32,
    pub pyramids: usize,
}

/// Gather the core's boundary from the layered mesh and the wall it was built from.
pub(super) fn core_boundary(layers: &VolumeMesh, wall: &Surface) -> Result<CoreBuild, FillError> {
    check_wall(layers, wall)?;
    let (mesh, triangles, quads) = without_top(layers);
    let mut build = CoreBuild { mesh, faces: Vec::new(), markers: Vec::new(), core_zone: 0, pyramids: 0 };
    build.core_zone = build.mesh.zone_names.len() as u32;
    build.mesh.zone_names.push(CORE_ZONE_NAME.to_owned());
    for t in triangles {
        build.push(t, MARKER_FRONT);
    }
    build.add_uncovered_wall(wall);
    for q in quads {
        build.add_pyramid(q)?;
    }
    Ok(build)
}

/// The wall's points must be the layered mesh's first points and its patches its first patches.
fn check_wall(layers: &VolumeMesh, wall: &Surface) -> Result<(), FillError> {
    let n = wall.points.len();
    if layers.points.get(..n) != Some(&wall.points[..]) {
        return Err(FillError::WallMismatch(format!(
            "the layered mesh does not start with the wall's {n} points"
        )));
    }
    if layers.patch_names.get(..wall.patch_names.len()) != Some(&wall.patch_names[..]) {
        return Err(FillError::WallMismatch(format!(
            "the layered mesh's patches {:?} do not start with the wall's {:?}",
            layers.patch_names, wall.patch_names
        )));
    }
    match wall.triangles.iter().position(|t| t.iter().any(|&v| v as usize >= n)) {
        Some(t) => Err(FillError::WallMismatch(format!("wall triangle {t} has a vertex index >= {n}"))),
        None => Ok(()),
    }
}

/// The layered mesh without the top patch, and the top faces (facing into the core).
fn without_top(layers: &VolumeMesh) -> (VolumeMesh, Vec<[u32; 3]>, Vec<[u32; 4]>) {
    let mut mesh = layers.clone();
    let Some(top) = layers.patch_names.iter().position(|p| p == TOP_PATCH).map(|p| p as u32) else {
        return (mesh, Vec::new(), Vec::new());
    };
    mesh.patch_names.remove(top as usize);
    let b = std::mem::take(&mut mesh.boundary);
    let (triangles, triangle_patch, front_triangles) = split_off(b.triangles, b.triangle_patch, top);
    let (quads, quad_patch, front_quads) = split_off(b.quads, b.quad_patch, top);
    mesh.boundary = BoundaryFaces { triangles, triangle_patch, quads, quad_patch };
    (mesh, front_triangles, front_quads)
}

/// The faces of patch `top` apart; the others with their patches renumbered without `top`.
fn split_off<F>(faces: Vec<F>, patches: Vec<u32>, top: u32) -> (Vec<F>, Vec<u32>, Vec<F>) {
    let (mut kept, mut kept_patches, mut taken) = (Vec::new(), Vec::new(), Vec::new());
    for (face, p) in faces.into_iter().zip(patches) {
        if p == top {
            taken.push(face);
        } else {
            kept.push(face);
            kept_patches.push(if p > top { p - 1 } else { p });
        }
    }
    (kept, kept_patches, taken)
}

impl CoreBuild {
    fn push(&mut self, face: [u32; 3], marker: u32) {
        self.faces.push(face);
        self.markers.push(marker);
    }

    /// Wall triangles under no layer cell are on the front as they are (facing the fluid) and
    /// boundary faces of the mesh (reversed: out of the domain, into the body).
    fn add_uncovered_wall(&mut self, wall: &Surface) {
        let covered: HashSet<[u32; 3]> =
            self.mesh.boundary.triangles.iter().map(|&t| sorted_triangle(t)).collect();
        for (t, &[a, b, c]) in wall.triangles.iter().enumerate() {
            if !covered.contains(&sorted_triangle([a, b, c])) {
                self.push([a, b, c], MARKER_WALL);
                self.mesh.boundary.triangles.push([a, c, b]);
                self.mesh.boundary.triangle_patch.push(wall.triangle_patch[t]);
            }
        }
    }

    /// A pyramid on a front quad (its base facing the core); its four triangles join the front.
    fn add_pyramid(&mut self, quad: [u32; 4]) -> Result<(), FillError> {
        let x = quad.map(|n| self.mesh.points[n as usize]);
        let centre = quad_centre(x[0], x[1], x[2], x[3]);
        let apex = crate::layers::guard::pyramid_apex(x)
            .ok_or(FillError::NoPyramid { nodes: quad, centre: centre.to_array() })?;
        let apex_node = self.mesh.points.len() as u32;
        self.mesh.points.push(apex);
        let [a, b, c, d] = quad;
        self.mesh.push_cell(CellKind::Pyramid, &[a, b, c, d, apex_node], self.core_zone);
        for (p, q) in [(a, b), (b, c), (c, d), (d, a)] {
            self.push([p, q, apex_node], MARKER_FRONT);
        }
        self.pyramids += 1;
        Ok(())
    }

    /// Close the core with a farfield around the wall (patch [`FARFIELD_PATCH`]).
    pub fn add_farfield(&mut self, wall: &Surface, spec: &FarfieldSpec) -> Result<(), FillError> {
        let shell = farfield::farfield(spec, wall.bounding_box())?;
        self.add_farfield_shell(shell);
        Ok(())
    }

    /// Close the core of a body on a symmetry plane: a half box on the fluid's side (patch
    /// [`FARFIELD_PATCH`]) and the rest of the plane, triangulated between the box's rim and
    /// the core's open edges on the plane (the layers' top edges there), as `symmetry.patch`.
    pub fn add_half_farfield(
        &mut self,
        wall: &Surface,
        spec: &FarfieldSpec,
        symmetry: &SymmetryPlane,
    ) -> Result<(), FillError> {
        let shell = farfield::half_box(spec, wall.bounding_box(), &symmetry.plane)?;
        let cell = spec.cell_size.unwrap_or(super::DEFAULT_FARFIELD_CELL * wall.bounding_box().diagonal());
        self.add_farfield_shell(shell);
        let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
        for t in &self.faces {
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                *uses.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        let mut open: Vec<(u32, u32)> = uses.into_iter().filter(|&(_, n)| n == 1).map(|(e, _)| e).collect();
        open.sort_unstable(); // the same mesh on every run
        let plane = symmetry.plane;
        let tolerance = 1e-9 * wall.bounding_box().diagonal();
        if let Some(&(a, _)) = open.iter().find(|&&(a, b)| {
            [a, b].iter().any(|&n| plane.signed_distance(self.mesh.points[n as usize]).abs() > tolerance)
        }) {
            return Err(FillError::Input(format!(
                "the core's boundary is open at {:?}, off the symmetry plane (the layers did not end on it)",
                self.mesh.points[a as usize].to_array()
            )));
        }
        let max_area = 0.25 * 3f64.sqrt() * cell * cell;
        let triangles = crate::layers::sliding::triangulate_region(
            &mut self.mesh.points,
            &open,
            &[],
            &plane,
            max_area,
        )
        .map_err(|why| FillError::Input(format!("the symmetry plane cannot be triangulated: {why}")))?;
        for [a, b, c] in triangles {
            self.push([a, b, c], MARKER_WALL);
            self.mesh.boundary.triangles.push([a, c, b]);
            self.mesh.boundary.triangle_patch.push(symmetry.patch);
        }
        Ok(())
    }

    /// Add a farfield shell (facing inward) to the mesh's points, the core's boundary and the
    /// mesh's boundary (patch [`FARFIELD_PATCH`]).
    fn add_farfield_shell(&mut self, shell: Surface) {
        let patch = match self.mesh.patch_names.iter().position(|p| p == FARFIELD_PATCH) {
            Some(p) => p as u32,
            None => {
                self.mesh.patch_names.push(FARFIELD_PATCH.to_owned());
                self.mesh.patch_names.len() as u32 - 1
            }
        };
        let offset = self.mesh.points.len() as u32;
        self.mesh.points.extend(shell.points);
        for [a, b, c] in shell.triangles.into_iter().map(|t| t.map(|v| v + offset)) {
            self.push([a, b, c], MARKER_FARFIELD);
            self.mesh.boundary.triangles.push([a, c, b]);
            self.mesh.boundary.triangle_patch.push(patch);
        }
    }

    /// The boundary with its own compact point numbering, and the mesh node of every point.
    pub fn closed_boundary(&self) -> (ClosedBoundary, Vec<u32>) {
        let mut local = vec![u32::MAX; self.mesh.points.len()];
        let mut nodes = Vec::new();
        let triangles = self
            .faces
            .iter()
            .map(|t| {
                t.map(|n| {
                    let slot = &mut local[n as usize];
                    if *slot == u32::MAX {
                        *slot = nodes.len() as u32;
                        nodes.push(n);
                    }
                    *slot
                })
            })
            .collect();
        let points = nodes.iter().map(|&n| self.mesh.points[n as usize]).collect();
        (ClosedBoundary { points, triangles, markers: self.markers.clone() }, nodes)
    }
}

impl CoreBuild {
    /// The last layer under the core's boundary ([`LastLayer`]), `nodes` being the mesh nodes
    /// of the boundary points (from [`CoreBuild::closed_boundary`]). With `on_prisms_only`, the
    /// front triangles with no prism under them get no height.
    pub fn front_layer(&self, nodes: &[u32], on_prisms_only: bool) -> FrontLayer {
        let last_layer = LastLayer::of(&self.mesh, LAYER_ZONE);
        let x = |n: u32| self.mesh.points[n as usize];
        let heights = (0..self.faces.len())
            .map(|f| {
                let face = self.faces[f];
                let height = (self.markers[f] == MARKER_FRONT).then(|| last_layer.height(face, face.map(x)));
                let height = height.flatten().filter(|&(_, on_prism)| on_prism || !on_prisms_only);
                height.map_or(f64::NAN, |(h, _)| h)
            })
            .collect();
        let steps = nodes.iter().map(|&n| last_layer.step(n).unwrap_or(DVec3::NAN)).collect();
        FrontLayer { heights, steps }
    }
}

/// The last layer under the core's boundary, for the seeds and the improvement.
#[derive(Clone, Debug, Default)]
pub struct FrontLayer {
    /// The last layer's height under every boundary triangle ([`LastLayer::height`]; NaN where
    /// there is none: walls without layers, the farfield, the pyramids' sides, front triangles
    /// with no column's last step at a node).
    pub heights: Vec<f64>,
    /// The last step of the column at every boundary point (NaN where none).
    pub steps: Vec<DVec3>,
}
