//! Layer marching: columns, the front, and the slab of cells between two fronts.
//!
//! [`build_layers`] turns the wall and its extrusion directions into the layered part of the
//! mesh: the wall points, the layer cells (zone [`march::LAYER_ZONE`]), the wall faces under
//! them and the final front as the boundary patch [`TOP_PATCH`].

pub mod bend;
pub mod coarsen;
pub mod collapse;
pub mod entropy;
pub mod front;
pub mod gap;
pub mod guard;
pub mod march;
pub mod reshape;
pub mod slab;
pub mod slab_plan;
pub mod sliding;
pub mod smoothness;
pub mod split;
pub mod swap;
pub mod tuning;
pub mod unfold;

use std::collections::HashMap;

use rayon::prelude::*;

use crate::config::LayerSpec;
use crate::mesh::VolumeMesh;
use crate::normals::constraint::Slide;
use crate::normals::WallNormals;
use crate::sizing::wall::mean_edge_length_per_vertex;
use crate::surface::features::Features;
use crate::surface::topology::Topology;
use crate::surface::Surface;
use tuning::TUNING;

pub use march::MarchStats;
pub use split::Adapt;

/// Name of the boundary patch made of the top faces of the layers.
pub const TOP_PATCH: &str = "bl_top";
/// Name of the volume zone of the layer cells.
pub const LAYER_ZONE_NAME: &str = "boundary_layer";

/// The layered mesh and what happened while marching.
#[derive(Clone, Debug)]
pub struct Layers {
    pub mesh: VolumeMesh,
    pub stats: MarchStats,
    /// Layers reached by every wall vertex (the fewest over its columns); `None` for vertices
    /// that get no layers.
    pub vertex_layers: Vec<Option<u32>>,
    /// Target layer count of every wall vertex.
    pub vertex_target: Vec<Option<u32>>,
    /// Target thickness of every wall vertex: its full stack's distance from the wall (the
    /// largest over its columns; for a stack ended at isotropy, where it ended).
    pub vertex_thickness: Vec<Option<f64>>,
    /// Where columns stopped early: wall vertex ids (all of them; the report shows a few), not
    /// counting those stopped at the medial surface of a thin gap.
    pub stopped_vertices: Vec<u32>,
    /// Wall vertices whose columns stopped early at the medial surface of a thin gap
    /// ([`gap::gap_limited`]): their stacks are as thick as the gap allows.
    pub gap_limited_vertices: Vec<u32>,
    pub smoothness: smoothness::Smoothness,
    /// The caps and folds of the final front, and the tops pulled back to undo them.
    pub unfold: unfold::UnfoldStats,
    /// Wall vertices whose first height is below the one asked for, with the ratio (the
    /// smallest over their columns): fitted to a finely faceted wall
    /// ([`LayerSettings::first_aspect`](crate::config::LayerSettings::first_aspect)), or graded
    /// from such a place or from a patch with a smaller one.
    pub lowered_first_heights: Vec<(u32, f64)>,
    /// The stack under every node of the final front: its wall vertex and layers (the fewest
    /// of the columns carried there).
    pub top_stacks: HashMap<u32, (u32, u32)>,
}

