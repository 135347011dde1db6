//! Interreflected transport: light that reaches a vertex after bouncing off the scene's
//! Lambertian surfaces, gathered in the Haar basis (issue 51's contract).
//!
//! **What is computed.** Bounce 0 is the direct transport `T0_v` ([`TransportSet`]). Bounce
//! `b + 1` gathers, over the rays visibility casts (the texel directions `u` of the
//! transport's parameterisation, origins `eps` off the surface along the normal, and with
//! `S > 1` the same `S x S` jittered sub-rays, each weighing `1 / S^2`), the bounce-`b`
//! transport of the **closest** surface each ray hits:
//!
//! `T(b+1)_v = sum over rays u that hit of max(0, n_v . u) dOmega_u / S^2 x (rho_hit / pi) x interp_hit(Tb)`
//!
//! the rendering equation's one-bounce operator on a Lambertian surface (Kajiya 1986) as
//! Sloan, Kautz and Snyder (2002, section 5) gather their interreflected transfer. The cosine
//! and the solid angle are those of the texel's centre, as in visibility. `interp_hit`
//! interpolates the hit triangle's three vertices' transport barycentrically (the [`Hit`]'s
//! `(1 - u - v, u, v)`), and `rho_hit` their RGB albedo the same way. A ray contributes zero
//! when the hit's **shading normal** (its triangle's three vertex normals interpolated by the
//! same weights) does not face back along it (`n_s . u >= 0`), whatever the triangle's
//! winding: a one-sided diffuse surface reflects only on its shading normal's side, as Mitsuba
//! 3's `diffuse` and pbrt-v4's `DiffuseBxDF` do (both evaluate the BSDF in the shading frame;
//! the winding decides nothing). A jittered sub-ray below the horizon contributes zero too (it
//! is not cast). Rays start where [`origin`](super::origin) says, off creases and contact.
//! [`SceneBvh`] holds one triangle of each set of duplicates (the same three corners in any
//! order) and none of zero area, and a hit names the mesh triangle it stands for: of a pair of
//! opposite-facing duplicates (a two-sided sheet) the first in the mesh's order answers, so
//! light bounces off the side it faces and the other side gathers nothing from it.
//!
//! **Linearity.** Every bounce is a sum of whole transport vectors indexed like `T0` by the
//! environment's texels (light from texel `s` reaches the hit and bounces to `v`), so it is
//! formed from Haar coefficients directly (the transform is linear), and the bounced sum obeys
//! `T1 + ... + T(b+1) = G(T0 + T1 + ... + Tb)`, `G` the gather above. The sum is therefore
//! built bounce by bounce from the direct transport and the previous sum only: what a cache
//! with `b` bounces stores, so a shard can add bounce `b + 1` from the merged cache of `b`
//! ([`bounce_range`]).
//!
//! **Sharing work.** A vertex's rays are cast once and folded into weights per hit vertex,
//! `W_c[v][i] = sum over rays hitting a triangle with corner i of w_ray beta_i rho_hit,c / pi`
//! (`beta_i` the corner's barycentric weight); then one sparse row combination per distinct
//! hit vertex, `sum_i W_c[v][i] (T0_i + S_i,c)`, accumulated densely in f64 and truncated.
//! The weights are kept between bounces, so `B` bounces cast each ray once, and a whole
//! precomputation casts it once for direct and bounced light together: the closest hit
//! answers visibility too (a ray is blocked exactly when it hits something, front or back).
//! The row combination is `precompute::combine`'s: dense tiles of the stored rows when
//! they are dense (the bunny's), a scatter of each sparse row otherwise, with the same bits
//! (`results/relight/bounces.md` reports the gather's seconds beside the casting's).
//!
//! **Channels.** `rho_hit` is baked in, so the bounced sum is per channel: three sparse
//! vectors a vertex ([`BouncedTransport::channels`] has three sets, R, G, B), or one when every
//! vertex's albedo is grey (its three values bit-equal: one set, used for all three
//! channels). The count of sets is what a reader goes by ([`BouncedTransport::is_grey`]).
//!
//! **Truncation.** The bounced sum of every channel is truncated with the direct transport's
//! [`Selection`] (`--keep-visibility`) after each bounce, by the rule that truncated `T0`, and
//! bounce `b + 1` gathers the **truncated** quantities: the stored `T0` and the stored sum of
//! bounce `b`, `S(b+1) = keep(G(T0~ + S(b)~))`. With every coefficient kept, this is the
//! exact sum. The spherical-harmonic transfer (when the direct set carries it) is gathered
//! the same way with the same weights, untruncated: Sloan, Kautz and Snyder's (2002)
//! interreflected transfer vectors.
//!
//! **Where it goes.** [`precompute`](super::precompute) with
//! [`PrecomputeOptions::bounces`](super::PrecomputeOptions::bounces) gathers the sum for
//! every vertex and the cache stores it beside the direct transport
//! ([`SceneCache::bounced`](crate::SceneCache::bounced)); the Lambertian Haar and
//! spherical-harmonic shaders add it ([`ShadingInput::bounced`](crate::shade::ShadingInput::bounced)).
//! Sharded, [`precompute_bounce_shard`](super::precompute_bounce_shard) adds one bounce to a
//! shard's vertices from the merged cache of the bounce before.
//!
//! **Limits.** Lambertian scenes only: the rendered radiance is `rho_v / pi x <T0_v + S_v,c,
//! L_c>`, so a cache with bounces renders with its stored albedo alone. At most
//! [`MAX_BOUNCES`].

