//! Haar product algebra on sets of square faces: integrals and products of several functions
//! computed directly on their sparse 2D Haar coefficients (Sun 2006 chapters 2-3, Sun and Mukherjee 2012, Vollick and Lessig).
//!
//! This module is pure algebra: a function is given on `F` square faces of side `S = 2^n`
//! (`(faces, S, S, C)` arrays: a cube map has 6 faces, a lat-long `H x 2H` map is two `H x H`
//! faces side by side) and knows nothing of the sphere. The sphere module supplies the faces
//! and the texel solid angles.
//!
//! | file | idea |
//! |---|---|
//! | [`basis`] | the non-standard Haar basis on a face; products of two basis functions |
//! | [`coefficient`] | the closed-form integral coefficient of `N` basis functions |
//! | [`selection`] | nonlinear approximation: which coefficients a tree keeps |
//! | [`tree`] | [`HaarTree`], the flat sparse quadtree with parent sums |
//! | [`transport`] | [`Transport`], the one factor that carries the weight |
//! | [`integral`] | [`product_integral`], the `N`-function tree traversal, depth limit |
//! | [`texel`] | [`TexelProduct`](texel::TexelProduct): the product of sparse factors through texels |
//! | [`triple`] | the `N = 3` fast paths: sparse on trees, dense `O(M)` |
//! | [`multiply`] | the product of `N` functions as a tree (reuse of fixed factors) |
//! | [`baseline`] | pixel domain (from pixel maps, or with inverse transforms) and pairwise products |
//!
//! # Conventions and normalisations
//!
//! * Face pixels `(i, j)`: row `i` down, column `j` right. Detail level `l = 0` is the
//!   coarsest (`2^l x 2^l` nodes of side `S >> l`), Sun 2006's "scale `j`"; quadrant
//!   `q = 2 row_bit + col_bit`.
//! * Coefficients are **orthonormal** ([`Normalization::Orthonormal`](crate::transform::Normalization)):
//!   a detail is `<f, psi>` with `psi = +-1/(S >> l)` on its block, the scaling coefficient the
//!   pixel sum over `S`. Selection compares these. Inside trees details are stored divided by
//!   the block side ([`tree`]).
//! * [`basis`] and [`coefficient`] also speak Sun 2006's continuous normalisation (unit
//!   square, amplitude `2^l`); the discrete functions are those over `S`.
//! * An **integral** is the weighted pixel sum `sum over faces and pixels of prod_k f_k(p)`, the
//!   weight folded into exactly one factor, the [`Transport`]. With solid angles as weights it
//!   is the integral over the sphere. Results are f64 whatever the sample type.
//!
//! # Errata in the sources
//!
//! Each checked against the definitions and the brute-force pixel sums of the tests
//! (`src/product/tests/`):
//!
//! 1. Sun and Mukherjee 2012 (the patent), the mother wavelets under FIG. 2: `psi_2^0` is printed as `-1` on
//!    both halves of the square (a negated box, not a wavelet); it is `+1` on one half and `-1`
//!    on the other. `psi_3^0` is printed as `-1` on the top-left and bottom-right quarters,
//!    which makes it `-(psi_1 psi_2)`, and with it the product rule of Sun 2006 (Lemma 5:
//!    `psi_1 x psi_2 = +2^j psi_3`) and the patent's own sign tables would fail. Here
//!    `D = H x V` ([`basis::product`] derives it; the transform's `c` agrees).
//! 2. Sun 2006 section 2.1.2, after the quad-coefficient theorem: "In case 2 ... the sign is
//!    that of the sub-region of the parent; in case 3, the product of the signs of two
//!    sub-regions": case 2 (two pairs of wavelets on one node) has no parent and is always
//!    positive; the one-parent sign belongs to case 3 and the two-parent product to case 4
//!    (the closed form of [`coefficient`] gives exactly these signs, tested exhaustively).
//!    Its "third-order" theorem writes `C_stuv` for the three-function coefficient `C_stu`.
//! 3. Sun and Mukherjee 2012 and Sun 2006 state the theorem's `+-2^(sum - 2 j0)` for functions normalised on
//!    the unit square and never say so; on the pixels of a `2^n` face (the orthonormal
//!    transform everyone computes) every coefficient of `N` functions carries `2^((2 - N) n)`
//!    ([`coefficient::discrete_integral_coefficient`]).
//! 4. Sun and Mukherjee 2012's `getWaveletProduct` (the listing at its lines 1908-1910) multiplies by
//!    `prod_{i=1}^{k-1} w_i.parentsum`: the bound is `m - 1` (the routine has no `k`).
//! 5. Sun 2006's `updateParents` (section 3.4.4) adds each node's value to `t_0 -> dc`, a
//!    field nodes do not have: it is the product tree's `T_0.dc` (the integral of the product
//!    is the sum of all node contributions). [`multiply`] computes the product bottom-up
//!    instead and is tested against the pointwise product.
//!
//! Not errata, though they look like ones: Sun 2006's `getProductIntegralDP`/`getW`
//! (section 3.4.3) mix integral coefficients (`T.phi`) and magnitudes (`T.psi`); its factors
//! `4^j` and `2^j` are exactly the continuous-normalisation conversions, and term by term the
//! routine is `integral::fold_excess` (which works in block means and steps, where those
//! factors are 1). The argument orders `(c, b, a)` against `(c, a, b)` in the two sources'
//! `getWaveletProduct` calls do not matter (the routine is symmetric in its last two
//! arguments). Vollick and Lessig's printed case-3 sums were not run verbatim here; [`triple`] derives
//! the three cases again and is tested against the general traversal and the pixel sum.
pub mod baseline;
pub mod basis;
pub mod coefficient;
pub mod integral;
pub mod kept;
pub mod multiply;
pub mod selection;
pub mod texel;
pub mod transport;
pub mod tree;
pub mod triple;

pub use integral::{Integral, IntegralOptions, product_integral};
pub use selection::{FaceLayout, Selection};
pub use transport::{Transport, WeightedPixels};
pub use tree::HaarTree;

#[cfg(test)]
mod tests;
