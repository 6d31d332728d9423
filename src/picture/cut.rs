//! A planar cut through a volume mesh, drawn as a picture.
//!
//! Every cell the plane crosses is intersected with it exactly: its standard decomposition
//! ([`for_each_subtet`]) is clipped tetrahedron by tetrahedron, so prisms, pyramids and hexahedra
//! with non-planar quads are cut as the checker sees them; the pieces are filled in the cell's
//! colour and only the cuts of the cell's faces are stroked. A point exactly on the plane counts
//! as on its positive side (the plane is shifted symbolically toward its negative side), so a
//! face lying in the plane is drawn once, as the section of the cell on the negative side.

use rayon::prelude::*;
use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Stroke, Transform};

use super::colour::{bucket_colour, Colouring};
use crate::geometry::{Aabb, DVec3};
use crate::layers::TOP_PATCH;
use crate::mesh::{CellKind, VolumeMesh};
use crate::quality::measures::{face_triangles, for_each_subtet, CellPoints};
use crate::quality::validity;

/// A plane: the points `p` with `(p - origin) . normal = 0` (the normal need not be unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutPlane {
    pub origin: DVec3,
    pub normal: DVec3,
}

/// The window of a picture: the square of side `2 half_width` centred on the projection of
/// `centre` onto the plane fits in the picture (the longer side of the picture shows more).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    pub centre: DVec3,
    pub half_width: f64,
}

impl View {
    /// The window of side `2 half_width` around `centre` (e.g. a zoom on a box corner).
    pub fn around(centre: DVec3, half_width: f64) -> View {
        View { centre, half_width }
    }

    /// The window showing the whole cut of the mesh, with a 5% margin (the whole mesh projected
    /// onto the plane if the plane cuts no cell).
    pub fn fit(mesh: &VolumeMesh, plane: &CutPlane) -> View {
        let Some(basis) = PlaneBasis::new(plane) else {
            return View::around(plane.origin, 1.0);
        };
        let coordinates: Vec<DVec3> = mesh.points.par_iter().map(|&p| basis.coordinates(p)).collect();
        let mut window =
            fold_cut_cells(mesh, &coordinates, Aabb::empty, |b, _, _, x| grow_by_cell(b, x), merge);
        if window.min.x > window.max.x {
            window = Aabb::from_points(coordinates.iter().filter(|c| c.is_finite()));
        }
        if !window.min.is_finite() {
            return View::around(plane.origin, 1.0);
        }
        let extent = (window.max - window.min).truncate().max_element();
        let half_width = if extent > 0.0 { 0.525 * extent } else { 1.0 };
        let c = window.center();
        View { centre: basis.origin + c.x * basis.u + c.y * basis.v, half_width }
    }
}

fn grow_by_cell(b: &mut Aabb, x: &[DVec3]) {
    for p in x {
        b.grow(*p);
    }
}

fn merge(a: Aabb, b: Aabb) -> Aabb {
    Aabb { min: a.min.min(b.min), max: a.max.max(b.max) }
}

/// The plane's orthonormal frame: `n` its unit normal, `(u, v, n)` right-handed. The viewer is on
/// the positive side; `v` (up in the picture) is the projection of +z unless the plane is nearly
/// horizontal, where `u` (right) is the projection of +x.
struct PlaneBasis {
    origin: DVec3,
    n: DVec3,
    u: DVec3,
    v: DVec3,
}

impl PlaneBasis {
    fn new(plane: &CutPlane) -> Option<PlaneBasis> {
        let n = plane.normal.try_normalize()?;
        if !plane.origin.is_finite() {
            return None;
        }
        let (u, v) = if n.z.abs() < 0.9 {
            let v = (DVec3::Z - n.z * n).normalize();
            (v.cross(n), v)
        } else {
            let u = (DVec3::X - n.x * n).normalize();
            (u, n.cross(u))
        };
        Some(PlaneBasis { origin: plane.origin, n, u, v })
    }

    /// (u, v, signed distance to the plane).
    fn coordinates(&self, p: DVec3) -> DVec3 {
        let d = p - self.origin;
        DVec3::new(d.dot(self.u), d.dot(self.v), d.dot(self.n))
    }
}

/// The map from space to the picture: (x pixel, y pixel, signed distance to the plane).
struct Frame {
    basis: PlaneBasis,
    /// Plane coordinates of the view centre's projection (w = 0).
    centre: DVec3,
    /// Pixels per unit length.
    scale: f64,
    width: f64,
    height: f64,
}

