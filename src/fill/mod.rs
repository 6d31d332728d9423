//! Core fill (docs/design.md): isotropic tetrahedra between the final layer front and the
//! farfield, merged with the layers into one conforming hybrid mesh.
//!
//! [`fill_core`] gathers the core's boundary from the layered mesh ([`front`]): the top faces
//! of the layers (patch [`crate::layers::TOP_PATCH`]), the wall triangles where no layer was
//! built, and a pyramid on every quad of the front (a tetrahedral mesher takes triangles only);
//! adds the farfield ([`farfield`]); has a [`CoreMesher`] fill the region with tetrahedra that
//! keep every boundary triangle exactly; and checks that they do before merging.

pub mod delaunay;
pub mod farfield;
mod front;
pub mod grading;
pub mod improve;
#[cfg(feature = "tetgen")]
pub(crate) mod isolate;
mod merge;
pub mod recover;
pub mod seeds;
pub mod size_jump;
#[cfg(feature = "tetgen")]
pub mod tetgen;

use std::time::Instant;

use serde::Serialize;

pub use front::FrontLayer;

use crate::config::{Config, CoreMesherChoice, FarfieldShape, Flow};
use crate::geometry::{triangle_area_vector, DVec3};
use crate::layers::sliding::SymmetryPlane;
use crate::mesh::VolumeMesh;
use crate::surface::topology::Topology;
use crate::surface::Surface;

/// Volume zone of the core cells (tetrahedra and the pyramids on front quads).
pub const CORE_ZONE_NAME: &str = "core";
/// Boundary patch of the generated farfield.
pub const FARFIELD_PATCH: &str = "farfield";
/// Default farfield extent (box side or sphere diameter) in body sizes (bounding-box diagonals).
pub const DEFAULT_FARFIELD_FACTOR: f64 = 20.0;
/// Default edge length of the farfield triangles, in body sizes.
pub const DEFAULT_FARFIELD_CELL: f64 = 2.0;

/// The meshers bound circumradii (TetGen's `-m`, the native refinement), the guide gives edge
/// lengths: the largest circumradius per size. A regular tetrahedron has sqrt(6)/4 = 0.61, but
/// the first core tetrahedra stand on a front triangle with a seed above one corner, like the
/// corner of a cube (circumradius 0.87 of its edge), and the front's edges vary around their
/// mean: at 0.61 TetGen split most of them and put its own points at half the layer height
/// (fandisk: 21% of the first core cells within [1/r, r] of the last layer, 66% at 1.2).
pub const CIRCUMRADIUS_PER_SIZE: f64 = 1.2;

/// Markers of the [`ClosedBoundary`] triangles built by [`fill_core`].
pub const MARKER_FRONT: u32 = 1;
pub const MARKER_WALL: u32 = 2;
pub const MARKER_FARFIELD: u32 = 3;

/// The closed triangle surface around the region to fill: every triangle's right-hand normal
/// points INTO the region (the convention of [`Surface`] for the fluid), so the tetrahedron on a
/// triangle `(a, b, c)` has its fourth node `d` with `orient3d(a, b, c, d)` positive. A shell
/// whose triangles face away from what it encloses (a body: positive enclosed volume) is a hole
/// of the region; a shell facing inward (the farfield, or the wall of an internal flow) bounds
/// it from outside.
#[derive(Clone, Debug, Default)]
pub struct ClosedBoundary {
    pub points: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    /// One marker per triangle (for [`fill_core`]: [`MARKER_FRONT`], [`MARKER_WALL`] or
    /// [`MARKER_FARFIELD`]).
    pub markers: Vec<u32>,
}

