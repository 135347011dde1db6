//! Dynamic scenes (Sun 2006 chapter 3): rigid objects that move, scale, turn about the
//! vertical and are cloned at run time, each shadowing the others through its
//! [occlusion field](crate::dynamic::fields), shaded by n-function product integrals and by
//! just-in-time radiance transfer ([`JustInTimeTransfer`]).
//!
//! **What is computed.** A Lambertian vertex `v` of albedo `a` reflects
//! `B_v = a / pi x integral of T_v x L x prod_(k != own) O_k`, Sun 2006 eq. 3.1-3.3 with the
//! BRDF constant: `T_v` the vertex's own transport (its object's self-visibility, the ground
//! plane's occlusion where the scene has one, cosine and solid angle; [`TransportSet`](crate::precompute::transport_set::TransportSet)
//! semantics), `L` the lighting, `O_k` object `k`'s occlusion looked up at the vertex
//! ([`OcclusionField::lookup`], with the options' [`Truncation`]); a vertex beyond an object's
//! outermost shell takes `O_k = 1`. Each factor is truncated as the options say (the lighting
//! by the caller's [`Lighting`]) and, with a `depth`, all factors are limited to the detail
//! levels `0..depth` (Sun 2006 Fig. 3.5's traversal depth: every factor is then constant on
//! blocks of side `S >> depth`, and so is their product).
//!
//! **Glossy materials** (a scene file's `phong` or `blinn` [`Material`](crate::Material), or
//! [`DynamicScene::set_brdf`]): the BRDF in the vertex's frame, seen from the
//! [eye](DynamicScene::eye), is one more factor, `B_v = a x integral of T_v x L x prod O_k x
//! rho_v`, `rho_v` the lobe of [`Orientation::lobe`] (by [`GlossyOptions::rotation`], in the
//! vertex's exact frame) in Haar coefficients; [`reference`](DynamicScene::reference) evaluates
//! the BRDF analytically per texel. The ground plane stays Lambertian.
//!
//! **Albedo per vertex.** `a` is the object's material albedo times the colour its mesh file
//! carries at the vertex (a glTF's base colour and texture, an OBJ's MTL, a PLY's colours:
//! [`SceneObject::albedo`](crate::SceneObject::albedo)), as in a static scene; a
//! clone keeps the albedo of the object it copies.
//!
//! **Own transport and the ground.** An object's `T_v` is precomputed at its placement in the
//! scene file, against itself and the ground plane (when the scene has one), exactly as
//! `vertex_major` does for a static scene. Moving the object keeps it; turning it by `k`
//! columns turns it (`yaw_sparse`). The ground's own transport sees the whole upper
//! hemisphere; objects shadow it through their planar fields. So one object alone at its
//! file placement, without a ground plane, is shaded exactly as the static path shades it
//! (tested); with a ground plane, moving an object keeps the ground's occlusion of it as it
//! was (exact for a plane much larger than the move; the experiment measures it).
//!
//! **Placements** ([`Placement`]): world `= Ry(turn) (s x local) + t`. An object turns about
//! the vertical by whole columns of a lat-long parameterisation (`360 / 2N` degrees; a file's
//! yaw is rounded to the nearest column and the rounded angle is the scene's, reference
//! included); a cube map cannot turn (refused). Pitch and roll are refused: an occlusion
//! field turns exactly about the vertical only (Sun 2006 cannot turn objects at all).
//!
//! **Shapes and clones.** Objects with the same mesh file or generator share one shape: one
//! set of fields (Sun 2006's instancing); [`DynamicScene::clone_object`] adds an instance of an
//! object's shape at run time, whose own transport is the original's.

use std::sync::Arc;
use std::time::Instant;

