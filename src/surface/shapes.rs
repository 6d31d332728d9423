//! Closed test surfaces built in code: boxes, blocks made of voxels (L-blocks, notched boxes),
//! icospheres. Used by tests, benchmarks and the shipped example; all are valid input
//! (closed, manifold, outward-oriented).

use std::collections::HashMap;

use glam::DVec3;

use super::Surface;

/// The surface of a union of unit voxels of a grid, scaled by `cell` and subdivided `n` times
/// along each voxel edge; `filled(i, j, k)` says which voxels are solid. Each of the six face
/// directions is its own patch (`xmin`, `xmax`, `ymin`, `ymax`, `zmin`, `zmax`).
pub fn voxels(
    dims: [usize; 3],
    cell: f64,
    n: usize,
    filled: impl Fn(usize, usize, usize) -> bool,
) -> Surface {
    let inside = |i: i64, j: i64, k: i64| {
        i >= 0
            && j >= 0
            && k >= 0
            && (i as usize) < dims[0]
            && (j as usize) < dims[1]
            && (k as usize) < dims[2]
            && filled(i as usize, j as usize, k as usize)
    };
    let mut builder = GridBuilder::new(cell / n as f64);
    let names = ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"];
    let mut surface =
        Surface { patch_names: names.iter().map(|s| s.to_string()).collect(), ..Default::default() };
    for (i, j, k) in
        (0..dims[0]).flat_map(|i| (0..dims[1]).flat_map(move |j| (0..dims[2]).map(move |k| (i, j, k))))
    {
        if !filled(i, j, k) {
            continue;
        }
        for axis in 0..3 {
            for (side, step) in [(0usize, -1i64), (1, 1)] {
                let mut nb = [i as i64, j as i64, k as i64];
                nb[axis] += step;
                if inside(nb[0], nb[1], nb[2]) {
                    continue;
                }
                let patch = (2 * axis + side) as u32;
                builder.voxel_face(&mut surface, [i, j, k], axis, side, n, patch);
            }
        }
    }
    surface.points = builder.points;
    surface
}

/// An axis-aligned box `[0, size]` with every face split into `n x n` squares of 2 triangles.
pub fn cuboid(size: DVec3, n: usize) -> Surface {
    let mut s = voxels([1, 1, 1], 1.0, n, |_, _, _| true);
    for p in &mut s.points {
        *p *= size;
    }
    s
}

/// A block 8 x 2 x 2 with a V groove along y, one deep, whose walls meet at `opening_deg` at
/// its bottom (x = 4, z = 1): a straight concave ridge of that opening as seen from the fluid,
/// between two convex lips. Built as a box grid with `n` squares per unit, moved in x so that
/// grid lines fall on the lips and the bottom, and squeezed in z under the groove.
pub fn grooved_block(opening_deg: f64, n: usize) -> Surface {
    let half_width = (0.5 * opening_deg.to_radians()).tan();
    assert!(half_width > 0.0 && half_width < 4.0, "opening {opening_deg} deg does not fit the block");
    let mut s = voxels([8, 2, 2], 1.0, n, |_, _, _| true);
    // Grid x 0..3 | 3..4 | 4..5 | 5..8 onto 0..4-w | 4-w..4 | 4..4+w | 4+w..8.
    let stations = [(0.0, 0.0), (3.0, 4.0 - half_width), (4.0, 4.0), (5.0, 4.0 + half_width), (8.0, 8.0)];
    let to_x = |x: f64| {
        let i = stations.windows(2).position(|w| x <= w[1].0).unwrap_or(stations.len() - 2);
        let ((x0, y0), (x1, y1)) = (stations[i], stations[i + 1]);
        y0 + (y1 - y0) * (x - x0) / (x1 - x0)
    };
    for p in &mut s.points {
        let x = to_x(p.x);
        let top = 2.0 - (1.0 - (x - 4.0).abs() / half_width).max(0.0);
        *p = DVec3::new(x, p.y, p.z * top / 2.0);
    }
    s
}

/// Shared grid points, so faces of neighbouring voxels are welded.
struct GridBuilder {
    h: f64,
    index: HashMap<[i64; 3], u32>,
    points: Vec<DVec3>,
}

