//! Columns that slide along the patches without layers (symmetry planes, inlets, outlets).
//!
//! Where a wall meets a patch that gets no layers, the layers must end against that patch with
//! no ledge and no overhang: the columns at the junction move in the patch's plane, and the
//! layer faces on it lie in that plane. Only planar patches can take sliding columns; each is
//! fitted with a [`Plane`] once, its vertices are snapped onto it (they moved by less than the
//! planarity tolerance), and every node a sliding column creates is projected onto it.
//! At a vertex on two such planes the column slides along their common line; on three or more
//! (or on a curved patch without layers) it cannot move.

use glam::DVec3;

use super::WallNormals;
use crate::surface::Surface;

/// A patch is planar when its vertices lie within this fraction of the body size of its plane.
pub const PLANARITY_TOLERANCE: f64 = 1e-6;
/// A sliding direction must keep at least this cosine with the wall faces it leaves (and a
/// projected direction at least this length), or the column does not move.
const MIN_COSINE: f64 = 0.2;
/// Normal components smaller than this are rounded to zero, so that axis-aligned planes are
/// exactly axis-aligned and their projection sets one coordinate exactly.
const AXIS_SNAP: f64 = 1e-9;

/// An oriented plane; `normal` is a unit vector (into the fluid for a patch).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    pub origin: DVec3,
    pub normal: DVec3,
}

impl Plane {
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        (p - self.origin).dot(self.normal)
    }

    /// The closest point of the plane; on an axis-aligned plane the coordinate is set exactly.
    pub fn project(&self, p: DVec3) -> DVec3 {
        let mut q = p - self.normal * self.signed_distance(p);
        for axis in 0..3 {
            if self.normal[axis].abs() == 1.0 {
                q[axis] = self.origin[axis];
            }
        }
        q
    }

    /// A right-handed frame (u, v) of the plane: u x v = normal.
    pub fn frame(&self) -> (DVec3, DVec3) {
        let u = self.normal.any_orthonormal_vector();
        (u, self.normal.cross(u))
    }
}

/// How a column may move.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Slide {
    /// Anywhere (a column away from the patches without layers).
    #[default]
    Free,
    /// In a plane.
    Plane(Plane),
    /// Along the line where two planes meet.
    Line { a: Plane, b: Plane },
    /// Not at all.
    Fixed,
}

impl Slide {
    /// The closest allowed position to `p` (`Fixed` columns are never moved: `p` itself).
    pub fn project(&self, p: DVec3) -> DVec3 {
        match self {
            Slide::Free | Slide::Fixed => p,
            Slide::Plane(plane) => plane.project(p),
            Slide::Line { a, b } => {
                // x0: the point of the line nearest the origin; then along the line to p.
                let line = a.normal.cross(b.normal);
                let (da, db) = (a.normal.dot(a.origin), b.normal.dot(b.origin));
                let x0 = (da * b.normal.cross(line) + db * line.cross(a.normal)) / line.length_squared();
                let unit = line.normalize();
                b.project(a.project(x0 + unit * unit.dot(p - x0)))
            }
        }
    }
}

/// Fit a plane to each patch without layers (`layered_patch[p]` false); `None` for the
/// layered patches and for those that are not planar within [`PLANARITY_TOLERANCE`] of the
/// body size. The vertices of every planar one are projected onto its plane.
pub fn snap_planar_patches(surface: &mut Surface, layered_patch: &[bool]) -> Vec<Option<Plane>> {
    let tolerance = PLANARITY_TOLERANCE * surface.bounding_box().diagonal();
    let planes: Vec<Option<Plane>> = (0..surface.patch_names.len())
        .map(|p| {
            if layered_patch.get(p).copied().unwrap_or(true) {
                return None;
            }
            fit_plane(surface, p as u32).filter(|plane| {
                patch_vertices(surface, p as u32)
                    .all(|v| plane.signed_distance(surface.points[v]).abs() <= tolerance)
            })
        })
        .collect();
    for (p, plane) in planes.iter().enumerate() {
        let Some(plane) = plane else { continue };
        let vertices: Vec<usize> = patch_vertices(surface, p as u32).collect();
        for v in vertices {
            surface.points[v] = plane.project(surface.points[v]);
        }
    }
    planes
}

