//! The ground truth of relighting, independent of every Haar path: direct quadrature over the
//! lighting's texels with one ray per texel.
//!
//! For a vertex `v` (albedo `a_v`, unit normal `n_v`, position `p_v`) of BRDF `rho` under a
//! lat-long lighting map `L` of `N x 2N` texels, the outgoing radiance toward the eye `e` is
//!
//! `R_v = a_v x sum_t L(t) V(v, t) max(0, n_v . w_t) rho(w_t, w_o,v) dOmega_t`,
//! `w_o,v = (e - p_v) / |e - p_v|`,
//!
//! the sum over every texel `t` with centre direction `w_t` and exact solid angle `dOmega_t`
//! ([`sphere::latlong`](haarshift::sphere::latlong)), `V(v, t)` one ray through the texel centre
//! from the origin of [`RayOrigins`] (`p_v + eps n_v`, moved off creases and contact), through the
//! [`Occlusion`] trait, and `rho` evaluated analytically at `(w_t, w_o,v)` in the vertex's own
//! frame ([`Brdf::evaluate`]): no local copy, no rotation. For a Lambertian vertex `rho = 1/pi`
//! leaves the sum as `a_v / pi x sum_t L(t) V(v, t) max(0, n_v . w_t) dOmega_t`, which is
//! what is computed (the eye is not needed). [`ReferenceOptions::object_vertices`] gives the
//! BRDF to the scene's objects only, the ground plane after them staying Lambertian
//! ([`Scene::object_vertices`](crate::Scene::object_vertices)).
//!
//! This is issue 11's contract for checking: `L` is the environment brought
//! to `N x 2N` by solid-angle-weighted means and rotated
//! ([`Environment::lat_long`](crate::light::environment::Environment::lat_long)); `N` need not be a
//! power of two. Nothing here touches the transport, the Haar transform or a product integral,
//! so the Haar path at full coefficients can be checked against it (the two cast the same rays
//! in the same `f32` arithmetic, so their visibility agrees bit for bit).
//!
//! Texels below the horizon (`n_v . w_t <= 0`) and texels where the lighting is 0 in every
//! channel cast no ray. Sums are `f64`; vertices run in parallel (rayon).

use std::time::Instant;

use ndarray::{Array2, ArrayView2, Axis};
use rayon::prelude::*;

use super::{
    FrameSpec, Preparation, Radiance, Shader, ShaderSpec, Shading, ShadingInput, Timing, seconds,
};
use crate::SceneBvh;
use crate::precompute::cast::f32x3;
use crate::precompute::origin::RayOrigins;
use crate::precompute::raycast::Occlusion;
use crate::scene::mesh::dot;
use crate::{Brdf, Mesh};
use crate::{Error, Result};
use haarshift::progress::Task;
use haarshift::sphere::LatLongMap;
use haarshift::sphere::latlong::{direction, pixel_centre, pixel_solid_angle};

pub mod interreflection;
pub mod path_trace;

/// How to compute the reference.
///
/// ```
/// use haarshift_relight::{Brdf, ReferenceOptions};
/// let o = ReferenceOptions::default();
/// assert!(!o.progress && o.brdf == Brdf::Lambert && o.eye.is_none());
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReferenceOptions {
    /// Report progress to the installed [reporter](haarshift::progress) (nothing is drawn without one).
    pub progress: bool,
    /// The objects' BRDF.
    pub brdf: Brdf,
    /// The camera's position, which fixes every vertex's outgoing direction: required unless
    /// `brdf` is Lambertian.
    pub eye: Option<[f64; 3]>,
    /// Vertices `0..object_vertices` have `brdf`, the rest (the ground plane) are Lambertian;
    /// `None`: every vertex has `brdf`.
    pub object_vertices: Option<usize>,
}

impl ReferenceOptions {
    /// The eye when the BRDF needs one, checked against `vertices`' count.
    fn checked_eye(&self, vertices: usize) -> Result<Option<[f64; 3]>> {
        if let Some(objects) = self.object_vertices
            && objects > vertices
        {
            return Err(Error::parameter(
                "object vertices",
                format!("{objects}, but the mesh has {vertices} vertices"),
            ));
        }
        if self.brdf.is_lambert() || self.object_vertices == Some(0) {
            return Ok(None);
        }
        match self.eye {
            None => Err(Error::parameter(
                "eye",
                format!(
                    "the BRDF {} depends on the outgoing direction: give the camera position",
                    self.brdf
                ),
            )),
            Some(e) if e.iter().any(|x| !x.is_finite()) => {
                Err(Error::parameter("eye", format!("{e:?}: must be finite")))
            }
            Some(e) => Ok(Some(e)),
        }
    }
}

