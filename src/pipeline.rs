//! The `mesh` pipeline, stage by stage (docs/design.md): validate, analyse features, normals,
//! layers, (core), check; with timings and the run's report.

use serde::Serialize;

use crate::config::{Config, ConfigError, Flow, LayerSpec, Role};
use crate::fill::improve::{min_dihedral, SLIVER_THRESHOLD};
use crate::fill::{fill_core_on_symmetry_plane, CoreOptions, CoreStats, FillError};
use crate::geometry::DVec3;
use crate::layers::sliding::SlidingError;
use crate::layers::{self, Adapt, MarchStats};
use crate::mesh::{CellKind, VolumeMesh};
use crate::normals::constraint::{self, Plane};
use crate::normals::{self, NormalStats};
use crate::progress::{Progress, Timings};
use crate::quality::{self, CheckReport};
use crate::sizing::SizingField;
use crate::surface::features::{FeatureCounts, Features, VertexKind};
use crate::surface::topology::Topology;
use crate::surface::validate::{format_point, validate, ValidationError, ValidationOptions};
use crate::surface::Surface;

/// Options of a run that are not meshing parameters.
#[derive(Clone, Debug)]
pub struct MeshOptions {
    /// Fill the core with tetrahedra up to the farfield (or, for internal flow, the whole
    /// inside); otherwise the mesh holds the layers alone, their top faces as a patch.
    pub core: bool,
}

