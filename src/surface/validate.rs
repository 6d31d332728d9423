//! Validation of an input wall surface.
//!
//! [`validate`] checks, in this order: vertex indices, coordinates (finite, in the accepted range of
//! [`crate::limits`]), degenerate triangles,
//! duplicate triangles, open edges, non-manifold edges, non-manifold vertices, consistent
//! orientation, self-intersections; then it measures every shell (connected component) and
//! flips the shells that enclose negative volume, so that every shell's normals point out of
//! it (the STL convention). Which side is fluid is decided later, from the flow type and the
//! nesting of the shells recorded in the report. The first failing check is returned as a
//! [`ValidationError`] naming the offending ids and coordinates. Every decision that depends on a
//! sign uses the exact predicates; slivers with tiny but non-zero area are valid.

use std::fmt;
use std::time::Instant;

use rayon::prelude::*;

use super::topology::{FanScratch, Topology};
use super::Surface;
use crate::geometry::grid::overlapping_pairs_where;
use crate::geometry::intersect::{folds_over_shared_edge, meet_beyond_shared_vertex, triangles_intersect};
use crate::geometry::predicates::{orient2d, orient3d, Sign};
use crate::geometry::{Aabb, DVec3};

#[derive(Clone, Debug)]
pub struct ValidationOptions {
    /// Check that no two triangles intersect (the most expensive check).
    pub self_intersections: bool,
    /// Flip a shell enclosing negative volume (with a warning) instead of rejecting the surface.
    pub flip_inverted_shells: bool,
    /// How many occurrences of a problem an error keeps (the total count is always given).
    pub max_examples: usize,
}

impl Default for ValidationOptions {
    fn default() -> Self {
        ValidationOptions { self_intersections: true, flip_inverted_shells: true, max_examples: 10 }
    }
}

/// One closed shell of a valid surface.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ShellReport {
    pub triangles: usize,
    pub vertices: usize,
    pub edges: usize,
    pub genus: Option<u32>,
    /// Enclosed volume (positive: after validation every shell's normals point out of it).
    pub volume: f64,
    pub bounding_box: Aabb,
    /// The innermost other shell that encloses this one.
    pub parent: Option<u32>,
    /// Its triangles were reversed because it enclosed negative volume.
    pub flipped: bool,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct ValidationReport {
    pub shells: Vec<ShellReport>,
    pub flipped_shells: Vec<u32>,
    pub warnings: Vec<String>,
    /// Wall-clock time the validation took.
    pub seconds: f64,
}

impl ValidationReport {
    /// For every shell, the innermost shell that encloses it.
    pub fn shell_parents(&self) -> Vec<Option<u32>> {
        self.shells.iter().map(|s| s.parent).collect()
    }
}

/// The first few occurrences of a problem, and how many there are in all.
#[derive(Clone, Debug, PartialEq)]
pub struct Examples<T> {
    pub total: usize,
    pub first: Vec<T>,
}

/// How many examples an error message shows (the error value keeps more).
const SHOWN_EXAMPLES: usize = 3;

impl<T: fmt::Display> fmt::Display for Examples<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "e.g. ")?;
        for (i, example) in self.first.iter().take(SHOWN_EXAMPLES).enumerate() {
            if i > 0 {
                write!(f, "; ")?;
            }
            write!(f, "{example}")?;
        }
        let shown = self.first.len().min(SHOWN_EXAMPLES);
        if self.total > shown {
            write!(f, "; and {} more", self.total - shown)?;
        }
        Ok(())
    }
}

/// A problem that makes a surface unusable as a wall, with the ids and coordinates of its first
/// occurrences.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ValidationError {
    #[error("empty surface: it has no triangles")]
    Empty,
    #[error("{} with vertex ids beyond the {vertex_count} vertices of the surface, {examples}",
        count(.examples.total, "triangle"))]
    VertexIndexOutOfRange { vertex_count: usize, examples: Examples<TriangleCorners> },
    #[error("non-finite coordinates (NaN or infinity) at {}, {examples}", count(.examples.total, "vertex"))]
    NonFiniteCoordinates { examples: Examples<CoordinateAt> },
    #[error("coordinates beyond the accepted range (|x| <= {:e}) at {}, {examples}; rescale or move \
        the surface", crate::limits::MAX_COORDINATE, count(.examples.total, "vertex"))]
    CoordinatesOutOfRange { examples: Examples<CoordinateAt> },
    #[error("body too small for where it is: its bounding box from {} to {} has a diagonal of {}, \
        below {:e} of its largest coordinate magnitude {} (or of 1); rescale or move the surface",
        format_point(.bounds.min), format_point(.bounds.max), format_coordinate(*.size),
        crate::limits::MIN_BODY_RATIO, format_coordinate(*.largest))]
    BodyTooSmall { bounds: Aabb, size: f64, largest: f64 },
    #[error("{} with zero area (a repeated vertex or three exactly collinear vertices), {examples}",
        count(.examples.total, "degenerate triangle"))]
    DegenerateTriangles { examples: Examples<TriangleAt> },
    #[error("{} (the same three vertices as another triangle), {examples}",
        count(.examples.total, "duplicate triangle"))]
    DuplicateTriangles { examples: Examples<TrianglePair> },
    #[error("open surface: {} (edges with only one triangle; the surface must be closed), {examples}",
        count(.examples.total, "boundary edge"))]
    OpenEdges { examples: Examples<EdgeAt> },
    #[error("non-manifold surface: {} shared by three or more triangles, {examples}",
        count(.examples.total, "edge"))]
    NonManifoldEdges { examples: Examples<EdgeAt> },
    #[error("non-manifold surface: {} where separate sheets touch (the triangles around the vertex \
        form several fans instead of one disc), {examples}", count(.examples.total, "vertex"))]
    NonManifoldVertices { examples: Examples<VertexFans> },
    #[error("inconsistent orientation: {} used in the same direction by both of its triangles (their \
        normals point to opposite sides), {examples}", count(.examples.total, "edge"))]
    InconsistentOrientation { examples: Examples<EdgeAt> },
    #[error("self-intersecting surface: {} intersect, {examples}",
        count(.examples.total, "pair of triangles"))]
    SelfIntersections { examples: Examples<TrianglePair> },
    #[error("inverted surface: {} enclose negative volume (normals point into the shell), {examples}",
        count(.examples.total, "shell"))]
    InvertedShells { examples: Examples<ShellAt> },
}

