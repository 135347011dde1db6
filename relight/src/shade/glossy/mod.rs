//! Glossy shading: per vertex, the triple product of lighting, transport and the BRDF rotated
//! into the vertex's frame.
//!
//! **What is computed.** For a vertex `v` of albedo `a_v` (the specular colour), seen from the
//! camera at `e` (`w_o = (e - p_v) / |e - p_v|`),
//! `B_v = a_v x integral of T_v(w) L(w) rho_v(w) dw`, with `T_v` the transport (visibility x
//! cosine x solid angle), `L` the lighting and `rho_v` the BRDF in the vertex's global frame
//! ([`orient`](crate::material::orient)). Each factor is truncated as the options say: the transport to
//! `--keep-visibility`, the lighting to `--keep-light`, the BRDF to `--keep-brdf` (the `K`
//! largest orthonormal details by RGB magnitude plus each face's scaling coefficient, the rule
//! of [`haarshift::product::selection`]), and all three to the detail levels `0..depth`. Vertices
//! from `object_vertices` on (the ground plane) stay Lambertian (`fn@crate::shade`).
//!
//! **How.** The triple product of the three truncated functions is the integral of the
//! product of their reconstructions, `B_v = a_v sum_p t_v(p) L~(p) rho~_v(p)` over the texels
//! `p`, with `t_v` the transport's texel values (its sparse coefficients inverted face by
//! face: the Haar basis is orthonormal, so this is Parseval's `<T_v, Q>` with `Q` the
//! coefficients of `L~ x rho~_v`). Per frame the lighting's texels are made once; per vertex,
//! one inverse transform of its transport, its BRDF's texels (rotated, or a blend of cached
//! bins) and one dense sum of `3 N` products, in buffers each thread reuses from vertex to
//! vertex. This is Sun 2006's just-in-time radiance transfer (section 3.5) with the lighting
//! and the BRDF as the fixed pair: the same number as
//! [`triple_integral`](haarshift::product::triple::triple_integral) on the three trees (tested to
//! 1e-12), and with a depth limit the same as the traversal stopped at that depth (all three
//! functions are then constant on blocks of side `S >> depth`, and so is their product).
//! A product per BRDF map and a sparse dot per vertex and map (one forward transform of
//! `L~ x rho~` per map) gives the same number; it costs more as soon as the vertices use as
//! many maps as there are vertices (no cache: one each; a cache: four bins a vertex, 4,007
//! distinct bins for the bunny's 1,839 glossy vertices at 64 x 128 bins).
//!
//! **Rotation cache** (`--rotation-cache N`, as Wang et al. 2006 precompute one rotation per
//! sampled normal). Without it every vertex rotates its own BRDF map (exact frame). With it the
//! key direction is quantised to the centres of an `N x 2N` lat-long grid of bins and each
//! bin's map is rotated once and kept for every later view and lighting:
//! * Phong: the key is the mirror direction; a vertex takes the bilinear blend of its four
//!   nearest bins (blended texel by texel; the triple product is linear in the BRDF), so the
//!   quantisation error is second order in the bin size;
//! * view-dependent BRDFs: the nearest normal bin, with the viewer's elevation and azimuth
//!   quantised as [`orient`](crate::material::orient) does anyway (the key is the triple).
//!
//! A cache starts empty and fills with the bins views ask for;
//! [`GlossyShader::fill_cache`] rotates every Phong bin ahead, so that any later view rotates
//! nothing (`--fill-cache`).
//!
//! **Precision.** The sums run in `T` (f32 for speed, f64 for checks): eight lanes over runs
//! of [`RUN`](super::lambert::RUN) texels in `T`, the runs added in f64. The BRDF maps are rotated in `T`
//! ([`Orientation::in_f32`] for f32), laid out and truncated in f64, and stored in `T`.
//! Against the f64 path's ancestor in f32 (a product per map, sparse dots) the radiance of the
//! bunny at lat-long 64 moves by 2e-7 of its RMS (`results/relight/glossy/vertex.md`).

use std::any::TypeId;
use std::collections::{BTreeSet, HashMap};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use ndarray::{Array2, ArrayView2};
use rayon::prelude::*;

