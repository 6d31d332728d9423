//! The cell between a front face and the same face one layer up, built "face first".
//!
//! A front face is a triangle or quad of columns. Each column gives a bottom node (where it is)
//! and a top node (where it goes; the same node when the column has stopped). The cell's faces
//! are the bottom polygon, the top polygon and one lateral polygon per face edge, each with its
//! repeated nodes removed: a lateral quad `(b_i, b_i+1, t_i+1, t_i)` becomes a triangle when a
//! column stopped (`t = b`), two columns merged (`t_i = t_i+1`) or two fan copies share a wall
//! node (`b_i = b_i+1`), and vanishes when two of these happen. Every face depends only on its own
//! nodes, so the two cells sharing a face always agree on it: the slab is conforming by
//! construction.
//!
//! A column that merged into another this slab (a collapse: its top is the survivor's top) makes
//! the lateral quads beside it twisted: their top edge runs towards the survivor, away from the
//! bottom edge. Such a quad is cut into two triangles along the diagonal from the merged
//! column's bottom node (when both merged, the caller picks one from the edge's two columns, see
//! [`Merging`]), so both cells agree. The cell over a front triangle with a merged column
//! is then a cone from that column's bottom node: no new point (the exact entropy picture: the
//! merged characteristic ends there).
//!
//! The cell is then emitted as the standard shape its faces make (prism, pyramid, tetrahedron,
//! hexahedron) or, for any other polyhedron, split from an apex (a merged column's bottom node,
//! or else a new centre point) into one tetrahedron per triangle face and one pyramid per quad
//! face not touching the apex (quads are never cut but for the twisted ones above).

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

    /// Whether `other` is this polygon with the opposite orientation.
    pub fn is_reverse_of(&self, other: &Polygon) -> bool {
        self.same_cycle(&other.reversed())
    }

    /// The same nodes in the same cyclic order (whatever the first one).
    pub fn same_cycle(&self, other: &Polygon) -> bool {
        let (a, b) = (self.nodes(), other.nodes());
        a.len() == b.len() && (0..b.len()).any(|shift| (0..a.len()).all(|i| a[i] == b[(i + shift) % b.len()]))
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
    /// A polyhedron to split into pieces from an apex: its outward faces, and the apex node
    /// (`None`: a new point at the centre of its nodes).
    Split { faces: Vec<Polygon>, apex: Option<u32> },
}

/// Which columns of a slab cell merged into another column this slab (bit `i`: column `i`), and
/// which twisted lateral faces are cut (bit `i` of `cut`: the quad over edge `(i, i + 1)`, from
/// column `i`'s bottom node if bit `i` of `cut_from_first` is set, else from column `i + 1`'s).
/// The caller decides the cuts from the edge's two columns only, so both cells sharing a lateral
/// face cut it alike.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Merging {
    pub merged: u8,
    pub cut: u8,
    pub cut_from_first: u8,
}

impl Merging {
    /// How the lateral face over edge `(i, i + 1)` is cut: `None` not at all, `Some(true)` from
    /// column `i`'s bottom, `Some(false)` from column `i + 1`'s.
    pub fn cut_of(&self, i: usize) -> Option<bool> {
        (self.cut & (1 << i) != 0).then_some(self.cut_from_first & (1 << i) != 0)
    }
}

/// The outward faces of the cell over a front face with `bottom` and `top` node ids
/// (the front face `bottom` is oriented with its right-hand normal pointing up, into the fluid).
/// Faces that come twice with opposite orientations (halves of cut quads lying on each other)
/// are left out: they enclose nothing.
pub fn slab_faces(bottom: &[u32], top: &[u32], merging: Merging) -> Vec<Polygon> {
    let n = bottom.len();
    let mut faces = Vec::with_capacity(n + 4);
    let reversed_bottom: Vec<u32> = bottom.iter().rev().copied().collect();
    faces.extend(Polygon::dedup(&reversed_bottom));
    faces.extend(Polygon::dedup(top));
    for i in 0..n {
        let j = (i + 1) % n;
        push_lateral(&mut faces, [bottom[i], bottom[j], top[j], top[i]], merging.cut_of(i));
    }
    remove_opposite_pairs(&mut faces);
    faces
}

/// The lateral face `(b_i, b_j, t_j, t_i)` over a front edge; a twisted quad (`cut` given) is cut
/// along the diagonal from `b_i` (`Some(true)`) or `b_j` (`Some(false)`).
pub fn push_lateral(faces: &mut Vec<Polygon>, quad: [u32; 4], cut: Option<bool>) {
    let Some(face) = Polygon::dedup(&quad) else { return };
    let (true, Some(from_i)) = (face.is_quad(), cut) else {
        faces.push(face);
        return;
    };
    let [bi, bj, tj, ti] = quad;
    let halves = if from_i { [[bi, bj, tj], [bi, tj, ti]] } else { [[bi, bj, ti], [bj, tj, ti]] };
    faces.extend(halves.iter().filter_map(|t| Polygon::dedup(t)));
}

/// Remove every pair of faces that are the same polygon with opposite orientations.
pub fn remove_opposite_pairs(faces: &mut Vec<Polygon>) {
    let mut i = 0;
    while i < faces.len() {
        match (i + 1..faces.len()).find(|&j| faces[j].is_reverse_of(&faces[i])) {
            Some(j) => {
                faces.remove(j);
                faces.remove(i);
            }
            None => i += 1,
        }
    }
}

