//! The hybrid volume mesh: points, cells of four kinds, boundary faces with patch ids.
//!
//! # Node orders (the one place they are defined)
//! Cells use the Gmsh order, which is also meshio's; a cell is valid when every tetrahedron of
//! its decomposition has positive volume ([`crate::geometry::tet_signed_volume`] > 0).
//!
//! ```text
//! Tetrahedron  0 1 2 3      (0,1,2) is counter-clockwise seen from 3: its right-hand normal points to 3.
//! Pyramid      0 1 2 3 | 4  base quad (0,1,2,3), right-hand normal pointing to the apex 4.
//! Prism        0 1 2 | 3 4 5  bottom (0,1,2) with right-hand normal pointing to the top;
//!              lateral edges 0-3, 1-4, 2-5.
//! Hexahedron   0 1 2 3 | 4 5 6 7  bottom quad with right-hand normal pointing to the top;
//!              lateral edges 0-4, 1-5, 2-6, 3-7.
//! ```
//! VTK uses the same orders except the prism (VTK_WEDGE), whose bottom normal points away from the
//! top: VTK wedge = Gmsh prism permuted by [`CellKind::vtk_permutation`]. SU2 files use the VTK
//! orders (meshio's SU2 reader does not permute them back: its wedges read from `.su2` are
//! inverted in its own convention).
//! CGNS (`TETRA_4`, `PYRA_5`, `PENTA_6`, `HEXA_8` of the SIDS) uses the Gmsh orders above: its
//! face tables list the same outward faces ([`CellKind::cgns_type`]).
//! Medit (`.mesh`/`.meshb`) cells are written in the Gmsh orders above, unpermuted: meshio's
//! Medit reader and writer apply no permutation to any kind, so meshio reads them as valid
//! cells. refine's `.meshb` writer (`ref_export.c`: pyramid "square basis is 0-1-2-3 (oriented
//! counter clockwise like trias) and top vertex is 4") writes our pyramid as 1,2,3,0,4, a rotation
//! of the same base, and our other kinds unpermuted. (libMeshb's own documentation was not
//! checked.)
//! UGRID (`.ugrid`, [`crate::io::ugrid`]) uses these orders except the pyramid, whose apex is its
//! third node: `ugrid = ours[1, 0, 4, 2, 3]` ([`crate::io::ugrid::PYRAMID`]).
//!
//! Faces of each kind, oriented outward, are in [`CellKind::faces`].

pub mod faces;

use crate::geometry::DVec3;

pub use faces::{Across, CellNumbering, FaceTable};