use super::lambert::{PreparedTransport, ShadeOptions, select_kept, within_depth};
use super::{
    Filled, FrameSpec, HaarEncoder, Preparation, Radiance, Shader, ShaderSpec, Shading,
    ShadingInput, Timing, seconds,
};
use crate::Mesh;
use crate::light::lighting::Lighting;
use crate::material::brdf::Brdf;
use crate::material::orient::{BrdfRotation, Frame, Orientation, to_pole, unit};
use crate::precompute::transport_set::TransportSet;
use crate::{Error, Result};
use haarshift::Sample;
use haarshift::faces::Parameterization;
use haarshift::product::Selection;
use haarshift::sphere::latlong::{angles, direction};
use haarshift::transform::{Normalization, pyramid};
use texels::{Blend, LobeBuffers, TransportWork, VertexWork, triple_sum};

mod texels;

/// The most bins per axis of the rotation cache (`N x 2N` bins).
pub const MAX_CACHE_BINS: usize = 1024;

/// How glossy vertices are shaded; see the [module docs](self).
///
/// ```
/// use haarshift_relight::shade::glossy::GlossyOptions;
/// use haarshift_relight::material::orient::BrdfRotation;
/// let o = GlossyOptions::default();
/// assert_eq!((o.rotation, o.level, o.keep_brdf, o.cache_bins), (BrdfRotation::Haar, None, None, None));
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct GlossyOptions {
    /// The material of the objects (the ground plane stays Lambertian).
    pub brdf: Brdf,
    /// How the BRDF is brought into each frame.
    pub rotation: BrdfRotation,
    /// The sphere module's detail level the rotation starts from (`None`: the finest).
    pub level: Option<usize>,
    /// Detail coefficients of each rotated BRDF map kept (`None`: all).
    pub keep_brdf: Option<usize>,
    /// The coarse-to-fine cutoff of each rotated BRDF map: only its detail levels `0..L`
    /// are kept, `4^L` coefficients per face (`None`: every level). Thesis Fig. 4.7's 4, 16,
    /// 64 and 256 coefficients are `L` = 1 to 4.
    pub brdf_levels: Option<usize>,
    /// Bins per axis of the rotation cache (`None`: no cache, one rotation per vertex).
    pub cache_bins: Option<usize>,
    /// Outgoing elevations of a view-dependent BRDF's local table.
    pub elevations: usize,
}

impl GlossyOptions {
    /// Refuses what maps of `param` cannot hold: more kept coefficients than a map has
    /// details, more levels than its faces have, a cache bin count outside `1..=1024`.
    ///
    /// ```
    /// use haarshift_relight::shade::glossy::GlossyOptions;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let param = Parameterization::new(ParamKind::LatLong, 8).unwrap(); // 2 x 8^2 texels
    /// assert!(GlossyOptions::default().check(param).is_ok());
    /// let levels = GlossyOptions { brdf_levels: Some(4), ..Default::default() };
    /// assert!(levels.check(param).unwrap_err().to_string().contains("3 detail levels"));
    /// ```
    pub fn check(&self, param: Parameterization) -> Result<()> {
        if let Some(k) = self.keep_brdf {
            Selection::Largest(k).limit(param.texels() - param.faces())?;
        }
        let levels = param.face_size().trailing_zeros() as usize;
        if let Some(l) = self.brdf_levels
            && l > levels
        {
            return Err(Error::parameter(
                "brdf levels",
                format!(
                    "{l}: faces {} texels wide have {levels} detail levels (L from 0 to {levels})",
                    param.face_size()
                ),
            ));
        }
        if let Some(n) = self.cache_bins
            && !(1..=MAX_CACHE_BINS).contains(&n)
        {
            return Err(Error::parameter(
                "rotation cache",
                format!("{n} bins per axis: expected 1 to {MAX_CACHE_BINS}"),
            ));
        }
        Ok(())
    }
}

