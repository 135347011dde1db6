//! Bringing a BRDF into a vertex's frame: one local copy, rotated at render time (Alnasser 2008
//! chapter 4, sections 4.3-4.6).
//!
//! A vertex with unit normal `n`, seen from the unit direction `w_o` (toward the camera), needs
//! its BRDF as a function of the incoming direction in the global frame,
//! `rho_v(w) = rho(w, w_o)` ([`Brdf::evaluate`]): the third factor of its triple product. The
//! local copies are [`Brdf::local_map`]s held in a [`LocalTable`], and the rotation that brings
//! one to the vertex is `g(p) = f(R p)` ([`haarshift::sphere`]):
//!
//! * **Phong** (mirror-symmetric): one lobe about +Y; `R` is the rotation taking the mirror
//!   direction `r = 2 (n . w_o) n - w_o` to +Y about the axis `r x Y` ([`to_pole`]), so
//!   `rho_v(w) = f(R w)` is the lobe about `r`. This is the Sun 2006 reflection-vector
//!   parameterisation: one map serves every normal and view.
//! * **View-dependent BRDFs** (Blinn-Phong, measured): the table's map of the outgoing
//!   elevation nearest `w_o`'s (normal at +Y, viewer at azimuth 0); `R0 = to_pole(n)` takes the
//!   normal to +Y and `w_o` to `R0 w_o` of azimuth `phi0`; the map is first turned about the
//!   normal by the whole number of columns nearest `-phi0` (an exact Haar-domain yaw shift,
//!   [`sphere::yaw`](haarshift::sphere::yaw), for every method), then rotated by `Y(d) R0`: the
//!   tilt and the remaining yaw `d` (less than half a column) about the normal. Only the
//!   viewer's elevation is quantised (to the table's step); an isotropic BRDF needs nothing
//!   else. (A cache's bins stand for viewers at whole columns, so there `d` is 0.)
//!
//! [`BrdfRotation`] chooses how the tilt is computed:
//!
//! | `--brdf-rotation` | how | needs |
//! |---|---|---|
//! | `haar` | the chain rule on the local map's Haar coefficients from `--level L` ([`Method::Haar`]) | lat-long |
//! | `haar-cubic` | the higher-order chain rule, still on the coefficients ([`Method::HaarCubic`]) | lat-long |
//! | `spatial` | the local map rotated in the pixel domain, bilinear, then transformed ([`Method::Bilinear`]) | lat-long |
//! | `reference` | rotation by solid-angle integration over each target texel ([`Method::Reference`]) | lat-long |
//! | `direct` | no rotation: [`Brdf::evaluate`] at each global texel centre with the exact `n`, `w_o` | any |
//!
//! **Prepared once.** For `haar` and `haar-cubic` each local map is prepared for rotation when
//! the [`Orientation`] is made (its approximation at the level, its derivative fields: a
//! [`Rotator`]); a vertex's lobe is then one chain-rule rotation, the column turn read from the
//! prepared fields rather than computed (equal to turning the map and rotating it, tested).
//! A turn that the level's blocks would split, or a rotation that is itself a whole-column
//! yaw, goes through [`rotate_map`] instead.
//!
//! **Levels.** `--level L` is the sphere module's detail level: the map is rotated from its
//! approximation with detail levels `0..=L` (the thesis's level `L + 1`, faces `2^(L+1)` texels
//! wide), finer levels zero. The thesis found its level 5 (`L = 4`) slightly better than 6.

use ndarray::{Array2, ArrayViewMut2, Axis};

use crate::Mesh;
use crate::material::brdf::{Brdf, LocalTable, mirror};
use crate::{Error, Result};
use haarshift::faces::param::{ParamKind, Parameterization, SphereMap};
use haarshift::named_enum;
use haarshift::sphere::chain_rule::{Rotator, Scheme};
use haarshift::sphere::latlong::{angles, direction};
use haarshift::sphere::{
    LatLongMap, Method, SphereCoefficients, SphereOptions, SphereRotation, rotate_map,
};
use haarshift::transform::Normalization;
use haarshift::transform::pyramid::inverse_into;

