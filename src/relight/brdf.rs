//! Materials: how a surface turns the light arriving at a vertex into the light leaving it.
//!
//! **Lambert** (this module's one material). A Lambertian surface reflects the constant BRDF
//! `rho = albedo / pi` (per channel), so the outgoing radiance at vertex `v` is
//! `B_v = albedo_v / pi x integral of L(w) V(v, w) max(0, n_v . w) dw`. The BRDF does not
//! depend on the direction, so it leaves the integral as a per-vertex constant
//! ([`Brdf::vertex_factors`]) and what is left is the double product integral `<T_v, L>` of the
//! transport and the lighting ([`super::shade`]).
//!
//! **Where a glossy BRDF enters.** A glossy BRDF depends on the incoming direction (and on
//! the outgoing one, fixed per vertex by the view): in the vertex's frame it is a function on
//! the sphere, brought into the global frame by a rotation (seed 004 chapter 4; seed 001's
//! one shared copy rotated per vertex), then a Haar tree `rho_v` in the same parameterisation
//! as `T_v` and `L`. It is then the third factor of the triple product
//! `B_v = integral of T_v L rho_v` ([`triple_integral`](crate::product::triple::triple_integral)
//! with `T_v` the [`Transport`](crate::product::Transport), `L` and `rho_v` plain
//! [`HaarTree`](crate::product::HaarTree)s; or [`product_integral`](crate::product::product_integral)
//! with more factors, for occluders). The Lambertian case is that same triple product with
//! `rho_v` the constant `albedo_v / pi`, whose tree has only scaling coefficients: the triple
//! integral then equals `albedo_v / pi x <T_v, L>` exactly (tested), which is why the shading
//! can multiply a double product by a constant here. For just-in-time radiance transfer with a
//! glossy BRDF and fixed view, `T_v x rho_v` is one fixed factor
//! ([`multiply::product`](crate::product::multiply::product)), formed once, and a change of
//! lighting is again one sparse dot product per vertex.

use ndarray::{Array2, ArrayView2};

use crate::named::named_enum;
use crate::{Error, Result};

named_enum! {
    /// A surface's BRDF (`--brdf`); see the [module docs](self).
    ///
    /// ```
    /// use haarshift::relight::Brdf;
    /// assert_eq!("lambert".parse::<Brdf>().unwrap(), Brdf::Lambert);
    /// assert!("phong".parse::<Brdf>().is_err());
    /// ```
    #[derive(Default)]
    pub enum Brdf ("brdf") {
        #[default]
        /// Lambertian: `albedo / pi` in every direction.
        Lambert = "lambert",
    }
}

impl Brdf {
    /// The per-vertex constant that multiplies `<T_v, L>`, `(V, 3)`, from the per-vertex RGB
    /// albedo `(V, 3)` (finite, non-negative): for [`Brdf::Lambert`], `albedo / pi`.
    ///
    /// ```
    /// use haarshift::relight::Brdf;
    /// use ndarray::array;
    /// let f = Brdf::Lambert.vertex_factors(array![[0.5f32, 0.25, 1.0]].view()).unwrap();
    /// assert!((f[[0, 0]] - 0.5 / std::f32::consts::PI).abs() < 1e-8);
    /// assert!(Brdf::Lambert.vertex_factors(array![[0.5f32, -0.25, 1.0]].view()).is_err());
    /// assert!(Brdf::Lambert.vertex_factors(array![[0.5f32, 0.25]].view()).is_err());
    /// ```
    pub fn vertex_factors(self, albedo: ArrayView2<'_, f32>) -> Result<Array2<f32>> {
        if albedo.ncols() != 3 {
            return Err(Error::shape(
                albedo.shape(),
                "the albedo must be (vertices, 3), one RGB triple per vertex",
            ));
        }
        if let Some((at, v)) = albedo
            .indexed_iter()
            .find(|(_, v)| !(v.is_finite() && **v >= 0.0))
        {
            return Err(Error::parameter(
                "albedo",
                format!("{v} at vertex {}: must be finite and non-negative", at.0),
            ));
        }
        Ok(match self {
            Brdf::Lambert => albedo.mapv(|a| a / std::f32::consts::PI),
        })
    }
}
