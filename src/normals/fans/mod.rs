//! Columns at wall vertices: one most-normal column per sector, fans across convex ridges,
//! spherical patches at convex corners.
//!
//! Around a vertex, the convex ridge edges ("fan edges") cut the ring of incident triangles
//! into sectors; each sector gets one column along the most normal direction of its triangles.
//! Across a fan edge (v, w) the front opens like the exact offset (a cylinder): a strip of quads
//! joins `m + 1` columns at v to `m + 1` columns at w, their directions turning from one sector's
//! direction to the other's in steps of at most the fan angle. `m` is the same along a whole
//! ridge line, so that ridge vertices share their fan columns between their two ridge edges.
//! Where three or more fan edges meet (a convex corner), the hole left between the strips is a
//! spherical polygon of directions, filled by a web of rings around its most normal direction
//! (the exact offset there is a sphere).
//!
//! Strip orientation: for a fan edge used as v -> w by triangle `t1` and w -> v by `t2`, fan index
//! 0 is on `t1`'s side; quad j is `(w_j, v_j, v_j+1, w_j+1)`, which runs along the shared column
//! edges opposite to `t1` and `t2`, so the front stays consistently oriented.

mod ridge_roots;

use glam::DVec3;

use super::most_normal::most_normal;
use crate::geometry::predicates::{orient2d, Sign};
use crate::geometry::triangle_min_angle;
use crate::layers::slab::Polygon;
use crate::surface::features::{EdgeKind, Features};
use crate::surface::topology::Topology;
use crate::surface::Surface;
use ridge_roots::RidgeRoot;

/// One column to extrude: from wall vertex `vertex` along `direction`, `scale` times the layer
/// distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColumnSeed {
    pub vertex: u32,
    pub direction: DVec3,
    pub scale: f64,
}

/// A face of a fan strip or corner patch: 3 or 4 columns, oriented into the fluid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FanFace {
    cols: [u32; 4],
    len: u8,
    pub patch: u32,
}

impl FanFace {
    fn new(cols: &[u32], patch: u32) -> Self {
        let mut c = [0; 4];
        c[..cols.len()].copy_from_slice(cols);
        FanFace { cols: c, len: cols.len() as u8, patch }
    }

    pub fn columns(&self) -> &[u32] {
        &self.cols[..self.len as usize]
    }
}

/// Counts for the report.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct NormalStats {
    pub columns: usize,
    pub fan_columns: usize,
    pub fan_edges: usize,
    pub corner_patches: usize,
    /// Convex ridges ending on concave ones, whose fans go on to their root
    /// ([`ridge_roots`]: a wing's trailing edge on a plate).
    pub ridge_roots: usize,
    /// Sectors where no single direction sees all their faces (an angle-weighted normal is used).
    pub no_common_normal: usize,
}

/// The extrusion directions of the whole wall.
#[derive(Clone, Debug, Default)]
pub struct WallNormals {
    pub columns: Vec<ColumnSeed>,
    /// The column of each corner of each wall triangle.
    pub triangle_columns: Vec<[u32; 3]>,
    pub fan_faces: Vec<FanFace>,
    /// How each column may move ([`super::constraint::constrain_columns`]); empty: all free.
    pub slides: Vec<super::constraint::Slide>,
    /// At every ridge root ([`ridge_roots`]), the directions across the ridge its fan columns
    /// turn towards the floor, as (wall vertex, direction), sorted by vertex: the normals of the
    /// ridge's offset cylinder there, a wall of their own for the entropy merges
    /// ([`crate::layers::entropy::VertexWalls`]).
    pub cylinder_normals: Vec<(u32, DVec3)>,
    pub stats: NormalStats,
}

/// Triangles around a vertex in counter-clockwise order (seen from the fluid), each with its
/// corner index at the vertex; `cut_after[i]` is the edge between triangle i and i + 1.
struct Ring {
    triangles: Vec<(u32, usize)>,
    edge_after: Vec<u32>,
}

