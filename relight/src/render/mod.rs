//! Images of per-vertex radiance: a perspective [`camera`], the software rasteriser
//! ([`raster`]: z-buffer, perspective-correct interpolation; [`sky`]: the environment behind), exposure,
//! sRGB and files ([`output`]), animated GIFs ([`animation`]), and the radiance baked into a
//! glTF 2.0 mesh ([`baked`]).

pub mod animation;
pub mod baked;
pub mod camera;
pub mod output;
pub mod raster;
pub mod sky;
pub mod view;

pub use camera::{Camera, DEFAULT_FOV};
pub use output::{render_format, srgb_encode, to_srgb8, write_render};
pub use raster::{Background, LitMesh, render};
pub use sky::{Sky, SkyLookup};
