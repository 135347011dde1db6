//! Materials: how a surface turns the light arriving at a vertex into the light leaving it.
//!
//! | [`Brdf`] | `--brdf` | value `rho(w_i, w_o)` (per unit albedo) |
//! |---|---|---|
//! | [`Brdf::Lambert`] | `lambert` | `1 / pi` |
//! | [`Brdf::Phong`] | `phong:EXP` | `(EXP + 2) / (2 pi) max(0, r . w_i)^EXP`, `r = 2 (n . w_o) n - w_o` the mirror direction |
//! | [`Brdf::BlinnPhong`] | `blinn:EXP` | `(EXP + 8) / (8 pi) max(0, n . h)^EXP`, `h = (w_i + w_o) / |w_i + w_o|` |
//! | [`Brdf::Measured`] | `merl:FILE` | a MERL table's RGB value at the directions' half/difference angles ([`merl`](super::merl)) |
//!
//! `w_i` points toward the light, `w_o` toward the viewer, both unit; `0^0 = 1`, so Phong
//! with exponent 0 is `1 / pi` everywhere: Lambert with albedo 1. The cosine
//! `max(0, n . w_i)` and the visibility are not part of the BRDF: they are the transport's
//! ([`crate::TransportSet`]). A vertex's outgoing radiance is `albedo x` the integral of
//! lighting x transport x `rho` (per channel), so `albedo` is the diffuse colour of a
//! Lambertian surface and the specular colour of a glossy one. A measured BRDF has its own
//! colour ([`Brdf::channels`] is 3), which the albedo scales.
//!
//! **Lambert** leaves the integral as a per-vertex constant (`1 / pi`, [`Brdf::evaluate`]) and
//! what is left is the double product integral `<T_v, L>` of the transport and the lighting
//! (`fn@crate::shade`): the triple product with `rho` constant, whose tree has only scaling
//! coefficients.
//!
//! **Glossy BRDFs** depend on `w_i` and on `w_o` (fixed per vertex by the camera). In the
//! vertex's global frame `rho_v(w) = rho(w, w_o)` is a spherical map, the third factor of the
//! triple product `B_v = integral of T_v L rho_v` ([`triple_integral`](haarshift::product::triple::triple_integral)).
//! haarshift keeps one copy in a local frame ([`Brdf::local_map`]) and brings it to each vertex
//! ([`crate::material::orient`]), Alnasser 2008 chapter 4:
//! * **the reflection-vector parameterisation** (Sun 2006): a Phong lobe depends only on the
//!   angle between `w_i` and `r`, so its local copy is the lobe about +Y (the lat-long north
//!   pole) and one rotation taking `r` to +Y brings it to any vertex, whatever its normal and
//!   view;
//! * **view-dependent BRDFs** (Blinn-Phong): local copies with the normal at +Y and the
//!   viewer at azimuth 0 (in the Y-Z plane, on the +Z side), one per outgoing elevation
//!   ([`LocalTable`]); the viewer's azimuth about the normal is a yaw of that map and the
//!   normal's tilt a rotation. A measured BRDF (MERL) is isotropic and view-dependent: it
//!   takes the same table of local copies, of three channels.
//!
//! A measured BRDF is evaluated in the local frame of the normal and any tangent: it is
//! isotropic, so only the angles between `n`, `w_i` and `w_o` matter.

use std::fmt;
use std::path::Path;
use std::str::FromStr;
use std::sync::Arc;

use ndarray::ArrayView2;

use super::merl::MerlBrdf;
use crate::scene::mesh::cross;
use crate::{Error, Result};
use haarshift::sphere::LatLongMap;
use haarshift::sphere::latlong::direction;

/// The largest exponent accepted for Phong and Blinn-Phong: a Phong lobe of `1e4` is 1.3
/// degrees wide at half maximum, finer than any map haarshift shades with.
pub const MAX_EXPONENT: f64 = 1e4;

/// A surface's BRDF (`--brdf`); see the [module docs](self).
///
/// ```
/// use haarshift_relight::Brdf;
/// assert_eq!("lambert".parse::<Brdf>().unwrap(), Brdf::Lambert);
/// assert_eq!("phong:50".parse::<Brdf>().unwrap(), Brdf::Phong { exponent: 50.0 });
/// assert_eq!("blinn:20".parse::<Brdf>().unwrap().to_string(), "blinn:20");
/// assert!("phong".parse::<Brdf>().is_err());
/// assert!("phong:-1".parse::<Brdf>().is_err());
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Brdf {
    /// Lambertian: `1 / pi` in every direction.
    #[default]
    Lambert,
    /// Energy-normalised Phong: a lobe about the mirror direction.
    Phong {
        /// Shininess, `0..=MAX_EXPONENT`.
        exponent: f64,
    },
    /// Energy-normalised Blinn-Phong: a lobe of the half vector about the normal.
    BlinnPhong {
        /// Shininess, `0..=MAX_EXPONENT`.
        exponent: f64,
    },
    /// A measured isotropic BRDF, RGB: a MERL table (`merl:FILE` reads it).
    Measured(Arc<MerlBrdf>),
}

