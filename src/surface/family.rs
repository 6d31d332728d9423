//! Randomised families of CFD-like closed bodies built in code, to measure the mesher over
//! many seeds (distributions, not one lucky mesh): a wing on a plate, a fin on a cylinder, a
//! post (cylinder or box) on a plate, oblique V-grooves, slots, steps and ledges, smooth bumps
//! and dips. Every body is closed, manifold and outward oriented.
//!
//! Each body is built face by face: a planar parameter region (boundary loops, holes, crease
//! lines) is triangulated by spade's constrained Delaunay triangulation through a jittered,
//! turned and stretched lattice of interior points (random triangle quality, meshes oblique to
//! the features), then mapped into space. Faces that meet share the very same boundary points
//! (bit-identical), which are welded at the end.
//!
//! The random parameters come from [`SplitMix64`], integer arithmetic only, so a seed gives the
//! same parameters on every platform; the coordinates then go through `sin`, `cos` and `exp`
//! of the platform's maths library.

use std::collections::HashSet;
use std::f64::consts::PI;

use glam::DVec3;
use spade::handles::FixedVertexHandle;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use super::Surface;
use crate::geometry::cdt::inside_faces;

/// The layer stack the families are sized against, as a fraction of the body's bounding-box
/// diagonal: 10 layers growing by 1.2 from 1e-3 of it (the sum of 1.2^k for k < 10 is 25.96).
/// Slot widths and bump curvature radii are drawn as multiples of it.
pub const SPEC_STACK_FRACTION: f64 = 1e-3 * 25.958_682_112;

/// The families of bodies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Family {
    /// A wing (NACA 00xx section, sweep, lean, taper, tip cap) standing on a plate.
    WingPlate,
    /// A fin standing on the curved side of a cylinder with flat or rounded ends (a fuselage).
    FinCylinder,
    /// A cylinder or a turned box standing on a plate (concave and saddle corners).
    PostPlate,
    /// A block with V-grooves of 25-150 deg across its top at an oblique angle.
    Grooves,
    /// A block with rectangular slots, some only one to two layer stacks wide.
    Slots,
    /// A block with a step up or down, or a raised ledge, with vertical walls.
    Steps,
    /// A block whose top has Gaussian bumps and dips curved like the layer stack is thick.
    Bumps,
}

impl Family {
    pub const ALL: [Family; 7] = [
        Family::WingPlate,
        Family::FinCylinder,
        Family::PostPlate,
        Family::Grooves,
        Family::Slots,
        Family::Steps,
        Family::Bumps,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Family::WingPlate => "wing-plate",
            Family::FinCylinder => "fin-cylinder",
            Family::PostPlate => "post-plate",
            Family::Grooves => "grooves",
            Family::Slots => "slots",
            Family::Steps => "steps",
            Family::Bumps => "bumps",
        }
    }

    pub fn from_name(name: &str) -> Option<Family> {
        Family::ALL.into_iter().find(|f| f.name() == name)
    }
}

/// The body of `family` for `seed`, at the family's own random wall spacing.
pub fn family_body(family: Family, seed: u64) -> Surface {
    family_body_at(family, seed, 1.0)
}

/// The body of `family` for `seed` with `fineness` times as many wall edges per length (the
/// shape and the other random choices do not depend on it).
pub fn family_body_at(family: Family, seed: u64, fineness: f64) -> Surface {
    // The family mixed into the seed (times PCG's 64-bit multiplier), so that the same seed
    // draws different numbers for different families.
    let mut rng = SplitMix64::new(seed ^ (family as u64).wrapping_mul(0x5851_F42D_4C95_7F2D));
    let spacing = WALL_SPACING[0] * (WALL_SPACING[1] / WALL_SPACING[0]).powf(rng.unit()) / fineness;
    let mut b = Builder { rng, spacing, fineness, pieces: Pieces::default() };
    match family {
        Family::WingPlate => b.wing_plate(),
        Family::FinCylinder => b.fin_cylinder(),
        Family::PostPlate => b.post_plate(),
        Family::Grooves => b.grooves(),
        Family::Slots => b.slots(),
        Family::Steps => b.steps(),
        Family::Bumps => b.bumps(),
    }
    b.pieces.finish()
}

/// Range of the wall edge length over seeds (bodies are about one unit across): a factor 3.
const WALL_SPACING: [f64; 2] = [0.025, 0.075];

/// SplitMix64 (Steele, Lea and Flood, 2014): a 64-bit counter through a mixing function.
/// Small, fast and the same on every platform; good enough to draw shapes.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1): the top 53 bits as a fraction.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform in 0..n.
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }

    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }
}

// ---------------------------------------------------------------------------------------------
// Faces: planar regions triangulated and mapped into space.

/// A point of a region's boundary or crease: where it lies in the region's parameter plane and
/// where in space (shared, bit for bit, with the faces that meet the region there).
#[derive(Clone, Copy, Debug)]
struct Node {
    uv: [f64; 2],
    at: DVec3,
}

/// A parameter region: closed loops (the outer boundary and holes alike, inside counted
/// even-odd) and open crease polylines that triangle edges follow and never cross.
#[derive(Default)]
struct Region {
    loops: Vec<Vec<Node>>,
    creases: Vec<Vec<Node>>,
}

/// Where a face's interior points go: a lattice of `spacing` turned by `angle`, stretched by
/// `stretch` along its first axis and squeezed along the other (long thin triangles), each
/// point moved by up to `jitter` lattice steps.
#[derive(Clone, Copy, Debug)]
struct Lattice {
    spacing: f64,
    angle: f64,
    stretch: f64,
    jitter: f64,
}