impl Frame {
    fn new(plane: &CutPlane, view: &View, width: u32, height: u32) -> Option<Frame> {
        let basis = PlaneBasis::new(plane)?;
        let scale = f64::from(width.min(height)) / (2.0 * view.half_width);
        if !(scale.is_finite() && scale > 0.0 && view.centre.is_finite()) {
            return None;
        }
        let centre = basis.coordinates(view.centre) * DVec3::new(1.0, 1.0, 0.0);
        Some(Frame { basis, centre, scale, width: f64::from(width), height: f64::from(height) })
    }

    /// Each coordinate is affine in `p`, so centroids of local points are local centroids.
    fn local(&self, p: DVec3) -> DVec3 {
        let c = self.basis.coordinates(p) - self.centre;
        DVec3::new(0.5 * self.width + c.x * self.scale, 0.5 * self.height - c.y * self.scale, c.z)
    }

    /// Whether the pixel box of these local points overlaps the picture.
    fn sees(&self, x: &[DVec3]) -> bool {
        let (lo, hi) = pixel_box(x);
        hi.x >= 0.0 && lo.x <= self.width && hi.y >= 0.0 && lo.y <= self.height
    }
}

fn pixel_box(x: &[DVec3]) -> (DVec3, DVec3) {
    x.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
}

/// The picture of the cut of `mesh` by `plane` within `view`, `width` x `height` pixels (each
/// clamped to 1..=8192) on a white background. Cells are filled by `colouring`; the cuts of
/// their faces are stroked in dark grey (not for cells smaller than 2 pixels, which would only
/// darken the picture), boundary faces thicker: walls black, the top of the layers blue. A
/// plane with a zero or non-finite normal, or a view of non-positive width, gives a blank picture.
pub fn cut_picture(
    mesh: &VolumeMesh,
    plane: &CutPlane,
    view: &View,
    colouring: Colouring,
    width: u32,
    height: u32,
) -> Pixmap {
    let (width, height) = (width.clamp(1, MAX_SIDE), height.clamp(1, MAX_SIDE));
    let mut pixmap = blank(width, height);
    if let Some(frame) = Frame::new(plane, view, width, height) {
        let local: Vec<DVec3> = mesh.points.par_iter().map(|&p| frame.local(p)).collect();
        let sections = fold_cut_cells(
            mesh,
            &local,
            || Sections::new(colouring.buckets()),
            |s, kind, nodes, x| s.add_cell(&frame, mesh, colouring, kind, nodes, x),
            Sections::merge,
        );
        sections.draw(&mut pixmap, colouring);
        draw_boundary(&mut pixmap, mesh, &local);
    }
    pixmap
}

/// Largest picture side (tiny-skia draws larger pictures in tiles; nobody needs them here).
const MAX_SIDE: u32 = 8192;

/// Cells whose cut is smaller than this many pixels are filled but not stroked.
const MIN_STROKED_CELL: f64 = 2.0;

const BACKGROUND: [u8; 3] = [255, 255, 255];

/// A picture of this size (clamped to 1..=[`MAX_SIDE`]) filled with the background colour.
pub(super) fn blank(width: u32, height: u32) -> Pixmap {
    let (width, height) = (width.clamp(1, MAX_SIDE), height.clamp(1, MAX_SIDE));
    let mut pixmap = Pixmap::new(width, height).unwrap_or_else(|| unreachable!("{width}x{height} fits"));
    pixmap.fill(colour(BACKGROUND));
    pixmap
}

fn colour([r, g, b]: [u8; 3]) -> Color {
    Color::from_rgba8(r, g, b, 255)
}

/// Fold `visit(acc, kind, nodes, local points)` over every cell crossed by the plane (some node
/// with w < 0, some with w >= 0), in parallel; cells with a bad node index or a non-finite
/// coordinate are skipped.
fn fold_cut_cells<T: Send>(
    mesh: &VolumeMesh,
    local: &[DVec3],
    init: impl Fn() -> T + Sync + Send,
    visit: impl Fn(&mut T, CellKind, &[u32], &[DVec3]) + Sync + Send,
    merge: impl Fn(T, T) -> T + Sync + Send,
) -> T {
    const CELLS_PER_TASK: usize = 4096;
    mesh.blocks
        .par_iter()
        .flat_map(|block| {
            let n = block.kind.node_count();
            block.nodes.par_chunks(n * CELLS_PER_TASK).map(move |chunk| (block.kind, chunk))
        })
        .fold(&init, |mut acc, (kind, chunk)| {
            let n = kind.node_count();
            for nodes in chunk.chunks_exact(n) {
                if let Some(x) = gather(nodes, local) {
                    if crosses_plane(&x[..n]) {
                        visit(&mut acc, kind, nodes, &x[..n]);
                    }
                }
            }
            acc
        })
        .reduce(&init, merge)
}

