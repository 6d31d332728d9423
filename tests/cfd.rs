//! CFD set-ups: internal flow and patches without layers whose columns slide.
//! Every mesh goes through `quality::check` (inside `pipeline::run`, and again here).

use std::collections::HashSet;

use blmesh::config::Config;
use blmesh::geometry::DVec3;
use blmesh::io::read_surface;
use blmesh::mesh::VolumeMesh;
use blmesh::pipeline::{run, MeshOptions, MeshOutput};
use blmesh::progress::Progress;
use blmesh::quality;
use blmesh::surface::{shapes, Surface};

#[path = "common/shared.rs"]
mod shared;
use shared::shared_geometry;

const ELBOW: &str = "elbow_90degree_cfmesh.stl";

fn mesh(surface: &Surface, config: &str, core: bool) -> MeshOutput {
    let config = Config::from_toml_str(config).expect("a valid config");
    config.validate().expect("valid parameters");
    let out =
        run(surface.clone(), &config, &MeshOptions { core }, Progress::hidden()).expect("meshing succeeds");
    let check = quality::check(&out.mesh);
    assert!(check.is_valid(), "{check}");
    out
}

/// The nodes of the boundary faces of patch `name`.
fn patch_nodes(mesh: &VolumeMesh, name: &str) -> Vec<u32> {
    let p = mesh.patch_names.iter().position(|n| n == name).expect("the patch exists") as u32;
    let b = &mesh.boundary;
    let triangles = b.triangles.iter().zip(&b.triangle_patch).filter(|(_, &q)| q == p);
    let quads = b.quads.iter().zip(&b.quad_patch).filter(|(_, &q)| q == p);
    let mut nodes: Vec<u32> =
        triangles.flat_map(|(t, _)| t.to_vec()).chain(quads.flat_map(|(q, _)| q.to_vec())).collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

/// The number of quads of patch `name` (layer faces lying on it).
fn patch_quads(mesh: &VolumeMesh, name: &str) -> usize {
    let p = mesh.patch_names.iter().position(|n| n == name).expect("the patch exists") as u32;
    mesh.boundary.quad_patch.iter().filter(|&&q| q == p).count()
}

/// Largest distance of `nodes` from the plane `x[axis] = value`.
fn off_plane(mesh: &VolumeMesh, nodes: &[u32], axis: usize, value: f64) -> f64 {
    nodes.iter().map(|&n| (mesh.points[n as usize][axis] - value).abs()).fold(0.0, f64::max)
}

#[test]
fn elbow_internal_flow_has_layers_on_the_walls_and_planar_inlet_and_outlet() {
    let surface = read_surface(&shared_geometry(ELBOW)).expect("the elbow reads");
    let size = surface.bounding_box().diagonal();
    let config = "flow = \"internal\"\n[layers]\ncount = 5\n\
                  [[patch]]\nmatch = \"inlet.*\"\nrole = \"inlet\"\n\
                  [[patch]]\nmatch = \"outlet.*\"\nrole = \"outlet\"\n";
    let out = mesh(&surface, config, true);
    let m = &out.mesh;
    assert!(out.report.warnings.iter().all(|w| !w.contains("matches no patch")), "{:?}", out.report.warnings);
    assert!(out.report.core.is_some(), "the core is filled");
    // The inlet is the plane x = const, the outlet y = const (their input vertices are on it).
    for (name, axis) in [("inlet_S73", 0), ("outlet_S74", 1)] {
        let nodes = patch_nodes(m, name);
        let value = m.points[nodes[0] as usize][axis];
        let input_value = input_patch_vertices(&surface, name).map(|p| p[axis]).fold(value, f64::min);
        assert!((input_value - value).abs() <= 1e-12 * size, "{name} is where the input has it");
        let off = off_plane(m, &nodes, axis, value);
        assert!(off <= 1e-12 * size, "{name}: {} nodes, up to {off} off its plane", nodes.len());
        // The layers end on the patch with their faces in its plane, all round the rim.
        assert!(patch_quads(m, name) >= 5 * 150, "{name}: {} layer faces", patch_quads(m, name));
        // No layer grew from the patch: none of its input triangles is under a cell any more
        // (they are all re-triangulated around the layer faces).
        let input: HashSet<[u32; 3]> = input_patch_triangles(&surface, name).collect();
        assert!(m.boundary.triangles.iter().all(|t| !input.contains(&sorted(*t))));
    }
    let layers = &out.report.layers;
    // Sliding columns: no transition layers, and a warning says so.
    assert!(
        out.report.warnings.iter().any(|w| w.contains("no transition layers")),
        "{:?}",
        out.report.warnings
    );
    assert!(layers.layers_max == 5 && layers.layers_median == 5);
    assert!(layers.full_coverage > 0.95, "coverage {}", layers.full_coverage);
    // Internal flow: the mesh fills the pipe, whose volume the input surface encloses.
    let volume: f64 = quality::check(m).volume.cells;
    let enclosed = surface.enclosed_volume().abs();
    assert!((volume - enclosed).abs() < 1e-6 * enclosed, "mesh {volume}, pipe {enclosed}");
}

fn sorted(mut t: [u32; 3]) -> [u32; 3] {
    t.sort_unstable();
    t
}

fn input_patch_triangles<'a>(s: &'a Surface, name: &str) -> impl Iterator<Item = [u32; 3]> + 'a {
    let p = s.patch_names.iter().position(|n| n == name).expect("the patch exists") as u32;
    (0..s.triangles.len()).filter(move |&t| s.triangle_patch[t] == p).map(move |t| sorted(s.triangles[t]))
}