use std::ops::Range;
use std::time::Instant;

use ndarray::{ArrayView2, ArrayView3};

use crate::Mesh;
use crate::material::brdf::check_albedo;
use crate::precompute::cast::{BATCH, Caster, Visible, cast_vertices, working_bytes};
use crate::precompute::combine::{RowCombiner, Terms, Weights};
use crate::precompute::raycast::{Hit, SceneBvh};
use crate::precompute::transport_set::Encoder;
use crate::precompute::transport_set::{Encoded, TransportSet};
use crate::precompute::visibility::{PrecomputeReport, VisibilityOptions, texel_directions};
use crate::scene::mesh::dot;
use crate::sh_transfer::ShTransfer;
use crate::{Error, Result};
use haarshift::faces::integrate::layout;
use haarshift::product::Selection;
use haarshift::product::kept::kept_of_coefficients;
use haarshift::progress::Task;

/// The most bounces a precomputation gathers (`--bounces`).
pub const MAX_BOUNCES: usize = 8;

/// The bounced sum `T1 + ... + TB` of a range of vertices, per channel; see the
/// [module docs](self).
///
/// ```
/// use haarshift_relight::precompute::bounce::{BouncedTransport, bounce_range};
/// use haarshift_relight::{Generator, SceneBvh, VisibilityOptions, vertex_major};
/// use haarshift::faces::{ParamKind, Parameterization};
/// use ndarray::Array2;
/// let mesh = Generator::Sphere { cells: 2 }.mesh().unwrap();
/// let options = VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 4).unwrap());
/// let bvh = SceneBvh::new(&mesh);
/// let (direct, _) = vertex_major(&mesh, &bvh, &options).unwrap();
/// let albedo = Array2::from_elem((54, 3), 0.5f32);
/// let all = 0..54;
/// let (bounced, _) = bounce_range(&mesh, &bvh, &options, albedo.view(), &direct, None, 2, all).unwrap();
/// assert_eq!((bounced.bounces(), bounced.is_grey(), bounced.vertex_count()), (2, true, 54));
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct BouncedTransport {
    bounces: usize,
    channels: Vec<TransportSet>,
}

impl BouncedTransport {
    /// The sum of `bounces` bounces (1 to [`MAX_BOUNCES`]) from its channels' sets: one
    /// (grey) or three (R, G, B), of the same vertices, parameterisation, truncation and
    /// spherical-harmonic bands.
    ///
    /// ```
    /// use haarshift::product::Selection;
    /// use haarshift_relight::TransportSet;
    /// use haarshift_relight::precompute::bounce::BouncedTransport;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let set = TransportSet::new(Parameterization::new(ParamKind::Cube, 4).unwrap(), Selection::All);
    /// assert!(BouncedTransport::new(1, vec![set.clone()]).unwrap().is_grey());
    /// assert!(BouncedTransport::new(1, vec![set.clone(), set.clone()]).is_err());
    /// assert!(BouncedTransport::new(9, vec![set]).is_err());
    /// ```
    pub fn new(bounces: usize, channels: Vec<TransportSet>) -> Result<Self> {
        check_bounces(bounces)?;
        let alike = |a: &TransportSet, b: &TransportSet| {
            let bands = |s: &TransportSet| s.sh().map(ShTransfer::bands);
            (a.param(), a.keep(), bands(a), a.vertex_count())
                == (b.param(), b.keep(), bands(b), b.vertex_count())
        };
        if !matches!(channels.len(), 1 | 3) || !channels.iter().all(|c| alike(c, &channels[0])) {
            return Err(Error::parameter(
                "bounced transport",
                "one set (grey albedo) or three (R, G, B) of the same vertices and parameters",
            ));
        }
        Ok(BouncedTransport { bounces, channels })
    }

