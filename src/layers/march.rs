//! Marching the front layer by layer: move the live columns, keep every new cell valid, emit
//! the slab.
//!
//! Each step proposes a new position for every live column (straight along its direction, at
//! the geometric-series distance of the next layer), builds the slab cell over every front face
//! ([`super::slab`]) and checks it with exact predicates. A column taking part in an invalid cell
//! is stopped (its top is its bottom) and the cells around it are rebuilt, until every cell is
//! valid; stopped columns turn their cells into pyramids and tetrahedra, so the slab stays
//! conforming. Only then are the new nodes created and the cells emitted.

use rayon::prelude::*;

use super::front::{Columns, Front};
use super::slab::{slab_cell, Polygon, SlabCell};
use crate::geometry::DVec3;
use crate::mesh::{CellKind, VolumeMesh};
use crate::quality::measures::CellPoints;
use crate::quality::validity::cell_validity;

/// Zone of the layer cells in the output mesh.
pub const LAYER_ZONE: u32 = 0;

/// What the march did, for the report.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct MarchStats {
    pub layers_marched: u32,
    /// Columns stopped before their target because a cell would have been invalid.
    pub columns_stopped_early: usize,
    /// Cells split from an added centre point (their shape was not a standard cell).
    pub steiner_points: usize,
}

/// Node ids of the slab being built: committed nodes are `< committed`, a live column `c`
/// proposes the node `committed + c`.
struct Proposal<'a> {
    points: &'a [DVec3],
    proposed: &'a [DVec3],
    committed: u32,
}

impl Proposal<'_> {
    fn position(&self, node: u32) -> DVec3 {
        match node.checked_sub(self.committed) {
            Some(c) => self.proposed[c as usize],
            None => self.points[node as usize],
        }
    }

    fn gather(&self, nodes: &[u32]) -> CellPoints {
        let mut x = [DVec3::ZERO; 8];
        for (xi, &n) in x.iter_mut().zip(nodes) {
            *xi = self.position(n);
        }
        x
    }

    /// Is the cell with these faces valid, whatever shape it is emitted as?
    fn cell_is_valid(&self, cell: &SlabCell) -> bool {
        match cell {
            SlabCell::Empty => true,
            SlabCell::Flat => false,
            SlabCell::Standard { kind, nodes } => cell_validity(*kind, &self.gather(nodes)).is_valid(),
            SlabCell::Split { faces } => {
                let centre = self.centre(faces);
                split_pieces(faces, u32::MAX).all(|(kind, nodes)| {
                    let apex = nodes.len() - 1;
                    let mut x = self.gather(&nodes[..apex]);
                    x[apex] = centre;
                    cell_validity(kind, &x).is_valid()
                })
            }
        }
    }

    /// The mean of the distinct nodes of a split cell.
    fn centre(&self, faces: &[Polygon]) -> DVec3 {
        let mut nodes: Vec<u32> = faces.iter().flat_map(|f| f.nodes().iter().copied()).collect();
        nodes.sort_unstable();
        nodes.dedup();
        nodes.iter().map(|&n| self.position(n)).sum::<DVec3>() / nodes.len() as f64
    }
}

/// The cells of a split polyhedron with apex `centre`: a tetrahedron per triangle face and a
/// pyramid per quad face (the apex is the last node).
fn split_pieces(faces: &[Polygon], centre: u32) -> impl Iterator<Item = (CellKind, Vec<u32>)> + '_ {
    faces.iter().map(move |f| {
        // The outward face reversed points into the cell, towards the centre.
        let mut nodes: Vec<u32> = f.nodes().iter().rev().copied().collect();
        nodes.push(centre);
        let kind = if f.is_quad() { CellKind::Pyramid } else { CellKind::Tetrahedron };
        (kind, nodes)
    })
}

/// Bottom and top node ids of a front face, given the proposed top of every column.
fn face_nodes(front: &Front, f: usize, top: &[u32], columns: &Columns) -> ([u32; 4], [u32; 4], usize) {
    let cols = front.face_columns(f);
    let mut b = [0; 4];
    let mut t = [0; 4];
    for (i, &c) in cols.iter().enumerate() {
        b[i] = columns.node[c as usize];
        t[i] = top[c as usize];
    }
    (b, t, cols.len())
}

