//! Concave ridges and corners: the layers never stop early where fronts meet; the
//! columns merge on the bisectors (the entropy solution) and every mesh passes the checker.

mod common;

use blmesh::config::{Config, LayerCount, LayerSettings};
use blmesh::geometry::distance::closest_point_on_triangle;
use blmesh::layers::TOP_PATCH;
use blmesh::pipeline::{run, LayerSummary, MeshOptions, MeshOutput};
use blmesh::progress::Progress;
use blmesh::surface::family::{family_body_at, Family};
use blmesh::surface::{shapes, Surface};

#[path = "common/shared.rs"]
mod shared;
use shared::shared_geometry;

/// `layers` layers growing by 1.2 from `h0`; returns the output and the total thickness.
fn mesh(surface: &Surface, h0: f64, layers: u32) -> (MeshOutput, f64) {
    let config = layered_config(h0, layers);
    let out =
        run(surface.clone(), &config, &MeshOptions { core: false }, Progress::hidden()).expect("meshes");
    (out, h0 * (1.2f64.powi(layers as i32) - 1.0) / 0.2)
}

/// `layers` layers growing by 1.2 from `h0`, no transition layers.
fn layered_config(h0: f64, layers: u32) -> Config {
    Config {
        layers: LayerSettings {
            first_height: Some(h0),
            growth: Some(1.2),
            count: Some(LayerCount::Fixed(layers)),
            thickness: None,
            transition: Some(false),
            first_aspect: None,
        },
        ..Default::default()
    }
}

/// The concave-ridge set-up on a shared geometry: 10 layers from 1e-3 of its diagonal.
fn mesh_shared(name: &str) -> MeshOutput {
    let surface = blmesh::io::read_surface(&shared_geometry(name)).expect("reads");
    let h0 = 1e-3 * surface.bounding_box().diagonal();
    mesh(&surface, h0, 10).0
}

/// Largest relative deviation of the top front's nodes from the exact offset at `thickness`.
fn offset_error(surface: &Surface, out: &MeshOutput, thickness: f64) -> f64 {
    let mesh = &out.mesh;
    let top = mesh.patch_names.iter().position(|n| n == TOP_PATCH).unwrap() as u32;
    let b = &mesh.boundary;
    let nodes = b
        .triangles
        .iter()
        .zip(&b.triangle_patch)
        .filter(|(_, &p)| p == top)
        .flat_map(|(t, _)| *t)
        .chain(b.quads.iter().zip(&b.quad_patch).filter(|(_, &p)| p == top).flat_map(|(q, _)| *q));
    nodes
        .map(|n| {
            let p = mesh.points[n as usize];
            let d = (0..surface.triangles.len())
                .map(|t| {
                    let [a, b, c] = surface.triangle_points(t);
                    (closest_point_on_triangle(p, a, b, c) - p).length()
                })
                .fold(f64::INFINITY, f64::min);
            (d - thickness).abs() / thickness
        })
        .fold(0.0, f64::max)
}

/// At least `share` of the wall vertices near concave ridges keep their full stack.
fn assert_near_concave(name: &str, layers: &LayerSummary, share: f64) {
    assert!(
        layers.near_concave_coverage >= share,
        "{name}: near-concave full stacks {:.1}% of {}, {} stopped",
        100.0 * layers.near_concave_coverage,
        layers.near_concave_vertices,
        layers.stopped_vertices
    );
}

fn assert_full_coverage(name: &str, out: &MeshOutput) {
    let r = &out.report;
    common::assert_valid_for_a_solver(name, &r.check);
    assert_eq!(
        r.layers.stopped_vertices, 0,
        "{name}: {} columns stopped early, e.g. at {:?}",
        r.layers.stopped_vertices, r.layers.stopped_examples
    );
    eprintln!(
        "{name}: {} collapses ({} tangential), {} Steiner points, {} prisms {} pyramids {} tets {} hexes",
        r.layers.march.collapses,
        r.layers.march.tangential_collapses,
        r.layers.march.steiner_points,
        r.cells.prisms,
        r.cells.pyramids,
        r.cells.tetrahedra,
        r.cells.hexahedra
    );
}

