//! The product of lat-long maps as a map on the sphere, computed in the Haar domain: the
//! maps' trees multiplied by [`product::multiply::product`](crate::product::multiply::product)
//! (Sun 2006 section 3.4.4), not pixel by pixel.
//!
//! [`map_product`] takes the maps as [`integrate`](super::integrate::integrate) does (one size,
//! `H` a power of two, one-channel maps broadcast over the channels of the others; lat-long at
//! the maps' own height or a cube map, at any working resolution), builds each map's tree with
//! its [`Selection`] and returns the product as a [`SphereMap`] and as its Haar coefficients.
//! No factor carries a weight: the product is a function, not an integral. So:
//!
//! * with everything kept, the product map is the pointwise product of the maps (of the
//!   converted maps for the cube), to rounding;
//! * with [`Selection::Largest`]`(K)`, it is the pointwise product of the maps reconstructed
//!   from their `K` largest orthonormal detail coefficients (plus the face scaling
//!   coefficients; the rule of [`selection`](crate::product::selection)).
//!
//! **Coefficients.** [`SphereProduct::coefficients`] is a `(faces, S, S, C)` array: per face,
//! its full-depth orthonormal Mallat pyramid ([`transform::pyramid`](crate::transform::pyramid)
//! with [`Normalization::Orthonormal`](crate::transform::Normalization)): `[face, 0, 0, c]` is
//! the pixel sum over `S`, detail `(row, col)` of level `l` sits at `(row, 2^l + col)` (`H`),
//! `(2^l + row, col)` (`V`) and `(2^l + row, 2^l + col)` (`D`). Faces are the lat-long map's
//! halves (`phi` in `[0, pi)` then `[pi, 2 pi)`) or the cube's `+X, -X, +Y, -Y, +Z, -Z`.

use std::time::Instant;

use ndarray::Array4;

use super::integrate::{layout, plain_trees, working_faces};
use super::param::{ParamKind, SphereMap};
use crate::product::Selection;
use crate::product::multiply::product;
use crate::sphere::LatLongMap;
use crate::{Result, Sample};

/// What [`map_product`] does.
///
/// ```
/// use haarshift::faces::map_product::ProductOptions;
/// let o = ProductOptions::default();
/// assert!(o.resolution.is_none() && o.selections.is_empty());
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ProductOptions {
    /// The parameterisation to multiply in (and of the result).
    pub param: ParamKind,
    /// The face side: lat-long `N x 2N`, cube `6 x N x N` (`None`: the maps' height `H` for
    /// lat-long, `H / 2` for the cube).
    pub resolution: Option<usize>,
    /// One selection for every map, or one per map (empty: keep everything).
    pub selections: Vec<Selection>,
}

/// The result of [`map_product`].
#[derive(Clone, Debug, PartialEq)]
pub struct SphereProduct<T> {
    /// The product map, in the working parameterisation.
    pub map: SphereMap<T>,
    /// Its orthonormal Haar coefficients, `(faces, S, S, C)` (see the [module docs](self)).
    pub coefficients: Array4<T>,
    /// Detail coefficients kept per map (scaling coefficients not counted).
    pub kept: Vec<usize>,
    /// Nodes of the product tree.
    pub nodes: usize,
    /// Seconds spent in the product itself (trees already built).
    pub seconds: f64,
}

/// The product of `maps` (lat-long `H x 2H`, `H` a power of two, each of 1 or `C` channels)
/// through their Haar trees; see the [module docs](self).
///
/// ```
/// use haarshift::sphere::LatLongMap;
/// use haarshift::faces::map_product::{ProductOptions, map_product};
/// let f = LatLongMap::<f64>::from_fn(8, 1, |d, out| out[0] = 1.0 + d[1]).unwrap();
/// let g = LatLongMap::<f64>::from_fn(8, 3, |d, out| out.fill(2.0 + d[0])).unwrap();
/// let fg = map_product(&[f.clone(), g.clone()], &ProductOptions::default()).unwrap();
/// let got = fg.map.to_lat_long().unwrap();
/// let want = &f.as_array() * &g.as_array();
/// assert!(got.as_array().iter().zip(want.iter()).all(|(a, b)| (a - b).abs() < 1e-12));
/// ```
pub fn map_product<T: Sample>(
    maps: &[LatLongMap<T>],
    options: &ProductOptions,
) -> Result<SphereProduct<T>> {
    let work = working_faces(maps, options.param, options.resolution, &options.selections)?;
    let layout = layout(work.param);
    macro_rules! channels {
        ($c:literal) => {{
            let trees = plain_trees::<T, $c>(&work.faces, &work.selections, layout)?;
            let refs: Vec<_> = trees.iter().collect();
            let start = Instant::now();
            let tree = product(&refs)?;
            let seconds = start.elapsed().as_secs_f64();
            SphereProduct {
                map: SphereMap::new(work.param, tree.to_pixels()?)?,
                coefficients: tree.to_coefficients(),
                kept: trees.iter().map(|t| t.kept()).collect(),
                nodes: tree.nodes().len(),
                seconds,
            }
        }};
    }
    Ok(match work.channels {
        1 => channels!(1),
        2 => channels!(2),
        3 => channels!(3),
        _ => channels!(4),
    })
}

#[cfg(test)]
#[path = "map_product_tests.rs"]
mod tests;