/// Extrude the wall. `patch_spec[p]` is the layer stack of patch `p`, `None` for patches
/// without layers (their vertices do not move). `adapt` says whether and to which sizes the
/// front's edges are split while it marches.
pub fn build_layers(
    surface: &Surface,
    topology: &Topology,
    features: &Features,
    normals: &WallNormals,
    patch_spec: &[Option<LayerSpec>],
    adapt: Adapt,
    caps: &[u32],
    at_slivers: &[bool],
    mut on_layer: impl FnMut(u32, u32),
) -> Layers {
    let layered = |p: u32| patch_spec.get(p as usize).copied().flatten().is_some();
    let start = MarchStart { surface, topology, features, normals, patch_spec, adapt, caps };
    let mut fitted = vec![false; surface.points.len()];
    let mut marched = start.march(&fitted, &mut on_layer);
    // Stacks stopped short where the first layer is too tall for the wall's facets: march
    // again with the first height fitted there (and graded around).
    for _ in 0..TUNING.first_layer.refits {
        let refit: Vec<u32> = stopped_too_tall_for_the_wall(surface, &marched)
            .into_iter()
            .filter(|&v| !fitted[v as usize])
            .collect();
        if refit.is_empty() {
            break;
        }
        tracing::info!(
            vertices = refit.len(),
            "first layer too tall for the wall: marching again with it fitted"
        );
        for v in refit {
            fitted[v as usize] = true;
        }
        marched = start.march(&fitted, &mut on_layer);
    }
    let Marched { mut mesh, mut columns, front, sizes, stats, lowered_first_heights } = marched;
    let unfold = unfold::unfold_front(&mut mesh, &mut columns, &front, surface, layered, at_slivers);
    let front_edges = sizes.front_edge_lengths(&mesh.points, &columns, &front);
    add_boundary(&mut mesh, surface, &front, &columns);
    let growth = patch_spec.iter().flatten().map(|s| s.growth).fold(1.0, f64::max);
    let reached: Vec<Option<f64>> = (0..columns.len())
        .map(|c| {
            let carrier = columns.carrier(c);
            let layers = columns.layers[carrier];
            (layers > 0).then(|| columns.distance(carrier, layers)).flatten()
        })
        .collect();
    let smoothness = smoothness::measure(surface, &columns, &reached, growth, front_edges);
    let mut vertex_layers: Vec<Option<u32>> = vec![None; surface.points.len()];
    let mut vertex_target: Vec<Option<u32>> = vec![None; surface.points.len()];
    let mut vertex_thickness: Vec<Option<f64>> = vec![None; surface.points.len()];
    let mut stopped_vertices = Vec::new();
    for c in 0..columns.len() {
        let v = columns.wall_vertex[c] as usize;
        if let Some(t) = columns.full_count(c) {
            // A column that merged is carried on by the bisector column it merged into.
            let carrier = columns.carrier(c);
            let reached = columns.layers[carrier];
            // A stack ended at isotropy is complete (even before its full count).
            let t = if columns.ended_isotropic(carrier) { reached.min(t) } else { t };
            vertex_layers[v] = Some(vertex_layers[v].map_or(reached, |l| l.min(reached)));
            vertex_target[v] = Some(vertex_target[v].map_or(t, |x| x.max(t)));
            if let Some(d) = columns.distance(c, t) {
                vertex_thickness[v] = Some(vertex_thickness[v].map_or(d, |x: f64| x.max(d)));
            }
            if reached < t {
                tracing::debug!(v, at = ?surface.points[v], reached, full = t, "stack short of its full count");
                stopped_vertices.push(v as u32);
            }
        }
    }
    stopped_vertices.sort_unstable();
    stopped_vertices.dedup();
    let mut top_stacks: HashMap<u32, (u32, u32)> = HashMap::new();
    for c in 0..columns.len() {
        let carrier = columns.carrier(c);
        if columns.spec[carrier].is_none() || columns.layers[carrier] == 0 {
            continue;
        }
        let stack = (columns.wall_vertex[carrier], columns.layers[carrier]);
        top_stacks
            .entry(columns.node[carrier])
            .and_modify(|s| {
                if stack.1 < s.1 {
                    *s = stack;
                }
            })
            .or_insert(stack);
    }
    let limited = gap::gap_limited(surface, topology, &columns, &mesh.points, &stopped_vertices);
    let (gap_limited_vertices, stopped_vertices) =
        stopped_vertices.into_iter().partition(|&v| limited[v as usize]);
    Layers {
        mesh,
        stats,
        vertex_layers,
        vertex_target,
        vertex_thickness,
        stopped_vertices,
        gap_limited_vertices,
        smoothness,
        unfold,
        lowered_first_heights,
        top_stacks,
    }
}

/// What a march starts from: the wall, its normals and the patches' stacks.
struct MarchStart<'a> {
    surface: &'a Surface,
    topology: &'a Topology,
    features: &'a Features,
    normals: &'a WallNormals,
    patch_spec: &'a [Option<LayerSpec>],
    adapt: Adapt<'a>,
    /// Most layers of every wall vertex's stack (`u32::MAX`: its full count).
    caps: &'a [u32],
}

/// A march's result, before the front is unfolded and the layers are counted.
struct Marched<'a> {
    mesh: VolumeMesh,
    columns: front::Columns,
    front: front::Front,
    sizes: split::Sizes<'a>,
    stats: MarchStats,
    lowered_first_heights: Vec<(u32, f64)>,
}