/// March `layers` steps (or until every column has stopped), appending points and cells to
/// `mesh`. `distance(c, k)` is how far column `c` should be from the wall after `k` layers, or
/// `None` when its stack is complete.
pub fn march(
    mesh: &mut VolumeMesh,
    columns: &mut Columns,
    front: &mut Front,
    max_layers: u32,
    distance: impl Fn(usize, u32) -> Option<f64> + Sync,
    mut on_layer: impl FnMut(u32),
) -> MarchStats {
    let mut stats = MarchStats::default();
    for k in 1..=max_layers {
        for c in 0..columns.len() {
            if columns.alive[c] && distance(c, k).is_none() {
                columns.alive[c] = false;
            }
        }
        if !columns.alive.iter().any(|&a| a) {
            break;
        }
        let proposed: Vec<DVec3> = (0..columns.len())
            .into_par_iter()
            .map(|c| match distance(c, k) {
                Some(d) if columns.alive[c] => columns.base[c] + columns.dir[c] * (columns.scale[c] * d),
                _ => DVec3::ZERO,
            })
            .collect();
        let moving = settle_slab(mesh, columns, front, &proposed);
        stats.columns_stopped_early += columns.alive.iter().zip(&moving).filter(|(a, m)| **a && !**m).count();
        commit_slab(mesh, columns, front, &proposed, &moving, &mut stats);
        for (alive, m) in columns.alive.iter_mut().zip(&moving) {
            *alive = *m;
        }
        stats.layers_marched = k;
        on_layer(k);
    }
    stats
}

/// Decide which live columns move: stop the columns of invalid cells until every cell is valid.
fn settle_slab(mesh: &VolumeMesh, columns: &Columns, front: &Front, proposed: &[DVec3]) -> Vec<bool> {
    let committed = mesh.points.len() as u32;
    let proposal = Proposal { points: &mesh.points, proposed, committed };
    let mut moving = columns.alive.clone();
    let mut to_check: Vec<usize> = (0..front.len()).collect();
    while !to_check.is_empty() {
        let top: Vec<u32> = (0..columns.len())
            .map(|c| if moving[c] { committed + c as u32 } else { columns.node[c] })
            .collect();
        let invalid: Vec<usize> = to_check
            .par_iter()
            .copied()
            .filter(|&f| {
                let (b, t, n) = face_nodes(front, f, &top, columns);
                !proposal.cell_is_valid(&slab_cell(&b[..n], &t[..n]))
            })
            .collect();
        let mut stopped = Vec::new();
        for &f in &invalid {
            for &c in front.face_columns(f) {
                if std::mem::replace(&mut moving[c as usize], false) {
                    stopped.push(c);
                }
            }
        }
        // Only the cells around a newly stopped column can change.
        to_check = front.faces_around_columns(&stopped);
    }
    moving
}

/// Create the nodes of the moving columns and emit the slab's cells.
fn commit_slab(
    mesh: &mut VolumeMesh,
    columns: &mut Columns,
    front: &mut Front,
    proposed: &[DVec3],
    moving: &[bool],
    stats: &mut MarchStats,
) {
    let mut top = columns.node.clone();
    for c in 0..columns.len() {
        if moving[c] {
            top[c] = mesh.points.len() as u32;
            mesh.points.push(proposed[c]);
            columns.layers[c] += 1;
        }
    }
    for f in 0..front.len() {
        let (b, t, n) = face_nodes(front, f, &top, columns);
        if b[..n] != t[..n] {
            // The top is now front, even under a flat cell whose top lies on a neighbour's face.
            front.raised[f] = true;
        }
        match slab_cell(&b[..n], &t[..n]) {
            SlabCell::Empty | SlabCell::Flat => {}
            SlabCell::Standard { kind, nodes } => {
                mesh.push_cell(kind, &nodes[..kind.node_count()], LAYER_ZONE)
            }
            SlabCell::Split { faces } => {
                let centre = mesh.points.len() as u32;
                let proposal = Proposal { points: &mesh.points, proposed: &[], committed: u32::MAX };
                let c = proposal.centre(&faces);
                mesh.points.push(c);
                for (kind, nodes) in split_pieces(&faces, centre) {
                    mesh.push_cell(kind, &nodes, LAYER_ZONE);
                }
                stats.steiner_points += 1;
            }
        }
    }
    columns.node = top;
}