/// What the reference computation did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceReport {
    /// Rays cast.
    pub rays: u64,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// A texel of the lighting that can contribute: its centre direction, solid angle and
/// radiance (RGB).
struct LitTexel {
    /// Row-major index `i x 2N + j` in the map.
    index: usize,
    direction: [f64; 3],
    ray: [f32; 3],
    solid_angle: f64,
    radiance: [f64; 3],
}

/// The texels of `lighting` with radiance in some channel; gray maps are spread to RGB.
fn lit_texels(lighting: &LatLongMap<f64>) -> Result<Vec<LitTexel>> {
    let (h, w, ch) = lighting.as_array().dim();
    if !(ch == 1 || ch == 3) {
        return Err(Error::parameter(
            "lighting",
            format!("{ch} channels: the reference takes gray or RGB lighting"),
        ));
    }
    let map = lighting.as_array();
    let mut out = Vec::new();
    for i in 0..h {
        let solid_angle = pixel_solid_angle(h, i);
        for j in 0..w {
            let radiance = std::array::from_fn(|c| map[[i, j, c.min(ch - 1)]]);
            if radiance == [0.0; 3] {
                continue;
            }
            let (theta, phi) = pixel_centre(h, i, j);
            let d = direction(theta, phi);
            out.push(LitTexel {
                index: i * w + j,
                direction: d,
                ray: f32x3(d),
                solid_angle,
                radiance,
            });
        }
    }
    Ok(out)
}

/// Every vertex's outgoing radiance `(V, 3)` by direct quadrature over `lighting`'s texels
/// (see the [module docs](self)); `albedo` is `(V, 3)`, `lighting` a lat-long map of any height
/// `N`, gray or RGB, already rotated. A BRDF other than Lambert needs `options.eye`.
///
/// ```
/// use haarshift_relight::{Mesh, ReferenceOptions, SceneBvh, reference};
/// use haarshift::sphere::LatLongMap;
/// use ndarray::{Array2, array};
/// // One upward triangle under a sky of radiance 1: irradiance pi, so R = albedo.
/// let m = Mesh::new(array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]],
///                   vec![[0, 1, 2]], None).unwrap();
/// let sky = LatLongMap::<f64>::from_fn(24, 1, |_, o| o[0] = 1.0).unwrap();
/// let albedo = Array2::from_elem((3, 3), 0.5f32);
/// let (r, report) = reference(&m, &SceneBvh::new(&m), albedo.view(), &sky,
///                             &ReferenceOptions::default()).unwrap();
/// assert!((r[[0, 0]] - 0.5).abs() < 2e-3); // the quadrature: 0.5 x 1.0021
/// assert_eq!(report.rays, 3 * 12 * 48); // the upper half of 24 x 48 texels, per vertex
/// // Phong 1 seen from straight above vertex 0: at normal incidence it also reflects albedo.
/// let phong = ReferenceOptions { brdf: "phong:1".parse().unwrap(), eye: Some([0.0, 5.0, 0.0]),
///                                ..Default::default() };
/// let (r, _) = reference(&m, &SceneBvh::new(&m), albedo.view(), &sky, &phong).unwrap();
/// assert!((r[[0, 0]] - 0.5).abs() < 2e-3);
/// ```
pub fn reference(
    mesh: &Mesh,
    occlusion: &impl Occlusion,
    albedo: ArrayView2<'_, f32>,
    lighting: &LatLongMap<f64>,
    options: &ReferenceOptions,
) -> Result<(Array2<f64>, ReferenceReport)> {
    quadrature(mesh, albedo, lighting, options, |_, origin, t| {
        !occlusion.occluded(origin, t.ray, f32::INFINITY)
    })
}

