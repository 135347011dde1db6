//! Shading a dynamic scene: each vertex's own transport, the other objects' occlusion looked
//! up at it and the lighting, multiplied and integrated (Sun 2006 eq. 3.1-3.3), and the
//! reference that evaluates the same integral texel by texel.

use ndarray::Array2;
use rayon::prelude::*;

use crate::dynamic::fields::yaw_sparse;
use crate::light::lighting::Lighting;
use crate::material::brdf::Brdf;
use crate::shade::reference::ReferenceVisibility;
use crate::shade::within_depth;
use crate::{Error, Result};
use crate::{ReferenceOptions, SceneBvh};
use haarshift::Sample;
use haarshift::faces::integrate::layout;
use haarshift::faces::param::Parameterization;
use haarshift::product::{HaarTree, IntegralOptions, Selection, Transport, product_integral};
use haarshift::sphere::LatLongMap;

use crate::dynamic::{DynamicScene, columns};

impl DynamicScene {
    /// Every vertex: its owner (`None`: the ground), its index in its owner, its world
    /// position lifted off the surface along its normal by the scene's ray offset (where
    /// field lookups are made; fixed at build, so that a move changes no other lookup).
    pub(super) fn receivers(&self) -> Vec<Receiver> {
        let param = self.param();
        let eps = self.lift;
        let mut out = Vec::with_capacity(self.vertex_count());
        let lift = |p: [f64; 3], n: [f64; 3]| std::array::from_fn(|k| p[k] + eps * n[k]);
        for (k, o) in self.objects.iter().enumerate() {
            let mesh = &self.shapes[o.shape];
            let rot = o.placement.rotation(param);
            let (p, n) = (mesh.positions(), mesh.normals());
            for v in 0..mesh.vertex_count() {
                let world = o
                    .placement
                    .to_world([p[[v, 0]], p[[v, 1]], p[[v, 2]]], param);
                let normal = rot.apply([n[[v, 0]], n[[v, 1]], n[[v, 2]]]);
                out.push(Receiver {
                    owner: Some(k),
                    vertex: v,
                    point: lift(world, normal),
                    position: world,
                    normal,
                });
            }
        }
        if let Some((g, _)) = &self.ground {
            let (p, n) = (g.positions(), g.normals());
            for v in 0..g.vertex_count() {
                let (position, normal) = (
                    [p[[v, 0]], p[[v, 1]], p[[v, 2]]],
                    [n[[v, 0]], n[[v, 1]], n[[v, 2]]],
                );
                out.push(Receiver {
                    owner: None,
                    vertex: v,
                    point: lift(position, normal),
                    position,
                    normal,
                });
            }
        }
        out
    }

    /// The receiver's own transport at its owner's turn, depth-limited.
    pub(super) fn own_transport(&self, r: &Receiver, depth: usize) -> Result<(Vec<u32>, Vec<f32>)> {
        let param = self.param();
        let (indices, values, turn) = match r.owner {
            Some(k) => {
                let o = &self.objects[k];
                let (i, v) = o.transport.row(r.vertex);
                let w = columns(param);
                (i, v, (o.placement.turn + w - o.rest.turn) % w)
            }
            None => {
                let (i, v) = self
                    .ground
                    .as_ref()
                    .expect("a ground receiver")
                    .1
                    .row(r.vertex);
                (i, v, 0)
            }
        };
        let (i, v) = if turn == 0 {
            (indices.to_vec(), values.to_vec())
        } else {
            yaw_sparse(param, indices, values, turn, Selection::Threshold(0.0))?
        };
        Ok(limit_depth(param, depth, i, v))
    }