impl ClosedBoundary {
    /// Markers for every triangle, node indices in range, finite points, no triangle of zero
    /// area.
    pub fn check_structure(&self) -> Result<(), FillError> {
        let n = self.points.len();
        if self.markers.len() != self.triangles.len() {
            let (m, t) = (self.markers.len(), self.triangles.len());
            return Err(FillError::Input(format!("{m} markers for {t} triangles")));
        }
        if let Some(p) = self.points.iter().position(|p| !p.is_finite()) {
            return Err(FillError::Input(format!("point {p} is not finite: {:?}", self.points[p])));
        }
        if let Some(t) = self.triangles.iter().position(|t| t.iter().any(|&v| v as usize >= n)) {
            return Err(FillError::Input(format!("triangle {t} {:?} has a node >= {n}", self.triangles[t])));
        }
        let flat = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|v| self.points[v as usize]);
            triangle_area_vector(a, b, c) == DVec3::ZERO
        };
        match self.triangles.iter().position(flat) {
            Some(t) => {
                let points = self.triangles[t].map(|v| self.points[v as usize].to_array());
                Err(FillError::Input(format!("triangle {t} {:?} has no area: {points:?}", self.triangles[t])))
            }
            None => Ok(()),
        }
    }

    /// One point inside every hole of the region (behind each shell that encloses a positive
    /// volume), strictly away from every triangle. An error when no shell bounds the region from
    /// outside (it would be unbounded).
    pub fn hole_points(&self) -> Result<Vec<DVec3>, FillError> {
        self.check_structure()?;
        let surface = self.as_surface();
        let topology = Topology::new(&surface);
        let (start, triangles) = topology.shell_triangles();
        let mut holes = Vec::new();
        let mut outer_shells = 0;
        for w in start.windows(2) {
            let shell = &triangles[w[0] as usize..w[1] as usize];
            let volume: f64 = shell
                .iter()
                .map(|&t| surface.triangle_points(t as usize))
                .map(|[a, b, c]| a.dot(b.cross(c)))
                .sum();
            if volume > 0.0 {
                holes.extend(self.point_behind(&surface, shell));
            } else {
                outer_shells += 1;
            }
        }
        if outer_shells == 0 {
            return Err(FillError::Input(format!(
                "none of the {} shells bounds the region from outside (no farfield, and no shell \
                 facing inward)",
                start.len().saturating_sub(1)
            )));
        }
        Ok(holes)
    }

    /// An error naming a few pairs of triangles that cross or touch where they should not
    /// (exact tests; see [`crate::surface::validate::intersecting_pairs`]).
    pub fn check_no_self_intersection(&self) -> Result<(), FillError> {
        self.check_structure()?;
        let surface = self.as_surface();
        let pairs = crate::surface::validate::intersecting_pairs(&surface);
        if pairs.is_empty() {
            return Ok(());
        }
        let describe = |t: u32| {
            let [a, b, c] = surface.triangle_points(t as usize);
            let marker = self.markers.get(t as usize).copied().unwrap_or(0);
            format!("{} triangle {t} at {:?}", marker_name(marker), ((a + b + c) / 3.0).to_array())
        };
        let examples = pairs.iter().take(5).map(|&(s, t)| format!("{} and {}", describe(s), describe(t)));
        Err(FillError::SelfIntersecting { pairs: pairs.len(), examples: examples.collect() })
    }

    fn as_surface(&self) -> Surface {
        Surface {
            points: self.points.clone(),
            triangles: self.triangles.clone(),
            triangle_patch: vec![0; self.triangles.len()],
            patch_names: vec![String::new()],
        }
    }

    /// A point behind the largest triangle of `shell`, half way to the nearest other triangle.
    fn point_behind(&self, surface: &Surface, shell: &[u32]) -> Option<DVec3> {
        let &largest = shell.iter().max_by(|&&s, &&t| {
            let area = |t: u32| surface.triangle_area_vector(t as usize).length();
            area(s).total_cmp(&area(t))
        })?;
        let [a, b, c] = surface.triangle_points(largest as usize);
        let centre = (a + b + c) / 3.0;
        let clearance = (0..self.triangles.len())
            .filter(|&t| t != largest as usize)
            .map(|t| {
                let [p, q, r] = surface.triangle_points(t);
                (crate::geometry::distance::closest_point_on_triangle(centre, p, q, r) - centre).length()
            })
            .fold(f64::INFINITY, f64::min);
        let normal = surface.triangle_normal(largest as usize);
        (clearance.is_finite() && clearance > 0.0).then(|| centre - normal * (0.5 * clearance))
    }
}

