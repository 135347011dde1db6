//! A vertex's products of sparse factors for just-in-time radiance transfer: the fixed
//! product `T` (formed once) and a frame's `<T, prod F_k>` when several factors vary.
//!
//! Two ways give the same numbers (tested against each other and against the full product
//! integral): on quadtrees (issue 7's [`product`] and the triple or `n`-function traversal with
//! `T` as the transport) and through texels ([`TexelProduct`]: inverse-transform each factor,
//! multiply, transform back). Which is cheaper depends on the face size, not on the scene.
//! The `product` bench's `vertex` groups (`RAYON_NUM_THREADS=1 cargo bench -p haarshift-relight --bench product --
//! vertex`, one run committed as `results/product/vertex.txt`) time the fixed product of a
//! transport (70 kept), two occlusion maps (200 each) and the lighting (200, RGB), and a
//! frame's `<T, O_a O_b>`, per vertex on one core:
//!
//! | faces | fixed product, texels / trees | frame, texels / trees |
//! |---|---|---|
//! | lat-long 32 (2 x 32^2) | 14 / 53 us | 4.9 / 38 us |
//! | cube 32 (6 x 32^2) | 41 / 58 us | 12 / 42 us |
//! | cube 64 (6 x 64^2) | 140 / 63 us | 38 / 52 us |
//!
//! So texels form the fixed product up to 6 x 32^2 texels and take a frame's product up to
//! 6 x 64^2 ([`Method::for_param`]); quadtrees beyond.

use super::*;
use haarshift::product::texel::{FactorValue, TexelProduct};
use haarshift::product::triple::triple_integral;

/// How a vertex's products are computed; see the [module docs](self).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Method {
    Texels,
    Trees,
}

/// What a product is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Use {
    /// The fixed product `T`, all of its coefficients.
    Fixed,
    /// A frame's `<T, product>`.
    Frame,
}

impl Method {
    /// The cheaper way at `param`'s size (the bench figures of the [module docs](self)).
    pub(super) fn for_param(param: Parameterization, what: Use) -> Self {
        let most = match what {
            Use::Fixed => 6 * 32 * 32,
            Use::Frame => 6 * 64 * 64,
        };
        if param.texels() <= most {
            Method::Texels
        } else {
            Method::Trees
        }
    }
}

/// A factor shared by every vertex's product (the lighting), transformed once in the form
/// the method multiplies.
pub(super) enum SharedFactor<T> {
    Texels(TexelProduct<T>),
    Tree(HaarTree<T, 3>),
}

impl<T: Sample> SharedFactor<T> {
    /// The sparse RGB function of `indices` and `values` for `method`.
    pub(super) fn new(
        param: Parameterization,
        method: Method,
        indices: &[u32],
        values: &[[T; 3]],
    ) -> Result<Self> {
        Ok(match method {
            Method::Texels => {
                let mut p = TexelProduct::new(param.faces(), param.face_size())?;
                p.multiply(indices, values)?;
                SharedFactor::Texels(p)
            }
            Method::Trees => SharedFactor::Tree(HaarTree::from_sparse(
                param.faces(),
                param.face_size(),
                layout(param),
                indices,
                values,
            )?),
        })
    }
}

/// One vertex's running product of sparse factors (reused from vertex to vertex).
#[derive(Clone)]
pub(super) enum VertexProduct<T> {
    Texels(TexelProduct<T>),
    Trees {
        param: Parameterization,
        trees: Vec<HaarTree<T, 3>>,
    },
}

impl<T: Sample> VertexProduct<T> {
    /// The constant 1, computed by `method`.
    pub(super) fn new(param: Parameterization, method: Method) -> Result<Self> {
        Ok(match method {
            Method::Texels => {
                VertexProduct::Texels(TexelProduct::new(param.faces(), param.face_size())?)
            }
            Method::Trees => VertexProduct::Trees {
                param,
                trees: Vec::new(),
            },
        })
    }

    /// Back to the constant 1.
    pub(super) fn reset(&mut self) {
        match self {
            VertexProduct::Texels(p) => p.reset(),
            VertexProduct::Trees { trees, .. } => trees.clear(),
        }
    }

    /// Times the sparse function of `indices` and `values` (one channel or RGB).
    pub(super) fn multiply<V: FactorValue>(&mut self, indices: &[u32], values: &[V]) -> Result<()> {
        match self {
            VertexProduct::Texels(p) => Ok(p.multiply(indices, values)?),
            VertexProduct::Trees { param, trees } => {
                let rgb: Vec<[T; 3]> = values
                    .iter()
                    .map(|v| std::array::from_fn(|c| T::from_f64(v.channel(c % V::CHANNELS))))
                    .collect();
                trees.push(HaarTree::from_sparse(
                    param.faces(),
                    param.face_size(),
                    layout(*param),
                    indices,
                    &rgb,
                )?);
                Ok(())
            }
        }
    }

    /// The product times `shared` (`None`: as it is), its non-zero coefficients ascending.
    pub(super) fn coefficients(
        &mut self,
        shared: Option<&SharedFactor<T>>,
    ) -> Result<(Vec<u32>, Vec<[T; 3]>)> {
        match (self, shared) {
            (VertexProduct::Texels(p), shared) => {
                if let Some(SharedFactor::Texels(s)) = shared {
                    p.multiply_by(s)?;
                }
                let (mut indices, mut values) = (Vec::new(), Vec::new());
                p.sparse_coefficients(&mut indices, &mut values);
                Ok((indices, values))
            }
            (VertexProduct::Trees { param, trees }, shared) => {
                let mut refs: Vec<&HaarTree<T, 3>> = trees.iter().collect();
                if let Some(SharedFactor::Tree(t)) = shared {
                    refs.push(t);
                }
                if refs.is_empty() {
                    // The constant 1: each face's scaling coefficient is S.
                    let s = param.face_size();
                    return Ok((0..param.faces())
                        .map(|f| ((f * s * s) as u32, [T::from_f64(s as f64); 3]))
                        .unzip());
                }
                Ok(product(&refs)?.sparse_coefficients())
            }
        }
    }

    /// `<T, product>` for the fixed product `T` of `ti` and `tv` (it carries the weight).
    pub(super) fn dot(&mut self, ti: &[u32], tv: &[[T; 3]]) -> Result<[T; 3]> {
        let value = match self {
            VertexProduct::Texels(p) => p.dot(ti, tv)?,
            VertexProduct::Trees { param, trees } => {
                let own = HaarTree::from_sparse(
                    param.faces(),
                    param.face_size(),
                    layout(*param),
                    ti,
                    tv,
                )?;
                let transport = Transport::from_weighted_tree(own);
                match &trees[..] {
                    [a, b] => triple_integral(&transport, a, b)?.value,
                    _ => {
                        let refs: Vec<&HaarTree<T, 3>> = trees.iter().collect();
                        product_integral(&transport, &refs, IntegralOptions::default())?.value
                    }
                }
            }
        };
        Ok(value.map(T::from_f64))
    }
}
