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
    /// What a finite-volume solver would reject (a wrong face pyramid, a face at 90 degrees
    /// non-orthogonality or more), if anything.
    pub solver_rejection: Option<String>,
    /// The checker's finite-volume figures over the interior faces (non-orthogonality in
    /// degrees), and what the wall's own triangulation gives the prisms' lateral faces.
    pub non_orthogonality_max: f64,
    pub faces_above_70_share: f64,
    pub faces_above_85: usize,
    pub skewness_max: f64,
    pub wall_edges_above_70: usize,
    pub wall_edges_above_85: usize,
    /// Core tetrahedra below 10 deg after each peeling round (the first is the plain march's).
    pub slivers_by_round: Vec<usize>,
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
        let (fv, wall) = (&r.check.fv, &r.input.wall_non_orthogonality);
        Measures {
            near_concave_coverage: r.layers.near_concave_coverage,
            near_concave_vertices: r.layers.near_concave_vertices,
            full_coverage: r.layers.full_coverage,
            core_min_dihedral: r.core.as_ref().map_or(f64::NAN, |c| c.min_dihedral),
            valid: r.check.is_valid(),
            conforming: r.check.conformity.errors == 0,
            volume_identity: r.check.volume_identity_holds(),
            solver_rejection: fv.rejection(),
            non_orthogonality_max: fv.non_orthogonality_max,
            faces_above_70_share: fv.faces_above_70 as f64 / fv.interior_faces.max(1) as f64,
            faces_above_85: fv.faces_above_85,
            skewness_max: fv.skewness_max,
            wall_edges_above_70: wall.edges_above_70,
            wall_edges_above_85: wall.edges_above_85,
            slivers_by_round: r.peel.slivers_by_round.clone(),
        }
    });
    SeedResult { family: family.name(), seed, triangles, seconds, measures }
}

/// One line per seed, for the logs.
pub fn describe(r: &SeedResult) -> String {
    match &r.measures {
        Ok(m) => format!(
            "{} seed {}: {} triangles, near-concave {:.2}% of {}, full {:.2}%, core min dihedral {:.2} deg, \
             valid {}, non-orthogonality max {:.1} deg ({} faces above 85, wall edges above 85: {}), {:.1} s",
            r.family,
            r.seed,
            r.triangles,
            100.0 * m.near_concave_coverage,
            m.near_concave_vertices,
            100.0 * m.full_coverage,
            m.core_min_dihedral,
            m.valid,
            m.non_orthogonality_max,
            m.faces_above_85,
            m.wall_edges_above_85,
            r.seconds
        ),
        Err(e) => format!(
            "{} seed {}: {} triangles, FAILED after {:.1} s: {e}",
            r.family, r.seed, r.triangles, r.seconds
        ),
    }
}

/// Median, 5th percentile (nearest rank) and worst of `values`; `low_is_bad` says which end
/// is the worst (when high is bad, `p5` is the 95th percentile).
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
    out += "* over the seeds with wall vertices near a concave ridge\n\n";
    out + &fv_table(&families, &all)
}

/// The finite-volume figures of `results` as a table: one row per family, then `all`.
fn fv_table(families: &[&str], all: &[&SeedResult]) -> String {
    let mut out = format!(
        "{:<13} | {:^17} | {:^20} | {:^17} | {:^17} | {:^17} | {}\n{:<13} | {:^17} | {:^20} | {:^17} | {:^17} | {:^17} |\n",
        "family",
        "non-orth max deg",
        "faces above 70 %",
        "faces above 85",
        "skewness max",
        "wall edges > 85 *",
        "rejected **",
        "",
        "median  p95  max",
        "median   p95    max",
        "median  p95  max",
        "median  p95  max",
        "median  p95  max",
    );
    for family in families.iter().copied().chain(["all"]) {
        let rows: Vec<&SeedResult> =
            all.iter().copied().filter(|r| family == "all" || r.family == family).collect();
        out += &fv_row(family, &rows);
        out.push('\n');
    }
    out + "* the wall's own triangulation makes the prisms' lateral faces over these edges above 85 deg\n\
           ** meshes a finite-volume solver rejects (a wrong face pyramid, a face at 90 deg or more)\n"
}

fn fv_row(name: &str, rows: &[&SeedResult]) -> String {
    let measured: Vec<&Measures> = rows.iter().filter_map(|r| r.measures.as_ref().ok()).collect();
    let pick = |f: fn(&Measures) -> f64| measured.iter().map(|m| f(m)).collect::<Vec<f64>>();
    let spread = |values: Vec<f64>, scale: f64, width: usize, digits: usize| {
        Spread::of(&values, false).map_or("-".to_owned(), |s| {
            let cell = |x: f64| format!("{:>width$.digits$}", scale * x);
            format!("{} {} {}", cell(s.median), cell(s.p5), cell(s.worst))
        })
    };
    let rejected = measured.iter().filter(|m| m.solver_rejection.is_some()).count();
    format!(
        "{:<13} | {:^17} | {:^20} | {:^17} | {:^17} | {:^17} | {}",
        name,
        spread(pick(|m| m.non_orthogonality_max), 1.0, 5, 1),
        spread(pick(|m| m.faces_above_70_share), 100.0, 6, 3),
        spread(pick(|m| m.faces_above_85 as f64), 1.0, 5, 0),
        spread(pick(|m| m.skewness_max), 1.0, 5, 2),
        spread(pick(|m| m.wall_edges_above_85 as f64), 1.0, 5, 0),
        rejected,
    )
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
