//! VTK XML unstructured grid (`.vtu`) reader and writer (to be written).

use super::ParseError;
use crate::mesh::VolumeMesh;

pub fn parse(_bytes: &[u8]) -> Result<VolumeMesh, ParseError> {
    Err(ParseError::file("vtu reader not written yet"))
}

pub fn write(_w: &mut dyn std::io::Write, _mesh: &VolumeMesh) -> std::io::Result<()> {
    Err(std::io::Error::other("vtu writer not written yet"))
}
