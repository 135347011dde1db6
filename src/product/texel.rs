//! Products of sparse functions through their texels: each factor's sparse orthonormal
//! coefficients are inverse-transformed face by face, the texels multiplied, and the product
//! transformed back (Sun 2006 section 3.2.3's "pixel domain", per product).
//!
//! It is the same product as [`multiply::product`](super::multiply::product) (a product of
//! functions that are constant on texels is computed exactly texel by texel; tested against
//! it), at a cost that grows with the texels (two pyramid transforms per factor channel) and
//! not with the factors' nodes. Where faces are small and every factor holds a few hundred
//! coefficients, as in the per-vertex products of dynamic scenes, that is the cheaper way:
//! it builds no tree, sorts nothing and allocates nothing per product (`results/product/vertex.txt`,
//! from the `product` bench's `vertex` groups: 14 us against 53 us for a transport, two maps
//! and the lighting on 2 x 32^2 texels; 140 us against 63 us on 6 x 64^2).
//!
//! A factor that is constant on blocks of side `S >> d` (every detail below level `d` zero)
//! has bit-identical texels within each block, so the product's details below `d` come out
//! exactly zero: a depth limit carries over.

use ndarray::{ArrayView2, ArrayViewMut2};

use super::tree::check_face_array;
use crate::transform::{Normalization, pyramid};
use crate::{Error, Result, Sample};

/// One coefficient of a sparse factor: one channel (the same for every colour) or RGB.
pub trait FactorValue: Copy {
    /// 1 or 3.
    const CHANNELS: usize;
    /// Channel `c` (`c < CHANNELS`).
    fn channel(self, c: usize) -> f64;
}

impl FactorValue for f32 {
    const CHANNELS: usize = 1;
    #[inline(always)]
    fn channel(self, _: usize) -> f64 {
        f64::from(self)
    }
}

impl FactorValue for f64 {
    const CHANNELS: usize = 1;
    #[inline(always)]
    fn channel(self, _: usize) -> f64 {
        self
    }
}

impl<T: Sample> FactorValue for [T; 3] {
    const CHANNELS: usize = 3;
    #[inline(always)]
    fn channel(self, c: usize) -> f64 {
        self[c].as_f64()
    }
}

/// The running product of sparse functions on `F` square faces of side `S`, held as texels;
/// see the [module docs](self). Reuse one per thread: after [`new`](Self::new) nothing is
/// allocated.
///
/// Coefficients are the face-Mallat positions of [`HaarTree::from_sparse`](super::HaarTree::from_sparse)
/// (`face x S^2 + row x S + col`, orthonormal, `(face, 0, 0)` the scaling coefficient).
///
/// ```
/// use haarshift::product::{FaceLayout, HaarTree, texel::TexelProduct, multiply::product};
/// // Two functions on two 4 x 4 faces, sparse: the scaling coefficients and a few details.
/// let a: (Vec<u32>, Vec<f64>) = (vec![0, 1, 5, 16, 19], vec![4.0, 0.5, -0.25, 2.0, 0.75]);
/// let b: (Vec<u32>, Vec<[f64; 3]>) = (vec![0, 2, 16, 30],
///     vec![[8.0, 4.0, 2.0], [1.0, 0.5, 0.0], [6.0, 6.0, 6.0], [-1.0, 0.0, 1.0]]);
/// let mut p = TexelProduct::<f64>::new(2, 4).unwrap();
/// p.multiply(&a.0, &a.1).unwrap();
/// p.multiply(&b.0, &b.1).unwrap();
/// let (mut indices, mut values) = (Vec::new(), Vec::new());
/// p.sparse_coefficients(&mut indices, &mut values);
/// // The quadtree product of the same two functions.
/// let ta = HaarTree::from_sparse(2, 4, FaceLayout::Stacked, &a.0,
///     &a.1.iter().map(|&v| [v; 3]).collect::<Vec<_>>()).unwrap();
/// let tb = HaarTree::from_sparse(2, 4, FaceLayout::Stacked, &b.0, &b.1).unwrap();
/// let (want_i, want_v) = product(&[&ta, &tb]).unwrap().sparse_coefficients();
/// assert_eq!(indices, want_i);
/// for (got, want) in values.iter().zip(&want_v) {
///     assert!((0..3).all(|c| (got[c] - want[c]).abs() < 1e-12));
/// }
/// ```
#[derive(Clone, Debug)]
pub struct TexelProduct<T> {
    faces: usize,
    side: usize,
    /// The product of the one-channel factors, `F x S x S`, when `has_mono` (else 1).
    mono: Vec<T>,
    has_mono: bool,
    /// The product of the RGB factors, three planes of `F x S x S`, when `has_rgb` (else 1).
    rgb: Vec<T>,
    has_rgb: bool,
    /// One channel of a factor's coefficients; all zeros between calls.
    scatter: Vec<T>,
    /// One channel of a factor's texels; then one face of the product's.
    texels: Vec<T>,
    /// The product's coefficients: one plane, or three.
    coefficients: Vec<T>,
    work: Vec<T>,
}