use ndarray::Array2;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::Mesh;
use crate::dynamic::fields::{Blend, OcclusionField, Truncation, select_rows};
use crate::light::lighting::Lighting;
use crate::material::brdf::Brdf;
use crate::material::orient::Orientation;
use crate::precompute::sparse::SparseRows;
use crate::scene::shapes::merge;
use crate::scene::{CameraSpec, EnvironmentSpec};
use crate::shade::glossy::GlossyOptions;
use crate::shade::{select_kept, within_depth};
use crate::{Error, Result};
use haarshift::Sample;
use haarshift::faces::integrate::layout;
use haarshift::faces::param::{ParamKind, Parameterization};
use haarshift::product::multiply::product;
use haarshift::product::selection::Candidate;
use haarshift::product::{HaarTree, IntegralOptions, Selection, Transport, product_integral};

/// One object of a dynamic scene.
#[derive(Clone, Debug)]
struct Object {
    name: Option<String>,
    shape: usize,
    /// Where its own transport was computed.
    rest: Placement,
    placement: Placement,
    /// Per vertex of its shape, `(V, 3)`: the material's albedo times the colour its mesh
    /// file carries ([`SceneObject::albedo`](crate::SceneObject::albedo)).
    albedo: Array2<f32>,
    /// Its material's BRDF, with the orientation that brings it into vertex frames (`None`:
    /// Lambertian).
    brdf: Brdf,
    orientation: Option<Arc<Orientation>>,
    transport: Arc<SparseRows<f32>>,
    /// The shape's field turned to the placement.
    field: Arc<OcclusionField>,
}

/// What building a dynamic scene did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BuildReport {
    /// Rays cast for the occlusion fields, all shapes.
    pub field_rays: u64,
    /// Seconds building the fields.
    pub field_seconds: f64,
    /// Bytes of the stored field maps.
    pub field_bytes: usize,
    /// Shapes whose fields were read from a field file.
    pub fields_loaded: usize,
    /// Field files written (shapes whose file was absent or replaced).
    pub fields_written: usize,
    /// Bytes of the field files read or written.
    pub field_file_bytes: u64,
    /// Seconds reading and checking field files.
    pub field_load_seconds: f64,
    /// Rays cast for the vertices' own transport.
    pub transport_rays: u64,
    /// Seconds precomputing the own transport.
    pub transport_seconds: f64,
}

/// A scene of rigid objects with occlusion fields; see the [module docs](self).
///
/// ```
/// use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
/// use haarshift_relight::SceneFile;
/// use haarshift::faces::{ParamKind, Parameterization};
/// let file: SceneFile = serde_json::from_str(r#"{"objects": [
///     {"name": "a", "generator": {"sphere": {"cells": 2}}},
///     {"name": "b", "generator": {"sphere": {"cells": 2}}, "transform": {"translate": [3, 0, 0]}}
///   ], "ground_plane": true}"#).unwrap();
/// let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap());
/// (options.field.circles, options.field.circle_points) = (8, 16);
/// (options.field.shells, options.field.shell_grid) = (4, 3);
/// let scene = DynamicScene::build(&file, std::path::Path::new("."), &options).unwrap();
/// assert_eq!((scene.object_count(), scene.shape_count()), (2, 1)); // one shape, two instances
/// assert_eq!(scene.vertex_count(), 2 * 54 + 33 * 33);
/// assert_eq!(scene.object_index("b"), Some(1));
/// assert_eq!((scene.object_name(0), scene.object_name(1)), (Some("a"), Some("b")));
/// ```
#[derive(Clone, Debug)]
pub struct DynamicScene {
    options: DynamicOptions,
    shapes: Vec<Mesh>,
    fields: Vec<Arc<OcclusionField>>,
    objects: Vec<Object>,
    ground: Option<(Mesh, Arc<SparseRows<f32>>)>,
    /// How far lookups are lifted off their surface: the ray offset of the scene as built.
    lift: f64,
    /// The lighting of the scene file, path resolved.
    pub environment: Option<EnvironmentSpec>,
    /// The camera of the scene file.
    pub camera: Option<CameraSpec>,
    /// Where glossy vertices are seen from (the file's camera position unless set).
    eye: Option<[f64; 3]>,
    /// How glossy BRDFs are brought into vertex frames and truncated.
    glossy: GlossyOptions,
    report: BuildReport,
}

