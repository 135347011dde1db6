//! Precomputing every vertex's transport: visibility x cosine x solid angle at the texel
//! directions of a [`Parameterization`], Haar-transformed and truncated ([`TransportSet`]).
//!
//! **What is computed.** For vertex `v` (position `p`, unit normal `n`) and texel `t` (centre
//! direction `w_t`, solid angle `dOmega_t`), `T_v(t) = V(v, t) max(0, n . w_t) dOmega_t`. Rays
//! start at `p + eps n`, `eps = 1e-4 x` the scene's bounding-box diagonal ([`ray_offset`]); a
//! ray that hits any triangle is blocked. Texels whose centre is below the horizon
//! (`n . w_t <= 0`) are 0 and cast no ray. With `samples = S > 1`, `V(v, t)` is the fraction of
//! `S x S` stratified rays through the texel that escape (sub-cell `(a, b)` of the texel's
//! parameter square, jittered uniformly inside it by a hash of the seed, vertex, texel and
//! sample, so the result does not depend on the thread schedule); a jittered ray below the
//! horizon counts as blocked. `S = 1` is one ray through the texel centre. The cosine is the
//! centre's.
//!
//! **Two loop orders.**
//! * [`vertex_major`]: vertices outer (rayon), directions inner, rays through a BVH
//!   ([`Occlusion`]), a vertex's rays asked together ([`Occlusion::occluded_from`]) in 4 x 4
//!   texel blocks, so that a packet of them is a narrow cone; each vertex is encoded as soon as
//!   it is done, so the working memory is one `(faces, S, S)` array per thread and a buffer of
//!   1,024 rays. The order the rays are cast in changes no answer.
//! * [`direction_major`]: Microsoft 2003's order: directions outer, vertices inner, a software shadow
//!   buffer per direction ([`ShadowMap`]) instead of rays. Visibility of all (vertex, direction)
//!   pairs is held as bits, one column of `V` bits per direction (`V x D / 8` bytes: 352 MB for
//!   85,860 vertices x 32,768 directions, against 11 GB as f32), then each vertex is encoded.
//!   Texel centres only (`samples = 1`).
//!
//! With [`VisibilityOptions::sh_bands`], both also project every vertex's values onto spherical
//! harmonics ([`harmonics`](crate::sh_transfer): `t_i = sum_t V cos Y_i(w_t) dOmega_t`, the
//! basis tabulated once per texel and shared by all threads); the returned set carries the
//! transfer ([`TransportSet::sh`]).
//!
//! Both report what they did in a [`PrecomputeReport`]: rays cast, wall time, the working
//! memory the method holds beyond its inputs and outputs.

use std::ops::Range;
use std::time::Instant;

use ndarray::Array3;
use rayon::prelude::*;

use crate::Mesh;
use crate::precompute::cast::{Occluding, Visible, cast_vertices, working_bytes};
use crate::precompute::origin::RayOrigins;
use crate::precompute::raycast::{Occlusion, RayTracer};
use crate::precompute::shadowmap::ShadowMap;
use crate::precompute::transport_set::{Encoded, Encoder, TransportSet};
use crate::scene::mesh::dot;
use crate::sh_transfer::check_bands;
use crate::{Error, Result};
use haarshift::faces::Parameterization;
use haarshift::product::Selection;
use haarshift::progress::Task;

/// How to precompute; see the [module docs](self).
///
/// ```
/// use haarshift_relight::VisibilityOptions;
/// use haarshift::faces::{ParamKind, Parameterization};
/// let o = VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 16).unwrap());
/// assert_eq!((o.samples, o.seed, o.sh_bands, o.progress), (1, 0, None, false));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VisibilityOptions {
    /// The directions: texel centres of this parameterisation.
    pub param: Parameterization,
    /// `S`: `S x S` stratified rays per texel (1: the centre).
    pub samples: usize,
    /// Which coefficients of each vertex's transport to keep.
    pub keep: Selection,
    /// Seed of the stratified jitter.
    pub seed: u64,
    /// Also project every vertex's transport onto this many bands of spherical harmonics
    /// (`--sh-bands B`: degrees `0..B`, `B^2` coefficients, 1 to
    /// [`MAX_SH_BANDS`](crate::sh_transfer::MAX_SH_BANDS)); the set then carries an
    /// [`ShTransfer`](crate::sh_transfer::ShTransfer).
    pub sh_bands: Option<usize>,
    /// Report progress to the installed [reporter](haarshift::progress) (nothing is drawn without one).
    pub progress: bool,
}

impl VisibilityOptions {
    /// One ray per texel centre, every coefficient kept, seed 0, no progress reported.
    pub fn new(param: Parameterization) -> Self {
        VisibilityOptions {
            param,
            samples: 1,
            keep: Selection::All,
            seed: 0,
            sh_bands: None,
            progress: false,
        }
    }