/// What a [`ClosedBoundary`] marker of [`fill_core`] stands for.
fn marker_name(marker: u32) -> &'static str {
    match marker {
        MARKER_FRONT => "front",
        MARKER_WALL => "wall",
        MARKER_FARFIELD => "farfield",
        _ => "boundary",
    }
}

/// The nodes of a triangle in increasing order: the key of the triangle whatever its orientation.
fn sorted_triangle(mut t: [u32; 3]) -> [u32; 3] {
    t.sort_unstable();
    t
}

/// What the mesher gets besides the boundary: points it must keep inside the region (the
/// [`seeds`] over the front, and on a graded fill the first fill's points, which carry the
/// graded sizes) and the target edge length at every boundary point and then every interior
/// point; the mesher interpolates the sizes in between.
#[derive(Clone, Debug, Default)]
pub struct CoreGuide {
    /// The seeds, then `sizing_points` points that only carry sizes inside.
    pub interior: Vec<DVec3>,
    /// `boundary.points.len() + interior.len()` sizes, or none (the mesher's own sizes).
    pub size: Vec<f64>,
    /// How many of the last interior points carry sizes only (a first fill's points, see
    /// [`grading`]): they are not seeds, and the improvement may move them.
    pub sizing_points: usize,
}

impl CoreGuide {
    /// No interior points; at every boundary point the mean length of the boundary edges there
    /// (each edge counted once per triangle using it, so both sides weigh alike).
    pub fn mean_edge_length(boundary: &ClosedBoundary) -> CoreGuide {
        CoreGuide {
            interior: Vec::new(),
            size: crate::sizing::wall::mean_edge_length_per_vertex(&boundary.points, &boundary.triangles),
            sizing_points: 0,
        }
    }

    /// [`CoreGuide::mean_edge_length`] and the seeds over the front's last layer `front` (see
    /// [`seeds::seed_points`]). A seed and the front vertex under it are sized by the larger of
    /// the front's edges and the seed's height:
    /// where the last layer is taller than the front is wide, the first core cell is too, and
    /// sized by the edges alone the mesher would split it half way up.
    pub fn with_seeds(boundary: &ClosedBoundary, front: &FrontLayer) -> (CoreGuide, seeds::Seeds) {
        let mut guide = CoreGuide::mean_edge_length(boundary);
        let seeds = seeds::seed_points(boundary, front, &guide.size);
        guide.interior = seeds.points.clone();
        let mut seed_sizes = Vec::with_capacity(seeds.vertex.len());
        for (&v, &h) in seeds.vertex.iter().zip(&seeds.height) {
            let size = &mut guide.size[v as usize];
            *size = size.max(h);
            seed_sizes.push(*size);
        }
        guide.size.extend(seed_sizes);
        (guide, seeds)
    }
}

/// What a [`CoreMesher`] returns: the boundary points first, unchanged and in order, then the
/// points inside (the guide's, where it kept them, and its own); tetrahedra positive in the
/// Gmsh convention (`orient3d` positive).
#[derive(Clone, Debug, Default)]
pub struct CoreTets {
    pub points: Vec<DVec3>,
    pub tets: Vec<[u32; 4]>,
    /// Added points lying on the boundary (the fill must keep the boundary: always 0 when
    /// [`CoreMesher::fill`] succeeds through [`fill_core`]).
    pub boundary_steiner_points: usize,
}

/// Fills the region bounded by a [`ClosedBoundary`] with tetrahedra, keeping every boundary
/// triangle as a face of exactly one tetrahedron (no point added on the boundary), starting
/// from the guide's interior points (which it may still move or remove).
pub trait CoreMesher {
    fn fill(&self, boundary: &ClosedBoundary, guide: &CoreGuide) -> Result<CoreTets, FillError>;
}

