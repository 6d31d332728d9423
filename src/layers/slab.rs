//! The cell between a front face and the same face one layer up, built "face first".
//!
//! A front face is a triangle or quad of columns. Each column gives a bottom node (where it is)
//! and a top node (where it goes; the same node when the column has stopped). The cell's faces
//! are the bottom polygon, the top polygon and one lateral polygon per face edge, each with its
//! repeated nodes removed: a lateral quad `(b_i, b_i+1, t_i+1, t_i)` becomes a triangle when a
//! column stopped (`t = b`), two columns merged (`t_i = t_i+1`) or two fan copies share a wall
//! node (`b_i = b_i+1`), and vanishes when two of these happen. Every face depends only on its own
//! nodes, so the two cells sharing a face always agree on it: the slab is conforming by
//! construction (DESIGN.md, "Staying conforming").
//!
//! The cell is then emitted as the standard shape its faces make (prism, pyramid, tetrahedron,
//! hexahedron) or, for any other polyhedron, split from its centroid into one tetrahedron per
//! triangle face and one pyramid per quad face (quads are never cut).

use crate::mesh::CellKind;

/// A polygon face of a slab cell: 3 or 4 mesh node ids, oriented out of the cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Polygon {
    nodes: [u32; 4],
    len: u8,
}

impl Polygon {
    /// The polygon through `nodes` with cyclically repeated nodes removed; `None` when fewer
    /// than 3 distinct nodes are left (the face has collapsed to an edge or a point).
    pub fn dedup(nodes: &[u32]) -> Option<Polygon> {
        let mut out = [0u32; 4];
        let mut len = 0usize;
        for &n in nodes {
            if len == 0 || out[len - 1] != n {
                out[len] = n;
                len += 1;
            }
        }
        while len > 1 && out[len - 1] == out[0] {
            len -= 1;
        }
        (len >= 3).then_some(Polygon { nodes: out, len: len as u8 })
    }

    pub fn nodes(&self) -> &[u32] {
        &self.nodes[..self.len as usize]
    }

    pub fn is_quad(&self) -> bool {
        self.len == 4
    }

    fn reversed(&self) -> Polygon {
        let mut p = *self;
        p.nodes[..self.len as usize].reverse();
        p
    }

    fn contains(&self, n: u32) -> bool {
        self.nodes().contains(&n)
    }

    /// Directed edges (a, b) of the polygon.
    fn edges(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        let n = self.nodes();
        (0..n.len()).map(move |i| (n[i], n[(i + 1) % n.len()]))
    }
}

/// What to emit for one slab cell.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SlabCell {
    /// Nothing: every column of the face has stopped.
    Empty,
    /// Some columns moved but the faces enclose no volume (e.g. a fan triangle at the wall with
    /// one column stopped: its top lies on its own lateral face). Never emitted: the march
    /// treats it as invalid and stops the face's other columns too.
    Flat,
    /// One standard cell in Gmsh node order (the first `kind.node_count()` of `nodes`).
    Standard { kind: CellKind, nodes: [u32; 8] },
    /// A polyhedron to split from a new centre point: its outward faces.
    Split { faces: Vec<Polygon> },
}

/// The outward faces of the cell over a front face with `bottom` and `top` node ids
/// (the front face `bottom` is oriented with its right-hand normal pointing up, into the fluid).
pub fn slab_faces(bottom: &[u32], top: &[u32]) -> Vec<Polygon> {
    let n = bottom.len();
    let mut faces = Vec::with_capacity(n + 2);
    let reversed_bottom: Vec<u32> = bottom.iter().rev().copied().collect();
    faces.extend(Polygon::dedup(&reversed_bottom));
    faces.extend(Polygon::dedup(top));
    for i in 0..n {
        let j = (i + 1) % n;
        faces.extend(Polygon::dedup(&[bottom[i], bottom[j], top[j], top[i]]));
    }
    faces
}

/// Decide the cell over a front face (see module docs).
pub fn slab_cell(bottom: &[u32], top: &[u32]) -> SlabCell {
    if bottom == top {
        return SlabCell::Empty;
    }
    if let Some(cell) = intact_column_cell(bottom, top) {
        return cell;
    }
    cell_from_faces(slab_faces(bottom, top))
}

