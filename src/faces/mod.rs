//! Functions on the sphere stored as square faces, the layout product integrals work on:
//! [`param`] (one [`Parameterization`] over lat-long, two `H x H` faces, and the cube map,
//! six; texel directions, exact texel solid angles, [`SphereMap`]), [`cube`] (the cube map's
//! faces, orientation and exact spherical-quadrilateral solid angles), [`convert`] (between
//! parameterisations by solid-angle integration over each target texel), [`integrate`] (the
//! integral over the sphere of a product of maps, on their Haar trees) and `product` (the
//! product of maps as a map, through their Haar trees).
//!
//! Directions and conventions are [`crate::sphere::latlong`]'s.

pub mod convert;
pub mod cube;
pub mod integrate;
pub mod map_product;
pub mod param;

pub use param::{ParamKind, Parameterization, SphereMap};
