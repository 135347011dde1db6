//! Shading: every vertex's outgoing radiance `(V, 3)` from its sparse transport and the
//! lighting's coefficients.
//!
//! **What is computed.** For a Lambertian vertex `v`,
//! `B_v = albedo_v / pi x <T_v, L> = albedo_v / pi x sum_t L(t) T_v(t)`, `T_v(t) = V(v, t)
//! max(0, n_v . w_t) dOmega_t` ([`TransportSet`]): issue 7's double product integral. For two
//! functions in one orthonormal basis the integral of the product is the dot product of their
//! coefficients (Parseval, face by face), so it is a sparse dot product of the vertex's stored
//! `(index, value)` pairs with the lighting's dense `(texels, 3)` rows ([`Lighting`]). This is
//! Sun 2006's just-in-time radiance transfer (section 3.5, eq. 3.9): the fixed factors
//! (visibility, cosine, solid angle, and the BRDF's constant) are formed once, at
//! precomputation and in [`PreparedTransport::new`]; a change of lighting costs one sparse dot
//! per vertex. The same number as [`product_integral`](haarshift::product::product_integral) of
//! the two trees (tested), without building a tree per vertex.
//!
//! **Options** ([`ShadeOptions`]), applied once when the transport is prepared, not per frame:
//! * `keep_visibility`: re-truncates each vertex's stored transport to the coefficients a
//!   [`Selection`] picks among those stored (the rule of [`haarshift::product::selection`]: scaling
//!   coefficients always kept, ties by the layout's index), exactly what
//!   [`Transport::select`](haarshift::product::Transport::select) keeps. Asking for more than a
//!   vertex stores keeps what it stores.
//! * `depth = d`: the traversal depth of Sun 2006 Fig. 3.5: only the detail levels `0..d` take
//!   part, i.e. the integral of the two functions averaged over blocks of side `S >> d` (faces
//!   `2^d` texels wide, the thesis's "level `d`"). `d = 0` keeps only the scaling
//!   coefficients (the product of face means); `d = log2 S` is the full integral.
//!   [`product_integral`](haarshift::product::product_integral) with
//!   `finest_level = Some(d - 1)` gives the same (tested). Applied after `keep_visibility`.
//!
//! **Precision.** [`PreparedTransport<T>`] computes in `T`: f32 (the fast path) or f64. Each
//! vertex's dot product is accumulated in `T` over runs of [`RUN`] coefficients and the runs in
//! f64, so an f32 sum of thousands of terms (full coefficients) loses no more than a run's
//! rounding. The output is `T`.
//!
//! **Speed.** Vertices in parallel (rayon) in chunks of [`CHUNK`]; the hot loop allocates
//! nothing and reads the lighting rows at the vertex's indices, which are ascending: the
//! dense rows (`texels x 4 x size_of T`, 393 KB for a `6 x 64^2` cube in f32), or for a
//! truncated lighting its few non-zero rows through a byte table (`LightRows`), visiting only
//! the terms whose texel the lighting lights, found sixteen at a time (`LitTexels`): the same
//! sums, bit for bit.

use ndarray::{Array2, ArrayView2};
use rayon::prelude::*;

use super::{
    FrameSpec, HaarEncoder, Preparation, Radiance, Shader, ShaderSpec, Shading, ShadingInput,
    Timing, seconds,
};
use crate::light::lighting::Lighting;
use crate::material::brdf::check_albedo;
use crate::precompute::sparse::SparseRows;
use crate::precompute::transport_set::TransportSet;
use crate::{Error, Result};
use haarshift::Sample;
use haarshift::faces::Parameterization;
use haarshift::faces::integrate::layout;
use haarshift::product::Selection;
use haarshift::product::selection::{Candidate, keep_largest};
use haarshift::product::tree::mallat_detail;

mod lit;
mod quantised;
mod rows;
pub use quantised::QuantisedTransport;
use rows::{DotBuffers, LightRows};

