//! Validation and feature analysis on the real test surfaces of ../shared/geometries.
//!
//! Every file there is a valid wall (closed, manifold, oriented outward, no self-intersection).
//! `every_geometry_is_valid` prints a summary table (run with `--nocapture` to see it).

use std::path::PathBuf;
use std::time::Instant;

use blmesh::io::{read_surface, SurfaceFormat};
use blmesh::surface::features::{EdgeKind, Features, VertexKind, DEFAULT_FEATURE_ANGLE_DEG};
use blmesh::surface::topology::Topology;
use blmesh::surface::validate::{validate, ValidationOptions, ValidationReport};
use blmesh::surface::Surface;

#[path = "common/shared.rs"]
mod shared;

fn geometries() -> PathBuf {
    shared::shared_dir().join("geometries")
}

fn read(name: &str) -> Surface {
    let path = geometries().join(name);
    read_surface(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Read, validate (must succeed) and analyse a surface as seen from the fluid.
fn analyse(name: &str) -> (Surface, ValidationReport, Topology, Features) {
    let mut surface = read(name);
    let report =
        validate(&mut surface, &ValidationOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"));
    if is_internal_flow(name) {
        surface.flip_all();
    }
    let topology = Topology::new(&surface);
    let features = Features::compute(&surface, &topology, DEFAULT_FEATURE_ANGLE_DEG);
    (surface, report, topology, features)
}

/// The elbow bounds the fluid (internal flow): its normals must be flipped to point into it.
fn is_internal_flow(name: &str) -> bool {
    name.starts_with("elbow")
}

fn surface_files() -> Vec<PathBuf> {
    let dir = geometries();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|entry| entry.unwrap().path())
        .filter(|path| SurfaceFormat::from_path(path).is_some())
        .collect();
    files.sort();
    files
}

#[test]
fn every_geometry_is_valid() {
    let files = surface_files();
    assert!(files.len() >= 11, "{files:?}");
    let mut failures = Vec::new();
    let mut table = String::from(
        "| file | triangles | shells | genus | convex ridge edges | concave ridge edges | \
         ridge lines cvx/ccv | corners cvx/ccv/saddle | validate ms |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for path in &files {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let mut surface = match read_surface(path) {
            Ok(s) => s,
            Err(e) => {
                failures.push(format!("{e}"));
                continue;
            }
        };
        let start = Instant::now();
        let report = match validate(&mut surface, &ValidationOptions::default()) {
            Ok(r) => r,
            Err(e) => {
                failures.push(format!("{name}: {e}"));
                continue;
            }
        };
        let ms = 1e3 * start.elapsed().as_secs_f64();
        for w in &report.warnings {
            failures.push(format!("{name}: unexpected warning (the files are oriented outward): {w}"));
        }
        if is_internal_flow(&name) {
            surface.flip_all();
        }
        let c = Features::compute(&surface, &Topology::new(&surface), DEFAULT_FEATURE_ANGLE_DEG).counts;
        let genus: Vec<String> =
            report.shells.iter().map(|s| format!("{:?}", s.genus.unwrap_or(u32::MAX))).collect();
        let flow = if is_internal_flow(&name) { " (internal)" } else { "" };
        table += &format!(
            "| {name}{flow} | {} | {} | {} | {} | {} | {}/{} | {}/{}/{} | {ms:.1} |\n",
            surface.triangles.len(),
            report.shells.len(),
            genus.join(","),
            c.convex_ridge_edges,
            c.concave_ridge_edges,
            c.convex_ridge_lines,
            c.concave_ridge_lines,
            c.convex_corners,
            c.concave_corners,
            c.saddle_corners,
        );
    }
    let build = if cfg!(debug_assertions) { "debug" } else { "release" };
    eprintln!("feature angle {DEFAULT_FEATURE_ANGLE_DEG} deg, {build} build\n{table}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn fandisk_has_the_readme_ridge_counts() {
    let (_, report, _, features) = analyse("fandisk.obj");
    assert_eq!(report.shells[0].genus, Some(0));
    let c = &features.counts;
    assert_eq!((c.convex_ridge_edges, c.concave_ridge_edges), (607, 115));
    assert!(c.convex_corners > 0 && c.saddle_corners > 0);
}

#[test]
fn cut_cube_has_three_concave_ridge_lines_meeting_at_one_concave_corner() {
    let (_, _, topology, features) = analyse("cutcube_cfmesh.stl");
    let c = &features.counts;
    assert_eq!((c.concave_ridge_edges, c.concave_ridge_lines, c.concave_corners), (3, 3, 1));
    assert_eq!(c.saddle_corners, 3, "where each concave ridge meets the outer convex edges");
    let corner = features.vertex_kind.iter().position(|&k| k == VertexKind::ConcaveCorner).unwrap() as u32;
    let mut lines_at_corner: Vec<u32> = (0..topology.edge_count())
        .filter(|&e| topology.edges[e].contains(&corner) && features.edge_kind[e] == EdgeKind::ConcaveRidge)
        .filter_map(|e| features.edge_line[e])
        .collect();
    lines_at_corner.sort_unstable();
    lines_at_corner.dedup();
    assert_eq!(lines_at_corner.len(), 3);
    for e in 0..topology.edge_count() {
        if features.edge_kind[e] == EdgeKind::ConcaveRidge {
            assert!((features.turn_deg[e] + 90.0).abs() < 1e-6, "{}", features.turn_deg[e]);
        }
    }
}

#[test]
fn flange_has_genus_four() {
    let (_, report, _, features) = analyse("flange.stl");
    assert_eq!(report.shells.len(), 1);
    assert_eq!(report.shells[0].genus, Some(4));
    assert!(features.counts.concave_ridge_edges > 0);
}

#[test]
fn building_slivers_are_valid() {
    // The README: min angle 0.14 degrees; such slivers have non-zero area and must pass.
    let (surface, report, _, features) = analyse("building_wtc2.obj");
    assert_eq!(report.shells.len(), 1);
    let info = blmesh::surface::info::SurfaceInfo::compute(&surface, DEFAULT_FEATURE_ANGLE_DEG);
    assert!(info.min_angle_deg.unwrap() < 0.2, "{info}");
    assert!(features.counts.concave_ridge_edges > 0, "stepped concave corners");
}

#[test]
fn arrow_cape_uh3d_and_stl_agree() {
    let (uh3d, _, _, a) = analyse("arrow_cape.uh3d");
    let (stl, _, _, b) = analyse("arrow_cape.stl");
    assert_eq!((uh3d.triangles.len(), uh3d.points.len()), (stl.triangles.len(), stl.points.len()));
    assert_eq!(a.counts, b.counts);
    assert!(a.counts.concave_ridge_edges > 0, "fin-body junctions");
}

#[test]
fn elbow_seen_from_inside_is_mostly_concave() {
    // Internal flow: after flipping, the pipe wall curves around the fluid (concave), and the
    // rims where inlet/outlet caps meet the pipe are concave too.
    let (_, report, _, features) = analyse("elbow_90degree_cfmesh.stl");
    assert!(report.shells[0].volume > 0.0);
    let c = &features.counts;
    assert!(c.concave_ridge_edges > c.convex_ridge_edges, "{c:?}");
}

#[test]
fn large_surfaces_validate_fast() {
    for name in ["onera_m6_gmsh_coarse.stl", "bunny_closed_herholz.off"] {
        let mut surface = read(name);
        let report = validate(&mut surface, &ValidationOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        eprintln!("{name}: {} triangles validated in {:.3} s", surface.triangles.len(), report.seconds);
        if !cfg!(debug_assertions) {
            assert!(report.seconds < 1.0, "{name}: {} s", report.seconds);
        }
    }
}