/// The vertices of patch `p`'s triangles (with repeats).
fn patch_vertices(surface: &Surface, p: u32) -> impl Iterator<Item = usize> + '_ {
    surface
        .triangles
        .iter()
        .zip(&surface.triangle_patch)
        .filter(move |(_, &q)| q == p)
        .flat_map(|(t, _)| t.iter().map(|&v| v as usize))
}

/// The plane through the area-weighted centre of patch `p` normal to its total area vector;
/// `None` when the patch is empty or closes on itself (no net area).
fn fit_plane(surface: &Surface, p: u32) -> Option<Plane> {
    let (mut area, mut total, mut moment) = (DVec3::ZERO, 0.0, DVec3::ZERO);
    for t in (0..surface.triangles.len()).filter(|&t| surface.triangle_patch[t] == p) {
        let [a, b, c] = surface.triangle_points(t);
        let vector = surface.triangle_area_vector(t);
        area += vector;
        total += vector.length();
        moment += vector.length() * (a + b + c) / 3.0;
    }
    if !(total > 0.0 && area.length() > 0.5 * total) {
        return None;
    }
    let mut normal = area / area.length();
    for axis in 0..3 {
        if normal[axis].abs() < AXIS_SNAP {
            normal[axis] = 0.0;
        }
    }
    let normal = normal.normalize();
    let mut origin = moment / total;
    // On an axis-aligned plane take the coordinate of a vertex, so that vertices already on
    // the plane stay exactly where they are.
    if let Some(axis) = (0..3).find(|&a| normal[a].abs() == 1.0) {
        if let Some(v) = patch_vertices(surface, p).next() {
            origin[axis] = surface.points[v][axis];
        }
    }
    Some(Plane { origin, normal })
}

/// Constrain the columns at the vertices where the wall meets a patch without layers: their
/// direction is turned into the patch's plane (or the line of two planes) and their distance
/// scale recomputed against the layered triangles they serve. Returns one [`Slide`] per column.
/// `planes[p]` is patch `p`'s plane ([`snap_planar_patches`]); a vertex on a patch without
/// layers and without a plane gets fixed columns.
pub fn constrain_columns(
    surface: &Surface,
    normals: &mut WallNormals,
    layered_patch: &[bool],
    planes: &[Option<Plane>],
) -> Vec<Slide> {
    let layered = |t: usize| layered_patch.get(surface.triangle_patch[t] as usize).copied().unwrap_or(true);
    // The constraints at each vertex: the planes of the patches without layers around it.
    let mut vertex_planes: Vec<Vec<Option<Plane>>> = vec![Vec::new(); surface.points.len()];
    // The layered triangles of every column (to recompute its distance scale).
    let mut column_triangles: Vec<Vec<usize>> = vec![Vec::new(); normals.columns.len()];
    for (t, tri) in surface.triangles.iter().enumerate() {
        if layered(t) {
            for &c in &normals.triangle_columns[t] {
                if let Some(list) = column_triangles.get_mut(c as usize) {
                    list.push(t);
                }
            }
            continue;
        }
        let plane = planes.get(surface.triangle_patch[t] as usize).copied().flatten();
        for &v in tri {
            let list = &mut vertex_planes[v as usize];
            if !list.contains(&plane) {
                list.push(plane);
            }
        }
    }
    (0..normals.columns.len())
        .map(|c| {
            let seed = &mut normals.columns[c];
            let slide = match vertex_planes[seed.vertex as usize].as_slice() {
                [] => return Slide::Free,
                [Some(plane)] => Slide::Plane(*plane),
                [Some(a), Some(b)] => Slide::Line { a: *a, b: *b },
                _ => return Slide::Fixed,
            };
            let Some(direction) = slide_direction(&slide, seed.direction) else { return Slide::Fixed };
            let cosine = column_triangles[c]
                .iter()
                .map(|&t| direction.dot(surface.triangle_normal(t)))
                .fold(f64::INFINITY, f64::min);
            if cosine < MIN_COSINE {
                return Slide::Fixed;
            }
            seed.direction = direction;
            if cosine.is_finite() {
                seed.scale = 1.0 / cosine;
            }
            slide
        })
        .collect()
}

