//! The baselines every tree algorithm is measured against, as first-class methods.
//!
//! * [`pixel_integral`]: Sun 2006's "pixel domain" (section 3.2.3, `O(M N)`): the weighted
//!   pixel sum of the product of stored pixel maps.
//! * [`pixel_integral_of_trees`]: the same from Haar trees, the inverse transforms included
//!   (what the pixel domain costs when the functions live as coefficients).
//! * [`pairwise_integral`]: Sun 2006's "recursive Haar" (eq. 3.8): multiply two functions into
//!   a tree ([`multiply`](super::multiply)), then that with the next, and so on, and end with a
//!   two-function product integral.
//!
//! All return the same number as [`product_integral`] (tested),
//! in the same normalisation: the weighted pixel sum, f64.

use ndarray::{ArrayView4, Axis, Zip};
use rayon::prelude::*;

use super::integral::{Integral, IntegralOptions, product_integral};
use super::multiply::weighted_product;
use super::transport::{Transport, WeightedPixels};
use super::tree::{HaarTree, check_face_array};
use crate::{Error, Result, Sample};

/// Values multiplied per chunk before summing (fits in L1, vectorises).
const CHUNK: usize = 512;

/// `sum over faces and pixels of weighted x factors[0] x ...`, per channel, from pixel maps
/// (`(faces, S, S, C)`, all the shape of the weighted one). `visited` counts pixels.
///
/// ```
/// use haarshift::product::{WeightedPixels, baseline::pixel_integral};
/// use ndarray::{Array3, Array4};
/// let w = WeightedPixels::<f64, 1>::new(Array4::from_elem((2, 2, 2, 1), 3.0).view(),
///                                       Array3::from_elem((2, 2, 2), 0.5).view()).unwrap();
/// let f = Array4::from_elem((2, 2, 2, 1), 2.0);
/// assert_eq!(pixel_integral(&w, &[f.view()]).unwrap().value, [8.0 * 3.0 * 0.5 * 2.0]);
/// ```
pub fn pixel_integral<T: Sample, const C: usize>(
    weighted: &WeightedPixels<T, C>,
    factors: &[ArrayView4<'_, T>],
) -> Result<Integral<C>> {
    let first = weighted.as_array();
    for f in factors {
        check_face_array(f.shape(), C, "factor")?;
        if f.shape() != first.shape() {
            return Err(Error::shape(
                f.shape(),
                format!(
                    "factor must have the shape {:?} of the weighted map",
                    first.shape()
                ),
            ));
        }
    }
    let mut maps = vec![first];
    maps.extend(factors.iter().map(|f| f.view()));
    Ok(pixel_product_sum(&maps))
}

/// The weighted pixel sum of the product of the functions of a transport and factor trees,
/// inverse transforms included.
///
/// ```
/// use haarshift::product::{FaceLayout, HaarTree, IntegralOptions, Selection, Transport,
///     WeightedPixels, baseline::pixel_integral_of_trees, product_integral};
/// use ndarray::{Array3, Array4};
/// let f = Array4::from_shape_fn((6, 4, 4, 1), |(k, i, j, _)| (k + i * j) as f64);
/// let w = WeightedPixels::<f64, 1>::new(f.view(), Array3::ones((6, 4, 4)).view()).unwrap();
/// let t = Transport::new(&w, FaceLayout::Stacked, Selection::Largest(20)).unwrap();
/// let g = HaarTree::<f64, 1>::from_pixels(f.view(), FaceLayout::Stacked, Selection::Largest(9)).unwrap();
/// let pixel = pixel_integral_of_trees(&t, &[&g]).unwrap().value[0];
/// let tree = product_integral(&t, &[&g], IntegralOptions::default()).unwrap().value[0];
/// assert!((pixel - tree).abs() < 1e-12 * pixel.abs());
/// ```
pub fn pixel_integral_of_trees<T: Sample, const C: usize>(
    transport: &Transport<T, C>,
    factors: &[&HaarTree<T, C>],
) -> Result<Integral<C>> {
    for f in factors {
        transport.tree().check_compatible(f)?;
    }
    let mut pixels = vec![transport.tree().to_pixels()?];
    for f in factors {
        pixels.push(f.to_pixels()?);
    }
    let views: Vec<_> = pixels.iter().map(|p| p.view()).collect();
    Ok(pixel_product_sum(&views))
}

/// Sun 2006's recursive two-function products: `((transport x f_1) x f_2) ...`, each product
/// a full tree, then a two-function integral with the last factor. `visited` counts the
/// nodes of the intermediate products and of the final integral.
///
/// ```
/// use haarshift::product::{FaceLayout, HaarTree, IntegralOptions, Selection, Transport,
///     WeightedPixels, baseline::pairwise_integral, product_integral};
/// use ndarray::{Array3, Array4};
/// let f = Array4::from_shape_fn((2, 8, 8, 1), |(k, i, j, _)| 1.0 + (k + i * j) as f64);
/// let w = WeightedPixels::<f64, 1>::new(f.view(), Array3::ones((2, 8, 8)).view()).unwrap();
/// let t = Transport::new(&w, FaceLayout::SideBySide, Selection::All).unwrap();
/// let g = HaarTree::<f64, 1>::from_pixels(f.view(), FaceLayout::SideBySide, Selection::Largest(30)).unwrap();
/// let pairwise = pairwise_integral(&t, &[&g, &g, &g]).unwrap().value[0];
/// let tree = product_integral(&t, &[&g, &g, &g], IntegralOptions::default()).unwrap().value[0];
/// assert!((pairwise - tree).abs() < 1e-12 * tree.abs());
/// ```
pub fn pairwise_integral<T: Sample, const C: usize>(
    transport: &Transport<T, C>,
    factors: &[&HaarTree<T, C>],
) -> Result<Integral<C>> {
    let Some((last, rest)) = factors.split_last() else {
        return product_integral(transport, &[], IntegralOptions::default());
    };
    let mut acc = transport.clone();
    let mut nodes = 0;
    for f in rest {
        acc = weighted_product(&acc, &[f])?;
        nodes += acc.tree().nodes().len();
    }
    let mut result = product_integral(&acc, &[last], IntegralOptions::default())?;
    result.visited += nodes;
    Ok(result)
}

/// `sum of maps[0] x maps[1] x ...` per channel over same-shaped `(faces, S, S, C)` arrays,
/// faces in parallel, chunks of products summed in f64.
fn pixel_product_sum<T: Sample, const C: usize>(maps: &[ArrayView4<'_, T>]) -> Integral<C> {
    let faces = maps[0].len_of(Axis(0));
    let per_face: Vec<[f64; C]> = (0..faces)
        .into_par_iter()
        .map(|face| {
            let views: Vec<_> = maps.iter().map(|m| m.index_axis(Axis(0), face)).collect();
            let slices: Vec<std::borrow::Cow<'_, [T]>> = views
                .iter()
                .map(|v| match v.as_slice() {
                    Some(s) => std::borrow::Cow::Borrowed(s),
                    None => std::borrow::Cow::Owned(v.iter().copied().collect()),
                })
                .collect();
            let len = slices[0].len();
            let mut sum = [0.0f64; C];
            let mut buf = [T::zero(); CHUNK];
            // A whole number of pixels per chunk, so element k is channel k % C.
            let chunk = CHUNK / C * C;
            let mut start = 0;
            while start < len {
                let n = chunk.min(len - start);
                let buf = &mut buf[..n];
                buf.copy_from_slice(&slices[0][start..start + n]);
                for s in &slices[1..] {
                    Zip::from(&mut *buf)
                        .and(&s[start..start + n])
                        .for_each(|b, &v| *b *= v);
                }
                for (k, v) in buf.iter().enumerate() {
                    sum[k % C] += v.as_f64();
                }
                start += n;
            }
            sum
        })
        .collect();
    let mut value = [0.0; C];
    for s in per_face {
        for (v, x) in value.iter_mut().zip(s) {
            *v += x;
        }
    }
    Integral {
        value,
        visited: maps[0].len() / C,
    }
}
