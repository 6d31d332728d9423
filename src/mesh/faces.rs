//! The face table: every distinct face of a volume mesh once, with its owner cell and what lies
//! across it (a neighbour cell or a boundary patch), the face-based view finite-volume solvers
//! and their mesh formats use.
//!
//! Cells are numbered globally ([`CellNumbering`]): block by block in [`CellKind::ALL`] order
//! (tetrahedra, pyramids, prisms, hexahedra), each block in its own order.
//!
//! A face shared by two cells is owned by the lower-numbered one and oriented out of it (owner <
//! neighbour, as OpenFOAM's polyMesh wants). A face of one cell is oriented out of that cell, and
//! its patch is the patch of the boundary face listed on the same nodes.
//!
//! Faces are matched by their sorted vertex sets ([`FaceUses`], shared with the checker's
//! conformity scan, so the mesh is sorted once).

use rayon::prelude::*;

use crate::mesh::{CellKind, VolumeMesh};

/// Global cell numbers: the cells of the blocks in [`CellKind::ALL`] order, one after the other.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CellNumbering {
    /// Global number of the first cell of each block, and the cell count at the end.
    starts: [usize; 5],
}

impl CellNumbering {
    pub fn new(mesh: &VolumeMesh) -> Self {
        let mut starts = [0; 5];
        for (i, kind) in CellKind::ALL.into_iter().enumerate() {
            starts[i + 1] = starts[i] + mesh.block(kind).nodes.len() / kind.node_count();
        }
        CellNumbering { starts }
    }

    pub fn cell_count(&self) -> usize {
        self.starts[4]
    }

    /// The global number of cell `index` of the block of `kind`.
    pub fn global(&self, kind: CellKind, index: usize) -> usize {
        self.starts[kind as usize] + index
    }

    /// The kind of global cell `cell` and its index in that kind's block.
    pub fn locate(&self, cell: usize) -> (CellKind, usize) {
        let k = (0..4).rfind(|&k| self.starts[k] <= cell).unwrap_or(0);
        (CellKind::ALL[k], cell - self.starts[k])
    }

    /// The nodes of global cell `cell`.
    pub fn nodes<'m>(&self, mesh: &'m VolumeMesh, cell: usize) -> &'m [u32] {
        let (kind, index) = self.locate(cell);
        let n = kind.node_count();
        &mesh.block(kind).nodes[index * n..(index + 1) * n]
    }
}

/// One use of an `N`-vertex face: by a cell (`owner` < cell count, its local face `local`) or by a
/// listed boundary face (`owner` = cell count + its index). `key` is the sorted vertex set.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) struct FaceUse<const N: usize> {
    pub key: [u32; N],
    pub owner: u32,
    pub local: u8,
}

pub(crate) fn sorted<const N: usize>(mut face: [u32; N]) -> [u32; N] {
    face.sort_unstable();
    face
}

/// Every use of every triangle and quad of the mesh (cell faces and listed boundary faces),
/// sorted: the uses of one vertex set are adjacent, cells before boundary faces.
pub(crate) struct FaceUses {
    pub numbering: CellNumbering,
    pub triangles: Vec<FaceUse<3>>,
    pub quads: Vec<FaceUse<4>>,
}

impl FaceUses {
    /// Owners are `u32`: the caller makes sure cells and boundary faces number less than 2^32.
    pub fn new(mesh: &VolumeMesh) -> Self {
        let numbering = CellNumbering::new(mesh);
        let b = &mesh.boundary;
        let (triangles, quads) =
            rayon::join(|| uses(mesh, &numbering, &b.triangles), || uses(mesh, &numbering, &b.quads));
        FaceUses { numbering, triangles, quads }
    }
}

fn uses<const N: usize>(
    mesh: &VolumeMesh,
    numbering: &CellNumbering,
    boundary: &[[u32; N]],
) -> Vec<FaceUse<N>> {
    let mut uses: Vec<FaceUse<N>> = Vec::new();
    for kind in CellKind::ALL {
        let start = numbering.global(kind, 0);
        let cells = mesh.block(kind).nodes.par_chunks_exact(kind.node_count());
        uses.par_extend(cells.enumerate().flat_map_iter(move |(i, cell)| {
            let owner = (start + i) as u32;
            let faces = kind.faces().iter().enumerate().filter(|(_, f)| f.len() == N);
            faces.map(move |(local, f)| FaceUse {
                key: sorted(std::array::from_fn(|j| cell[f[j]])),
                owner,
                local: local as u8,
            })
        }));
    }
    let first = numbering.cell_count();
    uses.extend(boundary.iter().enumerate().map(|(i, f)| FaceUse {
        key: sorted(*f),
        owner: (first + i) as u32,
        local: 0,
    }));
    uses.par_sort_unstable();
    uses
}

