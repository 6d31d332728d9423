use super::*;
use crate::surface::shapes::icosphere;
use proptest::prelude::*;

/// One equilateral triangle of side 1 in the plane z = 0: every vertex has mean edge 1.
fn flat_wall() -> Surface {
    Surface {
        points: vec![
            DVec3::new(-0.5, 0.0, 0.0),
            DVec3::new(0.5, 0.0, 0.0),
            DVec3::new(0.0, 0.75f64.sqrt(), 0.0),
        ],
        triangles: vec![[0, 1, 2]],
        triangle_patch: vec![0],
        patch_names: vec!["wall".into()],
    }
}

fn spec(first_height: f64, growth: f64, max_size: f64) -> SizingSpec {
    SizingSpec { first_height, growth, max_size, gradation: 1.2, regions: Vec::new() }
}

#[test]
fn sizes_above_a_flat_wall_follow_the_layers_and_the_gradation() {
    let field = SizingField::new(&flat_wall(), &spec(1e-3, 1.3, 10.0)).unwrap();
    let foot = DVec3::new(0.0, 0.3, 0.0);
    for d in [0.0, 1e-3, 0.05, 1.0, 3.0, 10.0, 30.0, 60.0] {
        let s = field.sizes(foot + DVec3::Z * d);
        let tangential = (1.0 + 0.2 * d).min(10.0);
        assert!((s.tangential_size - tangential).abs() < 1e-12, "d {d}: {s:?}");
        let normal = (1e-3 + 0.3 * d).min(tangential);
        assert!((s.normal_size - normal).abs() < 1e-12, "d {d}: {s:?}");
        assert!((s.wall_distance - d).abs() < 1e-15);
        assert!(s.normal.dot(DVec3::Z).abs() > 1.0 - 1e-12);
        let m = field.metric(foot + DVec3::Z * d);
        assert!((m.size_along(DVec3::Z) - normal).abs() < 1e-9 * normal);
        assert!((m.size_along(DVec3::new(1.0, 1.0, 0.0)) - tangential).abs() < 1e-9 * tangential);
    }
}

#[test]
fn a_geometric_layer_stack_measures_about_one_in_the_normal_direction() {
    let (h0, r) = (1e-3, 1.2);
    let field = SizingField::new(&flat_wall(), &spec(h0, r, 10.0)).unwrap();
    // The continuum h_n(d) = h0 + (r - 1) d gives every layer h0 r^k the length ln(r) / (r - 1).
    let exact = r.ln() / (r - 1.0);
    let foot = DVec3::new(0.1, 0.4, 0.0);
    for k in 0..20 {
        let z = |k: i32| h0 * (r.powi(k) - 1.0) / (r - 1.0);
        let length = field.edge_length(foot + DVec3::Z * z(k), foot + DVec3::Z * z(k + 1));
        assert!((length - exact).abs() < 1e-3, "layer {k}: {length} vs {exact}");
        assert!((0.9..=1.0).contains(&length));
    }
}

#[test]
fn a_refinement_sphere_is_isotropic_inside_and_graded_outside() {
    let mut s = spec(0.01, 1.2, 2.0);
    let center = DVec3::new(10.0, 0.0, 0.0);
    s.regions.push(Region::Sphere { center, radius: 1.0, size: 0.05 });
    let field = SizingField::new(&icosphere(0.1, 1), &s).unwrap();
    for p in [center, center + DVec3::new(0.3, -0.5, 0.6), center - DVec3::X * 0.99] {
        let m = field.metric(p);
        for dir in [DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE] {
            assert!((m.size_along(dir) - 0.05).abs() < 1e-12, "{p} {dir}");
        }
    }
    for gap in [0.1, 1.0, 4.0] {
        let p = center + DVec3::X * (1.0 + gap);
        let expected = 0.05 + 0.2 * gap;
        assert!((field.normal_size(p) - expected).abs() < 1e-12);
        assert!((field.tangential_size(p) - expected).abs() < 1e-12);
    }
    // Far from everything the maximum size rules.
    assert!((field.tangential_size(DVec3::new(0.0, 100.0, 0.0)) - 2.0).abs() < 1e-12);
}

#[test]
fn box_regions_grade_from_their_boundary() {
    let mut s = spec(0.01, 1.2, 1.0);
    s.regions.push(Region::Box { min: DVec3::new(5.0, 0.0, 0.0), max: DVec3::new(6.0, 1.0, 1.0), size: 0.1 });
    let field = SizingField::new(&icosphere(0.1, 1), &s).unwrap();
    assert!((field.user_size(DVec3::new(5.5, 0.5, 0.5)) - 0.1).abs() < 1e-15);
    assert!((field.user_size(DVec3::new(7.0, 2.0, 0.5)) - (0.1 + 0.2 * 2f64.sqrt())).abs() < 1e-12);
}

