//! The generated outer boundary of an external flow: a box or an icosphere around the body,
//! centred on its bounding box, triangulated at the farfield cell size and facing inward (into
//! the fluid, like the front: see [`super::ClosedBoundary`]).

use super::{FarfieldSpec, FillError, DEFAULT_FARFIELD_CELL, FARFIELD_PATCH};
use crate::config::FarfieldShape;
use crate::geometry::{Aabb, DVec3};
use crate::normals::constraint::Plane;
use crate::surface::{shapes, Surface};

/// The farfield must leave room around the body and its layers.
pub const MIN_FACTOR: f64 = 2.0;
/// Most squares along a box side (6 x 2 x 400^2 triangles at most).
const MAX_BOX_DIVISIONS: usize = 400;
/// Finest icosphere (20 x 4^7 triangles).
const MAX_SPHERE_LEVEL: usize = 7;
/// Edge length of an icosahedron of circumradius 1: 1 / sin(2 pi / 5).
const ICOSAHEDRON_EDGE: f64 = 1.051_462_224_238_267_3;

/// The farfield around a body with bounding box `body`, as one patch [`FARFIELD_PATCH`].
pub fn farfield(spec: &FarfieldSpec, body: Aabb) -> Result<Surface, FillError> {
    let size = body.diagonal();
    if !(size.is_finite() && size > 0.0) {
        return Err(FillError::Options(format!("the body has no extent (bounding-box diagonal {size})")));
    }
    if !(spec.factor.is_finite() && spec.factor >= MIN_FACTOR) {
        return Err(FillError::Options(format!(
            "farfield factor {} must be at least {MIN_FACTOR} body sizes",
            spec.factor
        )));
    }
    let extent = spec.factor * size;
    let cell = spec.cell_size.unwrap_or(DEFAULT_FARFIELD_CELL * size);
    if !(cell.is_finite() && cell > 0.0) {
        return Err(FillError::Options(format!("farfield cell size {cell} must be a positive length")));
    }
    let mut shell = match spec.shape {
        FarfieldShape::Box => cube(body.center(), extent, cell)?,
        FarfieldShape::Sphere => sphere(body.center(), extent / 2.0, cell)?,
    };
    shell.flip_all();
    shell.patch_names = vec![FARFIELD_PATCH.to_owned()];
    shell.triangle_patch = vec![0; shell.triangles.len()];
    Ok(shell)
}

/// The farfield of a body on a symmetry plane: the cube of [`farfield`] moved onto the fluid's
/// side of `plane` (its normal into the fluid, along an axis), one face on the plane exactly,
/// and that face left open (the symmetry face is triangulated around the body's footprint by
/// the caller); facing inward, as one patch [`FARFIELD_PATCH`].
pub fn half_box(spec: &FarfieldSpec, body: Aabb, plane: &Plane) -> Result<Surface, FillError> {
    let Some(axis) = (0..3).find(|&a| plane.normal[a].abs() == 1.0) else {
        return Err(FillError::Options(format!(
            "a symmetry plane must be normal to a coordinate axis for the half-box farfield; its \
             normal is {:?}",
            plane.normal.to_array()
        )));
    };
    let mut centre = body.center();
    let on_plane = plane.origin[axis];
    let spec = FarfieldSpec { shape: FarfieldShape::Box, ..*spec };
    let mut cube = farfield(&spec, body)?;
    // Half the cube's side: the distance from the centre to its faces.
    let half = cube.points.iter().map(|p| (p[axis] - centre[axis]).abs()).fold(0.0, f64::max);
    centre[axis] = on_plane + plane.normal[axis] * half;
    let shift = centre[axis] - body.center()[axis];
    for p in &mut cube.points {
        p[axis] += shift;
        if (p[axis] - on_plane).abs() <= 1e-9 * half {
            p[axis] = on_plane;
        }
    }
    let on_face = |t: &[u32; 3], points: &[DVec3]| t.iter().all(|&v| points[v as usize][axis] == on_plane);
    let keep: Vec<bool> = cube.triangles.iter().map(|t| !on_face(t, &cube.points)).collect();
    let mut kept = keep.iter();
    cube.triangles.retain(|_| kept.next().copied().unwrap_or(true));
    cube.triangle_patch.truncate(cube.triangles.len());
    cube.remove_unused_points();
    Ok(cube)
}