impl DynamicScene {
    /// The options it was built with.
    pub fn options(&self) -> &DynamicOptions {
        &self.options
    }

    /// What building it did.
    pub fn report(&self) -> &BuildReport {
        &self.report
    }

    /// The parameterisation of every map.
    pub fn param(&self) -> Parameterization {
        self.options.param()
    }

    /// The scene with every vertex's own transport re-truncated to `keep_visibility` and
    /// every field map to `keep_field` (each can only keep fewer than the build kept): a
    /// budget without a new build.
    pub fn truncated(&self, keep_visibility: Selection, keep_field: Selection) -> Result<Self> {
        let param = self.param();
        keep_visibility.limit(param.texels() - param.faces())?;
        let fields = self
            .fields
            .iter()
            .map(|f| Ok(Arc::new(f.truncated(keep_field)?)))
            .collect::<Result<Vec<_>>>()?;
        let select = |rows: &SparseRows<f32>| Arc::new(select_rows(param, keep_visibility, rows));
        let objects = self
            .objects
            .iter()
            .map(|o| {
                Ok(Object {
                    transport: select(&o.transport),
                    field: turned(&fields[o.shape], o.placement.turn)?,
                    ..o.clone()
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let mut options = self.options;
        options.keep_visibility = keep_visibility;
        options.field.keep = keep_field;
        Ok(DynamicScene {
            options,
            fields,
            objects,
            ground: self
                .ground
                .as_ref()
                .map(|(g, rows)| (g.clone(), select(rows))),
            ..self.clone()
        })
    }

    /// Changes how the scene is shaded (none of these needs a new build): the truncation of
    /// looked-up maps, of just-in-time transfer's fixed products, and the depth.
    pub fn set_shading(
        &mut self,
        truncation: Truncation,
        keep_product: Selection,
        depth: Option<usize>,
    ) -> Result<()> {
        let mut options = self.options;
        (options.truncation, options.keep_product, options.depth) =
            (truncation, keep_product, depth);
        options.check()?;
        self.options = options;
        Ok(())
    }

    /// Objects (instances).
    pub fn object_count(&self) -> usize {
        self.objects.len()
    }

    /// Distinct shapes (each with one set of fields).
    pub fn shape_count(&self) -> usize {
        self.shapes.len()
    }

    /// The fields of object `k`'s shape, turned to its placement.
    pub fn field(&self, k: usize) -> &OcclusionField {
        &self.objects[k].field
    }

    /// The object named `name`.
    pub fn object_index(&self, name: &str) -> Option<usize> {
        self.objects
            .iter()
            .position(|o| o.name.as_deref() == Some(name))
    }

    /// Object `k`'s name in the scene file, if it has one.
    pub fn object_name(&self, k: usize) -> Option<&str> {
        self.objects.get(k).and_then(|o| o.name.as_deref())
    }

    /// Object `k`'s placement.
    pub fn placement(&self, k: usize) -> Placement {
        self.objects[k].placement
    }

    /// Moves object `k`; a new turn turns its field (every map: the cost of a re-formation,
    /// not of a frame).
    pub fn place(&mut self, k: usize, placement: Placement) -> Result<()> {
        self.check_object(k)?;
        if !(placement.scale.is_finite() && placement.scale > 0.0)
            || placement.translate.iter().any(|x| !x.is_finite())
            || placement.turn >= columns(self.param())
            || (self.param().kind() == ParamKind::Cube && placement.turn != 0)
        {
            return Err(Error::parameter(
                "placement",
                format!(
                    "{placement:?}: the scale must be positive, the translation finite, the \
                     turn below {} columns (0 for a cube map)",
                    columns(self.param())
                ),
            ));
        }
        // Every placed vertex stays in range, as a scene file's are: a rotation keeps lengths,
        // so `|R(s q) + t|_k <= s |q| + |t_k|`.
        let b = self.shapes[self.objects[k].shape].bounds();
        let radius = (0..3)
            .map(|c| b.min[c].abs().max(b.max[c].abs()).powi(2))
            .sum::<f64>()
            .sqrt();
        let reach = placement
            .translate
            .map(|t| t.abs() + placement.scale * radius);
        crate::scene::validate::check_point("the placed object", reach)?;
        let o = &mut self.objects[k];
        if placement.turn != o.placement.turn {
            o.field = turned(&self.fields[o.shape], placement.turn)?;
        }
        o.placement = placement;
        Ok(())
    }

    /// Adds an instance of object `k`'s shape at `placement` (its own transport is `k`'s);
    /// returns its index. Its vertices come after every object's, before the ground's.
    pub fn clone_object(&mut self, k: usize, placement: Placement) -> Result<usize> {
        self.check_object(k)?;
        let mut copy = self.objects[k].clone();
        copy.name = None;
        copy.placement = copy.rest;
        self.objects.push(copy);
        let new = self.objects.len() - 1;
        self.place(new, placement)?;
        Ok(new)
    }

    fn check_object(&self, k: usize) -> Result<()> {
        if k >= self.objects.len() {
            return Err(Error::parameter(
                "object",
                format!("{k}: the scene has {} objects", self.objects.len()),
            ));
        }
        Ok(())
    }

    /// Vertices of all objects and the ground plane.
    pub fn vertex_count(&self) -> usize {
        self.objects
            .iter()
            .map(|o| self.shapes[o.shape].vertex_count())
            .sum::<usize>()
            + self.ground.as_ref().map_or(0, |g| g.0.vertex_count())
    }

    /// The vertices of object `k`: a range of the merged mesh's.
    pub fn object_vertices(&self, k: usize) -> std::ops::Range<usize> {
        let start: usize = self.objects[..k]
            .iter()
            .map(|o| self.shapes[o.shape].vertex_count())
            .sum();
        start..start + self.shapes[self.objects[k].shape].vertex_count()
    }

    /// Every object at its placement, then the ground plane, as one mesh (for the reference
    /// and the rasteriser).
    pub fn mesh(&self) -> Mesh {
        let param = self.param();
        merge(
            self.objects
                .iter()
                .map(|o| {
                    place_mesh(&self.shapes[o.shape], &o.placement, param)
                        .expect("placements are checked in range when made")
                })
                .chain(self.ground.iter().map(|g| g.0.clone())),
        )
    }

    /// The albedo of every vertex of [`mesh`](Self::mesh), `(V, 3)`.
    pub fn albedo(&self) -> Array2<f32> {
        let ground = self
            .ground
            .iter()
            .flat_map(|(g, _)| std::iter::repeat_n(crate::scene::GROUND_ALBEDO, g.vertex_count()));
        let rows: Vec<[f32; 3]> = self
            .objects
            .iter()
            .flat_map(|o| o.albedo.rows().into_iter().map(|r| [r[0], r[1], r[2]]))
            .chain(ground)
            .collect();
        Array2::from_shape_fn((rows.len(), 3), |(v, c)| rows[v][c])
    }
}

mod build;
pub mod fields;
mod glossy;
mod jrt;
pub mod motion;
mod options;
mod placement;
mod products;
pub mod request;
mod shading;
pub use jrt::{Change, JustInTimeTransfer, TransferReport};
pub use options::{DynamicBudgets, DynamicOptions};
pub use placement::Placement;
use placement::{columns, place_mesh, turned};
use shading::{Receiver, Scratch, light_sparse, light_tree, radiance};

#[cfg(test)]
mod tests;