#[test]
fn l_block_layers_merge_on_the_bisector() {
    // 2 x 1 x 2 block without the (1, 0, 1) voxel: a 90-degree concave ridge along y.
    let surface = shapes::voxels([2, 1, 2], 1.0, 4, |i, _, k| !(i == 1 && k == 1));
    // Thickness ~0.58: more than two wall edges (0.25) meet at the ridge.
    let (out, t) = mesh(&surface, 0.02, 12);
    assert_full_coverage("L-block", &out);
    let march = &out.report.layers.march;
    // Merged on the bisector by the entropy rule, or earlier by the tangential collapse of the
    // compressed front (both are the same merge).
    assert!(march.collapses + march.tangential_collapses > 0, "the fronts met: columns must have merged");
    let err = offset_error(&surface, &out, t);
    assert!(err < 0.02, "top front off the exact offset by {:.2}% of the thickness", 100.0 * err);
}

#[test]
fn notched_box_layers_merge_at_the_concave_corner() {
    // A cube without one octant: three concave ridges meeting at a concave corner.
    let surface = shapes::voxels([2, 2, 2], 0.5, 4, |i, j, k| !(i == 1 && j == 1 && k == 1));
    let (out, t) = mesh(&surface, 0.01, 12);
    assert_full_coverage("notch", &out);
    let err = offset_error(&surface, &out, t);
    assert!(err < 0.02, "top front off the exact offset by {:.2}% of the thickness", 100.0 * err);
}

/// Straight concave ridges of 60, 90 and 120 degrees (wedges: a V groove in a block):
/// the fronts of the groove's walls meet on its bisector plane and keep marching, every wall
/// vertex gets its full stack, and the top front lies on the exact offset.
#[test]
fn v_grooves_of_60_90_120_degrees_keep_every_layer() {
    for opening in [60.0, 90.0, 120.0] {
        let surface = shapes::grooved_block(opening, 4);
        // 12 layers from 0.01: 0.40 thick, more than one wall edge (0.25) each side of the ridge.
        let (out, t) = mesh(&surface, 0.01, 12);
        let name = format!("{opening}-degree groove");
        assert_full_coverage(&name, &out);
        let err = offset_error(&surface, &out, t);
        eprintln!("{name}: top front off the exact offset by at most {:.2}% of the thickness", 100.0 * err);
        assert!(err < 0.02, "{name}: top front off the exact offset by {:.2}% of the thickness", 100.0 * err);
    }
}

/// The same four surfaces hold nothing a finite-volume solver would reject.
#[test]
fn cutcube_fandisk_flange_and_arrow_are_accepted_by_a_finite_volume_solver() {
    let names = ["cutcube_cfmesh.stl", "fandisk.obj", "flange.stl", "arrow_cape.stl"];
    let rejected: Vec<String> = names
        .iter()
        .filter_map(|name| {
            let check = mesh_shared(name).report.check;
            assert!(check.is_valid(), "{name}: {check}");
            check.fv.rejection().map(|why| format!("{name}: {why}\n{}", check.fv))
        })
        .collect();
    assert!(rejected.is_empty(), "{}", rejected.join("\n"));
}

/// Thin gaps: `mech_test_gapdetection.obj` has holes narrower than two stack
/// thicknesses. Their fronts stop where they meet, at the medial surface, and those stacks
/// count as full; the rest of the wall keeps its layers, and the mesh is valid.
#[test]
fn thin_gaps_stop_at_the_medial_surface() {
    let out = mesh_shared("mech_test_gapdetection.obj");
    let r = &out.report;
    common::assert_valid_for_a_solver("thin_gaps_stop_at_the_medial_surface", &r.check);
    let l = &r.layers;
    eprintln!(
        "mech: full {:.3}, {} stopped early, {} at the medial surface of a gap",
        l.full_coverage, l.stopped_vertices, l.gap_limited_vertices
    );
    assert!(l.gap_limited_vertices >= 10, "the holes' walls stop at their axes");
    assert!(l.full_coverage >= 0.85, "full stacks (or gap-limited) at {:.3} of the wall", l.full_coverage);
}

