//! Just-in-time radiance transfer (Sun 2006 sections 3.2.2 and 3.5.3): per vertex the product
//! `T` of the factors that stay fixed while one varies, formed once ([`JustInTimeTransfer::form`]); a frame is
//! then one sparse dot product per vertex with the varying factor.

use super::products::{Method, SharedFactor, Use, VertexProduct};
use super::*;
use haarshift::product::texel::FactorValue;

/// What just-in-time radiance transfer holds fixed and what varies between frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Change {
    /// Object `k` moves (translation and scale; a turn re-forms): every other vertex's fixed
    /// product holds its own transport, the lighting, the other objects' occlusion and its
    /// BRDF; object `k`'s own vertices hold their transport and the lighting (a glossy one's
    /// view, so its BRDF, moves with it).
    Object(usize),
    /// The lighting changes: every vertex holds its own transport, all occlusion and its
    /// BRDF.
    Lighting,
    /// The eye moves ([`DynamicScene::set_eye`]): every vertex holds its own transport, the
    /// lighting and all occlusion; a frame re-orients each glossy vertex's BRDF toward the new
    /// eye and takes one dot product with it (a Lambertian vertex's radiance does not change).
    View,
}

/// What forming or using a [`JustInTimeTransfer`] cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TransferReport {
    /// Wall-clock seconds.
    pub seconds: f64,
    /// Coefficients of the fixed products, all vertices.
    pub coefficients: usize,
    /// Bytes of the fixed products.
    pub bytes: usize,
}

/// Just-in-time radiance transfer (Sun 2006 sections 3.2.2 and 3.5.3): per vertex the product
/// `T` of the factors that stay fixed while one [`Change`] varies, pruned to the options'
/// `keep_product`; each frame is then `<T, F>` with `F` the varying factor (the looked-up map
/// of the moving object, or the new lighting): one sparse dot product per vertex. Re-form it
/// when the kind of change switches.
///
/// A vertex of the moving object sees every other object move: its `F` is the product of
/// their looked-up maps (one map: a dot product; several: the product integral of `T` and the
/// maps, the triple product for two, without forming their product).
///
/// ```
/// use haarshift::product::Selection;
/// use haarshift_relight::dynamic::{Change, DynamicOptions, DynamicScene, JustInTimeTransfer, Placement};
/// use haarshift_relight::{Lighting, SceneFile};
/// use haarshift::faces::param::{ParamKind, Parameterization, SphereMap};
/// let file: SceneFile = serde_json::from_str(r#"{"objects": [
///     {"generator": {"sphere": {"cells": 2}}},
///     {"generator": {"sphere": {"cells": 2}}, "transform": {"translate": [2.5, 0, 0]}}
///   ], "ground_plane": true}"#).unwrap();
/// let param = Parameterization::new(ParamKind::LatLong, 8).unwrap();
/// let mut options = DynamicOptions::new(param);
/// (options.field.circles, options.field.circle_points) = (8, 16);
/// (options.field.shells, options.field.shell_grid) = (4, 3);
/// let mut scene = DynamicScene::build(&file, std::path::Path::new("."), &options).unwrap();
/// let sky = SphereMap::<f64>::from_fn(param, 3, |d, o| o.fill(0.2 + d[1].max(0.0))).unwrap();
/// let light = Lighting::from_map(&sky, Selection::All).unwrap();
/// let jrt = JustInTimeTransfer::<f64>::form(&scene, &light, Change::Object(1)).unwrap();
/// // Move object 1; a frame is one dot product per vertex with its looked-up map.
/// let moved = Placement { translate: [1.5, 0.0, 1.0], ..scene.placement(1) };
/// scene.place(1, moved).unwrap();
/// let fast = jrt.frame_moved(&scene).unwrap();
/// let full = scene.shade::<f64>(&light).unwrap(); // every product integral from scratch
/// assert!(fast.iter().zip(&full).all(|(a, b)| (a - b).abs() < 1e-9));
/// ```
#[derive(Clone, Debug)]
pub struct JustInTimeTransfer<T> {
    change: Change,
    /// Every object's turn at formation (a vertex's own transport turns with its object).
    turns: Vec<usize>,
    /// Every placement at formation (a change of view holds them all).
    placements: Vec<Placement>,
    products: SparseRows<[T; 3]>,
    report: TransferReport,
}