impl<'a> MarchStart<'a> {
    /// March from the wall, the first heights fitted to the wall at the wall vertices marked
    /// `fitted` ([`fit_first_heights_to_wall`]) and graded across the wall.
    fn march(&self, fitted: &[bool], on_layer: &mut impl FnMut(u32, u32)) -> Marched<'a> {
        let (surface, patch_spec) = (self.surface, self.patch_spec);
        let (mut columns, mut front) = front::initial_front(surface, self.normals);
        // The faces without layers never move: leave them out of the front.
        let layered = |p: u32| patch_spec.get(p as usize).copied().flatten().is_some();
        front.retain_patches(layered, columns.len());
        front.set_wall_ridges(self.topology, self.features);
        let mut column_spec = column_specs(self.normals, &front, patch_spec);
        let requested = column_spec.clone();
        fit_first_heights_to_wall(surface, &columns, fitted, &mut column_spec);
        grade_first_heights(surface, &columns, &mut column_spec);
        let lowered_first_heights = lowered_first_heights(&columns, &requested, &column_spec);
        columns.spec = column_spec;
        for c in 0..columns.len() {
            if columns.spec[c].is_none() || columns.slide[c] == Slide::Fixed {
                columns.stop(c);
            }
        }
        let max_layers = (0..columns.len()).filter_map(|c| columns.target(c)).max().unwrap_or(0);
        let mut mesh = VolumeMesh {
            points: surface.points.clone(),
            zone_names: vec![LAYER_ZONE_NAME.to_owned()],
            ..Default::default()
        };
        let mut sizes =
            split::Sizes::new(self.adapt, front.mean_edge_length_at_columns(&mesh.points, &columns));
        let walls = entropy::VertexWalls::new(surface, self.topology, layered)
            .with_cylinders(&self.normals.cylinder_normals);
        let stats = march::march(
            &mut mesh,
            &mut columns,
            &mut front,
            max_layers,
            &mut sizes,
            &walls,
            self.caps,
            |k| on_layer(k, max_layers),
        );
        Marched { mesh, columns, front, sizes, stats, lowered_first_heights }
    }
}

/// The wall vertices whose stack stopped short of its full count (not at isotropy) with a
/// first layer taller than the mean length of the wall's edges there over the stack's
/// `first_aspect`.
fn stopped_too_tall_for_the_wall(surface: &Surface, marched: &Marched) -> Vec<u32> {
    let columns = &marched.columns;
    let size = mean_edge_length_per_vertex(&surface.points, &surface.triangles);
    let mut vertices: Vec<u32> = (0..columns.len())
        .filter(|&c| {
            let Some(spec) = columns.spec[c] else { return false };
            // A stack ended at isotropy is complete.
            let carrier = columns.carrier(c);
            let short = columns.layers[carrier] < spec.full_count() && !columns.ended_isotropic(carrier);
            short && spec.first_aspect * spec.first_height > size[columns.wall_vertex[c] as usize]
        })
        .map(|c| columns.wall_vertex[c])
        .collect();
    vertices.sort_unstable();
    vertices.dedup();
    vertices
}

/// The layer stack of each column: that of the first front face using it, `None` if any face
/// using it has no layers or if none does.
fn column_specs(
    normals: &WallNormals,
    front: &front::Front,
    patch_spec: &[Option<LayerSpec>],
) -> Vec<Option<LayerSpec>> {
    let mut spec: Vec<Option<Option<LayerSpec>>> = vec![None; normals.columns.len()];
    for f in 0..front.len() {
        let s = patch_spec.get(front.patch[f] as usize).copied().flatten();
        for &c in front.face_columns(f) {
            let slot = &mut spec[c as usize];
            *slot = match (*slot, s) {
                (None, s) => Some(s),
                (Some(None), _) | (Some(Some(_)), None) => Some(None),
                (Some(Some(a)), Some(_)) => Some(Some(a)),
            };
        }
    }
    spec.into_iter().map(Option::flatten).collect()
}

/// Lower the first height of every column whose wall is faceted finer than its spec's
/// `first_aspect` first heights (the mean length of the wall edges at its vertex) to that
/// size over `first_aspect`, at the wall vertices marked `fitted`; [`grade_first_heights`] then grades the lowered heights back over
/// the wall. On the ONERA M6 wing tip (edges 0.2-0.4 under a first layer of 1.675, H = 1e-3 D)
/// the stacks stopped in their first layer: 49 wall vertices without a layer.
fn fit_first_heights_to_wall(
    surface: &Surface,
    columns: &front::Columns,
    fitted: &[bool],
    column_spec: &mut [Option<LayerSpec>],
) {
    let size = mean_edge_length_per_vertex(&surface.points, &surface.triangles);
    for (c, spec) in column_spec.iter_mut().enumerate() {
        let v = columns.wall_vertex[c] as usize;
        if !fitted[v] {
            continue;
        }
        let size = size[v];
        if let Some(s) = spec.as_mut().filter(|s| s.first_aspect > 0.0) {
            s.first_height = s.first_height.min(size / s.first_aspect);
        }
    }
}