/// "1 edge", "3 edges", "2 vertices", "2 pairs of triangles".
fn count(n: usize, noun: &str) -> String {
    if n == 1 {
        return format!("1 {noun}");
    }
    let plural = if let Some(rest) = noun.strip_prefix("pair ") {
        format!("pairs {rest}")
    } else if let Some(stem) = noun.strip_suffix("ex") {
        format!("{stem}ices")
    } else {
        format!("{noun}s")
    };
    format!("{n} {plural}")
}

/// A coordinate with about 7 significant digits, without exponent for usual magnitudes.
pub(crate) fn format_coordinate(x: f64) -> String {
    if x == 0.0 || (1e-4..1e7).contains(&x.abs()) {
        format!("{}", x as f32)
    } else {
        format!("{x:.6e}")
    }
}

/// "(x, y, z)" with [`format_coordinate`].
pub(crate) fn format_point(p: DVec3) -> String {
    let [x, y, z] = p.to_array().map(format_coordinate);
    format!("({x}, {y}, {z})")
}

#[derive(Clone, Debug, PartialEq)]
pub struct VertexAt {
    pub vertex: u32,
    pub point: DVec3,
}

impl fmt::Display for VertexAt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "vertex {} at {}", self.vertex, format_point(self.point))
    }
}

/// A vertex and the first triangle that uses it (none: the vertex is unused).
#[derive(Clone, Debug, PartialEq)]
pub struct CoordinateAt {
    pub vertex: VertexAt,
    pub triangle: Option<TriangleTag>,
}

impl fmt::Display for CoordinateAt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.triangle {
            Some(t) => write!(f, "{} of {t}", self.vertex),
            None => write!(f, "{} (used by no triangle)", self.vertex),
        }
    }
}

/// A triangle id and the name of its patch (empty when the surface has no patch names).
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleTag {
    pub triangle: u32,
    pub patch: String,
}

impl fmt::Display for TriangleTag {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "triangle {}", self.triangle)?;
        if !self.patch.is_empty() {
            write!(f, " (patch {})", self.patch)?;
        }
        Ok(())
    }
}

/// A triangle with its vertex ids but no coordinates (some ids do not exist).
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleCorners {
    pub triangle: TriangleTag,
    pub vertices: [u32; 3],
}

impl fmt::Display for TriangleCorners {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [a, b, c] = self.vertices;
        write!(f, "{} with vertices ({a}, {b}, {c})", self.triangle)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct TriangleAt {
    pub triangle: TriangleTag,
    pub vertices: [u32; 3],
    pub points: [DVec3; 3],
}

impl fmt::Display for TriangleAt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [a, b, c] = self.vertices;
        let [p, q, r] = self.points.map(format_point);
        write!(f, "{} with vertices ({a}, {b}, {c}) at {p}, {q}, {r}", self.triangle)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct TrianglePair {
    pub first: TriangleAt,
    pub second: TriangleAt,
}

impl fmt::Display for TrianglePair {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} and {}", self.first, self.second)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct EdgeAt {
    pub edge: [u32; 2],
    pub points: [DVec3; 2],
    pub triangles: Vec<TriangleTag>,
}

impl fmt::Display for EdgeAt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [a, b] = self.edge;
        let [p, q] = self.points.map(format_point);
        write!(f, "edge ({a}, {b}) at {p}-{q} of ")?;
        for (i, t) in self.triangles.iter().enumerate() {
            let separator = match i {
                0 => "",
                _ if i + 1 == self.triangles.len() => " and ",
                _ => ", ",
            };
            write!(f, "{separator}{t}")?;
        }
        Ok(())
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct VertexFans {
    pub vertex: VertexAt,
    pub triangles: usize,
    pub fans: usize,
}

impl fmt::Display for VertexFans {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}, whose {} triangles form {} separate fans", self.vertex, self.triangles, self.fans)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct ShellAt {
    pub shell: u32,
    pub triangles: usize,
    pub volume: f64,
    pub example: TriangleTag,
}

impl fmt::Display for ShellAt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "shell {} ({} triangles, e.g. {}) encloses volume {}",
            self.shell,
            self.triangles,
            self.example,
            format_coordinate(self.volume)
        )
    }
}

/// Check `surface` (see the module docs); flips inverted shells in place when allowed.
pub fn validate(
    surface: &mut Surface,
    options: &ValidationOptions,
) -> Result<ValidationReport, ValidationError> {
    let start = Instant::now();
    let describe = Describe { surface, max: options.max_examples };
    describe.check_elements()?;
    let topology = Topology::new(surface);
    describe.check_topology(&topology)?;
    if options.self_intersections {
        describe.check_self_intersections()?;
    }
    let unused = describe.unused_vertices(&topology);
    let mut shells = measure_shells(surface, &topology);
    let (flipped_shells, mut warnings) = orient_shells_outward(surface, &topology, &mut shells, options)?;
    warnings.extend(unused);
    nest_shells(surface, &topology, &mut shells);
    Ok(ValidationReport { shells, flipped_shells, warnings, seconds: start.elapsed().as_secs_f64() })
}

