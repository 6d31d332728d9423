//! Adjacency of a triangle surface: unique edges, edge -> triangles, triangle -> edges,
//! vertex -> triangles (flat CSR arrays) and shells (connected components through edges).
//!
//! A [`Topology`] is a snapshot of `surface.triangles`: rebuild it after changing them (e.g.
//! after [`super::validate::validate`] flipped an inverted shell). It is built in O(n log n) by
//! one sort of the edge keys and works on any input, valid or not.

use super::Surface;

/// One triangle using an edge, and the direction it traverses it in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EdgeUse {
    pub triangle: u32,
    /// True when the triangle goes from `edges[e][0]` to `edges[e][1]` (the smaller vertex id
    /// first); two consistently oriented neighbours use their shared edge in opposite directions.
    pub forward: bool,
}

/// A connected component of triangles (connected through shared edges).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Shell {
    pub triangles: usize,
    pub vertices: usize,
    pub edges: usize,
    /// Every edge of the shell has exactly two triangles.
    pub closed: bool,
    /// Closed, and the triangles around every vertex of the shell form a single disc.
    pub manifold: bool,
    /// V - E + F.
    pub euler_characteristic: i64,
    /// Number of handles, from V - E + F = 2 - 2g; only for a closed manifold shell.
    pub genus: Option<u32>,
}

#[derive(Clone, Debug)]
pub struct Topology {
    /// Unique undirected edges, each as (smaller vertex id, larger vertex id).
    pub edges: Vec<[u32; 2]>,
    edge_use_start: Vec<u32>,
    edge_uses: Vec<EdgeUse>,
    /// `triangle_edges[t][i]` is the edge from corner `i` to corner `i + 1` (mod 3) of `t`.
    pub triangle_edges: Vec<[u32; 3]>,
    vertex_triangle_start: Vec<u32>,
    vertex_triangles: Vec<u32>,
    /// The shell of every triangle.
    pub triangle_shell: Vec<u32>,
    pub shells: Vec<Shell>,
}

/// Reusable buffers for [`Topology::vertex_fan_count`] (no allocation per vertex).
#[derive(Default)]
pub struct FanScratch {
    edge_triangle: Vec<(u32, u32)>,
    parent: Vec<u32>,
}

/// The key of an undirected edge: both vertex ids, smaller first, in one integer.
fn edge_key(a: u32, b: u32) -> u64 {
    (u64::from(a.min(b)) << 32) | u64::from(a.max(b))
}

impl Topology {
    pub fn new(surface: &Surface) -> Topology {
        let (edges, edge_use_start, edge_uses, triangle_edges) = build_edges(&surface.triangles);
        let (vertex_triangle_start, vertex_triangles) = build_vertex_triangles(surface);
        let mut topology = Topology {
            edges,
            edge_use_start,
            edge_uses,
            triangle_edges,
            vertex_triangle_start,
            vertex_triangles,
            triangle_shell: Vec::new(),
            shells: Vec::new(),
        };
        topology.triangle_shell = topology.label_shells();
        topology.shells = topology.describe_shells();
        topology
    }

    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    /// Number of vertex slots (the point count, or more if a triangle refers past it).
    pub fn vertex_count(&self) -> usize {
        self.vertex_triangle_start.len() - 1
    }

    /// The triangles using edge `e`, sorted by triangle id.
    pub fn edge_uses(&self, e: u32) -> &[EdgeUse] {
        let e = e as usize;
        &self.edge_uses[self.edge_use_start[e] as usize..self.edge_use_start[e + 1] as usize]
    }

    /// The triangle across edge `e` from triangle `t` (`t` itself on an open edge).
    pub fn other_triangle(&self, e: u32, t: u32) -> u32 {
        self.edge_uses(e).iter().map(|u| u.triangle).find(|&x| x != t).unwrap_or(t)
    }

    /// The triangle that runs along edge `e` from vertex `from` to vertex `to`.
    pub fn triangle_using(&self, e: u32, from: u32, to: u32) -> u32 {
        let forward = self.edges[e as usize] == [from, to];
        self.edge_uses(e).iter().find(|u| u.forward == forward).map_or(u32::MAX, |u| u.triangle)
    }

    /// The triangles having `v` as a corner, sorted by triangle id.
    pub fn vertex_triangles(&self, v: u32) -> &[u32] {
        let v = v as usize;
        let range = self.vertex_triangle_start[v] as usize..self.vertex_triangle_start[v + 1] as usize;
        &self.vertex_triangles[range]
    }