/// The quadrature of [`reference`] with `visible(v, origin, texel)` answering for each texel
/// above vertex `v`'s horizon whether its ray from `origin` escapes.
fn quadrature(
    mesh: &Mesh,
    albedo: ArrayView2<'_, f32>,
    lighting: &LatLongMap<f64>,
    options: &ReferenceOptions,
    visible: impl Fn(usize, [f32; 3], &LitTexel) -> bool + Sync,
) -> Result<(Array2<f64>, ReferenceReport)> {
    let vertices = mesh.vertex_count();
    if albedo.dim() != (vertices, 3) {
        return Err(Error::shape(
            albedo.shape(),
            format!("the albedo must be ({vertices}, 3), one RGB row per vertex"),
        ));
    }
    let eye = options.checked_eye(vertices)?;
    let objects = options.object_vertices.unwrap_or(vertices);
    let start = Instant::now();
    let texels = lit_texels(lighting)?;
    let origins = RayOrigins::new(mesh);
    let bar = Task::begin(options.progress, "reference (rays)", vertices);
    let mut out = Array2::<f64>::zeros((vertices, 3));
    let rays: u64 = out
        .axis_iter_mut(Axis(0))
        .into_par_iter()
        .enumerate()
        .map(|(v, mut radiance)| {
            let (origin, n) = origins.origin_and_normal(v);
            // The glossy vertex's view, or None for a Lambertian one.
            let view = match eye {
                Some(e) if v < objects => Some(outgoing(mesh, v, n, e)),
                _ => None,
            };
            let o = f32x3(origin);
            let mut sum = [0.0f64; 3];
            let mut rays = 0u64;
            for t in &texels {
                let cos = dot(n, t.direction);
                if cos <= 0.0 {
                    continue;
                }
                rays += 1;
                if visible(v, o, t) {
                    let w = cos * t.solid_angle;
                    let rho = match view {
                        Some(wo) => options.brdf.evaluate(n, t.direction, wo),
                        None => [1.0; 3],
                    };
                    sum.iter_mut()
                        .zip(t.radiance)
                        .zip(rho)
                        .for_each(|((s, l), r)| *s += l * w * r);
                }
            }
            for c in 0..3 {
                let a = f64::from(albedo[[v, c]]);
                // A Lambertian sum still lacks its 1 / pi.
                radiance[c] = match view {
                    Some(_) => a * sum[c],
                    None => a / std::f64::consts::PI * sum[c],
                };
            }
            bar.advance(1);
            rays
        })
        .sum();
    let report = ReferenceReport {
        rays,
        seconds: start.elapsed().as_secs_f64(),
    };
    Ok((out, report))
}

/// Every vertex's visibility over the texels of an `N x 2N` lat-long map, one bit per texel
/// (set: above the vertex's horizon and the ray through the texel centre escapes), cast once
/// so that [`fn@reference`] can be evaluated under many lightings, BRDFs and views without
/// casting again. The rays are [`fn@reference`]'s own, so its quadrature over these bits equals
/// [`fn@reference`] bit for bit.
///
/// ```
/// use haarshift_relight::{Mesh, ReferenceOptions, SceneBvh, reference};
/// use haarshift_relight::shade::reference::ReferenceVisibility;
/// use haarshift::sphere::LatLongMap;
/// use ndarray::{Array2, array};
/// let m = Mesh::new(array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]],
///                   vec![[0, 1, 2]], None).unwrap();
/// let bvh = SceneBvh::new(&m);
/// let sky = LatLongMap::<f64>::from_fn(24, 3, |d, o| o.fill(1.0 + d[0])).unwrap();
/// let albedo = Array2::from_elem((3, 3), 0.5f32);
/// let bits = ReferenceVisibility::new(&m, &bvh, 24, false).unwrap();
/// let o = ReferenceOptions::default();
/// assert_eq!(bits.reference(&m, albedo.view(), &sky, &o).unwrap().0,
///            reference(&m, &bvh, albedo.view(), &sky, &o).unwrap().0);
/// ```
#[derive(Clone, Debug)]
pub struct ReferenceVisibility {
    height: usize,
    vertices: usize,
    words: usize,
    bits: Vec<u64>,
    report: ReferenceReport,
}

impl ReferenceVisibility {
    /// Casts every vertex's rays through the texel centres of an `height x 2 height` map.
    pub fn new(
        mesh: &Mesh,
        occlusion: &impl Occlusion,
        height: usize,
        progress: bool,
    ) -> Result<Self> {
        let sky = LatLongMap::<f64>::from_fn(height, 1, |_, o| o[0] = 1.0)?;
        let texels = lit_texels(&sky)?;
        let words = (2 * height * height).div_ceil(64);
        let vertices = mesh.vertex_count();
        let origins = RayOrigins::new(mesh);
        let start = Instant::now();
        let bar = Task::begin(progress, "reference visibility (rays)", vertices);
        let mut bits = vec![0u64; vertices * words];
        let rays: u64 = bits
            .par_chunks_mut(words.max(1))
            .enumerate()
            .map(|(v, row)| {
                let (origin, n) = origins.origin_and_normal(v);
                let o = f32x3(origin);
                let mut rays = 0;
                for t in &texels {
                    if dot(n, t.direction) <= 0.0 {
                        continue;
                    }
                    rays += 1;
                    if !occlusion.occluded(o, t.ray, f32::INFINITY) {
                        row[t.index / 64] |= 1 << (t.index % 64);
                    }
                }
                bar.advance(1);
                rays
            })
            .sum();
        Ok(ReferenceVisibility {
            height,
            vertices,
            words,
            bits,
            report: ReferenceReport {
                rays,
                seconds: start.elapsed().as_secs_f64(),
            },
        })
    }

