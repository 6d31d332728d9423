//! The state of one slab while it is being decided: which columns move and where to, and which
//! merge ([`SlabPlan`]; the front edges split or swapped are [`super::reshape::Reshape`]). The
//! march ([`super::march`]) builds it; the repairs and adaptations change it; the slab's cells
//! are built from it once every cell is valid.

use super::collapse::Merges;
use super::front::Columns;
use crate::geometry::DVec3;

/// The decisions for one slab: which columns move, where to, and which merge.
#[derive(Clone)]
pub(super) struct SlabPlan {
    pub moving: Vec<bool>,
    pub proposed: Vec<DVec3>,
    pub merges: Merges,
    /// New direction and scale of survivors placed between the two columns they merged.
    pub redirected: Vec<(u32, DVec3, f64)>,
    /// Merges made, entropy and tangential.
    pub collapses: usize,
    /// Of those, the tangential collapses of short edges ([`super::coarsen`]), as the pairs of
    /// columns `(a, b)`, `a < b`, that were their ends.
    pub coarsened: Vec<(u32, u32)>,
    /// Of those, the collapses of faces left flat along a line ([`super::entropy::merge_flat_tops`]).
    pub flat_tops: usize,
    /// Columns bent to mend an invalid cell ([`super::bend::bend_to_mend`]).
    pub bends: usize,
    /// Columns tipped to mend an invalid cell ([`super::bend::nudge_to_mend`]).
    pub tips: usize,
    /// Columns stopped in their transition layers at crushed edges (`march::stop_crushed_transition`).
    pub crushed_stops: usize,
    /// Columns stopped because the new front crossed itself (`march::stop_to_uncross`).
    pub uncrossed: Vec<u32>,
}

impl SlabPlan {
    /// A plan moving the columns marked `moving` to their `proposed` tops, nothing merged yet.
    pub(super) fn new(moving: Vec<bool>, proposed: Vec<DVec3>) -> SlabPlan {
        let merges = Merges::new(moving.len());
        SlabPlan {
            moving,
            proposed,
            merges,
            redirected: Vec::new(),
            collapses: 0,
            coarsened: Vec::new(),
            flat_tops: 0,
            bends: 0,
            tips: 0,
            crushed_stops: 0,
            uncrossed: Vec::new(),
        }
    }

    /// A plan moving every column to its `proposed` top.
    #[cfg(test)]
    pub(super) fn moving_to(proposed: Vec<DVec3>) -> SlabPlan {
        SlabPlan::new(vec![true; proposed.len()], proposed)
    }

    /// The top node of column `c` in the proposal's numbering.
    pub(super) fn top(&self, c: u32, columns: &Columns, committed: u32) -> u32 {
        let r = self.merges.root(c);
        if self.moving[r as usize] {
            committed + r
        } else {
            columns.node[c as usize]
        }
    }

    /// Stop the groups of those of `columns` still moving ([`SlabPlan::stop`]); returns the
    /// columns whose cells change.
    pub(super) fn stop_all(&mut self, columns: impl IntoIterator<Item = u32>) -> Vec<u32> {
        let mut changed = Vec::new();
        for c in columns {
            if self.moving[self.merges.root(c) as usize] {
                changed.extend(self.stop(c));
            }
        }
        changed
    }

    /// Stop the columns `cols` where they are, each taken out of the group it merged into (whose
    /// root marches on; one that is a root stops with its group, [`SlabPlan::stop`]); returns
    /// the columns whose cells change.
    pub(super) fn stop_out_of_groups(&mut self, cols: &[u32]) -> Vec<u32> {
        let mut stopped = Vec::new();
        for &c in cols {
            if self.merges.detach(c) {
                self.moving[c as usize] = false;
                stopped.push(c);
            } else if self.moving[c as usize] {
                stopped.extend(self.stop(c));
            }
        }
        stopped
    }

    /// Stop the group of `c`'s root: the root and every column merged into it keep their node.
    /// Returns the columns whose cells change.
    pub(super) fn stop(&mut self, c: u32) -> Vec<u32> {
        let r = self.merges.root(c);
        let mut changed = self.merges.release(r);
        changed.push(r);
        for &m in &changed {
            self.moving[m as usize] = false;
        }
        changed
    }
}
