//! Geometry of one cell: its standard decomposition, volume, scaled Jacobian and dihedral angles.
//!
//! Definitions follow `shared/bench/measure.py`, so our checker and the benchmark agree:
//! - standard decomposition: a tetrahedron is itself; any other cell is its centroid joined to
//!   every outward face triangle, each quad split into 4 triangles at its centre;
//! - scaled Jacobian: tetrahedra `sqrt(2) 6V / max over corners |e1||e2||e3|` (regular tet 1),
//!   other cells the minimum over corners of `det(e1, e2, e3) / (|e1||e2||e3|)`.

use crate::geometry::{tet_signed_volume, DVec3};
use crate::mesh::CellKind;

/// The points of one cell, in its node order (only the first `kind.node_count()` are used).
pub type CellPoints = [DVec3; 8];

/// Centre of a quad face, summed in the given order so every caller gets the same rounding.
pub fn quad_centre(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> DVec3 {
    (a + b + c + d) * 0.25
}

fn centroid(kind: CellKind, x: &CellPoints) -> DVec3 {
    let n = kind.node_count();
    x[..n].iter().fold(DVec3::ZERO, |s, p| s + *p) / n as f64
}

/// The triangles of a face (a quad gives 4 around its centre), oriented like the face.
pub fn face_triangles(face: &[DVec3], mut f: impl FnMut([DVec3; 3])) {
    match *face {
        [a, b, c] => f([a, b, c]),
        [a, b, c, d] => {
            let m = quad_centre(a, b, c, d);
            f([a, b, m]);
            f([b, c, m]);
            f([c, d, m]);
            f([d, a, m]);
        }
        _ => {}
    }
}

/// Call `f(face, tet)` for every tetrahedron of the standard decomposition, in the
/// orientation that is positive in a valid cell (`face` is the local face, 0 for a tet).
pub fn for_each_subtet(kind: CellKind, x: &CellPoints, mut f: impl FnMut(usize, [DVec3; 4])) {
    if kind == CellKind::Tetrahedron {
        f(0, [x[0], x[1], x[2], x[3]]);
        return;
    }
    let c = centroid(kind, x);
    for (i, face) in kind.faces().iter().enumerate() {
        let mut pts = [DVec3::ZERO; 4];
        for (p, &v) in pts.iter_mut().zip(face.iter()) {
            *p = x[v];
        }
        face_triangles(&pts[..face.len()], |[a, b, d]| f(i, [c, a, b, d]));
    }
}

/// Volume of the cell (sum over its standard decomposition).
pub fn volume(kind: CellKind, x: &CellPoints) -> f64 {
    let mut v = 0.0;
    for_each_subtet(kind, x, |_, [a, b, c, d]| v += tet_signed_volume(a, b, c, d));
    v
}

/// A cell whose smallest decomposition tetrahedron is below this fraction of the cube of its
/// bounding-box diagonal is flat in floating point: a triple product's round-off is about 1e-16
/// of that cube, so the signs of the face-pyramid volumes a finite-volume solver computes on it
/// would be noise, however the exact orientation tests decide.
pub const FLOAT_FLAT: f64 = 1e-12;

/// Whether a cell that may be valid by exact predicates is flat in floating point
/// ([`FLOAT_FLAT`]).
pub fn is_float_flat(kind: CellKind, x: &CellPoints) -> bool {
    let nodes = &x[..kind.node_count()];
    let (lo, hi) = nodes.iter().fold((nodes[0], nodes[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let floor = FLOAT_FLAT * (hi - lo).length().powi(3);
    let mut flat = false;
    for_each_subtet(kind, x, |_, [a, b, c, d]| flat |= tet_signed_volume(a, b, c, d) <= floor);
    flat
}

/// The corner edge vectors of corner `[o, a, b, d]`.
fn corner_edges(x: &CellPoints, [o, a, b, d]: [usize; 4]) -> [DVec3; 3] {
    [x[a] - x[o], x[b] - x[o], x[d] - x[o]]
}

/// Scaled Jacobian (see module docs); 0 for a cell with a zero-length edge.
pub fn scaled_jacobian(kind: CellKind, x: &CellPoints) -> f64 {
    let det = |[e1, e2, e3]: [DVec3; 3]| e1.dot(e2.cross(e3));
    let lengths = |[e1, e2, e3]: [DVec3; 3]| (e1.length() * e2.length() * e3.length()).max(1e-300);
    let corners = kind.corners();
    if kind == CellKind::Tetrahedron {
        let longest = corners.iter().map(|&c| lengths(corner_edges(x, c))).fold(0.0, f64::max);
        return std::f64::consts::SQRT_2 * det(corner_edges(x, corners[0])) / longest;
    }
    corners
        .iter()
        .map(|&c| {
            let e = corner_edges(x, c);
            det(e) / lengths(e)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Pairs of local faces sharing an edge, for every kind.
pub fn edge_face_pairs(kind: CellKind) -> Vec<(usize, usize)> {
    let faces = kind.faces();
    let edges = |f: &[usize]| (0..f.len()).map(move |k| (f[k], f[(k + 1) % f.len()])).collect::<Vec<_>>();
    let mut pairs = Vec::new();
    for (i, fi) in faces.iter().enumerate() {
        for (j, fj) in faces.iter().enumerate().skip(i + 1) {
            let shares = edges(fi).iter().any(|&(a, b)| edges(fj).contains(&(b, a)));
            if shares {
                pairs.push((i, j));
            }
        }
    }
    pairs
}

/// Outward normal direction of a face (a quad: the cross product of its diagonals).
fn face_normal(face: &[usize], x: &CellPoints) -> DVec3 {
    match *face {
        [a, b, c] => (x[b] - x[a]).cross(x[c] - x[a]),
        [a, b, c, d] => (x[c] - x[a]).cross(x[d] - x[b]),
        _ => DVec3::ZERO,
    }
    .normalize_or_zero()
}

/// (min, max) interior dihedral angle in degrees over the given face pairs.
pub fn dihedral_range(kind: CellKind, x: &CellPoints, pairs: &[(usize, usize)]) -> (f64, f64) {
    let faces = kind.faces();
    let mut normals = [DVec3::ZERO; 6];
    for (n, f) in normals.iter_mut().zip(faces.iter()) {
        *n = face_normal(f, x);
    }
    // The angle falls as its cosine rises: two arc cosines per cell, not one per pair (the
    // quality measure of every change the core improvement weighs).
    let (least, most) = pairs.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &(i, j)| {
        let cosine = (-normals[i].dot(normals[j])).clamp(-1.0, 1.0);
        (lo.min(cosine), hi.max(cosine))
    });
    let angle = |cosine: f64| cosine.acos().to_degrees();
    if most == f64::NEG_INFINITY {
        return (f64::INFINITY, f64::NEG_INFINITY);
    }
    (angle(most), angle(least))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cell_flatter_than_round_off_is_float_flat_and_a_thin_layer_cell_is_not() {
        let tet = |apex_height: f64| {
            let mut x = [DVec3::ZERO; 8];
            x[..4].copy_from_slice(&[DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.3, 0.3, apex_height)]);
            x
        };
        assert!(is_float_flat(CellKind::Tetrahedron, &tet(1e-14)));
        assert!(is_float_flat(CellKind::Tetrahedron, &tet(-1.0)));
        // A first layer a millionth of its wall edge is still a solid prism.
        assert!(!is_float_flat(CellKind::Tetrahedron, &tet(1e-6)));
        let mut prism = [DVec3::ZERO; 8];
        let h = 1e-6 * DVec3::Z;
        prism[..6].copy_from_slice(&[DVec3::ZERO, DVec3::X, DVec3::Y, h, DVec3::X + h, DVec3::Y + h]);
        assert!(!is_float_flat(CellKind::Prism, &prism));
    }

    /// measure.py's self-test cells: unit cube corners plus a pyramid apex.
    fn reference(kind: CellKind) -> (CellPoints, f64, f64) {
        let h = 0.5f64.sqrt();
        let p = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(0.0, 1.0, 1.0),
            DVec3::new(0.5, 0.5, h),
        ];
        let (nodes, vol, q): (&[usize], f64, f64) = match kind {
            CellKind::Tetrahedron => (&[0, 1, 3, 4], 1.0 / 6.0, h),
            CellKind::Pyramid => (&[0, 1, 2, 3, 8], h / 3.0, h),
            CellKind::Prism => (&[0, 1, 3, 4, 5, 7], 0.5, h),
            CellKind::Hexahedron => (&[0, 1, 2, 3, 4, 5, 6, 7], 1.0, 1.0),
        };
        let mut x = [DVec3::ZERO; 8];
        for (xi, &n) in x.iter_mut().zip(nodes) {
            *xi = p[n];
        }
        (x, vol, q)
    }

    #[test]
    fn reference_cells_match_measure_py() {
        for kind in CellKind::ALL {
            let (x, vol, q) = reference(kind);
            assert!((volume(kind, &x) - vol).abs() < 1e-14, "{kind:?} volume {}", volume(kind, &x));
            assert!((scaled_jacobian(kind, &x) - q).abs() < 1e-12, "{kind:?}");
            let mut smallest = f64::INFINITY;
            for_each_subtet(kind, &x, |_, [a, b, c, d]| {
                smallest = smallest.min(tet_signed_volume(a, b, c, d))
            });
            assert!(smallest > 0.0, "{kind:?}");
        }
    }

    #[test]
    fn dihedral_angles_of_unit_cells() {
        let (x, _, _) = reference(CellKind::Hexahedron);
        let pairs = edge_face_pairs(CellKind::Hexahedron);
        assert_eq!(pairs.len(), 12);
        let (lo, hi) = dihedral_range(CellKind::Hexahedron, &x, &pairs);
        assert!((lo - 90.0).abs() < 1e-9 && (hi - 90.0).abs() < 1e-9);
        let (x, _, _) = reference(CellKind::Prism);
        let pairs = edge_face_pairs(CellKind::Prism);
        assert_eq!(pairs.len(), 9);
        let (lo, hi) = dihedral_range(CellKind::Prism, &x, &pairs);
        assert!((lo - 45.0).abs() < 1e-9 && (hi - 90.0).abs() < 1e-9, "{lo} {hi}");
        assert_eq!(edge_face_pairs(CellKind::Tetrahedron).len(), 6);
        assert_eq!(edge_face_pairs(CellKind::Pyramid).len(), 8);
    }
}