/// An edge as its two node ids, smaller first: the key of an edge whichever way it is walked.
pub fn sorted_edge(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CellKind {
    Tetrahedron,
    Pyramid,
    Prism,
    Hexahedron,
}

/// A face of a reference cell, as local node indices, oriented outward.
pub type LocalFace = &'static [usize];

impl CellKind {
    pub const ALL: [CellKind; 4] =
        [CellKind::Tetrahedron, CellKind::Pyramid, CellKind::Prism, CellKind::Hexahedron];

    pub fn node_count(self) -> usize {
        match self {
            CellKind::Tetrahedron => 4,
            CellKind::Pyramid => 5,
            CellKind::Prism => 6,
            CellKind::Hexahedron => 8,
        }
    }

    /// Outward-oriented faces (right-hand normal points out of the cell).
    pub fn faces(self) -> &'static [LocalFace] {
        match self {
            CellKind::Tetrahedron => &[&[0, 2, 1], &[0, 1, 3], &[1, 2, 3], &[0, 3, 2]],
            CellKind::Pyramid => &[&[0, 3, 2, 1], &[0, 1, 4], &[1, 2, 4], &[2, 3, 4], &[3, 0, 4]],
            CellKind::Prism => &[&[0, 2, 1], &[3, 4, 5], &[0, 1, 4, 3], &[1, 2, 5, 4], &[2, 0, 3, 5]],
            CellKind::Hexahedron => {
                &[&[0, 3, 2, 1], &[4, 5, 6, 7], &[0, 1, 5, 4], &[1, 2, 6, 5], &[2, 3, 7, 6], &[3, 0, 4, 7]]
            }
        }
    }

    /// The corners of the cell as (corner, e1, e2, e3): the three edge neighbours of the corner in
    /// right-handed order, so `det(e1 - c, e2 - c, e3 - c) > 0` in a valid cell. A pyramid lists its
    /// four base corners only (its apex has four edges). Same table as `shared/bench/measure.py`.
    pub fn corners(self) -> &'static [[usize; 4]] {
        match self {
            CellKind::Tetrahedron => &[[0, 1, 2, 3], [1, 2, 0, 3], [2, 0, 1, 3], [3, 0, 2, 1]],
            CellKind::Pyramid => &[[0, 1, 3, 4], [1, 2, 0, 4], [2, 3, 1, 4], [3, 0, 2, 4]],
            CellKind::Prism => {
                &[[0, 1, 2, 3], [1, 2, 0, 4], [2, 0, 1, 5], [3, 5, 4, 0], [4, 3, 5, 1], [5, 4, 3, 2]]
            }
            CellKind::Hexahedron => &[
                [0, 1, 3, 4],
                [1, 2, 0, 5],
                [2, 3, 1, 6],
                [3, 0, 2, 7],
                [4, 7, 5, 0],
                [5, 4, 6, 1],
                [6, 5, 7, 2],
                [7, 6, 4, 3],
            ],
        }
    }

    /// The kind of a first-order Gmsh element type number, if it is a volume cell.
    pub fn from_gmsh_type(t: i32) -> Option<CellKind> {
        CellKind::ALL.into_iter().find(|k| k.gmsh_type() == t)
    }

    /// The kind of a VTK cell type number, if it is one of the four volume cells.
    pub fn from_vtk_type(t: u8) -> Option<CellKind> {
        CellKind::ALL.into_iter().find(|k| k.vtk_type() == t)
    }

    /// Gmsh element type number (first order).
    pub fn gmsh_type(self) -> i32 {
        match self {
            CellKind::Tetrahedron => 4,
            CellKind::Pyramid => 7,
            CellKind::Prism => 6,
            CellKind::Hexahedron => 5,
        }
    }

    /// CGNS `ElementType_t` value (same node order as ours).
    pub fn cgns_type(self) -> i32 {
        match self {
            CellKind::Tetrahedron => 10,
            CellKind::Pyramid => 12,
            CellKind::Prism => 14,
            CellKind::Hexahedron => 17,
        }
    }

    /// The kind of a CGNS `ElementType_t` value, if it is one of the four linear volume cells.
    pub fn from_cgns_type(t: i32) -> Option<CellKind> {
        CellKind::ALL.into_iter().find(|k| k.cgns_type() == t)
    }

    /// VTK cell type number.
    pub fn vtk_type(self) -> u8 {
        match self {
            CellKind::Tetrahedron => 10,
            CellKind::Pyramid => 14,
            CellKind::Prism => 13,
            CellKind::Hexahedron => 12,
        }
    }

    /// `vtk_nodes[i] = gmsh_nodes[perm[i]]`; the permutation is an involution.
    pub fn vtk_permutation(self) -> &'static [usize] {
        match self {
            CellKind::Tetrahedron => &[0, 1, 2, 3],
            CellKind::Pyramid => &[0, 1, 2, 3, 4],
            CellKind::Prism => &[0, 2, 1, 3, 5, 4],
            CellKind::Hexahedron => &[0, 1, 2, 3, 4, 5, 6, 7],
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            CellKind::Tetrahedron => "tetrahedron",
            CellKind::Pyramid => "pyramid",
            CellKind::Prism => "prism",
            CellKind::Hexahedron => "hexahedron",
        }
    }
}

/// One block of cells of a single kind; `nodes` holds `kind.node_count()` indices per cell.
#[derive(Clone, Debug)]
pub struct CellBlock {
    pub kind: CellKind,
    pub nodes: Vec<u32>,
    /// Volume zone of every cell (index into [`VolumeMesh::zone_names`]).
    pub zone: Vec<u32>,
}

impl CellBlock {
    pub fn new(kind: CellKind) -> Self {
        CellBlock { kind, nodes: Vec::new(), zone: Vec::new() }
    }

    pub fn len(&self) -> usize {
        self.zone.len()
    }

    pub fn is_empty(&self) -> bool {
        self.zone.is_empty()
    }

    pub fn cell(&self, i: usize) -> &[u32] {
        let n = self.kind.node_count();
        &self.nodes[i * n..(i + 1) * n]
    }

    pub fn push(&mut self, nodes: &[u32], zone: u32) {
        debug_assert_eq!(nodes.len(), self.kind.node_count());
        self.nodes.extend_from_slice(nodes);
        self.zone.push(zone);
    }

    pub fn iter(&self) -> impl Iterator<Item = &[u32]> {
        self.nodes.chunks_exact(self.kind.node_count())
    }
}

