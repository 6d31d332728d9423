//! stl surface reader (to be written).

use super::ParseError;
use crate::surface::Surface;

pub fn parse(_bytes: &[u8]) -> Result<Surface, ParseError> {
    Err(ParseError::file("stl reader not written yet"))
}
