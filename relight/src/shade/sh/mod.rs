//! Shading from spherical-harmonic transfer ([`ShTransfer`], Microsoft 2003's low-frequency
//! precomputed radiance transfer), the baseline all-frequency relighting is compared against.
//!
//! **Shading.** The lighting's coefficients are its own projection,
//! `l_i = sum_t L(w_t) Y_i(w_t) dOmega_t` ([`SphericalHarmonics::project`], which weights by
//! the solid angle once, in any parameterisation), and a Lambertian vertex of albedo `a`
//! reflects `R_v = a / pi x sum_i l_i t_i` ([`shade_sh`]). The double sum is the integral of
//! lighting x transfer with both cut to `B` bands: exact (to the texel quadrature) when the
//! lighting has no degree `>= B`, a low-pass approximation otherwise: sharp shadows and small
//! bright lights are what it loses, and what the Haar path keeps.
//!
//! **Glossy baseline (`--basis sh` with `phong:EXP`).** A Phong vertex reflects
//! `B_v = albedo_v x int T_v(w) L(w) rho_v(w) dw`, `rho_v(w) = (e + 2) / (2 pi)
//! max(0, r_v . w)^e` the energy-normalised lobe about the vertex's mirror direction `r_v`. The
//! lobe is zonal about `r_v`, so its coefficients need no rotation machinery:
//! `rho_lm = lambda_l Y_lm(r_v)` with the lobe's Funk-Hecke factors `lambda_l`
//! ([`phong_factors`], exact;
//! [`SphericalHarmonics::rotated_zonal`]). With all three factors cut to `B` bands the integral
//! is the triple product `B_v = albedo_v x sum_ijk G_ijk t_i l_j rho_k`, `G` the real Gaunt
//! coefficients ([`Gaunt`]). [`PhongSh`] holds the Gaunt table and the factors (made once);
//! each frame contracts the lighting once, `M^c_ik = sum_j G_ijk l^c_j` (`B^2 x B^2` per
//! channel, one pass over the sparse table), and each vertex costs one evaluation of the
//! harmonics at `r_v` and `t^T M^c rho_v`: `B^4` multiply-adds per channel, 4,096 at `B = 8`
//! against `B^2 = 64` for a Lambertian vertex. With exponent 0 (and `0^0 = 1`) the lobe is the
//! constant `1 / pi` and a Phong vertex is a Lambertian vertex of albedo 1 (tested to `1e-12`).
//! For inputs of degree below `B` the triple product is the integral of the three functions
//! exactly (tested against their pixel-domain integral to `1e-13`); for real ones it converges
//! as `B` grows (Phong 10, transfer `max(0, y)` and a smooth light: relative error `4.2e-4` at
//! `B = 8`, `3.1e-7` at 16, about `B^-10`).
//!
//! **What it cannot do.** Only zonal lobes, a function of the angle to one axis: Lambert and
//! Phong. Blinn-Phong's lobe about the half vector and measured (MERL) BRDFs are not zonal about
//! any direction, and a rotation of a general `B`-band function costs `B^3` per vertex with
//! Wigner matrices, not implemented here: they are refused with [`non_zonal_material`]. And the
//! cut to `B <= 16` bands blurs sharp lobes: a Phong 200 lobe (9.5 degrees wide at half
//! maximum) needs far more bands than the transfer stores, which is the Haar path's case.

use std::f64::consts::PI;

use ndarray::{Array2, ArrayView1, ArrayView2, Axis, Zip};
use rayon::prelude::*;

use std::time::Instant;

use super::lambert::{add_channels, bounced_sets};
use super::{
    FrameMapping, FrameSpec, Preparation, Radiance, Shader, ShaderSpec, Shading, ShadingInput,
    Timing, seconds,
};
use crate::material::orient::mirror_directions;
use crate::sh_transfer::{ShTransfer, check_bands};
use crate::{Brdf, Mesh};
use crate::{Error, Result};
use haarshift::sphere::gaunt::Gaunt;
use haarshift::sphere::harmonics::{SphericalHarmonics, phong_factors};

