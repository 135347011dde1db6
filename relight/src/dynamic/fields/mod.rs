//! Occlusion fields of rigid objects (Sun 2006 sections 2.3.1 and 3.5.1): an object's
//! visibility as seen from sample points around it, one sparse Haar map over the sphere per
//! point, looked up by interpolation wherever another object's vertex is.
//!
//! **What a sample holds.** For sample point `x` and texel `t` (centre direction `w_t`),
//! `O(x, t) = 1` when the ray `x + s w_t`, `s > 0`, misses the object and 0 when it hits it:
//! one ray per texel over the whole sphere, through the object's BVH alone. The map is
//! transformed (orthonormal Haar, face by face, no weight: the receiver's transport carries
//! the solid angle) and truncated to [`FieldOptions::keep`]; only non-zero kept coefficients
//! are stored ([`SparseRows`]).
//!
//! **Where the samples are**, in the object's own frame (the mesh as loaded, before its
//! placement in a scene). `c` is the centre of its bounding box, `R` the largest distance of a
//! vertex from `c` (the bounding sphere), `r` the largest horizontal distance from the
//! vertical through `c` (the footprint), `y0` its lowest `y` (the virtual ground plane):
//! * the **planar field**: `circles` concentric circles on the plane `y = y0` about the
//!   vertical through `c`, radii from `circle_radii.0 x r` to `circle_radii.1 x r` (Sun 2006:
//!   100 circles, 0.05 r to 10 r), each with `circle_points` points at equal angles from +X
//!   towards +Z (001: 200); points are lifted by the ray offset so rays leave the plane;
//! * the **spherical field**: `shells` concentric spheres about `c`, radii `shell_radii.0 x R`
//!   to `shell_radii.1 x R` (001: 20 shells, 0.2 R to 6 R), each sampled at a
//!   `shell_grid x shell_grid` grid on each of the six cube faces (001: 6 x 9 x 9), the grid
//!   uniform in the face coordinates `a, b` of [`haarshift::faces::cube`] (edge points are on two
//!   faces, as in 001).
//!
//! Neighbouring circles (shells) are spaced in proportion to their radius, as 001 asks ("the
//! spacing grows linearly with the distance"): the radii are geometric, `rho_k = rho_0 g^k`.
//!
//! **Lookup** ([`OcclusionField::lookup`]): a point on the virtual ground plane (within
//! [`PLANE_TOLERANCE`]` x R` of `y0`) and inside the outermost circle takes the planar field:
//! bilinear in (circle, angle); any other point inside the outermost shell takes the spherical
//! field: trilinear, linear between the two shells about its radius and bilinear on their
//! face grids. Inside the innermost circle (shell) the innermost one is used. **Beyond the
//! outermost shell the object is taken not to occlude at all** (the lookup is `None`, the
//! map is 1): at `6 R` the object covers at most `2 pi (1 - cos asin(1/6)) = 0.088` sr of the
//! `4 pi`, so the light a receiver gains when an object crosses the boundary is at most
//! 0.7 % of its unshadowed irradiance (an overcast sky; less under a sun that the object does
//! not cover). Interpolating pixels or coefficients is the same (the transform is linear);
//! what matters is whether the maps are truncated before or after the interpolation:
//! [`Truncation`], measured by `experiment dynamic`.
//!
//! **Turning** ([`OcclusionField::turned`]): an object turned about the vertical by `k`
//! whole columns of a lat-long parameterisation has the field whose maps are every sample's
//! map turned by `k` columns ([`yaw_sparse`]); the sample points do not move, the lookup
//! turns the query point into the object's frame instead (001's "rotation of the ring
//! index", without restricting the angle to the ring's spacing).
//!
//! **On disk** ([`file`](mod@file)): a field is written to a checksummed `.hsf` file whose header records
//! everything that decides its maps, and read back only for the same mesh and options.

use std::time::Instant;