    /// Number of separate fans around vertex `v`: groups of its triangles connected through
    /// edges incident to `v`. One for a manifold vertex (a disc, or a half-disc on a boundary);
    /// two or more where sheets touch only at the vertex (e.g. two cones tip to tip).
    pub fn vertex_fan_count(&self, v: u32, scratch: &mut FanScratch) -> usize {
        let triangles = self.vertex_triangles(v);
        // (edge at v, index of the triangle in `triangles`), sorted so that the triangles
        // sharing an edge are adjacent.
        let FanScratch { edge_triangle, parent } = scratch;
        edge_triangle.clear();
        for (i, &t) in triangles.iter().enumerate() {
            for &e in &self.triangle_edges[t as usize] {
                if self.edges[e as usize].contains(&v) {
                    edge_triangle.push((e, i as u32));
                }
            }
        }
        edge_triangle.sort_unstable();
        parent.clear();
        parent.extend(0..triangles.len() as u32);
        let mut fans = triangles.len();
        for pair in edge_triangle.windows(2) {
            if pair[0].0 == pair[1].0 && union(parent, pair[0].1, pair[1].1) {
                fans -= 1;
            }
        }
        fans
    }

    /// The triangles of every shell, grouped: `(start offsets per shell, triangle ids)`.
    pub fn shell_triangles(&self) -> (Vec<u32>, Vec<u32>) {
        group_by_key(&self.triangle_shell, self.shells.len())
    }

    /// Union-find over triangles through every edge; shells numbered by their smallest triangle.
    fn label_shells(&self) -> Vec<u32> {
        let triangle_count = self.triangle_edges.len();
        let mut parent: Vec<u32> = (0..triangle_count as u32).collect();
        for e in 0..self.edges.len() as u32 {
            let uses = self.edge_uses(e);
            for pair in uses.windows(2) {
                union(&mut parent, pair[0].triangle, pair[1].triangle);
            }
        }
        let mut label = vec![u32::MAX; triangle_count];
        let mut shell_of_root = vec![u32::MAX; triangle_count];
        let mut shells = 0;
        for (t, shell) in label.iter_mut().enumerate() {
            let root = find(&mut parent, t as u32) as usize;
            if shell_of_root[root] == u32::MAX {
                shell_of_root[root] = shells;
                shells += 1;
            }
            *shell = shell_of_root[root];
        }
        label
    }

    fn describe_shells(&self) -> Vec<Shell> {
        let shell_count = self.triangle_shell.iter().map(|&s| s as usize + 1).max().unwrap_or(0);
        let mut shells = vec![
            Shell {
                triangles: 0,
                vertices: 0,
                edges: 0,
                closed: true,
                manifold: true,
                euler_characteristic: 0,
                genus: None,
            };
            shell_count
        ];
        for &s in &self.triangle_shell {
            shells[s as usize].triangles += 1;
        }
        for e in 0..self.edges.len() as u32 {
            let uses = self.edge_uses(e);
            let shell = &mut shells[self.triangle_shell[uses[0].triangle as usize] as usize];
            shell.edges += 1;
            shell.closed &= uses.len() == 2;
        }
        self.count_shell_vertices(&mut shells);
        for shell in &mut shells {
            shell.manifold &= shell.closed;
            shell.euler_characteristic = shell.vertices as i64 - shell.edges as i64 + shell.triangles as i64;
            let twice_genus = 2 - shell.euler_characteristic;
            if shell.manifold && twice_genus >= 0 && twice_genus % 2 == 0 {
                shell.genus = u32::try_from(twice_genus / 2).ok();
            }
        }
        shells
    }

    /// Count each vertex once in every shell it touches; a vertex whose triangles form several
    /// fans makes every shell it touches non-manifold.
    fn count_shell_vertices(&self, shells: &mut [Shell]) {
        let mut last_vertex_seen = vec![u32::MAX; shells.len()];
        let mut scratch = FanScratch::default();
        for v in 0..self.vertex_count() as u32 {
            let triangles = self.vertex_triangles(v);
            if triangles.is_empty() {
                continue;
            }
            let pinched = self.vertex_fan_count(v, &mut scratch) > 1;
            for &t in triangles {
                let s = self.triangle_shell[t as usize] as usize;
                if last_vertex_seen[s] != v {
                    last_vertex_seen[s] = v;
                    shells[s].vertices += 1;
                }
                shells[s].manifold &= !pinched;
            }
        }
    }
}