/// Lambertian shading from spherical-harmonic transfer: `R_v = albedo_v / pi x sum_i l_i t_i`
/// per channel, `(V, 3)`. `albedo` is `(V, 3)`; `lighting` holds the lighting's coefficients
/// `(B^2, C)` with `C` 1 (gray, the same in every channel) or 3, e.g.
/// [`SphericalHarmonics::project`] of the rotated environment. Both must be finite.
///
/// ```
/// use haarshift_relight::sh_transfer::ShTransfer;
/// use haarshift_relight::shade::sh::shade_sh;
/// use ndarray::{Array2, array};
/// let pi = std::f64::consts::PI;
/// // One upward vertex that sees its whole hemisphere: t_00 = int cos Y_00 = pi / (2 sqrt pi).
/// let t = ShTransfer::new(1, array![[(pi.sqrt() / 2.0) as f32]]).unwrap();
/// // Radiance 1 everywhere: l_00 = 4 pi Y_00 = 2 sqrt pi.
/// let l = array![[2.0 * pi.sqrt()]];
/// let r = shade_sh(&t, Array2::from_elem((1, 3), 0.5).view(), l.view()).unwrap();
/// assert!((r[[0, 1]] - 0.5).abs() < 1e-6); // albedo x irradiance pi / pi
/// ```
pub fn shade_sh(
    transfer: &ShTransfer,
    albedo: ArrayView2<'_, f32>,
    lighting: ArrayView2<'_, f64>,
) -> Result<Array2<f32>> {
    check_shading(transfer, albedo, lighting)?;
    let mut out = Array2::<f32>::zeros((transfer.vertex_count(), 3));
    Zip::from(out.rows_mut())
        .and(transfer.coefficients().rows())
        .and(albedo.rows())
        .par_for_each(|mut o, t, a| {
            let r = lambert(t, a, lighting);
            o.iter_mut().zip(r).for_each(|(o, r)| *o = r as f32);
        });
    Ok(out)
}

/// The checks every shading makes: `albedo` `(V, 3)` and `lighting` `(B^2, 1 or 3)` for the
/// transfer's `V` vertices and `B` bands, both finite.
fn check_shading(
    transfer: &ShTransfer,
    albedo: ArrayView2<'_, f32>,
    lighting: ArrayView2<'_, f64>,
) -> Result<()> {
    let v = transfer.vertex_count();
    let n = transfer.bands() * transfer.bands();
    if albedo.dim() != (v, 3) {
        return Err(Error::shape(
            albedo.shape(),
            format!("the albedo must be ({v}, 3), one RGB row per vertex"),
        ));
    }
    let (rows, channels) = lighting.dim();
    if rows != n || !(channels == 1 || channels == 3) {
        return Err(Error::shape(
            lighting.shape(),
            format!(
                "the lighting's coefficients must be ({n}, 1) or ({n}, 3) for {} bands",
                transfer.bands()
            ),
        ));
    }
    check_finite(albedo)?;
    check_finite(lighting)
}

/// An [`Error::NonFinite`] naming the first NaN or infinity of `values`.
fn check_finite<T: Copy + Into<f64>>(values: ArrayView2<'_, T>) -> Result<()> {
    match values
        .indexed_iter()
        .map(|(at, v)| (at, (*v).into()))
        .find(|(_, v): &(_, f64)| !v.is_finite())
    {
        Some(((r, c), v)) => Err(crate::Error::from(haarshift::Error::NonFinite {
            value: v,
            index: vec![r, c],
        })),
        None => Ok(()),
    }
}

/// One Lambertian vertex, `albedo / pi x sum_i l_i t_i` per channel, in `f64`.
fn lambert(
    transfer: ArrayView1<'_, f32>,
    albedo: ArrayView1<'_, f32>,
    lighting: ArrayView2<'_, f64>,
) -> [f64; 3] {
    let channels = lighting.ncols();
    std::array::from_fn(|c| {
        let l = lighting.column(c.min(channels - 1));
        let sum: f64 = transfer
            .iter()
            .zip(l)
            .map(|(&ti, &li)| f64::from(ti) * li)
            .sum();
        f64::from(albedo[c]) / PI * sum
    })
}