impl<T: Sample> TexelProduct<T> {
    /// The product of no factors (the constant 1) on `faces` faces of side `side` (a power of
    /// two).
    pub fn new(faces: usize, side: usize) -> Result<Self> {
        check_face_array(&[faces, side, side, 1], 1, "a texel product")?;
        let n = faces
            .checked_mul(side * side)
            .filter(|&n| n <= u32::MAX as usize / 3)
            .ok_or_else(|| {
                Error::shape(&[faces, side, side], "more texels than u32 indices reach")
            })?;
        Ok(TexelProduct {
            faces,
            side,
            mono: vec![T::zero(); n],
            has_mono: false,
            rgb: vec![T::zero(); 3 * n],
            has_rgb: false,
            scatter: vec![T::zero(); n],
            texels: vec![T::zero(); n],
            coefficients: vec![T::zero(); 3 * n],
            work: Vec::new(),
        })
    }

    /// Texels of one face set, `F x S x S`.
    pub fn texel_count(&self) -> usize {
        self.scatter.len()
    }

    /// Back to the constant 1.
    pub fn reset(&mut self) {
        self.has_mono = false;
        self.has_rgb = false;
    }

    /// Multiplies the product by the function whose non-zero coefficients are `indices`
    /// (distinct, below [`texel_count`](Self::texel_count)) and `values` (finite).
    pub fn multiply<V: FactorValue>(&mut self, indices: &[u32], values: &[V]) -> Result<()> {
        self.check_sparse(indices, values)?;
        let n = self.texel_count();
        for c in 0..V::CHANNELS {
            for (&i, v) in indices.iter().zip(values) {
                self.scatter[i as usize] = T::from_f64(v.channel(c));
            }
            synthesise(
                self.faces,
                self.side,
                &self.scatter,
                &mut self.texels[..n],
                &mut self.work,
            );
            for &i in indices {
                self.scatter[i as usize] = T::zero();
            }
            let (acc, set) = match V::CHANNELS {
                1 => (&mut self.mono[..], self.has_mono),
                _ => (&mut self.rgb[c * n..(c + 1) * n], self.has_rgb),
            };
            if set {
                acc.iter_mut().zip(&self.texels).for_each(|(a, &t)| *a *= t);
            } else {
                acc.copy_from_slice(&self.texels[..n]);
            }
        }
        match V::CHANNELS {
            1 => self.has_mono = true,
            _ => self.has_rgb = true,
        }
        Ok(())
    }

    /// Multiplies the product by `other`'s (a factor shared by many products is transformed
    /// once this way: the lighting of every vertex).
    pub fn multiply_by(&mut self, other: &TexelProduct<T>) -> Result<()> {
        if (other.faces, other.side) != (self.faces, self.side) {
            return Err(Error::shape(
                &[other.faces, other.side, other.side],
                format!(
                    "the products live on different faces ({} x {}^2 and {} x {}^2)",
                    self.faces, self.side, other.faces, other.side
                ),
            ));
        }
        for (own, set, theirs, given) in [
            (
                &mut self.mono,
                &mut self.has_mono,
                &other.mono,
                other.has_mono,
            ),
            (&mut self.rgb, &mut self.has_rgb, &other.rgb, other.has_rgb),
        ] {
            match (*set, given) {
                (_, false) => {}
                (false, true) => own.copy_from_slice(theirs),
                (true, true) => own.iter_mut().zip(theirs).for_each(|(a, &b)| *a *= b),
            }
            *set |= given;
        }
        Ok(())
    }