use ndarray::{Array2, Array3, Axis, s};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::Mesh;
use crate::precompute::cast::f32x3;
use crate::precompute::raycast::{Occlusion, SceneBvh};
use crate::precompute::sparse::SparseRows;
use crate::precompute::transport_set::encode;
use crate::precompute::visibility::{ray_offset, texel_directions};
use crate::{Error, Result};
use haarshift::faces::cube::{face_direction, face_point};
use haarshift::faces::param::{ParamKind, Parameterization};
use haarshift::product::Selection;
use haarshift::product::selection::Candidate;
use haarshift::progress::Task;
use haarshift::sphere::latlong::atan2;
use haarshift::transform::{Normalization, pyramid};

/// A point is on the virtual ground plane when within this many bounding radii of it (a
/// receiver's lookup point is lifted off its surface by a scene's ray offset, `1e-4 x` its
/// diagonal, which can be a millionth of a large scene's but a tenth of a per cent of a
/// small object's radius).
pub const PLANE_TOLERANCE: f64 = 1e-2;

/// The most sample points a field may have.
pub const MAX_SAMPLES: usize = 4_000_000;

/// Whether a looked-up map is truncated before or after the interpolation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Truncation {
    /// Blend the samples' stored (truncated) maps: the blend has up to 8 x their coefficients
    /// (001's run-time path; nothing is selected per vertex).
    Before,
    /// Blend the stored maps, then keep what this selection picks of the blend.
    After(Selection),
}

/// How to sample an occlusion field; see the [module docs](self). The defaults are seed
/// 001's.
///
/// ```
/// use haarshift_relight::dynamic::fields::FieldOptions;
/// use haarshift::faces::{ParamKind, Parameterization};
/// let o = FieldOptions::new(Parameterization::new(ParamKind::Cube, 64).unwrap());
/// assert_eq!(o.samples(), 100 * 200 + 20 * 6 * 9 * 9);
/// assert_eq!(o.samples() * o.param.texels(), 730_398_720); // 001's rays at 6 x 64^2
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldOptions {
    /// The directions of every sample's map.
    pub param: Parameterization,
    /// What each sample's map keeps.
    pub keep: Selection,
    /// Concentric circles of the planar field.
    pub circles: usize,
    /// Points per circle.
    pub circle_points: usize,
    /// Innermost and outermost circle radius, in footprint radii `r`.
    pub circle_radii: (f64, f64),
    /// Concentric shells of the spherical field.
    pub shells: usize,
    /// Points per face edge of a shell's cube grid.
    pub shell_grid: usize,
    /// Innermost and outermost shell radius, in bounding radii `R`.
    pub shell_radii: (f64, f64),
    /// Report progress to the installed [reporter](haarshift::progress) (nothing is drawn without one).
    pub progress: bool,
}

impl FieldOptions {
    /// Sun 2006's field: 100 circles x 200 points from 0.05 r to 10 r, 20 shells of 6 x 9 x 9
    /// points from 0.2 R to 6 R, every coefficient kept.
    pub fn new(param: Parameterization) -> Self {
        FieldOptions {
            param,
            keep: Selection::All,
            circles: 100,
            circle_points: 200,
            circle_radii: (0.05, 10.0),
            shells: 20,
            shell_grid: 9,
            shell_radii: (0.2, 6.0),
            progress: false,
        }
    }

    /// Sample points of the planar field.
    pub fn planar_samples(&self) -> usize {
        self.circles * self.circle_points
    }

    /// Sample points of both fields.
    pub fn samples(&self) -> usize {
        self.planar_samples() + self.shells * 6 * self.shell_grid * self.shell_grid
    }