fn vertex_ring(surface: &Surface, topology: &Topology, v: u32) -> Ring {
    let incident = topology.vertex_triangles(v);
    let corner = |t: u32| surface.triangles[t as usize].iter().position(|&x| x == v).unwrap_or(0);
    let mut triangles = Vec::with_capacity(incident.len());
    let mut edge_after = Vec::with_capacity(incident.len());
    let mut t = incident[0];
    for _ in 0..incident.len() {
        let i = corner(t);
        // t = (v, a, b): the next triangle around v uses the edge (v, b) as v -> b.
        let edge = topology.triangle_edges[t as usize][(i + 2) % 3];
        triangles.push((t, i));
        edge_after.push(edge);
        t = topology.other_triangle(edge, t);
    }
    Ring { triangles, edge_after }
}

/// Build the columns and fan faces of the wall (every patch layered).
pub fn wall_normals(
    surface: &Surface,
    topology: &Topology,
    features: &Features,
    fan_angle_deg: f64,
) -> WallNormals {
    wall_normals_of_layered(surface, topology, features, fan_angle_deg, &[])
}

/// Build the columns and fan faces of the wall where patch `p` gets layers when
/// `layered_patch[p]` (missing entries: layered). The triangles of the other patches get
/// columns of their own (they do not move), the layered triangles' columns see only layered
/// triangles, and only ridges between layered triangles get fans.
pub fn wall_normals_of_layered(
    surface: &Surface,
    topology: &Topology,
    features: &Features,
    fan_angle_deg: f64,
    layered_patch: &[bool],
) -> WallNormals {
    let fan_angle = fan_angle_deg.to_radians();
    let mut out =
        WallNormals { triangle_columns: vec![[u32::MAX; 3]; surface.triangles.len()], ..Default::default() };
    let layered =
        |t: u32| layered_patch.get(surface.triangle_patch[t as usize] as usize).copied().unwrap_or(true);
    let uses_layered = |e: u32| topology.edge_uses(e).iter().map(|u| layered(u.triangle));
    let is_fan_edge =
        |e: u32| features.edge_kind[e as usize] == EdgeKind::ConvexRidge && uses_layered(e).all(|l| l);
    // Sectors also end where the layered triangles end.
    let is_cut = |e: u32| is_fan_edge(e) || (uses_layered(e).any(|l| l) && uses_layered(e).any(|l| !l));
    // Per (vertex, fan edge): the sector columns on the edge's t1 side (index 0) and t2 side.
    let mut fan_ends: Vec<Vec<(u32, u32, u32)>> = vec![Vec::new(); surface.points.len()];
    let roots = ridge_roots::find(surface, topology, features, &is_cut);
    let mut next_root = roots.iter().peekable();
    for v in 0..surface.points.len() as u32 {
        if topology.vertex_triangles(v).is_empty() {
            continue;
        }
        if let Some(root) = next_root.next_if(|r| r.vertex == v) {
            root.side_columns(surface, topology, &mut out, &mut fan_ends[v as usize]);
            continue;
        }
        let ring = vertex_ring(surface, topology, v);
        let cuts = (&is_cut, &is_fan_edge);
        sector_columns(surface, topology, v, &ring, cuts, &mut out, &mut fan_ends[v as usize]);
    }
    let fan_edges: Vec<u32> = (0..topology.edge_count() as u32).filter(|&e| is_fan_edge(e)).collect();
    let segments = fan_segments(topology, &fan_edges, &fan_ends, &out.columns, fan_angle);
    let fans = fan_columns(surface, topology, &fan_edges, &segments, &fan_ends, &roots, &mut out);
    strips(surface, topology, &fan_edges, &segments, &fans, &mut out);
    for root in &roots {
        let i = fan_edges.binary_search(&root.ridge).expect("a ridge root's ridge is a fan edge");
        let side = usize::from(topology.edges[root.ridge as usize][1] == root.vertex);
        root.close_onto_floor(surface, &fans.at[i][side], &mut out);
    }
    out.stats.ridge_roots = roots.len();
    out.cylinder_normals.sort_by_key(|&(v, _)| v);
    corner_patches(surface, topology, &fan_edges, &fan_ends, &fans, fan_angle, &mut out);
    out.stats.columns = out.columns.len();
    out.stats.fan_edges = fan_edges.len();
    out
}

