//! The integral over the sphere of a product of lat-long maps, computed on their Haar trees:
//! the glue between maps ([`LatLongMap`]), parameterisations ([`Parameterization`]) and the
//! product algebra ([`crate::product`]).
//!
//! [`integrate`] brings every map into the chosen parameterisation and resolution (a lat-long
//! map at its own height is only reshaped into its two faces; anything else goes through
//! [`convert`](super::convert)), broadcasts one-channel maps over the channels of the others,
//! folds each texel's solid angle into the **first** map (the [`Transport`], so the weight is
//! applied exactly once), builds each map's tree with its [`Selection`], and integrates by the
//! chosen [`IntegralMethod`]. With lat-long at the maps' own height, every coefficient kept
//! and no depth limit, the result is `sum over pixels of prod_k f_k(p) x solid_angle(p)`.
//!
//! It computes in the maps' sample type (`f32` or `f64`; the geometry and the sums in `f64`),
//! converts and builds the maps' trees in parallel (rayon over maps, and over faces within a
//! map), and integrates all channels in one traversal (an RGB coefficient is one tree node).

use std::time::Instant;

use ndarray::{Array3, Array4};
use rayon::prelude::*;

use super::convert::{Conversion, default_samples};
use super::param::{ParamKind, Parameterization, SphereMap};
use crate::named::named_enum;
use crate::product::baseline::{pairwise_integral, pixel_integral_of_trees};
use crate::product::triple::triple_integral;
use crate::product::{
    FaceLayout, HaarTree, IntegralOptions, Selection, Transport, WeightedPixels, product_integral,
};
use crate::sphere::LatLongMap;
use crate::{Error, Result, Sample};

named_enum! {
    /// How [`integrate`] computes the product integral.
    #[derive(Default)]
    pub enum IntegralMethod ("method") {
        #[default]
        /// The N-function tree traversal ([`product_integral`]).
        Tree = "tree",
        /// The three-function fast path on trees ([`triple_integral`]); exactly three maps.
        Triple = "triple",
        /// Inverse transforms of the (pruned) trees, then the weighted pixel sum.
        Pixel = "pixel",
        /// Products of two functions at a time, then an integral ("recursive Haar").
        Pairwise = "pairwise",
    }
}

/// What [`integrate`] does.
///
/// ```
/// use haarshift::faces::integrate::IntegrateOptions;
/// let o = IntegrateOptions::default();
/// assert!(o.resolution.is_none() && o.depth.is_none() && o.selections.is_empty());
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IntegrateOptions {
    /// The parameterisation to integrate in.
    pub param: ParamKind,
    /// The face side: lat-long `N x 2N`, cube `6 x N x N` (`None`: the maps' height `H` for
    /// lat-long, `H / 2` for the cube).
    pub resolution: Option<usize>,
    /// One selection for every map, or one per map (empty: keep everything).
    pub selections: Vec<Selection>,
    /// The finest detail level visited ([`IntegralOptions::finest_level`]); tree method only.
    pub depth: Option<usize>,
    /// The method.
    pub method: IntegralMethod,
}

/// The result of [`integrate`].
#[derive(Clone, Debug, PartialEq)]
pub struct SphereIntegral {
    /// The integral per channel.
    pub value: Vec<f64>,
    /// Detail coefficients kept per map (scaling coefficients not counted).
    pub kept: Vec<usize>,
    /// Tree nodes (pixels for [`IntegralMethod::Pixel`]) where the method did work.
    pub visited: usize,
    /// Seconds spent in the integral itself (trees already built).
    pub seconds: f64,
}

