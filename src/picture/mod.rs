//! PNG pictures of a volume mesh, to see the boundary layers: a planar cut through the cells
//! ([`cut_picture`], filled by kind or by quality, faces stroked) and a histogram of a quality
//! measure ([`histogram_picture`]), and the standard set of both ([`write_overview`]). Drawn with
//! tiny-skia, written atomically ([`write_png`]).

mod colour;
mod cut;
mod histogram;
mod overview;
#[cfg(test)]
mod tests;

use std::path::Path;

pub use colour::{kind_colour, quality_colour, Colouring};
pub use cut::{cut_picture, CutPlane, View};
pub use histogram::{histogram, histogram_picture};
pub use overview::{scaled_jacobians, write_overview, PictureSpot};
pub use tiny_skia::Pixmap;

/// Write a picture as a PNG file, atomically (a failure leaves no file).
pub fn write_png(pixmap: &Pixmap, path: &Path) -> std::io::Result<()> {
    let png = pixmap
        .encode_png()
        .map_err(|e| std::io::Error::other(format!("encoding the PNG picture {}: {e}", path.display())))?;
    crate::io::write_atomic(path, |w| w.write_all(&png))
}