    fn check(&self) -> Result<()> {
        let radii = |(a, b): (f64, f64), what: &'static str| {
            if a.is_finite() && b.is_finite() && 0.0 < a && a < b {
                Ok(())
            } else {
                Err(Error::parameter(
                    what,
                    format!("{a} to {b}: must be finite, positive and increasing"),
                ))
            }
        };
        radii(self.circle_radii, "circle radii")?;
        radii(self.shell_radii, "shell radii")?;
        if self.circles < 2 || self.circle_points < 3 || self.shells < 2 || self.shell_grid < 2 {
            return Err(Error::parameter(
                "field samples",
                format!(
                    "{} circles of {} points, {} shells of 6 x {}^2: at least 2 circles of 3 \
                     points and 2 shells of 6 x 2^2",
                    self.circles, self.circle_points, self.shells, self.shell_grid
                ),
            ));
        }
        let samples = self
            .circles
            .checked_mul(self.circle_points)
            .zip(
                (self.shells * 6)
                    .checked_mul(self.shell_grid)
                    .and_then(|x| x.checked_mul(self.shell_grid)),
            )
            .and_then(|(a, b)| a.checked_add(b));
        if samples.is_none_or(|n| n > MAX_SAMPLES) {
            return Err(Error::parameter(
                "field samples",
                format!("more than {MAX_SAMPLES} sample points"),
            ));
        }
        let p = self.param;
        self.keep.limit(p.texels() - p.faces())?;
        Ok(())
    }
}

/// The frame the samples are placed in, from the object's mesh.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldFrame {
    /// Centre of the bounding box.
    pub centre: [f64; 3],
    /// Bounding radius `R` about the centre.
    pub radius: f64,
    /// Footprint radius `r` about the vertical through the centre.
    pub footprint: f64,
    /// The virtual ground plane `y = y0`.
    pub plane: f64,
}

impl FieldFrame {
    /// The frame of `mesh` (an error when it has no extent).
    pub fn of(mesh: &Mesh) -> Result<Self> {
        let b = mesh.bounds();
        let c = b.centre();
        let p = mesh.positions();
        let (mut radius, mut footprint) = (0.0f64, 0.0f64);
        for row in p.rows() {
            let d = [row[0] - c[0], row[1] - c[1], row[2] - c[2]];
            radius = radius.max((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt());
            footprint = footprint.max((d[0] * d[0] + d[2] * d[2]).sqrt());
        }
        if !(radius > 0.0 && footprint > 0.0) {
            return Err(Error::parameter(
                "mesh",
                "an occlusion field needs an object with width and depth",
            ));
        }
        Ok(FieldFrame {
            centre: c,
            radius,
            footprint,
            plane: b.min[1],
        })
    }
}

/// What building a field did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldReport {
    /// Rays cast.
    pub rays: u64,
    /// Wall-clock seconds, encoding included.
    pub seconds: f64,
}

/// Up to eight samples and their interpolation weights (which sum to 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blend {
    samples: [(u32, f32); 8],
    len: usize,
}

impl Blend {
    /// The `(sample, weight)` pairs with non-zero weight.
    pub fn samples(&self) -> &[(u32, f32)] {
        &self.samples[..self.len]
    }

    fn push(&mut self, sample: usize, weight: f64) {
        if weight > 0.0 {
            self.samples[self.len] = (sample as u32, weight as f32);
            self.len += 1;
        }
    }
}

/// An object's planar and spherical occlusion fields; see the [module docs](self).
///
/// ```
/// use haarshift_relight::{Generator, dynamic::fields::{FieldOptions, OcclusionField}};
/// use haarshift::faces::{ParamKind, Parameterization};
/// let ball = Generator::Sphere { cells: 4 }.mesh().unwrap();
/// let mut options = FieldOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap());
/// (options.circles, options.circle_points, options.shells, options.shell_grid) = (4, 8, 3, 3);
/// let (field, report) = OcclusionField::build(&ball, &options).unwrap();
/// assert_eq!(field.sample_count(), 4 * 8 + 3 * 6 * 9);
/// assert_eq!(report.rays, field.sample_count() as u64 * 128);
/// // Far beyond the outermost shell (6 R) the ball occludes nothing.
/// assert!(field.lookup([100.0, 0.0, 0.0]).is_none());
/// // Between shells: eight samples, weights summing to 1.
/// let blend = field.lookup([2.0, 0.3, 0.1]).unwrap();
/// let total: f32 = blend.samples().iter().map(|s| s.1).sum();
/// assert!(blend.samples().len() == 8 && (total - 1.0).abs() < 1e-6);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct OcclusionField {
    options: FieldOptions,
    frame: FieldFrame,
    maps: SparseRows<f32>,
    turn: usize,
}