/// Turns offending ids into error examples with coordinates and patch names.
struct Describe<'a> {
    surface: &'a Surface,
    max: usize,
}

impl Describe<'_> {
    /// Checks on single vertices and triangles, before any adjacency is built.
    fn check_elements(&self) -> Result<(), ValidationError> {
        let s = self.surface;
        if s.triangles.is_empty() {
            return Err(ValidationError::Empty);
        }
        let vertex_count = s.points.len();
        let out_of_range = filter_ids(s.triangles.len(), |t| {
            s.triangles[t as usize].iter().any(|&v| v as usize >= vertex_count)
        });
        let corners = |t: u32| TriangleCorners { triangle: self.tag(t), vertices: s.triangles[t as usize] };
        let error = |examples| ValidationError::VertexIndexOutOfRange { vertex_count, examples };
        self.reject(&out_of_range, corners, error)?;
        self.check_coordinates()?;
        let degenerate = filter_ids(s.triangles.len(), |t| is_degenerate(s, t as usize));
        let error = |examples| ValidationError::DegenerateTriangles { examples };
        self.reject(&degenerate, |t| self.triangle(t), error)?;
        let duplicates = duplicate_triangles(&s.triangles);
        let error = |examples| ValidationError::DuplicateTriangles { examples };
        self.reject(&duplicates, |(a, b)| self.pair(a, b), error)?;
        Ok(())
    }

    /// Finite, within [`crate::limits::MAX_COORDINATE`], and a body not too small for where it
    /// is ([`crate::limits::smallest_body`]): later stages size their work from coordinates.
    fn check_coordinates(&self) -> Result<(), ValidationError> {
        let s = self.surface;
        let first_use = first_triangle_of_vertices(s);
        let at = |v: u32| CoordinateAt {
            vertex: self.vertex(v),
            triangle: first_use.get(v as usize).copied().flatten().map(|t| self.tag(t)),
        };
        let non_finite = filter_ids(s.points.len(), |v| !s.points[v as usize].is_finite());
        let error = |examples| ValidationError::NonFiniteCoordinates { examples };
        self.reject(&non_finite, at, error)?;
        let in_range = |p: DVec3| p.to_array().into_iter().all(crate::limits::coordinate_in_range);
        let far = filter_ids(s.points.len(), |v| !in_range(s.points[v as usize]));
        let error = |examples| ValidationError::CoordinatesOutOfRange { examples };
        self.reject(&far, at, error)?;
        let bounds = s.bounding_box();
        let (size, largest) = (bounds.diagonal(), bounds.min.abs().max(bounds.max.abs()).max_element());
        if size < crate::limits::smallest_body(largest) {
            return Err(ValidationError::BodyTooSmall { bounds, size, largest });
        }
        Ok(())
    }

    /// Closed, edge-manifold, vertex-manifold, consistently oriented.
    fn check_topology(&self, topo: &Topology) -> Result<(), ValidationError> {
        let edge_count = topo.edge_count();
        let open = filter_ids(edge_count, |e| topo.edge_uses(e).len() == 1);
        let error = |examples| ValidationError::OpenEdges { examples };
        self.reject(&open, |e| self.edge(topo, e), error)?;
        let crowded = filter_ids(edge_count, |e| topo.edge_uses(e).len() > 2);
        let error = |examples| ValidationError::NonManifoldEdges { examples };
        self.reject(&crowded, |e| self.edge(topo, e), error)?;
        let mut scratch = FanScratch::default();
        let pinched: Vec<(u32, usize)> = (0..topo.vertex_count() as u32)
            .map(|v| (v, topo.vertex_fan_count(v, &mut scratch)))
            .filter(|&(_, fans)| fans > 1)
            .collect();
        let fans = |(v, fans)| VertexFans {
            vertex: self.vertex(v),
            triangles: topo.vertex_triangles(v).len(),
            fans,
        };
        let error = |examples| ValidationError::NonManifoldVertices { examples };
        self.reject(&pinched, fans, error)?;
        let misoriented = filter_ids(edge_count, |e| {
            let uses = topo.edge_uses(e);
            uses[0].forward == uses[1].forward
        });
        let error = |examples| ValidationError::InconsistentOrientation { examples };
        self.reject(&misoriented, |e| self.edge(topo, e), error)?;
        Ok(())
    }

    fn check_self_intersections(&self) -> Result<(), ValidationError> {
        let pairs = intersecting_pairs(self.surface);
        let error = |examples| ValidationError::SelfIntersections { examples };
        self.reject(&pairs, |(a, b)| self.pair(a, b), error)
    }

    /// A warning about vertices of no triangle (they are ignored).
    fn unused_vertices(&self, topo: &Topology) -> Option<String> {
        let unused = filter_ids(self.surface.points.len(), |v| topo.vertex_triangles(v).is_empty());
        if unused.is_empty() {
            return None;
        }
        let examples = self.examples(&unused, |v| self.vertex(v));
        Some(format!("{} used by no triangle (ignored), {examples}", count(unused.len(), "vertex")))
    }

    /// An error listing `ids` when there are any.
    fn reject<I: Copy, T>(
        &self,
        ids: &[I],
        describe: impl Fn(I) -> T,
        error: impl FnOnce(Examples<T>) -> ValidationError,
    ) -> Result<(), ValidationError> {
        if ids.is_empty() {
            return Ok(());
        }
        Err(error(self.examples(ids, describe)))
    }

    fn examples<I: Copy, T>(&self, ids: &[I], describe: impl Fn(I) -> T) -> Examples<T> {
        Examples { total: ids.len(), first: ids.iter().take(self.max).map(|&i| describe(i)).collect() }
    }

    fn point(&self, v: u32) -> DVec3 {
        self.surface.points.get(v as usize).copied().unwrap_or(DVec3::NAN)
    }

    fn vertex(&self, v: u32) -> VertexAt {
        VertexAt { vertex: v, point: self.point(v) }
    }

    fn tag(&self, t: u32) -> TriangleTag {
        TriangleTag { triangle: t, patch: patch_name(self.surface, t as usize).to_owned() }
    }

    fn triangle(&self, t: u32) -> TriangleAt {
        let vertices = self.surface.triangles[t as usize];
        TriangleAt { triangle: self.tag(t), vertices, points: vertices.map(|v| self.point(v)) }
    }

    fn pair(&self, a: u32, b: u32) -> TrianglePair {
        TrianglePair { first: self.triangle(a), second: self.triangle(b) }
    }

    fn edge(&self, topo: &Topology, e: u32) -> EdgeAt {
        let edge = topo.edges[e as usize];
        let triangles = topo.edge_uses(e).iter().map(|u| self.tag(u.triangle)).collect();
        EdgeAt { edge, points: edge.map(|v| self.point(v)), triangles }
    }
}