fn input_patch_vertices<'a>(s: &'a Surface, name: &str) -> impl Iterator<Item = DVec3> + 'a {
    input_patch_triangles(s, name).flat_map(|t| t.map(|v| s.points[v as usize]))
}

/// A duct of square section (internal flow) whose floor is a symmetry plane.
#[test]
fn a_box_with_a_symmetry_face_keeps_its_layers_on_the_plane_with_full_coverage() {
    let surface = shapes::cuboid(DVec3::new(2.0, 1.0, 0.5), 4);
    let size = surface.bounding_box().diagonal();
    let config = "flow = \"internal\"\n[layers]\ncount = 8\nfirst_height = 1e-3\n\
                  [[patch]]\nmatch = \"zmin\"\nrole = \"symmetry\"\n";
    for core in [false, true] {
        let out = mesh(&surface, config, core);
        let m = &out.mesh;
        let nodes = patch_nodes(m, "zmin");
        let off = off_plane(m, &nodes, 2, 0.0);
        assert!(off <= 1e-12 * size, "core {core}: symmetry nodes up to {off} off the plane");
        // Every wall column reached its 8 layers, those sliding on the plane too.
        assert_eq!(out.report.layers.full_coverage, 1.0, "core {core}");
        assert_eq!(out.report.layers.layers_min, 8);
        // The layer faces on the plane: 8 per segment of the floor's border (4 x 4 of them).
        assert!(patch_quads(m, "zmin") >= 8 * 4 * 4 - 8, "core {core}: {} quads", patch_quads(m, "zmin"));
    }
}

/// A box standing on a symmetry plane in an external flow: the farfield is a half box whose
/// face on the plane is triangulated around the layers sliding on it.
#[test]
fn a_box_on_a_symmetry_plane_meshes_in_a_half_box() {
    let surface = shapes::cuboid(DVec3::new(2.0, 1.0, 0.5), 4);
    let size = surface.bounding_box().diagonal();
    let config =
        "[layers]\ncount = 8\nfirst_height = 1e-3\n[[patch]]\nmatch = \"zmin\"\nrole = \"symmetry\"\n";
    let out = mesh(&surface, config, true);
    let m = &out.mesh;
    let nodes = patch_nodes(m, "zmin");
    assert!(off_plane(m, &nodes, 2, 0.0) <= 1e-12 * size);
    assert!(m.points.iter().all(|p| p.z >= 0.0), "nothing below the symmetry plane");
    assert_eq!(out.report.layers.full_coverage, 1.0);
    // The symmetry patch: the layer faces on the plane and the plane around them, out to the
    // farfield (much larger than the box's footprint).
    let extent = nodes.iter().map(|&n| m.points[n as usize].x).fold(0.0, f64::max);
    assert!(extent > 5.0 * size, "the symmetry face reaches the farfield ({extent})");
    assert!(patch_quads(m, "zmin") >= 8 * 4 * 4);
}