impl OcclusionField {
    /// Samples the fields of `mesh` (in its own frame) by ray casting through its BVH.
    pub fn build(mesh: &Mesh, options: &FieldOptions) -> Result<(Self, FieldReport)> {
        options.check()?;
        let start = Instant::now();
        let frame = FieldFrame::of(mesh)?;
        let bvh = SceneBvh::new(mesh);
        let points = sample_points(options, &frame, ray_offset(mesh));
        let param = options.param;
        let directions: Vec<[f32; 3]> = texel_directions(param).into_iter().map(f32x3).collect();
        let ones = Array3::<f32>::ones((param.faces(), param.face_size(), param.face_size()));
        let bar = Task::begin(options.progress, "occlusion field", points.len());
        let encoded = points
            .par_chunks(64)
            .map(|chunk| -> Result<Vec<(Vec<u32>, Vec<f32>)>> {
                let mut values = ones.clone();
                let out = chunk
                    .iter()
                    .map(|&x| {
                        let origin = f32x3(x);
                        let flat = values.as_slice_mut().expect("fresh array is contiguous");
                        for (v, d) in flat.iter_mut().zip(&directions) {
                            *v = if bvh.occluded(origin, *d, f32::INFINITY) {
                                0.0
                            } else {
                                1.0
                            };
                        }
                        encode(values.view(), ones.view(), param, options.keep)
                    })
                    .collect::<Result<Vec<_>>>()?;
                bar.advance(chunk.len());
                Ok(out)
            })
            .collect::<Result<Vec<_>>>()?;
        let maps: SparseRows<f32> = encoded.iter().flatten().map(|(i, v)| (i, v)).collect();
        let report = FieldReport {
            rays: (points.len() * directions.len()) as u64,
            seconds: start.elapsed().as_secs_f64(),
        };
        Ok((
            OcclusionField {
                options: *options,
                frame,
                maps,
                turn: 0,
            },
            report,
        ))
    }

    /// How the field was sampled.
    pub fn options(&self) -> &FieldOptions {
        &self.options
    }

    /// The frame its samples are placed in.
    pub fn frame(&self) -> &FieldFrame {
        &self.frame
    }

    /// Sample points, planar first (circle after circle), then spherical (shell, face, `a`,
    /// `b`).
    pub fn sample_count(&self) -> usize {
        self.maps.len()
    }

    /// The position of every sample, in the object's frame, in sample order.
    pub fn sample_points(&self) -> Vec<[f64; 3]> {
        sample_points(&self.options, &self.frame, 0.0)
    }

    /// Sample `i`'s stored map: face-Mallat indices and orthonormal coefficients.
    pub fn map(&self, i: usize) -> (&[u32], &[f32]) {
        self.maps.row(i)
    }

    /// Coefficients stored over all samples.
    pub fn coefficient_count(&self) -> usize {
        self.maps.coefficient_count()
    }

    /// Bytes of the stored maps.
    pub fn stored_bytes(&self) -> usize {
        self.maps.bytes()
    }

    /// The field with every stored map re-truncated to `keep` (which can only keep fewer
    /// than the field was built with): the budget of an experiment without a new build.
    pub fn truncated(&self, keep: Selection) -> Result<Self> {
        let param = self.options.param;
        keep.limit(param.texels() - param.faces())?;
        Ok(OcclusionField {
            maps: select_rows(param, keep, &self.maps),
            options: FieldOptions {
                keep,
                ..self.options
            },
            frame: self.frame,
            turn: self.turn,
        })
    }

