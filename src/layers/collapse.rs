//! Front edge collapse: two columns merge into one at the new front.
//!
//! The operator behind both the entropy collapse at concave ridges and corners (fronts meeting on
//! a bisector) and the tangential collapse of short edges. During a slab, merges are only
//! recorded (`root`): the bottom of every column stays where it is, and the merged columns share
//! the survivor's top node; [`super::front::Front::apply_merges`] rewrites the front after the
//! slab is emitted. A collapse is allowed only where it keeps the front a manifold surface (the
//! link condition), evaluated on the front as it will be with the merges already recorded.

use super::front::Front;
use super::slab::Polygon;

/// The merges recorded during one slab.
#[derive(Clone, Debug)]
pub struct Merges {
    /// The column each column's top goes to (itself when not merged).
    root: Vec<u32>,
    /// For each survivor, the columns merged into it (not including itself).
    members: Vec<Vec<u32>>,
}

impl Merges {
    pub fn new(columns: usize) -> Self {
        Merges { root: (0..columns as u32).collect(), members: vec![Vec::new(); columns] }
    }

    pub fn root(&self, c: u32) -> u32 {
        self.root[c as usize]
    }

    pub fn roots(&self) -> &[u32] {
        &self.root
    }

    pub fn is_merged(&self, c: u32) -> bool {
        self.root[c as usize] != c
    }

