//! The changes of the front's topology proposed for one slab (tangential adaptivity): the
//! splits of long edges ([`super::split`]) and the swaps of badly shaped pairs
//! ([`super::swap`]), decided with the slab's [`SlabPlan`] and given up where a cell they make
//! is invalid.

use super::front::Front;
use super::slab_plan::SlabPlan;
use super::split::Splits;
use super::swap::Swaps;

/// The changes of the front's topology proposed for one slab (tangential adaptivity): splits
/// of long edges and swaps of badly shaped pairs (the collapses are merges of the plan).
#[derive(Clone, Debug, Default)]
pub(super) struct Reshape {
    pub splits: Splits,
    pub swaps: Swaps,
    /// The tangential size at every column's proposed top (evaluated once a slab: a sizing
    /// field's size is a search over the wall).
    pub target: Vec<f64>,
}

impl Reshape {
    /// Give up the swap, else the splits, of invalid face `f`; returns the faces whose cells
    /// change (none if it had neither).
    pub(super) fn give_up(&mut self, f: usize, plan: &SlabPlan) -> Vec<usize> {
        let swapped = self.swaps.give_up(f, plan);
        if !swapped.is_empty() {
            return swapped;
        }
        self.splits.give_up(f, plan)
    }

    /// The faces whose cells change with the columns `changed`: the faces around them, and both
    /// faces of a swap with one of them (its face without that column turns back into a cell of
    /// its own when the swap is no longer made).
    pub(super) fn faces_around_columns(&self, front: &Front, changed: &[u32]) -> Vec<usize> {
        let mut faces = front.faces_around_columns(changed);
        faces.extend(self.swaps.faces_with_columns(changed));
        faces.sort_unstable();
        faces.dedup();
        faces
    }
}