#[derive(Debug, thiserror::Error)]
pub enum FillError {
    #[error("the wall surface does not match the layered mesh: {0}")]
    WallMismatch(String),
    #[error("invalid core options: {0}")]
    Options(String),
    #[error("no valid pyramid fits on the front quad {nodes:?} (centre {centre:?}): the front folds there")]
    NoPyramid { nodes: [u32; 4], centre: [f64; 3] },
    #[error(
        "the core boundary intersects itself ({pairs} pairs of triangles; the layers' front folds or \
         crosses itself, or reaches the farfield), e.g. {}", examples.join("; ")
    )]
    SelfIntersecting { pairs: usize, examples: Vec<String> },
    #[error("the core boundary cannot be passed to the mesher: {0}")]
    Input(String),
    #[error("TetGen failed (code {code}): {message}")]
    TetGen { code: i32, message: String },
    #[error(
        "TetGen crashed (signal {signal}; it aborts when an internal assertion fails, as TetGen 1.5 \
         can on points inserted very near each other or near the boundary)"
    )]
    TetGenCrashed { signal: i32 },
    #[error("the mesher returned a broken mesh: {0}")]
    BadOutput(String),
    #[error(
        "the mesher did not keep the boundary triangle {triangle} (nodes {nodes:?}, centre {centre:?}): \
         it is a face of {tets} tetrahedra on its inner side"
    )]
    BoundaryNotKept { triangle: usize, nodes: [u32; 3], centre: [f64; 3], tets: usize },
    #[error("boundary recovery failed: {0}")]
    Recovery(String),
    #[error(
        "blmesh was built without TetGen (enable the cargo feature `tetgen`, or choose the native \
         core mesher: `--core-mesher native`, `[core] mesher = \"native\"`)"
    )]
    NoMesher,
}

/// The farfield around an external body.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FarfieldSpec {
    pub shape: FarfieldShape,
    /// Box side or sphere diameter, in body sizes (bounding-box diagonal of the wall).
    pub factor: f64,
    /// Edge length of the farfield triangles (absolute); `None`: [`DEFAULT_FARFIELD_CELL`] body
    /// sizes.
    pub cell_size: Option<f64>,
}

impl Default for FarfieldSpec {
    fn default() -> Self {
        FarfieldSpec { shape: FarfieldShape::Box, factor: DEFAULT_FARFIELD_FACTOR, cell_size: None }
    }
}

/// Options of the core fill.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CoreOptions {
    /// The outer boundary; `None` for internal flow (the front alone bounds the core).
    pub farfield: Option<FarfieldSpec>,
    /// Our improvement of the mesher's tetrahedra ([`improve`]).
    pub improve: improve::ImproveOptions,
    /// Give the mesher a point over every front vertex at the last layer's height ([`seeds`]).
    pub seed_front: bool,
    /// The core's sizes beyond the boundary's ([`grading`]); `None`: the mesher's own.
    pub sizing: Option<grading::CoreSizing>,
    /// Which mesher fills the core.
    pub mesher: CoreMesherChoice,
}

impl Default for CoreOptions {
    /// External flow in the default box farfield.
    fn default() -> Self {
        CoreOptions {
            farfield: Some(FarfieldSpec::default()),
            improve: Default::default(),
            seed_front: true,
            sizing: Some(grading::CoreSizing::default()),
            mesher: CoreMesherChoice::default(),
        }
    }
}

impl CoreOptions {
    /// A farfield of the configured shape for external flow, none for internal flow.
    pub fn from_config(config: &Config) -> Self {
        let farfield = match config.flow {
            Flow::External => Some(FarfieldSpec { shape: config.farfield, ..Default::default() }),
            Flow::Internal => None,
        };
        CoreOptions {
            farfield,
            sizing: Some(grading::CoreSizing {
                gradation: config.sizing.gradation.unwrap_or(crate::sizing::DEFAULT_GRADATION),
                max_size: config.sizing.max_size,
                regions: config.sizing.regions.clone(),
            }),
            mesher: config.core.mesher.unwrap_or_default(),
            ..Default::default()
        }
    }
}