/// The points of these nodes, if every index is valid and every coordinate finite.
pub(super) fn gather(nodes: &[u32], points: &[DVec3]) -> Option<CellPoints> {
    validity::gather(points, nodes).filter(|x| x[..nodes.len()].iter().all(|p| p.is_finite()))
}

fn crosses_plane(x: &[DVec3]) -> bool {
    x.iter().any(|p| p.z < 0.0) && x.iter().any(|p| p.z >= 0.0)
}

/// The point where segment (p, q) crosses w = 0 (one end has w < 0, the other w >= 0), in pixels.
/// Interpolated from the end with w >= 0, so an end on the plane is returned exactly.
fn crossing(p: DVec3, q: DVec3) -> [f32; 2] {
    let (on, below) = if p.z >= 0.0 { (p, q) } else { (q, p) };
    let s = on.z / (on.z - below.z);
    let x = on + s * (below - on);
    // tiny-skia clips its paths to the picture; only keep the coordinates finite in f32.
    const FAR: f64 = 1e12;
    [x.x.clamp(-FAR, FAR) as f32, x.y.clamp(-FAR, FAR) as f32]
}

/// The section of a tetrahedron (local points) by the plane: a triangle or a quad, in order.
fn tet_section(t: &[DVec3; 4]) -> Option<([[f32; 2]; 4], usize)> {
    let (mut below, mut above) = ([0; 4], [0; 4]);
    let (mut nb, mut na) = (0, 0);
    for (i, p) in t.iter().enumerate() {
        if p.z < 0.0 {
            below[nb] = i;
            nb += 1;
        } else {
            above[na] = i;
            na += 1;
        }
    }
    let cut = |a: usize, b: usize| crossing(t[a], t[b]);
    let fan = |apex: usize, o: [usize; 3]| ([cut(apex, o[0]), cut(apex, o[1]), cut(apex, o[2]), [0.0; 2]], 3);
    match nb {
        1 => Some(fan(below[0], [above[0], above[1], above[2]])),
        3 => Some(fan(above[0], [below[0], below[1], below[2]])),
        2 => {
            let ([a, b], [c, d]) = ([below[0], below[1]], [above[0], above[1]]);
            Some(([cut(a, c), cut(a, d), cut(b, d), cut(b, c)], 4))
        }
        _ => None,
    }
}

/// The cut of a triangle (local points) by the plane: a segment, if the plane crosses it.
fn triangle_section(t: [DVec3; 3]) -> Option<[f32; 4]> {
    let below = t.map(|p| p.z < 0.0);
    let lone = (0..3).find(|&i| below[i] != below[(i + 1) % 3] && below[i] != below[(i + 2) % 3])?;
    let [x0, y0] = crossing(t[lone], t[(lone + 1) % 3]);
    let [x1, y1] = crossing(t[lone], t[(lone + 2) % 3]);
    Some([x0, y0, x1, y1])
}

/// Twice the signed area of a polygon (pixels).
fn signed_area(corners: &[[f32; 2]]) -> f32 {
    let n = corners.len();
    (0..n)
        .map(|i| {
            let ([x0, y0], [x1, y1]) = (corners[i], corners[(i + 1) % n]);
            x0 * y1 - x1 * y0
        })
        .sum()
}

/// Convex polygons of one fill colour, all with positive signed area so that their union is
/// filled once with the non-zero rule.
#[derive(Default)]
struct Polygons {
    corners: Vec<[f32; 2]>,
    sizes: Vec<u8>,
}

impl Polygons {
    fn push(&mut self, corners: &[[f32; 2]]) {
        let area = signed_area(corners);
        if area == 0.0 || !area.is_finite() {
            return;
        }
        let start = self.corners.len();
        self.corners.extend_from_slice(corners);
        if area < 0.0 {
            self.corners[start..].reverse();
        }
        self.sizes.push(corners.len() as u8);
    }