impl GlossyOptions {
    /// These options for `brdf`: as they are for a glossy one, the defaults for a Lambertian
    /// one (which they would not change).
    ///
    /// ```
    /// use haarshift_relight::Brdf;
    /// use haarshift_relight::shade::glossy::GlossyOptions;
    /// let o = GlossyOptions { keep_brdf: Some(40), ..GlossyOptions::default() };
    /// assert_eq!(o.for_brdf(&Brdf::Lambert), GlossyOptions::default());
    /// assert_eq!(o.for_brdf(&"phong:9".parse().unwrap()).keep_brdf, Some(40));
    /// ```
    pub fn for_brdf(&self, brdf: &Brdf) -> GlossyOptions {
        if brdf.is_lambert() {
            GlossyOptions::default()
        } else {
            GlossyOptions {
                brdf: brdf.clone(),
                ..self.clone()
            }
        }
    }
}

impl Default for GlossyOptions {
    fn default() -> Self {
        GlossyOptions {
            brdf: Brdf::default(),
            rotation: BrdfRotation::default(),
            level: None,
            keep_brdf: None,
            brdf_levels: None,
            cache_bins: None,
            elevations: crate::material::brdf::DEFAULT_ELEVATIONS,
        }
    }
}

/// Which bin of the rotation cache a vertex uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum MapKey {
    /// A Phong bin: the mirror direction at bin `(row, col)`.
    Mirror(u32, u32),
    /// A view-dependent bin: the normal bin `(row, col)`, the table entry and the column turn.
    View(u32, u32, u32, u32),
}

/// What one call of [`GlossyShader::shade`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GlossyReport {
    /// Distinct BRDF maps the vertices used.
    pub maps: usize,
    /// Of those, maps rotated by this call (the rest came from the cache).
    pub rotated: usize,
    /// BRDF maps held by the cache after the call.
    pub cached: usize,
    /// Seconds spent filling the rotation cache (0 without a cache).
    pub rotate_seconds: f64,
    /// Seconds spent on the products and dot products (without a cache, the per-vertex
    /// rotations too).
    pub shade_seconds: f64,
}

/// A scene's transport made ready for glossy shading, with its BRDF and rotation cache;
/// see the [module docs](self).
///
/// ```
/// use haarshift::product::Selection;
/// use haarshift_relight::{Brdf, Lighting, Mesh, ShadeOptions, TransportSet};
/// use haarshift_relight::shade::glossy::{GlossyOptions, GlossyShader};
/// use haarshift_relight::material::orient::BrdfRotation;
/// use haarshift::faces::param::{ParamKind, Parameterization, SphereMap};
/// use ndarray::{Array2, Axis, array};
/// // An upward triangle whose vertices see the whole sky: transport = cosine x solid angle.
/// let mesh = Mesh::new(array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]],
///                      vec![[0, 1, 2]], None).unwrap();
/// let param = Parameterization::new(ParamKind::LatLong, 16).unwrap();
/// let cosine = SphereMap::<f64>::from_fn(param, 1, |d, o| o[0] = d[1].max(0.0)).unwrap();
/// let unweighted = cosine.as_array().index_axis(Axis(3), 0).mapv(|v| v as f32);
/// let mut set = TransportSet::new(param, Selection::All);
/// for _ in 0..3 {
///     set.push(unweighted.view()).unwrap();
/// }
/// let sky = SphereMap::from_fn(param, 1, |_, o| o[0] = 1.0).unwrap();
/// let light = Lighting::from_map(&sky, Selection::All).unwrap();
/// let albedo = Array2::from_elem((3, 3), 1.0f32);
/// let options = GlossyOptions { brdf: Brdf::Phong { exponent: 0.0 }, rotation: BrdfRotation::Direct,
///                               ..Default::default() };
/// let shader = GlossyShader::<f64>::new(&set, &mesh, albedo.view(), &ShadeOptions::default(),
///                                       &options, 3).unwrap();
/// let (b, report) = shader.shade(&light, [0.0, 5.0, 0.0]).unwrap();
/// // Phong 0 is 1/pi everywhere: the irradiance of a unit sky, pi, times 1/pi.
/// assert!((b[[0, 0]] - 1.0).abs() < 1e-2);
/// assert_eq!(report.maps, 3); // no cache: one map per vertex
/// ```
#[derive(Debug)]
pub struct GlossyShader<T> {
    transport: PreparedTransport<T>,
    orientation: Orientation,
    keep_brdf: Option<usize>,
    brdf_levels: usize,
    bins: Option<usize>,
    positions: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
    object_vertices: usize,
    cache: Mutex<HashMap<MapKey, Arc<Vec<T>>>>,
}

