//! cart3d surface reader (to be written).

use super::ParseError;
use crate::surface::Surface;

pub fn parse(_bytes: &[u8]) -> Result<Surface, ParseError> {
    Err(ParseError::file("cart3d reader not written yet"))
}
