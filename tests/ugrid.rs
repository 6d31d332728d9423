//! Our UGRID files read by a small reader of their own (not the library's): the counts are the
//! MSH's of the same run, every cell has a positive volume in UGRID's node order, the cells'
//! faces match (each interior face twice, opposite, each boundary face once), and every
//! boundary face has its normal into the domain, as `src/io/ugrid.rs` says. The `.mapbc` beside
//! lists every patch with the code of its role.
//!
//! UGRID's faces here come from refine's face tables (`ref_cell.c`, `ref_cell_f2n`), whose
//! right-hand normals point into the cell, in UGRID's own node order (refine reads UGRID
//! unpermuted): an independent decomposition, not `CellKind::faces`.

use std::collections::HashMap;
use std::path::Path;
use std::process::Command;

use blmesh::config::{Config, Role};
use blmesh::io::{
    cgns::default_role, read_surface, read_volume_mesh, write_volume_mesh_with_roles, MeshFormat,
};
use blmesh::mesh::{CellKind, VolumeMesh};
use blmesh::pipeline::{run, MeshOptions};
use blmesh::progress::Progress;

mod common;

#[path = "common/shared.rs"]
mod shared;
use shared::shared_geometry;

/// Faces of the UGRID tetrahedron, pyramid (apex 2), prism and hexahedron, normals into the cell.
const INWARD_FACES: [&[&[usize]]; 4] = [
    &[&[1, 3, 2], &[0, 2, 3], &[0, 3, 1], &[0, 1, 2]],
    &[&[0, 1, 2], &[1, 4, 2], &[2, 4, 3], &[0, 2, 3], &[0, 3, 4, 1]],
    &[&[0, 3, 4, 1], &[1, 4, 5, 2], &[0, 2, 5, 3], &[0, 1, 2], &[3, 5, 4]],
    &[&[0, 4, 5, 1], &[1, 5, 6, 2], &[2, 6, 7, 3], &[0, 3, 7, 4], &[0, 1, 2, 3], &[4, 7, 6, 5]],
];
const NODES_PER_CELL: [usize; 4] = [4, 5, 6, 8];

/// A UGRID file as read: 0-based node indices.
struct Ugrid {
    points: Vec<[f64; 3]>,
    triangles: Vec<Vec<usize>>,
    quads: Vec<Vec<usize>>,
    surface_ids: Vec<i64>,
    /// Tetrahedra, pyramids, prisms, hexahedra.
    cells: [Vec<Vec<usize>>; 4],
}

/// Numbers from a `.b8` (big-endian), `.lb8` (little-endian) or ASCII UGRID file.
struct Numbers<'a> {
    bytes: &'a [u8],
    at: usize,
    big: bool,
    tokens: Option<std::str::SplitAsciiWhitespace<'a>>,
}

impl Numbers<'_> {
    fn int(&mut self) -> i64 {
        if let Some(t) = &mut self.tokens {
            return t.next().expect("a number").parse().expect("an integer");
        }
        let b: [u8; 4] = self.bytes[self.at..self.at + 4].try_into().unwrap();
        self.at += 4;
        i64::from(if self.big { i32::from_be_bytes(b) } else { i32::from_le_bytes(b) })
    }

    fn real(&mut self) -> f64 {
        if let Some(t) = &mut self.tokens {
            return t.next().expect("a number").parse().expect("a real");
        }
        let b: [u8; 8] = self.bytes[self.at..self.at + 8].try_into().unwrap();
        self.at += 8;
        if self.big {
            f64::from_be_bytes(b)
        } else {
            f64::from_le_bytes(b)
        }
    }

    fn at_end(&mut self) -> bool {
        match &mut self.tokens {
            Some(t) => t.next().is_none(),
            None => self.at == self.bytes.len(),
        }
    }
}