/// A BRDF map as the product needs it: `channels x texels`, channel-planar, face-major.
type Planes<T> = Vec<T>;

/// The cached bins a frame uses, by key.
type Maps<T> = HashMap<MapKey, Arc<Planes<T>>>;

impl<T: Sample> GlossyShader<T> {
    /// Prepares `set` (the transport of `mesh`'s vertices) with per-vertex RGB `albedo`
    /// (`(V, 3)`): vertices `0..object_vertices` carry `options.brdf`, the rest are Lambertian.
    pub fn new(
        set: &TransportSet,
        mesh: &Mesh,
        albedo: ArrayView2<'_, f32>,
        shade: &ShadeOptions,
        options: &GlossyOptions,
        object_vertices: usize,
    ) -> Result<Self> {
        let transport = PreparedTransport::new(set, albedo, shade)?;
        let vertices = transport.vertex_count();
        if mesh.vertex_count() != vertices || object_vertices > vertices {
            return Err(Error::parameter(
                "vertices",
                format!(
                    "the mesh has {} vertices, the transport {vertices}, {object_vertices} glossy",
                    mesh.vertex_count()
                ),
            ));
        }
        let param = set.param();
        let orientation = Orientation::new(
            &options.brdf,
            param,
            options.rotation,
            options.level,
            options.elevations,
        )?;
        // An f32 shading rotates in f32 too: its lobes are rounded to f32 anyway.
        let orientation = if TypeId::of::<T>() == TypeId::of::<f32>() {
            orientation.in_f32()?
        } else {
            orientation
        };
        options.check(param)?;
        let levels = param.face_size().trailing_zeros() as usize;
        let rows = |a: ArrayView2<'_, f64>| -> Vec<[f64; 3]> {
            a.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect()
        };
        Ok(GlossyShader {
            transport,
            orientation,
            keep_brdf: options.keep_brdf,
            brdf_levels: options.brdf_levels.unwrap_or(levels),
            bins: options.cache_bins,
            positions: rows(mesh.positions()),
            normals: rows(mesh.normals()),
            object_vertices,
            cache: Mutex::new(HashMap::new()),
        })
    }

    /// The prepared transport.
    pub fn transport(&self) -> &PreparedTransport<T> {
        &self.transport
    }

    /// The BRDF maps the rotation cache holds.
    pub fn cached(&self) -> usize {
        self.cache
            .lock()
            .expect("the cache lock is never poisoned")
            .len()
    }

    /// Every vertex's outgoing radiance `(V, 3)` under `lighting`, seen from `eye`.
    pub fn shade(&self, lighting: &Lighting, eye: [f64; 3]) -> Result<(Array2<T>, GlossyReport)> {
        if !eye.iter().all(|v| v.is_finite()) {
            return Err(Error::parameter(
                "camera",
                format!("{eye:?} is not a finite position"),
            ));
        }
        let mut out = self.transport.shade(lighting)?;
        let light = light_pixels::<T>(lighting, self.transport.depth())?;
        let mut report = GlossyReport::default();
        let start = Instant::now();
        let blends: Option<(Vec<Blend>, Maps<T>)> = match self.bins {
            Some(n) => {
                let blends = (0..self.object_vertices)
                    .into_par_iter()
                    .map(|v| Ok(self.bin_keys(&self.vertex_frame(v, eye)?, n)))
                    .collect::<Result<Vec<_>>>()?;
                let used: BTreeSet<MapKey> = blends.iter().flat_map(|b| b.keys()).collect();
                report.maps = used.len();
                report.rotated = self.fill(used.iter().copied())?;
                report.rotate_seconds = start.elapsed().as_secs_f64();
                let cache = self.cache.lock().expect("the cache lock is never poisoned");
                report.cached = cache.len();
                let maps = used.iter().map(|k| (*k, Arc::clone(&cache[k]))).collect();
                Some((blends, maps))
            }
            None => {
                report.maps = self.object_vertices;
                report.rotated = self.object_vertices;
                None
            }
        };
        let start = Instant::now();
        let sums: Vec<[f64; 3]> = (0..self.object_vertices)
            .into_par_iter()
            .map_init(VertexWork::default, |work, v| {
                let rho = match &blends {
                    Some((blends, maps)) => blends[v].blend(maps, &mut work.rho),
                    None => {
                        let frame = self.vertex_frame(v, eye)?;
                        self.brdf_planes(&frame, &mut work.lobe, &mut work.rho)?;
                        &work.rho[..]
                    }
                };
                let t = self.transport_pixels(v, &mut work.transport)?;
                Ok(triple_sum(t, &light, rho))
            })
            .collect::<Result<_>>()?;
        for (v, s) in sums.iter().enumerate() {
            let a = self.transport.albedo(v);
            for c in 0..3 {
                out[[v, c]] = T::from_f64(a[c] * s[c]);
            }
        }
        report.shade_seconds = start.elapsed().as_secs_f64();
        Ok((out, report))
    }

    /// Rotates every bin of a mirror-symmetric BRDF's rotation cache that it does not hold
    /// yet (`N x 2N` maps for `--rotation-cache N`), so that every later view finds its maps
    /// there: the precomputation of one rotation per sampled direction that Wang et al. 2006
    /// make. Returns the maps rotated. A view-dependent BRDF's bins (normal x elevation x
    /// turn) are too many to fill ahead and are refused, as is a shader without a cache.
    ///
    /// ```
    /// # use haarshift::product::Selection;
    /// # use haarshift_relight::{Brdf, Mesh, ShadeOptions, TransportSet};
    /// # use haarshift_relight::shade::glossy::{GlossyOptions, GlossyShader};
    /// # use haarshift::faces::param::{ParamKind, Parameterization};
    /// # use ndarray::{Array2, Array3, array};
    /// # let mesh = Mesh::new(array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]],
    /// #                      vec![[0, 1, 2]], None).unwrap();
    /// # let param = Parameterization::new(ParamKind::LatLong, 8).unwrap();
    /// # let mut set = TransportSet::new(param, Selection::All);
    /// # for _ in 0..3 { set.push(Array3::from_elem((2, 8, 8), 0.1f32).view()).unwrap(); }
    /// # let albedo = Array2::from_elem((3, 3), 1.0f32);
    /// let options = GlossyOptions { brdf: Brdf::Phong { exponent: 20.0 }, cache_bins: Some(4),
    ///                               ..Default::default() };
    /// let shader = GlossyShader::<f32>::new(&set, &mesh, albedo.view(), &ShadeOptions::default(),
    ///                                       &options, 3).unwrap();
    /// assert_eq!(shader.fill_cache().unwrap(), 4 * 8);
    /// assert_eq!(shader.fill_cache().unwrap(), 0); // already full
    /// ```
    pub fn fill_cache(&self) -> Result<usize> {
        let Some(n) = self.bins else {
            return Err(Error::parameter(
                "rotation cache",
                "there is no cache to fill: give the shader cache bins",
            ));
        };
        if !self.orientation.brdf().is_mirror_symmetric() {
            return Err(Error::parameter(
                "rotation cache",
                format!(
                    "{} depends on the view: its bins are filled as views need them, not ahead",
                    self.orientation.brdf()
                ),
            ));
        }
        let (rows, columns) = (n as u32, 2 * n as u32);
        let keys = (0..rows).flat_map(|i| (0..columns).map(move |j| MapKey::Mirror(i, j)));
        self.fill(keys)
    }

    /// Rotates the maps of `keys` the cache lacks and adds them; returns how many.
    fn fill(&self, keys: impl Iterator<Item = MapKey>) -> Result<usize> {
        let missing: Vec<MapKey> = {
            let cache = self.cache.lock().expect("the cache lock is never poisoned");
            keys.filter(|k| !cache.contains_key(k)).collect()
        };
        let filled: Vec<(MapKey, Arc<Vec<T>>)> = missing
            .par_iter()
            .map_init(LobeBuffers::default, |lobe, &key| {
                let mut planes = Vec::new();
                self.brdf_planes(&self.frame_of(key), lobe, &mut planes)?;
                Ok((key, Arc::new(planes)))
            })
            .collect::<Result<_>>()?;
        let rotated = filled.len();
        self.cache
            .lock()
            .expect("the cache lock is never poisoned")
            .extend(filled);
        Ok(rotated)
    }

    /// Vertex `v`'s frame as seen from `eye`.
    fn vertex_frame(&self, v: usize, eye: [f64; 3]) -> Result<Frame> {
        let p = self.positions[v];
        let view = std::array::from_fn(|k| eye[k] - p[k]);
        Frame::new(self.normals[v], view).map_err(|_| {
            Error::parameter(
                "camera",
                format!("the camera {eye:?} sits on vertex {v}: it has no view direction"),
            )
        })
    }

    /// The cache bins of `frame` with their weights (see the [module docs](self)).
    fn bin_keys(&self, frame: &Frame, n: usize) -> Blend {
        let step = std::f64::consts::PI / n as f64;
        if self.orientation.brdf().is_mirror_symmetric() {
            let (theta, phi) = angles(unit(frame.mirror()).unwrap_or(frame.normal));
            let (fi, fj) = (theta / step - 0.5, phi / step - 0.5);
            let (i0, j0) = (fi.floor(), fj.floor());
            let (ti, tj) = (fi - i0, fj - j0);
            let mut keys = Blend::new();
            for (di, wi) in [(0, 1.0 - ti), (1, ti)] {
                for (dj, wj) in [(0, 1.0 - tj), (1, tj)] {
                    let w = wi * wj;
                    if w == 0.0 {
                        continue;
                    }
                    // Rows clamp at the poles, columns wrap at the seam.
                    let i = (i0 as i64 + di).clamp(0, n as i64 - 1) as u32;
                    let j = (j0 as i64 + dj).rem_euclid(2 * n as i64) as u32;
                    keys.add(MapKey::Mirror(i, j), w);
                }
            }
            return keys;
        }
        let (theta, phi) = angles(frame.normal);
        let i = ((theta / step) as usize).min(n - 1);
        let j = ((phi / step) as usize).min(2 * n - 1);
        let centre = bin_centre(n, i as u32, j as u32);
        let (entry, turn) = self
            .orientation
            .quantise(&Frame {
                normal: centre,
                outgoing: frame.outgoing,
            })
            .unwrap_or((0, 0));
        let mut keys = Blend::new();
        keys.add(
            MapKey::View(i as u32, j as u32, entry as u32, turn as u32),
            1.0,
        );
        keys
    }

    /// The frame a map key stands for.
    fn frame_of(&self, key: MapKey) -> Frame {
        let n = self.bins.unwrap_or(1);
        match key {
            MapKey::Mirror(i, j) => {
                let r = bin_centre(n, i, j);
                Frame {
                    normal: r,
                    outgoing: r,
                }
            }
            MapKey::View(i, j, entry, turn) => {
                let normal = bin_centre(n, i, j);
                let local = self.orientation.outgoing_of(entry as usize, turn as usize);
                let outgoing = to_pole(normal).inverse().apply(local);
                Frame { normal, outgoing }
            }
        }
    }

    /// The BRDF in `frame`, truncated to `--keep-brdf`, `--brdf-levels` and the depth, as
    /// channel planes in `T` ([`Planes`]) written into `out`.
    fn brdf_planes(
        &self,
        frame: &Frame,
        lobe: &mut LobeBuffers,
        out: &mut Planes<T>,
    ) -> Result<()> {
        let planes = &mut lobe.planes;
        self.orientation
            .lobe_planes(frame, planes, &mut lobe.work)?;
        let param = self.orientation.param();
        let channels = planes.len() / param.texels();
        let depth = self.transport.depth().min(self.brdf_levels);
        let levels = param.face_size().trailing_zeros() as usize;
        if self.keep_brdf.is_some() || depth < levels {
            truncate_planes(param, planes, channels, self.keep_brdf, depth)?;
        }
        out.clear();
        out.extend(planes.iter().map(|&v| T::from_f64(v)));
        Ok(())
    }

    /// Vertex `v`'s transport as texel values (face by face, row by row): its sparse
    /// coefficients scattered and inverted face by face into `work`.
    fn transport_pixels<'w>(&self, v: usize, work: &'w mut TransportWork<T>) -> Result<&'w [T]> {
        let param = self.transport.param();
        let texels = param.texels();
        let (indices, values) = self.transport.coefficients(v);
        work.coefficients.clear();
        work.coefficients.resize(texels, T::zero());
        for (&i, &c) in indices.iter().zip(values) {
            work.coefficients[i as usize] = c;
        }
        work.pixels.resize(texels, T::zero());
        transform_faces(
            &work.coefficients,
            &mut work.pixels,
            param.face_size(),
            false,
            &mut work.scratch,
        )?;
        Ok(&work.pixels)
    }
}

