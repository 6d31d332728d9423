//! The sizing field on a real surface: exact wall distance on the bunny, sizes that follow the
//! layer law, and (ignored, run with `--release -- --ignored --nocapture`) evaluation speed.

use std::time::Instant;

use blmesh::geometry::distance::closest_point_on_triangle;
use blmesh::geometry::DVec3;
use blmesh::sizing::{SizingField, SizingSpec};
use blmesh::surface::Surface;
use rayon::prelude::*;

#[path = "common/shared.rs"]
mod shared;
use shared::shared_geometry;

fn bunny() -> Surface {
    blmesh::io::read_surface(&shared_geometry("bunny_closed_herholz.off")).expect("the bunny reads")
}

/// Deterministic pseudo-random points in the bounding box grown by `margin` on every side.
fn points_around(s: &Surface, margin: f64, n: usize) -> Vec<DVec3> {
    let b = s.bounding_box();
    let (lo, span) = (b.min - DVec3::splat(margin), b.max - b.min + DVec3::splat(2.0 * margin));
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n).map(|_| lo + span * DVec3::new(next(), next(), next())).collect()
}

fn field(s: &Surface) -> SizingField {
    let d = s.bounding_box().diagonal();
    let spec = SizingSpec {
        first_height: 1e-3 * d,
        growth: 1.2,
        max_size: 0.1 * d,
        gradation: 1.2,
        regions: vec![],
    };
    SizingField::new(s, &spec).expect("valid spec")
}

#[test]
fn bunny_wall_distance_is_exact_and_sizes_follow_the_layer_law() {
    let s = bunny();
    let f = field(&s);
    let d = s.bounding_box().diagonal();
    for p in points_around(&s, 0.2 * d, 60) {
        let near = f.wall().closest(p).unwrap();
        let brute = (0..s.triangles.len())
            .map(|t| {
                let [a, b, c] = s.triangle_points(t);
                closest_point_on_triangle(p, a, b, c).distance(p)
            })
            .fold(f64::INFINITY, f64::min);
        assert_eq!(near.distance, brute, "at {p}");
        let sizes = f.sizes(p);
        let layer_law = 1e-3 * d + 0.2 * near.distance;
        assert!(sizes.normal_size <= layer_law * (1.0 + 1e-12));
        assert!(sizes.normal_size <= sizes.tangential_size && sizes.tangential_size <= 0.1 * d);
        if layer_law < sizes.tangential_size {
            assert!((sizes.normal_size - layer_law).abs() <= 1e-12 * d);
        }
    }
}

#[test]
#[ignore]
fn bunny_evaluation_speed() {
    let s = bunny();
    let t = Instant::now();
    let f = field(&s);
    println!("bunny: {} triangles, field built in {:.3} s", s.triangles.len(), t.elapsed().as_secs_f64());
    let d = s.bounding_box().diagonal();
    let near_wall: Vec<DVec3> = points_around(&s, 0.0, 200_000)
        .into_iter()
        .map(|p| {
            let w = f.wall().closest(p).unwrap();
            w.point + f.wall().direction_from(&w, p) * (0.02 * d * (p.x * 1e3).fract().abs())
        })
        .collect();
    for (name, points) in
        [("box + 20% margin", points_around(&s, 0.2 * d, 200_000)), ("within 0.02 D of the wall", near_wall)]
    {
        let t = Instant::now();
        let sum: f64 = points.iter().map(|&p| f.metric(p).matrix().x_axis.x).sum();
        let serial = points.len() as f64 / t.elapsed().as_secs_f64();
        let t = Instant::now();
        let sum2: f64 = points.par_iter().map(|&p| f.metric(p).matrix().x_axis.x).sum();
        let parallel = points.len() as f64 / t.elapsed().as_secs_f64();
        let t = Instant::now();
        let dist: f64 = points.iter().map(|&p| f.wall().closest(p).unwrap().distance).sum();
        let closest = points.len() as f64 / t.elapsed().as_secs_f64();
        assert!(sum.is_finite() && sum2.is_finite() && dist.is_finite());
        println!(
            "{name}: metric {serial:.0}/s on 1 thread, {parallel:.0}/s on {} threads; closest point alone {closest:.0}/s",
            rayon::current_num_threads()
        );
    }
}