impl GridBuilder {
    fn new(h: f64) -> Self {
        GridBuilder { h, index: HashMap::new(), points: Vec::new() }
    }

    fn point(&mut self, g: [i64; 3]) -> u32 {
        let (h, points) = (self.h, &mut self.points);
        *self.index.entry(g).or_insert_with(|| {
            points.push(DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64) * h);
            points.len() as u32 - 1
        })
    }

    /// The face of voxel `v` normal to `axis` on `side` (0: low, 1: high), outward.
    fn voxel_face(&mut self, s: &mut Surface, v: [usize; 3], axis: usize, side: usize, n: usize, patch: u32) {
        let (u_axis, w_axis) = ((axis + 1) % 3, (axis + 2) % 3);
        for a in 0..n {
            for b in 0..n {
                let corner = |du: usize, dw: usize| {
                    let mut g = [0i64; 3];
                    g[axis] = ((v[axis] + side) * n) as i64;
                    g[u_axis] = (v[u_axis] * n + a + du) as i64;
                    g[w_axis] = (v[w_axis] * n + b + dw) as i64;
                    g
                };
                let q = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)].map(|g| self.point(g));
                // (u, w, axis) is right-handed: u x w points along +axis.
                let tris = if side == 1 {
                    [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
                } else {
                    [[q[0], q[2], q[1]], [q[0], q[3], q[2]]]
                };
                for t in tris {
                    s.triangles.push(t);
                    s.triangle_patch.push(patch);
                }
            }
        }
    }
}

/// A sphere of radius `r` at the origin: an icosahedron subdivided `level` times, projected.
pub fn icosphere(r: f64, level: usize) -> Surface {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut points: Vec<DVec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| DVec3::from_array(*p).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut midpoint: HashMap<(u32, u32), u32> = HashMap::new();
        let mut mid = |a: u32, b: u32, points: &mut Vec<DVec3>| {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                points.push((points[a as usize] + points[b as usize]).normalize());
                points.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(triangles.len() * 4);
        for [a, b, c] in triangles {
            let (ab, bc, ca) = (mid(a, b, &mut points), mid(b, c, &mut points), mid(c, a, &mut points));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = next;
    }
    let count = triangles.len();
    Surface {
        points: points.into_iter().map(|p| p * r).collect(),
        triangles,
        triangle_patch: vec![0; count],
        patch_names: vec!["sphere".into()],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cuboid_encloses_its_volume() {
        let s = cuboid(DVec3::new(1.0, 2.0, 3.0), 3);
        assert_eq!(s.triangles.len(), 6 * 9 * 2);
        assert_eq!(s.points.len(), 6 * 9 + 2); // V = E - F + 2 on the quad grid: 2 + 6 n^2
        assert!((s.enclosed_volume() - 6.0).abs() < 1e-12);
    }

    #[test]
    fn l_block_and_notch_have_the_right_volume() {
        let l = voxels([2, 1, 2], 1.0, 2, |i, _, k| !(i == 1 && k == 1));
        assert!((l.enclosed_volume() - 3.0).abs() < 1e-12);
        let notch = voxels([2, 2, 2], 0.5, 1, |i, j, k| !(i == 1 && j == 1 && k == 1));
        assert!((notch.enclosed_volume() - 7.0 / 8.0).abs() < 1e-12);
    }

    #[test]
    fn icosphere_converges_to_the_sphere() {
        let s = icosphere(2.0, 3);
        assert_eq!(s.triangles.len(), 20 * 64);
        let exact = 4.0 / 3.0 * std::f64::consts::PI * 8.0;
        let v = s.enclosed_volume();
        assert!(v > 0.97 * exact && v < exact, "{v} vs {exact}");
    }

    #[test]
    fn grooved_blocks_lose_the_groove_volume() {
        for opening in [60.0f64, 90.0, 120.0] {
            let s = grooved_block(opening, 2);
            let w = (0.5 * opening.to_radians()).tan();
            // 8 x 2 x 2 less the groove's triangle (width 2w, depth 1) along y = 0..2.
            let exact = 32.0 - 2.0 * w;
            assert!((s.enclosed_volume() - exact).abs() < 1e-9, "{opening}: {}", s.enclosed_volume());
        }
    }
}