/// The wall vertices whose columns' first height in `spec` is below the `requested` one, with
/// the smallest ratio over their columns, by vertex.
fn lowered_first_heights(
    columns: &front::Columns,
    requested: &[Option<LayerSpec>],
    spec: &[Option<LayerSpec>],
) -> Vec<(u32, f64)> {
    let mut lowered: Vec<(u32, f64)> = (0..columns.len())
        .filter_map(|c| {
            let (r, s) = (requested[c]?, spec[c]?);
            (s.first_height < r.first_height)
                .then(|| (columns.wall_vertex[c], s.first_height / r.first_height))
        })
        .collect();
    lowered.sort_unstable_by(|x, y| x.0.cmp(&y.0).then(x.1.total_cmp(&y.1)));
    lowered.dedup_by_key(|x| x.0);
    lowered
}

/// Where patches with different first heights meet, lower the larger ones near the border so
/// that neighbouring wall vertices' first heights (and with equal counts and growth, their
/// stack thicknesses) differ by at most the growth ratio: no step in the layers at a patch
/// border. A graded minimum over the wall's edges, by Dijkstra's order; heights only go down
/// (a finer first cell is always allowed).
fn grade_first_heights(surface: &Surface, columns: &front::Columns, column_spec: &mut [Option<LayerSpec>]) {
    let n = surface.points.len();
    let mut height = vec![f64::INFINITY; n];
    let mut growth = vec![f64::INFINITY; n];
    for (c, spec) in column_spec.iter().enumerate() {
        if let Some(s) = spec {
            let v = columns.wall_vertex[c] as usize;
            height[v] = height[v].min(s.first_height);
            growth[v] = growth[v].min(s.growth);
        }
    }
    let distinct = column_spec
        .iter()
        .flatten()
        .map(|s| s.first_height.to_bits())
        .collect::<std::collections::BTreeSet<_>>();
    if distinct.len() < 2 {
        return;
    }
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); n];
    for t in &surface.triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            neighbours[a as usize].push(b);
        }
    }
    // A little under r: the thickness of curved fronts varies a little more than h0.
    crate::sizing::graded_minimum(
        &mut height,
        |v, out| out.extend(neighbours[v].iter().map(|&w| w as usize)),
        |v, w, h| h * growth[w].min(growth[v]).powf(TUNING.grading.growth_share),
    );
    for (c, spec) in column_spec.iter_mut().enumerate() {
        if let Some(s) = spec {
            s.first_height = s.first_height.min(height[columns.wall_vertex[c] as usize]);
        }
    }
}

/// Boundary faces of the layered mesh: the wall triangles with a cell on them (oriented out of
/// the domain, i.e. into the body) and the raised front faces (patch [`TOP_PATCH`]).
fn add_boundary(mesh: &mut VolumeMesh, surface: &Surface, front: &front::Front, columns: &front::Columns) {
    mesh.patch_names = surface.patch_names.clone();
    let top_patch = mesh.patch_names.len() as u32;
    mesh.patch_names.push(TOP_PATCH.to_owned());
    for t in 0..surface.triangles.len() {
        if front.wall_raised.get(t).copied().unwrap_or(false) {
            let [a, b, c] = surface.triangles[t];
            mesh.boundary.triangles.push([a, c, b]);
            mesh.boundary.triangle_patch.push(surface.triangle_patch[t]);
        }
    }
    for top in front_tops(front, columns, (0..front.len()).filter(|&f| front.raised[f])) {
        match *top.nodes() {
            [a, b, c] => {
                mesh.boundary.triangles.push([a, b, c]);
                mesh.boundary.triangle_patch.push(top_patch);
            }
            [a, b, c, d] => {
                mesh.boundary.quads.push([a, b, c, d]);
                mesh.boundary.quad_patch.push(top_patch);
            }
            _ => {}
        }
    }
}