    /// Bounces summed.
    pub fn bounces(&self) -> usize {
        self.bounces
    }

    /// The sets stored: one when every albedo is grey, else R, G and B.
    pub fn channels(&self) -> &[TransportSet] {
        &self.channels
    }

    /// Whether one set serves all three channels.
    pub fn is_grey(&self) -> bool {
        self.channels.len() == 1
    }

    /// The set of colour channel `c` (0, 1, 2: R, G, B; the one set when grey).
    pub fn channel(&self, c: usize) -> &TransportSet {
        &self.channels[c.min(self.channels.len() - 1)]
    }

    /// Vertices held.
    pub fn vertex_count(&self) -> usize {
        self.channels[0].vertex_count()
    }

    /// Haar coefficients stored, all channels.
    pub fn coefficient_count(&self) -> usize {
        self.channels
            .iter()
            .map(TransportSet::coefficient_count)
            .sum()
    }

    /// Bytes held, all channels.
    pub fn stored_bytes(&self) -> usize {
        self.channels.iter().map(TransportSet::stored_bytes).sum()
    }

    /// Appends every vertex of `other` after this sum's (the merge of shards): both must sum
    /// the same bounces in as many channels of the same parameters.
    pub(crate) fn append(&mut self, other: &BouncedTransport) -> Result<()> {
        if (self.bounces, self.channels.len()) != (other.bounces, other.channels.len()) {
            return Err(Error::parameter(
                "bounced transport",
                "only sums of the same bounces and channels are joined",
            ));
        }
        for (mine, theirs) in self.channels.iter_mut().zip(&other.channels) {
            mine.append(theirs)?;
        }
        Ok(())
    }
}

/// Refuses a bounce count outside `1..=MAX_BOUNCES`.
pub(crate) fn check_bounces(bounces: usize) -> Result<()> {
    if (1..=MAX_BOUNCES).contains(&bounces) {
        return Ok(());
    }
    Err(Error::parameter(
        "bounces",
        format!("{bounces}: must be 0 to {MAX_BOUNCES}"),
    ))
}

/// Whether every vertex's albedo is grey (R, G and B bit-equal): the bounced sum is then one
/// set.
///
/// ```
/// use haarshift_relight::precompute::bounce::is_grey;
/// use ndarray::array;
/// assert!(is_grey(array![[0.5f32, 0.5, 0.5], [0.8, 0.8, 0.8]].view()));
/// assert!(!is_grey(array![[0.5f32, 0.5, 0.5], [0.8, 0.8, 0.7]].view()));
/// ```
pub fn is_grey(albedo: ArrayView2<'_, f32>) -> bool {
    albedo
        .rows()
        .into_iter()
        .all(|r| r.iter().all(|x| x.to_bits() == r[0].to_bits()))
}