/// The cut cube, fandisk, the flange and the arrow with the concave-ridge set-up (10 layers from 1e-3 of
/// the diagonal): concave ridges that meet saddles, thin wall triangles along them, a 1 mm
/// bore, fins on a body with blunt edges. Full stacks (or limited by a thin gap) within two
/// thicknesses of a concave ridge, without transition layers: the cut cube 100% (its 4 such
/// vertices), fandisk 100%, flange 99.1%, arrow 99.4% here (flange 98.9% before the bore's
/// mouth counted as closing on its axis; arrow 98.1% before a fan whose columns merged into
/// several bisector columns could stop alone; 95.9% before a column's top could tip sideways
/// to mend a cell, fandisk 99.3%; 88.3% before columns born between two ridge corners moved at
/// the ridge's scale, not the corners'; fandisk 95.9% and flange 93.7% before a thin
/// triangle's late corner could merge early, or stop alone, to mend its cell; flange 97.3% and
/// arrow 80.1% before faces left flat along a ridge by the merges were collapsed; flange 98.2%
/// before stacks closing on the bore's axis counted as gap-limited; with the CLI's defaults,
/// transition layers on, the flange has 99.2%); valid meshes.
#[test]
fn cutcube_fandisk_flange_and_arrow_keep_their_layers_at_the_concave_ridges() {
    let cases = [
        ("cutcube_cfmesh.stl", 1.0, 1.0),
        ("fandisk.obj", 0.995, 0.998),
        ("flange.stl", 0.985, 0.985),
        ("arrow_cape.stl", 0.99, 0.995),
    ];
    for (name, near_concave, full) in cases {
        let out = mesh_shared(name);
        let r = &out.report;
        assert!(r.check.is_valid(), "{name}: {}", r.check);
        let l = &r.layers;
        eprintln!(
            "{name}: full {:.4}, near concave {:.4} of {}, {} stopped early",
            l.full_coverage, l.near_concave_coverage, l.near_concave_vertices, l.stopped_vertices
        );
        assert_near_concave(name, l, near_concave);
        assert!(l.full_coverage >= full, "{name}: full stacks at {:.4} of the wall", l.full_coverage);
    }
}

/// `surface` with the vertices inside its planar faces moved within their plane, each by up to
/// a quarter of its shortest edge in a direction fixed by its index: the wall's edges then run
/// obliquely to the ridges, as on real meshes (arrow's fin-body junctions), where faces turn
/// over at a ridge with no edge shrinking much.
fn jittered(surface: &Surface) -> Surface {
    let topology = blmesh::surface::topology::Topology::new(surface);
    let mut moved = surface.clone();
    for v in 0..surface.points.len() {
        let around = topology.vertex_triangles(v as u32);
        let n = surface.triangle_normal(around[0] as usize);
        if around.iter().any(|&t| surface.triangle_normal(t as usize).dot(n) < 1.0 - 1e-12) {
            continue;
        }
        let p = surface.points[v];
        // The lowest height of the triangles around: moving less than a quarter of it (and its
        // neighbours the same) turns none over.
        let lowest = around
            .iter()
            .map(|&t| {
                let [a, b, c] = surface.triangle_points(t as usize);
                let longest = a.distance(b).max(b.distance(c)).max(c.distance(a));
                2.0 * surface.triangle_area_vector(t as usize).length() / 2.0 / longest
            })
            .fold(f64::INFINITY, f64::min);
        let angle = (v as f64 * 2.399963).rem_euclid(std::f64::consts::TAU);
        let u = n.any_orthonormal_vector();
        let w = n.cross(u);
        moved.points[v] = p + 0.25 * lowest * (angle.cos() * u + angle.sin() * w);
    }
    moved
}

/// The 60-degree groove meshed obliquely: every stack should stay full, the top front on the
/// exact offset. Known to fail: 22 columns stop where the groove's walls meet the
/// block's ends (y = 0 and 2: fans at the lips' convex edges meeting the groove), 36 without the
/// corner rule of the entropy collapse, 26 without the merge of flat tops.
#[test]
#[ignore = "known to fail: columns stop at the ends of an obliquely meshed groove"]
fn an_obliquely_meshed_groove_keeps_every_layer() {
    let straight = shapes::grooved_block(60.0, 8);
    let surface = jittered(&straight);
    let (out, t) = mesh(&surface, 0.01, 12);
    assert_full_coverage("oblique 60-degree groove", &out);
    let err = offset_error(&surface, &out, t);
    eprintln!(
        "oblique groove: top front off the exact offset by at most {:.2}% of the thickness",
        100.0 * err
    );
    assert!(err < 0.02, "top front off the exact offset by {:.2}% of the thickness", 100.0 * err);
}

