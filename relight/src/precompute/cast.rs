//! Casting every vertex's rays, once, for whatever is folded from them: visibility's escaped
//! counts and, with bounces, the hit weights ([`bounce`](super::bounce)).
//!
//! **The rays** ([`RaySet`], the contract of [`visibility`](super::visibility)): from
//! `p + eps n` ([`origin_and_normal`]), one ray through each texel centre above the horizon, or
//! with `S > 1` the `S x S` jittered sub-rays of each such texel that are above it, texels in
//! 4 x 4 blocks ([`block_order`]) so that a packet of consecutive rays is a narrow cone; cast
//! [`BATCH`] at a time.
//!
//! **Casters.** A [`Caster`] answers a batch (is each ray blocked?) and may fold what it
//! learns into per-thread state, which it turns into one row per vertex when the vertex is
//! done; [`cast_vertices`] drives any caster over a range of vertices in parallel and counts
//! the rays that escaped per texel for it. An any-hit caster ([`Occluding`]) gives visibility
//! alone. A closest-hit caster gives visibility too (a ray is blocked exactly when it has a
//! closest hit), so one cast can serve both the direct transport and the bounces' gather
//! ([`Visible`] wraps a caster to encode the direct transport as well).

use std::ops::Range;

use ndarray::Array3;
use rayon::prelude::*;

use crate::Mesh;
use crate::Result;
use crate::precompute::origin::RayOrigins;
use crate::precompute::raycast::Occlusion;
use crate::precompute::transport_set::{Encoded, Encoder};
use crate::precompute::visibility::{VisibilityOptions, texel_directions};
use crate::scene::mesh::dot;
use haarshift::faces::Parameterization;
use haarshift::progress::Task;

/// SplitMix64: a well-mixed hash of a 64-bit key.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Two uniform numbers in `[0, 1)` for one (seed, vertex, texel, sample).
pub(crate) fn jitter(seed: u64, vertex: usize, texel: usize, sample: usize) -> (f64, f64) {
    let h = mix(seed ^ mix((vertex as u64) << 32 ^ texel as u64) ^ mix(sample as u64 + 1));
    let unit = |x: u64| (x >> 11) as f64 / (1u64 << 53) as f64;
    (unit(h), unit(mix(h)))
}

#[inline]
pub(crate) fn f32x3(a: [f64; 3]) -> [f32; 3] {
    a.map(|x| x as f32)
}

/// The rays a vertex casts (the [module docs](self)): the texel centres above its horizon,
/// or with `S > 1` their `S x S` jittered sub-rays above it, in [`block_order`].
pub(crate) struct RaySet {
    param: Parameterization,
    /// Texel centre directions, by texel index.
    pub(crate) directions: Vec<[f64; 3]>,
    order: Vec<usize>,
    samples: usize,
    seed: u64,
}

impl RaySet {
    pub(crate) fn new(options: &VisibilityOptions) -> Self {
        RaySet {
            param: options.param,
            directions: texel_directions(options.param),
            order: block_order(options.param),
            samples: options.samples,
            seed: options.seed,
        }
    }

    /// Calls `ray(direction, texel)` for every ray vertex `v` (unit normal `n`) casts.
    pub(crate) fn for_each(&self, v: usize, n: [f64; 3], mut ray: impl FnMut([f32; 3], usize)) {
        let (s, samples) = (self.param.face_size(), self.samples);
        for &t in &self.order {
            if dot(n, self.directions[t]) <= 0.0 {
                continue;
            }
            if samples == 1 {
                ray(f32x3(self.directions[t]), t);
                continue;
            }
            let (face, row, col) = (t / (s * s), (t / s) % s, t % s);
            for k in 0..samples * samples {
                let (ju, jv) = jitter(self.seed, v, t, k);
                let r = row as f64 + ((k / samples) as f64 + ju) / samples as f64;
                let c = col as f64 + ((k % samples) as f64 + jv) / samples as f64;
                let d = self.param.point(face, r, c);
                if dot(n, d) > 0.0 {
                    ray(f32x3(d), t);
                }
            }
        }
    }
}