named_enum! {
    /// How a BRDF is brought into a vertex's frame (`--brdf-rotation`); see the
    /// [module docs](self).
    #[derive(Default)]
    pub enum BrdfRotation ("brdf rotation") {
        #[default]
        /// The chain rule in the Haar domain.
        Haar = "haar",
        /// The higher-order chain rule in the Haar domain.
        HaarCubic = "haar-cubic",
        /// Bilinear rotation in the pixel domain.
        Spatial = "spatial",
        /// Solid-angle integration per texel.
        Reference = "reference",
        /// No rotation: the BRDF evaluated at every global texel direction.
        Direct = "direct",
    }
}

impl BrdfRotation {
    /// The sphere module's method for the tilt (`None`: [`BrdfRotation::Direct`]).
    fn method(self) -> Option<Method> {
        match self {
            BrdfRotation::Haar => Some(Method::Haar),
            BrdfRotation::HaarCubic => Some(Method::HaarCubic),
            BrdfRotation::Spatial => Some(Method::Bilinear),
            BrdfRotation::Reference => Some(Method::Reference),
            BrdfRotation::Direct => None,
        }
    }
}

/// A vertex's shading frame: the unit normal and the unit direction toward the viewer.
///
/// ```
/// use haarshift_relight::material::orient::Frame;
/// let f = Frame::new([0.0, 2.0, 0.0], [0.0, 1.0, 1.0]).unwrap();
/// assert!((f.outgoing[1] - 0.5f64.sqrt()).abs() < 1e-15);
/// assert!(Frame::new([0.0; 3], [0.0, 1.0, 0.0]).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Unit normal.
    pub normal: [f64; 3],
    /// Unit direction from the surface toward the viewer.
    pub outgoing: [f64; 3],
}

/// `v / |v|`, or `None` when `v` is zero or not finite.
pub(crate) fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (len.is_finite() && len > 0.0).then(|| v.map(|x| x / len))
}

impl Frame {
    /// The frame of `normal` and `outgoing` (any non-zero finite lengths; normalised here).
    pub fn new(normal: [f64; 3], outgoing: [f64; 3]) -> Result<Frame> {
        let bad = |what: &str, v: [f64; 3]| {
            Error::parameter("frame", format!("the {what} {v:?} has no direction"))
        };
        Ok(Frame {
            normal: unit(normal).ok_or_else(|| bad("normal", normal))?,
            outgoing: unit(outgoing).ok_or_else(|| bad("outgoing direction", outgoing))?,
        })
    }

    /// The mirror direction of the viewer about the normal.
    pub fn mirror(&self) -> [f64; 3] {
        mirror(self.normal, self.outgoing)
    }
}

/// Every vertex's unit mirror direction of the view from `eye`, `(V, 3)` (the normal where
/// the eye sits on the vertex, so every row is a direction).
///
/// ```
/// use haarshift_relight::{Mesh, material::orient::mirror_directions};
/// use ndarray::array;
/// let m = Mesh::new(array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]],
///                   vec![[0, 1, 2]], None).unwrap();
/// let r = mirror_directions(&m, [0.0, 1.0, 1.0]);
/// assert!((r[[0, 1]] - 0.5f64.sqrt()).abs() < 1e-15 && (r[[0, 2]] + 0.5f64.sqrt()).abs() < 1e-15);
/// assert_eq!(mirror_directions(&m, [0.0; 3]).row(0).to_vec(), vec![0.0, 1.0, 0.0]);
/// ```
pub fn mirror_directions(mesh: &Mesh, eye: [f64; 3]) -> Array2<f64> {
    let (p, n) = (mesh.positions(), mesh.normals());
    let mut out = Array2::zeros((mesh.vertex_count(), 3));
    for (v, mut row) in out.rows_mut().into_iter().enumerate() {
        let normal = [n[[v, 0]], n[[v, 1]], n[[v, 2]]];
        let view = std::array::from_fn(|k| eye[k] - p[[v, k]]);
        let r = Frame::new(normal, view)
            .ok()
            .and_then(|f| unit(f.mirror()))
            .unwrap_or(normal);
        row.assign(&ndarray::arr1(&r));
    }
    out
}

