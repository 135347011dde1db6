//! Haar product algebra on sets of square faces: integrals and products of several functions
//! computed directly on their sparse 2D Haar coefficients (seeds 001 chapters 2-3, 000, 002).
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
//!
//! # Conventions and normalisations
//!
//! * Face pixels `(i, j)`: row `i` down, column `j` right. Detail level `l = 0` is the
//!   coarsest (`2^l x 2^l` nodes of side `S >> l`), seed 001's "scale `j`"; quadrant
//!   `q = 2 row_bit + col_bit`.
//! * Coefficients are **orthonormal** ([`Normalization::Orthonormal`](crate::transform::Normalization)):
//!   a detail is `<f, psi>` with `psi = +-1/(S >> l)` on its block, the scaling coefficient the
//!   pixel sum over `S`. Selection compares these. Inside trees details are stored divided by
//!   the block side ([`tree`]).
//! * [`basis`] and [`coefficient`] also speak seed 001's continuous normalisation (unit
//!   square, amplitude `2^l`); the discrete functions are those over `S`.
//! * An **integral** is the weighted pixel sum `sum over faces and pixels of prod_k f_k(p)`, the
//!   weight folded into exactly one factor, the [`Transport`]. With solid angles as weights it
//!   is the integral over the sphere. Results are f64 whatever the sample type.
//!
//! # Errata in the seeds (each found by checking against the brute-force pixel sum)
//!
//! Listed in the module docs where the corresponding formula is implemented; summary:
//! * Seed 001 section 3.3.1 (and 2.1.1) calls the scale-`j` functions "normalized" with
//!   amplitude `2^j`; they have unit `L2` norm on the unit square, which is what the theorem
//!   assumes, but the discrete orthonormal basis of a `2^n` face is that over `2^n`, so every
//!   integral coefficient of `N` functions on pixels carries `2^((2 - N) n)` (stated in neither
//!   seed).
pub mod baseline;
pub mod basis;
pub mod coefficient;
pub mod integral;
pub mod multiply;
pub mod selection;
pub mod transport;
pub mod tree;
pub mod triple;

pub use integral::{Integral, IntegralOptions, product_integral};
pub use selection::{FaceLayout, Selection};
pub use transport::{Transport, WeightedPixels};
pub use tree::HaarTree;

#[cfg(test)]
mod tests;
