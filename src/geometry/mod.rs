//! Geometric vocabulary: the point type and the exact predicates every topological decision uses.

pub mod bvh;
pub mod cdt;
pub mod distance;
pub mod grid;
pub mod intersect;
pub mod predicates;

/// Every coordinate in blmesh is an `f64` 3-vector.
pub type Point = glam::DVec3;
pub use glam::DVec3;

/// Axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Aabb {
    pub min: DVec3,
    pub max: DVec3,
}

impl Aabb {
    /// The empty box (min = +inf, max = -inf); growing it by any point gives that point.
    pub fn empty() -> Self {
        Aabb { min: DVec3::splat(f64::INFINITY), max: DVec3::splat(f64::NEG_INFINITY) }
    }

    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a DVec3>) -> Self {
        let mut b = Aabb::empty();
        for p in points {
            b.grow(*p);
        }
        b
    }

    pub fn grow(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    pub fn diagonal(&self) -> f64 {
        (self.max - self.min).length()
    }

    pub fn center(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// Whether the two closed boxes have a point in common (touching counts).
    pub fn overlaps(&self, other: &Aabb) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }
}

/// Twice the signed area vector of triangle (a, b, c): its direction is the right-hand normal.
pub fn triangle_area_vector(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    (b - a).cross(c - a)
}

/// The corner angles of triangle (a, b, c) at a, b and c, in degrees.
fn triangle_angles(a: DVec3, b: DVec3, c: DVec3) -> [f64; 3] {
    let corner = |p: DVec3, q: DVec3, r: DVec3| (q - p).angle_between(r - p).to_degrees();
    [corner(a, b, c), corner(b, c, a), corner(c, a, b)]
}

/// The smallest corner angle of triangle (a, b, c), in degrees.
pub fn triangle_min_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    triangle_angles(a, b, c).into_iter().fold(f64::INFINITY, f64::min)
}

/// The largest corner angle of triangle (a, b, c), in degrees (near 180 for a cap: a corner
/// nearly on the opposite edge).
pub fn triangle_max_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    triangle_angles(a, b, c).into_iter().fold(f64::NEG_INFINITY, f64::max)
}

/// Signed turn in degrees across the edge shared by triangles `first` and `second`, whose corner
/// off that edge is `far`. The angle is that between the two right-hand normals (atan2 of their
/// cross and dot products: accurate near 0 and 180); the sign is exact: positive (convex) when
/// `far` lies behind the plane of `first`, zero when it lies in it.
pub fn signed_turn_deg(first: [DVec3; 3], second: [DVec3; 3], far: DVec3) -> f64 {
    let [a, b, c] = first;
    let sign = match predicates::orient3d(a, b, c, far) {
        predicates::Sign::Negative => 1.0,
        predicates::Sign::Positive => -1.0,
        predicates::Sign::Zero => return 0.0,
    };
    let n1 = triangle_area_vector(a, b, c);
    let n2 = triangle_area_vector(second[0], second[1], second[2]);
    sign * n1.cross(n2).length().atan2(n1.dot(n2)).to_degrees()
}

/// Signed volume of tetrahedron (a, b, c, d): positive when d lies on the side the right-hand
/// normal of (a, b, c) points to (the Gmsh/VTK convention for a valid tetrahedron).
pub fn tet_signed_volume(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    (b - a).cross(c - a).dot(d - a) / 6.0
}

/// The centre of the sphere through the corners of a tetrahedron (none when it is flat).
pub fn tet_circumcentre([a, b, c, d]: [DVec3; 4]) -> Option<DVec3> {
    let (u, v, w) = (b - a, c - a, d - a);
    let denominator = 2.0 * u.dot(v.cross(w));
    let centre =
        (u.length_squared() * v.cross(w) + v.length_squared() * w.cross(u) + w.length_squared() * u.cross(v))
            / denominator;
    (denominator != 0.0 && centre.is_finite()).then_some(a + centre)
}

/// The centre of the circle through the corners of a triangle, in its plane (none when it has
/// no area).
pub fn triangle_circumcentre(a: DVec3, b: DVec3, c: DVec3) -> Option<DVec3> {
    let (u, v) = (b - a, c - a);
    let normal = u.cross(v);
    let centre = (u.length_squared() * v.cross(normal) + v.length_squared() * normal.cross(u))
        / (2.0 * normal.length_squared());
    centre.is_finite().then_some(a + centre)
}