/// Interior points keep this many of the lattice's shorter steps away from boundaries and
/// creases, so that no triangle there is much thinner than the boundary makes it.
const CLEARANCE: f64 = 0.5;

impl Lattice {
    /// Random angle, stretch up to 1.8 (aspect up to about 3) and jitter up to 0.35 steps.
    fn random(rng: &mut SplitMix64, spacing: f64) -> Self {
        Lattice {
            spacing,
            angle: rng.range(0.0, PI),
            stretch: rng.range(1.0, 1.8),
            jitter: rng.range(0.0, 0.35),
        }
    }

    fn shortest_step(&self) -> f64 {
        self.spacing / self.stretch
    }

    /// The lattice points in the box `[lo, hi]`.
    fn points(&self, lo: [f64; 2], hi: [f64; 2], rng: &mut SplitMix64) -> Vec<[f64; 2]> {
        let (s, c) = self.angle.sin_cos();
        let e1 = [c * self.spacing * self.stretch, s * self.spacing * self.stretch];
        let e2 = [-s * self.shortest_step(), c * self.shortest_step()];
        let centre = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
        let radius = 0.5 * ((hi[0] - lo[0]).hypot(hi[1] - lo[1]));
        let reach = (radius / self.shortest_step()).ceil() as i64 + 1;
        let mut points = Vec::new();
        for i in -reach..=reach {
            for j in -reach..=reach {
                let a = i as f64 + rng.range(-self.jitter, self.jitter);
                let b = j as f64 + rng.range(-self.jitter, self.jitter);
                let p = [centre[0] + a * e1[0] + b * e2[0], centre[1] + a * e1[1] + b * e2[1]];
                if (lo[0]..=hi[0]).contains(&p[0]) && (lo[1]..=hi[1]).contains(&p[1]) {
                    points.push(p);
                }
            }
        }
        points
    }
}

/// Triangles in space, oriented by their parameter region (counter-clockwise there).
#[derive(Default)]
struct Face {
    points: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
}

/// The constrained Delaunay triangulation of `region` through the lattice points inside it,
/// mapped into space by `map` (boundary and crease nodes go to their own `at`).
fn triangulate(
    region: &Region,
    lattice: &Lattice,
    rng: &mut SplitMix64,
    map: impl Fn([f64; 2]) -> DVec3,
) -> Face {
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> = ConstrainedDelaunayTriangulation::new();
    let mut node_at: Vec<Option<DVec3>> = Vec::new();
    let mut loop_edges = HashSet::new();
    let closed = region.loops.iter().map(|l| (l, true));
    for (line, is_loop) in closed.chain(region.creases.iter().map(|c| (c, false))) {
        let handles: Vec<FixedVertexHandle> =
            line.iter().map(|n| insert_node(&mut cdt, &mut node_at, n)).collect();
        let wrap = if is_loop { handles.len() } else { handles.len() - 1 };
        for k in 0..wrap {
            let (a, b) = (handles[k], handles[(k + 1) % handles.len()]);
            assert!(cdt.can_add_constraint(a, b), "family: a boundary or crease edge crosses another");
            cdt.add_constraint(a, b);
            if is_loop {
                loop_edges.insert(edge_key(a.index(), b.index()));
            }
        }
    }
    let segments = segments(region);
    let (lo, hi) = uv_box(&region.loops);
    let clearance = CLEARANCE * lattice.shortest_step();
    for p in lattice.points(lo, hi, rng) {
        if inside(p, &region.loops) && distance_to_segments(p, &segments) > clearance {
            cdt.insert(point2(p)).expect("a finite lattice point");
        }
    }
    collect_face(&cdt, &node_at, &loop_edges, map)
}

fn edge_key(a: usize, b: usize) -> (usize, usize) {
    (a.min(b), a.max(b))
}

/// Spade refuses coordinates below about 1e-42 in size other than zero: those are zero here.
fn point2(uv: [f64; 2]) -> Point2<f64> {
    let flush = |x: f64| if x.abs() < 1e-30 { 0.0 } else { x };
    Point2::new(flush(uv[0]), flush(uv[1]))
}

fn insert_node(
    cdt: &mut ConstrainedDelaunayTriangulation<Point2<f64>>,
    node_at: &mut Vec<Option<DVec3>>,
    node: &Node,
) -> FixedVertexHandle {
    let h = cdt.insert(point2(node.uv)).expect("a finite boundary node");
    if node_at.len() <= h.index() {
        node_at.resize(h.index() + 1, None);
    }
    node_at[h.index()] = Some(node.at);
    h
}

/// The triangles of `cdt` inside the loops, with their points in space.
fn collect_face(
    cdt: &ConstrainedDelaunayTriangulation<Point2<f64>>,
    node_at: &[Option<DVec3>],
    loop_edges: &HashSet<(usize, usize)>,
    map: impl Fn([f64; 2]) -> DVec3,
) -> Face {
    let inside = inside_faces(cdt, |e| {
        let [a, b] = cdt.undirected_edge(e).vertices().map(|v| v.fix().index());
        loop_edges.contains(&edge_key(a, b))
    });
    let points = cdt
        .vertices()
        .map(|v| {
            let p = v.position();
            node_at.get(v.fix().index()).copied().flatten().unwrap_or_else(|| map([p.x, p.y]))
        })
        .collect();
    let triangles = cdt
        .inner_faces()
        .filter(|f| inside[f.fix().index()])
        .map(|f| f.vertices().map(|v| v.fix().index() as u32))
        .collect();
    Face { points, triangles }
}

