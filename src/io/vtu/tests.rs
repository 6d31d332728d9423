//! Tests of the VTU reader and writer.

use super::*;
use crate::quality::{check, samples::hybrid_column};

fn write_to_vec(mesh: &VolumeMesh) -> Vec<u8> {
    let mut bytes = Vec::new();
    write(&mut bytes, mesh).unwrap();
    bytes
}

#[test]
fn round_trip() {
    let mesh = hybrid_column();
    let back = parse(&write_to_vec(&mesh)).unwrap();
    assert_eq!(back.points, mesh.points);
    for kind in CellKind::ALL {
        assert_eq!(back.block(kind).nodes, mesh.block(kind).nodes, "{kind:?}");
        assert_eq!(back.block(kind).zone, mesh.block(kind).zone, "{kind:?}");
    }
    assert_eq!(back.boundary.triangles, mesh.boundary.triangles);
    assert_eq!(back.boundary.quad_patch, mesh.boundary.quad_patch);
    assert_eq!(back.zone_names, mesh.zone_names);
    assert_eq!(back.patch_names, ["patch_0", "patch_1", "patch_2", "patch_3", "patch_4", "patch_5"]);
    assert!(check(&back).is_valid());
}