/// The refusal of a material that is not one zonal lobe (Blinn-Phong, whose lobe about the
/// normal is not a function of one angle to a fixed axis, and measured BRDFs): the spherical
/// harmonics baseline shades Lambert and Phong only. Its message, for `material` =
/// `blinn:50`: `invalid basis: sh shades zonal lobes only (lambert, phong:EXP), not blinn:50;
/// use --basis haar`.
///
/// ```
/// use haarshift_relight::shade::sh::non_zonal_material;
/// let e = non_zonal_material("merl:gold.binary");
/// assert_eq!(
///     e.to_string(),
///     "invalid basis: sh shades zonal lobes only (lambert, phong:EXP), not merl:gold.binary; \
///      use --basis haar"
/// );
/// ```
pub fn non_zonal_material(material: &str) -> Error {
    Error::parameter(
        "basis",
        format!(
            "sh shades zonal lobes only (lambert, phong:EXP), not {material}; use --basis haar"
        ),
    )
}

/// The glossy spherical-harmonics baseline for one Phong exponent and `B` bands, made once
/// (its Gaunt table and the lobe's factors) and used for every frame; see the
/// [module docs](self).
///
/// ```
/// use haarshift_relight::sh_transfer::ShTransfer;
/// use haarshift_relight::shade::sh::PhongSh;
/// use ndarray::{Array2, array};
/// let pi = std::f64::consts::PI;
/// let phong = PhongSh::new(2, 0.0).unwrap(); // exponent 0: the constant 1 / pi
/// let t = ShTransfer::new(2, array![[(pi.sqrt() / 2.0) as f32, 0.0, 1.0, 0.0]]).unwrap();
/// let l = array![[2.0 * pi.sqrt()], [0.0], [0.0], [0.0]]; // radiance 1 everywhere
/// let mirror = array![[0.0, 1.0, 0.0]];
/// let r = phong.shade(&t, Array2::ones((1, 3)).view(), l.view(), mirror.view(), 1).unwrap();
/// // 1 / pi x the integral of the cosine over the upper hemisphere (pi); t_10 meets no light.
/// assert!((r[[0, 0]] - 1.0).abs() < 1e-6);
/// ```
#[derive(Clone, Debug)]
pub struct PhongSh {
    sh: SphericalHarmonics,
    gaunt: Gaunt,
    lambda: Vec<f64>,
}

impl PhongSh {
    /// The baseline for `bands` bands (1 to `MAX_SH_BANDS`) and the energy-normalised Phong
    /// lobe `(e + 2) / (2 pi) max(0, r . w)^e`, `e = exponent` from 0 to
    /// [`MAX_PHONG_EXPONENT`](haarshift::sphere::harmonics::MAX_PHONG_EXPONENT).
    pub fn new(bands: usize, exponent: f64) -> Result<Self> {
        check_bands(bands)?;
        Ok(PhongSh {
            sh: SphericalHarmonics::new(bands)?,
            gaunt: Gaunt::new(bands)?,
            lambda: phong_factors(exponent, bands)?,
        })
    }

    /// The number of bands `B`.
    pub fn bands(&self) -> usize {
        self.sh.bands()
    }