/// The cell enclosed by `faces` (outward polygons): the standard shape they make, a polyhedron
/// to split from its centre, or flat when they enclose no volume.
pub fn cell_from_faces(faces: Vec<Polygon>) -> SlabCell {
    let mut distinct: Vec<u32> = faces.iter().flat_map(|f| f.nodes().iter().copied()).collect();
    distinct.sort_unstable();
    distinct.dedup();
    if faces.len() < 4 || distinct.len() < 4 {
        return SlabCell::Flat;
    }
    let quads = faces.iter().filter(|f| f.is_quad()).count();
    let tris = faces.len() - quads;
    let standard = match (distinct.len(), tris, quads) {
        (4, 4, 0) => tetrahedron(&faces),
        (5, 4, 1) => pyramid(&faces, &distinct),
        (6, 2, 3) => prism(&faces),
        (8, 0, 6) => hexahedron(&faces),
        _ => None,
    };
    match standard {
        Some((kind, nodes)) => standard_cell(kind, &nodes),
        None => SlabCell::Split { faces },
    }
}

fn standard_cell(kind: CellKind, nodes: &[u32]) -> SlabCell {
    let mut n = [0; 8];
    n[..nodes.len()].copy_from_slice(nodes);
    SlabCell::Standard { kind, nodes: n }
}

/// The common case without building faces: every column moves to a new node and the bottom
/// has distinct nodes, so the cell is the prism (or hexahedron) over the face.
fn intact_column_cell(bottom: &[u32], top: &[u32]) -> Option<SlabCell> {
    let n = bottom.len();
    let distinct = |x: &[u32]| (0..n).all(|i| (i + 1..n).all(|j| x[i] != x[j]));
    let moved = (0..n).all(|i| !bottom.contains(&top[i]));
    if !(moved && distinct(bottom) && distinct(top)) {
        return None;
    }
    let kind = if n == 3 { CellKind::Prism } else { CellKind::Hexahedron };
    let mut nodes = [0; 8];
    nodes[..n].copy_from_slice(bottom);
    nodes[n..2 * n].copy_from_slice(top);
    Some(SlabCell::Standard { kind, nodes })
}

fn tetrahedron(faces: &[Polygon]) -> Option<(CellKind, Vec<u32>)> {
    let base = faces[0].reversed();
    let apex = faces.iter().flat_map(|f| f.nodes()).find(|&&n| !base.contains(n))?;
    Some((CellKind::Tetrahedron, vec![base.nodes[0], base.nodes[1], base.nodes[2], *apex]))
}

fn pyramid(faces: &[Polygon], distinct: &[u32]) -> Option<(CellKind, Vec<u32>)> {
    let base = faces.iter().find(|f| f.is_quad())?.reversed();
    let apex = distinct.iter().find(|&&n| !base.contains(n))?;
    let mut nodes = base.nodes().to_vec();
    nodes.push(*apex);
    Some((CellKind::Pyramid, nodes))
}

/// Prism or hexahedron: the bottom is one end face reversed; the top nodes are the partners of
/// the bottom nodes along the lateral quads' edges.
fn extruded(faces: &[Polygon], end_len: usize, kind: CellKind) -> Option<(CellKind, Vec<u32>)> {
    let bottom_end = faces.iter().find(|f| f.len as usize == end_len)?;
    let top_end = faces
        .iter()
        .find(|f| f.len as usize == end_len && f.nodes().iter().all(|&n| !bottom_end.contains(n)))?;
    let bottom = bottom_end.reversed();
    let mut nodes = bottom.nodes().to_vec();
    for &b in bottom.nodes() {
        let partner =
            faces.iter().filter(|f| f.is_quad() && f.contains(b)).flat_map(|f| f.edges()).find_map(
                |(x, y)| match (x == b, y == b) {
                    (true, false) if top_end.contains(y) => Some(y),
                    (false, true) if top_end.contains(x) => Some(x),
                    _ => None,
                },
            )?;
        nodes.push(partner);
    }
    let mut tops = nodes[end_len..].to_vec();
    tops.sort_unstable();
    tops.dedup();
    (tops.len() == end_len).then_some((kind, nodes))
}