/// Texel indices face by face in [`BLOCK`] x [`BLOCK`] blocks (row-major inside a block and
/// across blocks): consecutive rays of a vertex then point at neighbouring texels, so a packet
/// of them is a narrow cone.
fn block_order(param: Parameterization) -> Vec<usize> {
    let s = param.face_size();
    let mut order = Vec::with_capacity(param.texels());
    for face in 0..param.faces() {
        for r0 in (0..s).step_by(BLOCK) {
            for c0 in (0..s).step_by(BLOCK) {
                for r in r0..(r0 + BLOCK).min(s) {
                    for c in c0..(c0 + BLOCK).min(s) {
                        order.push((face * s + r) * s + c);
                    }
                }
            }
        }
    }
    order
}

/// The side of the texel blocks rays are cast in: a block's `BLOCK^2` centres fill one packet.
const BLOCK: usize = 4;

/// The rays cast per call of [`Caster::cast`]: a bound on the buffer whatever the samples per
/// texel.
pub(crate) const BATCH: usize = 1024;

/// What a vertex's rays are asked, and what is folded from them; see the [module docs](self).
pub(crate) trait Caster: Sync {
    /// One thread's working state, reused from vertex to vertex.
    type Thread: Send;
    /// What is kept of one vertex.
    type Row: Send;

    /// A fresh thread state.
    fn thread(&self) -> Self::Thread;

    /// Bytes one thread state holds.
    fn thread_bytes(&self) -> usize;

    /// Sets `blocked[k]` for the rays `directions[k]` (through texels `texels[k]`) from
    /// `origin` of the vertex with normal `n`, folding what else it keeps into `thread`.
    fn cast(
        &self,
        thread: &mut Self::Thread,
        origin: [f32; 3],
        n: [f64; 3],
        directions: &[[f32; 3]],
        texels: &[u32],
        blocked: &mut [bool],
    );

    /// The row of the vertex with normal `n` whose rays escaped `escaped[t]` times through
    /// texel `t`; `thread` is left ready for the next vertex.
    fn finish(&self, thread: &mut Self::Thread, n: [f64; 3], escaped: &[u32]) -> Result<Self::Row>;
}

/// Visibility alone, by any-hit queries.
pub(crate) struct Occluding<'a, O>(pub(crate) &'a O);

impl<O: Occlusion> Caster for Occluding<'_, O> {
    type Thread = ();
    type Row = ();

    fn thread(&self) {}

    fn thread_bytes(&self) -> usize {
        0
    }

    fn cast(
        &self,
        _: &mut (),
        origin: [f32; 3],
        _: [f64; 3],
        directions: &[[f32; 3]],
        _: &[u32],
        blocked: &mut [bool],
    ) {
        self.0
            .occluded_from(origin, directions, f32::INFINITY, blocked);
    }

    fn finish(&self, _: &mut (), _: [f64; 3], _: &[u32]) -> Result<()> {
        Ok(())
    }
}

/// A caster whose rows also carry the vertex's direct transport, encoded:
/// `T_v(t) = escaped_t / S^2 x max(0, n . w_t)`, weighted by the solid angle and transformed
/// by the [`Encoder`] ([`visibility`](super::visibility)'s contract).
pub(crate) struct Visible<'a, C> {
    inner: C,
    encoder: &'a Encoder,
    param: Parameterization,
    directions: Vec<[f64; 3]>,
    samples: usize,
}

impl<'a, C: Caster> Visible<'a, C> {
    pub(crate) fn new(inner: C, encoder: &'a Encoder, options: &VisibilityOptions) -> Self {
        Visible {
            inner,
            encoder,
            param: options.param,
            directions: texel_directions(options.param),
            samples: options.samples,
        }
    }
}

impl<C: Caster> Caster for Visible<'_, C> {
    type Thread = (C::Thread, Array3<f32>);
    type Row = (Encoded, C::Row);

    fn thread(&self) -> Self::Thread {
        let (f, s) = (self.param.faces(), self.param.face_size());
        (self.inner.thread(), Array3::zeros((f, s, s)))
    }

    /// The inner caster's and the texel values encoded.
    fn thread_bytes(&self) -> usize {
        self.inner.thread_bytes() + self.param.texels() * 4
    }

    fn cast(
        &self,
        (inner, _): &mut Self::Thread,
        origin: [f32; 3],
        n: [f64; 3],
        directions: &[[f32; 3]],
        texels: &[u32],
        blocked: &mut [bool],
    ) {
        (self.inner).cast(inner, origin, n, directions, texels, blocked);
    }

    fn finish(
        &self,
        (inner, values): &mut Self::Thread,
        n: [f64; 3],
        escaped: &[u32],
    ) -> Result<Self::Row> {
        let rays = (self.samples * self.samples) as f64;
        let flat = values.as_slice_mut().expect("fresh array is contiguous");
        for ((value, &w), &e) in flat.iter_mut().zip(&self.directions).zip(escaped) {
            let cos = dot(n, w);
            *value = if cos <= 0.0 {
                0.0
            } else {
                (e as f64 / rays * cos) as f32
            };
        }
        let encoded = self.encoder.encode(values.view())?;
        Ok((encoded, self.inner.finish(inner, n, escaped)?))
    }
}

