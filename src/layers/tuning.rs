//! The layers' tuning values: the thresholds, ratios, angles, fractions tried in turn and round
//! counts that were chosen by judgement (some by measurement, given with them), gathered in one
//! [`Tuning`] and grouped by the stage of the march that reads them. The code reads them from
//! [`TUNING`].
//!
//! What is not a choice stays beside its use: sentinels ([`super::split::NONE`]), names and
//! zones ([`super::TOP_PATCH`], [`super::LAYER_ZONE_NAME`], [`super::march::LAYER_ZONE`]), array
//! lengths ([`super::smoothness::HISTOGRAM_BINS`]) and the floating-point tolerance of the
//! sliding patches' plane test.

use std::f64::consts::{FRAC_1_SQRT_2, SQRT_2};

/// The layers' tuning values, by stage (see the module doc).
#[derive(Clone, Copy, Debug)]
pub struct Tuning {
    /// Entropy merges: columns of fronts that meet ([`super::entropy`]).
    pub entropy: Entropy,
    /// Repairs of invalid cells by bending or tipping a column, before its stack stops
    /// ([`super::bend`]).
    pub repairs: Repairs,
    /// Tangential adaptation of the front's edges: splits ([`super::split`]), collapses
    /// ([`super::coarsen`]) and swaps ([`super::swap`]).
    pub adaptation: Adaptation,
    /// The crossing guard: the new front must not cross itself ([`super::guard`]).
    pub guard: Guard,
    /// Pyramids on the front's quads ([`super::guard::pyramid_apex`]).
    pub pyramids: Pyramids,
    /// Thin gaps: stacks stopped at the medial surface between walls that face each other
    /// ([`super::gap`]).
    pub gaps: Gaps,
    /// How much neighbouring stacks may differ: first heights, tangential sizes, pits
    /// ([`super::march`]).
    pub grading: Grading,
    /// Undoing the caps and folds of the final front ([`super::unfold`]).
    pub unfolding: Unfolding,
    /// Closing the layers against the patches their columns slid on ([`super::sliding`]).
    pub sliding: Sliding,
    /// Marching again with the first layer fitted to a finely faceted wall
    /// ([`super::build_layers`]).
    pub first_layer: FirstLayer,
}

/// Entropy merges ([`super::entropy`]).
#[derive(Clone, Copy, Debug)]
pub struct Entropy {
    // Columns meeting.
    /// Two columns meet when their proposed top edge keeps less than this fraction of its bottom
    /// edge: merging them then moves neither far (merging columns still apart twists the lateral
    /// faces of the cells around them).
    pub meeting_ratio: f64,
    /// Two extrusion scales closer than this ratio are the same kind of column: of two merged
    /// columns of one kind neither survives alone, they meet in the middle.
    pub same_scale: f64,
    /// Where a V's columns merging into its crease may meet, as parts of the way from the
    /// crease's top to the middle of the V's tops, tried in turn.
    pub meeting_heights: [f64; 5],

    // Columns overtaken by another wall's front.
    /// A column has been overtaken by another wall's front once its proposed top lags its
    /// layer's distance from the wall by more than this many of its layer's heights, counting
    /// [`anticipation`](Self::anticipation) times what it fell behind in this layer.
    pub overtaken: f64,
    /// A column falling behind by less than this many layer heights in one layer is not being
    /// overtaken: a split column (a chord across a convex front) lags the offset by as much at
    /// its bottom as at its top, and so do faceting errors. (The lag of a column passing a
    /// 90-degree ridge's bisector grows by about one height per layer; with no floor on it every
    /// column counts as late: fandisk's coverage near concave ridges fell to 50%.)
    pub falling_behind: f64,

    // Flat tops.
    /// A face top keeping less than this fraction of its bottom's area, with three corners or
    /// more still apart, is flat.
    pub flat_top: f64,
    /// A flat top ([`flat_top`](Self::flat_top)) whose longest edge keeps at least this fraction
    /// of its bottom's is flat along a line.
    pub line_like: f64,

