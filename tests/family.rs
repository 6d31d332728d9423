//! The randomised families of CFD-like bodies (`surface::family`): every body is a valid wall
//! surface, and a spread of seeds runs through the whole pipeline at H = 1e-3 D, growth 1.2,
//! 10 layers, the other settings at their defaults (core filled). The checker's invariants are
//! asserted on every mesh; coverage and core quality are printed as distributions, and the
//! bars today's march does not reach yet live in an ignored test.

use std::time::Instant;

use rayon::prelude::*;

use blmesh::surface::family::{family_body, family_body_at, Family};
use blmesh::surface::validate::{validate, ValidationOptions};

/// Seeds per family whose bodies must all validate.
const VALIDATED_SEEDS: u64 = 100;

#[test]
fn every_family_body_is_closed_manifold_outward_and_free_of_self_intersections() {
    for family in Family::ALL {
        let start = Instant::now();
        let mut triangles = Vec::new();
        for seed in 0..VALIDATED_SEEDS {
            let mut surface = family_body(family, seed);
            let report = validate(
                &mut surface,
                &ValidationOptions { flip_inverted_shells: false, ..Default::default() },
            )
            .unwrap_or_else(|e| panic!("{} seed {seed}: {e}", family.name()));
            assert_eq!(report.shells.len(), 1, "{} seed {seed}: one closed body", family.name());
            assert!(report.shells[0].volume > 0.0, "{} seed {seed}: outward", family.name());
            triangles.push(surface.triangles.len());
        }
        triangles.sort_unstable();
        eprintln!(
            "{}: {} bodies valid, triangles {}..{} (median {}), {:.1} s",
            family.name(),
            VALIDATED_SEEDS,
            triangles[0],
            triangles[triangles.len() - 1],
            triangles[triangles.len() / 2],
            start.elapsed().as_secs_f64()
        );
    }
}

#[test]
fn a_seed_gives_the_same_body_every_time_and_fineness_only_refines() {
    for family in Family::ALL {
        let (a, b) = (family_body(family, 7), family_body(family, 7));
        assert_eq!(a.points, b.points, "{}", family.name());
        assert_eq!(a.triangles, b.triangles, "{}", family.name());
        let fine = family_body_at(family, 7, 2.0);
        assert!(fine.triangles.len() > 2 * a.triangles.len(), "{}", family.name());
        assert_ne!(family_body(family, 8).points, a.points, "{}", family.name());
    }
}

#[path = "common/family_run.rs"]
mod family_run;

use family_run::{describe, run_seed, table, with_concave_ridges, SeedResult, Spread};

/// The CI spread: three seeds of each family (21 bodies) at a moderate tessellation.
const PIPELINE_SEEDS: u64 = 3;
/// Wall edges per length relative to the families' own: coarser, to keep the run short.
const CI_FINENESS: f64 = 0.7;

/// The CI spread through the pipeline, two bodies at a time (each run is mostly one thread:
/// the core mesher's), in family and seed order.
fn pipeline_results() -> Vec<SeedResult> {
    let start = Instant::now();
    let jobs: Vec<(Family, u64)> =
        Family::ALL.into_iter().flat_map(|f| (0..PIPELINE_SEEDS).map(move |s| (f, s))).collect();
    let results: Vec<SeedResult> = jobs
        .par_iter()
        .map(|&(family, seed)| {
            let r = run_seed(family, seed, CI_FINENESS);
            eprintln!("{}", describe(&r));
            r
        })
        .collect();
    eprintln!("{}\n{} bodies in {:.1} s", table(&results), results.len(), start.elapsed().as_secs_f64());
    results
}

#[test]
fn family_meshes_pass_the_checker_and_a_solver_on_every_seed() {
    let results = pipeline_results();
    for r in &results {
        let m = r.measures.as_ref().unwrap_or_else(|e| panic!("{} seed {}: {e}", r.family, r.seed));
        assert!(m.valid && m.conforming && m.volume_identity, "{}", describe(r));
        assert!(m.solver_rejection.is_none(), "{}: {:?}", describe(r), m.solver_rejection);
        let rounds = &m.slivers_by_round;
        assert!(
            rounds.iter().rev().skip(1).all(|&n| n > 0),
            "{}: peeling went on after a round without slivers: {rounds:?}",
            describe(r)
        );
    }
}

/// The bars the layer march is to reach on unseen bodies: near-concave coverage median at
/// least 99.5% and 5th percentile at least 98%, no core tetrahedron below 10 deg on any seed.
#[test]
#[ignore = "a target the march does not reach yet: run with --ignored"]
fn family_near_concave_coverage_and_core_dihedral_reach_the_targets() {
    let results = pipeline_results();
    let measured: Vec<_> = results.iter().filter_map(|r| r.measures.as_ref().ok()).collect();
    assert_eq!(measured.len(), results.len(), "every seed meshes");
    let coverage: Vec<f64> = with_concave_ridges(&measured).map(|m| m.near_concave_coverage).collect();
    let spread = Spread::of(&coverage, true).expect("some seeds");
    assert!(spread.median >= 0.995, "near-concave coverage median {:.2}%", 100.0 * spread.median);
    assert!(spread.p5 >= 0.98, "near-concave coverage 5th percentile {:.2}%", 100.0 * spread.p5);
    for r in &results {
        let m = r.measures.as_ref().unwrap();
        assert!(m.core_min_dihedral >= 10.0, "{}", describe(r));
    }
}