    fn append(&mut self, mut other: Polygons) {
        self.corners.append(&mut other.corners);
        self.sizes.append(&mut other.sizes);
    }

    fn path(&self) -> Option<tiny_skia::Path> {
        let mut path = PathBuilder::with_capacity(self.corners.len() + self.sizes.len(), self.corners.len());
        let mut corners = self.corners.iter();
        for &size in &self.sizes {
            for (k, &[x, y]) in corners.by_ref().take(size as usize).enumerate() {
                if k == 0 {
                    path.move_to(x, y);
                } else {
                    path.line_to(x, y);
                }
            }
            path.close();
        }
        path.finish()
    }
}

/// The cut cells, as fills per colour and the segments of their cut faces.
struct Sections {
    fills: Vec<Polygons>,
    edges: Vec<[f32; 4]>,
}

impl Sections {
    fn new(buckets: usize) -> Sections {
        Sections { fills: (0..buckets).map(|_| Polygons::default()).collect(), edges: Vec::new() }
    }

    fn merge(mut self, mut other: Sections) -> Sections {
        for (mine, theirs) in self.fills.iter_mut().zip(other.fills) {
            mine.append(theirs);
        }
        self.edges.append(&mut other.edges);
        self
    }

    /// Add the section of one cell (`x`: its local points) if the picture sees it.
    fn add_cell(
        &mut self,
        frame: &Frame,
        mesh: &VolumeMesh,
        colouring: Colouring,
        kind: CellKind,
        nodes: &[u32],
        x: &[DVec3],
    ) {
        if !frame.sees(x) {
            return;
        }
        let Some(world) = gather(nodes, &mesh.points) else { return };
        let mut local = [DVec3::ZERO; 8];
        local[..x.len()].copy_from_slice(x);
        let fill = &mut self.fills[colouring.bucket(kind, &world).min(colouring.buckets() - 1)];
        for_each_subtet(kind, &local, |_, t| {
            if let Some((corners, n)) = tet_section(&t) {
                fill.push(&corners[..n]);
            }
        });
        let (lo, hi) = pixel_box(x);
        if (hi - lo).truncate().max_element() >= MIN_STROKED_CELL {
            for face in kind.faces() {
                add_face_cut(face.iter().map(|&k| local[k]), &mut self.edges);
            }
        }
    }

    fn draw(&self, pixmap: &mut Pixmap, colouring: Colouring) {
        for (bucket, polygons) in self.fills.iter().enumerate() {
            if let Some(path) = polygons.path() {
                let mut paint = paint(bucket_colour(colouring, bucket));
                // Pixel-centre sampling tiles neighbouring fills without seams; strokes smooth them.
                paint.anti_alias = false;
                pixmap.fill_path(&path, &paint, FillRule::Winding, Transform::identity(), None);
            }
        }
        stroke_segments(pixmap, &self.edges, EDGE_COLOUR, 1.0);
    }
}

const EDGE_COLOUR: [u8; 3] = [70, 70, 70];
const WALL_COLOUR: [u8; 3] = [0, 0, 0];
const TOP_COLOUR: [u8; 3] = [30, 70, 200];

pub(super) fn paint(rgb: [u8; 3]) -> Paint<'static> {
    let mut paint = Paint::default();
    paint.set_color(colour(rgb));
    paint
}

/// Push the cut of one face (3 or 4 local points; a quad is cut as its 4 triangles, the same
/// decomposition as the fill).
fn add_face_cut(corners: impl Iterator<Item = DVec3>, segments: &mut Vec<[f32; 4]>) {
    let mut face = [DVec3::ZERO; 4];
    let mut n = 0;
    for (slot, p) in face.iter_mut().zip(corners) {
        *slot = p;
        n += 1;
    }
    face_triangles(&face[..n], |t| segments.extend(triangle_section(t)));
}

/// All segments in one path, stroked once (so segments drawn twice are not darker).
fn stroke_segments(pixmap: &mut Pixmap, segments: &[[f32; 4]], rgb: [u8; 3], width: f32) {
    let mut path = PathBuilder::with_capacity(2 * segments.len(), 2 * segments.len());
    for &[x0, y0, x1, y1] in segments {
        path.move_to(x0, y0);
        path.line_to(x1, y1);
    }
    if let Some(path) = path.finish() {
        let stroke = Stroke { width, ..Stroke::default() };
        pixmap.stroke_path(&path, &paint(rgb), &stroke, Transform::identity(), None);
    }
}