    /// The outgoing radiance `(V, 3)`: vertices `0..glossy` Phong,
    /// `albedo x sum_ijk G_ijk t_i l_j rho_k` with `rho` the lobe turned to the vertex's row of
    /// `mirror`, the rest Lambertian as [`shade_sh`] (in `f64`). `transfer` must have this
    /// baseline's bands; `albedo` `(V, 3)` and `lighting` `(B^2, 1 or 3)` as for [`shade_sh`];
    /// `mirror` `(V, 3)`, one unit direction per vertex (every row is checked; rows
    /// `glossy..` are not used), finite, of length 1 within `1e-6`; `glossy <= V`.
    pub fn shade(
        &self,
        transfer: &ShTransfer,
        albedo: ArrayView2<'_, f32>,
        lighting: ArrayView2<'_, f64>,
        mirror: ArrayView2<'_, f64>,
        glossy: usize,
    ) -> Result<Array2<f64>> {
        let bands = self.bands();
        if transfer.bands() != bands {
            return Err(Error::shape(
                transfer.coefficients().shape(),
                format!(
                    "the transfer has {} bands, the Phong baseline {bands}",
                    transfer.bands()
                ),
            ));
        }
        check_shading(transfer, albedo, lighting)?;
        let v = transfer.vertex_count();
        if mirror.dim() != (v, 3) {
            return Err(Error::shape(
                mirror.shape(),
                format!("the mirror directions must be ({v}, 3), one row per vertex"),
            ));
        }
        check_finite(mirror)?;
        if let Some((row, r)) = mirror
            .rows()
            .into_iter()
            .enumerate()
            .find(|(_, r)| (r.dot(r) - 1.0).abs() > 1e-6)
        {
            return Err(Error::parameter(
                "mirror direction",
                format!(
                    "vertex {row} has length {} (must be a unit vector)",
                    r.dot(&r).sqrt()
                ),
            ));
        }
        if glossy > v {
            return Err(Error::parameter(
                "glossy vertices",
                format!("{glossy} of {v} vertices"),
            ));
        }
        // M^c_ik = sum_j G_ijk l^c_j, once per frame, interleaved [i][k][c]: per vertex then
        // u = sum_i t_i M_i.. (one contiguous axpy per i) and B^c = albedo^c sum_k u_kc rho_k.
        let n = bands * bands;
        let channels = lighting.ncols();
        let mut m = vec![0.0; n * n * channels];
        let mut single = vec![0.0; n * n];
        for (c, column) in lighting.columns().into_iter().enumerate() {
            self.gaunt.contract(&column.to_vec(), &mut single);
            for (at, value) in single.iter().enumerate() {
                m[at * channels + c] = *value;
            }
        }
        let mut out = Array2::<f64>::zeros((v, 3));
        out.axis_iter_mut(Axis(0))
            .into_par_iter()
            .zip(transfer.coefficients().axis_iter(Axis(0)))
            .zip(albedo.axis_iter(Axis(0)))
            .zip(mirror.axis_iter(Axis(0)))
            .enumerate()
            .for_each_init(
                || (vec![0.0; n * channels], vec![0.0; n]),
                |(u, rho), (vertex, (((mut o, t), a), r))| {
                    let result = if vertex < glossy {
                        self.sh.rotated_zonal(&self.lambda, [r[0], r[1], r[2]], rho);
                        u.fill(0.0);
                        for (&ti, row) in t.iter().zip(m.chunks_exact(n * channels)) {
                            let ti = f64::from(ti);
                            u.iter_mut().zip(row).for_each(|(u, mik)| *u += ti * mik);
                        }
                        let mut sums = [0.0; 3];
                        for (uk, rk) in u.chunks_exact(channels).zip(rho.iter()) {
                            sums.iter_mut().zip(uk).for_each(|(s, x)| *s += x * rk);
                        }
                        std::array::from_fn(|c| f64::from(a[c]) * sums[c.min(channels - 1)])
                    } else {
                        lambert(t, a, lighting)
                    };
                    o.iter_mut().zip(result).for_each(|(o, r)| *o = r);
                },
            );
        Ok(out)
    }
}

/// [`PhongSh::new`]`(transfer.bands(), exponent)` then [`PhongSh::shade`]: one frame of the
/// glossy spherical-harmonics baseline (an animation makes the [`PhongSh`] once instead).
pub fn shade_sh_glossy(
    transfer: &ShTransfer,
    albedo: ArrayView2<'_, f32>,
    lighting: ArrayView2<'_, f64>,
    exponent: f64,
    mirror: ArrayView2<'_, f64>,
    glossy: usize,
) -> Result<Array2<f64>> {
    PhongSh::new(transfer.bands(), exponent)?.shade(transfer, albedo, lighting, mirror, glossy)
}

