//! Benchmark of the whole pipeline over the randomised families of CFD-like bodies
//! (`blmesh::surface::family`) at H = 1e-3 D, growth 1.2, 10 layers, the rest at its defaults:
//! distributions over many seeds, never one lucky mesh.
//!
//! `cargo bench --features cgns --bench family [-- FAMILY...]` meshes `FAMILY_SEEDS` seeds
//! (default 200) spread round-robin over the families (or those named), prints a line per seed
//! and a table per family and overall (median, 5th percentile and worst of the near-concave
//! and full coverage, the core's smallest dihedral angle and the time; failed runs and invalid
//! meshes counted), and writes every seed's result as JSON to `FAMILY_JSON` when set, so runs
//! can be compared. `FAMILY_FINENESS` (default 1) refines the bodies' walls. Under
//! `cargo test --all-targets` one seed of each family runs as a smoke test.

#[path = "../tests/common/family_run.rs"]
mod family_run;

use blmesh::surface::family::Family;
use family_run::{describe, run_seed, table};

/// Seeds a full run meshes unless `FAMILY_SEEDS` says otherwise.
const DEFAULT_SEEDS: usize = 200;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let full = std::env::args().any(|a| a == "--bench");
    let env_number = |name: &str| std::env::var(name).ok().map(|v| v.parse::<f64>()).transpose();
    let wanted: Vec<Family> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .map(|a| Family::from_name(&a).ok_or(format!("no family {a}")))
        .collect::<Result<_, _>>()?;
    let families = if wanted.is_empty() { Family::ALL.to_vec() } else { wanted };
    let seeds = match env_number("FAMILY_SEEDS")? {
        Some(n) => n as usize,
        None if full => DEFAULT_SEEDS,
        None => families.len(),
    };
    let fineness = env_number("FAMILY_FINENESS")?.unwrap_or(1.0);
    let mut results = Vec::with_capacity(seeds);
    for k in 0..seeds {
        let family = families[k % families.len()];
        let r = run_seed(family, (k / families.len()) as u64, fineness);
        println!("{}", describe(&r));
        results.push(r);
    }
    results.sort_by_key(|r| (Family::from_name(r.family).map(|f| f as usize), r.seed));
    println!("\n{}", table(&results));
    if let Ok(path) = std::env::var("FAMILY_JSON") {
        std::fs::write(&path, serde_json::to_string_pretty(&results)?)?;
        println!("per-seed results written to {path}");
    }
    Ok(())
}