/// Unique edges from one sort of the 3 directed edge keys per triangle.
#[allow(clippy::type_complexity)]
fn build_edges(triangles: &[[u32; 3]]) -> (Vec<[u32; 2]>, Vec<u32>, Vec<EdgeUse>, Vec<[u32; 3]>) {
    let mut keys: Vec<(u64, u32)> = Vec::with_capacity(3 * triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        for i in 0..3 {
            keys.push((edge_key(tri[i], tri[(i + 1) % 3]), 3 * t as u32 + i as u32));
        }
    }
    keys.sort_unstable();
    let mut edges: Vec<[u32; 2]> = Vec::with_capacity(keys.len() / 2 + 1);
    let mut start = Vec::with_capacity(keys.len() / 2 + 2);
    let mut uses = Vec::with_capacity(keys.len());
    let mut triangle_edges = vec![[0u32; 3]; triangles.len()];
    let mut previous = None;
    for &(key, corner) in &keys {
        if previous != Some(key) {
            previous = Some(key);
            start.push(uses.len() as u32);
            edges.push([(key >> 32) as u32, key as u32]);
        }
        let (t, i) = ((corner / 3) as usize, (corner % 3) as usize);
        let e = edges.len() as u32 - 1;
        triangle_edges[t][i] = e;
        uses.push(EdgeUse { triangle: t as u32, forward: triangles[t][i] == edges[e as usize][0] });
    }
    start.push(uses.len() as u32);
    (edges, start, uses, triangle_edges)
}

/// Vertex -> incident triangles (each triangle listed once per distinct corner vertex).
fn build_vertex_triangles(surface: &Surface) -> (Vec<u32>, Vec<u32>) {
    let max_index = surface.triangles.iter().flatten().map(|&v| v as usize + 1).max().unwrap_or(0);
    let vertex_count = surface.points.len().max(max_index);
    let mut vertices = Vec::with_capacity(3 * surface.triangles.len());
    let mut owners = Vec::with_capacity(3 * surface.triangles.len());
    for (t, tri) in surface.triangles.iter().enumerate() {
        for (i, &v) in tri.iter().enumerate() {
            if !tri[..i].contains(&v) {
                vertices.push(v);
                owners.push(t as u32);
            }
        }
    }
    group_by_key_with(&vertices, &owners, vertex_count)
}

/// Counting sort of `0..keys.len()` by key: CSR `(start offsets, item indices)`.
fn group_by_key(keys: &[u32], key_count: usize) -> (Vec<u32>, Vec<u32>) {
    let items: Vec<u32> = (0..keys.len() as u32).collect();
    group_by_key_with(keys, &items, key_count)
}

/// Counting sort of `items` by `keys` (stable): CSR `(start offsets, items)`.
pub(crate) fn group_by_key_with(keys: &[u32], items: &[u32], key_count: usize) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; key_count + 1];
    for &k in keys {
        start[k as usize + 1] += 1;
    }
    for k in 0..key_count {
        start[k + 1] += start[k];
    }
    let mut next = start.clone();
    let mut grouped = vec![0u32; items.len()];
    for (&k, &item) in keys.iter().zip(items) {
        grouped[next[k as usize] as usize] = item;
        next[k as usize] += 1;
    }
    (start, grouped)
}

/// Root of `x` in a union-find forest (with path halving).
pub(crate) fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let grandparent = parent[parent[x as usize] as usize];
        parent[x as usize] = grandparent;
        x = grandparent;
    }
    x
}

/// Join the sets of `a` and `b`; false when they were already one set.
pub(crate) fn union(parent: &mut [u32], a: u32, b: u32) -> bool {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra == rb {
        return false;
    }
    let (low, high) = (ra.min(rb), ra.max(rb));
    parent[high as usize] = low;
    true
}

