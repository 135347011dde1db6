//! Interreflected light by gathering in the pixel domain: issue 51's contract for bounced
//! transport, with the lighting applied first and no Haar transform anywhere, so that the
//! Haar-domain bounces can be checked against it (`relight reference --bounces B`).
//!
//! Lambertian scenes only. Write `U_b(v)` for the bounce-`b` light reaching vertex `v` divided
//! by `pi` (the radiance a vertex of albedo 1 would reflect), RGB. Bounce 0 is the direct
//! reference's ([`fn@super::reference`] with albedo 1, through [`ReferenceVisibility`], so that
//! its rays are the direct reference's own). Bounce `b + 1` gathers over the same rays: the
//! centres `w_t` of the `N x 2N` lat-long texels above `v`'s horizon (solid angle
//! `dOmega_t`), from the same origin `p_v + eps n_v`, each asking for the **closest**
//! triangle it meets ([`SceneBvh::closest_hits_from`]):
//!
//! `U_(b+1)(v) = sum over rays t that hit of (n_v . w_t) dOmega_t (rho_hit / pi) interp_hit(U_b)`,
//!
//! `interp_hit` and `rho_hit` the barycentric interpolation of the hit triangle's three
//! corners' `U_b` and albedo (Sloan, Kautz and Snyder 2002's interreflected transfer, section
//! 5, gathered at vertices as their PRT does). A hit on the far side of its shading normal (the
//! hit triangle's vertex normals interpolated, `n_s . w_t >= 0`: the gather's one-sided rule,
//! [`bounce`](crate::precompute::bounce)) contributes zero, as does every ray that escapes (its
//! light is bounce 0's). Rays start at [`RayOrigins`]'s origins, as the precomputation's do. The BVH keeps one of
//! repeated triangles and never returns one of zero area ([`raycast`](crate::precompute::raycast)),
//! so a pair of opposite-facing duplicates answers as the first in the mesh's order: lit from
//! that one's front, dark from its back.
//!
//! The outgoing radiance of vertex `v` (albedo `a_v`) is `a_v (U_0 + U_1 + ... + U_B)`; the
//! direct part `a_v U_0` is [`fn@super::reference`]'s array bit for bit, and each bounce is
//! kept apart ([`Interreflection::bounces`]).
//!
//! **How.** The hits do not depend on the lighting or the bounce, so they are cast once and
//! folded into a sparse gather matrix `W[v][h]` (per channel: the sum over `v`'s rays that hit
//! a triangle with corner `h` of `cos dOmega / pi x rho_hit x` the corner's barycentric
//! weight); each bounce is then one sparse product `U_(b+1) = W U_b`. Sums are `f64`.

use std::f64::consts::PI;
use std::time::Instant;

use ndarray::{Array2, ArrayView2, Axis};
use rayon::prelude::*;

use super::{ReferenceOptions, ReferenceReport, ReferenceVisibility, lit_texels};
use crate::precompute::bounce::facing_normal;
use crate::precompute::cast::f32x3;
use crate::precompute::origin::RayOrigins;
use crate::scene::mesh::dot;
use crate::{Brdf, Mesh, SceneBvh};
use crate::{Error, Result};
use haarshift::progress::Task;
use haarshift::sphere::LatLongMap;

/// The most bounces a gather or a path may take.
pub const MAX_BOUNCES: usize = 8;

/// The reference radiance with its bounces apart ([`interreflected`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Interreflection {
    /// `a_v U_0`, `(V, 3)`: [`fn@super::reference`]'s direct light.
    pub direct: Array2<f64>,
    /// `bounces[b - 1] = a_v U_b`, `(V, 3)` each, for `b = 1..=B`.
    pub bounces: Vec<Array2<f64>>,
    /// The rays cast (direct and gather) and the seconds taken.
    pub report: ReferenceReport,
}

impl Interreflection {
    /// The outgoing radiance with the first `bounces` bounces (at most those computed):
    /// `direct + bounces[0] + ... `, added in that order.
    ///
    /// ```
    /// use haarshift_relight::shade::reference::interreflection::interreflected;
    /// use haarshift_relight::{Generator, SceneBvh};
    /// use haarshift::sphere::LatLongMap;
    /// use ndarray::Array2;
    /// let mesh = Generator::Sphere { cells: 2 }.mesh().unwrap();
    /// let sky = LatLongMap::<f64>::from_fn(8, 1, |_, o| o[0] = 1.0).unwrap();
    /// let albedo = Array2::from_elem((mesh.vertex_count(), 3), 0.5f32);
    /// let r = interreflected(&mesh, &SceneBvh::new(&mesh), albedo.view(), &sky, 2, false).unwrap();
    /// assert_eq!(r.radiance(0), r.direct);
    /// assert_eq!(r.radiance(9), r.radiance(2));
    /// ```
    pub fn radiance(&self, bounces: usize) -> Array2<f64> {
        let mut out = self.direct.clone();
        for b in self.bounces.iter().take(bounces) {
            out += b;
        }
        out
    }
}