fn prism(faces: &[Polygon]) -> Option<(CellKind, Vec<u32>)> {
    extruded(faces, 3, CellKind::Prism)
}

fn hexahedron(faces: &[Polygon]) -> Option<(CellKind, Vec<u32>)> {
    extruded(faces, 4, CellKind::Hexahedron)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn standard(bottom: &[u32], top: &[u32]) -> (CellKind, Vec<u32>) {
        match slab_cell(bottom, top) {
            SlabCell::Standard { kind, nodes } => (kind, nodes[..kind.node_count()].to_vec()),
            other => panic!("expected a standard cell, got {other:?}"),
        }
    }

    #[test]
    fn dedup_removes_cyclic_repeats() {
        assert_eq!(Polygon::dedup(&[1, 1, 2, 3]).unwrap().nodes(), &[1, 2, 3]);
        assert_eq!(Polygon::dedup(&[1, 2, 3, 1]).unwrap().nodes(), &[1, 2, 3]);
        assert!(Polygon::dedup(&[1, 1, 2, 2]).is_none());
        assert!(Polygon::dedup(&[5, 5, 5]).is_none());
    }

    #[test]
    fn intact_columns_give_a_prism() {
        assert_eq!(standard(&[0, 1, 2], &[3, 4, 5]), (CellKind::Prism, vec![0, 1, 2, 3, 4, 5]));
    }

    #[test]
    fn one_stopped_column_gives_a_pyramid_with_the_live_quad_as_base() {
        let (kind, nodes) = standard(&[0, 1, 2], &[0, 4, 5]);
        assert_eq!(kind, CellKind::Pyramid);
        assert_eq!(nodes[4], 0, "the stopped column is the apex");
        let mut base = nodes[..4].to_vec();
        base.sort_unstable();
        assert_eq!(base, vec![1, 2, 4, 5]);
    }

    #[test]
    fn two_stopped_columns_give_a_tetrahedron() {
        let (kind, nodes) = standard(&[0, 1, 2], &[0, 1, 5]);
        assert_eq!(kind, CellKind::Tetrahedron);
        assert_eq!(nodes, vec![0, 1, 2, 5]);
    }

    #[test]
    fn all_stopped_gives_nothing() {
        assert_eq!(slab_cell(&[0, 1, 2], &[0, 1, 2]), SlabCell::Empty);
    }

    #[test]
    fn fan_strip_quad_gives_a_prism_on_its_side() {
        // Ridge edge (v=0, w=1); fan copies v_i, v_i+1 share node 0, w_i, w_i+1 share node 1.
        let (kind, nodes) = standard(&[0, 1, 1, 0], &[10, 11, 12, 13]);
        assert_eq!(kind, CellKind::Prism);
        let mut ends = [nodes[..3].to_vec(), nodes[3..].to_vec()];
        ends.iter_mut().for_each(|e| e.sort_unstable());
        assert!(ends.contains(&vec![0, 10, 13]) && ends.contains(&vec![1, 11, 12]), "{nodes:?}");
    }

    #[test]
    fn fan_corner_triangle_gives_a_tetrahedron() {
        let (kind, nodes) = standard(&[0, 0, 0], &[1, 2, 3]);
        assert_eq!(
            (kind, nodes),
            (CellKind::Tetrahedron, vec![3, 2, 1, 0]),
            "top reversed, wall node as apex"
        );
    }

    #[test]
    fn quad_front_face_gives_a_hexahedron() {
        let (kind, nodes) = standard(&[0, 1, 2, 3], &[4, 5, 6, 7]);
        assert_eq!((kind, nodes), (CellKind::Hexahedron, vec![0, 1, 2, 3, 4, 5, 6, 7]));
    }

    #[test]
    fn merged_top_with_two_quads_is_split() {
        // Columns 1 and 2 merge into node 9: faces are 2 quads and 3 triangles on 5 nodes.
        match slab_cell(&[0, 1, 2], &[8, 9, 9]) {
            SlabCell::Split { faces } => {
                assert_eq!(faces.iter().filter(|f| f.is_quad()).count(), 2);
            }
            other => panic!("{other:?}"),
        }
    }
}