/// What lies across a face from its owner cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Across {
    /// An interior face: the neighbour cell's global number (greater than the owner's).
    Cell(u32),
    /// A boundary face of this patch (index into [`VolumeMesh::patch_names`]).
    Patch(u32),
    /// A face of one cell that no listed boundary face covers (a mesh that lists no boundary,
    /// or a hole), or a face used by three or more cells (listed once per cell).
    Free,
}

/// Every distinct face of a mesh once, in this order: interior faces by (owner, neighbour)
/// (OpenFOAM's upper-triangular order), then boundary faces by (patch, owner), then free faces
/// by owner. Interior faces are `0..interior_count()`.
#[derive(Clone, Debug, Default)]
pub struct FaceTable {
    /// Nodes of face `f`: `nodes[offsets[f]..offsets[f + 1]]`.
    offsets: Vec<usize>,
    nodes: Vec<u32>,
    owner: Vec<u32>,
    across: Vec<Across>,
    interior: usize,
}

/// A face before it is placed: its owner's local face, and across.
#[derive(Clone, Copy, Debug)]
struct Entry {
    owner: u32,
    local: u8,
    across: Across,
}

impl Entry {
    fn order(&self) -> (u8, u32, u32, u8) {
        match self.across {
            Across::Cell(n) => (0, self.owner, n, self.local),
            Across::Patch(p) => (1, p, self.owner, self.local),
            Across::Free => (2, 0, self.owner, self.local),
        }
    }
}

impl FaceTable {
    /// The face table of `mesh`, which must have fewer than 2^32 cells and boundary faces.
    pub fn new(mesh: &VolumeMesh) -> Self {
        Self::from_uses(mesh, &FaceUses::new(mesh))
    }

    pub(crate) fn from_uses(mesh: &VolumeMesh, uses: &FaceUses) -> Self {
        let cells = uses.numbering.cell_count();
        let b = &mesh.boundary;
        let mut entries: Vec<Entry> = entries_of(&uses.triangles, cells, &b.triangle_patch).collect();
        entries.extend(entries_of(&uses.quads, cells, &b.quad_patch));
        entries.par_sort_unstable_by_key(Entry::order);
        let faces: Vec<([u32; 4], usize)> = entries
            .par_iter()
            .map(|e| {
                let cell = uses.numbering.nodes(mesh, e.owner as usize);
                let (kind, _) = uses.numbering.locate(e.owner as usize);
                let local = kind.faces()[e.local as usize];
                let mut f = [0; 4];
                for (n, &l) in f.iter_mut().zip(local) {
                    *n = cell[l];
                }
                (f, local.len())
            })
            .collect();
        let mut table = FaceTable {
            offsets: Vec::with_capacity(faces.len() + 1),
            nodes: Vec::with_capacity(4 * faces.len()),
            owner: entries.iter().map(|e| e.owner).collect(),
            across: entries.iter().map(|e| e.across).collect(),
            interior: entries.iter().filter(|e| matches!(e.across, Across::Cell(_))).count(),
        };
        table.offsets.push(0);
        for (f, len) in faces {
            table.nodes.extend_from_slice(&f[..len]);
            table.offsets.push(table.nodes.len());
        }
        table
    }

    /// Number of faces.
    pub fn len(&self) -> usize {
        self.owner.len()
    }

    pub fn is_empty(&self) -> bool {
        self.owner.is_empty()
    }

    /// Interior faces come first: faces `0..interior_count()`.
    pub fn interior_count(&self) -> usize {
        self.interior
    }

    /// The nodes of face `f`, oriented out of its owner (right-hand normal).
    pub fn nodes(&self, f: usize) -> &[u32] {
        &self.nodes[self.offsets[f]..self.offsets[f + 1]]
    }

    /// The global number of the owner cell of face `f` ([`CellNumbering`]).
    pub fn owner(&self, f: usize) -> u32 {
        self.owner[f]
    }

    pub fn across(&self, f: usize) -> Across {
        self.across[f]
    }

    /// The neighbour cell of face `f`, if it is an interior face.
    pub fn neighbour(&self, f: usize) -> Option<u32> {
        match self.across[f] {
            Across::Cell(n) => Some(n),
            _ => None,
        }
    }
}