/// The integral over the sphere of the product of `maps` (lat-long `H x 2H`, `H` a power of
/// two, each of 1 or `C` channels), see the [module docs](self).
///
/// ```
/// use haarshift::sphere::LatLongMap;
/// use haarshift::faces::integrate::{IntegrateOptions, integrate};
/// use haarshift::sphere::latlong::pixel_solid_angle;
/// let f = LatLongMap::<f64>::from_fn(8, 1, |d, out| out[0] = 1.0 + d[1]).unwrap();
/// let g = LatLongMap::<f64>::from_fn(8, 3, |d, out| out.fill(2.0 + d[0])).unwrap();
/// let got = integrate(&[f.clone(), g.clone()], &IntegrateOptions::default()).unwrap();
/// let (fa, ga) = (f.as_array(), g.as_array());
/// let mut want = 0.0;
/// for i in 0..8 {
///     for j in 0..16 {
///         want += fa[[i, j, 0]] * ga[[i, j, 1]] * pixel_solid_angle(8, i);
///     }
/// }
/// assert_eq!(got.value.len(), 3);
/// assert!((got.value[1] - want).abs() < 1e-12 * want);
/// ```
pub fn integrate<T: Sample>(
    maps: &[LatLongMap<T>],
    options: &IntegrateOptions,
) -> Result<SphereIntegral> {
    if options.method == IntegralMethod::Triple && maps.len() != 3 {
        return Err(Error::parameter(
            "method",
            format!("triple integrates exactly 3 maps, not {}", maps.len()),
        ));
    }
    if options.depth.is_some() && options.method != IntegralMethod::Tree {
        return Err(Error::parameter(
            "depth",
            format!(
                "a depth limit applies to the tree method, not {}",
                options.method
            ),
        ));
    }
    let work = working_faces(maps, options.param, options.resolution, &options.selections)?;
    match work.channels {
        1 => integrate_faces::<T, 1>(&work, options),
        2 => integrate_faces::<T, 2>(&work, options),
        3 => integrate_faces::<T, 3>(&work, options),
        _ => integrate_faces::<T, 4>(&work, options),
    }
}

/// The maps of a product on the sphere, ready for their trees: in the working
/// parameterisation, broadcast to one channel count, each with its selection.
pub(super) struct Working<T> {
    /// The working parameterisation.
    pub(super) param: Parameterization,
    /// Channels of every face array (1 to 4).
    pub(super) channels: usize,
    /// Each map as a `(faces, S, S, channels)` array.
    pub(super) faces: Vec<Array4<T>>,
    /// Each map's selection.
    pub(super) selections: Vec<Selection>,
}

/// Checks `maps` and brings them into the parameterisation `kind` at face side `resolution`
/// (`None`: the maps' height `H` for lat-long, `H / 2` for the cube), maps in parallel; one
/// selection per map from `selections` (one for all, one each, or none: everything kept).
pub(super) fn working_faces<T: Sample>(
    maps: &[LatLongMap<T>],
    kind: ParamKind,
    resolution: Option<usize>,
    selections: &[Selection],
) -> Result<Working<T>> {
    let channels = check_maps(maps)?;
    let selections = per_map_selections(maps.len(), selections)?;
    let h = maps[0].height();
    let size = match (resolution, kind) {
        (Some(n), _) => n,
        (None, ParamKind::LatLong) => h,
        (None, ParamKind::Cube) => (h / 2).max(1),
    };
    let param = Parameterization::new(kind, size)?;
    let faces = face_arrays(maps, param, channels)?;
    Ok(Working {
        param,
        channels,
        faces,
        selections,
    })
}

/// Checks the maps: at least one, one height (a power of two), 1 or `C` channels with `C` at
/// most 4; returns `C`.
fn check_maps<T: Sample>(maps: &[LatLongMap<T>]) -> Result<usize> {
    let Some(first) = maps.first() else {
        return Err(Error::parameter("maps", "no map given"));
    };
    for m in maps {
        check_size(first.height(), m)?;
    }
    let channels = maps.iter().map(|m| m.channels()).max().unwrap_or(1);
    if channels > 4
        || maps
            .iter()
            .any(|m| m.channels() != 1 && m.channels() != channels)
    {
        let counts: Vec<usize> = maps.iter().map(|m| m.channels()).collect();
        return Err(Error::parameter(
            "channels",
            format!("maps have {counts:?} channels: each must have 1 or the same 2 to 4"),
        ));
    }
    Ok(channels)
}

/// Checks that `map` can join maps of height `height` (the first map's) in [`integrate`] or
/// [`map_product`](super::map_product::map_product): its height is `height`, a power of two. A caller
/// that reads maps one by one can name the file at fault.
///
/// ```
/// use haarshift::sphere::LatLongMap;
/// use haarshift::faces::integrate::check_size;
/// let m = LatLongMap::<f32>::from_fn(8, 1, |_, o| o[0] = 1.0).unwrap();
/// assert!(check_size(8, &m).is_ok());
/// assert!(check_size(16, &m).unwrap_err().to_string().contains("different sizes"));
/// let odd = LatLongMap::<f32>::from_fn(6, 1, |_, o| o[0] = 1.0).unwrap();
/// assert!(check_size(6, &odd).unwrap_err().to_string().contains("not a power of two"));
/// ```
pub fn check_size<T: Sample>(height: usize, map: &LatLongMap<T>) -> Result<()> {
    let h = map.height();
    if h != height {
        return Err(Error::shape(
            &[h, map.width()],
            format!(
                "maps of different sizes: {} x {height} and {} x {h} (width x height)",
                2 * height,
                map.width(),
            ),
        ));
    }
    if !h.is_power_of_two() {
        return Err(Error::shape(
            &[h, map.width()],
            format!("the map's height {h} is not a power of two"),
        ));
    }
    Ok(())
}