/// `direction` turned into the plane or line of `slide`; `None` when little of it is left.
fn slide_direction(slide: &Slide, direction: DVec3) -> Option<DVec3> {
    let turned = match slide {
        Slide::Plane(p) => direction - p.normal * direction.dot(p.normal),
        Slide::Line { a, b } => {
            let line = a.normal.cross(b.normal);
            if line.length() < MIN_COSINE {
                return None;
            }
            let line = line.normalize();
            line * direction.dot(line)
        }
        Slide::Free | Slide::Fixed => direction,
    };
    (turned.length() >= MIN_COSINE).then(|| turned.normalize())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::shapes::cuboid;

    #[test]
    fn planar_patches_are_fitted_and_curved_ones_are_not() {
        let mut s = cuboid(DVec3::new(1.0, 2.0, 3.0), 2);
        // zmin without layers; xmax without layers but bent out of its plane.
        let bent = s.triangles.iter().zip(&s.triangle_patch).find(|(_, &p)| p == 1).map(|(t, _)| t[0]);
        let mut layered = vec![true; 6];
        layered[4] = false;
        layered[1] = false;
        if let Some(v) = bent {
            s.points[v as usize].x += 0.01;
        }
        let planes = snap_planar_patches(&mut s, &layered);
        let zmin = planes[4].expect("zmin is planar");
        assert_eq!(zmin.normal, DVec3::new(0.0, 0.0, -1.0));
        assert_eq!(zmin.origin.z, 0.0);
        assert!(planes[1].is_none(), "a bent patch has no plane");
        assert!(planes[0].is_none(), "a layered patch has no plane");
        assert_eq!(zmin.project(DVec3::new(0.3, 0.4, 1e-3)), DVec3::new(0.3, 0.4, 0.0));
    }

    #[test]
    fn columns_at_a_symmetry_face_slide_in_its_plane_and_its_ridges_get_no_fans() {
        use crate::surface::features::Features;
        use crate::surface::topology::Topology;
        let mut s = cuboid(DVec3::ONE, 2);
        let mut layered = vec![true; 6];
        layered[4] = false; // zmin
        let planes = snap_planar_patches(&mut s, &layered);
        let topology = Topology::new(&s);
        let features = Features::compute(&s, &topology, 30.0);
        let mut n = super::super::wall_normals_of_layered(&s, &topology, &features, 20.0, &layered);
        // 4 edges of 2 segments at the top, 4 vertical ones: none along the floor.
        assert_eq!(n.stats.fan_edges, 16);
        let slides = constrain_columns(&s, &mut n, &layered, &planes);
        let zmin = planes[4].expect("planar");
        let on_floor = |c: usize| s.points[n.columns[c].vertex as usize].z == 0.0;
        let layered_column = |c: usize| {
            let t = n.triangle_columns.iter().position(|cols| cols.contains(&(c as u32)));
            t.is_none_or(|t| layered[s.triangle_patch[t] as usize])
        };
        let sliding: Vec<usize> =
            (0..n.columns.len()).filter(|&c| on_floor(c) && layered_column(c)).collect();
        assert!(!sliding.is_empty());
        for c in sliding {
            assert_eq!(slides[c], Slide::Plane(zmin), "column {c}");
            assert_eq!(n.columns[c].direction.z, 0.0);
        }
        assert!((0..n.columns.len()).filter(|&c| !on_floor(c)).all(|c| slides[c] == Slide::Free));
    }

    #[test]
    fn a_line_slide_stays_on_both_planes() {
        let a = Plane { origin: DVec3::ZERO, normal: DVec3::new(0.6, 0.8, 0.0) };
        let b = Plane { origin: DVec3::new(0.0, 0.0, 1.0), normal: DVec3::new(0.0, 0.6, 0.8) };
        let q = Slide::Line { a, b }.project(DVec3::new(3.0, -2.0, 5.0));
        assert!(a.signed_distance(q).abs() < 1e-12 && b.signed_distance(q).abs() < 1e-12, "{q}");
    }
}
