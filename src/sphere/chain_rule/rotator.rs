//! The whole rotation ([`rotate`]) and a [`Rotator`] that keeps its workspace for many
//! rotations of maps of one shape.

use crate::sphere::{LatLongMap, SphereCoefficients, SphereRotation};
use crate::{Error, Result, Sample};

use super::fields::DifferenceFields;
use super::gradient::{Scheme, SourceGradient};
use super::mean::{pole_weight, row_solid_angles, sampled_integral, set_mean};

/// The Haar coefficients of `g = f(R p)` at the resolution of `approx` (the approximation of
/// `f` at resolution `L + 1`, an `m x 2m` map): a full `m x 2m` pyramid holding detail
/// levels `0..=L`. Embed it in a larger pyramid with
/// [`SphereCoefficients::zero_padded`].
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereRotation, chain_rule::{Scheme, rotate}};
/// let f = LatLongMap::<f64>::from_fn(16, 1, |d, out| out[0] = 1.0 + d[0]).unwrap();
/// let r = SphereRotation::from_degrees(0.0, 30.0, 0.0).unwrap();
/// let g = rotate(&f, &r, Scheme::Linear).unwrap().to_map().unwrap();
/// // g = 1 + x(R p) and a pitch about X keeps x: g is f, to the method's accuracy.
/// let err = (&g.as_array() - &f.as_array()).iter().fold(0.0f64, |a, v| a.max(v.abs()));
/// assert!(err < 0.02);
/// ```
pub fn rotate<T: Sample>(
    approx: &LatLongMap<T>,
    rotation: &SphereRotation,
    scheme: Scheme,
) -> Result<SphereCoefficients<T>> {
    Rotator::new(approx, scheme)?.rotate(rotation)
}

/// One source map prepared for any number of rotations: its derivative fields (step 1 of
/// the [module docs](super)) and the integral every rotation keeps (step 6) are computed once,
/// so a rotation costs the chain rule and the filters alone. This is what a renderer needs
/// to bring one BRDF into every vertex's frame. A zonal source (constant along every row,
/// such as a lobe about the pole, [`SourceGradient::is_zonal`]) takes a shorter path with
/// the same result: one angle per pre-image and a one-dimensional interpolation.
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereRotation, chain_rule::{Rotator, Scheme, rotate}};
/// let lobe = LatLongMap::<f64>::from_fn(32, 1, |d, out| out[0] = d[1].max(0.0).powi(20)).unwrap();
/// let rotator = Rotator::new(&lobe, Scheme::Linear).unwrap();
/// assert!(rotator.is_zonal());
/// for pitch in [10.0, 50.0, 120.0] {
///     let r = SphereRotation::from_degrees(30.0, pitch, 0.0).unwrap();
///     let diff = &rotator.rotate(&r).unwrap().as_array() - &rotate(&lobe, &r, Scheme::Linear).unwrap().as_array();
///     assert!(diff.iter().all(|v| v.abs() < 1e-12));
/// }
/// ```
#[derive(Clone, Debug)]
pub struct Rotator<T> {
    pub(super) grad: SourceGradient<T>,
    /// Per channel, what step 6 keeps: the solid-angle integral, or (cubic) the sampled one.
    pub(super) integral: Vec<f64>,
    /// [`row_solid_angles`] of the source's rows, which every rotation's step 6 weighs by.
    pub(super) solid: Vec<f64>,
}

impl<T: Sample> Rotator<T> {
    /// `approx` (an `m x 2m` map, `m` a power of two from 2 on) prepared for rotation by
    /// `scheme`.
    pub fn new(approx: &LatLongMap<T>, scheme: Scheme) -> Result<Self> {
        let m = approx.height();
        if m < 2 || !m.is_power_of_two() {
            return Err(Error::shape(
                &[m, 2 * m],
                "the Haar method needs a height that is a power of two from 2 on",
            ));
        }
        Ok(Rotator {
            grad: SourceGradient::with_scheme(approx, scheme),
            integral: match scheme {
                Scheme::Linear => approx.energy(),
                Scheme::Cubic => sampled_integral(approx),
            },
            solid: row_solid_angles(m),
        })
    }

    /// Whether the source is zonal ([`SourceGradient::is_zonal`]).
    pub fn is_zonal(&self) -> bool {
        self.grad.is_zonal()
    }

    /// The coefficients of `g = f(R p)`, as [`rotate`].
    pub fn rotate(&self, rotation: &SphereRotation) -> Result<SphereCoefficients<T>> {
        self.rotate_turned(rotation, 0)
    }

    /// The coefficients of `g = f_k(R p)`, with `f_k` the source turned by `turn` columns
    /// ([`yaw_pixels`](crate::sphere::yaw::yaw_pixels)`(f, turn)`): the turn is exact (the fields
    /// are read `turn` columns on, with the taps and weights the turned source would give)
    /// and costs nothing.
    ///
    /// ```
    /// use haarshift::sphere::{LatLongMap, SphereRotation, chain_rule::{Rotator, Scheme}, yaw::yaw_pixels};
    /// let f = LatLongMap::<f64>::from_fn(16, 1, |d, out| out[0] = (d[0] + 2.0 * d[1]).exp()).unwrap();
    /// let r = SphereRotation::from_degrees(10.0, 40.0, -20.0).unwrap();
    /// let turned = Rotator::new(&f, Scheme::Cubic).unwrap().rotate_turned(&r, 5).unwrap();
    /// let want = Rotator::new(&yaw_pixels(&f, 5), Scheme::Cubic).unwrap().rotate(&r).unwrap();
    /// let diff = &turned.as_array() - &want.as_array();
    /// assert!(diff.iter().all(|v| v.abs() < 1e-13));
    /// ```
    pub fn rotate_turned(
        &self,
        rotation: &SphereRotation,
        turn: usize,
    ) -> Result<SphereCoefficients<T>> {
        let fields = DifferenceFields::from_gradient(&self.grad, rotation, turn % self.grad.n);
        let mut coeffs = fields.to_coefficients()?;
        let pole = match self.grad.scheme {
            Scheme::Linear => 0.0,
            Scheme::Cubic => pole_weight(self.grad.m),
        };
        set_mean(&mut coeffs, &self.integral, pole, &self.solid)?;
        Ok(coeffs)
    }
}