/// The spherical-harmonics baseline behind [`Shader`]: the stored transfer
/// (its first [`ShaderSpec::sh_bands`] bands), each frame's lighting projected onto the same
/// bands and shaded by [`shade_sh`], or for Phong by [`PhongSh`] (made once) toward the
/// frame's eye. Blinn-Phong and measured BRDFs are refused ([`non_zonal_material`]).
#[derive(Debug)]
pub struct ShShader {
    transfer: ShTransfer,
    /// The bounced sum's transfer (Sloan, Kautz and Snyder 2002's interreflected transfer),
    /// each with the channel it lights (`None`: a grey set, all); Lambertian only.
    bounced: Vec<(ShTransfer, Option<usize>)>,
    albedo: Array2<f32>,
    mesh: Mesh,
    object_vertices: usize,
    mapping: FrameMapping,
    phong: Option<PhongSh>,
    prepare_seconds: f64,
}

impl ShShader {
    /// `input`'s transfer, cut to `spec`'s bands, for `spec`'s material.
    pub(crate) fn new(spec: &ShaderSpec, input: &ShadingInput<'_>) -> Result<Self> {
        let start = Instant::now();
        let set = input.transport(spec.method)?;
        let stored = set.sh().ok_or_else(|| {
            input.refusal(
                "the cache holds no spherical-harmonic transfer: precompute it with --sh-bands B",
            )
        })?;
        let cut = |stored: &ShTransfer| match spec.sh_bands {
            None => Ok(stored.clone()),
            Some(bands) if bands <= stored.bands() => ShTransfer::new(
                bands,
                stored
                    .coefficients()
                    .slice(ndarray::s![.., ..bands * bands])
                    .to_owned(),
            ),
            Some(bands) => Err(Error::parameter(
                "sh-bands",
                format!("{bands}: the transfer stores {} bands", stored.bands()),
            )),
        };
        let transfer = cut(stored)?;
        // A bounced sum has the transport's bands (the cache checks it).
        let bounced = bounced_sets(input)
            .filter_map(|(set, channel)| set.sh().map(|t| Ok((cut(t)?, channel))))
            .collect::<Result<_>>()?;
        let phong = match &spec.material.brdf {
            Brdf::Lambert => None,
            Brdf::Phong { exponent } => Some(PhongSh::new(transfer.bands(), *exponent)?),
            other => return Err(non_zonal_material(&other.to_string())),
        };
        Ok(ShShader {
            transfer,
            bounced,
            albedo: input.albedo.to_owned(),
            mesh: input.mesh.clone(),
            object_vertices: input.object_vertices,
            mapping: FrameMapping::new(set.param(), spec.light_rotation),
            phong,
            prepare_seconds: seconds(start),
        })
    }
}

impl Shader for ShShader {
    fn shade(&mut self, frame: &FrameSpec<'_>) -> Result<Shading> {
        let start = Instant::now();
        let bands = self.transfer.bands();
        let map = self.mapping.apply(frame)?;
        let lighting = SphericalHarmonics::new(bands)?.project(&map);
        let encode_seconds = seconds(start);
        let start = Instant::now();
        let albedo = self.albedo.view();
        let radiance = match &self.phong {
            None => {
                let mut sum = shade_sh(&self.transfer, albedo, lighting.view())?;
                for (transfer, channel) in &self.bounced {
                    let part = shade_sh(transfer, albedo, lighting.view())?;
                    add_channels(&mut sum, &part, *channel);
                }
                Radiance::F32(sum)
            }
            Some(phong) => {
                let mirror = mirror_directions(&self.mesh, frame.eye()?);
                Radiance::F64(phong.shade(
                    &self.transfer,
                    albedo,
                    lighting.view(),
                    mirror.view(),
                    self.object_vertices,
                )?)
            }
        };
        Ok(Shading {
            radiance,
            timing: Timing::unrotated(encode_seconds, seconds(start)),
            description: format!(
                "spherical harmonics, {bands} bands ({} coefficients){}",
                bands * bands,
                match self.bounced.len() {
                    0 => "",
                    _ => ", with the bounced transfer",
                }
            ),
            maps: None,
            light_coefficients: Some(bands * bands),
        })
    }

    fn preparation(&self) -> Preparation {
        Preparation {
            seconds: self.prepare_seconds,
            filled: None,
        }
    }
}

#[cfg(test)]
mod tests;