    /// Object `k`'s occlusion map at the world point `x`, depth-limited, in `scratch.map`
    /// (`None`: beyond its fields).
    pub(super) fn occlusion<'s>(
        &self,
        k: usize,
        x: [f64; 3],
        depth: usize,
        scratch: &'s mut Scratch,
    ) -> Option<(&'s [u32], &'s [f64])> {
        let o = &self.objects[k];
        let local = o.placement.to_local(x, self.param());
        o.field.blended(
            local,
            self.options.truncation,
            &mut scratch.blend,
            &mut scratch.map,
        )?;
        let s = self.param().face_size();
        if depth < s.trailing_zeros() as usize {
            let (i, v) = &mut scratch.map;
            let mut at = 0;
            for slot in 0..i.len() {
                if within_depth(s, depth, i[slot] as usize) {
                    (i[at], v[at]) = (i[slot], v[slot]);
                    at += 1;
                }
            }
            i.truncate(at);
            v.truncate(at);
        }
        Some((&scratch.map.0, &scratch.map.1))
    }

    /// Every vertex's outgoing radiance `(V, 3)` by the n-function product integral of its
    /// own transport, the lighting and every other object's occlusion (issue 7's traversal),
    /// with no reuse between frames: the oracle of `JustInTimeTransfer` and the cost it saves.
    pub fn shade<T: Sample>(&self, lighting: &Lighting) -> Result<Array2<T>> {
        let depth = self.check_lighting(lighting)?;
        let param = self.param();
        let light = light_tree::<T>(lighting, depth)?;
        let receivers = self.receivers();
        let reflectance = self.reflectance();
        let rows: Vec<[T; 3]> = receivers
            .par_iter()
            .map_init(
                || Scratch::new(param),
                |scratch, r| -> Result<[T; 3]> {
                    let (i, v) = self.own_transport(r, depth)?;
                    let own = Transport::from_weighted_tree(tree(
                        param,
                        &i,
                        v.iter().map(|&x| f64::from(x)),
                    )?);
                    let mut factors = Vec::new();
                    for k in (0..self.objects.len()).filter(|&k| Some(k) != r.owner) {
                        if let Some((i, v)) = self.occlusion(k, r.point, depth, scratch) {
                            factors.push(tree(param, i, v.iter().copied())?);
                        }
                    }
                    factors.extend(self.brdf_tree(r, depth)?);
                    let mut refs: Vec<&HaarTree<T, 3>> = vec![&light];
                    refs.extend(factors.iter());
                    let value = product_integral(&own, &refs, IntegralOptions::default())?.value;
                    Ok(value.map(T::from_f64))
                },
            )
            .collect::<Result<_>>()?;
        Ok(radiance(&rows, &reflectance))
    }

    /// The ground truth of the scene as placed now: [`reference`](crate::reference()) with
    /// visibility ray-cast against every object and the ground plane, over `lighting` (a
    /// lat-long map, rotated), no field, no Haar transform; a glossy object's BRDF evaluated
    /// analytically per texel toward the [eye](Self::eye), as `relight reference --brdf` does.
    pub fn reference(&self, lighting: &LatLongMap<f64>) -> Result<Array2<f64>> {
        let mesh = self.mesh();
        let bvh = SceneBvh::new(&mesh);
        let albedo = self.albedo();
        let lambert = ReferenceOptions {
            progress: self.options.progress,
            ..ReferenceOptions::default()
        };
        let mut glossy: Vec<&Brdf> = Vec::new();
        for o in self.objects.iter().filter(|o| !o.brdf.is_lambert()) {
            if !glossy.contains(&&o.brdf) {
                glossy.push(&o.brdf);
            }
        }
        if glossy.is_empty() {
            return Ok(crate::reference(&mesh, &bvh, albedo.view(), lighting, &lambert)?.0);
        }
        // The rays once; then one quadrature per material, each vertex taking its own's.
        let eye = self.glossy_eye()?;
        let bits = ReferenceVisibility::new(&mesh, &bvh, lighting.height(), lambert.progress)?;
        let mut out = bits.reference(&mesh, albedo.view(), lighting, &lambert)?.0;
        for brdf in glossy {
            let options = ReferenceOptions {
                brdf: brdf.clone(),
                eye: Some(eye),
                ..ReferenceOptions::default()
            };
            let (shaded, _) = bits.reference(&mesh, albedo.view(), lighting, &options)?;
            for k in (0..self.objects.len()).filter(|&k| self.objects[k].brdf == *brdf) {
                let rows = ndarray::s![self.object_vertices(k), ..];
                out.slice_mut(rows).assign(&shaded.slice(rows));
            }
        }
        Ok(out)
    }

    /// The depth the options name, after checking `lighting` against the scene.
    pub(super) fn check_lighting(&self, lighting: &Lighting) -> Result<usize> {
        if lighting.param() != self.param() {
            return Err(Error::parameter(
                "lighting",
                format!(
                    "{} {}: the scene's maps are {} {}",
                    lighting.param().kind(),
                    lighting.param().face_size(),
                    self.param().kind(),
                    self.param().face_size()
                ),
            ));
        }
        self.options.check()
    }
}