    // Columns passing a concave ridge's bisector.
    /// How many of its last approaches to a bisector ahead a column is merged: one, so that a
    /// column short of the bisector by less than it closed in this layer, which the next layer
    /// would take past, merges now. (At 0.5 of the approach: flange 89.8% near concave, fandisk
    /// 95.3%, arrow 68.1%; at 1: 93.7%, 95.9%, 69.3%; at 1.5 fandisk 97.6% but flange 86.9%.)
    pub anticipation: f64,
    /// How many of its last approaches to a bisector ahead a column may be merged to mend a
    /// cell.
    pub repair_anticipation: f64,
    /// The edge from a ridge column to a face column must run this much across the bisector
    /// (cosine of its angle to the bisector plane's normal): ridge edges lie in the plane.
    pub across_ridge: f64,
    /// A column's direction within this cosine of a wall triangle's normal is that wall's.
    pub same_wall_cosine: f64,
    /// Directions closer than this (the length of `n - (n . d) d`, the sine of their angle)
    /// leave the bisector test undecided.
    pub min_bisector_sine: f64,

    // Corners closing in on their opposite edge along a ridge.
    /// A face with a column whose extrusion scale exceeds another's by this ratio spans a ridge
    /// (a concave ridge's bisector column has `1/sin(phi/2)`: 1.1 for phi = 130 degrees).
    pub ridge_scale: f64,
    /// A corner whose height over its opposite edge falls below this fraction of what it was,
    /// in one layer, is closing in on it.
    pub closing_in: f64,
    /// A wall triangle whose corner stands less than this fraction of its opposite edge's
    /// length over it is a sliver there.
    pub sliver: f64,
}

/// Repairs by bending or tipping a column ([`super::bend`]).
#[derive(Clone, Copy, Debug)]
pub struct Repairs {
    /// How far a column turns to its neighbours' mean direction (parts of the way), tried in
    /// order (the least bend that mends first).
    pub bends: [f64; 3],
    /// How far a top is tipped sideways to mend a cell, as a fraction of its step, tried in
    /// order.
    pub nudges: [f64; 4],
}

/// Tangential adaptation: splits, collapses and swaps of the front's edges.
#[derive(Clone, Copy, Debug)]
pub struct Adaptation {
    // Splits (`split`).
    /// A front edge longer than this in the metric is split.
    pub split_length: f64,
    /// A new column's first top lies at least this fraction of its layer's height beyond the
    /// middle of its ends' tops.
    pub split_lift: f64,

    // The sizes collapses are measured against (`split::EdgeSizes`).
    /// An edge between two wall columns is collapsed only once its size (target or wall length)
    /// has compressed to this fraction of its wall length (it is then below `compressed / sqrt 2`
    /// of it). Collapsed earlier, the columns merge while still far apart, and the twisted cells
    /// around them span several layers along the wall's normal: measure.py's resolution coverage
    /// at concave ridges (H = 1e-3 D, 10 layers) is, for 1 / 0.5 / 0.3 here and without
    /// collapses, flange 0.837 / 0.933 / 0.944 / 0.947, mech 0.41 / 0.63 / 0.64 / 0.61, fandisk
    /// 0.972 / 0.923 / 0.909 / 0.835.
    pub compressed: f64,
    /// A front edge this many times shorter than its layer is high is collapsed
    /// ([`EdgeSizes::collapse_length`](super::split::EdgeSizes::collapse_length)). At 2, the ONERA
    /// M6's wing-tip cap (facets of 0.2-0.4 under a first layer of 1.67) coarsens: 574 core
    /// slivers -> 114, and the first core cells match the last layer at 99.0% of the front
    /// triangles (94.9% before); at 1.4, 58 slivers but the box's transition layers coarsen too
    /// (94.9% -> 93.5%).
    pub tallest_cell: f64,