/// The bounced sum of `bounces` bounces of the vertices `vertices`, from the direct transport
/// `direct` of **every** vertex (made with `options`) and, when given, `lower`: the bounced
/// sum of fewer bounces of every vertex (a merged cache's), which it continues; see the
/// [module docs](self). A range short of the whole mesh adds one bounce only (bounce `b + 1`
/// of one vertex needs bounce `b` of all), so a sharded run goes bounce by bounce with a merge
/// between. The report counts the rays cast (each once, whatever the bounces).
///
/// ```
/// use haarshift_relight::precompute::bounce::bounce_range;
/// use haarshift_relight::{Generator, SceneBvh, VisibilityOptions, vertex_major};
/// use haarshift::faces::{ParamKind, Parameterization};
/// use ndarray::Array2;
/// let mesh = Generator::Sphere { cells: 2 }.mesh().unwrap();
/// let options = VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 4).unwrap());
/// let bvh = SceneBvh::new(&mesh);
/// let (direct, _) = vertex_major(&mesh, &bvh, &options).unwrap();
/// let albedo = Array2::from_elem((54, 3), 0.5f32);
/// let run = |lower, b, range| bounce_range(&mesh, &bvh, &options, albedo.view(), &direct, lower, b, range);
/// let (two, _) = run(None, 2, 0..54).unwrap();
/// let (one, _) = run(None, 1, 0..54).unwrap();
/// let (part, _) = run(Some(&one), 2, 10..20).unwrap(); // shard of bounce 2 from bounce 1
/// assert_eq!(part.channel(0).coefficients(3), two.channel(0).coefficients(13));
/// assert!(run(None, 2, 10..20).is_err()); // two bounces of a part at once
/// ```
#[allow(clippy::too_many_arguments)]
pub fn bounce_range(
    mesh: &Mesh,
    bvh: &SceneBvh,
    options: &VisibilityOptions,
    albedo: ArrayView2<'_, f32>,
    direct: &TransportSet,
    lower: Option<&BouncedTransport>,
    bounces: usize,
    vertices: Range<usize>,
) -> Result<(BouncedTransport, PrecomputeReport)> {
    options.check()?;
    check_bounces(bounces)?;
    check_albedo(albedo)?;
    let count = mesh.vertex_count();
    let grey = is_grey(albedo);
    let from = lower.map_or(0, BouncedTransport::bounces);
    let whole = vertices == (0..count);
    let why = if albedo.nrows() != count || direct.vertex_count() != count {
        Some(format!(
            "the albedo and the direct transport must have the mesh's {count} vertices"
        ))
    } else if (direct.param(), direct.keep()) != (options.param, options.keep) {
        Some("the direct transport was made with other directions or truncation".into())
    } else if vertices.start > vertices.end || vertices.end > count {
        Some(format!(
            "vertices {}..{} of {count}",
            vertices.start, vertices.end
        ))
    } else if from >= bounces {
        Some(format!("{bounces} bounces asked for from a sum of {from}"))
    } else if !whole && bounces - from > 1 {
        Some(format!(
            "a part of the vertices adds one bounce at a time (bounce {} of all vertices is \
             needed first)",
            bounces - 1
        ))
    } else {
        lower.and_then(|l| {
            let bands = |s: &TransportSet| s.sh().map(ShTransfer::bands);
            let c = l.channel(0);
            ((l.vertex_count(), l.is_grey(), c.param(), c.keep(), bands(c))
                != (count, grey, direct.param(), direct.keep(), bands(direct)))
                .then(|| "the lower bounces were made for other vertices, albedo or options".into())
        })
    };
    if let Some(why) = why {
        return Err(Error::parameter("bounces", why));
    }
    let start = Instant::now();
    let folding = HitFolding::new(mesh, bvh, options, albedo, grey);
    let (rows, rays) = cast_vertices(mesh, &folding, options, vertices, "bounce rays")?;
    let weights = HitWeights::from_rows(folding.channels, rows);
    let (sum, gathering) = sum_up(&weights, direct, lower, bounces, options.progress)?;
    let seconds = start.elapsed().as_secs_f64();
    let report = PrecomputeReport {
        rays,
        seconds,
        working_bytes: weights.bytes() + working_bytes(&folding, options.param).max(gathering),
        tracer: Some(bvh.tracer()),
        bounce_seconds: seconds,
    };
    Ok((sum, report))
}