/// The centre direction of bin `(i, j)` of an `n x 2n` lat-long grid.
fn bin_centre(n: usize, i: u32, j: u32) -> [f64; 3] {
    let step = std::f64::consts::PI / n as f64;
    direction((i as f64 + 0.5) * step, (j as f64 + 0.5) * step)
}

/// The orthonormal Haar transform, forward or inverse, of every `s x s` face block of `src`
/// (any number of faces and planes, back to back) into the same block of `dst`.
fn transform_faces<T: Sample>(
    src: &[T],
    dst: &mut [T],
    s: usize,
    forward: bool,
    work: &mut Vec<T>,
) -> Result<()> {
    let levels = s.trailing_zeros() as usize;
    for (from, to) in src.chunks_exact(s * s).zip(dst.chunks_exact_mut(s * s)) {
        let from = ArrayView2::from_shape((s, s), from).expect("a face is s x s");
        let to = ndarray::ArrayViewMut2::from_shape((s, s), to).expect("a face is s x s");
        if forward {
            pyramid::forward_into(from, levels, Normalization::Orthonormal, to, work)?;
        } else {
            pyramid::inverse_into(from, levels, Normalization::Orthonormal, to, work)?;
        }
    }
    Ok(())
}

/// Truncates a function given as pixel planes (`channels x texels`) in place: forward
/// (orthonormal, per face), keep the `keep` largest details by RGB magnitude and the scaling
/// coefficients, zero the levels from `depth` on, inverse.
fn truncate_planes(
    param: Parameterization,
    planes: &mut [f64],
    channels: usize,
    keep: Option<usize>,
    depth: usize,
) -> Result<()> {
    let s = param.face_size();
    let texels = param.texels();
    let mut work = Vec::new();
    let mut coefficients = vec![0.0f64; planes.len()];
    transform_faces(planes, &mut coefficients, s, true, &mut work)?;
    let indices: Vec<u32> = (0..texels as u32).collect();
    let kept = match keep {
        Some(k) => select_kept(
            param,
            Selection::Largest(k),
            &indices,
            |t| {
                (0..channels)
                    .map(|c| coefficients[c * texels + t].powi(2))
                    .sum()
            },
            &mut Vec::new(),
        ),
        None => vec![true; texels],
    };
    for c in 0..channels {
        for t in 0..texels {
            if !(kept[t] && within_depth(s, depth, t)) {
                coefficients[c * texels + t] = 0.0;
            }
        }
    }
    transform_faces(&coefficients, planes, s, false, &mut work)
}