fn segments(region: &Region) -> Vec<[[f64; 2]; 2]> {
    let mut out = Vec::new();
    for l in &region.loops {
        out.extend((0..l.len()).map(|k| [l[k].uv, l[(k + 1) % l.len()].uv]));
    }
    for c in &region.creases {
        out.extend(c.windows(2).map(|w| [w[0].uv, w[1].uv]));
    }
    out
}

fn uv_box(loops: &[Vec<Node>]) -> ([f64; 2], [f64; 2]) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for n in loops.iter().flatten() {
        for k in 0..2 {
            lo[k] = lo[k].min(n.uv[k]);
            hi[k] = hi[k].max(n.uv[k]);
        }
    }
    (lo, hi)
}

/// Even-odd point in polygon over all loops.
fn inside(p: [f64; 2], loops: &[Vec<Node>]) -> bool {
    let mut odd = false;
    for l in loops {
        for k in 0..l.len() {
            let (a, b) = (l[k].uv, l[(k + 1) % l.len()].uv);
            if (a[1] > p[1]) != (b[1] > p[1]) && p[0] < a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]) {
                odd = !odd;
            }
        }
    }
    odd
}

fn distance_to_segments(p: [f64; 2], segments: &[[[f64; 2]; 2]]) -> f64 {
    segments
        .iter()
        .map(|[a, b]| {
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let t = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
            (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
        })
        .fold(f64::INFINITY, f64::min)
}

// ---------------------------------------------------------------------------------------------
// Assembly.

/// The faces gathered so far, as one surface whose shared points are still repeated.
#[derive(Default)]
struct Pieces {
    surface: Surface,
}

impl Pieces {
    fn patch(&mut self, name: &str) -> u32 {
        let names = &mut self.surface.patch_names;
        names.iter().position(|n| n == name).unwrap_or_else(|| {
            names.push(name.to_owned());
            names.len() - 1
        }) as u32
    }

    /// Add `face` to patch `name`, reversed when its parameter plane faces into the body.
    fn add(&mut self, face: Face, name: &str, reversed: bool) {
        let patch = self.patch(name);
        let s = &mut self.surface;
        let base = s.points.len() as u32;
        s.points.extend(face.points);
        for [a, b, c] in face.triangles {
            s.triangles.push(if reversed {
                [base + a, base + c, base + b]
            } else {
                [base + a, base + b, base + c]
            });
            s.triangle_patch.push(patch);
        }
    }

    fn finish(mut self) -> Surface {
        self.surface.weld_exact();
        self.surface.remove_unused_points();
        self.surface
    }
}

/// Values from `a` to `b` (both exact) no further apart than `h`, through every break strictly
/// between them; the same values either way round (opposite sides of a seam then meet).
fn samples(a: f64, b: f64, h: f64, breaks: &[f64]) -> Vec<f64> {
    if a > b {
        let mut out = samples(b, a, h, breaks);
        out.reverse();
        return out;
    }
    let mut stops: Vec<f64> = breaks.iter().copied().filter(|&x| a < x && x < b).collect();
    stops.sort_by(f64::total_cmp);
    stops.insert(0, a);
    stops.push(b);
    let mut out = vec![a];
    for w in stops.windows(2) {
        let n = ((w[1] - w[0]) / h).ceil().max(1.0) as usize;
        out.extend((1..n).map(|k| w[0] + (w[1] - w[0]) * k as f64 / n as f64));
        out.push(w[1]);
    }
    out
}

/// Points from `a` to `b` (both exact) no further apart than `h`.
fn straight(a: DVec3, b: DVec3, h: f64) -> Vec<DVec3> {
    let t = samples(0.0, 1.0, h / (b - a).length(), &[]);
    let last = t.len() - 1;
    t.iter()
        .enumerate()
        .map(|(k, &t)| {
            if k == last {
                b
            } else if k == 0 {
                a
            } else {
                a.lerp(b, t)
            }
        })
        .collect()
}

fn nodes(uvs: impl IntoIterator<Item = [f64; 2]>, map: impl Fn([f64; 2]) -> DVec3) -> Vec<Node> {
    uvs.into_iter().map(|uv| Node { uv, at: map(uv) }).collect()
}

/// A loop of the four sides (each from corner to corner), every corner once.
fn join_sides(sides: &[Vec<Node>; 4]) -> Vec<Node> {
    sides.iter().flat_map(|s| s[..s.len() - 1].iter().copied()).collect()
}

/// The rectangle `[0, size[0]] x [0, size[1]]`'s sides in parameters, counter-clockwise
/// (south: v = 0, east, north, west), sampled every `h` through `breaks` (per side, along it).
fn rectangle_sides(size: [f64; 2], h: f64, breaks: &[Vec<f64>; 4]) -> [Vec<[f64; 2]>; 4] {
    let [w, d] = size;
    [
        samples(0.0, w, h, &breaks[0]).into_iter().map(|u| [u, 0.0]).collect(),
        samples(0.0, d, h, &breaks[1]).into_iter().map(|v| [w, v]).collect(),
        samples(w, 0.0, h, &breaks[2]).into_iter().map(|u| [u, d]).collect(),
        samples(d, 0.0, h, &breaks[3]).into_iter().map(|v| [0.0, v]).collect(),
    ]
}

/// A body standing on a wall: its root loop (on the wall) and its tip loop (in a plane
/// `z = const`), point for point, counter-clockwise seen from above.
struct Standing<'a> {
    root: &'a [DVec3],
    tip: &'a [DVec3],
    patch: &'a str,
}