/// Coefficients summed in the working precision before the sum is added in f64.
pub const RUN: usize = 64;

/// Vertices per parallel task.
pub const CHUNK: usize = 512;

/// How to shade; see the [module docs](self).
///
/// ```
/// use haarshift_relight::ShadeOptions;
/// let o = ShadeOptions::default();
/// assert_eq!((o.keep_visibility, o.depth), (None, None));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShadeOptions {
    /// Re-truncation of each vertex's stored transport (`None`: as stored).
    pub keep_visibility: Option<Selection>,
    /// Detail levels taking part, `0..=log2 S` (`None`: all).
    pub depth: Option<usize>,
}

/// The transport of every vertex made ready to shade: re-truncated, depth-limited, converted
/// to `T`, with each vertex's BRDF constant; reused for every lighting (an animation's
/// frames). See the [module docs](self).
///
/// ```
/// use haarshift::product::Selection;
/// use haarshift_relight::{Lighting, PreparedTransport, ShadeOptions, TransportSet};
/// use haarshift::faces::param::{ParamKind, Parameterization, SphereMap};
/// use ndarray::{Array2, Array3};
/// let param = Parameterization::new(ParamKind::LatLong, 8).unwrap();
/// // One vertex that sees the whole sphere with cosine 1: its transport is the solid angle.
/// let mut set = TransportSet::new(param, Selection::All);
/// set.push(Array3::ones((2, 8, 8)).view()).unwrap();
/// let sky = SphereMap::<f64>::from_fn(param, 3, |d, out| out.fill(1.0 + d[1])).unwrap();
/// let light = Lighting::from_map(&sky, Selection::All).unwrap();
/// let albedo = Array2::from_elem((1, 3), std::f32::consts::PI);
/// let prepared = PreparedTransport::<f64>::new(&set, albedo.view(), &ShadeOptions::default()).unwrap();
/// let b = prepared.shade(&light).unwrap();
/// // pi / pi x the integral of 1 + y over the sphere, 4 pi (y integrates to 0 by symmetry).
/// assert!((b[[0, 1]] - 4.0 * std::f64::consts::PI).abs() < 1e-4);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct PreparedTransport<T> {
    param: Parameterization,
    rows: SparseRows<T>,
    albedo: Vec<[f64; 3]>,
    depth: usize,
}

impl<T: Sample> PreparedTransport<T> {
    /// Prepares `set` for shading with per-vertex RGB `albedo` (`(V, 3)`) under `options`.
    /// With nothing to re-truncate or limit and `T = f32`, the stored coefficients are used
    /// as they are: a set read in place from a cache file stays in place
    /// ([`TransportSet::is_mapped`]).
    pub fn new(
        set: &TransportSet,
        albedo: ArrayView2<'_, f32>,
        options: &ShadeOptions,
    ) -> Result<Self> {
        let param = set.param();
        let vertices = set.vertex_count();
        if albedo.dim() != (vertices, 3) {
            return Err(Error::shape(
                albedo.shape(),
                format!(
                    "the albedo must be ({vertices}, 3): one RGB triple per vertex of the transport"
                ),
            ));
        }
        check_albedo(albedo)?;
        let albedo = albedo
            .rows()
            .into_iter()
            .map(|r| [r[0], r[1], r[2]].map(f64::from))
            .collect();
        let s = param.face_size();
        let levels = s.trailing_zeros() as usize;
        let depth = match options.depth {
            Some(d) if d > levels => {
                return Err(Error::parameter(
                    "depth",
                    format!("{d}: faces of side {s} have detail levels 0 to {levels}"),
                ));
            }
            Some(d) => d,
            None => levels,
        };
        let keep = options.keep_visibility.unwrap_or(Selection::All);
        keep.limit(param.texels() - param.faces())?;
        if let Selection::LargestPerFace(k) = keep
            && k >= s * s
        {
            return Err(Error::parameter(
                "keep",
                format!(
                    "{k} coefficients per face asked for but a face has {}",
                    s * s - 1
                ),
            ));
        }
        let as_stored = keep == Selection::All && depth == levels;
        let rows = match as_stored.then(|| set.rows().shared_as::<T>()).flatten() {
            Some(rows) => rows,
            None => {
                let per_vertex: Vec<(Vec<u32>, Vec<T>)> = (0..vertices)
                    .into_par_iter()
                    .map_init(Vec::new, |pool, v| {
                        let (indices, values) = set.coefficients(v);
                        retruncate(param, keep, depth, indices, values, pool)
                    })
                    .collect();
                per_vertex.iter().map(|(i, c)| (i, c)).collect()
            }
        };
        Ok(PreparedTransport {
            param,
            rows,
            albedo,
            depth,
        })
    }