/// The rotation `R` with `R a = +Y` (for unit `a`), about the axis `a x Y` (the shortest
/// turn; a half turn about X when `a = -Y`). With `g(p) = f(R p)`, what `f` has at +Y, `g` has
/// at `a`.
///
/// ```
/// use haarshift_relight::material::orient::to_pole;
/// let a = [0.6, 0.0, 0.8];
/// let y = to_pole(a).apply(a);
/// assert!(y[0].abs() < 1e-15 && (y[1] - 1.0).abs() < 1e-15 && y[2].abs() < 1e-15);
/// ```
pub fn to_pole(a: [f64; 3]) -> SphereRotation {
    let c = a[1].clamp(-1.0, 1.0);
    let s = (a[0] * a[0] + a[2] * a[2]).sqrt();
    if s < 1e-12 {
        return if c > 0.0 {
            SphereRotation::identity()
        } else {
            SphereRotation::from_matrix([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]])
                .expect("a half turn is a rotation")
        };
    }
    // Rodrigues about k = (a x Y) / |a x Y| = (-a_z, 0, a_x) / s, by the angle acos(c).
    let k = [-a[2] / s, 0.0, a[0] / s];
    let (sin, t) = (s, 1.0 - c);
    let m = [
        [c + t * k[0] * k[0], -sin * k[2], t * k[0] * k[2]],
        [sin * k[2], c, -sin * k[0]],
        [t * k[2] * k[0], sin * k[0], c + t * k[2] * k[2]],
    ];
    SphereRotation::from_matrix(m).expect("Rodrigues' formula gives a rotation")
}

/// A BRDF ready to be brought into vertex frames: its local table, the parameterisation of
/// the result and the method; see the [module docs](self).
///
/// ```
/// use haarshift_relight::Brdf;
/// use haarshift_relight::material::orient::{BrdfRotation, Frame, Orientation};
/// use haarshift::faces::param::{ParamKind, Parameterization};
/// let param = Parameterization::new(ParamKind::LatLong, 32).unwrap();
/// let phong = Brdf::Phong { exponent: 10.0 };
/// let frame = Frame::new([0.0, 1.0, 0.0], [0.0, 0.8, 0.6]).unwrap();
/// let direct = Orientation::new(&phong, param, BrdfRotation::Direct, None, 16).unwrap();
/// let haar = Orientation::new(&phong, param, BrdfRotation::Haar, None, 16).unwrap();
/// let (a, b) = (direct.lobe(&frame).unwrap(), haar.lobe(&frame).unwrap());
/// let peak = a.as_array().iter().fold(0.0f64, |m, v| m.max(*v));
/// let err = (&a.as_array() - &b.as_array()).iter().fold(0.0f64, |m, v| m.max(v.abs()));
/// assert!(err < 0.05 * peak);
/// ```
#[derive(Clone, Debug)]
pub struct Orientation {
    brdf: Brdf,
    table: LocalTable,
    param: Parameterization,
    rotation: BrdfRotation,
    options: SphereOptions,
    /// For the Haar methods, each table map at the working level prepared for rotation once.
    prepared: Option<Prepared>,
}

/// The table's maps at the working level prepared for rotation ([`Rotator`]).
#[derive(Clone, Debug)]
struct Prepared {
    rotators: Rotators,
    /// The working level's block width in full-resolution columns.
    block: usize,
    scheme: Scheme,
}

/// Prepared rotations in the precision they run in.
#[derive(Clone, Debug)]
enum Rotators {
    F64(Vec<Rotator<f64>>),
    /// From the f64 maps rounded to f32 ([`Orientation::in_f32`]).
    F32(Vec<Rotator<f32>>),
}