/// What the fill did, for the report.
#[derive(Clone, Debug, Default, Serialize)]
pub struct CoreStats {
    pub tetrahedra: usize,
    /// Pyramids put on the quads of the front.
    pub pyramids: usize,
    /// Points inside the core: all of them (the seeds included), and the seeds over the front
    /// the mesher kept in place, of the candidates (front vertices with a last layer under them).
    pub steiner_points: usize,
    pub seeds: usize,
    pub seed_candidates: usize,
    /// Times the mesher crashed on the seeds and was run again with fewer (0 to 2).
    pub mesher_crashes: usize,
    /// Points the mesher added on the boundary (0: the front is kept exactly).
    pub boundary_steiner_points: usize,
    /// The ratio the core's sizes grew by from the boundary ([`grading`]); `None`: the
    /// mesher's own sizes.
    pub gradation: Option<f64>,
    /// Points sampled in the refinement regions for the mesher ([`grading::region_points`]).
    pub region_points: usize,
    /// How smoothly the core's sizes grow ([`grading::size_ratio_across_edges`]).
    pub size_ratio: crate::layers::smoothness::RatioStats,
    /// Smallest and largest dihedral angle of the core tetrahedra, degrees.
    pub min_dihedral: f64,
    pub max_dihedral: f64,
    /// The dihedral angles before and after our improvement, and what is left below 10 degrees.
    pub quality: improve::CoreQuality,
    /// First core tetrahedron's height over the last layer's, over the front triangles (set by
    /// the pipeline, which knows the growth ratio).
    pub size_jump: size_jump::SizeJump,
    /// Wall-clock time of the whole fill and of the mesher alone, seconds.
    pub seconds: f64,
    pub mesher_seconds: f64,
}

/// Fill the core of a layered mesh with the mesher of `options` (TetGen by default); see
/// [`fill_core_with`].
pub fn fill_core(
    layers: &VolumeMesh,
    wall: &Surface,
    options: &CoreOptions,
) -> Result<(VolumeMesh, CoreStats), FillError> {
    fill_core_on_symmetry_plane(layers, wall, options, None)
}

/// [`fill_core`] for a body on a symmetry plane (external flow): the farfield is a half box on
/// the fluid's side of the plane, and the plane around the layers is its face
/// ([`crate::layers::sliding::close_sliding_patches`] gives the plane).
pub fn fill_core_on_symmetry_plane(
    layers: &VolumeMesh,
    wall: &Surface,
    options: &CoreOptions,
    symmetry: Option<&SymmetryPlane>,
) -> Result<(VolumeMesh, CoreStats), FillError> {
    match options.mesher {
        CoreMesherChoice::Native => {
            fill_core_with_symmetry(&recover::NativeCore::default(), layers, wall, options, symmetry)
        }
        #[cfg(feature = "tetgen")]
        CoreMesherChoice::TetGen => {
            fill_core_with_symmetry(&tetgen::TetGen::default(), layers, wall, options, symmetry)
        }
        #[cfg(not(feature = "tetgen"))]
        CoreMesherChoice::TetGen => Err(FillError::NoMesher),
    }
}

/// Fill the core of `layers` (built by [`crate::layers::build_layers`] from `wall` exactly as
/// that got it: validated, and flipped for internal flow; or the wall
/// [`crate::layers::sliding::close_sliding_patches`] returns when columns slid on patches
/// without layers; its points are the mesh's first points) and return the whole mesh: the layer cells, the pyramids on the front
/// quads and the core tetrahedra (zone [`CORE_ZONE_NAME`]); boundary patches are the wall's and
/// [`FARFIELD_PATCH`] (the layers' top faces are interior now).
pub fn fill_core_with(
    mesher: &dyn CoreMesher,
    layers: &VolumeMesh,
    wall: &Surface,
    options: &CoreOptions,
) -> Result<(VolumeMesh, CoreStats), FillError> {
    fill_core_with_symmetry(mesher, layers, wall, options, None)
}

