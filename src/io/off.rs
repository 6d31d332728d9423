//! off surface reader (to be written).

use super::ParseError;
use crate::surface::Surface;

pub fn parse(_bytes: &[u8]) -> Result<Surface, ParseError> {
    Err(ParseError::file("off reader not written yet"))
}
