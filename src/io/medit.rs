//! Medit `.mesh` (ASCII) / `.meshb` (binary) surface reader (to be written).

use super::ParseError;
use crate::surface::Surface;

pub fn parse_surface(_bytes: &[u8]) -> Result<Surface, ParseError> {
    Err(ParseError::file("medit reader not written yet"))
}