const ONERA_M6: &str = "onera_m6_gmsh_coarse.stl";

/// The ONERA M6 half wing on its symmetry plane (root face `face9`, y = 0), 25 layers from
/// y+ = 1 at Re = 14.6e6 on the mean aerodynamic chord (mm): the usual ONERA M6 set-up.
#[test]
fn onera_m6_half_wing_on_its_symmetry_plane() {
    let surface = read_surface(&shared_geometry(ONERA_M6)).expect("the wing reads");
    let span = surface.bounding_box().max.y - surface.bounding_box().min.y;
    let config = "[layers]\nyplus = 1.0\ncount = 25\ngrowth = 1.2\n\
                  [flow_conditions]\nreynolds = 14.6e6\nlength = 646.07\n\
                  [[patch]]\nmatch = \"face9\"\nrole = \"symmetry\"\n";
    let out = mesh(&surface, config, true);
    let m = &out.mesh;
    let nodes = patch_nodes(m, "face9");
    assert!(off_plane(m, &nodes, 1, 0.0) <= 1e-12 * span, "symmetry nodes off the plane y = 0");
    assert!(m.points.iter().all(|p| p.y >= 0.0), "nothing on the mirror side");
    let layers = &out.report.layers;
    assert!(layers.full_coverage > 0.99, "coverage {}", layers.full_coverage);
    // The columns that stop early are at the wing tip, none at the root junction.
    assert!(layers.stopped_examples.iter().all(|p| p[1] > 0.5 * span), "{:?}", layers.stopped_examples);
    // Every root vertex slid along the plane with its full stack: 25 layer faces on the plane
    // per border edge of the root face.
    let root_edges = input_patch_border_edges(&surface, "face9");
    assert!(patch_quads(m, "face9") >= 25 * (root_edges - 4), "{} layer faces", patch_quads(m, "face9"));
}

/// Border edges of patch `name` (edges used once by its triangles).
fn input_patch_border_edges(s: &Surface, name: &str) -> usize {
    let mut count = std::collections::HashMap::new();
    for t in input_patch_triangles(s, name) {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    count.values().filter(|&&n| n == 1).count()
}

/// Known bug: stacks that grow on to isotropy (`count = "auto"`, and transition
/// layers, which the pipeline turns off on sliding planes for this reason) cross each other in
/// the symmetry plane where the upper and lower fronts of the trailing edge meet at the root:
/// the core fails with "front triangle ... and wall triangle ..." (the plane's re-triangulation)
/// near x = 903-911, y = 0.3-2.2. Nothing guards the sliding plane yet.
#[test]
#[ignore = "known bug: thick stacks cross on the ONERA M6 root plane"]
fn onera_m6_half_wing_with_layers_to_isotropy() {
    let surface = read_surface(&shared_geometry(ONERA_M6)).expect("the wing reads");
    let config = "[layers]\nyplus = 1.0\ncount = \"auto\"\ngrowth = 1.2\n\
                  [flow_conditions]\nreynolds = 14.6e6\nlength = 646.07\n\
                  [[patch]]\nmatch = \"face9\"\nrole = \"symmetry\"\n";
    let out = mesh(&surface, config, true);
    assert!(out.report.core.is_some());
}

/// The elbow as an external body with 5 layers from 2e-3 of its diagonal at growth 1.15: two
/// front faces end on one triangle with opposite orientations (the cells under them meet
/// there). Kept as front, that doubled triangle made the core fill refuse its boundary as
/// self-intersecting; it is an interior face, and the mesh is whole and valid.
#[test]
fn a_front_closing_on_itself_is_no_boundary_for_the_core() {
    let surface = read_surface(&shared_geometry(ELBOW)).expect("the elbow reads");
    let h0 = 2e-3 * surface.bounding_box().diagonal();
    let out = mesh(&surface, &format!("[layers]\ncount = 5\nfirst_height = {h0}\ngrowth = 1.15\n"), true);
    assert!(out.report.core.is_some(), "a core");
}