fn read_ugrid(path: &Path) -> Ugrid {
    let bytes = std::fs::read(path).unwrap();
    let name = path.to_str().unwrap();
    let binary = name.ends_with(".b8.ugrid") || name.ends_with(".lb8.ugrid");
    let tokens = (!binary).then(|| std::str::from_utf8(&bytes).unwrap().split_ascii_whitespace());
    let mut n = Numbers { bytes: &bytes, at: 0, big: name.ends_with(".b8.ugrid"), tokens };
    let counts: Vec<usize> = (0..7).map(|_| n.int() as usize).collect();
    let points = (0..counts[0]).map(|_| [n.real(), n.real(), n.real()]).collect();
    let mut nodes = |count: usize, per: usize| -> Vec<Vec<usize>> {
        (0..count)
            .map(|_| {
                (0..per)
                    .map(|_| {
                        let i = n.int();
                        assert!(i >= 1 && i as usize <= counts[0], "node index {i} out of 1..={}", counts[0]);
                        i as usize - 1
                    })
                    .collect()
            })
            .collect()
    };
    let triangles = nodes(counts[1], 3);
    let quads = nodes(counts[2], 4);
    let surface_ids = (0..counts[1] + counts[2]).map(|_| n.int()).collect();
    let cells = std::array::from_fn(|k| {
        let per = NODES_PER_CELL[k];
        (0..counts[3 + k])
            .map(|_| (0..per).map(|_| n.int() as usize - 1).collect::<Vec<_>>())
            .collect::<Vec<_>>()
    });
    assert!(n.at_end(), "{name}: data after the hexahedra");
    Ugrid { points, triangles, quads, surface_ids, cells }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn mean(points: &[[f64; 3]], nodes: &[usize]) -> [f64; 3] {
    let s =
        nodes.iter().fold([0.0; 3], |s, &n| [s[0] + points[n][0], s[1] + points[n][1], s[2] + points[n][2]]);
    s.map(|v| v / nodes.len() as f64)
}

/// The volume of a cell from its inward faces: the cell centroid joined to each face's
/// triangles (a quad's four triangles around its centroid), the sign flipped for inward faces.
fn cell_volume(points: &[[f64; 3]], kind: usize, cell: &[usize]) -> f64 {
    let c = mean(points, cell);
    let mut volume = 0.0;
    for face in INWARD_FACES[kind] {
        let nodes: Vec<usize> = face.iter().map(|&l| cell[l]).collect();
        let m = mean(points, &nodes);
        for i in 0..nodes.len() {
            let (a, b) = (points[nodes[i]], points[nodes[(i + 1) % nodes.len()]]);
            let (a, b, m) = (sub(a, c), sub(b, c), sub(m, c));
            // A triangle's fan around its centroid adds up to the triangle itself.
            volume -= dot(a, cross(b, m)) / 6.0;
        }
    }
    volume
}

/// A face's nodes rotated so that the smallest comes first (same cycle, same orientation).
fn canonical(face: &[usize]) -> Vec<usize> {
    let i = (0..face.len()).min_by_key(|&i| face[i]).unwrap();
    (0..face.len()).map(|k| face[(i + k) % face.len()]).collect()
}

fn reversed(face: &[usize]) -> Vec<usize> {
    canonical(&face.iter().rev().copied().collect::<Vec<_>>())
}

/// Every cell positive; interior faces used twice, opposite; each boundary face once, on a cell
/// face of the same orientation (its normal into that cell, so into the domain). The total
/// volume.
fn assert_consistent(name: &str, u: &Ugrid) -> f64 {
    let mut total = 0.0;
    let mut uses: HashMap<Vec<usize>, Vec<Vec<usize>>> = HashMap::new();
    for (kind, cells) in u.cells.iter().enumerate() {
        for cell in cells {
            let v = cell_volume(&u.points, kind, cell);
            assert!(v > 0.0, "{name}: UGRID cell kind {kind} {cell:?} has volume {v:e}");
            total += v;
            for face in INWARD_FACES[kind] {
                let nodes: Vec<usize> = face.iter().map(|&l| cell[l]).collect();
                let mut key = nodes.clone();
                key.sort_unstable();
                uses.entry(key).or_default().push(canonical(&nodes));
            }
        }
    }
    let mut boundary = 0;
    for face in u.triangles.iter().chain(&u.quads) {
        let mut key = face.clone();
        key.sort_unstable();
        let cell_faces =
            uses.remove(&key).unwrap_or_else(|| panic!("{name}: boundary face {face:?} is on no cell"));
        assert_eq!(cell_faces, [canonical(face)], "{name}: boundary face {face:?} not once, into its cell");
        boundary += 1;
    }
    for (key, faces) in &uses {
        assert_eq!(faces.len(), 2, "{name}: face {key:?} used {} times, not a boundary face", faces.len());
        assert_eq!(faces[0], reversed(&faces[1]), "{name}: face {key:?} not opposite in its two cells");
    }
    assert_eq!(boundary, u.triangles.len() + u.quads.len());
    total
}

/// The header counts and the faces per surface id equal the mesh's (or its MSH's).
fn assert_counts(name: &str, u: &Ugrid, msh: &VolumeMesh) {
    for (k, kind) in CellKind::ALL.into_iter().enumerate() {
        assert_eq!(u.cells[k].len(), msh.block(kind).len(), "{name}: {}s", kind.name());
    }
    assert_eq!(u.points.len(), msh.points.len(), "{name}: nodes");
    let b = &msh.boundary;
    assert_eq!((u.triangles.len(), u.quads.len()), (b.triangles.len(), b.quads.len()), "{name}");
    // Faces per surface id (the MSH lists its faces patch by patch, so compare counts).
    let histogram = |ids: &mut dyn Iterator<Item = i64>| {
        let mut counts = std::collections::BTreeMap::new();
        ids.for_each(|id| *counts.entry(id).or_insert(0usize) += 1);
        counts
    };
    let ours = histogram(&mut b.triangle_patch.iter().chain(&b.quad_patch).map(|&p| i64::from(p) + 1));
    assert_eq!(histogram(&mut u.surface_ids.iter().copied()), ours, "{name}: faces per surface id");
}

/// The `.mapbc` lines as (id, code, name).
fn read_mapbc(path: &Path) -> Vec<(usize, u32, String)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let count: usize = lines.next().unwrap().trim().parse().unwrap();
    let rows: Vec<(usize, u32, String)> = lines
        .map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            assert_eq!(w.len(), 3, "{l}");
            (w[0].parse().unwrap(), w[1].parse().unwrap(), w[2].to_owned())
        })
        .collect();
    assert_eq!(rows.len(), count);
    rows
}