struct Builder {
    rng: SplitMix64,
    /// Wall edge length of this body.
    spacing: f64,
    /// The factor [`family_body_at`] refines by.
    fineness: f64,
    pieces: Pieces,
}

/// Block walls and bottoms are meshed this much coarser than the top, where the features are.
const BLOCK_SIDE_COARSENING: f64 = 1.5;

impl Builder {
    fn lattice(&mut self, spacing: f64) -> Lattice {
        Lattice::random(&mut self.rng, spacing)
    }

    fn face(&mut self, region: &Region, spacing: f64, map: impl Fn([f64; 2]) -> DVec3) -> Face {
        let lattice = self.lattice(spacing);
        triangulate(region, &lattice, &mut self.rng, map)
    }

    /// The four walls and the bottom (at `z = bottom`) of a block under a top face whose
    /// boundary is `sides` (south, east, north, west, counter-clockwise seen from above, each
    /// from corner to corner, in vertical planes).
    fn close_block(&mut self, sides: &[Vec<DVec3>; 4], bottom: f64) {
        let h = BLOCK_SIDE_COARSENING * self.spacing;
        let columns: Vec<Vec<DVec3>> =
            sides.iter().map(|s| straight(s[0], DVec3::new(s[0].x, s[0].y, bottom), h)).collect();
        let foot = |k: usize| *columns[k % 4].last().unwrap();
        let bottoms: Vec<Vec<DVec3>> = (0..4).map(|k| straight(foot(k), foot(k + 1), h)).collect();
        for k in 0..4 {
            let next = &columns[(k + 1) % 4];
            let ring = sides[k].iter().chain(&next[1..]).chain(bottoms[k].iter().rev().skip(1));
            let ring: Vec<DVec3> = ring.chain(columns[k].iter().rev().skip(1)).copied().collect();
            self.wall(&ring[..ring.len() - 1], sides[k][0], *sides[k].last().unwrap(), h);
        }
        let ring: Vec<Node> =
            bottoms.iter().flat_map(|b| &b[..b.len() - 1]).map(|&p| Node { uv: [p.x, p.y], at: p }).collect();
        let face = self
            .face(&Region { loops: vec![ring], ..Default::default() }, h, |[x, y]| DVec3::new(x, y, bottom));
        self.pieces.add(face, "wall", true);
    }

    /// A vertical wall through `ring` (closed), seen from outside with `from` on the left and
    /// `to` on the right at the top.
    fn wall(&mut self, ring: &[DVec3], from: DVec3, to: DVec3, h: f64) {
        let origin = DVec3::new(from.x, from.y, 0.0);
        let along = DVec3::new(to.x - from.x, to.y - from.y, 0.0).normalize();
        let ring = ring.iter().map(|&p| Node { uv: [(p - origin).dot(along), p.z], at: p }).collect();
        let face = self.face(&Region { loops: vec![ring], ..Default::default() }, h, |[u, v]| {
            origin + along * u + DVec3::Z * v
        });
        self.pieces.add(face, "wall", false);
    }

    /// A block `[0, size[0]] x [0, size[1]] x [-depth, height(x, y)]`, its top meshed with
    /// the crease segments `creases` (ends on the sides) and the hole loops `holes`.
    fn heightfield_block(
        &mut self,
        size: [f64; 2],
        depth: f64,
        height: &dyn Fn(f64, f64) -> f64,
        creases: &[[[f64; 2]; 2]],
        holes: Vec<Vec<Node>>,
    ) {
        let h = self.spacing;
        let map = |[x, y]: [f64; 2]| DVec3::new(x, y, height(x, y));
        let breaks = crease_breaks(size, creases);
        let sides = rectangle_sides(size, h, &breaks).map(|s| nodes(s, map));
        let crease_nodes = creases.iter().map(|&[a, b]| {
            let t = samples(0.0, 1.0, h / (b[0] - a[0]).hypot(b[1] - a[1]), &[]);
            // The ends exactly: they are nodes of the sides.
            let last = t.len() - 1;
            nodes(t.iter().enumerate().map(|(k, &t)| if k == last { b } else { lerp2(a, b, t) }), map)
        });
        let mut region = Region { loops: vec![join_sides(&sides)], creases: crease_nodes.collect() };
        region.loops.extend(holes);
        let face = self.face(&region, h, map);
        self.pieces.add(face, "wall", false);
        self.close_block(&sides.map(|s| s.iter().map(|n| n.at).collect()), -depth);
    }