    /// Whether the coefficients are a mapped cache file's, read in place.
    pub(crate) fn is_mapped(&self) -> bool {
        self.rows.is_mapped()
    }

    /// The parameterisation of the transport.
    pub fn param(&self) -> Parameterization {
        self.param
    }

    /// Vertices.
    pub fn vertex_count(&self) -> usize {
        self.albedo.len()
    }

    /// Coefficients kept over all vertices (scaling coefficients included).
    pub fn coefficient_count(&self) -> usize {
        self.rows.coefficient_count()
    }

    /// Vertex `v`'s coefficients as shaded: Mallat indices (ascending) and values.
    pub fn coefficients(&self, v: usize) -> (&[u32], &[T]) {
        self.rows.row(v)
    }

    /// The detail levels taking part, `0..depth`.
    pub fn depth(&self) -> usize {
        self.depth
    }

    /// Vertex `v`'s albedo, RGB.
    pub(crate) fn albedo(&self, v: usize) -> [f64; 3] {
        self.albedo[v]
    }

    /// Every vertex's outgoing radiance under `lighting`, `(V, 3)`.
    pub fn shade(&self, lighting: &Lighting) -> Result<Array2<T>> {
        let mut out = Array2::zeros((self.vertex_count(), 3));
        self.shade_into(lighting, &mut out)?;
        Ok(out)
    }

    /// [`shade`](Self::shade) into `out` (`(V, 3)`), reused from frame to frame.
    pub fn shade_into(&self, lighting: &Lighting, out: &mut Array2<T>) -> Result<()> {
        let out = checked_output(self.param, self.vertex_count(), lighting, out)?;
        let light = LightRows::<T>::new(lighting);
        // The flat arrays once, not a row lookup per vertex: this loop runs at memory speed.
        let (offsets, indices, values) = self.rows.parts();
        let upcoming = |w: usize| {
            if w + 1 < offsets.len() {
                let run = offsets[w] as usize..offsets[w + 1] as usize;
                prefetch(&indices[run.clone()]);
                prefetch(&values[run]);
            }
        };
        shade_vertices(out, DotBuffers::default, upcoming, |v, buffers| {
            let (a, b) = (offsets[v] as usize, offsets[v + 1] as usize);
            let sum = light.dot(&indices[a..b], &values[a..b], buffers);
            let a = self.albedo[v];
            std::array::from_fn(|c| sum[c] * a[c] * std::f64::consts::FRAC_1_PI)
        });
        Ok(())
    }
}

/// Writes `radiance(v, buffers)` into row `v` of the flat `(V, 3)` `out`, vertices in
/// parallel in chunks of [`CHUNK`], `buffers` made by `buffers()` once per parallel task and
/// kept from vertex to vertex; before each vertex `v`, `upcoming(v + PREFETCH_AHEAD)` asks
/// the cache for a later vertex's transport ([`prefetch`]; it is given indices past the last
/// vertex too, and ignores them).
fn shade_vertices<T: Sample, B>(
    out: &mut [T],
    buffers: impl Fn() -> B + Sync + Send,
    upcoming: impl Fn(usize) + Sync,
    radiance: impl Fn(usize, &mut B) -> [f64; 3] + Sync,
) {
    out.par_chunks_mut(3 * CHUNK)
        .enumerate()
        .for_each_init(buffers, |buffers, (chunk, rows)| {
            for (k, row) in rows.chunks_exact_mut(3).enumerate() {
                upcoming(chunk * CHUNK + k + PREFETCH_AHEAD);
                let r = radiance(chunk * CHUNK + k, buffers);
                for c in 0..3 {
                    row[c] = T::from_f64(r[c]);
                }
            }
        });
}