/// One column per sector of the ring; records the columns on both sides of each fan edge.
fn sector_columns(
    surface: &Surface,
    topology: &Topology,
    v: u32,
    ring: &Ring,
    (is_cut, is_fan_edge): (&impl Fn(u32) -> bool, &impl Fn(u32) -> bool),
    out: &mut WallNormals,
    ends: &mut Vec<(u32, u32, u32)>,
) {
    let n = ring.triangles.len();
    // Start the walk just after a cut, so each sector is contiguous.
    let start = (0..n).find(|&i| is_cut(ring.edge_after[i])).map_or(0, |i| (i + 1) % n);
    let mut sector: Vec<(u32, usize)> = Vec::new();
    let mut sector_col_of_ring = vec![0u32; n];
    for step in 0..n {
        let i = (start + step) % n;
        sector.push(ring.triangles[i]);
        if is_cut(ring.edge_after[i]) || step == n - 1 {
            let col = push_sector_column(surface, v, &sector, out);
            for k in 0..sector.len() {
                sector_col_of_ring[(i + n - k) % n] = col;
            }
            sector.clear();
        }
    }
    for i in 0..n {
        let e = ring.edge_after[i];
        if is_fan_edge(e) {
            // The triangle after e in the ring uses e as v -> other, so it is t1 (which runs
            // from edges[e][0] to edges[e][1]) when v is the edge's first vertex.
            let (after, before) = (sector_col_of_ring[(i + 1) % n], sector_col_of_ring[i]);
            ends.push(if topology.edges[e as usize][0] == v {
                (e, after, before)
            } else {
                (e, before, after)
            });
        }
    }
}

fn push_sector_column(surface: &Surface, v: u32, sector: &[(u32, usize)], out: &mut WallNormals) -> u32 {
    let normals: Vec<DVec3> = sector.iter().map(|&(t, _)| surface.triangle_normal(t as usize)).collect();
    let (direction, scale) = match most_normal(&normals) {
        Some(m) => (m.direction, m.extrusion_scale()),
        None => {
            out.stats.no_common_normal += 1;
            (angle_weighted_normal(surface, sector), 1.0)
        }
    };
    let col = out.columns.len() as u32;
    out.columns.push(ColumnSeed { vertex: v, direction, scale });
    for &(t, corner) in sector {
        out.triangle_columns[t as usize][corner] = col;
    }
    col
}

fn angle_weighted_normal(surface: &Surface, sector: &[(u32, usize)]) -> DVec3 {
    let mut sum = DVec3::ZERO;
    for &(t, corner) in sector {
        let p = surface.triangle_points(t as usize);
        let (a, b, c) = (p[corner], p[(corner + 1) % 3], p[(corner + 2) % 3]);
        let angle = (b - a).angle_between(c - a);
        sum += angle * surface.triangle_normal(t as usize);
    }
    sum.normalize_or(surface.triangle_normal(sector[0].0 as usize))
}

/// Sector columns (t1 side, t2 side) of fan edge `e` at vertex `v`.
fn ends_at(fan_ends: &[Vec<(u32, u32, u32)>], v: u32, e: u32) -> (u32, u32) {
    fan_ends[v as usize].iter().find(|x| x.0 == e).map_or((u32::MAX, u32::MAX), |x| (x.1, x.2))
}

