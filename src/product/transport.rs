//! The weighting contract: which factor of a product integral carries the integration weight.
//!
//! An integral over a set of faces is a weighted pixel sum, `sum over faces and pixels of
//! w(p) f_1(p) ... f_N(p)` (on the sphere `w` is each texel's solid angle). Exactly one factor
//! must carry `w`. Here that factor has its own type, [`Transport`], and the only way to make
//! one is from [`WeightedPixels`], whose only constructor multiplies values by weights, once.
//! [`product_integral`](super::product_integral) takes one transport and any number of plain
//! [`HaarTree`] factors, so a weight can be neither forgotten nor applied twice. (The name is
//! Sun 2006's: the transport is visibility x cosine x solid angle, or any product that
//! includes it, eq. 3.9.)
//!
//! This module knows no geometry: the weights are whatever the caller passes (texel solid
//! angles from the sphere module; all ones for a plain pixel sum).

use ndarray::{Array4, ArrayView3, ArrayView4, Axis};

use super::selection::{FaceLayout, Selection};
use super::tree::{HaarTree, check_face_array};
use crate::{Error, Result, Sample, ensure_finite};

/// Pixel values multiplied by per-pixel weights, `(faces, S, S, C)`: the only source of a
/// [`Transport`].
///
/// ```
/// use haarshift::product::WeightedPixels;
/// use ndarray::{Array3, Array4};
/// let values = Array4::from_elem((2, 2, 2, 3), 2.0f32);
/// let weights = Array3::from_elem((2, 2, 2), 0.25f32);
/// let w = WeightedPixels::<f32, 3>::new(values.view(), weights.view()).unwrap();
/// assert_eq!(w.as_array()[[1, 0, 1, 2]], 0.5);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct WeightedPixels<T, const C: usize> {
    data: Array4<T>,
}

impl<T: Sample, const C: usize> WeightedPixels<T, C> {
    /// `values (faces, S, S, C) x weights (faces, S, S)`, the weight broadcast over channels.
    pub fn new(values: ArrayView4<'_, T>, weights: ArrayView3<'_, T>) -> Result<Self> {
        let (faces, s) = check_face_array(values.shape(), C, "values")?;
        if weights.dim() != (faces, s, s) {
            return Err(Error::shape(
                weights.shape(),
                format!("weights must be ({faces}, {s}, {s}), one per pixel of the values"),
            ));
        }
        ensure_finite(&values)?;
        ensure_finite(&weights)?;
        let data = &values * &weights.insert_axis(Axis(3));
        Ok(WeightedPixels { data })
    }

    /// The weighted values.
    pub fn as_array(&self) -> ArrayView4<'_, T> {
        self.data.view()
    }
}

/// A function that carries the integration weight, as a Haar tree: the one factor of a product
/// integral that may; see the [module docs](self).
///
/// ```
/// use haarshift::product::{FaceLayout, Selection, Transport, WeightedPixels};
/// use ndarray::{Array3, Array4};
/// let w = WeightedPixels::<f64, 1>::new(Array4::ones((6, 4, 4, 1)).view(),
///                                       Array3::from_elem((6, 4, 4), 0.5).view()).unwrap();
/// let t = Transport::new(&w, FaceLayout::Stacked, Selection::All).unwrap();
/// assert_eq!(t.tree().scaling()[0], [2.0]); // pixel sum 8 over S = 4
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Transport<T, const C: usize> {
    tree: HaarTree<T, C>,
}

impl<T: Sample, const C: usize> Transport<T, C> {
    /// The Haar tree of weighted pixels, with `selection` applied.
    pub fn new(
        pixels: &WeightedPixels<T, C>,
        layout: FaceLayout,
        selection: Selection,
    ) -> Result<Self> {
        Ok(Transport {
            tree: HaarTree::from_pixels(pixels.as_array(), layout, selection)?,
        })
    }

    /// The tree (read only: a transport cannot be turned into a plain factor and back).
    pub fn tree(&self) -> &HaarTree<T, C> {
        &self.tree
    }

    /// This transport with a new selection applied.
    pub fn select(&self, selection: Selection) -> Result<Self> {
        Ok(Transport {
            tree: self.tree.select(selection)?,
        })
    }

    /// Wraps a tree known to carry the weight (a product that includes a transport).
    #[doc(hidden)] // For haarshift-relight : public only for the sibling crates (crate docs).
    pub fn from_weighted_tree(tree: HaarTree<T, C>) -> Self {
        Transport { tree }
    }
}