/// The choices `--brdf` accepts, for help texts and errors.
pub const BRDF_SYNTAX: &str = "lambert, phong:EXP, blinn:EXP, merl:FILE";

impl FromStr for Brdf {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        let bad = |why: String| Error::parameter("brdf", format!("{s:?}: {why}"));
        let (name, arg) = match s.split_once(':') {
            Some((name, arg)) => (name, Some(arg)),
            None => (s, None),
        };
        let exponent = || -> Result<f64> {
            let text = arg.ok_or_else(|| bad(format!("{name} needs an exponent: {name}:EXP")))?;
            let e: f64 = text
                .trim()
                .parse()
                .map_err(|_| bad(format!("the exponent {text:?} is not a number")))?;
            if !(0.0..=MAX_EXPONENT).contains(&e) {
                return Err(bad(format!(
                    "the exponent must be from 0 to {MAX_EXPONENT}"
                )));
            }
            Ok(e)
        };
        match name {
            "lambert" if arg.is_none() => Ok(Brdf::Lambert),
            "phong" => Ok(Brdf::Phong {
                exponent: exponent()?,
            }),
            "blinn" => Ok(Brdf::BlinnPhong {
                exponent: exponent()?,
            }),
            "merl" => match arg {
                Some(path) if !path.is_empty() => {
                    Ok(Brdf::Measured(Arc::new(MerlBrdf::read(Path::new(path))?)))
                }
                _ => Err(bad("merl needs a file: merl:FILE".into())),
            },
            _ => Err(bad(format!("expected one of {BRDF_SYNTAX}"))),
        }
    }
}

impl fmt::Display for Brdf {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Brdf::Lambert => f.write_str("lambert"),
            Brdf::Phong { exponent } => write!(f, "phong:{exponent}"),
            Brdf::BlinnPhong { exponent } => write!(f, "blinn:{exponent}"),
            Brdf::Measured(m) => match m.path() {
                Some(path) => write!(f, "merl:{}", path.display()),
                None => f.write_str("merl:(a computed table)"),
            },
        }
    }
}

/// `a . b`.
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The mirror direction of `w_o` about the normal `n`: `2 (n . w_o) n - w_o`.
///
/// ```
/// use haarshift_relight::material::brdf::mirror;
/// let r = mirror([0.0, 1.0, 0.0], [0.6, 0.8, 0.0]);
/// assert!((r[0] + 0.6).abs() < 1e-15 && (r[1] - 0.8).abs() < 1e-15 && r[2] == 0.0);
/// ```
pub fn mirror(n: [f64; 3], wo: [f64; 3]) -> [f64; 3] {
    let k = 2.0 * dot(n, wo);
    std::array::from_fn(|i| k * n[i] - wo[i])
}

/// Two unit vectors completing the unit `n` to a right-handed orthonormal frame `(t, b, n)`.
pub(crate) fn tangents(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    // Crossed with the axis least aligned with n, so the tangent never degenerates.
    let axis = if n[0].abs() < 0.6 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let b = cross(n, axis);
    let len = dot(b, b).sqrt();
    let b = b.map(|x| x / len);
    (cross(b, n), b)
}

/// `max(0, c)^e` with `0^0 = 1`.
fn lobe(c: f64, e: f64) -> f64 {
    if e == 0.0 { 1.0 } else { c.max(0.0).powf(e) }
}

impl Brdf {
    /// Whether the BRDF is Lambertian, so that it leaves the integral as a constant.
    pub fn is_lambert(&self) -> bool {
        matches!(self, Brdf::Lambert)
    }

    /// Whether the outgoing radiance depends on the eye (every BRDF but Lambert's), so that
    /// a render from another camera needs shading again.
    ///
    /// ```
    /// use haarshift_relight::Brdf;
    /// assert!(!Brdf::Lambert.is_view_dependent());
    /// assert!(Brdf::Phong { exponent: 10.0 }.is_view_dependent());
    /// ```
    pub fn is_view_dependent(&self) -> bool {
        !self.is_lambert()
    }