/// [`fill_core_with`] on a symmetry plane (see [`fill_core_on_symmetry_plane`]).
pub fn fill_core_with_symmetry(
    mesher: &dyn CoreMesher,
    layers: &VolumeMesh,
    wall: &Surface,
    options: &CoreOptions,
    symmetry: Option<&SymmetryPlane>,
) -> Result<(VolumeMesh, CoreStats), FillError> {
    let start = Instant::now();
    let mut core = front::core_boundary(layers, wall)?;
    match (&options.farfield, symmetry) {
        (Some(spec), Some(symmetry)) => core.add_half_farfield(wall, spec, symmetry)?,
        (Some(spec), None) => core.add_farfield(wall, spec)?,
        (None, Some(_)) => {
            return Err(FillError::Options(
                "a symmetry plane the layers slid away from needs a farfield (external flow)".into(),
            ))
        }
        (None, None) => {}
    }
    let (mut boundary, nodes) = core.closed_boundary();
    let front_layer = core.front_layer(&nodes, false);
    let mesher_start = Instant::now();
    let SeededFill { tets, seeds_used, seeds, crashes: mesher_crashes, guide } = if options.seed_front {
        fill_with_seeds(mesher, &boundary, &front_layer, || core.front_layer(&nodes, true))?
    } else {
        let mut guide = CoreGuide::mean_edge_length(&boundary);
        let (tets, _) = fill_keeping_boundary(mesher, &boundary, &mut guide)?;
        SeededFill { tets, seeds_used: 0, seeds: seeds::Seeds::default(), crashes: 0, guide }
    };
    let (tets, seeds_used, graded) = match &options.sizing {
        Some(sizing) => grading::fill_graded(mesher, &boundary, tets, seeds_used, guide, sizing)?,
        None => (tets, seeds_used, grading::Graded::default()),
    };
    let mesher_seconds = mesher_start.elapsed().as_secs_f64();
    // The seeds stay where they are: they give the first core cells the last layer's height.
    let fixed = boundary.points.len() + seeds_used;
    let slides = improve::FrontSlides::new(&boundary, &front_layer.steps, &core.mesh, &nodes);
    let (tets, quality) = improve::improve_core(
        &mut boundary,
        tets,
        fixed,
        &front_layer.heights,
        Some(slides),
        &options.improve,
    );
    merge::check_boundary_kept(&boundary, &tets)?;
    let gradation = options.sizing.as_ref().map_or(crate::sizing::DEFAULT_GRADATION, |s| s.gradation);
    let size_ratio = grading::size_ratio_across_edges(&tets.points, &tets.tets, gradation);
    merge::check_mesh_boundary_kept(&core, &nodes, &tets)?;
    let (mesh, mut stats) = merge::merge(core, &nodes, &tets);
    stats.quality = quality;
    stats.seeds = seeds_used;
    stats.seed_candidates = seeds.candidates;
    stats.mesher_crashes = mesher_crashes;
    stats.gradation = options.sizing.as_ref().filter(|_| graded.graded).map(|s| s.gradation);
    stats.region_points = graded.region_points;
    stats.size_ratio = size_ratio;
    stats.boundary_steiner_points = tets.boundary_steiner_points;
    stats.mesher_seconds = mesher_seconds;
    stats.seconds = start.elapsed().as_secs_f64();
    Ok((mesh, stats))
}

/// A fill with seeds over the front: the tetrahedra, how many seeds are in place, the seeds
/// given, the mesher's crashes and the guide it ran with last.
struct SeededFill {
    tets: CoreTets,
    seeds_used: usize,
    seeds: seeds::Seeds,
    crashes: usize,
    guide: CoreGuide,
}