impl<T: Sample> JustInTimeTransfer<T> {
    /// Forms every vertex's fixed product for `change` in `scene`'s present placement under
    /// `lighting` (which a [`Change::Lighting`] will replace).
    pub fn form(scene: &DynamicScene, lighting: &Lighting, change: Change) -> Result<Self> {
        let start = Instant::now();
        let depth = scene.check_lighting(lighting)?;
        let moving = match change {
            Change::Object(k) => {
                scene.check_object(k)?;
                Some(k)
            }
            Change::Lighting | Change::View => None,
        };
        let param = scene.param();
        let method = Method::for_param(param, Use::Fixed);
        let (li, lv) = light_sparse::<T>(lighting, depth);
        let light = SharedFactor::new(param, method, &li, &lv)?;
        let one = VertexProduct::new(param, method)?;
        let receivers = scene.receivers();
        let keep = scene.options.keep_product;
        let rows: Vec<(Vec<u32>, Vec<[T; 3]>)> = receivers
            .par_iter()
            .map_init(
                || (Scratch::new(param), Vec::new(), one.clone()),
                |(scratch, pool, fixed), r| -> Result<_> {
                    fixed.reset();
                    let (i, v) = scene.own_transport(r, depth)?;
                    fixed.multiply(&i, &v)?;
                    let fixed_occluders = (0..scene.objects.len())
                        .filter(|&k| Some(k) != r.owner && Some(k) != moving)
                        .filter(|_| moving.is_none() || r.owner != moving);
                    for k in fixed_occluders {
                        if let Some((i, v)) = scene.occlusion(k, r.point, depth, scratch) {
                            fixed.multiply(i, v)?;
                        }
                    }
                    // The BRDF is fixed unless the view of it varies.
                    if change != Change::View
                        && (moving.is_none() || r.owner != moving)
                        && let Some((i, v)) = scene.brdf_sparse(r, depth)?
                    {
                        fixed.multiply(&i, &v)?;
                    }
                    let shared = (change != Change::Lighting).then_some(&light);
                    let (indices, values) = fixed.coefficients(shared)?;
                    Ok(prune(param, keep, indices, values, pool))
                },
            )
            .collect::<Result<_>>()?;
        let products: SparseRows<[T; 3]> = rows.iter().map(|(i, v)| (i, v)).collect();
        let report = TransferReport {
            seconds: start.elapsed().as_secs_f64(),
            coefficients: products.coefficient_count(),
            bytes: products.bytes(),
        };
        Ok(JustInTimeTransfer {
            change,
            turns: scene.objects.iter().map(|o| o.placement.turn).collect(),
            placements: scene.objects.iter().map(|o| o.placement).collect(),
            products,
            report,
        })
    }

    /// What was held fixed.
    pub fn change(&self) -> Change {
        self.change
    }

    /// What forming it cost.
    pub fn report(&self) -> &TransferReport {
        &self.report
    }