/// The tops of front faces `faces` where the columns are now, but for the pairs that are one
/// polygon with opposite orientations: the two cells under such a pair meet there (a front
/// closing on itself over a collapsed edge: the elbow with 5 layers at r = 1.15), so it is no
/// front; kept, the core would see a doubled boundary face.
fn front_tops(
    front: &front::Front,
    columns: &front::Columns,
    faces: impl Iterator<Item = usize>,
) -> Vec<slab::Polygon> {
    let tops: Vec<slab::Polygon> = faces.filter_map(|f| top_polygon(front, columns, f)).collect();
    // The tops by their sorted nodes (and count): those with the same nodes are together, in
    // increasing order.
    let mut by_nodes: Vec<((usize, [u32; 4]), usize)> = tops
        .iter()
        .enumerate()
        .map(|(i, top)| {
            let n = top.nodes();
            let mut key = [0; 4];
            key[..n.len()].copy_from_slice(n);
            key[..n.len()].sort_unstable();
            ((n.len(), key), i)
        })
        .collect();
    by_nodes.par_sort_unstable();
    let mut keep = vec![true; tops.len()];
    for group in by_nodes.chunk_by(|x, y| x.0 == y.0).filter(|g| g.len() > 1) {
        let same: Vec<usize> = group.iter().map(|&(_, i)| i).collect();
        for (n, &i) in same.iter().enumerate() {
            if let Some(&j) =
                same[n + 1..].iter().find(|&&j| keep[i] && keep[j] && tops[j].is_reverse_of(&tops[i]))
            {
                keep[i] = false;
                keep[j] = false;
            }
        }
    }
    tops.into_iter().zip(keep).filter_map(|(top, k)| k.then_some(top)).collect()
}

/// The top of front face `f` where the columns are now: its distinct nodes (a triangle or a
/// quad; `None` when merges left fewer than three).
fn top_polygon(front: &front::Front, columns: &front::Columns, f: usize) -> Option<slab::Polygon> {
    let cols = front.face_columns(f);
    let mut nodes = [0; 4];
    for (n, &c) in nodes.iter_mut().zip(cols) {
        *n = columns.node[c as usize];
    }
    slab::Polygon::dedup(&nodes[..cols.len()])
}

#[cfg(test)]
mod tests {
    use crate::surface::shapes::cuboid;

    #[test]
    fn the_first_height_is_fitted_to_the_wall_only_where_asked() {
        // A unit cube faceted at 1/4 (mean edge length at its vertices 0.25 to 0.3).
        let surface = cuboid(DVec3::ONE, 4);
        let columns = front::Columns::rising(&surface.points, Some(LayerSpec::fixed(0.5, 1.2, 5)));
        let mut spec = columns.spec.clone();
        let mut fitted = vec![false; surface.points.len()];
        fitted[0] = true;
        fit_first_heights_to_wall(&surface, &columns, &fitted, &mut spec);
        let size = mean_edge_length_per_vertex(&surface.points, &surface.triangles);
        let height = |c: usize| spec[c].unwrap().first_height;
        assert!((height(0) - size[0] / 2.0).abs() < 1e-12, "{} vs {}", height(0), size[0]);
        assert!((1..surface.points.len()).all(|c| height(c) == 0.5));
        let lowered = lowered_first_heights(&columns, &columns.spec, &spec);
        assert_eq!(lowered, vec![(0, height(0) / 0.5)]);
        // Off with a first aspect of 0.
        let mut off = columns.spec.clone();
        for s in off.iter_mut().flatten() {
            s.first_aspect = 0.0;
        }
        fit_first_heights_to_wall(&surface, &columns, &fitted, &mut off);
        assert_eq!(off[0].unwrap().first_height, 0.5);
    }

    use super::*;
    use glam::DVec3;

    /// Two front faces whose tops became one triangle with opposite orientations (the cells
    /// under them meet there) are no front: both go, a third face stays, and so does a top that
    /// is the same triangle with the same orientation (a fold, for the checks to find).
    #[test]
    fn a_top_doubled_with_opposite_orientations_is_no_front() {
        let points: Vec<DVec3> = (0..5).map(|i| DVec3::new(i as f64, (i * i) as f64, 0.0)).collect();
        let columns = front::Columns::rising(&points, None);
        let mut front = front::Front::default();
        for face in [[0, 1, 2], [2, 1, 0], [1, 3, 4], [3, 4, 1]] {
            front.push(&face, 0, None);
        }
        front.index_columns(columns.len());
        let tops: Vec<Vec<u32>> =
            front_tops(&front, &columns, 0..front.len()).iter().map(|p| p.nodes().to_vec()).collect();
        assert_eq!(tops, vec![vec![1, 3, 4], vec![3, 4, 1]]);
    }
}