/// One entry per distinct face of the uses of one face size.
fn entries_of<'a, const N: usize>(
    uses: &'a [FaceUse<N>],
    cells: usize,
    patches: &'a [u32],
) -> impl Iterator<Item = Entry> + 'a {
    uses.chunk_by(|a, b| a.key == b.key).flat_map(move |group| {
        let split = group.partition_point(|u| (u.owner as usize) < cells);
        let (users, listed) = group.split_at(split);
        let patch = listed.first().and_then(|u| patches.get(u.owner as usize - cells)).copied();
        let entry = |u: &FaceUse<N>, across| Entry { owner: u.owner, local: u.local, across };
        let out: Vec<Entry> = match users {
            [] => Vec::new(),
            [one] => vec![entry(one, patch.map_or(Across::Free, Across::Patch))],
            [a, b] => vec![entry(a, Across::Cell(b.owner))],
            many => many.iter().map(|u| entry(u, Across::Free)).collect(),
        };
        out
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::DVec3;
    use crate::quality::samples::{cube_grid, hybrid_column, CubeSplit};

    /// The right-hand normal of a face, by Newell's sum.
    fn normal(mesh: &VolumeMesh, face: &[u32]) -> DVec3 {
        let p = |i: usize| mesh.points[face[i % face.len()] as usize];
        (0..face.len()).map(|i| p(i).cross(p(i + 1))).sum::<DVec3>()
    }

    fn cell_centre(mesh: &VolumeMesh, numbering: &CellNumbering, cell: u32) -> DVec3 {
        let nodes = numbering.nodes(mesh, cell as usize);
        nodes.iter().map(|&n| mesh.points[n as usize]).sum::<DVec3>() / nodes.len() as f64
    }

    #[test]
    fn every_face_once_oriented_out_of_its_owner_in_order() {
        let mesh = hybrid_column();
        let table = FaceTable::new(&mesh);
        let numbering = CellNumbering::new(&mesh);
        let b = &mesh.boundary;
        let boundary = b.triangles.len() + b.quads.len();
        let uses: usize = mesh.cells().map(|(k, _)| k.faces().len()).sum();
        assert_eq!(table.len() - table.interior_count(), boundary);
        assert_eq!(2 * table.interior_count() + boundary, uses);
        let mut previous = None;
        for f in 0..table.len() {
            let owner = table.owner(f);
            let face_centre = table.nodes(f).iter().map(|&n| mesh.points[n as usize]).sum::<DVec3>()
                / table.nodes(f).len() as f64;
            let outward = face_centre - cell_centre(&mesh, &numbering, owner);
            assert!(normal(&mesh, table.nodes(f)).dot(outward) > 0.0, "face {f} points into its owner");
            let order = Entry { owner, local: 0, across: table.across(f) }.order();
            assert!(previous.is_none_or(|p| p <= order), "face {f} out of order");
            previous = Some(order);
            match table.across(f) {
                Across::Cell(n) => assert!(f < table.interior_count() && n > owner),
                Across::Patch(p) => {
                    assert!(f >= table.interior_count() && (p as usize) < mesh.patch_names.len())
                }
                Across::Free => panic!("face {f} is free in a closed mesh"),
            }
        }
    }

    #[test]
    fn two_hexahedra_share_one_face_and_the_rest_are_patched() {
        let mesh = cube_grid([2, 1, 1], DVec3::ONE, &|_| CubeSplit::Hexahedron, &|_| 0);
        let table = FaceTable::new(&mesh);
        assert_eq!((table.len(), table.interior_count()), (11, 1));
        assert_eq!((table.owner(0), table.neighbour(0)), (0, Some(1)));
        let xmin = crate::quality::samples::SIDES.iter().position(|s| *s == "xmin").unwrap() as u32;
        assert_eq!(table.across(1), Across::Patch(xmin));
        assert_eq!(table.nodes(0).len(), 4);
    }

    #[test]
    fn without_listed_boundary_faces_the_outer_faces_are_free() {
        let mut mesh = cube_grid([1, 1, 1], DVec3::ONE, &|_| CubeSplit::Tetrahedra, &|_| 0);
        mesh.boundary = Default::default();
        let table = FaceTable::new(&mesh);
        assert_eq!((table.len(), table.interior_count()), (18, 6));
        assert!((6..18).all(|f| table.across(f) == Across::Free));
        let numbering = CellNumbering::new(&mesh);
        assert_eq!(numbering.locate(5), (CellKind::Tetrahedron, 5));
        assert_eq!(numbering.global(CellKind::Tetrahedron, 5), 5);
    }
}