    /// Every vertex's radiance `(V, 3)` with the moving object where `scene` has it now (every
    /// other placement as at formation).
    pub fn frame_moved(&self, scene: &DynamicScene) -> Result<Array2<T>> {
        let Change::Object(moving) = self.change else {
            return Err(self.wrong_frame());
        };
        self.check_scene(scene)?;
        let depth = scene.options.check()?;
        let param = scene.param();
        let receivers = scene.receivers();
        let one = VertexProduct::new(param, Method::for_param(param, Use::Frame))?;
        let rows: Vec<[T; 3]> = receivers
            .par_iter()
            .enumerate()
            .map_init(
                || {
                    let dense = vec![[T::zero(); 3]; param.texels()];
                    (Scratch::new(param), dense, Vec::new(), one.clone())
                },
                |(scratch, dense, held, varying), (v, r)| -> Result<[T; 3]> {
                    let (ti, tv) = self.products.row(v);
                    if r.owner != Some(moving) {
                        // The one varying factor: a dot product with the moving object's map;
                        // truncated before the blend, the dot of the blend is the blend of
                        // the samples' dots, so no map is formed.
                        if scene.options.truncation == Truncation::Before {
                            let o = &scene.objects[moving];
                            let local = o.placement.to_local(r.point, param);
                            return Ok(match o.field.lookup(local) {
                                None => dot_one(param, ti, tv),
                                Some(blend) => dot_blend(dense, ti, tv, &o.field, &blend, depth),
                            });
                        }
                        return Ok(match scene.occlusion(moving, r.point, depth, scratch) {
                            None => dot_one(param, ti, tv),
                            Some((fi, fv)) => dot_dense(dense, ti, tv, fi, fv),
                        });
                    }
                    // A vertex of the moving object: every other object's map varies, and so
                    // does a glossy vertex's BRDF (its view moves with it). Each map found is
                    // swapped out of the scratch (no copy).
                    let brdf = scene.brdf_sparse(r, depth)?;
                    let mut found = 0;
                    for k in (0..scene.objects.len()).filter(|&k| k != moving) {
                        if scene.occlusion(k, r.point, depth, scratch).is_some() {
                            if held.len() == found {
                                held.push((Vec::new(), Vec::new()));
                            }
                            std::mem::swap(&mut held[found], &mut scratch.map);
                            found += 1;
                        }
                    }
                    Ok(match (&held[..found], &brdf) {
                        ([], None) => dot_one(param, ti, tv),
                        ([(fi, fv)], None) => dot_dense(dense, ti, tv, fi, fv),
                        ([], Some((bi, bv))) => dot_dense(dense, ti, tv, bi, bv),
                        (maps, brdf) => {
                            varying.reset();
                            for (fi, fv) in maps {
                                varying.multiply(fi, fv)?;
                            }
                            if let Some((bi, bv)) = brdf {
                                varying.multiply(bi, bv)?;
                            }
                            varying.dot(ti, tv)?
                        }
                    })
                },
            )
            .collect::<Result<_>>()?;
        Ok(radiance(&rows, &scene.reflectance()))
    }

    /// Every vertex's radiance `(V, 3)` under `lighting` (formed for [`Change::Lighting`]).
    pub fn frame_lit(&self, scene: &DynamicScene, lighting: &Lighting) -> Result<Array2<T>> {
        if self.change != Change::Lighting {
            return Err(self.wrong_frame());
        }
        self.check_scene(scene)?;
        let depth = scene.check_lighting(lighting)?;
        let param = scene.param();
        let light = lighting.coefficients_f64();
        let s = param.face_size();
        let rows: Vec<[T; 3]> = (0..self.products.len())
            .into_par_iter()
            .map(|v| {
                let (ti, tv) = self.products.row(v);
                let mut acc = [0.0f64; 3];
                for (&i, t) in ti.iter().zip(tv) {
                    if within_depth(s, depth, i as usize) {
                        for c in 0..3 {
                            acc[c] += t[c].as_f64() * light[[i as usize, c]];
                        }
                    }
                }
                acc.map(T::from_f64)
            })
            .collect();
        Ok(radiance(&rows, &scene.reflectance()))
    }

