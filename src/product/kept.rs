//! The coefficients a `HaarTree` keeps, as a flat list, without building the tree: what a
//! precomputation stores of every vertex's transport.
//!
//! `HaarTree::from_pixels` followed by `HaarTree::to_coefficients` and a scan for the
//! non-zero ones gives the same list (tested to the bit), but builds a quadtree node by node
//! and walks every candidate coefficient to mark it kept; a vertex-major precomputation does
//! that once per vertex, where it cost as much as casting a third of the vertex's rays. Here
//! each face is transformed by [`pyramid::forward_into`] into one reused buffer and, when
//! every coefficient is kept, nothing is marked at all.

use ndarray::{Array4, ArrayView3, Axis};

use super::selection::{FaceLayout, Selection};
use super::tree::{check_face_array, kept_mask, selection_limit};
use crate::transform::{Normalization, pyramid};
use crate::{Result, Sample, ensure_finite};

/// The non-zero coefficients that `HaarTree::from_pixels(pixels, layout, selection)` keeps
/// (every face's scaling coefficient and the selected details), as flat indices into its
/// [`to_coefficients`](super::HaarTree::to_coefficients) array `(faces, S, S)` and values.
///
/// ```
/// use haarshift::product::{FaceLayout, HaarTree, Selection, kept::kept_coefficients};
/// use ndarray::{Array3, Axis};
/// let pixels = Array3::from_shape_fn((2, 4, 4), |(f, r, c)| (f * 16 + r * 4 + c % 2) as f32);
/// let (indices, values) = kept_coefficients(pixels.view(), FaceLayout::Stacked, Selection::All).unwrap();
/// let tree = HaarTree::<f32, 1>::from_pixels(pixels.view().insert_axis(Axis(3)), FaceLayout::Stacked, Selection::All).unwrap();
/// let flat = tree.to_coefficients();
/// let want: Vec<usize> = (0..32).filter(|&i| flat.as_slice().unwrap()[i] != 0.0).collect();
/// assert_eq!(indices.iter().map(|&i| i as usize).collect::<Vec<_>>(), want);
/// assert_eq!(values[0], flat[[0, 0, 0, 0]]);
/// ```
pub fn kept_coefficients<T: Sample>(
    pixels: ArrayView3<'_, T>,
    layout: FaceLayout,
    selection: Selection,
) -> Result<(Vec<u32>, Vec<T>)> {
    let pixels = pixels.insert_axis(Axis(3));
    let (faces, s) = check_face_array(pixels.shape(), 1, "pixels")?;
    ensure_finite(&pixels)?;
    let levels = s.trailing_zeros() as usize;
    selection_limit(faces, s, selection)?;
    let mut coefficients = Array4::zeros(pixels.raw_dim());
    let mut work = Vec::new();
    for (face, mut out) in pixels.outer_iter().zip(coefficients.outer_iter_mut()) {
        let plane = face.index_axis_move(Axis(2), 0);
        let out = out.index_axis_mut(Axis(2), 0);
        pyramid::forward_into(plane, levels, Normalization::Orthonormal, out, &mut work)?;
    }
    kept_of_coefficients(
        coefficients.index_axis_move(Axis(3), 0).view(),
        layout,
        selection,
    )
}

/// What [`kept_coefficients`] keeps of `coefficients`, already transformed `(faces, S, S)`
/// (the face-Mallat layout): every face's non-zero scaling coefficient and the non-zero
/// details `selection` picks, as flat indices and values. The bounces' gather truncates its
/// sums of transformed transport with it, by the rule the direct transport was truncated by.
#[doc(hidden)] // For haarshift-relight : public only for the sibling crates (crate docs).
pub fn kept_of_coefficients<T: Sample>(
    coefficients: ArrayView3<'_, T>,
    layout: FaceLayout,
    selection: Selection,
) -> Result<(Vec<u32>, Vec<T>)> {
    let coefficients = coefficients.insert_axis(Axis(3));
    let (faces, s) = check_face_array(coefficients.shape(), 1, "coefficients")?;
    let limit = selection_limit(faces, s, selection)?;
    let kept = match selection {
        Selection::All => None,
        _ => Some(kept_mask::<T, 1>(
            coefficients,
            faces,
            s,
            layout,
            selection,
            limit,
        )),
    };
    let standard = coefficients.as_standard_layout();
    let flat = standard.as_slice().expect("standard layout");
    let mut indices = Vec::new();
    let mut values = Vec::new();
    for (i, &c) in flat.iter().enumerate() {
        let scaling = i % (s * s) == 0;
        if c != T::zero() && (scaling || kept.as_ref().is_none_or(|k| k[i])) {
            indices.push(i as u32);
            values.push(c);
        }
    }
    Ok((indices, values))
}