/// Boundary faces (triangles or quads) with the patch of each, oriented out of the domain.
#[derive(Clone, Debug, Default)]
pub struct BoundaryFaces {
    pub triangles: Vec<[u32; 3]>,
    pub triangle_patch: Vec<u32>,
    pub quads: Vec<[u32; 4]>,
    pub quad_patch: Vec<u32>,
}

impl BoundaryFaces {
    /// The nodes of the triangles, then of the quads, face by face (a node once per face).
    pub fn nodes(&self) -> impl Iterator<Item = u32> + '_ {
        self.triangles.iter().flatten().chain(self.quads.iter().flatten()).copied()
    }
}

/// A hybrid volume mesh.
#[derive(Clone, Debug)]
pub struct VolumeMesh {
    pub points: Vec<DVec3>,
    /// One block per kind, in [`CellKind::ALL`] order.
    pub blocks: [CellBlock; 4],
    pub zone_names: Vec<String>,
    pub boundary: BoundaryFaces,
    pub patch_names: Vec<String>,
}

impl Default for VolumeMesh {
    fn default() -> Self {
        VolumeMesh {
            points: Vec::new(),
            blocks: CellKind::ALL.map(CellBlock::new),
            zone_names: Vec::new(),
            boundary: BoundaryFaces::default(),
            patch_names: Vec::new(),
        }
    }
}

impl VolumeMesh {
    pub fn block(&self, kind: CellKind) -> &CellBlock {
        &self.blocks[kind as usize]
    }

    pub fn block_mut(&mut self, kind: CellKind) -> &mut CellBlock {
        &mut self.blocks[kind as usize]
    }

    pub fn push_cell(&mut self, kind: CellKind, nodes: &[u32], zone: u32) {
        self.block_mut(kind).push(nodes, zone);
    }

    pub fn cell_count(&self) -> usize {
        self.blocks.iter().map(CellBlock::len).sum()
    }

    /// Every cell as (kind, nodes), block by block.
    pub fn cells(&self) -> impl Iterator<Item = (CellKind, &[u32])> {
        self.blocks.iter().flat_map(|b| b.iter().map(move |c| (b.kind, c)))
    }

    /// Leave out the points no cell uses (solvers and converters count them as errors) and
    /// renumber the rest in their order; returns how many went.
    pub fn drop_unused_points(&mut self) -> usize {
        let mut used = vec![false; self.points.len()];
        for b in &self.blocks {
            for &n in &b.nodes {
                used[n as usize] = true;
            }
        }
        let (points, new_id) = compact_points(&self.points, &used);
        let dropped = self.points.len() - points.len();
        if dropped == 0 {
            return 0;
        }
        self.points = points;
        let renumber = |n: &mut u32| *n = new_id[*n as usize];
        self.blocks.iter_mut().for_each(|b| b.nodes.iter_mut().for_each(renumber));
        let faces = &mut self.boundary;
        faces.triangles.iter_mut().flatten().chain(faces.quads.iter_mut().flatten()).for_each(renumber);
        dropped
    }
}

/// The points with `used[i]`, in their order, and the new number of every old point
/// (`u32::MAX` for those left out).
pub fn compact_points(points: &[DVec3], used: &[bool]) -> (Vec<DVec3>, Vec<u32>) {
    let mut ids = vec![u32::MAX; points.len()];
    let mut kept = Vec::with_capacity(points.len());
    for (i, p) in points.iter().enumerate() {
        if used[i] {
            ids[i] = kept.len() as u32;
            kept.push(*p);
        }
    }
    (kept, ids)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unused_points_are_dropped_and_the_rest_renumbered() {
        let mut mesh = VolumeMesh::default();
        mesh.points = (0..6).map(|i| DVec3::splat(i as f64)).collect();
        mesh.push_cell(CellKind::Tetrahedron, &[1, 3, 4, 5], 0);
        mesh.boundary.triangles.push([1, 4, 3]);
        mesh.boundary.triangle_patch.push(0);
        assert_eq!(mesh.drop_unused_points(), 2);
        assert_eq!(mesh.points, [1.0, 3.0, 4.0, 5.0].map(DVec3::splat));
        assert_eq!(mesh.block(CellKind::Tetrahedron).cell(0), [0, 1, 2, 3]);
        assert_eq!(mesh.boundary.triangles, [[0, 2, 1]]);
        assert_eq!(mesh.drop_unused_points(), 0);
    }
}