/// The lighting's pixels (`3 x texels`, channel planes) as the product sees them: its kept
/// coefficients, limited to the detail levels `0..depth`, inverted face by face.
fn light_pixels<T: Sample>(lighting: &Lighting, depth: usize) -> Result<Vec<T>> {
    let param = lighting.param();
    let s = param.face_size();
    let texels = param.texels();
    let c = lighting.coefficients_f64();
    let mut coefficients = vec![0.0f64; 3 * texels];
    for t in 0..texels {
        if within_depth(s, depth, t) {
            for ch in 0..3 {
                coefficients[ch * texels + t] = c[[t, ch]];
            }
        }
    }
    let mut pixels = vec![0.0f64; 3 * texels];
    transform_faces(&coefficients, &mut pixels, s, false, &mut Vec::new())?;
    Ok(pixels.into_iter().map(T::from_f64).collect())
}

/// Glossy Haar shading behind [`Shader`]: a [`GlossyShader`] made once (and
/// with [`ShaderSpec::fill_cache`] its rotation cache filled), each frame's lighting encoded
/// and shaded from the frame's eye; the rotation cache lasts from frame to frame.
#[derive(Debug)]
pub struct GlossyHaarShader<T> {
    shader: GlossyShader<T>,
    encoder: HaarEncoder,
    options: GlossyOptions,
    preparation: Preparation,
}

