//! Benchmark of the Delaunay kernel (`fill::delaunay`) against TetGen's (feature `tetgen`) on
//! the same points in the same run: `cube-100k` and `cube-1m`, uniform random points in the
//! unit cube; `sphere-100k`, points on the unit sphere (normalised: cospherical up to
//! rounding); `shell-100k`, points in the shell between radii 1 and 1.01; `grid-125k`, the
//! nodes of a 50 x 50 x 50 cubic grid (every cube's corners on one sphere: every tie broken by
//! the predicates' perturbation). Target: at least half of TetGen's tetrahedra per second.
//!
//! `cargo bench --bench delaunay [-- CASE]` builds each tetrahedralisation several times and
//! prints the median time, the tetrahedra and points per second of both kernels and their
//! ratio; under `cargo test --all-targets` a 10,000-point cube runs once as a smoke test. Our
//! time covers the insertion order, the insertion and the list of finite tetrahedra; TetGen's
//! its whole call (`tetgen::delaunay_of_points`: its own order and insertion, and the copy
//! out of its output).

use std::time::{Duration, Instant};

use blmesh::fill::delaunay::Delaunay;
use blmesh::geometry::DVec3;
use blmesh::surface::family::SplitMix64;

fn main() {
    let full = std::env::args().any(|a| a == "--bench");
    let wanted: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with('-')).collect();
    let picked = |name: &str| if wanted.is_empty() { full } else { wanted.iter().any(|w| w == name) };
    if !full && wanted.is_empty() {
        compare("cube-10k", 1, &cube(10_000));
        return;
    }
    let cases = [("cube-100k", 5), ("cube-1m", 3), ("sphere-100k", 3), ("shell-100k", 5), ("grid-125k", 3)];
    for (name, runs) in cases {
        if picked(name) {
            compare(name, runs, &points_of(name));
        }
    }
}

/// The points of case `name`.
fn points_of(name: &str) -> Vec<DVec3> {
    match name {
        "cube-100k" => cube(100_000),
        "cube-1m" => cube(1_000_000),
        "sphere-100k" => shell(100_000, 0.0),
        "shell-100k" => shell(100_000, 0.01),
        _ => grid(50),
    }
}

/// The nodes of an `n` x `n` x `n` grid of unit spacing.
fn grid(n: usize) -> Vec<DVec3> {
    let axis = || (0..n).map(|i| i as f64);
    axis().flat_map(|x| axis().flat_map(move |y| axis().map(move |z| DVec3::new(x, y, z)))).collect()
}

/// `n` points uniform in the unit cube.
fn cube(n: usize) -> Vec<DVec3> {
    let mut rng = SplitMix64::new(1);
    (0..n).map(|_| DVec3::new(rng.unit(), rng.unit(), rng.unit())).collect()
}

/// `n` points with directions uniform on the unit sphere and radii uniform in `1..1 + depth`.
fn shell(n: usize, depth: f64) -> Vec<DVec3> {
    let mut rng = SplitMix64::new(2);
    let mut points = Vec::with_capacity(n);
    while points.len() < n {
        let p = DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
        if (0.1..=1.0).contains(&p.length()) {
            points.push(p.normalize() * (1.0 + depth * rng.unit()));
        }
    }
    points
}

/// Our kernel and TetGen's on `points`, `runs` times each, alternating.
fn compare(name: &str, runs: usize, points: &[DVec3]) {
    let mut ours = Timing::default();
    #[cfg_attr(not(feature = "tetgen"), allow(unused_mut))]
    let mut theirs = Timing::default();
    for _ in 0..runs {
        ours.time(|| Delaunay::new(points).expect("not flat").tets().collect::<Vec<_>>().len());
        #[cfg(feature = "tetgen")]
        theirs.time(|| blmesh::fill::tetgen::delaunay_of_points(points).expect("TetGen runs").len());
    }
    let n = points.len();
    println!("delaunay/{name}: {n} points");
    println!("  ours:   {}", ours.report(n));
    if theirs.times.is_empty() {
        println!("  TetGen: not built (feature `tetgen` off)");
        return;
    }
    println!("  TetGen: {}", theirs.report(n));
    println!("  ours / TetGen: {:.2} x the tetrahedra per second", ours.rate() / theirs.rate());
}

/// The times of one kernel's runs and the tetrahedra it made.
#[derive(Default)]
struct Timing {
    times: Vec<Duration>,
    tets: usize,
}

impl Timing {
    fn time(&mut self, build: impl FnOnce() -> usize) {
        let start = Instant::now();
        self.tets = build();
        self.times.push(start.elapsed());
        self.times.sort();
    }

    fn median(&self) -> f64 {
        self.times[self.times.len() / 2].as_secs_f64()
    }

    /// Tetrahedra per second at the median time.
    fn rate(&self) -> f64 {
        self.tets as f64 / self.median()
    }

    fn report(&self, points: usize) -> String {
        format!(
            "{} tets, median {:.3} s over {} runs (min {:.3} s), {:.2} M tets/s, {:.2} M points/s",
            self.tets,
            self.median(),
            self.times.len(),
            self.times[0].as_secs_f64(),
            self.rate() / 1e6,
            points as f64 / self.median() / 1e6
        )
    }
}