/// A step lower than the layers are thick: the riser's fronts are overtaken by the
/// floor's and the top's (a fin's trailing edge standing near the body's end on the arrow). Its
/// columns merge into the columns on time (the first-arrival rule over the whole wall); at its
/// ends, saddle corners where the riser meets the side walls, the corner's fan and the foot's
/// bisector column converge and merge to keep their cell valid. Every stack reaches its
/// thickness, on the exact offset.
#[test]
fn a_step_lower_than_the_layers_are_thick_keeps_every_layer() {
    // 2 x 1 x 1.25 block without the top fifth of its right half: a step 0.25 high.
    let surface = shapes::voxels([8, 4, 5], 0.25, 1, |i, _, k| !(i >= 4 && k == 4));
    // 12 layers from 0.01: 0.40 thick, more than the step is high.
    let (out, t) = mesh(&surface, 0.01, 12);
    assert_full_coverage("step", &out);
    let err = offset_error(&surface, &out, t);
    assert!(err < 0.02, "top front off the exact offset by {:.2}% of the thickness", 100.0 * err);
}

/// A slot narrower than two stacks: the fronts of its side walls meet head on at its medial
/// plane. They stop a layer short of it, so the core between them is two layers high and not
/// a slab of any thinness; those stacks count as gap-limited, and the core has no sliver.
#[test]
fn fronts_meeting_across_a_slot_leave_the_core_a_gap_it_can_fill() {
    // A 3 x 1 x 2 block with a slot of width 1 and depth 1 across the middle of its top; 12
    // layers from 0.02 are 0.79 thick, more than the slot's half-width.
    let surface = shapes::voxels([3, 1, 2], 1.0, 4, |i, _, k| !(i == 1 && k == 1));
    let (layered, _) = mesh(&surface, 0.02, 12);
    let r = &layered.report;
    common::assert_valid_for_a_solver("slot", &r.check);
    assert!(r.layers.gap_limited_vertices >= 20, "{} gap-limited vertices", r.layers.gap_limited_vertices);
    // Above the slot's bottom corners' bisectors (which are the columns' own: they merge on
    // them), the slot's medial surface is the plane x = 1.5; the side walls' tops stay clear
    // of it by more than a first layer.
    let mesh = &layered.mesh;
    let top = mesh.patch_names.iter().position(|n| n == TOP_PATCH).unwrap() as u32;
    let b = &mesh.boundary;
    let nodes = b.triangles.iter().zip(&b.triangle_patch).filter(|(_, &p)| p == top).flat_map(|(t, _)| *t);
    let quads = b.quads.iter().zip(&b.quad_patch).filter(|(_, &p)| p == top).flat_map(|(q, _)| *q);
    let closest = nodes
        .chain(quads)
        .map(|n| mesh.points[n as usize])
        .filter(|p| p.z > 1.6 && p.z < 2.0 && p.x > 1.0 && p.x < 2.0)
        .map(|p| (p.x - 1.5).abs())
        .fold(f64::INFINITY, f64::min);
    assert!(closest > 0.02, "a front in the slot within {closest:.4} of its medial plane");
    let config = layered_config(0.02, 12);
    let out = run(surface, &config, &MeshOptions { core: true }, Progress::hidden()).expect("meshes");
    common::assert_valid_for_a_solver("slot with its core", &out.report.check);
    let core = out.report.core.as_ref().expect("a core");
    assert!(core.min_dihedral >= 10.0, "core minimum dihedral {:.2} deg", core.min_dihedral);
}

/// The layers alone of a body of the randomised family at the families' spec (10 layers from
/// 1e-3 of its diagonal, growth 1.2, the default transition layers).
fn family_layers(family: Family, seed: u64) -> MeshOutput {
    family_run(family, seed, false)
}

/// The layers alone of a body of the randomised family ([`family_layers`]) pass the solver check
/// and keep at least `share` of the wall vertices near concave ridges with their full stack.
fn assert_family_layers_keep(family: Family, seed: u64, share: f64) {
    let name = format!("family {} {seed}", family.name());
    let out = family_layers(family, seed);
    common::assert_valid_for_a_solver(&name, &out.report.check);
    assert_near_concave(&name, &out.report.layers, share);
}

/// A body of the randomised families at their spec (10 layers from 1e-3 of its diagonal,
/// growth 1.2, transition layers), with its core or layers only.
fn family_run(family: Family, seed: u64, core: bool) -> MeshOutput {
    let surface = family_body_at(family, seed, 1.0);
    let h0 = 1e-3 * surface.bounding_box().diagonal();
    let mut config = layered_config(h0, 10);
    config.layers.transition = None;
    run(surface, &config, &MeshOptions { core }, Progress::hidden()).expect("meshes")
}