    /// Whether the BRDF depends on the incoming direction only through its angle to the
    /// mirror direction (the reflection-vector parameterisation: one local lobe about +Y).
    pub fn is_mirror_symmetric(&self) -> bool {
        matches!(self, Brdf::Phong { .. })
    }

    /// `rho(w_i, w_o)` per RGB channel (per unit albedo) at a vertex of unit normal `n`;
    /// every vector unit. See the [module docs](self) for the formulas.
    ///
    /// ```
    /// use haarshift_relight::Brdf;
    /// let n = [0.0, 1.0, 0.0];
    /// let up = Brdf::Phong { exponent: 10.0 }.evaluate(n, n, n); // w_i on the mirror direction
    /// assert!((up[0] - 12.0 / (2.0 * std::f64::consts::PI)).abs() < 1e-12);
    /// let flat = Brdf::Phong { exponent: 0.0 }.evaluate(n, [1.0, 0.0, 0.0], n);
    /// assert_eq!(flat, Brdf::Lambert.evaluate(n, [1.0, 0.0, 0.0], n));
    /// ```
    pub fn evaluate(&self, n: [f64; 3], wi: [f64; 3], wo: [f64; 3]) -> [f64; 3] {
        let value = match *self {
            Brdf::Measured(ref m) => {
                let (t, b) = tangents(n);
                let local = |w: [f64; 3]| [dot(t, w), dot(b, w), dot(n, w)];
                return m.evaluate(local(wi), local(wo));
            }
            Brdf::Lambert => std::f64::consts::FRAC_1_PI,
            Brdf::Phong { exponent } => {
                (exponent + 2.0) / std::f64::consts::TAU * lobe(dot(mirror(n, wo), wi), exponent)
            }
            Brdf::BlinnPhong { exponent } => {
                let h: [f64; 3] = std::array::from_fn(|i| wi[i] + wo[i]);
                let len = dot(h, h).sqrt();
                let c = if len > 0.0 { dot(n, h) / len } else { 0.0 };
                (exponent + 8.0) / (8.0 * std::f64::consts::PI) * lobe(c, exponent)
            }
        };
        [value; 3]
    }

    /// Channels of [`evaluate`](Self::evaluate) that differ and of [`local_map`](Self::local_map):
    /// 1 for the analytic BRDFs (the same in R, G and B), 3 for a measured one.
    ///
    /// ```
    /// use haarshift_relight::Brdf;
    /// assert_eq!(Brdf::BlinnPhong { exponent: 8.0 }.channels(), 1);
    /// ```
    pub fn channels(&self) -> usize {
        match self {
            Brdf::Measured(_) => 3,
            _ => 1,
        }
    }

    /// The BRDF's copy in its local frame, an `height x 2 height` lat-long map of
    /// [`channels`](Self::channels) channels sampled at texel centres: for a mirror-symmetric BRDF
    /// ([`is_mirror_symmetric`](Self::is_mirror_symmetric)) the lobe about +Y as a function of
    /// the angle to the mirror direction (`theta_o` does not matter); otherwise
    /// `rho(w, w_o)` for the normal +Y and the viewer `w_o = direction(theta_o, 0)` (elevation
    /// `theta_o` from the normal, on the +Z side).
    ///
    /// ```
    /// use haarshift_relight::Brdf;
    /// let map = Brdf::Phong { exponent: 20.0 }.local_map(16, 0.0).unwrap();
    /// assert_eq!(map.as_array().dim(), (16, 32, 1));
    /// // Brightest in the top row (about +Y), and every column alike.
    /// let a = map.as_array();
    /// assert!(a[[0, 0, 0]] > a[[1, 0, 0]] && a[[0, 0, 0]] == a[[0, 17, 0]]);
    /// ```
    pub fn local_map(&self, height: usize, theta_o: f64) -> Result<LatLongMap<f64>> {
        if !(0.0..=std::f64::consts::PI).contains(&theta_o) {
            return Err(Error::parameter(
                "outgoing elevation",
                format!("{theta_o} radians: must be from 0 to pi"),
            ));
        }
        let up = [0.0, 1.0, 0.0];
        let (wo, n) = if self.is_mirror_symmetric() {
            // The mirror direction of w_o = n about n is n itself: the lobe about +Y.
            (up, up)
        } else {
            (direction(theta_o, 0.0), up)
        };
        let channels = self.channels();
        Ok(LatLongMap::from_fn(height, channels, |w, out| {
            out.copy_from_slice(&self.evaluate(n, w, wo)[..channels])
        })?)
    }
}

