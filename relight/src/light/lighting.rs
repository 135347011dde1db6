//! The lighting as the shading needs it: the environment's orthonormal Haar coefficients at
//! the working [`Parameterization`], RGB, rotated and truncated.
//!
//! **Pipeline.** [`Lighting::new`] takes the environment to the parameterisation, rotated by
//! `g(p) = f(R p)` ([`Environment::sphere_map`]: lat-long `N x 2N` by solid-angle-weighted
//! means, or a cube map `6 x N^2`), transforms each face to its orthonormal Haar pyramid and
//! keeps the coefficients a [`Selection`] picks (`--keep-light K`). [`Lighting::encode`] does
//! the same with the mapping into the parameterisation made once ([`SphereMapping`]: for a
//! cube map, the conversion's overlap table), for many lightings. [`Lighting::from_map`]
//! starts from a map already at the working resolution.
//!
//! **Selection on the RGB magnitude.** A coefficient is kept or dropped for all three channels
//! together, on `sqrt(r^2 + g^2 + b^2)` of its orthonormal channel values (the rule of
//! [`haarshift::product::selection`]): one set of positions serves every channel, and a grey
//! environment broadcast to RGB keeps what the grey map would. Every face's scaling
//! coefficient is always kept; `K` counts detail coefficients.
//!
//! **Layout.** The coefficients are a dense `(texels, 3)` array, zero where not kept, row `i`
//! the coefficient at Mallat index `i = (face, row, col)` row-major: face after face, each face
//! a full-depth [`pyramid`](haarshift::transform::pyramid), exactly the index of a vertex's sparse
//! transport ([`TransportSet`](crate::TransportSet)). So `<T_v, L>` is a sparse dot product
//! of the vertex's stored `(index, value)` pairs with these rows (`fn@crate::shade`). The values
//! are computed in f64; an f32 copy is kept for the fast path.
//!
//! **Channels.** A one-channel (grey) environment is broadcast to RGB; a map of any other
//! channel count than 1 or 3 is an error.

use ndarray::{Array2, Array4, ArrayView2};

use crate::light::environment::{Environment, SphereMapping};
use crate::{Error, Result};
use haarshift::Sample;
use haarshift::faces::integrate::layout;
use haarshift::faces::param::{Parameterization, SphereMap};
use haarshift::product::{HaarTree, Selection};
use haarshift::sphere::SphereRotation;

/// The environment's kept Haar coefficients, RGB; see the [module docs](self).
///
/// ```
/// use haarshift::product::Selection;
/// use haarshift_relight::Lighting;
/// use haarshift_relight::light::environment::Environment;
/// use haarshift::faces::param::{ParamKind, Parameterization};
/// use haarshift::sphere::{LatLongMap, SphereRotation};
/// let sky = LatLongMap::<f64>::from_fn(32, 3, |d, out| out.fill(1.0 + d[1].max(0.0))).unwrap();
/// let param = Parameterization::new(ParamKind::Cube, 8).unwrap();
/// let turn = SphereRotation::from_degrees(30.0, 0.0, 0.0).unwrap();
/// let light = Lighting::new(&Environment::new(sky), param, &turn, Selection::Largest(20)).unwrap();
/// assert_eq!(light.coefficients().dim(), (6 * 64, 3));
/// assert_eq!(light.kept(), 20);
/// // Row 0 is face 0's scaling coefficient: the pixel sum over S, never dropped.
/// assert!(light.coefficients()[[0, 0]] > 0.0);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Lighting {
    param: Parameterization,
    keep: Selection,
    kept: usize,
    coefficients: Array2<f64>,
    coefficients_f32: Array2<f32>,
}

impl Lighting {
    /// `env` rotated by `rotation` (`g(p) = f(R p)`), brought to `param`, transformed and
    /// truncated to `keep`.
    pub fn new(
        env: &Environment,
        param: Parameterization,
        rotation: &SphereRotation,
        keep: Selection,
    ) -> Result<Lighting> {
        Lighting::encode(
            env,
            &SphereMapping::new(env.map().height(), param)?,
            rotation,
            keep,
        )
    }