#[test]
fn the_metric_is_the_intersection_of_the_wall_and_user_metrics() {
    let mut s = spec(1e-3, 1.2, 0.3);
    s.regions.push(Region::Sphere { center: DVec3::new(1.5, 0.0, 0.0), radius: 0.2, size: 0.02 });
    let field = SizingField::new(&icosphere(1.0, 2), &s).unwrap();
    for i in 0..50 {
        let p =
            DVec3::new((i as f64 * 0.37).sin() * 2.5, (i as f64 * 0.73).cos() * 2.0, (i as f64 * 0.11).sin());
        let near = field.wall().closest(p).unwrap();
        let n = field.wall().direction_from(&near, p);
        let (t1, t2) = n.any_orthonormal_pair();
        let h_t = field.wall.graded_minimum(
            p,
            &near,
            &field.wall_size,
            &field.wall_size_node_min,
            0.2,
            f64::INFINITY,
        );
        let h_n = (1e-3 + 0.2 * near.distance).min(h_t);
        let wall = Metric::from_sizes([n, t1, t2], [h_n, h_t, h_t]);
        let expected = wall.intersect(&Metric::isotropic(field.user_size(p)));
        let got = field.metric(p);
        for dir in [DVec3::X, DVec3::Y, DVec3::Z, n, t1] {
            let (a, b) = (got.size_along(dir), expected.size_along(dir));
            assert!((a - b).abs() <= 1e-8 * b, "{p}: {a} vs {b}");
        }
    }
}

#[test]
fn bad_specs_are_named() {
    let err = |s: SizingSpec| s.check().unwrap_err().to_string();
    assert!(err(spec(0.0, 1.2, 1.0)).contains("first_height"));
    assert!(err(spec(1e-3, 0.9, 1.0)).contains("growth"));
    assert!(err(spec(1e-3, 1.2, f64::NAN)).contains("max_size"));
    let mut s = spec(1e-3, 1.2, 1.0);
    s.regions.push(Region::Box { min: DVec3::ONE, max: DVec3::ZERO, size: 0.1 });
    assert!(err(s.clone()).contains("region 0"));
    assert!(SizingField::new(&flat_wall(), &s).is_err());
    let mut broken = flat_wall();
    broken.triangles[0][2] = 7;
    assert!(SizingField::new(&broken, &spec(1e-3, 1.2, 1.0)).unwrap_err().to_string().contains("triangle 0"));
}

#[test]
fn the_spec_reads_from_toml_with_a_default_gradation() {
    let text = r#"
        first_height = 1e-4
        growth = 1.15
        max_size = 0.5
        [[regions]]
        shape = "sphere"
        center = [0.0, 0.0, 1.0]
        radius = 1.1
        size = 0.02
        [[regions]]
        shape = "box"
        min = [1.0, -1.0, -1.0]
        max = [3.0, 1.0, 1.0]
        size = 0.05
    "#;
    let s: SizingSpec = toml::from_str(text).unwrap();
    assert_eq!(s.gradation, DEFAULT_GRADATION);
    assert_eq!(s.regions[0], Region::Sphere { center: DVec3::Z, radius: 1.1, size: 0.02 });
    assert_eq!(s.regions[1].size(), 0.05);
    assert!(s.check().is_ok());
    assert!(
        toml::from_str::<SizingSpec>("first_height = 1.0\ngrowth = 1.2\nmax_size = 1.0\nsizes = 2").is_err()
    );
}

#[test]
fn without_a_wall_the_user_sizing_alone_applies() {
    let field = SizingField::new(&Surface::default(), &spec(1e-3, 1.2, 0.7)).unwrap();
    let (m, iso) = (field.metric(DVec3::ONE).0, Metric::isotropic(0.7).0);
    assert!((m - iso).to_cols_array().iter().all(|d| d.abs() < 1e-12 * iso.x_axis.x), "{m:?}");
}

proptest! {
    /// Nearby points get nearby sizes: every size is the minimum of functions growing at most
    /// (r - 1), (g - 1) + the steepest wall-size gradient, per unit length.
    #[test]
    fn sizes_are_lipschitz(p in proptest::array::uniform3(-2.0f64..2.0),
                           step in proptest::array::uniform3(-0.05f64..0.05)) {
        let wall = icosphere(1.0, 2);
        let mut s = spec(1e-3, 1.3, 0.8);
        s.regions.push(Region::Sphere { center: DVec3::new(1.2, 0.0, 0.0), radius: 0.3, size: 0.01 });
        let field = SizingField::new(&wall, &s).unwrap();
        let h = wall::mean_edge_length_per_vertex(&wall.points, &wall.triangles);
        let spread = h.iter().cloned().fold(0.0, f64::max) - h.iter().cloned().fold(f64::INFINITY, f64::min);
        // The steepest linear interpolation on these near-equilateral triangles: < 2 spread / edge.
        let gradient = 2.0 * spread / 0.2;
        let lipschitz = 0.3f64.max(0.2 + gradient);
        let (a, b) = (DVec3::from_array(p), DVec3::from_array(p) + DVec3::from_array(step));
        let (sa, sb) = (field.sizes(a), field.sizes(b));
        let bound = lipschitz * (b - a).length() + 1e-12;
        prop_assert!((sa.normal_size - sb.normal_size).abs() <= bound, "{:?} {:?}", sa, sb);
        prop_assert!((sa.tangential_size - sb.tangential_size).abs() <= bound, "{:?} {:?}", sa, sb);
    }
}