/// Bytes the threads of [`cast_vertices`] hold: each its [`Batch`] and `caster`'s state.
pub(crate) fn working_bytes<C: Caster>(caster: &C, param: Parameterization) -> usize {
    let batch = param.texels() * 4 + BATCH * (12 + 4 + 1);
    rayon::current_num_threads() * (batch + caster.thread_bytes())
}

/// Casts every ray of the vertices `vertices` of `mesh` through `caster`, in parallel: its
/// rows in vertex order and the rays cast. `label` names the progress bar.
pub(crate) fn cast_vertices<C: Caster>(
    mesh: &Mesh,
    caster: &C,
    options: &VisibilityOptions,
    vertices: Range<usize>,
    label: &str,
) -> Result<(Vec<C::Row>, u64)> {
    let rays = RaySet::new(options);
    let origins = RayOrigins::new(mesh);
    let texels = options.param.texels();
    let bar = Task::begin(options.progress, label, vertices.len());
    let rows: Vec<Result<(C::Row, u64)>> = vertices
        .into_par_iter()
        .map_init(
            || (Batch::new(texels), caster.thread()),
            |(batch, thread), v| {
                let (origin, n) = origins.origin_and_normal(v);
                batch.start(f32x3(origin), n);
                rays.for_each(v, n, |d, t| batch.push(caster, thread, d, t));
                batch.flush(caster, thread);
                let row = caster.finish(thread, n, &batch.escaped)?;
                bar.advance(1);
                Ok((row, batch.rays))
            },
        )
        .collect();
    let mut out = Vec::with_capacity(rows.len());
    let mut cast = 0;
    for row in rows {
        let (row, r) = row?;
        out.push(row);
        cast += r;
    }
    Ok((out, cast))
}

/// One thread's rays waiting to be cast, their texels and answers, and the escaped counts of
/// the vertex being cast.
struct Batch {
    origin: [f32; 3],
    normal: [f64; 3],
    directions: Vec<[f32; 3]>,
    texels: Vec<u32>,
    blocked: Vec<bool>,
    escaped: Vec<u32>,
    rays: u64,
}

impl Batch {
    fn new(texels: usize) -> Self {
        Batch {
            origin: [0.0; 3],
            normal: [0.0; 3],
            directions: Vec::with_capacity(BATCH),
            texels: Vec::with_capacity(BATCH),
            blocked: vec![false; BATCH],
            escaped: vec![0; texels],
            rays: 0,
        }
    }

    fn start(&mut self, origin: [f32; 3], normal: [f64; 3]) {
        (self.origin, self.normal, self.rays) = (origin, normal, 0);
        self.escaped.fill(0);
    }

    fn push<C: Caster>(
        &mut self,
        caster: &C,
        thread: &mut C::Thread,
        direction: [f32; 3],
        texel: usize,
    ) {
        self.directions.push(direction);
        self.texels.push(texel as u32);
        if self.directions.len() == BATCH {
            self.flush(caster, thread);
        }
    }

    /// Casts the waiting rays and counts the escaped ones into their texels.
    fn flush<C: Caster>(&mut self, caster: &C, thread: &mut C::Thread) {
        let n = self.directions.len();
        let blocked = &mut self.blocked[..n];
        caster.cast(
            thread,
            self.origin,
            self.normal,
            &self.directions,
            &self.texels,
            blocked,
        );
        for (&t, &b) in self.texels.iter().zip(blocked.iter()) {
            self.escaped[t as usize] += u32::from(!b);
        }
        self.rays += n as u64;
        self.directions.clear();
        self.texels.clear();
    }
}
