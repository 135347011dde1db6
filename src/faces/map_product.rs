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
mod tests {
    use super::*;
    use crate::faces::convert::{convert, default_samples};
    use crate::faces::param::Parameterization;
    use crate::product::{FaceLayout, HaarTree};
    use crate::transform::{Normalization, pyramid};
    use ndarray::{Array3, Axis};

    fn map<T: Sample>(h: usize, channels: usize, seed: u64) -> LatLongMap<T> {
        let mut x = seed;
        LatLongMap::new(Array3::from_shape_fn((h, 2 * h, channels), |_| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            T::from_f64(0.1 + (x >> 11) as f64 / (1u64 << 53) as f64)
        }))
        .unwrap()
    }

    fn max_relative(got: &[f64], want: &[f64]) -> f64 {
        assert_eq!(got.len(), want.len());
        got.iter()
            .zip(want)
            .map(|(g, w)| ((g - w) / w).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn the_product_map_is_the_pointwise_product_in_f64_and_f32() {
        let maps = [map::<f64>(16, 3, 1), map(16, 1, 2), map(16, 3, 3)];
        let want: Vec<f64> = Array3::from_shape_fn((16, 32, 3), |(i, j, c)| {
            maps.iter()
                .map(|m| m.as_array()[[i, j, c.min(m.channels() - 1)]])
                .product()
        })
        .into_iter()
        .collect();
        /// The product's lat-long pixels, in f64.
        fn pixels<T: Sample>(maps: &[LatLongMap<T>]) -> Vec<f64> {
            let got = map_product(maps, &ProductOptions::default()).unwrap();
            assert_eq!(got.kept, vec![16 * 32 - 2; 3]);
            let map = got.map.to_lat_long().unwrap();
            map.as_array().iter().map(|v| v.as_f64()).collect()
        }
        assert!(max_relative(&pixels(&maps), &want) < 1e-13);
        let single: Vec<LatLongMap<f32>> = maps
            .iter()
            .map(|m| LatLongMap::new(m.as_array().mapv(|v| v as f32)).unwrap())
            .collect();
        let err = max_relative(&pixels(&single), &want);
        assert!(err < 2e-5 && err > 0.0, "{err}");
    }

    #[test]
    fn coefficients_are_the_orthonormal_pyramids_of_the_product_faces() {
        let maps = [map::<f64>(8, 1, 4), map(8, 1, 5)];
        let got = map_product(&maps, &ProductOptions::default()).unwrap();
        let faces = got.map.as_array();
        for f in 0..2 {
            let plane = faces
                .index_axis(Axis(0), f)
                .index_axis(Axis(2), 0)
                .to_owned();
            let want = pyramid::forward(plane.view(), 3, Normalization::Orthonormal).unwrap();
            let have = got
                .coefficients
                .index_axis(Axis(0), f)
                .index_axis(Axis(2), 0)
                .to_owned();
            assert!(
                have.iter()
                    .zip(want.iter())
                    .all(|(a, b)| (a - b).abs() < 1e-12)
            );
        }
    }

    #[test]
    fn with_k_kept_it_is_the_product_of_the_pruned_maps() {
        // The selection rule itself is tested in `product::tests`; here the pruned maps are
        // the pixels of each map's own pruned tree, multiplied pixel by pixel.
        let maps = [map::<f64>(16, 1, 6), map::<f64>(16, 1, 7)];
        let k = 37;
        let pruned: Vec<Array4<f64>> = maps
            .iter()
            .map(|m| {
                let faces = SphereMap::from_lat_long(m).unwrap().into_array();
                HaarTree::<f64, 1>::from_pixels(
                    faces.view(),
                    FaceLayout::SideBySide,
                    Selection::Largest(k),
                )
                .unwrap()
                .to_pixels()
                .unwrap()
            })
            .collect();
        let want = &pruned[0] * &pruned[1];
        let o = ProductOptions {
            selections: vec![Selection::Largest(k)],
            ..Default::default()
        };
        let got = map_product(&maps, &o).unwrap();
        assert_eq!(got.kept, vec![k, k]);
        let err = got
            .map
            .as_array()
            .iter()
            .zip(want.iter())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-12, "{err}");
        let full = map_product(&maps, &ProductOptions::default()).unwrap();
        assert!(
            max_relative(
                &got.map.as_array().iter().copied().collect::<Vec<_>>(),
                &full.map.as_array().iter().copied().collect::<Vec<_>>()
            ) > 1e-3
        );
    }

    #[test]
    fn in_the_cube_it_is_the_product_of_the_converted_maps() {
        let maps = [map::<f64>(16, 3, 8), map(16, 1, 9)];
        let o = ProductOptions {
            param: ParamKind::Cube,
            ..Default::default()
        };
        let got = map_product(&maps, &o).unwrap();
        let (ll, cube) = (
            Parameterization::new(ParamKind::LatLong, 16).unwrap(),
            Parameterization::new(ParamKind::Cube, 8).unwrap(),
        );
        assert_eq!(got.map.param(), cube);
        let converted: Vec<_> = maps
            .iter()
            .map(|m| {
                let s = SphereMap::from_lat_long(m).unwrap();
                convert(&s, cube, default_samples(ll, cube))
                    .unwrap()
                    .into_array()
            })
            .collect();
        let want = &converted[0] * &converted[1];
        let err = got
            .map
            .as_array()
            .iter()
            .zip(want.iter())
            .map(|(a, b)| (a - b).abs() / b)
            .fold(0.0, f64::max);
        assert!(err < 1e-13, "{err}");
    }

    #[test]
    fn bad_requests_are_errors() {
        let (a, b) = (map::<f64>(16, 1, 10), map::<f64>(8, 1, 11));
        let d = ProductOptions::default();
        assert_err!(
            map_product(&[a.clone(), b], &d),
            InvalidShape { .. },
            "maps of different sizes"
        );
        assert_err!(
            map_product::<f64>(&[], &d),
            InvalidParameter { name: "maps", .. },
            "no map given"
        );
        let many = ProductOptions {
            selections: vec![Selection::Largest(16 * 32)],
            ..Default::default()
        };
        assert_err!(
            map_product(&[a.clone(), a.clone()], &many),
            InvalidParameter { name: "keep", .. },
            "only 510 details"
        );
        let odd = LatLongMap::<f64>::from_fn(6, 1, |_, o| o[0] = 1.0).unwrap();
        assert_err!(
            map_product(&[odd.clone(), odd], &d),
            InvalidShape { .. },
            "not a power of two"
        );
    }
}
