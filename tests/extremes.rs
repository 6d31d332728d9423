//! Extreme but valid-looking surfaces through the pipeline (layers alone), in process: bodies
//! from 1e-9 to 1e9 across, placed far from the origin, with near-coincident vertices, needle
//! and cap triangles, and single coordinates at extreme magnitudes. Nothing panics; a rejection
//! names where; a plain body inside the accepted ranges meshes and passes its own check.

use blmesh::config::Config;
use blmesh::geometry::DVec3;
use blmesh::limits::MAX_COORDINATE;
use blmesh::pipeline::{run, MeshError, MeshOptions};
use blmesh::progress::Progress;
use blmesh::surface::{shapes, Surface};
use proptest::prelude::*;

fn shape(k: usize) -> Surface {
    match k {
        0 => shapes::cuboid(DVec3::new(1.0, 0.7, 0.4), 1),
        1 => shapes::icosphere(0.5, 1),
        2 => shapes::grooved_block(90.0, 1),
        _ => shapes::voxels([2, 2, 1], 0.5, 1, |i, j, _| i == 0 || j == 0),
    }
}

/// What is done to one vertex of the placed body.
#[derive(Clone, Debug)]
enum Damage {
    None,
    /// Vertex `v` moved to within `eps` (relative to the body) of vertex `w`.
    NearCoincident {
        v: usize,
        w: usize,
        eps: f64,
    },
    /// The first corner of triangle `t` moved to `1 - t_left` of the way to its second corner.
    Needle {
        t: usize,
        left: f64,
    },
    /// The third corner of triangle `t` lowered to `lift` of its height over the other two.
    Cap {
        t: usize,
        lift: f64,
    },
    /// One coordinate of vertex `v` set to `x`.
    Coordinate {
        v: usize,
        axis: usize,
        x: f64,
    },
}

fn damage() -> impl Strategy<Value = Damage> {
    let eps = (-17i32..-2).prop_map(|e| 10f64.powi(e));
    prop_oneof![
        Just(Damage::None),
        (0usize..1000, 0usize..1000, eps.clone()).prop_map(|(v, w, eps)| Damage::NearCoincident {
            v,
            w,
            eps
        }),
        (0usize..1000, eps.clone()).prop_map(|(t, left)| Damage::Needle { t, left }),
        (0usize..1000, eps).prop_map(|(t, lift)| Damage::Cap { t, lift }),
        (
            0usize..1000,
            0usize..3,
            prop_oneof![Just(1e19), Just(-1e300), Just(1e12), Just(-2e12), Just(5e-324)]
        )
            .prop_map(|(v, axis, x)| Damage::Coordinate { v, axis, x }),
    ]
}

fn apply(s: &mut Surface, damage: &Damage, size: f64) {
    let (n, m) = (s.points.len(), s.triangles.len());
    match *damage {
        Damage::None => {}
        Damage::NearCoincident { v, w, eps } => s.points[v % n] = s.points[w % n] + DVec3::splat(eps * size),
        Damage::Needle { t, left } => {
            let [a, b, _] = s.triangles[t % m].map(|v| v as usize);
            s.points[a] = s.points[b].lerp(s.points[a], left);
        }
        Damage::Cap { t, lift } => {
            let [a, b, c] = s.triangles[t % m].map(|v| v as usize);
            let mid = 0.5 * (s.points[a] + s.points[b]);
            s.points[c] = mid + lift * (s.points[c] - mid);
        }
        Damage::Coordinate { v, axis, x } => s.points[v % n][axis] = x,
    }
}

/// Words that place a rejection: in the surface, or a parameter.
fn names_a_place(e: &MeshError) -> bool {
    let text = e.to_string();
    ["triangle", "vertex", "vertices", "edge", "bounding box", "parameter", "patch"]
        .iter()
        .any(|w| text.contains(w))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn extreme_bodies_never_panic_and_rejections_say_where(
        k in 0usize..4,
        scale in -9i32..=9,
        offset in -3i32..=15,
        damage in damage(),
    ) {
        let mut s = shape(k);
        let size = 10f64.powi(scale);
        let shift = DVec3::new(1.0, -0.5, 0.25) * 10f64.powi(offset);
        s.points.iter_mut().for_each(|p| *p = *p * size + shift);
        apply(&mut s, &damage, size);
        let plain = matches!(damage, Damage::None);
        let largest = s.points.iter().map(|p| p.abs().max_element()).fold(0.0, f64::max);
        let result = run(s, &Config::default(), &MeshOptions { core: false }, Progress::new(true));
        match result {
            Ok(out) => prop_assert!(out.report.check.is_valid()),
            // A damaged body may still fail the mesh's own check: its volume identity holds to
            // 1e-9, and the round-off of needles a trillion times longer than wide exceeds that.
            Err(MeshError::InvalidResult(report)) => prop_assert!(!plain, "an invalid mesh: {report}"),
            Err(e) => {
                prop_assert!(names_a_place(&e), "unplaced rejection: {e}");
                // A plain body well inside the ranges (its coordinates within bounds, its
                // default first layer 1e-3 of its size above 1e-8 of its coordinates) must mesh.
                let inside = largest <= MAX_COORDINATE && largest < 1e4 * size;
                prop_assert!(!(plain && inside), "a plain body was rejected: {e}");
            }
        }
    }
}