    /// Columns the maps have been turned by ([`turned`](Self::turned)).
    pub fn turn(&self) -> usize {
        self.turn
    }

    /// The field of the object turned by `k` columns about +Y (lat-long only): every map
    /// turned, re-truncated to the field's selection.
    pub fn turned(&self, k: usize) -> Result<Self> {
        let param = self.options.param;
        let k = k % (2 * param.face_size());
        let delta = (k + 2 * param.face_size() - self.turn) % (2 * param.face_size());
        let rows: Vec<(Vec<u32>, Vec<f32>)> = (0..self.maps.len())
            .into_par_iter()
            .map(|i| {
                let (indices, values) = self.maps.row(i);
                yaw_sparse(param, indices, values, delta, self.options.keep)
            })
            .collect::<Result<_>>()?;
        let maps: SparseRows<f32> = rows.iter().map(|(i, v)| (i, v)).collect();
        Ok(OcclusionField {
            maps,
            turn: k,
            options: self.options,
            frame: self.frame,
        })
    }

    /// The samples and weights that interpolate the field at `x` (object frame), `None`
    /// beyond the outermost shell; see the [module docs](self).
    pub fn lookup(&self, x: [f64; 3]) -> Option<Blend> {
        let o = &self.options;
        let f = &self.frame;
        let d = [x[0] - f.centre[0], x[1] - f.centre[1], x[2] - f.centre[2]];
        let mut blend = Blend {
            samples: [(0, 0.0); 8],
            len: 0,
        };
        let on_plane = (x[1] - f.plane).abs() <= PLANE_TOLERANCE * f.radius;
        let rho = (d[0] * d[0] + d[2] * d[2]).sqrt();
        let (c0, c1) = (
            o.circle_radii.0 * f.footprint,
            o.circle_radii.1 * f.footprint,
        );
        // The outermost ring itself is inside, whatever the rounding of the radius.
        if on_plane && rho <= c1 * (1.0 + 1e-12) {
            let (k, t) = ring(rho, c0, c1, o.circles);
            let m = o.circle_points;
            let angle = atan2(d[2], d[0]).rem_euclid(std::f64::consts::TAU);
            let u = angle / std::f64::consts::TAU * m as f64;
            let j = (u.floor() as usize).min(m - 1);
            let a = u - j as f64;
            for (dk, wk) in [(0, 1.0 - t), (1, t)] {
                for (dj, wj) in [(0, 1.0 - a), (1, a)] {
                    blend.push((k + dk) * m + (j + dj) % m, wk * wj);
                }
            }
            return Some(blend);
        }
        let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let (s0, s1) = (o.shell_radii.0 * f.radius, o.shell_radii.1 * f.radius);
        if r > s1 * (1.0 + 1e-12) {
            return None;
        }
        let (k, t) = ring(r, s0, s1, o.shells);
        let g = o.shell_grid;
        let (face, a, b) = face_point(if r > 0.0 { d } else { [0.0, 1.0, 0.0] });
        let grid = |v: f64| {
            let u = (v + 1.0) * 0.5 * (g - 1) as f64;
            let i = (u.floor() as usize).min(g - 2);
            (i, u - i as f64)
        };
        let ((ia, ta), (ib, tb)) = (grid(a), grid(b));
        let planar = o.planar_samples();
        for (dk, wk) in [(0, 1.0 - t), (1, t)] {
            for (da, wa) in [(0, 1.0 - ta), (1, ta)] {
                for (db, wb) in [(0, 1.0 - tb), (1, tb)] {
                    let i = (((k + dk) * 6 + face) * g + ia + da) * g + ib + db;
                    blend.push(planar + i, wk * wa * wb);
                }
            }
        }
        Some(blend)
    }

