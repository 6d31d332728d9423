//! The native core mesher ([`NativeCore`]): the Delaunay tetrahedralisation of the
//! boundary's points ([`crate::fill::delaunay`]), boundary recovery, exterior removal, the
//! guide's points inserted, and Delaunay refinement to the guide's sizes.
//!
//! Steps, every decision by an exact predicate:
//! 1. The Delaunay tetrahedralisation of the boundary points and of the 8 corners of a box
//!    around them, a box-diagonal away: the boundary lies strictly inside the hull, so every
//!    edge and face it needs is inside, where flips have tetrahedra on both sides (a farfield
//!    box's coplanar faces are flipped like any other).
//! 2. Edge recovery (`flip`, then `cavity`): each boundary edge that is not an edge is
//!    crossed by fewer and fewer faces and edges by flips (or two in a row where one does not
//!    help), else it is made by a cone from one of its ends over the cavity around it, else
//!    the cavity of its two boundary triangles (when their other edges are there) is filled
//!    again like a missing triangle's (step 3), else a Steiner point goes in near it, off it
//!    into the region (Bowyer–Watson with the present boundary triangles as walls), and flips
//!    and cones are tried again (a point that does not help is taken out again).
//! 3. Triangle recovery: each boundary triangle that is not a face (its edges are) loses the
//!    edges through it by flips, else the tetrahedra crossing it are replaced by a cone on
//!    each side, from a vertex or from a Steiner point strictly inside that side (never on
//!    the boundary: tested exactly against every boundary triangle).
//! 4. Exterior removal (`exterior`): the tetrahedra on the region's side of the boundary
//!    triangles (their right-hand normals point into the region, as [`ClosedBoundary`] says),
//!    flooded across the other faces; the box's corners go with the outside.
//! 5. The guide's interior points inside the region, inserted by Bowyer–Watson with the
//!    boundary as walls (`insert`); points outside, on the boundary or at a vertex are left
//!    out.
//! 6. Delaunay refinement ([`refine`]): tetrahedra too large for the sizes (the guide's at its
//!    points, interpolated at the points added) or poorly shaped get a point inside, never on
//!    or near the boundary.
//!
//! Present boundary edges and triangles are never taken away by a later step (the flips and
//! cavities check it), so recovery goes forward; what it cannot recover is an error naming it
//! (known: building_wtc2's boundary triangles of 0.14 degrees, where a cavity side of the two
//! sliver triangles on a missing edge has no cone).
//!
//! Cost: the boundary of spot's core (front, seeds' boundary, box farfield; 1351 of its edges
//! missing from the Delaunay tetrahedralisation, mostly the farfield's and the front's
//! diagonals) recovers in 0.3-0.5 s; with the guide's points and the refinement, the two
//! native fills of a graded core take 2.5-3.5 times TetGen's two.

mod cavity;
mod cross;
mod exterior;
mod flip;
mod insert;
mod recovery;
pub mod refine;
#[cfg(test)]
mod tests;

use std::time::Instant;

use serde::Serialize;

use self::cross::Target;
use self::recovery::Recovery;
use super::delaunay::Delaunay;
use super::improve::TetMesh;
use super::{ClosedBoundary, CoreGuide, CoreMesher, CoreTets, FillError};
use crate::geometry::DVec3;
use crate::mesh::sorted_edge;

/// Steiner points at most inserted near a missing edge.
const STEINER_TRIES: usize = 7;

/// Passes over the missing edges and triangles (a later pass sees the changes of the first).
const PASSES: usize = 2;

/// The native core mesher (see the module documentation).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NativeCore {
    pub refine: refine::RefineOptions,
}

impl CoreMesher for NativeCore {
    fn fill(&self, boundary: &ClosedBoundary, guide: &CoreGuide) -> Result<CoreTets, FillError> {
        self.fill_refined(boundary, guide).map(|(core, _)| core)
    }
}

impl NativeCore {
    /// [`CoreMesher::fill`], and what the refinement did.
    pub fn fill_refined(
        &self,
        boundary: &ClosedBoundary,
        guide: &CoreGuide,
    ) -> Result<(CoreTets, refine::RefineStats), FillError> {
        let n = boundary.points.len();
        if !guide.size.is_empty() && guide.size.len() != n + guide.interior.len() {
            let points = n + guide.interior.len();
            return Err(FillError::Input(format!("{} sizes for {points} points", guide.size.len())));
        }
        let (mut mesh, stats) = recover_region(boundary)?;
        let corners = boundary.triangles.iter().map(|t| t.map(|v| boundary.points[v as usize])).collect();
        let bvh = crate::geometry::bvh::TriangleBvh::new(corners);
        let inserted = insert_guide(&mut mesh, &boundary.triangles, &bvh, &guide.interior);
        let skipped: Vec<insert::Skipped> = inserted.iter().filter_map(|r| r.err()).collect();
        tracing::info!(?stats, ?skipped, of = guide.interior.len(), "native core: boundary recovered");
        let mut size = point_sizes(&mesh, guide, n, &inserted);
        let refined = refine::Refinement::new(&mut mesh, &mut size, &bvh, &self.refine).run();
        tracing::info!(?refined, points = mesh.points.len(), "native core: refined");
        let (points, tets) = mesh.into_parts();
        let mut core = CoreTets { points, tets, boundary_steiner_points: 0 };
        super::merge::drop_unused_points(&mut core, n);
        Ok((core, refined))
    }
}