/// A groove of the randomised family (seed 2: 71 degrees, oblique to the block, one triangle
/// from lip to bottom) at the families' spec: at layer 10 the walls' fronts have shrunk to a
/// quarter of their width and the tangential collapses merged lip and bisector columns, which
/// turned the lips' fans over one another and stopped 43 stacks. A collapse whose columns the
/// slab then stops because the front crosses itself is taken back.
#[test]
fn tangential_collapses_never_cost_a_groove_its_layers() {
    let out = family_layers(Family::Grooves, 2);
    assert!(out.report.layers.march.tangential_collapses > 0, "the groove's fronts must coarsen");
    assert_full_coverage("family groove 2", &out);
}

/// A groove of the randomised family (seed 15: oblique to the block, its mouth narrower than
/// the layers are thick) at the families' spec, layers only: the walls' fronts merge into the
/// bisector, which reaches the mouth as the lips' fans meet over it. Each lip's fan strip then
/// rises from the crease the merges left, and the two close a V over it, a cusp of the exact
/// front; the pyramids the core would stand on the strips' quads cross, and stopping both
/// strips' columns left 37.2% of the vertices near the groove's bottom with their full stack.
/// The V's columns merge into the crease instead.
#[test]
fn lip_fans_meeting_over_a_filled_groove_merge_into_its_crease() {
    assert_family_layers_keep(Family::Grooves, 15, 0.7);
}

/// A groove of the randomised family (seed 11: 45 degrees, its mouth narrower than the layers
/// are thick) at the families' spec, layers only: the lips' fans close a V over the crease the
/// walls' merges left along the whole groove in one layer. Merged pair by pair, each raise of
/// the crease stepped it up beside the next pair's, whose cell turned over, and every lip's
/// stack stopped: 20.9% of the vertices near the bottom kept their full stack. The V closes
/// along its crease at once.
#[test]
fn a_v_closing_along_a_groove_closes_at_once() {
    assert_family_layers_keep(Family::Grooves, 11, 0.8);
}

/// A groove of the randomised family (seed 0: 30 degrees, oblique to the block) at the
/// families' spec, layers only: beside the bisector columns, a triangle on each wall whose far
/// corner passed the bisector with no collapse; the two share that column and no edge, and
/// their tops cross. The corner of each nearest the other meets at the shared column, where
/// stopping both left 70.8% of the vertices near the bottom with their full stack.
#[test]
fn two_triangles_crossing_at_a_bisector_column_meet_there() {
    assert_family_layers_keep(Family::Grooves, 0, 0.8);
}

/// A wing on a plate of the randomised family (seed 0: its trailing edge leans over the plate
/// behind the root) at the families' spec, layers only: the trailing edge's fan, turned down
/// towards the plate near the root, meets the plate's front head on. The fan's columns that the
/// plate's front reached first merge into their fan mates and the fan goes on above them;
/// stopping both fronts' columns there left 71.7% of the vertices near the root with their full
/// stack.
#[test]
fn a_trailing_edge_fan_over_the_plate_retreats_where_the_plate_front_meets_it() {
    assert_family_layers_keep(Family::WingPlate, 0, 0.78);
}

/// A wing on a plate of the randomised family (seed 2) at the families' spec, layers only: where
/// the plate's and the wing's face columns merge into the root's, faces end up with their three
/// columns along the root, slivers lying in the front's crease that pinch it; they are swapped
/// with their neighbours like the pairs a split makes. Without those swaps 31 stacks stop and
/// 68.9% of the vertices near the root keep their full stack; the stacks that still stop are at
/// the trailing edge's root.
#[test]
fn slivers_that_merges_leave_along_a_wing_root_are_swapped_away() {
    let surface = family_body_at(Family::WingPlate, 2, 1.0);
    let h0 = 1e-3 * surface.bounding_box().diagonal();
    let out = run(surface, &layered_config(h0, 10), &MeshOptions { core: false }, Progress::hidden())
        .expect("meshes");
    let layers = &out.report.layers;
    common::assert_valid_for_a_solver("family wing-plate 2", &out.report.check);
    assert!(layers.march.swaps > 0, "the root's slivers must be swapped");
    assert_near_concave("family wing-plate 2", layers, 0.8);
}