/// The corner of `triangle` that is not on `edge` (the first one if the triangle is degenerate).
pub fn opposite_vertex(triangle: [u32; 3], edge: [u32; 2]) -> u32 {
    triangle.into_iter().find(|v| !edge.contains(v)).unwrap_or(triangle[0])
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::geometry::DVec3;
    use crate::surface::shapes;

    /// The closed surface of a union of unit voxels at the given (non-negative) grid positions.
    /// Voxels touching along an edge or at a corner give non-manifold input.
    pub fn voxel_surface(cells: &[[usize; 3]]) -> Surface {
        let mut dims = [1; 3];
        for c in cells {
            for k in 0..3 {
                dims[k] = dims[k].max(c[k] + 1);
            }
        }
        shapes::voxels(dims, 1.0, 1, |i, j, k| cells.contains(&[i, j, k]))
    }

    /// The n x n x n block of voxels without the voxel `hole`.
    pub fn block_without(n: usize, hole: [usize; 3]) -> Surface {
        shapes::voxels([n; 3], 1.0, 1, |i, j, k| [i, j, k] != hole)
    }

    /// All 8 voxels of the 2x2x2 block except the one at (1, 1, 1).
    pub fn cube_without_octant() -> Surface {
        block_without(2, [1, 1, 1])
    }

    /// A torus of 8 voxels: the ring of a 3x3 block without its centre.
    pub fn voxel_torus() -> Surface {
        shapes::voxels([3, 3, 1], 1.0, 1, |i, j, _| [i, j] != [1, 1])
    }

    #[test]
    fn cube_counts() {
        let s = voxel_surface(&[[0, 0, 0]]);
        let topo = Topology::new(&s);
        assert_eq!(topo.edge_count(), 18);
        assert_eq!(topo.shells.len(), 1);
        let shell = &topo.shells[0];
        assert_eq!((shell.vertices, shell.edges, shell.triangles), (8, 18, 12));
        assert!(shell.closed && shell.manifold);
        assert_eq!(shell.genus, Some(0));
        assert!((s.enclosed_volume() - 1.0).abs() < 1e-12, "outward");
        for e in 0..topo.edge_count() as u32 {
            let uses = topo.edge_uses(e);
            assert_eq!(uses.len(), 2);
            assert_ne!(uses[0].forward, uses[1].forward, "consistent orientation");
        }
        for t in 0..12 {
            for (i, &e) in topo.triangle_edges[t].iter().enumerate() {
                let (a, b) = (s.triangles[t][i], s.triangles[t][(i + 1) % 3]);
                assert_eq!(topo.edges[e as usize], [a.min(b), a.max(b)]);
            }
        }
        let around: usize = (0..8).map(|v| topo.vertex_triangles(v).len()).sum();
        assert_eq!(around, 36);
    }

    #[test]
    fn torus_has_genus_one() {
        let topo = Topology::new(&voxel_torus());
        assert_eq!(topo.shells.len(), 1);
        assert_eq!(topo.shells[0].euler_characteristic, 0);
        assert_eq!(topo.shells[0].genus, Some(1));
    }

    #[test]
    fn disjoint_cubes_are_two_shells() {
        let topo = Topology::new(&voxel_surface(&[[0, 0, 0], [2, 0, 0]]));
        assert_eq!(topo.shells.len(), 2);
        assert!(topo.shells.iter().all(|s| s.genus == Some(0) && s.triangles == 12));
        assert!(topo.triangle_shell[..12].iter().all(|&s| s == 0));
        assert!(topo.triangle_shell[12..].iter().all(|&s| s == 1));
        let (start, triangles) = topo.shell_triangles();
        assert_eq!(start, vec![0, 12, 24]);
        assert_eq!(triangles[12], 12);
    }

    #[test]
    fn cubes_touching_at_a_corner_pinch_the_vertex() {
        let s = voxel_surface(&[[0, 0, 0], [1, 1, 1]]);
        let topo = Topology::new(&s);
        assert_eq!(topo.shells.len(), 2);
        let corner = s.points.iter().position(|p| *p == DVec3::ONE).unwrap() as u32;
        let mut scratch = FanScratch::default();
        assert_eq!(topo.vertex_fan_count(corner, &mut scratch), 2);
        assert_eq!(topo.vertex_fan_count(0, &mut scratch), 1);
        assert!(topo.shells.iter().all(|s| s.closed && !s.manifold && s.genus.is_none()));
    }

    #[test]
    fn open_and_degenerate_input_does_not_panic() {
        let mut s = voxel_surface(&[[0, 0, 0]]);
        s.triangles.pop();
        s.triangles.push([3, 3, 3]);
        s.triangles.push([0, 1, 99]);
        let topo = Topology::new(&s);
        assert!(!topo.shells[0].closed);
        assert_eq!(topo.vertex_count(), 100);
        assert_eq!(opposite_vertex([3, 3, 3], [3, 3]), 3);
    }
}