    /// Every vertex's radiance `(V, 3)` seen from `scene`'s [eye](DynamicScene::eye) (formed
    /// for [`Change::View`]; every placement as at formation): per glossy vertex the BRDF in
    /// its new frame and one sparse dot product with the fixed product.
    ///
    /// ```
    /// use haarshift::product::Selection;
    /// use haarshift_relight::dynamic::{Change, DynamicOptions, DynamicScene, JustInTimeTransfer};
    /// use haarshift_relight::{Lighting, SceneFile};
    /// use haarshift::faces::param::{ParamKind, Parameterization, SphereMap};
    /// let file: SceneFile = serde_json::from_str(r#"{"objects": [
    ///     {"generator": {"sphere": {"cells": 2}},
    ///      "material": {"brdf": "phong", "exponent": 10, "albedo": [0.9, 0.9, 0.9]}},
    ///     {"generator": {"sphere": {"cells": 2}}, "transform": {"translate": [2.5, 0, 0]}}
    ///   ], "camera": {"position": [0, 2, 6], "look_at": [0, 0, 0]}}"#).unwrap();
    /// let param = Parameterization::new(ParamKind::LatLong, 8).unwrap();
    /// let mut options = DynamicOptions::new(param);
    /// (options.field.circles, options.field.circle_points) = (8, 16);
    /// (options.field.shells, options.field.shell_grid) = (4, 3);
    /// let mut scene = DynamicScene::build(&file, std::path::Path::new("."), &options).unwrap();
    /// let sky = SphereMap::<f64>::from_fn(param, 3, |d, o| o.fill(0.2 + d[1].max(0.0))).unwrap();
    /// let light = Lighting::from_map(&sky, Selection::All).unwrap();
    /// let jrt = JustInTimeTransfer::<f64>::form(&scene, &light, Change::View).unwrap();
    /// scene.set_eye([5.0, 1.0, 1.0]).unwrap(); // the camera moves
    /// let fast = jrt.frame_view(&scene).unwrap();
    /// let full = scene.shade::<f64>(&light).unwrap();
    /// assert!(fast.iter().zip(&full).all(|(a, b)| (a - b).abs() < 1e-9));
    /// ```
    pub fn frame_view(&self, scene: &DynamicScene) -> Result<Array2<T>> {
        if self.change != Change::View {
            return Err(self.wrong_frame());
        }
        self.check_scene(scene)?;
        if scene
            .objects
            .iter()
            .map(|o| o.placement)
            .ne(self.placements.iter().copied())
        {
            return Err(Error::parameter(
                "scene",
                "an object moved since the transfer was formed for a change of view: re-form it",
            ));
        }
        let depth = scene.options.check()?;
        let param = scene.param();
        let rows: Vec<[T; 3]> = scene
            .receivers()
            .par_iter()
            .enumerate()
            .map_init(
                || vec![[T::zero(); 3]; param.texels()],
                |dense, (v, r)| -> Result<[T; 3]> {
                    let (ti, tv) = self.products.row(v);
                    Ok(match scene.brdf_sparse(r, depth)? {
                        Some((fi, fv)) => dot_dense(dense, ti, tv, &fi, &fv),
                        None => dot_one(param, ti, tv),
                    })
                },
            )
            .collect::<Result<_>>()?;
        Ok(radiance(&rows, &scene.reflectance()))
    }

    /// The refusal of a frame of another kind than the transfer was formed for.
    fn wrong_frame(&self) -> Error {
        let use_instead = match self.change {
            Change::Object(_) => "frame_moved",
            Change::Lighting => "frame_lit",
            Change::View => "frame_view",
        };
        Error::parameter(
            "change",
            format!(
                "this transfer was formed for {:?}: use {use_instead}",
                self.change
            ),
        )
    }

    fn check_scene(&self, scene: &DynamicScene) -> Result<()> {
        let turns: Vec<usize> = scene.objects.iter().map(|o| o.placement.turn).collect();
        if scene.vertex_count() != self.products.len() {
            return Err(Error::parameter(
                "scene",
                format!(
                    "{} vertices, but the transfer was formed for {}: re-form it after cloning",
                    scene.vertex_count(),
                    self.products.len()
                ),
            ));
        }
        if turns != self.turns {
            return Err(Error::parameter(
                "scene",
                "an object turned since the transfer was formed: re-form it (a turn moves \
                 the object's own transport and the fixed products that hold it)",
            ));
        }
        Ok(())
    }
}