    /// `<g, product>` per channel: the integral of `g` times the product with the weight
    /// folded into `g` (a transport, as [`Transport`](super::Transport) has it), i.e. the
    /// coefficient-wise dot product, for the sparse `g` of `indices` and `values` (a
    /// one-channel `g` multiplies every channel).
    pub fn dot<V: FactorValue>(&mut self, indices: &[u32], values: &[V]) -> Result<[f64; 3]> {
        self.check_sparse(indices, values)?;
        let planes = self.analyse();
        let n = self.texel_count();
        let p = &self.coefficients;
        let mut acc = [0.0f64; 3];
        for (&i, v) in indices.iter().zip(values) {
            for (c, a) in acc.iter_mut().enumerate() {
                *a += v.channel(c % V::CHANNELS) * p[(c % planes) * n + i as usize].as_f64();
            }
        }
        Ok(acc)
    }

    /// The product's non-zero coefficients, ascending, into `indices` and `values` (cleared
    /// first; a one-channel product fills every channel).
    pub fn sparse_coefficients(&mut self, indices: &mut Vec<u32>, values: &mut Vec<[T; 3]>) {
        indices.clear();
        values.clear();
        let planes = self.analyse();
        let n = self.texel_count();
        let p = &self.coefficients;
        for i in 0..n {
            let v = [p[i], p[(1 % planes) * n + i], p[(2 % planes) * n + i]];
            if v.iter().any(|x| *x != T::zero()) {
                indices.push(i as u32);
                values.push(v);
            }
        }
    }

    fn check_sparse<V: FactorValue>(&self, indices: &[u32], values: &[V]) -> Result<()> {
        let n = self.texel_count();
        if indices.len() != values.len()
            || indices.iter().any(|&i| i as usize >= n)
            || values
                .iter()
                .any(|v| (0..V::CHANNELS).any(|c| !v.channel(c).is_finite()))
        {
            return Err(Error::parameter(
                "coefficients",
                format!(
                    "{} indices and {} values: one finite value per index below {n}",
                    indices.len(),
                    values.len()
                ),
            ));
        }
        Ok(())
    }

    /// The product's coefficients in `coefficients` (one plane when every factor had one
    /// channel, else three); returns how many planes.
    fn analyse(&mut self) -> usize {
        let n = self.texel_count();
        let planes = if self.has_rgb { 3 } else { 1 };
        let source: Option<&[T]> = match (self.has_mono, self.has_rgb) {
            (false, false) => {
                // The constant 1: on each face only the scaling coefficient, S.
                let c = &mut self.coefficients[..n];
                c.fill(T::zero());
                let area = self.side * self.side;
                for f in 0..self.faces {
                    c[f * area] = T::from_f64(self.side as f64);
                }
                return 1;
            }
            (true, false) => Some(&self.mono[..]),
            (false, true) => Some(&self.rgb[..]),
            (true, true) => None,
        };
        let (s, area) = (self.side, self.side * self.side);
        let levels = s.trailing_zeros() as usize;
        for f in 0..planes * self.faces {
            let range = f * area..(f + 1) * area;
            let face: &[T] = match source {
                Some(source) => &source[range.clone()],
                None => {
                    // RGB times mono, one face at a time (a face stays in cache).
                    let rgb = &self.rgb[range.clone()];
                    let mono = &self.mono[(f % self.faces) * area..][..area];
                    let t = &mut self.texels[..area];
                    for ((t, &a), &b) in t.iter_mut().zip(rgb).zip(mono) {
                        *t = a * b;
                    }
                    t
                }
            };
            let image = ArrayView2::from_shape((s, s), face).expect("S x S");
            let out =
                ArrayViewMut2::from_shape((s, s), &mut self.coefficients[range]).expect("S x S");
            pyramid::forward_into(
                image,
                levels,
                Normalization::Orthonormal,
                out,
                &mut self.work,
            )
            .expect("a face is a square power of two");
        }
        planes
    }
}

/// The inverse transform of the coefficients `from` into the texels `to`, face by face.
fn synthesise<T: Sample>(faces: usize, s: usize, from: &[T], to: &mut [T], work: &mut Vec<T>) {
    let (area, levels) = (s * s, s.trailing_zeros() as usize);
    for f in 0..faces {
        let range = f * area..(f + 1) * area;
        let coefficients = ArrayView2::from_shape((s, s), &from[range.clone()]).expect("S x S");
        let out = ArrayViewMut2::from_shape((s, s), &mut to[range]).expect("S x S");
        pyramid::inverse_into(coefficients, levels, Normalization::Orthonormal, out, work)
            .expect("a face is a square power of two");
    }
}

#[cfg(test)]
mod tests;