/// The direct transport of every vertex of `mesh` and the bounced sum of `bounces` bounces
/// (1 to [`MAX_BOUNCES`]), from **one** cast of every ray: a closest-hit query answers
/// visibility (a ray is blocked exactly when it hits something) as the any-hit query of
/// [`vertex_major`](super::visibility::vertex_major) does, and its hit is folded into the
/// weights per hit vertex; the direct transport has the bits [`vertex_major`] gives and the
/// sum those of [`bounce_range`] over every vertex. The report's bounce seconds are the
/// gather's.
pub(crate) fn direct_and_bounced(
    mesh: &Mesh,
    bvh: &SceneBvh,
    options: &VisibilityOptions,
    albedo: ArrayView2<'_, f32>,
    bounces: usize,
) -> Result<(TransportSet, BouncedTransport, PrecomputeReport)> {
    options.check()?;
    check_bounces(bounces)?;
    check_albedo(albedo)?;
    let count = mesh.vertex_count();
    if albedo.nrows() != count {
        return Err(Error::parameter(
            "bounces",
            format!("the albedo must have the mesh's {count} vertices"),
        ));
    }
    let start = Instant::now();
    let encoder = Encoder::new(options.param, options.keep, options.sh_bands)?;
    let folding = HitFolding::new(mesh, bvh, options, albedo, is_grey(albedo));
    let channels = folding.channels;
    let caster = Visible::new(folding, &encoder, options);
    let label = "visibility and bounce rays";
    let (rows, rays) = cast_vertices(mesh, &caster, options, 0..count, label)?;
    let mut direct = encoder.empty_set()?;
    let mut hits = Vec::with_capacity(rows.len());
    for (vertex, row) in rows {
        direct.extend(&vertex);
        hits.push(row);
    }
    let weights = HitWeights::from_rows(channels, hits);
    let gathering = Instant::now();
    let (sum, gather_bytes) = sum_up(&weights, &direct, None, bounces, options.progress)?;
    let cast_bytes = working_bytes(&caster, options.param) + encoder.bytes();
    let report = PrecomputeReport {
        rays,
        seconds: start.elapsed().as_secs_f64(),
        working_bytes: weights.bytes() + cast_bytes.max(gather_bytes),
        tracer: Some(bvh.tracer()),
        bounce_seconds: gathering.elapsed().as_secs_f64(),
    };
    Ok((direct, sum, report))
}

/// `lower` (or nothing) continued to `bounces` bounces by gathering through `weights`, and
/// the most bytes a gather held besides its inputs and output.
fn sum_up(
    weights: &HitWeights,
    direct: &TransportSet,
    lower: Option<&BouncedTransport>,
    bounces: usize,
    progress: bool,
) -> Result<(BouncedTransport, usize)> {
    let from = lower.map_or(0, BouncedTransport::bounces);
    let (mut sum, mut most) = (lower.cloned(), 0);
    for bounce in from + 1..=bounces {
        let (next, bytes) = gather(weights, direct, sum.as_ref(), bounce, progress)?;
        (sum, most) = (Some(next), most.max(bytes));
    }
    let sum = sum.ok_or_else(|| {
        Error::parameter(
            "bounces",
            format!("{bounces} bounces asked for from a sum of {from}"),
        )
    })?;
    Ok((sum, most))
}

/// The weights per hit vertex of a range of vertices, `W_c[v][i]` (see the
/// [module docs](self)), as sparse rows: row `k` is vertex `first + k`, its hit vertices
/// ascending, `channels` weights each.
struct HitWeights {
    channels: usize,
    offsets: Vec<usize>,
    hits: Vec<u32>,
    weights: Vec<f32>,
}

impl HitWeights {
    fn row(&self, k: usize) -> (&[u32], &[f32]) {
        let (a, b) = (self.offsets[k], self.offsets[k + 1]);
        (
            &self.hits[a..b],
            &self.weights[a * self.channels..b * self.channels],
        )
    }

    fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    fn bytes(&self) -> usize {
        self.offsets.len() * 8 + self.hits.len() * 4 + self.weights.len() * 4
    }

    /// The weights of `channels` channels from one row (hit vertices, weights) a vertex.
    fn from_rows(channels: usize, rows: Vec<(Vec<u32>, Vec<f32>)>) -> Self {
        let mut out = HitWeights {
            channels,
            offsets: Vec::with_capacity(rows.len() + 1),
            hits: Vec::new(),
            weights: Vec::new(),
        };
        out.offsets.push(0);
        for (hits, w) in rows {
            out.hits.extend_from_slice(&hits);
            out.weights.extend_from_slice(&w);
            out.offsets.push(out.hits.len());
        }
        out
    }
}

/// Folds the front-face closest hits of a vertex's rays into its weights per hit vertex (see
/// the [module docs](self)); a ray is blocked when it hits anything, front or back.
struct HitFolding<'a> {
    mesh: &'a Mesh,
    bvh: &'a SceneBvh,
    albedo: ArrayView2<'a, f32>,
    channels: usize,
    /// Texel centre directions and solid angles, by texel index.
    directions: Vec<[f64; 3]>,
    solid: Vec<f64>,
    /// `1 / (S^2 pi)`.
    per_ray: f64,
}