    // Collapses (`coarsen`).
    /// A front edge shorter than this against the collapse sizes is collapsed.
    pub collapse_length: f64,
    /// A front edge shorter than this against the collapse sizes that no collapse could take is
    /// crushed: its cells are needles along the front (in the transition layers the march ends
    /// the stacks at its ends). Fandisk's two fans crossing were at 0.017 and 0.037; at 0.1 the
    /// arrow's fin roots ended too (0.053 to 0.09, where the fin and body fronts meet and a later
    /// layer's merges take them), and their pits left core slivers where it had none.
    pub crushed_length: f64,
    /// Rounds of collapses in one slab: a front leaving a refinement region coarsens by up to a
    /// factor of 2^rounds a layer.
    pub collapse_rounds: usize,

    // Swaps (`swap`).
    /// A pair of front triangles is swapped only when its worst angle is below this
    /// (degrees)...
    pub swap_poor_angle: f64,
    /// ...and the swap raises it by at least this factor.
    pub swap_gain: f64,
}

/// The crossing guard ([`super::guard`]).
#[derive(Clone, Copy, Debug)]
pub struct Guard {
    /// Layers one set of candidate pairs covers when no collapse changes the front.
    pub lookahead_layers: u32,
    /// Two triangles sharing a vertex whose columns' mean directions make a cosine below this
    /// may fold over it with both cells valid: the front turns sharply there (45 deg).
    pub turned: f64,
}

/// Pyramids on the front's quads ([`super::guard::pyramid_apex`]).
#[derive(Clone, Copy, Debug)]
pub struct Pyramids {
    /// Apex heights tried for a pyramid on a front quad: half its shortest edge, then halved.
    pub apex_tries: i32,
}

/// Thin gaps ([`super::gap`]).
#[derive(Clone, Copy, Debug)]
pub struct Gaps {
    /// Walls whose normals are within this angle (degrees) of opposite face each other across
    /// a gap.
    pub facing_angle_deg: f64,
    /// Hits nearer than this fraction of the column's first layer height are the wall at the
    /// column's own vertex.
    pub own_wall: f64,
    /// Steps of a climb per length `reach` ([`super::gap::room_above`]).
    pub climb_steps: f64,
    /// Tilt (degrees) of the rays that probe whether the wall across curves around a column.
    pub probe_tilt_deg: f64,
    /// How much the probe rays also lean across their tilt (a fraction of it, both ways): at a
    /// bore's mouth the rays tilted along the rim would graze the far rim; leaning into the bore
    /// they hit its wall just inside (the flange's 1 mm bore: 0.035 mm inside).
    pub probe_lean: f64,
}

/// How much neighbouring stacks may differ ([`super::march`]).
#[derive(Clone, Copy, Debug)]
pub struct Grading {
    /// The share of the growth ratio (as an exponent) that neighbouring first heights may differ
    /// by where patches with different first heights meet, and neighbouring front sizes for the
    /// isotropic stop: a little under the ratio, as the thickness of curved fronts varies a
    /// little more than the first height.
    pub growth_share: f64,
    /// How steeply (thickness over wall distance) stacks may rise around a pit (a stack stopped
    /// with no layer). Measured on the ONERA M6's tip (H = 1e-3 D, 10 layers, growth 1.1999 /
    /// 1.2 / 1.2001; without the cone 11/12/9 core tetrahedra below 10 deg, the worst 0.95 deg,
    /// coverage 99.85%): at slope 1, 1/6/1 below 10 deg and coverage 99.42%; at 2, 3/0/0 and
    /// 99.63%; at 3, 0/0/1 (worst 9.6 deg) and 99.74%; at 4, 5/6/7 (worst 3.2 deg).
    pub pit_slope: f64,
}