/// A post on a plate of the randomised family (seed 0) at the families' spec, at the defaults
/// with its core: where the plate's and the post's face columns merge into the foot's, faces end
/// with their three columns on the foot, slivers lying in the front's crease; they are turned
/// in the slab whose merges made them. Without the turns the crease is pinched to 45 deg, the
/// core meets it with slivers, and peeling leaves 44.9% of the vertices near the foot with
/// their full stack.
#[test]
fn slivers_that_merges_leave_at_a_post_foot_are_turned_in_their_slab() {
    let out = family_run(Family::PostPlate, 0, true);
    let report = &out.report;
    common::assert_valid_for_a_solver("family post-plate 0", &report.check);
    assert!(report.layers.march.swaps > 0, "the foot's slivers must be turned");
    assert_near_concave("family post-plate 0", &report.layers, 0.95);
    let core = report.core.as_ref().expect("a core");
    assert!(core.min_dihedral >= 10.0, "core minimum dihedral {:.2} deg", core.min_dihedral);
}

/// A post on a plate of the randomised family (seed 15) at the families' spec, at the defaults
/// with its core: the plate's and the post's face columns converge on the foot's bisector, and
/// one about to reach it has its top nearly on the line of two crease columns that did, a cap
/// of the front. Left on the final front, every core tetrahedron on it is a sliver, and peeling
/// lowered the stacks there: 58.0% of the vertices near the foot kept their full stack, after
/// three rounds. Such a column merges into the crease a step early instead, and the core needs
/// no peeling.
#[test]
fn caps_on_a_post_foots_crease_merge_into_it() {
    let out = family_run(Family::PostPlate, 15, true);
    let report = &out.report;
    common::assert_valid_for_a_solver("family post-plate 15", &report.check);
    assert_eq!(report.peel.slivers_by_round.first(), Some(&0), "core slivers before any peeling");
    assert_near_concave("family post-plate 15", &report.layers, 0.85);
    let core = report.core.as_ref().expect("a core");
    assert!(core.min_dihedral >= 10.0, "core minimum dihedral {:.2} deg", core.min_dihedral);
}

/// A post on a plate of the randomised family (seed 5) at the families' spec with its core:
/// the first round leaves core slivers (4) on the front; peeling pulls those tops back along
/// their last step, which mends them with every stack keeping its layers.
#[test]
fn peeling_pulls_tops_back_before_it_lowers_stacks() {
    let out = family_run(Family::PostPlate, 5, true);
    let report = &out.report;
    common::assert_valid_for_a_solver("family post-plate 5", &report.check);
    assert!(report.peel.slivers_by_round.first().is_some_and(|&n| n > 0), "slivers before peeling");
    assert!(report.peel.kept_round > 0, "a peeled round is kept");
    assert_eq!(report.peel.capped_vertices, 0, "no stack lowered");
    assert_near_concave("family post-plate 5", &report.layers, 0.95);
    let core = report.core.as_ref().expect("a core");
    assert!(core.min_dihedral >= 10.0, "core minimum dihedral {:.2} deg", core.min_dihedral);
}

/// A fin on a cylinder of the randomised family (seed 24) at the families' spec, layers only:
/// in a transition layer the merges along the fin's root leave a cap whose pair is turned in
/// its slab, after the slab's crossing guard tested it; the turned triangles crossed the tops
/// beside them and the front handed to the core crossed itself (the run failed its own check).
/// A turn that would cross the tops around it is not made.
#[test]
fn a_turn_in_a_merging_slab_never_crosses_the_front_around_it() {
    let out = family_layers(Family::FinCylinder, 24);
    common::assert_valid_for_a_solver("family fin-cylinder 24", &out.report.check);
}

/// A wing on a plate of the randomised family (seed 7: its trailing edge leans sideways over
/// the plate) at the families' spec, layers only: at the trailing edge's root the plate's
/// columns that the trailing edge's front overtakes merge into the root's crease columns, and
/// where the front then crossed itself, stopping both crossing faces' columns stopped the
/// roots of those merges and every column merged into the crease: 84.1% of the vertices near
/// the root kept their full stack. The one stop among the faces' roots and fans that uncrosses
/// them with the fewest wall points is taken instead.
#[test]
fn a_crossing_of_the_front_stops_the_fewest_columns() {
    assert_family_layers_keep(Family::WingPlate, 7, 0.88);
}