impl Orientation {
    /// `brdf` brought into frames of `param` by `rotation` from the sphere module's detail
    /// level `level` (`None`: the finest), with `elevations` local maps for a view-dependent
    /// BRDF. The rotations need a lat-long `param`; a level needs a rotation.
    pub fn new(
        brdf: &Brdf,
        param: Parameterization,
        rotation: BrdfRotation,
        level: Option<usize>,
        elevations: usize,
    ) -> Result<Self> {
        let method = rotation.method();
        if method.is_some() && param.kind() != ParamKind::LatLong {
            return Err(Error::parameter(
                "brdf rotation",
                format!(
                    "{rotation} rotates lat-long maps: precompute with --param latlong, or use \
                     --brdf-rotation direct with a cube map"
                ),
            ));
        }
        let h = param.face_size();
        let levels = h.trailing_zeros() as usize;
        if let Some(l) = level {
            if method.is_none() {
                return Err(Error::parameter(
                    "level",
                    "direct evaluation rotates nothing: a level needs --brdf-rotation haar, \
                     spatial or reference",
                ));
            }
            if h < 2 || l >= levels {
                return Err(Error::parameter(
                    "level",
                    format!(
                        "{l}: a {h}-row map has detail levels 0..={} (thesis levels 1..={levels})",
                        levels.max(1) - 1
                    ),
                ));
            }
        }
        let table = if method.is_some() {
            LocalTable::new(brdf, h, elevations)?
        } else {
            // Direct evaluation reads no local map; one tiny map keeps the type simple.
            LocalTable::new(brdf, 2, 1)?
        };
        let prepared = match method.and_then(Method::scheme) {
            Some(scheme) => {
                // Level L works on the 2^(L+1)-row approximation.
                let block = level.map_or(1, |l| h >> (l + 1));
                let rotators = (0..table.len())
                    .map(|e| Rotator::new(&table.map(e).downsample(block)?, scheme))
                    .collect::<haarshift::Result<_>>()?;
                Some(Prepared {
                    rotators: Rotators::F64(rotators),
                    block,
                    scheme,
                })
            }
            None => None,
        };
        Ok(Orientation {
            brdf: brdf.clone(),
            table,
            param,
            rotation,
            options: SphereOptions {
                method: method.unwrap_or_default(),
                level,
                ..SphereOptions::default()
            },
            prepared,
        })
    }

    /// The same orientation with its chain-rule rotations (`haar`, `haar-cubic`) run in f32,
    /// the local maps rounded to f32 first: eight lanes to a vector and the profile's taps
    /// gathered ([`haarshift::sphere::chain_rule`]), for a renderer that shades in f32 anyway.
    /// The lobes stay within a few 1e-7 of the f64 ones' peak (tested); the other methods
    /// are unchanged.
    ///
    /// ```
    /// use haarshift_relight::Brdf;
    /// use haarshift_relight::material::orient::{BrdfRotation, Frame, Orientation};
    /// use haarshift::faces::param::{ParamKind, Parameterization};
    /// let param = Parameterization::new(ParamKind::LatLong, 32).unwrap();
    /// let phong = Brdf::Phong { exponent: 10.0 };
    /// let frame = Frame::new([0.0, 1.0, 0.0], [0.0, 0.8, 0.6]).unwrap();
    /// let f64 = Orientation::new(&phong, param, BrdfRotation::Haar, None, 16).unwrap();
    /// let f32 = f64.clone().in_f32().unwrap();
    /// let (a, b) = (f64.lobe(&frame).unwrap(), f32.lobe(&frame).unwrap());
    /// let err = (&a.as_array() - &b.as_array()).iter().fold(0.0f64, |m, v| m.max(v.abs()));
    /// assert!(err > 0.0 && err < 1e-6 * a.as_array().iter().fold(0.0f64, |m, v| m.max(*v)));
    /// ```
    pub fn in_f32(mut self) -> Result<Self> {
        if let Some(p) = &mut self.prepared {
            let rotators = (0..self.table.len())
                .map(|e| {
                    let map = self.table.map(e).downsample(p.block)?;
                    let map = LatLongMap::new(map.as_array().mapv(|v| v as f32))?;
                    Rotator::new(&map, p.scheme)
                })
                .collect::<haarshift::Result<_>>()?;
            p.rotators = Rotators::F32(rotators);
        }
        Ok(self)
    }

