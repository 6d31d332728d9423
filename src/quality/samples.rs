//! Reference meshes built in code, for tests of the checker, the writers and the readers.
//!
//! [`cube_grid`] fills a box with unit cubes (scaled by `spacing`), each cut into cells of the kind
//! asked for. Faces are decided first, from a rule that looks only at the two cubes sharing the
//! face, so neighbours always agree: a face is a quad when both cubes want a quad there, else it
//! is cut into two triangles along the diagonal through its lowest and highest grid corners (the
//! diagonal the 6-tetrahedra Kuhn cut uses). A cube whose faces do not fit the cut it asked for is
//! cut from its centre instead: a pyramid on every quad face, two tetrahedra on every cut face.

use crate::geometry::{tet_signed_volume, DVec3};
use crate::mesh::{CellKind, VolumeMesh};

/// How a cube of a [`cube_grid`] is cut into cells.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CubeSplit {
    Hexahedron,
    /// Six tetrahedra around the main diagonal (Kuhn).
    Tetrahedra,
    /// Two prisms extruded along z.
    Prisms,
    /// Pyramids and tetrahedra from the cube centre (fits any face shapes).
    Centre,
}

impl CubeSplit {
    pub const ALL: [CubeSplit; 4] =
        [CubeSplit::Hexahedron, CubeSplit::Tetrahedra, CubeSplit::Prisms, CubeSplit::Centre];

    fn wants_quad(self, axis: usize) -> bool {
        match self {
            CubeSplit::Hexahedron | CubeSplit::Centre => true,
            CubeSplit::Tetrahedra => false,
            CubeSplit::Prisms => axis != 2,
        }
    }
}

/// Patch names of the six sides of a [`cube_grid`], in patch index order.
pub const SIDES: [&str; 6] = ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"];

/// (axis, side) of the outward faces of a hexahedron, in [`CellKind::faces`] order.
const HEX_FACE_SIDES: [(usize, usize); 6] = [(2, 0), (2, 1), (1, 0), (0, 1), (1, 1), (0, 0)];

/// Kuhn's six tetrahedra: paths 0 -> a -> b -> 6 along cube edges.
const KUHN_PATHS: [(usize, usize); 6] = [(1, 2), (1, 5), (3, 2), (3, 7), (4, 5), (4, 7)];

struct Grid<'a> {
    dims: [usize; 3],
    split: &'a dyn Fn([usize; 3]) -> CubeSplit,
}

impl Grid<'_> {
    fn point_index(&self, [i, j, k]: [usize; 3]) -> u32 {
        let [nx, ny, _] = self.dims;
        (i + (nx + 1) * (j + (ny + 1) * k)) as u32
    }

    /// Hexahedron nodes of cube `c`.
    fn cube_nodes(&self, [i, j, k]: [usize; 3]) -> [u32; 8] {
        let corner = |a, b, c| self.point_index([i + a, j + b, k + c]);
        [
            corner(0, 0, 0),
            corner(1, 0, 0),
            corner(1, 1, 0),
            corner(0, 1, 0),
            corner(0, 0, 1),
            corner(1, 0, 1),
            corner(1, 1, 1),
            corner(0, 1, 1),
        ]
    }

    /// The cube across face (axis, side), if inside the grid.
    fn neighbour(&self, c: [usize; 3], (axis, side): (usize, usize)) -> Option<[usize; 3]> {
        let mut n = c;
        n[axis] = if side == 0 { c[axis].checked_sub(1)? } else { c[axis] + 1 };
        (n[axis] < self.dims[axis]).then_some(n)
    }

    fn face_is_quad(&self, c: [usize; 3], face: (usize, usize)) -> bool {
        let axis = face.0;
        (self.split)(c).wants_quad(axis)
            && self.neighbour(c, face).is_none_or(|n| (self.split)(n).wants_quad(axis))
    }

    /// The cut actually used for cube `c`: the one asked for if its faces fit, else `Centre`.
    fn actual_split(&self, c: [usize; 3]) -> CubeSplit {
        let wanted = (self.split)(c);
        let fits = HEX_FACE_SIDES.iter().all(|&f| self.face_is_quad(c, f) == wanted.wants_quad(f.0));
        if fits {
            wanted
        } else {
            CubeSplit::Centre
        }
    }
}

/// The two triangles of a quad cut along the diagonal through its lowest-numbered node
/// (grid numbering grows with every coordinate, so that is the face's lowest corner).
fn cut_quad(q: [u32; 4]) -> [[u32; 3]; 2] {
    let m = (0..4).min_by_key(|&i| q[i]).unwrap_or(0);
    let at = |k: usize| q[(m + k) % 4];
    [[at(0), at(1), at(2)], [at(0), at(2), at(3)]]
}