/// What boundary recovery did.
#[derive(Clone, Debug, Default, Serialize, PartialEq, Eq)]
pub struct RecoveryStats {
    /// Boundary edges and triangles missing from the Delaunay tetrahedralisation.
    pub missing_edges: usize,
    pub missing_triangles: usize,
    /// Flips made, and edges and triangles recovered by filling a cavity again.
    pub flips: usize,
    pub edges_by_cavity: usize,
    pub triangles_by_cavity: usize,
    /// Edges recovered after Steiner points were inserted near them.
    pub edges_by_steiner: usize,
    /// Steiner points added (strictly off the boundary), and those inside the region.
    pub steiner_points: usize,
    pub steiner_points_inside: usize,
}

/// The tetrahedralisation of the region bounded by `boundary` keeping every triangle, its
/// boundary points first (then its Steiner points, and points no tetrahedron uses). With the
/// environment variable `BLMESH_DUMP_RECOVERY=FILE`, a boundary it cannot recover is written
/// to FILE as JSON (points, triangles) for the ignored test `dumped_boundary`.
pub fn recover_region(boundary: &ClosedBoundary) -> Result<(TetMesh, RecoveryStats), FillError> {
    let start = Instant::now();
    boundary.check_no_self_intersection()?;
    let checked = start.elapsed().as_secs_f64();
    let n = boundary.points.len();
    let mut points = boundary.points.clone();
    points.extend(box_corners(&boundary.points));
    let delaunay = Delaunay::new(&points).map_err(|e| FillError::Input(e.to_string()))?;
    if let Some(d) = delaunay.duplicates().first() {
        return Err(FillError::Input(format!("boundary points {} and {} coincide", d.point, d.of)));
    }
    let triangulated = start.elapsed().as_secs_f64();
    let mut recovery = Recovery::new(delaunay.to_tet_mesh(n), &boundary.triangles);
    let linked = start.elapsed().as_secs_f64();
    let mut stats = RecoveryStats::default();
    let failed = recover(&mut recovery, boundary, &mut stats);
    let recovered = start.elapsed().as_secs_f64();
    if !failed.is_empty() {
        if let Ok(path) = std::env::var("BLMESH_DUMP_RECOVERY") {
            let json = serde_json::json!({"points": boundary.points, "triangles": boundary.triangles});
            let _ = std::fs::write(path, json.to_string());
        }
        let examples: Vec<String> =
            failed.iter().take(5).map(|t| describe(t, &recovery.mesh.points)).collect();
        return Err(FillError::Recovery(format!(
            "{} boundary edges or triangles not recovered, e.g. {}",
            failed.len(),
            examples.join("; ")
        )));
    }
    let inside = exterior::region_tets(&recovery.mesh, &boundary.triangles)?;
    let mesh = recovery.mesh;
    let tets: Vec<[u32; 4]> = (0..mesh.slots() as u32)
        .filter(|&t| mesh.is_alive(t) && inside[t as usize])
        .map(|t| mesh.tet(t))
        .collect();
    if tets.is_empty() {
        return Err(FillError::Input(
            "the boundary encloses no region (no shell bounds it from outside)".into(),
        ));
    }
    let steiner = n + 8;
    let mut used = vec![false; mesh.points.len()];
    for &v in tets.iter().flatten() {
        used[v as usize] = true;
    }
    stats.steiner_points = mesh.points.len() - steiner;
    stats.steiner_points_inside = used[steiner..].iter().filter(|&&u| u).count();
    tracing::debug!(
        ?stats,
        checked,
        triangulated,
        linked,
        recovered,
        seconds = start.elapsed().as_secs_f64(),
        "boundary recovery (seconds from its start)"
    );
    Ok((TetMesh::new(mesh.points, tets, n), stats))
}