    /// The field's map at `x`: the blend of [`lookup`](Self::lookup) made sparse and, with
    /// [`Truncation::After`], truncated; `None` beyond the field. `scratch` must hold
    /// `param.texels()` zeros and is left so.
    pub fn blended(
        &self,
        x: [f64; 3],
        truncation: Truncation,
        scratch: &mut [f64],
        out: &mut (Vec<u32>, Vec<f64>),
    ) -> Option<()> {
        let blend = self.lookup(x)?;
        blend_maps(
            self.options.param,
            blend
                .samples()
                .iter()
                .map(|&(i, w)| (self.map(i as usize), w)),
            truncation,
            scratch,
            out,
        );
        Some(())
    }
}

/// The weighted sum of sparse maps, sparse (indices in first-touched order), then truncated
/// as `truncation` says. `scratch` holds `param.texels()` zeros and is left so.
fn blend_maps<'a>(
    param: Parameterization,
    maps: impl Iterator<Item = ((&'a [u32], &'a [f32]), f32)>,
    truncation: Truncation,
    scratch: &mut [f64],
    out: &mut (Vec<u32>, Vec<f64>),
) {
    let (indices, values) = out;
    indices.clear();
    values.clear();
    for ((idx, val), w) in maps {
        for (&i, &v) in idx.iter().zip(val) {
            let cell = &mut scratch[i as usize];
            if *cell == 0.0 {
                indices.push(i);
            }
            // A sum that cancels to exactly 0 would be pushed twice: keep it non-zero.
            *cell += f64::from(w) * f64::from(v);
            if *cell == 0.0 {
                *cell = f64::MIN_POSITIVE;
            }
        }
    }
    values.extend(indices.iter().map(|&i| {
        let v = scratch[i as usize];
        scratch[i as usize] = 0.0;
        if v == f64::MIN_POSITIVE { 0.0 } else { v }
    }));
    if let Truncation::After(keep) = truncation {
        let mut pool: Vec<Candidate> = Vec::new();
        let kept =
            crate::shade::select_kept(param, keep, indices, |s| values[s] * values[s], &mut pool);
        let mut at = 0;
        for (slot, k) in kept.iter().enumerate() {
            if *k {
                indices[at] = indices[slot];
                values[at] = values[slot];
                at += 1;
            }
        }
        indices.truncate(at);
        values.truncate(at);
    }
}

/// Every row of `rows` re-truncated to what `keep` picks of it (rule of
/// [`haarshift::product::selection`]).
pub(crate) fn select_rows(
    param: Parameterization,
    keep: Selection,
    rows: &SparseRows<f32>,
) -> SparseRows<f32> {
    let mut out = SparseRows::new();
    let mut pool = Vec::new();
    let (mut idx, mut val) = (Vec::new(), Vec::new());
    for r in 0..rows.len() {
        let (i, v) = rows.row(r);
        let kept = crate::shade::select_kept(
            param,
            keep,
            i,
            |s| f64::from(v[s]) * f64::from(v[s]),
            &mut pool,
        );
        idx.clear();
        val.clear();
        for ((&i, &v), k) in i.iter().zip(v).zip(kept) {
            if k {
                idx.push(i);
                val.push(v);
            }
        }
        out.push(&idx, &val);
    }
    out
}

/// Ring `k` below `x` on geometric radii `lo .. hi` (`n` of them) and the fraction towards
/// ring `k + 1`; inside `lo`, ring 0 with fraction 0.
fn ring(x: f64, lo: f64, hi: f64, n: usize) -> (usize, f64) {
    if x <= lo {
        return (0, 0.0);
    }
    let u = (x / lo).ln() / (hi / lo).ln() * (n - 1) as f64;
    let k = (u.floor() as usize).min(n - 2);
    // Linear in the distance between the two rings (the fraction of the way from one to the
    // other), not in the logarithm.
    let (a, b) = (ring_radius(k, lo, hi, n), ring_radius(k + 1, lo, hi, n));
    (k, ((x - a) / (b - a)).clamp(0.0, 1.0))
}