/// One vertex as the shading sees it.
pub(super) struct Receiver {
    pub(super) owner: Option<usize>,
    pub(super) vertex: usize,
    pub(super) point: [f64; 3],
    /// On the surface, and the unit normal: a glossy vertex's frame.
    pub(super) position: [f64; 3],
    pub(super) normal: [f64; 3],
}

/// Per-thread working memory: a dense blend buffer and a sparse map.
pub(super) struct Scratch {
    pub(super) blend: Vec<f64>,
    pub(super) map: (Vec<u32>, Vec<f64>),
}

impl Scratch {
    pub(super) fn new(param: Parameterization) -> Self {
        Scratch {
            blend: vec![0.0; param.texels()],
            map: (Vec::new(), Vec::new()),
        }
    }
}

/// The entries within the detail levels `0..depth`.
pub(super) fn limit_depth<V>(
    param: Parameterization,
    depth: usize,
    indices: Vec<u32>,
    values: Vec<V>,
) -> (Vec<u32>, Vec<V>) {
    let s = param.face_size();
    if depth == s.trailing_zeros() as usize {
        return (indices, values);
    }
    indices
        .into_iter()
        .zip(values)
        .filter(|(i, _)| within_depth(s, depth, *i as usize))
        .unzip()
}

/// A one-channel sparse function as a three-channel tree (every channel the same).
pub(super) fn tree<T: Sample>(
    param: Parameterization,
    indices: &[u32],
    values: impl Iterator<Item = f64>,
) -> Result<HaarTree<T, 3>> {
    let values: Vec<[T; 3]> = values.map(|v| [T::from_f64(v); 3]).collect();
    Ok(HaarTree::from_sparse(
        param.faces(),
        param.face_size(),
        layout(param),
        indices,
        &values,
    )?)
}

/// The lighting's kept coefficients, depth-limited, sparse and ascending.
pub(super) fn light_sparse<T: Sample>(
    lighting: &Lighting,
    depth: usize,
) -> (Vec<u32>, Vec<[T; 3]>) {
    let param = lighting.param();
    lighting
        .coefficients_f64()
        .rows()
        .into_iter()
        .enumerate()
        .filter(|(i, row)| {
            row.iter().any(|&x| x != 0.0) && within_depth(param.face_size(), depth, *i)
        })
        .map(|(i, row)| (i as u32, [row[0], row[1], row[2]].map(T::from_f64)))
        .unzip()
}

/// The lighting's kept coefficients as a tree, depth-limited.
pub(super) fn light_tree<T: Sample>(lighting: &Lighting, depth: usize) -> Result<HaarTree<T, 3>> {
    let param = lighting.param();
    let (indices, values) = light_sparse::<T>(lighting, depth);
    Ok(HaarTree::from_sparse(
        param.faces(),
        param.face_size(),
        layout(param),
        &indices,
        &values,
    )?)
}

/// `reflectance x integral`, per vertex and channel ([`DynamicScene::reflectance`]).
pub(super) fn radiance<T: Sample>(integrals: &[[T; 3]], reflectance: &Array2<f64>) -> Array2<T> {
    Array2::from_shape_fn((integrals.len(), 3), |(v, c)| {
        T::from_f64(integrals[v][c].as_f64() * reflectance[[v, c]])
    })
}
