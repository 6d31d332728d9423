//! Gmsh MSH 4.1 / 2.2 reader and MSH 4.1 writer (to be written).

use super::ParseError;
use crate::mesh::VolumeMesh;
use crate::surface::Surface;

pub fn parse_surface(_bytes: &[u8]) -> Result<Surface, ParseError> {
    Err(ParseError::file("msh reader not written yet"))
}

pub fn parse_volume(_bytes: &[u8]) -> Result<VolumeMesh, ParseError> {
    Err(ParseError::file("msh reader not written yet"))
}

pub fn write(_w: &mut dyn std::io::Write, _mesh: &VolumeMesh, _ascii: bool) -> std::io::Result<()> {
    Err(std::io::Error::other("msh writer not written yet"))
}