/// Number of fan segments `m` of every fan edge: enough for the fan angle at both ends, and
/// the largest along each ridge line (chains of fan edges through vertices with two of them).
fn fan_segments(
    topology: &Topology,
    fan_edges: &[u32],
    fan_ends: &[Vec<(u32, u32, u32)>],
    columns: &[ColumnSeed],
    fan_angle: f64,
) -> Vec<u32> {
    let index_of = |e: u32| fan_edges.binary_search(&e).ok();
    let mut m: Vec<u32> = fan_edges
        .iter()
        .map(|&e| {
            let [v, w] = topology.edges[e as usize];
            let angle = [v, w]
                .iter()
                .map(|&x| {
                    let (a, b) = ends_at(fan_ends, x, e);
                    columns[a as usize].direction.angle_between(columns[b as usize].direction)
                })
                .fold(0.0, f64::max);
            ((angle / fan_angle).ceil() as u32).max(1)
        })
        .collect();
    // Ridge lines: union the two fan edges of every vertex that has exactly two.
    let mut parent: Vec<usize> = (0..fan_edges.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for ends in fan_ends.iter().filter(|ends| ends.len() == 2) {
        if let (Some(a), Some(b)) = (index_of(ends[0].0), index_of(ends[1].0)) {
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
            parent[ra] = rb;
        }
    }
    let mut line_max = vec![0u32; fan_edges.len()];
    for i in 0..fan_edges.len() {
        let r = root(&mut parent, i);
        line_max[r] = line_max[r].max(m[i]);
    }
    for i in 0..fan_edges.len() {
        m[i] = line_max[root(&mut parent, i)];
    }
    m
}

/// The m + 1 columns across each fan edge at each of its two ends (index 0 on t1's side).
struct FanColumns {
    /// Per fan edge (in `fan_edges` order): columns at [v, w] of `topology.edges[e as usize]`.
    at: Vec<[Vec<u32>; 2]>,
}

fn fan_columns(
    surface: &Surface,
    topology: &Topology,
    fan_edges: &[u32],
    segments: &[u32],
    fan_ends: &[Vec<(u32, u32, u32)>],
    roots: &[RidgeRoot],
    out: &mut WallNormals,
) -> FanColumns {
    let mut at: Vec<[Vec<u32>; 2]> = vec![[Vec::new(), Vec::new()]; fan_edges.len()];
    for (i, &e) in fan_edges.iter().enumerate() {
        let m = segments[i] as usize;
        for (side, &v) in topology.edges[e as usize].iter().enumerate() {
            let ends = &fan_ends[v as usize];
            let (a, b) = ends_at(fan_ends, v, e);
            if let Ok(r) = roots.binary_search_by_key(&v, |r| r.vertex) {
                at[i][side] = roots[r].fan(surface, topology, (a, b), m, out);
                continue;
            }
            // A ridge vertex shares its fan between its two ridge edges, if the other edge's
            // fan is already built between the same two sector columns.
            let shared = (ends.len() == 2)
                .then(|| ends.iter().find(|x| x.0 != e).map(|x| x.0))
                .flatten()
                .and_then(|other| {
                    let j = fan_edges.binary_search(&other).ok()?;
                    let side_other = topology.edges[other as usize].iter().position(|&x| x == v)?;
                    let cols = &at[j][side_other];
                    match (cols.first(), cols.last()) {
                        _ if cols.len() != m + 1 => None,
                        (Some(&x), Some(&y)) if (x, y) == (a, b) => Some(cols.clone()),
                        (Some(&x), Some(&y)) if (x, y) == (b, a) => {
                            Some(cols.iter().rev().copied().collect())
                        }
                        _ => None,
                    }
                });
            let other = (ends.len() == 2).then(|| ends.iter().find(|x| x.0 != e).copied()).flatten();
            at[i][side] = match (shared, other) {
                (Some(cols), _) => cols,
                (None, Some(other)) if a != b => {
                    ridge_vertex_fan(surface, topology, v, (e, other), (a, b), m, out)
                }
                (None, _) => interpolated_fan(v, a, b, m, out),
            };
        }
    }
    FanColumns { at }
}

/// The normals of the triangles on the t1 and t2 sides of edge `e`, and its unit direction
/// leaving vertex `v`.
fn edge_sides(surface: &Surface, topology: &Topology, e: u32, v: u32) -> (DVec3, DVec3, DVec3) {
    let [p, q] = topology.edges[e as usize];
    let t1 = topology.triangle_using(e, p, q);
    let t2 = topology.other_triangle(e, t1);
    let w = if p == v { q } else { p };
    let dir = (surface.points[w as usize] - surface.points[v as usize]).normalize_or_zero();
    (surface.triangle_normal(t1 as usize), surface.triangle_normal(t2 as usize), dir)
}

/// Columns across fan edge `e` at a vertex whose other fan edge is `other` (an entry of the
/// vertex's fan ends): each column ends where the offset cylinders around the two edges meet,
/// so the front stays at the layer distance from both. On a straight ridge that is the plain
/// fan; where the ridge turns (at a saddle, where a concave bisector meets the fan) the columns
/// lengthen and lean, as the exact offset does.
fn ridge_vertex_fan(
    surface: &Surface,
    topology: &Topology,
    v: u32,
    (e, other): (u32, (u32, u32, u32)),
    (a, b): (u32, u32),
    m: usize,
    out: &mut WallNormals,
) -> Vec<u32> {
    let (p1, q1, d1) = edge_sides(surface, topology, e, v);
    let (p2, q2, d2) = edge_sides(surface, topology, other.0, v);
    // The other edge's fan runs from its t1 side; it turns the same way as ours if that side is
    // the same sector as ours.
    let same_way = other.1 == a;
    let mut cols = vec![a];
    for j in 1..m {
        let t = j as f64 / m as f64;
        let u1 = slerp(p1, q1, t);
        let u2 = if same_way { slerp(p2, q2, t) } else { slerp(q2, p2, t) };
        let (direction, scale) = match cylinders_meet(u1, d1, u2, d2) {
            Some(x) if x.length() <= MAX_RIDGE_FAN_SCALE => (x.normalize(), x.length()),
            _ => (slerp(out.columns[a as usize].direction, out.columns[b as usize].direction, t), 1.0),
        };
        cols.push(out.columns.len() as u32);
        out.columns.push(ColumnSeed { vertex: v, direction, scale });
        out.stats.fan_columns += 1;
    }
    cols.push(b);
    cols
}

/// Where a ridge turns by less than this angle (radians) its fans stay plain.
const RIDGE_TURN: f64 = std::f64::consts::FRAC_PI_6;

/// Longest ridge-vertex fan column, in layer distances (beyond it the two edges are nearly
/// parallel and the plain fan is used).
const MAX_RIDGE_FAN_SCALE: f64 = 3.0;

/// The point at unit distance from both edge lines through the origin (directions `d1`, `d2`),
/// reached along the fan directions `u1` and `u2` (each perpendicular to its edge): the
/// least-squares meeting point of `u1 + alpha d1` and `u2 + beta d2`. `None` for parallel edges.
fn cylinders_meet(u1: DVec3, d1: DVec3, u2: DVec3, d2: DVec3) -> Option<DVec3> {
    let c = d1.dot(d2);
    let det = 1.0 - c * c;
    // Edges continuing each other (a ridge turning by less than RIDGE_TURN) keep the plain fan.
    if c < -RIDGE_TURN.cos() || det < 1e-9 {
        return None;
    }
    let r = u2 - u1;
    // Normal equations of min |alpha d1 - beta d2 - r|^2.
    let (r1, r2) = (d1.dot(r), -d2.dot(r));
    let alpha = (r1 + c * r2) / det;
    let beta = (c * r1 + r2) / det;
    Some(0.5 * ((u1 + alpha * d1) + (u2 + beta * d2)))
}

/// Columns from `a` (index 0) to `b` (index m) at vertex v, new ones in between.
fn interpolated_fan(v: u32, a: u32, b: u32, m: usize, out: &mut WallNormals) -> Vec<u32> {
    let mut cols = vec![a];
    let (da, db) = (out.columns[a as usize].direction, out.columns[b as usize].direction);
    for j in 1..m {
        let cols_len = out.columns.len() as u32;
        let direction = if a == b { da } else { slerp(da, db, j as f64 / m as f64) };
        if a == b {
            cols.push(a); // A ridge ending here: the fan closes onto the single sector column.
            continue;
        }
        out.columns.push(ColumnSeed { vertex: v, direction, scale: 1.0 });
        out.stats.fan_columns += 1;
        cols.push(cols_len);
    }
    cols.push(b);
    cols
}

/// Spherical linear interpolation between unit vectors (falls back to a normalised lerp).
fn slerp(a: DVec3, b: DVec3, t: f64) -> DVec3 {
    let angle = a.angle_between(b);
    if angle < 1e-9 || (std::f64::consts::PI - angle) < 1e-6 {
        return a.lerp(b, t).normalize_or(a);
    }
    let s = angle.sin();
    (a * ((1.0 - t) * angle).sin() / s + b * (t * angle).sin() / s).normalize()
}

fn strips(
    surface: &Surface,
    topology: &Topology,
    fan_edges: &[u32],
    segments: &[u32],
    fans: &FanColumns,
    out: &mut WallNormals,
) {
    for (i, &e) in fan_edges.iter().enumerate() {
        let [v, w] = topology.edges[e as usize];
        let t1 = topology.triangle_using(e, v, w);
        let patch = surface.triangle_patch[t1 as usize];
        let (vc, wc) = (&fans.at[i][0], &fans.at[i][1]);
        for j in 0..segments[i] as usize {
            let quad = [wc[j], vc[j], vc[j + 1], wc[j + 1]];
            // A ridge ending at both ends (a single fan column each) needs no strip.
            if let Some(face) = Polygon::dedup(&quad) {
                out.fan_faces.push(FanFace::new(face.nodes(), patch));
            }
        }
    }
}

/// Fill the hole at every vertex with three or more fan edges.
fn corner_patches(
    surface: &Surface,
    topology: &Topology,
    fan_edges: &[u32],
    fan_ends: &[Vec<(u32, u32, u32)>],
    fans: &FanColumns,
    fan_angle: f64,
    out: &mut WallNormals,
) {
    for (v, ends) in fan_ends.iter().enumerate() {
        if ends.len() < 3 {
            continue;
        }
        // Walking counter-clockwise, each fan edge is crossed from the sector before it to
        // the sector after it: from index m to 0 where v is the edge's first vertex (the
        // triangle after is t1), from 0 to m otherwise. Each fan adds all but its last column
        // (the next fan starts with it).
        let mut polygon = Vec::new();
        for &(e, _, _) in ends {
            let Ok(i) = fan_edges.binary_search(&e) else { continue };
            let first = topology.edges[e as usize][0] as usize == v;
            let cols = &fans.at[i][if first { 0 } else { 1 }];
            if first {
                polygon.extend(cols[1..].iter().rev().copied());
            } else {
                polygon.extend(cols[..cols.len() - 1].iter().copied());
            }
        }
        let patch = surface.triangle_patch[topology.vertex_triangles(v as u32)[0] as usize];
        web_patch(v as u32, &polygon, patch, fan_angle, out);
        out.stats.corner_patches += 1;
    }
}

/// Fill the spherical polygon of columns `polygon` (oriented as the front) with rings of new
/// columns around its most normal direction, `fan_angle` apart at most along the spokes.
fn web_patch(v: u32, polygon: &[u32], patch: u32, fan_angle: f64, out: &mut WallNormals) {
    let dirs: Vec<DVec3> = polygon.iter().map(|&c| out.columns[c as usize].direction).collect();
    let centre_dir =
        most_normal(&dirs).map_or_else(|| dirs.iter().sum::<DVec3>().normalize(), |m| m.direction);
    let spoke = dirs.iter().map(|d| d.angle_between(centre_dir)).fold(0.0, f64::max);
    let rings = ((spoke / fan_angle).ceil() as usize).max(1);
    let new_column = |direction: DVec3, out: &mut WallNormals| {
        out.columns.push(ColumnSeed { vertex: v, direction, scale: 1.0 });
        out.stats.fan_columns += 1;
        out.columns.len() as u32 - 1
    };
    if !star_shaped(centre_dir, &dirs) {
        // Rings around the centre would turn over where the polygon folds back (a corner of
        // three ridges on a coarse, irregular wall): its own columns, ear by ear, instead.
        if let Some(triangles) = ear_triangles(centre_dir, &dirs) {
            tracing::debug!(vertex = v, columns = dirs.len(), "corner patch cut into ears");
            for [a, b, c] in triangles {
                out.fan_faces.push(FanFace::new(&[polygon[a], polygon[b], polygon[c]], patch));
            }
            return;
        }
    }
    let centre = new_column(centre_dir, out);
    // ring[l][i]: l = 1..rings-1 inner rings, the polygon itself is ring `rings`.
    let mut previous: Vec<u32> = Vec::new();
    for l in 1..=rings {
        let ring: Vec<u32> = if l == rings {
            polygon.to_vec()
        } else {
            dirs.iter().map(|&d| new_column(slerp(centre_dir, d, l as f64 / rings as f64), out)).collect()
        };
        let n = ring.len();
        for i in 0..n {
            let j = (i + 1) % n;
            let face = if l == 1 {
                FanFace::new(&[centre, ring[i], ring[j]], patch)
            } else {
                FanFace::new(&[previous[j], previous[i], ring[i], ring[j]], patch)
            };
            out.fan_faces.push(face);
        }
        previous = ring;
    }
}

/// Whether every triangle `(centre, d_i, d_i+1)` of the polygon of directions `dirs` turns the
/// front's way (seen from outside the unit sphere): its first cells, cones from the wall point,
/// then have positive volumes.
fn star_shaped(centre: DVec3, dirs: &[DVec3]) -> bool {
    let n = dirs.len();
    (0..n).all(|i| centre.dot(dirs[i].cross(dirs[(i + 1) % n])) > 0.0)
}

/// A triangulation of the polygon of directions `dirs` (the front's way round) by ear clipping,
/// seen through the tangent plane at `centre` (a direction's point there is `d / (d . centre)`):
/// triangles of polygon indices, or `None` when some direction is not in front of the plane or
/// no ear is left (the polygon crosses itself there).
fn ear_triangles(centre: DVec3, dirs: &[DVec3]) -> Option<Vec<[usize; 3]>> {
    if dirs.iter().any(|d| d.dot(centre) <= 1e-6) {
        return None;
    }
    // Every direction's point on the tangent plane, in coordinates of the plane (z = 0).
    let x_axis = centre.any_orthonormal_vector();
    let y_axis = centre.cross(x_axis);
    let plane: Vec<DVec3> = dirs
        .iter()
        .map(|&d| {
            let p = d / d.dot(centre);
            DVec3::new(p.dot(x_axis), p.dot(y_axis), 0.0)
        })
        .collect();
    let xy = |i: usize| [plane[i].x, plane[i].y];
    let turn = |a: usize, b: usize, c: usize| orient2d(xy(a), xy(b), xy(c));
    let mut left: Vec<usize> = (0..dirs.len()).collect();
    let mut triangles = Vec::with_capacity(dirs.len().saturating_sub(2));
    while left.len() > 3 {
        let n = left.len();
        let corners = |i: usize| (left[(i + n - 1) % n], left[i], left[(i + 1) % n]);
        let ears = (0..n).filter(|&i| {
            let (a, b, c) = corners(i);
            turn(a, b, c) == Sign::Positive
                && left.iter().filter(|&&q| q != a && q != b && q != c).all(|&q| {
                    let outside = |x: usize, y: usize| turn(x, y, q) == Sign::Negative;
                    outside(a, b) || outside(b, c) || outside(c, a)
                })
        });
        // The best shaped ear first: the front over the patch is made of these triangles.
        let shape = |i: usize| {
            let (a, b, c) = corners(i);
            triangle_min_angle(plane[a], plane[b], plane[c])
        };
        let ear = ears.max_by(|&i, &j| shape(i).total_cmp(&shape(j)))?;
        let (a, b, c) = corners(ear);
        triangles.push([a, b, c]);
        left.remove(ear);
    }
    let [a, b, c] = [left[0], left[1], left[2]];
    (turn(a, b, c) == Sign::Positive).then_some(())?;
    triangles.push([a, b, c]);
    Some(triangles)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::shapes;

    fn cube_normals(n: usize) -> (Surface, WallNormals) {
        let s = shapes::cuboid(DVec3::ONE, n);
        let topo = Topology::new(&s);
        let features = Features::compute(&s, &topo, 30.0);
        let normals = wall_normals(&s, &topo, &features, 20.0);
        (s, normals)
    }

    /// Every fan face, lifted to distance 1 along its columns, faces away from the body
    /// (its Newell normal agrees with its columns' mean direction).
    #[test]
    fn fan_faces_face_the_fluid() {
        let (s, normals) = cube_normals(2);
        for f in &normals.fan_faces {
            let pts: Vec<DVec3> = f
                .columns()
                .iter()
                .map(|&c| {
                    let seed = normals.columns[c as usize];
                    s.points[seed.vertex as usize] + seed.direction
                })
                .collect();
            let mut newell = DVec3::ZERO;
            for i in 0..pts.len() {
                newell += pts[i].cross(pts[(i + 1) % pts.len()]);
            }
            let mean: DVec3 = f.columns().iter().map(|&c| normals.columns[c as usize].direction).sum();
            assert!(newell.dot(mean) > 0.0, "fan face {:?} faces the body", f.columns());
        }
    }
}

#[cfg(test)]
mod closed_front_tests {
    use super::*;
    use std::collections::HashMap;

    /// Directed column edges of the initial front that have no opposite twin.
    pub(crate) fn unmatched_edges(normals: &WallNormals) -> Vec<(u32, u32)> {
        let mut count: HashMap<(u32, u32), i32> = HashMap::new();
        let faces = normals
            .triangle_columns
            .iter()
            .map(|t| t.as_slice())
            .chain(normals.fan_faces.iter().map(|f| f.columns()));
        for cols in faces {
            for i in 0..cols.len() {
                let (a, b) = (cols[i], cols[(i + 1) % cols.len()]);
                if a != b {
                    *count.entry((a, b)).or_default() += 1;
                }
            }
        }
        let mut bad: Vec<(u32, u32)> = count
            .iter()
            .filter(|(&(a, b), &n)| n != 1 || count.get(&(b, a)) != Some(&1))
            .map(|(&e, _)| e)
            .collect();
        bad.sort_unstable();
        bad
    }

    #[test]
    fn initial_front_is_closed_on_real_geometries() {
        for name in [
            "building_wtc2.obj",
            "spot.obj",
            "cutcube_cfmesh.stl",
            "fandisk.obj",
            "flange.stl",
            "arrow_cape.stl",
        ] {
            let s = crate::io::read_surface(&crate::test_shared::shared_geometry(name)).unwrap();
            let topo = Topology::new(&s);
            let features = Features::compute(&s, &topo, 30.0);
            let normals = wall_normals(&s, &topo, &features, 20.0);
            let bad = unmatched_edges(&normals);
            let show: Vec<String> = bad
                .iter()
                .take(6)
                .map(|&(a, b)| {
                    let (va, vb) = (normals.columns[a as usize].vertex, normals.columns[b as usize].vertex);
                    let kinds = (features.vertex_kind[va as usize], features.vertex_kind[vb as usize]);
                    format!("({a},{b}) at vertices ({va},{vb}) {kinds:?}")
                })
                .collect();
            assert!(bad.is_empty(), "{name}: {} unmatched front edges: {}", bad.len(), show.join("; "));
        }
    }
}

#[cfg(test)]
mod ridge_fan_tests {
    use super::*;

    #[test]
    fn a_corner_polygon_folding_back_is_cut_into_ears_that_face_the_fluid() {
        // A simple polygon, counter-clockwise seen from +z, whose edges (-2, 1) -> (1, 1) -> (1, -1)
        // turn clockwise around the centre: rings around it would turn over there.
        let plane = [(2.0, -1.0), (2.0, 2.0), (-2.0, 2.0), (-2.0, 1.0), (1.0, 1.0), (1.0, -1.0)];
        let dirs: Vec<DVec3> = plane.iter().map(|&(x, y)| DVec3::new(x, y, 1.0).normalize()).collect();
        assert!(!star_shaped(DVec3::Z, &dirs));
        let ears = ear_triangles(DVec3::Z, &dirs).expect("a simple polygon has ears");
        assert_eq!(ears.len(), plane.len() - 2);
        let mut area = 0.0;
        for [a, b, c] in ears {
            // The first cells of a corner patch are cones from the wall point: positive volumes.
            assert!(dirs[a].dot(dirs[b].cross(dirs[c])) > 0.0, "{a} {b} {c}");
            let (p, q, r) = (plane[a], plane[b], plane[c]);
            area += 0.5 * ((q.0 - p.0) * (r.1 - p.1) - (q.1 - p.1) * (r.0 - p.0));
        }
        assert!((area - 6.0).abs() < 1e-12, "the ears cover the polygon once: area {area}");
        // A polygon crossing itself has no ear left at some point.
        let bow: Vec<DVec3> = [(1.0, 1.0), (-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0)]
            .iter()
            .map(|&(x, y)| DVec3::new(x, y, 1.0).normalize())
            .collect();
        assert!(ear_triangles(DVec3::Z, &bow).is_none());
    }

    #[test]
    fn saddle_fan_columns_meet_both_cylinders() {
        // L-block saddle: edges along +z (faces +x, -y) and +x (faces +z, -y).
        for phi in [0.0f64, 0.3, 0.8, 1.2, std::f64::consts::FRAC_PI_2] {
            let (c, s) = (phi.cos(), phi.sin());
            let x =
                cylinders_meet(DVec3::new(c, -s, 0.0), DVec3::Z, DVec3::new(0.0, -s, c), DVec3::X).unwrap();
            assert!((x - DVec3::new(c, -s, c)).length() < 1e-12, "{phi}: {x}");
            // At unit distance from both edge lines.
            assert!(((x - x.dot(DVec3::Z) * DVec3::Z).length() - 1.0).abs() < 1e-12);
            assert!(((x - x.dot(DVec3::X) * DVec3::X).length() - 1.0).abs() < 1e-12);
        }
        assert!(cylinders_meet(DVec3::Y, DVec3::X, DVec3::Y, -DVec3::X).is_none(), "a straight ridge");
    }
}
