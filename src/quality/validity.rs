//! Validity of every cell by exact orientation tests, and the per-cell measures, block by block.
//!
//! A cell is valid when every tetrahedron of two decompositions is positive by the exact
//! [`orient3d`]: its corner tetrahedra (each corner with its three edge neighbours, see
//! [`CellKind::corners`]) and its standard decomposition ([`for_each_subtet`]). The centroid and
//! quad centres are rounded floats; the predicate is exact on those rounded points.

use rayon::prelude::*;

use super::measures::{
    dihedral_range, edge_face_pairs, for_each_subtet, scaled_jacobian, volume, CellPoints,
};
use super::report::{CellRef, InvalidCell, KindQuality, Validity, EXAMPLES};
use crate::geometry::predicates::{BoxedOrient3d, Sign};
use crate::geometry::DVec3;
use crate::mesh::{CellKind, VolumeMesh};

/// The first non-positive tetrahedron of each decomposition, if any.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CellValidity {
    /// (corner index, sign) of the first corner tetrahedron that is not positive.
    pub bad_corner: Option<(usize, Sign)>,
    /// (local face, sign) of the first tetrahedron of the standard decomposition not positive.
    pub bad_subtet: Option<(usize, Sign)>,
}

impl CellValidity {
    pub fn is_valid(&self) -> bool {
        self.bad_corner.is_none() && self.bad_subtet.is_none()
    }
}

/// Exact validity of one cell.
pub fn cell_validity(kind: CellKind, x: &CellPoints) -> CellValidity {
    // Centroid and quad centres lie in the box of the corners (up to rounding, which the
    // filter's padding covers).
    let orient3d = BoxedOrient3d::new(&x[..kind.node_count()]);
    let orient3d = |a, b, c, d| orient3d.orient3d(a, b, c, d);
    let bad_corner = kind.corners().iter().enumerate().find_map(|(i, &[o, a, b, d])| {
        let s = orient3d(x[o], x[a], x[b], x[d]);
        (s != Sign::Positive).then_some((i, s))
    });
    let mut bad_subtet = None;
    for_each_subtet(kind, x, |face, [a, b, c, d]| {
        if bad_subtet.is_none() {
            let s = orient3d(a, b, c, d);
            if s != Sign::Positive {
                bad_subtet = Some((face, s));
            }
        }
    });
    CellValidity { bad_corner, bad_subtet }
}

/// The points of a cell, or `None` when a node index is out of range.
pub fn gather(points: &[DVec3], nodes: &[u32]) -> Option<CellPoints> {
    let mut x = [DVec3::ZERO; 8];
    for (xi, &n) in x.iter_mut().zip(nodes) {
        *xi = *points.get(n as usize)?;
    }
    Some(x)
}

/// What the pass over one block found.
#[derive(Clone, Debug, Default)]
pub struct BlockResult {
    pub validity: Validity,
    pub volume: f64,
    pub quality: KindQuality,
}

impl BlockResult {
    /// Append the result of the cells that follow (keeps the first examples).
    fn append(&mut self, other: BlockResult) {
        self.validity.append(other.validity);
        self.volume += other.volume;
        self.quality.merge(&other.quality);
    }
}

/// Cells per parallel task; the chunks are summed in order so the result is deterministic.
const CHUNK: usize = 4096;

/// Validity, volume and quality of every cell of one block.
pub fn check_block(mesh: &VolumeMesh, kind: CellKind) -> BlockResult {
    let n = kind.node_count();
    let nodes = &mesh.block(kind).nodes;
    let pairs = edge_face_pairs(kind);
    let parts: Vec<BlockResult> = nodes
        .par_chunks(CHUNK * n)
        .enumerate()
        .map(|(chunk, cells)| {
            let mut part = BlockResult::default();
            for (i, cell) in cells.chunks_exact(n).enumerate() {
                check_cell(mesh, CellRef { kind, index: chunk * CHUNK + i }, cell, &pairs, &mut part);
            }
            part
        })
        .collect();
    let mut result = BlockResult::default();
    for part in parts {
        result.append(part);
    }
    result
}

fn check_cell(
    mesh: &VolumeMesh,
    cell: CellRef,
    nodes: &[u32],
    pairs: &[(usize, usize)],
    out: &mut BlockResult,
) {
    let kind = cell.kind;
    let Some(x) = gather(&mesh.points, nodes) else {
        let v = &mut out.validity;
        v.invalid_cells += 1;
        v.nodes_out_of_range += 1;
        if v.examples.len() < EXAMPLES {
            v.examples.push(InvalidCell::new(cell, nodes, &[], "node index out of range".into()));
        }
        return;
    };
    let validity = cell_validity(kind, &x);
    if !validity.is_valid() {
        let v = &mut out.validity;
        v.invalid_cells += 1;
        v.inverted_corners += usize::from(validity.bad_corner.is_some());
        v.nonpositive_decomposition += usize::from(validity.bad_subtet.is_some());
        if v.examples.len() < EXAMPLES {
            let problem = describe(kind, &validity);
            v.examples.push(InvalidCell::new(cell, nodes, &x[..kind.node_count()], problem));
        }
    }
    out.volume += volume(kind, &x);
    out.quality.add(scaled_jacobian(kind, &x), dihedral_range(kind, &x, pairs));
}

fn describe(kind: CellKind, v: &CellValidity) -> String {
    let sign = |s: Sign| if s == Sign::Zero { "flat" } else { "negative" };
    let mut parts = Vec::new();
    if let Some((c, s)) = v.bad_corner {
        parts.push(format!("corner tetrahedron at node {} is {}", kind.corners()[c][0], sign(s)));
    }
    if let Some((f, s)) = v.bad_subtet {
        parts.push(format!("decomposition tetrahedron on face {:?} is {}", kind.faces()[f], sign(s)));
    }
    parts.join("; ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn points(p: &[[f64; 3]]) -> CellPoints {
        let mut x = [DVec3::ZERO; 8];
        for (xi, q) in x.iter_mut().zip(p) {
            *xi = DVec3::from_array(*q);
        }
        x
    }

    #[test]
    fn unit_tet_is_valid_and_its_mirror_is_not() {
        let x = points(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
        assert!(cell_validity(CellKind::Tetrahedron, &x).is_valid());
        let m = points(&[[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]);
        let v = cell_validity(CellKind::Tetrahedron, &m);
        assert_eq!(v.bad_corner, Some((0, Sign::Negative)));
        assert_eq!(v.bad_subtet, Some((0, Sign::Negative)));
    }

    #[test]
    fn flat_tet_is_invalid_exactly() {
        // (0.1, 0.2, 0) lies exactly in the plane z = 0 even though 0.1 and 0.2 are inexact.
        let x = points(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.1, 0.2, 0.0]]);
        assert_eq!(cell_validity(CellKind::Tetrahedron, &x).bad_corner, Some((0, Sign::Zero)));
    }

    #[test]
    fn pyramid_with_a_dart_base_fails_at_its_reflex_corner() {
        let mut p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.5, 0.5, 1.0]];
        assert!(cell_validity(CellKind::Pyramid, &points(&p)).is_valid());
        p[2] = [0.3, 0.3, 0.0];
        let v = cell_validity(CellKind::Pyramid, &points(&p));
        assert_eq!(v.bad_corner, Some((2, Sign::Negative)));
    }

    #[test]
    fn out_of_range_node_has_no_points() {
        assert!(gather(&[DVec3::ZERO], &[0, 1]).is_none());
    }
}