    /// The map height `N` the bits were cast for.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The rays cast and the seconds they took.
    pub fn report(&self) -> ReferenceReport {
        self.report
    }

    /// Bytes of the bits.
    pub fn bytes(&self) -> usize {
        self.bits.len() * 8
    }

    /// [`fn@reference`] of `mesh` (the mesh the bits were cast for) under `lighting` (`N x 2N`,
    /// the bits' `N`), with no ray cast: the report counts 0 rays.
    pub fn reference(
        &self,
        mesh: &Mesh,
        albedo: ArrayView2<'_, f32>,
        lighting: &LatLongMap<f64>,
        options: &ReferenceOptions,
    ) -> Result<(Array2<f64>, ReferenceReport)> {
        if lighting.height() != self.height || mesh.vertex_count() != self.vertices {
            return Err(Error::parameter(
                "reference visibility",
                format!(
                    "cast for {} vertices and {} x {} texels, asked for {} vertices and {} x {}",
                    self.vertices,
                    self.height,
                    2 * self.height,
                    mesh.vertex_count(),
                    lighting.height(),
                    2 * lighting.height()
                ),
            ));
        }
        let (out, report) = quadrature(mesh, albedo, lighting, options, |v, _, t| {
            self.bits[v * self.words + t.index / 64] >> (t.index % 64) & 1 == 1
        })?;
        Ok((out, ReferenceReport { rays: 0, ..report }))
    }
}

/// The unit direction from vertex `v` to the eye `e` (the normal `n` if the eye is on it).
fn outgoing(mesh: &Mesh, v: usize, n: [f64; 3], e: [f64; 3]) -> [f64; 3] {
    let d: [f64; 3] = std::array::from_fn(|k| e[k] - mesh.positions()[[v, k]]);
    let len = dot(d, d).sqrt();
    if len > 0.0 { d.map(|x| x / len) } else { n }
}

/// The reference behind [`Shader`]: each frame's environment downsampled to
/// `N x 2N` ([`ShaderSpec::reference_resolution`], default the transport's face size) and
/// integrated by [`reference()`] toward the frame's eye, against the scene's own bounding
/// volume hierarchy (built once).
pub struct ReferenceShader {
    mesh: Mesh,
    bvh: SceneBvh,
    albedo: Array2<f32>,
    options: ReferenceOptions,
    resolution: usize,
    prepare_seconds: f64,
}

impl ReferenceShader {
    /// The reference of `input` for `spec`'s material.
    pub(crate) fn new(spec: &ShaderSpec, input: &ShadingInput<'_>) -> Result<Self> {
        let start = Instant::now();
        let resolution = match (spec.reference_resolution, input.transport) {
            (Some(n), _) => n,
            (None, Some(set)) => set.param().face_size(),
            (None, None) => {
                return Err(Error::parameter(
                    "resolution",
                    "the reference of a scene without a transport needs its lat-long height N",
                ));
            }
        };
        Ok(ReferenceShader {
            mesh: input.mesh.clone(),
            bvh: SceneBvh::new(input.mesh),
            albedo: input.albedo.to_owned(),
            options: ReferenceOptions {
                progress: spec.progress,
                brdf: spec.material.brdf.clone(),
                eye: None,
                object_vertices: Some(input.object_vertices),
            },
            resolution,
            prepare_seconds: seconds(start),
        })
    }
}

impl Shader for ReferenceShader {
    fn shade(&mut self, frame: &FrameSpec<'_>) -> Result<Shading> {
        let start = Instant::now();
        let lighting = frame
            .environment
            .lat_long(self.resolution, &frame.rotation)?;
        let encode_seconds = seconds(start);
        let options = ReferenceOptions {
            eye: frame.eye,
            ..self.options.clone()
        };
        let start = Instant::now();
        let (radiance, report) = reference(
            &self.mesh,
            &self.bvh,
            self.albedo.view(),
            &lighting,
            &options,
        )?;
        Ok(Shading {
            radiance: Radiance::F64(radiance),
            timing: Timing::unrotated(encode_seconds, seconds(start)),
            description: format!(
                "radiance ({}) by quadrature over {} x {} texels: rays {}, {:.3} s",
                options.brdf,
                self.resolution,
                2 * self.resolution,
                report.rays,
                report.seconds
            ),
            maps: None,
            light_coefficients: Some(2 * self.resolution * self.resolution),
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