/// How many vertices ahead a frame prefetches the transport ([`shade_vertices`]).
const PREFETCH_AHEAD: usize = 3;

/// Asks the second-level cache for the lines of `run` (a later vertex's indices or values).
///
/// Each vertex's transport is a run of a few hundred coefficients, read once, with a gather
/// from the lighting's rows for each; asked for a few vertices ahead, the runs are in the
/// cache by the time the frame reaches them: the cubes scene's frame was 15% faster when this
/// was added (`results/relight/frame_floor.md`). The lines go to the second-level cache: into
/// the first, the frame was slower. A prefetch only hints: the sums are the same.
#[inline(always)]
fn prefetch<X>(run: &[X]) {
    #[cfg(target_arch = "x86_64")]
    for line in run.chunks((64 / size_of::<X>()).max(1)) {
        use std::arch::x86_64::{_MM_HINT_T1, _mm_prefetch};
        // SAFETY: a prefetch never faults, and the address is inside `run`.
        unsafe { _mm_prefetch::<_MM_HINT_T1>(line.as_ptr().cast()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = run; // the hardware's own prefetcher alone
}

/// `out` as a flat slice, once the lighting is of `param` and `out` is `(vertices, 3)` and
/// contiguous.
fn checked_output<'a, T: Sample>(
    param: Parameterization,
    vertices: usize,
    lighting: &Lighting,
    out: &'a mut Array2<T>,
) -> Result<&'a mut [T]> {
    if lighting.param() != param {
        return Err(Error::parameter(
            "lighting",
            format!(
                "it is a {} {} map but the transport was precomputed at {} {}",
                lighting.param().kind(),
                lighting.param().face_size(),
                param.kind(),
                param.face_size()
            ),
        ));
    }
    if out.dim() != (vertices, 3) {
        return Err(Error::shape(
            out.shape(),
            format!("the output must be ({vertices}, 3)"),
        ));
    }
    out.as_slice_mut()
        .ok_or_else(|| Error::shape(&[vertices, 3], "the output must be contiguous"))
}

/// Zero rows appended up to a power of two: a valid index `i` equals `i & (len - 1)`, and
/// reading `rows[i & (len - 1)]` in the hot loops ([`LightRows`]) needs no bounds check.
pub(crate) fn pad_to_power_of_two<Q: Default + Clone>(rows: &mut Vec<Q>) {
    rows.resize(rows.len().next_power_of_two(), Q::default());
}

/// `sum_k term(a_k, b_k)` per channel, in order (`a` and `b` of one length): runs of [`RUN`]
/// in `T`, runs added in f64.
///
/// Within a run, term `k` goes to accumulator `k % LANES`: one chain of dependent additions
/// would cost a floating-point add's latency per coefficient, four independent chains let the
/// loads and multiplies of the next terms proceed meanwhile. A term is an RGB row and a zero
/// in four SIMD lanes (the sample type's `Quad`): one coefficient is one row
/// load and one multiply-add. The accumulators are added in a fixed order, so the sum does
/// not depend on the thread schedule.
#[inline(always)]
fn sum_runs<T: Sample, A: Copy, B: Copy>(
    a: &[A],
    b: &[B],
    mut term: impl FnMut(A, B) -> T::Quad,
) -> [f64; 3] {
    debug_assert_eq!(a.len(), b.len());
    let mut total = [0.0f64; 3];
    for (a, b) in a.chunks(RUN).zip(b.chunks(RUN)) {
        let mut acc = [T::Quad::default(); LANES];
        let (a_quads, a_rest) = a.as_chunks::<LANES>();
        let (b_quads, b_rest) = b.as_chunks::<LANES>();
        for (aq, bq) in a_quads.iter().zip(b_quads) {
            for lane in 0..LANES {
                acc[lane] += term(aq[lane], bq[lane]);
            }
        }
        for (lane, (&x, &y)) in a_rest.iter().zip(b_rest).enumerate() {
            acc[lane] += term(x, y);
        }
        add_run::<T>(&mut total, acc);
    }
    total
}

/// Independent accumulators of a run in [`sum_runs`].
const LANES: usize = 4;

/// Adds a run's accumulators, in a fixed order, to `total` in f64 ([`sum_runs`]).
#[inline(always)]
fn add_run<T: Sample>(total: &mut [f64; 3], acc: [T::Quad; LANES]) {
    let run = T::first_three((acc[0] + acc[1]) + (acc[2] + acc[3]));
    for c in 0..3 {
        total[c] += run[c].as_f64();
    }
}

/// Every vertex's outgoing radiance: [`PreparedTransport::new`] then
/// [`shade`](PreparedTransport::shade), for one lighting.
///
/// ```
/// use haarshift::product::Selection;
/// use haarshift_relight::{Lighting, ShadeOptions, TransportSet, shade_lambertian};
/// use haarshift::faces::param::{ParamKind, Parameterization, SphereMap};
/// use ndarray::{Array2, Array3};
/// let param = Parameterization::new(ParamKind::Cube, 4).unwrap();
/// let mut set = TransportSet::new(param, Selection::All);
/// set.push(Array3::ones((6, 4, 4)).view()).unwrap();
/// let one = SphereMap::<f64>::from_fn(param, 1, |_, out| out[0] = 1.0).unwrap();
/// let light = Lighting::from_map(&one, Selection::All).unwrap();
/// let albedo = Array2::from_elem((1, 3), 0.5f32);
/// let b = shade_lambertian::<f32>(&set, albedo.view(), &light, &ShadeOptions::default()).unwrap();
/// assert!((b[[0, 2]] - 2.0).abs() < 1e-5); // 0.5 / pi x 4 pi
/// // A lighting in another parameterisation is refused.
/// let other = Parameterization::new(ParamKind::Cube, 8).unwrap();
/// let wrong = Lighting::from_map(&SphereMap::from_fn(other, 1, |_, o| o[0] = 1.0).unwrap(),
///                                Selection::All).unwrap();
/// assert!(shade_lambertian::<f32>(&set, albedo.view(), &wrong, &ShadeOptions::default()).is_err());
/// ```
pub fn shade_lambertian<T: Sample>(
    set: &TransportSet,
    albedo: ArrayView2<'_, f32>,
    lighting: &Lighting,
    options: &ShadeOptions,
) -> Result<Array2<T>> {
    PreparedTransport::<T>::new(set, albedo, options)?.shade(lighting)
}

/// Which of the coefficients at face-Mallat `indices` (`face x S^2 + row x S + col`, any
/// order) `keep` retains: every scaling coefficient, and the details the rule of
/// [`haarshift::product::selection`] picks by `magnitude2(slot)`, their squared (RGB) magnitudes.
pub(crate) fn select_kept(
    param: Parameterization,
    keep: Selection,
    indices: &[u32],
    magnitude2: impl Fn(usize) -> f64,
    pool: &mut Vec<Candidate>,
) -> Vec<bool> {
    let (faces, s) = (param.faces(), param.face_size());
    let face_layout = layout(param);
    let mut kept = vec![false; indices.len()];
    pool.clear();
    for (slot, &i) in indices.iter().enumerate() {
        let i = i as usize;
        let face = i / (s * s);
        match mallat_detail((i / s) % s, i % s) {
            None => kept[slot] = true,
            Some((band, level, row, col)) => pool.push(Candidate {
                magnitude2: magnitude2(slot),
                index: face_layout.index(faces, s, face, band, level, row, col),
                slot,
            }),
        }
    }
    let mut mark = |pool: &mut [Candidate], k: usize| {
        let count = keep_largest(pool, k);
        for cand in &pool[..count] {
            kept[cand.slot] = true;
        }
    };
    match keep {
        Selection::All => mark(pool, usize::MAX),
        Selection::Threshold(t) => {
            pool.retain(|c| c.magnitude2 > t * t);
            mark(pool, usize::MAX);
        }
        Selection::Largest(k) => mark(pool, k),
        Selection::LargestPerFace(k) => {
            // The indices need not be sorted: group the candidates by face first.
            let face_of = |c: &Candidate| indices[c.slot] as usize / (s * s);
            pool.sort_unstable_by_key(face_of);
            for run in pool.chunk_by_mut(|a, b| face_of(a) == face_of(b)) {
                mark(run, k);
            }
        }
    }
    kept
}

/// Whether the coefficient at face-Mallat index `i` (faces of side `s`) belongs to a detail
/// level below `depth` (or is a scaling coefficient).
pub(crate) fn within_depth(s: usize, depth: usize, i: usize) -> bool {
    (i / s) % s < (1 << depth) && i % s < (1 << depth)
}

/// One vertex's stored coefficients re-truncated by `keep` (among the stored details) and
/// limited to detail levels `0..depth`, ascending by index, converted to `T`.
fn retruncate<T: Sample>(
    param: Parameterization,
    keep: Selection,
    depth: usize,
    indices: &[u32],
    values: &[f32],
    pool: &mut Vec<Candidate>,
) -> (Vec<u32>, Vec<T>) {
    let s = param.face_size();
    let kept = select_kept(
        param,
        keep,
        indices,
        |slot| f64::from(values[slot]).powi(2),
        pool,
    );
    let mut out: Vec<(u32, T)> = indices
        .iter()
        .zip(values)
        .zip(&kept)
        .filter(|&((&i, _), &k)| k && within_depth(s, depth, i as usize))
        .map(|((&i, &c), _)| (i, T::from_f64(f64::from(c))))
        .collect();
    out.sort_unstable_by_key(|&(i, _)| i);
    out.into_iter().unzip()
}

/// Lambertian Haar shading behind [`Shader`]: the transport prepared once
/// ([`PreparedTransport`], or with [`Precision::Q16`](super::Precision::Q16) a
/// [`QuantisedTransport`]), each frame's lighting encoded and dotted with it. With a bounced
/// sum ([`ShadingInput::bounced`]) each of its sets is prepared alike and dotted too, channel
/// `c` of the radiance `albedo / pi x (<T0, L_c> + <S_c, L_c>)`: up to four dots a vertex.
#[derive(Debug)]
pub struct LambertShader<T> {
    transport: Prepared<T>,
    /// The bounced sum's sets, each with the channel it lights (`None`: a grey set, all).
    bounced: Vec<(Prepared<T>, Option<usize>)>,
    encoder: HaarEncoder,
    prepare_seconds: f64,
}

/// The transport a [`LambertShader`] dots the lighting with.
#[derive(Debug)]
enum Prepared<T> {
    Exact(PreparedTransport<T>),
    Quantised(QuantisedTransport),
}

impl<T: Sample> Prepared<T> {
    /// `set` prepared with `albedo` and `spec`'s truncation (and quantised for
    /// [`Precision::Q16`](super::Precision::Q16)).
    fn new(spec: &ShaderSpec, set: &TransportSet, albedo: ArrayView2<'_, f32>) -> Result<Self> {
        Ok(match spec.precision {
            super::Precision::Q16 => Prepared::Quantised(QuantisedTransport::new(
                &PreparedTransport::<f32>::new(set, albedo, &spec.shade)?,
            )),
            _ => Prepared::Exact(PreparedTransport::new(set, albedo, &spec.shade)?),
        })
    }

    fn vertex_count(&self) -> usize {
        match self {
            Prepared::Exact(t) => t.vertex_count(),
            Prepared::Quantised(t) => t.vertex_count(),
        }
    }

    /// Shades into `out`; returns what it shaded with.
    fn shade_into(&self, lighting: &Lighting, out: &mut Array2<T>) -> Result<String> {
        Ok(match self {
            Prepared::Exact(t) => {
                t.shade_into(lighting, out)?;
                let place = if t.is_mapped() {
                    " read in place from the cache file"
                } else {
                    ""
                };
                format!("{} coefficients{place}", t.coefficient_count())
            }
            Prepared::Quantised(t) => {
                t.shade_into(lighting, out)?;
                format!("{} entries of 16 bits", t.entry_count())
            }
        })
    }
}

impl<T: Sample> LambertShader<T> {
    /// `input`'s transport (and bounced sum) prepared with its albedo and `spec`'s truncation
    /// (and quantised for [`Precision::Q16`](super::Precision::Q16)).
    pub(crate) fn new(spec: &ShaderSpec, input: &ShadingInput<'_>) -> Result<Self> {
        let start = std::time::Instant::now();
        let set = input.transport(spec.method)?;
        let transport = Prepared::new(spec, set, input.albedo)?;
        let bounced = bounced_sets(input)
            .map(|(set, channel)| Ok((Prepared::new(spec, set, input.albedo)?, channel)))
            .collect::<Result<_>>()?;
        Ok(LambertShader {
            encoder: HaarEncoder::new(set.param(), spec.keep_light, spec.light_rotation),
            transport,
            bounced,
            prepare_seconds: seconds(start),
        })
    }
}

/// The sets of `input`'s bounced sum (none without one), each with the channel it lights:
/// `None` for a grey sum's one set, else 0, 1, 2.
pub(crate) fn bounced_sets<'a>(
    input: &ShadingInput<'a>,
) -> impl Iterator<Item = (&'a TransportSet, Option<usize>)> {
    let sets = input.bounced.map_or(&[][..], |b| b.channels());
    let grey = sets.len() == 1;
    sets.iter()
        .enumerate()
        .map(move |(c, set)| (set, (!grey).then_some(c)))
}

