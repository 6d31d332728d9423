//! Tangential collapse of short front edges (tangential adaptivity): a front edge whose proposed
//! top is shorter than
//! [`TUNING.adaptation.collapse_length`](super::tuning::Adaptation::collapse_length) against its
//! size ([`EdgeSizes::collapse_length`]: the target, or a part of its length on the wall where
//! shorter) merges its two columns into one, as the entropy collapse does
//! ([`super::entropy::collapse`]): a column ends. It is the inverse of the split
//! ([`super::split`]): where the field coarsens (out of a refinement region) or the front
//! compresses (concave walls), the front's edges stay near the wanted size.
//!
//! Collapses are tried shortest edge first, in rounds of at most one per column, until a round
//! makes none (or
//! [`TUNING.adaptation.collapse_rounds`](super::tuning::Adaptation::collapse_rounds)): a front
//! leaving a refinement region coarsens by up to a factor of 2^rounds a layer. Each must pass the
//! link condition ([`super::collapse::Merges::can_collapse`]) and leave every cell around it valid
//! (exact predicates); one that does not is undone. Fan edges (copies of one wall vertex) never
//! collapse: they open with the distance and are what makes the fan.

use rayon::prelude::*;

use super::entropy;
use super::front::{Columns, Front};
use super::slab_plan::SlabPlan;
use super::split::EdgeSizes;
use super::tuning::TUNING;

/// What [`collapse_short_edges`] did.
pub(super) struct Coarsening {
    /// The edges collapsed, as the pairs of columns `(a, b)`, `a < b`, that were their ends.
    pub made: Vec<(u32, u32)>,
    /// The short edges left shorter than
    /// [`TUNING.adaptation.crushed_length`](super::tuning::Adaptation::crushed_length), as root
    /// pairs.
    pub crushed: Vec<(u32, u32)>,
}

/// Collapse the plan's short front edges of layer `k` against the tangential sizes `h` at the
/// columns' proposed tops (and the layer's height, within the user's sizes `user`), but not the
/// edges `vetoed` (pairs `(a, b)`, `a < b`); `cells_valid(plan, group)` tells whether every cell
/// around the columns `group` is valid under the plan.
pub(super) fn collapse_short_edges(
    plan: &mut SlabPlan,
    front: &Front,
    columns: &Columns,
    (h, user, k): (&[f64], &[f64], u32),
    vetoed: &[(u32, u32)],
    cells_valid: impl Fn(&SlabPlan, &[u32]) -> bool,
) -> Coarsening {
    let height: Vec<f64> = (0..columns.len()).map(|c| columns.layer_height(c, k)).collect();
    let sizes = EdgeSizes { target: h, height: &height, user };
    let mut made = Vec::new();
    // The short edges under the plan as it is: a round that collapses nothing leaves the plan
    // as it was (a collapse that fails is undone), so its list stays the plan's.
    let mut short = short_edges(plan, front, columns, &sizes);
    for _ in 0..TUNING.adaptation.collapse_rounds {
        let mut shortest_first = short.clone();
        shortest_first.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
        let mut touched = vec![false; columns.len()];
        let before = made.len();
        for (_, a, b) in shortest_first {
            if touched[a as usize]
                || touched[b as usize]
                || vetoed.contains(&(a, b))
                || !plan.merges.can_collapse(front, a, b)
            {
                continue;
            }
            if entropy::try_collapse(plan, columns, a, b, &cells_valid) {
                touched[a as usize] = true;
                touched[b as usize] = true;
                made.push((a, b));
            }
        }
        if made.len() == before {
            break;
        }
        short = short_edges(plan, front, columns, &sizes);
    }
    let crushed = short
        .into_iter()
        .filter(|&(length, _, _)| length < TUNING.adaptation.crushed_length)
        .map(|(_, a, b)| (a, b))
        .collect();
    Coarsening { made, crushed }
}

/// The front edges `(length, a, b)` between two moving roots (after the merges so far) that are
/// shorter than [`TUNING.adaptation.collapse_length`](super::tuning::Adaptation::collapse_length)
/// against the sizes `[target, layer height, user]` ([`EdgeSizes::collapse_length`]), each once;
/// fan edges and edges between columns that slide differently are left out.
fn short_edges(plan: &SlabPlan, front: &Front, columns: &Columns, sizes: &EdgeSizes) -> Vec<(f64, u32, u32)> {
    let root = |c: u32| plan.merges.root(c) as usize;
    // Filtered by face in parallel, then ordered by their ends: the few short edges are all
    // that is sorted (an edge's length depends only on its ends, so its copies are equal).
    let mut short: Vec<(f64, u32, u32)> = (0..front.len())
        .into_par_iter()
        .flat_map_iter(|f| {
            let cols = front.face_columns(f);
            let n = cols.len();
            (0..n).filter_map(move |i| {
                let (a, b) = (root(cols[i]), root(cols[(i + 1) % n]));
                let short = a < b
                    && plan.moving[a]
                    && plan.moving[b]
                    && !columns.is_fan_edge(a, b)
                    && columns.slide[a] == columns.slide[b];
                let length = short
                    .then(|| sizes.collapse_length(columns, a, b, plan.proposed[b] - plan.proposed[a]))?;
                (length < TUNING.adaptation.collapse_length).then_some((length, a as u32, b as u32))
            })
        })
        .collect();
    short.sort_unstable_by_key(|&(_, a, b)| (a, b));
    short.dedup_by_key(|&mut (_, a, b)| (a, b));
    short
}