/// A cube grid of `dims` cubes of size `spacing`, cut as `split` asks, cells in zone `zone`;
/// boundary faces on the six sides in patches [`SIDES`]. Every cell is positive.
pub fn cube_grid(
    dims: [usize; 3],
    spacing: DVec3,
    split: &dyn Fn([usize; 3]) -> CubeSplit,
    zone: &dyn Fn([usize; 3]) -> u32,
) -> VolumeMesh {
    let grid = Grid { dims, split };
    let mut mesh = VolumeMesh::default();
    for k in 0..=dims[2] {
        for j in 0..=dims[1] {
            for i in 0..=dims[0] {
                mesh.points.push(DVec3::new(i as f64, j as f64, k as f64) * spacing);
            }
        }
    }
    mesh.patch_names = SIDES.iter().map(|s| s.to_string()).collect();
    let mut zones = 0;
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let c = [i, j, k];
                zones = zones.max(zone(c) + 1);
                add_cube(&grid, c, zone(c), &mut mesh);
            }
        }
    }
    mesh.zone_names = (0..zones).map(|z| format!("zone_{z}")).collect();
    mesh
}

fn add_cube(grid: &Grid, c: [usize; 3], zone: u32, mesh: &mut VolumeMesh) {
    let h = grid.cube_nodes(c);
    let faces = CellKind::Hexahedron.faces();
    for (f, &side) in faces.iter().zip(HEX_FACE_SIDES.iter()) {
        if grid.neighbour(c, side).is_none() {
            let q = [h[f[0]], h[f[1]], h[f[2]], h[f[3]]];
            let patch = (2 * side.0 + side.1) as u32;
            if grid.face_is_quad(c, side) {
                mesh.boundary.quads.push(q);
                mesh.boundary.quad_patch.push(patch);
            } else {
                for t in cut_quad(q) {
                    mesh.boundary.triangles.push(t);
                    mesh.boundary.triangle_patch.push(patch);
                }
            }
        }
    }
    match grid.actual_split(c) {
        CubeSplit::Hexahedron => mesh.push_cell(CellKind::Hexahedron, &h, zone),
        CubeSplit::Prisms => {
            mesh.push_cell(CellKind::Prism, &[h[0], h[1], h[2], h[4], h[5], h[6]], zone);
            mesh.push_cell(CellKind::Prism, &[h[0], h[2], h[3], h[4], h[6], h[7]], zone);
        }
        CubeSplit::Tetrahedra => {
            for (a, b) in KUHN_PATHS {
                push_tet(mesh, [h[0], h[a], h[b], h[6]], zone);
            }
        }
        CubeSplit::Centre => {
            let centre = mesh.points.len() as u32;
            let corners = h.map(|n| mesh.points[n as usize]);
            mesh.points.push(corners.iter().sum::<DVec3>() / 8.0);
            for (f, &side) in faces.iter().zip(HEX_FACE_SIDES.iter()) {
                let q = [h[f[0]], h[f[1]], h[f[2]], h[f[3]]];
                if grid.face_is_quad(c, side) {
                    mesh.push_cell(CellKind::Pyramid, &[q[3], q[2], q[1], q[0], centre], zone);
                } else {
                    for [a, b, d] in cut_quad(q) {
                        mesh.push_cell(CellKind::Tetrahedron, &[a, d, b, centre], zone);
                    }
                }
            }
        }
    }
}

/// Push a tetrahedron, swapping two nodes if it is negative.
fn push_tet(mesh: &mut VolumeMesh, [a, b, c, d]: [u32; 4], zone: u32) {
    let p = |n: u32| mesh.points[n as usize];
    let nodes = if tet_signed_volume(p(a), p(b), p(c), p(d)) > 0.0 { [a, b, c, d] } else { [a, c, b, d] };
    mesh.push_cell(CellKind::Tetrahedron, &nodes, zone);
}

/// A column of four cubes holding every kind: a hexahedron, a centre-cut cube (pyramids and
/// tetrahedra), two prisms and six tetrahedra; zone 0 below z = 2, zone 1 above.
pub fn hybrid_column() -> VolumeMesh {
    let splits = [CubeSplit::Hexahedron, CubeSplit::Centre, CubeSplit::Prisms, CubeSplit::Tetrahedra];
    cube_grid([1, 1, 4], DVec3::ONE, &|c| splits[c[2]], &|c| u32::from(c[2] >= 2))
}