    /// The parameterisation of the lobes.
    pub fn param(&self) -> Parameterization {
        self.param
    }

    /// The BRDF.
    pub fn brdf(&self) -> &Brdf {
        &self.brdf
    }

    /// The method.
    pub fn rotation(&self) -> BrdfRotation {
        self.rotation
    }

    /// The table entry and the column turn `frame` uses (see the [module docs](self)); for a
    /// mirror-symmetric BRDF `(0, 0)`.
    pub fn quantise(&self, frame: &Frame) -> Result<(usize, usize)> {
        self.plan(frame).map(|(entry, turn, _)| (entry, turn))
    }

    /// The viewer, in the tilted frame (normal at +Y), that table entry `entry` turned by
    /// `turn` columns stands for: the inverse of [`quantise`](Self::quantise).
    pub fn outgoing_of(&self, entry: usize, turn: usize) -> [f64; 3] {
        let columns = 2 * self.param.face_size();
        direction(
            self.table.elevation(entry),
            -(turn as f64) * std::f64::consts::TAU / columns as f64,
        )
    }

    /// For a rotated view-dependent BRDF, the table entry and the column turn the frame
    /// uses, and the rotation `Y(d) R0` (the tilt and the rest of the turn); for Phong entry 0,
    /// no turn and the rotation to the mirror direction.
    fn plan(&self, frame: &Frame) -> Result<(usize, usize, SphereRotation)> {
        if self.brdf.is_mirror_symmetric() {
            let r = unit(frame.mirror()).ok_or_else(|| {
                Error::parameter("frame", "the mirror direction is not a direction")
            })?;
            return Ok((0, 0, to_pole(r)));
        }
        let tilt = to_pole(frame.normal);
        let (theta_o, phi0) = angles(tilt.apply(frame.outgoing));
        let columns = 2 * self.param.face_size();
        let exact = -phi0 * columns as f64 / std::f64::consts::TAU;
        let turn = exact.round();
        // f turned by `turn` columns is f(Y(turn) w); the rest of the turn joins the tilt:
        // g(p) = f(Y(exact) R0 p) = f_turned(Y(exact - turn) R0 p).
        let rest = SphereRotation::from_degrees((exact - turn) * 360.0 / columns as f64, 0.0, 0.0)?;
        let rotation = rest.after(&tilt);
        Ok((
            self.table.nearest(theta_o),
            (turn as i64).rem_euclid(columns as i64) as usize,
            rotation,
        ))
    }

    /// The BRDF in the global frame of `frame`, `rho(w, w_o)` per texel of the
    /// parameterisation (as many channels as the BRDF has).
    pub fn lobe(&self, frame: &Frame) -> Result<SphereMap<f64>> {
        match self.rotated(frame)? {
            Lobe::Map(map) => Ok(map),
            Lobe::Pyramid(c) => {
                let c = c.zero_padded(self.param.face_size())?;
                Ok(SphereMap::from_lat_long(&c.to_map()?)?)
            }
        }
    }

