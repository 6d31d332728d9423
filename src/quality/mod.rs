//! Volume-mesh checker: the oracle every test uses ([`check`]).
//!
//! It checks the invariants of `docs/design.md`: every cell positive by exact orientation tests of two
//! decompositions ([`validity`]), faces conforming and the boundary closed ([`conformity`]), the
//! cell volumes adding up to the volume enclosed by the boundary, and it measures the quality of
//! the cells with the definitions of `shared/bench/measure.py` ([`measures`]).

mod conformity;
pub mod fv;
mod fv_report;
pub mod measures;
pub mod overlap;
mod report;
pub mod samples;
pub mod validity;

pub use fv_report::{FvReport, LocatedFace, PairNonOrthogonality};
pub use report::*;

use crate::mesh::faces::{FaceTable, FaceUses};
use crate::mesh::{CellKind, VolumeMesh};

/// Check a volume mesh: counts, validity, conformity, volume identity and quality.
pub fn check(mesh: &VolumeMesh) -> CheckReport {
    let mut report = CheckReport { points: mesh.points.len(), ..Default::default() };
    check_structure(mesh, &mut report);
    if !conformity::owner_ids_fit(mesh) {
        report.structure_errors.push("too many cells and boundary faces for 32-bit face owners".into());
        return report;
    }
    let (blocks, faces) = rayon::join(
        || CellKind::ALL.map(|kind| validity::check_block(mesh, kind)),
        || {
            let uses = FaceUses::new(mesh);
            let table = FaceTable::from_uses(mesh, &uses);
            rayon::join(|| conformity::check_faces(mesh, &uses), || fv::measure(mesh, &table))
        },
    );
    let ((conformity, enclosed), fv) = faces;
    let mut volume = 0.0;
    for (kind, block) in CellKind::ALL.into_iter().zip(blocks) {
        report.validity.append(block.validity);
        volume += block.volume;
        *report.quality.get_mut(kind) = block.quality;
    }
    if conformity.free_faces_taken_as_boundary {
        report.warnings.push(format!(
            "the mesh lists no boundary faces: its {} free faces are taken as its boundary",
            conformity.free_triangles + conformity.free_quads
        ));
    }
    report.conformity = conformity;
    report.fv = fv;
    report.volume =
        VolumeCheck { cells: volume, enclosed, relative_difference: relative_difference(volume, enclosed) };
    report.overlap = overlap::boundary_overlap(mesh);
    report.unused_points = count_unused_points(mesh);
    if report.unused_points > 0 {
        report.warnings.push(format!("{} points are used by no cell", report.unused_points));
    }
    report
}

fn relative_difference(a: f64, b: f64) -> f64 {
    let scale = a.abs().max(b.abs());
    if scale == 0.0 {
        0.0
    } else {
        (a - b).abs() / scale
    }
}

/// Cell counts, patch counts, and indices that do not fit their tables.
fn check_structure(mesh: &VolumeMesh, report: &mut CheckReport) {
    for kind in CellKind::ALL {
        let block = mesh.block(kind);
        let n = kind.node_count();
        *report.cells.get_mut(kind) = block.nodes.len() / n;
        if block.nodes.len() != block.zone.len() * n {
            report.structure_errors.push(format!(
                "{} block: {} node indices for {} zone entries ({} nodes per cell)",
                kind.name(),
                block.nodes.len(),
                block.zone.len(),
                n
            ));
        }
        let bad_zones = block.zone.iter().filter(|&&z| z as usize >= mesh.zone_names.len()).count();
        if bad_zones > 0 {
            report.structure_errors.push(format!(
                "{bad_zones} {} cells have a zone index >= {} (the number of zone names)",
                kind.name(),
                mesh.zone_names.len()
            ));
        }
    }
    let b = &mesh.boundary;
    report.patches =
        mesh.patch_names.iter().map(|name| PatchCount { name: name.clone(), ..Default::default() }).collect();
    let count = |what: &str, faces: usize, patches: &[u32], quads: bool, report: &mut CheckReport| {
        if faces != patches.len() {
            report
                .structure_errors
                .push(format!("{faces} boundary {what} but {} patch indices", patches.len()));
        }
        let mut bad = 0;
        for &p in patches {
            match report.patches.get_mut(p as usize) {
                Some(c) if quads => c.quads += 1,
                Some(c) => c.triangles += 1,
                None => bad += 1,
            }
        }
        if bad > 0 {
            report.structure_errors.push(format!(
                "{bad} boundary {what} have a patch index >= {} (the number of patch names)",
                mesh.patch_names.len()
            ));
        }
    };
    count("triangles", b.triangles.len(), &b.triangle_patch, false, report);
    count("quads", b.quads.len(), &b.quad_patch, true, report);
    let points = mesh.points.len();
    let out_of_range = b.nodes().filter(|&n| n as usize >= points).count();
    if out_of_range > 0 {
        report
            .structure_errors
            .push(format!("{out_of_range} boundary face node indices >= {points} (the point count)"));
    }
}

fn count_unused_points(mesh: &VolumeMesh) -> usize {
    let mut used = vec![false; mesh.points.len()];
    for block in &mesh.blocks {
        for &n in &block.nodes {
            if let Some(u) = used.get_mut(n as usize) {
                *u = true;
            }
        }
    }
    used.iter().filter(|u| !**u).count()
}

#[cfg(test)]
mod tests;