/// The gather matrix `W` in compressed rows: row `v`'s entries are
/// `columns[offsets[v]..offsets[v + 1]]` (hit vertices, ascending) and their RGB weights.
struct Gather {
    offsets: Vec<usize>,
    columns: Vec<u32>,
    weights: Vec<[f64; 3]>,
}

impl Gather {
    /// Casts every vertex's rays through the centres of the `height x 2 height` texels above
    /// its horizon and folds the front-face hits into `W`; returns it and the rays cast.
    fn new(
        mesh: &Mesh,
        bvh: &SceneBvh,
        albedo: ArrayView2<'_, f32>,
        height: usize,
        progress: bool,
    ) -> Result<(Self, u64)> {
        let sky = LatLongMap::<f64>::from_fn(height, 1, |_, o| o[0] = 1.0)?;
        let texels = lit_texels(&sky)?;
        let origins = RayOrigins::new(mesh);
        let triangles = mesh.triangles();
        let bar = Task::begin(progress, "reference bounces (rays)", mesh.vertex_count());
        let rows: Vec<(GatherRow, u64)> = (0..mesh.vertex_count())
            .into_par_iter()
            .map_init(
                || (Vec::new(), Vec::new(), Vec::new()),
                |(rays, weights, hits), v| {
                    let (origin, n) = origins.origin_and_normal(v);
                    rays.clear();
                    weights.clear();
                    for t in &texels {
                        let cos = dot(n, t.direction);
                        if cos > 0.0 {
                            rays.push(t.ray);
                            weights.push((t.direction, cos * t.solid_angle / PI));
                        }
                    }
                    hits.clear();
                    hits.resize(rays.len(), None);
                    bvh.closest_hits_from(f32x3(origin), rays, f32::INFINITY, hits);
                    let mut row = Vec::new();
                    for (hit, &(w, weight)) in hits.iter().zip(weights.iter()) {
                        let Some(hit) = hit else { continue };
                        let tri = triangles[hit.triangle];
                        if facing_normal(mesh, hit, w).is_none() {
                            continue; // the far side of the shading normal, or edge on
                        }
                        let bary = hit.weights();
                        let rho: [f64; 3] = std::array::from_fn(|ch| {
                            (0..3)
                                .map(|k| bary[k] * f64::from(albedo[[tri[k] as usize, ch]]))
                                .sum()
                        });
                        for k in 0..3 {
                            row.push((tri[k], rho.map(|r| weight * r * bary[k])));
                        }
                    }
                    bar.advance(1);
                    (merge_columns(row), rays.len() as u64)
                },
            )
            .collect();
        let mut gather = Gather {
            offsets: vec![0],
            columns: Vec::new(),
            weights: Vec::new(),
        };
        let mut cast = 0;
        for (row, r) in rows {
            cast += r;
            for (column, weight) in row {
                gather.columns.push(column);
                gather.weights.push(weight);
            }
            gather.offsets.push(gather.columns.len());
        }
        Ok((gather, cast))
    }

    /// `W u`, channel by channel.
    fn apply(&self, u: &Array2<f64>) -> Array2<f64> {
        let mut out = Array2::<f64>::zeros(u.dim());
        out.axis_iter_mut(Axis(0))
            .into_par_iter()
            .enumerate()
            .for_each(|(v, mut row)| {
                let range = self.offsets[v]..self.offsets[v + 1];
                let mut sum = [0.0f64; 3];
                for (&h, w) in self.columns[range.clone()].iter().zip(&self.weights[range]) {
                    for c in 0..3 {
                        sum[c] += w[c] * u[[h as usize, c]];
                    }
                }
                row.iter_mut().zip(sum).for_each(|(o, s)| *o = s);
            });
        out
    }
}

/// `row`'s entries sorted by column, the weights of equal columns summed.
fn merge_columns(mut row: Vec<(u32, [f64; 3])>) -> Vec<(u32, [f64; 3])> {
    row.sort_by_key(|&(h, _)| h);
    let mut out: Vec<(u32, [f64; 3])> = Vec::with_capacity(row.len());
    for (h, w) in row {
        match out.last_mut() {
            Some((last, sum)) if *last == h => (0..3).for_each(|c| sum[c] += w[c]),
            _ => out.push((h, w)),
        }
    }
    out
}