/// Radius of ring `k` of `n` geometric radii `lo .. hi`.
fn ring_radius(k: usize, lo: f64, hi: f64, n: usize) -> f64 {
    lo * (hi / lo).powf(k as f64 / (n - 1) as f64)
}

/// Every sample point in sample order; planar points lifted by `lift`.
fn sample_points(o: &FieldOptions, f: &FieldFrame, lift: f64) -> Vec<[f64; 3]> {
    let mut out = Vec::with_capacity(o.samples());
    let c = f.centre;
    for k in 0..o.circles {
        let rho = ring_radius(
            k,
            o.circle_radii.0 * f.footprint,
            o.circle_radii.1 * f.footprint,
            o.circles,
        );
        for j in 0..o.circle_points {
            let a = std::f64::consts::TAU * j as f64 / o.circle_points as f64;
            out.push([c[0] + rho * a.cos(), f.plane + lift, c[2] + rho * a.sin()]);
        }
    }
    let g = o.shell_grid;
    for k in 0..o.shells {
        let r = ring_radius(
            k,
            o.shell_radii.0 * f.radius,
            o.shell_radii.1 * f.radius,
            o.shells,
        );
        for face in 0..6 {
            for ia in 0..g {
                for ib in 0..g {
                    let coord = |i: usize| -1.0 + 2.0 * i as f64 / (g - 1) as f64;
                    let d = face_direction(face, coord(ia), coord(ib));
                    out.push(std::array::from_fn(|i| c[i] + r * d[i]));
                }
            }
        }
    }
    out
}

/// A lat-long function given by sparse face-Mallat coefficients turned by `k` columns about
/// +Y (`g(theta, phi) = f(theta, phi - k 2 pi / W)`: what an object turned by `+k` columns
/// sees), re-truncated to `keep`. Exact up to the rounding of one transform pair.
///
/// ```
/// use haarshift::product::Selection;
/// use haarshift_relight::dynamic::fields::yaw_sparse;
/// use haarshift::faces::{ParamKind, Parameterization};
/// let param = Parameterization::new(ParamKind::LatLong, 4).unwrap();
/// // Face 0's scaling coefficient: 1 on columns 0..4 (scaling = pixel sum / S = 4).
/// let (i, v) = yaw_sparse(param, &[0], &[4.0], 4, Selection::All).unwrap();
/// assert_eq!((i, v), (vec![16], vec![4.0])); // now face 1's
/// ```
pub fn yaw_sparse(
    param: Parameterization,
    indices: &[u32],
    values: &[f32],
    k: usize,
    keep: Selection,
) -> Result<(Vec<u32>, Vec<f32>)> {
    if param.kind() != ParamKind::LatLong {
        return Err(Error::parameter(
            "turn",
            "turning a map about the vertical needs a lat-long parameterisation",
        ));
    }
    let h = param.face_size();
    let n = h.trailing_zeros() as usize;
    let mut map = Array2::<f32>::zeros((h, 2 * h));
    let mut coeffs = Array3::<f32>::zeros((2, h, h));
    {
        let flat = coeffs.as_slice_mut().expect("fresh array is contiguous");
        for (&i, &v) in indices.iter().zip(values) {
            flat[i as usize] = v;
        }
    }
    for face in 0..2 {
        let pixels = pyramid::inverse(
            coeffs.index_axis(Axis(0), face),
            n,
            Normalization::Orthonormal,
        )?;
        map.slice_mut(s![.., face * h..(face + 1) * h])
            .assign(&pixels);
    }
    let w = 2 * h;
    let k = k % w;
    let mut turned = Array3::<f32>::zeros((2, h, h));
    for face in 0..2 {
        for i in 0..h {
            for j in 0..h {
                turned[[face, i, j]] = map[[i, (face * h + j + w - k) % w]];
            }
        }
    }
    let ones = Array3::<f32>::ones((2, h, h));
    encode(turned.view(), ones.view(), param, keep)
}

pub mod file;

#[cfg(test)]
mod tests;
