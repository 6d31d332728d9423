//! Benchmark of the layer stage on the bunny with 20 layers, h0 = 1e-4 of the bounding-box
//! diagonal, r = 1.2 (target: at least 2 million layer cells per second), in three
//! set-ups: `plain` (no tangential adaptivity), `adapted` (split and collapse to the wall's
//! sizes, as `blmesh mesh` runs by default) and `refined` (to a sizing field with a refinement
//! box of size 0.004 = half the bunny's shortest wall edge over a quarter of it).
//!
//! `cargo bench --bench layers [-- CASE]` runs the stage several times and prints the median
//! time, the cells per second and the peak memory (of the process: run one case for its own);
//! under `cargo test --all-targets` the plain and adapted cases run once as a smoke test. A plain harness:
//! criterion's statistics add nothing to a half-second stage.

use std::time::{Duration, Instant};

use blmesh::config::{LayerCount, LayerSettings, LayerSpec};
use blmesh::geometry::DVec3;
use blmesh::layers::build_layers;
use blmesh::layers::split::Adapt;
use blmesh::normals::wall_normals;
use blmesh::sizing::{Region, SizingField, SizingSpec};
use blmesh::surface::features::Features;
use blmesh::surface::topology::Topology;
use blmesh::surface::validate::{validate, ValidationOptions};

#[path = "../tests/common/shared.rs"]
mod shared;

fn main() {
    let full = std::env::args().any(|a| a == "--bench");
    let runs = if full { 7 } else { 1 };
    let mut surface = blmesh::io::read_surface(&shared::shared_geometry("bunny_closed_herholz.off"))
        .expect("the bunny reads");
    validate(&mut surface, &ValidationOptions::default()).expect("the bunny is valid");
    let body_size = surface.bounding_box().diagonal();
    let topology = Topology::new(&surface);
    let features = Features::compute(&surface, &topology, 30.0);
    let normals = wall_normals(&surface, &topology, &features, 20.0);
    let settings = LayerSettings {
        first_height: Some(1e-4 * body_size),
        growth: Some(1.2),
        count: Some(LayerCount::Fixed(20)),
        thickness: None,
        transition: Some(false),
        first_aspect: None,
    };
    let spec = LayerSpec::resolve(&settings, body_size).expect("a valid layer spec");
    let patch_spec = vec![Some(spec); surface.patch_names.len()];
    let field = SizingField::new(
        &surface,
        &SizingSpec {
            first_height: spec.first_height,
            growth: spec.growth,
            max_size: body_size,
            gradation: 1.2,
            regions: vec![Region::Box {
                min: DVec3::new(-0.5, -0.5, -0.4),
                max: DVec3::new(0.0, 0.0, 0.4),
                size: 0.004,
            }],
        },
    )
    .expect("a valid sizing spec");
    let cases = [("plain", Adapt::Off), ("adapted", Adapt::Wall), ("refined", Adapt::Field(&field))];
    let wanted: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with('-')).collect();
    for (name, adapt) in cases {
        // The smoke test under `cargo test` leaves out the 20-second refined case (tests/adapt.rs
        // covers the sizing field).
        let picked =
            if wanted.is_empty() { full || name != "refined" } else { wanted.iter().any(|w| w == name) };
        if picked {
            bench(name, runs, || {
                build_layers(&surface, &topology, &normals, &patch_spec, adapt, &[], |_, _| {})
            });
        }
    }
}

/// Run `build` `runs` times and print the median time, the cells per second and the peak memory.
fn bench(name: &str, runs: usize, build: impl Fn() -> blmesh::layers::Layers) {
    let mut times: Vec<Duration> = Vec::new();
    let mut cells = 0;
    let mut splits = 0;
    for _ in 0..runs {
        let start = Instant::now();
        let layers = build();
        times.push(start.elapsed());
        cells = layers.mesh.cell_count();
        splits = layers.stats.splits;
    }
    times.sort();
    let median = times[times.len() / 2].as_secs_f64();
    let memory = blmesh::progress::peak_memory_mib().map_or("?".to_owned(), |m| format!("{m:.0} MiB"));
    println!(
        "layers/bunny-20/{name}: {cells} cells, {splits} splits, median {median:.3} s over {runs} runs \
         (min {:.3} s), {:.2} M cells/s, peak memory {memory}",
        times[0].as_secs_f64(),
        cells as f64 / median / 1e6
    );
}