/// Adds `part` to `sum` (both `(V, 3)`): every channel, or `channel` alone.
pub(crate) fn add_channels<T: Sample>(
    sum: &mut Array2<T>,
    part: &Array2<T>,
    channel: Option<usize>,
) {
    for (mut s, p) in sum.rows_mut().into_iter().zip(part.rows()) {
        for c in channel.map_or(0..3, |c| c..c + 1) {
            s[c] = T::from_f64(s[c].as_f64() + p[c].as_f64());
        }
    }
}

impl<T: Sample> Shader for LambertShader<T>
where
    Radiance: From<Array2<T>>,
{
    fn shade(&mut self, frame: &FrameSpec<'_>) -> Result<Shading> {
        let (lighting, encode_seconds) = self.encoder.encode(frame)?;
        let start = std::time::Instant::now();
        let mut radiance = Array2::zeros((self.transport.vertex_count(), 3));
        let mut stored = format!(
            "transport {}",
            self.transport.shade_into(&lighting, &mut radiance)?
        );
        let mut part = Array2::zeros(radiance.dim());
        for (k, (set, channel)) in self.bounced.iter().enumerate() {
            let what = set.shade_into(&lighting, &mut part)?;
            add_channels(&mut radiance, &part, *channel);
            stored += &format!("{} {what}", if k == 0 { ", bounced sum" } else { " +" });
        }
        Ok(Shading {
            radiance: radiance.into(),
            timing: Timing::unrotated(encode_seconds, seconds(start)),
            description: format!(
                "Haar, lighting kept {} detail coefficients, {stored}; transport prepared once \
                 in {:.1} ms",
                lighting.kept(),
                self.prepare_seconds * 1e3
            ),
            maps: None,
            light_coefficients: Some(lighting.kept() + lighting.param().faces()),
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