impl<T: Sample> GlossyHaarShader<T> {
    /// `input`'s transport prepared for `spec`'s material on its objects.
    pub(crate) fn new(spec: &ShaderSpec, input: &ShadingInput<'_>) -> Result<Self> {
        let start = Instant::now();
        let set = input.transport(spec.method)?;
        let shader = GlossyShader::new(
            set,
            input.mesh,
            input.albedo,
            &spec.shade,
            &spec.material,
            input.object_vertices,
        )?;
        let prepare_seconds = seconds(start);
        let filled = if spec.fill_cache {
            let start = Instant::now();
            let maps = shader.fill_cache()?;
            Some(Filled {
                maps,
                seconds: seconds(start),
            })
        } else {
            None
        };
        Ok(GlossyHaarShader {
            shader,
            encoder: HaarEncoder::new(set.param(), spec.keep_light, spec.light_rotation),
            options: spec.material.clone(),
            preparation: Preparation {
                seconds: prepare_seconds,
                filled,
            },
        })
    }

    /// What the frame's shading did with the BRDF maps, for its description.
    fn cache_note(&self, report: &GlossyReport) -> String {
        let filled = self.preparation.filled.map_or(String::new(), |f| {
            format!(
                "cache filled ahead: {} maps rotated in {:.1} ms; ",
                f.maps,
                f.seconds * 1e3
            )
        });
        match self.options.cache_bins {
            Some(n) => format!(
                "rotation cache {n} x {}: {filled}{} maps rotated in {:.1} ms, {} from the cache",
                2 * n,
                report.rotated,
                report.rotate_seconds * 1e3,
                report.maps - report.rotated
            ),
            None => format!("no rotation cache: {} maps rotated", report.rotated),
        }
    }
}