    pub(crate) fn check(&self) -> Result<()> {
        if !(1..=64).contains(&self.samples) {
            return Err(Error::parameter(
                "visibility samples",
                format!("{}: must be 1 to 64 (S x S rays per texel)", self.samples),
            ));
        }
        if let Some(b) = self.sh_bands {
            check_bands(b)?;
        }
        let p = self.param;
        self.keep.limit(p.texels() - p.faces())?;
        Ok(())
    }
}

/// What a precomputation did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrecomputeReport {
    /// Rays cast (0 for the shadow-buffer order).
    pub rays: u64,
    /// Wall-clock seconds, encoding included.
    pub seconds: f64,
    /// Bytes of working memory the method held at its peak beyond the mesh and the output
    /// (visibility bits and depth buffers, or per-thread texel arrays, and the shared tables:
    /// solid angles and spherical harmonics).
    pub working_bytes: usize,
    /// The ray tracer that answered ([`Occlusion::tracer`]; `None` for the shadow-buffer order
    /// and for an [`Occlusion`] of the caller's own).
    pub tracer: Option<RayTracer>,
    /// Of [`seconds`](Self::seconds), those gathering bounces of interreflected light
    /// ([`bounce`](super::bounce); 0 without).
    pub bounce_seconds: f64,
}

impl PrecomputeReport {
    /// This report and then `next`'s (a later stage of the same precomputation): rays and
    /// seconds added, bounce seconds too, the larger working memory, this tracer.
    pub(crate) fn followed_by(&self, next: &PrecomputeReport) -> PrecomputeReport {
        PrecomputeReport {
            rays: self.rays + next.rays,
            seconds: self.seconds + next.seconds,
            working_bytes: self.working_bytes.max(next.working_bytes),
            tracer: self.tracer,
            bounce_seconds: self.bounce_seconds + next.bounce_seconds,
        }
    }
}

/// The distance rays start off their surface: `1e-4 x` the bounding-box diagonal.
///
/// ```
/// use haarshift_relight::{Mesh, ray_offset};
/// use ndarray::array;
/// let m = Mesh::new(array![[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 4.0, 0.0]],
///                   vec![[0, 1, 2]], None).unwrap();
/// assert!((ray_offset(&m) - 5e-4).abs() < 1e-15);
/// ```
pub fn ray_offset(mesh: &Mesh) -> f64 {
    1e-4 * mesh.bounds().diagonal()
}

/// Texel centre directions in Mallat/texel index order `(face, row, col)`.
pub(crate) fn texel_directions(param: Parameterization) -> Vec<[f64; 3]> {
    let s = param.face_size();
    (0..param.texels())
        .map(|t| param.texel_direction(t / (s * s), (t / s) % s, t % s))
        .collect()
}

/// Vertex-major precomputation by ray casting; see the [module docs](self).
///
/// ```
/// use haarshift_relight::{Mesh, SceneBvh, VisibilityOptions, vertex_major};
/// use haarshift::faces::{ParamKind, Parameterization};
/// use ndarray::array;
/// // One upward triangle: nothing occludes it, so each vertex sees the upper hemisphere.
/// let m = Mesh::new(array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]],
///                   vec![[0, 1, 2]], None).unwrap();
/// let options = VisibilityOptions::new(Parameterization::new(ParamKind::LatLong, 16).unwrap());
/// let (set, report) = vertex_major(&m, &SceneBvh::new(&m), &options).unwrap();
/// let total: f32 = set.transport(0).unwrap().tree().to_pixels().unwrap().sum();
/// assert!((total - std::f32::consts::PI).abs() < 0.02); // the integral of cos over a hemisphere
/// assert_eq!(report.rays, 3 * 16 * 16); // the upper half of 16 x 32 texels, per vertex
/// ```
pub fn vertex_major(
    mesh: &Mesh,
    occlusion: &impl Occlusion,
    options: &VisibilityOptions,
) -> Result<(TransportSet, PrecomputeReport)> {
    vertex_range(mesh, occlusion, options, 0..mesh.vertex_count())
}