    /// A block `[0, x_end] x [0, width] x [-depth, profile]` whose top follows the polyline
    /// `profile` (points (x, z), x never decreasing, from x = 0 to x_end) along y: vertical
    /// walls allowed. Its top is meshed in (arc length, y) with a crease at every profile
    /// corner.
    fn profile_block(&mut self, profile: &[[f64; 2]], width: f64, depth: f64) {
        let h = self.spacing;
        let arc: Vec<f64> = std::iter::once(0.0)
            .chain(profile.windows(2).scan(0.0, |s, w| {
                *s += (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]);
                Some(*s)
            }))
            .collect();
        let at_arc = |s: f64| {
            let k = arc.windows(2).position(|w| s <= w[1]).unwrap_or(arc.len() - 2);
            let t = ((s - arc[k]) / (arc[k + 1] - arc[k])).clamp(0.0, 1.0);
            lerp2(profile[k], profile[k + 1], t)
        };
        let map = |[s, y]: [f64; 2]| {
            let [x, z] = at_arc(s);
            DVec3::new(x, y, z)
        };
        let corners = &arc[1..arc.len() - 1];
        let length = arc[arc.len() - 1];
        let sides =
            rectangle_sides([length, width], h, &[corners.to_vec(), vec![], corners.to_vec(), vec![]])
                .map(|s| nodes(s, map));
        let across = samples(0.0, width, h, &[]);
        let creases = corners.iter().map(|&s| nodes(across.iter().map(|&y| [s, y]), map)).collect();
        let region = Region { loops: vec![join_sides(&sides)], creases };
        let face = self.face(&region, h, map);
        self.pieces.add(face, "wall", false);
        self.close_block(&sides.map(|s| s.iter().map(|n| n.at).collect()), -depth);
    }

    /// The side of a standing body, rows from root to tip (quads split along a random
    /// diagonal), and its flat tip cap.
    fn standing(&mut self, body: Standing) {
        let rows = self.rows(body.root, body.tip);
        let face = self.loft(&rows);
        self.pieces.add(face, body.patch, false);
        let z = body.tip[0].z;
        let ring = body.tip.iter().map(|&p| Node { uv: [p.x, p.y], at: p }).collect();
        let face = self.face(&Region { loops: vec![ring], ..Default::default() }, self.spacing, |[x, y]| {
            DVec3::new(x, y, z)
        });
        self.pieces.add(face, body.patch, false);
    }

    /// Rows of points from `root` to `tip` (both exact), about a wall spacing apart, the
    /// stations between them jittered.
    fn rows(&mut self, root: &[DVec3], tip: &[DVec3]) -> Vec<Vec<DVec3>> {
        let length = root.iter().zip(tip).map(|(a, b)| (*b - *a).length()).fold(0.0, f64::max);
        let n = (length / self.spacing).ceil().max(1.0) as usize;
        let mut rows = vec![root.to_vec()];
        for k in 1..n {
            let t = (k as f64 + self.rng.range(-0.3, 0.3)) / n as f64;
            rows.push(root.iter().zip(tip).map(|(a, b)| a.lerp(*b, t)).collect());
        }
        rows.push(tip.to_vec());
        rows
    }

    fn loft(&mut self, rows: &[Vec<DVec3>]) -> Face {
        let width = rows[0].len();
        let index = |row: usize, i: usize| (row * width + i % width) as u32;
        let mut triangles = Vec::new();
        for row in 0..rows.len() - 1 {
            for i in 0..width {
                let [a, b, c, d] =
                    [index(row, i), index(row, i + 1), index(row + 1, i + 1), index(row + 1, i)];
                if self.rng.chance(0.5) {
                    triangles.extend([[a, b, c], [a, c, d]]);
                } else {
                    triangles.extend([[a, b, d], [b, c, d]]);
                }
            }
        }
        Face { points: rows.concat(), triangles }
    }
}