/// Undoing the caps and folds of the final front ([`super::unfold`]).
#[derive(Clone, Copy, Debug)]
pub struct Unfolding {
    /// A front triangle whose largest angle is above this (degrees) is a cap...
    pub cap_angle: f64,
    /// ...and a front edge whose angle on the core's side is below this (degrees) a fold: the
    /// fill's tetrahedra at such an edge seldom all keep 10 degrees (20 here left spot 81
    /// tetrahedra below 10 degrees, 40 leaves 59; at 60 the pulled-back tops cost the flange
    /// coverage).
    pub fold_angle: f64,
    /// A fold sharper than this (degrees) leaves every core tetrahedron at its edge below the
    /// core's sliver bound ([`crate::fill::improve::SLIVER_THRESHOLD`], 10 degrees): there the
    /// tops of full stacks are pulled back too (spot, H = 1e-3 D, 10 layers: its worst core
    /// tetrahedron, 3.7 degrees on a fold of that angle between stacks of 4 and 10 prisms, goes;
    /// 20 degrees here left more slivers on the ONERA M6's wing tip).
    pub sliver_fold_angle: f64,
    /// The parts of its last step a top may be pulled back by.
    pub pull_backs: [f64; 4],
    /// Rounds over the defects (a move may make one beside it).
    pub rounds: usize,
}

/// Closing the layers against the sliding patches ([`super::sliding`]).
#[derive(Clone, Copy, Debug)]
pub struct Sliding {
    /// Interior patch vertices closer to the new boundary than this fraction of the nearest
    /// boundary edge's length are left out of the new triangulation (they would make slivers).
    pub clearance: f64,
    /// A bound on the points the refinement of a patch may add, per boundary edge.
    pub max_added_per_edge: usize,
}

/// The first layer fitted to the wall ([`super::build_layers`]).
#[derive(Clone, Copy, Debug)]
pub struct FirstLayer {
    /// Marches again at most, each with the first height fitted at more wall vertices (where
    /// stacks stopped short under a first layer too tall for the wall's facets).
    pub refits: usize,
}

impl Default for Tuning {
    /// [`TUNING`].
    fn default() -> Self {
        TUNING
    }
}

/// The tuning values the layers use.
pub const TUNING: Tuning = Tuning {
    entropy: Entropy {
        meeting_ratio: 0.25,
        same_scale: 1.01,
        meeting_heights: [1.0, 0.75, 0.5, 0.25, 0.0],
        overtaken: 0.1,
        falling_behind: 0.25,
        flat_top: 0.05,
        line_like: 0.5,
        anticipation: 1.0,
        repair_anticipation: 2.0,
        across_ridge: 0.1,
        same_wall_cosine: 0.9,
        min_bisector_sine: 0.2,
        ridge_scale: 1.1,
        closing_in: 0.5,
        sliver: 0.2,
    },
    repairs: Repairs { bends: [0.25, 0.5, 1.0], nudges: [0.1, 0.2, 0.35, 0.5] },
    adaptation: Adaptation {
        split_length: SQRT_2,
        split_lift: 0.02,
        compressed: 0.5,
        tallest_cell: 2.0,
        collapse_length: FRAC_1_SQRT_2,
        crushed_length: 0.05,
        collapse_rounds: 3,
        swap_poor_angle: 30.0,
        swap_gain: 1.25,
    },
    guard: Guard { lookahead_layers: 4, turned: FRAC_1_SQRT_2 },
    pyramids: Pyramids { apex_tries: 6 },
    gaps: Gaps {
        facing_angle_deg: 30.0,
        own_wall: 1e-3,
        climb_steps: 16.0,
        probe_tilt_deg: 20.0,
        probe_lean: 0.05,
    },
    grading: Grading { growth_share: 0.9, pit_slope: 3.0 },
    unfolding: Unfolding {
        cap_angle: 160.0,
        fold_angle: 40.0,
        sliver_fold_angle: 10.0,
        pull_backs: [0.2, 0.4, 0.6, 0.8],
        rounds: 3,
    },
    sliding: Sliding { clearance: 0.5, max_added_per_edge: 50 },
    first_layer: FirstLayer { refits: 2 },
};