/// Whether the outward `faces` close a polyhedron: every directed edge once, and its reverse
/// once.
pub fn is_closed(faces: &[Polygon]) -> bool {
    let mut edges: Vec<(u32, u32)> = faces.iter().flat_map(|f| f.edges()).collect();
    edges.sort_unstable();
    let unique = edges.windows(2).all(|w| w[0] != w[1]);
    unique && edges.iter().all(|&(a, b)| edges.binary_search(&(b, a)).is_ok())
}

/// Decide the cell over a front face (see module docs).
pub fn slab_cell(bottom: &[u32], top: &[u32], merging: Merging) -> SlabCell {
    if bottom == top {
        return SlabCell::Empty;
    }
    let merged = merging.merged;
    if merging.cut == 0 {
        if let Some(cell) = intact_column_cell(bottom, top) {
            return cell;
        }
    }
    let faces = slab_faces(bottom, top, merging);
    if merged != 0 {
        if faces.len() < 4 {
            return SlabCell::Flat;
        }
        return SlabCell::Split { apex: cone_apex(&faces, bottom, merged), faces };
    }
    cell_from_faces(faces)
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
        None => SlabCell::Split { faces, apex: None },
    }
}

/// The apex of a cell with merged columns: the bottom node of a merged column through which
/// every face is a triangle (a quad through the apex would have to be cut, and its other cell
/// keeps it whole), and of those the one on the most faces: it leaves the fewest pieces, and the
/// halves of a quad cut from it lie on it (ties: the smaller node). `None` if there is none.
fn cone_apex(faces: &[Polygon], bottom: &[u32], merged: u8) -> Option<u32> {
    (0..bottom.len())
        .filter(|&i| merged & (1 << i) != 0)
        .map(|i| bottom[i])
        .filter(|&apex| faces.iter().all(|f| !(f.is_quad() && f.contains(apex))))
        .map(|apex| (faces.iter().filter(|f| f.contains(apex)).count(), std::cmp::Reverse(apex)))
        .max()
        .map(|(_, std::cmp::Reverse(apex))| apex)
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
        match slab_cell(bottom, top, Merging::default()) {
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
        assert_eq!(slab_cell(&[0, 1, 2], &[0, 1, 2], Merging::default()), SlabCell::Empty);
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
        match slab_cell(&[0, 1, 2], &[8, 9, 9], Merging::default()) {
            SlabCell::Split { faces, apex: None } => {
                assert_eq!(faces.iter().filter(|f| f.is_quad()).count(), 2);
            }
            other => panic!("{other:?}"),
        }
    }

    /// Column 2 of face (0, 1, 2) merged into column 1 (tops 10, 11, 11); the lateral over
    /// (2, 0) is cut from node 2.
    fn merged_face() -> (Vec<Polygon>, SlabCell) {
        let merging = Merging { merged: 0b100, cut: 0b110, cut_from_first: 0b100 };
        (slab_faces(&[0, 1, 2], &[10, 11, 11], merging), slab_cell(&[0, 1, 2], &[10, 11, 11], merging))
    }

    #[test]
    fn a_merged_column_is_the_apex_of_its_cell() {
        let (_, cell) = merged_face();
        let SlabCell::Split { faces, apex: Some(2) } = cell else { panic!("{cell:?}") };
        let pieces: Vec<&Polygon> = faces.iter().filter(|f| !f.contains(2)).collect();
        assert_eq!(pieces.len(), 1, "{faces:?}");
        assert!(pieces[0].same_cycle(&Polygon::dedup(&[0, 1, 11, 10]).unwrap()), "{pieces:?}");
    }

    #[test]
    fn both_cells_cut_a_twisted_quad_alike() {
        let (faces_a, _) = merged_face();
        // Face (0, 2, 4) shares the edge (2, 0); its lateral over (0, 2) is cut from node 2 too.
        let merging = Merging { merged: 0b010, cut: 0b011, cut_from_first: 0b010 };
        let faces_c = slab_faces(&[0, 2, 4], &[10, 11, 14], merging);
        for half in [[0, 2, 10], [2, 11, 10]] {
            let half = Polygon::dedup(&half).unwrap();
            assert!(faces_c.iter().any(|f| f.same_cycle(&half)), "{faces_c:?}");
            assert!(faces_a.iter().any(|f| f.same_cycle(&half.reversed())), "{faces_a:?}");
        }
    }

    #[test]
    fn a_cell_is_closed_by_all_its_faces_and_open_without_one() {
        let faces = slab_faces(&[0, 1, 2], &[3, 4, 5], Merging::default());
        assert!(is_closed(&faces));
        assert!(!is_closed(&faces[1..]));
        let mut twice = faces.clone();
        twice.extend(faces);
        assert!(!is_closed(&twice), "a face twice");
    }

    #[test]
    fn opposite_faces_cancel() {
        let mut faces: Vec<Polygon> =
            [[1, 2, 3], [2, 1, 3], [3, 2, 1], [1, 4, 5]].iter().map(|t| Polygon::dedup(t).unwrap()).collect();
        remove_opposite_pairs(&mut faces);
        let left: Vec<&[u32]> = faces.iter().map(|f| f.nodes()).collect();
        assert_eq!(left, vec![&[3, 2, 1][..], &[1, 4, 5][..]]);
    }
}