impl<'a> HitFolding<'a> {
    fn new(
        mesh: &'a Mesh,
        bvh: &'a SceneBvh,
        options: &VisibilityOptions,
        albedo: ArrayView2<'a, f32>,
        grey: bool,
    ) -> Self {
        let samples = options.samples * options.samples;
        HitFolding {
            mesh,
            bvh,
            albedo,
            channels: if grey { 1 } else { 3 },
            directions: texel_directions(options.param),
            solid: options.param.solid_angles().into_iter().collect(),
            per_ray: 1.0 / samples as f64 / std::f64::consts::PI,
        }
    }
}

impl Caster for HitFolding<'_> {
    type Thread = Folder;
    type Row = (Vec<u32>, Vec<f32>);

    fn thread(&self) -> Folder {
        Folder::new(self.mesh.vertex_count(), self.channels)
    }

    /// The batch's hits and the dense weights over the mesh's vertices.
    fn thread_bytes(&self) -> usize {
        let hits = BATCH * std::mem::size_of::<Option<Hit>>();
        hits + self.mesh.vertex_count() * (8 * self.channels + 1)
    }

    fn cast(
        &self,
        folder: &mut Folder,
        origin: [f32; 3],
        n: [f64; 3],
        directions: &[[f32; 3]],
        texels: &[u32],
        blocked: &mut [bool],
    ) {
        let hits = &mut folder.hits[..directions.len()];
        (self.bvh).closest_hits_from(origin, directions, f32::INFINITY, hits);
        let triangles = self.mesh.triangles();
        for (k, hit) in hits.iter().enumerate() {
            blocked[k] = hit.is_some();
            let Some(hit) = hit else { continue };
            let corners = triangles[hit.triangle];
            if facing_normal(self.mesh, hit, directions[k].map(f64::from)).is_none() {
                continue; // the far side of the hit's shading normal
            }
            let beta = hit.weights();
            let mut rho = [0.0; 3];
            for (&corner, &bk) in corners.iter().zip(&beta) {
                let albedo = self.albedo.row(corner as usize);
                for (r, &x) in rho.iter_mut().zip(albedo) {
                    *r += bk * f64::from(x);
                }
            }
            let t = texels[k] as usize;
            let w = dot(n, self.directions[t]) * self.solid[t] * self.per_ray;
            for (&corner, &bk) in corners.iter().zip(&beta) {
                folder.weights.add(corner, rho.map(|r| w * bk * r));
            }
        }
    }

    fn finish(&self, folder: &mut Folder, _: [f64; 3], _: &[u32]) -> Result<Self::Row> {
        Ok(folder.weights.take())
    }
}

/// The shading normal at `hit` (its triangle's vertex normals interpolated by the hit's
/// barycentric weights, not normalised) when it faces back along the ray's direction `d`
/// (`n_s . d < 0`), and `None` otherwise: the one-sided rule by which a hit sends light back
/// (see the [module docs](self)).
pub(crate) fn facing_normal(mesh: &Mesh, hit: &Hit, d: [f64; 3]) -> Option<[f64; 3]> {
    let corners = mesh.triangles()[hit.triangle];
    let normals = mesh.normals();
    let beta = hit.weights();
    let n: [f64; 3] = std::array::from_fn(|k| {
        (0..3)
            .map(|i| beta[i] * normals[[corners[i] as usize, k]])
            .sum()
    });
    (dot(n, d) < 0.0).then_some(n)
}

/// One thread's closest hits of a batch and the weights of the vertex being cast.
struct Folder {
    hits: Vec<Option<Hit>>,
    weights: DenseWeights,
}

impl Folder {
    fn new(vertices: usize, channels: usize) -> Self {
        Folder {
            hits: vec![None; BATCH],
            weights: DenseWeights {
                channels,
                dense: vec![0.0; vertices * channels],
                touched: Vec::new(),
                seen: vec![false; vertices],
            },
        }
    }
}

/// Weights per hit vertex, dense over the mesh's vertices with the list of those touched,
/// reused from vertex to vertex.
struct DenseWeights {
    channels: usize,
    dense: Vec<f64>,
    touched: Vec<u32>,
    seen: Vec<bool>,
}