impl<T: Sample> Shader for GlossyHaarShader<T>
where
    Radiance: From<Array2<T>>,
{
    fn shade(&mut self, frame: &FrameSpec<'_>) -> Result<Shading> {
        let eye = frame.eye()?;
        let (lighting, encode_seconds) = self.encoder.encode(frame)?;
        let start = Instant::now();
        let (radiance, report) = self.shader.shade(&lighting, eye)?;
        let shade_seconds = seconds(start);
        let o = &self.options;
        let description = format!(
            "Haar triple product, {} rotated by {}{}, lighting kept {} detail coefficients, \
             transport {} coefficients; {}; transport prepared once in {:.1} ms",
            o.brdf,
            o.rotation,
            o.level.map_or(String::new(), |l| format!(
                " from level {l} (thesis level {})",
                l + 1
            )),
            lighting.kept(),
            self.shader.transport().coefficient_count(),
            self.cache_note(&report),
            self.preparation.seconds * 1e3
        );
        Ok(Shading {
            radiance: radiance.into(),
            timing: Timing {
                encode_seconds,
                rotate_seconds: report.rotate_seconds,
                shade_seconds,
            },
            description,
            maps: Some(report),
            light_coefficients: Some(lighting.kept() + lighting.param().faces()),
        })
    }

    fn preparation(&self) -> Preparation {
        self.preparation
    }
}

#[cfg(test)]
mod tests;
