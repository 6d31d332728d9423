//! Tests of the MSH reader and writer.

use super::*;
use crate::quality::{check, samples::hybrid_column};

fn write_to_vec(mesh: &VolumeMesh, ascii: bool) -> Vec<u8> {
    let mut bytes = Vec::new();
    write(&mut bytes, mesh, ascii).unwrap();
    bytes
}

#[test]
fn round_trip_ascii_and_binary() {
    let mesh = hybrid_column();
    for ascii in [true, false] {
        let bytes = write_to_vec(&mesh, ascii);
        let back = parse_volume(&bytes).unwrap();
        assert_eq!(back.points, mesh.points);
        for kind in crate::mesh::CellKind::ALL {
            assert_eq!(back.block(kind).nodes, mesh.block(kind).nodes, "{kind:?}");
            assert_eq!(back.block(kind).zone, mesh.block(kind).zone, "{kind:?}");
        }
        assert_eq!(back.patch_names, mesh.patch_names);
        assert_eq!(back.zone_names, mesh.zone_names);
        let r = check(&back);
        assert!(r.is_valid(), "{r}");
        assert_eq!(r.patches, check(&mesh).patches);
    }
}
