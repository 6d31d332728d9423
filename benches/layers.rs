//! Benchmark of the layer stage on the bunny with 20 layers, h0 = 1e-4 of the bounding-box
//! diagonal, r = 1.2 (target: at least 2 million layer cells per second), in three
//! set-ups: `plain` (no tangential adaptivity), `adapted` (split and collapse to the wall's
//! sizes, as `blmesh mesh` runs by default) and `refined` (to a sizing field with a refinement
//! box of size 0.004 = half the bunny's shortest wall edge over a quarter of it); and `sphere`:
//! a sphere of 327,680 triangles with 10 layers, h0 = 1e-3 of the diagonal, r = 1.2, adapted
//! (target: at least 1 million layer cells per second, the march's throughput on a wall with
//! nothing to repair).
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
use blmesh::normals::{wall_normals, WallNormals};
use blmesh::sizing::{Region, SizingField, SizingSpec};
use blmesh::surface::features::Features;
use blmesh::surface::shapes::icosphere;
use blmesh::surface::topology::Topology;
use blmesh::surface::validate::{validate, ValidationOptions};
use blmesh::surface::Surface;

#[path = "../tests/common/shared.rs"]
mod shared;

fn main() {
    let full = std::env::args().any(|a| a == "--bench");
    let runs = if full { 7 } else { 1 };
    let wanted: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with('-')).collect();
    // The smoke test under `cargo test` leaves out the refined case (20 s; tests/adapt.rs covers
    // the sizing field) and the sphere (its mesh takes 1.5 GiB).
    let picked = |name: &str| {
        if wanted.is_empty() {
            full || !matches!(name, "refined" | "sphere")
        } else {
            wanted.iter().any(|w| w == name)
        }
    };
    let bunny = Wall::new(
        blmesh::io::read_surface(&shared::shared_geometry("bunny_closed_herholz.off"))
            .expect("the bunny reads"),
        1e-4,
        20,
    );
    let field = SizingField::new(
        &bunny.surface,
        &SizingSpec {
            first_height: bunny.spec[0].unwrap().first_height,
            growth: 1.2,
            max_size: bunny.size,
            gradation: 1.2,
            regions: vec![Region::Box {
                min: DVec3::new(-0.5, -0.5, -0.4),
                max: DVec3::new(0.0, 0.0, 0.4),
                size: 0.004,
            }],
        },
    )
    .expect("a valid sizing spec");
    for (name, adapt) in [("plain", Adapt::Off), ("adapted", Adapt::Wall), ("refined", Adapt::Field(&field))]
    {
        if picked(name) {
            bench(&format!("bunny-20/{name}"), runs, || bunny.layers(adapt));
        }
    }
    if picked("sphere") {
        let sphere = Wall::new(icosphere(1.0, 7), 1e-3, 10);
        bench("sphere-330k-10/adapted", runs, || sphere.layers(Adapt::Wall));
    }
}

/// A validated wall with its normals and one layer stack on every patch.
struct Wall {
    surface: Surface,
    topology: Topology,
    features: Features,
    normals: WallNormals,
    spec: Vec<Option<LayerSpec>>,
    size: f64,
}

impl Wall {
    /// Layers of `count` at first height `first` (of the bounding-box diagonal), r = 1.2.
    fn new(mut surface: Surface, first: f64, count: u32) -> Wall {
        validate(&mut surface, &ValidationOptions::default()).expect("a valid wall");
        let size = surface.bounding_box().diagonal();
        let topology = Topology::new(&surface);
        let features = Features::compute(&surface, &topology, 30.0);
        let normals = wall_normals(&surface, &topology, &features, 20.0);
        let settings = LayerSettings {
            first_height: Some(first * size),
            growth: Some(1.2),
            count: Some(LayerCount::Fixed(count)),
            thickness: None,
            transition: Some(false),
            first_aspect: None,
        };
        let spec = LayerSpec::resolve(&settings, size).expect("a valid layer spec");
        let spec = vec![Some(spec); surface.patch_names.len()];
        Wall { surface, topology, features, normals, spec, size }
    }

    fn layers(&self, adapt: Adapt) -> blmesh::layers::Layers {
        build_layers(
            &self.surface,
            &self.topology,
            &self.features,
            &self.normals,
            &self.spec,
            adapt,
            &[],
            &[],
            |_, _| {},
        )
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
        "layers/{name}: {cells} cells, {splits} splits, median {median:.3} s over {runs} runs \
         (min {:.3} s), {:.2} M cells/s, peak memory {memory}",
        times[0].as_secs_f64(),
        cells as f64 / median / 1e6
    );
}