/// [`vertex_major`] for the vertices `vertices` only (a [shard](super::shard)): the set's row
/// `k` is vertex `vertices.start + k`, with the bits [`vertex_major`] gives that vertex, since
/// every ray goes through the whole scene's `occlusion` and the jitter is keyed by the global
/// vertex index.
///
/// ```
/// use haarshift_relight::{Generator, SceneBvh, VisibilityOptions, vertex_major, vertex_range};
/// use haarshift::faces::{ParamKind, Parameterization};
/// let mesh = Generator::Sphere { cells: 2 }.mesh().unwrap();
/// let mut options = VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 4).unwrap());
/// options.samples = 2;
/// let bvh = SceneBvh::new(&mesh);
/// let (all, _) = vertex_major(&mesh, &bvh, &options).unwrap();
/// let (part, _) = vertex_range(&mesh, &bvh, &options, 10..20).unwrap();
/// assert_eq!(part.vertex_count(), 10);
/// assert_eq!(part.coefficients(3), all.coefficients(13));
/// assert!(vertex_range(&mesh, &bvh, &options, 50..55).is_err()); // 54 vertices
/// ```
pub fn vertex_range(
    mesh: &Mesh,
    occlusion: &impl Occlusion,
    options: &VisibilityOptions,
    vertices: Range<usize>,
) -> Result<(TransportSet, PrecomputeReport)> {
    options.check()?;
    if vertices.start > vertices.end || vertices.end > mesh.vertex_count() {
        return Err(Error::parameter(
            "vertices",
            format!(
                "{}..{}: the mesh has {} vertices",
                vertices.start,
                vertices.end,
                mesh.vertex_count()
            ),
        ));
    }
    let start = Instant::now();
    let encoder = Encoder::new(options.param, options.keep, options.sh_bands)?;
    let caster = Visible::new(Occluding(occlusion), &encoder, options);
    let (rows, rays) = cast_vertices(mesh, &caster, options, vertices, "visibility (rays)")?;
    let mut set = encoder.empty_set()?;
    for (vertex, ()) in &rows {
        set.extend(vertex);
    }
    let report = PrecomputeReport {
        rays,
        seconds: start.elapsed().as_secs_f64(),
        working_bytes: working_bytes(&caster, options.param) + encoder.bytes(),
        tracer: occlusion.tracer(),
        bounce_seconds: 0.0,
    };
    Ok((set, report))
}

/// Direction-major precomputation with a shadow buffer of `map_size x map_size` texels per
/// direction (Microsoft 2003); see the [module docs](self).
///
/// ```
/// use haarshift_relight::{Mesh, SceneBvh, VisibilityOptions, direction_major, vertex_major};
/// use haarshift::faces::{ParamKind, Parameterization};
/// use ndarray::array;
/// let m = Mesh::new(array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]],
///                   vec![[0, 1, 2]], None).unwrap();
/// let options = VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 4).unwrap());
/// let (by_maps, _) = direction_major(&m, &options, 256).unwrap();
/// let (by_rays, _) = vertex_major(&m, &SceneBvh::new(&m), &options).unwrap();
/// assert_eq!(by_maps, by_rays); // nothing occludes: both are the cosine lobe
/// ```
pub fn direction_major(
    mesh: &Mesh,
    options: &VisibilityOptions,
    map_size: usize,
) -> Result<(TransportSet, PrecomputeReport)> {
    options.check()?;
    if options.samples != 1 {
        return Err(Error::parameter(
            "visibility samples",
            "the direction-major order samples texel centres only: use 1",
        ));
    }
    if !(1..=16384).contains(&map_size) {
        return Err(Error::parameter(
            "shadow map size",
            format!("{map_size}: must be 1 to 16384"),
        ));
    }
    let start = Instant::now();
    let param = options.param;
    let directions = texel_directions(param);
    let vertices = mesh.vertex_count();
    let words = vertices.div_ceil(64);
    let origins = RayOrigins::new(mesh);
    let origins: Vec<([f64; 3], [f64; 3])> = (0..vertices)
        .map(|v| origins.origin_and_normal(v))
        .collect();
    // One column of V bits per direction: bit v set when vertex v sees the direction.
    let columns: Vec<Vec<u64>> = directions
        .par_iter()
        .map(|&w| {
            let mut column = vec![0u64; words];
            if origins.iter().all(|(_, n)| dot(*n, w) <= 0.0) {
                return column;
            }
            let map = ShadowMap::render(mesh, w, map_size);
            for (v, (o, n)) in origins.iter().enumerate() {
                let cos = dot(*n, w);
                if cos > 0.0 && map.lit(*o, cos) {
                    column[v / 64] |= 1 << (v % 64);
                }
            }
            column
        })
        .collect();
    let bits_bytes = directions.len() * words * 8;
    let maps_bytes = rayon::current_num_threads() * map_size * map_size * 4;
    let s = param.face_size();
    let encoder = Encoder::new(param, options.keep, options.sh_bands)?;
    let bar = Task::begin(options.progress, "transport (shadow maps)", vertices);
    let encoded: Vec<Result<Encoded>> = (0..vertices)
        .into_par_iter()
        .map(|v| {
            let n = origins[v].1;
            let values = Array3::from_shape_fn((param.faces(), s, s), |(f, r, c)| {
                let t = (f * s + r) * s + c;
                let lit = columns[t][v / 64] >> (v % 64) & 1 == 1;
                if lit {
                    dot(n, directions[t]) as f32
                } else {
                    0.0
                }
            });
            let out = encoder.encode(values.view());
            bar.advance(1);
            out
        })
        .collect();
    let mut set = encoder.empty_set()?;
    for vertex in encoded {
        set.extend(&vertex?);
    }
    let report = PrecomputeReport {
        rays: 0,
        seconds: start.elapsed().as_secs_f64(),
        working_bytes: bits_bytes + maps_bytes + encoder.bytes(),
        tracer: None,
        bounce_seconds: 0.0,
    };
    Ok((set, report))
}

#[cfg(test)]
#[path = "visibility_tests.rs"]
mod tests;
