//! All-frequency relighting: lighting, images and animations of meshes lit by environment
//! maps.
//!
//! * [`environment`]: the lighting, loaded, downsampled by solid-angle-weighted means to the
//!   working resolution, rotated and laid out as the product integrals need it.
//! * [`raster`]: the software rasteriser (perspective camera, z-buffer, perspective-correct
//!   interpolation of per-vertex radiance, the environment as background), exposure and sRGB.
//! * [`animation`]: frames into an animated GIF.
//!
//! Conventions are the sphere module's: world Y up, right-handed, directions as in
//! [`crate::sphere::latlong`], rotations `g(p) = f(R p)` with `R = Rz(roll) Ry(yaw) Rx(pitch)`.

pub mod animation;
pub mod environment;
pub mod raster;