/// Checks a per-vertex RGB albedo `(V, 3)`: finite and non-negative.
///
/// ```
/// use haarshift_relight::material::brdf::check_albedo;
/// use ndarray::array;
/// assert!(check_albedo(array![[0.5f32, 0.25, 1.0]].view()).is_ok());
/// assert!(check_albedo(array![[0.5f32, -0.25, 1.0]].view()).is_err());
/// assert!(check_albedo(array![[0.5f32, 0.25]].view()).is_err());
/// ```
pub fn check_albedo(albedo: ArrayView2<'_, f32>) -> Result<()> {
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
    Ok(())
}

/// The centre of elevation bin `k` when `per_quadrant` bins span `[0, pi/2]`.
fn elevation_of(k: usize, per_quadrant: usize) -> f64 {
    (k as f64 + 0.5) * std::f64::consts::FRAC_PI_2 / per_quadrant as f64
}

/// A view-dependent BRDF's local copies: one map per outgoing elevation
/// `theta_k = (k + 1/2) (pi / 2) / E`, `k = 0..2E` ([`Brdf::local_map`]): `E` above the surface
/// and as many below it, where a vertex seen from behind has its viewer (hidden in an image,
/// but the per-vertex radiance is the BRDF's own formula there too, as `relight reference`
/// evaluates it); a viewer at elevation `theta_o` uses the nearest, the thesis's "BRDF
/// transformed map corresponding to that direction". A mirror-symmetric BRDF needs one map,
/// whatever `E`.
///
/// ```
/// use haarshift_relight::material::brdf::{Brdf, LocalTable};
/// let t = LocalTable::new(&Brdf::BlinnPhong { exponent: 10.0 }, 16, 8).unwrap();
/// assert_eq!(t.len(), 16);
/// assert_eq!(t.nearest(0.0), 0);
/// assert_eq!(t.nearest(std::f64::consts::FRAC_PI_2 - 1e-9), 7);
/// assert_eq!(t.nearest(std::f64::consts::PI), 15);
/// assert_eq!(LocalTable::new(&Brdf::Phong { exponent: 10.0 }, 16, 8).unwrap().len(), 1);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct LocalTable {
    maps: Vec<LatLongMap<f64>>,
    /// Elevations per quadrant, `E`.
    per_quadrant: usize,
}

/// Outgoing elevations of a view-dependent BRDF's [`LocalTable`] unless asked otherwise: 5.6
/// degrees apart.
pub const DEFAULT_ELEVATIONS: usize = 16;

impl LocalTable {
    /// `brdf`'s local maps of `height` rows at `elevations` (1 to 1024) outgoing elevations
    /// above the surface, and as many below.
    pub fn new(brdf: &Brdf, height: usize, elevations: usize) -> Result<Self> {
        if !(1..=1024).contains(&elevations) {
            return Err(Error::parameter(
                "elevations",
                format!("{elevations}: expected 1 to 1024"),
            ));
        }
        let (count, per_quadrant) = if brdf.is_mirror_symmetric() {
            (1, 1)
        } else {
            (2 * elevations, elevations)
        };
        let maps = (0..count)
            .map(|k| brdf.local_map(height, elevation_of(k, per_quadrant)))
            .collect::<Result<_>>()?;
        Ok(LocalTable { maps, per_quadrant })
    }

    /// The number of maps.
    pub fn len(&self) -> usize {
        self.maps.len()
    }

    /// Whether the table is empty (never: it holds at least one map).
    pub fn is_empty(&self) -> bool {
        self.maps.is_empty()
    }

    /// The map of the elevation nearest `theta_o` (radians from the normal, clamped to
    /// `[0, pi]`).
    pub fn nearest(&self, theta_o: f64) -> usize {
        let bins = theta_o.clamp(0.0, std::f64::consts::PI) / std::f64::consts::FRAC_PI_2
            * self.per_quadrant as f64;
        (bins.floor() as usize).min(self.maps.len() - 1)
    }

    /// The outgoing elevation of map `k`, radians from the normal.
    pub fn elevation(&self, k: usize) -> f64 {
        elevation_of(k, self.per_quadrant)
    }

    /// Map `k`.
    pub fn map(&self, k: usize) -> &LatLongMap<f64> {
        &self.maps[k]
    }
}

#[cfg(test)]
#[path = "brdf_tests.rs"]
mod tests;