    /// [`new`](Self::new) with the mapping into the parameterisation made once
    /// ([`SphereMapping`]) and reused: what an animation or a benchmark calls per frame.
    ///
    /// ```
    /// use haarshift::product::Selection;
    /// use haarshift_relight::Lighting;
    /// use haarshift_relight::light::environment::{Environment, SphereMapping};
    /// use haarshift::faces::param::{ParamKind, Parameterization};
    /// use haarshift::sphere::{LatLongMap, SphereRotation};
    /// let env = Environment::new(LatLongMap::<f64>::from_fn(32, 3, |d, o| o.fill(1.0 + d[2])).unwrap());
    /// let cube = Parameterization::new(ParamKind::Cube, 8).unwrap();
    /// let mapping = SphereMapping::new(32, cube).unwrap();
    /// for step in 0..4 {
    ///     let turn = SphereRotation::from_degrees(90.0 * step as f64, 0.0, 0.0).unwrap();
    ///     let light = Lighting::encode(&env, &mapping, &turn, Selection::Largest(30)).unwrap();
    ///     assert_eq!(light, Lighting::new(&env, cube, &turn, Selection::Largest(30)).unwrap());
    /// }
    /// ```
    pub fn encode(
        env: &Environment,
        mapping: &SphereMapping,
        rotation: &SphereRotation,
        keep: Selection,
    ) -> Result<Lighting> {
        Lighting::from_map(&mapping.apply(env, rotation)?, keep)
    }

    /// The lighting of a map already at the working resolution (1 or 3 channels), truncated
    /// to `keep`.
    ///
    /// ```
    /// use haarshift::product::Selection;
    /// use haarshift_relight::Lighting;
    /// use haarshift::faces::param::{ParamKind, Parameterization, SphereMap};
    /// let p = Parameterization::new(ParamKind::LatLong, 4).unwrap();
    /// let grey = SphereMap::<f64>::from_fn(p, 1, |_, out| out[0] = 2.0).unwrap();
    /// let light = Lighting::from_map(&grey, Selection::All).unwrap();
    /// // A constant: each face's scaling coefficient is 2 x 16 / 4, every detail 0.
    /// assert_eq!(light.coefficients_f64().row(16).to_vec(), vec![8.0; 3]);
    /// assert_eq!(light.coefficients_f64().sum(), 2.0 * 3.0 * 8.0);
    /// ```
    pub fn from_map(map: &SphereMap<f64>, keep: Selection) -> Result<Lighting> {
        let param = map.param();
        let rgb = match map.channels() {
            3 => map.as_array().to_owned(),
            1 => {
                let (f, s, _, _) = map.as_array().dim();
                map.as_array()
                    .broadcast((f, s, s, 3))
                    .expect("one channel broadcasts to three")
                    .to_owned()
            }
            c => {
                return Err(Error::parameter(
                    "lighting",
                    format!("{c} channels: an environment must be grey (1) or RGB (3)"),
                ));
            }
        };
        let tree = HaarTree::<f64, 3>::from_pixels(rgb.view(), layout(param), keep)?;
        let coefficients = flatten(tree.to_coefficients());
        Ok(Lighting {
            param,
            keep,
            kept: tree.kept(),
            coefficients_f32: coefficients.mapv(|v| v as f32),
            coefficients,
        })
    }

    /// The parameterisation the coefficients live in.
    pub fn param(&self) -> Parameterization {
        self.param
    }

    /// The truncation applied.
    pub fn keep(&self) -> Selection {
        self.keep
    }

    /// Detail coefficients kept (scaling coefficients not counted).
    pub fn kept(&self) -> usize {
        self.kept
    }

    /// The coefficients, `(texels, 3)` in Mallat order, f32.
    pub fn coefficients(&self) -> ArrayView2<'_, f32> {
        self.coefficients_f32.view()
    }

    /// The coefficients, `(texels, 3)` in Mallat order, f64 (as computed).
    pub fn coefficients_f64(&self) -> ArrayView2<'_, f64> {
        self.coefficients.view()
    }

    /// The coefficients as RGB rows in the sample type `T`, each in four SIMD lanes (the
    /// shading's working copy), padded by
    /// [`pad_to_power_of_two`](crate::shade::lambert::pad_to_power_of_two).
    pub(crate) fn quads<T: Sample>(&self) -> Vec<T::Quad> {
        let mut rows: Vec<T::Quad> = self
            .coefficients
            .rows()
            .into_iter()
            .map(|r| T::rgb([r[0], r[1], r[2]].map(T::from_f64)))
            .collect();
        crate::shade::lambert::pad_to_power_of_two(&mut rows);
        rows
    }

    /// The lighting's tree (all kept coefficients, RGB), for the general product integrals.
    pub fn tree(&self) -> Result<HaarTree<f64, 3>> {
        let s = self.param.face_size();
        let faces = self
            .coefficients
            .view()
            .into_shape_with_order((self.param.faces(), s, s, 3))
            .expect("texels are faces x S x S");
        // Threshold 0 keeps exactly the non-zero (kept) coefficients.
        Ok(HaarTree::from_coefficients(
            faces,
            layout(self.param),
            Selection::Threshold(0.0),
        )?)
    }
}

/// `(faces, S, S, C)` to `(texels, C)`, row-major.
fn flatten<T: Clone>(a: Array4<T>) -> Array2<T> {
    let (f, s, _, c) = a.dim();
    a.as_standard_layout()
        .into_owned()
        .into_shape_with_order((f * s * s, c))
        .expect("standard layout")
}