/// Stroke the cuts of the boundary faces: the layers' top (patch [`TOP_PATCH`]) in blue, every
/// other patch as a wall in black, on top of the cells.
fn draw_boundary(pixmap: &mut Pixmap, mesh: &VolumeMesh, local: &[DVec3]) {
    let top = mesh.patch_names.iter().position(|n| n == TOP_PATCH).map(|p| p as u32);
    let (mut walls, mut tops) = (Vec::new(), Vec::new());
    let b = &mesh.boundary;
    let triangles = b.triangles.iter().map(|t| &t[..]).zip(&b.triangle_patch);
    let quads = b.quads.iter().map(|q| &q[..]).zip(&b.quad_patch);
    for (face, &patch) in triangles.chain(quads) {
        let Some(x) = gather(face, local) else { continue };
        if crosses_plane(&x[..face.len()]) {
            let segments = if Some(patch) == top { &mut tops } else { &mut walls };
            add_face_cut(x[..face.len()].iter().copied(), segments);
        }
    }
    stroke_segments(pixmap, &tops, TOP_COLOUR, 2.0);
    stroke_segments(pixmap, &walls, WALL_COLOUR, 2.5);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: f64, y: f64, w: f64) -> DVec3 {
        DVec3::new(x, y, w)
    }

    #[test]
    fn tet_sections_are_triangles_and_quads() {
        let t = [p(0.0, 0.0, -1.0), p(2.0, 0.0, 1.0), p(0.0, 2.0, 1.0), p(0.0, 0.0, 1.0)];
        let (corners, n) = tet_section(&t).unwrap();
        assert_eq!(n, 3);
        assert_eq!(&corners[..3], &[[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]]);
        let t = [p(0.0, 0.0, -1.0), p(2.0, 0.0, -1.0), p(0.0, 2.0, 1.0), p(2.0, 2.0, 3.0)];
        let (corners, n) = tet_section(&t).unwrap();
        assert_eq!(n, 4);
        assert_eq!(corners, [[0.0, 1.0], [0.5, 0.5], [2.0, 0.5], [1.0, 1.0]]);
        assert_eq!(signed_area(&corners), 1.25);
        assert!(tet_section(&[p(0.0, 0.0, 1.0); 4]).is_none());
    }

    #[test]
    fn a_face_on_the_plane_belongs_to_the_cell_below() {
        let face = [p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(0.0, 1.0, 0.0)];
        let below = [face[0], face[1], face[2], p(0.0, 0.0, -1.0)];
        let above = [face[0], face[1], face[2], p(0.0, 0.0, 1.0)];
        let (corners, n) = tet_section(&below).unwrap();
        assert_eq!(&corners[..n], &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], "exactly the face");
        assert!(tet_section(&above).is_none());
        assert!(triangle_section(face).is_none());
        assert_eq!(triangle_section([face[0], face[1], below[3]]), Some([0.0, 0.0, 1.0, 0.0]));
    }

    #[test]
    fn basis_is_orthonormal_and_right_handed() {
        for normal in [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::Z, DVec3::new(1.0, 1.0, 0.0), DVec3::splat(-2.0)]
        {
            let b = PlaneBasis::new(&CutPlane { origin: DVec3::ZERO, normal }).unwrap();
            assert!((b.u.length() - 1.0).abs() < 1e-12 && (b.v.length() - 1.0).abs() < 1e-12);
            assert!(b.u.dot(b.v).abs() < 1e-12 && b.u.dot(b.n).abs() < 1e-12);
            assert!((b.u.cross(b.v) - b.n).length() < 1e-12, "{normal}");
        }
        let b = PlaneBasis::new(&CutPlane { origin: DVec3::ZERO, normal: DVec3::Z }).unwrap();
        assert_eq!((b.u, b.v), (DVec3::X, DVec3::Y));
        let b = PlaneBasis::new(&CutPlane { origin: DVec3::ZERO, normal: DVec3::X }).unwrap();
        assert_eq!((b.u, b.v), (DVec3::Y, DVec3::Z));
        for normal in [DVec3::ZERO, DVec3::new(f64::NAN, 0.0, 1.0)] {
            assert!(PlaneBasis::new(&CutPlane { origin: DVec3::ZERO, normal }).is_none());
        }
    }
}