/// One selection per map: `given` repeated when it has one, all kept when it is empty.
fn per_map_selections(maps: usize, given: &[Selection]) -> Result<Vec<Selection>> {
    match given.len() {
        0 => Ok(vec![Selection::All; maps]),
        1 => Ok(vec![given[0]; maps]),
        n if n == maps => Ok(given.to_vec()),
        n => Err(Error::parameter(
            "keep",
            format!("{n} counts given for {maps} maps (give one, or one per map)"),
        )),
    }
}

/// Each map in `param`, broadcast to `channels` channels, as a `(faces, S, S, C)` array; maps
/// in parallel.
fn face_arrays<T: Sample>(
    maps: &[LatLongMap<T>],
    param: Parameterization,
    channels: usize,
) -> Result<Vec<Array4<T>>> {
    let own = SphereMap::from_lat_long(&maps[0])?.param();
    let conversion = if own == param {
        None
    } else {
        Some(Conversion::new(own, param, default_samples(own, param))?)
    };
    maps.par_iter()
        .map(|m| {
            let map = SphereMap::from_lat_long(m)?;
            let map = match &conversion {
                Some(c) => c.apply(&map)?,
                None => map,
            };
            let data = map.into_array();
            if data.dim().3 == channels {
                return Ok(data);
            }
            let (f, s, _, _) = data.dim();
            Ok(data
                .broadcast((f, s, s, channels))
                .expect("one channel broadcasts")
                .to_owned())
        })
        .collect()
}

/// The plain (unweighted) trees of `faces[k]` with `selections[k]`, in parallel.
pub(super) fn plain_trees<T: Sample, const C: usize>(
    faces: &[Array4<T>],
    selections: &[Selection],
    layout: FaceLayout,
) -> Result<Vec<HaarTree<T, C>>> {
    faces
        .par_iter()
        .zip(selections.par_iter())
        .map(|(f, &s)| HaarTree::from_pixels(f.view(), layout, s))
        .collect()
}

/// The layout whose Mallat index breaks selection ties: lat-long faces side by side.
#[doc(hidden)] // For haarshift-relight : public only for the sibling crates (crate docs).
pub fn layout(param: Parameterization) -> FaceLayout {
    match param.kind() {
        ParamKind::LatLong => FaceLayout::SideBySide,
        ParamKind::Cube => FaceLayout::Stacked,
    }
}

/// Trees and the integral, for `C` channels.
fn integrate_faces<T: Sample, const C: usize>(
    work: &Working<T>,
    options: &IntegrateOptions,
) -> Result<SphereIntegral> {
    let layout = layout(work.param);
    let weights: Array3<T> = work.param.solid_angles().mapv(T::from_f64);
    let weighted = WeightedPixels::<T, C>::new(work.faces[0].view(), weights.view())?;
    let (transport, trees) = rayon::join(
        || Transport::new(&weighted, layout, work.selections[0]),
        || plain_trees::<T, C>(&work.faces[1..], &work.selections[1..], layout),
    );
    let (transport, trees) = (transport?, trees?);
    let refs: Vec<&HaarTree<T, C>> = trees.iter().collect();
    let start = Instant::now();
    let integral = match options.method {
        IntegralMethod::Tree => product_integral(
            &transport,
            &refs,
            IntegralOptions {
                finest_level: options.depth,
            },
        )?,
        IntegralMethod::Triple => triple_integral(&transport, refs[0], refs[1])?,
        IntegralMethod::Pixel => pixel_integral_of_trees(&transport, &refs)?,
        IntegralMethod::Pairwise => pairwise_integral(&transport, &refs)?,
    };
    let seconds = start.elapsed().as_secs_f64();
    let mut kept = vec![transport.tree().kept()];
    kept.extend(trees.iter().map(|t| t.kept()));
    Ok(SphereIntegral {
        value: integral.value.to_vec(),
        kept,
        visited: integral.visited,
        seconds,
    })
}

#[cfg(test)]
#[path = "integrate_tests.rs"]
mod tests;