#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("invalid surface: {0}")]
    Surface(#[from] ValidationError),
    #[error(transparent)]
    Config(#[from] ConfigError),
    #[error("{0}")]
    Unsupported(String),
    #[error("core fill failed: {0} (the layers alone can be written with --no-core)")]
    Fill(#[from] FillError),
    #[error("the layers cannot be closed against a patch without layers: {0}")]
    Sliding(#[from] SlidingError),
    #[error(transparent)]
    Sizing(#[from] crate::sizing::SpecError),
    #[error(
        "no cell was made: the columns of {stopped} wall vertices stopped before their first layer, \
         e.g. at {examples}; a first layer far thinner than the wall's triangles are wide may need \
         a finer wall"
    )]
    NoCells { stopped: usize, examples: String },
    #[error("the mesh failed its own check (a bug in blmesh; please report it):\n{0}")]
    InvalidResult(Box<CheckReport>),
}

/// The mesh and its report.
pub struct MeshOutput {
    pub mesh: VolumeMesh,
    pub report: MeshReport,
}

/// Everything the run measured; printed as a summary and written with `--report`.
#[derive(Clone, Debug, Serialize)]
pub struct MeshReport {
    pub input: InputSummary,
    pub features: FeatureCounts,
    pub normals: NormalStats,
    pub layers: LayerSummary,
    /// The rounds that marched again with the stacks under the core's slivers lower.
    pub peel: PeelStats,
    /// The core fill, when it was run.
    pub core: Option<CoreStats>,
    pub cells: CellCounts,
    pub check: CheckReport,
    pub timings: Timings,
    /// Peak resident memory of the run, in MiB (Linux only).
    pub peak_memory_mib: Option<f64>,
    pub warnings: Vec<String>,
    /// Where `--pictures` cuts the mesh besides the overview: the most concave ridge edge and a
    /// convex corner.
    pub picture_spots: Vec<crate::picture::PictureSpot>,
}

#[derive(Clone, Debug, Serialize)]
pub struct InputSummary {
    pub triangles: usize,
    pub vertices: usize,
    pub patches: Vec<String>,
    pub body_size: f64,
    /// What the wall's own triangulation gives the first prisms' lateral faces: their
    /// non-orthogonality, which every layer of full prisms over an edge repeats.
    pub wall_non_orthogonality: quality::fv::WallNonOrthogonality,
}

#[derive(Clone, Debug, Serialize)]
pub struct LayerSummary {
    pub march: MarchStats,
    /// Layers reached over the wall vertices that get layers: min, median, max.
    pub layers_min: u32,
    pub layers_median: u32,
    pub layers_max: u32,
    /// Fraction of layered wall vertices that reached their full stack, or stopped at the
    /// medial surface of a thin gap (as thick as the gap allows).
    pub full_coverage: f64,
    /// The same over the vertices on concave ridges and at concave or saddle corners, and over
    /// those on convex ridges and at convex or saddle corners (1 when there are none).
    pub concave_coverage: f64,
    pub convex_coverage: f64,
    /// The same over the vertices within two target thicknesses of a concave ridge edge, where
    /// fronts meet (1 when there are none), and how many they are.
    pub near_concave_coverage: f64,
    pub near_concave_vertices: usize,
    /// Wall vertices whose column stopped before its target (not at a gap's medial surface),
    /// with a few examples.
    pub stopped_vertices: usize,
    pub stopped_examples: Vec<[f64; 3]>,
    /// The caps and folds of the final front, before and after tops were pulled back.
    pub unfold: layers::unfold::UnfoldStats,
    /// Wall vertices whose column stopped at the medial surface of a thin gap.
    pub gap_limited_vertices: usize,
    pub smoothness: crate::layers::smoothness::Smoothness,
    /// Wall vertices whose first layer is lower than asked: fitted where stacks stopped under
    /// a first layer too tall for the wall ([`crate::config::LayerSettings::first_aspect`]),
    /// graded around, or graded from a patch with a lower one; and the lowest ratio to the
    /// height asked (1 when none).
    pub lowered_first_height_vertices: usize,
    pub lowest_first_height_ratio: f64,
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct CellCounts {
    pub tetrahedra: usize,
    pub pyramids: usize,
    pub prisms: usize,
    pub hexahedra: usize,
    pub points: usize,
}

impl CellCounts {
    fn total(&self) -> usize {
        self.tetrahedra + self.pyramids + self.prisms + self.hexahedra
    }

    fn of(mesh: &VolumeMesh) -> Self {
        CellCounts {
            tetrahedra: mesh.block(CellKind::Tetrahedron).len(),
            pyramids: mesh.block(CellKind::Pyramid).len(),
            prisms: mesh.block(CellKind::Prism).len(),
            hexahedra: mesh.block(CellKind::Hexahedron).len(),
            points: mesh.points.len(),
        }
    }
}

/// Run the whole pipeline on a surface.
pub fn run(
    mut surface: Surface,
    config: &Config,
    options: &MeshOptions,
    progress: Progress,
) -> Result<MeshOutput, MeshError> {
    let mut timings = Timings::default();
    let mut warnings = Vec::new();
    let validation =
        progress.stage(&mut timings, "validate", || validate(&mut surface, &ValidationOptions::default()))?;
    warnings.extend(validation.warnings.iter().cloned());
    if config.flow == Flow::Internal {
        // Layers grow into the fluid, which is inside the surface: face the normals inward.
        surface.flip_all();
    }
    let body_size = surface.bounding_box().diagonal();
    warnings.extend(config.unmatched_rules(&surface.patch_names).into_iter().map(|pattern| {
        format!("[[patch]] match = {pattern:?} matches no patch (it must match a whole name)")
    }));
    let mut patch_spec = patch_layer_specs(&surface, config, body_size)?;
    check_first_heights(&surface, &patch_spec, body_size)?;
    let layered_patch: Vec<bool> = patch_spec.iter().map(Option::is_some).collect();
    let symmetry_patch: Vec<bool> =
        surface.patch_names.iter().map(|name| config.patch_settings(name).0 == Role::Symmetry).collect();
    // Columns slide on the planar patches without layers, whose vertices are snapped onto
    // their planes first.
    let planes = constraint::snap_planar_patches(&mut surface, &layered_patch);
    warnings.extend(not_planar_warnings(&surface, &layered_patch, &planes));
    if planes.iter().any(Option::is_some) && patch_spec.iter().flatten().any(|s| s.transition) {
        // Stacks that grow on to isotropy can cross each other in a sliding plane where two
        // fronts meet on it (the ONERA M6's trailing edge at its root, also with
        // `count = "auto"`), and nothing guards the plane yet.
        warnings.push(
            "no transition layers where columns slide on a planar patch without layers: the \
             stacks end at their count"
                .to_owned(),
        );
        patch_spec.iter_mut().flatten().for_each(|s| *s = s.without_transition());
    }
    let (topology, features) = progress.stage(&mut timings, "features", || {
        let topology = Topology::new(&surface);
        let features = Features::compute(&surface, &topology, config.feature_angle());
        (topology, features)
    });
    let wall_non_orthogonality = quality::fv::wall_non_orthogonality(&surface, &topology, &layered_patch);
    warnings.extend(wall_non_orthogonality_warning(&wall_non_orthogonality));
    let wall_normals = progress.stage(&mut timings, "normals", || {
        let fan_angle = config.fan_angle();
        let mut n =
            normals::wall_normals_of_layered(&surface, &topology, &features, fan_angle, &layered_patch);
        n.slides = constraint::constrain_columns(&surface, &mut n, &layered_patch, &planes);
        n
    });
    let sizing = match config.sizing.field_spec(&LayerSpec::resolve(&config.layers, body_size)?, body_size) {
        Some(spec) => Some(progress.stage(&mut timings, "sizing", || SizingField::new(&surface, &spec))?),
        None => None,
    };
    let adapt = match (&sizing, config.sizing.adapt()) {
        (_, false) => Adapt::Off,
        (Some(field), true) => Adapt::Field(field),
        (None, true) => Adapt::Wall,
    };
    let stages = LayersAndCore {
        surface: &surface,
        topology: &topology,
        features: &features,
        wall_normals: &wall_normals,
        patch_spec: &patch_spec,
        adapt,
        planes: &planes,
        symmetry_patch: &symmetry_patch,
        config,
        options,
        progress: &progress,
    };
    let (Round { layered, mut mesh, core, .. }, peel) = stages.run_peeling(&mut timings)?;
    // A layers-only mesh keeps every wall point first (a core filled later starts from them,
    // those of patches without layers too); a whole mesh leaves out what no cell uses.
    if options.core {
        let unused = mesh.drop_unused_points();
        if unused > 0 {
            tracing::info!(unused, "points used by no cell left out");
        }
    }
    warnings.extend(peel.failed_round.clone());
    let layer_summary = layer_summary(&layered, &surface, &topology, &features);
    if CellCounts::of(&mesh).total() == 0 {
        let examples = layer_summary.stopped_examples.iter().take(3).map(|&p| format_point(DVec3::from(p)));
        let examples = examples.collect::<Vec<_>>().join(", ");
        return Err(MeshError::NoCells { stopped: layer_summary.stopped_vertices, examples });
    }
    let check = progress.stage(&mut timings, "check", || quality::check(&mesh));
    if !check.is_valid() {
        return Err(MeshError::InvalidResult(Box::new(check)));
    }
    let report = MeshReport {
        input: InputSummary {
            triangles: surface.triangles.len(),
            vertices: surface.points.len(),
            patches: surface.patch_names.clone(),
            body_size,
            wall_non_orthogonality,
        },
        features: features.counts.clone(),
        normals: wall_normals.stats.clone(),
        layers: layer_summary,
        peel,
        core,
        cells: CellCounts::of(&mesh),
        check,
        timings,
        peak_memory_mib: crate::progress::peak_memory_mib(),
        picture_spots: picture_spots(&surface, &topology, &features, &patch_spec),
        warnings,
    };
    Ok(MeshOutput { mesh, report })
}

/// The layers and the core of one march: what [`LayersAndCore::round`] needs.
struct LayersAndCore<'a> {
    surface: &'a Surface,
    topology: &'a Topology,
    features: &'a Features,
    wall_normals: &'a normals::WallNormals,
    patch_spec: &'a [Option<LayerSpec>],
    adapt: Adapt<'a>,
    planes: &'a [Option<Plane>],
    symmetry_patch: &'a [bool],
    config: &'a Config,
    options: &'a MeshOptions,
    progress: &'a Progress,
}

/// A march and its core.
struct Round {
    layered: layers::Layers,
    mesh: VolumeMesh,
    core: Option<CoreStats>,
    slivers: SliverScore,
}

/// What the peeling rounds did ([`LayersAndCore::run_peeling`]).
#[derive(Clone, Debug, Default, Serialize)]
pub struct PeelStats {
    /// Core tetrahedra below 10 deg after each round (the first is the plain march's).
    pub slivers_by_round: Vec<usize>,
    /// The round whose mesh was kept: the fewest slivers, then the best worst angle.
    pub kept_round: usize,
    /// Wall vertices whose stack was capped a layer under its top in the kept round's march.
    pub capped_vertices: usize,
    /// Why a round failed (the layers or the core), when one did: the best before it is kept.
    pub failed_round: Option<String>,
}

impl LayersAndCore<'_> {
    /// March, fill the core, and while it leaves a few slivers (at most
    /// [`PEEL_MAX_SLIVER_SHARE`] of the front's nodes), march again with the tops under their
    /// front nodes free to be pulled back along their last step (most stand at caps of the
    /// front, which a pulled-back top opens, and the stacks keep their layers), and where a
    /// sliver stays over tops freed before, with those stacks a layer lower: the core there had
    /// no room for a good tetrahedron (fronts meeting head on in a crevice, a crumpled front),
    /// and one layer less gives it room. At most `peel_rounds` more marches, none after a round
    /// without slivers, and none after [`PEEL_PATIENCE`] rounds in a row that did not beat the
    /// best; the round with the fewest slivers (then the best worst angle) is kept.
    fn run_peeling(&self, timings: &mut Timings) -> Result<(Round, PeelStats), MeshError> {
        let mut caps = vec![u32::MAX; self.surface.points.len()];
        let mut at_slivers = vec![false; self.surface.points.len()];
        let mut stats = PeelStats::default();
        let mut best: Option<Round> = None;
        let mut kept_caps = 0;
        let mut marked_last: Vec<u32> = Vec::new();
        let mut lowered_instead = caps.clone();
        for round in 0..=self.config.peel_rounds() {
            let this = match self.round(&caps, &at_slivers, timings) {
                Ok(this) => this,
                // A later round that fails leaves the best so far; where its tops pulled back
                // made the front unfit for the core, the best round's stacks are lowered instead.
                Err(e) if best.is_some() => {
                    stats.failed_round =
                        Some(format!("peeling round {round} failed, an earlier one kept: {e}"));
                    let best = best.as_ref().expect("a best round");
                    if marked_last.is_empty() {
                        break;
                    }
                    for v in marked_last.drain(..) {
                        at_slivers[v as usize] = false;
                    }
                    if best.slivers.lower_caps(&best.layered, &mut caps) == 0 {
                        break;
                    }
                    continue;
                }
                Err(e) => return Err(e),
            };
            stats.slivers_by_round.push(this.slivers.tets.len());
            let front_nodes = this.layered.top_stacks.len() as f64;
            // A round without slivers leaves nothing to mend: later rounds could only lower more
            // stacks or pull more tops back.
            let clean = this.slivers.tets.is_empty();
            let peelable = !clean && this.slivers.tets.len() as f64 <= PEEL_MAX_SLIVER_SHARE * front_nodes;
            let capped_now = caps.iter().filter(|&&c| c != u32::MAX).count();
            let (marked, mut lowered) = if peelable {
                this.slivers.pull_back_or_lower(&this.layered, &mut at_slivers, &mut caps)
            } else {
                (Vec::new(), 0)
            };
            if !marked.is_empty() {
                // The caps these slivers would have lowered, for when the pulled tops leave
                // slivers that no more marks or caps reach.
                lowered_instead = caps.clone();
                this.slivers.lower_caps(&this.layered, &mut lowered_instead);
            } else if peelable && lowered == 0 && lowered_instead != caps {
                lowered = lowered_instead.iter().zip(&caps).filter(|(a, b)| a != b).count();
                caps.clone_from(&lowered_instead);
            }
            // The next round differs where tops were marked or caps lowered.
            let next_differs = !marked.is_empty() || lowered > 0;
            tracing::info!(
                round,
                slivers = this.slivers.tets.len(),
                worst = this.slivers.worst,
                marked = marked.len(),
                lowered,
                "core slivers"
            );
            marked_last = marked;
            if best.as_ref().is_none_or(|b| this.slivers.better_than(&b.slivers)) {
                stats.kept_round = round;
                kept_caps = capped_now;
                best = Some(this);
            }
            if !next_differs || round - stats.kept_round >= PEEL_PATIENCE {
                break;
            }
        }
        stats.capped_vertices = kept_caps;
        Ok((best.expect("one round at least"), stats))
    }

    /// March with the stacks at most `caps` layers high (by wall vertex) and fill the core.
    fn round(&self, caps: &[u32], at_slivers: &[bool], timings: &mut Timings) -> Result<Round, MeshError> {
        let surface = self.surface;
        let bar = self.progress.bar("layers");
        let (mut layered, core_wall) = self.progress.stage(timings, "layers", || {
            let mut layered = layers::build_layers(
                surface,
                self.topology,
                self.features,
                self.wall_normals,
                self.patch_spec,
                self.adapt,
                caps,
                at_slivers,
                |k, n| bar.set(k.into(), n.into()),
            );
            let core_wall = layers::sliding::close_sliding_patches(
                &mut layered.mesh,
                surface,
                self.planes,
                self.symmetry_patch,
            );
            (layered, core_wall)
        });
        bar.finish();
        let closed = core_wall?;
        let symmetry = match closed.symmetry.as_slice() {
            [] => None,
            [one] => Some(one),
            [_, more @ ..] => {
                let names: Vec<&str> =
                    more.iter().map(|s| surface.patch_names[s.patch as usize].as_str()).collect();
                return Err(MeshError::Unsupported(format!(
                    "more than one symmetry plane with the body on it (also {names:?}): the farfield \
                     can be cut by one only"
                )));
            }
        };
        if !self.options.core {
            let mesh = std::mem::take(&mut layered.mesh);
            return Ok(Round { layered, mesh, core: None, slivers: SliverScore::default() });
        }
        let growth = self.patch_spec.iter().flatten().map(|s| s.growth).fold(1.0, f64::max);
        let (mesh, mut stats) = self.progress.stage(timings, "core", || {
            let mut options = CoreOptions::from_config(self.config);
            options.improve.size_band = growth;
            fill_core_on_symmetry_plane(&layered.mesh, &closed.core_wall, &options, symmetry)
        })?;
        let mut slivers = SliverScore::default();
        if let Some(core_zone) = mesh.zone_names.iter().position(|z| z == crate::fill::CORE_ZONE_NAME) {
            let (layer_zone, core_zone) = (crate::layers::march::LAYER_ZONE, core_zone as u32);
            stats.size_jump = crate::fill::size_jump::measure(&mesh, layer_zone, core_zone, growth);
            slivers = SliverScore::of(&mesh, core_zone);
        }
        Ok(Round { layered, mesh, core: Some(stats), slivers })
    }
}

/// Rounds in a row without a new best after which peeling stops: there the front does not
/// settle, each lower cap only moves the slivers elsewhere, and every round re-runs the march
/// and the whole core.
const PEEL_PATIENCE: usize = 3;

/// The most slivers, as a share of the front's nodes, that peeling tries to mend: more come
/// from elsewhere (a wall faceted too coarsely for its layers: the elbow, wtc2), and peeling
/// would strip their layers.
const PEEL_MAX_SLIVER_SHARE: f64 = 0.01;

/// The core tetrahedra below [`SLIVER_THRESHOLD`] and the worst angle.
#[derive(Clone, Debug)]
struct SliverScore {
    tets: Vec<[u32; 4]>,
    worst: f64,
}

impl Default for SliverScore {
    fn default() -> Self {
        SliverScore { tets: Vec::new(), worst: 180.0 }
    }
}

impl SliverScore {
    fn of(mesh: &VolumeMesh, core_zone: u32) -> SliverScore {
        let block = mesh.block(CellKind::Tetrahedron);
        let mut score = SliverScore::default();
        for (i, &zone) in block.zone.iter().enumerate() {
            let Ok(tet) = <[u32; 4]>::try_from(block.cell(i)) else { continue };
            if zone != core_zone {
                continue;
            }
            let angle = min_dihedral(tet.map(|v| mesh.points[v as usize]));
            score.worst = score.worst.min(angle);
            if angle < SLIVER_THRESHOLD {
                score.tets.push(tet);
            }
        }
        score
    }

    fn better_than(&self, other: &SliverScore) -> bool {
        self.tets.len() < other.tets.len()
            || (self.tets.len() == other.tets.len() && self.worst > other.worst)
    }

    /// Mark the wall vertices under each sliver's front nodes whose tops the next round may pull
    /// back ([`layers::unfold`]: the stack keeps its layers, its last one thinner); where all of
    /// a sliver's were marked in an earlier round and it is still there, lower their caps
    /// ([`SliverScore::lower_caps`]). Returns the vertices marked now and how many caps were
    /// lowered.
    fn pull_back_or_lower(
        &self,
        layered: &layers::Layers,
        at_slivers: &mut [bool],
        caps: &mut [u32],
    ) -> (Vec<u32>, usize) {
        let before = at_slivers.to_vec();
        let mut marked = Vec::new();
        let mut again = SliverScore { tets: Vec::new(), worst: self.worst };
        for tet in &self.tets {
            let stacks: Vec<u32> =
                tet.iter().filter_map(|n| layered.top_stacks.get(n).map(|s| s.0)).collect();
            if stacks.iter().all(|&v| before[v as usize]) {
                again.tets.push(*tet);
            }
            for v in stacks {
                if !at_slivers[v as usize] {
                    at_slivers[v as usize] = true;
                    marked.push(v);
                }
            }
        }
        (marked, again.lower_caps(layered, caps))
    }

    /// Cap the tallest stacks under each sliver's front nodes (those that reached the most
    /// layers) a layer under their top; a stack keeps one layer at least (none would leave a
    /// pit). Returns how many caps were lowered. (Every front node's stack instead: spot's
    /// coverage 87.3-88.1% in 6-8 rounds over growth 1.1999 / 1.2 / 1.2001; the tallest alone:
    /// 88.5-89.7% in 4-5.)
    fn lower_caps(&self, layered: &layers::Layers, caps: &mut [u32]) -> usize {
        let mut lowered = 0;
        for tet in &self.tets {
            let stacks: Vec<(u32, u32)> =
                tet.iter().filter_map(|n| layered.top_stacks.get(n).copied()).collect();
            let Some(tallest) = stacks.iter().map(|s| s.1).max() else { continue };
            for (v, reached) in stacks.into_iter().filter(|s| s.1 == tallest) {
                let cap = &mut caps[v as usize];
                if reached >= 2 && reached - 1 < *cap {
                    *cap = reached - 1;
                    lowered += 1;
                }
            }
        }
        lowered
    }
}

/// Cuts for the pictures: across the most concave ridge edge (normal along it, through its
/// middle) and through the convex corner with the sharpest ridge (normal along that ridge), each
/// zoomed to four layer thicknesses or two edge lengths, whichever is larger.
fn picture_spots(
    surface: &Surface,
    topology: &Topology,
    features: &Features,
    patch_spec: &[Option<LayerSpec>],
) -> Vec<crate::picture::PictureSpot> {
    use crate::picture::PictureSpot;
    use crate::surface::features::{EdgeKind, VertexKind};
    let thickness = patch_spec.iter().flatten().map(|s| s.distance(s.full_count())).fold(0.0, f64::max);
    let edge = |e: usize| topology.edges[e].map(|v| surface.points[v as usize]);
    let spot = |name: &str, origin: crate::geometry::DVec3, along: [crate::geometry::DVec3; 2]| PictureSpot {
        name: name.to_owned(),
        origin,
        normal: (along[1] - along[0]).normalize_or(crate::geometry::DVec3::Z),
        half_width: (4.0 * thickness).max(2.0 * along[0].distance(along[1])),
    };
    let mut spots = Vec::new();
    let ridges =
        |kind: EdgeKind| (0..features.edge_kind.len()).filter(move |&e| features.edge_kind[e] == kind);
    if let Some(e) =
        ridges(EdgeKind::ConcaveRidge).min_by(|&a, &b| features.turn_deg[a].total_cmp(&features.turn_deg[b]))
    {
        let [a, b] = edge(e);
        spots.push(spot("concave_ridge", 0.5 * (a + b), [a, b]));
    }
    let at_convex_corner = |e: &usize| {
        topology.edges[*e].iter().any(|&v| features.vertex_kind[v as usize] == VertexKind::ConvexCorner)
    };
    if let Some(e) = ridges(EdgeKind::ConvexRidge)
        .filter(at_convex_corner)
        .max_by(|&a, &b| features.turn_deg[a].total_cmp(&features.turn_deg[b]))
    {
        let [a, b] = topology.edges[e];
        let (corner, other) =
            if features.vertex_kind[a as usize] == VertexKind::ConvexCorner { (a, b) } else { (b, a) };
        let (corner, other) = (surface.points[corner as usize], surface.points[other as usize]);
        spots.push(spot("convex_corner", corner, [corner, other]));
    }
    spots
}

/// The resolved layer stack of every patch (`None`: no layers on it).
fn patch_layer_specs(
    surface: &Surface,
    config: &Config,
    body_size: f64,
) -> Result<Vec<Option<LayerSpec>>, MeshError> {
    surface
        .patch_names
        .iter()
        .map(|name| {
            let (role, settings) = config.patch_settings(name);
            if !role.has_layers() {
                return Ok(None);
            }
            Ok(Some(LayerSpec::resolve(&settings, body_size)?))
        })
        .collect()
}

/// A first layer height that makes no sense at the body's scale or position
/// ([`crate::limits::first_height_problem`]) is an error naming the patch.
fn check_first_heights(
    surface: &Surface,
    specs: &[Option<LayerSpec>],
    body_size: f64,
) -> Result<(), ConfigError> {
    let bounds = surface.bounding_box();
    let largest = bounds.min.abs().max(bounds.max.abs()).max_element();
    for (name, spec) in surface.patch_names.iter().zip(specs) {
        let Some(h) = spec.map(|s| s.first_height) else { continue };
        if let Some(why) = crate::limits::first_height_problem(h, body_size, largest) {
            let name = format!("first_height (patch {name})");
            return Err(ConfigError::Parameter { name, value: h.to_string(), why });
        }
    }
    Ok(())
}

/// A warning for every patch without layers that is not planar: columns cannot slide on it,
/// so the layers stop where they meet it.
fn not_planar_warnings(surface: &Surface, layered_patch: &[bool], planes: &[Option<Plane>]) -> Vec<String> {
    let counts = surface.patch_triangle_counts();
    (0..surface.patch_names.len())
        .filter(|&p| !layered_patch[p] && planes[p].is_none() && counts[p] > 0)
        .map(|p| {
            format!(
                "patch {} gets no layers and is not planar: the layers stop where they meet it",
                surface.patch_names[p]
            )
        })
        .collect()
}

/// A warning when the wall's own triangles make lateral prism faces that a solver's
/// non-orthogonal correction can hardly mend: the layers repeat them, only a better wall
/// triangulation removes them.
fn wall_non_orthogonality_warning(wall: &quality::fv::WallNonOrthogonality) -> Option<String> {
    let at = wall.worst_at.filter(|_| wall.edges_above_85 > 0)?;
    Some(format!(
        "{} wall edges (of {}) lie between triangles so thin side by side that the prisms over them \
         have lateral faces above {} deg non-orthogonal in every layer (worst {:.1} deg at {}): \
         the wall's triangulation sets them",
        wall.edges_above_85,
        wall.edges,
        quality::fv::SOLVER_LIMIT_NON_ORTHOGONALITY,
        wall.max,
        format_point(DVec3::from(at))
    ))
}

fn layer_summary(
    layered: &layers::Layers,
    surface: &Surface,
    topology: &Topology,
    features: &Features,
) -> LayerSummary {
    let mut reached: Vec<u32> = layered.vertex_layers.iter().flatten().copied().collect();
    reached.sort_unstable();
    let pick = |i: usize| reached.get(i).copied().unwrap_or(0);
    // Fraction of the layered vertices `counted` that got their full stack, and their number.
    let mut gap_limited = vec![false; layered.vertex_layers.len()];
    for &v in &layered.gap_limited_vertices {
        gap_limited[v as usize] = true;
    }
    let coverage_where = |counted: &dyn Fn(usize) -> bool| {
        let (mut full, mut all) = (0usize, 0usize);
        for (v, (l, t)) in layered.vertex_layers.iter().zip(&layered.vertex_target).enumerate() {
            if let (Some(l), Some(t)) = (l, t) {
                if counted(v) {
                    all += 1;
                    full += usize::from(l >= t || gap_limited[v]);
                }
            }
        }
        (if all == 0 { 1.0 } else { full as f64 / all as f64 }, all)
    };
    let coverage = |kinds: &[VertexKind]| coverage_where(&|v| kinds.contains(&features.vertex_kind[v])).0;
    let reach: Vec<Option<f64>> = layered.vertex_thickness.iter().map(|t| t.map(|t| 2.0 * t)).collect();
    let near = features.near_concave_ridges(surface, topology, &reach);
    let (near_concave_coverage, near_concave_vertices) = coverage_where(&|v| near[v]);
    use VertexKind::*;
    LayerSummary {
        march: layered.stats.clone(),
        layers_min: pick(0),
        layers_median: pick(reached.len() / 2),
        layers_max: reached.last().copied().unwrap_or(0),
        full_coverage: if reached.is_empty() {
            0.0
        } else {
            coverage(&[Smooth, ConvexRidge, ConcaveRidge, ConvexCorner, ConcaveCorner, SaddleCorner])
        },
        concave_coverage: coverage(&[ConcaveRidge, ConcaveCorner, SaddleCorner]),
        convex_coverage: coverage(&[ConvexRidge, ConvexCorner, SaddleCorner]),
        near_concave_coverage,
        near_concave_vertices,
        stopped_vertices: layered.stopped_vertices.len(),
        stopped_examples: layered
            .stopped_vertices
            .iter()
            .take(5)
            .map(|&v| surface.points[v as usize].to_array())
            .collect(),
        gap_limited_vertices: layered.gap_limited_vertices.len(),
        unfold: layered.unfold.clone(),
        smoothness: layered.smoothness.clone(),
        lowered_first_height_vertices: layered.lowered_first_heights.len(),
        lowest_first_height_ratio: layered.lowered_first_heights.iter().map(|l| l.1).fold(1.0, f64::min),
    }
}

impl std::fmt::Display for MeshReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let c = &self.cells;
        let l = &self.layers;
        writeln!(
            f,
            "input     {} triangles, {} vertices, {} patches",
            self.input.triangles,
            self.input.vertices,
            self.input.patches.len()
        )?;
        writeln!(
            f,
            "cells     {} prisms, {} pyramids, {} tetrahedra, {} hexahedra ({} points)",
            c.prisms, c.pyramids, c.tetrahedra, c.hexahedra, c.points
        )?;
        writeln!(
            f,
            "layers    min {} / median {} / max {}; full stack at {:.2}% of wall vertices ({:.2}% at concave, {:.2}% at convex features, {:.2}% of the {} within two thicknesses of a concave ridge); {} stopped early, {} at the medial surface of a thin gap (counted as full)",
            l.layers_min,
            l.layers_median,
            l.layers_max,
            100.0 * l.full_coverage,
            100.0 * l.concave_coverage,
            100.0 * l.convex_coverage,
            100.0 * l.near_concave_coverage,
            l.near_concave_vertices,
            l.stopped_vertices,
            l.gap_limited_vertices
        )?;
        if l.lowered_first_height_vertices > 0 {
            writeln!(
                f,
                "          first layer lowered at {} wall vertices (down to {:.3} of the height asked): fitted where stacks stopped under a first layer taller than the wall's edges over [layers] first_aspect, graded around (or from a patch with a lower one)",
                l.lowered_first_height_vertices, l.lowest_first_height_ratio
            )?;
        }
        let sm = &l.smoothness;
        write!(
            f,
            "smooth    neighbour thickness ratio median {:.3}, p95 {:.3}, max {:.3}; layer growth within r at {:.1}% of columns",
            sm.neighbour_thickness_ratio.median,
            sm.neighbour_thickness_ratio.p95,
            sm.neighbour_thickness_ratio.max,
            100.0 * sm.layer_height_ratio.within_band
        )?;
        if sm.isotropy_ratio.count > 0 {
            write!(
                f,
                "; last height / front edge at {} isotropic stops: median {:.2}, within [1/r, r] at {:.1}%",
                sm.isotropy_ratio.count,
                sm.isotropy_ratio.median,
                100.0 * sm.isotropy_ratio.within_band
            )?;
        }
        writeln!(f)?;
        let u = &l.unfold;
        writeln!(
            f,
            "front     {} caps and folds after the march, {} tops pulled back ({} more undone: they crossed the front), {} left",
            u.defects_before, u.moved_tops, u.undone_moves, u.defects_after
        )?;
        writeln!(
            f,
            "normals   {} columns ({} in fans over {} convex ridge edges, {} corner patches, {} ridges carried to their roots)",
            self.normals.columns,
            self.normals.fan_columns,
            self.normals.fan_edges,
            self.normals.corner_patches,
            self.normals.ridge_roots
        )?;
        match &self.core {
            Some(c) => {
                let q = &c.quality;
                let s = &q.slivers;
                let i = &q.improvement;
                writeln!(
                    f,
                    "core      {} tetrahedra ({} pyramids on front quads), dihedral {:.1}..{:.1} deg (TetGen's min {:.1}), {} boundary points added",
                    c.tetrahedra, c.pyramids, c.min_dihedral, c.max_dihedral, q.mesher_min_dihedral, c.boundary_steiner_points
                )?;
                let sizes = match (c.gradation, c.region_points) {
                    (Some(g), 0) => format!("sizes graded by {g} from the front's"),
                    (Some(g), n) => {
                        format!("sizes graded by {g} from the front's and the regions' ({n} points)")
                    }
                    (None, _) => "TetGen's own sizes".to_owned(),
                };
                let r = &c.size_ratio;
                writeln!(
                    f,
                    "          {sizes}: neighbouring points' sizes median {:.2}, p95 {:.2} apart ({:.1}% within the gradation)",
                    r.median,
                    r.p95,
                    100.0 * r.within_band
                )?;
                writeln!(
                    f,
                    "          {} seeds over the front in place (of {} front vertices with a last layer under them)",
                    c.seeds, c.seed_candidates
                )?;
                if c.mesher_crashes > 0 {
                    let then = if c.mesher_crashes == 1 { "over the prisms only" } else { "none" };
                    writeln!(
                        f,
                        "          TetGen crashed on the seeds {} times; meshed with seeds {then}",
                        c.mesher_crashes
                    )?;
                }
                writeln!(
                    f,
                    "          improvement: {} flips and moves to match the first core cells to the last layer, then {} flips 2-3, {} 3-2, {} 4-4, {} larger edge removals, {} points smoothed, {} removed, {} inserted ({:.2} s)",
                    i.front_matches, i.flips_23, i.flips_32, i.flips_44, i.edge_removals, i.smoothed_points, i.collapsed_edges, i.inserted_points, i.seconds
                )?;
                writeln!(
                    f,
                    "          {} tetrahedra below {:.0} deg: {} at a thin angle of the boundary, {} on a badly shaped boundary triangle, {} at a needle or cap of the boundary, {} in a thin gap, {} not forced by the boundary ({} with all nodes on the boundary)",
                    s.count, s.threshold, s.boundary_angle, s.boundary_triangle, s.poor_boundary_triangle, s.thin_gap, s.not_forced, s.all_nodes_on_boundary
                )?;
                writeln!(f, "          min dihedral per tetrahedron (deg): {}", q.histogram)?;
                let p = &self.peel;
                if p.slivers_by_round.len() > 1 {
                    let counts: Vec<String> = p.slivers_by_round.iter().map(usize::to_string).collect();
                    writeln!(
                        f,
                        "          peeling: tetrahedra below {:.0} deg by round {}; kept round {}, its stacks a layer lower at {} wall vertices",
                        s.threshold,
                        counts.join(" -> "),
                        p.kept_round,
                        p.capped_vertices
                    )?;
                }
                let j = &c.size_jump;
                let bins: Vec<String> =
                    j.histogram.iter().map(|(label, n)| format!("{label}: {n}")).collect();
                writeln!(
                    f,
                    "size jump first core tet over last layer height at {} of {} front triangles ({} sides of the layers): median {:.2}, within [1/r, r] at {:.1}% ({:.1}% of the {} on prisms); {}",
                    j.stats.count,
                    j.front_triangles,
                    j.side_faces,
                    j.stats.median,
                    100.0 * j.stats.within_band,
                    100.0 * j.on_prisms.within_band,
                    j.on_prisms.count,
                    bins.join(", ")
                )?;
            }
            None => {
                writeln!(f, "core      not built (--no-core): the layers' top faces are the patch bl_top")?
            }
        }
        writeln!(f, "quality   worst scaled Jacobian {:.3}", worst_scaled_jacobian(&self.check))?;
        let v = &self.check.fv;
        writeln!(
            f,
            "fv        non-orthogonality max {:.1} mean {:.1} deg ({} faces above 70, {} above 85), skewness max {:.2}, {} wrong face pyramids",
            v.non_orthogonality_max, v.non_orthogonality_mean, v.faces_above_70, v.faces_above_85, v.skewness_max, v.wrong_face_pyramids
        )?;
        for w in &self.warnings {
            writeln!(f, "warning   {w}")?;
        }
        if let Some(m) = self.peak_memory_mib {
            writeln!(f, "memory    {m:.0} MiB peak")?;
        }
        write!(f, "time\n{}", self.timings)
    }
}

/// The smallest scaled Jacobian over all cells.
fn worst_scaled_jacobian(check: &CheckReport) -> f64 {
    CellKind::ALL
        .iter()
        .map(|&k| check.quality.get(k))
        .filter(|q| q.cells > 0)
        .map(|q| q.scaled_jacobian.min)
        .fold(f64::INFINITY, f64::min)
}