/// Mesh `surface` with `config` (roles as the CLI gives them), write the MSH and the UGRID in
/// `encoding` of the same run, and check the UGRID against the MSH. Returns the mapbc rows.
fn check_run(name: &str, surface: &Path, config: &str, core: bool, ugrid: &str) -> Vec<(usize, u32, String)> {
    let config = Config::from_toml_str(config).unwrap();
    let surface = read_surface(surface).unwrap();
    let out = run(surface, &config, &MeshOptions { core }, Progress::hidden()).unwrap();
    let mesh = &out.mesh;
    for kind in CellKind::ALL {
        assert!(!mesh.block(kind).is_empty(), "{name} has {}s", kind.name());
    }
    let roles: Vec<Role> = mesh
        .patch_names
        .iter()
        .map(|n| match config.patch_settings(n).0 {
            Role::Wall => default_role(n),
            role => role,
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let (msh, ug) = (dir.path().join(format!("{name}.msh")), dir.path().join(ugrid));
    write_volume_mesh_with_roles(&msh, mesh, MeshFormat::Msh { ascii: false }, &roles).unwrap();
    write_volume_mesh_with_roles(&ug, mesh, MeshFormat::from_path(&ug, false).unwrap(), &roles).unwrap();
    let msh = read_volume_mesh(&msh).unwrap();
    let u = read_ugrid(&ug);
    assert_counts(name, &u, &msh);
    let volume = assert_consistent(name, &u);
    let expected = blmesh::quality::check(&msh).volume.cells;
    assert!((volume - expected).abs() <= 1e-9 * expected, "{name}: volume {volume} != {expected}");
    let mapbc = read_mapbc(&blmesh::io::ugrid::mapbc_path(&ug));
    let names: Vec<&str> = mapbc.iter().map(|(_, _, n)| n.as_str()).collect();
    assert_eq!(names, msh.patch_names, "{name}: mapbc names");
    assert!(mapbc.iter().enumerate().all(|(i, (id, _, _))| *id == i + 1), "{name}: ids 1..");
    mapbc
}

fn shared(name: &str) -> String {
    shared_geometry(name).display().to_string()
}

/// The ONERA M6 half wing on its symmetry plane (root `face9`, y = 0), 5 layers, with a core.
#[test]
fn onera_m6_ugrid_is_positive_and_faces_into_the_domain() {
    let config = "[layers]\ncount = 5\n[[patch]]\nmatch = \"face9\"\nrole = \"symmetry\"\n";
    let mapbc = check_run("m6", Path::new(&shared("onera_m6_gmsh_coarse.stl")), config, true, "m6.b8.ugrid");
    for (_, code, name) in &mapbc {
        let expected = match name.as_str() {
            "face9" => 6662,
            "farfield" => 5000,
            _ => 4000,
        };
        assert_eq!(*code, expected, "{name}");
    }
}

#[test]
fn spot_ugrid_is_positive_and_faces_into_the_domain() {
    let mapbc = check_run("spot", Path::new(&shared("spot.obj")), "", true, "spot.b8.ugrid");
    assert!(mapbc.iter().all(|(_, code, name)| *code == if name == "farfield" { 5000 } else { 4000 }));
}

/// The box's layers without core in the three encodings, and its open top (`none`) a tangency.
#[test]
fn layered_box_reads_the_same_in_every_encoding() {
    let (surface, config) = common::layered_box();
    let out = run(surface, &config, &MeshOptions { core: false }, Progress::hidden()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut volumes = Vec::new();
    for name in ["box.ugrid", "box.b8.ugrid", "box.lb8.ugrid"] {
        let path = dir.path().join(name);
        blmesh::io::write_volume_mesh(&path, &out.mesh, MeshFormat::from_path(&path, false).unwrap())
            .unwrap();
        let u = read_ugrid(&path);
        assert_counts(name, &u, &out.mesh);
        volumes.push(assert_consistent(name, &u));
    }
    assert!(volumes.iter().all(|v| (v - volumes[0]).abs() <= 1e-12 * volumes[0]), "{volumes:?}");
    let mapbc = read_mapbc(&dir.path().join("box.mapbc"));
    assert!(mapbc.iter().any(|(_, code, _)| *code == 3000), "the layers' top: {mapbc:?}");
}

/// `blmesh mesh -o x.b8.ugrid` writes the grid and `x.mapbc` with the config's roles.
#[test]
fn cli_writes_the_ugrid_and_its_mapbc() {
    let dir = tempfile::tempdir().unwrap();
    let stl = dir.path().join("box.stl");
    let (surface, _) = common::layered_box();
    let mut text = String::from("solid box\n");
    for t in &surface.triangles {
        text.push_str("facet normal 0 0 0\nouter loop\n");
        for &v in t {
            let p = surface.points[v as usize];
            text.push_str(&format!("vertex {} {} {}\n", p.x, p.y, p.z));
        }
        text.push_str("endloop\nendfacet\n");
    }
    text.push_str("endsolid box\n");
    std::fs::write(&stl, text).unwrap();
    let config = dir.path().join("box.toml");
    std::fs::write(&config, "[layers]\nfirst_height = 0.01\ngrowth = 1.2\ncount = 5\ntransition = false\n")
        .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_blmesh"))
        .args(["-q", "mesh", stl.to_str().unwrap(), "-o"])
        .arg(dir.path().join("box.b8.ugrid"))
        .arg("--config")
        .arg(&config)
        .arg("--no-core")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let u = read_ugrid(&dir.path().join("box.b8.ugrid"));
    assert_consistent("cli box", &u);
    let mapbc = read_mapbc(&dir.path().join("box.mapbc"));
    assert!(mapbc.iter().any(|(_, code, _)| *code == 4000), "{mapbc:?}");
}