/// A cube of side `side` centred at `centre`, split into squares of side about `cell`.
fn cube(centre: DVec3, side: f64, cell: f64) -> Result<Surface, FillError> {
    let divisions = (side / cell).ceil().max(1.0);
    if divisions > MAX_BOX_DIVISIONS as f64 {
        return Err(FillError::Options(format!(
            "farfield cell size {cell} is too fine for a box of side {side} (at most {MAX_BOX_DIVISIONS} \
             squares per side)"
        )));
    }
    let mut s = shapes::cuboid(DVec3::splat(side), divisions as usize);
    for p in &mut s.points {
        *p += centre - DVec3::splat(side / 2.0);
    }
    Ok(s)
}

/// An icosphere of radius `radius` centred at `centre` with edges of about `cell` or shorter.
fn sphere(centre: DVec3, radius: f64, cell: f64) -> Result<Surface, FillError> {
    let halvings = (ICOSAHEDRON_EDGE * radius / cell).log2().ceil().max(0.0);
    if halvings > MAX_SPHERE_LEVEL as f64 {
        return Err(FillError::Options(format!(
            "farfield cell size {cell} is too fine for a sphere of radius {radius} (at most level \
             {MAX_SPHERE_LEVEL})"
        )));
    }
    let mut s = shapes::icosphere(radius, halvings as usize);
    for p in &mut s.points {
        *p += centre;
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_body() -> Aabb {
        Aabb { min: DVec3::ZERO, max: DVec3::new(1.0, 2.0, 2.0) } // diagonal 3
    }

    #[test]
    fn box_farfield_faces_inward_with_the_requested_size() {
        let spec = FarfieldSpec { factor: 4.0, cell_size: Some(5.0), ..Default::default() };
        let s = farfield(&spec, unit_body()).unwrap();
        // Side 12, cells of 5 -> 3 squares per side.
        assert_eq!(s.triangles.len(), 6 * 9 * 2);
        assert!((s.enclosed_volume() + 12f64.powi(3)).abs() < 1e-9, "inward: negative volume");
        let b = s.bounding_box();
        assert!((b.center() - DVec3::new(0.5, 1.0, 1.0)).length() < 1e-12);
        assert_eq!(s.patch_names, vec![FARFIELD_PATCH.to_owned()]);
    }

    #[test]
    fn sphere_farfield_edges_are_at_most_the_cell_size() {
        let spec = FarfieldSpec { shape: FarfieldShape::Sphere, factor: 20.0, cell_size: None };
        let s = farfield(&spec, unit_body()).unwrap();
        let longest = s
            .triangles
            .iter()
            .flat_map(|t| (0..3).map(move |i| (t[i], t[(i + 1) % 3])))
            .map(|(a, b)| s.points[a as usize].distance(s.points[b as usize]))
            .fold(0.0, f64::max);
        assert!(longest <= 2.0 * 3.0, "longest edge {longest} > cell size 6");
        assert!(longest > 0.5 * 2.0 * 3.0, "needlessly fine: {longest}");
        assert!(s.enclosed_volume() < 0.0, "inward");
    }

    #[test]
    fn impossible_farfields_are_errors() {
        let tight = FarfieldSpec { factor: 1.5, ..Default::default() };
        assert!(matches!(farfield(&tight, unit_body()), Err(FillError::Options(_))));
        let fine = FarfieldSpec { cell_size: Some(1e-6), ..Default::default() };
        assert!(matches!(farfield(&fine, unit_body()), Err(FillError::Options(_))));
        let flat = Aabb { min: DVec3::ZERO, max: DVec3::ZERO };
        assert!(farfield(&FarfieldSpec::default(), flat).is_err());
    }
}