/// `indices, values` pruned to what `keep` picks (every scaling coefficient, the largest RGB
/// magnitudes), ascending.
fn prune<T: Sample>(
    param: Parameterization,
    keep: Selection,
    indices: Vec<u32>,
    values: Vec<[T; 3]>,
    pool: &mut Vec<Candidate>,
) -> (Vec<u32>, Vec<[T; 3]>) {
    if keep == Selection::All {
        return (indices, values);
    }
    let kept = select_kept(
        param,
        keep,
        &indices,
        |s| values[s].iter().map(|x| x.as_f64().powi(2)).sum(),
        pool,
    );
    indices
        .into_iter()
        .zip(values)
        .zip(kept)
        .filter(|(_, k)| *k)
        .map(|(e, _)| e)
        .unzip()
}

/// `<T, 1>`: the constant 1 has, on each face of side `S`, only its scaling coefficient `S`.
fn dot_one<T: Sample>(param: Parameterization, indices: &[u32], values: &[[T; 3]]) -> [T; 3] {
    let s = param.face_size();
    let mut acc = [0.0f64; 3];
    for (&i, t) in indices.iter().zip(values) {
        if (i as usize).is_multiple_of(s * s) {
            for c in 0..3 {
                acc[c] += t[c].as_f64() * s as f64;
            }
        }
    }
    acc.map(T::from_f64)
}

/// `<T, sum_s w_s M_s>` for the sample maps `M_s` of `field` that `blend` weighs, limited to
/// the detail levels `0..depth`, through a dense copy of `T` (`dense` is all zeros and is
/// left so).
fn dot_blend<T: Sample>(
    dense: &mut [[T; 3]],
    ti: &[u32],
    tv: &[[T; 3]],
    field: &OcclusionField,
    blend: &Blend,
    depth: usize,
) -> [T; 3] {
    let s = field.options().param.face_size();
    let all = depth == s.trailing_zeros() as usize;
    with_dense(dense, ti, tv, |dense| {
        let mut acc = [0.0f64; 3];
        for &(sample, w) in blend.samples() {
            let (fi, fv) = field.map(sample as usize);
            let mut part = [T::zero(); 3];
            for (&i, &f) in fi.iter().zip(fv) {
                if all || within_depth(s, depth, i as usize) {
                    let t = dense[i as usize];
                    let f = T::from_f64(f64::from(f));
                    for c in 0..3 {
                        part[c] += t[c] * f;
                    }
                }
            }
            for c in 0..3 {
                acc[c] += f64::from(w) * part[c].as_f64();
            }
        }
        acc.map(T::from_f64)
    })
}

/// `<T, F>` for a sparse `T` and a sparse `F` (one channel or RGB), through a dense copy of
/// `T` (`dense` is all zeros and is left so).
pub(super) fn dot_dense<T: Sample, F: FactorValue>(
    dense: &mut [[T; 3]],
    ti: &[u32],
    tv: &[[T; 3]],
    fi: &[u32],
    fv: &[F],
) -> [T; 3] {
    with_dense(dense, ti, tv, |dense| {
        let mut acc = [0.0f64; 3];
        for (&i, &f) in fi.iter().zip(fv) {
            let t = dense[i as usize];
            for c in 0..3 {
                acc[c] += t[c].as_f64() * f.channel(c % F::CHANNELS);
            }
        }
        acc.map(T::from_f64)
    })
}

/// `f` of the sparse `T` scattered into `dense` (all zeros, and left so): a dot with a sparse
/// map is then one load per map coefficient, not a merge of two index lists.
fn with_dense<T: Sample, R>(
    dense: &mut [[T; 3]],
    ti: &[u32],
    tv: &[[T; 3]],
    f: impl FnOnce(&[[T; 3]]) -> R,
) -> R {
    for (&i, t) in ti.iter().zip(tv) {
        dense[i as usize] = *t;
    }
    let out = f(dense);
    for &i in ti {
        dense[i as usize] = [T::zero(); 3];
    }
    out
}