    /// [`lobe`](Self::lobe)'s values (the same bits) as channel planes, `channels x texels`
    /// with the texels face by face, row by row (the layout the glossy shading multiplies),
    /// written into `planes`. A Haar rotation's pyramid is inverted channel by channel into
    /// `work` and copied into its faces: no map is made, and the buffers are reused from call
    /// to call.
    pub(crate) fn lobe_planes(
        &self,
        frame: &Frame,
        planes: &mut Vec<f64>,
        work: &mut LobeWork,
    ) -> Result<()> {
        let s = self.param.face_size();
        let texels = self.param.texels();
        match self.rotated(frame)? {
            Lobe::Map(map) => {
                let channels = map.as_array().dim().3;
                planes.resize(channels * texels, 0.0);
                for ((f, i, j, c), v) in map.as_array().indexed_iter() {
                    planes[c * texels + (f * s + i) * s + j] = *v;
                }
            }
            Lobe::Pyramid(c) => {
                let c = if c.height() < s { c.zero_padded(s)? } else { c };
                let channels = c.channels();
                planes.resize(channels * texels, 0.0);
                work.pixels.resize(texels, 0.0);
                for (k, plane) in planes.chunks_exact_mut(texels).enumerate() {
                    let mut pixels = ArrayViewMut2::from_shape((s, 2 * s), &mut work.pixels)
                        .expect("a lat-long map is s x 2s");
                    let pyramid = c.as_array().index_axis_move(Axis(0), k);
                    inverse_into(
                        pyramid,
                        c.levels(),
                        Normalization::Average,
                        pixels.view_mut(),
                        &mut work.scratch,
                    )?;
                    // The lat-long faces are the map's left and right halves.
                    for (f, face) in plane.chunks_exact_mut(s * s).enumerate() {
                        for (i, row) in face.chunks_exact_mut(s).enumerate() {
                            row.copy_from_slice(&work.pixels[i * 2 * s + f * s..][..s]);
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// The BRDF in `frame`: a Haar rotation's pyramid (an `m x 2m` lat-long pyramid, `m` the
    /// working level's height), or any other method's map.
    fn rotated(&self, frame: &Frame) -> Result<Lobe> {
        if self.rotation == BrdfRotation::Direct {
            let (n, wo) = (frame.normal, frame.outgoing);
            let channels = self.brdf.channels();
            return Ok(Lobe::Map(SphereMap::from_fn(
                self.param,
                channels,
                |w, out| {
                    out.copy_from_slice(&self.brdf.evaluate(n, w, wo)[..channels]);
                },
            )?));
        }
        let (entry, turn, rotation) = self.plan(frame)?;
        let local = self.table.map(entry);
        let columns = 2 * self.param.face_size();
        // The prepared map, read turned, unless the level's blocks split the turn or the
        // rotation is itself a whole-column yaw (which rotate_map does exactly).
        if let Some(Prepared {
            rotators, block, ..
        }) = &self.prepared
            && turn % block == 0
            && rotation.whole_column_yaw(columns).is_none()
        {
            let turn = turn / block;
            return Ok(Lobe::Pyramid(match rotators {
                Rotators::F64(r) => r[entry].rotate_turned(&rotation, turn)?,
                Rotators::F32(r) => {
                    let c = r[entry].rotate_turned(&rotation, turn)?;
                    SphereCoefficients::from_array(c.as_array().mapv(f64::from))?
                }
            }));
        }
        let turned;
        let source = if turn == 0 {
            local
        } else {
            let yaw = SphereRotation::from_degrees(turn as f64 * 360.0 / columns as f64, 0.0, 0.0)?;
            turned = rotate_map(local, &yaw, &self.options)?.map;
            &turned
        };
        Ok(Lobe::Map(SphereMap::from_lat_long(
            &rotate_map(source, &rotation, &self.options)?.map,
        )?))
    }
}

/// A BRDF brought into a frame, before it is laid out as texels.
enum Lobe {
    /// The Haar coefficients of a prepared rotation.
    Pyramid(SphereCoefficients<f64>),
    /// Texel values.
    Map(SphereMap<f64>),
}

/// Scratch buffers of [`Orientation::lobe_planes`], reused from call to call.
#[derive(Debug, Default)]
pub(crate) struct LobeWork {
    /// One channel of the lat-long map.
    pixels: Vec<f64>,
    /// The inverse transform's own buffers.
    scratch: Vec<f64>,
}

#[cfg(test)]
#[path = "orient_tests.rs"]
mod tests;