fn lerp2(a: [f64; 2], b: [f64; 2], t: f64) -> [f64; 2] {
    [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
}

/// Where the crease segments end on each side of the rectangle, as positions along the side.
fn crease_breaks(size: [f64; 2], creases: &[[[f64; 2]; 2]]) -> [Vec<f64>; 4] {
    let mut breaks: [Vec<f64>; 4] = Default::default();
    for p in creases.iter().flatten() {
        match () {
            _ if p[1] == 0.0 => breaks[0].push(p[0]),
            _ if p[0] == size[0] => breaks[1].push(p[1]),
            _ if p[1] == size[1] => breaks[2].push(p[0]),
            _ if p[0] == 0.0 => breaks[3].push(p[1]),
            _ => panic!("family: a crease ends inside the top at {p:?}"),
        }
    }
    breaks
}

/// The part of the line `{centre + along * t}` inside `[0, size[0]] x [0, size[1]]`, its ends
/// exactly on the sides (None when it misses).
fn clip_line(centre: [f64; 2], along: [f64; 2], size: [f64; 2]) -> Option<[[f64; 2]; 2]> {
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    let (mut side0, mut side1) = ((0, 0.0), (0, 0.0));
    for k in 0..2 {
        if along[k] == 0.0 {
            if !(0.0..=size[k]).contains(&centre[k]) {
                return None;
            }
            continue;
        }
        let (a, b) = ((0.0 - centre[k]) / along[k], (size[k] - centre[k]) / along[k]);
        let ((lo, lo_at), (hi, hi_at)) =
            if a < b { ((a, 0.0), (b, size[k])) } else { ((b, size[k]), (a, 0.0)) };
        if lo > t0 {
            (t0, side0) = (lo, (k, lo_at));
        }
        if hi < t1 {
            (t1, side1) = (hi, (k, hi_at));
        }
    }
    if t0 >= t1 {
        return None;
    }
    let point = |t: f64, (k, at): (usize, f64)| {
        let mut p = [centre[0] + along[0] * t, centre[1] + along[1] * t];
        p[k] = at;
        p
    };
    Some([point(t0, side0), point(t1, side1)])
}

// ---------------------------------------------------------------------------------------------
// The families.

/// A symmetric NACA four-digit section (00xx) of unit chord with a closed trailing edge,
/// counter-clockwise from the trailing edge over the upper side, `2 n` points, cosine-spaced
/// (fine at the leading edge).
fn naca_section(thickness: f64, n: usize) -> Vec<[f64; 2]> {
    let half = |x: f64| {
        5.0 * thickness
            * (0.2969 * x.sqrt() - 0.1260 * x - 0.3516 * x * x + 0.2843 * x.powi(3) - 0.1036 * x.powi(4))
    };
    let x = |k: usize| 0.5 * (1.0 - (PI * k as f64 / n as f64).cos());
    let upper = (0..=n).rev().map(|k| [x(k), if k == n { 0.0 } else { half(x(k)) }]);
    let lower = (1..n).map(|k| [x(k), -half(x(k))]);
    upper.chain(lower).collect()
}

/// A wing planform: a section's chord, thickness, span, sweep and lean (of the quarter-chord
/// line) and taper (tip chord over root chord).
struct Planform {
    chord: f64,
    thickness: f64,
    span: f64,
    sweep: f64,
    lean: f64,
    taper: f64,
}

impl Planform {
    /// Thickness 6-18%, sweep 0-45 deg, lean +-20 deg, taper 0.3-1.
    fn random(rng: &mut SplitMix64, chord: f64, span: f64) -> Self {
        Planform {
            chord,
            thickness: rng.range(0.06, 0.18),
            span,
            sweep: rng.range(0.0, 45f64).to_radians(),
            lean: rng.range(-20.0, 20f64).to_radians(),
            taper: rng.range(0.3, 1.0),
        }
    }

    /// The root section (x, y) with its leading edge at `nose`, about `h` apart at most.
    fn root(&self, nose: [f64; 2], h: f64) -> Vec<[f64; 2]> {
        let n = ((0.5 * PI * self.chord / h).ceil() as usize).max(8);
        naca_section(self.thickness, n)
            .into_iter()
            .map(|[x, y]| [nose[0] + self.chord * x, nose[1] + self.chord * y])
            .collect()
    }

    /// The tip section over `root` (points in space) at height `z`: scaled about the root's
    /// quarter chord, moved by the sweep and the lean.
    fn tip(&self, root: &[DVec3], nose: [f64; 2], z: f64) -> Vec<DVec3> {
        let pivot = [nose[0] + 0.25 * self.chord, nose[1]];
        let shift = [self.span * self.sweep.tan(), self.span * self.lean.tan()];
        root.iter()
            .map(|p| {
                let x = pivot[0] + (p.x - pivot[0]) * self.taper + shift[0];
                let y = pivot[1] + (p.y - pivot[1]) * self.taper + shift[1];
                DVec3::new(x, y, z)
            })
            .collect()
    }
}

impl Builder {
    fn wing_plate(&mut self) {
        let size = [self.rng.range(1.0, 1.4), self.rng.range(0.8, 1.2)];
        let depth = self.rng.range(0.15, 0.3);
        let chord = self.rng.range(0.2, 0.45);
        let span = self.rng.range(0.25, 0.6);
        let wing = Planform::random(&mut self.rng, chord, span);
        let nose = [self.rng.range(0.15, size[0] - chord - 0.15), 0.5 * size[1] + self.rng.range(-0.1, 0.1)];
        let root: Vec<DVec3> =
            wing.root(nose, self.spacing).iter().map(|&[x, y]| DVec3::new(x, y, 0.0)).collect();
        let tip = wing.tip(&root, nose, span);
        let hole = root.iter().map(|&p| Node { uv: [p.x, p.y], at: p }).collect();
        self.heightfield_block(size, depth, &|_, _| 0.0, &[], vec![hole]);
        self.standing(Standing { root: &root, tip: &tip, patch: "wing" });
    }

    fn fin_cylinder(&mut self) {
        let radius = self.rng.range(0.15, 0.3);
        let length = self.rng.range(1.0, 1.6);
        let chord = self.rng.range(0.25, 0.45) * length;
        let span = self.rng.range(0.6, 1.5) * radius;
        let mut fin = Planform::random(&mut self.rng, chord, span);
        // The section's half thickness stays under 0.3 radii, so that it wraps gently.
        fin.thickness = fin.thickness.min(0.6 * radius / chord);
        let nose = [self.rng.range(0.1 * length, length - chord - 0.1 * length), 0.0];
        // (x, arc length from the top) onto the cylinder of axis x; the seam is at the bottom.
        let map = |[x, w]: [f64; 2]| DVec3::new(x, radius * (w / radius).sin(), radius * (w / radius).cos());
        let root_uv = fin.root(nose, self.spacing);
        let root: Vec<DVec3> = root_uv.iter().map(|&uv| map(uv)).collect();
        let tip = fin.tip(&root, nose, radius + span);
        self.cylinder(radius, length, nodes(root_uv, map), map);
        self.standing(Standing { root: &root, tip: &tip, patch: "fin" });
    }

    /// The cylinder `map` draws over `[0, length] x [-pi r, pi r]`, with `hole` in its side and
    /// flat or rounded ends.
    fn cylinder(&mut self, radius: f64, length: f64, hole: Vec<Node>, map: impl Fn([f64; 2]) -> DVec3) {
        let h = self.spacing;
        let half = PI * radius;
        let sides = rectangle_sides([length, 2.0 * half], h, &Default::default())
            .map(|s| s.into_iter().map(|[x, w]| [x, w - half]).collect::<Vec<_>>());
        // The seam: the side w = +pi r is the same points as w = -pi r.
        let seam = |[x, w]: [f64; 2]| map([x, if w == half { -half } else { w }]);
        let side_nodes = sides.map(|s| nodes(s, seam));
        let region = Region { loops: vec![join_sides(&side_nodes), hole], ..Default::default() };
        let face = self.face(&region, h, &map);
        self.pieces.add(face, "wall", false);
        for (end, x, outward) in [(3, 0.0, -1.0), (1, length, 1.0)] {
            // Half the ends are flat, half rounded: half an ellipsoid 0.5-1.5 radii long.
            let nose = if self.rng.chance(0.5) { self.rng.range(0.5, 1.5) * radius } else { 0.0 };
            let ring: &Vec<Node> = &side_nodes[end];
            let ring =
                ring[..ring.len() - 1].iter().map(|n| Node { uv: [n.at.y, n.at.z], at: n.at }).collect();
            let face = self.face(&Region { loops: vec![ring], ..Default::default() }, h, |[y, z]| {
                let rise = (1.0 - (y * y + z * z) / (radius * radius)).max(0.0).sqrt();
                DVec3::new(x + outward * nose * rise, y, z)
            });
            // The (y, z) plane faces +x: the end at x = 0 is reversed (a rounded end is a graph
            // over it, so it turns alike).
            self.pieces.add(face, "wall", outward < 0.0);
        }
    }

    fn post_plate(&mut self) {
        let size = [self.rng.range(0.9, 1.3), self.rng.range(0.9, 1.3)];
        let depth = self.rng.range(0.15, 0.3);
        let height = self.rng.range(0.1, 0.5);
        let centre = [0.5 * size[0] + self.rng.range(-0.1, 0.1), 0.5 * size[1] + self.rng.range(-0.1, 0.1)];
        let root_uv = if self.rng.chance(0.5) {
            circle(centre, self.rng.range(0.05, 0.2), self.spacing)
        } else {
            turned_square(centre, self.rng.range(0.1, 0.3), self.rng.range(0.0, 0.5 * PI), self.spacing)
        };
        let root: Vec<DVec3> = root_uv.iter().map(|&[x, y]| DVec3::new(x, y, 0.0)).collect();
        let tip: Vec<DVec3> = root.iter().map(|&p| p + DVec3::Z * height).collect();
        let hole = root.iter().map(|&p| Node { uv: [p.x, p.y], at: p }).collect();
        self.heightfield_block(size, depth, &|_, _| 0.0, &[], vec![hole]);
        self.standing(Standing { root: &root, tip: &tip, patch: "post" });
    }

    fn grooves(&mut self) {
        let size = [self.rng.range(1.0, 1.3), self.rng.range(0.8, 1.2)];
        let depth = self.rng.range(0.25, 0.4);
        let turn = self.rng.range(-40.0, 40f64).to_radians();
        let (along, across) = ([turn.sin(), turn.cos()], [turn.cos(), -turn.sin()]);
        let centre = [0.5 * size[0], 0.5 * size[1]];
        let count = 1 + self.rng.below(2);
        let grooves: Vec<VGroove> = (0..count)
            .map(|k| {
                let opening = self.rng.range(25.0, 150f64).to_radians();
                let slope = (0.5 * opening).tan();
                // At most 0.18 wide each side, so that two grooves 0.45 apart never touch.
                let deep = self.rng.range(0.04, 0.15).min(0.18 / slope);
                let offset = (k as f64 - 0.5 * (count - 1) as f64) * 0.45 + self.rng.range(-0.05, 0.05);
                VGroove { offset, deep, half_width: deep * slope }
            })
            .collect();
        let across_of = move |x: f64, y: f64| (x - centre[0]) * across[0] + (y - centre[1]) * across[1];
        let height = |x: f64, y: f64| -grooves.iter().map(|g| g.depth_at(across_of(x, y))).sum::<f64>();
        let creases: Vec<[[f64; 2]; 2]> = grooves
            .iter()
            .flat_map(|g| [g.offset - g.half_width, g.offset, g.offset + g.half_width])
            .filter_map(|q| {
                clip_line(lerp2(centre, [centre[0] + across[0], centre[1] + across[1]], q), along, size)
            })
            .collect();
        self.heightfield_block(size, depth, &height, &creases, vec![]);
    }

    fn slots(&mut self) {
        let size = [self.rng.range(1.0, 1.3), self.rng.range(0.8, 1.2)];
        let depth = self.rng.range(0.25, 0.4);
        let stack = SPEC_STACK_FRACTION * (size[0].hypot(size[1]).hypot(depth));
        let count = 1 + self.rng.below(3);
        let pitch = size[0] / count as f64;
        let mut profile = vec![[0.0, 0.0]];
        for k in 0..count {
            // Half the slots are thin gaps, one to two layer stacks wide.
            let stacks =
                if self.rng.chance(0.5) { self.rng.range(1.0, 2.0) } else { self.rng.range(2.0, 8.0) };
            let width = (stacks * stack).min(0.6 * pitch);
            let deep = self.rng.range(0.04, 0.7 * depth);
            let left = pitch * k as f64 + (pitch - width) * self.rng.range(0.25, 0.75);
            profile.extend([[left, 0.0], [left, -deep], [left + width, -deep], [left + width, 0.0]]);
        }
        profile.push([size[0], 0.0]);
        self.profile_block(&profile, size[1], depth);
    }

    fn steps(&mut self) {
        let size = [self.rng.range(1.0, 1.3), self.rng.range(0.8, 1.2)];
        let depth = self.rng.range(0.25, 0.4);
        let rise = self.rng.range(0.04, 0.25) * if self.rng.chance(0.5) { 1.0 } else { -0.7 * depth / 0.25 };
        let at = self.rng.range(0.3, 0.7) * size[0];
        let profile = if self.rng.chance(0.5) {
            vec![[0.0, 0.0], [at, 0.0], [at, rise], [size[0], rise]]
        } else {
            // A ledge: up (or down) and back, at least 0.1 wide.
            let end = (at + self.rng.range(0.1, 0.4)).min(size[0] - 0.1);
            vec![[0.0, 0.0], [at, 0.0], [at, rise], [end, rise], [end, 0.0], [size[0], 0.0]]
        };
        self.profile_block(&profile, size[1], depth);
    }

    fn bumps(&mut self) {
        let size = [self.rng.range(1.0, 1.3), self.rng.range(0.8, 1.2)];
        let depth = self.rng.range(0.25, 0.4);
        let stack = SPEC_STACK_FRACTION * (size[0].hypot(size[1]).hypot(depth));
        let bumps: Vec<Gaussian> = (0..2 + self.rng.below(4))
            .map(|_| {
                let width = self.rng.range(0.04, 0.12);
                // Curvature radius at the crest width^2 / height: 0.5-3 stacks, no steeper
                // than a height of 1.5 widths, dips no deeper than 0.6 of the block.
                let radius = self.rng.range(0.5, 3.0) * stack;
                let mut amplitude = (width * width / radius).min(1.5 * width);
                if self.rng.chance(0.5) {
                    amplitude = -amplitude.min(0.6 * depth);
                }
                let margin = 3.0 * width;
                let centre =
                    [self.rng.range(margin, size[0] - margin), self.rng.range(margin, size[1] - margin)];
                Gaussian { centre, width, amplitude }
            })
            .collect();
        let narrowest = bumps.iter().map(|g| g.width).fold(f64::INFINITY, f64::min);
        // Two edges at least per width across the narrowest bump.
        self.spacing = self.spacing.min(0.5 * narrowest / self.fineness);
        let height = |x: f64, y: f64| bumps.iter().map(|g| g.at(x, y)).sum::<f64>();
        self.heightfield_block(size, depth, &height, &[], vec![]);
    }
}

/// A V-groove across the top: `offset` of its bottom line from the block's centre line,
/// its depth and half width at the top.
struct VGroove {
    offset: f64,
    deep: f64,
    half_width: f64,
}

impl VGroove {
    fn depth_at(&self, across: f64) -> f64 {
        self.deep * (1.0 - (across - self.offset).abs() / self.half_width).max(0.0)
    }
}

struct Gaussian {
    centre: [f64; 2],
    width: f64,
    amplitude: f64,
}

impl Gaussian {
    fn at(&self, x: f64, y: f64) -> f64 {
        let r2 = (x - self.centre[0]).powi(2) + (y - self.centre[1]).powi(2);
        self.amplitude * (-0.5 * r2 / (self.width * self.width)).exp()
    }
}

/// A circle's points about `h` apart, counter-clockwise.
fn circle(centre: [f64; 2], radius: f64, h: f64) -> Vec<[f64; 2]> {
    let n = ((2.0 * PI * radius / h).ceil() as usize).max(12);
    (0..n)
        .map(|k| {
            let (s, c) = (2.0 * PI * k as f64 / n as f64).sin_cos();
            [centre[0] + radius * c, centre[1] + radius * s]
        })
        .collect()
}

/// A square of side `side` turned by `angle`, its points about `h` apart through the corners,
/// counter-clockwise.
fn turned_square(centre: [f64; 2], side: f64, angle: f64, h: f64) -> Vec<[f64; 2]> {
    let (s, c) = angle.sin_cos();
    let corner = |[a, b]: [f64; 2]| {
        [centre[0] + 0.5 * side * (a * c - b * s), centre[1] + 0.5 * side * (a * s + b * c)]
    };
    let corners = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]].map(corner);
    let along = samples(0.0, 1.0, h / side, &[]);
    (0..4)
        .flat_map(|k| {
            along[..along.len() - 1].iter().map(move |&t| lerp2(corners[k], corners[(k + 1) % 4], t))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix64_gives_the_reference_sequence() {
        // The first output of SplitMix64 from state 0 in the reference implementation.
        assert_eq!(SplitMix64::new(0).next_u64(), 0xE220_A839_7B1D_CDAF);
        let mut rng = SplitMix64::new(42);
        assert!((0..1000).map(|_| rng.unit()).all(|u| (0.0..1.0).contains(&u)));
    }

    #[test]
    fn samples_are_the_same_either_way_and_pass_through_the_breaks() {
        let forward = samples(0.0, 1.3, 0.1, &[0.37, 2.0]);
        let mut backward = samples(1.3, 0.0, 0.1, &[0.37]);
        backward.reverse();
        assert_eq!(forward, backward);
        assert!(
            forward.contains(&0.37) && forward.windows(2).all(|w| w[1] > w[0] && w[1] - w[0] <= 0.1 + 1e-12)
        );
        assert_eq!((forward[0], *forward.last().unwrap()), (0.0, 1.3));
    }

    #[test]
    fn a_clipped_line_ends_exactly_on_the_sides() {
        let [a, b] = clip_line([0.5, 0.5], [0.3f64.sin(), 0.3f64.cos()], [1.0, 2.0]).unwrap();
        assert_eq!((a[1], b[1]), (0.0, 2.0), "through the south and north sides");
        let ends = crease_breaks([1.0, 2.0], &[[a, b]]);
        assert_eq!((ends[0].len(), ends[2].len()), (1, 1));
        assert!(clip_line([5.0, 0.5], [0.0, 1.0], [1.0, 2.0]).is_none());
    }

    #[test]
    fn a_naca_section_is_closed_counter_clockwise_and_as_thick_as_asked() {
        let section = naca_section(0.12, 40);
        let area: f64 = (0..section.len())
            .map(|k| {
                let (a, b) = (section[k], section[(k + 1) % section.len()]);
                0.5 * (a[0] * b[1] - b[0] * a[1])
            })
            .sum();
        assert!(area > 0.0, "counter-clockwise");
        let thickest = section.iter().map(|p| p[1]).fold(0.0, f64::max);
        assert!((2.0 * thickest - 0.12).abs() < 0.002, "{thickest}");
        assert_eq!(section[0], [1.0, 0.0]);
    }
}
