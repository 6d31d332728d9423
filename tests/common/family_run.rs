//! One body of the randomised families through the whole pipeline at the spec the families
//! are sized for (H = 1e-3 D, growth 1.2, 10 layers, everything else at its default, core
//! filled), and distributions over many seeds. Shared by tests/family.rs and benches/family.rs.

use std::time::Instant;

use blmesh::config::{Config, LayerCount, LayerSettings};
use blmesh::pipeline::{run, MeshOptions};
use blmesh::progress::Progress;
use blmesh::surface::family::{family_body_at, Family};
use serde::Serialize;

/// What one seed gave.
#[derive(Clone, Debug, Serialize)]
pub struct SeedResult {
    pub family: &'static str,
    pub seed: u64,
    pub triangles: usize,
    pub seconds: f64,
    /// The run's measures, or why it failed (an error of the pipeline, its own check included).
    pub measures: Result<Measures, String>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Measures {
    /// Wall vertices near concave ridges with their full stack (gap-limited ones count full).
    pub near_concave_coverage: f64,
    pub near_concave_vertices: usize,
    pub full_coverage: f64,
    /// Smallest dihedral angle of the core tetrahedra, degrees.
    pub core_min_dihedral: f64,
    /// The checker's verdict and the two invariants it is made of that matter most here.
    pub valid: bool,
    pub conforming: bool,
    pub volume_identity: bool,
}

/// The spec's first layer height as a fraction of the bounding-box diagonal.
const FIRST_HEIGHT_FRACTION: f64 = 1e-3;

pub fn spec_config(body_size: f64) -> Config {
    Config {
        layers: LayerSettings {
            first_height: Some(FIRST_HEIGHT_FRACTION * body_size),
            growth: Some(1.2),
            count: Some(LayerCount::Fixed(10)),
            thickness: None,
            transition: None,
            first_aspect: None,
        },
        ..Default::default()
    }
}

/// Mesh the body of `family` for `seed` at `fineness` (see `family_body_at`).
pub fn run_seed(family: Family, seed: u64, fineness: f64) -> SeedResult {
    let surface = family_body_at(family, seed, fineness);
    let triangles = surface.triangles.len();
    let config = spec_config(surface.bounding_box().diagonal());
    let start = Instant::now();
    let out = run(surface, &config, &MeshOptions { core: true }, Progress::hidden());
    let seconds = start.elapsed().as_secs_f64();
    let measures = out.map_err(|e| e.to_string()).map(|out| {
        let r = &out.report;
        Measures {
            near_concave_coverage: r.layers.near_concave_coverage,
            near_concave_vertices: r.layers.near_concave_vertices,
            full_coverage: r.layers.full_coverage,
            core_min_dihedral: r.core.as_ref().map_or(f64::NAN, |c| c.min_dihedral),
            valid: r.check.is_valid(),
            conforming: r.check.conformity.errors == 0,
            volume_identity: r.check.volume_identity_holds(),
        }
    });
    SeedResult { family: family.name(), seed, triangles, seconds, measures }
}

/// One line per seed, for the logs.
pub fn describe(r: &SeedResult) -> String {
    match &r.measures {
        Ok(m) => format!(
            "{} seed {}: {} triangles, near-concave {:.2}% of {}, full {:.2}%, core min dihedral {:.2} deg, \
             valid {}, {:.1} s",
            r.family,
            r.seed,
            r.triangles,
            100.0 * m.near_concave_coverage,
            m.near_concave_vertices,
            100.0 * m.full_coverage,
            m.core_min_dihedral,
            m.valid,
            r.seconds
        ),
        Err(e) => format!(
            "{} seed {}: {} triangles, FAILED after {:.1} s: {e}",
            r.family, r.seed, r.triangles, r.seconds
        ),
    }
}

/// Median, 5th percentile (nearest rank) and worst of `values`; `low_is_bad` says which end
/// is the worst.
#[derive(Clone, Copy, Debug)]
pub struct Spread {
    pub median: f64,
    pub p5: f64,
    pub worst: f64,
}

impl Spread {
    pub fn of(values: &[f64], low_is_bad: bool) -> Option<Spread> {
        let mut v: Vec<f64> = values.iter().copied().filter(|x| !x.is_nan()).collect();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        if !low_is_bad {
            v.reverse();
        }
        let rank = |p: f64| v[((p * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1];
        Some(Spread { median: rank(0.5), p5: rank(0.05), worst: v[0] })
    }
}

/// The measures of the seeds with wall vertices near a concave ridge: a smooth body's
/// near-concave coverage (1 by definition) says nothing.
pub fn with_concave_ridges<'a>(measured: &'a [&'a Measures]) -> impl Iterator<Item = &'a Measures> {
    measured.iter().copied().filter(|m| m.near_concave_vertices > 0)
}

/// The distributions of `results` as table rows: one per family present, then `all`.
pub fn table(results: &[SeedResult]) -> String {
    let mut families: Vec<&str> = results.iter().map(|r| r.family).collect();
    families.dedup();
    let mut out = format!(
        "{:<13} {:>5} {:>8} | {:^23} | {:^23} | {:^20} | {:^17}\n{:<13} {:>5} {:>8} | {:^23} | {:^23} | {:^20} | {:^17}\n",
        "family",
        "seeds",
        "failed",
        "near-concave cover %*",
        "full cover %",
        "core min dihedral",
        "time s",
        "",
        "",
        "/invalid",
        "median    p5     worst",
        "median    p5     worst",
        "median   p5   worst",
        "median  p95  max"
    );
    let all: Vec<&SeedResult> = results.iter().collect();
    for family in families.iter().copied().chain(["all"]) {
        let rows: Vec<&SeedResult> =
            all.iter().copied().filter(|r| family == "all" || r.family == family).collect();
        out += &row(family, &rows);
        out.push('\n');
    }
    out + "* over the seeds with wall vertices near a concave ridge\n"
}

fn row(name: &str, rows: &[&SeedResult]) -> String {
    let measured: Vec<&Measures> = rows.iter().filter_map(|r| r.measures.as_ref().ok()).collect();
    let failed = rows.len() - measured.len();
    let invalid = measured.iter().filter(|m| !m.valid).count();
    let pick = |f: fn(&Measures) -> f64| measured.iter().map(|m| f(m)).collect::<Vec<f64>>();
    let near_concave: Vec<f64> = with_concave_ridges(&measured).map(|m| m.near_concave_coverage).collect();
    let percent = |s: Option<Spread>| {
        s.map_or("-".to_owned(), |s| {
            format!("{:6.2} {:6.2} {:6.2}", 100.0 * s.median, 100.0 * s.p5, 100.0 * s.worst)
        })
    };
    let plain = |s: Option<Spread>| {
        s.map_or("-".to_owned(), |s| format!("{:5.1} {:5.1} {:5.1}", s.median, s.p5, s.worst))
    };
    let times: Vec<f64> = rows.iter().map(|r| r.seconds).collect();
    format!(
        "{:<13} {:>5} {:>4}/{:<3} | {:^23} | {:^23} | {:^20} | {:^17}",
        name,
        rows.len(),
        failed,
        invalid,
        percent(Spread::of(&near_concave, true)),
        percent(Spread::of(&pick(|m| m.full_coverage), true)),
        plain(Spread::of(&pick(|m| m.core_min_dihedral), true)),
        plain(Spread::of(&times, false)),
    )
}