/// Run the mesher with the seeds over the front's last layer `front`; when it crashes on them
/// (TetGen aborts on a failed assertion, seen on the ONERA M6 with seeds over the ramps between
/// stacks), again with the seeds over the prisms only (`on_prisms`), then with none.
fn fill_with_seeds(
    mesher: &dyn CoreMesher,
    boundary: &ClosedBoundary,
    front: &FrontLayer,
    on_prisms: impl FnOnce() -> FrontLayer,
) -> Result<SeededFill, FillError> {
    let mut next = Some(on_prisms);
    let mut layer = std::borrow::Cow::Borrowed(front);
    let mut crashes = 0;
    let candidates = loop {
        let (mut guide, seeds) = CoreGuide::with_seeds(boundary, &layer);
        let signal = match fill_keeping_boundary(mesher, boundary, &mut guide) {
            Err(FillError::TetGenCrashed { signal }) => signal,
            result => {
                return result.map(|(tets, seeds_used)| SeededFill {
                    tets,
                    seeds_used,
                    seeds,
                    crashes,
                    guide,
                })
            }
        };
        crashes += 1;
        let Some(on_prisms) = next.take() else {
            tracing::warn!(signal, "TetGen crashed: again without seeds");
            break seeds.candidates;
        };
        tracing::warn!(signal, "TetGen crashed: again with the seeds over the prisms only");
        layer = std::borrow::Cow::Owned(on_prisms());
    };
    let mut guide = CoreGuide::mean_edge_length(boundary);
    let (tets, _) = fill_keeping_boundary(mesher, boundary, &mut guide)?;
    let seeds = seeds::Seeds { candidates, ..Default::default() };
    Ok(SeededFill { tets, seeds_used: 0, seeds, crashes, guide })
}

/// Times the mesher is run again, with the seeds near the boundary triangle it lost removed,
/// before the seeds are given up.
const SEED_RETRIES: usize = 3;

/// Seeds within this many local sizes of a boundary triangle the mesher lost are removed
/// before it runs again.
const SEED_CLEARING: f64 = 3.0;

/// Run the mesher and check that it kept every boundary triangle; returns the tetrahedra and
/// the seeds still in place. TetGen's boundary recovery can fail where the front nearly
/// touches itself and seeds stand close by: then the seeds near the triangle it lost are
/// removed and it runs again (at most [`SEED_RETRIES`] times, then without any seeds).
fn fill_keeping_boundary(
    mesher: &dyn CoreMesher,
    boundary: &ClosedBoundary,
    guide: &mut CoreGuide,
) -> Result<(CoreTets, usize), FillError> {
    let n = boundary.points.len();
    let mut attempt = 0;
    loop {
        let mut tets = mesher.fill(boundary, guide)?;
        merge::drop_unused_points(&mut tets, n);
        let seeds_used = merge::seeds_in_place_first(boundary, guide, &mut tets);
        let lost = match merge::check_boundary_kept(boundary, &tets) {
            Ok(()) => return Ok((tets, seeds_used)),
            Err(FillError::BoundaryNotKept { triangle, .. }) if !guide.interior.is_empty() => triangle,
            Err(e) => return Err(e),
        };
        let [a, b, c] = boundary.triangles[lost].map(|v| boundary.points[v as usize]);
        let centre = (a + b + c) / 3.0;
        let reach = SEED_CLEARING * (a.distance(b) + b.distance(c) + c.distance(a)) / 3.0;
        let keep: Vec<bool> = if attempt < SEED_RETRIES {
            guide.interior.iter().map(|p| p.distance(centre) > reach).collect()
        } else {
            vec![false; guide.interior.len()]
        };
        tracing::info!(
            triangle = lost,
            removed = keep.iter().filter(|k| !**k).count(),
            "the mesher lost a boundary triangle: again without the seeds near it"
        );
        let mut kept = keep.iter();
        guide.interior.retain(|_| *kept.next().unwrap_or(&false));
        let mut kept = std::iter::repeat_n(&true, n).chain(keep.iter());
        guide.size.retain(|_| *kept.next().unwrap_or(&false));
        attempt += 1;
    }
}

#[cfg(test)]
mod tests;