/// Recover every boundary edge, then every triangle; returns those left missing.
fn recover(recovery: &mut Recovery, boundary: &ClosedBoundary, stats: &mut RecoveryStats) -> Vec<Target> {
    let mut edges: Vec<[u32; 2]> = recovery.edges.iter().copied().collect();
    edges.sort_unstable();
    let mut failed = Vec::new();
    for pass in 0..PASSES {
        failed.clear();
        for &edge in &edges {
            let target = Target::Edge(edge);
            if recovery.present(target) {
                continue;
            }
            if pass == 0 {
                stats.missing_edges += 1;
            }
            if recovery.flip_to(target, &mut stats.flips) {
                continue;
            }
            if recovery.refill_edge(edge) {
                stats.edges_by_cavity += 1;
                continue;
            }
            let [a, b] = edge;
            let patch: Vec<[u32; 3]> =
                boundary.triangles.iter().filter(|t| t.contains(&a) && t.contains(&b)).copied().collect();
            if let Some(added) = recovery.refill_patch(&patch, &boundary.triangles) {
                stats.edges_by_cavity += 1;
                stats.steiner_points += added;
                continue;
            }
            let mut recovered = false;
            for attempt in 0..STEINER_TRIES {
                // A Steiner point that does not help is taken out again (with the flips after it).
                let saved = recovery.mesh.clone();
                if !recovery.steiner_near_edge(edge, &boundary.triangles, attempt) {
                    continue;
                }
                recovered = recovery.flip_to(target, &mut stats.flips) || recovery.refill_edge(edge);
                if recovered {
                    stats.steiner_points += 1;
                    stats.edges_by_steiner += 1;
                    break;
                }
                recovery.mesh = saved;
            }
            if !recovered {
                tracing::debug!(
                    edge = describe(&target, &recovery.mesh.points),
                    crossings = recovery.crossing_tets(target).len(),
                    "edge not recovered"
                );
                failed.push(target);
            }
        }
        for &triangle in &boundary.triangles {
            let target = Target::Triangle(triangle);
            let edges_present = (0..3)
                .all(|i| recovery.present(Target::Edge(sorted_edge(triangle[i], triangle[(i + 1) % 3]))));
            if recovery.present(target) {
                continue;
            }
            if pass == 0 {
                stats.missing_triangles += 1;
            }
            if !edges_present {
                failed.push(target);
                continue;
            }
            if recovery.flip_to(target, &mut stats.flips) {
                continue;
            }
            match recovery.refill_patch(&[triangle], &boundary.triangles) {
                Some(added) => {
                    stats.triangles_by_cavity += 1;
                    stats.steiner_points += added;
                }
                None => failed.push(target),
            }
        }
        if failed.is_empty() {
            break;
        }
    }
    failed
}

/// A missing edge or triangle, for an error message.
fn describe(target: &Target, points: &[DVec3]) -> String {
    let (what, vertices) = match target {
        Target::Edge(e) => ("edge", &e[..]),
        Target::Triangle(t) => ("triangle", &t[..]),
    };
    let centre = vertices.iter().map(|&v| points[v as usize]).sum::<DVec3>() / vertices.len() as f64;
    format!("{what} {vertices:?} at {:?}", centre.to_array())
}

/// The corners of the box around `points` grown by its largest side on every side.
fn box_corners(points: &[DVec3]) -> [DVec3; 8] {
    let (lo, hi) =
        points.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let margin = (hi - lo).max_element().max(1.0);
    let (lo, hi) = (lo - margin, hi + margin);
    std::array::from_fn(|i| {
        DVec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

/// Insert the points `interior` inside the region bounded by `triangles` (`bvh` holds their
/// corners), in order; returns each one's index, or why it was left out. Each is located from
/// the last tetrahedron made, else from the one on the boundary triangle nearest to it.
fn insert_guide(
    mesh: &mut TetMesh,
    triangles: &[[u32; 3]],
    bvh: &crate::geometry::bvh::TriangleBvh,
    interior: &[DVec3],
) -> Vec<Result<u32, insert::Skipped>> {
    let mut inserted = Vec::with_capacity(interior.len());
    for &p in interior {
        let last = mesh.slots().saturating_sub(1) as u32;
        let near =
            bvh.nearest(p).and_then(|n| mesh.tets_with(&triangles[n.triangle as usize]).first().copied());
        let hints: Vec<u32> = std::iter::once(last).chain(near).collect();
        inserted.push(insert::insert_point(mesh, &hints, p));
    }
    inserted
}

/// The size at every point of `mesh`: the guide's at the `n` boundary points and at the
/// interior points that went in (`inserted`), the mean of their neighbours' at the Steiner
/// points of recovery; none (NaN) when the guide gives no sizes.
fn point_sizes(
    mesh: &TetMesh,
    guide: &CoreGuide,
    n: usize,
    inserted: &[Result<u32, insert::Skipped>],
) -> Vec<f64> {
    let mut size = vec![f64::NAN; mesh.points.len()];
    if guide.size.is_empty() {
        return size;
    }
    size[..n].copy_from_slice(&guide.size[..n]);
    for (k, index) in inserted.iter().enumerate() {
        if let Ok(v) = index {
            size[*v as usize] = guide.size[n + k];
        }
    }
    refine::complete_sizes(mesh, &mut size);
    size
}