/// The name of the patch of triangle `t` ("" when unknown).
pub(crate) fn patch_name(surface: &Surface, t: usize) -> &str {
    let patch = surface.triangle_patch.get(t).and_then(|&p| surface.patch_names.get(p as usize));
    patch.map_or("", String::as_str)
}

/// The first triangle of every vertex (triangle indices must be in range).
fn first_triangle_of_vertices(s: &Surface) -> Vec<Option<u32>> {
    let mut first = vec![None; s.points.len()];
    for (t, tri) in s.triangles.iter().enumerate().rev() {
        for &v in tri {
            first[v as usize] = Some(t as u32);
        }
    }
    first
}

fn filter_ids(n: usize, bad: impl Fn(u32) -> bool) -> Vec<u32> {
    (0..n as u32).filter(|&i| bad(i)).collect()
}

/// A repeated vertex, or three vertices exactly on a line (collinear in all three coordinate
/// projections). Slivers with a tiny but non-zero area are not degenerate.
fn is_degenerate(surface: &Surface, t: usize) -> bool {
    let [a, b, c] = surface.triangles[t];
    if a == b || b == c || c == a {
        return true;
    }
    let [p, q, r] = surface.triangle_points(t);
    let project = |v: DVec3, axis| crate::geometry::intersect::project(v, axis);
    (0..3).all(|axis| orient2d(project(p, axis), project(q, axis), project(r, axis)) == Sign::Zero)
}

/// Pairs (first, later) of triangles with the same vertex set, whatever the order.
fn duplicate_triangles(triangles: &[[u32; 3]]) -> Vec<(u32, u32)> {
    let mut keyed: Vec<([u32; 3], u32)> = triangles
        .iter()
        .enumerate()
        .map(|(t, tri)| {
            let mut key = *tri;
            key.sort_unstable();
            (key, t as u32)
        })
        .collect();
    keyed.sort_unstable();
    let mut pairs = Vec::new();
    let mut first = 0;
    for i in 1..keyed.len() {
        if keyed[i].0 != keyed[first].0 {
            first = i;
        } else {
            pairs.push((keyed[first].1, keyed[i].1));
        }
    }
    pairs.sort_unstable();
    pairs
}

/// All intersecting pairs (a < b): a grid of the triangles' boxes proposes the pairs whose
/// boxes touch, the exact tests decide (see [`triangle_pair_intersects`]).
pub fn intersecting_pairs(surface: &Surface) -> Vec<(u32, u32)> {
    let all: Vec<u32> = (0..surface.triangles.len() as u32).collect();
    intersecting_pairs_with(surface, &all, false)
}

/// The intersecting pairs (a < b) in which at least one triangle is in `queries`; with
/// `distant_only`, pairs of triangles sharing a vertex are not tested (a caller that knows its
/// neighbouring triangles are consistent saves most of the exact tests).
pub fn intersecting_pairs_with(surface: &Surface, queries: &[u32], distant_only: bool) -> Vec<(u32, u32)> {
    let boxes: Vec<Aabb> = (0..surface.triangles.len())
        .into_par_iter()
        .map(|t| Aabb::from_points(&surface.triangle_points(t)))
        .collect();
    let mut is_query = vec![false; boxes.len()];
    for &q in queries {
        is_query[q as usize] = true;
    }
    let mut pairs: Vec<(u32, u32)> =
        overlapping_pairs_where(&boxes, &is_query, |a, b| !distant_only || !shares_vertex(surface, a, b))
            .into_par_iter()
            .filter(|&(a, b)| triangle_pair_intersects(surface, a, b))
            .collect();
    pairs.sort_unstable();
    pairs
}

fn shares_vertex(surface: &Surface, a: u32, b: u32) -> bool {
    let tb = surface.triangles[b as usize];
    surface.triangles[a as usize].iter().any(|v| tb.contains(v))
}

