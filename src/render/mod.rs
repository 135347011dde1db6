//! Images of per-vertex radiance: the camera, the software rasteriser (z-buffer,
//! perspective-correct interpolation, sRGB) ([`raster`]), and animated GIFs ([`animation`]).

pub mod animation;
pub mod raster;