impl DenseWeights {
    fn add(&mut self, vertex: u32, weights: [f64; 3]) {
        let i = vertex as usize;
        if !self.seen[i] {
            self.seen[i] = true;
            self.touched.push(vertex);
        }
        let c = self.channels;
        for (d, w) in self.dense[i * c..(i + 1) * c].iter_mut().zip(weights) {
            *d += w;
        }
    }

    /// The touched vertices ascending with their weights (f32), the state cleared.
    fn take(&mut self) -> (Vec<u32>, Vec<f32>) {
        self.touched.sort_unstable();
        let c = self.channels;
        let mut weights = Vec::with_capacity(self.touched.len() * c);
        for &i in &self.touched {
            let i = i as usize;
            weights.extend(self.dense[i * c..(i + 1) * c].iter().map(|&w| w as f32));
            self.dense[i * c..(i + 1) * c].fill(0.0);
            self.seen[i] = false;
        }
        (std::mem::take(&mut self.touched), weights)
    }
}

/// One more bounce: `keep(G(T0~ + lower~))` per channel for the rows of `weights`, from the
/// direct transport and the lower sum of every vertex, and the bytes the row combination
/// held ([`RowCombiner::bytes`]).
fn gather(
    weights: &HitWeights,
    direct: &TransportSet,
    lower: Option<&BouncedTransport>,
    bounce: usize,
    progress: bool,
) -> Result<(BouncedTransport, usize)> {
    let param = direct.param();
    let (faces, s) = (param.faces(), param.face_size());
    let keep: Selection = direct.keep();
    let bands = direct.sh().map(ShTransfer::bands);
    let sh_len = bands.map_or(0, |b| b * b);
    let channels = weights.channels;
    let label = format!("bounce {bounce} (gather)");
    let bar = Task::begin(progress, &label, weights.len() * channels);
    // The sets added, direct first: channel `c` of output row `k * channels + c` adds set 0
    // and, from bounce 2, set `1 + c`, the lower sum's channel `c`.
    let lower_channels = lower
        .into_iter()
        .flat_map(|l| (0..channels).map(|c| l.channel(c)));
    let sets: Vec<&TransportSet> = std::iter::once(direct).chain(lower_channels).collect();
    let combiner = RowCombiner::plan(
        param.texels(),
        sets.iter().map(|set| set.rows()).collect(),
        None,
    );
    let terms = |r: usize| {
        let (k, c) = (r / channels, r % channels);
        let (hits, values) = weights.row(k);
        let w = Weights {
            values,
            stride: channels,
            offset: c,
        };
        let mut terms = vec![(0, hits, w)];
        if lower.is_some() {
            terms.push((1 + c, hits, w));
        }
        terms
    };
    let finish = |_: usize, terms: &Terms<'_>, texels: &[f32]| -> Result<Encoded> {
        let coefficients = ArrayView3::from_shape((faces, s, s), texels)
            .map_err(|e| Error::parameter("bounced transport", e.to_string()))?;
        let (indices, coefficients) = kept_of_coefficients(coefficients, layout(param), keep)?;
        let mut sh = vec![0.0f64; sh_len];
        for &(set, hits, w) in terms {
            let set = sets[set];
            for (j, &i) in hits.iter().enumerate() {
                let i = i as usize;
                let row = set
                    .sh()
                    .map_or(&[][..], |t| &t.as_slice()[i * sh_len..(i + 1) * sh_len]);
                for (o, &x) in sh.iter_mut().zip(row) {
                    *o += w.at(j) * f64::from(x);
                }
            }
        }
        bar.advance(1);
        Ok(Encoded {
            indices,
            coefficients,
            sh: sh.iter().map(|&x| x as f32).collect(),
        })
    };
    let n = weights.len() * channels;
    let rows = combiner.combine(n, terms, finish);
    let empty = || match bands {
        Some(b) => TransportSet::with_sh(param, keep, b),
        None => Ok(TransportSet::new(param, keep)),
    };
    let mut out = (0..channels).map(|_| empty()).collect::<Result<Vec<_>>>()?;
    for (r, row) in rows.into_iter().enumerate() {
        out[r % channels].extend(&row?);
    }
    Ok((BouncedTransport::new(bounce, out)?, combiner.bytes(n)))
}

#[cfg(test)]
#[path = "bounce_tests.rs"]
mod tests;