/// Whether triangles `a` and `b` of the surface intersect improperly: sharing no vertex, they
/// must not touch at all; sharing one vertex, they must meet only there; sharing an edge, they
/// must not fold onto each other; sharing all three vertices, they are duplicates.
fn triangle_pair_intersects(surface: &Surface, a: u32, b: u32) -> bool {
    let (ta, tb) = (surface.triangles[a as usize], surface.triangles[b as usize]);
    let p = |v: u32| surface.points[v as usize];
    let (mut shared, mut count) = ([(0, 0); 3], 0);
    for (i, corner) in ta.iter().enumerate() {
        if let Some(j) = tb.iter().position(|v| v == corner) {
            shared[count] = (i, j);
            count += 1;
        }
    }
    match shared[..count] {
        [] => triangles_intersect(ta.map(p), tb.map(p)),
        [(i, j)] => meet_beyond_shared_vertex(
            p(ta[i]),
            p(ta[(i + 1) % 3]),
            p(ta[(i + 2) % 3]),
            p(tb[(j + 1) % 3]),
            p(tb[(j + 2) % 3]),
        ),
        [(i1, j1), (i2, j2)] => {
            folds_over_shared_edge(p(ta[i1]), p(ta[i2]), p(ta[3 - i1 - i2]), p(tb[3 - j1 - j2]))
        }
        _ => true,
    }
}

/// Size, volume and box of every shell (topology shells, all closed and manifold by now).
fn measure_shells(surface: &Surface, topology: &Topology) -> Vec<ShellReport> {
    let mut reports: Vec<ShellReport> = topology
        .shells
        .iter()
        .map(|s| ShellReport {
            triangles: s.triangles,
            vertices: s.vertices,
            edges: s.edges,
            genus: s.genus,
            volume: 0.0,
            bounding_box: Aabb::empty(),
            parent: None,
            flipped: false,
        })
        .collect();
    // Volumes relative to a point of each shell, to keep the round-off of far-away shells small.
    let mut origin = vec![None; reports.len()];
    for (t, &s) in topology.triangle_shell.iter().enumerate() {
        let [a, b, c] = surface.triangle_points(t);
        let o = *origin[s as usize].get_or_insert(a);
        let report = &mut reports[s as usize];
        report.volume += (a - o).dot((b - o).cross(c - o)) / 6.0;
        for p in [a, b, c] {
            report.bounding_box.grow(p);
        }
    }
    reports
}

/// Flip every shell enclosing negative volume (or reject them when flipping is not allowed).
fn orient_shells_outward(
    surface: &mut Surface,
    topology: &Topology,
    shells: &mut [ShellReport],
    options: &ValidationOptions,
) -> Result<(Vec<u32>, Vec<String>), ValidationError> {
    let inverted: Vec<u32> = filter_ids(shells.len(), |s| shells[s as usize].volume < 0.0);
    let (start, triangles) = topology.shell_triangles();
    let first_triangle = |s: u32| triangles[start[s as usize] as usize];
    let describe = Describe { surface, max: options.max_examples };
    let at = |s: u32| ShellAt {
        shell: s,
        triangles: shells[s as usize].triangles,
        volume: shells[s as usize].volume,
        example: describe.tag(first_triangle(s)),
    };
    if !options.flip_inverted_shells {
        describe.reject(&inverted, at, |examples| ValidationError::InvertedShells { examples })?;
    }
    let warnings: Vec<String> = inverted
        .iter()
        .map(|&s| format!("{}: its normals pointed into it; flipped all its triangles", at(s)))
        .collect();
    for &s in &inverted {
        let range = start[s as usize] as usize..start[s as usize + 1] as usize;
        for &t in &triangles[range] {
            surface.triangles[t as usize].swap(1, 2);
        }
        shells[s as usize].volume = -shells[s as usize].volume;
        shells[s as usize].flipped = true;
    }
    Ok((inverted, warnings))
}

/// Record for every shell the innermost other shell enclosing it: shells do not intersect, so
/// one vertex of a shell decides whether the whole shell is inside another.
fn nest_shells(surface: &Surface, topology: &Topology, shells: &mut [ShellReport]) {
    if shells.len() < 2 {
        return;
    }
    let (start, triangles) = topology.shell_triangles();
    let shell_triangles = |s: usize| &triangles[start[s] as usize..start[s + 1] as usize];
    for inner in 0..shells.len() {
        let probe = surface.points[surface.triangles[shell_triangles(inner)[0] as usize][0] as usize];
        let parent = (0..shells.len())
            .filter(|&outer| outer != inner && contains_point(&shells[outer].bounding_box, probe))
            .filter(|&outer| {
                point_inside(surface, shell_triangles(outer), &shells[outer].bounding_box, probe)
            })
            .min_by(|&a, &b| shells[a].volume.abs().total_cmp(&shells[b].volume.abs()));
        shells[inner].parent = parent.map(|p| p as u32);
    }
}

fn contains_point(b: &Aabb, p: DVec3) -> bool {
    p.cmpge(b.min).all() && p.cmple(b.max).all()
}

/// Ray parity of `p` against a closed shell that does not pass through `p`. The ray is a
/// segment from `p` to beyond the shell's box; a direction whose segment touches an edge, a
/// vertex or a plane through its far end (exactly) is replaced by the next one.
fn point_inside(surface: &Surface, triangles: &[u32], bbox: &Aabb, p: DVec3) -> bool {
    let reach = (p - bbox.center()).length() + bbox.diagonal() + 1.0;
    for attempt in 0..64 {
        let k = f64::from(attempt);
        let direction = DVec3::new((1.0 + 0.618 * k).sin(), (2.0 + 1.414 * k).cos(), (3.0 + 1.732 * k).sin());
        let q = p + direction.normalize_or(DVec3::X) * reach;
        if let Some(crossings) = count_crossings(surface, triangles, p, q) {
            return crossings % 2 == 1;
        }
    }
    false
}