    /// `c` and every column merged into it.
    pub fn group(&self, c: u32) -> impl Iterator<Item = u32> + '_ {
        std::iter::once(c).chain(self.members[c as usize].iter().copied())
    }

    /// Record that `victim` (a root) now goes where `survivor` (a root) goes.
    pub fn merge(&mut self, survivor: u32, victim: u32) {
        let moved = std::mem::take(&mut self.members[victim as usize]);
        for &m in &moved {
            self.root[m as usize] = survivor;
        }
        self.root[victim as usize] = survivor;
        let group = &mut self.members[survivor as usize];
        group.push(victim);
        group.extend(moved);
    }

    /// The groups of roots `a` and `b` as they are, for [`Merges::restore_groups`].
    pub fn clone_groups(&self, a: u32, b: u32) -> [(u32, Vec<u32>); 2] {
        [a, b].map(|r| (r, self.members[r as usize].clone()))
    }

    /// Put the groups saved by [`Merges::clone_groups`] back (undoing a merge between them).
    pub fn restore_groups(&mut self, groups: [(u32, Vec<u32>); 2]) {
        for (r, members) in groups {
            self.root[r as usize] = r;
            for &m in &members {
                self.root[m as usize] = r;
            }
            self.members[r as usize] = members;
        }
    }

    /// Undo every merge into `survivor`; returns the columns released (each its own root again).
    pub fn release(&mut self, survivor: u32) -> Vec<u32> {
        let released = std::mem::take(&mut self.members[survivor as usize]);
        for &m in &released {
            self.root[m as usize] = m;
        }
        released
    }

    /// Take column `c` out of the group it merged into (it is its own root again; the columns
    /// merged into it before stay with the group's root). `false` when `c` is a root.
    pub fn detach(&mut self, c: u32) -> bool {
        let r = self.root[c as usize];
        if r == c {
            return false;
        }
        self.members[r as usize].retain(|&m| m != c);
        self.root[c as usize] = c;
        true
    }

    /// The distinct roots of face `f`'s columns, sorted (two or one where the face is down to an
    /// edge or a point).
    pub fn face_roots(&self, front: &Front, f: usize) -> Vec<u32> {
        let mut roots: Vec<u32> = front.face_columns(f).iter().map(|&c| self.root(c)).collect();
        roots.sort_unstable();
        roots.dedup();
        roots
    }

    /// Face `f` with every column replaced by its root, repeated columns removed.
    pub fn resolved_face(&self, front: &Front, f: usize) -> Option<Polygon> {
        let cols: Vec<u32> = front.face_columns(f).iter().map(|&c| self.root(c)).collect();
        Polygon::dedup(&cols)
    }

    /// The faces of root `x`'s group, resolved, each once.
    fn faces_around(&self, front: &Front, x: u32) -> Vec<usize> {
        let mut faces: Vec<usize> = self.group(x).flat_map(|c| front.faces_of(c)).collect();
        faces.sort_unstable();
        faces.dedup();
        faces
    }

    /// Roots adjacent to root `x` along front edges (after the recorded merges).
    fn neighbours(&self, front: &Front, x: u32) -> Vec<u32> {
        let mut out = Vec::new();
        for f in self.faces_around(front, x) {
            let Some(p) = self.resolved_face(front, f) else { continue };
            let n = p.nodes();
            for i in 0..n.len() {
                if n[i] == x {
                    out.push(n[(i + 1) % n.len()]);
                    out.push(n[(i + n.len() - 1) % n.len()]);
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Can roots `a` and `b` merge without making the front non-manifold? Their edge must be
    /// shared by exactly two faces (triangles, which vanish, or quads, which become triangles),
    /// no other face may hold both, and their only common neighbours must be the third vertices
    /// of those triangles (the link condition).
    pub fn can_collapse(&self, front: &Front, a: u32, b: u32) -> bool {
        if a == b || self.is_merged(a) || self.is_merged(b) {
            return false;
        }
        let mut faces_on_edge = 0;
        let mut opposite = Vec::new();
        for f in self.faces_around(front, a) {
            let Some(p) = self.resolved_face(front, f) else { continue };
            let n = p.nodes();
            let Some(i) = n.iter().position(|&x| x == a) else { continue };
            if !n.contains(&b) {
                continue;
            }
            let (next, prev) = (n[(i + 1) % n.len()], n[(i + n.len() - 1) % n.len()]);
            if next != b && prev != b {
                return false; // a and b are opposite corners of a quad
            }
            faces_on_edge += 1;
            if n.len() == 3 {
                opposite.extend(n.iter().copied().filter(|&x| x != a && x != b));
            }
        }
        if faces_on_edge != 2 {
            return false;
        }
        opposite.sort_unstable();
        let (na, nb) = (self.neighbours(front, a), self.neighbours(front, b));
        let common: Vec<u32> = na.iter().copied().filter(|x| nb.binary_search(x).is_ok()).collect();
        // The merged vertex and the opposite ones (each losing an edge) keep a proper disc of at
        // least three neighbours: no collapse of a tetrahedron into a flat pair.
        let merged_degree = na.len() + nb.len() - common.len() - 2;
        common == opposite
            && merged_degree >= 3
            && opposite.iter().all(|&o| self.neighbours(front, o).len() > 3)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An octahedron's front: 6 columns, 8 triangles, every vertex of degree 4.
    fn octahedron() -> Front {
        let mut f = Front::default();
        for t in [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]] {
            f.push(&t, 0, None);
        }
        f.index_columns(6);
        f
    }

    #[test]
    fn an_edge_of_an_octahedron_collapses_once() {
        let front = octahedron();
        let mut m = Merges::new(6);
        assert!(m.can_collapse(&front, 0, 2));
        assert!(!m.can_collapse(&front, 0, 1), "0 and 1 are not neighbours");
        m.merge(0, 2);
        assert_eq!(m.root(2), 0);
        // Now a triangular bipyramid (equator 0, 1, 3; apexes 4, 5): an equator-apex edge
        // may go, and leaves a tetrahedron, which may not collapse any further.
        assert!(!m.can_collapse(&front, 2, 4), "2 is merged");
        assert!(!m.can_collapse(&front, 0, 1), "0 and 1 have three common neighbours");
        assert!(m.can_collapse(&front, 0, 4));
        m.merge(0, 4);
        for (a, b) in [(0, 1), (0, 3), (1, 3), (0, 5), (1, 5)] {
            assert!(!m.can_collapse(&front, a, b), "({a}, {b}) of a tetrahedron");
        }
        assert_eq!(m.release(0), vec![2, 4]);
        assert!(!m.is_merged(2));
    }

    #[test]
    fn a_merge_between_groups_is_undone_exactly() {
        let mut m = Merges::new(6);
        m.merge(0, 2);
        m.merge(1, 3);
        let saved = m.clone_groups(0, 1);
        m.merge(0, 1);
        assert_eq!((m.root(1), m.root(3)), (0, 0));
        m.restore_groups(saved);
        assert_eq!((m.root(1), m.root(2), m.root(3)), (1, 0, 1));
        assert_eq!(m.group(0).collect::<Vec<_>>(), vec![0, 2]);
        assert_eq!(m.group(1).collect::<Vec<_>>(), vec![1, 3]);
    }

    #[test]
    fn a_detached_column_leaves_its_group_and_the_rest_stays() {
        let mut m = Merges::new(6);
        m.merge(1, 3);
        m.merge(0, 2);
        m.merge(0, 1);
        assert_eq!(m.group(0).collect::<Vec<_>>(), vec![0, 2, 1, 3]);
        assert!(!m.detach(0), "a root has no group to leave");
        assert!(m.detach(1));
        assert!(!m.is_merged(1));
        assert_eq!(m.group(1).collect::<Vec<_>>(), vec![1], "what merged into 1 before stays with 0");
        assert_eq!((m.root(2), m.root(3)), (0, 0));
        assert_eq!(m.group(0).collect::<Vec<_>>(), vec![0, 2, 3]);
    }
}