/// One vertex's gather row: the hit vertices and their RGB weights.
type GatherRow = Vec<(u32, [f64; 3])>;

/// The reference radiance of a Lambertian scene with `bounces` bounces of interreflected light
/// (see the [module docs](self)): `albedo` `(V, 3)`, `lighting` an `N x 2N` lat-long map, gray
/// or RGB, already rotated; `bounces` at most [`MAX_BOUNCES`]. With `bounces = 0` no gather
/// ray is cast.
///
/// ```
/// use haarshift_relight::shade::reference::interreflection::interreflected;
/// use haarshift_relight::{Mesh, ReferenceOptions, SceneBvh, reference};
/// use haarshift::sphere::LatLongMap;
/// use ndarray::{Array2, array};
/// // A floor and a wall at a right angle: the wall's light reaches the floor.
/// let m = Mesh::new(array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0],
///                          [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]],
///                   vec![[0, 1, 2], [3, 5, 4]], None).unwrap();
/// let sky = LatLongMap::<f64>::from_fn(16, 1, |_, o| o[0] = 1.0).unwrap();
/// let albedo = Array2::from_elem((6, 3), 0.5f32);
/// let bvh = SceneBvh::new(&m);
/// let r = interreflected(&m, &bvh, albedo.view(), &sky, 1, false).unwrap();
/// let direct = reference(&m, &bvh, albedo.view(), &sky, &ReferenceOptions::default()).unwrap().0;
/// assert_eq!(r.direct, direct);
/// assert!(r.bounces[0][[1, 0]] > 0.0); // the floor's far corner sees the wall
/// ```
pub fn interreflected(
    mesh: &Mesh,
    bvh: &SceneBvh,
    albedo: ArrayView2<'_, f32>,
    lighting: &LatLongMap<f64>,
    bounces: usize,
    progress: bool,
) -> Result<Interreflection> {
    check_bounces(bounces)?;
    let vertices = mesh.vertex_count();
    if albedo.dim() != (vertices, 3) {
        return Err(Error::shape(
            albedo.shape(),
            format!("the albedo must be ({vertices}, 3), one RGB row per vertex"),
        ));
    }
    let start = Instant::now();
    let height = lighting.height();
    let bits = ReferenceVisibility::new(mesh, bvh, height, progress)?;
    let options = ReferenceOptions::default();
    let (direct, _) = bits.reference(mesh, albedo, lighting, &options)?;
    let mut rays = bits.report().rays;
    let mut out = Vec::with_capacity(bounces);
    if bounces > 0 {
        let ones = Array2::<f32>::ones((vertices, 3));
        let (mut u, _) = bits.reference(mesh, ones.view(), lighting, &options)?;
        let (gather, cast) = Gather::new(mesh, bvh, albedo, height, progress)?;
        rays += cast;
        for _ in 0..bounces {
            u = gather.apply(&u);
            let mut radiance = u.clone();
            radiance.zip_mut_with(&albedo, |r, &a| *r *= f64::from(a));
            out.push(radiance);
        }
    }
    Ok(Interreflection {
        direct,
        bounces: out,
        report: ReferenceReport {
            rays,
            seconds: start.elapsed().as_secs_f64(),
        },
    })
}

/// Refuses more than [`MAX_BOUNCES`] bounces.
///
/// ```
/// use haarshift_relight::shade::reference::interreflection::check_bounces;
/// assert!(check_bounces(8).is_ok() && check_bounces(9).is_err());
/// ```
pub fn check_bounces(bounces: usize) -> Result<()> {
    if bounces > MAX_BOUNCES {
        return Err(Error::parameter(
            "bounces",
            format!("{bounces}: must be 0 to {MAX_BOUNCES}"),
        ));
    }
    Ok(())
}

/// Refuses a material other than Lambert's: the gather and the path tracer bounce light off
/// Lambertian surfaces only (issue 51's contract).
///
/// ```
/// use haarshift_relight::Brdf;
/// use haarshift_relight::shade::reference::interreflection::check_lambertian;
/// assert!(check_lambertian(&Brdf::Lambert).is_ok());
/// assert!(check_lambertian(&Brdf::Phong { exponent: 30.0 }).is_err());
/// ```
pub fn check_lambertian(brdf: &Brdf) -> Result<()> {
    if !brdf.is_lambert() {
        return Err(Error::parameter(
            "brdf",
            format!("{brdf}: bounces and paths take Lambertian scenes only"),
        ));
    }
    Ok(())
}

#[cfg(test)]
#[path = "interreflection_tests.rs"]
mod tests;