/// Number of triangles the segment `[p, q]` crosses through their interior; `None` when it
/// touches one in a degenerate way (through an edge or vertex, or `q` in a triangle's plane).
fn count_crossings(surface: &Surface, triangles: &[u32], p: DVec3, q: DVec3) -> Option<usize> {
    let mut crossings = 0;
    for &t in triangles {
        let [a, b, c] = surface.triangle_points(t as usize);
        let (sp, sq) = (orient3d(a, b, c, p), orient3d(a, b, c, q));
        if sq == Sign::Zero {
            return None;
        }
        // p off the shell: when p is in the plane, the segment meets it only outside the triangle.
        if sp == Sign::Zero || sp == sq {
            continue;
        }
        let sides = [orient3d(p, q, a, b), orient3d(p, q, b, c), orient3d(p, q, c, a)];
        if sides.contains(&Sign::Zero) {
            return None;
        }
        if sides[0] == sides[1] && sides[1] == sides[2] {
            crossings += 1;
        }
    }
    Some(crossings)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::shapes;
    use crate::surface::topology::tests::{block_without, cube_without_octant, voxel_surface, voxel_torus};

    fn check(surface: &mut Surface) -> Result<ValidationReport, ValidationError> {
        validate(surface, &ValidationOptions::default())
    }

    fn cube() -> Surface {
        voxel_surface(&[[0, 0, 0]])
    }

    /// Append `other` (its points moved by `offset` and scaled by `scale`) to `surface`.
    fn merge(surface: &mut Surface, other: &Surface, scale: f64, offset: DVec3) {
        let base = surface.points.len() as u32;
        surface.points.extend(other.points.iter().map(|&p| p * scale + offset));
        surface.triangles.extend(other.triangles.iter().map(|t| t.map(|v| v + base)));
        surface.triangle_patch.extend(&other.triangle_patch);
    }

    #[test]
    fn valid_solids() {
        for (name, mut s, genus) in [
            ("cube", cube(), 0),
            ("L-block", voxel_surface(&[[0, 0, 0], [1, 0, 0], [0, 1, 0]]), 0),
            ("cut cube", cube_without_octant(), 0),
            ("torus", voxel_torus(), 1),
            ("sphere", shapes::icosphere(1.0, 3), 0),
        ] {
            let before = s.triangles.clone();
            let report = check(&mut s).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(report.shells.len(), 1, "{name}");
            assert_eq!(report.shells[0].genus, Some(genus), "{name}");
            assert!(report.warnings.is_empty() && report.flipped_shells.is_empty(), "{name}");
            assert_eq!(s.triangles, before, "{name} unchanged");
            assert!((report.shells[0].volume - s.enclosed_volume()).abs() < 1e-12, "{name}");
        }
        let mut sphere = shapes::icosphere(1.0, 3);
        let volume = check(&mut sphere).unwrap().shells[0].volume;
        assert!((volume - 4.0 / 3.0 * std::f64::consts::PI).abs() < 0.05, "{volume}");
    }

    #[test]
    fn ray_parity_inside_and_outside_a_cube() {
        let s = cube();
        let all: Vec<u32> = (0..12).collect();
        let b = s.bounding_box();
        for (p, inside) in [
            ([0.5, 0.5, 0.5], true),
            ([0.1, 0.9, 0.2], true),
            ([2.0, 0.0, 0.5], false),
            ([-1.0, -1.0, -1.0], false),
            ([0.5, 0.5, 1.5], false),
        ] {
            assert_eq!(point_inside(&s, &all, &b, DVec3::from_array(p)), inside, "{p:?}");
        }
    }

    #[test]
    fn unused_vertices_are_a_warning() {
        let mut s = cube();
        s.points.push(DVec3::splat(5.0));
        let report = check(&mut s).unwrap();
        assert_eq!(
            report.warnings,
            vec!["1 vertex used by no triangle (ignored), e.g. vertex 8 at (5, 5, 5)"]
        );
    }

    #[test]
    fn disjoint_cubes_have_no_parent() {
        let mut s = voxel_surface(&[[0, 0, 0], [3, 0, 0]]);
        let report = check(&mut s).unwrap();
        assert_eq!(report.shell_parents(), vec![None, None]);
    }

    #[test]
    fn nested_cubes_record_parent_and_inverted_outer_is_flipped() {
        for inverted in [false, true] {
            let mut s = cube();
            if inverted {
                s.flip_all();
            }
            let unit = cube();
            merge(&mut s, &unit, 1.0 / 3.0, DVec3::splat(1.0 / 3.0));
            let report = check(&mut s).unwrap();
            assert_eq!(report.shell_parents(), vec![None, Some(0)], "inverted {inverted}");
            assert!(report.shells.iter().all(|sh| sh.volume > 0.0));
            let expected: Vec<u32> = if inverted { vec![0] } else { vec![] };
            assert_eq!(report.flipped_shells, expected);
            assert_eq!(report.warnings.len(), expected.len());
        }
        // A cavity in a block: the cavity's own surface points into the cavity, so it is flipped.
        let mut block = block_without(3, [1, 1, 1]);
        let report = check(&mut block).unwrap();
        assert_eq!(report.flipped_shells.len(), 1);
        let cavity = report.flipped_shells[0] as usize;
        assert_eq!(report.shells[cavity].triangles, 12);
        assert_eq!(report.shells[cavity].parent, Some(1 - cavity as u32));
    }

    #[test]
    fn inverted_cube_is_flipped_with_a_warning() {
        let mut s = cube();
        s.flip_all();
        let report = check(&mut s).unwrap();
        assert_eq!(report.flipped_shells, vec![0]);
        assert!(report.warnings[0].contains("shell 0 (12 triangles, e.g. triangle 0 (patch xmin))"));
        assert!(report.warnings[0].contains("flipped"), "{}", report.warnings[0]);
        assert!((s.enclosed_volume() - 1.0).abs() < 1e-12);
        assert_eq!(s.triangles, cube().triangles);
        let mut again = cube();
        again.flip_all();
        let strict = ValidationOptions { flip_inverted_shells: false, ..Default::default() };
        let e = validate(&mut again, &strict).unwrap_err();
        assert!(matches!(e, ValidationError::InvertedShells { .. }), "{e}");
        assert!(e.to_string().contains("shell 0"), "{e}");
    }

    #[test]
    fn open_box() {
        let mut s = cube();
        let removed = s.triangles.remove(5);
        s.triangle_patch.remove(5);
        let e = check(&mut s).unwrap_err();
        let ValidationError::OpenEdges { examples } = &e else { panic!("{e}") };
        assert_eq!(examples.total, 3);
        let message = e.to_string();
        assert!(message.starts_with("open surface: 3 boundary edges ("), "{message}");
        assert!(
            message.contains("e.g. edge (0, 4) at (0, 0, 0)-(1, 0, 0) of triangle 7 (patch zmin)"),
            "{message}"
        );
        for edge in &examples.first {
            assert!(edge.edge.iter().all(|v| removed.contains(v)));
            assert_eq!(edge.triangles.len(), 1);
        }
    }

    #[test]
    fn three_triangles_on_an_edge() {
        // A bipyramid over triangle (0, 1, 2) with that triangle added: its 3 edges have 3 triangles.
        let points =
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.3, 0.3, 1.0), DVec3::new(0.3, 0.3, -1.0)];
        let triangles = vec![[0, 1, 3], [1, 2, 3], [2, 0, 3], [1, 0, 4], [2, 1, 4], [0, 2, 4], [0, 1, 2]];
        let triangle_patch = vec![0; triangles.len()];
        let mut s = Surface { points, triangles, triangle_patch, patch_names: vec!["p".into()] };
        let e = check(&mut s).unwrap_err();
        let ValidationError::NonManifoldEdges { examples } = &e else { panic!("{e}") };
        assert_eq!(examples.total, 3);
        assert_eq!(examples.first[0].edge, [0, 1]);
        assert!(
            e.to_string().contains(
                "edge (0, 1) at (0, 0, 0)-(1, 0, 0) of triangle 0 (patch p), triangle 3 \
            (patch p) and triangle 6 (patch p)"
            ),
            "{e}"
        );
        // Two cubes sharing an edge: four triangles on it.
        let e = check(&mut voxel_surface(&[[0, 0, 0], [1, 1, 0]])).unwrap_err();
        let ValidationError::NonManifoldEdges { examples } = &e else { panic!("{e}") };
        assert_eq!((examples.total, examples.first[0].triangles.len()), (1, 4), "{e}");
    }

    #[test]
    fn two_tetrahedra_touching_at_a_vertex() {
        // The unit tetrahedron, and a copy moved up by one so that its corner 0 is the first's apex 3.
        let unit = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let mut points = unit.to_vec();
        points.extend(unit[1..].iter().map(|&p| p + DVec3::Z));
        let tet = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        let mut triangles = tet.to_vec();
        triangles.extend(tet.iter().map(|t| t.map(|v| v + 3)));
        let mut s =
            Surface { points, triangles, triangle_patch: vec![0; 8], patch_names: vec![String::new()] };
        assert!(s.enclosed_volume() > 0.0);
        let e = check(&mut s).unwrap_err();
        let ValidationError::NonManifoldVertices { examples } = &e else { panic!("{e}") };
        assert_eq!(examples.total, 1);
        assert_eq!((examples.first[0].vertex.vertex, examples.first[0].fans), (3, 2));
        assert!(
            e.to_string().contains("vertex 3 at (0, 0, 1), whose 6 triangles form 2 separate fans"),
            "{e}"
        );
    }

    #[test]
    fn two_flipped_triangles() {
        let mut s = cube();
        s.triangles[0].swap(1, 2);
        s.triangles[1].swap(1, 2);
        let e = check(&mut s).unwrap_err();
        let ValidationError::InconsistentOrientation { examples } = &e else { panic!("{e}") };
        assert_eq!(examples.total, 4, "the flipped quad's boundary");
        let named: Vec<u32> = examples.first[0].triangles.iter().map(|t| t.triangle).collect();
        assert_eq!(named.len(), 2);
        assert!(named[0] <= 1 && named[1] > 1, "{e}");
        assert!(e.to_string().contains(&format!("triangle {}", named[1])), "{e}");
    }

    #[test]
    fn overlapping_cubes_intersect() {
        let mut s = cube();
        merge(&mut s, &cube(), 1.0, DVec3::splat(0.5));
        let e = check(&mut s).unwrap_err();
        let ValidationError::SelfIntersections { examples } = &e else { panic!("{e}") };
        assert!(examples.total > 0);
        let pair = &examples.first[0];
        assert!(pair.first.triangle.triangle < 12 && pair.second.triangle.triangle >= 12, "{e}");
        assert!(e.to_string().starts_with("self-intersecting surface: "), "{e}");
    }

    #[test]
    fn folded_pair_intersects() {
        // Move one corner of the top face across the face's diagonal: its two triangles fold.
        let mut s = cube();
        let top: Vec<usize> =
            (0..s.triangles.len()).filter(|&t| s.triangle_points(t).iter().all(|p| p.z == 1.0)).collect();
        let [t0, t1] = [top[0], top[1]];
        let diagonal: Vec<u32> =
            s.triangles[t0].iter().copied().filter(|v| s.triangles[t1].contains(v)).collect();
        let lone = s.triangles[t1].iter().copied().find(|v| !diagonal.contains(v)).unwrap();
        let other = s.triangles[t0].iter().copied().find(|v| !diagonal.contains(v)).unwrap();
        let mid = 0.5 * (s.points[diagonal[0] as usize] + s.points[diagonal[1] as usize]);
        s.points[lone as usize] = mid + 0.5 * (s.points[other as usize] - mid);
        let e = check(&mut s).unwrap_err();
        let ValidationError::SelfIntersections { examples } = &e else { panic!("{e}") };
        let fold = (t0.min(t1) as u32, t0.max(t1) as u32);
        assert!(
            examples.first.iter().any(|p| (p.first.triangle.triangle, p.second.triangle.triangle) == fold),
            "{e}"
        );
    }

    #[test]
    fn nan_vertex() {
        let mut s = cube();
        s.points[3].y = f64::NAN;
        let e = check(&mut s).unwrap_err();
        assert!(matches!(e, ValidationError::NonFiniteCoordinates { .. }));
        assert!(e.to_string().contains("at 1 vertex, e.g. vertex 3 at ("), "{e}");
        assert!(e.to_string().contains("NaN"), "{e}");
    }

    #[test]
    fn coordinates_beyond_the_range_name_the_vertex_triangle_and_value() {
        let mut s = cube();
        s.points[3].x = 1e19;
        let e = check(&mut s).unwrap_err();
        assert!(matches!(e, ValidationError::CoordinatesOutOfRange { .. }), "{e}");
        let t = s.triangles.iter().position(|t| t.contains(&3)).unwrap();
        let text = e.to_string();
        assert!(text.contains(&format!("vertex 3 at (1.000000e19, ")), "{text}");
        assert!(text.contains(&format!("of triangle {t}")), "{text}");
        let mut s = cube();
        s.points.push(DVec3::new(0.0, -2e12, 0.0));
        let text = check(&mut s).unwrap_err().to_string();
        assert!(text.contains("vertex 8 at (0, -2.000000e12, 0) (used by no triangle)"), "{text}");
    }

    #[test]
    fn a_body_too_small_for_where_it_is_is_rejected() {
        for (scale, offset, ok) in
            [(1e-11, 0.0, true), (1e-13, 0.0, false), (1e-3, 1e9, true), (1e-3, 1e10, false)]
        {
            let mut s = cube();
            s.points.iter_mut().for_each(|p| *p = *p * scale + DVec3::splat(offset));
            let r = check(&mut s);
            if ok {
                r.unwrap();
            } else {
                let e = r.unwrap_err();
                assert!(matches!(e, ValidationError::BodyTooSmall { .. }), "{e}");
                assert!(e.to_string().contains("bounding box from ("), "{e}");
            }
        }
    }

    #[test]
    fn zero_area_triangles() {
        let mut s = cube();
        // Put a corner of the top face on the diagonal of its own triangle: exactly collinear.
        let t = (0..12).find(|&t| s.triangle_points(t).iter().all(|p| p.z == 1.0)).unwrap();
        let [a, b, c] = s.triangles[t];
        s.points[b as usize] = 0.5 * (s.points[a as usize] + s.points[c as usize]);
        let e = check(&mut s).unwrap_err();
        let ValidationError::DegenerateTriangles { examples } = &e else { panic!("{e}") };
        assert_eq!(examples.first[0].triangle.triangle, t as u32);
        assert!(
            e.to_string().contains(&format!("triangle {t} (patch zmax) with vertices ({a}, {b}, {c})")),
            "{e}"
        );
        let mut repeated = cube();
        repeated.triangles[7][2] = repeated.triangles[7][0];
        let e = check(&mut repeated).unwrap_err();
        assert!(e.to_string().starts_with("1 degenerate triangle with zero area"), "{e}");
        // A sliver with a tiny but non-zero area is valid.
        let mut sliver = cube();
        sliver.points[b as usize] =
            0.5 * (sliver.points[a as usize] + sliver.points[c as usize]) + DVec3::splat(1e-9);
        assert!(!is_degenerate(&sliver, t));
    }

    #[test]
    fn duplicate_triangle() {
        let mut s = cube();
        let [a, b, c] = s.triangles[4];
        s.triangles.push([a, c, b]);
        s.triangle_patch.push(0);
        let e = check(&mut s).unwrap_err();
        let ValidationError::DuplicateTriangles { examples } = &e else { panic!("{e}") };
        assert_eq!(examples.total, 1);
        assert!(
            e.to_string().contains("triangle 4 (patch ymin)") && e.to_string().contains("triangle 12"),
            "{e}"
        );
    }

    #[test]
    fn bad_indices_and_empty_surface() {
        let mut s = cube();
        s.triangles[2][1] = 100;
        let e = check(&mut s).unwrap_err();
        assert!(
            e.to_string().contains("beyond the 8 vertices") && e.to_string().contains("triangle 2"),
            "{e}"
        );
        assert_eq!(check(&mut Surface::default()).unwrap_err(), ValidationError::Empty);
    }
}
